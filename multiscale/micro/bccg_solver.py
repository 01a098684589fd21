"""Preconditioned constrained conjugate gradients for FFT-BEM normal contact (a chunk of patches).

The method is the bound-constrained CG (BCCG) of Vollebregt (2014), "A new solver for the
elastic normal contact problem using conjugate gradients, deflation, and an FFT-based
preconditioner", J. Comput. Phys. 257, 333–351: the Polonsky–Keer (1999) iteration on the free
set with an FFT-based preconditioner M = L⁻¹ (the inverse of the influence operator on the FFT
grid, ``InfluenceOperator.inverse_spectrum``) and the force balance kept by projecting the
gradient and the directions on Σ p = const over the free set (the deflation of the total force).
The details here:

- free set F = contact cells (p > 0) and cells with p = 0 and a negative gap; cells leave by the
  projection p <- max(p - tau t, 0) and enter along the preconditioned direction;
- preconditioner Eᵀ M E: the residual r on F is extended by E into two rings of gap cells around
  F (each ring gamma_k times the mean of its neighbours in the ring inside) before M and folded
  back by Eᵀ. M restricted to F (zero extension) over-estimates the stiffness of contact spots
  next to narrow gaps and of their edges: the exact inverse (L_FF)⁻¹ is the Schur complement
  E*ᵀ M E* with E* the displacement of the gap cells, which E imitates. On the self-affine
  benchmark surfaces at N = 1024 the condition number on the final contact set drops from 8.1
  to 4.1 (either way it grows with the roughness the grid resolves: more, smaller, more ragged
  spots; one surface on finer grids keeps its iterations, benchmarks/README). The growth sits in
  coarse modes, nearly constant over aggregates of F: on grids of ``COARSE_FROM`` cells and more
  a balancing two-level coarse correction takes them out (``bccg_coarse``; one-level on free sets
  of more than a tenth of the grid). Any E keeps Eᵀ M E symmetric positive definite, and so is
  the two-level preconditioner, so the discrete answer is that of Polonsky–Keer;
- Polak–Ribière(+) factors (conjugacy survives small changes of F), restart when t is not a
  descent direction;
- the rings can block the iteration: on a measured plateau surface (plu-1, 384², 61 % contact)
  eps stayed at 0.22 from the 10th iteration on, with 8 % too many contact cells (the
  preconditioned direction on F is not sign-consistent with the gap, and the projection clips
  what it would move). A patch whose best eps is not halved within ``STALL`` iterations drops its
  rings (gamma = 0: M restricted to F) and restarts the CG: 86 iterations there (Polonsky–Keer
  579). On the benchmark surfaces eps halves every one or two iterations and it never triggers;
- two FFT pairs per iteration: Y = M E r, and L t, whose inverse transform is also the update of
  u = L p: (t, L t) comes from Parseval, and u <- u + L(p_new - p); when the projection clipped
  cells, p_new - p (no longer -tau t) is transformed forward (2.5 pairs);
- on grids of 512² and more (``SINGLE_FROM``; there a float32 pair takes 0.42-0.79x the time of a
  double one) both pairs are in single precision, in the sense of Higham & Mary (2022, Acta
  Numerica 31, 347–414). The preconditioner's rounding (relative 1e-7) perturbs the direction,
  not the equations. The rounding of the updates of u stays in u instead: about ``DRIFT`` times
  ||p_new - p|| / ||p|| per step (measured 0.2-0.4 of that), summed in ``drift``. So u = L p is
  recomputed in double (the residual replacement of van der Vorst & Ye 2000, SIAM J. Sci.
  Comput. 22, 835–852) once that sum exceeds 1 % of the tolerance and either reaches ``ROOT`` =
  √DRIFT times eps (the iteration would soon stall on it) or eps comes within 100x of the
  tolerance (the last chance before the stop). The drift left at the end is below 1 % of the
  tolerance, so the answer is the discrete one and the stopping criterion below holds for the true
  residual.
  On the benchmark surfaces at N = 512 ... 2048, tol 1e-4 ... 1e-12: the same iterations as in
  double, 0-2 replacements, drift below 7e-4 tol; the solves take 0.84-0.87x the time of the
  double steps at 2048², 0.90-0.93x at 1024².

The start is nested (``ContactSolver.coarse_start``). Stopping criterion: eps = ||s|| / ||p|| <=
tol, with s = Eᵀ M E r (two-level: ``bccg_coarse``'s P r) the preconditioned residual over F,
i.e. the pressure correction that the preconditioner predicts: an estimate of the relative L2
error of the pressure (it was 0.3-0.7 times the true error on the benchmark surfaces), free of
units (a flat punch stops where a rough patch does).
"""
from __future__ import annotations

import numpy as np

from multiscale.micro import bccg_coarse, bccg_steps
from multiscale.micro.kernels import ConvolutionWorkspace, InfluenceOperator, multiply

GAMMAS = np.array([0.6, 0.3])   # extension factors of the rings 1, 2 around the free set
STALL = 30                      # iterations without halving a patch's best eps: its rings are dropped
REFRESH = 50                           # iterations between exact recomputations of u = L p
SINGLE_FROM = 512 * 512                # FFT grids of this many cells and more: the iteration's pairs in float32
DRIFT = float(np.finfo(np.float32).eps)   # drift of u per relative pressure step in float32 (measured: 0.2-0.4 of it)
ROOT = float(np.sqrt(DRIFT))           # u = L p recomputed when the drift reaches this fraction of eps
COARSE_FROM = 1024 * 1024              # grids of this many cells and more: two-level preconditioner (bccg_coarse)


class Scratch:
    """Buffers of one chunk of B patches (reused between solves of the same chunk size); the
    per-cell ones flattened to (B, ny * nx), see ``bccg_steps``. ``ws`` applies L in double (u =
    L p), ``step`` applies L to the directions and increments (``X``, ``Y``: its flat buffers) and
    ``pre`` the preconditioner M: both in single precision on large grids (``SINGLE_FROM``), else
    ``step`` is ``ws`` and ``pre`` double (``step`` is ``ws`` too when ``steps`` is False: buffers
    for ``estimate`` only, which takes no step); ``coarse``: the two-level correction of each
    patch (when asked for and the grid has ``COARSE_FROM`` cells or more, else None)."""

    def __init__(self, operator: InfluenceOperator, B: int, threads: int | None = None, coarse: bool = False,
                 steps: bool = True):
        ny, nx = operator.shape
        N = ny * nx
        single = operator.fft_shape[0] * operator.fft_shape[1] >= SINGLE_FROM
        self.ws: ConvolutionWorkspace = operator.workspace((B,), threads)
        self.step: ConvolutionWorkspace = operator.workspace((B,), threads, True) if single and steps else self.ws
        self.pre: ConvolutionWorkspace = operator.workspace((B,), threads, single)
        self.mmul = operator.inverse_multiplier.astype(self.pre.fft.input.dtype)
        self.X = self.step.load_buffer.reshape(B, -1)          # flat views of the FFT buffers
        self.Y = self.step.response_buffer.reshape(B, -1)
        self.XP = self.pre.load_buffer.reshape(B, -1)
        self.YP = self.pre.response_buffer.reshape(B, -1)
        self.label = np.full((B, N), -1, dtype=np.int8)
        self.count = np.zeros((B, N), dtype=np.int8)
        self.fi, self.fj, self.bi, self.bj = (np.zeros((B, N), dtype=np.int32) for _ in range(4))
        self.ring_end = np.zeros((B, len(GAMMAS)), dtype=np.int64)
        self.gammas = np.tile(GAMMAS, (B, 1))                  # per patch: 0 once its iteration stalled
        self.r, self.s, self.s_old, self.t = (np.zeros((B, N)) for _ in range(4))
        self.coarse = None
        if coarse and N >= COARSE_FROM and bccg_coarse.CoarseGrid.fits(operator):
            grid = bccg_coarse.CoarseGrid(operator)
            self.coarse = [bccg_coarse.CoarseCorrection(grid) for _ in range(B)]

    def clear(self) -> None:
        """Zero every buffer (after a failed solve)."""
        for w in {self.ws, self.step, self.pre}:
            w.clear()
        for a in (self.r, self.s, self.s_old, self.t):
            a[...] = 0.0
        self.label[...] = -1
        for c in self.coarse or ():
            c.reset()


def exact_displacement(operator: InfluenceOperator, ws: ConvolutionWorkspace, p: np.ndarray, u: np.ndarray,
                       which: np.ndarray) -> None:
    """u = L p on the patches ``which`` (p, u: (B, ny, nx); one batched FFT pair); the FFT input
    is left zeroed."""
    ny, nx = operator.shape
    ws.load_buffer[...] = 0.0
    ws.load_buffer[which, :ny, :nx] = p[which]
    ws.apply()
    u[which] = ws.response_buffer[which, :ny, :nx]
    ws.load_buffer[...] = 0.0


def preconditioned_residual(operator: InfluenceOperator, work: Scratch, z2, p2, u2, delta, load_control, which,
                            ccount, csum, d, nf, upper, fixed, pnorm, eps) -> None:
    """The free set, the residual r on it and s = Eᵀ M E r with eps = ||s|| / ||p|| (``work.r``,
    ``work.s``, ``eps``) of the patches ``which`` (flat (B, ny * nx) states, ``contact_sums``
    done): ``bccg_steps.free_set``, ``extend``, the preconditioner's FFT pair, ``back_extend``;
    with a coarse correction, r - K y1 is extended instead of r and s completed after
    (``bccg_coarse.CoarseCorrection``: s = P r of the two-level preconditioner)."""
    ny, nx = operator.shape
    Fx = operator.fft_shape[1]
    bccg_steps.free_set(u2, z2, p2, delta, load_control, which, ccount, csum, d, work.label, work.fi, work.fj, nf,
                        work.r, work.s_old, work.t, work.XP, work.X, upper, fixed, nx, Fx)
    coarse = [] if work.coarse is None else [(b, work.coarse[b]) for b in np.flatnonzero(which)]
    for b, c in coarse:
        c.prepare(work.fi[b], work.fj[b], nf[b])
        if c.active:
            c.balance(work.fi[b], work.fj[b], nf[b], work.r[b], work.XP[b], Fx)
    bccg_steps.extend(work.label, work.fi, work.fj, nf, work.bi, work.bj, work.ring_end, work.count, work.XP,
                      work.gammas, operator.periodic, which, ny, nx, Fx)
    work.pre.apply(work.mmul)
    bccg_steps.back_extend(work.label, work.fi, work.fj, nf, work.bi, work.bj, work.ring_end, work.count, work.YP,
                           work.s, work.gammas, operator.periodic, work.XP, load_control, which, pnorm, eps, ny, nx, Fx)
    for b, c in coarse:
        if c.active:
            ss = c.complete(work.fi[b], work.fj[b], nf[b], work.s[b], load_control)
            eps[b] = np.sqrt(ss / pnorm[b]) if pnorm[b] > 0.0 else (0.0 if ss == 0.0 else np.inf)


def estimate(operator: InfluenceOperator, work: Scratch, z, p, u, target, delta, which) -> tuple:
    """The stopping criterion of ``run`` for a state (p, u = L p; (B, ny, nx)) of the patches
    ``which``, without a pressure bound: (eps, d) per patch (one FFT pair; eps = inf elsewhere)."""
    B, ny, nx = z.shape
    z2, p2, u2 = (np.ascontiguousarray(a).reshape(B, ny * nx) for a in (z, p, u))
    load_control = target is not None
    delta = np.ascontiguousarray(np.zeros(B) if delta is None else delta, dtype=float)
    d, pnorm, eps, csum = np.zeros(B), np.zeros(B), np.full(B, np.inf), np.zeros(B)
    nf, ccount, fixed = (np.zeros(B, dtype=np.int64) for _ in range(3))
    upper = np.full(B, np.inf)
    work.X[...] = 0.0
    work.XP[...] = 0.0
    bccg_steps.contact_sums(p2, u2, z2, upper, which, ccount, csum, pnorm)
    preconditioned_residual(operator, work, z2, p2, u2, delta, load_control, which, ccount, csum, d, nf, upper, fixed,
                            pnorm, eps)
    work.XP[...] = 0.0
    return eps, d


def run(operator: InfluenceOperator, work: Scratch, z: np.ndarray, p: np.ndarray, u: np.ndarray, target, delta,
        tol: float, max_iter: int, history: list, upper=None) -> dict:
    """Iterate on the chunk (z, p, u: (B, ny, nx) contiguous; p the feasible start, balanced under
    load control: ``target`` the mean pressures, else ``delta`` the approaches; ``upper`` the
    pressure bounds H (B,), None: elastic). p and u (= L p) are updated in place; returns d,
    iterations, residual (eps), converged; ``history`` gets the largest eps per iteration."""
    B, ny, nx = z.shape
    N, Fx = ny * nx, operator.fft_shape[1]
    ws, step = work.ws, work.step
    X, Y, S = work.X, work.Y, step.fft.spectrum
    lmul = operator.multiplier
    load_control = target is not None
    target = np.ascontiguousarray(np.zeros(B) if target is None else target, dtype=float)
    delta = np.ascontiguousarray(np.zeros(B) if delta is None else delta, dtype=float)
    z2, p2, u2 = z.reshape(B, N), p.reshape(B, N), u.reshape(B, N)    # views
    active = np.ones(B, dtype=bool)
    d, pending, pnorm, eps, rt, tau, rho_old, csum, factor, steps, drift = (np.zeros(B) for _ in range(11))
    pending[:] = 1.0
    eps[:] = np.inf
    nf, ccount, fixed = (np.zeros(B, dtype=np.int64) for _ in range(3))
    upper = np.ascontiguousarray(np.full(B, np.inf) if upper is None else upper, dtype=float)
    conj, clipped, lost = (np.zeros(B, dtype=bool) for _ in range(3))
    iterations = np.zeros(B, dtype=int)
    work.label[...] = -1                     # no free set and no history yet
    for c in work.coarse or ():
        c.reset()
    work.XP[...] = 0.0
    work.s_old[...] = 0.0
    work.t[...] = 0.0
    work.gammas[...] = GAMMAS
    mark, marked = np.full(B, np.inf), np.zeros(B, dtype=int)    # best eps halved at iteration ``marked``

    def exact(which):                        # u = L p and the contact sums on the patches ``which``
        exact_displacement(operator, ws, p, u, which)
        bccg_steps.contact_sums(p2, u2, z2, upper, which, ccount, csum, pnorm)

    exact(active)
    since = 0                                # iterations since the last exact u
    while True:
        preconditioned_residual(operator, work, z2, p2, u2, delta, load_control, active, ccount, csum, d, nf, upper,
                                fixed, pnorm, eps)
        top, left, bad = bccg_steps.check(eps, tol, iterations, max_iter, active, work.XP, X)
        if bad:
            raise FloatingPointError("non-finite residual")
        history.append(top)
        if not left:
            break
        better = eps <= 0.5 * mark
        mark[better], marked[better] = eps[better], iterations[better]
        stalled = active & (iterations - marked >= STALL) & (work.gammas[:, 0] > 0.0)
        if stalled.any():                    # the rings' preconditioned direction is blocked: drop them
            work.gammas[stalled] = 0.0
            conj[stalled] = False
            mark[stalled], marked[stalled] = np.inf, iterations[stalled]
        bccg_steps.direction(work.fi, work.fj, nf, work.r, work.s, work.s_old, work.t, X, load_control, active, conj,
                             rho_old, rt, iterations, nx, Fx)
        step.fft.forward()
        if not bccg_steps.step_length(S, lmul, Fx, rt, active, tau):
            raise FloatingPointError("non-finite step length")
        clipped_any, lost_any = bccg_steps.update_pressure(p2, work.t, work.fi, work.fj, nf, tau, X, active,
                                                           load_control, target, pending, clipped, lost, upper,
                                                           fixed, steps, work.s, nx, Fx)   # s: free until back_extend
        if clipped_any:                      # u += L(p_new - p): one more forward FFT
            step.fft.forward()
            factor.fill(1.0)
        else:                                # u += -tau L t
            np.negative(tau, out=factor)
        multiply(S, lmul)
        step.fft.inverse(normalise=False)
        bccg_steps.add_response(u2, Y, factor, p2, z2, work.fi, work.fj, nf, pending, active, ccount, csum, pnorm,
                                upper, fixed, nx, Fx)
        since += 1
        if lost_any:                         # every cell left the contact: restart from the top
            for b in np.flatnonzero(lost):
                summit = (z[b] == 0).astype(float)
                p[b] = summit * (target[b] / summit.mean())
            conj[lost] = False
            exact(lost)
            drift[lost] = 0.0
        stale = None                         # patches whose u = L p is recomputed
        if since >= REFRESH:                 # bound the round-off drift of the updates of u
            stale, since = active & ~lost, 0
        elif step is not ws:                 # float32 steps: their rounding (DRIFT of each) stays in u
            drift += DRIFT * np.sqrt(np.divide(steps, pnorm, out=np.zeros(B), where=pnorm > 0.0))
            stale = active & ~lost & (drift > 0.01 * tol) & ((drift > ROOT * eps) | (eps < 100.0 * tol))
        if stale is not None and stale.any():
            exact(stale)
            drift[stale] = 0.0
    converged = eps <= tol
    return dict(d=d, iterations=iterations, residual=eps, converged=converged)

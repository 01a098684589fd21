"""Polonsky–Keer constrained conjugate gradients on a chunk of patches (``method="pk"``).

Polonsky & Keer (1999), "A numerical method for solving rough contact problems based on the
multi-level multi-summation and conjugate gradient techniques", Wear 231, 206–219: CG on the
contact set with the gap as residual, projection p >= 0, overlapping cells entering with -tau g
(and a restart), load balance by rescaling. The cell loops are compiled (``pk_steps``); the FFT
convolution of the direction runs on the whole chunk. Between exact evaluations u = L p is
updated as c (u − τ L t), exact while projection and overlap correction leave p alone; otherwise,
every ``REFRESH`` iterations and before accepting convergence, u is recomputed by FFT.

Stopping criterion: the one of ``bccg_solver`` (the relative L2 error of the pressure that the
FFT preconditioner predicts, ``bccg_solver.estimate``, one FFT pair), evaluated when a cheap
estimate says it may be met: the gap residual in pressure units, ||g_F|| / (L_00 ||p||) with L_00
the self-influence, times the ratio of the two found at the last evaluation.
"""
from __future__ import annotations

import numpy as np

from multiscale.micro import bccg_solver, pk_steps
from multiscale.micro.kernels import ConvolutionWorkspace, InfluenceOperator

REFRESH = 25  # iterations between exact recomputations of u = L p (bounds round-off drift)


def rescale(p, target, z):
    """Scale each patch of p (B, N) so that its mean is the target mean pressure (load balance,
    exact). A patch that lost all contact restarts from its highest points (z == 0)."""
    p = np.asarray(p, dtype=float)
    mean = p.mean(axis=1)
    if np.any(mean <= 0):
        p = np.where((mean > 0)[:, None], p, (z == 0).astype(float))
        mean = p.mean(axis=1)
    return p * (target / mean)[:, None]


def run(operator: InfluenceOperator, ws: ConvolutionWorkspace, estimator: bccg_solver.Scratch, z, p, u, target,
        delta, tol: float, max_iter: int, history: list) -> dict:
    """Polonsky–Keer iterations on B patches (z, p, u: (B, ny, nx), p feasible and balanced under
    load control; ``target`` mean pressures or ``delta`` approaches: (B,)). p and u (= L p) are
    updated in place; returns d, iterations, residual, converged. ``estimator``: buffers of the
    stopping test."""
    L, grid = operator, z.shape[-2:]
    B, N = z.shape[0], grid[0] * grid[1]
    load_control = target is not None
    target_, delta_ = (None if a is None else np.asarray(a, dtype=float) for a in (target, delta))
    target, delta = (np.ascontiguousarray(np.zeros(B) if a is None else a, dtype=float) for a in (target, delta))
    t, r = ws.load_buffer.reshape((B,) + L.fft_shape), ws.response_buffer.reshape((B,) + L.fft_shape)
    t[...] = 0.0
    p3, z3 = p, np.ascontiguousarray(z)
    pf = p.reshape(B, N)
    u3 = u
    exact = np.ones(B, dtype=bool)

    def recompute(which):                     # u = L p exactly on the patches ``which`` (the
        bccg_solver.exact_displacement(L, estimator.ws, p3, u3, which)   # chunk's own buffers)
        exact[which] = True

    recompute(exact)
    d, G, gmin, Gneg, pnorm = (np.zeros(B) for _ in range(5))
    count = np.zeros(B, dtype=np.int64)
    corrected, lost, conjugate = (np.zeros(B, dtype=bool) for _ in range(3))
    pending = np.ones(B)                      # load-balance factor of p and u, see pk_steps.step
    G_old, active = np.ones(B), np.ones(B, dtype=bool)
    ratio, res = np.ones(B), np.full(B, np.inf)
    iterations = np.zeros(B, dtype=int)
    since_refresh = 0
    while True:
        pk_steps.gap_statistics(p3, u3, z3, delta, load_control, pending, d, G, count, gmin, Gneg, pnorm)
        cheap = np.sqrt((G + Gneg) / np.where(pnorm > 0, pnorm, 1.0)) / L.self_influence
        cheap = np.where(pnorm > 0, cheap, np.where(G + Gneg > 0, np.inf, 0.0))
        if not np.all(np.isfinite(cheap[active])):
            raise FloatingPointError("non-finite residual")
        res = np.where(active, ratio * cheap, res)
        candidate = active & (res <= tol)
        if np.any(candidate & ~exact):        # accept convergence only on an exact displacement
            recompute(candidate & ~exact)
            since_refresh = 0
            continue
        if candidate.any():                   # confirm with the preconditioned estimate
            eps, _ = bccg_solver.estimate(L, estimator, z3, p3, u3, target_, delta_, candidate)
            ratio[candidate] = np.maximum(eps[candidate] / np.maximum(cheap[candidate], 1e-300), 1.0)
            res[candidate] = eps[candidate]
        done = candidate & (res <= tol)
        active &= ~done
        history.append(float(res[active | done].max()) if (active | done).any() else 0.0)
        if not active.any() or iterations.max() >= max_iter:
            break
        iterations += active
        beta = np.where(conjugate, G / G_old, 0.0)
        G_old = np.where(G > 0, G, 1.0)
        pk_steps.direction(p3, u3, z3, d, active, beta, t)                  # t: the direction
        ws.apply()
        pk_steps.step(p3, u3, z3, d, count, target, load_control, active, t, r, pending, corrected, lost,
                      conjugate)                                          # r = L t
        if lost.any():                        # every point left the contact: restart from the top
            pf[lost] = rescale(z3.reshape(B, N)[lost] == 0, target[lost], z3.reshape(B, N)[lost])
        since_refresh += 1
        exact[:] = False
        if since_refresh >= REFRESH:
            recompute(active)
            since_refresh = 0
        else:
            recompute(corrected & active)
    return dict(d=d, iterations=iterations, residual=res, converged=res <= tol)

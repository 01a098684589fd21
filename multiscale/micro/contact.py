"""FFT-BEM frictionless normal contact of a rough elastic solid and a rigid flat (thesis §3.3).

The complementary energy U = ½ pᵀ L p − pᵀ δ (Eqs. 3.4, 3.9) is minimised over p ≥ 0 by the
constrained conjugate gradient of Polonsky & Keer (1999), with ``L`` applied by FFT
(``InfluenceOperator``). Load control fixes the mean pressure, displacement control the rigid
approach. Batches of patches (leading axes) are solved in one call, each patch iterating on its
own until it converges (then it is frozen), so batched and looped answers agree. The cell loops
of an iteration are compiled (``pk_steps``, numba); a batch runs in chunks of ``_CHUNK_CELLS``
cells that keep the working set in the CPU cache.

Conventions: heights ``h`` [m] point towards the rigid flat. The flat first touches the highest
point; the approach ``delta`` [m] moves it into the solid. Gap
``g = (max h − h) − delta + u ≥ 0`` with the elastic displacement ``u = L p`` positive into the
solid; pressure [Pa] positive in compression.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.micro import pk_steps
from multiscale.micro.kernels import InfluenceOperator, Kernel


@dataclass
class ContactResult:
    """Solution of a (batch of) contact problem(s); per-patch arrays have the batch shape."""

    pressure: np.ndarray       # Pa, (..., ny, nx)
    displacement: np.ndarray   # m, elastic normal displacement, positive into the solid
    gap: np.ndarray            # m, >= 0, zero on the contact
    contact: np.ndarray        # bool, p > 0
    area_fraction: np.ndarray  # real contact area / nominal area
    mean_pressure: np.ndarray  # Pa, total force / nominal area
    approach: np.ndarray       # m, rigid approach delta from first touch
    mean_gap: np.ndarray       # m, mean separation between the flat and the deformed surface
    iterations: np.ndarray     # per patch
    residual: np.ndarray       # per patch, see ContactSolver.solve
    converged: np.ndarray      # bool per patch
    history: list = field(default_factory=list, repr=False)  # max residual per iteration


class ContactConvergenceError(ConvergenceError):
    """The contact solver reached ``max_iter`` before ``tol``."""


class ContactSolver:
    """Reusable FFT-BEM contact solver on one grid (plans and kernel spectrum built once).

    Parameters: kernel (e.g. ``HalfSpace``), grid ``shape`` (ny, nx), pixel ``dx`` (and ``dy``) [m],
    ``periodic`` (repeating patch) or not (isolated patch, zero-padded DC-FFT). A solver keeps
    its FFT buffers between calls: use one solver per thread.
    """

    def __init__(self, kernel: Kernel, shape, dx: float, dy: float | None = None, periodic: bool = True):
        self.operator = InfluenceOperator(kernel, shape, dx, dy, periodic)
        self.kernel, self.shape, self.periodic = kernel, self.operator.shape, periodic
        self._workspaces = {}                     # batch size -> FFT buffers of the direction

    def solve(self, heights, *, load=None, approach=None, tol: float = 1e-8, max_iter: int = 5000,
              initial_pressure=None, partial: bool = False) -> ContactResult:
        """Solve under load control (``load`` = mean pressure [Pa]) or displacement control
        (``approach`` = delta [m]); scalars or arrays of the batch shape.

        Stops when the residual ``max(rms(g on contact), max(−g off contact)) / rms(h)`` is below
        ``tol`` (the pressure then balances the load exactly). Raises ``ContactConvergenceError``
        after ``max_iter`` iterations unless ``partial`` is True.
        """
        h = np.asarray(heights, dtype=float)
        if h.ndim < 2 or h.shape[-2:] != self.shape:
            raise InputError("heights.shape", h.shape, f"last two axes must be {self.shape}")
        if h.size == 0:
            raise InputError("heights.shape", h.shape, "the batch holds no patch")
        if not np.all(np.isfinite(h)):
            raise InputError("heights", "array with NaN/inf", "all heights must be finite")
        check_positive("tol", tol)
        if (load is None) == (approach is None):
            raise InputError("load/approach", (load, approach), "give exactly one of them")
        batch = h.shape[:-2]
        z = h.max(axis=(-2, -1), keepdims=True) - h            # depth below the highest point, >= 0
        scale = np.sqrt(np.mean((h - h.mean(axis=(-2, -1), keepdims=True)) ** 2, axis=(-2, -1)))
        scale = np.where(scale > 0, scale, 1.0)
        if load is not None:
            target = np.broadcast_to(np.asarray(load, dtype=float), batch)
            if not np.all(np.isfinite(target)) or np.any(target <= 0):
                raise InputError("load", load, "mean pressure must be finite and > 0")
            delta = None
        else:
            target = None
            delta = np.broadcast_to(np.asarray(approach, dtype=float), batch)
            if not np.all(np.isfinite(delta)) or np.any(delta < 0):
                raise InputError("approach", approach, "rigid approach must be finite and >= 0")
            if self.periodic and np.any(delta >= z.mean(axis=(-2, -1))):
                raise InputError("approach", approach, "a periodic patch under displacement control needs "
                                 "approach < max(h) - mean(h) (full contact has no finite load)")
        p0 = None
        if initial_pressure is not None:
            p0 = np.broadcast_to(np.asarray(initial_pressure, dtype=float), h.shape)
            if np.any(p0 < 0) or not np.all(np.isfinite(p0)):
                raise InputError("initial_pressure", "array", "must be finite and >= 0")
        return self._run_chunks(z, scale, target, delta, tol, max_iter, p0, partial)

    def _run_chunks(self, z, scale, target, delta, tol, max_iter, p0, partial):
        """Run the iterations on chunks of the batch small enough for the CPU cache (the full-grid
        passes are memory bound: 400 patches of 64² in one block run ~2x slower than in chunks
        of 8), then assemble the batch result."""
        batch, grid = z.shape[:-2], z.shape[-2:]
        B = int(np.prod(batch, dtype=int))
        size = max(1, _CHUNK_CELLS // (grid[0] * grid[1]))

        def flat(a, cells=False):
            return None if a is None else np.reshape(a, (B,) + (grid if cells else ()))

        z, scale, target, delta, p0 = flat(z, True), flat(scale), flat(target), flat(delta), flat(p0, True)
        parts = [self._run(z[i:i + size], scale[i:i + size],
                           None if target is None else target[i:i + size],
                           None if delta is None else delta[i:i + size], tol, max_iter,
                           None if p0 is None else p0[i:i + size]) for i in range(0, B, size)]
        length = max(len(r.history) for r in parts)
        history = [max(r.history[k] for r in parts if k < len(r.history)) for k in range(length)]
        fields = {f: np.concatenate([getattr(r, f) for r in parts]).reshape(batch + np.shape(getattr(parts[0], f))[1:])
                  for f in ContactResult.__dataclass_fields__ if f != "history"}
        result = ContactResult(**fields, history=history)
        if not np.all(result.converged) and not partial:
            raise ContactConvergenceError(
                f"contact solver did not converge in {max_iter} iterations "
                f"(residual {result.residual.max():.3e} > tol {tol:.1e} on "
                f"{int(np.sum(~result.converged))} patch(es))", history, result)
        return result

    def _run(self, z, scale, target, delta, tol, max_iter, p0):
        """Polonsky–Keer iterations on B patches (z: (B, ny, nx); scale, target or delta: (B,));
        returns the partial result of shape (B, ...) when not converged.

        The cell loops of each iteration are compiled (``pk_steps``); the FFT convolution of the
        direction runs on the whole chunk. Between exact evaluations u = L p is updated as
        c (u − τ L t), exact while projection and overlap correction leave p alone; otherwise,
        every ``_REFRESH`` iterations and before accepting convergence, u is recomputed by FFT.
        """
        L, grid = self.operator, z.shape[-2:]
        B, N = z.shape[0], grid[0] * grid[1]
        zf = np.ascontiguousarray(z, dtype=float).reshape(B, N)
        load_control = target is not None
        if p0 is not None:
            p = np.array(p0, dtype=float).reshape(B, N)
        elif load_control:
            p = np.repeat(target[:, None], N, axis=1)
        else:
            p = np.maximum(delta[:, None] - zf, 0.0) / L.self_influence
        if load_control:
            p = _rescale(p, target, zf)
        target, delta = (np.ascontiguousarray(np.zeros(B) if a is None else a, dtype=float)
                         for a in (target, delta))          # the compiled loops take arrays
        ws = self._workspaces.get(B)
        if ws is None:
            ws = self._workspaces[B] = L.workspace((B,))
        t, r = ws.load_buffer.reshape((B,) + L.fft_shape), ws.response_buffer.reshape((B,) + L.fft_shape)
        p3 = p.reshape((B,) + grid)
        u = np.zeros((B, N))
        u3, z3 = u.reshape(p3.shape), zf.reshape(p3.shape)
        exact = np.ones(B, dtype=bool)

        def recompute(which):                     # u = L p exactly on the patches ``which``
            if 2 * np.count_nonzero(which) > B:
                L(p3, out=u3)
                exact[:] = True
            else:
                for b in np.flatnonzero(which):
                    L(p3[b], out=u3[b])
                exact[which] = True

        recompute(exact)
        d, G, gmin, count = np.zeros(B), np.zeros(B), np.zeros(B), np.zeros(B, dtype=np.int64)
        corrected, lost, conjugate = (np.zeros(B, dtype=bool) for _ in range(3))
        pending = np.ones(B)                      # load-balance factor of p and u, see pk_steps.step
        G_old, active = np.ones(B), np.ones(B, dtype=bool)
        iterations, history = np.zeros(B, dtype=int), []
        since_refresh = 0
        while True:
            pk_steps.gap_statistics(p3, u3, z3, delta, load_control, pending, d, G, count, gmin)
            res = np.maximum(np.sqrt(G / np.maximum(count, 1)), np.maximum(-gmin, 0.0)) / scale
            done = active & (res <= tol)
            if np.any(done & ~exact):        # accept convergence only on an exact displacement
                recompute(done & ~exact)
                since_refresh = 0
                continue
            active &= ~done
            history.append(float(res.max()))
            if not active.any() or iterations.max() >= max_iter:
                break
            iterations += active
            beta = np.where(conjugate, G / G_old, 0.0)
            G_old = np.where(G > 0, G, 1.0)
            pk_steps.direction(p3, u3, z3, d, active, beta, t)                  # t: the direction
            ws.apply()
            pk_steps.step(p3, u3, z3, d, count, target, load_control, active, t, r, pending, corrected, lost,
                     conjugate)                                             # r = L t
            if lost.any():                   # every point left the contact: restart from the top
                p[lost] = _rescale(zf[lost] == 0, target[lost], zf[lost])
            since_refresh += 1
            exact[:] = False
            if since_refresh >= _REFRESH:
                recompute(active)
                since_refresh = 0
            else:
                recompute(corrected & active)
        g = u + zf - d[:, None]
        gap = np.where(p > 0, 0.0, np.maximum(g, 0.0))
        shape = (B,) + grid
        return ContactResult(
            pressure=p.reshape(shape), displacement=u.reshape(shape), gap=gap.reshape(shape),
            contact=(p > 0).reshape(shape), area_fraction=np.mean(p > 0, axis=1),
            mean_pressure=p.mean(axis=1), approach=np.array(d, dtype=float), mean_gap=gap.mean(axis=1),
            iterations=iterations, residual=res, converged=~active, history=history)


_REFRESH = 25  # iterations between exact recomputations of u = L p (bounds round-off drift)
_CHUNK_CELLS = 32768  # cells per chunk of the batch (a few such float arrays fit in L2)


def _rescale(p, target, z):
    """Scale each row of p so that its mean is the target mean pressure (load balance, exact).

    A row that lost all contact restarts from its highest points (z == 0)."""
    p = np.asarray(p, dtype=float)
    mean = p.mean(axis=1)
    if np.any(mean <= 0):
        p = np.where((mean > 0)[:, None], p, (z == 0).astype(float))
        mean = p.mean(axis=1)
    return p * (target / mean)[:, None]


def solve_contact(heights, dx: float, kernel: Kernel, *, dy: float | None = None, periodic: bool = True,
                  **options) -> ContactResult:
    """One-call form of ``ContactSolver(kernel, heights.shape[-2:], dx, dy, periodic).solve(...)``."""
    h = np.asarray(heights)
    if h.ndim < 2:
        raise InputError("heights", h.shape, "must be at least 2-D (..., ny, nx)")
    return ContactSolver(kernel, h.shape[-2:], dx, dy, periodic).solve(h, **options)

"""FFT-BEM frictionless normal contact of a rough elastic solid and a rigid flat (thesis §3.3).

The complementary energy U = ½ pᵀ L p − pᵀ δ (Eqs. 3.4, 3.9) is minimised over p ≥ 0 by the
constrained conjugate gradient of Polonsky & Keer (1999), with ``L`` applied by FFT
(``InfluenceOperator``). Load control fixes the mean pressure, displacement control the rigid
approach. Batches of patches (leading axes) are solved in one call, each patch iterating on its
own until it converges (then it is frozen), so batched and looped answers agree.

Conventions: heights ``h`` [m] point towards the rigid flat. The flat first touches the highest
point; the approach ``delta`` [m] moves it into the solid. Gap
``g = (max h − h) − delta + u ≥ 0`` with the elastic displacement ``u = L p`` positive into the
solid; pressure [Pa] positive in compression.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import ConvergenceError, InputError, check_positive
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
    ``periodic`` (repeating patch) or not (isolated patch, zero-padded DC-FFT).
    """

    def __init__(self, kernel: Kernel, shape, dx: float, dy: float | None = None, periodic: bool = True):
        self.operator = InfluenceOperator(kernel, shape, dx, dy, periodic)
        self.kernel, self.shape, self.periodic = kernel, self.operator.shape, periodic

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
        if not np.all(np.isfinite(h)):
            raise InputError("heights", "array with NaN/inf", "all heights must be finite")
        check_positive("tol", tol)
        if (load is None) == (approach is None):
            raise InputError("load/approach", (load, approach), "give exactly one of them")
        batch = h.shape[:-2]
        z = h.max(axis=(-2, -1), keepdims=True) - h            # depth below the highest point, >= 0
        scale = np.sqrt(np.mean((h - h.mean(axis=(-2, -1), keepdims=True)) ** 2, axis=(-2, -1)))
        scale = np.where(scale > 0, scale, 1.0)[..., None, None]
        if load is not None:
            target = np.broadcast_to(np.asarray(load, dtype=float), batch)
            if not np.all(np.isfinite(target)) or np.any(target <= 0):
                raise InputError("load", load, "mean pressure must be finite and > 0")
            return self._run(z, scale, target, None, tol, max_iter, initial_pressure, partial)
        delta = np.broadcast_to(np.asarray(approach, dtype=float), batch)
        if not np.all(np.isfinite(delta)) or np.any(delta < 0):
            raise InputError("approach", approach, "rigid approach must be finite and >= 0")
        if self.periodic and np.any(delta >= z.mean(axis=(-2, -1))):
            raise InputError("approach", approach, "a periodic patch under displacement control needs "
                             "approach < max(h) - mean(h) (full contact has no finite load)")
        return self._run(z, scale, None, delta[..., None, None], tol, max_iter, initial_pressure, partial)

    def _run(self, z, scale, target, delta, tol, max_iter, p0, partial):
        """Polonsky–Keer iterations on (B, N) views of the batch (B patches of N cells).

        The conjugate direction lives on the contact set only, so the scalar products run on
        gathered contact values; full-grid passes are the FFT convolutions and a few updates.
        Between exact evaluations u = L p is updated as c (u − τ L t), exact while projection
        and overlap correction leave p alone; otherwise, every ``_REFRESH`` iterations and
        before accepting convergence, u is recomputed by FFT.
        """
        L = self.operator
        batch, grid = z.shape[:-2], z.shape[-2:]
        B, N = int(np.prod(batch, dtype=int)), grid[0] * grid[1]
        zf = np.ascontiguousarray(z, dtype=float).reshape(B, N)
        scale = np.asarray(scale, dtype=float).reshape(B)
        load_control = target is not None
        if load_control:
            target = np.asarray(target, dtype=float).reshape(B)
        else:
            delta = np.asarray(delta, dtype=float).reshape(B)
        if p0 is not None:
            p = np.array(np.broadcast_to(p0, z.shape), dtype=float).reshape(B, N)
            if np.any(p < 0) or not np.all(np.isfinite(p)):
                raise InputError("initial_pressure", "array", "must be finite and >= 0")
        elif load_control:
            p = np.repeat(target[:, None], N, axis=1)
        else:
            p = np.maximum(delta[:, None] - zf, 0.0) / L.self_influence
        if load_control:
            p = _rescale(p, target, zf)

        def rowsum(rows, values):
            return np.bincount(rows, values, minlength=B)

        ws = L.workspace((B,))                    # the direction t lives in ws.load
        t, r = ws.load, ws.response               # (B, ny, nx) views of the FFT buffers
        u, g = np.zeros((B, N)), np.zeros((B, N))
        u3 = u.reshape((B,) + grid)
        pv, uv, zv, gv = p.reshape(-1), u.reshape(-1), zf.reshape(-1), g.reshape(-1)
        L(p.reshape(u3.shape), out=u3)
        idx = np.flatnonzero(pv)                  # contact set (p >= 0 always), sorted
        exact = np.ones(B, dtype=bool)
        G_old, conjugate = np.ones(B), np.zeros(B, dtype=bool)
        active = np.ones(B, dtype=bool)
        iterations, history = np.zeros(B, dtype=int), []
        prev_at = None
        since_refresh = 0
        while True:
            rows, cell = np.divmod(idx, N)
            at = (rows,) + np.divmod(cell, grid[1])   # (b, i, j) of the contact cells
            nS = np.maximum(np.bincount(rows, minlength=B), 1)
            gS = uv[idx] + zv[idx]
            d = rowsum(rows, gS) / nS if load_control else delta   # approach (load: unknown)
            gS -= d[rows]
            G = rowsum(rows, gS * gS)
            np.subtract(u, d[:, None], out=g)
            g += zf
            res = np.maximum(np.sqrt(G / nS), np.maximum(-g.min(axis=1), 0.0)) / scale
            done = active & (res <= tol)
            if np.any(done & ~exact):        # accept convergence only on an exact displacement
                L(p.reshape(u3.shape), out=u3)
                exact[:] = True
                since_refresh = 0
                continue
            active &= ~done
            history.append(float(res.max()))
            if not active.any() or iterations.max() >= max_iter:
                break
            iterations += active
            beta = np.where(conjugate, G / G_old, 0.0)
            t_old = t[at]
            if prev_at is not None:
                t[prev_at] = 0.0                  # t is zero off its support
            tS = gS + beta[rows] * t_old
            t[at] = tS
            prev_at = at
            G_old = np.where(G > 0, G, 1.0)
            ws.apply()
            rS = r[at]
            rt = rowsum(rows, rS * tS)
            if load_control:
                rt -= rowsum(rows, rS) / nS * rowsum(rows, tS)
            tau = np.where(active & (rt > 0), rowsum(rows, gS * tS) / np.where(rt > 0, rt, 1.0), 0.0)
            pS = pv[idx] - tau[rows] * tS
            touched = rowsum(rows, pS < 0) > 0
            np.maximum(pS, 0.0, out=pS)
            # overlap: zero pressure but negative gap -> enters the contact (PK step 8)
            lift = (pS == 0) & (gS < 0) & active[rows]
            pS[lift] = -tau[rows[lift]] * gS[lift]
            enter = np.flatnonzero(g < 0)
            enter = enter[(pv[enter] == 0) & active[enter // N]]
            enter_rows = enter // N
            has_overlap = (rowsum(rows, lift) + np.bincount(enter_rows, minlength=B)) > 0
            conjugate = ~has_overlap
            p_enter = -tau[enter_rows] * gv[enter]
            if load_control:
                total = rowsum(rows, pS) + rowsum(enter_rows, p_enter)
                lost = active & (total <= 0)               # every point left: restart
                c = np.where(active, target * N / np.where(total > 0, total, 1.0), 1.0)
            else:
                lost, c = np.zeros(B, dtype=bool), np.ones(B)
            pv[idx] = pS * c[rows]
            pv[enter] = p_enter * c[enter_rows]
            if lost.any():
                p[lost] = _rescale(zf[lost] == 0, target[lost], zf[lost])
            idx = np.flatnonzero(pv)
            since_refresh += 1
            refresh = (touched | has_overlap | lost) & active
            if since_refresh >= _REFRESH:
                L(p.reshape(u3.shape), out=u3)
                exact[:], since_refresh = True, 0
            elif refresh.any():
                keep = ~refresh
                u_inc = c[keep, None, None] * (u3[keep] - tau[keep, None, None] * r[keep])
                L(p.reshape(u3.shape), out=u3)
                u3[keep] = u_inc
                exact = refresh.copy()
            else:
                u3 -= tau[:, None, None] * r
                u *= c[:, None]
                exact[:] = False
        converged = ~active
        gap = np.where(p > 0, 0.0, np.maximum(g, 0.0))
        shape = batch + grid
        result = ContactResult(
            pressure=p.reshape(shape), displacement=u.reshape(shape), gap=gap.reshape(shape),
            contact=(p > 0).reshape(shape), area_fraction=np.mean(p > 0, axis=1).reshape(batch),
            mean_pressure=p.mean(axis=1).reshape(batch), approach=np.array(d, dtype=float).reshape(batch),
            mean_gap=gap.mean(axis=1).reshape(batch), iterations=iterations.reshape(batch),
            residual=res.reshape(batch), converged=converged.reshape(batch), history=history)
        if not np.all(converged) and not partial:
            raise ContactConvergenceError(
                f"contact solver did not converge in {max_iter} iterations "
                f"(residual {res.max():.3e} > tol {tol:.1e} on {int(np.sum(~converged))} patch(es))",
                history, result)
        return result


_REFRESH = 25  # iterations between exact recomputations of u = L p (bounds round-off drift)


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

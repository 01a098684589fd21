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
        L, axes = self.operator, (-2, -1)
        load_control = target is not None
        if p0 is not None:
            p = np.array(np.broadcast_to(p0, z.shape), dtype=float)
            if np.any(p < 0) or not np.all(np.isfinite(p)):
                raise InputError("initial_pressure", "array", "must be finite and >= 0")
        elif load_control:
            p = np.empty_like(z)
            p[...] = target[..., None, None]
        else:
            p = np.maximum(delta - z, 0.0) / L.self_influence
        if load_control:
            p = _rescale(p, target, z)
        bshape = z.shape[:-2] + (1, 1)
        t = np.zeros_like(z)
        G_old = np.ones(bshape)
        conjugate = np.zeros(bshape, dtype=bool)
        active = np.ones(bshape, dtype=bool)
        iterations = np.zeros(z.shape[:-2], dtype=int)
        history = []
        u = np.empty_like(z)
        for it in range(max_iter + 1):
            L(p, out=u)
            g = u + z
            S = p > 0
            nS = np.maximum(S.sum(axis=axes, keepdims=True), 1)
            d = np.sum(g * S, axis=axes, keepdims=True) / nS if load_control else delta
            g -= d
            res = _residual(g, S, nS, scale)
            active &= res > tol
            history.append(float(res.max()))
            if not active.any() or it == max_iter:
                break
            iterations += active[..., 0, 0]
            gS = g * S
            G = np.sum(gS**2, axis=axes, keepdims=True)
            t = np.where(S, gS + np.where(conjugate, G / G_old, 0.0) * t, 0.0)
            G_old = np.where(G > 0, G, 1.0)
            r = L(t)
            if load_control:
                r -= np.sum(r * S, axis=axes, keepdims=True) / nS
            rt = np.sum(r * t, axis=axes, keepdims=True)
            tau = np.where(rt > 0, np.sum(gS * t, axis=axes, keepdims=True) / np.where(rt > 0, rt, 1), 0.0)
            p_new = np.maximum(p - tau * t, 0.0)
            overlap = (p_new == 0) & (g < 0)
            p_new = np.where(overlap, -tau * g, p_new)
            conjugate = ~np.any(overlap, axis=axes, keepdims=True)
            if load_control:
                p_new = _rescale(p_new, target, z)
            p = np.where(active, p_new, p)
        converged = ~active[..., 0, 0]
        gap = np.maximum(g, 0.0) * (p == 0)
        result = ContactResult(
            pressure=p, displacement=u, gap=gap, contact=p > 0,
            area_fraction=np.mean(p > 0, axis=axes), mean_pressure=np.mean(p, axis=axes),
            approach=np.broadcast_to(d, bshape)[..., 0, 0].copy(), mean_gap=np.mean(gap, axis=axes), iterations=iterations,
            residual=res[..., 0, 0], converged=converged, history=history)
        if not np.all(converged) and not partial:
            raise ContactConvergenceError(
                f"contact solver did not converge in {max_iter} iterations "
                f"(residual {res.max():.3e} > tol {tol:.1e} on {int(np.sum(~converged))} patch(es))",
                history, result)
        return result


def _rescale(p, target, z):
    """Scale p so that its mean is the target mean pressure (load balance, exact)."""
    mean = p.mean(axis=(-2, -1), keepdims=True)
    if np.any(mean <= 0):  # every point left the contact: restart from the highest ones
        p = np.where(mean > 0, p, (z == 0).astype(float))
        mean = p.mean(axis=(-2, -1), keepdims=True)
    return p * (target[..., None, None] / mean)


def _residual(g, S, nS, scale):
    """max(rms gap on the contact, max penetration off it), relative to the RMS height."""
    on = np.sqrt(np.sum((g * S) ** 2, axis=(-2, -1), keepdims=True) / nS)
    off = np.max(np.where(S, 0.0, np.maximum(-g, 0.0)), axis=(-2, -1), keepdims=True)
    return np.maximum(on, off) / scale


def solve_contact(heights, dx: float, kernel: Kernel, *, dy: float | None = None, periodic: bool = True,
                  **options) -> ContactResult:
    """One-call form of ``ContactSolver(kernel, heights.shape[-2:], dx, dy, periodic).solve(...)``."""
    h = np.asarray(heights)
    if h.ndim < 2:
        raise InputError("heights", h.shape, "must be at least 2-D (..., ny, nx)")
    return ContactSolver(kernel, h.shape[-2:], dx, dy, periodic).solve(h, **options)

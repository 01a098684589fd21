"""Normal contact stiffness of a solved rough contact: the load's derivative by the rigid approach.

At a solution of ``micro.contact`` a small approach increment dδ keeps the contact set C: the pressure
increment dp is zero off C and meets L dp = dδ on C, the incremental problem of a flat punch of
the shape of C (Johnson 1985, §3.8: K = 2 E* a for a circle of radius a). It is symmetric
positive definite on C and is solved by conjugate gradients with FFT convolutions
(``masked_krylov.masked_cg``), as the conduction of the same contact: by Barber's analogy (2003,
Proc. R. Soc. A 459, 53–66) K_t = (2 / E*)(κ₁κ₂ / (κ₁ + κ₂)) K on half-spaces,
``micro.conduction``. With a hardness, loading and unloading differ: on loading the cells at
p = H flow and take no more load (C: the elastic contact cells), on unloading every contact cell
unloads elastically (C: the whole contact, ``unloading=True``; 12x the loading stiffness at a
mean pressure of 2 MPa and H = 5 MPa in a trial). The unloading one is Barber's: the conduction
takes the whole contact. The stiffness is the exact derivative of the discrete solution where the
contact set does not change (a one-sided one where a cell is about to touch): no finite
difference, no resolution of its own beyond the grid's.

K = d(mean pressure)/dδ [Pa/m] per nominal area (the patch's, as ``mean_pressure``). On a periodic
patch of a half-space the mean gap falls as fast as the approach grows (dḡ = −dδ: the
displacement has mean zero), so K = −dp̄/dḡ, Persson's contact stiffness; on a layer the approach
includes the layer's bulk compression F(0) p̄. An isolated patch's approach holds its own
spreading (``ContactResult.approach``): K is then that of the whole loaded patch. The roughness'
own stiffness, what a macro interface law adds to the bodies it joins, takes that compliance out:
K_i = 1 / (1/K − C_u), C_u = mean(L 1) the patch's mean displacement under a uniform unit pressure
(isolated: its spreading, Love's mean for a rectangle; a layer: F(0); a periodic half-space: 0, so
K_i = K), as ``micro.laws`` does with Love's correction and ``micro.conduction`` with K_p.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.errors import ConvergenceError, InputError, check_count, check_flag, check_instance, check_positive
from multiscale.micro.contact import ContactResult, ContactSolver
from multiscale.micro.masked_krylov import masked_cg


class StiffnessConvergenceError(ConvergenceError):
    """The stiffness CG reached ``max_iter`` before ``tol``."""


@dataclass
class ContactStiffness:
    """Normal contact stiffness of a (batch of) solved patch(es); per-patch arrays have the batch shape.

    - ``stiffness`` [Pa/m], K = d(mean pressure)/dδ >= 0 (inf: a periodic half-space in full
      contact); ``total`` [N/m] = K x the nominal area, dF/dδ;
    - ``interface`` [Pa/m], K_i = 1/(1/K − C_u), the roughness' own (module docstring; inf where
      the patch is as stiff as a uniform pressure's, full contact), and ``uniform_compliance`` C_u [m/Pa];
    - ``increment`` [Pa/m] (..., ny, nx), dp/dδ: zero off the cells that take load;
    - ``iterations``, ``residual`` (|L dp − 1| / |1| on the contact cells) and ``converged``."""

    stiffness: np.ndarray
    total: np.ndarray
    interface: np.ndarray
    uniform_compliance: float
    increment: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    converged: np.ndarray


def contact_stiffness(solver: ContactSolver, result: ContactResult, *, unloading: bool = False, tol: float = 1e-10,
                      max_iter: int | None = None, partial: bool = False) -> ContactStiffness:
    """K of the contact ``result`` solved by ``solver`` (the same grid, kernel and periodicity;
    ``ContactSolver(kernel, s.shape, s.dx, s.dy, s.periodic)`` for a ``Surface`` s). ``unloading``:
    of an approach decrement, all contact cells elastic (the same as loading without a hardness;
    with one, the cells at H take no load on loading, the default). ``tol``:
    relative 2-norm residual of L dp = 1 on the contact; ``max_iter`` (default 20 sqrt(contact
    cells) + 100). Raises ``StiffnessConvergenceError`` if not converged, unless ``partial``."""
    check_instance("solver", solver, ContactSolver, "a ContactSolver")
    check_instance("result", result, ContactResult, "a ContactResult")
    check_positive("tol", tol)
    check_flag("partial", partial)
    check_flag("unloading", unloading)
    if result.pressure.shape[-2:] != solver.shape or result.grid not in (None, solver.grid):
        raise InputError("result", f"of a grid {result.pressure.shape[-2:]}, (dx, dy, periodic) = {result.grid}",
                         f"the solver's grid {solver.shape}, {solver.grid}: give the solver that solved it")
    elastic = result.contact if unloading or result.plastic is None else result.contact & ~(result.plastic > 0)
    op = solver.operator
    axes = (-2, -1)
    cells = elastic.sum(axis=axes)
    full = cells == elastic.shape[-1] * elastic.shape[-2]
    static = getattr(solver.kernel, "static_compliance", np.inf)
    singular = full & solver.periodic & (not (np.isfinite(static) and static > 0))   # L(q = 0) = 0: no finite K
    mask = elastic & ~singular[..., None, None]
    if max_iter is None:
        max_iter = int(20 * np.sqrt(max(int(cells.max(initial=0)), 1))) + 100
    max_iter = check_count("max_iter", max_iter)
    dp, its, res, ok = masked_cg(op, 1.0, mask, tol, max_iter, 1.0 / op.self_influence)
    if not np.all(np.isfinite(dp)):
        raise StiffnessConvergenceError("stiffness CG produced non-finite pressures", [], None)
    stiffness = np.where(singular, np.inf, dp.mean(axis=axes))
    uniform = float(op(np.ones(op.shape)).mean())        # m/Pa, C_u
    with np.errstate(divide="ignore"):
        excess = 1.0 / stiffness - uniform               # the roughness' compliance [m/Pa]
        interface = np.where(excess > 1e-12 / np.maximum(stiffness, 1e-300), 1.0 / excess, np.inf)
    interface = np.where(stiffness > 0, interface, 0.0)
    out = ContactStiffness(stiffness, stiffness * (op.shape[0] * op.shape[1] * op.dx * op.dy), interface, uniform,
                           dp, its, res, ok)
    if not np.all(ok) and not partial:
        raise StiffnessConvergenceError(
            f"stiffness CG did not converge in {max_iter} iterations (residual {res.max():.3e} > tol "
            f"{tol:.1e} on {int(np.sum(~ok))} patch(es))", [float(res.max())], out)
    return out

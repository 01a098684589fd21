"""The steady sliding state before a modal analysis and its linearisation (thesis §4.3.1).

``preload`` ramps the load of a ``Mechanics`` to its steady sliding state (Coulomb friction along
the rotation of body 1) and reports the interface forces; ``linearise`` returns (K, M) at that
state: K the consistent Newton matrix of the mechanics and interface forms (non-symmetric with
friction, including the exact tangent of embedded rough laws), M the block-diagonal mass with
diag 0 on Dirichlet rows (so constrained modes go to infinity).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc

from multiscale.errors import check_positive
from multiscale.macro.materials import body_fields
from multiscale.macro.mechanics import Mechanics, load_face_forces


@dataclass
class Preload:
    """Quasi-static sliding state before the modal analysis (§4.3.1, first step)."""

    pressure: float          # Pa or N, the load of the last step (a force for load_kind "force")
    friction: dict           # friction coefficient mu [-] per interface name (its facets' mean)
    normal_force: dict       # N, per interface name: integral of p_n
    friction_force: dict     # N, per interface name: resultant of mu p_n s (3-vector)
    load_force: dict         # N, per load face: pressure times the face area (its share of a force load)
    max_pressure: float      # Pa, largest per-facet mean contact pressure
    iterations: int          # Newton iterations of the last load step
    residuals: list          # residual norms of the last load step
    time: float              # s, wall time


NEWTON_FORCE_TOL = 1e-11    # absolute Newton tolerance relative to the applied force [-]


def preload(mech: Mechanics, pressure: float, steps: int = 1, reset: bool = True) -> Preload:
    """Ramp the load to ``pressure`` [Pa] (a force [N] for ``load_kind="force"``) in ``steps``
    Newton solves, from rest if ``reset``. The absolute residual tolerance is NEWTON_FORCE_TOL
    times the applied force: a re-solve from a nearly balanced state otherwise asks for a relative
    reduction below the round-off floor of the penalty-stiff system."""
    check_positive("pressure", pressure)
    t0 = time.perf_counter()
    tm, c = mech.tm, mech.contact
    loads = load_face_forces(tm, pressure, mech.load_kind)
    snes = mech.problem.solver
    rtol, atol, stol, max_it = snes.getTolerances()
    snes.setTolerances(atol=max(atol, NEWTON_FORCE_TOL * sum(loads.values())))
    if reset:
        for u in mech.u:
            u.x.array[:] = 0.0
    solved = mech.ramp(pressure, steps)
    normal, tangential = {}, {}
    mu, masks = tm.interface.values(c.friction), tm.interface.masks()
    for name, dS in tm.interface.dS_tag.items():
        normal[name] = tm.assemble_scalar(c.pressure * dS)
        tangential[name] = np.array([tm.assemble_scalar(c.friction_traction[i] * dS) for i in range(3)])
    friction = {name: float(mu[m].mean()) for name, m in masks.items()}
    return Preload(float(pressure), friction, normal, tangential, loads,
                   solved.max_pressure, solved.iterations, list(solved.residuals),
                   time.perf_counter() - t0)


def linearise(mech: Mechanics, materials: Mapping[str, object]):
    """(K, M) at the current state: K the consistent tangent (``ufl.derivative`` of the residual,
    non-symmetric with friction; it is the Newton matrix, overwritten by the next solve), M the
    block-diagonal mass with density ``rho`` of each material and diag 0 on Dirichlet rows."""
    rho = body_fields(mech.tm, materials, "rho", mech.reference_temperature)
    form = fem.form(mech.mass_forms(rho), entity_maps=mech.tm.entity_maps)
    M = fpetsc.assemble_matrix(form, bcs=mech.bcs, diag=0.0)
    M.assemble()
    return mech.tangent(), M

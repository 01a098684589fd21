"""The steady sliding state before a modal analysis and its linearisation (thesis §4.3.1).

``preload`` ramps the load of a ``Mechanics`` to its steady sliding state (Coulomb friction along
the rotation of body 1) and reports the interface forces; ``linearise`` returns (K, M) at that
state: K the consistent Newton matrix of the mechanics and interface forms (non-symmetric with
friction, including the exact tangent of embedded rough laws), M the block-diagonal mass with
diag 0 on Dirichlet rows (so constrained modes go to infinity). ``linearise_system`` adds the
optional parts of issue 20 (``macro.operators``, ``macro.friction``): material damping, the
friction-slope damping, the gyroscopic and centrifugal terms of the rotating body and the prestress
(geometric) stiffness, as a ``macro.damped.LinearSystem``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Mapping

import numpy as np
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from petsc4py import PETSc

from multiscale.errors import InputError, check_positive
from multiscale.geometry import Rotation
from multiscale.macro.damped import LinearSystem
from multiscale.macro.eigen import Damping
from multiscale.macro.friction import friction_damping
from multiscale.macro.materials import body_fields
from multiscale.macro.load_faces import load_face_forces
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.operators import (centrifugal_displacement, geometric_stiffness, material_damping,
                                        rotation_matrices)


@dataclass
class Preload:
    """Quasi-static sliding state before the modal analysis (§4.3.1, first step)."""

    pressure: float          # Pa or N, the load of the last step (a force for load_kind "force")
    friction: dict           # friction coefficient mu [-] per interface name (its facets' mean)
    normal_force: dict       # N, per interface name: integral of p_n
    friction_force: dict     # N, per interface name: resultant of mu p_n s (3-vector)
    load_force: dict         # N, per load face: its resultant (``load_face_forces``; a share of a force load)
    max_pressure: float      # Pa, largest per-facet mean contact pressure
    iterations: int          # Newton iterations of the last load step
    residuals: list          # residual norms of the last load step
    time: float              # s, wall time
    friction_moment: float | None = None   # N m, |moment| of the friction about body 1's axis (None: it translates)


TORQUE_TOL = 1e-3    # relative error of the friction moment left by the load's scaling to a torque
TORQUE_SOLVES = 5    # contact solves at most per scaling


def hold_moment(mech: Mechanics, load: float, target: float):
    """Scale ``load`` [N or Pa], the one ``mech`` solved last, until the friction moment about the
    rotation axis is ``target`` [N m] within ``TORQUE_TOL`` (secant steps, the moment being nearly
    linear in the load; at most ``TORQUE_SOLVES`` solves). Returns the load and the last
    ``SolveResult`` (None: no solve was needed, or at rest, where no friction acts). No moment
    while sliding (mu 0 wherever the bodies touch: a fade table or a mu(v) law falling to 0) raises
    an InputError on every rank (the moment is a global sum)."""
    solved = None
    for _ in range(TORQUE_SOLVES if target > 0 else 0):
        moment = abs(mech.contact.friction_moment())
        if not moment > 0 and float(mech.contact.speed.value):
            raise InputError("loading", None, f"the braking torque ({target:.6g} N m) needs a friction moment, 0 "
                             "while sliding: mu is 0 wherever the bodies touch (a friction_temperature table at the "
                             "interfaces' temperatures, or a mu(v) law at the slip speed): give mu > 0 there")
        if not moment > 0 or abs(moment - target) <= TORQUE_TOL * target:
            break
        load *= target / moment
        solved = mech.solve(load)
    return load, solved


def preload(mech: Mechanics, pressure: float, steps: int = 1, reset: bool = True,
            torque: float | None = None) -> Preload:
    """Ramp the load to ``pressure`` [Pa] (a force [N] for ``load_kind="force"``) in ``steps``
    Newton solves, from rest if ``reset``; with ``torque`` [N m], ``pressure`` is a first guess,
    scaled after the ramp until the friction moment is the torque (``hold_moment``); the Newton's
    tolerances are ``Mechanics.solve``'s (floors scaled by the load and the round-off)."""
    check_positive("pressure", pressure)
    t0 = time.perf_counter()
    tm, c = mech.tm, mech.contact
    loads = load_face_forces(tm, pressure, mech.load_kind)
    if reset:
        mech.set_displacements([0.0] * len(mech.u))
    solved = mech.ramp(pressure, steps)
    if torque is not None:
        pressure, again = hold_moment(mech, pressure, torque)
        solved, loads = again or solved, load_face_forces(tm, pressure, mech.load_kind)
    mu, masks = tm.interface.values(c.friction), tm.interface.masks()
    facet_normal, facet_friction = c.facet_normal_force(), c.facet_friction()
    normal = {name: float(facet_normal[m].sum()) for name, m in masks.items()}
    tangential = {name: facet_friction[m].sum(axis=0) for name, m in masks.items()}
    friction = {name: float(mu[m].mean()) for name, m in masks.items()}
    moment = abs(c.friction_moment()) if isinstance(tm.spec.motion, Rotation) else None
    return Preload(float(pressure), friction, normal, tangential, loads,
                   solved.max_pressure, solved.iterations, list(solved.residuals),
                   time.perf_counter() - t0, moment)


def linearise(mech: Mechanics, materials: Mapping[str, object]):
    """(K, M) at the current state: K the consistent tangent (``ufl.derivative`` of the residual,
    non-symmetric with friction; it is the Newton matrix, overwritten by the next solve), M the
    block-diagonal mass with density ``rho`` of each material and diag 0 on Dirichlet rows."""
    rho = body_fields(mech.tm, materials, "rho", mech.reference_temperature)
    form = fem.form(mech.mass_forms(rho), entity_maps=mech.tm.entity_maps)
    M = fpetsc.assemble_matrix(form, bcs=mech.bcs, diag=0.0)
    M.assemble()
    return mech.tangent(), M


@dataclass
class Linearised:
    """The linearised system and the parts it holds."""

    system: LinearSystem
    K_sigma: object = None        # PETSc.Mat, the geometric stiffness included in K (prestress)
    terms: tuple = ()             # names of the parts beyond K and M


def _add(total, A):
    if total is None:
        return A
    total.axpy(1.0, A, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    A.destroy()
    return total


def linearise_system(mech: Mechanics, materials: Mapping[str, object], *, damping: Damping | None = None,
                     slope: np.ndarray | None = None, prestress: bool = False, gyroscopic: bool = False,
                     material: bool = True) -> Linearised:
    """(K, M) of ``linearise`` plus: per-material damping (``material``: the loss factors and
    Rayleigh coefficients the materials give), the damping of the per-facet friction slope
    mu'(V) [s/m] (``slope``), the gyroscopic matrix and centrifugal stiffness of the rotating body
    at the contact's speed (``gyroscopic``), the geometric stiffness of the preloaded stress
    (``prestress``; with ``gyroscopic`` also of the centrifugal stress, solved with the tangent);
    ``damping``: the proportional part over the whole system."""
    K, M = linearise(mech, materials)
    C, H = material_damping(mech, materials) if material else (None, None)
    terms = [n for n, A in (("material viscous damping", C), ("material loss factors", H)) if A is not None]
    if slope is not None and np.any(slope):
        C = _add(C, friction_damping(mech, slope))
        terms.append("friction slope")
    omega = float(mech.contact.speed.value)
    extra = None
    if gyroscopic:
        if prestress and omega:
            extra = centrifugal_displacement(mech, materials, omega, K)
        G, Kw = rotation_matrices(mech, materials, omega)
        C = _add(C, G)
        K.axpy(1.0, Kw, PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        Kw.destroy()
        terms.append("gyroscopic and centrifugal")
    Ks = None
    if prestress:
        Ks = geometric_stiffness(mech, extra)
        K.axpy(1.0, Ks, PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        terms.append("prestress" + (" (with centrifugal stress)" if extra is not None else ""))
    if damping is not None and (damping.alpha or damping.beta or damping.eta):
        terms.append("proportional damping")
    return Linearised(LinearSystem(K, M, C, H, damping), Ks, tuple(terms))

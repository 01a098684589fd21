"""Transient heat conduction in both bodies, the rotating disc in an Eulerian frame (thesis Fig. 7.4).

Backward Euler in time, P1 in space. Body 1 (the disc) is advected by its rigid velocity
w = omega e_z x r (steady sliding seen from the lab frame), stabilised by SUPG with
tau = [(2/dt)^2 + (2|w|/h)^2 + 9 (4 chi/h^2)^2]^(-1/2). The interface heat sources come from
``ContactInterface.heat_residuals``: the frictional flux mu p_n |w| split by the per-facet partition
p_1, and with ``conductance`` an exchange h_c (T_0 − T_1). All other boundaries are adiabatic
(§7.3.1: convection is neglected during the heating sequence), so the heat stored in the bodies
equals the frictional energy dissipated.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.geometry import Rotation
from multiscale.macro.interface import ContactInterface, rigid_velocity
from multiscale.macro.mechanics import body_fields
from multiscale.macro.mesh import FormCache

LINEAR_OPTIONS = {"snes_type": "ksponly", "ksp_type": "preonly", "pc_type": "lu",
                  "pc_factor_mat_solver_type": "mumps"}


def temperature_functions(tm, degree: int = 1) -> list:
    """P1 temperature functions [K] on the two body submeshes."""
    return [fem.Function(fem.functionspace(b.mesh, ("Lagrange", degree)), name=f"temperature_{b.name}")
            for b in tm.bodies]


@dataclass
class ThermalStep:
    """One thermal time step."""

    time: float                    # s, at the end of the step
    heat_in: tuple                 # J, frictional heat put into body 0 and body 1 during the step
    max_temperature: tuple         # K, per body


class Thermal:
    """Heat problem of both bodies driven by the contact's frictional heat (see module docstring).

    ``materials`` maps material names to ``multiscale.scene.Material`` (``kappa`` [W/(m K)],
    ``heat_capacity`` rho c [J/(m^3 K)]). ``initial_temperature`` [K] is also the
    reference of the stored-heat balance.
    """

    def __init__(self, contact: ContactInterface, materials: Mapping[str, object], *,
                 initial_temperature: float = 293.15, dt: float = 1.0, frictional_heat: bool = True,
                 conductance: bool = False, temperatures=None, prefix: str = "heat_"):
        tm = contact.tm
        self.tm, self.contact = tm, contact
        self.T = list(temperatures) if temperatures is not None else temperature_functions(tm)
        self.spaces = [T.function_space for T in self.T]
        self.T_old = [fem.Function(V) for V in self.spaces]
        self.T_ref = float(initial_temperature)
        for f in self.T + self.T_old:
            f.x.array[:] = self.T_ref
        self.kappa = body_fields(tm, materials, "kappa")
        self.rho_c = body_fields(tm, materials, "heat_capacity", "rho_c")
        self.dt = fem.Constant(tm.parent, check_positive("dt", dt))
        self.time = 0.0
        self.cache = FormCache(tm)
        r = [ufl.TestFunction(V) for V in self.spaces]
        F = []
        for i in range(2):
            dx = tm.dx(tuple(reg.tag for reg in tm.bodies[i].spec.regions))
            rate = self.rho_c[i] * (self.T[i] - self.T_old[i]) / self.dt
            F.append((rate * r[i] + self.kappa[i] * ufl.dot(ufl.grad(self.T[i]), ufl.grad(r[i]))) * dx)
        F[1] += self._advection(r[1])
        Fi = contact.heat_residuals(self.T[0], self.T[1], r[0], r[1], frictional_heat=frictional_heat,
                                    conductance=conductance)
        self.residuals = [F[i] + Fi[i] if Fi[i] is not None else F[i] for i in range(2)]
        self.frictional_heat = frictional_heat
        self.problem = fpetsc.NonlinearProblem(self.residuals, self.T, petsc_options_prefix=prefix,
                                               petsc_options=LINEAR_OPTIONS, entity_maps=tm.entity_maps)

    def _advection(self, r):
        """Eulerian transport of the rotating body 1 with SUPG (Brooks–Hughes)."""
        tm = self.tm
        if not isinstance(tm.spec.motion, Rotation):
            raise InputError("geometry.builder", type(tm.spec.motion).__name__,
                             "heat transport needs a rotating body (a translating finite body has no "
                             "steady Eulerian frame)")
        x = ufl.SpatialCoordinate(tm.parent)
        w = rigid_velocity(tm.spec.motion, x, self.contact.speed)
        T, rho_c, kappa = self.T[1], self.rho_c[1], self.kappa[1]
        h = ufl.CellDiameter(tm.parent)
        chi = kappa / rho_c
        tau = 1 / ufl.sqrt((2 / self.dt) ** 2 + 4 * ufl.dot(w, w) / h**2 + 9 * (4 * chi / h**2) ** 2)
        residual = rho_c * ((T - self.T_old[1]) / self.dt + ufl.dot(w, ufl.grad(T)))
        dx = tm.dx(tuple(reg.tag for reg in tm.bodies[1].spec.regions))
        return (rho_c * ufl.dot(w, ufl.grad(T)) * r + tau * ufl.dot(w, ufl.grad(r)) * residual) * dx

    def step(self, dt: float) -> ThermalStep:
        """Advance by dt [s] with the current contact state (pressure, speed) as heat source."""
        self.dt.value = check_positive("dt", dt)
        power = self.contact.heat_power() if self.frictional_heat else (0.0, 0.0)
        for new, old in zip(self.T, self.T_old):
            old.x.array[:] = new.x.array
        self.problem.solve()
        snes = self.problem.solver
        ok = snes.getConvergedReason() > 0 and all(np.isfinite(T.x.array).all() for T in self.T)
        if not ok:
            raise ConvergenceError(f"heat step at t = {self.time + dt:.6g} s failed "
                                   f"(SNES reason {snes.getConvergedReason()})")
        self.time += dt
        return ThermalStep(self.time, (power[0] * dt, power[1] * dt), self.max_temperature())

    def max_temperature(self) -> tuple:
        """Largest nodal temperature of each body [K]."""
        comm = self.tm.comm
        return tuple(comm.allreduce(T.x.array.max(initial=-np.inf), op=MPI.MAX) for T in self.T)

    def stored_heat(self) -> tuple:
        """Heat stored in each body since the start, integral of rho c (T − T_0) [J]."""
        def energy(i):
            dx = self.tm.dx(tuple(reg.tag for reg in self.tm.bodies[i].spec.regions))
            return self.rho_c[i] * (self.T[i] - self.T_ref) * dx
        return tuple(self.cache.scalar(("stored", i), lambda: energy(i)) for i in range(2))

    def facet_temperature(self, side: int = 0) -> np.ndarray:
        """Mean temperature per interface facet [K] of body 0 ("+") or body 1 ("−")."""
        T = self.T[0]("+") if side == 0 else self.T[1]("-")
        return self.cache.facet_mean(("T", side), lambda: T)

"""Transient heat conduction in both bodies, the rotating disc in an Eulerian frame (thesis Fig. 7.4),
with convection, radiation and fixed temperatures on named surfaces and temperature-dependent
materials.

Equations (SI: T [K], t [s], lengths [m]). In each body, with the enthalpy per unit volume
e(T) = ∫_{T_0}^{T} rho c(s) ds [J/m^3] (``macro.materials``; e = rho c (T − T_0) for a constant
rho c) and the conductivity kappa(T) [W/(m K)],

    de/dt + w·∇e = ∇·(kappa ∇T),

w = 0 in body 0 and w = omega e × (x − c) in the rotating body 1 (steady sliding seen from the lab
frame; a translating body is accepted only at rest, w = 0). Backward Euler in time, P1 in space
(P2 in a rotating body 1: ``temperature_functions``), the storage term lumped (vertex quadrature)
in a body without transport, so that a heat pulse thinner than the elements neither under- nor
overshoots (``Thermal._storage_dx``), SUPG on body 1 with
tau = [(2/dt)^2 + (2|w|/h)^2 + 9 (4 chi/h^2)^2]^(-1/2), chi = kappa/(rho c), on the full residual
(with P2 its conduction term too, ∇·(kappa ∇T) = kappa ΔT + kappa'(T^n) |∇T|^2, a table's slope
at the step's start: at T^{n+1} the residual jumped where a quadrature point crossed one of the
table's points, and Newton cycled, |F| stuck at 0.857 W, on a CAD disc with kappa 54 -> 20 W/(m K)
over 40 K; at T^n it differs only where T crossed a point in the step, tests/test_macro_thermal.py):
find T^{n+1} such that for every test function r

    ∫ [(e(T^{n+1}) − e(T^n))/dt r + kappa ∇T^{n+1}·∇r − e(T^{n+1}) w·∇r] dx + SUPG
      − ∫_interface q_i r dS + ∫_convection h (T − T_a) r ds + ∫_radiation eps sigma (T^4 − T_a^4) r ds = 0

with T = T_fix on fixed-temperature surfaces and ∂T/∂n = 0 (insulated) on every other surface
(today's default, §7.3.1: convection neglected during the heating sequence). The interface sources
q_i come from ``ContactInterface.heat_residuals``: the frictional flux mu p_n |w| split by the
per-facet partition p_1, and with ``conductance`` an exchange h_c (T_0 − T_1). Boundary fluxes are
positive out of the body: convection h [W/(m^2 K)] towards the ambient T_a (Newton's law of cooling,
h constant or a function of the rotating body's speed, taken at the step's mean speed as the
transport is: ``MacroModel.macro_step``), grey-body radiation to surroundings at T_a with
emissivity eps and sigma = 5.670374419e-8 W/(m^2 K^4) (Incropera & DeWitt, Fundamentals of Heat
and Mass Transfer, §1.2.3). With constant materials and no radiation the step is one linear solve, its matrix's cell part (storage, conduction,
transport) kept between steps while dt and the speed stay (``kept_cells.KeptCells``), by GMRES to
1e-12 of the step's residual on the LU factors of an earlier step's matrix, refactorised after a
solve of more than ``KEPT_ITERATIONS`` iterations (the interface terms change every step; ch. 7's
P2 disc: 20 steps' heat solves 22.6 -> 9.7 s, temperatures equal to 3e-11); radiation or
a temperature table makes it Newton's method (SNES, exact tangent of T^4, kappa(T) and e(T); LU)
in its chord form (Kelley 1995, Iterative Methods for Linear and Nonlinear Equations, SIAM, ch. 5):
the tangent and its LU factors are kept across iterations and steps of the same dt while each
iteration brings the residual norm down to at most ``CHORD_CONTRACTION`` times the previous one
(else the next iteration assembles and factorises afresh). Such an iteration costs a residual and
the triangular solves, not also an assembly and a factorisation; the stopping test is on the true
residual, so the answer is Newton's to the same tolerance. The Newton's LU factors are in single
precision (``FACTOR_PRECISION``; MUMPS on the double matrix): they solve each correction to float32
round-off times the condition, which the next iteration's double residual takes out like the
chord's own error (Higham & Mary 2022, Acta Numerica 31, 347–414, §7), at 0.6x the factorisation's
time (car-brake stop: heat solves 8.3-9.1 → 7.7-8.1 s, benchmarks/README). A linear step, one solve, keeps double
factors. A solve that fails with kept or single factors is redone from the step's start with
fresh double ones, which then stay (``redone`` counts the redone steps). A Newton step still
failing is redone once more with PETSc's backtracking line search (``bt``: the full step if it
lowers ||F||^2 enough, else a shorter one along it) and a fresh tangent every iteration
(``backtracked`` counts them; the first is warned about, ``HeatStepWarning``). Where the tangent
is flat a full step overshoots far: a block from 300 K into 2000 K surroundings in one 1000 s
step (T^4 flat at the start) went to ~6e4 K, the residual 33 W -> 3e7 W (SNES reason -9);
backtracking converges in 5 iterations, the mean temperature within 0.44 K of the lumped body's
backward Euler step (tests/test_macro_thermal.py). Only on a failed step: always on, it shortened
steps that overshoot and recover (a radiating column: 14 -> 4 iterations, another path to the
same answer). Not ``cp`` (stalled: |F| 33.2 W for 30 iterations). Backtracking converged every
step tried (to 1e6 s, 3000 K surroundings, tables): a failed step is not cut into substeps.
The user's options under the prefix (``PETSC_OPTIONS="-heat_snes_linesearch_type ..."``) win over
ours, and a failed step's error names them; a line search the user chose is not replaced. So do a
linear problem's KSP and PC options (``-heat_ksp_type cg``; a user's ``preonly`` factorises every
step afresh); Newton's (``kept_cells.NEWTON_ONLY``) have no effect on it, a warning says so.

Energy balance. P1 test functions sum to one, so the residual summed over every dof of a body is
its heat balance over the step. The heat lost [J] during a step, consistent with it, is
dt ∫ h (T^{n+1} − T_a) ds through a convection surface, dt ∫ eps sigma ((T^{n+1})^4 − T_a^4) ds through
a radiating one (same quadrature as the residual, exact for P1), and minus dt times the residual
summed over the Dirichlet dofs of a fixed-temperature surface (its reaction flux). Hence

    stored heat ∫ (e(T^{n+1}) − e(T_0)) dx = frictional heat in − heat lost,

exactly up to the solver tolerance. The transport is in its conservative form −∫ e w·∇r dx (w is
divergence-free; no heat is carried through the body's surface, w·n = 0 on a body of revolution):
it sums to zero over the test functions whatever the quadrature and the faceting. Its advective
form ∫ rho c (w·∇T) r dx lost the flux dt ∮ e w·n ds through the faceted rim (6e-4 of the disc's
heat on the pin-on-disc test) and, with a peaked c(T) table, a quadrature error (2 % of a CAD
disc's heat; an adversarial test). The SUPG term sums to zero as well (its weight is w·∇r).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.geometry import Rotation
from multiscale.macro import kept_cells, mumps
from multiscale.macro.interface import ContactInterface, rigid_velocity
from multiscale.macro.kept_cells import KeptCells, assemble, backtracking, nonlinear_problem
from multiscale.macro.materials import body_properties, heat_capacity
from multiscale.macro.mesh import FormCache
from multiscale.macro.thermal_conditions import (AppliedBoundary, ThermalBoundary, kinds, measure_id, settle,
                                                 surface_rows)

# a linear step (its matrix's cell part kept): GMRES on the step's matrix, preconditioned by the LU
# factors of an earlier step's, refactorised when a solve took more than KEPT_ITERATIONS iterations
# (or failed)
KEPT_OPTIONS = {"snes_type": "ksponly", "ksp_type": "gmres", "ksp_max_it": 50, "pc_type": "lu",
                "pc_factor_mat_solver_type": "mumps", "ksp_rtol": 1e-12, "ksp_atol": 0.0}
KEPT_ITERATIONS = 8
NEWTON_OPTIONS = {"snes_type": "newtonls", "snes_linesearch_type": "basic", "snes_rtol": 1e-10,
                  "snes_atol": 1e-12, "snes_stol": 1e-12, "snes_max_it": 30,
                  "ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
STEFAN_BOLTZMANN = 5.670374419e-8      # W/(m^2 K^4), CODATA 2018 (exact)
CONVECTION_QUADRATURE = 2              # exact for h (T − T_a) r, P1 on flat facets (times the degree: P2)
RADIATION_QUADRATURE = 5               # exact for (T^4 − T_a^4) r, P1 (times the degree: P2)
ENTHALPY_QUADRATURE = 3                # e(T) r with a tabulated rho c, P1 (same rule for the stored heat);
                                       # + 2 per degree above 1 (P2: FFCx's degree-3 rule, one negative weight,
                                       # made the P2 storage matrix indefinite, rank 5 of 10)
CHORD_CONTRACTION = 0.01               # keep the Newton tangent while ||F_k|| <= this times ||F_k-1|| (0: never)
FACTOR_PRECISION = "single"            # the Newton's LU factors (mumps.precision); a linear step's stay double
BACKTRACKED = "converged only with a backtracking line search"     # in the note of the first such step
TRANSPORT_DEGREE = 2                   # Lagrange degree of the temperature of a rotating body (Eulerian transport)


def temperature_functions(tm) -> list:
    """Temperature functions [K] on the two body submeshes: P1, and P2 in a rotating body 1.

    Why P2 there: a heated layer thinner than the elements, carried around at a Peclet number of
    thousands, is not resolved by P1 with SUPG. The P1 interpolant of a field stratified across the
    thickness has spurious components along the streamlines, which the transport and its
    streamline diffusion turn into heat moved across the thickness. On a CAD disc (20 mm thick,
    6 mm elements, 500 rpm, two pads, 4 s) the surface under the pad track rose 18 K with P1
    (21 K on 3 mm elements), against 32 K from the semi-infinite solid with the flux averaged over
    the annulus (Carslaw & Jaeger §2.9: 2 q sqrt(t / (pi rho c kappa))), which P2 gives (31.6 K);
    P1's bottom face fell 7.5 K below the initial temperature, P2's rose 1.4 K (the image source
    of the insulated face gives 1.9 K)."""
    rotating = isinstance(tm.spec.motion, Rotation)
    return [fem.Function(fem.functionspace(b.mesh, ("Lagrange", TRANSPORT_DEGREE if i == 1 and rotating else 1)),
                         name=f"temperature_{b.name}") for i, b in enumerate(tm.bodies)]


class HeatStepWarning(UserWarning):
    """A heat step too long for full Newton steps (converged with a backtracking line search)."""


@dataclass
class ThermalStep:
    """One thermal time step."""

    time: float                    # s, at the end of the step
    heat_in: tuple                 # J, frictional heat put into body 0 and body 1 during the step
    max_temperature: tuple         # K, per body
    heat_lost: tuple = (0.0, 0.0)  # J, heat lost through the boundary conditions of each body
    heat_exchanged: float = 0.0    # J, conducted from body 0 to body 1 through the interface conductance
    facet_heat: np.ndarray | None = None   # J, frictional heat per interface facet into body 0 and 1, (n, 2)


class Thermal:
    """Heat problem of both bodies driven by the contact's frictional heat (see module docstring).

    ``materials`` maps material names to ``multiscale.scene.Material``-like objects (``kappa``
    [W/(m K)], ``rho`` and ``c`` or ``chi``; constants or temperature tables). ``initial_temperature``
    [K] is also the reference of the stored heat. ``boundaries``: ``ThermalBoundary`` conditions
    (none: every outer surface insulated). With Newton's method, ``jacobians`` counts the tangents
    assembled and factorised so far, ``redone`` the steps redone with fresh tangents (and double
    factors), ``backtracked`` those redone once more with a backtracking line search,
    ``precision`` that of the LU factors ("single", or "double" after a redone step). ``notes``:
    what the run's warnings add (the first backtracked step, also a ``HeatStepWarning`` on rank 0).
    """

    def __init__(self, contact: ContactInterface, materials: Mapping[str, object], *,
                 initial_temperature: float = 293.15, dt: float = 1.0, frictional_heat: bool = True,
                 conductance: bool = False, temperatures=None, boundaries: Sequence[ThermalBoundary] = (),
                 prefix: str = "heat_"):
        tm = contact.tm
        self.tm, self.contact = tm, contact
        self.T = list(temperatures) if temperatures is not None else temperature_functions(tm)
        self.spaces = [T.function_space for T in self.T]
        self.T_old = [fem.Function(V) for V in self.spaces]
        self.T_ref = float(initial_temperature)
        self.T0 = fem.Constant(tm.parent, self.T_ref)    # in forms: a literal compiled new ones for each T_ref
        for f in self.T + self.T_old:
            f.x.array[:] = self.T_ref
        self.conductivity = conductivity = body_properties(tm, materials, "kappa")
        self.capacity = body_properties(tm, materials, "rho_c", of=heat_capacity)
        self.kappa = [p.expression(T, self.T_ref) for p, T in zip(conductivity, self.T)]
        self.rho_c = [p.expression(T, self.T_ref) for p, T in zip(self.capacity, self.T)]
        self.dt = fem.Constant(tm.parent, check_positive("dt", dt))
        self.time = 0.0
        self.cache = FormCache(tm)
        self.region_dofs: dict = {}     # (body, "material" or "name") -> {group: its local dofs}
        self.cell_spaces = [b.region_space for b in tm.bodies]    # DG0: the stored heat per cell
        self.transport = isinstance(tm.spec.motion, Rotation)
        self._check_motion()
        r = [ufl.TestFunction(V) for V in self.spaces]
        F = []
        for i in range(2):
            conduction = self.kappa[i] * ufl.dot(ufl.grad(self.T[i]), ufl.grad(r[i]))
            F.append(self._rate(i) * r[i] * self._storage_dx(i) + conduction * self._dx(i))
        if self.transport:
            F[1] += self._advection(r[1])
        Fi = contact.heat_residuals(self.T[0], self.T[1], r[0], r[1], frictional_heat=frictional_heat,
                                    conductance=conductance)
        self.residuals = [F[i] + Fi[i] if Fi[i] is not None else F[i] for i in range(2)]
        self.frictional_heat, self.conductance = frictional_heat, conductance
        self.boundaries = tuple(boundaries)
        self.applied = self._apply_boundaries(r)
        self.bcs = [a.bc for a in self.applied if a.bc is not None]
        self.lost_step = np.zeros((len(self.boundaries), 2))      # J, per condition and body, last step
        self.lost_total = np.zeros((len(self.boundaries), 2))     # J, since the start
        self.nonlinear = (any(b.emissivity is not None for b in self.boundaries)
                          or not all(p.constant for p in conductivity + self.capacity))
        self.tables = [f"{b.name} ({', '.join(n for n, p in (('kappa', k), ('c', c)) if not p.constant)})"
                       for b, k, c in zip(tm.bodies, conductivity, self.capacity) if not (k.constant and c.constant)]
        # constant materials: the Jacobian's cell part (storage, conduction, transport with SUPG;
        # 105 of its 110 ms on the ch. 7 mesh, one rank) changes only with the constants and coefficients
        # in it (dt, the speed): kept, reassembled when one of them changed (``KeptCells``)
        J = kept_cells.jacobian(self.residuals, self.T)
        self._tangent = None if self.nonlinear else KeptCells(J, tm.entity_maps, self.bcs)
        # the user's options under the prefix (PETSC_OPTIONS="-heat_...") win over ours, a linear problem's too
        self.problem = nonlinear_problem(self.residuals, self.T, prefix,
                                         NEWTON_OPTIONS if self.nonlinear else KEPT_OPTIONS, bcs=self.bcs,
                                         J=J if self.nonlinear else self._tangent.cells, entity_maps=tm.entity_maps)
        self.notes: list = []                  # what the run's warnings add (said once per run)
        self._factored = None                  # linear steps: the kept factors' matrix
        # a failed step is redone with backtracking unless the user chose a line search (theirs alone remain)
        self._backtrack = self.nonlinear and not PETSc.Options(prefix).hasName("snes_linesearch_type")
        if not self.nonlinear:                 # (its SNES is "ksponly": the Newton's options have no effect)
            why = "the heat problem is linear (no radiation, no temperature tables)"
            self._say(kept_cells.newton_options_unused(self.problem.solver, why), kept_cells.SolverOptionWarning)
            self._tangent.attach(self.problem.A)
            self._factored = self.problem.A.duplicate()
            self.problem.solver.setJacobian(self._jacobian, self.problem.A, self._factored)
        self.factorisations = 0                # linear steps: LU factorisations so far
        self._stale = True                     # linear steps: refactorise at the next step
        self._kept = False                     # linear steps: the last solve ran on earlier factors
        self.jacobians = 0                     # Newton: tangents assembled (and factorised) so far
        self._norms: list = []                 # Newton: residual norms of the current solve
        self._chords = 0                       # Newton: iterations of the current solve on a kept tangent
        self._tangent_dt = None                # Newton: the step of the kept tangent [s]
        self.redone = 0                        # Newton: steps redone with fresh tangents
        self.backtracked = 0                   # Newton: steps redone with a backtracking line search
        self.precision = FACTOR_PRECISION if self.nonlinear else "double"    # of the LU factors
        self._fresh = False                    # Newton: a fresh tangent every iteration (a step redone)
        if self.nonlinear:
            self.problem.solver.setJacobian(self._chord_jacobian, self.problem.A, self.problem.P_mat)
            self.problem.solver.setMonitor(self._watch)

    def close(self) -> None:
        """Destroy the solver's PETSc objects (collective, ``Mechanics.close``); then ``ClosedError``."""
        if not isinstance(self.problem, kept_cells.Closed):
            self.problem = kept_cells.destroy(self.problem, "Thermal", self._factored, self._tangent and self._tangent.bulk)

    # ---- forms -----------------------------------------------------------------------------
    def _dx(self, i: int, degree: int | None = None, scheme: str | None = None):
        """Volume measure of body i on the parent mesh (optionally a fixed quadrature degree, or
        the "vertex" scheme: the nodal values weighted by a quarter of each tetrahedron)."""
        return self.tm.body_dx(i, degree=1 if scheme is not None else degree, scheme=scheme)

    def _storage_dx(self, i: int):
        """Measure of body i's storage term (and stored heat): the vertex rule, i.e. a lumped
        capacity, in a body without transport (the discrete maximum principle of backward Euler:
        a heat pulse thinner than the elements gave a consistent capacity 65 K and 2863 K in the
        car-brake pads from 303 K; Abaqus lumps first-order heat-transfer elements the same way);
        the transported body 1 keeps the consistent one (its SUPG term weighs the same residual)."""
        if not (i == 1 and self.transport):
            return self._dx(i, scheme="vertex")
        return self._dx(i) if self.capacity[i].constant else self._dx(i, self._enthalpy_degree(i))

    def _facet_degree(self, i: int, p1: int) -> int:
        """Quadrature degree of a boundary term of body i exact for P1 at ``p1``: ``p1`` times its
        temperature's degree (a product of P2 factors)."""
        return p1 * self.spaces[i].element.basix_element.degree

    def _enthalpy_degree(self, i: int) -> int:
        """Quadrature degree of body i's tabulated-material terms and of its transport (``ENTHALPY_QUADRATURE``)."""
        return ENTHALPY_QUADRATURE + 2 * (self.spaces[i].element.basix_element.degree - 1)

    def _rate(self, i: int):
        """(e(T) − e(T_old))/dt [W/m^3]: rho c (T − T_old)/dt for a constant rho c."""
        T, T_old = self.T[i], self.T_old[i]
        if self.capacity[i].constant:
            return self.rho_c[i] * (T - T_old) / self.dt
        p = self.capacity[i]
        return (p.integral(T, self.T0) - p.integral(T_old, self.T0)) / self.dt

    def _check_motion(self) -> None:
        """A translating body has no steady Eulerian frame: heat only at rest (no transport). A
        rotating body needs a surface of revolution: where the rotation crosses its surface (vanes,
        holes) the transport has inflow boundaries without a condition, and its temperatures
        diverged (a ventilated disc: 76 000 K after 2 s, 25 times the heat put in)."""
        if self.transport:
            motion, body = self.tm.spec.motion, self.tm.bodies[1]
            c = body.crossing(motion)
            if c.share > 0:
                r = np.linalg.norm(motion.velocity(c.where[None])[0])       # the distance from the axis
                raise InputError("effects", "thermal", f"the rotating body {body.name!r} is not a body of revolution "
                                 f"about its axis: its rotation crosses {100 * c.share:.2g} % of its surface "
                                 f"(weighted by speed; e.g. at r = {r * 1e3:.1f} mm, point "
                                 f"{np.round(c.where * 1e3, 1).tolist()} mm: vanes, holes or slots). Its heat "
                                 "problem is solved in a fixed (Eulerian) frame, which needs a surface of "
                                 "revolution: fill the holes and vanes of the geometry (a built disc: geometry.vanes = 0) "
                                 "for the thermal effects, or run without effect \"thermal\"")
        speed = float(self.contact.speed.value)
        if not self.transport and speed != 0.0:
            raise InputError("loading.sliding_speed", speed,
                             "heat transport needs a rotating body: a translating finite body has no steady "
                             "Eulerian frame (the heat problem runs with a translating body only at rest, "
                             "sliding_speed = 0)")

    def _advection(self, r):
        """Eulerian transport of the rotating body 1 with SUPG (Brooks–Hughes)."""
        tm = self.tm
        x = ufl.SpatialCoordinate(tm.parent)
        w = rigid_velocity(tm.spec.motion, x, self.contact.speed)
        T, rho_c, kappa = self.T[1], self.rho_c[1], self.kappa[1]
        h = ufl.CellDiameter(tm.parent)
        chi = kappa / rho_c
        tau = 1 / ufl.sqrt((2 / self.dt) ** 2 + 4 * ufl.dot(w, w) / h**2 + 9 * (4 * chi / h**2) ** 2)
        if self.capacity[1].constant:
            e = rho_c * (T - self.T0)
            residual = rho_c * ((T - self.T_old[1]) / self.dt + ufl.dot(w, ufl.grad(T)))
        else:
            e = self.capacity[1].integral(T, self.T0)
            residual = self._rate(1) + rho_c * ufl.dot(w, ufl.grad(T))
        if self.spaces[1].element.basix_element.degree > 1:     # the conduction term (0 in a P1 cell)
            T_n = ufl.variable(self.T_old[1])                   # kappa'(T) at T^n: see the module docstring
            slope = ufl.diff(self.conductivity[1].expression(T_n, self.T_ref), T_n)
            residual -= kappa * ufl.div(ufl.grad(T)) + slope * ufl.dot(ufl.grad(T), ufl.grad(T))
        # tau is no polynomial (UFL estimated degree 8-9: 45 points a P2 cell, one weight negative):
        # the enthalpy's rule (P2: degree 5, 15 points), exact for the Galerkin part e w.grad(r) with
        # constant materials; at least degree 4 (P1: FFCx's degree-3 rule has a negative weight)
        dx = self._dx(1, max(self._enthalpy_degree(1), 4))
        return (-e * ufl.dot(w, ufl.grad(r)) + tau * ufl.dot(w, ufl.grad(r)) * residual) * dx

    def _apply_boundaries(self, r) -> list[AppliedBoundary]:
        """Measures, residual terms and Dirichlet conditions of the boundary conditions."""
        tm, tdim = self.tm, self.tm.parent.topology.dim
        rows = {}               # (condition, body) -> (through "free:", rows of the body's exterior facets)
        for k, cond in enumerate(self.boundaries):
            for name in cond.surfaces:
                found = surface_rows(tm, name)
                if tm.comm.allreduce(len(found), op=MPI.SUM) == 0:
                    raise InputError("boundary.surfaces", name, "has no exterior facet (an interface or a "
                                     "face between two parts cannot carry a thermal condition)")
                for i, body in enumerate(tm.bodies):
                    inside = body.cell_map.sub_topology_to_topology(found[:, 0], inverse=True) >= 0
                    rows.setdefault((k, i), []).append((name.startswith("free:"), found[inside]))
        settled, applied, data = settle(rows, self.boundaries, tm.comm), [], ([], [])
        for k, i in rows:
            cond = self.boundaries[k]
            if tm.comm.allreduce(sum(len(settled[k, i, kind]) for kind in kinds(cond)), op=MPI.SUM) == 0:
                continue
            body, found = tm.bodies[i], settled[k, i, kinds(cond)[0]]    # a fixed temperature is alone
            sub_cells = body.cell_map.sub_topology_to_topology(found[:, 0], inverse=True)
            body.mesh.topology.create_connectivity(tdim, tdim - 1)
            c2f = body.mesh.topology.connectivity(tdim, tdim - 1)       # same local facets as the parent's cell
            facets = np.unique(c2f.array[c2f.offsets[sub_cells] + found[:, 1]]).astype(np.int32)
            ambient = fem.Constant(tm.parent, self.T_ref if cond.ambient is None else float(cond.ambient))
            applied.append(AppliedBoundary(k, i, cond, ambient, facets))
            data[i].extend((measure_id(k, kind), settled[k, i, kind].astype(np.int32).ravel()) for kind in kinds(cond))
        self.ds = [ufl.Measure("ds", domain=tm.parent, subdomain_data=d) if d else None for d in data]
        for a in applied:
            T, ds = self.T[a.body], self.ds[a.body]
            c = a.condition
            if c.temperature is not None:
                dofs = fem.locate_dofs_topological(self.spaces[a.body], tdim - 1, a.facets)
                a.bc = fem.dirichletbc(float(c.temperature), dofs, self.spaces[a.body])
            if c.convection is not None:
                a.h = fem.Constant(tm.parent, c.h(float(self.contact.speed.value)))
                self.residuals[a.body] += a.h * (T - a.ambient) * r[a.body] * ds(
                    measure_id(a.index, "convection"), degree=self._facet_degree(a.body, CONVECTION_QUADRATURE))
            if c.emissivity is not None:
                self.residuals[a.body] += self._radiation(a) * r[a.body] * ds(
                    measure_id(a.index, "emissivity"), degree=self._facet_degree(a.body, RADIATION_QUADRATURE))
        return applied

    def _radiation(self, a: AppliedBoundary):
        """eps sigma (T^4 − T_a^4) [W/m^2], out of the body."""
        eps_sigma = fem.Constant(self.tm.parent, a.condition.emissivity * STEFAN_BOLTZMANN)
        return eps_sigma * (self.T[a.body] ** 4 - a.ambient**4)

    # ---- solution --------------------------------------------------------------------------
    def _jacobian(self, snes, x, J, P) -> None:
        """SNES Jacobian callback with constant materials: the kept cell part (reassembled when a
        constant or coefficient of it changed) plus the interface and boundary terms at x. The
        preconditioner's matrix P (factorised by LU) is this J only when the factors are stale: at
        the first step, after a solve of more than ``KEPT_ITERATIONS`` GMRES iterations, or a
        failed one (PETSc refactorises P only when it changed); GMRES solves with J itself."""
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fpetsc.assign(x, self.T)
        self._tangent.update()
        self._tangent.compose(J)
        ksp = snes.getKSP()                   # a direct solve (the user's preonly) needs this step's factors
        self._kept = not (self._stale or ksp.getType() == PETSc.KSP.Type.PREONLY
                          or ksp.getIterationNumber() > KEPT_ITERATIONS)      # a global count
        if not self._kept:
            J.copy(P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
            self._stale, self.factorisations = False, self.factorisations + 1

    def _watch(self, snes, it: int, norm: float) -> None:
        """SNES monitor: the residual norms of the current solve."""
        if it == 0:
            self._norms.clear()
            self._chords = 0
        self._norms.append(norm)

    def _chord_jacobian(self, snes, x, J, P) -> None:
        """SNES Jacobian callback of the Newton steps (module docstring): J is left as it is, and
        so are its LU factors (PETSc refactorises only a changed matrix), while a tangent of the
        same dt is kept and the last iteration brought the residual norm down to
        ``CHORD_CONTRACTION`` times the one before or less (the norms are global: every rank
        decides alike); else the tangent is assembled at x."""
        f, dt = self._norms, float(self.dt.value)
        if (self.jacobians and not self._fresh and CHORD_CONTRACTION > 0 and dt == self._tangent_dt
                and (len(f) < 2 or f[-1] <= CHORD_CONTRACTION * f[-2])):
            self._chords += 1
            return
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fpetsc.assign(x, self.T)
        assemble(J, self.problem.J, self.bcs)
        self.jacobians, self._tangent_dt = self.jacobians + 1, dt

    def _solve(self) -> bool:
        """One solve from the current T; True if it converged to finite values on every rank."""
        with mumps.precision(self.problem.solver.getOptionsPrefix(), self.precision):
            self.problem.solve()
        finite = bool(self.tm.comm.allreduce(all(np.isfinite(T.x.array).all() for T in self.T), op=MPI.LAND))
        return self.problem.solver.getConvergedReason() > 0 and finite

    def _back_to_start(self) -> None:
        """The temperatures of the start of the step (to solve it again)."""
        for new, old in zip(self.T, self.T_old):
            new.x.array[:] = old.x.array

    def step(self, dt: float) -> ThermalStep:
        """Advance by dt [s] with the current contact state (pressure, speed) as heat source."""
        self.dt.value = check_positive("dt", dt)
        self._check_motion()
        speed = float(self.contact.speed.value)
        for a in self.applied:
            if a.h is not None:
                a.h.value = a.condition.h(speed)
        power = self.contact.facet_heat_power() if self.frictional_heat else np.zeros((self.tm.interface.n_facets, 2))
        for new, old in zip(self.T, self.T_old):
            old.x.array[:] = new.x.array
        ok = self._solve()                                        # the same answer on every rank
        if not ok and not self.nonlinear and self._kept:    # earlier factors: redo with fresh ones
            self._back_to_start()
            self._stale, self.redone = True, self.redone + 1
            ok = self._solve()
        if not ok and (self._chords or self.precision != "double"):    # redo with fresh double factors
            self._back_to_start()
            if self.precision != "double":                        # a new analysis in double, kept from now on
                self.precision = "double"
                self.problem.solver.getKSP().getPC().reset()
            self._fresh, self.redone = True, self.redone + 1
            try:
                ok = self._solve()
            finally:
                self._fresh = False
        if not ok and self._backtrack:          # a full Newton step overshot: again, backtracking (module docstring)
            self._back_to_start()
            self._fresh, self.backtracked = True, self.backtracked + 1
            try:
                with backtracking(self.problem.solver):
                    ok = self._solve()
            finally:
                self._fresh = False
            if ok and not any(BACKTRACKED in n for n in self.notes):    # notes restored on resume count
                self._note_backtracking(dt)
        snes = self.problem.solver
        if not ok:
            failed, given = mumps.describe(snes.getKSP().getPC()), kept_cells.user_options(snes.getOptionsPrefix())
            why = (f"; Newton may cycle on the kinks of the temperature tables of {', '.join(self.tables)}: a "
                   "steep change between two points of a table is one, spread it over a wider range or more "
                   "points" if self.tables and not failed else "")
            if not failed and any(a.condition.emissivity for a in self.applied):   # T^4: a long step strays far
                why += (f"; with radiation a step of {dt:.4g} s can take Newton far off"
                        f"{' (a backtracking line search too)' if self._backtrack else ''}: more time.steps or substeps")
            raise ConvergenceError(f"heat step at t = {self.time + dt:.6g} s failed (SNES reason "
                                   f"{snes.getConvergedReason()}, {snes.getIterationNumber()} iterations"
                                   f"{'; ' + failed if failed else ''}{given and f'; PETSC_OPTIONS = {given!r}'}){why}")
        cold = self.min_temperature()             # the same on every rank
        if min(cold) < 0.0:
            i = int(np.argmin(cold))
            raise ConvergenceError(f"heat step at t = {self.time + dt:.6g} s gave {cold[i]:.4g} K in the "
                                   f"{self.tm.bodies[i].name}, below absolute zero: an undershoot of the "
                                   "discretisation (a heated layer thinner than the elements, or a heat input far too "
                                   "large for the bodies); refine the mesh across the thickness near the interface "
                                   "or check the load, speed and materials (docs/architecture.md, Known problems)")
        self.time += dt
        self.lost_step = self._losses(dt)
        self.lost_total += self.lost_step
        lost = self.lost_step.sum(axis=0)
        return ThermalStep(self.time, tuple(dt * power.sum(axis=0)), self.max_temperature(), tuple(map(float, lost)),
                           dt * self.exchange_power() if self.conductance else 0.0, dt * power)

    def _note_backtracking(self, dt: float) -> None:
        """The first step that converged only with backtracking, said once: a note for the run's
        warnings and a ``HeatStepWarning`` (rank 0; the step is collective)."""
        self._say(f"the heat step to t = {self.time + dt:.6g} s was too long for full Newton steps ({dt:.4g} s: "
                  f"the radiation or the temperature tables change too much over it) and {BACKTRACKED}; a step "
                  "that long is coarse in time: more time.steps or substeps follow the heating more closely "
                  "(said for the first such step only)", HeatStepWarning)

    def _say(self, note: str, category: type) -> None:
        """``note`` (if any) added to the run's warnings, and a Python warning of ``category`` on rank 0."""
        if note:
            self.notes.append(note)
            if self.tm.comm.rank == 0:
                warnings.warn(note, category, stacklevel=4)

    def exchange_power(self) -> float:
        """Heat [W] conducted from body 0 to body 1 through the interface conductance at the current
        temperatures (the residual's own term: for the step just solved, backward Euler's flux)."""
        c = self.contact
        return self.cache.scalar("exchange", lambda: c.engaged * c.conductance("+") * (self.T[0]("+") - self.T[1]("-"))
                                 * self.tm.interface.dS)

    def _losses(self, dt: float) -> np.ndarray:
        """Heat lost [J] through each condition and body during the step just solved (see module
        docstring): boundary integrals, and the reaction of the fixed-temperature dofs."""
        out = np.zeros((len(self.boundaries), 2))
        claimed = [np.empty(0, np.int32), np.empty(0, np.int32)]
        residual = {}
        for a in self.applied:
            T, ds = self.T[a.body], self.ds[a.body]
            key = (a.index, a.body)
            if a.h is not None:
                out[key] += dt * self.cache.scalar(("convection",) + key, lambda: a.h * (T - a.ambient) * ds(
                    measure_id(a.index, "convection"), degree=self._facet_degree(a.body, CONVECTION_QUADRATURE)))
            if a.condition.emissivity is not None:
                out[key] += dt * self.cache.scalar(("radiation",) + key, lambda: self._radiation(a) * ds(
                    measure_id(a.index, "emissivity"), degree=self._facet_degree(a.body, RADIATION_QUADRATURE)))
            if a.bc is not None:
                if a.body not in residual:
                    residual[a.body] = self.cache.vector(("residual", a.body), lambda: self.residuals[a.body])
                dofs, owned = a.bc.dof_indices()
                dofs = np.setdiff1d(dofs[:owned], claimed[a.body])      # a dof counts once
                claimed[a.body] = np.union1d(claimed[a.body], dofs)
                out[key] -= dt * self.tm.comm.allreduce(residual[a.body][dofs].sum(), op=MPI.SUM)
        return out

    @property
    def heat_lost(self) -> np.ndarray:
        """Heat lost [J] through the boundary conditions since the start, per body."""
        return self.lost_total.sum(axis=0)

    def max_temperature(self) -> tuple:
        """Largest nodal temperature of each body [K]."""
        return tuple(self.tm.comm.allreduce(T.x.array.max(initial=-np.inf), op=MPI.MAX) for T in self.T)

    def region_temperature(self, i: int, by: str = "material", lowest: bool = False) -> dict:
        """Largest (``lowest``: smallest) nodal temperature [K] of the cells of body ``i`` grouped by
        their regions' ``by``: "material", or "name" (the parts of a geometry file, a brake's pads;
        collective; a node on a boundary between two groups belongs to both)."""
        if (i, by) not in self.region_dofs:
            body = self.tm.bodies[i]
            dofs = self.T[i].function_space.dofmap.list[:len(body.region_tags)]
            self.region_dofs[i, by] = {g: np.unique(dofs[cells]) for g, cells in body.region_cells(by).items()}
        T, (extreme, op, none) = self.T[i].x.array, (np.min, MPI.MIN, np.inf) if lowest else (np.max, MPI.MAX, -np.inf)
        return {g: self.tm.comm.allreduce(extreme(T[mine], initial=none), op=op) for g, mine in self.region_dofs[i, by].items()}

    def min_temperature(self) -> tuple:
        """Smallest nodal temperature of each body [K] (below every imposed temperature: an undershoot
        of the discretisation, ``workflows.run_warnings``)."""
        comm = self.tm.comm
        return tuple(comm.allreduce(T.x.array.min(initial=np.inf), op=MPI.MIN) for T in self.T)

    def stored_heat(self) -> tuple:
        """Heat stored in each body since the start [J] (``cell_stored_heat`` summed; collective)."""
        return tuple(self.tm.comm.allreduce(self.cell_stored_heat(i).sum(), op=MPI.SUM) for i in range(2))

    def region_stored_heat(self, i: int, by: str = "name") -> dict:
        """Heat stored since the start [J] in the cells of body ``i`` grouped by their regions' ``by``
        (``region_temperature``; the groups' sum is the body's; collective)."""
        heat = self.cell_stored_heat(i)
        return {g: self.tm.comm.allreduce(heat[cells].sum(), op=MPI.SUM)
                for g, cells in self.tm.bodies[i].region_cells(by).items()}

    def cell_stored_heat(self, i: int) -> np.ndarray:
        """Heat stored in each local cell of body ``i`` since the start [J], ∫ (e(T) − e(T_0)) dx
        (rho c (T − T_0) for a constant rho c) with the storage term's own quadrature, so that the
        balance is exact; 0 in ghost cells."""
        def energy():
            p = self.capacity[i]
            e = self.rho_c[i] * (self.T[i] - self.T0) if p.constant else p.integral(self.T[i], self.T0)
            return e * ufl.TestFunction(self.cell_spaces[i]) * self._storage_dx(i)
        return self.cache.vector(("stored", i), energy)[self.cell_spaces[i].dofmap.list[:, 0]]

    def facet_temperature(self, side: int = 0) -> np.ndarray:
        """Mean temperature per interface facet [K] of body 0 ("+") or body 1 ("−") (both sides'
        from one compiled form)."""
        both = self.cache.facet_integrals("T", lambda: ufl.as_vector([self.T[0]("+"), self.T[1]("-")]), components=2)
        return both[:, side] / self.tm.interface.areas


__all__ = ["STEFAN_BOLTZMANN", "HeatStepWarning", "Thermal", "ThermalBoundary", "ThermalStep", "temperature_functions"]

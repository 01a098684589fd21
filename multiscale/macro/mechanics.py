"""Quasi-static elasticity of the two bodies, coupled only through the contact interface.

Small-strain isotropic elasticity per material region, optional thermal strain alpha (T − T_ref) I
(thesis Fig. 7.4, "contact problem with thermal expansion"; alpha the mean, secant coefficient from
T_ref), a normal load on the builder's load faces, zero-displacement supports, and the penalty/law
contact with steady Coulomb sliding friction of ``interface.ContactInterface``. Solved
monolithically (block Jacobian, GMRES preconditioned by a MUMPS factorisation, see
``PRECONDITIONERS``) by SNES Newton from rest with load ramping; failures raise
``ConvergenceError`` with the residual history.

E, nu and alpha are constants per region (DG0) or, with a temperature field, piecewise-linear
functions of T (``macro.materials``); without a temperature field, tables are taken at T_ref.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field, replace
from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.macro import mumps
from multiscale.macro.compact_factor import CompactFactor
from multiscale.macro.interface import ContactInterface, PressureLaw
from multiscale.macro.kept_cells import (Closed, KeptCells, SolverOptionWarning, assemble, backtracking, check_user_options,
                                         destroy, integrals, jacobian, nonlinear_problem, options_named,
                                         user_options)
from multiscale.macro.load_faces import check_load_faces, load_face_areas
from multiscale.macro.materials import body_expressions
from multiscale.macro.mesh import TwoBodyMesh

# Inexact Newton on the assembled tangent (Eisenstat-Walker forcing terms, their choice 3 in PETSc:
# each linear solve only as accurate as the Newton step needs; the Newton tolerance is unchanged;
# on the thesis ch. 7 configuration 6-7 Newton iterations where choice 2 took 8-10).
# Each linear solve is GMRES on the current tangent, preconditioned by a factorisation (MUMPS) kept
# across Newton iterations and solves (time steps) until the time of the GMRES iterations it costs
# beyond one per linear solve exceeds the time of a factorisation, both measured on the run (the
# "ski rental" rule: never more than twice the better of the two choices in hindsight). Factors of a
# loaded state keep GMRES at a few iterations for steps on end on the thesis ch. 7 configuration
# (issue 23). A solve that fails with old factors is repeated from its start with fresh ones every
# iteration, and then once more with a backtracking line search, fresh ones too (``Mechanics.solve``).
# The preconditioner is built from a matrix of its own, written only at a refresh: PETSc
# refactorises when that matrix changed, and only then. The factors are in
# single precision (``FACTOR_PRECISION``; GMRES on the double tangent takes their rounding out, the
# Newton's residual and answer are double): half the factors' memory; on the thesis ch. 7 run (2
# ranks) a triangular solve takes 0.65x, a factorisation ~0.55x the time, and the Newton solves
# 0.64x (benchmarks/README). A retry factorises in double, and the Mechanics keeps double from
# then on.
# Flexible GMRES (the preconditioned directions kept): right-preconditioned GMRES forms its answer
# by one more application of the preconditioner, whose rounding in single precision then leaves a
# true residual of ~1e-7 where GMRES reports convergence (tests/test_compact_factor.py).
NEWTON_OPTIONS = {
    "snes_type": "newtonls", "snes_linesearch_type": "basic",
    "snes_rtol": 1e-10, "snes_atol": 1e-10, "snes_stol": 0.0, "snes_max_it": 30,
    "snes_ksp_ew": True, "snes_ksp_ew_version": 3,
    "ksp_type": "fgmres", "ksp_pc_side": "right", "ksp_rtol": 1e-10, "ksp_atol": 0.0, "ksp_max_it": 50,
    "ksp_gmres_restart": 50, "pc_type": "python",
}
# What the Newton GMRES is preconditioned by, MUMPS factors of a matrix without its zero entries
# (``compact_factor.CompactFactor``, options under <prefix>factor_): "lu", an LU of the tangent J
# itself (with fresh factors GMRES converges in one iteration in double precision, in a few in
# single); "cholesky", an LDL^T (sym=2) of the frictionless tangent J_0 (J with mu = 0:
# symmetric, the friction part J - J_0 = mu s (x) dp/du lives on the sliding interface only). The
# LDL^T takes about half the memory of the LU (0.58 vs 1.00 GB on the 106k-dof brake, double) and
# GMRES needs ~11 iterations per Newton step with fresh factors (measured on the 49k-dof brake at
# the preload, double; the symmetric part (J + J^T)/2 instead stalls: 200 iterations, 5e-5).
# Factors kept over the contact-status changes of the first Newton steps cost more GMRES
# iterations (~90 per step at 49k dofs with a fixed lag of 5), which the timed rule weighs against
# the factorisations they save.
PRECONDITIONERS = ("lu", "cholesky")
# The Newton's absolute tolerance is at least this share of the norm of the load vector: the
# residual's round-off floor is ~1.5e-12 of it (the coarse pin-on-disc at 200 and 867 N), so a solve
# starting near its answer (a load changed by 1 N of 867 N: first residual 0.15) stalled at 1.7e-10 above the
# fixed 1e-10 N and failed. Ours is at most TINY_LOAD of it (1e-9 N on the pin stopped at 1.045e-9 N).
NEWTON_FLOOR, TINY_LOAD = 1e-10, 1e-8
# ... and at least this many times eps ||diag(K_cell) x||, the residual's round-off at x (its cell
# part sums K_ij x_j): a stiff body carried far by a soft one stalls there (a steel pin on a 500 MPa
# disc at 100 N, bending 1.4 mm: 5.8e-9 N against a tolerance of 1.4e-9 N, eps ||diag(K) x|| = 9.2e-9
# N), and failed. A solve that stops short is accepted below it (``_newton``: a stall, not a runaway).
ROUNDOFF, SNES_LINEAR_FAILED = 10.0, PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
# ... and at most this share of the load vector's norm: a runaway's floor grows with it (a block
# pulled off its flat, backtracking with fresh factors: 7e7 m, floor 25.8 N, residual 20 -> 15.7 N
# of a ~400 N load taken as converged), the legitimate ones are ~1e-10 of the load
ROUNDOFF_CAP = 1e-6
FACTOR_PRECISION = "single"
# ``refresh`` with a scene's ``output.repeatable``: the factors renewed once the GMRES iterations
# beyond one per solve reach this count, not by measured times, so serial runs repeat bit for bit
# (docs/architecture.md §8: the count the runs there were compared with).
REPEATABLE_REFRESH = 20
# A friction coefficient beyond which a failed Newton names it: dry sliding pairs stay below ~1 (brake
# pads 0.3-0.6); far above, a sliding equilibrium may not exist (a squeal run at mu = 5 failed with no
# word of it: a user trial; the block of the tests fails at mu = 100, solves at 20).
HIGH_FRICTION = 1.0


@dataclass
class SolveResult:
    """One nonlinear solve."""

    converged: bool
    reason: int                    # PETSc SNES converged reason
    iterations: int                # Newton iterations, of every attempt (retries with fresh factors)
    residuals: list = field(default_factory=list)   # residual norm per Newton iteration (the last attempt)
    normal_force: float = 0.0      # N, total contact force
    max_pressure: float = 0.0      # Pa, largest per-facet mean pressure


class Mechanics:
    """Two-body contact mechanics (see module docstring).

    ``materials`` maps material names (of the geometry's regions) to objects with ``E`` [Pa],
    ``nu`` and, with ``temperatures`` given, ``alpha`` [1/K], each a constant or a temperature table
    ((K, value), ...). ``temperatures`` is a pair of Lagrange functions on the body submeshes (thermal
    expansion relative to ``reference_temperature`` [K], the temperature of tables without them).
    ``stiffness`` [Pa/m] (scalar or per-facet array), ``friction``, ``speed`` and ``law`` go to
    ``ContactInterface``. ``load`` is the total force [N] along the spec's load direction on its
    load faces (``load_kind="force"``), a traction [Pa] along it (``load_kind="pressure"``), or a
    fluid pressure p [Pa] (``load_kind="fluid"``: traction −p n with n the outward normal, so two
    faces that look at each other across the fluid, e.g. a brake's piston back and caliper bore,
    are pushed apart by the same pressure). ``refresh``: None (default) to refactorise by the timed
    rule of ``NEWTON_OPTIONS`` (runs then repeat within the Newton tolerance, not bit for bit), or a
    number of GMRES iterations beyond one per linear solve, summed since the last factorisation,
    from which on the next Newton iteration factorises afresh (0: a fresh factorisation every
    iteration; fresh serial processes then repeat bit for bit, docs/architecture.md "Known
    problems"); ``preconditioner``: one of ``PRECONDITIONERS`` (see there). ``factorisations``
    counts the preconditioner's factorisations so far. Options the user set under ``prefix``
    (``PETSC_OPTIONS="-mech_snes_max_it 50"``) win over ``NEWTON_OPTIONS``; a line search the user
    chose is not replaced on a failed solve, a ``-mech_pc_type`` replaces the preconditioner
    (``own_pc`` False; else its ``-mech_pc_...`` options have no effect, ``notes`` says so).
    """

    LOAD_KINDS = ("force", "pressure", "fluid")

    def __init__(self, tm: TwoBodyMesh, materials: Mapping[str, object], *, stiffness=1e13,
                 friction: float = 0.0, speed: float = 0.0, law: PressureLaw | None = None,
                 velocity=None, temperatures=None, reference_temperature: float = 293.15,
                 load_kind: str = "force", degree: int = 1, prefix: str = "mech_", refresh: int | None = None,
                 preconditioner: str = "lu"):
        if load_kind not in self.LOAD_KINDS:
            raise InputError("load_kind", load_kind, f"one of {', '.join(self.LOAD_KINDS)}")
        if preconditioner not in PRECONDITIONERS:
            raise InputError("preconditioner", preconditioner, f"one of {', '.join(PRECONDITIONERS)}")
        self.tm = tm
        self.spaces = [fem.functionspace(b.mesh, ("Lagrange", degree, (3,))) for b in tm.bodies]
        self.u = [fem.Function(V, name=f"displacement_{b.name}") for V, b in zip(self.spaces, tm.bodies)]
        self.temperatures = temperatures
        self.reference_temperature = float(reference_temperature)
        T, T_ref = temperatures, self.reference_temperature
        self.E = body_expressions(tm, materials, "E", T, T_ref)        # DG0, or UFL of T with tables
        self.nu = body_expressions(tm, materials, "nu", T, T_ref)
        if temperatures is not None:     # T_ref a form constant (a literal: new forms for each value)
            self.alpha, self.T0 = body_expressions(tm, materials, "alpha", T, T_ref), fem.Constant(tm.parent, T_ref)
        self.contact = ContactInterface(tm, *self.u, stiffness=stiffness, friction=friction, speed=speed,
                                        law=law, velocity=velocity)
        self.load = fem.Constant(tm.parent, 0.0)        # N (force) or Pa (pressure), ramped
        self.load_kind = load_kind
        v = [ufl.TestFunction(V) for V in self.spaces]
        F = [ufl.inner(self.stress(i), ufl.sym(ufl.grad(v[i]))) * self.dx(i) for i in range(2)]
        Fc = self.contact.residuals(*v)
        F = [F[i] + Fc[i] for i in range(2)]
        check_load_faces(tm)
        for name in tm.spec.load_faces:
            i = tm.body_of_face(name)
            F[i] -= ufl.dot(self.traction(), v[i]) * tm.ds(tm.face(name))
        self.residuals = F
        self._unit_load = self._load_norm(v)
        self.bcs = self._supports()
        self.refresh = None if refresh is None else int(refresh)
        # the tangent's cell integrals (small-strain elasticity: E, nu constant or of T, not of u)
        # are kept until an input of theirs changes (T with E(T), nu(T)), its facet integrals are
        # assembled every iteration; the residual's cell part is affine in u: assembled at a solve's
        # start x_0, then updated by the kept cell matrix times x - x_0, its facet part every
        # evaluation. Only the parts are compiled: the problem's matrices are created from the cell
        # parts (``KeptCells.attach``), its vectors from the cell residual
        P = self._frictionless_jacobian() if preconditioner == "cholesky" else None
        self._split = [KeptCells(form, tm.entity_maps, self.bcs) for form in (jacobian(F, self.u), P)
                       if form is not None]
        self._cell_residual, self._facet_residual = (
            fem.form([integrals(f, cells) for f in F], entity_maps=tm.entity_maps) for cells in (True, False))
        # the user's options under the prefix (PETSC_OPTIONS="-mech_...") win over ours
        self.problem = nonlinear_problem(self._cell_residual, self.u, prefix, NEWTON_OPTIONS, bcs=self.bcs,
                                         J=self._split[0].cells, P=None if P is None else self._split[1].cells,
                                         entity_maps=tm.entity_maps)
        self._atol = self.problem.solver.getTolerances()[1]     # ours or the user's: the floors' base (ours:
        self._own_atol = not PETSc.Options(prefix).hasName("snes_atol")   # at most TINY_LOAD of the load)
        # a failed solve is redone with backtracking unless the user chose a line search (theirs alone remain)
        self._backtrack = not PETSc.Options(prefix).hasName("snes_linesearch_type")
        self.factors = CompactFactor(preconditioner, prefix=prefix + "factor_", precision=FACTOR_PRECISION)
        # a -<prefix>pc_type of the user's replaces ours (``CompactFactor``), of the same matrix P
        self.own_pc = not PETSc.Options(prefix).hasName("pc_type")
        if self.own_pc:
            check_user_options(tm.comm, self.factors.prefix, self.factors.options)
            self.problem.solver.getKSP().getPC().setPythonContext(self.factors)
        unused = options_named(prefix, "pc_")
        self.notes = [] if not (self.own_pc and unused) else [   # said as a SolverOptionWarning
            f"PETSC_OPTIONS: {' '.join(unused)} had no effect: the contact Newton's preconditioner is its own kept "
            f"factorisation, whose options are under -{prefix}factor_ (e.g. -{prefix}factor_pc_factor_mat_solver_type"
            f"); -{prefix}pc_type would replace it by PETSc's"]
        for note in self.notes if tm.comm.rank == 0 else ():     # once a run, as the heat's (Thermal._say)
            warnings.warn(note, SolverOptionWarning, stacklevel=2)
        if P is not None:
            self.problem.P_mat.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            self.problem.P_mat.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
        for kept, matrix in zip(self._split, (self.problem.A, self.problem.P_mat)):
            kept.attach(matrix)
        self._fresh = False                # a fresh factorisation every Newton iteration (retry)
        self._pc_stale = True              # the preconditioner matrix is to be rewritten
        self._excess = 0                   # GMRES iterations beyond one per linear solve since then
        self.factorisations = 0
        self._clock = {"mark": 0.0, "factor": 0.0, "iteration": 0.0, "refreshing": False}   # s
        self.problem.solver.getKSP().setMonitor(self._tick)
        self._pc_mat = self.problem.P_mat if P is not None else self.problem.A.duplicate()
        self.problem.solver.setJacobian(self._jacobian, self.problem.A, self._pc_mat)
        self._blocks = self.problem.b.getAttr("_blocks")          # DOLFINx's block layout of the vectors
        self._offset, self._start, self._step = (self.problem.b.duplicate() for _ in range(3))
        self._offset.setAttr("_blocks", self._blocks)
        self._offset_stale = True
        self.bcs_by_body = fem.bcs_by_block(fem.extract_function_spaces(self._cell_residual), self.bcs)
        self.problem.solver.setFunction(self._residual, self.problem.b)
        self._frictionless = None          # (matrix, form) of ``frictionless_tangent`` without P
        self._history: list[float] = []
        self._solve_atol = self._atol      # N, the absolute tolerance of the current solve (``solve``)
        self._load_scale = 0.0             # N, the norm of the current solve's load vector (``solve``)
        self.problem.solver.setMonitor(self._watch)

    def release(self) -> None:
        """Free the factors of the Newton preconditioner (the next solve factorises afresh): a modal
        analysis after the preload then does not hold two factorisations at once."""
        self.problem.solver.getKSP().getPC().reset()
        self._pc_stale = True

    def close(self) -> None:
        """Destroy the Newton's PETSc objects, factors first (``kept_cells.destroy``: collective, on
        every rank in the same order); freed when dropped. A solve after raises ``ClosedError``."""
        if not isinstance(self.problem, Closed):              # (a second close does nothing)
            self.factors.reset(None)
            self.problem = destroy(self.problem, "Mechanics", self._pc_mat, self._offset, self._start, self._step,
                                   self._frictionless and self._frictionless[0], *(k.bulk for k in self._split))

    # ---- forms -----------------------------------------------------------------------------
    def _frictionless_jacobian(self) -> list:
        """Block Jacobian of the residuals with mu = 0 (UFL forms; symmetric)."""
        zero = fem.Constant(self.tm.parent, 0.0)
        return [[None if f is None else ufl.replace(f, {self.contact.friction: zero}) for f in row]
                for row in jacobian(self.residuals, self.u)]

    def _jacobian(self, snes, x, J, P) -> None:
        """SNES Jacobian callback: J = cell part (kept) + facet part at x; the preconditioner
        matrix P is rewritten (J itself, or J_0 with "cholesky") only at a refresh: the first
        call, after ``release``, on a retry, after a failed linear solve, or once the GMRES
        iterations beyond one per linear solve since the last refresh cost more than it (timed),
        or number ``refresh`` or more."""
        ksp, clock = snes.getKSP(), self._clock
        self._excess += max(ksp.getIterationNumber() - 1, 0)       # the last linear solve's
        if self.refresh is None:                 # timings differ between ranks: decide together
            due = self.tm.comm.allreduce(self._excess * clock["iteration"] > clock["factor"], op=MPI.LOR)
        else:
            due = self._excess >= self.refresh
        refresh = self._pc_stale or self._fresh or due or ksp.getConvergedReason() < 0
        if refresh:
            self._excess = 0
            self.factorisations += 1
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fpetsc.assign(x, self.u)
        self._compose(J, 0)
        if refresh and len(self._split) == 2:
            self._compose(P, 1)                                     # J_0 ("cholesky")
        elif refresh:
            J.copy(P, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self._pc_stale = False
        clock["refreshing"], clock["mark"] = refresh, time.perf_counter()

    def _tick(self, ksp, it: int, rnorm: float) -> None:
        """KSP monitor: the time to GMRES's first call after a refresh is the factorisation's, the
        time between later calls one iteration's (a running mean)."""
        clock, now = self._clock, time.perf_counter()
        if it == 0 and clock["refreshing"]:
            clock["factor"] = now - clock["mark"]
        elif it > 0:
            step = now - clock["mark"]
            clock["iteration"] = step if clock["iteration"] == 0.0 else 0.8 * clock["iteration"] + 0.2 * step
        clock["mark"] = now

    def _compose(self, A: PETSc.Mat, k: int) -> PETSc.Mat:
        """``A`` overwritten by split form k (0: the tangent, 1: J_0) at the current state: its cell
        part (reassembled if an input of it changed) plus its facet part, with the supports."""
        self._split[k].update()
        return self._split[k].compose(A)

    def _residual(self, snes, x, b) -> None:
        """SNES residual callback: F(x) = r_cell(x_0) + K_cell (x - x_0) + facet part at x (contact,
        load faces), with the supports (x - 0 on their rows; the supports are homogeneous and x
        meets them, so there is nothing to lift). The cell part is affine in x (linear elasticity,
        thermal expansion at the solve's temperatures): r_cell is assembled at x_0, a solve's first
        call, and K_cell is the tangent's kept cell part. Only the increment goes through K_cell:
        K_cell x itself would cancel against the thermal expansion term in round-off (a floor near
        the Newton tolerance where the thermal strains dominate)."""
        b.setAttr("_blocks", self._blocks)
        x.setAttr("_blocks", self._blocks)
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        fpetsc.assign(x, self.u)
        if self._offset_stale:
            self._split[0].update()
            self._assemble_vector(self._offset, self._cell_residual)
            x.copy(self._start)
            self._offset_stale = False
        self._assemble_vector(b, self._facet_residual)
        self._step.waxpy(-1.0, self._start, x)                     # x - x_0
        self._split[0].bulk.multAdd(self._step, b, b)
        b.axpy(1.0, self._offset)
        fpetsc.set_bc(b, self.bcs_by_body, x0=x, alpha=-1.0)
        b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    @staticmethod
    def _assemble_vector(b, forms) -> None:
        """``b`` overwritten by the block vector of ``forms`` (owned entries summed over ranks)."""
        with b.localForm() as local:
            local.set(0.0)
        fpetsc.assemble_vector(b, forms)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)

    def dx(self, i: int):
        """Volume measure over the regions of body i (on the parent mesh)."""
        return self.tm.body_dx(i)

    def stress(self, i: int):
        """Cauchy stress of body i [Pa], sigma = C(T):(eps − alpha(T) (T − T_ref) I)."""
        E, nu = self.E[i], self.nu[i]
        lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
        eps = ufl.sym(ufl.grad(self.u[i]))
        if self.temperatures is not None:
            eps = eps - self.alpha[i] * (self.temperatures[i] - self.T0) * ufl.Identity(3)
        return lam * ufl.tr(eps) * ufl.Identity(3) + 2 * mu * eps

    def von_mises(self, i: int):
        """Von Mises equivalent stress of body i [Pa] (UFL, on the body's submesh)."""
        s = self.stress(i)
        dev = s - ufl.tr(s) / 3 * ufl.Identity(3)
        return ufl.sqrt(1.5 * ufl.inner(dev, dev))

    def traction(self):
        """Applied traction on the load faces [Pa]."""
        if self.load_kind == "fluid":
            return -self.load * ufl.FacetNormal(self.tm.parent)
        direction = np.asarray(self.tm.spec.load_direction, float) / np.linalg.norm(self.tm.spec.load_direction)
        if self.load_kind == "force":                   # per unit area [1/m^2]: the faces' area, a mesh's number
            direction = direction / sum(load_face_areas(self.tm, self.load_kind).values())
        return self.load * fem.Constant(self.tm.parent, direction)      # a constant: no form per mesh

    def _load_norm(self, v) -> float:
        """Norm [N] of the load faces' nodal forces at load 1 (linear in the load; collective)."""
        forms = {}
        for name in self.tm.spec.load_faces:
            i = self.tm.body_of_face(name)
            forms[i] = forms.get(i, 0) + ufl.dot(self.traction(), v[i]) * self.tm.ds(self.tm.face(name))
        kept, self.load.value, total = float(self.load.value), 1.0, 0.0
        for f in forms.values():
            b = fpetsc.assemble_vector(fem.form(f, entity_maps=self.tm.entity_maps))
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            total += b.norm() ** 2
            b.destroy()
        self.load.value = kept
        return float(np.sqrt(total))

    def _supports(self) -> list:
        bcs = []
        fdim = self.tm.parent.topology.dim - 1
        for sup in self.tm.spec.supports:
            tag = self.tm.face(sup.face)
            for i, body in enumerate(self.tm.bodies):
                if not body.has_face(tag):
                    continue
                facets = body.facet_tags.find(tag)
                for c in sup.components:
                    sub = self.spaces[i].sub(c)
                    dofs = fem.locate_dofs_topological(sub, fdim, facets)
                    bcs.append(fem.dirichletbc(0.0, dofs, sub))
        return bcs

    def mass_forms(self, density):
        """Block-diagonal mass forms [[m_00, None], [None, m_11]] with per-body density fields."""
        trial = [ufl.TrialFunction(V) for V in self.spaces]
        test = [ufl.TestFunction(V) for V in self.spaces]
        m = [density[i] * ufl.dot(trial[i], test[i]) * self.dx(i) for i in range(2)]
        return [[m[0], None], [None, m[1]]]

    # ---- solution --------------------------------------------------------------------------
    def displacements(self) -> list:
        """Copies of each body's displacement array [m] (owned and ghost entries: no scatter needed
        to put them back with ``set_displacements``)."""
        return [u.x.array.copy() for u in self.u]

    def set_displacements(self, arrays) -> None:
        """Each body's displacements [m] from ``arrays`` (``displacements``' layout, or a number)."""
        for u, x in zip(self.u, arrays):
            u.x.array[:] = x

    def solve(self, load: float | None = None, guess: list | None = None) -> SolveResult:
        """Newton solve at the given load (N or Pa); raises ConvergenceError on failure. ``guess``:
        per-body displacement increments [m] (arrays of the ``u`` layout) to start from instead, if
        the residual there is smaller (e.g. the increment of a similar solve before)."""
        if load is not None:
            self.load.value = float(load)
        scale = abs(float(self.load.value)) * self._unit_load          # N, the load vector's norm
        self._load_scale = scale
        atol = min(self._atol, TINY_LOAD * scale) if scale > 0 and self._own_atol else self._atol
        self._solve_atol = max(atol, NEWTON_FLOOR * scale, self._roundoff())
        start = self.displacements()
        if guess is not None:
            before = self._residual_norm()
            self.set_displacements([x + du for x, du in zip(start, guess)])
            if not self._residual_norm() < before:       # the same on every rank (a global norm)
                self.set_displacements(start)
        result = first = self._newton()
        spent = first.iterations           # over the attempts
        if not result.converged:           # old or single-precision factors can mislead: again, fresh double ones
            self.factors.set_precision("double")
            result = self._afresh(start)
            spent += result.iterations
        if not result.converged and self._backtrack:   # a full step overshot (worn laws opening the contact: the
            with backtracking(self.problem.solver):    # residual 77 -> 1.5e6 N, SNES -9): again, backtracking
                result = self._afresh(start)
            spent += result.iterations
        if not result.converged:
            pc = self.factors.inner if self.own_pc else self.problem.solver.getKSP().getPC()
            failed = "" if pc is None else mumps.describe(pc)  # the same on every rank
            cause = f"; the preconditioner's factorisation failed: {failed}" if failed else ""
            if not self.own_pc:
                cause += (f"; preconditioned by the user's PC (PETSC_OPTIONS = "
                          f"'{user_options(self.problem.solver.getOptionsPrefix())}') instead of the contact "
                          "Newton's own factorisation (leave pc_type unset for it)")
            free = ("a body, or a solid of one, can move as a rigid body: give each a support ([[boundary]] fix) "
                    "or a contact that holds it in every direction (friction does not hold a body, and can tip one "
                    "its supports hold sideways only; a part that touches nothing is held by its supports alone), "
                    "or a penalty far above E*/h ill-conditions it")
            if first is not result:       # the retries start afresh: the first attempt says more
                cause += (f"; the first of its attempts: SNES reason {first.reason}, {first.iterations} iterations, "
                          f"residuals {['%.3g' % r for r in first.residuals[-4:]]}")
            mu = self.tm.comm.allreduce(float(np.max(self.contact.friction.x.array, initial=0.0)), op=MPI.MAX)
            if mu > HIGH_FRICTION:
                cause += (f"; the friction coefficient reaches {mu:.3g}, far above a dry sliding pair's (brake pads "
                          "0.3-0.6): with friction this high a sliding equilibrium may not exist (friction turns "
                          "the tangent unstable, a static divergence: a squeal analysis names it as unstable modes "
                          "at 0 Hz); check the friction given (loading.friction, the interfaces' own)")
            code = 0 if pc is None else mumps.status(pc)
            if code in mumps.MEMORY_ERRORS:      # (it gave the rigid-body advice: a user trial)
                cause += ("; the factors did not fit in memory: a coarser mesh (geometry.mesh_size), or more "
                          "memory, the model's ranks spread over more machines (docs/performance.rst)"
                          + (", or a higher cap mat_mumps_icntl_23" if code == -19 else ""))
            elif result.reason == SNES_LINEAR_FAILED:
                cause += f"; the linear solve failed, as it does when {free}"
            elif result.reason == PETSc.SNES.ConvergedReason.DIVERGED_DTOL:
                cause += f"; the residual grew, as it can when {free}"
            raise ConvergenceError(
                f"contact Newton did not converge at load {float(self.load.value):.6g} "
                f"{'N' if self.load_kind == 'force' else 'Pa'} "
                f"(SNES reason {result.reason}, {result.iterations} iterations, residuals "
                f"{['%.3g' % r for r in result.residuals]}{cause})", result.residuals,
                replace(result, iterations=spent))
        result.iterations = spent
        result.normal_force = self.contact.normal_force()
        result.max_pressure = float(self.contact.facet_pressure().max(initial=0.0))
        return result

    def _afresh(self, start: list) -> SolveResult:
        """``_newton`` from the displacements ``start`` with fresh factors at every iteration (a retry:
        factors kept by the refresh rule over the backtracking steps of a nearly singular tangent let
        GMRES reach its cap, SNES -3, where fresh ones converged; zone laws of H(T) flattened by flash
        softening after a wear step)."""
        self.set_displacements(start)
        self._fresh = True
        try:
            return self._newton()
        finally:
            self._fresh = False

    def _residual_norm(self) -> float:
        """||F(u)|| at the current state (collective)."""
        x, b = self.problem.x, self.problem.b
        fpetsc.assign(self.u, x)
        self._offset_stale = True
        self._residual(None, x, b)
        return b.norm()

    def _roundoff(self) -> float:
        """``ROUNDOFF`` eps ||diag(K_cell) x|| [N] at the current state (collective)."""
        fpetsc.assign(self.u, self.problem.x)
        return self._floor(self.problem.x)

    def _floor(self, x: PETSc.Vec) -> float:
        """``ROUNDOFF`` eps ||diag(K_cell) x|| [N] at displacements x, at most ``ROUNDOFF_CAP`` of the
        load (collective)."""
        d = self._split[0].bulk.getDiagonal()
        d.pointwiseMult(d, x)
        floor = ROUNDOFF * np.finfo(float).eps * d.norm()
        d.destroy()
        return min(floor, ROUNDOFF_CAP * self._load_scale) if self._load_scale > 0 else floor

    def _watch(self, snes, it, norm) -> None:
        """SNES monitor: the residual history, and the absolute tolerance raised to the round-off
        floor at the current iterate, at most the first residual (``_newton``'s stall, accepted as
        it comes: a block 1e6 x stiffer than its flat stalled at 3e-9 N from iteration 5 to the cap
        of 30, its floor 0 at the start; a runaway's floor grows with it: ``ROUNDOFF_CAP`` bounds it)."""
        self._history.append(norm)
        floor = min(self._floor(snes.getSolution()), self._history[0])
        if floor > snes.getTolerances()[1]:
            snes.setTolerances(atol=floor)

    def _newton(self) -> SolveResult:
        """One SNES solve from the current state; converged only if finite on every rank, and either
        converged by SNES or stalled: linear solves done, the last residual within ``_roundoff`` and
        not above the first (a block pulled off its flat ran away to 3.6e9 m, residual 20 -> 83 N)."""
        self._history.clear()
        self._offset_stale = True
        self.problem.solver.setTolerances(atol=self._solve_atol)     # each attempt from the solve's (``_watch``)
        self.problem.solve()
        snes = self.problem.solver
        reason, its, history = snes.getConvergedReason(), snes.getIterationNumber(), list(self._history)
        finite = all(np.isfinite(history)) and all(np.isfinite(u.x.array).all() for u in self.u)
        finite = bool(self.tm.comm.allreduce(finite, op=MPI.LAND))     # every rank decides alike
        converged = reason > 0 or (finite and bool(history) and reason != SNES_LINEAR_FAILED
                                   and history[-1] <= min(history[0], self._roundoff()))
        return SolveResult(converged and finite, reason, its, history)

    def ramp(self, load: float, steps: int = 1) -> SolveResult:
        """Solve from the current state at loads load/steps, 2 load/steps, ..., load."""
        steps = int(check_positive("ramp_steps", steps))
        for k in range(1, steps + 1):
            result = self.solve(load * k / steps)
        return result

    def frictionless_tangent(self) -> PETSc.Mat:
        """The assembled block Jacobian with mu = 0 at the current state (symmetric, flagged so). Owned by the
        model (with ``preconditioner="cholesky"`` the preconditioner matrix), overwritten by the next call or solve."""
        if self.problem.P_mat is not None:       # the preconditioner's matrix: refactorise next time
            P, self._pc_stale = self._compose(self.problem.P_mat, 1), True
        else:
            if self._frictionless is None:
                form = fem.form(self._frictionless_jacobian(), entity_maps=self.tm.entity_maps)
                self._frictionless = (fpetsc.create_matrix(form), form)
            P = assemble(*self._frictionless, self.bcs)
        P.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        return P

    def cell_system(self) -> tuple[PETSc.Mat, PETSc.Vec]:
        """(K, r_0) of the bodies without contact and load, K u + r_0 = 0: K the tangent's kept cell
        part at the current temperatures (elasticity, block-diagonal, the supports' rows unit;
        owned by the Mechanics and overwritten when an input of it changes), r_0 a new vector, the
        cell residual at u = 0 (minus the thermal load [N], 0 on the supports' rows). Collective;
        the displacements are kept."""
        r0 = self.problem.b.duplicate()          # (ClosedError after close, before a destroyed matrix is used)
        r0.setAttr("_blocks", self._blocks)
        self._split[0].update()
        kept = self.displacements()
        try:
            self.set_displacements([0.0] * len(kept))
            self._assemble_vector(r0, self._cell_residual)
        finally:
            self.set_displacements(kept)
        fpetsc.set_bc(r0, self.bcs_by_body)
        return self._split[0].bulk, r0

    def tangent(self) -> PETSc.Mat:
        """The assembled block Jacobian at the current state (assembled on request)."""
        return self._compose(self.problem.A, 0)

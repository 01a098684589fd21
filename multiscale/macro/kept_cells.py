"""A block Jacobian assembled as a kept cell part plus its other integrals (issue 23).

The cell integrals of the two bodies (linear elasticity, heat conduction and transport with
constant materials) change only with a few parameters, while the interface and boundary integrals
(contact, friction, conductance) change at every call. ``KeptCells`` assembles the cell part into
a matrix of its own when its owner says so (``refresh``) and composes the Jacobian from a copy of
it and a fresh assembly of the other integrals (``compose``): equal to the assembly of the whole
form (tests/test_macro_block.py, tests/test_macro_thermal.py) at a fraction of its cost. The
whole form is never compiled: its matrix is created from the cell part and given the rest's
entries by ``attach`` (docs/architecture.md §2, numbers in forms).

Blocks that are zero once their derivatives are expanded are left out (``jacobian``): compiled,
each was a form without kernels, new for every scene (docs/architecture.md §2, numbers in forms).

The Jacobian's matrix ignores exact zeros of the element matrices once its pattern is fixed
(``MAT_IGNORE_ZERO_ENTRIES``; the values are the same): most entries of the facet blocks of a
vector field are zeros, and every add searches its row (docs/architecture.md §5, the macro Newton).

``nonlinear_problem`` sets up the DOLFINx problem such a Jacobian belongs to (the contact's and the
heat's Newton) with our solver options, the user's winning; ``destroy`` frees it, ``Closed`` stands
for it after.
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.fem import petsc as fpetsc
from dolfinx.fem.forms import derivative_block
from mpi4py import MPI
from petsc4py import PETSc
from ufl.algorithms import expand_derivatives
from ufl.algorithms.analysis import extract_coefficients, extract_constants

from multiscale.errors import ClosedError, InputError
from multiscale.io import counted


def integrals(form, cells: bool):
    """The cell integrals (``cells``) or all the others of a UFL form; None if there are none."""
    if form is None:
        return None
    part = ufl.Form([i for i in form.integrals() if (i.integral_type() == "cell") == cells])
    return None if part.empty() else part


def nonzero(form):
    """A UFL form with its derivatives expanded; None if it is zero then (an off-diagonal block of
    a derivative whose integrals do not hold the other body's field: compiled, a form with no
    kernel that still costs a compilation for each new scene) or if it is None."""
    if form is None:
        return None
    form = expand_derivatives(form)
    return None if form.empty() else form


def jacobian(F: list, u: list) -> list:
    """The block Jacobian dF_i/du_j (UFL, a list of lists) without its zero blocks (``nonzero``)."""
    return [[nonzero(f) for f in row] for row in derivative_block(F, u)]


# the subdomain id of no cell or facet (gmsh's physical tags and MeshTags' values are int32)
NOWHERE = 2**31 - 1


def empty_block(block):
    """The mass-like form of ``block``'s arguments over nothing (subdomain ``NOWHERE`` of its first
    integral's measure): a diagonal block with nothing to assemble still needs a form, as DOLFINx
    assembles no block form with a row or column of None, nor a None diagonal block where a
    Dirichlet condition holds. Its signature is of the spaces only: compiled once for every scene."""
    test, trial = block.arguments()
    first = block.integrals()[0]
    nowhere = ufl.Measure(first.integral_type(), domain=first.ufl_domain(), subdomain_id=NOWHERE,
                          subdomain_data=first.subdomain_data())
    return ufl.inner(trial, test) * nowhere


def assemble(A: PETSc.Mat, form, bcs) -> PETSc.Mat:
    """``A`` overwritten by the block matrix of the compiled ``form``, with the Dirichlet rows of
    ``bcs`` (unit diagonal)."""
    A.zeroEntries()
    fpetsc.assemble_matrix(A, form, bcs=bcs)
    A.assemble()
    return A


def nonlinear_problem(F, u, prefix: str, options: Mapping, **kwargs) -> fpetsc.NonlinearProblem:
    """DOLFINx's ``NonlinearProblem`` of the residuals ``F`` in ``u`` under the options prefix
    ``prefix`` (``kwargs``: its other arguments), with our solver ``options`` less those the user
    set under the prefix (``PETSC_OPTIONS="-<prefix>..."``): theirs win (given to DOLFINx, ours
    overwrote them). Ours are removed from PETSc's database after the set-up: DOLFINx 0.11 leaves
    them there (its deletion misses the prefix it pushed), and a later problem with the prefix
    would take them for the user's. Only the user's then remain under the prefix. A value PETSc
    refuses among the user's, or with ours, raises ``InputError`` on every rank first
    (``check_user_options``)."""
    check_user_options((u[0] if isinstance(u, (list, tuple)) else u).function_space.mesh.comm, prefix, options)
    user = PETSc.Options(prefix)
    ours = {k: v for k, v in options.items() if not user.hasName(k)}
    try:
        return fpetsc.NonlinearProblem(F, u, petsc_options_prefix=prefix, petsc_options=ours, **kwargs)
    finally:
        for name in ours:
            user.delValue(name)


class Closed:
    """A closed model's ``problem`` (``destroy``): any use raises ``ClosedError`` naming the model,
    not PETSc's crash (a segfault) on its destroyed objects."""

    def __init__(self, owner: str):
        self.owner = owner

    def __getattr__(self, name: str):
        raise ClosedError(f"{self.owner} is closed: close() destroyed its PETSc solvers (asked for problem.{name}); "
                          "its fields stay readable, but to solve again build a new model")


def destroy(problem: fpetsc.NonlinearProblem, owner: str, *others) -> Closed:
    """Destroy ``problem``'s SNES (with its KSP and PC: their factors, and the callbacks PETSc
    keeps), matrices and vectors, then the PETSc ``others`` (None skipped, one destroyed already a
    no-op), in this order; returns what replaces ``problem`` in its ``owner`` (named: "Mechanics").
    Collective, on every rank in the same order: MUMPS' destruction communicates. Dropping is no
    substitute: PETSc keeps the callbacks (bound methods of their owner) in a dict of the C object
    that Python's cycle collector cannot see, so a problem never destroyed keeps its owner, meshes
    and MPI communicators for good (about 35 a model; MPICH has 2048 per process); and objects
    freed by each rank's collector go in a different order on each rank, which hangs MUMPS.
    DOLFINx's own destruction of the objects after this is a no-op."""
    for obj in (problem.solver, problem.A, problem.P_mat, problem.b, problem.x, *others):
        if obj is not None:
            obj.destroy()
    return Closed(owner)


@contextmanager
def closed_on_error(model, comm):
    """``model`` (anything with ``close()``) closed when the block raises, then the error passed
    on: on one rank only. Under MPI an error may have been raised on one rank alone, and closing
    communicates (``destroy``): the other ranks would never join, so there the model stays open
    (its process ends: ``io.abort_on_exception``). Serially a script that goes on after a failed
    run (a loop over scenes) gets the model's MPI communicators back (about 35 of 2048 each)."""
    try:
        yield model
    except BaseException:
        if comm.size == 1:
            model.close()
        raise


@contextmanager
def backtracking(snes: PETSc.SNES):
    """``snes`` with PETSc's backtracking line search (``bt``) inside the block and the full Newton
    step (``basic``, ours) after: the retry of a solve whose full steps overshot (the contact's and
    the heat's Newton; not when the user chose a line search)."""
    search = snes.getLineSearch()
    search.setType("bt")
    try:
        yield
    finally:
        search.setType("basic")


# PC types that factorise by a package (``pc_factor_mat_solver_type``), and PETSc's error code when
# that package cannot (not installed, or not for this factorisation or matrix type)
FACTORISATIONS = ("lu", "cholesky", "ilu", "icc")
MISSING_FACTOR = 92


def check_user_options(comm, prefix: str, ours: Mapping | None = None) -> None:
    """Raise ``InputError`` on every rank of ``comm`` if PETSc refuses the options the user set under
    ``prefix``, with ``ours`` (the solver's own) where the user set none: a value it cannot read
    (``PETSC_OPTIONS="-<prefix>ksp_type nonsense"``: an unknown type, error 86) or a factorisation
    by a package it does not have (``-heat_pc_factor_mat_solver_type superlu``, error 92; the error
    names those it has, ``factor_packages``). They are tried on a bare SNES (its KSP, PC and line
    search; a factorising PC resolves its package on a small matrix over ``comm``, as a solve's
    first set-up does) destroyed after: a DOLFINx problem that failed half-way through its set-up
    crashed the process when collected. Nothing to try if the user set no option under ``prefix``."""
    options, given = PETSc.Options(prefix), user_options(prefix)
    if not given:
        return
    put = {k: v for k, v in (ours or {}).items() if not options.hasName(k)}
    for name, value in put.items():
        options[name] = value
    snes, A = PETSc.SNES().create(comm), _unit_matrix(comm)
    failure = factor = None
    try:
        snes.setOptionsPrefix(prefix)
        snes.setFromOptions()
        pc = snes.getKSP().getPC()
        if pc.getType() in FACTORISATIONS:
            factor = pc.getType()
            pc.setOperators(A, A)
            pc.setFactorSetUpSolverType()
    except PETSc.Error as exc:
        failure = exc.ierr
    finally:
        snes.destroy()
        for name in put:
            options.delValue(name)
    codes = [c for c in comm.allgather(failure) if c is not None]
    try:
        if codes and codes[0] == MISSING_FACTOR and factor is not None:
            raise InputError("PETSC_OPTIONS", given, f"this PETSc cannot factorise (pc_type {factor}) by the package "
                             f"-{prefix}pc_factor_mat_solver_type asks for (error {MISSING_FACTOR}); it has "
                             f"{', '.join(factor_packages(A, factor)) or 'none'} for this factorisation on "
                             f"{counted(comm.size, 'rank')}")
        if codes:
            raise InputError("PETSC_OPTIONS", given, f"PETSc refused one of these solver options (error {codes[0]}: "
                             "an unknown type or a value it cannot read); see PETSc's manual pages for the choices")
    finally:
        A.destroy()


def user_options(prefix: str) -> str:
    """The options set under ``prefix`` as given (``-heat_pc_type jacobi ...``; "" if none): the
    user's, outside a problem's set-up."""
    return " ".join(f"-{k} {v}".rstrip() for k, v in sorted(PETSc.Options().getAll().items()) if k.startswith(prefix))


def _unit_matrix(comm) -> PETSc.Mat:
    """The identity as an AIJ matrix of one row per rank of ``comm`` (sequential on one rank, as
    the problems' matrices are)."""
    A = PETSc.Mat().createAIJ(((1, None), (1, None)), nnz=1, comm=comm)
    first = A.getOwnershipRange()[0]
    A.setValue(first, first, 1.0)
    A.assemble()
    return A


def factor_packages(A: PETSc.Mat, factor: str) -> list[str]:
    """The packages (PETSc's solver types) that factorise ``A`` by ``factor`` ("lu", "cholesky",
    "ilu", "icc") in this PETSc, each tried (collective; the same on every rank)."""
    found = []
    for package in sorted(getattr(PETSc.Mat.SolverType, n) for n in dir(PETSc.Mat.SolverType) if n.isupper()):
        pc = PETSc.PC().create(A.getComm())
        try:
            pc.setType(factor)
            pc.setFactorSolverType(package)
            pc.setOperators(A, A)
            pc.setFactorSetUpSolverType()
            found.append(package)
        except PETSc.Error:
            pass
        finally:
            pc.destroy()
    return found


# options under a prefix that only a Newton method reads: a linear solve (SNES "ksponly": one
# Jacobian, one KSP solve) queries some of them (PETSc's "option left" does not list them) and
# uses none
NEWTON_ONLY = ("snes_linesearch_", "snes_rtol", "snes_atol", "snes_stol", "snes_max_it", "snes_max_funcs",
               "snes_max_fail", "snes_max_linear_solve_fail", "snes_divergence_tolerance", "snes_lag_",
               "snes_ksp_ew")


def options_named(prefix: str, starts: str | tuple) -> list[str]:
    """The options set under ``prefix`` whose names after it start with ``starts`` (one or a tuple),
    as given and sorted: ["-heat_snes_rtol", ...]."""
    return sorted(f"-{k}" for k in PETSc.Options().getAll()
                  if k.startswith(prefix) and k[len(prefix):].startswith(starts))


class SolverOptionWarning(UserWarning):
    """Options the user set under a solver's prefix that the solver does not use."""


def newton_options_unused(snes: PETSc.SNES, problem: str) -> str:
    """A note naming the options the user set under ``snes``' prefix that only a Newton method
    uses (``NEWTON_ONLY``) when ``snes`` is a linear solve (type "ksponly"; "" if none or if it is
    not): ``problem`` says why it is linear."""
    prefix = snes.getOptionsPrefix() or ""
    unused = options_named(prefix, NEWTON_ONLY)
    if not unused or snes.getType() != PETSc.SNES.Type.KSPONLY:
        return ""
    return (f"PETSC_OPTIONS: {' '.join(unused)} had no effect: {problem}, one linear solve a step, not Newton's "
            f"method; its Krylov solver and preconditioner take -{prefix}ksp_... and -{prefix}pc_... options "
            f"(-{prefix}snes_type newtonls would solve it by Newton's method)")


class KeptCells:
    """The block Jacobian ``form`` (UFL, a list of lists: ``jacobian``'s, whose expanded blocks hold
    no zero integral) split into its cell part, kept in ``bulk``, and the rest, each compiled; the
    whole form is never compiled (its kernels are the parts' again). The matrix A is created from
    the cell part (``create_matrix(cells)``) and ``attach`` gives it the whole Jacobian's sparsity.
    ``refresh`` reassembles ``bulk`` at the current state (``update``: only if a constant or
    coefficient of the cell integrals changed since, e.g. dt or a speed); ``compose`` overwrites a
    matrix of A's sparsity by bulk plus the rest at the current state, with the Dirichlet rows of
    ``bcs``. Blocks of either part that are zero are left out, and a body's diagonal block of the
    rest that has nothing is an ``empty_block`` (a body without interface or boundary terms)."""

    def __init__(self, form: list, entity_maps, bcs):
        self.bcs = bcs
        cells = [[integrals(f, True) for f in row] for row in form]
        others = [[integrals(f, False) for f in row] for row in form]
        for i, row in enumerate(others):
            if row[i] is None:
                row[i] = empty_block(form[i][i])
        self.cells = fem.form(cells, entity_maps=entity_maps)
        self.inputs = sorted({c for row in cells for f in row if f is not None
                              for c in extract_constants(f) + extract_coefficients(f)}, key=str)
        self._state = None                  # the inputs' values at the last refresh
        self.others = fem.form(others, entity_maps=entity_maps)
        self.bulk = None

    def attach(self, A: PETSc.Mat) -> None:
        """Give ``A``, created from ``cells``, the whole Jacobian's sparsity: the union of the parts'
        entries assembled at the current state (an empty assembly would drop them), the rest added
        as a matrix of its own (PETSc's MatAXPY, DIFFERENT_NONZERO_PATTERN: A's layout and local-
        to-global maps kept; the interface integrals of a body's diagonal block reach beyond its
        cells' pattern, which DOLFINx would drop silently). Then exact zeros are ignored (module
        docstring), and ``bulk`` becomes a matrix of A's sparsity."""
        assemble(A, self.cells, self.bcs)
        rest = assemble(fpetsc.create_matrix(self.others), self.others, self.bcs)
        try:
            A.axpy(1.0, rest, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        finally:
            rest.destroy()
        A.setOption(PETSc.Mat.Option.IGNORE_ZERO_ENTRIES, True)
        self.bulk = A.duplicate()

    def refresh(self) -> None:
        """The cell part assembled anew at the current state."""
        assemble(self.bulk, self.cells, self.bcs)
        self._state = self._values()

    def update(self) -> None:
        """``refresh`` if an input of the cell part changed since the last one (decided on all
        ranks together: the assembly is collective)."""
        values = self._values()
        changed = self._state is None or any(not np.array_equal(a, b) for a, b in zip(values, self._state))
        if self.bulk.getComm().tompi4py().allreduce(changed, op=MPI.LOR):
            self.refresh()

    def _values(self) -> list:
        return [np.array(c.value if isinstance(c, fem.Constant) else c.x.array) for c in self.inputs]

    def compose(self, A: PETSc.Mat) -> PETSc.Mat:
        """``A`` = the kept cell part + the other integrals at the current state."""
        self.bulk.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        fpetsc.assemble_matrix(A, self.others, bcs=self.bcs)
        A.assemble()
        return A

"""Direct factors of a sparse matrix without its zero entries (a PETSc python preconditioner).

DOLFINx's sparsity of the two-body block forms is that of the element matrices of every cell pair
an interface facet joins, whatever the state: the couplings of facets out of contact (zero
stiffness), of the vertices off the facet and, from the facets of the parent mesh whose cells lie
in one body only, a dense row and column at the first dof of each body (~5000 entries each, all
zero). MUMPS factorises the structure it is given: on the thesis ch. 7 mesh (39k dofs, 11 % of the
entries exact zeros) the LU of the matrix as assembled holds 34.5M entries, the LU of its nonzeros
26.2M (factorisation 1.42 → 0.81 s, a triangular solve 31 → 26 ms; one rank, 2026-11-24).

``CompactFactor`` factorises the matrix restricted to the union of the nonzero patterns it has
seen, so that the symbolic analysis is redone only when a new entry appears (a facet comes into
contact), and the same Mat is refactorised otherwise. The factors are those of the matrix itself:
the dropped entries are zero.

A MUMPS workspace error is retried with a larger margin (``macro.mumps.factorise``), and the
larger margin kept for later factorisations.

Factors in single precision (``precision="single"``: MUMPS' SMUMPS on the double matrix, PETSc's
``<prefix>pc_precision``) take half the memory and bandwidth of double ones, for a preconditioner
whose rounding a Krylov method on the double operator takes out (Higham & Mary 2022, Acta
Numerica 31, 347-414, §7: mixed-precision preconditioning; the residual and the answer stay in
double). A user's own ``<prefix>pc_precision`` option overrides ``precision``. Single factors
need a PETSc whose MUMPS interface runs in mixed precision (3.25 built so, as the dolfinx-solver
wheel's is); elsewhere PETSc raises at the analysis ("MUMPS does not support single precision"),
and ``PETSC_OPTIONS="-mech_factor_pc_precision double"`` (the Newton's prefix) runs double
factors. That error cannot be caught and recovered from in-process: destroying the PC whose MUMPS
analysis failed so segfaults (PETSc 3.25, checked with an unsupported "half").
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.errors import InputError
from multiscale.macro import mumps


class CompactFactor:
    """Python context of a PETSc PC (``pc.setType("python"); pc.setPythonContext(...)``): the
    ``factor`` ("lu" or "cholesky", symmetric matrices) by ``solver`` of the preconditioner matrix
    with its zero entries dropped (the diagonal kept). ``prefix``: options prefix of the inner PC
    (e.g. MUMPS controls ``<prefix>mat_mumps_icntl_14``). ``analyses`` counts the symbolic
    analyses (pattern changes and workspace retries), ``entries`` the factorised matrix's nonzeros
    (this rank's rows), ``inner`` the PC that holds the factors (``macro.mumps.describe`` names its
    failure), ``workspace`` the ICNTL(14) margin [%] the retries raised (None: MUMPS' default).
    ``precision``: "double" or "single" factors (module docstring), changed by ``set_precision``."""

    PRECISIONS = ("double", "single")

    def __init__(self, factor: str = "lu", solver: str = "mumps", prefix: str = "", precision: str = "double"):
        self.factor, self.solver, self.prefix = factor, solver, prefix
        options = PETSc.Options(prefix)
        self.user_precision = options.getString("pc_precision") if options.hasName("pc_precision") else None
        self.precision = self.user_precision or "double"
        self.inner: PETSc.PC | None = None
        self.matrix: PETSc.Mat | None = None
        self.keys: np.ndarray | None = None       # row * columns + column of the kept entries (sorted)
        self.analyses = 0
        self.workspace: int | None = None
        self._csr: tuple = ()                     # (row pointers, columns) of the kept pattern, this rank's rows
        self.set_precision(precision)

    @property
    def entries(self) -> int:
        return 0 if self.keys is None else len(self.keys)

    @property
    def options(self) -> dict:
        """The inner PC's kind as PETSc options under ``prefix`` (a user's of the same names win)."""
        return {"pc_type": self.factor, "pc_factor_mat_solver_type": self.solver}

    def setUp(self, pc) -> None:
        _, P = pc.getOperators()
        comm = P.getComm().tompi4py()
        start, _ = P.getOwnershipRange()
        columns = P.getSize()[1]
        indptr, cols, values = P.getValuesCSR()
        rows = np.repeat(np.arange(start, start + len(indptr) - 1, dtype=np.int64), np.diff(indptr))
        keep = (values != 0) | (cols == rows)
        keys = rows[keep] * columns + cols[keep]
        known = np.zeros(0, dtype=np.int64) if self.keys is None else self.keys
        new = keys[~np.isin(keys, known, assume_unique=True)]
        if comm.allreduce(len(new) > 0, op=MPI.LOR):
            # two sorted runs: the stable sort merges them in linear time (np.union1d: 0.8 s)
            self.keys = np.sort(np.concatenate([known, new]), kind="stable")
            self._build(P)
        elif self.inner is None:                  # the same on every rank: after ``set_precision``
            self._build(P)
        full = np.zeros(len(self.keys))
        full[np.searchsorted(self.keys, keys)] = values[keep]
        self.matrix.setValuesCSR(*self._csr, full)
        self.matrix.assemble()
        with mumps.precision(self.prefix, self.precision):
            self.workspace, retries = mumps.factorise(self.inner, self.workspace)
        self.analyses += retries
        pc.setFailedReason(self.inner.getFailedReason())

    def _build(self, P: PETSc.Mat) -> None:
        """A new matrix of the kept pattern and a new inner PC on it (a new symbolic analysis)."""
        self.reset(None, keep_pattern=True)
        rows, cols = np.divmod(self.keys, P.getSize()[1])
        counts = np.bincount(rows - P.getOwnershipRange()[0], minlength=P.getLocalSize()[0])
        self._csr = (np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType), cols.astype(PETSc.IntType))
        M = PETSc.Mat().createAIJ(P.getSizes(), csr=(*self._csr, np.zeros(len(cols))), comm=P.getComm())
        if self.factor == "cholesky":
            M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            M.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
        inner = PETSc.PC().create(P.getComm())
        inner.setOptionsPrefix(self.prefix)
        inner.setType(self.factor)
        inner.setFactorSolverType(self.solver)
        inner.setOperators(M, M)
        inner.setFromOptions()
        self.matrix, self.inner = M, inner
        self.analyses += 1

    def set_precision(self, precision: str) -> None:
        """Factors in ``precision`` from the next set-up on (a change drops the current ones: a new
        analysis); ignored when the user's option fixes it. Collective in effect: call it on every
        rank alike."""
        if precision not in self.PRECISIONS:
            raise InputError("precision", precision, f"one of {', '.join(self.PRECISIONS)}")
        if self.user_precision is None and precision != self.precision:
            self.precision = precision
            self.reset(None, keep_pattern=True)

    def apply(self, pc, x, y) -> None:
        if self.inner is None:                    # ``set_precision`` dropped the factors of an unchanged matrix
            self.setUp(pc)
        self.inner.apply(x, y)

    def reset(self, pc, keep_pattern: bool = False) -> None:
        """Free the factors and the matrix (``PC.reset``); the next set-up analyses afresh."""
        for obj in (self.inner, self.matrix):
            if obj is not None:
                obj.destroy()
        self.inner = self.matrix = None
        if not keep_pattern:
            self.keys = None

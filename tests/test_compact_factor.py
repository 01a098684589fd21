"""Direct factors without the zero entries (``macro.compact_factor``, issue 23) against a dense
solve: structural zeros dropped, the pattern kept while it holds, grown when an entry appears, the
symmetric factorisation, and a singular matrix reported as a failed preconditioner."""
import numpy as np

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites before petsc4py)
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.macro import mumps
from multiscale.macro.compact_factor import CompactFactor
from test_mumps import indefinite, petsc

COMM = MPI.COMM_WORLD


def laplacian(n: int = 12) -> np.ndarray:
    """The 5-point Laplacian of an n x n grid (SPD), n^2 unknowns."""
    T = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    return np.kron(T, np.eye(n)) + np.kron(np.eye(n), T)


def with_zeros(A: np.ndarray, structure: np.ndarray) -> PETSc.Mat:
    """AIJ matrix of the values ``A`` whose stored pattern is ``structure`` (a superset of A's
    nonzeros: the extra entries are stored zeros, as in DOLFINx's two-body sparsity)."""
    n = A.shape[0]
    M = PETSc.Mat().createAIJ([n, n], comm=COMM)
    lo, hi = M.getOwnershipRanges()[COMM.rank], M.getOwnershipRanges()[COMM.rank + 1]
    rows = [np.flatnonzero(structure[i]) for i in range(lo, hi)]
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in rows])]).astype(PETSc.IntType)
    cols = np.concatenate(rows).astype(PETSc.IntType)
    values = np.concatenate([A[i, r] for i, r in zip(range(lo, hi), rows)])
    M.setPreallocationCSR((indptr, cols, values))
    M.assemble()
    return M


def set_values(M: PETSc.Mat, A: np.ndarray) -> None:
    """Overwrite the stored entries of ``M`` by those of ``A`` (same pattern)."""
    indptr, cols, _ = M.getValuesCSR()
    lo = M.getOwnershipRange()[0]
    rows = np.repeat(np.arange(lo, lo + len(indptr) - 1), np.diff(indptr))
    M.setValuesCSR(indptr, cols, A[rows, cols])
    M.assemble()


def solver(M: PETSc.Mat, factor: str = "lu") -> tuple:
    ksp = PETSc.KSP().create(COMM)
    ksp.setType("preonly")
    ksp.setOperators(M)
    context = CompactFactor(factor)
    ksp.getPC().setType("python")
    ksp.getPC().setPythonContext(context)
    return ksp, context


def error(ksp, A: np.ndarray) -> float:
    """Relative error of the KSP's x for A x = b, b = 1, 2, ..., n, against the dense solve (the
    KSP must converge)."""
    n = A.shape[0]
    b_all = np.arange(1.0, n + 1)
    M = ksp.getOperators()[0]
    b = M.createVecLeft()
    lo, hi = b.getOwnershipRange()
    b.setArray(b_all[lo:hi])
    x = b.duplicate()
    ksp.solve(b, x)
    assert ksp.getConvergedReason() > 0
    got = np.concatenate(COMM.allgather(x.getArray().copy()))
    expected = np.linalg.solve(A, b_all)
    return np.linalg.norm(got - expected) / np.linalg.norm(expected)


def solve(ksp, A: np.ndarray) -> None:
    """The KSP solves A x = b to round-off (1e-12)."""
    assert error(ksp, A) <= 1e-12


def test_zero_entries_dropped_and_the_pattern_kept_or_grown():
    A = laplacian()
    n = A.shape[0]
    structure = (A != 0) | (np.abs(np.subtract.outer(np.arange(n), np.arange(n))) <= 14)   # a wide band
    structure[0, :] = structure[:, 0] = True           # a dense row and column of zeros (DOLFINx's first dof)
    M = with_zeros(A, structure)
    ksp, context = solver(M)
    solve(ksp, A)
    assert context.analyses == 1
    kept = COMM.allreduce(context.entries)
    assert kept == np.count_nonzero(A) < np.count_nonzero(structure)

    set_values(M, 2 * A)                               # same nonzeros: refactorised, not re-analysed
    solve(ksp, 2 * A)
    assert context.analyses == 1

    B = A.copy()
    B[3, 17] = B[17, 3] = -0.5                         # an entry appears (a facet comes into contact)
    set_values(M, B)
    solve(ksp, B)
    assert context.analyses == 2 and COMM.allreduce(context.entries) == kept + 2

    set_values(M, A)                                   # it goes again: the grown pattern holds (a stored zero)
    solve(ksp, A)
    assert context.analyses == 2 and COMM.allreduce(context.entries) == kept + 2

    ksp.getPC().reset()                                # frees the factors: analysed afresh at the next set-up
    assert context.entries == 0
    ksp.setOperators(M)                                # (PCReset drops the operators; SNES sets them each solve)
    solve(ksp, A)
    assert context.analyses == 3 and COMM.allreduce(context.entries) == kept


def test_symmetric_factorisation():
    A = laplacian() + np.eye(144)
    M = with_zeros(A, (A != 0) | np.eye(144, k=30, dtype=bool) | np.eye(144, k=-30, dtype=bool))
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    ksp, context = solver(M, "cholesky")
    solve(ksp, A)
    assert context.analyses == 1


def test_singular_matrix_is_a_failed_preconditioner():
    A = laplacian()
    A[5, :] = A[:, 5] = 0.0                            # a zero row and column: no pivot
    structure = laplacian() != 0
    ksp, _ = solver(with_zeros(A, structure))
    b = ksp.getOperators()[0].createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    ksp.solve(b, x)
    assert ksp.getConvergedReason() == PETSc.KSP.ConvergedReason.DIVERGED_PCSETUP_FAILED


def test_mumps_workspace_too_small_is_retried_with_more():
    """The symmetric indefinite matrix of tests/test_mumps.py, whose delayed pivots overflow MUMPS'
    workspace with its default margin (ICNTL(14) = 20: INFOG(1) = -9, measured), is factorised on a
    retry with a larger one; the LDL^T then solves it to round-off."""
    M = petsc(indefinite())
    ksp, context = solver(M, "cholesky")
    b = M.createVecLeft()
    b.set(1.0)
    x = b.duplicate()
    ksp.solve(b, x)
    assert ksp.getConvergedReason() > 0 and mumps.status(context.inner) == 0
    assert context.workspace == 40 and context.analyses == 2                # one retry, twice the margin
    r = b.duplicate()
    M.mult(x, r)
    r.axpy(-1.0, b)
    assert r.norm() <= 1e-8 * b.norm()


def test_single_precision_factors_precondition_gmres_to_double_accuracy(petsc_options):
    """Single-precision factors (MUMPS' SMUMPS on the double matrix): applied alone they solve to
    float32 round-off times the condition (relative error between 1e-9 and 1e-4; double factors:
    1e-12), under flexible GMRES on the double operator to 1e-11 within 4 iterations (right-
    preconditioned GMRES stops at 1e-7: its answer applies the preconditioner once more, and that
    rounds differently). ``set_precision`` goes back to double factors (a new analysis); a user's
    ``<prefix>pc_precision`` wins."""
    A = laplacian(20) + 0.01 * np.eye(400)
    M = with_zeros(A, A != 0)
    ksp, context = solver(M)
    context.set_precision("single")
    assert 1e-9 < error(ksp, A) < 1e-4
    ksp.setType("fgmres")
    ksp.setTolerances(rtol=1e-13, atol=0.0)
    assert error(ksp, A) < 1e-11 and ksp.getIterationNumber() <= 4
    assert context.analyses == 1
    context.set_precision("double")
    ksp.setType("preonly")
    assert error(ksp, A) < 1e-12 and context.analyses == 2
    petsc_options(fixed_pc_precision="double")
    fixed = CompactFactor(prefix="fixed_", precision="single")
    fixed.set_precision("single")
    assert fixed.precision == "double"

"""MUMPS factorisations that survive a too-small workspace (``macro.mumps``) and name the failures
they cannot survive: a symmetric indefinite matrix whose delayed pivots overflow MUMPS' default
workspace, factorised on a retry with a larger one (checked by the residual of a solve), through a
plain PC, the block Lanczos factors and SLEPc's shift-and-invert; a singular matrix named by its
INFOG(1). The 2-rank LU of the same matrix: tests/mpi/test_factor_mpi.py."""
import math

import numpy as np
import pytest
import scipy.sparse as sp

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites before petsc4py)
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.errors import ConvergenceError
from multiscale.macro import eigen, mumps
from multiscale.macro.block_lanczos import ShiftInvert

COMM = MPI.COMM_WORLD


def indefinite(n: int = 2000, shift: float = 0.0) -> sp.csr_matrix:
    """Random symmetric couplings (4 per row), a diagonal of 1e-6 (random signs) + ``shift``: its
    LDL^T on one rank and its LU on two overflow MUMPS' workspace at the default ICNTL(14) = 20
    (INFOG(1) = -9, measured)."""
    R = sp.random(n, n, density=4 / n, random_state=3)
    A = (R + R.T).tocsr()
    A.setdiag(1e-6 * np.random.default_rng(3).standard_normal(n) + shift)
    A.sort_indices()
    return A


def petsc(A: sp.csr_matrix, comm=COMM) -> PETSc.Mat:
    """The rows of A each rank owns (PETSc's default split) as an AIJ matrix."""
    n = A.shape[0]
    M = PETSc.Mat().createAIJ([n, n], comm=comm)
    lo, hi = M.getOwnershipRanges()[comm.rank], M.getOwnershipRanges()[comm.rank + 1]
    rows = A[lo:hi]
    M.setPreallocationCSR((rows.indptr.astype(PETSc.IntType), rows.indices.astype(PETSc.IntType), rows.data))
    M.assemble()
    M.setOption(PETSc.Mat.Option.SYMMETRIC, True)
    return M


def residual(A: PETSc.Mat, pc: PETSc.PC) -> float:
    """||A x - b|| / ||b|| for x = pc(b), b = 1."""
    b = A.createVecLeft()
    b.set(1.0)
    x, r = b.duplicate(), b.duplicate()
    pc.apply(b, x)
    A.mult(x, r)
    r.axpy(-1.0, b)
    return r.norm() / b.norm()


def direct(A: PETSc.Mat, factor: str) -> PETSc.PC:
    pc = PETSc.PC().create(A.getComm())
    pc.setType(factor)
    pc.setFactorSolverType("mumps")
    pc.setOperators(A, A)
    return pc


def test_workspace_error_is_retried_with_a_doubled_margin():
    A = petsc(indefinite())
    pc = direct(A, "cholesky")
    workspace, retries = mumps.factorise(pc)
    assert (workspace, retries) == (40, 1) and mumps.status(pc) == 0 and mumps.describe(pc) == ""
    assert residual(A, pc) <= 1e-8
    assert mumps.factorise(pc, workspace) == (40, 0)          # a refactorisation keeps the margin


def test_singular_matrix_is_named_by_mumps_status():
    A = indefinite(200).tolil()
    A[5, :] = 0.0
    A[:, 5] = 0.0
    pc = direct(petsc(A.tocsr()), "lu")
    assert mumps.factorise(pc) == (None, 0)                   # not a workspace error: no retry
    assert "INFOG(1) = -10 (numerically singular)" in mumps.describe(pc)


def test_a_direct_solver_of_a_singular_matrix_is_a_convergence_error():
    """``mumps.direct_solver`` (the centrifugal preload's and the unloaded state's LU) names the
    failure: a KSP on the singular matrix solved to inf without a word (a review, 2026-12-06); the
    indefinite one, after its workspace retry, solves to 1e-8."""
    A = indefinite(200).tolil()
    A[5, :] = 0.0
    A[:, 5] = 0.0
    with pytest.raises(ConvergenceError, match=r"the test matrix could not be factorised \[.*numerically singular"):
        mumps.direct_solver(petsc(A.tocsr()), "the test matrix")
    A = petsc(indefinite())
    ksp = mumps.direct_solver(A, "the indefinite matrix")
    assert residual(A, ksp.getPC()) <= 1e-8
    ksp.destroy()


def test_block_lanczos_factors_survive_a_workspace_error():
    """ShiftInvert's LDL^T of K - theta M with M = I, theta = 2: the matrix above (it raised
    InputError before the retries)."""
    K, M = petsc(indefinite(shift=2.0)), petsc(sp.identity(2000, format="csr"))
    factors = ShiftInvert(K, M, shift=2.0)
    try:
        X = np.random.default_rng(1).standard_normal((factors.A.getLocalSize()[0], 3))
        np.testing.assert_allclose(multiscale.macro.dense.mat_mult(factors.A, factors.solve(X)), X,
                                   atol=1e-8 * np.abs(X).max())
    finally:
        factors.destroy()


def nearest_eigenvalues_against_dense() -> None:
    """The three eigenvalues of (A + 2 I, I) nearest the shift 2 by SLEPc's shift-and-invert against
    a dense solve; SLEPc's LU of A overflows MUMPS' workspace on two ranks (there it raised an
    InputError before the retries, measured), on one it need not."""
    A = indefinite(shift=2.0)
    result = eigen.solve_modes(petsc(A), petsc(sp.identity(2000, format="csr")), target=math.sqrt(2.0) / (2 * math.pi),
                               f_max=math.sqrt(2.05) / (2 * math.pi), n_modes=3, nev=3)
    dense = np.linalg.eigvalsh(A.toarray())
    nearest = np.sort(dense[np.argsort(abs(dense - 2.0))[:3]])
    np.testing.assert_allclose(np.sort(result.theta.real), nearest, rtol=1e-9)


def test_slepc_shift_invert_on_the_indefinite_matrix():
    nearest_eigenvalues_against_dense()


def test_factors_that_do_not_fit_in_memory_are_a_memory_error():
    """A squeal run under ``ulimit -v`` whose shift-and-invert factors ran out of memory (MUMPS
    INFOG(1) = -13) was told to choose another target. Factors over their cap (ICNTL(23) = 1 MB a
    rank, INFOG(1) = -19) are a ``MemoryError`` naming MUMPS' status and the cap, through SLEPc's
    shift-and-invert and the block Lanczos factors alike."""
    import pytest
    K, M = petsc(indefinite(shift=2.0)), petsc(sp.identity(2000, format="csr"))
    options = PETSc.Options()
    for prefix in ("capped_st_", "capped_"):
        options[f"{prefix}mat_mumps_icntl_23"] = 1
    try:
        with pytest.raises(MemoryError, match=r"the factors of the shifted operator did not fit \[.*INFOG\(1\) = "
                                              r"-19 .*\]; or raise the cap mat_mumps_icntl_23"):
            eigen.solve_modes(K, M, target=math.sqrt(2.0) / (2 * math.pi), f_max=math.sqrt(2.05) / (2 * math.pi),
                              n_modes=3, nev=3, options_prefix="capped_")
        with pytest.raises(MemoryError, match=r"INFOG\(1\) = -19"):
            ShiftInvert(K, M, shift=2.0, prefix="capped_")
    finally:
        for prefix in ("capped_st_", "capped_"):
            options.delValue(f"{prefix}mat_mumps_icntl_23")

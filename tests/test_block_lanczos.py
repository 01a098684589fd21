"""Shifted block Lanczos for the symmetric pencil (``macro.block_lanczos``, issue 20) against the
closed-form spring chain, with repeated eigenvalues, an interior shift and bad input; and the
dense-block products it is built on (``macro.dense``) against one vector at a time."""
import numpy as np
import pytest

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites before petsc4py)
from mpi4py import MPI
from petsc4py import PETSc

from multiscale.errors import ConvergenceError, InputError
from multiscale.macro import dense
from multiscale.macro.block_lanczos import ShiftInvert, symmetric_modes
from multiscale.references.stability import spring_chain, spring_chain_frequencies

COMM = MPI.COMM_WORLD


def aij(A: np.ndarray, comm=COMM) -> PETSc.Mat:
    """A dense array as a PETSc AIJ matrix over ``comm`` (each rank sets its owned rows)."""
    n = A.shape[0]
    m = PETSc.Mat().createAIJ([n, n], nnz=3 * max(1, int((A != 0).sum(axis=1).max())), comm=comm)
    m.setUp()
    lo, hi = m.getOwnershipRange()
    for i in range(lo, hi):
        cols = np.nonzero(A[i])[0].astype(PETSc.IntType)
        m.setValues(i, cols, A[i, cols])
    m.assemble()
    return m


def chain_pair(n=150, k=4e6, m=0.01, copies=1):
    """``copies`` uncoupled identical chains (each eigenvalue ``copies``-fold) as PETSc (K, M)."""
    K, M = spring_chain(n, k, m)
    K, M = np.kron(np.eye(copies), K), np.kron(np.eye(copies), M)
    return aij(K), aij(M), K, M


def test_band_of_the_chain_against_the_closed_form():
    K, M, Kd, Md = chain_pair()
    f = spring_chain_frequencies(150)
    f_max = 0.4 * f.max()                                   # 39 modes
    r = symmetric_modes(K, M, f_max=f_max, block=8)
    inband = f[f <= f_max]
    assert len(r) == inband.size == 39
    np.testing.assert_allclose(r.frequency, inband, rtol=1e-10)       # measured 2e-14
    assert r.errors.max() <= 1e-8 and r.growth.max() == 0.0          # measured 2e-10
    lo, hi = K.getOwnershipRange()
    X = np.zeros((Kd.shape[0], len(r)))
    X[lo:hi] = r.modes
    X = COMM.allreduce(X)
    np.testing.assert_allclose(X.T @ Md @ X, np.eye(len(r)), atol=1e-10)   # M-orthonormal
    assert np.abs(X[[0, -1]]).max() < 1e-12                             # constrained dofs


def test_double_eigenvalues_and_a_cap_with_an_interior_target():
    """Two identical chains: every frequency twice; the 20 band modes nearest a target inside the
    spectrum (K - theta_t M indefinite, LDL^T) are the 10 double frequencies nearest in theta = omega^2."""
    K, M, _, _ = chain_pair(n=60, copies=2)
    f = spring_chain_frequencies(60)
    target = 0.5 * f.max()
    r = symmetric_modes(K, M, f_max=f.max(), target=target, n_modes=20, block=6)
    near = np.sort(np.repeat(f[np.argsort(np.abs(f**2 - target**2))[:10]], 2))
    np.testing.assert_allclose(r.frequency, near, rtol=1e-10)


def test_dense_blocks_equal_one_vector_at_a_time():
    K, M, Kd, _ = chain_pair(n=40)
    rng = np.random.default_rng(COMM.rank)
    X = rng.standard_normal((K.getLocalSize()[0], 5))
    x, y = K.createVecs()
    loop = np.empty_like(X)
    for j in range(X.shape[1]):
        x.setArray(X[:, j].copy())
        K.mult(x, y)
        loop[:, j] = y.getArray()
    np.testing.assert_allclose(dense.mat_mult(K, X), loop, rtol=1e-14, atol=1e-14 * np.abs(loop).max())
    factors = ShiftInvert(K, M)
    try:
        np.testing.assert_allclose(dense.mat_mult(K, factors.solve(X)), X, atol=1e-9 * np.abs(X).max())
    finally:
        factors.destroy()


def test_bad_input_fails_loudly():
    K, M, Kd, Md = chain_pair(n=30)
    Kfree = aij(Kd - np.diag(np.diag(Kd)) + np.diag(Kd.sum(axis=1)))   # free-free: singular at 0 Hz
    with pytest.raises(InputError, match="factorised"):
        symmetric_modes(Kfree, M, f_max=1e3)
    with pytest.raises(InputError, match="f_max"):
        symmetric_modes(K, M, f_max=1.0)                        # below the first mode
    with pytest.raises(InputError, match="block"):
        symmetric_modes(K, M, f_max=1e4, block=0)
    with pytest.raises(ConvergenceError, match="did not converge"):
        symmetric_modes(K, M, f_max=spring_chain_frequencies(30).max(), n_modes=20, block=2, max_dim=6)

"""Blocks of vectors as numpy columns of rank-owned entries, applied through PETSc dense matrices.

A sparse matrix times b columns (``mat_mult``) reads the matrix once per block instead of once
per vector, and MUMPS solves b right-hand sides at once with level-3 BLAS (``block_solve``); on
the 106k-dof brake, 32 columns at once took 0.27x (products) and 0.21x (LDL^T solves) the time of
one at a time (docs/squeal.md).
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc


def to_dense(X: np.ndarray, A: PETSc.Mat) -> PETSc.Mat:
    """A dense PETSc matrix holding the columns ``X`` (real, owned rows of A's column layout)."""
    n_local, n = A.getLocalSize()[1], A.getSize()[1]
    if X.shape[0] != n_local:
        raise ValueError(f"{X.shape[0]} rows, the matrix owns {n_local} columns here")
    D = PETSc.Mat().createDense(((n_local, n), (PETSc.DECIDE, X.shape[1])), comm=A.getComm())
    D.setUp()
    D.getDenseArray()[:] = X
    D.assemble()
    return D


def from_dense(D: PETSc.Mat) -> np.ndarray:
    """The owned rows of a dense PETSc matrix as a numpy array (a copy), and D destroyed."""
    X = D.getDenseArray().copy()
    D.destroy()
    return X


def mat_mult(A: PETSc.Mat, X: np.ndarray, transpose: bool = False) -> np.ndarray:
    """A @ X (A^T @ X with ``transpose``: A square) for real columns X (MatMatMult,
    MatTransposeMatMult with a dense block)."""
    if X.shape[1] == 0:
        return np.empty((A.getLocalSize()[0], 0))
    B = to_dense(X, A)
    try:
        return from_dense(A.transposeMatMult(B) if transpose else A.matMult(B))
    finally:
        B.destroy()


def block_solve(ksp: PETSc.KSP, X: np.ndarray, transpose: bool = False) -> np.ndarray:
    """The solutions of ``ksp``'s operator (its transpose with ``transpose``) for the real
    right-hand sides X (KSPMatSolve, KSPMatSolveTranspose)."""
    if X.shape[1] == 0:
        return np.empty_like(X)
    A = ksp.getOperators()[0]
    B, Y = to_dense(X, A), to_dense(np.zeros_like(X), A)
    try:
        (ksp.matSolveTranspose if transpose else ksp.matSolve)(B, Y)
        return Y.getDenseArray().copy()
    finally:
        B.destroy(), Y.destroy()

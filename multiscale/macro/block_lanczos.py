"""Real modes of a symmetric pencil by the shifted block Lanczos method (issue 20).

    K phi = theta M phi,     K symmetric, M symmetric positive semi-definite,

here the frictionless tangent K_0 and the mass, whose modes span the ``"subspace"`` projection
(``macro.damped``). Shift-and-invert about theta_t = (2 pi target)^2: the Krylov space of
S = (K - theta_t M)^-1 M grows by a block of ``block`` vectors at a time from a random block, each
block M-orthonormal to all earlier ones (block classical Gram-Schmidt, twice: full
reorthogonalisation), and the Rayleigh-Ritz pairs of (K, M) on that space converge first near
theta_t. This is the shifted block Lanczos method of the commercial structural codes (Grimes, Lewis
& Simon, SIAM J. Matrix Anal. Appl. 15 (1994) 228), without restarts or shift changes: one
MUMPS LDL^T of K - theta_t M. What the block buys over a one-vector Krylov-Schur (SLEPc): every
solve with the factors and every product with K or M runs on ``block`` columns at once
(``macro.dense``: the factors and the matrices are read once per block).

The Ritz pairs are those of S on the Krylov space (the block tridiagonal T = Q^T M S Q, from the
orthogonalisation's own projections); a pair (nu, phi), theta = theta_t + 1/nu, is converged when
the Lanczos residual ||S phi - nu phi||_M = ||R y|| (R the last block's remainder) is at most
``tol`` |nu| (ARPACK's criterion), and the pairs are taken in order of |nu| (nearest theta_t
first) without a gap through the first one beyond the band, or the ``n_modes``-th in it, as SLEPc's
shift-and-invert Krylov-Schur in ``eigen.solve_modes``. A random start misses a mode only if it has
no part of it (probability zero); the block, wider than a multiplicity, finds repeated modes.
"""
from __future__ import annotations

import math
import time

import numpy as np
from petsc4py import PETSc

from multiscale.errors import ConvergenceError, InputError
from multiscale.macro import mumps
from multiscale.macro.dense import block_solve, mat_mult
from multiscale.macro.eigen import TWO_PI, ModalResult, check_band, lambda_from_theta, matrix_comm, reduce_sum


class ShiftInvert:
    """MUMPS LDL^T factors of K - theta_t M (K symmetric; LU with ``symmetric=False``) that solve
    blocks of right-hand sides (a too-small workspace retried, ``macro.mumps``); raises InputError
    if K - theta_t M cannot be factorised (singular). ``destroy`` frees them."""

    def __init__(self, K: PETSc.Mat, M: PETSc.Mat, shift: float = 0.0, prefix: str = "modes_",
                 symmetric: bool = True):
        self.shift = float(shift)
        self.A = K
        if self.shift:
            self.A = K.duplicate(copy=True)
            self.A.axpy(-self.shift, M, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        if symmetric:
            self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        self.ksp = PETSc.KSP().create(K.getComm())
        self.ksp.setOperators(self.A)
        self.ksp.setType(PETSc.KSP.Type.PREONLY)
        pc = self.ksp.getPC()
        pc.setType(PETSc.PC.Type.CHOLESKY if symmetric else PETSc.PC.Type.LU)
        if PETSc.Sys.hasExternalPackage("mumps"):
            pc.setFactorSolverType("mumps")
        self.ksp.setOptionsPrefix(prefix)
        self.ksp.setFromOptions()
        try:
            self.ksp.setUp()                              # the operators reach the PC
            mumps.factorise(pc)
            failed = mumps.describe(pc)                   # MUMPS' status: the same on every rank
        except PETSc.Error as exc:
            failed = str(exc).strip()
        if failed:
            try:
                mumps.check_memory(pc, "the shifted operator")
            finally:
                self.destroy()
            raise InputError("target", math.sqrt(max(self.shift, 0.0)) / TWO_PI,
                             f"K - (2 pi target)^2 M could not be factorised (singular at this shift? a free "
                             f"body needs a target > 0 away from an eigenvalue) [{failed}]")

    def solve(self, X: np.ndarray, transpose: bool = False) -> np.ndarray:
        """(K - theta_t M)^-1 X (with ``transpose`` (K^T - theta_t M)^-1 X) for real columns X of
        owned entries."""
        return block_solve(self.ksp, X, transpose)

    def destroy(self) -> None:
        self.ksp.destroy()
        if self.A is not None and self.shift:
            self.A.destroy()
        self.A = None


def m_orthonormalise(Z: np.ndarray, Q: list, MQ: list, M: PETSc.Mat, comm, drop: float = 1e-10, H=None):
    """(Z, M Z): the columns Z made M-orthogonal to the blocks Q (with their products MQ) and
    M-orthonormal among themselves, twice over; columns dependent to ``drop`` are dropped. ``H``:
    MQ^T Z if the caller has it (the first pass then uses it)."""
    for _ in range(2):
        if Q:
            H = reduce_sum(np.vstack([mq.T @ Z for mq in MQ]), comm) if H is None else H
            Z = Z - combine(Q, H)
            H = None
        MZ = mat_mult(M, Z)
        w, U = np.linalg.eigh(reduce_sum(Z.T @ MZ, comm))
        keep = w > drop * max(w.max(initial=0.0), np.finfo(float).tiny)
        T = U[:, keep] / np.sqrt(w[keep])
        Z, MZ = Z @ T, MZ @ T
    return Z, MZ


def symmetric_modes(K: PETSc.Mat, M: PETSc.Mat, *, f_max: float, f_min: float = 0.0, n_modes: int | None = None,
                    target: float | None = None, tol: float = 1e-8, block: int = 16, max_dim: int | None = None,
                    seed: int = 0, solver: ShiftInvert | None = None) -> ModalResult:
    """Real modes with f_min <= f <= f_max [Hz] of K phi = theta M phi, K symmetric (module
    docstring), or the ``n_modes`` band modes nearest ``target`` [Hz] (default f_min): modes
    M-orthonormal, sorted by frequency, theta their Rayleigh quotients, ``errors`` the relative
    residuals ||K phi - theta M phi|| / (||K phi|| + |theta| ||M phi||). ``solver``: the factors
    of K - (2 pi target)^2 M to use (the caller keeps and frees them), else made and freed here.
    ``max_dim`` bounds the subspace (default 8 ``n_modes`` + 2 blocks, unbounded without
    ``n_modes``); ConvergenceError beyond it."""
    f_min, f_max, target = check_band(f_min, f_max, target, n_modes)
    block = int(block)
    if block < 1:
        raise InputError("block", block, "must be a positive number of vectors")
    t0 = time.perf_counter()
    comm = matrix_comm(K)
    n = K.getSize()[0]
    shift = (TWO_PI * target) ** 2
    band = ((TWO_PI * f_min) ** 2, (TWO_PI * f_max) ** 2)
    radius = max(band[1] - shift, shift - band[0])
    cap = max_dim or (8 * n_modes + 2 * block if n_modes else n)
    op = solver if solver is not None else ShiftInvert(K, M, shift)
    if not math.isclose(op.shift, shift):
        raise ValueError(f"the factors are shifted by {op.shift}, the target asks for {shift}")
    rng = np.random.default_rng([seed, 0 if comm is None else comm.rank])
    try:
        start = op.solve(mat_mult(M, rng.uniform(-1.0, 1.0, (K.getLocalSize()[0], min(block, n)))))
        Q, MQ = map(list, zip(m_orthonormalise(start, [], [], M, comm)))
        T = np.empty((0, 0))
        while True:
            SZ = op.solve(MQ[-1])                    # S Q_j; T's column block j is Q^T M S Q_j
            H = reduce_sum(np.vstack([mq.T @ SZ for mq in MQ]), comm)
            m, b = T.shape[0] + H.shape[1], H.shape[1]
            T = np.pad(T, ((0, b), (0, b)))
            T[:, m - b:] = H
            T[m - b:, :] = H.T
            T[m - b:, m - b:] = 0.5 * (H[m - b:] + H[m - b:].T)
            Z, MZ = m_orthonormalise(SZ, Q, MQ, M, comm, H=H)
            R = reduce_sum(MZ.T @ SZ, comm)          # S Q_j = Q H + Z R: the Lanczos residual
            nu, Y = np.linalg.eigh(T)
            final = Z.shape[1] == 0 or m >= n         # an invariant subspace: the Ritz pairs are exact
            pick = wanted(nu, np.linalg.norm(R @ Y[m - b:], axis=0), shift, radius, band, n_modes, tol, final)
            if pick is not None:
                break
            if m >= cap:
                raise ConvergenceError(f"block Lanczos: the Ritz pairs did not converge in a subspace of "
                                       f"{m} vectors (tol {tol:g})", history=[len(Q)])
            Q.append(Z), MQ.append(MZ)
    finally:
        if solver is None:
            op.destroy()
    phi, Mphi = combine(Q, Y[:, pick]), combine(MQ, Y[:, pick])
    Kphi = mat_mult(K, phi)
    theta = reduce_sum(np.einsum("ij,ij->j", phi, Kphi), comm)      # Rayleigh quotients (phi' M phi = 1)
    norms = [np.sqrt(reduce_sum(np.einsum("ij,ij->j", X, X), comm)) for X in (Kphi - Mphi * theta, Kphi, Mphi)]
    errors = norms[0] / np.maximum(norms[1] + np.abs(theta) * norms[2], np.finfo(float).tiny)
    order = np.argsort(theta, kind="stable")
    return ModalResult(lambda_from_theta(theta[order]), theta[order].astype(complex), phi[:, order], errors[order],
                       (f_min, f_max), target, n, "ghep", len(Q), 1, time.perf_counter() - t0, comm)


def wanted(nu, residual, shift, radius, band, n_modes, tol, final):
    """Indices of the Ritz values ``nu`` of S (theta = shift + 1/nu) to keep, or None while the
    pairs nearest the shift are not converged (||S phi - nu phi||_M <= tol |nu|) without a gap
    through the first one beyond ``radius`` or the ``n_modes``-th in the band [1/s^2]."""
    order = np.argsort(-np.abs(nu), kind="stable")
    with np.errstate(divide="ignore"):
        theta = shift + 1.0 / nu[order]
    inband = (theta >= band[0]) & (theta <= band[1])
    ok = residual[order] <= tol * np.abs(nu[order])
    if final:
        ok[:] = True
    need = np.nonzero(np.abs(theta - shift) > radius)[0]
    need = int(need[0]) + 1 if need.size else order.size
    if n_modes is not None and inband.sum() >= n_modes:
        need = min(need, int(np.nonzero(np.cumsum(inband) == n_modes)[0][0]) + 1)
    if not ok[:need].all() or (need == order.size and not final):
        return None
    keep = order[:need][inband[:need]]
    if keep.size == 0:
        f = np.sqrt(np.maximum(theta, 0.0)) / TWO_PI
        raise InputError("f_max", tuple(np.sqrt(band) / TWO_PI), f"no eigenvalue in this frequency band [Hz]; "
                         f"widen it (nearest: {f[np.argmin(np.abs(theta - shift))]:.6g} Hz)")
    return keep


def combine(blocks: list, Y: np.ndarray) -> np.ndarray:
    """[B_1 B_2 ...] @ Y without joining the blocks."""
    out, start = 0.0, 0
    for b in blocks:
        out = out + b @ Y[start:start + b.shape[1]]
        start += b.shape[1]
    return out

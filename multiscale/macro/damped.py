"""Damped, gyroscopic and hysteretic linearised systems (issue 20):

    M u'' + C u' + (K + i H) u = 0,      u = phi exp(lambda t),   lambda = sigma + i omega.

``LinearSystem`` holds K (tangent, with the optional geometric and centrifugal parts), M, the
viscous C (per-material Rayleigh, friction slope, gyroscopic), the hysteretic H (per-material
loss factors: complex stiffness, the structural damping of the i omega > 0 branch) and a part
proportional to the whole system, ``Damping(alpha, beta, eta)``: C += alpha M + beta K,
H += eta K. ``solve_system`` picks the method:

- no C, no H: the GNHEP K phi = theta M phi and the exact map theta -> lambda of the
  proportional part (``eigen.solve_modes``): the undamped result, bit for bit;
- ``"quadratic"`` (``"auto"`` with viscous damping only, in a band from 0 Hz): SLEPc PEP on
  (K, C + alpha M + beta K, M) over the whole model, exact; in real arithmetic it converges from
  the lowest frequency up, so that it cannot reach a band above 0 Hz or a target;
- ``"projection"`` (``"auto"`` with hysteretic terms, which the real PEP cannot take, or a band
  above 0 Hz or a target: the GNHEP of its basis shifts to them): the
  complex modes of the undamped, friction-coupled system (K, M) up to ``basis`` x f_max and,
  with friction (K not symmetric), those of (K^T, M), its left eigenvectors, span a real
  M-orthonormal basis V (``Subspace``); the reduced quadratic problem
  (lambda^2 V'MV + lambda V'CV + V'(K + iH)V) q = 0 is solved densely
  (companion form), phi = V q. This is the subspace projection of commercial complex-eigenvalue
  solvers (Abaqus projects on the undamped modes of the symmetrised stiffness; here the basis
  already holds the friction coupling). The left modes make the damping's first-order shift of
  each eigenvalue exact (the two-sided Rayleigh quotient): on the right modes alone, a bar of two
  prisms with loss factors 0.02 and friction 0.2 had the instability of every lock-in pair on
  the wrong member (264.5 Hz unstable where a dense solve has 267.8 Hz; an adversarial test); with
  them every eigenvalue is within 2e-6 of the dense solve, at the cost of a second modal solve
  (without a second factorisation: ``eigen.shift_invert_modes(transpose_of=...)``).
  With damping terms the basis also holds the static responses to their forces,
  (K - theta_t M)^-1 A phi of the right and (K^T - theta_t M)^-1 A^T psi of the left modes in the
  band, A = H and A = C (those of the modes above it, which only pad the basis, changed little),
  by the same LU of K - theta_t M (modal truncation augmentation, Dickens, Nakagawa & Wittbrodt,
  Comput. Struct. 62 (1997) 985): a loss factor of one part (the pad) loads the part's faces to
  its neighbours with eta K_b phi, the friction slope the interface with lambda C phi, which no
  mode of the band balances. On the 20-mm demo brake (pad loss factor 0.05, 10 modes) the
  relative residuals fell from 0.22 to 4e-3 and the eigenvalues' error against the full complex
  solve from 7.5e-5 to 4e-8 (a basis of 3 x f_max without them: 0.22 and 5e-5); with a steep
  Stribeck law (0.9 to 0.2 over 0.5 m/s, 20 modes) the growth rates' error against the PEP from
  0.14 to 3e-4 1/s, the frequencies' from 2.6e-5 to 7e-8 (docs/squeal.md). A response joins the
  basis with its part outside the modes' span, if that holds ``RESPONSE_KEEP`` of it (``Subspace``;
  the responses to C phi are of the order of C/K ~ 1e-6 s: against the modes' scale they had all
  been dropped as if dependent).
  Its accuracy is reported per mode: the relative residual of the full quadratic problem.
- ``"subspace"`` (any system that carries ``K0``; never picked by ``"auto"``): the same projection
  on a basis that needs no non-symmetric factorisation, for models whose LU does not fit in
  memory: the real modes of the frictionless, symmetric tangent (K0, M) up to ``basis`` x f_max
  (GHEP, shift-and-invert through a MUMPS LDL^T: about half the memory of the LU), as in Abaqus'
  complex frequency step (real modes first, the friction-coupled system projected on them), plus
  one static correction per mode, (K0 - theta_t M)^-1 (K - K0) phi (modal truncation augmentation,
  Dickens, Nakagawa & Wittbrodt, Comput. Struct. 62 (1997) 985), with the same factors: the
  friction coupling K - K0 is local to the interface, and the real modes alone miss it (on the
  49k-dof brake: relative residuals up to 0.66 without the corrections, 0.04 with them).

``ReducedSystem`` keeps the projected matrices, so that a sweep (``macro.stability_map``) solves
each point and every bisection step densely.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg
from petsc4py import PETSc

from multiscale.errors import InputError
from multiscale.macro.block_lanczos import ShiftInvert, m_orthonormalise, symmetric_modes
from multiscale.macro.dense import block_solve, mat_mult
from multiscale.macro.eigen import (LOCKED, TWO_PI, Damping, ModalResult, by_frequency, capped, lambda_from_theta,
                                    matrix_comm, reduce_sum, shift_invert_modes, solve_modes, solve_quadratic)
from multiscale.macro.modal import mac_matrix, pair_modes

METHODS = ("auto", "projection", "quadratic", "subspace")
SPURIOUS = 0.5        # a projected eigenpair with a relative residual above this in the full model is no mode of it
RESPONSE_KEEP = 1e-3   # a static response joins the basis with its part outside the modes' span above this share
SYMMETRIC = 1e-12      # ||K - K^T|| <= this share of ||K|| (infinity norms): no left modes in the basis


@dataclass
class LinearSystem:
    """M u'' + C u' + (K + i H) u = 0 plus a proportional part (module docstring)."""

    K: PETSc.Mat
    M: PETSc.Mat
    C: PETSc.Mat | None = None        # viscous damping, gyroscopic [N s/m]
    H: PETSc.Mat | None = None        # hysteretic stiffness [N/m]
    damping: Damping | None = None    # alpha M + beta K, eta K over the whole system
    K0: PETSc.Mat | None = None       # symmetric reference stiffness (frictionless tangent), "subspace" only

    @property
    def general(self) -> bool:
        """True if C or H is present (the proportional map alone no longer applies)."""
        return self.C is not None or self.H is not None

    @property
    def hysteretic(self) -> bool:
        return self.H is not None or bool(self.damping and self.damping.eta)


def real_columns(X: np.ndarray) -> np.ndarray:
    """The real and imaginary parts of complex columns side by side (real columns as they are)."""
    return np.column_stack([X.real, X.imag]) if np.iscomplexobj(X) else X


def unit_columns(vectors, M, comm) -> np.ndarray:
    """The real columns of the blocks ``vectors`` (``real_columns``), each scaled to M-norm 1 (zero
    columns left out)."""
    X = np.hstack([real_columns(v) for v in vectors])
    norms = np.sqrt(reduce_sum(np.einsum("ij,ij->j", X, mat_mult(M, X)), comm))
    return X[:, norms > 0] / norms[norms > 0]


class Subspace:
    """Real M-orthonormal basis V of the span of the real and imaginary parts of complex vectors
    (e.g. ``ModalResult.modes`` of several cases), with its Gram matrix V^T V (for the MAC).
    ``responses`` (static responses, ``static_responses``) add their parts outside the span of
    ``vectors`` where these hold at least ``RESPONSE_KEEP`` of the response (M-norms): an LU
    solve's round-off in the rest, amplified by the orthonormalisation, had made the lowest modes
    of the 12-mm demo brake 100x less accurate (eigenvalues 7.8e-9 -> 6.4e-7 off)."""

    def __init__(self, vectors, M, comm=None, drop: float = 1e-10, responses=()):
        self.comm = comm
        V, MV = m_orthonormalise(unit_columns(vectors, M, comm), [], [], M, comm, drop)
        if responses:
            W = unit_columns(responses, M, comm)
            W = W - V @ reduce_sum(MV.T @ W, comm)
            new = np.sqrt(reduce_sum(np.einsum("ij,ij->j", W, mat_mult(M, W)), comm))
            W = W[:, new >= RESPONSE_KEEP] / new[new >= RESPONSE_KEEP]
            V = np.hstack([V, m_orthonormalise(W, [V], [MV], M, comm, RESPONSE_KEEP ** 2)[0]])
        self.V = V
        self.gram = reduce_sum(self.V.T @ self.V, comm)

    @property
    def size(self) -> int:
        return self.V.shape[1]

    def apply(self, A) -> np.ndarray:
        return mat_mult(A, self.V)

    def reduce(self, AV: np.ndarray) -> np.ndarray:
        """V^T A V from the product A V."""
        return reduce_sum(self.V.T @ AV, self.comm)

    def expand(self, Q: np.ndarray) -> np.ndarray:
        return self.V @ Q


@dataclass
class ReducedSystem:
    """Projected matrices (dense, the same on every rank); C, H None when absent."""

    K: np.ndarray
    M: np.ndarray
    C: np.ndarray | None = None
    H: np.ndarray | None = None
    damping: Damping | None = None

    def total(self) -> tuple:
        """(K, M, C, H) with the proportional part folded in (C, H None when zero)."""
        d = self.damping or Damping()
        C = self.C
        if d.alpha or d.beta:
            C = (0 if C is None else C) + d.alpha * self.M + d.beta * self.K
        H = self.H
        if d.eta:
            H = (0 if H is None else H) + d.eta * self.K
        return self.K, self.M, C, H

    def blend(self, other: "ReducedSystem", t: float) -> "ReducedSystem":
        """(1 - t) self + t other, matrix by matrix (a point between two sweep points)."""
        def mix(a, b):
            if a is None and b is None:
                return None
            return (1 - t) * (0 if a is None else a) + t * (0 if b is None else b)
        return replace(self, K=mix(self.K, other.K), M=mix(self.M, other.M), C=mix(self.C, other.C),
                       H=mix(self.H, other.H))

    def eigenpairs(self) -> tuple[np.ndarray, np.ndarray]:
        """All (lambda, q) of the reduced problem with omega >= 0 (module docstring)."""
        K, M, C, H = self.total()
        if C is None and H is None:
            theta, Q = scipy.linalg.eig(K, M)
            return lambda_from_theta(theta), Q
        m = K.shape[0]
        s = math.sqrt(max(np.linalg.norm(K), 1e-300) / max(np.linalg.norm(M), 1e-300))  # balance
        Kc = (K + 1j * (0 if H is None else H)) / s**2
        Cs = (np.zeros((m, m)) if C is None else C) / s
        A = np.block([[np.zeros((m, m)), np.eye(m)], [-Kc, -Cs]])
        B = np.block([[np.eye(m), np.zeros((m, m))], [np.zeros((m, m)), M]])
        mu, X = scipy.linalg.eig(A, B)
        lam = s * mu
        tiny = 1e-9 * np.abs(lam)
        keep = np.isfinite(lam) & ((lam.imag > tiny) | ((np.abs(lam.imag) <= tiny) & (lam.real >= 0)))
        return lam[keep], X[:m, keep]


def select(lam: np.ndarray, band, n_modes: int | None, target: float) -> np.ndarray:
    """Indices of the eigenvalues in the band (the ``n_modes`` nearest ``target`` [Hz], with the
    other half of a lock-in pair the cap ends in: ``eigen.capped``; and any as near the target as
    the last, to ``LOCKED`` of that distance and the target), by frequency."""
    f = lam.imag / TWO_PI
    idx = np.nonzero((f >= band[0]) & (f <= band[1]))[0]
    if n_modes is not None and idx.size > n_modes:
        gap = np.abs(f[idx] - target)
        order = np.argsort(gap, kind="stable")
        ranked, cut = idx[order], gap[order[n_modes - 1]]
        idx = np.union1d(capped(lam, ranked, n_modes), idx[gap <= cut + LOCKED * (cut + abs(target))])
    return idx[by_frequency(lam[idx])]


def project(system: LinearSystem, sub: Subspace) -> tuple[ReducedSystem, dict]:
    """The reduced system and the products {name: A V} of each operator (for residuals)."""
    AV = {name: sub.apply(A) for name, A in (("K", system.K), ("M", system.M), ("C", system.C), ("H", system.H))
          if A is not None}
    red = ReducedSystem(**{name: sub.reduce(P) for name, P in AV.items()}, damping=system.damping)
    return red, AV


def residuals(lam: np.ndarray, Q: np.ndarray, AV: dict, damping: Damping | None, comm) -> np.ndarray:
    """Relative residual ||(lambda^2 M + lambda C + K + i H) V q|| / (sum of the norms of the terms)."""
    d = damping or Damping()
    KQ, MQ = AV["K"] @ Q, AV["M"] @ Q
    CQ = (AV["C"] @ Q if "C" in AV else 0) + d.alpha * MQ + d.beta * KQ
    HQ = (AV["H"] @ Q if "H" in AV else 0) + d.eta * KQ
    stiff = KQ + 1j * HQ
    terms = [lam**2 * MQ, lam * CQ, stiff]
    r = terms[0] + terms[1] + terms[2]

    def norms(X):
        X = np.broadcast_to(X, r.shape)
        return np.sqrt(reduce_sum(np.einsum("ij,ij->j", X.conj(), X).real, comm))

    return norms(r) / np.maximum(sum(norms(t) for t in terms), np.finfo(float).tiny)


def modal_result(lam, Q, errs, sub: Subspace, band, target, n_dofs, t0, *, base=None,
                 expand: bool = True, method: str = "projection") -> ModalResult:
    """ModalResult of reduced eigenpairs (relative residuals ``errs``, ``residuals``): full modes
    phi = V q (``expand``) normalised to phi^H M phi = 1 with phi^T phi real positive, or the
    reduced q with the subspace's Gram matrix."""
    Q = Q / np.sqrt(np.maximum(np.einsum("ij,ij->j", Q.conj(), Q).real, np.finfo(float).tiny))   # V'MV = I
    sq = np.einsum("ij,ij->j", Q, sub.gram @ Q)
    Q = Q * np.exp(-0.5j * np.angle(sq))
    modes = sub.expand(Q) if expand else Q
    return ModalResult(lam, -lam**2, modes, errs, tuple(band), target, n_dofs, method,
                       base.iterations if base else 0, base.solves if base else 0, time.perf_counter() - t0,
                       sub.comm if expand else None, gram=None if expand else sub.gram)


def solve_projected(system: LinearSystem, sub: Subspace, *, band=(0.0, 16e3), n_modes: int | None = None,
                    target: float | None = None, base: ModalResult | None = None, t0: float | None = None,
                    expand: bool = True) -> tuple[ModalResult, ReducedSystem]:
    """Modes of ``system`` in the span of ``sub`` (module docstring), and the reduced system."""
    t0 = time.perf_counter() if t0 is None else t0
    target = band[0] if target is None else target
    red, AV = project(system, sub)
    lam, Q = red.eigenpairs()
    inband = select(lam, band, None, target)
    errs = residuals(lam[inband], Q[:, inband], AV, system.damping, sub.comm)    # (scale and phase free)
    false = errs > SPURIOUS
    lam, Q, errs, spurious = lam[inband[~false]], Q[:, inband[~false]], errs[~false], lam[inband[false]].imag / TWO_PI
    keep = select(lam, band, n_modes, target)
    if keep.size == 0:
        raise InputError("f_max", band, "no damped mode in this frequency band [Hz]; widen it" +
                         (f" ({spurious.size} values of the projected problem, not modes of the model: widen "
                          "stability.basis)" if spurious.size else ""))
    result = modal_result(lam[keep], Q[:, keep], errs[keep], sub, band, target, system.K.getSize()[0], t0,
                          base=base, expand=expand)
    return replace(result, spurious=tuple(float(x) for x in spurious)), red


def basis_band(band, n_modes, target, basis: float) -> dict:
    """The band of the projection basis: up to ``basis`` x the band's top (and ``basis`` x
    ``n_modes`` modes when capped); keywords of the modal solvers."""
    if not basis >= 1:
        raise InputError("stability.basis", basis, "must be >= 1 (the basis reaches basis x f_max)")
    f_min, f_max = band
    return dict(f_min=f_min / basis, f_max=basis * f_max, target=f_min / basis if target is None else target,
                n_modes=None if n_modes is None else int(math.ceil(basis * n_modes)))


def basis_modes(system: LinearSystem, *, band, n_modes, target, basis: float, left: bool = True,
                **kw) -> tuple[ModalResult, list, list]:
    """The undamped modes of (K, M) in the projection basis' band (``basis_band``) and the vectors
    that span the basis (``Subspace(vectors, M, responses=responses)``): those modes, with ``left``
    and K not symmetric (friction) the modes of (K^T, M), the left eigenvectors, and with damping
    terms (H, C) the static responses to their forces of the modes in ``band``
    (``static_responses``; module docstring). One LU of
    K - theta_t M serves them all, solved transposed for the left modes and their responses."""
    wanted = basis_band(band, n_modes, target, basis)
    with shift_invert_modes(system.K, system.M, **wanted, **kw) as (base, factors):
        found = [base]
        if left:
            KT = PETSc.Mat()
            system.K.transpose(KT)            # a new matrix (without one, petsc4py transposes in place)
            try:
                skew = KT.copy()
                skew.axpy(-1.0, system.K)
                asymmetric = skew.norm(PETSc.NormType.INFINITY) > SYMMETRIC * system.K.norm(PETSc.NormType.INFINITY)
                skew.destroy()
                if asymmetric:
                    found.append(solve_modes(KT, system.M, **wanted, **kw, transpose_of=factors))
            finally:
                KT.destroy()
        inside = [r.modes[:, (r.frequency >= band[0]) & (r.frequency <= band[1])] for r in found]
        responses = [x for A in (system.H, system.C) if A is not None    # of the modes of the band itself;
                     for x in static_responses(A, factors, *inside)]    # those above it pad the basis
    return base, [r.modes for r in found], responses


def static_responses(A: PETSc.Mat, factors: PETSc.KSP, right: np.ndarray, left: np.ndarray | None = None) -> list:
    """Static responses to the damping forces A phi of the basis modes (A = H hysteretic or C
    viscous), (K - theta_t M)^-1 A phi of the right modes phi and (K^T - theta_t M)^-1 A^T psi of
    the left modes psi (real and imaginary parts), by the ``factors`` of K - theta_t M (modal
    truncation augmentation, Dickens, Nakagawa & Wittbrodt, Comput. Struct. 62 (1997) 985;
    module docstring)."""
    out = [block_solve(factors, mat_mult(A, real_columns(right)))]
    if left is not None:
        out.append(block_solve(factors, mat_mult(A, real_columns(left), transpose=True), transpose=True))
    return out


def subspace_basis(system: LinearSystem, *, band, n_modes, target, basis: float,
                   **kw) -> tuple[ModalResult, Subspace]:
    """The ``"subspace"`` basis (module docstring): real modes of (K0, M) in ``basis_band`` by the
    shifted block Lanczos method, and their static corrections with the same factors. ``kw``:
    ``tol`` of the modes."""
    if system.K0 is None:
        raise InputError("stability.method", "subspace", "needs the frictionless tangent K0 of the system")
    wanted = basis_band(band, n_modes, target, basis)
    factors = ShiftInvert(system.K0, system.M, (TWO_PI * wanted["target"]) ** 2)
    try:
        base = symmetric_modes(system.K0, system.M, **wanted, solver=factors,
                               **{k: v for k, v in kw.items() if k == "tol"})
        V = base.modes
        W = factors.solve(mat_mult(system.K, V) - mat_mult(system.K0, V))
    finally:
        factors.destroy()
    return replace(base, modes=None), Subspace([V], system.M, matrix_comm(system.K), responses=[W])


def solve_system(system: LinearSystem, *, f_max: float = 16e3, f_min: float = 0.0, n_modes: int | None = None,
                 target: float | None = None, method: str = "auto", basis: float = 1.5,
                 **kw) -> ModalResult:
    """Complex modes of ``system`` with f_min <= f <= f_max [Hz] (module docstring); ``kw`` go to
    the SLEPc solvers (tol, max_it, nev, options_prefix)."""
    if method not in METHODS:
        raise InputError("stability.method", method, f"one of {', '.join(METHODS)}")
    if not system.general and method != "subspace":
        return solve_modes(system.K, system.M, f_max=f_max, f_min=f_min, n_modes=n_modes, target=target,
                           damping=system.damping, **kw)
    t0 = time.perf_counter()
    band = (f_min, f_max)
    if method == "auto":     # the real PEP converges from 0 Hz up (``solve_quadratic``): not to a band above it
        method = "projection" if system.hysteretic or f_min > 0 or (target or 0.0) > 0 else "quadratic"
    if method == "quadratic":
        if system.hysteretic:
            raise InputError("stability.method", method, "the full quadratic solver takes viscous damping only; "
                             "loss factors (complex stiffness) need method = \"projection\"")
        C = total_damping_matrix(system)
        try:
            return solve_quadratic(system.K, C, system.M, f_max=f_max, f_min=f_min, n_modes=n_modes,
                                   target=f_min if target is None else target,
                                   **{k: v for k, v in kw.items() if k in ("tol", "max_it")})
        finally:
            if C is not system.C:
                C.destroy()
    if method == "subspace":
        base, sub = subspace_basis(system, band=band, n_modes=n_modes, target=target, basis=basis, **kw)
    else:
        base, vectors, responses = basis_modes(system, band=band, n_modes=n_modes, target=target, basis=basis, **kw)
        sub = Subspace(vectors, system.M, matrix_comm(system.K), responses=responses)
    return solve_projected(system, sub, band=band, n_modes=n_modes, target=target, base=base, t0=t0)[0]


def total_damping_matrix(system: LinearSystem) -> PETSc.Mat:
    """C + alpha M + beta K as one matrix (``system.C`` itself without a proportional part)."""
    d = system.damping or Damping()
    if not (d.alpha or d.beta):
        return system.C
    C = system.M.duplicate(copy=True)
    C.scale(d.alpha)
    pattern = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
    if d.beta:          # not on the supports' rows: K holds 1 on their diagonal and M 0, so beta K
        C.axpy(d.beta, system.K, pattern)           # there made a mode lambda = -1/beta at 0 Hz of each
        held, k = system.M.getDiagonal(), system.K.getDiagonal()
        k.array[:] = np.where(held.array == 0.0, -d.beta * k.array, 0.0)
        C.setDiagonal(k, addv=PETSc.InsertMode.ADD_VALUES)
    if system.C is not None:
        C.axpy(1.0, system.C, pattern)
    return C


@dataclass
class PrestressEffect:
    """Frequencies with and without the prestress (geometric) stiffness, mode by mode (MAC-paired)."""

    frequency: np.ndarray            # Hz, with prestress (the analysis' modes)
    frequency_without: np.ndarray    # Hz, the paired mode without it
    growth: np.ndarray               # 1/s, with prestress
    growth_without: np.ndarray       # 1/s
    mac: np.ndarray                  # MAC of each pair [-]
    residual: np.ndarray             # relative residual of the modes without prestress
    method: str = field(default="projection on the prestressed modes")

    @property
    def shift(self) -> np.ndarray:
        """f_with - f_without [Hz]."""
        return self.frequency - self.frequency_without


def prestress_effect(result: ModalResult, system: LinearSystem, K_sigma: PETSc.Mat,
                     mac_min: float = 0.5) -> PrestressEffect:
    """The modes of ``system`` without its geometric stiffness ``K_sigma``, solved in the span of
    the prestressed modes ``result`` (a Galerkin estimate, its residual reported) and paired with
    them by MAC: what the prestress does to each frequency."""
    sub = Subspace([result.modes], system.M, result.comm)
    red, AV = project(system, sub)
    KsV = sub.apply(K_sigma)
    AV0 = dict(AV, K=AV["K"] - KsV)
    lam0, Q0 = replace(red, K=red.K - sub.reduce(KsV)).eigenpairs()
    Q0 = Q0 / np.sqrt(np.maximum(np.einsum("ij,ij->j", Q0.conj(), Q0).real, np.finfo(float).tiny))
    MV = AV["M"]
    Qw = reduce_sum(MV.T @ result.modes, sub.comm)          # q = V^T M phi (V M-orthonormal)
    mac = mac_matrix(Qw, Q0, gram=sub.gram)
    pairs = pair_modes(mac, result.eigenvalues, lam0, mac_min)
    n = len(result)
    f0, s0, m0, r0 = (np.full(n, np.nan) for _ in range(4))
    res0 = residuals(lam0, Q0, AV0, system.damping, sub.comm)
    for i, j in pairs:
        f0[i], s0[i], m0[i], r0[i] = lam0[j].imag / TWO_PI, lam0[j].real, mac[i, j], res0[j]
    return PrestressEffect(result.frequency.copy(), f0, result.growth.copy(), s0, m0, r0)

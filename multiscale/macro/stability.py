"""Complex eigenvalue (squeal) stability analysis of a pre-stressed sliding system (thesis ch. 4).

Linearised about a steady sliding state, the free vibrations obey ``M u'' + C u' + K u = 0`` with
``K`` the tangent stiffness, non-symmetric because of the friction forces (§4.3.1). With
``u = phi exp(lambda t)`` the undamped problem is the generalised non-Hermitian eigenproblem (GNHEP)

    K phi = theta M phi,        lambda = sigma + i omega = i sqrt(theta)   (omega >= 0),

solved with SLEPc by shift-and-invert about ``theta_t = (2 pi f_t)^2``. A real ``theta`` gives a
neutrally stable mode; two modes that coalesce ("lock in") become a conjugate pair theta, conj(theta):
one mode with sigma > 0 (unstable, growth rate [1/s]) and one with sigma < 0, at the same frequency.
Damping proportional to the operators (``Damping``: Rayleigh alpha, beta; structural loss factor eta)
keeps the eigenvectors and maps each theta exactly to lambda; a general damping matrix needs the
quadratic eigenproblem (SLEPc PEP, ``solve_quadratic``).

Post-processing (§4.4): unstable and potentially unstable modes (Fig. 4.14), MAC between two cases,
MMAC and its cumulative moving average (Figs. 4.16–4.19), strain-energy shares per component and
between the two pads (Figs. 4.20–4.21). Vectors are kept as the rank-owned part of the PETSc layout
(complex numpy arrays); inner products are reduced over the matrix communicator.

The brake (§4.3): ``HydraulicMechanics`` (pressure −p n on piston and caliper), ``preload``
(quasi-static steady sliding, Coulomb friction along the disc's rotation) and ``linearise``
(K = the consistent Newton matrix of the ``mechanics``/``interface`` forms, M = mass with diag 0 on
Dirichlet rows), ``RegionEnergy`` (strain energy per material region), ``squeal_case``. Rough pads
(§4.2, §4.3.2, Table 4.1): per-zone laws of ``multiscale.micro.laws`` (computed by the micro pool)
embedded per facet by ``LinearisedFacetLaw``/``settle``. Scenes: ``analyse``, ``run_scene``;
figures of §4.4: ``plot_*`` (rank 0).

Sign conventions: sigma > 0 is growth (unstable), frequency = omega / (2 pi) [Hz] >= 0, modes are
numbered from 1 in order of increasing frequency (ties: increasing sigma).
"""
from __future__ import annotations

import csv
import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

try:  # the PyPI DOLFINx wheel must be imported before petsc4py/slepc4py
    import dolfinx_solver  # noqa: F401
except ImportError:
    pass
import ufl
from dolfinx import fem, la
from dolfinx.fem import petsc as fpetsc
from petsc4py import PETSc
from slepc4py import SLEPc

from ..errors import ConvergenceError, InputError, check_positive
from .mechanics import Mechanics, body_fields

TWO_PI = 2.0 * math.pi


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------
@dataclass
class ModalResult:
    """Complex modes of a linearised system, sorted by frequency.

    ``modes[:, j]`` is mode j (rank-owned entries of the PETSc layout), normalised to
    ``phi^H M phi = 1`` with the phase that makes ``phi^T phi`` real positive.
    """

    eigenvalues: np.ndarray     # lambda = sigma + i omega [1/s], omega >= 0
    theta: np.ndarray           # eigenvalue of K phi = theta M phi [1/s^2] (= -lambda^2 undamped)
    modes: np.ndarray           # complex (n_owned, n_modes) [m per unit modal mass^(1/2)]
    errors: np.ndarray          # SLEPc relative residual of each pair [-]
    band: tuple[float, float]   # requested band (f_min, f_max) [Hz]
    target: float               # shift-and-invert target frequency [Hz]
    n_dofs: int                 # global problem size
    method: str                 # "gnhep" or "pep"
    iterations: int             # outer iterations of the last SLEPc solve
    solves: int                 # SLEPc solves (the band search may enlarge the subspace)
    time: float                 # wall time [s]
    comm: object = field(default=None, repr=False)   # mpi4py communicator of the modes (None: serial)

    @property
    def frequency(self) -> np.ndarray:
        """omega / 2 pi [Hz]."""
        return self.eigenvalues.imag / TWO_PI

    @property
    def growth(self) -> np.ndarray:
        """sigma = Re(lambda) [1/s]; > 0 means unstable."""
        return self.eigenvalues.real

    @property
    def damping_ratio(self) -> np.ndarray:
        """-sigma / |lambda| [-] (negative for an unstable mode)."""
        return -self.eigenvalues.real / np.maximum(np.abs(self.eigenvalues), np.finfo(float).tiny)

    def unstable(self, rtol: float = 1e-6) -> np.ndarray:
        """Boolean mask of modes with sigma > rtol |lambda| (round-off guard, default 1e-6)."""
        return self.eigenvalues.real > rtol * np.abs(self.eigenvalues)

    def __len__(self) -> int:
        return self.eigenvalues.size

    def write_csv(self, path: str | Path, rtol: float = 1e-6) -> Path:
        """Mode table: number, frequency [Hz], sigma [1/s], damping ratio, unstable flag, residual."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["mode", "frequency_Hz", "sigma_1_per_s", "damping_ratio", "unstable", "residual"])
            for j, (fr, s, z, u, e) in enumerate(zip(self.frequency, self.growth, self.damping_ratio,
                                                     self.unstable(rtol), self.errors), start=1):
                w.writerow([j, f"{fr:.6f}", f"{s:.6e}", f"{z:.6e}", int(u), f"{e:.2e}"])
        return path


@dataclass(frozen=True)
class Damping:
    """Damping proportional to the operators: C = alpha M + beta K, and K -> K (1 + i eta).

    Each GNHEP eigenvalue theta maps exactly (same eigenvector) to the root with omega >= 0 of
    lambda^2 + (alpha + beta theta) lambda + theta (1 + i eta) = 0.
    """

    alpha: float = 0.0   # mass-proportional coefficient [1/s]
    beta: float = 0.0    # stiffness-proportional coefficient [s]
    eta: float = 0.0     # structural (hysteretic) loss factor [-]

    def __post_init__(self):
        for name in ("alpha", "beta", "eta"):
            check_positive(f"damping.{name}", getattr(self, name), allow_zero=True)


@dataclass
class StabilityReport:
    """Unstable and potentially unstable modes of one case (thesis Fig. 4.14)."""

    unstable: np.ndarray              # mode numbers (1-based) with sigma > rtol |lambda|
    potentially_unstable: np.ndarray  # stable modes with a stable neighbour closer than close_tol
    frequency: np.ndarray             # [Hz] of all modes
    growth: np.ndarray                # sigma [1/s] of all modes
    rtol: float                       # instability threshold on sigma / |lambda| [-]
    close_tol: float                  # relative frequency gap of a potentially unstable pair [-]


@dataclass
class EnergyShares:
    """Strain-energy share of each component per mode (thesis Figs. 4.20–4.21)."""

    names: list[str]        # component names
    energy: np.ndarray      # (n_modes, n_components) 1/2 phi^H K_c phi [J per unit modal mass]
    share: np.ndarray       # energy / sum over components [-]

    def split(self, a: str, b: str) -> np.ndarray:
        """Share of component ``a`` in the energy of ``a`` and ``b`` (e.g. inner vs outer pad) [-]."""
        ia, ib = self._index(a), self._index(b)
        tot = self.energy[:, ia] + self.energy[:, ib]
        return self.energy[:, ia] / np.where(tot > 0, tot, 1.0)

    def _index(self, name: str) -> int:
        if name not in self.names:
            raise InputError("component", name, f"one of {self.names}")
        return self.names.index(name)


# --------------------------------------------------------------------------------------------
# Eigenvalue solvers
# --------------------------------------------------------------------------------------------
def lambda_from_theta(theta, damping: Damping | None = None) -> np.ndarray:
    """Map eigenvalues theta of K phi = theta M phi to lambda = sigma + i omega (omega >= 0).

    Undamped: lambda = i sqrt(theta). With ``damping``: the root of
    lambda^2 + (alpha + beta theta) lambda + theta (1 + i eta) = 0 with the larger imaginary part
    (ties, i.e. real roots from a negative theta, take the larger real part: divergence is unstable).
    """
    theta = np.asarray(theta, dtype=complex)
    d = damping or Damping()
    b = d.alpha + d.beta * theta
    disc = np.sqrt(b * b - 4.0 * theta * (1.0 + 1j * d.eta))
    r1, r2 = (-b + disc) / 2.0, (-b - disc) / 2.0
    take1 = (r1.imag > r2.imag) | ((r1.imag == r2.imag) & (r1.real >= r2.real))
    return np.where(take1, r1, r2)


def _check_band(f_min, f_max, target, n_modes):
    f_min = check_positive("f_min", f_min, allow_zero=True)
    f_max = check_positive("f_max", f_max)
    if f_max <= f_min:
        raise InputError("f_max", f_max, f"must exceed f_min = {f_min} Hz")
    if target is None:
        target = f_min
    try:
        target = float(target)
    except (TypeError, ValueError):
        raise InputError("target", target, "must be a frequency in Hz >= 0") from None
    if not (target >= 0 and math.isfinite(target)):
        raise InputError("target", target, "must be a finite frequency in Hz >= 0 (a shift below "
                         "the spectrum is not a frequency)")
    if n_modes is not None and (int(n_modes) != n_modes or n_modes < 1):
        raise InputError("n_modes", n_modes, "must be a positive integer")
    return f_min, f_max, target


def _direct_solver(st):
    st.setType(SLEPc.ST.Type.SINVERT)
    ksp = st.getKSP()
    ksp.setType(PETSc.KSP.Type.PREONLY)
    pc = ksp.getPC()
    pc.setType(PETSc.PC.Type.LU)
    if PETSc.Sys.hasExternalPackage("mumps"):
        pc.setFactorSolverType("mumps")


def _pairs(solver, i, vr, vi):
    val = solver.getEigenpair(i, vr, vi)
    return complex(val), vr.getArray() + 1j * vi.getArray()


def _normalise(phi: np.ndarray, M, comm) -> np.ndarray:
    """Scale columns to phi^H M phi = 1 and rotate so that phi^T phi is real positive."""
    mphi = _apply(M, phi)
    gram = np.array([np.vdot(phi[:, j], mphi[:, j]).real for j in range(phi.shape[1])])
    sq = np.einsum("ij,ij->j", phi, phi)
    gram, sq = _allreduce(np.concatenate([gram, sq]), comm).reshape(2, -1)
    scale = np.exp(-0.5j * np.angle(sq)) / np.sqrt(np.maximum(gram.real, np.finfo(float).tiny))
    return phi * scale


def _allreduce(a: np.ndarray, comm) -> np.ndarray:
    return a if comm is None else comm.allreduce(a)


def _mpi_comm(A):
    """None in serial; otherwise a duplicate of the matrix communicator (it outlives the matrix)."""
    comm = A.getComm().tompi4py()
    return None if comm.size == 1 else comm.Dup()


def _apply(A, phi: np.ndarray) -> np.ndarray:
    """A @ phi for a real PETSc matrix and complex columns of owned entries."""
    x, y = A.createVecs()
    out = np.empty_like(phi)
    for j in range(phi.shape[1]):
        parts = []
        for part in (phi[:, j].real, phi[:, j].imag):
            x.setArray(np.ascontiguousarray(part))
            A.mult(x, y)
            parts.append(y.getArray().copy())
        out[:, j] = parts[0] + 1j * parts[1]
    x.destroy(), y.destroy()
    return out


def _sorted(lam, theta, vecs, errs, band, seen_f):
    """Modes sorted by frequency then growth; none (an empty band) is an InputError.

    ``seen_f`` are the frequencies [Hz] of every converged eigenvalue (for the message).
    """
    if lam.size == 0:
        hint = (f"nearest found: {seen_f[np.argmin(np.minimum(abs(seen_f - band[0]), abs(seen_f - band[1])))]:.6g} Hz"
                if seen_f.size else "none found")
        raise InputError("f_max", band, f"no eigenvalue in this frequency band [Hz]; widen it ({hint})")
    order = np.lexsort((lam.real, lam.imag))
    return lam[order], theta[order], vecs[:, order], errs[order]


def solve_modes(K, M, *, f_max: float = 16e3, f_min: float = 0.0, n_modes: int | None = None,
                target: float | None = None, damping: Damping | None = None, tol: float = 1e-10,
                max_it: int = 300, nev: int = 20, options_prefix: str = "stability_") -> ModalResult:
    """Modes with f_min <= f <= f_max [Hz] of K phi = theta M phi (GNHEP, shift-and-invert, §4.3.1).

    ``K`` (tangent, may be non-symmetric) and ``M`` (mass, diag 0 on Dirichlet rows so that the
    constrained modes go to infinity) are assembled PETSc matrices. The shift is
    theta_t = (2 pi target)^2 (default target = f_min); K - theta_t M must be non-singular, so a
    free-free structure needs target > 0. Eigenvalues converge in order of |theta - theta_t|; the
    subspace grows (from ``nev``) until every theta with |theta - theta_t| <= max((2 pi f_max)^2 -
    theta_t, theta_t - (2 pi f_min)^2) is converged, i.e. the band is complete for modes with
    |sigma| << omega, or until ``n_modes`` band modes nearest the target are found (a cap; the
    conjugate partner of the last one is kept with it). Raises InputError for a bad request or an
    empty band, ConvergenceError if SLEPc does not converge.
    """
    f_min, f_max, target = _check_band(f_min, f_max, target, n_modes)
    t0 = time.perf_counter()
    comm = _mpi_comm(K)
    n = K.getSize()[0]
    shift = (TWO_PI * target) ** 2
    radius = max((TWO_PI * f_max) ** 2 - shift, shift - (TWO_PI * f_min) ** 2)
    if n_modes is not None and n_modes > n:
        raise InputError("n_modes", n_modes, f"must not exceed the number of dofs ({n})")
    want = min(max(int(nev), int(n_modes or 0)), n)

    eps = SLEPc.EPS().create(K.getComm())
    eps.setOperators(K, M)
    eps.setProblemType(SLEPc.EPS.ProblemType.GNHEP)
    eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
    eps.setTarget(shift)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setTolerances(tol, max_it)
    _direct_solver(eps.getST())
    eps.setOptionsPrefix(options_prefix)
    eps.setFromOptions()
    solves = 0
    while True:
        eps.setDimensions(want, PETSc.DECIDE)
        try:
            eps.solve()
        except PETSc.Error as exc:
            raise InputError("target", target, f"K - (2 pi target)^2 M could not be factorised "
                             f"(singular at this shift? choose a target > 0 away from an eigenvalue): "
                             f"{exc}") from None
        solves += 1
        nconv = eps.getConverged()
        if nconv < want:
            raise ConvergenceError(f"SLEPc converged {nconv} of {want} eigenpairs "
                                   f"(reason {eps.getConvergedReason()})",
                                   history=[eps.getIterationNumber()])
        theta = np.array([eps.getEigenvalue(i) for i in range(nconv)], dtype=complex)
        order = np.argsort(np.abs(theta - shift), kind="stable")[:want]   # complete up to 'reached'
        reached = abs(theta[order[-1]] - shift)
        f = lambda_from_theta(theta[order]).imag / TWO_PI
        inband = order[(f >= f_min) & (f <= f_max)]
        if n_modes is not None and inband.size >= n_modes:
            keep = inband[:n_modes]
            partner = inband[n_modes:n_modes + 1]
            if partner.size and np.isclose(theta[partner[0]], theta[keep[-1]].conjugate(), rtol=1e-10):
                keep = inband[:n_modes + 1]
            break
        if reached > radius or want >= n:
            keep = inband
            break
        # Weyl: the count of theta below R grows like R^(3/2) in 3D; aim 20 % beyond the band.
        grow = (1.2 * radius / max(reached, 1e-300)) ** 1.5
        if n_modes is not None and inband.size:
            grow = min(grow, 1.2 * n_modes / inband.size)
        want = min(n, max(want + 10, int(math.ceil(want * min(grow, 8.0)))))

    vr, vi = K.createVecs()
    vecs = np.empty((vr.getLocalSize(), keep.size), dtype=complex)
    errs = np.empty(keep.size)
    vals = np.empty(keep.size, dtype=complex)
    for j, i in enumerate(keep):
        vals[j], vecs[:, j] = _pairs(eps, int(i), vr, vi)
        errs[j] = eps.computeError(int(i), SLEPc.EPS.ErrorType.RELATIVE)
    iterations = eps.getIterationNumber()
    eps.destroy(), vr.destroy(), vi.destroy()

    lam = lambda_from_theta(vals, damping)
    lam, vals, vecs, errs = _sorted(lam, vals, vecs, errs, (f_min, f_max),
                                    lambda_from_theta(theta).imag / TWO_PI)
    return ModalResult(lam, vals, _normalise(vecs, M, comm), errs, (f_min, f_max), target, n,
                       "gnhep", iterations, solves, time.perf_counter() - t0, comm)


def solve_quadratic(K, C, M, *, f_max: float = 16e3, f_min: float = 0.0, n_modes: int = 20,
                    target: float = 0.0, tol: float = 1e-10, max_it: int = 300,
                    options_prefix: str = "stability_pep_") -> ModalResult:
    """Damped modes of (lambda^2 M + lambda C + K) phi = 0 with a general damping matrix C (SLEPc PEP).

    Real arithmetic cannot shift at i omega; the shift is the real rate s = 2 pi target [1/s]
    (K + s C + s^2 M is non-singular for s > 0 even for a free-free structure) and eigenvalues
    converge in order of |lambda - s|, i.e. by frequency for light damping. ``n_modes`` counts
    modes with omega >= 0 (conjugate pairs are computed together); the result is filtered to the
    band. ``theta`` is reported as -lambda^2.
    """
    f_min, f_max, target = _check_band(f_min, f_max, target, n_modes)
    t0 = time.perf_counter()
    comm = _mpi_comm(K)
    n = K.getSize()[0]
    pep = SLEPc.PEP().create(K.getComm())
    pep.setOperators([K, C, M])
    pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
    pep.setType(SLEPc.PEP.Type.TOAR)
    pep.setTarget(TWO_PI * target)
    pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
    pep.setTolerances(tol, max_it)
    pep.setDimensions(min(2 * int(n_modes), 2 * n), PETSc.DECIDE)
    _direct_solver(pep.getST())
    pep.setOptionsPrefix(options_prefix)
    pep.setFromOptions()
    try:
        pep.solve()
    except PETSc.Error as exc:
        raise InputError("target", target, f"K + s C + s^2 M could not be factorised: {exc}") from None
    nconv = pep.getConverged()
    if nconv < min(2 * int(n_modes), 2 * n):
        raise ConvergenceError(f"SLEPc PEP converged {nconv} of {2 * n_modes} eigenpairs",
                               history=[pep.getIterationNumber()])
    vr, vi = K.createVecs()
    lam, vecs, errs = [], [], []
    for i in range(nconv):
        val, v = _pairs(pep, i, vr, vi)
        if val.imag < 0:
            continue  # the conjugate partner of a kept mode
        lam.append(val)
        vecs.append(v)
        errs.append(pep.computeError(i, SLEPc.PEP.ErrorType.BACKWARD))
    iterations = pep.getIterationNumber()
    pep.destroy(), vr.destroy(), vi.destroy()
    lam = np.array(lam, dtype=complex)
    vecs = np.column_stack(vecs) if vecs else np.empty((K.getLocalSize()[0], 0), complex)
    errs = np.array(errs)
    seen = lam.imag / TWO_PI
    inband = (seen >= f_min) & (seen <= f_max)
    lam, theta, vecs, errs = _sorted(lam[inband], -lam[inband] ** 2, vecs[:, inband], errs[inband],
                                     (f_min, f_max), seen)
    return ModalResult(lam, theta, _normalise(vecs, M, comm), errs, (f_min, f_max), target, n,
                       "pep", iterations, 1, time.perf_counter() - t0, comm)


def onset_of_instability(build: Callable[[float], tuple], mu_lo: float, mu_hi: float, *,
                         xtol: float = 1e-9, rtol: float = 1e-6, **solve_kw) -> float:
    """Smallest friction coefficient in [mu_lo, mu_hi] with an unstable mode, by bisection.

    ``build(mu) -> (K, M)``; ``solve_kw`` go to ``solve_modes``. Stable at mu_lo and unstable at
    mu_hi are required (InputError otherwise). Returns the onset mu [-] within ``xtol``.
    """
    mu_lo = check_positive("mu_lo", mu_lo, allow_zero=True)
    mu_hi = check_positive("mu_hi", mu_hi)
    if mu_hi <= mu_lo:
        raise InputError("mu_hi", mu_hi, f"must exceed mu_lo = {mu_lo}")

    def unstable(mu):
        return bool(solve_modes(*build(mu), **solve_kw).unstable(rtol).any())

    if unstable(mu_lo):
        raise InputError("mu_lo", mu_lo, "the system is already unstable there")
    if not unstable(mu_hi):
        raise InputError("mu_hi", mu_hi, "the system is still stable there")
    while mu_hi - mu_lo > xtol:
        mid = 0.5 * (mu_lo + mu_hi)
        mu_lo, mu_hi = (mu_lo, mid) if unstable(mid) else (mid, mu_hi)
    return 0.5 * (mu_lo + mu_hi)


def hoffmann_model(mu: float, k11: float = 1.0, k22: float = 1.5, k12: float = 0.3,
                   k21: float = 0.3, k3: float = 1.0, mass: float = 1.0, comm=None):
    """(K, M) of the Hoffmann 2-DOF minimal model of mode-coupling instability.

    A mass on a belt held by springs; the normal contact spring k3 and Coulomb friction mu k3 x2
    add the circulatory term: K = [[k11, k12 - mu k3], [k21, k22]], M = mass I. The two modes
    coalesce at mu_c = [(k11 - k22)^2 + 4 k12 k21] / (4 k21 k3).
    """
    mu = check_positive("mu", mu, allow_zero=True)
    for name, v in (("k11", k11), ("k22", k22), ("k3", k3), ("mass", mass)):
        check_positive(name, v)
    comm = comm or PETSc.COMM_SELF
    out = []
    for rows in (((k11, k12 - mu * k3), (k21, k22)), ((mass, 0.0), (0.0, mass))):
        A = PETSc.Mat().createAIJ([2, 2], nnz=2, comm=comm)
        A.setUp()
        for i in range(2):
            A.setValues(i, [0, 1], rows[i])
        A.assemble()
        out.append(A)
    return tuple(out)


# --------------------------------------------------------------------------------------------
# Post-processing (§4.4)
# --------------------------------------------------------------------------------------------
def stability_report(result: ModalResult, rtol: float = 1e-6, close_tol: float = 1e-3) -> StabilityReport:
    """Unstable modes (sigma > rtol |lambda|) and potentially unstable ones (Fig. 4.14).

    A stable mode is potentially unstable when a neighbouring stable mode lies within
    ``close_tol`` relative frequency: the pair is close to coalescence but not yet locked in.
    """
    check_positive("rtol", rtol)
    check_positive("close_tol", close_tol)
    f = result.frequency
    bad = result.unstable(rtol)
    close = np.zeros(f.size, bool)
    if f.size > 1:
        gap = np.diff(f) <= close_tol * np.maximum(f[1:], np.finfo(float).tiny)
        both_stable = ~bad[1:] & ~bad[:-1]
        pair = gap & both_stable
        close[1:] |= pair
        close[:-1] |= pair
    number = np.arange(1, f.size + 1)
    return StabilityReport(number[bad], number[close], f.copy(), result.growth.copy(), rtol, close_tol)


def mac_matrix(a: ModalResult | np.ndarray, b: ModalResult | np.ndarray, comm=None) -> np.ndarray:
    """MAC_ij = |y_i^H y_j|^2 / (y_i^H y_i  y_j^H y_j) between modes of two cases (§4.4).

    Both sets must live on the same dof layout (same mesh and spaces). Returns (n_a, n_b) in [0, 1].
    """
    comm = comm or getattr(a, "comm", None) or getattr(b, "comm", None)
    ya = a.modes if isinstance(a, ModalResult) else np.asarray(a)
    yb = b.modes if isinstance(b, ModalResult) else np.asarray(b)
    if ya.shape[0] != yb.shape[0]:
        raise InputError("modes", (ya.shape, yb.shape), "the two cases must share the dof layout")
    cross = ya.conj().T @ yb
    na = np.einsum("ij,ij->j", ya.conj(), ya).real
    nb = np.einsum("ij,ij->j", yb.conj(), yb).real
    cross, na, nb = _allreduce(cross, comm), _allreduce(na, comm), _allreduce(nb, comm)
    return np.abs(cross) ** 2 / np.maximum(np.outer(na, nb), np.finfo(float).tiny)


def mmac(mac: np.ndarray) -> np.ndarray:
    """MMAC_i = max_j MAC_ij: best correlation of mode i of the first case (§4.4)."""
    return np.asarray(mac).max(axis=1)


def cumulative_moving_average(x) -> np.ndarray:
    """xbar_n = (1/n) sum_{k=0}^{n-1} x_{n-k}, n = 1..N (Fig. 4.19)."""
    x = np.asarray(x, dtype=float)
    return np.cumsum(x) / np.arange(1, x.size + 1)


def strain_energy_shares(result: ModalResult, meter) -> EnergyShares:
    """Per-mode strain energy of each component (thesis Figs. 4.20–4.21).

    ``meter`` has ``names`` and ``meter(x) -> (n_components,)`` global energies 1/2 x^T K_c x of a
    real vector of owned dofs (``MatrixEnergy`` from matrices, ``RegionEnergy`` from a DOLFINx model).
    For a complex mode phi = a + i b and symmetric K_c, 1/2 phi^H K_c phi = E_c(a) + E_c(b).
    """
    names = list(meter.names)
    energy = np.array([meter(np.ascontiguousarray(phi.real)) + meter(np.ascontiguousarray(phi.imag))
                       for phi in result.modes.T]).reshape(len(result), len(names))
    tot = energy.sum(axis=1, keepdims=True)
    return EnergyShares(names, energy, energy / np.where(tot > 0, tot, 1.0))


class MatrixEnergy:
    """Energy meter from assembled symmetric component stiffness matrices {name: K_c}."""

    def __init__(self, stiffness: Mapping[str, object]):
        if not stiffness:
            raise InputError("stiffness", stiffness, "at least one component matrix")
        self.names = list(stiffness)
        self._mats = [stiffness[n] for n in self.names]
        self._comm = _mpi_comm(self._mats[0])

    def __call__(self, x: np.ndarray) -> np.ndarray:
        out = np.empty(len(self._mats))
        for c, K in enumerate(self._mats):
            out[c] = 0.5 * x @ _apply(K, x[:, None].astype(complex))[:, 0].real
        return _allreduce(out, self._comm)


def write_modes_xdmf(path: str | Path, result: ModalResult, functions: Sequence,
                     modes: Sequence[int] | None = None) -> list[Path]:
    """Mode shapes to XDMF, one file per body mesh: real and imaginary parts, "time" = mode number.

    ``functions`` are displacement Functions of the bodies in the block order of the matrices (the
    owned dofs of body 0, then of body 1, ... on each rank). Shapes are interpolated to linear
    vertex values (XDMF stores the mesh's own degree). Returns the written paths.
    """
    from dolfinx import io

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sel = range(1, len(result) + 1) if modes is None else modes
    sizes = [u.function_space.dofmap.bs * u.function_space.dofmap.index_map.size_local
             for u in functions]
    if sum(sizes) != result.modes.shape[0]:
        raise InputError("functions", len(functions), "must span the dof layout of the modes")
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    files = []
    for k, u in enumerate(functions):
        mesh = u.function_space.mesh
        work = fem.Function(u.function_space)
        W = fem.functionspace(mesh, ("Lagrange", 1, (mesh.geometry.dim,)))
        parts = (fem.Function(W, name="mode_re"), fem.Function(W, name="mode_im"))
        out = path.with_name(f"{path.stem}_body{k}.xdmf")
        with io.XDMFFile(mesh.comm, str(out), "w") as w:
            w.write_mesh(mesh)
            for j in sel:
                block = result.modes[offsets[k]:offsets[k + 1], j - 1]
                for f, values in zip(parts, (block.real, block.imag)):
                    work.x.array[:sizes[k]] = values
                    work.x.scatter_forward()
                    f.interpolate(work)
                    w.write_function(f, float(j))
        files.append(out)
    return files


# --------------------------------------------------------------------------------------------
# Linearisation of a DOLFINx two-body model at its steady sliding state (§4.3.1)
# --------------------------------------------------------------------------------------------
class HydraulicMechanics(Mechanics):
    """``Mechanics`` loaded by a fluid pressure p = ``load`` [Pa]: traction −p n on each load face.

    n is the outward normal, so two faces that look at each other across the fluid (the brake's
    piston back and caliper bore, §4.3.1) are pushed apart by the same pressure.
    """

    def __init__(self, tm, materials, **kwargs):
        kwargs["load_kind"] = "pressure"
        super().__init__(tm, materials, **kwargs)

    def traction(self):
        return -self.load * ufl.FacetNormal(self.tm.parent)


@dataclass
class Preload:
    """Quasi-static sliding state before the modal analysis (§4.3.1, first step)."""

    pressure: float          # Pa, hydraulic pressure (load of the last step)
    friction: float          # friction coefficient mu [-]
    normal_force: dict       # N, per interface name: integral of p_n
    friction_force: dict     # N, per interface name: resultant of mu p_n s (3-vector)
    load_force: dict         # N, per load face: p times the face area (its share of a force load)
    max_pressure: float      # Pa, largest per-facet mean contact pressure
    iterations: int          # Newton iterations of the last load step
    residuals: list          # residual norms of the last load step
    time: float              # s, wall time


NEWTON_FORCE_TOL = 1e-11    # absolute Newton tolerance relative to the applied force [-]


def preload(mech: Mechanics, pressure: float, steps: int = 1, reset: bool = True) -> Preload:
    """Ramp the load to ``pressure`` [Pa] (a force [N] for ``load_kind="force"``) in ``steps``
    Newton solves, from rest if ``reset``. The absolute residual tolerance is NEWTON_FORCE_TOL
    times the applied force: a re-solve from a nearly balanced state (``settle``) otherwise asks
    for a relative reduction below the round-off floor of the penalty-stiff system."""
    check_positive("pressure", pressure)
    t0 = time.perf_counter()
    tm, c = mech.tm, mech.contact
    area = {f: tm.assemble_scalar(1.0 * tm.ds(tm.face(f))) for f in tm.spec.load_faces}
    total = sum(area.values())
    loads = {f: float(pressure) * (a if mech.load_kind == "pressure" else a / total) for f, a in area.items()}
    snes = mech.problem.solver
    rtol, atol, stol, max_it = snes.getTolerances()
    snes.setTolerances(atol=max(atol, NEWTON_FORCE_TOL * sum(loads.values())))
    if reset:
        for u in mech.u:
            u.x.array[:] = 0.0
    solved = mech.ramp(pressure, steps)
    friction_traction = c.friction * c.pressure * c.slip_direction
    normal, tangential = {}, {}
    for name, dS in tm.interface.dS_tag.items():
        normal[name] = tm.assemble_scalar(c.pressure * dS)
        tangential[name] = np.array([tm.assemble_scalar(friction_traction[i] * dS) for i in range(3)])
    return Preload(float(pressure), float(c.friction.value), normal, tangential, loads,
                   solved.max_pressure, solved.iterations, list(solved.residuals),
                   time.perf_counter() - t0)


def linearise(mech: Mechanics, materials: Mapping[str, object]):
    """(K, M) at the current state: K the consistent tangent (``ufl.derivative`` of the residual,
    non-symmetric with friction; it is the Newton matrix, overwritten by the next solve), M the
    block-diagonal mass with density ``rho`` of each material and diag 0 on Dirichlet rows."""
    rho = body_fields(mech.tm, materials, "rho")
    form = fem.form(mech.mass_forms(rho), entity_maps=mech.tm.entity_maps)
    M = fpetsc.assemble_matrix(form, bcs=mech.bcs, diag=0.0)
    M.assemble()
    return mech.tangent(), M


class RegionEnergy:
    """Energy meter per material region of a DOLFINx model: 1/2 int sigma(x):eps(x) over each region."""

    def __init__(self, mech: Mechanics):
        self.mech = mech
        self.names, self._forms, self._work, self._sizes = [], [], [], []
        self._regions = []
        for i, body in enumerate(mech.tm.bodies):
            w = fem.Function(mech.spaces[i])
            sigma = ufl.replace(mech.stress(i), {mech.u[i]: w})
            Q = body.region_space
            q = ufl.TestFunction(Q)
            self._forms.append((fem.form(0.5 * ufl.inner(sigma, ufl.sym(ufl.grad(w))) * q * mech.dx(i),
                                         entity_maps=mech.tm.entity_maps), Q))
            self._work.append(w)
            dm = mech.spaces[i].dofmap
            self._sizes.append(dm.bs * dm.index_map.size_local)
            n_owned = body.mesh.topology.index_map(body.mesh.topology.dim).size_local
            cell_dofs = Q.dofmap.list[:n_owned, 0]
            for r in body.spec.regions:
                self.names.append(r.name)
                self._regions.append((i, cell_dofs[body.region_tags[:n_owned] == r.tag]))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        per_cell, start = [], 0
        for (form, Q), w, n in zip(self._forms, self._work, self._sizes):
            w.x.array[:n] = x[start:start + n]
            w.x.scatter_forward()
            start += n
            vec = fem.assemble_vector(form)
            vec.scatter_reverse(la.InsertMode.add)
            per_cell.append(vec.array)
        local = np.array([per_cell[i][dofs].sum() for i, dofs in self._regions])
        return self.mech.tm.comm.allreduce(local)


@dataclass
class SquealCase:
    """One case of the squeal study: preload, complex modes and their post-processing (§4.4)."""

    name: str
    preload: Preload
    modes: ModalResult
    report: StabilityReport
    energy: EnergyShares | None
    facet_pressure: np.ndarray      # Pa, per interface facet (global order of tm.interface)
    mech: Mechanics | None = field(default=None, repr=False)   # the model (spaces of the modes)


def squeal_case(mech: Mechanics, materials: Mapping[str, object], name: str = "case", *,
                pressure: float = 1e6, steps: int = 1, band=(0.0, 16e3), n_modes: int | None = None,
                target: float | None = None, damping: Damping | None = None, energy: bool = True,
                rtol: float = 1e-6, close_tol: float = 1e-3) -> SquealCase:
    """Preload, linearise and extract the complex modes of ``mech`` (§4.3.1, two steps)."""
    pre = preload(mech, pressure, steps)
    K, M = linearise(mech, materials)
    modes = solve_modes(K, M, f_min=band[0], f_max=band[1], n_modes=n_modes, target=target,
                        damping=damping)
    M.destroy()
    shares = strain_energy_shares(modes, RegionEnergy(mech)) if energy else None
    return SquealCase(name, pre, modes, stability_report(modes, rtol, close_tol), shares,
                      mech.contact.facet_pressure(), mech)


# --------------------------------------------------------------------------------------------
# Rough pad interfaces: per-zone homogenized laws embedded per facet (§4.2, §4.3.2, Table 4.1)
# --------------------------------------------------------------------------------------------
class LinearisedFacetLaw:
    """A per-facet pressure–gap law in the UFL contact form, by successive linearisation.

    The contact pressure is p_n = <p* + K* (g* − g_n)>_+ with per-facet DG0 fields (p*, K*, g*)
    [Pa, Pa/m, m]; ``linearise_at`` re-linearises each facet's true law (``law(g) -> (p_n, K_n)``
    and ``law.onset() -> (g_open, K_open)``, numpy over the global facets, e.g. ``FacetZoneLaws``)
    at its current mean gap. Repeated to convergence (``settle``) this is Newton's method on the
    facet laws: the state satisfies every law at its facet-mean gap and the Newton matrix holds
    the law's stiffness K_n = −dp_n/dg_n, the consistent tangent of the embedded interface
    (§4.2.1). An open facet (p_n = 0) is linearised at its first touch g_open with the secant
    stiffness of its first law node, so that it resists closing in the next solve instead of
    being pushed through (which would make the iteration cycle).
    Pass the object as ``law=`` to ``Mechanics``; gaps follow interface.py (g_n > 0 open).
    """

    def __init__(self, tm, law):
        self.tm, self.law = tm, law
        iface = tm.interface
        self.p_star = iface.field("law_pressure", 0.0)
        self.k_star = iface.field("law_stiffness", 0.0)
        self.g_star = iface.field("law_gap", 0.0)

    def __call__(self, g):
        lin = self.p_star("+") + self.k_star("+") * (self.g_star("+") - g)
        return ufl.conditional(ufl.gt(lin, 0), lin, 0)

    def mismatch(self, gap: np.ndarray) -> float:
        """Largest |p_affine − p_law| over the facets at the per-facet ``gap`` [m], in Pa."""
        iface = self.tm.interface
        gap = np.asarray(gap, dtype=float)
        affine = iface.values(self.p_star) + iface.values(self.k_star) * (iface.values(self.g_star) - gap)
        return float(np.abs(np.maximum(affine, 0.0) - self.law(gap)[0]).max(initial=0.0))

    def linearise_at(self, gap: np.ndarray) -> None:
        """Set (p*, K*, g*) from the laws at the per-facet ``gap`` [m]."""
        iface = self.tm.interface
        gap = np.asarray(gap, dtype=float)
        p, K = self.law(gap)
        g_open, K_open = self.law.onset()
        is_open = p <= 0
        star = (p, np.where(is_open, K_open, K), np.where(is_open, g_open, gap))
        for f, value in zip((self.p_star, self.k_star, self.g_star), star):
            iface.set_field(f, value)


@dataclass
class LawPreload(Preload):
    """``Preload`` of an interface with embedded laws (``time``: the whole settling), plus the
    linearisation history; the other fields are those of the last Newton solve."""

    law_iterations: int = 0            # re-linearisations until the laws held
    law_residuals: list = field(default_factory=list)   # Pa, max |p_affine − p_law| per iteration


def settle(mech: Mechanics, law: LinearisedFacetLaw, pressure: float, *, initial_gap: np.ndarray,
           steps: int = 1, rtol: float = 1e-6, max_iter: int = 40) -> LawPreload:
    """Preload with embedded facet laws: solve, re-linearise, until every law holds within
    ``rtol`` of the mean interface pressure. ``initial_gap`` [m] per facet: where the laws are
    first linearised (the macro gap field g_0 of the interface is set to it, u starts at rest).

    Newton on the facet laws; when the mismatch stops decreasing (a stiffening law makes facets
    overshoot back and forth) the next linearisation point is relaxed towards the previous one
    (factor halved, down to 1/32) and restored once the mismatch decreases again.
    """
    t0 = time.perf_counter()
    iface = mech.tm.interface
    g_lin = np.asarray(initial_gap, dtype=float)
    iface.set_field(mech.contact.initial_gap, g_lin)
    law.linearise_at(g_lin)
    pre = preload(mech, pressure, steps)
    scale = max(sum(pre.normal_force.values()) / iface.areas.sum(), np.finfo(float).tiny)
    history, omega = [], 1.0
    for it in range(1, max_iter + 1):
        gap = mech.contact.facet_gap()
        history.append(law.mismatch(gap))
        if history[-1] <= rtol * scale:
            # re-linearising at the solution moves no facet pressure by more than the tolerance;
            # the Newton matrix assembled next then holds the laws' stiffness
            law.linearise_at(gap)
            return LawPreload(**{**vars(pre), "time": time.perf_counter() - t0}, law_iterations=it,
                              law_residuals=history)
        if len(history) > 1:
            omega = min(1.0, 2 * omega) if history[-1] < 0.7 * history[-2] else max(omega / 2, 1 / 32)
        g_lin = g_lin + omega * (gap - g_lin)
        law.linearise_at(g_lin)
        pre = preload(mech, pressure, 1, reset=False)
    raise ConvergenceError(f"embedded interface laws did not settle in {max_iter} linearisations "
                           f"(max pressure mismatch {history[-1]:.3g} Pa)", history)


class FacetZoneLaws:
    """Per-facet view of zone laws: facet i follows the law of zone ``zone_ids[i]`` (§4.2.1).

    ``laws`` is a ``multiscale.micro.laws.ZoneLaws``; calling with per-facet gaps [m] returns
    (p_n [Pa], K_n [Pa/m]).
    """

    def __init__(self, laws, zone_ids: np.ndarray):
        self.laws, self.zone_ids = laws, np.asarray(zone_ids, dtype=int)

    def __call__(self, gap: np.ndarray):
        v = self.laws.pressure(np.asarray(gap, dtype=float), self.zone_ids)
        return v.pressure, v.stiffness

    def onset(self):
        """Per facet: first-touch gap g_open [m] and the secant stiffness to the first node [Pa/m]."""
        law = self.laws.mechanical
        rows = self.laws.rows(self.zone_ids)
        g_open = law.g_open[rows]
        return g_open, law.pressure[rows, 0] / (g_open - law.gap[rows, 0])


# R_q and sigma [m] of the pad surfaces of thesis Table 4.1 (case 0 roughest, case 5 smoothest)
TABLE_4_1 = {0: (11.8e-6, 5.5e-6), 1: (5.7e-6, 2.7e-6), 2: (4.9e-6, 2.3e-6), 3: (4.3e-6, 2.0e-6),
             4: (3.9e-6, 1.8e-6), 5: (3.5e-6, 1.6e-6)}


@dataclass(frozen=True)
class PadRoughness:
    """Rough pad faces of one case (§4.3.2): every interface gets its own fractal surface with the
    same statistics, cut into a grid of zones over its footprint in the (x, y) plane, one patch of
    ``grid`` x ``grid`` cells per zone (``zones.generate_zones``; cut-offs in wavelengths per zone).
    The counter-face (disc) is flat.
    """

    rms: float                       # m, R_q of each pad surface
    hurst: float = 0.8
    k_min: tuple = (1.0, 1.0)        # wavelengths per zone, (x, y)
    k_max: tuple = (8.0, 8.0)
    zones: tuple = (6, 3)            # zones over each pad's bounding box, (nx, ny)
    grid: int = 32                   # cells per zone side
    seed: int = 0

    def __post_init__(self):
        check_positive("rms", self.rms)


def interface_facets(tm) -> dict:
    """{interface name: boolean mask over the global interface facets}."""
    iface = tm.interface
    q = ufl.TestFunction(iface.space)
    out = {}
    for name, dS in iface.dS_tag.items():
        vec = fem.assemble_vector(fem.form(q("+") * dS, entity_maps=tm.entity_maps))
        vec.scatter_reverse(la.InsertMode.add)
        out[name] = iface.gather(vec.array[iface._owned_dofs()]) > 0
    return out


def rough_pad_laws(tm, roughness: PadRoughness, spec, pool=None) -> FacetZoneLaws:
    """Zone laws of every interface (pad) and the facet -> zone map (thesis §4.2, Table 4.1).

    ``spec``: ``multiscale.micro.laws.LawSpec`` (kernel of the pad on the flat disc, p_max,
    nodes); ``pool``: a ``multiscale.pool.MicroPool`` (default: one over the mesh communicator).
    Only zones that hold a facet midpoint are solved. Zone ids: 100000 k + grid id for pad k.
    """
    from multiscale.micro.zones import ZoneGrid, generate_zones
    from multiscale.pool import MicroPool

    pool = pool or MicroPool(spec, tm.comm)
    mid = tm.interface.midpoints
    zone_ids = np.full(len(mid), -1)
    zones = []
    for k, (name, mask) in enumerate(interface_facets(tm).items()):
        lo, hi = mid[mask, :2].min(axis=0), mid[mask, :2].max(axis=0)
        pad = 1e-9 + 1e-6 * (hi - lo).max()
        counts = tuple(int(c) for c in roughness.zones)
        grid = ZoneGrid(tuple(lo - pad), counts, tuple((hi - lo + 2 * pad) / np.array(counts)))
        local = grid.zone_of(mid[mask, 0], mid[mask, 1])
        zone_ids[mask] = 100000 * k + local
        used = set(local.tolist())
        for z in generate_zones(grid, roughness.grid, roughness.hurst, roughness.k_min, roughness.k_max,
                                roughness.rms, seed=roughness.seed + 7919 * k):
            if z.id in used:
                zones.append(replace(z, id=100000 * k + z.id))
    if np.any(zone_ids < 0):
        raise InputError("interface", "facets", "every interface facet must belong to an interface tag")
    return FacetZoneLaws(pool.laws(zones, spec, gather="own"), zone_ids)


def datum_gap(law: Callable, areas: np.ndarray, masks: Mapping[str, np.ndarray],
              mean_pressure: Mapping[str, float]) -> np.ndarray:
    """Per-facet initial gap: on each interface the constant gap G at which the area-weighted mean
    of the facet laws equals ``mean_pressure[name]`` [Pa] (a rigid pad's equilibrium; bisection)."""
    out = np.zeros(len(areas))
    for name, mask in masks.items():
        target = check_positive(f"mean_pressure[{name}]", mean_pressure[name])
        a = areas[mask] / areas[mask].sum()
        mean_p = lambda G: float(a @ law(np.full(len(areas), G))[0][mask])  # noqa: E731
        hi = 1e-3
        while mean_p(hi) > 0:
            hi *= 2
        lo = hi - 1e-6
        while mean_p(lo) < target:
            lo -= 2 * (hi - lo)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if mean_p(mid) > target else (lo, mid)
            if hi - lo <= 1e-12 * max(abs(hi), 1e-9):
                break
        out[mask] = 0.5 * (lo + hi)
    return out


# --------------------------------------------------------------------------------------------
# Scene-driven workflow (effects include "stability")
# --------------------------------------------------------------------------------------------
SQUEAL_DEGREE = 2     # quadratic tetrahedra: linear ones are far too stiff in bending (tests)


def mechanics_from_scene(scene, tm, *, law=None, degree: int = SQUEAL_DEGREE,
                         prefix: str = "squeal_") -> Mechanics:
    """The quasi-static sliding model of a scene: a fluid-pressure load for builders that declare
    ``FLUID_PRESSURE`` (the disc brake), the scene's force or pressure otherwise."""
    ld = scene.loading
    prefix = "".join(ch if ch.isalnum() else "_" for ch in prefix)
    kwargs = dict(friction=ld.friction if scene.has("friction") else 0.0, speed=ld.angular_speed(0.0),
                  stiffness=scene.interface.penalty or 0.0, law=law, degree=degree, prefix=prefix)
    if getattr(scene.geometry.module(), "FLUID_PRESSURE", False):
        if ld.pressure is None:
            raise InputError("loading.pressure", None, f'builder "{scene.geometry.builder}" is loaded by '
                             "the hydraulic pressure on its piston and caliper")
        return HydraulicMechanics(tm, dict(scene.materials), **kwargs)
    kind = "force" if ld.normal_force is not None else "pressure"
    return Mechanics(tm, dict(scene.materials), load_kind=kind, **kwargs)


def scene_roughness(scene) -> PadRoughness | None:
    """``PadRoughness`` of a scene with effect "roughness" ([roughness], [micro]); else None."""
    if not scene.has("roughness"):
        return None
    r, m = scene.roughness, scene.micro
    if r.rms is None:
        raise InputError("roughness.file", r.file, "the squeal analysis generates its zone patches "
                         "(give roughness.rms, hurst, k_min, k_max)")
    return PadRoughness(r.rms, r.hurst, tuple(r.k_min), tuple(r.k_max), tuple(m.zones), int(m.grid[0]),
                        r.seed)


def law_spec_for(materials, spec_p_max: float, n_points: int = 20):
    """``LawSpec`` of pads on a flat disc: E* of the pad and disc materials (§4.3.2: only the pads
    are rough), top node at ``spec_p_max`` [Pa]."""
    from multiscale.micro.kernels import HalfSpace
    from multiscale.micro.laws import LawSpec

    pad, disc = materials["pad"], materials["disc"]
    return LawSpec(HalfSpace.from_materials(pad.E, pad.nu, disc.E, disc.nu), p_max=spec_p_max,
                   n_points=n_points)


def analyse(scene, tm, *, name: str | None = None, roughness: PadRoughness | None = None,
            law_spec=None, energy: bool = True, degree: int = SQUEAL_DEGREE) -> SquealCase:
    """One squeal case of a scene on the mesh ``tm``: perfect penalty contact, or the embedded
    rough laws of ``roughness`` (default: the scene's [roughness]/[micro]) with ``law_spec``
    (default ``law_spec_for``: nodes per law from [micro], p_max 5 x the mean pad pressure)."""
    st_ = scene.stability
    materials = dict(scene.materials)
    roughness = roughness or scene_roughness(scene)
    pressure = scene.loading.pressure
    band = tuple(st_.band)
    damping = Damping(eta=st_.damping) if st_.damping else None
    name = name or scene.name
    if roughness is None:
        mech = mechanics_from_scene(scene, tm, degree=degree, prefix=f"squeal_{name}_")
        return squeal_case(mech, materials, name, pressure=pressure, steps=scene.loading.ramp_steps,
                           band=band, n_modes=st_.modes, target=st_.target, damping=damping, energy=energy)
    masks = interface_facets(tm)
    areas = tm.interface.areas
    load_area = {f: tm.assemble_scalar(1.0 * tm.ds(tm.face(f))) for f in tm.spec.load_faces}
    clamp = pressure * max(load_area.values())
    nominal = {k: clamp / areas[m].sum() for k, m in masks.items()}
    if law_spec is None:
        n_points = scene.micro.law_points if scene.micro is not None else 20
        law_spec = law_spec_for(materials, 5 * max(nominal.values()), n_points)
    laws = rough_pad_laws(tm, roughness, law_spec)
    law = LinearisedFacetLaw(tm, laws)
    mech = mechanics_from_scene(scene, tm, law=law, degree=degree, prefix=f"squeal_{name}_")
    pre = settle(mech, law, pressure, initial_gap=datum_gap(laws, areas, masks, nominal),
                 steps=scene.loading.ramp_steps)
    K, M = linearise(mech, materials)
    modes = solve_modes(K, M, f_min=band[0], f_max=band[1], n_modes=st_.modes, target=st_.target,
                        damping=damping)
    M.destroy()
    shares = strain_energy_shares(modes, RegionEnergy(mech)) if energy else None
    return SquealCase(name, pre, modes, stability_report(modes), shares, mech.contact.facet_pressure(), mech)


@dataclass
class SquealRun:
    """Where a scene's squeal analysis wrote its results."""

    folder: Path
    case: SquealCase
    files: list          # written paths
    wall_time: float     # s


def run_scene(scene, *, comm=None, overwrite: bool = False, verbose: bool = True,
              degree: int = SQUEAL_DEGREE) -> SquealRun:
    """``multiscale run`` for a scene whose effects include "stability" (thesis §4.3–4.4).

    Preload, complex modes and, in ``scene.output.folder``: ``modes.csv``, mode shapes
    (``modes_body*.xdmf``), ``pressure.png`` (Fig. 4.12), ``re_im.png`` (Fig. 4.13) and
    ``energy.png`` (Figs. 4.20–4.21).
    """
    from mpi4py import MPI

    from multiscale import io
    from multiscale.macro import mesh as two_body
    from multiscale.macro.runner import prepare_folder

    comm = comm or MPI.COMM_WORLD
    t0 = time.perf_counter()
    if not scene.has("stability"):
        raise InputError("effects", sorted(scene.effects), 'the squeal analysis needs effect "stability"')
    folder = prepare_folder(scene, overwrite, False, comm)
    io.abort_on_exception(comm)
    tm = two_body.build(scene.geometry.builder, dict(scene.geometry.params), comm)
    case = analyse(scene, tm, degree=degree)
    files = [case.modes.write_csv(folder / "modes.csv")] if comm.rank == 0 else []
    files += write_modes_xdmf(folder / "modes.xdmf", case.modes, case.mech.u)
    masks = interface_facets(tm)
    if comm.rank == 0:
        files += [plot_pressure(tm.interface.midpoints, masks, case, folder / "pressure.png"),
                  plot_re_im([case], folder / "re_im.png"),
                  plot_energy(case, folder / "energy.png")]
    comm.barrier()
    run = SquealRun(folder, case, files, time.perf_counter() - t0)
    if verbose and comm.rank == 0:
        rep = case.report
        print(f"{scene.name}: {len(case.modes)} modes up to {case.modes.frequency.max():.0f} Hz, "
              f"{rep.unstable.size} unstable ({', '.join(f'{f:.0f} Hz' for f in rep.frequency[rep.unstable - 1])}), "
              f"{rep.potentially_unstable.size} potentially unstable; {run.wall_time:.1f} s on {comm.size} rank(s)")
        print(f"  results: {folder}")
    return run


# --------------------------------------------------------------------------------------------
# Figures of §4.4 (rank 0; matplotlib with the Agg backend)
# --------------------------------------------------------------------------------------------
def _figure(*args, **kwargs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt, plt.subplots(*args, **kwargs)


def _save(plt, fig, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_pressure(midpoints: np.ndarray, masks: Mapping[str, np.ndarray], case: SquealCase, path) -> Path:
    """Contact pressure on each pad at the preloaded state (thesis Fig. 4.12) [MPa].

    ``midpoints`` (global interface facets) and ``masks`` (``interface_facets``, collective) are
    gathered beforehand, so that rank 0 alone can draw."""
    plt, (fig, axes) = _figure(1, len(masks), figsize=(5 * len(masks), 3.6), squeeze=False)
    mid, p = midpoints, case.facet_pressure / 1e6
    for ax, (name, mask) in zip(axes[0], masks.items()):
        art = ax.tricontourf(mid[mask, 0] * 1e3, mid[mask, 1] * 1e3, p[mask], levels=20, cmap="jet")
        fig.colorbar(art, ax=ax, label="contact pressure [MPa]")
        ax.set(title=f"{case.name}: {name}", xlabel="x [mm]", ylabel="y [mm]", aspect="equal")
    return _save(plt, fig, path)


def plot_re_im(cases: Sequence[SquealCase], path) -> Path:
    """Real part against imaginary part of the eigenvalues, one marker set per case (Fig. 4.13)."""
    plt, (fig, ax) = _figure(figsize=(8, 4.5))
    for c in cases:
        ax.plot(c.modes.frequency, c.modes.growth, "o", ms=3, label=c.name)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="imaginary part: frequency [Hz]", ylabel="real part sigma [1/s]",
           title="complex eigenvalues (sigma > 0: unstable)")
    ax.legend(fontsize=7)
    return _save(plt, fig, path)


def plot_energy(case: SquealCase, path) -> Path:
    """Strain-energy share of each component per mode (Fig. 4.20) and the pad split (Fig. 4.21)."""
    sh = case.energy
    plt, (fig, (a, b)) = _figure(2, 1, figsize=(9, 6), sharex=True)
    n = np.arange(1, len(case.modes) + 1)
    bottom = np.zeros(len(n))
    for j, name in enumerate(sh.names):
        a.bar(n, sh.share[:, j], bottom=bottom, label=name, width=0.9)
        bottom += sh.share[:, j]
    a.set(ylabel="strain-energy share [-]", title=f"{case.name}: strain energy per component")
    a.legend(fontsize=7, ncol=4)
    pads = [x for x in sh.names if x.startswith("pad")]
    if len(pads) == 2:
        b.bar(n, sh.split(*pads), width=0.9, label=f"{pads[0]} / ({pads[0]} + {pads[1]})")
        b.axhline(0.5, color="k", lw=0.5)
        b.legend(fontsize=7)
    for j in case.report.unstable:
        b.axvline(j, color="r", lw=0.8, ls=":")
    b.set(xlabel="mode number (red: unstable)", ylabel="share of the pads' energy [-]")
    return _save(plt, fig, path)

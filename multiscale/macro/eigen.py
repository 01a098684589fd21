"""Complex eigenvalues of a linearised sliding system with SLEPc (thesis §4.3.1).

Linearised about a steady sliding state, the free vibrations obey ``M u'' + C u' + K u = 0`` with
``K`` the tangent stiffness, non-symmetric because of the friction forces (§4.3.1). With
``u = phi exp(lambda t)`` the undamped problem is the generalised non-Hermitian eigenproblem (GNHEP)

    K phi = theta M phi,        lambda = sigma + i omega = i sqrt(theta)   (omega >= 0),

solved by shift-and-invert about ``theta_t = (2 pi f_t)^2`` (``solve_modes``). A real ``theta``
gives a neutrally stable mode; two modes that coalesce ("lock in") become a conjugate pair theta,
conj(theta): one mode with sigma > 0 (unstable, growth rate [1/s]) and one with sigma < 0, at the
same frequency. Damping proportional to the operators (``Damping``: Rayleigh alpha, beta;
structural loss factor eta) keeps the eigenvectors and maps each theta exactly to lambda; a general
damping matrix needs the quadratic eigenproblem (SLEPc PEP, ``solve_quadratic``).
``onset_of_instability`` bisects the friction coefficient at which a mode first goes unstable.

Vectors are kept as the rank-owned part of the PETSc layout (complex numpy arrays); inner products
are reduced over the matrix communicator (``reduce_sum``). Sign conventions: sigma > 0 is growth
(unstable), frequency = omega / (2 pi) [Hz] >= 0, modes are numbered from 1 in order of increasing
frequency (ties: increasing sigma).
"""
from __future__ import annotations

import csv
import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.macro import mumps
from multiscale.macro.dense import mat_mult

TWO_PI = 2.0 * math.pi
LOCKED = 1e-4    # relative frequency gap of a stable mode to an unstable one: a lock-in pair's halves (equal
                 # frequencies; split by 2e-5 by a pad's loss factor, ``damped.select``)
SPLIT = 1 / (4 * np.pi)   # a lock-in pair split by damping (~ eta sigma / 2 pi) lies within this x sigma [Hz]
# The first shift-and-invert solve asks at most this many pairs of a mode cap; more are asked only
# if the band holds more (a cap of 300 on the 20-mm brake's band of 71 modes took 51.6 s, asked at
# once, for 14.0 s at a cap of 100; a user trial).
FIRST_MODES = 101


def locked_window(frequency: float, sigma: float) -> float:
    """How far [Hz] the stable half of a lock-in pair may lie from its unstable half at ``frequency``
    [Hz] growing at ``sigma`` [1/s]: ``LOCKED`` of the frequency without damping (the halves share
    it), and ``SPLIT`` sigma with it: a loss factor eta splits the pair by the order of eta sigma / 2 pi (the
    car brake at eta = 0.01: 0.56 Hz at 4810 Hz, 1.2e-4 of it, sigma 201 1/s; both halves were left
    unpaired and the stable one flagged potentially unstable: an NVH trial)."""
    return max(LOCKED * frequency, SPLIT * abs(sigma))


def capped(lam: np.ndarray, ranked: np.ndarray, n_modes: int) -> np.ndarray:
    """The first ``n_modes`` of ``ranked`` (indices of eigenvalues ``lam`` [1/s], nearest the target
    first) and the others within ``locked_window`` of the last one's frequency (at the larger |sigma|
    of the two where one is unstable: damping lowers the unstable half's growth, not the split;
    at ``LOCKED`` of the frequency where both are stable): a lock-in pair, sigma +-, is never
    cut in two, also where gyroscopic or damping terms split it (0.034 Hz at 2680 Hz, 1.3e-5: a cap
    kept the stable member and dropped the unstable one, sigma +64 1/s, a user trial; a loss
    factor 1.2e-4, beyond the 1e-4 the cap allowed, a review). A doublet kept beyond the cap costs
    nothing."""
    kept, rest = ranked[:n_modes], ranked[n_modes:]
    if not kept.size:
        return kept
    f, last = lam.imag / TWO_PI, kept[-1]
    def split(i):                                   # [1/s]: the growth rates' share of the window
        return max(abs(lam[i].real), abs(lam[last].real)) if max(lam[i].real, lam[last].real) > 0 else 0.0
    near = [i for i in rest if abs(f[i] - f[last]) <= locked_window(abs(f[last]), split(i))]
    return np.concatenate([kept, np.asarray(near, dtype=kept.dtype)])


@dataclass
class ModalResult:
    """Complex modes of a linearised system, sorted by frequency.

    ``modes[:, j]`` is mode j (rank-owned entries of the PETSc layout), normalised to
    ``phi^H M phi = 1`` with the phase that makes ``phi^T phi`` real positive; with ``gram`` set,
    the reduced coordinates q of phi = V q in an M-orthonormal basis V instead (same on every rank).
    ``method``: "gnhep", "pep" or "projection".
    """

    eigenvalues: np.ndarray     # lambda = sigma + i omega [1/s], omega >= 0
    theta: np.ndarray           # eigenvalue of K phi = theta M phi [1/s^2] (= -lambda^2 undamped)
    modes: np.ndarray           # complex (n_owned, n_modes) [m per unit modal mass^(1/2)]
    errors: np.ndarray          # SLEPc relative residual of each pair [-]
    band: tuple[float, float]   # requested band (f_min, f_max) [Hz]
    target: float               # shift-and-invert target frequency [Hz]
    n_dofs: int                 # global problem size
    method: str                 # "gnhep", "pep" or "projection"
    iterations: int             # outer iterations of the last SLEPc solve
    solves: int                 # SLEPc solves (the band search may enlarge the subspace)
    time: float                 # wall time [s]
    comm: object = field(default=None, repr=False)   # mpi4py communicator of the modes (None: serial)
    gram: np.ndarray | None = field(default=None, repr=False)   # modes in reduced coordinates q of a
    #                                 basis V (``macro.damped.Subspace``): V^T V, for the MAC
    spurious: tuple = ()        # projection: frequencies [Hz] of the band's reduced eigenvalues left out,
    #                             their relative residual in the full model above ``damped.SPURIOUS``

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

    def write_csv(self, path: str | Path, rtol: float = 1e-6, potentially_unstable=(), energy=None,
                  partner=None, disc=None, body: str | None = None) -> Path:
        """Mode table: number, frequency [Hz], sigma [1/s], damping ratio, unstable flag, potentially
        unstable flag (mode numbers from 1, ``modal.StabilityReport``), the other half of a flutter
        pair (``partner``: its number per mode, 0 none; empty), residual; with ``energy``
        (``modal.EnergyShares``) each component's share of the mode's strain energy; with ``disc``
        (``nodal_diameters.DiscShapes`` of the rotating ``body``) its nodal diameters, their share,
        the out-of-plane share of its motion and the nodal diameters of its axial motion."""
        if (disc is None) != (body is None):
            raise InputError("body", body, "the rotating body's name with its disc shapes, none without")
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        close = set(int(m) for m in potentially_unstable)
        n_modes = len(self.frequency)
        names, shares = ([], np.zeros((n_modes, 0))) if energy is None else (energy.names, energy.share)
        shapes = np.zeros((n_modes, 0)) if disc is None else np.column_stack(
            [disc.nodal_diameters, disc.share, disc.out_of_plane, disc.axial_nodal_diameters])
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["mode", "frequency_Hz", "sigma_1_per_s", "damping_ratio", "unstable", "potentially_unstable",
                        "flutter_partner", "residual", *(f"energy_share_{n}" for n in names),
                        *([] if disc is None else [f"nodal_diameters_{body}", f"nodal_diameter_share_{body}",
                                                   f"out_of_plane_share_{body}",
                                                   f"out_of_plane_nodal_diameters_{body}"])])
            pairs = np.zeros(n_modes, int) if partner is None else partner
            for j, (fr, s, z, u, p, e, share, shape) in enumerate(zip(
                    self.frequency, self.growth, self.damping_ratio, self.unstable(rtol), pairs, self.errors, shares,
                    shapes), start=1):
                w.writerow([j, f"{fr:.6f}", f"{s + 0.0:.6e}", f"{z + 0.0:.6e}", int(u), int(j in close),
                            p or "", f"{e:.2e}", *(f"{v:.6f}" for v in share),      # no -0
                            *([f"{int(shape[0])}", f"{shape[1]:.3f}", f"{shape[2]:.3f}", f"{int(shape[3])}"]
                              if disc is not None else [])])
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


def check_band(f_min, f_max, target, n_modes):
    """(f_min, f_max, target) [Hz] checked (InputError), target None -> f_min."""
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


def _shift_invert(solver, target, tol, max_it, prefix):
    """Configure a SLEPc EPS or PEP: the eigenvalues nearest ``target`` by shift-and-invert through an
    LU factorisation (MUMPS when available), then the options under ``prefix``."""
    solver.setTarget(target)
    solver.setWhichEigenpairs(type(solver).Which.TARGET_MAGNITUDE)
    solver.setTolerances(tol, max_it)
    st = solver.getST()
    st.setType(SLEPc.ST.Type.SINVERT)
    ksp = st.getKSP()
    ksp.setType(PETSc.KSP.Type.PREONLY)
    pc = ksp.getPC()
    pc.setType(PETSc.PC.Type.LU)
    if PETSc.Sys.hasExternalPackage("mumps"):
        pc.setFactorSolverType("mumps")
    solver.setOptionsPrefix(prefix)
    solver.setFromOptions()


def _set_up(solver, want: int, failure: tuple) -> None:
    """Set a configured EPS or PEP up for ``want`` eigenpairs, its factorisation with a too-small
    MUMPS workspace retried (``macro.mumps``). ``failure``: (name, value, text) of the InputError
    raised when the shifted operator cannot be factorised."""
    solver.setDimensions(want, PETSc.DECIDE)
    pc = solver.getST().getKSP().getPC()
    try:
        try:
            solver.setUp()                     # the ST factorises (once); a failure raises
        except (PETSc.Error, SystemError):     # (slepc4py passes PETSc's error on as a SystemError)
            if mumps.status(pc) not in mumps.WORKSPACE_ERRORS:
                raise
            mumps.factorise(pc)
            solver.setUp()                     # the rest of the set-up, on the new factors
        failed = mumps.describe(pc)
    except (PETSc.Error, SystemError) as exc:
        failed = mumps.describe(pc) or str(exc.__cause__ or exc).strip()
    if failed:
        mumps.check_memory(pc, "the shifted operator")
        name, value, text = failure
        raise InputError(name, value, f"{text} [{failed}]")


def _pairs(solver, i, vr, vi):
    val = solver.getEigenpair(i, vr, vi)
    return complex(val), vr.getArray() + 1j * vi.getArray()


def _products(phi: np.ndarray, M, comm, other: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(phi^H M phi, phi'^T phi) of every column over all ranks, phi' = ``other`` (phi: phi^T phi;
    phi.conj(): phi^H phi)."""
    mphi = mat_apply(M, phi)
    gram = np.array([np.vdot(phi[:, j], mphi[:, j]).real for j in range(phi.shape[1])])
    sq = np.einsum("ij,ij->j", other, phi)
    gram, sq = reduce_sum(np.concatenate([gram, sq]), comm).reshape(2, -1)
    return gram.real, sq


def _normalise(phi: np.ndarray, M, comm) -> np.ndarray:
    """Scale columns to phi^H M phi = 1 and rotate so that phi^T phi is real positive."""
    gram, sq = _products(phi, M, comm, phi)
    scale = np.exp(-0.5j * np.angle(sq)) / np.sqrt(np.maximum(gram, np.finfo(float).tiny))
    return phi * scale


MASSLESS = 1e-9   # phi^H M phi below this share of phi^H phi max(diag M): a mode without mass


def _carry_mass(phi: np.ndarray, M, comm) -> np.ndarray:
    """True for the columns with mass. A support (K 1, C and M 0 on its row, as DOLFINx assembles
    them) adds an infinite eigenvalue to the quadratic problem, whose eigenvector has none: SLEPc
    returns it as a large real pair (+-3.4e8 on a 12-mass chain asked for all 24, quotient 2e-14),
    at 0 Hz, in every band. The least Rayleigh quotient of a consistent mass matrix is 0.07 (P1)
    and 0.05 (P2) of its largest diagonal on a uniform mesh, that times the ratio of the smallest
    to the largest cell volume on a graded one (above 1e-9 up to a 100-fold element size)."""
    gram, norm = _products(phi, M, comm, phi.conj())
    return gram > MASSLESS * M.getDiagonal().max()[1] * norm.real


def reduce_sum(a: np.ndarray, comm) -> np.ndarray:
    return a if comm is None else comm.allreduce(a)


def matrix_comm(A):
    """None in serial; otherwise a duplicate of the matrix communicator (it outlives the matrix)."""
    comm = A.getComm().tompi4py()
    return None if comm.size == 1 else comm.Dup()


def mat_apply(A, phi: np.ndarray) -> np.ndarray:
    """A @ phi for a real PETSc matrix and complex columns of owned entries."""
    k = phi.shape[1]
    out = mat_mult(A, np.hstack([phi.real, phi.imag]))
    return out[:, :k] + 1j * out[:, k:]


def by_frequency(lam: np.ndarray, rtol: float = 1e-9) -> np.ndarray:
    """Indices ordering eigenvalues by frequency, then growth rate; frequencies within ``rtol``
    relative count as equal, so that the members of a lock-in pair (sigma +-) are numbered stable
    first whatever the rounding (it differed between 1 and 2 ranks)."""
    order = np.lexsort((lam.real, lam.imag))
    f = lam.imag[order]
    group = np.concatenate([[0], np.cumsum(np.diff(f) > rtol * np.abs(f[1:]))])
    return order[np.lexsort((lam.real[order], group))]


def _sorted(lam, band, seen_f) -> np.ndarray:
    """The order of the modes by frequency then growth; none (an empty band) is an InputError.

    ``seen_f`` are the frequencies [Hz] of every converged eigenvalue (for the message).
    """
    if lam.size == 0:
        hint = (f"nearest found: {seen_f[np.argmin(np.minimum(abs(seen_f - band[0]), abs(seen_f - band[1])))]:.6g} Hz"
                if seen_f.size else "none found")
        raise InputError("f_max", band, f"no eigenvalue in this frequency band [Hz]; widen it ({hint})")
    return by_frequency(lam)


def solve_modes(K, M, **kw) -> ModalResult:
    """Modes with f_min <= f <= f_max [Hz] of K phi = theta M phi (GNHEP, shift-and-invert, §4.3.1):
    ``shift_invert_modes``' result, its factors freed."""
    with shift_invert_modes(K, M, **kw) as (result, _):
        return result


class TransposedSolve:
    """A PETSc python PC: the transposed solve of another KSP's factors (``solveTranspose``)."""

    def __init__(self, ksp: PETSc.KSP):
        self.ksp = ksp

    def apply(self, pc, x, y) -> None:
        self.ksp.solveTranspose(x, y)


@contextmanager
def shift_invert_modes(K, M, *, f_max: float = 16e3, f_min: float = 0.0, n_modes: int | None = None,
                       target: float | None = None, damping: Damping | None = None, tol: float = 1e-10,
                       max_it: int = 300, nev: int = 20, options_prefix: str = "stability_",
                       transpose_of: PETSc.KSP | None = None) -> Iterator[tuple[ModalResult, PETSc.KSP]]:
    """Modes with f_min <= f <= f_max [Hz] of K phi = theta M phi (GNHEP, shift-and-invert, §4.3.1)
    and, inside the block, the KSP of the shift-and-invert: its factors of K - theta_t M solve blocks
    both ways (``dense.block_solve``).

    ``K`` (tangent, may be non-symmetric) and ``M`` (mass, diag 0 on Dirichlet rows so that the
    constrained modes go to infinity) are assembled PETSc matrices. The shift is
    theta_t = (2 pi target)^2 (default target = f_min); K - theta_t M must be non-singular, so a
    free-free structure needs target > 0. Eigenvalues converge in order of |theta - theta_t|; the
    subspace grows (from ``nev``) until every theta with |theta - theta_t| <= max((2 pi f_max)^2 -
    theta_t, theta_t - (2 pi f_min)^2) is converged, i.e. the band is complete for modes with
    |sigma| << omega, or until ``n_modes`` band modes nearest the target are found (a cap; the
    conjugate partner of the last one is kept with it). ``transpose_of``: the KSP of this block for
    the transposed pencil (K^T, M) at the same band: its factors, solved transposed, invert
    K - theta_t M here, so that the left modes need no second factorisation. Raises InputError for a
    bad request or an empty band, ConvergenceError if SLEPc does not converge.
    """
    f_min, f_max, target = check_band(f_min, f_max, target, n_modes)
    t0 = time.perf_counter()
    comm = matrix_comm(K)
    n = K.getSize()[0]
    shift = (TWO_PI * target) ** 2
    radius = max((TWO_PI * f_max) ** 2 - shift, shift - (TWO_PI * f_min) ** 2)
    if n_modes is not None and n_modes > n:
        raise InputError("n_modes", n_modes, f"must not exceed the number of dofs ({n})")
    want = min(max(int(nev), min(int(n_modes or 0) + 1, FIRST_MODES)), n)   # + 1: the last mode's conjugate

    eps = SLEPc.EPS().create(K.getComm())
    vr, vi = K.createVecs()
    try:
        eps.setOperators(K, M)
        eps.setProblemType(SLEPc.EPS.ProblemType.GNHEP)
        eps.setType(SLEPc.EPS.Type.KRYLOVSCHUR)
        _shift_invert(eps, shift, tol, max_it, options_prefix)
        if transpose_of is not None:
            eps.getST().setMatMode(SLEPc.ST.MatMode.SHELL)     # K - theta_t M is never formed
            pc = eps.getST().getKSP().getPC()
            pc.setType(PETSc.PC.Type.PYTHON)
            pc.setPythonContext(TransposedSolve(transpose_of))
        failure = ("target", target, "K - (2 pi target)^2 M could not be factorised (singular at this shift? "
                                     "choose a target > 0 away from an eigenvalue)")
        solves = 0
        while True:
            _set_up(eps, want, failure)
            eps.solve()
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

        vecs = np.empty((vr.getLocalSize(), keep.size), dtype=complex)
        errs = np.empty(keep.size)
        vals = np.empty(keep.size, dtype=complex)
        for j, i in enumerate(keep):
            vals[j], vecs[:, j] = _pairs(eps, int(i), vr, vi)
            errs[j] = eps.computeError(int(i), SLEPc.EPS.ErrorType.RELATIVE)
        lam = lambda_from_theta(vals, damping)
        order = _sorted(lam, (f_min, f_max), lambda_from_theta(theta).imag / TWO_PI)
        result = ModalResult(lam[order], vals[order], _normalise(vecs[:, order], M, comm), errs[order],
                             (f_min, f_max), target, n, "gnhep", eps.getIterationNumber(), solves,
                             time.perf_counter() - t0, comm)
        yield result, eps.getST().getKSP()
    finally:
        eps.destroy(), vr.destroy(), vi.destroy()


def solve_quadratic(K, C, M, *, f_max: float = 16e3, f_min: float = 0.0, n_modes: int | None = 20,
                    target: float = 0.0, tol: float = 1e-10, max_it: int = 300, nev: int = 20,
                    options_prefix: str = "stability_pep_") -> ModalResult:
    """Damped modes of (lambda^2 M + lambda C + K) phi = 0 with a general damping matrix C (SLEPc PEP).

    Real arithmetic cannot shift at i omega; the shift is the real rate s = 2 pi target [1/s]
    (K + s C + s^2 M is non-singular for s > 0 even for a free-free structure) and eigenvalues
    converge in order of |lambda - s|, i.e. by frequency for light damping, from the lowest: a
    target or a band's lower edge does not reach the modes above the lowest ``n_modes`` (growing
    the subspace to reach them gave unconverged ones, residuals 1e-4, one marked unstable: an open
    defect, docs/squeal.md). ``n_modes`` counts modes with omega >= 0 (conjugate pairs are
    computed together; at most ``n_modes`` in the band, the nearest s, are returned, and the
    other member of a lock-in pair that the cap ends in, as ``solve_modes`` keeps it);
    ``n_modes=None`` asks for the
    whole band: the subspace grows until a converged |lambda - s| exceeds |i 2 pi f_max - s|.
    The result is filtered to the band. ``theta`` is reported as -lambda^2.
    """
    f_min, f_max, target = check_band(f_min, f_max, target, n_modes)
    t0 = time.perf_counter()
    comm = matrix_comm(K)
    n = K.getSize()[0]
    s = TWO_PI * target
    radius = abs(complex(-s, TWO_PI * f_max))
    pep = SLEPc.PEP().create(K.getComm())
    pep.setOperators([K, C, M])
    pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
    pep.setType(SLEPc.PEP.Type.TOAR)
    if comm is not None and comm.allreduce(K.getLocalSize()[0] == 0, op=MPI.LOR):
        pep.getBV().setType(SLEPc.BV.Type.VECS)     # the default BV's LAPACK fails on a rank without rows
    _shift_invert(pep, s, tol, max_it, options_prefix)
    want = min(2 * (int(n_modes) + 1 if n_modes is not None else max(nev, 1)), 2 * n)   # + 1: a lock-in partner
    solves = 0
    while True:
        _set_up(pep, want, ("target", target, "K + s C + s^2 M could not be factorised"))
        pep.solve()
        solves += 1
        nconv = pep.getConverged()
        if nconv < want:
            raise ConvergenceError(f"SLEPc PEP converged {nconv} of {want} eigenpairs",
                                   history=[pep.getIterationNumber()])
        reached = max(abs(pep.getEigenpair(i) - s) for i in range(nconv))
        if n_modes is not None or reached > radius or want >= 2 * n:
            break
        grow = (1.2 * radius / max(reached, 1e-300)) ** 3      # eigenvalue count ~ omega^3 in 3D
        want = min(2 * n, max(want + 20, int(math.ceil(want * min(grow, 8.0)))))
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
    inband = np.nonzero((seen >= f_min) & (seen <= f_max) & _carry_mass(vecs, M, comm))[0]
    if n_modes is not None:             # the n_modes nearest the shift, as they converge
        inband = capped(lam, inband[np.argsort(np.abs(lam[inband] - s), kind="stable")], int(n_modes))
    short = n_modes is not None and f_min > 0 and inband.size < n_modes and seen.size and seen.max() < f_max
    if short or (not inband.size and seen.size and seen.max() < f_min):   # (it said "widen it", nearest a spurious
        raise InputError("stability.modes", n_modes, f"the quadratic solver finds the lowest modes first: they "  # root)
                         f"reach {seen.max():.6g} Hz, {inband.size} of them in the band from {f_min:g} Hz; cover the "
                         'band from 0 Hz, or stability.method = "auto" projects on the band')
    order = inband[_sorted(lam[inband], (f_min, f_max), seen)]
    lam, vecs, errs = lam[order], vecs[:, order], errs[order]
    return ModalResult(lam, -lam ** 2, _normalise(vecs, M, comm), errs, (f_min, f_max), target, n,
                       "pep", iterations, solves, time.perf_counter() - t0, comm)


def onset_of_instability(build: Callable[[float], tuple], mu_lo: float, mu_hi: float, *,
                         xtol: float = 1e-9, rtol: float = 1e-6, solve: Callable | None = None,
                         **solve_kw) -> float:
    """Smallest friction coefficient in [mu_lo, mu_hi] with an unstable mode, by bisection.

    ``build(mu) -> (K, M)`` solved by ``solve_modes``, or any system that ``solve(system,
    **solve_kw) -> ModalResult`` takes (e.g. ``macro.damped.solve_system`` for damped systems);
    ``solve_kw`` go to the solver. Stable at mu_lo and unstable at mu_hi are required (InputError
    otherwise). Returns the onset mu [-] within ``xtol``.
    """
    mu_lo = check_positive("mu_lo", mu_lo, allow_zero=True)
    mu_hi = check_positive("mu_hi", mu_hi)
    if mu_hi <= mu_lo:
        raise InputError("mu_hi", mu_hi, f"must exceed mu_lo = {mu_lo}")

    def unstable(mu):
        system = build(mu)
        result = solve(system, **solve_kw) if solve is not None else solve_modes(*system, **solve_kw)
        return bool(result.unstable(rtol).any())

    if unstable(mu_lo):
        raise InputError("mu_lo", mu_lo, "the system is already unstable there")
    if not unstable(mu_hi):
        raise InputError("mu_hi", mu_hi, "the system is still stable there")
    while mu_hi - mu_lo > xtol:
        mid = 0.5 * (mu_lo + mu_hi)
        mu_lo, mu_hi = (mu_lo, mid) if unstable(mid) else (mid, mu_hi)
    return 0.5 * (mu_lo + mu_hi)

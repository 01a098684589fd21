"""Influence kernels of a solid's surface and their FFT convolution (thesis §3.3.1–3.3.3).

A ``Kernel`` gives the normal surface compliance of a solid: in Fourier space (periodic grids,
``compliance(q)``, thesis Eq. 3.8 ``w_z = F11(rho) tau_z``) and as influence coefficients of
piecewise-constant pressure on square cells (non-periodic grids, ``influence``, Eq. 3.2).
``InfluenceOperator`` applies ``u = L * p`` by FFT over the last two axes of batched arrays:
periodic (spectral kernel) or non-periodic (zero-padded DC-FFT, linear convolution exact).

Sign convention: pressure positive in compression, displacement positive into the solid.
"""
from __future__ import annotations

import functools
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import scipy.fft
from numba import njit

from multiscale.errors import InputError, check_positive, check_real
from multiscale.micro.fft import RealFFT2
from multiscale.references.love import love_rectangle


class Kernel(ABC):
    """Linear surface response of a solid to a surface load distribution.

    Elastic kernels: normal displacement [m] per normal pressure [Pa]. Thermal kernels: surface
    temperature rise [K] per surface heat flux [W/m²] (``thermal``: a kernel of one's own sets it
    True; the solvers refuse a kernel of the other kind). Responses are axisymmetric (isotropic
    solids), so the Fourier transfer function depends on |k| only.
    """

    thermal: ClassVar[bool] = False     # temperature per heat flux, not displacement per pressure

    @abstractmethod
    def compliance(self, q: np.ndarray) -> np.ndarray:
        """Fourier transfer function (response over load of one Fourier mode, e.g. û_z/p̂ [m/Pa] = 2/(E* q) on a half-space)
        at wavenumber modulus ``q`` [rad/m]. Where it is infinite (q = 0 on a half-space) it
        returns 0: a periodic patch then has a zero-mean response."""

    @abstractmethod
    def influence(self, ny: int, nx: int, dy: float, dx: float) -> np.ndarray:
        """Response at cell centres per unit load on the (dx × dy) cell at the origin.

        Returns the ``(2 ny, 2 nx)`` array in wrap-around order (offset ``i`` at index ``i``,
        offset ``-i`` at index ``2n - i``), ready for a zero-padded linear convolution.
        """

    def key(self) -> tuple:
        """Hashable identity (for caches of laws computed with this kernel)."""
        return (type(self).__name__,) + tuple(
            np.asarray(v).tobytes() if isinstance(v, np.ndarray) else v
            for v in vars(self).values())


@dataclass(frozen=True)
class HalfSpace(Kernel):
    """Homogeneous elastic half-space against a rigid flat (Boussinesq/Love, thesis §3.3.2).

    ``E_star`` is the composite modulus, 1/E* = (1-nu1²)/E1 + (1-nu2²)/E2; build it with
    ``HalfSpace.from_materials``.
    """

    E_star: float

    def __post_init__(self):
        object.__setattr__(self, "E_star", check_positive("E_star", self.E_star))

    @classmethod
    def from_materials(cls, E: float, nu: float, E2: float = np.inf, nu2: float = 0.0) -> "HalfSpace":
        """Composite modulus of a solid (E, nu) against a second one (E2, nu2; default: rigid,
        E2 = inf). Poisson ratios in (-1, 0.5]."""
        inv = (1 - poisson_ratio("nu", nu) ** 2) / check_positive("E", E)
        nu2 = poisson_ratio("nu2", nu2)
        if check_real("E2", E2) != np.inf:       # +inf: a rigid counter-face; nan, -inf, <= 0 refused
            inv += (1 - nu2**2) / check_positive("E2", E2)
        return cls(1.0 / inv)

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        with np.errstate(divide="ignore"):
            return np.where(q > 0, 2.0 / (self.E_star * np.where(q > 0, q, 1.0)), 0.0)

    def influence(self, ny, nx, dy, dx):
        return love_cells(ny, nx, dy, dx) / (np.pi * self.E_star)


@dataclass(frozen=True)
class Winkler(Kernel):
    """The solid ``base`` under a Winkler layer of compliance ``c`` [m/Pa]: each cell's own pressure
    moves it c p further (u = L p + c p). The implicit Archard step is a contact on it: the depth
    worn with the new pressure, c p (c = k_w mu ds), acts as such a layer (``post_analysis``)."""

    base: Kernel
    c: float

    def __post_init__(self):
        if not isinstance(self.base, Kernel):
            raise InputError("base", self.base, "must be a Kernel (e.g. HalfSpace)")
        object.__setattr__(self, "c", check_positive("c", self.c, allow_zero=True))

    def compliance(self, q):
        base = np.asarray(self.base.compliance(q), dtype=float)
        return np.where(base > 0, base + self.c, 0.0)      # (an infinite mode stays infinite, written 0)

    def influence(self, ny, nx, dy, dx):
        coeffs = np.array(self.base.influence(ny, nx, dy, dx), dtype=float)
        coeffs[0, 0] += self.c
        return coeffs


@dataclass(frozen=True)
class ThermalHalfSpace(Kernel):
    """Steady conduction in a homogeneous half-space of conductivity ``kappa`` [W/(m K)].

    Surface temperature rise per surface heat flux: point source T = Q/(2 pi kappa r), Fourier
    transfer 1/(kappa q) (thesis §5.3, homogeneous limit of F(rho)).
    """

    kappa: float
    thermal: ClassVar[bool] = True

    def __post_init__(self):
        object.__setattr__(self, "kappa", check_positive("kappa", self.kappa))

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        return np.where(q > 0, 1.0 / (self.kappa * np.where(q > 0, q, 1.0)), 0.0)

    def influence(self, ny, nx, dy, dx):
        return love_cells(ny, nx, dy, dx) / (2 * np.pi * self.kappa)


def poisson_ratio(name: str, value) -> float:
    nu = check_real(name, value)
    if not -1.0 < nu <= 0.5:
        raise InputError(name, value, "Poisson ratio must lie in (-1, 0.5]")
    return nu


def grid_shape(name: str, shape, minimum: int = 4) -> tuple[int, int]:
    """(ny, nx) of whole numbers >= ``minimum``, else ``InputError`` (no silent truncation)."""
    try:
        values = [v for v in shape]
    except TypeError:
        raise InputError(name, shape, "must be a pair (ny, nx) of whole numbers") from None
    if len(values) != 2 or any(isinstance(v, (str, bytes, bool, np.bool_)) or np.ndim(v) != 0 for v in values):
        raise InputError(name, shape, "must be a pair (ny, nx) of whole numbers")
    try:
        ints = [int(v) for v in values]
        exact = all(float(v) == i for v, i in zip(values, ints))
    except (TypeError, ValueError, OverflowError):
        raise InputError(name, shape, "must be a pair (ny, nx) of whole numbers") from None
    if not exact:
        raise InputError(name, shape, "grid sizes must be whole numbers")
    if min(ints) < minimum:
        raise InputError(name, shape, f"the grid needs at least {minimum} x {minimum} cells")
    return ints[0], ints[1]


@functools.lru_cache(maxsize=32)
def love_cells(ny: int, nx: int, dy: float, dx: float) -> np.ndarray:
    """Love's integral [m] over the (dx × dy) cell at the origin, at the centres of the (2 ny, 2 nx)
    wrap-around offsets (``wrap_offsets``): a half-space's influence coefficients times pi E*.
    Cached, read-only (the implicit wear step builds a solver per zone and update: 70 % of its
    set-up was this sum)."""
    ox = wrap_offsets(nx) * dx
    oy = wrap_offsets(ny) * dy
    out = love_rectangle(ox[None, :], oy[:, None], dx / 2, dy / 2)
    out.flags.writeable = False
    return out


def wrap_offsets(n: int) -> np.ndarray:
    """Cell offsets 0, 1, …, n-1, -n, …, -1 of a 2n zero-padded circular grid."""
    i = np.arange(2 * n)
    return np.where(i < n, i, i - 2 * n).astype(float)


def padded_size(n: int) -> int:
    """Half the FFT length along an axis of n cells of an isolated patch: the smallest 5-smooth
    m >= n (``scipy.fft.next_fast_len``). Any length >= 2n - 1 gives the same linear convolution
    on the patch (the kernel on (2m, 2m) wrap-around offsets, zero load beyond the patch), and
    FFTW's pair is 2-4x faster on 5-smooth lengths: 511² cells 8.2 ms on 1024² against 33.6 ms
    on 1022², 1017² 50.6 against 181.5 ms (benchmarks/README)."""
    return int(scipy.fft.next_fast_len(int(n), real=True))


def wavenumbers(ny: int, nx: int, dy: float, dx: float) -> np.ndarray:
    """|k| [rad/m] on the rfft2 grid of an (ny, nx) periodic patch with pixel (dy, dx)."""
    kx = 2 * np.pi * np.fft.rfftfreq(nx, dx)
    ky = 2 * np.pi * np.fft.fftfreq(ny, dy)
    return np.hypot(ky[:, None], kx[None, :])


def check_kernel(name: str, kernel, thermal: bool) -> Kernel:
    """``kernel`` if it is a ``Kernel`` of the kind asked (``thermal``: temperature per heat flux;
    else displacement per pressure), else an InputError naming ``name``: a ThermalHalfSpace taken
    for an elastic solid put a patch in full contact without a word (a user trial)."""
    kind = ("a thermal Kernel (temperature rise per heat flux, e.g. ThermalHalfSpace(kappa))" if thermal else
            "an elastic Kernel (displacement per pressure, e.g. HalfSpace(E_star))")
    if not isinstance(kernel, Kernel) or kernel.thermal != thermal:
        other = f"; this one is {'thermal' if kernel.thermal else 'elastic'}" if isinstance(kernel, Kernel) else ""
        raise InputError(name, kernel, f"must be {kind}{other}")
    return kernel


class InfluenceOperator:
    """``u = L * p`` on an (ny, nx) grid of pixel (dy, dx), over the last two axes.

    periodic=True: the patch repeats (spectral kernel, the mean displacement is the kernel's
    q = 0 value, zero for a half-space). periodic=False: an isolated patch (zero-padded DC-FFT
    with the kernel's influence coefficients) on the FFT grid (2 my, 2 mx), my >= ny and mx >= nx
    the next 5-smooth sizes (``padded_size``). FFT plans are built once per batch shape.

    ``spectrum`` (real: the kernels are even) is the transfer function on the FFT grid
    ``fft_shape``; ``inverse_spectrum`` its inverse where it is positive (0 elsewhere, e.g. at
    q = 0 of a periodic half-space): the FFT-based preconditioner M ≈ L⁻¹ of the contact solver.
    ``multiplier`` and ``inverse_multiplier`` include the 1/(Fy Fx) of the inverse FFT.
    ``least_compliance`` [m/Pa]: the smallest positive value of ``spectrum``, a lower bound of the
    eigenvalues of L on any set of cells (Cauchy interlacing; e.g. the stability bound of an
    explicit wear step, ``micro.wear.stable_substeps``).
    """

    def __init__(self, kernel: Kernel, shape: tuple[int, int], dx: float, dy: float | None = None,
                 periodic: bool = True):
        if not isinstance(kernel, Kernel):
            raise InputError("kernel", kernel, "must be a Kernel (e.g. HalfSpace)")
        if not isinstance(periodic, (bool, np.bool_)):
            raise InputError("periodic", periodic, "must be True or False")
        ny, nx = grid_shape("shape", shape)
        self.kernel, self.shape, self.periodic = kernel, (ny, nx), bool(periodic)
        self.dx = check_positive("dx", dx)
        self.dy = check_positive("dy", dy if dy is not None else dx)
        if self.periodic:
            self.fft_shape = (ny, nx)
            spectrum = np.asarray(kernel.compliance(wavenumbers(ny, nx, self.dy, self.dx)), float)
        else:
            my, mx = padded_size(ny), padded_size(nx)
            self.fft_shape = (2 * my, 2 * mx)
            coeffs = np.asarray(kernel.influence(my, mx, self.dy, self.dx), float)
            if coeffs.shape != self.fft_shape:
                raise InputError("kernel", kernel, f"influence() returned shape {coeffs.shape}, not {self.fft_shape}")
            spectrum = np.fft.rfft2(coeffs)
        if not np.all(np.isfinite(spectrum)):
            raise InputError("kernel", kernel, "produced non-finite influence coefficients")
        if np.iscomplexobj(spectrum):     # even coefficients: imaginary parts are round-off
            if np.max(np.abs(spectrum.imag), initial=0.0) <= 1e-9 * np.max(np.abs(spectrum), initial=0.0):
                spectrum = np.ascontiguousarray(spectrum.real)
        self.spectrum = spectrum
        size = self.fft_shape[0] * self.fft_shape[1]
        self.multiplier = self.spectrum / size
        real = np.real(self.spectrum)
        positive = real > 1e-12 * np.max(real, initial=0.0)
        self.inverse_spectrum = np.where(positive, 1.0 / np.where(positive, real, 1.0), 0.0)
        self.inverse_multiplier = self.inverse_spectrum / size
        self._workspaces: dict[tuple[int, ...], ConvolutionWorkspace] = {}
        self.self_influence = float(np.fft.irfft2(self.spectrum, s=self.fft_shape)[0, 0])
        self.least_compliance = float(np.min(real[positive]))   # m/Pa: 1 / the stiffest mode's stiffness

    def workspace(self, batch: tuple[int, ...] = (), threads: int | None = None,
                  single: bool = False) -> "ConvolutionWorkspace":
        """A new workspace of this operator for a batch shape (buffers owned by the caller;
        ``single``: in single precision, see ``RealFFT2``)."""
        return ConvolutionWorkspace(self, tuple(batch), threads, single)

    def __call__(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Displacement [m] of pressure ``p`` [Pa] of shape (..., ny, nx)."""
        p = np.asarray(p)
        if p.shape[-2:] != self.shape:
            raise InputError("pressure.shape", p.shape, f"last two axes must be {self.shape}")
        ws = self._workspaces.get(p.shape[:-2])
        if ws is None:
            ws = self._workspaces[p.shape[:-2]] = self.workspace(p.shape[:-2])
        ws.load[...] = p
        if out is None:
            out = np.empty(p.shape)
        out[...] = ws.apply()
        return out


class ConvolutionWorkspace:
    """FFT buffers and plans to apply an ``InfluenceOperator`` repeatedly without copies.

    Write the load into ``load`` (a (..., ny, nx) view of the FFT input; zero padding around it
    stays zero), call ``apply()``, read ``response`` (a view of the FFT output, overwritten by the
    next ``apply``). ``load_buffer``/``response_buffer`` are the whole (contiguous) buffers,
    padding included, and ``fft`` the plan (its ``spectrum`` buffer), for compiled loops. On a
    zero-padded grid the transforms skip the padding rows (``RealFFT2``'s ``rows``): the rows of
    ``load_buffer`` below the patch are not read, those of ``response_buffer`` not written.
    """

    def __init__(self, operator: InfluenceOperator, batch: tuple[int, ...], threads: int | None = None,
                 single: bool = False):
        ny, nx = operator.shape
        self.fft = RealFFT2(batch + operator.fft_shape, threads, single, rows=ny)   # zero padding: rows skipped
        self.multiplier = operator.multiplier
        self.load = self.fft.input[..., :ny, :nx]
        self.response = self.fft.output[..., :ny, :nx]
        self.load_buffer, self.response_buffer = self.fft.input, self.fft.output

    def apply(self, multiplier: np.ndarray | None = None) -> np.ndarray:
        """response = irfft2(multiplier * rfft2(load)); default multiplier: the operator's."""
        spectrum = self.fft.forward()
        multiply(spectrum.reshape((-1,) + spectrum.shape[-2:]), self.multiplier if multiplier is None else multiplier)
        self.fft.inverse(normalise=False)
        return self.response

    def clear(self) -> None:
        """Zero every buffer (after a failed solve, so that nothing of it leaks into the next)."""
        for a in (self.fft.input, self.fft.spectrum, self.fft.output):
            a[...] = 0.0


@njit(cache=True, nogil=True)
def multiply(S, m):
    """``S *= m`` in place: spectra S (B, Fy, Fh) times a real transfer function m (Fy, Fh) (2-3x
    faster than numpy's broadcast ``*=``, which converts m to complex on the way)."""
    B, Fy, Fh = S.shape
    for b in range(B):
        for i in range(Fy):
            for j in range(Fh):
                S[b, i, j] *= m[i, j]

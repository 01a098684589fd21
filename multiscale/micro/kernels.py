"""Influence kernels of a solid's surface and their FFT convolution (thesis §3.3.1–3.3.3).

A ``Kernel`` gives the normal surface compliance of a solid: in Fourier space (periodic grids,
``compliance(q)``, thesis Eq. 3.8 ``w_z = F11(rho) tau_z``) and as influence coefficients of
piecewise-constant pressure on square cells (non-periodic grids, ``influence``, Eq. 3.2).
``InfluenceOperator`` applies ``u = L * p`` by FFT over the last two axes of batched arrays:
periodic (spectral kernel) or non-periodic (zero-padded DC-FFT, linear convolution exact).

Sign convention: pressure positive in compression, displacement positive into the solid.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from multiscale.errors import InputError, check_positive
from multiscale.micro.fft import RealFFT2
from multiscale.references.love import love_rectangle


class Kernel(ABC):
    """Linear surface response of a solid to a surface load distribution.

    Elastic kernels: normal displacement [m] per normal pressure [Pa]. Thermal kernels: surface
    temperature rise [K] per surface heat flux [W/m²]. Responses are axisymmetric (isotropic
    solids), so the Fourier transfer function depends on |k| only.
    """

    @abstractmethod
    def compliance(self, q: np.ndarray) -> np.ndarray:
        """Fourier transfer function (response/load per unit wavenumber, e.g. û_z/p̂ [m/Pa·m])
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
        check_positive("E_star", self.E_star)

    @classmethod
    def from_materials(cls, E: float, nu: float, E2: float = np.inf, nu2: float = 0.0) -> "HalfSpace":
        """Composite modulus of a solid (E, nu) against a second one (default: rigid)."""
        check_positive("E", E)
        if not -1.0 < nu < 0.5:
            raise InputError("nu", nu, "Poisson ratio must lie in (-1, 0.5)")
        inv = (1 - nu**2) / E
        if np.isfinite(E2):
            check_positive("E2", E2)
            inv += (1 - nu2**2) / E2
        return cls(1.0 / inv)

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        with np.errstate(divide="ignore"):
            return np.where(q > 0, 2.0 / (self.E_star * np.where(q > 0, q, 1.0)), 0.0)

    def influence(self, ny, nx, dy, dx):
        ox = wrap_offsets(nx) * dx
        oy = wrap_offsets(ny) * dy
        return love_rectangle(ox[None, :], oy[:, None], dx / 2, dy / 2) / (np.pi * self.E_star)


@dataclass(frozen=True)
class ThermalHalfSpace(Kernel):
    """Steady conduction in a homogeneous half-space of conductivity ``kappa`` [W/(m K)].

    Surface temperature rise per surface heat flux: point source T = Q/(2 pi kappa r), Fourier
    transfer 1/(kappa q) (thesis §5.3, homogeneous limit of F(rho)).
    """

    kappa: float

    def __post_init__(self):
        check_positive("kappa", self.kappa)

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        return np.where(q > 0, 1.0 / (self.kappa * np.where(q > 0, q, 1.0)), 0.0)

    def influence(self, ny, nx, dy, dx):
        ox = wrap_offsets(nx) * dx
        oy = wrap_offsets(ny) * dy
        return love_rectangle(ox[None, :], oy[:, None], dx / 2, dy / 2) / (2 * np.pi * self.kappa)


def wrap_offsets(n: int) -> np.ndarray:
    """Cell offsets 0, 1, …, n-1, -n, …, -1 of a 2n zero-padded circular grid."""
    i = np.arange(2 * n)
    return np.where(i < n, i, i - 2 * n).astype(float)


def wavenumbers(ny: int, nx: int, dy: float, dx: float) -> np.ndarray:
    """|k| [rad/m] on the rfft2 grid of an (ny, nx) periodic patch with pixel (dy, dx)."""
    kx = 2 * np.pi * np.fft.rfftfreq(nx, dx)
    ky = 2 * np.pi * np.fft.fftfreq(ny, dy)
    return np.hypot(ky[:, None], kx[None, :])


class InfluenceOperator:
    """``u = L * p`` on an (ny, nx) grid of pixel (dy, dx), over the last two axes.

    periodic=True: the patch repeats (spectral kernel, the mean displacement is the kernel's
    q = 0 value, zero for a half-space). periodic=False: an isolated patch (zero-padded DC-FFT
    with the kernel's influence coefficients). FFT plans are built once per batch shape.
    """

    def __init__(self, kernel: Kernel, shape: tuple[int, int], dx: float, dy: float | None = None,
                 periodic: bool = True):
        ny, nx = (int(s) for s in shape)
        if ny < 4 or nx < 4:
            raise InputError("shape", shape, "the grid needs at least 4 x 4 cells")
        self.kernel, self.shape, self.periodic = kernel, (ny, nx), bool(periodic)
        self.dx = check_positive("dx", dx)
        self.dy = check_positive("dy", dy if dy is not None else dx)
        if self.periodic:
            self.fft_shape = (ny, nx)
            self.spectrum = np.asarray(kernel.compliance(wavenumbers(ny, nx, self.dy, self.dx)), float)
        else:
            self.fft_shape = (2 * ny, 2 * nx)
            coeffs = np.asarray(kernel.influence(ny, nx, self.dy, self.dx), float)
            self.spectrum = np.fft.rfft2(coeffs)
        if not np.all(np.isfinite(self.spectrum)):
            raise InputError("kernel", kernel, "produced non-finite influence coefficients")
        self._scaled_spectrum = self.spectrum / (self.fft_shape[0] * self.fft_shape[1])
        self._workspaces: dict[tuple[int, ...], ConvolutionWorkspace] = {}
        self.self_influence = float(np.fft.irfft2(self.spectrum, s=self.fft_shape)[0, 0])

    def workspace(self, batch: tuple[int, ...] = ()) -> "ConvolutionWorkspace":
        """A new workspace of this operator for a batch shape (buffers owned by the caller)."""
        return ConvolutionWorkspace(self, tuple(batch))

    def __call__(self, p: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Displacement [m] of pressure ``p`` [Pa] of shape (..., ny, nx)."""
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
    padding included, for compiled loops.
    """

    def __init__(self, operator: InfluenceOperator, batch: tuple[int, ...]):
        ny, nx = operator.shape
        self._plan = RealFFT2(batch + operator.fft_shape)
        self._multiplier = operator._scaled_spectrum
        self.load = self._plan.input[..., :ny, :nx]
        self.response = self._plan.output[..., :ny, :nx]
        self.load_buffer, self.response_buffer = self._plan.input, self._plan.output

    def apply(self) -> np.ndarray:
        self._plan.forward()
        self._plan.spectrum *= self._multiplier
        self._plan.inverse(normalise=False)
        return self.response

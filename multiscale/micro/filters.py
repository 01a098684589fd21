"""The areal Gaussian filter of ISO 16610-61 (the L-filter of a measured topography: waviness and
roughness at a cut-off wavelength λc) and its transmission; per axis, the anti-aliasing S-filter
of ``topography.resample``."""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, check_positive
from multiscale.micro.surface import Surface

ALPHA = np.sqrt(np.log(2) / np.pi)     # ISO 16610-21/-61 Gaussian: 50 % transmission at the cut-off
LONG_CUTOFF = 0.5    # λc beyond this share of the surface's shorter side: filtered in Fourier space


def gaussian_transmission(wavelength, cutoff: float) -> np.ndarray:
    """Amplitude transmission of the ISO 16610-61 areal Gaussian filter's mean surface (waviness)
    at a wavelength: exp(−π (α λc/λ)²), α = sqrt(ln 2/π) (50 % at λ = λc); the roughness keeps the
    rest, 1 − that."""
    return np.exp(-np.pi * (ALPHA * cutoff / np.asarray(wavelength, dtype=float)) ** 2)


def gaussian_filter(surface: Surface, cutoff: float) -> Surface:
    """The Gaussian mean surface (waviness) of ISO 16610-61 at the cut-off wavelength λc [m]:
    convolution with s(x, y) = exp(−π (x² + y²)/(α λc)²)/(α λc)², truncated at ±λc (where it has
    fallen to 7e-7 of its peak), so that a sinusoid of wavelength λ keeps
    ``gaussian_transmission(λ, λc)`` of its amplitude. Edges:
    periodic surfaces wrap, others are mirrored (one of the end-effect treatments of ISO 16610-28).
    SurfaceTopography filters periodic topographies in Fourier space only, hence this one."""
    check_cutoff("cutoff", cutoff, surface.dx, surface.dy)
    return gaussian_per_axis(surface, cutoff, cutoff)


def resolved(cutoff: float, dx: float, dy: float) -> bool:
    """Whether λc = ``cutoff`` [m] spans 2 pixels of dx x dy [m] (to 1e-9: the sizes are quotients)."""
    return cutoff >= 2 * max(dx, dy) * (1 - 1e-9)


def check_cutoff(name: str, cutoff: float, dx: float, dy: float, pixels: str = "", measured=None) -> None:
    """Raise ``InputError`` (naming ``name``) unless λc = ``cutoff`` [m] spans at least 2 pixels of
    dx x dy [m] (``pixels``: whose, for the message; to 1e-9, the sizes being quotients), or with
    ``measured`` (the measurement's size (mx, my) [m]) 2 of the micro grid's cells of dx x dy: the
    roughness the filter leaves, wavelengths below about λc, is finer than a coarser grid, whose
    surface would be nearly flat (a user trial: Sq 0.0003 of 0.0103 um; check warned of the
    gradient the grid missed, not of the cut-off)."""
    check_positive(name, cutoff)
    short = not resolved(cutoff, dx, dy)
    if short and measured is not None:
        fix = "a finer micro.grid or a longer cutoff" if 2 * max(dx, dy) <= min(measured) else \
            f"a finer micro.grid: 2 of its cells are longer than the measurement ({measured[0] * 1e6:.4g} x " \
            f"{measured[1] * 1e6:.4g} um)"
        raise InputError(name, None, f"λc = {cutoff * 1e6:.4g} um must span at least 2 cells of the micro grid "
                         f"({2e6 * max(dx, dy):.4g} um): the roughness the filter leaves is finer than the grid, whose "
                         f"surface would be nearly flat; use {fix}")
    if short:
        raise InputError(name, None, f"λc = {cutoff * 1e6:.4g} um must span at least 2 pixels "
                         f"({2e6 * max(dx, dy):.4g} um)" + (f": {pixels}'s pixels" if pixels else ""))


def gaussian_per_axis(surface: Surface, cut_x: float, cut_y: float) -> Surface:
    """``gaussian_filter`` with a cut-off per axis [m] (0: that axis unfiltered): the ISO filter
    (cut_x = cut_y) or the anti-aliasing S-filter of ``resample`` (its new pixel per axis)."""
    import scipy.ndimage  # ~0.4 s to import: only when a surface is filtered
    h = surface.heights
    ny, nx = h.shape[-2:]
    if max(cut_x, cut_y) > LONG_CUTOFF * min(ny * surface.dy, nx * surface.dx):
        return _fourier_filter(surface, cut_x, cut_y)
    sigma = ALPHA * np.array([cut_y, cut_x]) / np.sqrt(2 * np.pi)      # exp(-π x²/(αλc)²) = exp(-x²/(2σ²))
    axes = (h.ndim - 2, h.ndim - 1)
    w = scipy.ndimage.gaussian_filter(h, sigma=(sigma[0] / surface.dy, sigma[1] / surface.dx), axes=axes,
                                      mode="wrap" if surface.periodic else "mirror",
                                      truncate=np.sqrt(2 * np.pi) / ALPHA)      # at ±λc
    return Surface(w, surface.dx, surface.dy, periodic=surface.periodic)


def _fourier_filter(surface: Surface, cut_x: float, cut_y: float) -> Surface:
    """``gaussian_per_axis`` by its transmission in Fourier space, on the surface (periodic) or on its
    whole-sample mirror image (period 2n - 2 along each axis, the convolution's "mirror" edges): the
    cost does not grow with λc, whose kernel would be longer than the surface."""
    h = surface.heights
    ny, nx = h.shape[-2:]
    if not surface.periodic:
        h = np.concatenate([h, h[..., -2:0:-1, :]], axis=-2) if ny > 2 else h
        h = np.concatenate([h, h[..., -2:0:-1]], axis=-1) if nx > 2 else h
    qy = np.fft.fftfreq(h.shape[-2], d=surface.dy)[:, None]
    qx = np.fft.rfftfreq(h.shape[-1], d=surface.dx)[None, :]
    keep = np.exp(-np.pi * ALPHA ** 2 * ((cut_x * qx) ** 2 + (cut_y * qy) ** 2))   # gaussian_transmission per axis
    w = np.fft.irfft2(np.fft.rfft2(h) * keep, s=h.shape[-2:])[..., :ny, :nx]
    return Surface(w, surface.dx, surface.dy, periodic=surface.periodic)


def roughness_of(h: np.ndarray, dx: float, dy: float, cutoff: float) -> np.ndarray:
    """``h`` [m] (pixels ``dx`` x ``dy`` [m]) minus its Gaussian mean surface at λc = ``cutoff`` [m],
    the undefined points (NaN) left out of the means: the outliers of a map that is then filtered
    are judged against the Sq of its roughness (against the Sq before the filter, 4.5 times the
    roughness' on sur-2.sur at λc = 0.5 mm, its pits stayed: Sku 57; a user trial)."""
    defined = np.isfinite(h)
    means = [gaussian_filter(Surface(a, dx, dy, periodic=False), cutoff).heights
             for a in (np.where(defined, h, 0.0), defined.astype(float))]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(defined, h - means[0] / means[1], np.nan)

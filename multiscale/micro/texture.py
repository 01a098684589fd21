"""Spatial parameters of a rough surface (ISO 25178-2:2012 §4.2): the areal autocorrelation function,
its fastest decay length Sal, the texture aspect ratio Str, and the direction of its slowest decay
(the lay of a ground or turned surface).

f_ACF(t) = Σ z(x) z(x + t) / Σ z² over the pairs of points t apart, z the heights less their mean:
circular on a periodic patch, over the overlapping points of a measured one (zero-padded FFTs,
each lag normalised by its number of pairs, as SurfaceTopography's ``autocorrelation_from_area``
does for its height-difference form), out to half the patch. That map holds only lags with
non-negative components, which cannot tell a lay at 30° from one at 150°; hence this module. The decay to s (ISO's default
0.2) is searched along rays from the origin (cubic spline interpolation, every 0.5°) out to half the
patch along each axis, where a lag still has at least a quarter of the pairs.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft
from scipy.ndimage import map_coordinates, spline_filter

from multiscale.errors import InputError, check_real
from multiscale.micro.surface import Surface, check_surface, row_blocks

DECAY = 0.2          # ISO 25178-2's default threshold s of Sal and Str
ANGLES = 360         # rays over [0°, 180°) (the function is even: f(-t) = f(t))
STEPS = 4            # samples a pixel along each ray
MAX_POINTS = 2048 * 2048     # points of a map beyond which it is read at a stride


@dataclass(frozen=True)
class Texture:
    """Sal, Str and the lay of one patch. Along a direction where f_ACF stays above s out to half
    the patch (a lay longer than the measurement can tell), the longest decay is only known to
    exceed that reach: ``bounded`` is False and ``Str`` is then an upper bound (Sal over the reach)."""

    Sal: float            # m, shortest lag at which f_ACF falls to s (fastest decay)
    Str: float            # -, Sal over the longest such lag: 1 isotropic, -> 0 a strong lay
    lay: float            # degrees from the x axis towards y, in (-90, 90]: the longest correlation
    bounded: bool         # False: f_ACF stays above s out to half the patch along some direction
    threshold: float      # s
    stride: int = 1       # every stride-th point of a large map was read


def autocorrelation(surface: Surface) -> np.ndarray:
    """f_ACF of one patch at the lags of up to half its size: shape (2 (ny // 2) + 1, 2 (nx // 2) + 1),
    lag (ty, tx) pixels at index (ny // 2 + ty, nx // 2 + tx). Circular on a periodic patch; on a
    measured one over its overlapping points, zero-padded to n + n // 2 + 1 so no longer lag wraps
    onto these. Transforms in single precision (f_ACF to ~1e-6; 22 bytes a point at the peak, traced
    on 512 x 640 points, under ``spectrum.statistics_memory``'s 25)."""
    z = check_surface(surface).heights
    if z.ndim != 2:
        raise InputError("surface.heights", z.shape, "the autocorrelation of one 2-D patch at a time")
    mean = z.mean()
    power = float(np.sum([np.sum((z[rows] - mean) ** 2) for rows in row_blocks(*z.shape)]))
    if power == 0:
        raise InputError("surface", "flat", "a flat surface has no autocorrelation (its heights are all equal)")
    ny, nx = z.shape
    shape = (ny, nx) if surface.periodic else (ny + ny // 2 + 1, nx + nx // 2 + 1)
    spectrum = scipy.fft.rfft2((z - mean).astype(np.float32), s=shape)
    spectrum.real = spectrum.real ** 2 + spectrum.imag ** 2      # |F|^2 in place
    spectrum.imag = 0
    sums = scipy.fft.irfft2(spectrum, s=shape, overwrite_x=True)
    del spectrum
    ly, lx = np.arange(-(ny // 2), ny // 2 + 1), np.arange(-(nx // 2), nx // 2 + 1)
    acf = sums[np.ix_(ly % shape[0], lx % shape[1])].astype(np.float64)
    del sums
    acf /= power
    if not surface.periodic:                   # the mean over each lag's pairs
        acf *= ny / (ny - np.abs(ly))[:, None]
        acf *= nx / (nx - np.abs(lx))[None, :]
    return acf


def texture(surface: Surface, threshold: float = DECAY) -> Texture:
    """Sal, Str and the lay of one patch (ISO 25178-2 §4.2.1-4.2.2). The lay is the direction
    whose f_ACF has the largest integral out to half the patch's shorter side (its correlation
    length: the major axis of an elliptic f_ACF; it stands for ISO's Std, which takes the angular
    spectrum). A map of more than ``MAX_POINTS`` points is read every ``stride``-th point along
    both axes (the same f_ACF at the lags it keeps, from fewer pairs)."""
    threshold = check_real("threshold", threshold)
    if not 0 < threshold < 1:
        raise InputError("threshold", threshold, "must be between 0 and 1 (ISO's default 0.2)")
    ny, nx = check_surface(surface).shape
    stride = int(np.ceil(np.sqrt(nx * ny / MAX_POINTS)))
    if stride > 1:
        surface = Surface(surface.heights[..., ::stride, ::stride], surface.dx * stride, surface.dy * stride,
                          surface.periodic and nx % stride == 0 and ny % stride == 0)
        ny, nx = surface.shape
    coefficients = spline_filter(autocorrelation(surface), order=3, mode="nearest")   # cubic interpolation
    dx, dy = surface.dx, surface.dy
    theta = np.arange(ANGLES) * (np.pi / ANGLES)      # rad, from x towards y
    reach = np.empty(ANGLES)                          # m, to half the patch along each ray
    lag = np.empty(ANGLES)                            # m, where f_ACF falls to the threshold, else the reach
    area = np.empty(ANGLES)                           # the integral of f_ACF out to the shortest reach
    step = min(dx, dy) / STEPS
    for i, (c, s) in enumerate(zip(np.cos(theta), np.sin(theta))):
        reach[i] = min(0.5 * nx * dx / abs(c) if abs(c) > 1e-12 else np.inf,
                       0.5 * ny * dy / abs(s) if abs(s) > 1e-12 else np.inf)
        r = np.arange(0.0, reach[i] + 0.5 * step, step)
        f = map_coordinates(coefficients, [ny // 2 + s * r / dy, nx // 2 + c * r / dx], order=3, mode="nearest",
                            prefilter=False)
        area[i] = f[r <= 0.5 * min(nx * dx, ny * dy)].sum()
        k = int(np.argmax(f <= threshold))
        lag[i] = r[k - 1] + step * (f[k - 1] - threshold) / (f[k - 1] - f[k]) if k else reach[i]
    decays = lag < reach
    if not decays.any():
        raise InputError("surface", "undecayed", f"f_ACF stays above {threshold:g} out to half the patch in every "
                         "direction: no Sal (a form or waviness the detrending left, or a patch too small)")
    sal = float(lag[decays].min())
    lay = float(np.degrees(theta[int(np.argmax(area))]))
    return Texture(Sal=sal, Str=sal / float(lag.max()), lay=lay if lay <= 90 else lay - 180,
                   bounded=bool(decays.all()), threshold=threshold, stride=stride)

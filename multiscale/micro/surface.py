"""Rough surfaces: generation, import, statistics and asperity detection (thesis §1.3.1).

Heights ``h[..., ny, nx]`` [m], positive towards the counter-face; pixel sizes dx, dy [m];
row index ↔ y, column index ↔ x. Generated surfaces are periodic; imported ones are not.
"""
from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multiscale.errors import (InputError, check_count, check_field, check_flag, check_instance, check_positive,
                               check_real)
from multiscale.memory import beyond_limit

FRACTAL_BYTES = 29        # fractal_surface's least peak [bytes per point] (traced: 29-42 from 256² to 1024²)


@dataclass(frozen=True)
class Surface:
    """Topography of one patch or a batch of patches (leading axes)."""

    heights: np.ndarray   # m, (..., ny, nx)
    dx: float             # m, pixel size along x (columns)
    dy: float             # m, pixel size along y (rows)
    periodic: bool = True

    def __post_init__(self):
        if np.asarray(self.heights).dtype.kind == "b":     # (read as 1 m and 0 m: a user trial)
            raise InputError("heights", "array", "must be real numbers [m], not bool")
        h = check_field("heights", self.heights, min_ndim=2)
        if min(h.shape[-2:]) < 4:
            raise InputError("heights.shape", h.shape, "need a grid of at least 4 x 4 points")
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "dx", check_positive("dx", self.dx))
        object.__setattr__(self, "dy", check_positive("dy", self.dy))
        object.__setattr__(self, "periodic", check_flag("periodic", self.periodic))

    @property
    def shape(self) -> tuple[int, int]:
        return self.heights.shape[-2:]

    @property
    def size(self) -> tuple[float, float]:
        """(Lx, Ly) [m]."""
        return self.shape[1] * self.dx, self.shape[0] * self.dy

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Cell-centre coordinates x[nx], y[ny] [m], origin at the patch corner."""
        ny, nx = self.shape
        return (np.arange(nx) + 0.5) * self.dx, (np.arange(ny) + 0.5) * self.dy


def _pair(name: str, value) -> tuple[float, float]:
    v = check_field(name, value)
    if v.shape not in ((), (1,), (2,)) or np.any(v <= 0):
        raise InputError(name, value, "must be > 0 (a number, or a pair (x, y))")
    v = np.broadcast_to(v, (2,))
    return float(v[0]), float(v[1])


def fractal_surface(n, size, hurst: float, k_min, k_max, rms: float, seed: int = 0,
                    batch: tuple[int, ...] = ()) -> Surface:
    """Self-affine random surface with a power-law PSD S(q) ∝ |q|^(−2(H+1)) (Eqs. 1.24–1.25).

    n: grid points (n or (nx, ny)); size: patch size [m] (L or (Lx, Ly)); hurst: H in (0, 1];
    k_min, k_max: lower and upper cut-offs in wavelengths per patch (thesis Table 1.1 units),
    a number or a pair (kx, ky) for an anisotropic surface: the PSD is non-zero where
    (kx/kx_max)² + (ky/ky_max)² <= 1 and (kx/kx_min)² + (ky/ky_min)² >= 1.
    rms: RMS height [m] (each patch is scaled to it exactly); seed: random seed (a whole number
    >= 0 or a numpy SeedSequence); batch: leading shape of a batch of independent patches. Random
    phases uniform in [0, 2π) (Eq. 1.25), each wavevector q with the power of S(|q|) (the
    spectrum Hermitian, h real).
    """
    nx, ny = whole_numbers("n", n, 2)
    if min(nx, ny) < 4:
        raise InputError("n", n, "need at least 4 points per side")
    batch = whole_numbers("batch", batch, max(np.size(batch), 1)) if np.size(batch) or np.ndim(batch) == 0 else ()
    seed = check_seed(seed)
    Lx, Ly = _pair("size", size)
    if not 0 < check_real("hurst", hurst) <= 1:
        raise InputError("hurst", hurst, "Hurst exponent must lie in (0, 1]")
    kx_min, ky_min = _pair("k_min", k_min)
    kx_max, ky_max = _pair("k_max", k_max)
    if kx_max <= kx_min or ky_max <= ky_min:
        raise InputError("k_max", k_max, f"must exceed k_min = {k_min}")
    if kx_max > nx // 2 or ky_max > ny // 2:
        raise InputError("k_max", k_max, f"must not exceed the Nyquist index ({nx // 2}, {ny // 2})")
    if check_positive("rms", rms) > max(Lx, Ly):      # (6 for 6 um: an rms slope of 1.6e5, a user trial)
        warnings.warn(f"rms = {rms:g} m: taller than the patch is wide ({max(Lx, Ly):g} m); rms is in m (6 um: "
                      "6e-6)", UserWarning, stacklevel=2)
    need = FRACTAL_BYTES * nx * ny * int(np.prod(batch))
    if have := beyond_limit(need):                   # (200 000²: a raw MemoryError for 149 GiB, a user trial)
        raise InputError("n", n, f"{nx} x {ny} points{f' x {int(np.prod(batch))} patches' * bool(batch)} take about "
                         f"{need / 2**30:.3g} GiB to generate, more than the {have / 2**30:.3g} GiB this process may "
                         "use: fewer points (a coarser grid or a smaller patch)")
    kx = np.fft.rfftfreq(nx, 1.0 / nx)[None, :]
    ky = np.fft.fftfreq(ny, 1.0 / ny)[:, None]
    band = ((kx / kx_max) ** 2 + (ky / ky_max) ** 2 <= 1 + 1e-12) & \
           ((kx / kx_min) ** 2 + (ky / ky_min) ** 2 >= 1 - 1e-12)
    q = np.hypot(kx / Lx, ky / Ly)
    amplitude = np.where(band, np.where(q > 0, q, 1.0) ** (-(hurst + 1.0)), 0.0)
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0.0, 2 * np.pi, size=tuple(batch) + amplitude.shape)
    spectrum = amplitude * np.exp(1j * phase)
    # the columns kx = 0 (and nx/2) hold both q and -q: Hermitian along ky, their self-conjugate
    # points real; else irfft2 keeps the real part of their y-transform only, half their power
    # (an adversarial test: the kx = 0 line had 0.50 of the PSD's power)
    j = np.arange(1, (ny + 1) // 2)
    for c in [0] + ([nx // 2] if nx % 2 == 0 else []):
        spectrum[..., ny - j, c] = np.conj(spectrum[..., j, c])
        for r in [0] + ([ny // 2] if ny % 2 == 0 else []):
            spectrum[..., r, c] = amplitude[r, c] * np.sign(np.cos(phase[..., r, c]))
    h = np.fft.irfft2(spectrum, s=(ny, nx))
    h -= h.mean(axis=(-2, -1), keepdims=True)
    h *= rms / np.sqrt(np.mean(h**2, axis=(-2, -1), keepdims=True))
    return Surface(h, Lx / nx, Ly / ny, periodic=True)


def refine(surface: Surface, n) -> Surface:
    """The periodic ``surface`` on a finer grid of n (or (nx, ny)) >= its own points per side, the
    same size: its trigonometric interpolant (the Fourier series of its samples, a Nyquist term
    split evenly between +k and -k) sampled at the new cell centres. Exact for a
    band-limited surface such as ``fractal_surface``'s: the same surface sampled finer, e.g. for a
    grid-convergence study of a contact patch. Measured (non-periodic) surfaces: see
    ``topography.resample``."""
    s = check_surface(surface)
    if not s.periodic:
        raise InputError("surface", "non-periodic", "refine interpolates a periodic surface; a measured one "
                                                     "goes through topography.resample")
    ny0, nx0 = s.shape
    nx, ny = whole_numbers("n", n, 2)
    if nx < nx0 or ny < ny0:
        raise InputError("n", n, f"must be at least the surface's own grid ({nx0}, {ny0})")
    given = np.fft.rfft2(s.heights)
    ky, kx = np.fft.fftfreq(ny0, 1.0 / ny0).astype(int), np.arange(nx0 // 2 + 1)
    if ny > ny0 and ny0 % 2 == 0:                      # the Nyquist row: half at -ny0/2, half at +ny0/2
        given[..., ny0 // 2, :] *= 0.5
        given = np.concatenate([given, given[..., ny0 // 2:ny0 // 2 + 1, :]], axis=-2)
        ky = np.append(ky, ny0 // 2)
    if nx > nx0 and nx0 % 2 == 0:                      # the Nyquist column (its -nx0/2 twin is implied)
        given[..., nx0 // 2] *= 0.5
    # the new cell centres (i + 1/2) L/n lie (1/n - 1/n0) L/2 from the old ones (i + 1/2) L/n0
    shift = np.exp(1j * np.pi * (kx[None, :] * (1 / nx - 1 / nx0) + ky[:, None] * (1 / ny - 1 / ny0)))
    spectrum = np.zeros(s.heights.shape[:-2] + (ny, nx // 2 + 1), complex)
    spectrum[..., ky % ny, :kx.size] = given * shift
    h = np.fft.irfft2(spectrum, s=(ny, nx)) * (nx * ny / (nx0 * ny0))
    return Surface(h, s.dx * nx0 / nx, s.dy * ny0 / ny, periodic=True)


def whole_numbers(name: str, value, count: int) -> tuple[int, ...]:
    """``value`` (a number or ``count`` numbers) as whole numbers >= 1, else ``InputError`` (a float
    grid size used to be truncated)."""
    a = np.asarray(value, dtype=object) if not isinstance(value, (str, bytes)) else np.asarray([value], dtype=object)
    if a.ndim > 1 or a.size not in (1, count):
        raise InputError(name, value, f"must be one or {count} whole numbers")
    return tuple(check_count(name, v) for v in np.broadcast_to(a, (count,)))


def check_seed(seed):
    """A random seed: a whole number >= 0 (returned as int) or a numpy SeedSequence,
    BitGenerator or Generator (returned as is), else ``InputError``."""
    if isinstance(seed, (np.random.SeedSequence, np.random.BitGenerator, np.random.Generator)):
        return seed
    return check_count("seed", seed, minimum=0)


def read_matrix(path) -> np.ndarray:
    """The height matrix (rows ↔ y) of a .npy or .txt/.csv/.dat/.asc file, as stored (NaN kept)."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError("path", path, "a file name (str or Path)")
    path = Path(path)
    if not path.is_file():
        raise InputError("path", str(path), "no such file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            h = np.load(path, allow_pickle=False)
        elif suffix in (".txt", ".csv", ".dat", ".asc"):
            delimiter = "," if suffix == ".csv" else None
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)       # "input contained no data": checked below
                h = np.loadtxt(path, delimiter=delimiter, comments="#", ndmin=2)
        else:
            raise InputError("path", str(path), "expected .npy, .txt, .csv, .dat or .asc")
        if h.dtype.kind not in "iuf":
            raise InputError("path", str(path), f"heights must be real numbers, not {h.dtype} (an imaginary "
                             "part or a flag is no height)")
        h = np.asarray(h, dtype=float)
    except (ValueError, TypeError, OSError, EOFError) as exc:     # EOFError: an empty .npy
        if isinstance(exc, InputError):
            raise
        raise InputError("path", str(path), f"could not read a height matrix ({exc})") from None
    if h.ndim != 2:
        raise InputError("path", str(path), f"expected a 2-D height matrix, got shape {h.shape}")
    if min(h.shape) < 4:      # as reading.py says it of an instrument file's map (it said 2 x 2 here)
        raise InputError("path", str(path), f"the height matrix has {h.shape[1]} x {h.shape[0]} points: a height "
                         "map of at least 4 x 4 points is needed")
    return h


@dataclass(frozen=True)
class SurfaceStats:
    """Roughness statistics (per patch for batches). Profile moments are x/y averages."""

    rms_height: np.ndarray  #: m, sqrt(m0)
    rms_slope: np.ndarray   #: -, sqrt(<|grad h|²>), spectral or central differences (not Sdq's forward ones)
    m0: np.ndarray          #: m², <h²>
    m2: np.ndarray          #: -, (<h_x²> + <h_y²>)/2
    m4: np.ndarray          #: 1/m², (<h_xx²> + <h_yy²>)/2
    nayak: np.ndarray       #: -, m0 m4 / m2²


def row_blocks(rows: int, columns: int, size: int = 1 << 16):
    """Slices of ``rows`` of about ``size`` values each (``columns`` per row): row-block
    reductions need temporaries of a block, not of the map."""
    step = max(1, size // max(columns, 1))
    return (slice(a, min(a + step, rows)) for a in range(0, rows, step))


def defined_sums(h: np.ndarray, orders=(2,)) -> tuple[int, float, list]:
    """Count, mean [m] and the sums of |h - mean|^k for each k of ``orders`` over the defined
    (finite) heights of ``h`` (NaN: undefined), in row blocks (``row_blocks``)."""
    blocks = list(row_blocks(*h.shape))
    count, total = 0, 0.0
    for rows in blocks:
        d = h[rows][np.isfinite(h[rows])]
        count, total = count + d.size, total + d.sum()
    mean, sums = total / count, [0.0] * len(orders)
    for rows in blocks:
        c = np.abs(h[rows][np.isfinite(h[rows])] - mean)
        sums = [s + float(np.sum(c ** k)) for s, k in zip(sums, orders)]
    return count, mean, sums


def statistics(surface: Surface) -> SurfaceStats:
    """RMS height and slope, spectral moments m0, m2, m4 and Nayak's parameter.

    Periodic surfaces: exact spectral derivatives. Others: central finite differences (in row
    blocks: no temporaries of the map's size). The asperity models and κ take this slope. It is not
    ``spectrum.surface_statistics``' Sdq (SurfaceTopography's forward differences), which on a
    measured map with pixel-scale noise is larger: 0.0181 against 0.0146 on the shared opd-1 file.
    """
    check_surface(surface)
    dx, dy = surface.dx, surface.dy
    ny, nx = surface.shape
    mean = surface.heights.mean(axis=(-2, -1), keepdims=True)
    if surface.periodic:
        h = surface.heights - mean
        m0 = np.mean(h**2, axis=(-2, -1))
        H = np.fft.fft2(h) / (nx * ny)
        P = np.abs(H) ** 2
        qx = 2 * np.pi * np.fft.fftfreq(nx, dx)[None, :]
        qy = 2 * np.pi * np.fft.fftfreq(ny, dy)[:, None]
        m20, m02 = np.sum(P * qx**2, axis=(-2, -1)), np.sum(P * qy**2, axis=(-2, -1))
        m40, m04 = np.sum(P * qx**4, axis=(-2, -1)), np.sum(P * qy**4, axis=(-2, -1))
    else:
        sums = np.zeros((5,) + surface.heights.shape[:-2])     # h², hx², hy², hxx², hyy²
        for rows in row_blocks(ny, nx):
            h = surface.heights[..., rows, :] - mean
            v = surface.heights[..., rows.start:rows.stop + 2, :] - mean      # the block and two rows below
            hx, hxx = (h[..., 2:] - h[..., :-2]) / (2 * dx), (h[..., 2:] - 2 * h[..., 1:-1] + h[..., :-2]) / dx**2
            hy, hyy = ((v[..., 2:, :] - v[..., :-2, :]) / (2 * dy),
                       (v[..., 2:, :] - 2 * v[..., 1:-1, :] + v[..., :-2, :]) / dy**2)
            sums += [np.sum(d * d, axis=(-2, -1)) for d in (h, hx, hy, hxx, hyy)]
        counts = np.array([ny * nx, ny * (nx - 2), (ny - 2) * nx, ny * (nx - 2), (ny - 2) * nx])
        m0, m20, m02, m40, m04 = sums / counts.reshape((5,) + (1,) * (sums.ndim - 1))
    m2, m4 = (m20 + m02) / 2, (m40 + m04) / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        nayak = np.where(m2 > 0, m0 * m4 / np.where(m2 > 0, m2, 1) ** 2, np.inf)
    return SurfaceStats(np.sqrt(m0), np.sqrt(m20 + m02), m0, m2, m4, nayak[()])     # a scalar like the others


@dataclass(frozen=True)
class AsperityTable:
    """Summits of one patch, one entry per asperity (arrays of equal length).

    Principal radii R1 >= R2 > 0 [m] of the summit's curvature (R' and R'' of Eq. 1.2),
    ``angle`` [rad] of the R1 axis (the long semi-axis of the Hertz ellipse) from +x,
    equivalent radius R = sqrt(R1 R2), eccentricity e = sqrt(1 − (R2/R1)^(4/3)) (Eq. 1.2).
    """

    x: np.ndarray        # m, cell-centre coordinates of the summit
    y: np.ndarray        # m
    height: np.ndarray   # m
    R1: np.ndarray       # m
    R2: np.ndarray       # m
    angle: np.ndarray    # rad
    row: np.ndarray      # grid indices of the summit
    col: np.ndarray

    def __len__(self) -> int:
        return len(self.height)

    @property
    def radius(self) -> np.ndarray:
        return np.sqrt(self.R1 * self.R2)

    @property
    def eccentricity(self) -> np.ndarray:
        return np.sqrt(np.clip(1.0 - (self.R2 / self.R1) ** (4.0 / 3.0), 0.0, 1.0))


def check_surface(surface) -> Surface:
    """``surface`` if it is a ``Surface``, else ``InputError`` naming it."""
    return check_instance("surface", surface, Surface, "a multiscale.micro.surface.Surface")


def find_asperities(surface: Surface) -> AsperityTable:
    """Summits as strict 8-neighbour maxima with finite-difference Hessians (thesis §1.3.1).

    Principal radii are the inverse eigenvalues of −Hessian, directions its eigenvectors.
    Summits whose Hessian is not negative definite (a ridge or saddle-like maximum in the
    discrete sense) have no finite radii and are left out. Periodic surfaces wrap around;
    on others the border rows and columns are not candidates.
    """
    check_surface(surface)
    if surface.heights.ndim != 2:
        raise InputError("surface.heights", surface.heights.shape, "asperity detection takes one patch (2-D)")
    h, dx, dy = surface.heights, surface.dx, surface.dy
    (ny, nx), inner = h.shape, (slice(None),) * 2 if surface.periodic else (slice(1, -1),) * 2
    peak = np.zeros(h.shape, dtype=bool)
    peak[inner] = True
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di or dj:        # periodic: wrapped copies; others: views (border cells are never candidates)
                peak[inner] &= h[inner] > (np.roll(h, (-di, -dj), axis=(0, 1)) if surface.periodic else
                                           h[1 + di:ny - 1 + di, 1 + dj:nx - 1 + dj])
    r, c = np.nonzero(peak)
    del peak

    def nb(di, dj):
        """Heights of the summits' neighbours (the border wraps: only periodic summits reach it)."""
        return h[(r + di) % ny, (c + dj) % nx]
    hxx = (nb(0, 1) - 2 * h[r, c] + nb(0, -1)) / dx**2
    hyy = (nb(1, 0) - 2 * h[r, c] + nb(-1, 0)) / dy**2
    hxy = (nb(1, 1) - nb(1, -1) - nb(-1, 1) + nb(-1, -1)) / (4 * dx * dy)
    a, b, d = -hxx, -hxy, -hyy                              # curvature tensor K = −Hessian
    mean, dev = (a + d) / 2, np.sqrt(((a - d) / 2) ** 2 + b**2)
    k_small, k_large = mean - dev, mean + dev               # R1 = 1/k_small >= R2 = 1/k_large
    keep = k_small > 0
    r, c, a, b, d = r[keep], c[keep], a[keep], b[keep], d[keep]
    k_small, k_large = k_small[keep], k_large[keep]
    angle = 0.5 * np.arctan2(-2 * b, d - a)                 # eigenvector of k_small
    x, y = surface.coordinates()
    return AsperityTable(x=x[c], y=y[r], height=h[r, c], R1=1 / k_small, R2=1 / k_large,
                         angle=np.mod(angle, np.pi), row=r, col=c)

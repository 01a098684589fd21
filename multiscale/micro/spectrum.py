"""Power spectrum of a rough surface, its self-affine fit, statistically equivalent surfaces and the
areal roughness parameters (ISO 25178-2), computed through SurfaceTopography where it has them.

Conventions (Jacobs, Junge & Pastewka, Surf. Topogr. Metrol. Prop. 5 (2017) 013001): wavevector q
[rad/m]; the two-dimensional PSD C(q) = |h̃(q)|²/A with h̃ = Δx Δy Σ h e^(−i q·x), so that
<h²> = (2π)⁻² ∫ C(q) d²q; ``Spectrum`` holds the map C(q) and its radial average C_iso(q) [m⁴] in
logarithmic bins, those of SurfaceTopography's ``power_spectrum_from_area`` (to round-off): of the
patch itself if it is periodic, of its mirror-stitched double if it is measured (no window needed,
Parseval exact: see ``power_spectrum``; SurfaceTopography's Hann window on request), computed from
half or a quarter of the modes in row blocks.

A self-affine surface has C(q) ∝ q^(−2−2H) between a long-wavelength roll-off q_r (below it C is
flat, or zero for a band-limited surface) and a short-wavelength cut-off q_s (thesis Eqs. 1.24–1.25);
``fit_power_law`` finds H, q_r and q_s of a measured spectrum (SurfaceTopography fits none).
``equivalent_surface`` draws a random surface with the measured PSD itself (not only its fit, and
with its anisotropy) on any grid; ``surface_statistics`` gives Sq, Sdq, Ssk, Sku, Nayak's parameter, the summit
density, Sal, Str and the lay (``texture``) and both of the above.

SurfaceTopography stores heights as [x, y]; here they are [y, x] (``multiscale.micro.surface``):
``as_topography`` transposes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft

from multiscale.errors import InputError, check_count, check_field, check_instance, check_positive
from multiscale.micro.surface import Surface, check_surface, find_asperities, row_blocks, statistics
from multiscale.micro.texture import DECAY, Texture, texture

POWER_FLOOR = 1e-24     # modes below this fraction of the largest C carry no power (FFT round-off: ~1e-32)
HURST_RANGE = (0.0, 1.5)   # the power-law segment of a fit (a flat roll-off is no self-affine range)
LOW_HURST = 0.1            # a fit below this is said to be near noise (a scene's hurst is plausibly 0.1 to 1)
POOR_MISFIT = 1.0          # rms misfit in ln C above which a fit's H is said to be no more than a slope
FEW_BINS = 5               # bins below which too


def surface_topography():
    """The SurfaceTopography package, imported on first use: it takes about 2 s to load, which
    ``multiscale check`` and the commands that read no topography must not pay."""
    import SurfaceTopography  # heavy (~2 s to import): loaded when a topography is first analysed
    return SurfaceTopography


def make_grid(q_lo: float, q_hi: float, points_per_decade: int) -> np.ndarray:
    """Logarithmic bin edges [rad/m] from q_lo to q_hi (SurfaceTopography's, as its PSDs use)."""
    return surface_topography().Support.Regression.make_grid("log", q_lo, q_hi,
                                                             nb_points_per_decade=points_per_decade)[1]


def as_topography(surface: Surface, heights=None):
    """The surface as a SurfaceTopography ``Topography`` [m] (heights[x, y]); ``heights`` replaces
    the surface's own (a masked array keeps undefined points undefined)."""
    h = surface.heights if heights is None else heights
    if h.ndim != 2:
        raise InputError("surface.heights", h.shape, "one 2-D patch at a time")
    Lx, Ly = surface.size
    return surface_topography().Topography(h.T, (Lx, Ly), periodic=surface.periodic, unit="m")


# --------------------------------------------------------------------------- spectrum
@dataclass(frozen=True)
class Spectrum:
    """PSD of one patch: C(q) [m⁴] on the modes of its periodic grid (``grid`` (My, Mx) points of
    size ``period`` (Px, Py) [m]: the patch itself, or its mirror-stitched double, see
    ``power_spectrum``), and its radial average in logarithmic bins (bins holding modes only).

    ``power``: C on the modes that determine all others (C(−q) = C(q)): the half qx >= 0 (rfft2
    layout [y, x], Mx//2 + 1 columns) or, ``mirrored``, the quarter qx, qy >= 0 below Nyquist
    (My/2, Mx/2: the map is even in qx and in qy, its Nyquist modes vanish); ``map`` expands it.
    ``complete``: every mode of the bin carries power (False in the bins a band-limited surface
    fills only partly: fits and comparisons leave them out). ``band``: lowest and highest |q|
    carrying power; ``limits``: the grid's lowest |q|, 2π/max(Px, Py), and the top of the radial
    average, π/max(Δx, Δy).
    """

    q: np.ndarray          # rad/m, mean |q| of the bin's modes
    C: np.ndarray          # m^4, mean C(q) of the bin's modes
    edges: np.ndarray      # rad/m, (lower, upper) edge of each bin
    modes: np.ndarray      # number of modes in each bin (a bin's C scatters by about 1/sqrt(modes))
    complete: np.ndarray   # bool
    band: tuple[float, float]
    limits: tuple[float, float]
    power: np.ndarray      # m^4, the half or quarter of the map (above)
    period: tuple[float, float]
    grid: tuple[int, int]
    mirrored: bool

    @property
    def map(self) -> np.ndarray:
        """C [m⁴] at every mode, fft2 layout [y, x] (My, Mx); built on each call (32 bytes per
        measured point if mirror-stitched)."""
        (My, Mx), P = self.grid, self.power
        full = np.zeros((My, Mx))
        if self.mirrored:
            ny, nx = P.shape
            full[:ny, :nx] = P
            full[:ny, nx + 1:] = P[:, :0:-1]
            full[ny + 1:] = full[ny - 1:0:-1]
        else:
            full[:, :P.shape[1]] = P
            full[:, P.shape[1]:] = P[-np.arange(My) % My][:, Mx - np.arange(P.shape[1], Mx)]
        return full


def _radial_sums(power, qy, wy, qx, wx, edges, q_hi):
    """Per bin (SurfaceTopography's: edges[i-1] < |q| <= edges[i], index 0 and len(edges) beyond
    them): modes, Σ|q|, ΣC (all modes, as its radial average), modes inside 0 < |q| <= q_hi, those
    carrying power (C > ``POWER_FLOOR`` max C), and the band of these. ``power`` holds the first
    rows and columns of the modes (qy, qx) [rad/m], each standing for wy × wx modes (its mirror
    images); the modes beyond it (a mirror-stitched grid's Nyquist modes) have no power and count
    only in the average. Row blocks: no temporaries of the map's size."""
    n = len(edges) + 1
    sums = np.zeros((5, n))
    band = [np.inf, -np.inf]
    floor = POWER_FLOOR * power.max()
    for rows in row_blocks(len(qy), len(qx)):
        q = np.hypot(qy[rows, None], qx[None, :])
        w = wy[rows, None] * wx[None, :]
        C = np.zeros(q.shape)
        held = power[rows]
        C[:len(held), :power.shape[1]] = held
        which = np.searchsorted(edges, q)
        inside = (q > 0) & (q <= q_hi)
        inside[len(held):] = False
        inside[:, power.shape[1]:] = False
        on = inside & (C > floor)
        for i, values in enumerate((w, w * q, w * C)):
            sums[i] += np.bincount(which.ravel(), values.ravel(), minlength=n)
        sums[3] += np.bincount(which[inside], w[inside], minlength=n)
        sums[4] += np.bincount(which[on], w[on], minlength=n)
        if on.any():
            band = [min(band[0], q[on].min()), max(band[1], q[on].max())]
    return sums, band


def power_spectrum(surface: Surface, points_per_decade: int = 10, window: str | None = None,
                   edges=None) -> Spectrum:
    """PSD of one patch (Jacobs et al. 2017), ``points_per_decade`` bins per decade: the map and
    radial average of SurfaceTopography's ``power_spectrum_from_area`` (equal to round-off),
    computed without full-size temporaries.

    A periodic surface: its own periodogram (rfft2). A measured (non-periodic) one: by default the
    periodogram of its mirror-stitched double (SurfaceTopography ``mirror_stitch``: the patch and
    its three reflections, periodic and without steps at the borders), which needs no window, so
    that Parseval holds: (2π)⁻² Σ C Δq² is exactly Sq², and the finite-difference Sdq² is likewise
    the map's sum — what ``equivalent_surface`` needs to reproduce both. Its transform is the
    patch's DCT-II (|h̃| at qx, qy >= 0; scipy.fft.dctn): a quarter of the double's modes, real.
    ``window="hann"`` gives SurfaceTopography's default for non-periodic data instead (radial Hann
    window, <w²> = 1; it weights the middle of the patch and leaves the corners out). ``edges``:
    explicit bin edges [rad/m] instead (e.g. another spectrum's, to compare two surfaces bin by
    bin).
    """
    check_surface(surface)
    if surface.heights.ndim != 2:
        raise InputError("surface.heights", surface.heights.shape, "the spectrum of one 2-D patch at a time")
    points_per_decade = check_count("points_per_decade", points_per_decade, minimum=2)
    if not (window is None or isinstance(window, str) and window == "hann"):
        raise InputError("window", window, "None (mirror-stitched periodogram) or 'hann'")
    (ny, nx), (dx, dy) = surface.shape, (surface.dx, surface.dy)
    mirrored = not surface.periodic and window is None
    My, Mx = (2 * ny, 2 * nx) if mirrored else (ny, nx)
    Px, Py = Mx * dx, My * dy
    q_lo, q_hi = 2 * np.pi / max(Px, Py), np.pi / max(dx, dy)
    if edges is None:
        edges = make_grid(q_lo, q_hi, points_per_decade)
    edges = check_field("edges", edges)
    if edges.ndim != 1 or edges.size < 2 or np.any(edges <= 0) or np.any(np.diff(edges) <= 0):
        raise InputError("edges", edges, "bin edges [rad/m]: a 1-D increasing sequence of at least 2 values > 0")
    if mirrored:
        power = scipy.fft.dctn(surface.heights, type=2)       # |h̃| of the double at qx, qy >= 0
        power *= power
        rows, columns = np.arange(ny + 1), np.arange(nx + 1)     # with the (vanishing) Nyquist modes
    else:
        h = surface.heights if window is None else \
            as_topography(surface).window(window=window, direction="radial").heights().T
        transform = scipy.fft.rfft2(h)
        power = np.abs(transform)
        del transform
        power *= power
        rows, columns = np.fft.fftfreq(ny, 1 / ny), np.arange(nx // 2 + 1)
    power *= (dx * dy) ** 2 / (Px * Py)
    power[0, 0] = 0.0                                      # the mean (a window leaves some) is no roughness
    folded = 2.0 - (columns == 0) - (2 * columns == Mx)    # a mode with qx > 0 stands for its image at -qx
    weights_y = 2.0 - (rows == 0) - (2 * rows == My) if mirrored else np.ones(len(rows))
    (count, q_sum, C_sum, total, powered), band = _radial_sums(
        power, 2 * np.pi * rows / Py, weights_y, 2 * np.pi * columns / Px, folded, edges, q_hi)
    if not np.isfinite(band[0]):
        raise InputError("surface.heights", "flat", "the surface has no roughness (zero power spectrum)")
    inner = slice(1, len(edges))
    keep = (count[inner] > 0) & (total[inner] > 0)
    pairs = np.column_stack([edges[:-1], edges[1:]])
    return Spectrum((q_sum / np.maximum(count, 1))[inner][keep], (C_sum / np.maximum(count, 1))[inner][keep],
                    pairs[keep], total[inner][keep].astype(int), (powered == total)[inner][keep],
                    (float(band[0]), float(band[1])), (q_lo, q_hi), power, (float(Px), float(Py)), (My, Mx), mirrored)


# --------------------------------------------------------------------------- self-affine fit
@dataclass(frozen=True)
class PowerLaw:
    """C(q) = C_r for q < q_r, C_r (q/q_r)^(−2−2H) for q_r <= q <= q_s (thesis Eq. 1.24).

    ``resolved``: whether each cut-off lies inside the spectrum (a roll-off or band edge seen in
    the data); an unresolved one is the end of the measured range (the true cut-off lies beyond).
    ``misfit``: rms of ln(C/C_fit) over the ``bins`` bins of the power law.
    """

    hurst: float
    C_r: float              # m^4
    q_r: float              # rad/m
    q_s: float              # rad/m
    resolved: tuple[bool, bool]
    misfit: float
    bins: int

    @property
    def wavelengths(self) -> tuple[float, float]:
        """Long and short cut-off wavelengths λ_r = 2π/q_r, λ_s = 2π/q_s [m]."""
        return 2 * np.pi / self.q_r, 2 * np.pi / self.q_s

    def __call__(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        return self.C_r * (np.clip(q, self.q_r, None) / self.q_r) ** (-2 - 2 * self.hurst)


def fit_power_law(spectrum: Spectrum, step: float = 0.02, noise: float = 0.05, full_weight: int = 100) -> PowerLaw:
    """Hurst exponent and cut-offs of a spectrum: a broken line in log-log, flat below ln q_r (the
    roll-off), slope −2−2H up to ln q_s, then a line of its own (the instrument's drop, a band
    limit's cliff or a noise floor: not continuous with the power law).

    Weighted least squares on ln C: a bin of fewer than ``full_weight`` modes weighs
    modes/``full_weight`` (the mean of few modes scatters by about 1/sqrt(modes)). Each breakpoint
    is searched on a grid of ``step`` in ln q; the power law spans at least 3 bins and no fewer
    than the tail, a breakpoint has 0 or >= 2 bins beyond it, and the bin straddling q_s (within
    half a bin of it: it holds modes of both sides) counts as a misfit σ. The fit of each kind
    (line; roll-off + line; line + tail; all three; k = 2 per segment) is scored by the Bayesian
    information criterion n ln((SSE + Σw σ²)/n) + k ln n (σ = ``noise``, the scatter of ln C below
    which differences do not count), and the lowest score wins: a cut-off is reported only when
    the data show it. The power law's H must lie in ``HURST_RANGE`` (else a flat roll-off followed
    by the power law could pass for a "power law" of H = −1 and a "tail"), unless no breakpoints
    give one. Only complete bins enter (see ``Spectrum``); the edges of a band-limited spectrum (no
    power below or above on the grid) are its cut-offs. An unresolved cut-off is the end of the
    data (the true one lies beyond). SurfaceTopography generates self-affine surfaces but fits
    none, hence this fit.
    """
    check_instance("spectrum", spectrum, Spectrum, "a Spectrum (power_spectrum)")
    step = check_positive("step", step)
    noise = check_positive("noise", noise)
    full_weight = check_count("full_weight", full_weight)
    x, y = np.log(spectrum.q[spectrum.complete]), np.log(spectrum.C[spectrum.complete])
    w = np.minimum(spectrum.modes[spectrum.complete] / full_weight, 1.0)      # few modes: a noisy mean
    n = len(x)
    if n < 4:
        raise InputError("spectrum", f"{n} complete bins", "need at least 4 bins to fit a power law")
    grid = np.concatenate([[x[0]], np.arange(x[0] + step, x[-1], step), [x[-1]]])
    gap = float(np.median(np.log(spectrum.edges[:, 1] / spectrum.edges[:, 0])))     # one bin

    def evaluate(xr, xs):
        """Score, coefficients and bin roles of the breakpoint pairs (xr, xs) (inf: not allowed)."""
        X = x[None, :]
        cut = xs < x[-1]                                            # a short cut-off inside the data
        straddle = cut[:, None] & (np.abs(X - xs[:, None]) < gap / 2)   # the bin(s) at the cut-off itself
        tail = cut[:, None] & (X > xs[:, None]) & ~straddle
        law = ~tail & ~straddle
        below, above = (law & (X < xr[:, None])).sum(axis=1), tail.sum(axis=1)
        span = (law & (X >= xr[:, None])).sum(axis=1)
        ok = (span >= 3) & (span >= above) & (below != 1) & np.where(cut, above >= 2, True)
        B = np.stack([law, np.where(law, np.clip(X, xr[:, None], xs[:, None]) - xr[:, None], 0.0),
                      tail, np.where(tail, X - xs[:, None], 0.0)], axis=2).astype(float)   # (pairs, bins, 4)
        normal = np.einsum("pbi,pbj,b->pij", B, B, w) + 1e-12 * np.eye(4)
        coef = np.linalg.solve(normal, np.einsum("pbi,b->pi", B, w * y)[..., None])[..., 0]
        residual = np.where(straddle, 0.0, np.einsum("pbi,pi->pb", B, coef) - y)
        sse = (w * residual**2).sum(axis=1) + (straddle * w).sum(axis=1) * noise**2   # a straddling bin: σ²
        k = 2 + 2 * (below > 0) + 2 * cut
        score = n * np.log((sse + w.sum() * noise**2) / n) + k * np.log(n)
        hurst = -coef[:, 1] / 2 - 1
        self_affine = (hurst >= HURST_RANGE[0]) & (hurst <= HURST_RANGE[1])
        return np.where(ok, score, np.inf), self_affine, coef, (below > 0, cut, law)

    best = {True: (np.inf, 0.0, 0.0), False: (np.inf, 0.0, 0.0)}    # self-affine or not: (score, xr, xs)
    for xr in grid[:-1]:                                            # one roll-off at a time: small arrays
        xs = grid[grid > xr]
        score, self_affine, _, _ = evaluate(np.full(len(xs), xr), xs)
        for kind in (True, False):
            values = np.where(self_affine == kind, score, np.inf)
            i = int(np.argmin(values))
            best[kind] = min(best[kind], (values[i], xr, xs[i]))
    score, lo, hi = best[True] if np.isfinite(best[True][0]) else best[False]
    if not np.isfinite(score):
        raise InputError("spectrum", f"{n} complete bins", "no broken power law fits them")
    _, _, coef, (has_roll_off, has_cut, law) = evaluate(np.array([lo]), np.array([hi]))
    a, slope = coef[0][:2]
    resolved = [bool(has_roll_off[0]), bool(has_cut[0])]
    q_r = float(np.exp(lo))
    q_s = float(np.exp(hi))
    # a band-limited spectrum: its edges are the cut-offs (no power beyond them on the grid)
    if not resolved[0] and spectrum.band[0] > spectrum.limits[0] * 1.5:
        q_r, resolved[0] = spectrum.band[0], True
    if not resolved[1] and spectrum.band[1] < spectrum.limits[1] / 1.5:
        q_s, resolved[1] = spectrum.band[1], True
    inside = law[0] & (x >= lo)
    misfit = float(np.sqrt(np.mean((a + slope * (x[inside] - lo) - y[inside]) ** 2)))
    C_r = float(np.exp(a + slope * (np.log(q_r) - lo)))
    return PowerLaw(float(-slope / 2 - 1), C_r, q_r, q_s, tuple(resolved), misfit, int(inside.sum()))


# --------------------------------------------------------------------------- equivalent surfaces
def _wavevectors(shape, period) -> tuple[np.ndarray, np.ndarray]:
    """qx, qy [rad/m] of the modes of a periodic grid (fft2 layout [y, x])."""
    (ny, nx), (Px, Py) = shape, period
    return (2 * np.pi * np.fft.fftfreq(nx, Px / nx)[None, :].repeat(ny, 0),
            2 * np.pi * np.fft.fftfreq(ny, Py / ny)[:, None].repeat(nx, 1))


def _regroup(power, spread, sectors, edges, q_lowest) -> np.ndarray:
    """Power per cell moved where the new grid has modes: a cell without any gives its power to the
    other cells of its ring (in proportion to theirs), a ring without any (new modes sparser than
    the measured ones) to the nearest ring that has some — so that the total is kept, except for
    rings of wavelengths longer than the new grid (``q_lowest``: its lowest |q|), which are lost."""
    rings = np.repeat(np.arange(len(sectors)), sectors)
    n = len(sectors)
    has = np.bincount(rings, spread > 0, minlength=n) > 0
    if not has.any():
        return np.zeros_like(power)
    upper = np.concatenate([edges, [np.inf]])[:n]            # ring i holds edges[i-1] < |q| <= edges[i]
    lost = (spread == 0) & (power > 0) & (upper[rings] >= q_lowest)
    moved = np.bincount(rings, np.where(lost, power, 0.0), minlength=n)
    populated = np.nonzero(has)[0]
    target = populated[np.abs(np.arange(n)[:, None] - populated[None, :]).argmin(axis=1)]
    gain = np.bincount(target, moved, minlength=n)
    kept = np.where(spread > 0, power, 0.0)
    weight = np.where(np.bincount(rings, kept, minlength=n)[rings] > 0, kept, np.where(spread > 0, spread, 0.0))
    total = np.bincount(rings, weight, minlength=n)[rings]
    return kept + gain[rings] * np.divide(weight, total, out=np.zeros_like(weight), where=total > 0)


def equivalent_surface(spectrum: Spectrum, n, size, seed=0, *, amplitudes: str = "constant",
                       modes_per_sector: int = 8) -> Surface:
    """A random surface of n = (nx, ny) points over size = (Lx, Ly) [m] with the measured PSD
    (the map itself, with its anisotropy, not a power-law fit).

    q-space is cut into cells: the spectrum's logarithmic bins (continued to the corners of the
    grids) split into angular sectors of [0, π) centred on the axes (as many as the ring's measured
    modes allow, at least ``modes_per_sector`` each, a power of 2 up to 32). Each cell keeps the measured power
    (2π)⁻² Σ C Δq² of its modes, spread over the new grid's modes in it along the shape of the
    ring-averaged C(|q|) (log-log interpolated): so the new surface has the measured power in every
    ring and direction on any grid, whatever its mode spacing, and within a ring the measured
    distribution over |q| (a cell or ring the new grid has no mode in passes its power on to its
    neighbours). Only the wavevectors both grids hold enter: wavelengths longer than the measured
    period or the new grid and shorter than either grid's pixels get no power (none is invented;
    the long ones are the macro model's form). On the measurement's pixel size and at least its
    mirror-stitched size the result has its Sq and Sdq (``power_spectrum`` is exact for both);
    a coarser grid loses the modes above its Nyquist wavenumber.

    Fourier synthesis (Ramisetti et al. 2011; Jacobs et al. 2017): H(q) = N sqrt(C(q)/A) a_q e^(iφ_q),
    phases uniform in [0, 2π) from the FFT of white noise drawn from ``seed`` (an int or a
    ``numpy.random.SeedSequence``: reproducible), a_q = 1 (``"constant"``: every realisation has
    this PSD, thesis Eq. 1.25) or Rayleigh (``"gaussian"``: in expectation). SurfaceTopography's
    ``fourier_synthesis`` takes an isotropic C(|q|) only, hence this synthesis. Periodic, [y, x].
    """
    nx, ny = (int(v) for v in np.broadcast_to(np.asarray(n), (2,)))
    Lx, Ly = (check_positive("size", v) for v in np.broadcast_to(np.asarray(size, dtype=float), (2,)))
    if min(nx, ny) < 4:
        raise InputError("n", n, "need at least 4 points per side")
    if amplitudes not in ("constant", "gaussian"):
        raise InputError("amplitudes", amplitudes, "one of 'constant', 'gaussian'")
    (My, Mx), (Px, Py), measured = spectrum.grid, spectrum.period, spectrum.map
    old_q, new_q = _wavevectors((My, Mx), (Px, Py)), _wavevectors((ny, nx), (Lx, Ly))
    top = (np.pi * min(Mx / Px, nx / Lx), np.pi * min(My / Py, ny / Ly))     # wavevectors both grids hold

    def common(qx, qy):
        return (np.abs(qx) <= top[0] * (1 + 1e-12)) & (np.abs(qy) <= top[1] * (1 + 1e-12)) & ((qx != 0) | (qy != 0))

    keep_old, keep_new = common(*old_q), common(*new_q)
    (ox, oy), C_old = (v[keep_old] for v in old_q), measured[keep_old]
    nqx, nqy = (v[keep_new] for v in new_q)
    C = np.zeros((ny, nx))
    if len(C_old) and len(nqx):
        r_old, r_new = np.hypot(ox, oy), np.hypot(nqx, nqy)
        edges = np.unique(spectrum.edges)           # the spectrum's bins, continued to the corners
        ratio = edges[-1] / edges[-2]
        extra = int(np.ceil(np.log(max(r_old.max(), r_new.max()) / edges[-1]) / np.log(ratio))) + 1
        edges = np.concatenate([edges, edges[-1] * ratio ** np.arange(1, max(extra, 0) + 1)])
        ring_old, ring_new = np.searchsorted(edges, r_old), np.searchsorted(edges, r_new)
        count = np.bincount(ring_old, minlength=len(edges) + 1)
        mean_C = np.bincount(ring_old, C_old, minlength=len(edges) + 1) / np.maximum(count, 1)
        mean_q = np.bincount(ring_old, r_old, minlength=len(edges) + 1) / np.maximum(count, 1)
        filled = (count > 0) & (mean_C > 0)
        shape = np.exp(np.interp(np.log(r_new), np.log(mean_q[filled]), np.log(mean_C[filled])))
        sectors = 2 ** np.clip(np.floor(np.log2(np.maximum(count / modes_per_sector, 1))), 0, 5).astype(int)
        offset = np.concatenate([[0], np.cumsum(sectors)])

        def cell(ring, qx, qy):
            k = sectors[ring]
            return offset[ring] + np.floor(np.mod(np.arctan2(qy, qx), np.pi) / (np.pi / k) + 0.5).astype(int) % k

        cell_old, cell_new = cell(ring_old, ox, oy), cell(ring_new, nqx, nqy)
        power = np.bincount(cell_old, C_old, minlength=offset[-1]) / (Px * Py)      # measured, per cell
        spread = np.bincount(cell_new, shape, minlength=offset[-1]) / (Lx * Ly)     # the shape's, per cell
        power = _regroup(power, spread, sectors, edges, 2 * np.pi / max(Lx, Ly))
        factor = np.divide(power, spread, out=np.zeros_like(power), where=spread > 0)
        C[keep_new] = factor[cell_new] * shape
    noise = np.fft.fft2(np.random.default_rng(seed).standard_normal((ny, nx)))
    a = noise / np.where(noise == 0, 1.0, np.abs(noise)) if amplitudes == "constant" else noise / np.sqrt(nx * ny)
    h = np.fft.ifft2(nx * ny * np.sqrt(C / (Lx * Ly)) * a).real
    return Surface(h - h.mean(), Lx / nx, Ly / ny, periodic=True)


# --------------------------------------------------------------------------- statistics
@dataclass(frozen=True)
class Statistics:
    """Areal roughness parameters of one patch (ISO 25178-2 names) and its spectrum.

    Sq, Sdq: SurfaceTopography's ``Sq`` and ``rms_gradient`` (upwind finite differences, what its
    users compare with), computed alike in row blocks. Ssk = <h³>/Sq³ and Sku = <h⁴>/Sq⁴ (ISO
    25178-2; SurfaceTopography has neither). m0, m2, m4 and Nayak's α = m0 m4/m2² (Nayak,
    ASME J. Lubr. Technol. 93 (1971) 398): profile moments averaged over x and y,
    ``multiscale.micro.surface.statistics`` (what the asperity models use). Summit density: strict
    8-neighbour maxima with a curvature (``find_asperities``) per unit area, and Nayak's value for
    an isotropic Gaussian surface, m4/(6π√3 m2).
    """

    Sq: float                 # m
    Sdq: float                # -
    Ssk: float                # -
    Sku: float                # -
    m0: float                 # m^2
    m2: float                 # -
    m4: float                 # 1/m^2
    nayak: float              # -
    summit_density: float     # 1/m^2, counted
    summit_density_gaussian: float   # 1/m^2, Nayak (1971) for an isotropic Gaussian surface
    spectrum: Spectrum
    power_law: PowerLaw | None       # None if the spectrum has too few bins to fit
    texture: Texture | None = None   # Sal, Str, lay (``texture.texture``); None if f_ACF never falls to 0.2

    def table(self, filtered: bool = False) -> list[str]:
        """The statistics as aligned text lines (``multiscale surface``; ``filtered``: of a roughness
        its ``--cutoff`` separated, whose advice is then a shorter cut-off)."""
        rows = [("Sq   RMS height", _length(self.Sq)), ("Sdq  RMS gradient", f"{self.Sdq:.4g}"),
                ("Ssk  skewness", f"{self.Ssk:.4g}"), ("Sku  kurtosis", f"{self.Sku:.4g}"),
                ("Nayak parameter m0 m4/m2^2", f"{self.nayak:.4g}"),
                ("summit density", f"{self.summit_density * 1e-6:.4g} 1/mm^2 (Gaussian surface, Nayak: "
                                   f"{self.summit_density_gaussian * 1e-6:.4g} 1/mm^2)")]
        t = self.texture
        rows += [("Sal  autocorrelation length", _length(t.Sal) + f"  (fastest decay of f_ACF to {t.threshold:g})"),
                 ("Str  texture aspect ratio", f"{t.Str:.3g}" + (
                     "  (1 isotropic, towards 0 a lay)" if t.bounded else
                     f"  (at most: f_ACF stays above {t.threshold:g} out to half the measurement along the lay)")),
                 ("lay  longest correlation", f"{t.lay:.1f} deg from x towards y")] if t else \
            [("Sal, Str", f"no decay of f_ACF to {DECAY:g} within half the measurement (a form or waviness left)")]
        fit = self.power_law
        if fit is None:
            rows.append(("PSD fit", "too few bins"))
        else:
            (lr, ls), (rr, rs) = fit.wavelengths, fit.resolved
            outside = not HURST_RANGE[0] <= fit.hurst <= HURST_RANGE[1]
            poor = fit.misfit > POOR_MISFIT or fit.bins < FEW_BINS
            rows += [("Hurst exponent H (PSD fit)", f"{fit.hurst:.3f}  (rms misfit {fit.misfit:.2f} in ln C "
                                                   f"over {fit.bins} bins)" + (
                          f"; outside {HURST_RANGE[0]:g}-{HURST_RANGE[1]:g}: no self-affine range (e.g. noise), "
                          "the fit only gives the PSD's slope" if outside else
                          "; the PSD is no power law there (misfit over a factor e, or under "
                          f"{FEW_BINS} bins): H is only its mean slope" if poor else
                          "; above 1, steeper than a self-affine surface's (a scene's hurst is at most 1): "
                          + ("a waviness the filter left (a shorter --cutoff takes it out)" if filtered else
                             "a form or waviness the detrending left (--cutoff takes it out)") if fit.hurst > 1 else
                          f"; below {LOW_HURST:g}, a PSD nearly as flat as q^-2 (H = 0): instrument noise rather than "
                          "self-affine roughness, or its lowest end (a scene's hurst is plausibly 0.1 to 1)"
                          if fit.hurst < LOW_HURST else "")),     # (opd-1's H = 0.005 said nothing: a user trial)
                     ("long cut-off  2pi/q_r", _length(lr, 2) + ("  (to a PSD bin)" if rr else
                                                              "  (not resolved: >= this)")),
                     ("short cut-off 2pi/q_s", _length(ls, 2) + ("  (to a PSD bin)" if rs else
                                                              "  (not resolved: <= this)"))]
        return [f"  {name:<28} {value}" for name, value in rows]


def statistics_memory(shape) -> float:
    """Peak memory [bytes] of ``surface_statistics`` on a patch of ``shape`` (ny, nx): 25 bytes a
    point (traced from 512 x 640 to 2000² points of white noise, the most summits: the
    periodogram's quarter, 8 bytes a point, and the summits' table; a self-affine map takes 12)."""
    return 25.0 * shape[0] * shape[1]


def _height_moments(surface: Surface) -> tuple[float, float, float, float]:
    """<h²>, <h³>, <h⁴> [m², m³, m⁴] about the mean height and Sdq² [-]: upwind differences,
    SurfaceTopography's ``rms_gradient`` (periodic: wrapping; else the last row and column have
    no forward neighbour and are left out), in row blocks (no temporaries of the map's size)."""
    h, (ny, nx) = surface.heights, surface.shape
    mean = h.mean()
    m, k = (ny, nx) if surface.periodic else (ny - 1, nx - 1)
    sums = np.zeros(4)
    for rows in row_blocks(ny, nx):
        d = h[rows] - mean
        d2 = d * d
        sums[:3] += d2.sum(), np.vdot(d2, d), np.vdot(d2, d2)
        if rows.start < m:
            block = h[rows.start:min(rows.stop, m)]
            below = h[np.arange(rows.start + 1, rows.start + len(block) + 1) % ny]     # the next rows
            gx = (np.roll(block, -1, axis=1) - block)[:, :k] / surface.dx
            gy = (below - block)[:, :k] / surface.dy
            sums[3] += np.vdot(gx, gx) + np.vdot(gy, gy)
    return sums[0] / h.size, sums[1] / h.size, sums[2] / h.size, sums[3] / (m * k)


def surface_statistics(surface: Surface, points_per_decade: int = 10) -> Statistics:
    """``Statistics`` of one patch (complete heights: fill undefined points first)."""
    if check_surface(surface).heights.ndim != 2:
        raise InputError("surface.heights", surface.heights.shape, "statistics of one 2-D patch at a time")
    spatial = _texture(surface)          # first: its transforms' memory is free before the periodogram's
    m0, m3, m4_height, slope2 = _height_moments(surface)
    Sq = float(np.sqrt(m0))
    moments = statistics(surface)
    m2, m4 = float(moments.m2), float(moments.m4)
    ny, nx = surface.shape
    inner = (nx if surface.periodic else nx - 2) * (ny if surface.periodic else ny - 2) * surface.dx * surface.dy
    spectrum = power_spectrum(surface, points_per_decade)
    try:
        fit = fit_power_law(spectrum)
    except InputError:
        fit = None
    return Statistics(Sq=Sq, Sdq=float(np.sqrt(slope2)), Ssk=float(m3 / Sq**3), Sku=float(m4_height / Sq**4),
                      m0=float(moments.m0), m2=m2, m4=m4, nayak=float(moments.nayak),
                      summit_density=len(find_asperities(surface)) / inner,
                      summit_density_gaussian=m4 / (6 * np.pi * np.sqrt(3) * m2) if m2 > 0 else 0.0,
                      spectrum=spectrum, power_law=fit, texture=spatial)


def _texture(surface: Surface) -> Texture | None:
    """``texture.texture`` of the patch, None where its f_ACF does not decay to ``DECAY``."""
    try:
        return texture(surface)
    except InputError:
        return None


def _length(value: float, digits: int = 4) -> str:
    """A length [m] in mm, um or nm to ``digits`` significant digits (a cut-off is located to a
    PSD bin, 26 % in q at 10 bins per decade: its best break moved 6 % with the round-off of a
    rescaled measurement; an adversarial test)."""
    for unit, factor in (("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)):
        if abs(value) >= factor:           # rounded, then plain: "110 um", not "1.1e+02 um"
            return f"{float(f'{value / factor:.{digits}g}'):g} {unit}"
    return f"{value:.{digits}g} m"

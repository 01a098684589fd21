"""Measured topographies: instrument files read through SurfaceTopography, conditioned step by step,
and spread over an interface larger than the measurement.

Reading (``read_topography``, ``Measurement``): ``multiscale.micro.reading``, every format
SurfaceTopography reads and plain height matrices, in SI units; undefined points are NaN.

Conditioning (``condition``), in the order of ISO 25178-3 and each step reported: form removal (the
F-operator: least-squares mean, plane or polynomial fitted on the defined points, ``remove_form``),
outliers found (``multiscale.micro.outliers``: warned of, or removed with ``despike``), undefined
points filled (harmonic interpolation; refused above a stated fraction), waviness and roughness separated by
the areal Gaussian filter of ISO 16610-61 (the L-filter, cut-off wavelength λc: the roughness is the
S-L surface). ``resample`` puts a surface on another grid (the micro grid) with an anti-aliasing
S-filter when it coarsens.

Covering an interface (``cover``): the measurement itself (it must cover the interface: ``covers``,
which ``multiscale check`` asks before meshing), mirrored or tiled copies (with a warning:
wavelengths longer than the measurement are missing and the pattern repeats), or a statistically
equivalent surface drawn from the measured PSD (``multiscale.micro.spectrum.equivalent_surface``;
the measurement must hold a wavelength the micro grid resolves: ``check_resolved``, asked before
meshing too). ``coarse_grid`` warns when the micro grid resolves less than ``GRADIENT_KEPT`` of the
measured RMS gradient, which the real contact area follows (Bush, Gibson & Thomas 1975).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from multiscale.errors import InputError, check_count, check_instance, check_pair, check_positive, check_real
from multiscale.micro.filters import check_cutoff, gaussian_filter, gaussian_per_axis, resolved, roughness_of
from multiscale.micro.outliers import DESPIKE, find_outliers
from multiscale.micro.reading import LOWEST, TALLEST, Measurement, TopographyWarning, option, read_topography
from multiscale.micro.spectrum import Spectrum, as_topography, equivalent_surface, power_spectrum
from multiscale.micro.surface import Surface, defined_sums, row_blocks

MAX_UNDEFINED = 0.1       # default largest fraction of undefined points that is filled
DETREND = {"none": None, "mean": "mean", "plane": "height", "poly2": "curvature"}   # -> SurfaceTopography
COVER = ("measured", "mirror", "tile", "equivalent")
TILTED = 0.5             # a map whose Sq a plane would halve (75 % of its variance a tilt) is said to be tilted
MAX_CELLS = 1024          # cells per zone side taken from a measurement's own pixel size (no micro.grid)
GRADIENT_KEPT = 0.5       # a micro grid resolving less of the measured RMS gradient is warned about
LONG_POWER = 0.5          # an equivalent surface with more of its power beyond the measurement is warned about
S_FILTER_PIXELS = 3.0     # anti-aliasing before coarsening: resolved to λs = 3 new pixels (21 % at the new Nyquist)


def probe_topography(path, channel: int | None = None, *, pixel_size=None, height_unit=None,
                     max_undefined: float = MAX_UNDEFINED, detrend: str = "plane", despike: float | None = None,
                     cutoff: float | None = None, prefix: str = "") -> tuple[list[str], list[str]]:
    """What ``read_topography`` and ``condition`` would refuse in a file, without filling or
    filtering it (``multiscale check``): (problems, notes), one line each; no problems for a usable
    file, the notes say what overrides the file and ``condition``'s warning of outliers."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", TopographyWarning)      # returned as notes
            m = read_topography(path, channel, pixel_size=pixel_size, height_unit=height_unit, prefix=prefix)
    except InputError as exc:
        return [str(exc)], []
    form = "plane" if detrend in ("plane", "poly2") else "mean"      # the cheap part of condition's test
    flattened = remove_form(m.heights, form)
    why = _too_many_undefined(m, max_undefined, prefix) or _form_only(m, flattened)
    if why is not None:
        return [str(InputError(option(prefix, "file"), m.path.name, why))], list(m.notes)
    rough = flattened if detrend != "poly2" else remove_form(m.heights, "poly2")   # condition's form (a curved
    searched = rough if detrend in (form, "poly2") else None      # map passed: a review); the outlier search's
    if cutoff is not None and not resolved(cutoff, m.dx, m.dy):   # refused in the scene's words (``check_cutoff``):
        cutoff = None                                             # the outliers as if without it
    low = _too_smooth(float(np.nanstd(rough)), m.path.name, prefix)
    return [], list(m.notes) + ([] if despike is not None else _outlier_notes(m, detrend, cutoff, prefix, searched)) \
        + ([low] if low else [])


def _outlier_notes(m: Measurement, detrend: str, cutoff: float | None, prefix: str,
                   h: np.ndarray | None = None) -> list[str]:
    """``condition``'s warning of outliers at the default threshold in ``m``'s heights with the form
    ``detrend`` removed (``h`` [m]: those heights, if at hand), judged against the roughness' Sq
    with a ``cutoff`` (``filters.roughness_of``): none or one line. Searched once per ``Measurement`` (kept in
    ``m.found``; ``read_topography`` returns the same one while the file is unchanged:
    ``multiscale run`` reads and searches a file once, not at the scene's check too)."""
    key = (detrend, cutoff)
    if h is None and (key not in m.found or m.found[key].count):     # to search, or for the slopes
        h = m.heights if DETREND[detrend] is None else remove_form(m.heights, detrend)
    if key not in m.found:
        m.found[key] = _outliers(h, m, DESPIKE, cutoff)
    found = m.found[key]
    if not found.count:
        return []
    return [found.note(m.path.name, option(prefix, "despike", f"{DESPIKE:g}"), found.gradient_share(h, m.dx, m.dy))]


def _outliers(h: np.ndarray, m: Measurement, k: float, cutoff: float | None):
    """``find_outliers`` of the heights ``h`` [m] of ``m`` at k Sq: of the roughness at λc = ``cutoff``
    [m] when a waviness filter follows (``filters.roughness_of``)."""
    if cutoff is None:
        return find_outliers(h, k)
    return find_outliers(h, k, roughness_of(h, m.dx, m.dy, cutoff), f"of the roughness at λc = {cutoff * 1e3:.4g} mm")


def _form_only(m: Measurement, flattened: np.ndarray) -> str | None:
    """Why nothing but a form is in ``m``'s heights, or None: ``flattened`` [m] are they with the
    least-squares mean (or plane) removed, Sq within ``FLAT`` of their largest height (a constant
    or a plane, to round-off)."""
    scale, sq = float(np.nanmax(np.abs(m.heights), initial=0.0)), _defined_std(flattened)
    return None if sq > FLAT * scale else _no_roughness(sq, scale)


def _no_roughness(sq: float, scale: float) -> str:
    return (f"no roughness is left after the form removal and filtering (Sq {sq:.3g} m against heights up to "
            f"{scale:.3g} m: a constant or a plane, to round-off)")


def _too_many_undefined(m: Measurement, max_undefined: float, prefix: str) -> str | None:
    """Why the measurement has too many undefined points to fill, or None."""
    share = m.undefined / m.heights.size
    if share > max_undefined:
        return (f"{m.undefined} of its {m.heights.size} points ({100 * share:.2f} %) are undefined, more than "
                f"{option(prefix, 'max_undefined')} = {100 * max_undefined:.3g} % (too much to fill by interpolation)")
    return None


# --------------------------------------------------------------------------- conditioning
@dataclass(frozen=True)
class Conditioned:
    """A conditioned measurement: ``surface`` (the roughness, non-periodic, mean zero), ``waviness``
    (what the Gaussian filter took out; None without a cut-off), ``report`` (one line per step) and
    ``notes`` (its warnings, "warning: " lines of the report too)."""

    surface: Surface
    waviness: Surface | None
    report: tuple[str, ...]
    notes: tuple[str, ...] = ()


FLAT = 1e-10        # a conditioned surface whose Sq is below this share of its largest height is flat
def _defined_std(h: np.ndarray) -> float:
    """Standard deviation [m] of the defined (not NaN) heights, in row blocks."""
    count, _, (squares,) = defined_sums(h)
    return float(np.sqrt(squares / count))


def remove_form(heights: np.ndarray, detrend: str) -> np.ndarray:
    """The heights [m] (NaN: undefined, kept) minus their form ``detrend`` (not "none"): the
    least-squares polynomial of degree 0, 1 or 2 in x/Lx, y/Ly on the defined points, as
    SurfaceTopography's detrend (``DETREND``) and by its tall-skinny QR (the R factors of row
    blocks stacked): no temporaries of the map's size. A new array."""
    ny, nx = heights.shape
    terms = {"mean": 1, "plane": 3, "poly2": 6}[detrend]

    def design(rows):         # SurfaceTopography's columns: 1, x, y, x², y², xy
        y, x = np.meshgrid(np.arange(rows.start, rows.stop) / ny, np.arange(nx) / nx, indexing="ij")
        return [np.ones_like(x), x, y, x * x, y * y, x * y][:terms]
    factor = np.zeros((0, terms + 1))
    for rows in row_blocks(ny, nx):
        defined = np.isfinite(heights[rows])
        block = np.column_stack([c[defined] for c in design(rows)] + [heights[rows][defined]])
        factor = np.linalg.qr(np.concatenate([factor, block]), mode="r")
    coefficients = np.linalg.lstsq(factor[:, :-1], factor[:, -1], rcond=None)[0]
    out = np.empty((ny, nx))
    for rows in row_blocks(ny, nx):
        out[rows] = heights[rows]
        for a, c in zip(coefficients, design(rows)):       # its order of subtraction
            out[rows] -= a * c
    return out


def condition(m: Measurement, detrend: str = "plane", cutoff: float | None = None,
              max_undefined: float = MAX_UNDEFINED, prefix: str = "", despike: float | None = None) -> Conditioned:
    """Form removal, outliers, filling of undefined points, waviness/roughness separation (see module
    docstring); ``detrend`` one of ``DETREND`` (SurfaceTopography's detrend modes: mean, least-squares
    plane, second-order polynomial), ``cutoff`` λc [m] of the Gaussian filter (None: no filter),
    ``despike`` the threshold k of ``outliers.find_outliers`` at which outliers are removed (filled as
    undefined points; None: found at k = ``DESPIKE``, a warning, a ``TopographyWarning`` too).
    Errors and warnings name the options as ``reading.option(prefix, ...)`` does (a scene's keys,
    or with ``reading.COMMAND_LINE`` those of ``multiscale surface``)."""
    check_instance("m", m, Measurement, "a Measurement (read_topography)")
    if not isinstance(detrend, str) or detrend not in DETREND:
        raise InputError(option(prefix, "detrend"), detrend, f"one of {', '.join(DETREND)}")
    if cutoff is not None:
        check_cutoff(option(prefix, "cutoff"), cutoff, m.dx, m.dy, m.path.name)
    if despike is not None:
        check_positive(option(prefix, "despike"), despike)
    if not 0 <= check_real(option(prefix, "max_undefined"), max_undefined) <= 1:
        raise InputError(option(prefix, "max_undefined"), max_undefined, "a fraction of the points, in [0, 1]")
    too_many = _too_many_undefined(m, max_undefined, prefix)
    if too_many is not None:
        raise InputError(option(prefix, "file"), m.path.name, too_many)
    report = [f"read {m.path.name}, channel {m.channel} (\"{m.channel_name}\"): {m.shape[1]} x {m.shape[0]} points "
              f"of {m.dx * 1e6:.4g} x {m.dy * 1e6:.4g} um ({m.size[0] * 1e3:.4g} x {m.size[1] * 1e3:.4g} mm)"
              + (f", heights in {m.unit}" if m.unit else "")] + [f"warning: {n}" for n in m.notes]
    before, h = _defined_std(m.heights), m.heights
    if DETREND[detrend] is not None:
        h = remove_form(m.heights, detrend)
        names = {"mean": "mean height", "plane": "least-squares plane", "poly2": "least-squares polynomial of degree 2"}
        report.append(f"form removed: {names[detrend]} (SurfaceTopography detrend \"{DETREND[detrend]}\"): "
                      f"Sq {_um(before)} -> {_um(_defined_std(h))} um")
    undefined, notes = m.undefined, []
    if detrend in ("none", "mean") and (flat := _defined_std(remove_form(m.heights, "plane"))) < TILTED * before:
        share = 100 * (1 - (flat / before) ** 2)     # (--detrend none on plu-1 said nothing: a user trial)
        notes.append(f"a tilt holds {share:.5g} % of the height variance: Sq {_um(before)} um with it, "
                     f"{_um(flat)} um without ({option(prefix, 'detrend', 'plane')} removes it; the statistics keep it)")
    if despike is None:
        notes += _outlier_notes(m, detrend, cutoff, prefix, h)
    elif (found := _outliers(h, m, despike, cutoff)).count:
        h = h.copy() if h is m.heights else h
        h[found.rows, found.cols] = np.nan
        undefined += found.count
        report.append(f"removed {found.count} outliers ({option(prefix, 'despike', f'{despike:g}')}), "
                      f"{found.describe()}: filled as undefined points")
        if undefined > max_undefined * h.size:
            raise InputError(option(prefix, "despike"), despike, f"{undefined} of {m.path.name}'s {h.size} points are "
                             f"undefined or outliers, more than {option(prefix, 'max_undefined')} = "
                             f"{100 * max_undefined:.3g} %")
    for note in notes:
        warnings.warn(note, TopographyWarning, stacklevel=2)
    report += [f"warning: {note}" for note in notes]
    if undefined:
        frame = Surface(np.broadcast_to(0.0, m.shape), m.dx, m.dy, periodic=False)
        t = as_topography(frame, np.ma.masked_invalid(h)).interpolate_undefined_data("harmonic")
        h = np.ascontiguousarray(np.asarray(t.heights(), dtype=float).T)
        report.append(f"filled {undefined} undefined points ({undefined / m.heights.size:.2%}) by harmonic "
                      "interpolation (SurfaceTopography interpolate_undefined_data)")
    if h is m.heights:            # nothing removed or filled: a copy, not the measurement's array
        h = h - h.mean()
    else:
        h -= h.mean()
    surface = Surface(h, m.dx, m.dy, periodic=False)
    waviness = None
    if cutoff is not None:
        waviness = gaussian_filter(surface, cutoff)
        rough = surface.heights - waviness.heights
        surface = Surface(rough - rough.mean(), m.dx, m.dy, periodic=False)
        longer = " (longer than the measurement: little is removed)" if cutoff > min(m.size) else ""
        report.append(f"waviness removed: Gaussian filter (ISO 16610-61) at λc = {cutoff * 1e3:.4g} mm{longer}: "
                      f"Sq waviness {_um(float(waviness.heights.std()))} um, roughness "
                      f"{_um(float(surface.heights.std()))} um")
    scale, sq = float(np.nanmax(np.abs(m.heights), initial=0.0)), float(surface.heights.std())
    if not sq > FLAT * scale:
        raise InputError(option(prefix, "file"), m.path.name, _no_roughness(sq, scale))
    if sq > TALLEST:          # (um read as m ran to the end: micro pressures 28x E*, exit 0; a user trial)
        raise InputError(option(prefix, "file"), m.path.name, f"Sq {sq:.3g} m after form removal and outliers, "
                         f"beyond any roughness (an instrument's z range is mm): is {option(prefix, 'height_unit')} right?")
    if (low := _too_smooth(sq, m.path.name, prefix)) is not None:
        notes.append(low)
        warnings.warn(low, TopographyWarning, stacklevel=2)
        report.append(f"warning: {low}")
    return Conditioned(surface, waviness, tuple(report), tuple(notes))


def _too_smooth(sq: float, name: str, prefix: str) -> str | None:
    """A note if the Sq [m] left after form removal is below ``reading.LOWEST``, an atomic step: heights
    in a smaller unit than the file's (um given as nm: Sq 0.018 nm passed without a word, the raw
    heights' check seeing the tilt and offset; a user trial)."""
    if sq >= LOWEST:
        return None
    return (f"{option(prefix, 'file')} = '{name}': Sq {sq:.3g} m after form removal, below an atomic step (0.1 nm) "
            f"and any measured roughness: is {option(prefix, 'height_unit')} right?")


def _um(value: float) -> str:
    return f"{value * 1e6:.4g}"


def _pixel(dx: float, dy: float) -> str:
    """A pixel size for people: "1 um", or "1 x 2 um" when dx and dy differ [m in, um out]."""
    return f"{_um(dx)} um" if _um(dx) == _um(dy) else f"{_um(dx)} x {_um(dy)} um"


# --------------------------------------------------------------------------- grids
def resample(surface: Surface, n, size=None, antialias: bool = True) -> tuple[Surface, str]:
    """The surface on a grid of n = (nx, ny) cells over size (Lx, Ly) [m] (default: its own size),
    cell centres at ((i + ½) Lx/nx, (j + ½) Ly/ny) from its corner, by cubic splines; a coarser grid
    first low-passes with the Gaussian S-filter along each coarsened axis, against aliasing, to a
    resolution of λs = ``S_FILTER_PIXELS`` new pixels: the surface counts as resolved to that many
    of its own pixels already and Gaussian cut-offs add in quadrature, so the filter is at
    ``S_FILTER_PIXELS`` sqrt(new² − old²) pixel sizes (a grid barely coarser is barely filtered;
    an axis kept as fine is not; none with ``antialias`` False, for a surface filtered at about the
    new pixels already). Returns the surface and one report line."""
    import scipy.ndimage  # ~0.4 s to import: only when a surface is resampled
    nx, ny = check_pair("n", n, check_count)
    Lx, Ly = surface.size if size is None else check_pair("size", size, check_positive)
    dx, dy = Lx / nx, Ly / ny
    if (ny, nx) == surface.shape and np.isclose(dx, surface.dx, rtol=1e-9) and np.isclose(dy, surface.dy, rtol=1e-9):
        return surface, "on the micro grid already"
    source, filtered = surface, ""
    cut_x = S_FILTER_PIXELS * np.sqrt(dx ** 2 - surface.dx ** 2) if antialias and dx > surface.dx * (1 + 1e-9) else 0.0
    cut_y = S_FILTER_PIXELS * np.sqrt(dy ** 2 - surface.dy ** 2) if antialias and dy > surface.dy * (1 + 1e-9) else 0.0
    if cut_x or cut_y:
        source = gaussian_per_axis(surface, cut_x, cut_y)
        cuts = f"{cut_x * 1e6:.4g} um" if cut_x == cut_y else \
            f"{cut_x * 1e6:.4g} um along x, {cut_y * 1e6:.4g} um along y" if cut_x and cut_y else \
            f"{max(cut_x, cut_y) * 1e6:.4g} um along {'x' if cut_x else 'y'}"
        filtered = f" after an S-filter at λs = {cuts} against aliasing"
    rows = (np.arange(ny) + 0.5) * dy / surface.dy - 0.5
    cols = (np.arange(nx) + 0.5) * dx / surface.dx - 0.5
    R, Cc = np.meshgrid(rows, cols, indexing="ij")
    h = scipy.ndimage.map_coordinates(source.heights, [R, Cc], order=3,
                                      mode="grid-wrap" if surface.periodic else "mirror")
    same = np.isclose(Lx, surface.size[0], rtol=1e-9) and np.isclose(Ly, surface.size[1], rtol=1e-9)
    out = Surface(h, dx, dy, periodic=surface.periodic and same)
    return out, (f"resampled {surface.shape[1]} x {surface.shape[0]} points of {_pixel(surface.dx, surface.dy)} to "
                 f"{nx} x {ny} of {_pixel(dx, dy)} (cubic splines){filtered}: Sq "
                 f"{_um(float(surface.heights.std()))} -> {_um(float(out.heights.std()))} um")


def cover(surface: Surface, n, size, method: str = "measured", seed=0, prefix: str = "",
          warn: bool = True) -> tuple[Surface, list[str]]:
    """A surface of n = (nx, ny) cells over size (Lx, Ly) [m] made from a conditioned measurement
    (at its own pixel size) by ``method`` (one of ``COVER``):

    - ``"measured"``: the measurement itself, cropped at its centre and resampled; it must cover
      the size;
    - ``"mirror"`` / ``"tile"``: copies of it (mirror-stitched by SurfaceTopography, so without
      steps at the seams, or repeated as they are), coarsened once (to whole cells of the grid,
      or whole periods of the mirror-stitched one) and sampled, a ``TopographyWarning`` if more
      than one copy is needed (wavelengths longer than the measurement are missing and the
      pattern repeats) and if it spans fewer than 4 cells;
    - ``"equivalent"``: a statistically equivalent surface from its PSD
      (``spectrum.equivalent_surface``, ``seed``) over the whole size.

    ``warn``: the grid's resolution of the gradient (``coarse_grid``), the equivalent surface's
    power beyond the measurement (``beyond_measurement``) and the copies (``copy_notes``) checked
    (False: said already, e.g. by a scene's check for a face whose extent its geometry knows).
    Returns the (non-periodic) surface and report lines.
    """
    nx, ny = check_pair(f"{prefix}n", n, check_count)
    Lx, Ly = check_pair(f"{prefix}size", size, check_positive)
    short = not covers(surface.size, (Lx, Ly), method, prefix)
    target = _sized("the interface", (Lx, Ly))
    # one PSD for the checks and the equivalent surface, none for a cover neither takes
    spectrum = power_spectrum(surface) if warn or method == "equivalent" else None
    coarse = coarse_grid(surface, (Lx / nx, Ly / ny), prefix, spectrum) if warn else None
    if coarse is not None:
        warnings.warn(coarse, TopographyWarning, stacklevel=2)
    lines = [f"warning: {coarse}"] if coarse is not None else []
    if method == "equivalent":
        check_resolved(surface.size, (nx, ny), (Lx, Ly), prefix)
        beyond = beyond_measurement(surface, (Lx / nx, Ly / ny), prefix, spectrum) if warn else None
        if beyond is not None:
            warnings.warn(beyond, TopographyWarning, stacklevel=2)
            lines.append(f"warning: {beyond}")
        s = equivalent_surface(spectrum, (nx, ny), (Lx, Ly), seed)
        s = Surface(s.heights, s.dx, s.dy, periodic=False)
        return s, lines + [f"statistically equivalent surface over {target} from the measured PSD (seed {seed}): "
                   f"{nx} x {ny} cells of {Lx / nx * 1e6:.4g} x {Ly / ny * 1e6:.4g} um, Sq {_um(float(s.heights.std()))} "
                   f"um (measured {_um(float(surface.heights.std()))} um; the grid resolves wavelengths down to "
                   f"{2 * max(Lx / nx, Ly / ny) * 1e6:.4g} um, the measurement "
                   f"{2 * max(surface.dx, surface.dy) * 1e6:.4g} um)"]
    filtered = False
    if short:
        cell = (Lx / nx, Ly / ny)
        counts, reps = copy_layout(surface.size, (surface.dx, surface.dy), (Lx, Ly), cell, method)
        notes = copy_notes(surface.size, (surface.dx, surface.dy), (Lx, Ly), cell, method, prefix) if warn else []
        base = surface
        if method == "mirror":
            t = as_topography(surface).mirror_stitch()
            base = Surface(np.asarray(t.heights()).T, surface.dx, surface.dy, periodic=True)
        if counts is not None:        # coarsened once (to whole cells, or whole periods), then copied
            base, note = resample(base, counts, None if base.periodic else (counts[0] * cell[0], counts[1] * cell[1]))
            lines.append(note)
            filtered = True           # the copies are sampled below, not filtered a second time
        for message in notes:
            warnings.warn(message, TopographyWarning, stacklevel=2)
            lines.append(f"warning: {message}")
        if base.periodic:   # mirror: its copies sampled where they lie, not tiled at its pixels (0.77 um tiled
            #                 over 10 mm: 26k x 26k points, a minute; a user trial's measurement)
            c0 = int(np.floor((reps[1] * base.size[0] - Lx) / 2 / base.dx + 1e-9))
            r0 = int(np.floor((reps[0] * base.size[1] - Ly) / 2 / base.dy + 1e-9))
            rolled = Surface(np.roll(base.heights, (-r0, -c0), axis=(0, 1)), base.dx, base.dy, periodic=True)
            out, note = resample(rolled, (nx, ny), (Lx, Ly), antialias=not filtered)
            lines += [f"cropped the central {Lx * 1e3:.4g} x {Ly * 1e3:.4g} mm", note]
            return Surface(out.heights - out.heights.mean(), out.dx, out.dy, periodic=False), lines
        surface = Surface(np.tile(base.heights, reps), base.dx, base.dy, periodic=False)
    # the central Lx x Ly of it, on the target grid
    cx, cy = (surface.size[0] - Lx) / 2, (surface.size[1] - Ly) / 2
    c0, r0 = int(np.floor(cx / surface.dx + 1e-9)), int(np.floor(cy / surface.dy + 1e-9))
    c1, r1 = int(np.ceil((cx + Lx) / surface.dx - 1e-9)), int(np.ceil((cy + Ly) / surface.dy - 1e-9))
    crop = Surface(surface.heights[r0:r1, c0:c1], surface.dx, surface.dy, periodic=False)
    if crop.shape != surface.shape:
        lines.append(f"cropped the central {Lx * 1e3:.4g} x {Ly * 1e3:.4g} mm")
    out, note = resample(crop, (nx, ny), (Lx, Ly), antialias=not filtered)
    lines.append(note)
    return Surface(out.heights - out.heights.mean(), out.dx, out.dy, periodic=False), lines


def copy_layout(measured, pixel, size, cell, method: str) -> tuple[tuple | None, tuple[int, int]]:
    """How ``cover`` copies a measurement of ``measured`` = (mx, my) [m] in pixels ``pixel`` [m] over a
    face of ``size`` [m] in micro cells ``cell`` [m] (``method`` "mirror" or "tile"): the points
    (nx, ny) the base (the measurement, or its mirror-stitched double) is coarsened to first, None if
    its pixels are not finer than the cells (whole periods of the double, at least 4; whole cells of
    a tile, at least 4), and the copies (rows, columns) of the base."""
    base = _copied(measured, method)
    counts = None
    if pixel[0] < cell[0] * (1 - 1e-9) or pixel[1] < cell[1] * (1 - 1e-9):
        if method == "mirror":        # whole periods, so that the copies meet without steps
            counts = tuple(max(4, round(b / c)) for b, c in zip(base, cell))
        else:                         # tiles of whole cells
            counts = tuple(max(4, int(np.floor(b / c + 1e-9))) for b, c in zip(base, cell))
            base = (counts[0] * cell[0], counts[1] * cell[1])
    return counts, (int(np.ceil(size[1] / base[1])), int(np.ceil(size[0] / base[0])))


def _copied(measured, method: str) -> tuple:
    """The size [m] of what ``cover`` copies: the measurement, or with "mirror" its mirror-stitched double."""
    return tuple(2 * m for m in measured) if method == "mirror" else tuple(measured)


def copy_notes(measured, pixel, size, cell, method: str, prefix: str = "") -> list[str]:
    """The warnings of ``cover``'s copies (``copy_layout``; [] if the measurement covers the face or
    ``method`` takes no copies): the pattern repeats, and a measurement (or its mirror-stitched
    double) spanning fewer than 4 cells keeps little of its roughness. ``multiscale check`` says them
    for a face whose extent the geometry knows (it did not: a user trial's run did), a run with the
    mesh's."""
    if method not in ("mirror", "tile") or covers(measured, size, method, prefix):
        return []
    base = _copied(measured, method)
    counts, reps = copy_layout(measured, pixel, size, cell, method)
    wide = _sized("the measurement", measured)
    out = [f"{prefix}cover = \"{method}\": {wide} spans fewer than 4 cells of the micro grid ({cell[0] * 1e6:.4g} x "
           f"{cell[1] * 1e6:.4g} um) along an axis: its roughness is finer than the grid and the copies keep little "
           "of it; use \"equivalent\" or a finer micro.grid"] \
        if counts is not None and min(b / c for b, c in zip(base, cell)) < 4 else []
    period = base if counts is None or method == "mirror" else tuple(n * c for n, c in zip(counts, cell))
    longer = f"{period[0] * 1e3:.4g} mm" if abs(period[0] - period[1]) <= 1e-9 * max(period) else \
        f"{period[0] * 1e3:.4g} mm along x and {period[1] * 1e3:.4g} mm along y"   # (one said for both: a trial)
    return out + [f"{prefix}cover = \"{method}\": {wide} is smaller than {_sized('the interface', size)}: "
                  f"{reps[1]} x {reps[0]} {'mirror-stitched ' if method == 'mirror' else ''}copies; wavelengths "
                  f"longer than {longer} are missing and the pattern repeats"]


def covers(measured, size, method: str = "measured", prefix: str = "") -> bool:
    """Whether a measurement of ``measured`` = (mx, my) [m] covers a face of ``size`` = (Lx, Ly) [m]
    (to 1e-6 of the face); if not, and ``method`` (one of ``COVER``) is "measured", the InputError
    of ``cover``. ``multiscale check`` asks it with the face's extent before meshing, a run with
    the mesh's."""
    if method not in COVER:
        raise InputError(f"{prefix}cover", method, f"one of {', '.join(COVER)}")
    (mx, my), (Lx, Ly) = measured, size
    short = mx < Lx * (1 - 1e-6) or my < Ly * (1 - 1e-6)
    if short and method == "measured":
        raise InputError(f"{prefix}cover", method, f"{_sized('the measurement', measured)} does not cover "
                         f"{_sized('the interface', size)}: use "
                         "\"equivalent\" (a statistically equivalent surface) or \"mirror\"/\"tile\" (copies)")
    return not short


def check_resolved(measured, n, size, prefix: str = "") -> None:
    """The InputError of ``cover = "equivalent"`` if a measurement of ``measured`` = (mx, my) [m]
    holds no wavelength that a grid of n = (nx, ny) cells over ``size`` = (Lx, Ly) [m] resolves: its
    equivalent surface would be flat (its zone laws then failed far from the cause, "lower p_max").
    ``equivalent_surface`` draws only the wavevectors that both the measured PSD and the grid hold
    (|q_x| <= π nx/Lx, |q_y| <= π ny/Ly); the measured PSD (``power_spectrum``: the mirror-stitched
    double, period 2 mx x 2 my) has its lowest at q_x = π/mx and q_y = π/my, so the measurement must
    be at least one cell long along an axis (its longest wavelength 2 m, the grid's shortest two
    cells). ``multiscale check`` asks it with the face's extent before meshing, a run with the mesh's."""
    (mx, my), (nx, ny), (Lx, Ly) = measured, n, size
    if mx * (1 + 1e-12) < Lx / nx and my * (1 + 1e-12) < Ly / ny:     # equivalent_surface's tolerance
        raise InputError(f"{prefix}cover", "equivalent", f"{_sized('the measurement', measured)} holds no wavelength "
                         f"the micro grid resolves ({nx} x {ny} cells of {Lx / nx * 1e6:.4g} x {Ly / ny * 1e6:.4g} um: "
                         f"wavelengths from {2 * max(Lx / nx, Ly / ny) * 1e6:.4g} um up): the equivalent surface would "
                         "be flat; use a finer micro.grid or a larger measurement")


def kept_gradient(surface: Surface, cell) -> float:
    """Share [0, 1] of a conditioned measurement's RMS gradient that a grid of cells ``cell`` =
    (dx, dy) [m] resolves: sqrt(Σ w q² C over the modes |q_x| <= π/dx, |q_y| <= π/dy / Σ w q² C
    over all), C its PSD (``power_spectrum``; w the modes each entry stands for). Within 10 % of
    the RMS gradient ratio of an equivalent surface on that grid (the four instrument files, cells
    of 8 pixels: 0.28 / 0.26, 0.16 / 0.15, 0.12 / 0.11, 0.77 / 0.75)."""
    return _gradient_share(surface)(cell)


def _modes(s: Spectrum) -> tuple:
    """(qy, qx [rad/m], C [m⁴]) of the spectrum ``s``'s entries, C weighted by the modes each
    stands for: of a mirrored one the quarter qx, qy >= 0 (a mode off an axis stands for its
    mirror images), else the whole map."""
    (Px, Py), (My, Mx) = s.period, s.grid
    if s.mirrored:
        qy, qx = (2 * np.pi * np.arange(n) / P for n, P in zip(s.power.shape, (Py, Px)))
        return qy, qx, s.power * np.where(qy > 0, 2.0, 1.0)[:, None] * np.where(qx > 0, 2.0, 1.0)[None, :]
    qy, qx = (2 * np.pi * np.fft.fftfreq(n, P / n) for n, P in ((My, Py), (Mx, Px)))
    return qy, qx, s.map


def _gradient_share(surface: Surface, spectrum: Spectrum | None = None):
    """``kept_gradient`` of ``surface`` (its PSD ``spectrum``, if at hand) as a function of the
    cell (dx, dy) [m]."""
    qy, qx, C = _modes(spectrum or power_spectrum(surface))
    g = C * (qy[:, None] ** 2 + qx[None, :] ** 2)
    total, ay, ax = g.sum(), np.abs(qy), np.abs(qx)

    def share(cell) -> float:
        inside = (ay[:, None] <= np.pi / cell[1]) & (ax[None, :] <= np.pi / cell[0])
        return float(np.sqrt(g[inside].sum() / total)) if total > 0 else 1.0
    return share


def coarse_grid(surface: Surface, cell, prefix: str = "", spectrum: Spectrum | None = None) -> str | None:
    """The warning for a micro grid of cells ``cell`` = (dx, dy) [m] that resolves less than
    ``GRADIENT_KEPT`` of the RMS gradient of the conditioned measurement ``surface`` (its PSD
    ``spectrum``, if at hand; with the cells that would keep that much, by bisection on their
    scale), else None."""
    share = _gradient_share(surface, spectrum)
    kept = share(cell)
    if kept >= GRADIENT_KEPT:
        return None
    low, high = min(surface.dx / cell[0], surface.dy / cell[1]), 1.0     # scales of the cell: kept, not kept
    for _ in range(30):
        mid = np.sqrt(low * high)
        low, high = (mid, high) if share((mid * cell[0], mid * cell[1])) >= GRADIENT_KEPT else (low, mid)
    return (f"{prefix}file: the micro grid's cells ({cell[0] * 1e6:.4g} x {cell[1] * 1e6:.4g} um) resolve "
            f"{kept:.1%} of the measured RMS gradient (pixels of {_pixel(surface.dx, surface.dy)}; cells of "
            f"{low * cell[0] * 1e6:.3g} x {low * cell[1] * 1e6:.3g} um would resolve {GRADIENT_KEPT:.0%}): the real "
            "contact area, flash temperatures and heat partition follow the gradient, so they are those of a "
            "smoother surface than the one measured (a finer micro.grid or more micro.zones keep more)")


def beyond_measurement(surface: Surface, cell, prefix: str = "", spectrum: Spectrum | None = None) -> str | None:
    """The warning for ``cover = "equivalent"`` on cells ``cell`` = (dx, dy) [m] when more than
    ``LONG_POWER`` of the power that surface draws from the measurement ``surface`` (its modes
    that the cells resolve) lies in the mirror-stitched spectrum's first modes along x or y
    (``power_spectrum``: wavelength 2 mx or 2 my, longer than the measurement: its form left
    after the detrending, not roughness; a user trial: 99 % of an 83 um x3p map's on 78 um cells,
    a 13 nm face from ~5 modes; ``spectrum``: its PSD, if at hand), else None."""
    s = spectrum or power_spectrum(surface)
    if not s.mirrored:
        return None
    qy, qx, C = _modes(s)
    band = (qy[:, None] <= np.pi / cell[1]) & (qx[None, :] <= np.pi / cell[0])
    band[0, 0] = False
    first = np.zeros_like(band)
    first[1:2, :], first[:, 1:2] = True, True
    total = float(C[band].sum())
    share = float(C[band & first].sum()) / total if total > 0 else 0.0
    if share <= LONG_POWER:
        return None
    mx, my = surface.size
    return (f"{prefix}file: {share:.0%} of the power the equivalent surface draws from the measurement "
            f"({mx * 1e6:.4g} x {my * 1e6:.4g} um) is at wavelengths longer than it (its first mirror-stitched "
            f"modes, {2 * mx * 1e6:.4g} or {2 * my * 1e6:.4g} um): the form its detrending left, not roughness; the "
            f"micro grid's cells ({cell[0] * 1e6:.4g} x {cell[1] * 1e6:.4g} um) resolve little else of it: a longer "
            "measurement or a finer micro.grid")


def zone_cells(grid, method: str, size, zones, pixel, default, name: str) -> tuple[int, int]:
    """Cells (nx, ny) per zone of a face of ``size`` = (Lx, Ly) [m] cut into ``zones`` = (zx, zy),
    covered by ``method`` (one of ``COVER``) from a measurement of ``pixel`` = (dx, dy) [m] named
    ``name``: ``grid`` (``micro.grid``) when given, ``default`` for "equivalent", else the pixel
    size rounded to whole cells per zone (at least 4), refused (InputError naming micro.grid)
    above ``MAX_CELLS``. ``multiscale check`` asks it with the face's extent before meshing, a run
    with the mesh's."""
    if grid is not None:
        return tuple(int(g) for g in grid)
    if method == "equivalent":
        return tuple(int(g) for g in default)
    cells = tuple(max(4, int(round(s / z / d))) for s, z, d in zip(size, zones, pixel))
    if max(cells) > MAX_CELLS:
        raise InputError("micro.grid", None, f"{name}'s pixels give {cells[0]} x {cells[1]} cells per zone: set "
                         f"micro.grid (at most {MAX_CELLS} without it)")
    return cells


def _sized(what: str, size) -> str:
    """``what`` and its size (x, y) [m] in mm, as the messages of ``cover`` give them."""
    return f"{what} ({size[0] * 1e3:.4g} x {size[1] * 1e3:.4g} mm)"

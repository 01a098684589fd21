"""Measured topographies (issue 17): instrument files read through SurfaceTopography (heights, pixel
sizes and RMS values equal its own), channels and overrides, one clear error per bad input, and the
conditioning steps checked against exact answers: harmonic filling of a plane, form removal, the
ISO 16610-61 Gaussian filter's transmission, resampling and covering an interface."""
import logging
import os
import warnings
from pathlib import Path

import numpy as np
import pytest
import SurfaceTopography as ST
from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

from multiscale.errors import InputError
from multiscale.micro import filters, spectrum, topography
from multiscale.micro.reading import formats
from multiscale.micro.spectrum import surface_statistics
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.filters import gaussian_filter, gaussian_transmission
from multiscale.micro.topography import (Measurement, TopographyWarning, condition, cover, probe_topography,
                                         read_topography, resample)

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
# the shared measurements beside the repository (../shared; ../../shared from a worktree)
SHARED = next((p for p in (Path(os.environ.get("MULTISCALE_TOPOGRAPHIES", "/nonexistent")),
                           ROOT.parent / "shared/data/topographies", ROOT.parent.parent / "shared/data/topographies")
               if p.is_dir()), None)
FOUR = ["x3p-2.x3p", "plu-1.plu", "sur-2.sur", "opd-1.opd"]
FILES = [DATA / "top-1.top", DATA / "sdf-1.sdf"] + [
    pytest.param(SHARED / name if SHARED else Path(name), id=name,
                 marks=pytest.mark.skipif(SHARED is None, reason="../shared/data/topographies not here"))
    for name in FOUR]


def write_nc(path, heights, dx, dy):
    """A NetCDF topography file written by SurfaceTopography: heights [y, x] in m, NaN undefined."""
    h = np.ma.masked_invalid(np.asarray(heights, dtype=float).T)
    ST.Topography(h, (h.shape[0] * dx, h.shape[1] * dy), unit="m").to_netcdf(str(path))
    return path


@pytest.mark.filterwarnings("ignore::RuntimeWarning")      # SurfaceTopography's NetCDF reader, on close
@pytest.mark.parametrize("path", FILES)
def test_heights_pixel_sizes_and_rms_equal_surfacetopography(path):
    m = read_topography(path)
    t = ST.open_topography(str(path)).topography()
    f = get_unit_conversion_factor(t.unit, "m")
    ref = np.ma.masked_invalid(np.ma.asarray(t.heights(), dtype=float))         # [x, y], file unit
    mine = m.heights.T / f
    undefined = np.ma.getmaskarray(ref)
    np.testing.assert_array_equal(np.isnan(mine), undefined)
    np.testing.assert_allclose(mine[~undefined], ref.data[~undefined], rtol=1e-9, atol=0)
    assert (m.dx, m.dy) == pytest.approx((t.pixel_size[0] * f, t.pixel_size[1] * f), rel=1e-9)
    assert m.size == pytest.approx(tuple(s * f for s in t.physical_sizes), rel=1e-9)
    # RMS height and gradient as read (undefined points filled alike): SurfaceTopography's own values
    stats = surface_statistics(condition(m, detrend="none").surface)
    filled = t.interpolate_undefined_data() if t.has_undefined_data else t
    assert stats.Sq == pytest.approx(filled.Sq() * f, rel=1e-9)
    assert stats.Sdq == pytest.approx(filled.rms_gradient(), rel=1e-9)


def test_channel_selection_and_overrides_with_a_warning():
    t = ST.open_topography(str(DATA / "top-1.top")).topography()
    assert read_topography(DATA / "top-1.top", 0).channel_name == "Default"
    with pytest.warns(TopographyWarning, match="overrides the file's") as caught:
        m = read_topography(DATA / "top-1.top", pixel_size=(1e-8, 2e-8), height_unit=1e-6)
    assert len(caught) == 2 and len(m.notes) == 2
    assert (m.dx, m.dy) == (1e-8, 2e-8)
    np.testing.assert_allclose(m.heights, np.asarray(t.heights()).T * 1e-6, rtol=1e-12)


def test_plain_matrices_still_read_as_before(tmp_path):
    h = fractal_surface(16, 1e-3, 0.8, 1, 4, 1.0, seed=3).heights
    np.save(tmp_path / "pad.npy", h)
    m = read_topography(tmp_path / "pad.npy", pixel_size=2e-6, height_unit=1e-6)
    np.testing.assert_array_equal(m.heights, h * 1e-6)
    assert (m.dx, m.dy) == (2e-6, 2e-6)
    with pytest.raises(InputError, match=r'^roughness\.pixel_size: pad\.npy is a plain height matrix .* e\.g\. "0\.5 um"$'):
        read_topography(tmp_path / "pad.npy", prefix="roughness.")
    # in Python the keyword takes metres: the example says so (it said "0.5 um", which the keyword refuses)
    with pytest.raises(InputError, match=r"^pixel_size: pad\.npy .* e\.g\. pixel_size=0\.5e-6 \(metres\)$"):
        read_topography(tmp_path / "pad.npy")
    assert read_topography(tmp_path / "pad.npy", pixel_size=0.5e-6).dx == 0.5e-6


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("case, message", [
    ("unreadable", r"roughness\.file = '.*pad\.x3p': cannot read it as a topography"),
    ("garbage sur", r"roughness\.file = '.*pad\.sur': cannot read it as a topography"),
    ("missing", r"roughness\.file = '.*nowhere\.x3p': no such file"),
    ("unknown channel", r"roughness\.channel = 3: top-1\.top has the channels 0 \"Default\" \(2-D\)"),
    ("all undefined", r"roughness\.file = '.*empty\.nc': channel 0 \(\"[^\"]*\"\) holds no defined height"),
    ("all undefined matrix", r"roughness\.file = '.*empty\.npy': the height matrix holds no defined height$"),
    ("profile", r"roughness\.file = '.*opdx-3\.opdx': channel 0 \(\"Height\"\) is a 1-D profile \(line scan\): "
                r"a height map \(2-D\) is needed"),
    # an empty file (a failed copy): it asked for the pixel size (SurfaceTopography's .hgt reader took
    # it for a 0 x 0 map), or a .npy ended in numpy's EOFError traceback
    ("empty x3p", r"roughness\.file = 'pad\.x3p': the file is empty \(0 bytes\)$"),
    ("empty npy", r"roughness\.file = 'pad\.npy': the file is empty \(0 bytes\)$"),
    # a map 1 or 3 points wide: Surface's "heights.shape = (50, 1): need a grid of at least 4 x 4
    # points", naming neither the file nor the field, and `multiscale check` passed it
    ("one pixel wide", r"roughness\.file = 'line\.nc': channel 0 \(\"[^\"]*\"\) has 1 x 50 points: a height map "
                       r"of at least 4 x 4 points is needed$"),
    ("tiny matrix", r"roughness\.file = 'crop\.npy': the height matrix has 3 x 3 points: a height map of at "
                    r"least 4 x 4 points is needed$"),
])
def test_bad_input_is_one_clear_error_naming_the_file_and_the_field(tmp_path, case, message):
    path, channel = {"empty x3p": (tmp_path / "pad.x3p", None), "empty npy": (tmp_path / "pad.npy", None),"unreadable": (tmp_path / "pad.x3p", None), "garbage sur": (tmp_path / "pad.sur", None),
                     "missing": (tmp_path / "nowhere.x3p", None), "unknown channel": (DATA / "top-1.top", 3),
                     "all undefined": (tmp_path / "empty.nc", None), "profile": (DATA / "opdx-3.opdx", None),
                     "all undefined matrix": (tmp_path / "empty.npy", None),
                     "one pixel wide": (tmp_path / "line.nc", None), "tiny matrix": (tmp_path / "crop.npy", None)}[case]
    if case in ("unreadable", "garbage sur"):
        path.write_bytes(b"this is no topography\n" * 40)
    if case.startswith("empty"):
        path.write_bytes(b"")
    if case == "all undefined":
        write_nc(path, np.full((6, 8), np.nan), 1e-6, 1e-6)
    if case == "one pixel wide":
        write_nc(path, np.linspace(0, 1e-6, 50)[:, None] ** 2, 1e-6, 1e-6)
    if case == "tiny matrix":
        np.save(path, np.arange(9.0).reshape(3, 3) ** 2 * 1e-9)
    pixel = 1e-6 if case in ("empty npy", "tiny matrix") else None
    if case == "all undefined matrix":     # it said "heights up to nan m overflow ... is height_unit right?"
        np.save(path, np.full((6, 8), np.nan))
        pixel = 1e-6
    with pytest.raises(InputError, match=message):
        read_topography(path, channel, prefix="roughness.", pixel_size=pixel)
    problems, _ = probe_topography(path, channel, prefix="roughness.", pixel_size=pixel)   # what `multiscale check` says
    assert len(problems) == 1 and problems[0].startswith("roughness.")


def test_formats_are_surfacetopographys():
    names = " ".join(formats())
    for fmt in (".x3p", ".sur", ".plu", ".opd", ".datx", ".al3d", ".ibw", ".npy"):
        assert fmt in names


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_undefined_points_of_a_plane_are_filled_exactly_and_too_many_refused(tmp_path):
    n, d = 40, 1e-6
    y, x = np.mgrid[:n, :n] * d
    plane = 2e-3 * x - 1e-3 * y + 1e-7
    holes = plane.copy()
    holes[10:14, 5:9] = holes[30, 30] = holes[17, 21:23] = np.nan        # 19 points inside
    m = read_topography(write_nc(tmp_path / "holes.nc", holes, d, d))
    assert m.undefined == 19
    done = condition(m, detrend="none")
    np.testing.assert_allclose(done.surface.heights, plane - plane.mean(), atol=1e-12 * np.abs(plane).max())
    assert "filled 19 undefined points (1.19%) by harmonic interpolation" in " ".join(done.report)
    with pytest.raises(InputError, match=r"roughness\.file = '.*holes\.nc': 19 of its 1600 points \(1\.19 %\) are "
                                         r"undefined, more than roughness\.max_undefined = 1 %"):
        condition(m, max_undefined=0.01, prefix="roughness.")
    with pytest.raises(InputError, match=r"19 of its 1600 points \(1\.19 %\) are undefined, more than "
                                         r"max_undefined = 0 %"):          # (it said 0.0% of 0.0%)
        condition(m, max_undefined=0.0)
    assert probe_topography(m.path, max_undefined=0.01)[0]


def test_form_removal_plane_and_polynomial():
    n, d = 32, 1e-6
    y, x = np.mgrid[:n, :n] * d
    rough = 1e-8 * np.sin(2 * np.pi * x / (8 * d)) * np.sin(2 * np.pi * y / (8 * d))   # no plane, no curvature

    def conditioned(h, mode):
        return condition(Measurement(h, d, d, Path("synthetic.x3p")), detrend=mode).surface.heights

    tilt, bowl = 3e-3 * x + 1e-3 * y, 2e2 * ((x - 16e-6) ** 2 + (y - 10e-6) ** 2)
    for form, mode in ((tilt, "plane"), (bowl, "poly2")):       # removed to round-off: nothing left
        with pytest.raises(InputError, match="no roughness is left after the form removal"):
            conditioned(form, mode)
    assert np.abs(conditioned(bowl, "plane")).max() > 1e-2 * np.abs(bowl).max()   # a plane leaves the bowl
    np.testing.assert_allclose(conditioned(tilt + rough, "plane"), conditioned(rough, "plane"), atol=1e-20)
    np.testing.assert_allclose(conditioned(bowl + rough, "poly2"), conditioned(rough, "poly2"), atol=1e-12 * 1e-8)
    with pytest.raises(InputError, match=r"detrend = 'cubic': one of none, mean, plane, poly2"):
        conditioned(tilt, "cubic")


def test_a_tilt_left_in_is_said_with_its_share_of_the_variance():
    """--detrend none on a tilted map gave its tilt's Sq as the roughness's without a word (plu-1:
    2.834 um, 99.6 % tilt; a user trial); its share of the variance, 1 - (Sq_plane / Sq)^2, is said,
    computed here from the sums of squares; a rough map without a tilt, or detrended, says nothing."""
    n, d = 64, 1e-6
    y, x = np.mgrid[:n, :n] * d
    rough = 1e-8 * np.sin(2 * np.pi * x / (8 * d)) * np.sin(2 * np.pi * y / (8 * d))
    tilted = rough + 1e-3 * x
    share = 1 - np.var(rough) / np.var(tilted)
    for mode in ("none", "mean"):
        with pytest.warns(TopographyWarning, match=rf"a tilt holds {100 * share:.5g} % of the height variance: "
                                                   r"Sq .* um with it, 0\.005 um without \(detrend = plane removes"):
            done = condition(Measurement(tilted, d, d, Path("tilted.plu")), detrend=mode)
        assert any(line.startswith("warning: a tilt holds") for line in done.report)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TopographyWarning)
        condition(Measurement(tilted, d, d, Path("tilted.plu")), detrend="plane")
        condition(Measurement(rough, d, d, Path("rough.plu")), detrend="none")


def test_gaussian_filter_splits_two_sinusoids_as_its_transmission_says():
    """ISO 16610-61: the mean surface keeps exp(-π (α λc/λ)²) of a sinusoid, 50 % at λ = λc."""
    n, d, cutoff = 256, 1e-6, 32e-6
    y, x = np.mgrid[:n, :n] * d
    long_wave, short_wave = 128e-6, n * d / (16 * np.sqrt(2))       # 4 λc along x; λc/2.8 diagonally
    a, b = 2e-6, 0.5e-6
    wave = a * np.cos(2 * np.pi * x / long_wave)
    ripple = b * np.sin(2 * np.pi * 16 * (x + y) / (n * d))
    expected = gaussian_transmission(long_wave, cutoff) * wave + gaussian_transmission(short_wave, cutoff) * ripple
    assert gaussian_transmission(cutoff, cutoff) == pytest.approx(0.5, rel=1e-15)
    periodic = gaussian_filter(Surface(wave + ripple, d, d, periodic=True), cutoff).heights
    np.testing.assert_allclose(periodic, expected, atol=1e-6 * a)
    # a measurement (mirrored at its edges): exact one cut-off away from the edges (the kernel's reach)
    done = condition(Measurement(wave + ripple, d, d, Path("waves.sur")), detrend="none", cutoff=cutoff)

    def inner(h):
        h = h[32:-32, 32:-32]
        return h - h.mean()

    np.testing.assert_allclose(inner(done.waviness.heights), inner(expected), atol=1e-6 * a)
    np.testing.assert_allclose(inner(done.surface.heights), inner(wave + ripple - expected), atol=1e-6 * a)
    assert "Gaussian filter (ISO 16610-61) at λc = 0.032 mm" in done.report[-1]



@pytest.mark.parametrize("periodic", [True, False])
def test_a_cutoff_longer_than_the_surface_filters_by_its_transmission(periodic, monkeypatch):
    """From half the surface's side on (``LONG_CUTOFF``), λc is applied in Fourier space (on the
    mirror image of a measurement): the same mean surface as the truncated convolution (1e-6 of
    the heights; measured 4e-8-1.4e-7), a periodic sinusoid of the surface's length kept by exactly
    its transmission at λc = 1 m, in no time (before: a kernel of 2 λc / dx taps per row, minutes
    at 50 mm, and a bare 0.8 read as metres never ended)."""
    n, d = 128, 1e-6
    s = fractal_surface(n, n * d, 0.8, 2, 32, 1e-6, seed=3)
    surface = Surface(s.heights[:, : n - 28], d, d, periodic=False) if not periodic else s
    cutoff = 0.4 * min(surface.size)
    convolved = gaussian_filter(surface, cutoff).heights
    monkeypatch.setattr(filters, "LONG_CUTOFF", 0.1)
    assert np.abs(gaussian_filter(surface, cutoff).heights - convolved).max() < 1e-6 * np.abs(surface.heights).max()
    x = np.arange(n) * d
    wave = np.tile(np.cos(2 * np.pi * x / (n * d)), (n, 1))
    kept = gaussian_filter(Surface(wave, d, d, periodic=True), 1.0).heights
    np.testing.assert_allclose(kept, gaussian_transmission(n * d, 1.0) * wave, atol=1e-15)

def test_resampling_keeps_a_smooth_surface_and_filters_before_coarsening():
    n, d = 64, 1e-6
    wave = 32e-6                                         # two periods over the patch

    def sampled(m, dx):
        x = (np.arange(m) + 0.5) * dx
        return 1e-6 * np.cos(2 * np.pi * x / wave)[None, :] * np.cos(2 * np.pi * x / wave)[:, None]

    s = Surface(sampled(n, d), d, d, periodic=True)
    fine, note = resample(s, (2 * n, 2 * n))
    np.testing.assert_allclose(fine.heights, sampled(2 * n, d / 2), atol=1e-3 * 1e-6)
    assert fine.dx == d / 2 and "cubic splines" in note and "S-filter" not in note
    coarse, note = resample(s, (n // 4, n // 4))
    assert "S-filter at λs = 11.62 um against aliasing" in note      # 3 sqrt(4² - 1²) um: 12 um in all
    keep = gaussian_transmission(wave, 3 * np.sqrt(15) * 1e-6) ** 2          # the S-filter's, in x and in y
    np.testing.assert_allclose(coarse.heights, keep * sampled(n // 4, 4 * d), atol=2e-2 * 1e-6)


def test_covering_an_interface():
    d = 1e-6
    s = Surface(fractal_surface(40, 40e-6, 0.8, 1, 10, 1e-7, seed=4).heights, d, d, periodic=False)
    inside, lines = cover(s, (20, 20), (20e-6, 20e-6))                    # the measured centre, as it is
    np.testing.assert_allclose(inside.heights, s.heights[10:30, 10:30] - s.heights[10:30, 10:30].mean(), atol=1e-20)
    with pytest.raises(InputError, match=r'roughness\.cover = .measured.: the measurement \(0\.04 x 0\.04 mm\) does '
                                         r'not cover the interface \(0\.1 x 0\.08 mm\): use "equivalent"'):
        cover(s, (100, 80), (100e-6, 80e-6), prefix="roughness.")
    with pytest.warns(TopographyWarning, match=r"3 x 2 mirror-stitched copies; wavelengths longer than 0\.08 mm "
                                               r"are missing and the pattern repeats"):
        mirrored, lines = cover(s, (200, 100), (200e-6, 100e-6), "mirror")
    twice = np.block([[s.heights, s.heights[:, ::-1]], [s.heights[::-1], s.heights[::-1, ::-1]]])
    tiles = np.tile(twice, (2, 3))[30:130, 20:220]                          # the central 200 x 100 cells
    np.testing.assert_allclose(mirrored.heights, tiles - tiles.mean(), atol=1e-20)
    with pytest.warns(TopographyWarning, match="3 x 2 copies; wavelengths longer than 0.04 mm are missing"):
        tiled, _ = cover(s, (100, 60), (100e-6, 60e-6), "tile")
    with pytest.warns(TopographyWarning, match=r"wavelengths longer than 0\.035 mm along x and 0\.036 mm along y"):
        cover(s, (10, 10), (70e-6, 90e-6), "tile")     # tiles of whole 7 x 9 um cells (one length said for both: a trial)
    assert tiled.shape == (60, 100) and not tiled.periodic
    with pytest.warns(TopographyWarning, match="13 x 7 mirror-stitched copies"):     # coarsened before copying
        coarse, lines = cover(s, (100, 50), (1e-3, 0.5e-3), "mirror")
    assert coarse.shape == (50, 100) and lines[0].startswith("resampled 80 x 80 points of 1 um to 8 x 8 of 10 um")
    a, _ = cover(s, (64, 48), (128e-6, 96e-6), "equivalent", seed=5)
    b, _ = cover(s, (64, 48), (128e-6, 96e-6), "equivalent", seed=5)
    c, _ = cover(s, (64, 48), (128e-6, 96e-6), "equivalent", seed=6)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert a.shape == (48, 64) and a.dx == 2e-6 and not np.allclose(a.heights, c.heights)


def test_undefined_points_of_a_plain_matrix_are_filled_like_an_instrument_files(tmp_path):
    """NaN in a .npy height matrix marks undefined points: conditioned like those of an instrument
    file (filled up to max_undefined, said in the report; before: refused whatever max_undefined);
    an infinite height is refused."""
    h = fractal_surface(64, 64e-6, 0.8, 2, 16, 1e-6, seed=2).heights
    h[10, 10:19] = np.nan
    np.save(tmp_path / "holes.npy", h / 1e-6)
    m = read_topography(tmp_path / "holes.npy", pixel_size=1e-6, height_unit=1e-6)
    assert np.isnan(m.heights).sum() == 9
    done = condition(m, detrend="none")
    assert np.all(np.isfinite(done.surface.heights)) and any("filled 9 undefined points" in r for r in done.report)
    kept, given = done.surface.heights[~np.isnan(h)], h[~np.isnan(h)]          # the defined points stay
    np.testing.assert_allclose(kept - kept.mean(), given - given.mean(), atol=1e-12 * np.abs(given).max())
    with pytest.raises(InputError, match="undefined"):
        condition(m, detrend="none", max_undefined=1e-4)
    h[0, 0] = np.inf
    np.save(tmp_path / "inf.npy", h)
    with pytest.raises(InputError, match="infinite values"):
        read_topography(tmp_path / "inf.npy", pixel_size=1e-6)


@pytest.mark.parametrize("heights", [np.zeros((32, 32)), np.ones((32, 32)) * 1e-3,
                                     np.add.outer(np.arange(32) * 1e-5, np.arange(32) * 2e-5)])
def test_a_flat_or_planar_matrix_has_no_roughness(tmp_path, heights):
    """A constant or a plane leaves only round-off after the form removal: one InputError naming
    the file (before: the zeros were refused by the spectrum under a Python name, a constant or a
    plane gave the statistics of its round-off, Sq 1e-17 m), also from `multiscale check`'s probe
    (before: OK, then the run refused it)."""
    np.save(tmp_path / "flat.npy", heights)
    m = read_topography(tmp_path / "flat.npy", pixel_size=1e-6)
    with pytest.raises(InputError, match=r"file = 'flat.npy': no roughness is left after the form removal"):
        condition(m, prefix="roughness.")
    problems, _ = probe_topography(tmp_path / "flat.npy", pixel_size=1e-6, prefix="roughness.")   # check says so
    assert len(problems) == 1 and "roughness.file = 'flat.npy': no roughness is left" in problems[0]


def test_heights_in_the_wrong_unit_are_warned_about_and_an_overflow_refused(tmp_path, capsys):
    """A matrix in um read as metres (Sq 2 m on a 20 mm pin ran to the end without a word): a
    warning naming the file and height_unit, also in `multiscale check`, and refused once its
    conditioned Sq exceeds ``reading.TALLEST`` (the run went on with the warning); heights whose spread
    overflows (1e294) one InputError (before: Sq inf, then a ContactNonFiniteError in every zone); a
    conditioned Sq below ``reading.LOWEST`` warned of."""
    from multiscale.micro.topography import TopographyWarning, probe_topography
    h = fractal_surface(32, 32e-6, 0.8, 2, 8, 1e-6, seed=1).heights
    np.save(tmp_path / "um.npy", h * 1e6)
    with pytest.warns(TopographyWarning, match=r"roughness\.file = 'um.npy': heights up to [0-9.]+ m \(Sq [0-9.]+ m, "
                      r"one unit of the file = m\), far beyond a rough surface's: is roughness\.height_unit right\?"):
        read_topography(tmp_path / "um.npy", pixel_size=1e-6, prefix="roughness.")
    assert probe_topography(tmp_path / "um.npy", pixel_size=1e-6)[1][0].startswith("file = 'um.npy': heights up to")
    from multiscale.micro.topography import condition        # its conditioned Sq beyond a measurement's: refused
    with pytest.raises(InputError, match=r"^roughness\.file = 'um.npy': Sq 0\.[0-9]+ m after form removal and "
                       r"outliers, beyond any roughness .*: is roughness\.height_unit right\?"):   # (it ran to
        with pytest.warns(TopographyWarning):                                          # the end: a user trial)
            condition(read_topography(tmp_path / "um.npy", pixel_size=1e-6, prefix="roughness."), prefix="roughness.")
    with warnings.catch_warnings():
        warnings.simplefilter("error", TopographyWarning)
        read_topography(tmp_path / "um.npy", pixel_size=1e-6, height_unit=1e-6)      # in its unit: no word
    # the other way (a file in m said to be in nm: Sq 7.7e-17 m printed as a result, without a word)
    with pytest.warns(TopographyWarning, match=r"file = 'm.npy': heights up to [0-9.e-]+ m \(Sq 1e-15 m, one unit of "
                      r"the file = 1e-09 m\), far below a rough surface's: is height_unit right\?"):
        np.save(tmp_path / "m.npy", h)
        read_topography(tmp_path / "m.npy", pixel_size=1e-6, height_unit=1e-9)
    # a pixel size in um given as m (a 126 x 94 m map without a word: a user trial), and in pm
    with pytest.warns(TopographyWarning, match=r"file = 'um.npy': a map of 32 x 32 m \(pixels of 1 x 1 m\), wider "
                      r"than any measurement's: is pixel_size in m\?"):
        read_topography(tmp_path / "um.npy", pixel_size=1.0, height_unit=1e-6)
    with pytest.warns(TopographyWarning, match=r"pixels finer than any measurement's: is pixel_size in m\?"):
        read_topography(tmp_path / "um.npy", pixel_size=1e-12, height_unit=1e-6)
    np.save(tmp_path / "huge.npy", h * 1e300)
    with pytest.raises(InputError, match=r"file = 'huge.npy': heights up to .* m overflow"):
        read_topography(tmp_path / "huge.npy", pixel_size=1e-6)
    # um given as nm under a tilt and an offset (the raw heights' peak passed: Sq 0.018 nm without a word,
    # a user trial): the conditioned Sq below an atomic step is warned of, in the report too
    y, x = np.mgrid[:32, :32]
    np.save(tmp_path / "tilted.npy", h * 1e4 + 5.0 + 0.3 * x)     # a 10 nm Sq in um, on a 5 um offset and a tilt
    tilted = read_topography(tmp_path / "tilted.npy", pixel_size=1e-6, height_unit=1e-9, prefix="roughness.")
    with pytest.warns(TopographyWarning, match=r"^roughness\.file = 'tilted\.npy': Sq [0-9.e-]+ m after form removal, "
                      r"below an atomic step \(0\.1 nm\) and any measured roughness: is roughness\.height_unit right\?"):
        low = condition(tilted, prefix="roughness.")
    assert low.report[-1] == f"warning: {low.notes[-1]}"
    assert probe_topography(tmp_path / "tilted.npy", pixel_size=1e-6, height_unit=1e-9)[1] == [   # check says it
        low.notes[-1].replace("roughness.", "")]
    np.save(tmp_path / "cap.npy", 1e-3 * (x - 16.0) ** 2 + 1e-3 * (y - 16.0) ** 2 + h * 30.0)   # a curved form: check
    notes = probe_topography(tmp_path / "cap.npy", pixel_size=1e-6, height_unit=1e-6, detrend="poly2")[1]  # removes
    assert [n for n in notes if "below an atomic step" in n]      # it as condition does (a plane did not: a review)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TopographyWarning)                    # in its unit: no word
        condition(read_topography(tmp_path / "tilted.npy", pixel_size=1e-6, height_unit=1e-6))


def test_a_strip_of_a_few_points_across_is_warned_of(tmp_path):
    """A 300 x 4 map (6.6 um wide) was read with full statistics and a PSD without a word (a user
    trial): fewer than reading.NARROWEST points along a side are warned of; 16 are not."""
    from multiscale.micro.topography import TopographyWarning
    rng = np.random.default_rng(3)
    np.save(tmp_path / "strip.npy", rng.normal(size=(4, 300)))
    with pytest.warns(TopographyWarning, match=r"^file = 'strip.npy': a map of 300 x 4 points, fewer than 16 along a "
                                               r"side: a strip"):
        read_topography(tmp_path / "strip.npy", pixel_size=1e-6, height_unit=1e-6)
    np.save(tmp_path / "square.npy", rng.normal(size=(16, 300)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", TopographyWarning)
        read_topography(tmp_path / "square.npy", pixel_size=1e-6, height_unit=1e-6)


def test_a_plain_matrix_has_one_channel(tmp_path):
    """--channel 2 on a .npy is refused (before: silently read as channel 0); 0 reads it."""
    np.save(tmp_path / "rough.npy", fractal_surface(32, 32e-6, 0.8, 2, 8, 1e-6, seed=1).heights)
    assert read_topography(tmp_path / "rough.npy", channel=0, pixel_size=1e-6).shape == (32, 32)
    with pytest.raises(InputError, match="channel = 2: rough.npy is a plain height matrix: one channel, 0"):
        read_topography(tmp_path / "rough.npy", channel=2, pixel_size=1e-6)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_a_truncated_file_gets_its_readers_diagnosis_and_no_log_of_its_bytes(tmp_path, caplog):
    """A damaged file of a known format: what its format's reader says (before: 'not a format
    SurfaceTopography recognises'); igor2's reader, tried during the format detection, logged the
    bytes of a truncated .opd as an error (6.5 MB on the terminal for half of opd-1.opd); a
    folder is not 'no such file'."""
    whole = (DATA / "opdx-3.opdx").read_bytes()
    (tmp_path / "cut.opdx").write_bytes(whole[:len(whole) // 2])
    with pytest.raises(InputError, match=r"cut\.opdx': cannot read it as a topography: as Dektak OPDx, "
                                         r"CorruptFile: .*probably truncated"):
        read_topography(tmp_path / "cut.opdx")
    (tmp_path / "pad.plu").mkdir()
    with pytest.raises(InputError, match=r"'pad\.plu': a folder, not a file"):
        read_topography(tmp_path / "pad.plu")
    with pytest.raises(InputError, match=r"= '\.': a folder, not a file"):      # its name was '' (a user trial)
        read_topography(".")
    if SHARED is not None:
        (tmp_path / "cut.opd").write_bytes((SHARED / "opd-1.opd").read_bytes()[:3000])
        with caplog.at_level(logging.DEBUG), pytest.raises(InputError, match="as Wyko OPD, CorruptFile"):
            read_topography(tmp_path / "cut.opd")
        assert not caplog.records



def test_contents_of_another_format_than_the_extension_are_refused(tmp_path):
    """A .x3p cut to 2 n² bytes was taken for NASA SRTM elevations (HGT, detected by its size
    alone), and the error asked for a pixel size (given, the zip's bytes would be heights); a
    .top renamed .x3p was read as WSxM without a word. Both are refused with the extension's
    reader's diagnosis."""
    (tmp_path / "cut.x3p").write_bytes(b"PK\x03\x04" + bytes(2 * 100 ** 2 - 4))     # a zip's start
    (tmp_path / "top.x3p").write_bytes((DATA / "top-1.top").read_bytes())
    for name, taken in (("cut", "NASA SRTM"), ("top", "WSxM")):
        with pytest.raises(InputError, match=rf"^roughness\.file = '{name}\.x3p': its contents were taken for {taken}, "
                                             r"not the format of its \.x3p extension: as XML 3D surface profile \(X3P\), "
                                             r"FileFormatMismatch: .*\(a damaged file, or one to rename\)$"):
            read_topography(tmp_path / f"{name}.x3p", prefix="roughness.")

@pytest.mark.parametrize("call, message", [
    (lambda s, p: read_topography(p, pixel_size=(1e-6, 2e-6, 3e-6)), "pixel_size = (1e-06, 2e-06, 3e-06): one value or a pair"),
    (lambda s, p: read_topography(p, pixel_size="1 um"), "pixel_size = '1 um': must be a real number"),
    (lambda s, p: cover(s, 0, (1e-4, 1e-4)), "n = 0: must be a whole number >= 1"),
    (lambda s, p: cover(s, 64.7, (6e-5, 6e-5)), "n = 64.7: must be a whole number >= 1"),
    (lambda s, p: cover(s, 64, (-5e-5, 5e-5)), "size = -5e-05: must be finite and > 0"),
    (lambda s, p: resample(s, -4), "n = -4: must be a whole number >= 1"),
    (lambda s, p: condition(Measurement(s.heights, 1e-6, 1e-6, p), max_undefined="0.1"),
     "max_undefined = '0.1': must be a real number"),
    (lambda s, p: condition(Measurement(s.heights, 1e-6, 1e-6, p), detrend=["plane"]), "detrend = ['plane']: one of"),
    (lambda s, p: condition(s.heights), "must be a Measurement"),
    (lambda s, p: read_topography(None), "file: a file name"),
])
def test_bad_arguments_of_the_measured_surface_functions_name_themselves(tmp_path, call, message):
    """Each is one InputError naming the argument (before: numpy's broadcast ValueError, a
    ZeroDivisionError, a count of 64.7 cut to 64, a grid of (160, 0) cells, a TypeError; for a
    detrend list, a height array for the Measurement, a None path: TypeError, AttributeError)."""
    s = fractal_surface(64, 64e-6, 0.8, 2, 16, 1e-6, seed=2)
    np.save(tmp_path / "m.npy", s.heights)
    with pytest.raises(InputError) as info:
        call(Surface(s.heights, s.dx, s.dy, periodic=False), tmp_path / "m.npy")
    assert message in str(info.value)


@pytest.mark.skipif(SHARED is None, reason="../shared/data/topographies not here")
def test_bccg_converges_on_a_measured_plateau_surface():
    """A 384 x 384 crop of plu-1 (a plateau surface: valleys 30 Sq deep) at 10 MPa on E* = 5.4 GPa,
    61 % contact: bccg's ring extension stalled at eps 0.22 from the 10th iteration on (found by an
    adversarial test); with ``bccg_solver.STALL`` it drops the rings and ends at the solution.
    Checked by the contact conditions with the displacement convolved here (Love's coefficients,
    thesis Eq. 1.30, ``scipy.signal.fftconvolve``): h − u constant on the contact, below it
    elsewhere, p >= 0 carrying the load. (Polonsky–Keer's answer, which took 579 iterations and
    12 s of the suite, agreed to 1e-7 in pressure.)"""
    from scipy.signal import fftconvolve
    from multiscale.micro.contact import ContactSolver
    from multiscale.micro.kernels import HalfSpace
    from multiscale.references.love import love_rectangle
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TopographyWarning)
        s = condition(read_topography(SHARED / "plu-1.plu")).surface
    h = s.heights[:384, :384]
    kernel = HalfSpace.from_materials(5e9, 0.3, 220e9, 0.3)
    got = ContactSolver(kernel, h.shape, s.dx, s.dy, periodic=False).solve(h, load=1e7, max_iter=800)
    assert got.iterations < 150 and got.area_fraction == pytest.approx(0.6075, abs=1e-3)
    offsets = np.arange(-383, 384)
    G = love_rectangle(offsets[None, :] * s.dx, offsets[:, None] * s.dy, s.dx / 2, s.dy / 2)
    e_star = 1 / ((1 - 0.3 ** 2) / 5e9 + (1 - 0.3 ** 2) / 220e9)
    u = fftconvolve(got.pressure, G, mode="same") / (np.pi * e_star)
    assert np.abs(u - got.displacement).max() < 1e-10 * np.abs(u).max()
    level, sq = (h - u)[got.contact], h.std()
    assert np.ptp(level) < 1e-6 * sq and (h - u)[~got.contact].max() < level.mean() + 1e-6 * sq
    assert got.pressure.min() >= 0 and got.pressure.mean() == pytest.approx(1e7, rel=1e-9)


def test_resampling_to_unequal_pixels_filters_each_axis_at_its_own_pixel():
    """A wave along x of 8 new x-pixels keeps the same amplitude on a 10 x 10 um and a 10 x 40 um
    grid, the S-filter's transmission at λs = 3 new x-pixels (``gaussian_transmission``) within the
    splines' 1 %: the coarser y pixel filters only y (it kept 0.21 of it, found by an adversarial test)."""
    d, lam = 1e-6, 80e-6
    x = (np.arange(800) + 0.5) * d
    s = Surface(1e-7 * np.cos(2 * np.pi * x / lam)[None, :].repeat(800, axis=0), d, d, periodic=False)
    kept = []
    for n in ((80, 80), (80, 20)):
        out, note = resample(s, n)
        kept.append(out.heights[:, 10:-10].std() * np.sqrt(2) / 1e-7)
    assert "29.85 um along x, 120 um along y" in note          # 3 sqrt(10² - 1²), 3 sqrt(40² - 1²) um
    assert note.startswith("resampled 800 x 800 points of 1 um to 80 x 20 of 10 x 40 um")
    _, back = resample(out, (40, 40))                   # unequal source pixels are both named (was dx only)
    assert back.startswith("resampled 80 x 20 points of 10 x 40 um to 40 x 40 of 20 um")
    assert kept[1] == pytest.approx(kept[0], rel=1e-3)
    assert kept[1] == pytest.approx(gaussian_transmission(lam, 3 * np.sqrt(99) * 1e-6), rel=0.01)


def test_a_grid_barely_coarser_than_the_measurement_is_barely_filtered():
    """Cells 0.4 % larger than the pixels: a 4-pixel wave keeps its amplitude as on cells 0.4 %
    smaller (the S-filter at 3 whole new pixels kept 0.69 of it: a measured opd-1 crop lost 15 % of
    its RMS slope and its contact area at 20 MPa came out 29 % high, 3.11 % against 2.41 % on its own
    pixels; found by an adversarial test); the filter tops the surface's own resolution up to 3
    new pixels, Gaussian cut-offs adding in quadrature."""
    n, d, lam = 256, 1e-6, 4e-6
    x = (np.arange(n) + 0.5) * d
    s = Surface(1e-7 * np.cos(2 * np.pi * x / lam)[None, :].repeat(n, axis=0), d, d, periodic=False)
    kept = {}
    for m in (n - 1, n + 1):
        out, note = resample(s, (m, n), s.size)
        kept[m] = out.heights[:, 16:-16].std() * np.sqrt(2) / 1e-7
    assert kept[n - 1] == pytest.approx(kept[n + 1], rel=0.01) and kept[n + 1] > 0.9
    cut = 3 * np.sqrt((n * d / (n - 1)) ** 2 - d ** 2)
    assert f"S-filter at λs = {cut * 1e6:.4g} um along x" in resample(s, (n - 1, n), s.size)[1]


def test_copies_of_a_small_measurement_are_filtered_once():
    """tile / mirror: the measurement is coarsened once to whole cells of the micro grid (the
    S-filter at 3 cells: half the amplitude of a 3-cell wave) and its copies are sampled at their
    pixels, not filtered again (a wave kept 0.37 of itself, about the square; found by an
    adversarial test); a measurement narrower than 4 cells is warned about."""
    d, lam, A = 1e-6, 0.9e-3, 1e-6
    x = (np.arange(2000) + 0.5) * d
    s = Surface(A * np.cos(2 * np.pi * (x - 0.1e-3) / lam)[None, :].repeat(200, axis=0), d, d, periodic=False)
    for method, rel in (("tile", 0.06), ("mirror", 0.12)):        # the filter's mirrored edges, the seams
        with pytest.warns(TopographyWarning, match=r"spans fewer than 4 cells of the micro grid \(300 x 300 um\)"):
            out, _ = cover(s, (10, 10), (3e-3, 3e-3), method)
        assert out.heights.std() / (A / np.sqrt(2)) == pytest.approx(gaussian_transmission(lam, 0.9e-3), rel=rel)


def test_read_topography_takes_a_path_like_and_a_home_folder_not_an_open_file(tmp_path, monkeypatch):
    """Only str and Path were taken: "~" was not expanded ("no such file"), another os.PathLike and
    an open file were refused alike ("a file name (str or Path)"). An open file is still refused
    (the format detection, the messages and the kept reads need its name), saying so."""
    monkeypatch.setenv("HOME", str(tmp_path))
    np.save(tmp_path / "m.npy", np.random.default_rng(0).normal(0.0, 1e-6, (8, 6)))

    class Named:
        def __fspath__(self):
            return str(tmp_path / "m.npy")

    assert read_topography("~/m.npy", pixel_size=1e-6).shape == (8, 6)
    assert read_topography(Named(), pixel_size=1e-6).shape == (8, 6)
    with open(tmp_path / "m.npy", "rb") as f, pytest.raises(InputError) as opened:
        read_topography(f, pixel_size=1e-6, prefix="roughness.")
    assert str(opened.value) == ("roughness.file = 'an open BufferedReader': a file name (str or os.PathLike, e.g. "
                                 "pathlib.Path): pass the name of the open file")


def test_an_equivalent_surface_with_no_measured_wavelength_on_the_grid_is_refused():
    """A measurement shorter than a cell of the micro grid (x3p-2.x3p, 0.08 x 0.2 mm, on the
    312.5 um cells of a 10 mm face at 32 x 32) gave a flat "equivalent" surface (Sq 0, reported as
    such) and the run failed in the zone laws with "lower p_max". Refused, naming the cause."""
    s = fractal_surface(64, 64e-6, 0.8, 2, 16, 1e-6, seed=2)
    s = Surface(s.heights, s.dx, s.dy, periodic=False)
    with pytest.raises(InputError) as flat:
        cover(s, (32, 32), (10e-3, 10e-3), "equivalent", prefix="roughness.")
    assert str(flat.value) == ("roughness.cover = 'equivalent': the measurement (0.064 x 0.064 mm) holds no wavelength "
                               "the micro grid resolves (32 x 32 cells of 312.5 x 312.5 um: wavelengths from 625 um "
                               "up): the equivalent surface would be flat; use a finer micro.grid or a larger measurement")
    assert cover(s, (320, 320), (1e-3, 1e-3), "equivalent")[0].heights.std() > 0.1 * s.heights.std()


@pytest.mark.parametrize("cells, flat", [((64e-6 * (1 + 1e-9),) * 2, True), ((64e-6 * (1 - 1e-9),) * 2, False),
                                         ((64e-6 * (1 + 1e-9), 64e-6 * (1 - 1e-9)), False)])
def test_check_resolved_says_what_the_equivalent_surface_would_be(cells, flat):
    """``check_resolved`` (what `multiscale check` asks before meshing, and ``cover``) refuses
    exactly the grids on which ``equivalent_surface`` is flat: a measurement shorter than one cell
    along both axes (its longest wavelength, 2 m, shorter than the grid's shortest, two cells)."""
    s = fractal_surface(64, 64e-6, 0.8, 2, 16, 1e-6, seed=2)
    s = Surface(s.heights, s.dx, s.dy, periodic=False)          # 64 x 64 um
    n, size = (8, 8), (8 * cells[0], 8 * cells[1])
    drawn = spectrum.equivalent_surface(spectrum.power_spectrum(s), n, size)
    assert (not np.any(drawn.heights)) == flat
    if flat:
        with pytest.raises(InputError, match="roughness.cover = 'equivalent': the measurement .* holds no wavelength"):
            topography.check_resolved(s.size, n, size, prefix="roughness.")
    else:
        topography.check_resolved(s.size, n, size, prefix="roughness.")


def test_heights_that_underflow_are_refused_by_name(tmp_path):
    """Heights of 1e-170 m (a height unit of 1e-200 m on micrometre numbers): ``multiscale surface``
    ended in a ZeroDivisionError traceback (a trial of odd files); now the file is named and the
    height unit questioned."""
    from multiscale.errors import InputError
    from multiscale.micro.reading import read_topography
    np.save(tmp_path / "tiny.npy", np.random.default_rng(1).normal(size=(16, 16)) * 1e-170)
    with pytest.raises(InputError, match=r"'tiny.npy': heights up to .* m underflow .*: is height_unit right\?"):
        read_topography(tmp_path / "tiny.npy", pixel_size=1e-6)

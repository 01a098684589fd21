"""Measured surfaces in use (issue 17): `multiscale surface FILE` (steps, statistics, figure),
scenes with `[roughness] file = ...` (validated by `multiscale check` from the file itself), and the
zones the one rough-interface builder makes from them."""
import collections
import dataclasses
import os
import re
import subprocess
import sys
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np
import pytest
import SurfaceTopography as ST

import multiscale.cli as cli
from multiscale.cli import main
from multiscale.errors import InputError, SceneError
from multiscale.micro import filters, reading, topography
from multiscale.micro.spectrum import statistics_memory, surface_statistics
from multiscale.micro.surface import Surface
from multiscale.micro.topography import condition, cover, read_topography
from multiscale.scene import loads

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
TOP = DATA / "top-1.top"
SCENE = (ROOT / "demos" / "block_on_flat.toml").read_text().replace(
    'effects = ["contact"]', 'effects = ["contact", "roughness"]').replace('penalty = "1e13 Pa/m"', "") + """
[roughness]
body = "block"
{roughness}
[micro]
zones = [2, 2]
{micro}
"""


GRID = "grid = [16, 16]"     # micro.grid of scenes whose file's pixels give too many cells (topography.MAX_CELLS)


def scene(tmp_path, roughness, micro=""):
    return loads(SCENE.format(roughness=roughness, micro=micro), tmp_path)


def apart(found) -> tuple:
    """The scene's warnings but the micro grid's on the measured gradient (``topography.coarse_grid``:
    top-1.top's 0.6 um measurement on the block's 10 mm face keeps none of it, and says so) and
    those of the copies that cover it (``topography.copy_notes``, tested on their own)."""
    return tuple(w for w in found if "of the measured RMS gradient" not in w
                 and not (w.startswith("roughness.cover") and ("pattern repeats" in w or "fewer than 4 cells" in w)))


def test_check_says_what_the_copies_of_a_small_measurement_lose_as_the_run_does(tmp_path):
    """top-1.top (0.77 um wide at the scene's 3 nm pixels) tiled or mirrored over the block's 10 mm
    face: check warns, as the run's cover does (and before the run only the run did: a user
    trial), that the pattern repeats and that it spans fewer than 4 cells of the micro grid; the
    run's warnings are the same sentences. Mirrored, the run's cover samples the copies where they lie
    (it tiled the 4-point periods over 10 mm: 26k x 26k points, 5 GB and a minute)."""
    import tracemalloc
    import warnings

    from multiscale.micro.reading import read_topography
    from multiscale.micro.topography import condition, cover
    for method in ("tile", "mirror"):
        s = scene(tmp_path, f'file = "{TOP}"\npixel_size = "3 nm"\ncover = "{method}"', GRID)
        said = [w for w in s.warnings if w.startswith(f'roughness.cover = "{method}"')]
        assert len(said) == 2 and "spans fewer than 4 cells of the micro grid" in said[0], said
        assert "copies; wavelengths longer than" in said[1] and said[1].endswith("the pattern repeats")
        done = condition(read_topography(TOP, pixel_size=3e-9, prefix="roughness."), "plane", prefix="roughness.")
        tracemalloc.start()
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            lines = cover(done.surface, (32, 32), (10e-3, 10e-3), method, prefix="roughness.")[1]   # 2 x 2 zones of 16^2
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert [line.removeprefix("warning: ") for line in lines if "roughness.cover" in line] == said
        assert peak < 50e6, peak        # (mirrored: 5.4 GB before)


def test_surface_command_prints_the_steps_and_surfacetopographys_sq(tmp_path, capsys):
    figure = tmp_path / "top.png"
    assert main(["surface", str(TOP), "--figure", str(figure)]) == 0
    out = capsys.readouterr().out
    sq = ST.open_topography(str(TOP)).topography().detrend("height").Sq()      # nm
    assert f"Sq   RMS height              {sq:.4g} nm" in out
    assert "read top-1.top, channel 0 (\"Default\"): 256 x 256 points" in out and "form removed" in out
    for row in ("Sdq  RMS gradient", "Ssk  skewness", "Sku  kurtosis", "Nayak parameter", "summit density",
                "Hurst exponent H (PSD fit)", "long cut-off", "short cut-off"):
        assert row in out
    assert figure.stat().st_size > 10_000 and f"figure: {figure}" in out
    assert main(["surface", str(TOP), "--cutoff", "0.1 um", "--detrend", "poly2", "--figure", "none"]) == 0
    out = capsys.readouterr().out
    assert "Gaussian filter (ISO 16610-61) at λc = 0.0001 mm" in out and "statistics of the roughness" in out
    # --height-unit takes a unit's name as a scene's roughness.height_unit does (it was refused)
    for unit in ("um", "1 um"):
        assert main(["surface", str(TOP), "--height-unit", unit, "--figure", "none"]) == 0
        assert f"Sq   RMS height              {sq:.4g} um" in capsys.readouterr().out   # its nm read as um


@pytest.mark.parametrize("args, message", [
    (["--channel", "2"], 'error: --channel = 2: top-1.top has the channels 0 "Default" (2-D)'),
    (["--cutoff", "3 kg"], 'error: --cutoff = \'3 kg\': expected a length'),
    (["--cutoff", "1 nm"], "error: --cutoff: λc = 0.001 um must span at least 2 pixels (0.004688 um): top-1.top's pixels"),
    # ISO cut-offs are said in mm: "--cutoff 0.8" filtered at 0.8 m, "little is removed", and went on; with a
    # unit it is taken as meant (a user trial read the refusal as one of 0.8 m)
    (["--cutoff", "0.8"], "error: --cutoff = '0.8': 0.8 m, longer than the measurement (0.6 x 0.6 um); plain "
                          'numbers are metres: give a unit ("0.8 m" filters at 0.8 m anyway)'),
    (["--cutoff", "2e-4"], "error: --cutoff = '2e-4': 0.0002 m, longer than the measurement (0.6 x 0.6 um); plain "
                           'numbers are metres: did you mean "2e-4 mm"? ("2e-4 m" filters'),
])
def test_surface_command_bad_options_are_one_line(capsys, args, message):
    assert main(["surface", str(TOP), "--figure", "none", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("figure, message", [("missing_folder/x.png", "no folder "),
                                             ("x.txt", "a figure is a .avif, .eps, "),
                                             ("x", "(matplotlib), not a name without extension")])
def test_surface_command_figure_that_cannot_be_written_is_one_line(tmp_path, capsys, figure, message):
    """(A traceback from matplotlib before; an adversarial test.) Said before the analysis, which
    takes minutes on a large file (it came after the statistics); a name without extension was
    written as NAME.png while the command said NAME."""
    assert main(["surface", str(TOP), "--figure", str(tmp_path / figure)]) == 2
    out, err = capsys.readouterr()
    assert err.startswith("error: --figure = ") and "cannot write the figure there: " in err
    assert message in err and len(err.strip().splitlines()) == 1
    assert out == "" and list(tmp_path.iterdir()) == []


def test_surface_command_warnings_name_its_options_a_scenes_warnings_its_keys(tmp_path, capsys):
    """`multiscale surface FILE --height-unit ... --pixel-size ...` warned "height_unit = ... overrides"
    and "file = '...': ... is height_unit right?" (the scene's keys) where its errors say --height-unit
    and FILE. Now its options (reading.option); the scene's warnings of the same file keep its keys."""
    assert main(["surface", str(TOP), "--height-unit", "1 mm", "--pixel-size", "3 nm", "--figure", "none"]) == 0
    warned = [line for line in capsys.readouterr().out.splitlines() if line.startswith("warning: ")]
    heights = ("'top-1.top': heights up to 0.134 m (Sq 0.00315 m, one unit of the file = 0.001 m), far beyond a "
               "rough surface's: is {}height_unit right?")
    assert warned == ["warning: --pixel-size 3e-09 x 3e-09 m overrides the file's 2.344e-09 x 2.344e-09 m",
                      "warning: --height-unit 0.001 m overrides the file's unit (nm = 1e-09 m)",
                      "warning: FILE = " + heights.replace("{}height_unit", "--height-unit")]
    s = scene(tmp_path, f'file = "{TOP}"\nheight_unit = "1 mm"\npixel_size = "3 nm"\ncover = "tile"', GRID)
    assert apart(s.warnings) == ("roughness.pixel_size = 3e-09 x 3e-09 m overrides the file's 2.344e-09 x 2.344e-09 m",
                          "roughness.height_unit = 0.001 m overrides the file's unit (nm = 1e-09 m)",
                          "roughness.file = " + heights.format("roughness."))


def test_surface_command_lists_the_formats(capsys):
    assert main(["surface", "--formats"]) == 0
    assert "XML 3D surface profile (X3P) (.x3p)" in capsys.readouterr().out


def test_scene_reads_a_measured_file_with_its_options(tmp_path):
    s = scene(tmp_path, f'file = "{TOP}"\nchannel = 0\ndetrend = "poly2"\ncutoff = "1 mm"\ncover = "mirror"\n'
                        'seed = 4\nmax_undefined = 0.2', GRID)   # ("equivalent" of 0.6 um on 10 mm: refused, flat)
    r = s.roughness            # (a cut-off of 2 cells at least: 0.625 mm, longer than the 0.6 um map)
    assert (r.file, r.channel, r.detrend, r.cutoff, r.cover, r.seed, r.max_undefined) == (
        TOP, 0, "poly2", pytest.approx(1e-3), "mirror", 4, 0.2)
    assert r.pixel_size is None and r.height_unit is None
    assert [w.split(":")[0] for w in apart(s.warnings)] == ["roughness.cutoff = 1000 um is longer than the measurement "
                                                            "(0.6 x 0.6 um)"]
    assert [w for w in s.warnings if "resolve 0.0% of the measured RMS gradient" in w]
    over = scene(tmp_path, f'file = "{TOP}"\npixel_size = "3 nm"\ncover = "tile"', GRID)
    assert apart(over.warnings) == ("roughness.pixel_size = 3e-09 x 3e-09 m overrides the file's 2.344e-09 x 2.344e-09 m",)


@pytest.mark.parametrize("roughness, fragment", [
    ('file = "pad.x3p"', "roughness.file = 'pad.x3p': cannot read it as a topography: as XML 3D surface profile "
                        "(X3P), FileFormatMismatch: Stream is not a valid ZIP archive"),
    (f'file = "{TOP}"\nchannel = 4', 'roughness.channel = 4: top-1.top has the channels 0 "Default" (2-D)'),
    (f'file = "{DATA / "opdx-3.opdx"}"', "is a 1-D profile (line scan): a height map (2-D) is needed"),
    ('file = "pad.npy"', "roughness.pixel_size: pad.npy is a plain height matrix without units"),
    (f'file = "{TOP}"\ncover = "stretch"', 'roughness.cover = "stretch": unknown'),
    (f'file = "{TOP}"\nhurst = 0.5', "roughness.hurst: only used with roughness.rms"),
    (f'file = "{TOP}"\ncutoff = "1 nm"', "roughness.cutoff: λc = 0.001 um must span at least 2 pixels (0.004688 um): "
                                         "top-1.top's pixels"),       # before: refused by the run, after meshing
])
def test_check_reports_a_bad_measured_file_from_the_file_itself(tmp_path, roughness, fragment):
    (tmp_path / "pad.x3p").write_bytes(b"\x00garbage" * 50)
    np.save(tmp_path / "pad.npy", np.zeros((8, 8)))
    with pytest.raises(SceneError) as info:
        scene(tmp_path, roughness)
    assert any(fragment in p for p in info.value.problems), info.value.problems


def test_check_of_a_bad_file_runs_nothing_heavy(tmp_path):
    (tmp_path / "pad.x3p").write_bytes(b"\x00garbage" * 50)
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(roughness='file = "pad.x3p"', micro=""))
    code = ("import sys; from multiscale.cli import main; rc = main(['check', sys.argv[1]]); "
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('dolfinx', 'gmsh', 'numba', 'pyfftw')); "
            "assert not heavy, heavy; sys.exit(rc)")
    result = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True)
    assert result.returncode == 2, result.stderr
    assert "error: roughness.file = 'pad.x3p': cannot read it as a topography" in result.stderr


def test_zones_from_a_measured_file_for_every_cover(tmp_path):
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import rough

    def make_zones(s, *args, cover=None, grid=None, **kwargs):       # cover, micro.grid: instead of the scene's
        r = s.roughness if cover is None else dataclasses.replace(s.roughness, cover=cover)
        return rough.make_zones(r, dataclasses.replace(s.micro, grid=grid), *args, **kwargs)

    lo = (0.0, 0.0)
    lines = []
    with warnings.catch_warnings():
        warnings.simplefilter("error")             # the warnings come as report lines, not per rank
        grid, zones = make_zones(scene(tmp_path, f'file = "{TOP}"\ncover = "mirror"', GRID),
                                 lo, (2e-6, 1e-6), seed=0, log=lines.append, grid=(64, 32))
    assert len(zones) == 4 and zones[0].shape == (32, 64) and grid.size == pytest.approx((1e-6, 0.5e-6))
    assert any(line.startswith("roughness: warning: roughness.cover = \"mirror\"") for line in lines)
    # the measurement as it is: its own pixels, rounded to whole cells per zone (on the faces given
    # here: the scene's 10 mm block, which it cannot cover, is refused when the scene is read, and
    # without micro.grid its zones would take 1.7 million cells per side)
    tiled = scene(tmp_path, f'file = "{TOP}"\ncover = "tile"', GRID)
    as_is = dataclasses.replace(tiled.roughness, cover="measured")
    pixels = dataclasses.replace(tiled.micro, grid=None)
    grid, zones = rough.make_zones(as_is, pixels, lo, (0.3e-6, 0.3e-6), seed=0)
    assert zones[0].shape == (64, 64) and zones[0].surface.dx == pytest.approx(0.15e-6 / 64)
    with pytest.raises(InputError, match=r'roughness\.cover = .measured.: the measurement \(0\.0006 x 0\.0006 mm\) '
                                         r'does not cover the interface'):
        rough.make_zones(as_is, pixels, lo, (1e-6, 1e-6), seed=0)
    # a statistically equivalent face: 50 x 50 cells per zone unless micro.grid says otherwise, seeded
    # (on the faces given here: on the block's, the 0.6 um measurement is shorter than a cell)
    eq = scene(tmp_path, f'file = "{TOP}"\ncover = "tile"\nseed = 3', GRID)
    lines = []
    _, a = make_zones(eq, lo, (4e-6, 4e-6), seed=10, log=lines.append, cover="equivalent")
    _, b = make_zones(eq, lo, (4e-6, 4e-6), seed=10, cover="equivalent")
    assert a[0].shape == (50, 50) and np.array_equal(a[3].surface.heights, b[3].surface.heights)
    assert any("statistically equivalent surface" in line for line in lines)
    # what overrides the file is a warning of the scene (printed at the start of a run), not a report
    # line again (it was printed twice)
    over = scene(tmp_path, f'file = "{TOP}"\npixel_size = "3 nm"\ncover = "tile"', GRID)
    lines = []
    make_zones(over, lo, (4e-6, 4e-6), seed=10, log=lines.append, cover="equivalent")
    assert apart(over.warnings) == ("roughness.pixel_size = 3e-09 x 3e-09 m overrides the file's 2.344e-09 x 2.344e-09 m",)
    assert lines[0].startswith("roughness: read top-1.top") and not any("overrides" in line for line in lines)


def test_a_measurement_smaller_than_the_face_is_refused_by_check_before_meshing(tmp_path):
    """A measurement used as it is (cover = "measured") that does not cover the interface passed
    `multiscale check` and was refused by a run after meshing. Now check refuses it, and a run
    stops before meshing, with the run's own message, from the builder's face (the block's
    10 x 10 mm); one that covers the face passes."""
    rng = np.random.default_rng(1)
    np.save(tmp_path / "short.npy", rng.normal(0.0, 1e-6, (64, 48)))      # 9.6 x 12.8 mm at 200 um
    np.save(tmp_path / "wide.npy", rng.normal(0.0, 1e-6, (64, 64)))       # 12.8 x 12.8 mm
    for name in ("short", "wide"):
        (tmp_path / f"{name}.toml").write_text(SCENE.format(
            roughness=f'file = "{name}.npy"\npixel_size = "200 um"', micro="grid = [16, 16]").replace(
            'folder = "../results/block_on_flat"', f'folder = "{tmp_path / name}"'))
    code = ("import sys; from multiscale.cli import main; rcs = [main([c, sys.argv[1]]) for c in ('check', 'run')]; "
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('dolfinx', 'gmsh')); "
            "assert not heavy, heavy; sys.exit(max(rcs))")
    result = subprocess.run([sys.executable, "-c", code, str(tmp_path / "short.toml")], capture_output=True, text=True)
    # the run's refusal of that face (multiscale.workflows.rough.measured_face, after meshing)
    measured = read_topography(tmp_path / "short.npy", pixel_size=2e-4)
    with pytest.raises(InputError) as later:
        cover(condition(measured).surface, (32, 32), (10e-3, 10e-3), "measured", prefix="roughness.")
    message = ("roughness.cover = 'measured': the measurement (9.6 x 12.8 mm) does not cover the interface (10 x 10 mm): "
               'use "equivalent" (a statistically equivalent surface) or "mirror"/"tile" (copies)')
    assert str(later.value) == message
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines() == [f"error: {message}", f"{tmp_path / 'short.toml'}: 1 problem",
                                          f"error: {message}"]
    assert main(["check", str(tmp_path / "wide.toml")]) == 0
    # other covers than "measured" take a small measurement (with a warning, at the run)
    assert scene(tmp_path, 'file = "short.npy"\npixel_size = "200 um"\ncover = "tile"').roughness.cover == "tile"


def test_an_equivalent_cover_the_grid_cannot_resolve_is_refused_by_check_before_meshing(tmp_path):
    """cover = "equivalent" from a measurement shorter than a cell of the face's micro grid along
    both axes (x3p-2.x3p's 0.08 x 0.2 mm on the 312.5 um cells of the block's 10 mm face at 2 x 16)
    passed `multiscale check`; the run refused its flat surface when it built the zones, after
    meshing. Now the scene's check, which a run makes before meshing, refuses it with the run's
    message under the interface's own key; 0.4 mm along one axis passes."""
    rng = np.random.default_rng(4)
    np.save(tmp_path / "wide.npy", rng.normal(0.0, 1e-6, (64, 64)))       # 12.8 mm at 200 um: [roughness]
    np.save(tmp_path / "small.npy", rng.normal(0.0, 1e-6, (40, 16)))      # 0.08 x 0.2 mm at 5 um
    own = ('grid = [16, 16]\n[interfaces.interface.roughness]\nfile = "small.npy"\npixel_size = "{pixel}"\n'
           'cover = "equivalent"')
    with pytest.raises(SceneError) as info:
        scene(tmp_path, 'file = "wide.npy"\npixel_size = "200 um"', own.format(pixel="5 um"))
    # the run's refusal of that face (multiscale.workflows.rough.measured_face, after meshing)
    measured = condition(read_topography(tmp_path / "small.npy", pixel_size=5e-6)).surface
    with pytest.raises(InputError) as later:
        cover(measured, (32, 32), (10e-3, 10e-3), "equivalent", prefix="interfaces.interface.roughness.")
    assert info.value.problems == [str(later.value)]
    assert str(later.value).startswith("interfaces.interface.roughness.cover = 'equivalent': the measurement (0.08 x "
                                       "0.2 mm) holds no wavelength the micro grid resolves (32 x 32 cells of 312.5")
    scene(tmp_path, 'file = "wide.npy"\npixel_size = "200 um"', own.format(pixel="10 um"))     # 0.16 x 0.4 mm


def test_cells_from_the_pixels_beyond_the_cap_are_refused_by_check_before_meshing(tmp_path):
    """Without micro.grid a zone takes the measurement's pixels as its cells, at most
    topography.MAX_CELLS per side: 2 um pixels on the block's 10 mm face at 2 x 2 zones give 2500
    (5 um: 1000). The cap was the run's, after meshing; now the scene's check (which a run makes
    before meshing) refuses it with the run's message (topography.zone_cells, which both ask);
    micro.grid lifts it."""
    np.save(tmp_path / "fine.npy", np.random.default_rng(2).normal(0.0, 1e-6, (64, 64)))
    tiled = 'file = "fine.npy"\npixel_size = "{}"\ncover = "tile"'
    with pytest.raises(SceneError) as info:
        scene(tmp_path, tiled.format("2 um"))
    with pytest.raises(InputError) as later:        # the run's rule (workflows.rough.measured_face)
        topography.zone_cells(None, "tile", (10e-3, 10e-3), (2, 2), (2e-6, 2e-6), (50, 50), "fine.npy")
    assert info.value.problems == [str(later.value)]
    assert str(later.value) == ("micro.grid: fine.npy's pixels give 2500 x 2500 cells per zone: set micro.grid "
                                "(at most 1024 without it)")
    assert topography.zone_cells(None, "tile", (10e-3, 10e-3), (2, 2), (5e-6, 5e-6), (50, 50), "f") == (1000, 1000)
    assert topography.zone_cells(None, "equivalent", (10e-3, 10e-3), (2, 2), (2e-6, 2e-6), (50, 50), "f") == (50, 50)
    assert topography.zone_cells([16, 8], "tile", (10e-3, 10e-3), (2, 2), (2e-6, 2e-6), (50, 50), "f") == (16, 8)
    scene(tmp_path, tiled.format("5 um"))
    scene(tmp_path, tiled.format("2 um"), "grid = [64, 64]")


def test_a_rewritten_measured_file_changes_the_runs_fingerprint(tmp_path):
    """``--resume`` compares fingerprints: a measured surface rewritten under the same name makes
    another one (before, the resume went on: the checkpoint's worn heights against the new file's
    unworn ones gave wear depths 12 % off; an adversarial test); the same bytes the same one."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale import checkpoint
    from multiscale.workflows.output import fingerprint
    heights = np.random.default_rng(1).normal(size=(64, 64))
    np.save(tmp_path / "pad.npy", heights)
    text = 'file = "pad.npy"\npixel_size = "10 um"\nheight_unit = "um"\ncover = "tile"'
    before = fingerprint(scene(tmp_path, text))
    np.save(tmp_path / "pad.npy", heights)
    assert fingerprint(scene(tmp_path, text)) == before
    np.save(tmp_path / "pad.npy", 3 * heights)
    after = fingerprint(scene(tmp_path, text))
    assert after.digest != before.digest
    assert checkpoint.changes(before.inputs, after.inputs) == [f"file {tmp_path / 'pad.npy'} (other bytes)"]


def test_surface_command_writes_no_figure_unless_asked(tmp_path, monkeypatch, capsys):
    """Without --figure nothing is written: it wrote FILE-stem_surface.png into the working folder,
    the stray *_surface.png files found in the repository's root."""
    monkeypatch.chdir(tmp_path)
    assert main(["surface", str(TOP)]) == 0
    assert list(tmp_path.iterdir()) == []
    assert "figure: none written (--figure PATH.png" in capsys.readouterr().out
    assert main(["surface", str(TOP), "--figure", "none"]) == 0
    assert list(tmp_path.iterdir()) == [] and "figure:" not in capsys.readouterr().out


def test_a_missing_option_is_named_without_a_python_value(tmp_path, capsys):
    """A missing option or key is named, not shown as a Python value: "--pixel-size = None: h.npy
    is a plain height matrix ..." was the error of `multiscale surface h.npy` (an adversarial review)."""
    np.save(tmp_path / "h.npy", np.zeros((8, 8)))
    assert main(["surface", str(tmp_path / "h.npy")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        'error: --pixel-size: h.npy is a plain height matrix without units: give its pixel size, e.g. "0.5 um"']
    assert str(InputError("roughness.height_unit", None, "give it")) == "roughness.height_unit: give it"
    assert str(InputError("x", 0, "must be > 0")) == "x = 0: must be > 0"        # a value is still shown


@pytest.mark.parametrize("pixel, problem", [
    ("10", 'roughness.pixel_size = 10: 10 m per pixel; a measured surface\'s pixel is far below 1 mm (refused from '
           '1 mm up); plain numbers are metres: did you mean "10 um"?'),
    ('["0.5 um", "2 mm"]', 'roughness.pixel_size = ["0.5 um", "2 mm"]: item 2 ("2 mm"): 0.002 m per pixel; a '
                           "measured surface's pixel is far below 1 mm (refused from 1 mm up)"),
])
def test_a_pixel_size_of_a_millimetre_or_more_is_refused(tmp_path, pixel, problem):
    """pixel_size = 10 is a 10 m pixel (plain numbers are metres) and passed check silently (an
    adversarial review); a measured surface's pixel is far below 1 mm."""
    np.save(tmp_path / "pad.npy", np.random.default_rng(1).normal(0.0, 1e-6, (24, 24)))    # 12 mm at 0.5 mm
    with pytest.raises(SceneError) as info:
        scene(tmp_path, f'file = "pad.npy"\npixel_size = {pixel}')
    assert info.value.problems == [problem]
    assert scene(tmp_path, 'file = "pad.npy"\npixel_size = "0.5 mm"').roughness.pixel_size == (5e-4, 5e-4)


def test_a_pixel_size_of_a_millimetre_or_more_is_refused_on_the_command_line(tmp_path, capsys):
    """`multiscale surface h.npy --pixel-size 10` read a 10 m pixel (the scene's limit was not the
    command's): the same refusal and hint."""
    np.save(tmp_path / "h.npy", np.random.default_rng(1).normal(0.0, 1e-6, (8, 8)))
    for given, hint in (("10", '; plain numbers are metres: did you mean "10 um"?'), ("2 mm", "")):
        assert main(["surface", str(tmp_path / "h.npy"), "--pixel-size", given]) == 2
        assert capsys.readouterr().err.splitlines() == [
            f"error: --pixel-size = {given!r}: {float(given.split()[0]) * (1e-3 if 'mm' in given else 1):g} m per "
            f"pixel; a measured surface's pixel is far below 1 mm (refused from 1 mm up){hint}"]
    assert main(["surface", str(tmp_path / "h.npy"), "--pixel-size", "0.5 um"]) == 0


def test_a_map_too_large_for_the_memory_is_refused_before_its_statistics(monkeypatch, capsys):
    """An 8000 x 8000 map took 20 GB for its statistics (2 min): beyond the memory available, the
    OOM killer ends the command without a word; it is refused first, naming the file."""
    monkeypatch.setattr(cli, "memory_available", lambda: 1e6)
    assert main(["surface", str(TOP)]) == 2
    out, err = capsys.readouterr()
    assert err.splitlines() == ["error: FILE = 'top-1.top': 256 x 256 points: their statistics need about 0.0027 GB "
                                "of memory, 0.001 GB are available: crop or coarsen the map first"] and out == ""
    monkeypatch.setattr(cli, "memory_available", lambda: None)       # unknown (not Linux): no check
    assert main(["surface", str(TOP), "--figure", "none"]) == 0


def test_the_memory_of_the_statistics_is_what_they_take():
    """``statistics_memory`` against the peak that tracemalloc sees (numpy's arrays included), 5 %:
    25 bytes a point on white noise (the most summits; old code: 300, the mirror-stitched
    periodogram), from 512 x 640 points (on fewer, the row blocks' temporaries of a few MB count)."""
    s = Surface(np.random.default_rng(2).normal(0.0, 1e-7, (512, 640)), 1e-6, 1e-6, periodic=False)
    surface_statistics(s)          # first call: imports and caches out of the count
    tracemalloc.start()
    try:
        surface_statistics(s)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak == pytest.approx(statistics_memory(s.shape), rel=0.05)


def test_the_memory_check_counts_what_the_command_takes(tmp_path, capsys):
    """``cli.surface_memory`` against the peak tracemalloc sees over the whole command (reading,
    conditioning, statistics), 5 %: the measurement and the conditioned heights are held while the
    statistics run (old check: the statistics alone, 16 bytes a point short)."""
    path = tmp_path / "noise.npy"
    np.save(path, np.random.default_rng(2).normal(0.0, 1e-7, (512, 640)))
    args = ["surface", str(path), "--pixel-size", "1 um", "--figure", "none"]
    assert main(args) == 0              # first call: imports and caches out of the count
    tracemalloc.start()
    try:
        assert main(args) == 0
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    capsys.readouterr()
    assert peak == pytest.approx(cli.surface_memory((512, 640)), rel=0.05)


def test_a_measured_file_is_read_and_searched_for_outliers_once(tmp_path, monkeypatch):
    """A scene with a measured surface read its file three times and searched it for outliers twice
    in one `multiscale run` (the scene's check of the file, its cover check, the zones): 5 s a search
    on a 4000² map. Now once; a changed file is read again, and one just written is not kept (file
    times are as coarse as a clock tick: its next change might keep them)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import rough      # local: imports DOLFINx
    calls = collections.Counter()

    def counted(name, f):
        def call(*args, **kwargs):
            calls[name] += 1
            return f(*args, **kwargs)
        return call

    monkeypatch.setattr(reading, "read_matrix", counted("read", reading.read_matrix))
    monkeypatch.setattr(topography, "find_outliers", counted("search", topography.find_outliers))
    path, old = tmp_path / "map.npy", time.time() - 60
    np.save(path, np.random.default_rng(2).normal(0.0, 1e-6, (64, 64)))   # 12.8 mm at 200 um: covers the block
    os.utime(path, (old, old))
    s = scene(tmp_path, 'file = "map.npy"\npixel_size = "200 um"', "grid = [16, 16]")
    zones = rough.make_zones(s.roughness, s.micro, (0.0, 0.0), (10e-3, 10e-3), seed=0)[1]
    assert calls == {"read": 1, "search": 1}
    assert not read_topography(path, pixel_size=2e-4, prefix="roughness.").heights.flags.writeable    # shared
    np.save(path, -np.load(path))          # the same size, a later time
    os.utime(path, (old + 1, old + 1))
    again = rough.make_zones(s.roughness, s.micro, (0.0, 0.0), (10e-3, 10e-3), seed=0)[1]
    assert calls == {"read": 2, "search": 2}
    assert np.allclose(again[0].surface.heights, -zones[0].surface.heights, rtol=0, atol=1e-18)
    np.save(path, np.load(path))           # just written
    for _ in range(2):
        read_topography(path, pixel_size=2e-4, prefix="roughness.")
    assert calls["read"] == 4


def test_an_interfaces_own_measured_file_is_named_by_its_key_and_read_once(tmp_path, monkeypatch):
    """With [interfaces.<name>.roughness] the zones' read and errors said "roughness." where the
    scene's check said "interfaces.<name>.roughness.", and the run read the file again."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import rough      # local: imports DOLFINx
    reads = []
    monkeypatch.setattr(reading, "read_matrix", lambda path: reads.append(path) or np.load(path))
    np.save(tmp_path / "map.npy", np.random.default_rng(3).normal(0.0, 1e-6, (64, 64)))
    os.utime(tmp_path / "map.npy", (1e9, 1e9))       # long settled: kept
    s = scene(tmp_path, 'file = "map.npy"\npixel_size = "300 um"', "grid = [16, 16]\n"
              '[interfaces.interface.roughness]\nfile = "map.npy"\npixel_size = "200 um"')
    own = s.interface_settings("interface")
    prefix = f"{s.roughness_key('interface')}."
    assert prefix == "interfaces.interface.roughness." and len(reads) == 2     # the [roughness] table's too
    rough.make_zones(own.roughness, own.micro, (0.0, 0.0), (10e-3, 10e-3), seed=0, prefix=prefix)
    assert len(reads) == 2
    with pytest.raises(InputError, match=r"^interfaces\.interface\.roughness\.cover = 'measured': the measurement "
                                         r"\(12\.8 x 12\.8 mm\) does not cover"):
        rough.make_zones(own.roughness, own.micro, (0.0, 0.0), (20e-3, 20e-3), seed=0, prefix=prefix)


def test_a_micro_grid_too_coarse_for_the_measured_gradient_is_warned_about(tmp_path):
    """The real contact area follows the RMS gradient (Bush, Gibson & Thomas 1975), which a micro grid
    coarser than the measurement's pixels loses: a user trial's x3p file on 41.6 um cells kept 1 % of
    it, and check said nothing. ``topography.kept_gradient`` (the PSD's gradient below the grid's
    Nyquist) is the gradient ratio of the equivalent surface drawn on that grid within 15 %; check
    warns below ``GRADIENT_KEPT`` with the cells that keep that much, and they do (to 2 %)."""
    from multiscale.micro.spectrum import surface_statistics
    from multiscale.micro.surface import fractal_surface
    f = fractal_surface((256, 256), (2.56e-3, 2.56e-3), 0.3, 1, 128, 1e-6, seed=2)
    measured = Surface(f.heights, f.dx, f.dy, periodic=False)
    np.save(tmp_path / "pad.npy", measured.heights)
    for pixels in (2, 8):
        cell = (pixels * measured.dx, pixels * measured.dy)
        with warnings.catch_warnings(record=True):        # the run's report line instead (below half: 8 pixels)
            drawn, lines = cover(measured, (256 // pixels, 256 // pixels), measured.size, "equivalent")
        assert any("of the measured RMS gradient" in line for line in lines) == (pixels == 8)
        ratio = surface_statistics(drawn).Sdq / surface_statistics(measured).Sdq
        assert topography.kept_gradient(measured, cell) == pytest.approx(ratio, rel=0.15)
    s = scene(tmp_path, 'file = "pad.npy"\npixel_size = "10 um"\ncover = "equivalent"', "grid = [50, 50]")
    (warned,) = [w for w in s.warnings if "of the measured RMS gradient" in w]       # 100 um cells
    kept = topography.kept_gradient(condition(read_topography(tmp_path / "pad.npy", pixel_size=1e-5)).surface,
                                    (1e-4, 1e-4))
    assert kept < topography.GRADIENT_KEPT and f"resolve {kept:.1%} of" in warned
    half = float(warned.split("cells of ")[1].split(" x")[0]) * 1e-6       # the cells it names
    assert topography.kept_gradient(measured, (half, half)) == pytest.approx(topography.GRADIENT_KEPT, rel=0.02)
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import rough
    for said in (False, True):    # a run repeats it only where the scene's check could not (a face's extent unknown)
        lines = []                # before meshing); it said it twice, with 78.12 and 78.13 um cells
        rough.make_zones(s.roughness, s.micro, (0.0, 0.0), (10e-3, 10e-3), seed=0, log=lines.append, warned=said)
        assert sum("of the measured RMS gradient" in line for line in lines) == (not said)
    assert "interface" in s.geometry.spec.interface_extents        # so a run of this scene says it once
    fine = scene(tmp_path, 'file = "pad.npy"\npixel_size = "10 um"\ncover = "equivalent"', "grid = [500, 500]")
    assert not [w for w in fine.warnings if "of the measured RMS gradient" in w]      # 10 um cells: the pixels


SHARED = next((p for p in (Path(os.environ.get("MULTISCALE_TOPOGRAPHIES", "/nonexistent")),
                           Path(__file__).resolve().parents[2] / "shared/data/topographies") if p.is_dir()), None)


@pytest.mark.skipif(SHARED is None, reason="../shared/data/topographies not here")
@pytest.mark.parametrize("name, warned", [("x3p-2.x3p", True), ("opd-1.opd", True), ("plu-1.plu", False),
                                          ("sur-2.sur", False)])
def test_an_equivalent_surface_from_beyond_the_measurement_is_warned_about(name, warned):
    """On 78 um cells an 83 x 204 um x3p map gave an equivalent surface of 13 nm from ~5 modes, 99 % of
    its power in the mirror-stitched spectrum's first modes (wavelengths longer than the map: its
    form, not roughness), and an opd map one of 0.12 nm whose zone laws failed naming p_max; check
    said OK (a user trial). The share is computed here from the mirror-stitched map's FFT."""
    done = condition(read_topography(SHARED / name))
    cell = (20e-3 / 256, 20e-3 / 256)
    t = ST.Topography(done.surface.heights.T, done.surface.size).mirror_stitch()
    h = np.asarray(t.heights()).T                      # (2 my, 2 mx), period 2 m
    C = np.abs(np.fft.fft2(h)) ** 2
    ky, kx = (np.fft.fftfreq(n, 1 / n) for n in h.shape)
    (Py, Px) = 2 * done.surface.size[1], 2 * done.surface.size[0]
    band = (np.abs(ky)[:, None] * 2 * np.pi / Py <= np.pi / cell[1]) & (np.abs(kx)[None, :] * 2 * np.pi / Px
                                                                          <= np.pi / cell[0])
    band[0, 0] = False
    first = (np.abs(ky)[:, None] == 1) | (np.abs(kx)[None, :] == 1)
    share = C[band & first].sum() / C[band].sum()
    note = topography.beyond_measurement(done.surface, cell, "roughness.")
    assert (note is not None) == warned == (share > topography.LONG_POWER)
    if warned:
        assert f"roughness.file: {share:.0%} of the power the equivalent surface draws" in note


def test_a_missing_micro_grid_does_not_hide_that_the_measurement_does_not_cover_the_face(tmp_path):
    """check said only "set micro.grid" and the measurement's cover came out once the grid was set:
    not every problem at once (a user trial)."""
    with pytest.raises(SceneError) as info:
        scene(tmp_path, f'file = "{TOP}"\ncover = "measured"')
    problems = "\n".join(info.value.problems)
    assert "set micro.grid" in problems and "does not cover the interface" in problems


def test_a_cutoff_longer_than_the_measurement_is_warned_about(tmp_path):
    """cutoff = 8 mm on a 1.3 mm measurement passed check without a word (a user trial); top-1.top
    spans 0.6 um."""
    s = scene(tmp_path, f'file = "{TOP}"\ncover = "tile"\ncutoff = "1 mm"', GRID)
    assert any(w.startswith("roughness.cutoff = 1000 um is longer than the measurement (0.6") for w in s.warnings), \
        s.warnings


@pytest.mark.parametrize("cover", ["tile", "equivalent"])
def test_a_cutoff_shorter_than_two_micro_cells_is_refused(tmp_path, cover):
    """The roughness a filter at λc leaves (wavelengths below about λc) is finer than micro cells
    over λc / 2: the face's surface was nearly flat (a user trial: Sq 0.0003 of 0.0103 um) and check
    warned only of the gradient the grid missed. The block's 10 mm face in 2 x 16 cells: 312.5 um;
    a cut-off of 2 cells passes."""
    wide = 'file = "{}"\ncover = "{}"\npixel_size = "4 um"\ncutoff = "{}"'     # 1 mm wide: "equivalent" resolves it
    with pytest.raises(SceneError) as info:
        scene(tmp_path, wide.format(TOP, cover, "600 um"), GRID)
    assert info.value.problems == ["roughness.cutoff: λc = 600 um must span at least 2 cells of the micro grid (625 "
                                   "um): the roughness the filter leaves is finer than the grid, whose surface would "
                                   "be nearly flat; use a finer micro.grid or a longer cutoff"]
    s = scene(tmp_path, wide.format(TOP, cover, "625 um"), GRID)
    assert not any("longer than the measurement" in w for w in s.warnings)      # 625 um of a 1.024 mm map
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.workflows import rough      # local: imports DOLFINx
    short = dataclasses.replace(s.roughness, cutoff=600e-6)     # the run's own check (a face check did not know)
    with pytest.raises(InputError, match=r"^roughness.cutoff: λc = 600 um must span at least 2 cells of the micro "
                                         r"grid \(625 um\)"):
        rough.measured_face(short, s.micro, (2, 2), np.array([10e-3, 10e-3]), seed=0)
    # at the bound of a quotient (3 mm in 10 cells: 3.0000000000000003e-4 m) it passes (a review); where 2
    # cells are longer than the map, a longer cut-off cannot help: the message says the grid only (a review)
    filters.check_cutoff("cutoff", 600e-6, 3e-3 / 10, 3e-3 / 10, measured=(1e-3, 1e-3))
    with pytest.raises(InputError, match=r"use a finer micro.grid: 2 of its cells are longer than the "
                                         r"measurement \(500 x 500 um\)$"):     # in um as the cells (a review)
        filters.check_cutoff("cutoff", 0.4e-3, 312.5e-6, 312.5e-6, measured=(0.5e-3, 0.5e-3))


@pytest.mark.skipif(SHARED is None, reason="../shared/data/topographies not here")
def test_the_micro_patch_tutorial_solves_a_measured_surface_as_the_isolated_patch_it_is(capsys):
    """The tutorial's measured-surface block, run on the shared x3p-2 map, prints the numbers its
    text quotes; the bare-heights form it warns of (periodic, dy = dx) gives the other pair it quotes.
    The tutorial taught only that form, which a user trial applied to this map: 5.75 % for 7.78 %."""
    from multiscale.micro.contact import ContactSolver
    from multiscale.micro.kernels import HalfSpace
    text = (Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "micro_patch.rst").read_text()
    block = [b for b in re.findall(r"\.\. code-block:: python\n\n((?:    .*\n|\n)+)", text) if "read_topography" in b]
    code = "\n".join(line[4:] for line in block[0].splitlines()).replace('"x3p-2.x3p"', repr(str(SHARED / "x3p-2.x3p")))
    scope = {"HalfSpace": HalfSpace}
    exec(code, scope)
    out = capsys.readouterr().out
    quoted = re.search(r"this gives (\S+) % and\s+(\S+) nm", text)
    assert f"real contact area {quoted.group(1)} %, approach {quoted.group(2)} nm" in out
    s, r = scope["s"], scope["r"]
    # what the approach holds (a user trial): the patch's mean indentation under a uniform 5 MPa, by Love's
    # rectangle (measured 143.5 nm on the grid against 143.8 nm), and the mean gap, which does not depend on it
    from multiscale.references.love import love_rectangle_mean
    indent = float(re.search(r"Of that approach, (\S+) nm is the indentation", text).group(1)) * 1e-9
    Lx, Ly = s.size
    assert indent == pytest.approx(5e6 / (np.pi * HalfSpace.from_materials(4e9, 0.15).E_star)
                                   * love_rectangle_mean(Lx / 2, Ly / 2), rel=0.005)
    assert re.search(r"``r.mean_gap``, (\S+) nm", text).group(1) == f"{1e9 * r.mean_gap:.1f}"
    assert (s.periodic, s.dx != s.dy) == (False, True)
    bare = ContactSolver(HalfSpace.from_materials(4e9, 0.15), s.shape, s.dx).solve(s.heights, load=5e6)
    warned = re.search(r"gave (\S+) %\s+and (\S+) nm", text)
    assert (f"{100 * bare.area_fraction:.2f}", f"{1e9 * bare.approach:.1f}") == warned.groups()

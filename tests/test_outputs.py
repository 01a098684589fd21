"""What `multiscale check` promises is what `multiscale run` writes, and people can open it (issue 22).

For the block, the pin-on-disc with perfect and with rough contact and the squeal scene (coarse
versions of the demos): the results folder holds exactly the files of ``outputs.plan``; every field
file is read back (meshio's XDMF time-series reader and h5py; the VTX mode shapes with adios2)
with one mesh, the promised named arrays at exactly the promised times, units recorded; the
provenance (scene as given, resolved scene that loads back to itself, versions, command line,
ranks, times per stage) and the pvpython script are there."""
import csv
import hashlib
import json
import os
import subprocess
import sys
import time
import tomllib
import types
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from multiscale.cli import main
from multiscale.outputs import FIELDS, MODE_ARRAYS, PART_ARRAY, Plan, array_name, paraview_script, plan, summary
from multiscale import provenance
from multiscale.provenance import resolved_toml
from multiscale.scene import FIG_7_9_WEAR_RATE, load, loads

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

DEMOS = Path(__file__).resolve().parents[1] / "demos"
COARSE_POD = {"geometry.mesh_size": "15 mm", "geometry.holder_mesh_size": "6 mm",
              "geometry.interface_mesh_size": "2.5 mm", "geometry.track_mesh_size": "8 mm",
              "time.end": "2.4 s", "time.steps": 2, "output.every": 1}
CASES = {
    "block": ("block_on_flat.toml", {}),
    "perfect": ("pin_on_disc_perfect.toml", {**COARSE_POD, "time.steps": 3, "output.every": 2,
                                             "output.figures": False}),     # (the others draw them)
    "rough": ("pin_on_disc.toml", {**COARSE_POD, "micro.zones": [3, 3], "micro.grid": [16, 16],
                                   "micro.law_points": 8}),
    "squeal": ("brake_squeal.toml", {"geometry.mesh_size": "20 mm", "stability.modes": 6}),
}


@pytest.fixture(scope="module", params=list(CASES))
def case(request, tmp_path_factory):
    from multiscale.workflows import run
    name, overrides = CASES[request.param]
    folder = tmp_path_factory.mktemp(request.param) / "results"
    scene = load(DEMOS / name, {**overrides, "output.folder": str(folder)})
    if request.param == "squeal":
        # `multiscale run` in a process of its own, as a user runs it (inside the whole suite's
        # process it once ended with exit code 15: MPICH out of communicators, the models of
        # earlier tests not closed; docs/architecture.md §7)
        path = folder.parent / "scene.toml"
        path.write_text(resolved_toml(scene))
        scene = load(path)
        done = subprocess.run([str(Path(sys.executable).with_name("multiscale")), "run", str(path), "--quiet"],
                              capture_output=True, text=True, timeout=900, start_new_session=True)
        assert done.returncode == 0, done.stderr[-3000:]
        return scene, plan(scene), None
    result = run(scene, verbose=False)
    return scene, plan(scene), result


def test_the_folder_holds_exactly_what_check_promised(case, capsys):
    scene, p, result = case
    assert sorted(f.name for f in p.folder.iterdir()) == sorted(p.files)
    if result is not None:
        assert sorted(f.name for f in result.files) == sorted(p.files)
    assert main(["check", str(scene.source)]) == 0
    shown = capsys.readouterr().out
    assert all(f"    {name} " in shown for name in p.files)      # check lists every file


@pytest.mark.parametrize("name, overrides, pngs", [
    ("pin_on_disc.toml", {}, {"history", "multiscale", "wear_map"}),
    ("brake_squeal.toml", {"stability.sweep.friction": [0.2, 0.4], "stability.prestress": True},
     {"pressure", "re_im", "energy", "map", "map_tracks"})])
def test_without_figures_check_promises_every_file_but_the_pngs(name, overrides, pngs):
    """output.figures = false drops the PNG figures from the plan and nothing else (the tables
    and fields they are drawn from stay)."""
    drawn, bare = (plan(load(DEMOS / name, {**overrides, "output.figures": f})).files for f in (True, False))
    assert {n[:-4] for n in drawn if n.endswith(".png")} == pngs
    assert bare == {n: w for n, w in drawn.items() if not n.endswith(".png")}


def test_a_long_file_name_stays_apart_from_what_it_holds():
    """check's file list pads names to the longest: wear_map_inner_pad_L.png (24 characters) ran into
    its description ("wear_map_inner_pad_L.pngwear depth over...", a caliper trial)."""
    p = plan(load(DEMOS / "pin_on_disc.toml"))
    long = replace(p, files={"wear_map_inner_pad_L.png": "wear depth", **p.files})
    lines = [line for line in summary(long) if line.startswith("    ") and not line.startswith("     ")]
    starts = {line.index(what, 4) for line in lines for name, what in long.files.items() if line[4:].startswith(name)}
    assert starts == {4 + len("wear_map_inner_pad_L.png") + 2}


def test_check_names_every_column_of_modes_csv(case):
    """check's line for modes.csv names each column the squeal run writes (before: not the
    unstable and potentially unstable flags); the strain-energy share of each component, the
    numbers of energy.png, add up to 1 per mode (before: in the figure only; a user trial)."""
    scene, p, result = case
    if p.analysis != "squeal":
        pytest.skip("modes.csv: squeal analysis only")
    words = {"frequency_Hz": "frequency", "sigma_1_per_s": "growth rate", "damping_ratio": "damping ratio",
             "unstable": "unstable", "potentially_unstable": "potentially unstable", "flutter_partner": "flutter partner",
             "residual": "residual"}
    words["energy_share_"] = "strain-energy share"
    rows = list(csv.DictReader((p.folder / "modes.csv").open()))
    shares = [k for k in rows[0] if k.startswith("energy_share_")]
    disc = scene.bodies[1]                    # the rotating body's motion: nodal diameters, out-of-plane share
    shapes = [f"nodal_diameters_{disc}", f"nodal_diameter_share_{disc}", f"out_of_plane_share_{disc}",
              f"out_of_plane_nodal_diameters_{disc}"]
    words.update({"nodal_diameter": "nodal diameters", "out_of_plane": "out-of-plane share"})
    assert set(rows[0]) == {"mode", *words, *shares, *shapes} - {"energy_share_", "nodal_diameter", "out_of_plane"}
    assert len(shares) >= 2
    assert all(w in p.files["modes.csv"] for w in words.values())
    np.testing.assert_allclose([sum(float(r[k]) for k in shares) for r in rows], 1.0, atol=1e-5)


def test_field_files_hold_one_mesh_with_named_arrays_at_the_output_times(case):
    import h5py
    import meshio
    scene, p, _ = case
    assert p.field_files, "every analysis writes fields"
    expected_times = list(p.times)
    if p.analysis != "squeal":
        t = scene.time
        steps = t.steps if scene.has("thermal") else 0
        assert expected_times == [0.0] + [float(f"{n * t.dt:.12g}") for n in range(1, steps + 1)
                                          if n % scene.output.every == 0 or n == steps]
    parts = {f"{b.name}.xdmf": len(b.regions) for b in scene.geometry.spec.bodies if len(b.regions) > 1}
    assert parts or scene.geometry.builder == "block_on_flat", "a case with a body of several parts"
    for name, fields in p.field_files.items():
        reader = meshio.xdmf.TimeSeriesReader(p.folder / name)
        points, cells = reader.read_points_cells()
        assert len(cells) == 1 and points.shape[1] == 3
        times = []
        for k in range(reader.num_steps):
            t, point_data, cell_data = reader.read_data(k)
            times.append(t)
            assert sorted(point_data) + sorted(cell_data) == sorted(
                [array_name(f) for f in fields if f in ("displacement", "temperature")]) + sorted(
                [array_name(f) for f in fields if f not in ("displacement", "temperature")]
                + ([PART_ARRAY] if name in parts else []))
            if name in parts:          # every part's cells, numbered 1, 2, ... (the plan names them)
                assert set(cell_data[PART_ARRAY][0]) == set(range(1, parts[name] + 1))
                assert f"{PART_ARRAY} (1 " in p.files[name]
            for values in point_data.values():
                assert len(values) == len(points) and np.isfinite(values).all()
            for values in cell_data.values():
                assert len(values[0]) == len(cells[0].data) and np.isfinite(values[0]).all()
        assert times == expected_times                      # exact: no float drift
        with h5py.File((p.folder / name).with_suffix(".h5"), "r") as f:
            assert list(f["times"][...]) == expected_times and f["times"].attrs["unit"] == "s"
            for field in fields:
                assert f[f"data/0/{field}"].attrs["unit"] == FIELDS[field][1]
            # which part or interface a number is, in the file itself (a user audit: only in check's console)
            named = {a: [n.decode() for n in f[f"names/{a}"][()]] for a in f.get("names", {})}
            spec = scene.geometry.spec
            assert named == ({PART_ARRAY: [r.name for b in spec.bodies if f"{b.name}.xdmf" == name for r in b.regions]}
                             if name in parts else {array_name("interface"): list(spec.interfaces)}
                             if "interface" in fields else {})
        text = (p.folder / name).read_text()
        assert text.count("<Grid ") == 1 + len(expected_times) and "Block" not in text


def test_mode_shapes_read_back_from_vtx(case):
    scene, p, result = case
    if p.analysis != "squeal":
        pytest.skip("mode shapes: squeal analysis only")
    adios2 = pytest.importorskip("adios2")
    n = len((p.folder / "modes.csv").read_text().strip().splitlines()) - 1      # one line per mode
    for body in p.bodies:
        with adios2.FileReader(str(p.folder / f"modes_{body}.bp")) as reader:
            variables = reader.available_variables()
            assert {"mode shape real part [1/kg^0.5]", "mode shape imaginary part [1/kg^0.5]"} <= set(variables)
            assert int(variables["step"]["AvailableStepsCount"]) == n
            steps = reader.read("step", step_selection=[0, n])
            np.testing.assert_array_equal(steps, np.arange(1, n + 1))
            xml = reader.read_attribute_string("vtk.xml")
            assert "mode shape real part" in (xml if isinstance(xml, str) else xml[0])


def test_provenance_and_paraview_script(case):
    scene, p, _ = case
    record = json.loads((p.folder / "provenance.json").read_text())
    assert record["status"] == "finished" and record["ranks"] == 1 and record["analysis"] == p.analysis
    assert {"python", "multiscale", "numpy", "dolfinx", "petsc", "slepc", "mpi"} <= set(record["versions"])
    if p.analysis == "squeal":
        assert {"meshing", "model set-up", "preload", "eigen solve"} <= set(record["stage_wall_time_s"])
    else:
        assert {"meshing", "macro steps"} <= set(record["stage_wall_time_s"])
    assert record["start"] <= record["end"] and record["total_wall_time_s"] > 0
    assert record["parts"] == [{"code": record["code"]["sha1"], **{k: record[k] for k in (
        "status", "command", "directory", "ranks", "start", "end", "stage_wall_time_s", "total_wall_time_s")},
        "free": provenance.free(tomllib.loads(resolved_toml(scene)))}]
    assert "output.folder" in record["parts"][0]["free"]      # (keys a resume may change, as this part ran them)
    assert record["directory"] == os.getcwd()     # the command's relative paths are from there (not said: a trial)
    assert record["files"] == sorted(p.files)          # what a later --overwrite deletes
    overrides = dict(record["overrides"])         # scene.toml alone is not this run (before: nothing said so)
    if p.analysis == "squeal":                    # run from its resolved scene, no overrides
        assert overrides == {}
    else:
        assert Path(overrides.pop("output.folder")).resolve() == p.folder.resolve()
        assert overrides == next(o for f, o in CASES.values() if Path(f).stem == scene.name)
    assert (p.folder / "scene.toml").read_text() == scene.source.read_text()
    # the code, environment and inputs that ran (before: "multiscale": "0.1.0" for any copy; a user trial)
    assert record["code"] == provenance.code() and len(record["code"]["sha1"]) == 40
    assert record["inputs"][str(scene.source.resolve())] == hashlib.sha1(scene.source.read_bytes()).hexdigest()
    assert record["environment"].get("OMP_NUM_THREADS") == os.environ.get("OMP_NUM_THREADS")
    resolved = (p.folder / "scene_resolved.toml").read_text()
    again = loads(resolved, scene.source.parent, name=scene.name)
    assert resolved_toml(again).splitlines()[2:] == resolved.splitlines()[2:]
    script = (p.folder / "open_in_paraview.py").read_text()
    compile(script, "open_in_paraview.py", "exec")
    for name in p.field_files:
        assert repr(name) in script
    assert "'temperature [K]'" in script if scene.has("thermal") else "'contact pressure [Pa]'" in script


def test_every_column_and_dataset_written_is_documented(case, documented):
    """Every history column, zones.h5 dataset and modes.csv column is in docs/results.rst (before:
    22 of the rough run's 38 columns were not, nor the modes.csv columns)."""
    import h5py
    _, p, _ = case
    names = []
    for file in ("history.h5", "zones.h5"):
        if (p.folder / file).is_file():
            with h5py.File(p.folder / file, "r") as f:
                names += list(f) + list(f.attrs)
                assert all("unit" in f[k].attrs for k in f)
    if (p.folder / "modes.csv").is_file():
        names += (p.folder / "modes.csv").read_text().splitlines()[0].split(",")
    assert names and [n for n in names if not documented(n)] == []


def test_zone_results_say_where_each_value_is(case):
    """zones.h5 gives the facets of its per-facet data (``counter_wear_depth``: in the interface's
    global facet order, not that of interface.xdmf's cells) and each zone's centre in space
    (``centre`` is in the interface's plane); before, neither could be placed."""
    import h5py
    _, p, _ = case
    if p.analysis != "multiscale":
        pytest.skip("zone results: multiscale loop only")
    with h5py.File(p.folder / "zones.h5", "r") as z, h5py.File(p.folder / "interface.h5", "r") as f:
        facets = f["mesh/geometry"][...][f["mesh/topology"][...]].mean(axis=1)
        centres = z["facet_centre"][...]
        assert centres.shape == facets.shape and z["counter_wear_depth"].shape == (len(facets),)
        distance = np.linalg.norm(centres[:, None] - facets[None], axis=2)        # every centre is a cell's, once
        assert distance.min(axis=1).max() < 1e-12 and len(set(distance.argmin(axis=1))) == len(facets)
        position = z["position"][...]
        np.testing.assert_allclose(position[:, :2], z["centre"][...], rtol=0, atol=1e-15)   # the pin face
        np.testing.assert_allclose(position[:, 2], facets[:, 2].mean(), rtol=0, atol=1e-15)


def data_range(path: Path, array: str) -> tuple[float, float]:
    """The least and largest value of ``array`` of an XDMF file's HDF5 data over every time (a
    vector's magnitude, as ParaView colours it)."""
    import h5py
    values = []
    with h5py.File(path.with_suffix(".h5"), "r") as f:
        for group in f["data"].values():
            for d in group.values():
                if d.attrs["name"] == array:
                    v = d[...]
                    values.append(np.linalg.norm(v, axis=1) if v.ndim == 2 and v.shape[1] > 1 else v.ravel())
    v = np.concatenate(values)
    return float(v.min()), float(v.max())


class StubColourMap:
    """A colour map of ParaView's (one per array name): ``RGBPoints`` x, r, g, b of each point."""

    def __init__(self):
        self.RGBPoints, self.AutomaticRescaleRangeMode = [0.0, 0, 0, 1, 1.0, 1, 0, 0], "Grow and update on 'Apply'"

    def RescaleTransferFunction(self, lo, hi):
        self.RGBPoints = [lo, 0, 0, 1, hi, 1, 0, 0]


class StubDisplay:
    def __init__(self, source, maps):
        self.source, self.maps, self.array = source, maps, None

    def SetScalarBarVisibility(self, view, on):
        pass

    def RescaleTransferFunctionToDataRangeOverTime(self):
        """As ParaView does: the array's colour map set to this display's range alone (replaced;
        a script run without its files: 0 to 1)."""
        path = Path(self.source.path)
        self.maps.setdefault(self.array, StubColourMap()).RescaleTransferFunction(
            *(data_range(path, self.array) if path.with_suffix(".h5").exists() else (0.0, 1.0)))


class StubParaView:
    """paraview.simple as far as open_in_paraview.py uses it, recording what the script opens, shows and
    colours (``opened``: path -> reader; ``coloured``: (reader, array name); ``maps``: array name ->
    its colour map, ``opacities``: array name -> its opacity map's range)."""

    def __init__(self):
        self.view = types.SimpleNamespace(ResetCamera=lambda: None)
        self.face = types.SimpleNamespace(ResetCamera=lambda: None)            # the interface's own view
        self.opened, self.coloured, self.shown, self.cells, self.maps, self.opacities = {}, [], [], {}, {}, {}
        m = self.module = types.ModuleType("paraview.simple")
        m.__all__ = ["GetActiveViewOrCreate", "GetLayout", "CreateView", "GetAnimationScene", "Xdmf3ReaderS",
                     "ADIOS2VTXReader", "WarpByVector", "Show", "ColorBy", "Render", "Interact",
                     "GetColorTransferFunction", "GetOpacityTransferFunction"]
        m.GetColorTransferFunction = lambda array: self.maps.setdefault(array, StubColourMap())
        m.GetOpacityTransferFunction = lambda array: types.SimpleNamespace(
            RescaleTransferFunction=lambda lo, hi: self.opacities.update({array: (lo, hi)}))
        m.GetActiveViewOrCreate = lambda kind: self.view
        m.GetLayout = lambda view: types.SimpleNamespace(SplitHorizontal=lambda cell, fraction: None,
                                                         AssignView=lambda cell, view: self.cells.update({cell: view}))
        m.CreateView = lambda kind: self.face
        m.GetAnimationScene = lambda: types.SimpleNamespace(UpdateAnimationUsingDataTimeSteps=lambda: None,
                                                            GoToLast=lambda: None)
        m.Xdmf3ReaderS = lambda registrationName, FileName: self.open(FileName[0])
        m.ADIOS2VTXReader = lambda registrationName, FileName: self.open(FileName)
        m.WarpByVector = lambda Input, Vectors, ScaleFactor: self.coloured.append((Input, Vectors[1])) or Input
        m.Show = lambda source, view: self.shown.append((source, view)) or StubDisplay(source, self.maps)
        m.ColorBy = lambda shown, array: self.coloured.append((shown.source, array[1])) or \
            setattr(shown, "array", array[1])
        m.Render = m.Interact = lambda: None

    def shown_in(self, view) -> list[str]:
        """Names of the files shown in ``view``."""
        return sorted(Path(source.path).name for source, v in self.shown if v is view)

    def open(self, path):
        self.opened[path] = types.SimpleNamespace(path=path)
        return self.opened[path]


def run_script(script: str, folder: Path, monkeypatch) -> StubParaView:
    """Execute a open_in_paraview.py as if it lay in ``folder``, against ``StubParaView``."""
    stub = StubParaView()
    monkeypatch.setitem(sys.modules, "paraview", types.ModuleType("paraview"))
    monkeypatch.setitem(sys.modules, "paraview.simple", stub.module)
    exec(compile(script, "open_in_paraview.py", "exec"), {"__file__": str(folder / "open_in_paraview.py"), "__name__": "pv"})
    return stub


def test_the_paraview_script_opens_files_and_arrays_that_exist(case, monkeypatch):
    """open_in_paraview.py, run against a stub of paraview.simple: every file it opens is in the folder and
    every array it colours or warps by is in that file."""
    import h5py
    _, p, _ = case
    stub = run_script((p.folder / "open_in_paraview.py").read_text(), p.folder, monkeypatch)
    assert sorted(Path(path).name for path in stub.opened) == sorted(
        list(p.field_files) + ([f"modes_{b}.bp" for b in p.bodies] if p.analysis == "squeal" else []))
    # the interface in a view of its own (on the bodies' faces it was hidden); squeal: the mode
    # shapes, the preloaded bodies hidden (a user trial)
    interface = ["interface.xdmf"] if "interface.xdmf" in p.field_files else []
    assert stub.shown_in(stub.face) == interface and (not interface or stub.cells == {2: stub.face})
    assert stub.shown_in(stub.view) == sorted([f"modes_{b}.bp" for b in p.bodies] if p.analysis == "squeal" else
                                              [f for f in p.field_files if f not in interface])
    for source, array in stub.coloured:
        path = Path(source.path)
        assert path.parent == p.folder and path.exists()
        if path.suffix == ".bp":
            assert array == MODE_ARRAYS[0]
        else:
            with h5py.File(path.with_suffix(".h5"), "r") as f:
                assert array in {d.attrs["name"] for d in f["data/0"].values()}
    # one colour map per array name spans every file coloured by it over every time (each display's
    # rescale replaced the last one's: the pin's 330 K would have had the disc's top colour)
    by_array = {}
    for source, array in stub.coloured:
        if Path(source.path).suffix == ".xdmf":
            by_array.setdefault(array, []).append(data_range(Path(source.path), array))
    assert by_array and set(stub.opacities) == set(by_array)
    assert p.analysis == "squeal" or max(len(r) for r in by_array.values()) == 2     # both bodies by one array
    for array, ranges in by_array.items():
        lo, hi = min(r[0] for r in ranges), max(r[1] for r in ranges)
        points = stub.maps[array].RGBPoints
        assert (points[0], points[-4]) == stub.opacities[array] == (lo, hi), array
        assert stub.maps[array].AutomaticRescaleRangeMode == "Never"


def test_a_body_named_like_a_name_of_the_script_keeps_the_script_working(tmp_path, monkeypatch):
    """Bodies called "view" and "in" (a user's geometry file names them): the script assigned its
    readers to those names, showing the disc in a reader instead of the view, or did not compile."""
    fields = ("displacement", "temperature")
    for bodies in (("view", "os"), ("in", "here")):
        p = Plan("squeal", tmp_path, bodies, fields, ("contact_pressure",), (0.0,), {}, ())
        stub = run_script(paraview_script(p), tmp_path, monkeypatch)
        assert f"body 0 is {bodies[0]} and body 1 is {bodies[1]}" in paraview_script(p)   # the arrays' words
        assert sorted(Path(f).name for f in stub.opened) == sorted(
            [f"{b}.xdmf" for b in bodies] + ["interface.xdmf"] + [f"modes_{b}.bp" for b in bodies])
        assert stub.shown_in(stub.view) == sorted(f"modes_{b}.bp" for b in bodies)
        assert stub.shown_in(stub.face) == ["interface.xdmf"]


@pytest.mark.parametrize("path", sorted(DEMOS.glob("*.toml")), ids=lambda p: p.stem)
def test_resolved_scene_loads_back_to_itself(path):
    try:
        scene = load(path)
    except Exception as exc:           # the STEP demos need demos/cad_models.py first
        pytest.skip(f"{path.name}: {exc}")
    text = resolved_toml(scene)
    again = loads(text, path.parent, name=scene.name)
    assert resolved_toml(again).splitlines()[2:] == text.splitlines()[2:]
    assert again.effects == scene.effects and again.output == scene.output and again.time == scene.time


def test_the_resolved_scene_keeps_each_interfaces_own_roughness_and_micro():
    """[interfaces.<name>.roughness] and [interfaces.<name>.micro] are written out merged (before:
    dropped, so the resolved scene loaded back with the scene-wide rms and zones; a user trial)."""
    scene = load(DEMOS / "brake_squeal.toml", {
        "effects": ["contact", "friction", "roughness"], "roughness": {"rms": "3 um", "hurst": 0.8, "k_min": 1,
                                                                    "k_max": 6},
        "micro": {"zones": [2, 2], "grid": [16, 16]}, "interfaces.outer_pad.roughness.rms": "8 um",
        "interfaces.inner_pad.micro.zones": [3, 3], "interfaces.outer_pad.friction": 0.2})
    text = resolved_toml(scene)
    again = loads(text, DEMOS, name=scene.name)
    assert resolved_toml(again).splitlines()[2:] == text.splitlines()[2:]
    for name in ("inner_pad", "outer_pad"):
        assert again.interface_settings(name) == scene.interface_settings(name)
    own = again.interface_settings
    assert (own("outer_pad").roughness.rms, own("inner_pad").micro.zones, own("outer_pad").micro.zones) == (8e-6, (3, 3),
                                                                                                         (2, 2))


def test_the_default_wear_rate_table_is_written_out_in_the_resolved_scene():
    """scene_resolved.toml ("every default filled in") left wear.k_w_table unset when the default
    table of thesis Fig. 7.9 ran; a rough material's own k_w, which that table would override, stays
    unwritten."""
    scene = load(DEMOS / "pin_on_disc_thesis.toml")
    text = resolved_toml(scene)
    assert "# wear.k_w_table is the default table: shape of thesis Fig. 7.9" in text
    again = loads(text, DEMOS, name=scene.name)
    assert again.wear.k_w_table == FIG_7_9_WEAR_RATE and again.wear.rate == scene.wear.rate
    pad = scene.geometry.spec.interface_materials(scene.rough_interfaces[0])[0]
    own = load(DEMOS / "pin_on_disc_thesis.toml", {f"materials.{pad}.k_w": "1e-14 1/Pa"})
    assert own.rough_material_wears and "k_w_table" not in resolved_toml(own)


def test_a_temperature_column_of_the_resolved_scene_is_commented_in_kelvin():
    """The comment of a table against the temperature named its column "-" (dimensionless)."""
    scene = load(DEMOS / "block_on_flat.toml", {"effects": ["contact", "thermal"], "materials.block.kappa":
                 [["20 degC", "5 W/(m K)"], ["100 degC", "6 W/(m K)"]], "materials.block.chi": "1e-6 m^2/s",
                 "materials.flat.kappa": 50, "materials.flat.chi": 1e-5, "time.initial_temperature": "20 degC",
                 "time.end": 1, "time.steps": 1})
    line = next(x for x in resolved_toml(scene).splitlines() if x.startswith("kappa = [["))
    assert line.endswith('= [["293.15 K", 5.0], ["373.15 K", 6.0]]   # [temperature, kappa] in [K, W/(m K)]')


def test_a_rank_owning_one_node_or_cell_keeps_its_axis():
    """``output.components``: the gathered per-rank arrays keep their first axis (a rank owning one
    interface cell of the perfect-contact demo on 2 ranks stopped the run with squeeze's 0-d array)."""
    from multiscale.macro.output import components
    assert components(np.array([2.0]), 1).shape == (1,)
    assert components(np.arange(3.0), 3).shape == (1, 3)
    assert np.array_equal(components(np.arange(6.0), 3)[1], [3.0, 4.0, 5.0])
    assert components(np.zeros(0), 3).shape == (0, 3)


def test_a_quadratic_field_is_written_on_quadratic_cells_and_integrates_exactly(tmp_path):
    """A P2 temperature (the rotating body's) keeps its edge-midpoint values: the body's file holds
    ``Tetrahedron_10`` cells in VTK node order, the values at all ten nodes are those of the field,
    and its integral from the file (a P2 function over a tetrahedron of volume V: V (Σ_edges u / 5
    − Σ_vertices u / 20)) equals DOLFINx's to round-off; from the vertices alone (the file before)
    it was 3.1 % off here. A linear field beside it is interpolated exactly."""
    import h5py
    import meshio
    from dolfinx import fem, mesh
    from mpi4py import MPI
    from multiscale.macro.output import FieldWriter
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 3, 2, 2)
    T = fem.Function(fem.functionspace(msh, ("Lagrange", 2)))
    T.interpolate(lambda x: 40.0 * x[0] ** 2 - 25.0 * x[1] * x[2])     # K above the start
    u = fem.Function(fem.functionspace(msh, ("Lagrange", 1, (3,))))
    u.interpolate(lambda x: np.vstack([x[0], 2 * x[1], -x[2]]))
    FieldWriter(tmp_path, [("disc", msh, {"temperature": T, "displacement": u})]).write(0.5)
    reader = meshio.xdmf.TimeSeriesReader(tmp_path / "disc.xdmf")
    points, cells = reader.read_points_cells()
    _, data, _ = reader.read_data(0)
    assert len(cells) == 1 and cells[0].type == "tetra10"
    nodes = cells[0].data
    x = points[nodes]                                           # (cells, 10, 3)
    pairs = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]    # VTK's quadratic tetrahedron
    midpoints = np.stack([(x[:, a] + x[:, b]) / 2 for a, b in pairs], axis=1)
    np.testing.assert_allclose(x[:, 4:], midpoints, atol=1e-14)
    t = data[array_name("temperature")]
    exact = 40.0 * points[:, 0] ** 2 - 25.0 * points[:, 1] * points[:, 2]
    np.testing.assert_allclose(t, exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(data[array_name("displacement")], points * [1, 2, -1], atol=1e-14)
    v = x[:, 1:4, :] - x[:, :1, :]
    volume = np.abs(np.linalg.det(v)) / 6
    tn = t[nodes]
    integral = volume @ (tn[:, 4:].sum(axis=1) / 5 - tn[:, :4].sum(axis=1) / 20)
    reference = msh.comm.allreduce(fem.assemble_scalar(fem.form(T * ufl_dx(msh))), op=MPI.SUM)
    assert abs(integral - reference) < 1e-12 * abs(reference)
    vertex_only = volume @ tn[:, :4].mean(axis=1)
    assert abs(vertex_only - reference) > 0.02 * abs(reference)    # 3.1 %: a case a vertex-only file gets wrong
    with h5py.File(tmp_path / "disc.h5", "r") as f:
        assert f["mesh/topology"].attrs["cell_type"] == "Tetrahedron_10"


def ufl_dx(msh):
    import ufl
    return ufl.dx(domain=msh)


def test_the_commit_is_read_from_git_files(tmp_path):
    """``provenance.code`` reads the commit a checkout holds from git's files (no process forked
    from an MPI rank): a branch's ref file, a packed ref, a detached head and a worktree's
    ``.git`` file; none without a git folder."""
    from multiscale.provenance import git_commit
    a, b = "1" * 40, "2" * 40
    git = tmp_path / "repo" / ".git"
    (git / "refs" / "heads").mkdir(parents=True)
    (git / "HEAD").write_text("ref: refs/heads/main\n")
    (git / "refs" / "heads" / "main").write_text(a + "\n")
    assert git_commit(git) == a
    (git / "refs" / "heads" / "main").unlink()
    (git / "packed-refs").write_text(f"# pack-refs with: peeled\n{b} refs/heads/other\n{a} refs/heads/main\n")
    assert git_commit(git) == a
    work = tmp_path / "work"
    (git / "worktrees" / "work").mkdir(parents=True)
    (git / "worktrees" / "work" / "HEAD").write_text(b + "\n")              # detached
    (git / "worktrees" / "work" / "commondir").write_text("../..\n")
    work.mkdir()
    (work / ".git").write_text(f"gitdir: {git / 'worktrees' / 'work'}\n")
    assert git_commit(work / ".git") == b
    assert git_commit(tmp_path / "none" / ".git") is None


def test_the_index_written_time_by_time_is_the_one_the_file_gives(tmp_path):
    """``SeriesFile.write`` adds one time's grid to the index (it read every time's datasets back,
    5.6 ms per time written: a 400-step run spent 80 % of its wall time there, a long-run trial).
    The index after 4 times and one written again with another field is the one a run resumed at
    1 s rebuilds from the HDF5 file and completes; a write reads no earlier time's datasets (an
    attribute removed from the first does not stop it)."""
    import h5py
    from dolfinx import fem, mesh
    from mpi4py import MPI
    from multiscale.macro.output import FieldWriter
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2)
    T = fem.Function(fem.functionspace(msh, ("Lagrange", 1)))
    writer = FieldWriter(tmp_path, [("disc", msh, {"temperature": T})])
    for t in (0.0, 0.5, 1.0, 1.5):
        writer.write(t)
    series = writer.groups[0][0]
    series.write(1.5, {"displacement": (np.zeros((len(series.layout.geometry), 3)), "Node")})
    written = (tmp_path / "disc.xdmf").read_text()
    assert written.count("<Grid ") == 5 and written.count('Name="displacement [m]"') == 1
    resumed = FieldWriter(tmp_path, [("disc", msh, {"temperature": T})], resume_at=1.0)
    assert (tmp_path / "disc.xdmf").read_text().count("<Grid ") == 4      # 1.5 s dropped
    resumed.write(1.5)
    resumed.groups[0][0].write(1.5, {"displacement": (np.zeros((len(series.layout.geometry), 3)), "Node")})
    assert (tmp_path / "disc.xdmf").read_text() == written
    with h5py.File(tmp_path / "disc.h5", "a") as f:
        del f["data/0/temperature"].attrs["centre"]
    resumed.write(2.0)
    assert (tmp_path / "disc.xdmf").read_text().count("<Grid ") == 6


def test_a_run_refuses_a_folder_another_living_run_writes_into(tmp_path):
    """Two runs in one folder (one started with --resume while the other ran) both failed, with
    HDF5's lock errors, and one record was lost (a long-run trial). provenance.json names the
    writing process (host, pid, its start); a run refuses a folder whose record says running by a
    process that lives, on --overwrite or --resume alike, and takes one whose writer is gone (a
    killed run) or is itself (the Python API's runs, one after another)."""
    from multiscale.errors import SceneError
    from multiscale.workflows import run
    folder = tmp_path / "results"
    scene = load(DEMOS / "pin_on_disc_perfect.toml", {"output.folder": str(folder), "time.steps": 1,
                                                       "time.end": "0.1 s"})
    run(scene, verbose=False)
    record = json.loads((folder / "provenance.json").read_text())
    assert record["process"] == provenance.process() and record["parts"][0]["total_wall_time_s"] > 0
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        record.update(status=provenance.RUNNING, process=provenance.process(other.pid))
        (folder / "provenance.json").write_text(json.dumps(record))
        with pytest.raises(SceneError, match=rf'another run writes into it \(process {other.pid} on this host, '
                                             r"started .*\): two runs would write over each other's files"):
            run(scene, verbose=False, overwrite=True)
        assert provenance.writer(folder)["process"]["pid"] == other.pid
    finally:
        other.kill()
        other.wait()
    assert provenance.writer(folder) is None                     # killed: its folder is free
    run(scene, verbose=False, overwrite=True)
    record.update(process=provenance.process())                  # this process's own record
    (folder / "provenance.json").write_text(json.dumps(record))
    assert provenance.writer(folder) is None


def _living_record(folder: Path, pid: int) -> None:
    """A provenance.json in ``folder`` saying that process ``pid`` of this host runs there."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "provenance.json").write_text(json.dumps({"status": provenance.RUNNING,
                                                         "process": provenance.process(pid)}))


def test_two_runs_claiming_one_folder_at_once_one_is_refused(tmp_path):
    """Two runs started at the same instant into one new folder both passed the record check, both
    wrote, both failed (HDF5's "unable to lock file", a checkpoint's "No such file") and the second's
    failed record replaced the first's (a user trial, 4 of 4 tries). The claim holds a lock on the
    folder from its check to its record: a second claim waits for it, then finds the first run's
    record and is refused, writing nothing."""
    import threading
    from mpi4py import MPI
    from multiscale.errors import SceneError
    from multiscale.workflows.output import exclusive, prepare_folder
    folder = tmp_path / "results"
    out = prepare_folder(load(DEMOS / "pin_on_disc_perfect.toml", {"output.folder": str(folder)}), False, False,
                         MPI.COMM_WORLD)
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    errors = []

    def claim():
        try:
            out.claim()
        except SceneError as exc:
            errors.append(str(exc))
    try:
        with exclusive(folder):                  # the other run between its check and its record
            second = threading.Thread(target=claim)
            second.start()
            second.join(0.5)
            assert second.is_alive()             # waits for the lock
            _living_record(folder, other.pid)
        second.join(30)
        assert not second.is_alive() and len(errors) == 1
        assert f"another run writes into it (process {other.pid} on this host" in errors[0]
        assert json.loads((folder / "provenance.json").read_text())["process"]["pid"] == other.pid
    finally:
        other.kill()
        other.wait()


def test_a_claim_refuses_results_that_appeared_since_the_run_prepared(tmp_path):
    """A run that began and ended while this one meshed leaves results the folder check did not see:
    the claim refuses them instead of writing over them without --overwrite."""
    from mpi4py import MPI
    from multiscale.errors import SceneError
    from multiscale.workflows.output import prepare_folder
    folder = tmp_path / "results"
    out = prepare_folder(load(DEMOS / "pin_on_disc_perfect.toml", {"output.folder": str(folder)}), False, False,
                         MPI.COMM_WORLD)
    (folder / "history.csv").write_text("t\n")
    with pytest.raises(SceneError, match=r"1 entry appeared in it while this run prepared \(history.csv\)"):
        out.claim()
    assert sorted(p.name for p in folder.iterdir()) == ["history.csv"]


def test_a_killed_run_not_yet_reaped_frees_its_folder(tmp_path):
    """``--resume`` right after a SIGKILL was refused for a moment: the killed process, a zombie until
    its parent reaps it, still had its pid and start. A zombie writes nothing: its folder is free."""
    short = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.5)"])
    _living_record(tmp_path, short.pid)
    assert provenance.writer(tmp_path)["process"]["pid"] == short.pid
    stat = Path(f"/proc/{short.pid}/stat")
    for _ in range(300):                         # not reaped: no wait() before the check
        if stat.read_text().rsplit(")", 1)[1].split()[0] == "Z":
            break
        time.sleep(0.05)
    try:
        assert stat.read_text().rsplit(")", 1)[1].split()[0] == "Z"
        assert provenance.writer(tmp_path) is None
    finally:
        short.wait()

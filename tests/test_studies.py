"""Parametric studies (`multiscale study`): sweep expansion, resumable runs in fresh processes, errors
against independent computations, failed and timed-out runs, clear errors for bad study files."""
import csv
import hashlib
import json
import math
import re
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from multiscale.cli import main
from multiscale.errors import SceneError
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import fractal_surface
from multiscale.studies import Row, load_study, pareto, relative_error
from multiscale.studies.reporting import elapsed  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
GRIDS = (12, 16, 24, 32)

HERTZ = """
name = "hertz"
problem = "hertz"
metrics = ["contact_radius", "max_pressure", "approach"]
[fixed]
load = "10 N"
radius = "10 mm"
[sweep]
grid = [12, 16, 24, 32]
[reference]
kind = "analytic"
[run]
processes = 2
[report]
errors = ["1 %", "5 %"]
"""


def write(folder, text, name="study.toml"):
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def table(path):
    """results.csv's rows keyed by column name (its header's units, "name [unit]", left off)."""
    with open(path, newline="") as fh:
        return [{k.split(" [")[0]: v for k, v in row.items()} for row in csv.DictReader(fh)]


def hertz_independent(grid, load=10.0, R=10e-3, E=210e9, nu=0.3, window=4.0):
    """Hertz errors computed here: the closed form (Johnson §4.2) and a direct FFT-BEM solve."""
    E_star = E / (1 - nu**2)
    a = (3 * load * R / (4 * E_star)) ** (1 / 3)
    exact = {"contact_radius": a, "max_pressure": 3 * load / (2 * np.pi * a * a), "approach": a * a / R}
    side = window * a
    dx = side / grid
    x = (np.arange(grid) + 0.5) * dx - side / 2
    h = -(x[None, :] ** 2 + x[:, None] ** 2) / (2 * R)
    r = ContactSolver(HalfSpace(E_star), h.shape, dx, periodic=False).solve(h, load=load / side**2)
    got = {"contact_radius": math.sqrt(r.contact.sum() * dx * dx / math.pi), "max_pressure": r.pressure.max(),
           "approach": float(r.approach)}
    return {m: abs(got[m] - exact[m]) / exact[m] for m in exact}


@pytest.fixture(scope="module")
def hertz_study(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hertz")
    path = write(folder, HERTZ)
    assert main(["study", str(path)]) == 0
    return path, folder / "results" / "hertz"


def test_hertz_study_errors_match_an_independent_computation(hertz_study):
    path, out = hertz_study
    rows = table(out / "results.csv")
    assert [int(r["grid"]) for r in rows] == list(GRIDS)
    for row in rows:
        assert row["status"] == "ok" and row["converged"] == "True"
        assert float(row["wall_time"]) > 0 and float(row["peak_memory_mb"]) > 10 and int(row["iterations"]) > 0
        # the first timing of a fresh process holds numba's loading of its compiled code (~1 s against
        # a solve of ~0.01 s: grid 32 was reported at 14.9 s, 1.0-1.9 s the others; a user trial):
        # such a run is timed once more, and the best time kept
        record = json.loads((out / "runs" / f"{row['run']}.json").read_text())
        assert record["jit_time"] > 0.05 * record["wall_times"][0] and len(record["wall_times"]) == 2
        assert record["wall_time"] == min(record["wall_times"]) == record["wall_times"][1]
        mine = hertz_independent(int(row["grid"]))
        for m, err in mine.items():
            assert float(row[f"{m}_error"]) == pytest.approx(err, rel=1e-6, abs=1e-12)
        assert float(row["max_error"]) == pytest.approx(max(mine.values()), rel=1e-6)
    # the same table in HDF5, one row per run
    with h5py.File(out / "results.h5", "r") as h5:
        np.testing.assert_allclose(h5["max_pressure_error"][...], [float(r["max_pressure_error"]) for r in rows])
        assert list(h5["grid"][...]) == list(GRIDS)
        # units as history.h5's (they were in the report alone; a user trial); a relative error has none
        assert (h5["max_pressure"].attrs["unit"], h5["contact_radius_reference"].attrs["unit"],
                h5["wall_time"].attrs["unit"]) == ("Pa", "m", "s") and "unit" not in h5["max_pressure_error"].attrs
    # and in the CSV's header (results.h5 alone had them: a user trial)
    header = (out / "results.csv").read_text().splitlines()[0].split(",")
    assert {"grid", "max_pressure [Pa]", "contact_radius_reference [m]", "max_pressure_error",
            "wall_time [s]", "peak_memory_mb [MB]"} <= set(header), header
    # the report names the cheapest grid meeting each error, from the same errors
    worst = {int(r["grid"]): float(r["max_error"]) for r in rows}
    time = {int(r["grid"]): float(r["wall_time"]) for r in rows}
    text = (out / "hertz.md").read_text()
    # the runs table names each metric's unit (from the problem's description of it)
    assert "| grid | contact_radius [m] | error | max_pressure [Pa] | error | approach [m] | error |" in text
    assert f"4 ok, 0 failed; {elapsed(sum(time.values()))} of run wall time in all (failed runs included)" in text
    assert [elapsed(t) for t in (0.0217, 4.24, 4800.0)] == ["0.022 s", "4.2 s", "1 h 20 min"]    # (was "0.0 s")
    # the code that made the runs (a record is reused across code changes: the report says which)
    from multiscale.provenance import code
    assert f"- Code: package SHA-1 {code()['sha1'][:12]}" in text and {r["code"] for r in rows} == {code()["sha1"][:12]}
    for tol, shown in ((0.01, "| 1 % |"), (0.05, "| 5 % |")):
        good = [g for g in GRIDS if worst[g] <= tol]
        line = next(line for line in text.splitlines() if line.startswith(shown))
        if good:
            best = min(good, key=time.get)
            assert line.split("|")[2].strip() == str(best)
        else:
            assert "none of the runs" in line
    for png in ("hertz_error_vs_time.png", "hertz_grid.png"):
        assert (out / png).stat().st_size > 5000


def test_rerun_skips_finished_runs_and_runs_only_new_points(hertz_study, capsys):
    path, out = hertz_study
    before = {p.name: p.read_text() for p in (out / "runs").glob("*.json")}
    path.write_text(HERTZ + "plots = false\n")
    assert main(["study", str(path)]) == 0
    assert "4 recorded before, 0 run now" in capsys.readouterr().out
    assert {p.name: p.read_text() for p in (out / "runs").glob("*.json")} == before
    # a report without plots leaves none of the earlier ones beside it (a report of failed runs sat
    # beside the plots of the study before; a user trial)
    assert not [p for p in ("hertz_error_vs_time.png", "hertz_grid.png") if (out / p).exists()]
    # a fifth grid: only that run is computed; a range giving the same points names the same runs
    path.write_text(HERTZ.replace("grid = [12, 16, 24, 32]", "grid = [12, 16, 24, 32, 20]") + "plots = false\n")
    assert main(["study", str(path)]) == 0
    assert "4 recorded before, 1 run now" in capsys.readouterr().out
    path.write_text(HERTZ.replace("grid = [12, 16, 24, 32]", "grid = {start = 12, stop = 24, step = 4}")
                    + "plots = false\n")
    assert main(["study", str(path)]) == 0
    out_text = capsys.readouterr().out
    assert "4 recorded before, 0 run now" in out_text
    # the run of grid 32 is no longer in the study: said (nothing was), kept, out of the table
    assert f"hertz: 1 other record in {out / 'runs'} (runs not in this study: its file changed since they ran" in out_text
    assert len(table(out / "results.csv")) == 4 and len(list((out / "runs").glob("*.json"))) == 5


def test_runs_timed_fewer_times_than_asked_run_again_and_the_report_says_how_often(tmp_path, capsys):
    """[run] repeat = 2 over records of repeat = 1: they run again (before: "0 run now", and the
    report said "best of 2" over runs timed once; found by a user trial); back to 1, the records of
    2 are kept and the report says what they hold."""
    study = HERTZ.replace("grid = [12, 16, 24, 32]", "grid = [12, 16]")
    path = write(tmp_path, study + "plots = false\n")
    assert main(["study", str(path)]) == 0
    capsys.readouterr()
    report = tmp_path / "results" / "hertz" / "hertz.md"
    path.write_text(study.replace("processes = 2", "processes = 2\nrepeat = 2") + "plots = false\n")
    assert main(["study", str(path)]) == 0
    assert "0 recorded before, 2 run now" in capsys.readouterr().out and "best of 2 repetition(s)" in report.read_text()
    runs = sorted((tmp_path / "results" / "hertz" / "runs").glob("*.json"))
    assert [json.loads(p.read_text())["repeat"] for p in runs] == [2, 2]
    path.write_text(study + "plots = false\n")
    assert main(["study", str(path)]) == 0
    assert "2 recorded before, 0 run now" in capsys.readouterr().out and "best of 2 repetition(s)" in report.read_text()
    # a record of other code is reused; the report says so (it said nothing: a user trial)
    record = json.loads(runs[0].read_text())
    runs[0].write_text(json.dumps({**record, "code": {"sha1": "0" * 40}}))
    assert main(["study", str(path)]) == 0
    assert "**the runs were made by 2 versions of the package** (SHA-1 " in report.read_text()


@pytest.fixture
def made(monkeypatch) -> list:
    """The (figure, axes) of every ``plt.subplots`` of the study figures, kept open to be read (closed
    after the test)."""
    import matplotlib.pyplot as plt

    from multiscale.plots import studies as figures
    made, every, subplots, close = [], [], plt.subplots, plt.close

    def kept(*a, **k):
        made.append(subplots(*a, **k))
        every.append(made[-1][0])              # (a test may clear ``made``)
        return made[-1]
    monkeypatch.setattr(figures.plt, "subplots", kept)
    monkeypatch.setattr(figures.plt, "close", lambda fig: None)
    yield made
    for fig in every:
        close(fig)


def test_the_error_figure_draws_the_pareto_front_of_each_case(tmp_path, made):
    """[report] cases are problems of their own (here two loads): the error-vs-time figure draws the
    Pareto front of each (before: one front over all runs, which put a setting 17 % off at one
    approach on the front for its 7 % at another; found by a user trial)."""
    from multiscale.studies.results import case_key, collect
    study = (HERTZ.replace("grid = [12, 16, 24, 32]", 'grid = [12, 16]\nload = ["5 N", "20 N"]')
             .replace('load = "10 N"\n', "").replace("[report]", '[report]\ncases = ["load"]'))
    path = write(tmp_path, study)
    assert main(["study", str(path)]) == 0
    loaded = load_study(path)
    rows = [r for r in collect(loaded) if r.ok]                   # the rows the figure was drawn from
    (fig, axes), = made[:1]
    for ax, metric in zip(axes[0], ("contact_radius", "max_pressure", "approach")):
        steps = [line for line in ax.get_lines() if line.get_drawstyle() == "steps-post"]
        for case, line in zip(list(dict.fromkeys(case_key(loaded, r) for r in rows)), steps):
            mine = [r for r in rows if case_key(loaded, r) == case and r.errors[metric] > 0]
            front = pareto([r.record["wall_time"] for r in mine], [r.errors[metric] for r in mine])
            assert list(line.get_xdata()) == [mine[i].record["wall_time"] for i in front]
        assert len(steps) == 2


@pytest.mark.parametrize("times, errors", [((4.1, 4.3, 4.5, 4.7), (0.018, 0.016, 0.014, 0.012)),
                                           ((1000.2, 1000.9, 1001.6, 1002.3), (0.0104, 0.0103, 0.0102, 0.0101)),
                                           ((0.9, 2, 4, 8), (0.3, 0.1, 0.05, 0.011)),
                                           ((1, 3, 30, 200), (0.8, 0.1, 0.02, 0.011))])
def test_a_log_axis_of_the_error_figure_has_at_least_two_labels(tmp_path, made, times, errors):
    """Wall times 4.1 ... 4.7 s: no decade, 2, 3 or 5 fell on the log axis, which had no tick label
    at all (a user trial); each axis now has at least two, distinct (1000.2 ... 1002.3 s read
    "1e+03" each: a review), each where its number is."""
    from multiscale.plots import studies as figures
    study = load_study(write(tmp_path, HERTZ.replace('errors = ["1 %", "5 %"]', 'errors = ["1 %"]')))
    rows = [Row(run, {"status": "ok", "wall_time": t, "metrics": {m: 1.0 for m in study.metrics}},
                errors={m: e for m in study.judged}) for run, t, e in zip(study.runs, times, errors)]
    figures.plot(study, rows, tmp_path)
    fig, axes = made[0]
    fig.canvas.draw()
    for axis in (axes[0][0].xaxis, axes[0][0].yaxis):
        lo, hi = axis.get_view_interval()
        ticks = [(t.get_loc(), t.label1.get_text()) for t in axis.get_major_ticks() + axis.get_minor_ticks()
                 if t.label1.get_text() and lo <= t.get_loc() <= hi]
        assert len(ticks) >= 2 and len({text for _, text in ticks}) == len(ticks), (axis.axis_name, ticks)
        for at, text in ticks:
            assert float(text) == pytest.approx(at, rel=5e-3)


def test_the_figures_mark_the_reference_run_and_label_only_what_they_draw(tmp_path, made):
    """The reference run's error 0 has no place on a log axis: the knob figure marks its setting with
    a line (it was missing: a user trial); a Pareto front's points are ringed, so that a front of one
    point is seen under its legend entry (it drew nothing: a user trial)."""
    from multiscale.plots import studies as figures
    study = load_study(write(tmp_path, HERTZ.replace('kind = "analytic"', 'kind = "run"\nrun = {grid = 32}')))
    for errors, front in (((0.05, 0.02, 0.01), 3), ((0.01, 0.02, 0.05), 1)):
        made.clear()
        rows = [Row(run, {"status": "ok", "wall_time": t, "metrics": {m: 1.0 for m in study.metrics}},
                    errors={m: e for m in study.judged}, is_reference=e == 0)
                for run, t, e in zip(study.runs, (1.0, 2.0, 3.0, 4.0), (*errors, 0.0))]
        figures.plot(study, rows, tmp_path)
        pareto_ax, knob_ax = made[0][1][0][0], made[1][1][0][0]
        steps = [line for line in pareto_ax.get_lines() if line.get_drawstyle() == "steps-post"]
        assert [len(line.get_xdata()) for line in steps] == [front] and steps[0].get_marker() == "o"
        assert steps[0].get_label() == "Pareto front"
        marks = [line for line in knob_ax.get_lines() if line.get_label() == "the reference (error 0)"]
        assert len(marks) == 1 and list(marks[0].get_xdata()) == [32, 32]


@pytest.mark.parametrize("dt, ticks, label", [('{start = "50 us", stop = "450 us", num = 3, log = true}',
                                               ["50 µs", "150 µs", "450 µs"], "dt"),
                                              ("[5e-05, 0.00015, 0.00045]", ["5e-05", "0.00015", "0.00045"], "dt [s]")])
def test_a_knob_axis_is_labelled_as_the_study_wrote_it(tmp_path, made, dt, ticks, label):
    """A range in rpm was ticked in rad/s without a unit (1000 rpm shown "104.7"; a user trial): the
    ticks are the values as written, in the range's unit; bare numbers get the SI unit on the axis."""
    from multiscale.plots import studies as figures
    study = load_study(write(tmp_path, f'problem = "heat_partition"\nmetrics = ["partition_1"]\n[sweep]\ndt = {dt}\n'))
    rows = [Row(run, {"status": "ok", "wall_time": 1.0, "metrics": {"partition_1": 0.5}}) for run in study.runs]
    figures.plot(study, rows, tmp_path)
    ax = made[0][1][0][0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ticks and ax.get_xlabel() == label


def test_reference_from_a_stored_file_and_records_shared_by_studies(hertz_study, tmp_path, capsys):
    """kind = "file": the stored exact values give the analytic errors; a second study pointing at
    the same run folder reuses the first one's runs (records are keyed by parameters)."""
    path, out = hertz_study
    E_star = 210e9 / (1 - 0.3**2)
    a = (3 * 10.0 * 10e-3 / (4 * E_star)) ** (1 / 3)
    (tmp_path / "hertz.json").write_text(json.dumps({"contact_radius": a, "max_pressure": 3 * 10.0 / (2 * np.pi * a * a),
                                                    "approach": a * a / 10e-3}))
    other = write(tmp_path, HERTZ.replace('kind = "analytic"', 'kind = "file"\nfile = "hertz.json"')
                  .replace("[run]", f'[run]\nfolder = "{out}"').replace('name = "hertz"', 'name = "stored"')
                  + f'plots = false\nfolder = "{tmp_path}"\n')
    capsys.readouterr()
    assert main(["study", str(other)]) == 0
    assert "4 recorded before, 0 run now" in capsys.readouterr().out
    rows = table(out / "results.csv")          # rewritten by the "stored" study
    for row in rows:
        for m, err in hertz_independent(int(row["grid"])).items():
            assert float(row[f"{m}_error"]) == pytest.approx(err, rel=1e-6)
    assert "stored result hertz.json" in (tmp_path / "stored.md").read_text()


def test_a_reference_file_of_some_metrics_judges_those_and_tabulates_the_rest(hertz_study, tmp_path, capsys):
    """A measurement of some metrics only (user trial M: a worn volume, no temperature) judges
    those; the others are tabulated without an error (before: "no number for metric"). A key
    like a misspelt metric, or no metric at all, is still refused."""
    path, out = hertz_study
    a = (3 * 10.0 * 10e-3 / (4 * 210e9 / (1 - 0.3**2))) ** (1 / 3)
    ref = tmp_path / "some.json"
    ref.write_text(json.dumps({"contact_radius": a, "max_pressure": 3 * 10.0 / (2 * np.pi * a * a)}))
    text = (HERTZ.replace('kind = "analytic"', f'kind = "file"\nfile = "{ref.name}"')
            .replace("[run]", f'[run]\nfolder = "{out}"').replace('name = "hertz"', 'name = "some"')
            + f'folder = "{tmp_path / "report"}"\n')
    assert main(["study", str(write(tmp_path, text))]) == 0
    capsys.readouterr()
    with h5py.File(out / "results.h5") as h5:
        assert "approach" in h5 and "approach_error" not in h5 and "approach_reference" not in h5
        errors = {m: h5[f"{m}_error"][...] for m in ("contact_radius", "max_pressure")}
        np.testing.assert_allclose(h5["max_error"][...], np.maximum(*errors.values()), rtol=1e-12)
    for row in table(out / "results.csv"):
        exact = hertz_independent(int(row["grid"]))
        assert float(row["max_pressure_error"]) == pytest.approx(exact["max_pressure"], rel=1e-6)
        assert "approach_error" not in row and row["message"] == ""
    md = (tmp_path / "report" / "some.md").read_text()
    assert "stored result some.json (of contact_radius, max_pressure; approach tabulated without one)" in md
    head = next(line for line in md.splitlines() if line.startswith("| grid |"))
    assert head.count("| error |") == 2 and "approach" in head
    assert (tmp_path / "report" / "some_error_vs_time.png").exists()
    for given, message in (({"contact_radius": a, "aproach": 1e-6}, '"aproach" is no metric of the study (did you '
                                                                    'mean "approach"?)'),    # (said of the metric)
                           ({"radius": a}, '"radius" is no metric of the study (did you mean "contact_radius"?)'),
                           ({"wear": a}, "holds no number for any metric of the study (contact_radius, max_pressure, "
                                         "approach); it holds wear")):
        ref.write_text(json.dumps(given))
        assert main(["study", str(write(tmp_path, text))]) == 2
        assert message in capsys.readouterr().err


def test_a_zone_law_sweep_over_the_grid_judges_each_grid_by_its_own_reference(tmp_path, capsys):
    """zone_laws without reference_n takes the whole surface on the run's own n as reference; the
    cached reference's key left n out, so a sweep over n judged every grid against the first one
    solved (a user trial: 2.96 % / 11.7 % reported at n = 120 where its own reference gives 5.24 % /
    3.87 %). Each row's reference is checked against a direct FFT-BEM solve on its grid."""
    path = write(tmp_path, """
name = "zones"
problem = "zone_laws"
metrics = ["mean_pressure", "area_fraction"]
[fixed]
zones = [2, 2]
law_points = 6
k_max = 6
source_n = 32
[sweep]
n = [16, 32]
[reference]
kind = "analytic"
[run]
processes = 2
[report]
plots = false
""")
    assert main(["study", str(path)]) == 0, capsys.readouterr().err
    rows = table(tmp_path / "results" / "zones" / "results.csv")
    assert len({row["mean_pressure_reference"] for row in rows}) == 2
    for row in rows:
        n = int(row["n"])
        h = fractal_surface(32, 1e-3, 0.95, 2.0, 6.0, 4e-6, seed=1).heights
        if n != 32:                      # resampled by its Fourier series (content below k = 8)
            H, out = np.fft.rfft2(h), np.zeros((n, n // 2 + 1), complex)
            out[:8, :8], out[n - 7:, :8] = H[:8, :8], H[32 - 7:, :8]
            h = np.fft.irfft2(out, s=(n, n)) * (n * n) / 32**2
        r = ContactSolver(HalfSpace.from_materials(4e9, 0.15), (n, n), 1e-3 / n, periodic=False).solve(
            h, approach=6e-6, tol=1e-8)
        assert float(row["mean_pressure_reference"]) == pytest.approx(r.mean_pressure, rel=1e-6)
        assert float(row["area_fraction_reference"]) == pytest.approx(r.area_fraction, rel=1e-6)


def test_a_sweep_of_a_list_valued_knob_draws_its_figure(tmp_path, capsys):
    """zones = [[2, 2], [4, 4]]: the figure's tick map keyed the values themselves, and a list is
    not hashable: `make report` stopped at zone_laws.toml with a TypeError after its runs, no
    zone_laws.md (a docs audit). Such an axis is categorical, ticked as written."""
    path = write(tmp_path, """
name = "zones"
problem = "zone_laws"
metrics = ["mean_pressure"]
[fixed]
n = 16
law_points = 6
k_max = 6
source_n = 32
[sweep]
zones = [[2, 2], [4, 4]]
[reference]
kind = "analytic"
""")
    assert main(["study", str(path)]) == 0, capsys.readouterr().err
    assert (tmp_path / "results" / "zones" / "zones.md").is_file()
    assert (tmp_path / "results" / "zones" / "zones_zones.png").stat().st_size > 5000


def test_the_cheapest_setting_meets_the_error_on_every_sample_averaged_over(tmp_path):
    """With ``average_over = ["seed"]`` the table of what accuracy costs named one lucky seed as the
    setting ("circular, seed 1: 19.6 %" where seeds 2 and 3 gave 31.7 % and 38.6 %; a user trial).
    A setting is now judged by its worst error over the seeds and costed by their mean time."""
    from multiscale.studies import cheapest
    path = write(tmp_path, """
name = "rough"
problem = "rough_contact"
metrics = ["area_fraction"]
[fixed]
n = 64
[[sweep]]
model = ["fft-bem", "circular", "elliptic-interacting"]
[[sweep]]
seed = [1, 2, 3]
[reference]
kind = "run"
run = {model = "fft-bem"}
[report]
errors = ["10 %", "30 %", "50 %"]
average_over = ["seed"]
""")
    study = load_study(path)
    errors = {"fft-bem": (0, 0, 0), "circular": (0.196, 0.317, 0.386), "elliptic-interacting": (0.05, 0.08, 0.09)}
    times = {"fft-bem": 3.0, "circular": 0.1, "elliptic-interacting": 1.0}
    rows = []
    for run in study.runs:
        model, seed = run.shown["model"], int(run.shown["seed"])
        row = Row(run, {"status": "ok", "wall_time": times[model] + 0.01 * seed, "metrics": {}})
        row.errors = {"area_fraction": errors[model][seed - 1]}
        row.is_reference = model == "fft-bem"
        rows.append(row)
    found = {c["error"]: c["setting"] for c in cheapest(study, rows)}
    assert [r.run.shown["model"] for r in found[0.3].rows] == ["elliptic-interacting"] * 3     # not circular
    assert found[0.5].rows[0].run.shown["model"] == "circular" and found[0.5].max_error == 0.386
    assert found[0.5].wall_time == pytest.approx(0.12) and found[0.5].shown(study, "seed") == "3 samples"
    rows[4].record["status"] = "failed"                          # circular, seed 2: a setting short of a sample
    assert {c["error"]: c["setting"] for c in cheapest(study, rows)}[0.5].rows[0].run.shown["model"] != "circular"


def test_a_knob_that_changes_nothing_gets_its_report(tmp_path, capsys):
    """Errors 0 in every run (the metric does not depend on the knob) made the knob figure's log
    axis raise: no Markdown report, a matplotlib traceback (a user trial)."""
    path = write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]", "max_iter = [3000, 5000]").replace(
        'kind = "analytic"', 'kind = "run"\nrun = {max_iter = 5000}').replace("[fixed]", "[fixed]\ngrid = 12"))
    assert main(["study", str(path)]) == 0, capsys.readouterr().err
    assert all(float(r["max_error"]) == 0 for r in table(tmp_path / "results" / "hertz" / "results.csv"))
    assert (tmp_path / "results" / "hertz" / "hertz.md").is_file()
    assert (tmp_path / "results" / "hertz" / "hertz_max_iter.png").stat().st_size > 5000


def test_a_sweep_of_too_many_runs_is_refused_before_it_is_made(tmp_path):
    """Two ranges within the 10 000-value cap each made 10 M runs: the expansion ran silently for
    minutes at 1 GB (a user trial). The product is counted first."""
    path = write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]",
                                         'grid = {start = 8, stop = 2000, step = 1}\nmax_iter = {start = 1, stop = '
                                         '5000, step = 1}'))
    with pytest.raises(SceneError, match=r"sweep: the sweep makes 9,965,000 runs or more, over 100,000"):
        load_study(path)


def test_study_command_errors_are_one_line(tmp_path, capsys):
    """A reference file with unit strings says a number is expected (it said 'no number for metric
    "contact_radius" (did you mean "contact_radius"?)'); --processes 0 is refused (it hung); a
    report folder under a file is one error line, not a traceback (adversarial tests)."""
    (tmp_path / "ref.json").write_text(json.dumps({"contact_radius": "68.76 um", "max_pressure": 1e9, "approach": 1e-6}))
    stored = write(tmp_path, HERTZ.replace('kind = "analytic"', 'kind = "file"\nfile = "ref.json"') + "plots = false\n")
    assert main(["study", str(stored)]) == 2
    assert 'metric "contact_radius" is \'68.76 um\': give a number in SI units' in capsys.readouterr().err
    path = write(tmp_path, HERTZ + "plots = false\n", "plain.toml")
    with pytest.raises(SystemExit) as e:
        main(["study", str(path), "--processes", "0"])
    assert e.value.code == 2 and "a whole number >= 1" in capsys.readouterr().err
    (tmp_path / "afile").write_text("")
    assert main(["study", str(path), "--report", str(tmp_path / "afile" / "rep")]) == 2
    assert capsys.readouterr().err.strip().splitlines()[-1].startswith("error: cannot write ")


def test_failing_and_timed_out_runs_are_recorded_and_the_rest_completes(tmp_path, capsys):
    text = HERTZ.replace("[sweep]\ngrid = [12, 16, 24, 32]",
                         '[sweep]\ncombine = "zip"\ngrid = [12, 16, 24]\nmax_iter = [5000, 1, 5000]') + "plots = false\n"
    path = write(tmp_path, text)
    assert main(["study", str(path)]) == 1          # runs failed: exit 1, not a user error
    failed = [line for line in capsys.readouterr().out.splitlines() if " failed: " in line]
    assert len(failed) == 1 and failed[0].startswith("  1 failed: ContactConvergenceError: ")
    assert failed[0].endswith("(grid = 16, max_iter = 1)")          # which run (it said none: an MPI trial)
    rows = table(tmp_path / "results" / "hertz" / "results.csv")
    assert [r["status"] for r in rows] == ["ok", "failed", "ok"]
    assert rows[1]["message"].startswith("ContactConvergenceError: ") and "1 iterations" in rows[1]["message"]
    assert float(rows[0]["max_error"]) < 0.1 and math.isnan(float(rows[1]["max_error"]))
    report = (tmp_path / "results" / "hertz" / "hertz.md").read_text()
    assert "grid = 16, max_iter = 1: ContactConvergenceError" in report
    # --rerun-failed runs only the failed one again
    capsys.readouterr()
    assert main(["study", str(path), "--rerun-failed"]) == 1
    assert "2 recorded before, 1 run now, 1 failed" in capsys.readouterr().out
    # a run over its time limit is killed and recorded as failed
    slow = write(tmp_path, text.replace("[run]", '[run]\ntimeout = "0.05 s"').replace('name = "hertz"', 'name = "slow"'),
                 "slow.toml")
    assert main(["study", str(slow)]) == 1
    rows = table(tmp_path / "results" / "slow" / "results.csv")
    assert all(r["status"] == "failed" and r["message"] == "timed out after 0.05 s (run.timeout)" for r in rows)
    # the same limit: not run again; a longer one runs them (they stayed failed, "--rerun-failed" needed)
    capsys.readouterr()
    assert main(["study", str(slow)]) == 1
    assert "3 recorded before, 0 run now, 3 failed" in capsys.readouterr().out
    slow.write_text(slow.read_text().replace('timeout = "0.05 s"', 'timeout = "1 h"'))
    assert main(["study", str(slow)]) == 1
    assert "0 recorded before, 3 run now, 1 failed" in capsys.readouterr().out


def test_sweep_expansion_products_zips_and_ranges(tmp_path):
    path = write(tmp_path, """
problem = "heat_partition"
metrics = ["partition_1"]
[[sweep]]
dt = {start = "50 us", stop = "450 us", num = 3, log = true}
[[sweep]]
combine = "zip"
n = [32, 48]
seed = {start = 3, stop = 4, num = 2}
[reference]
kind = "run"
run = {dt = "50 us"}
""")
    study = load_study(path)
    assert study.knobs == ("dt", "n", "seed")
    labels = [r.label for r in study.runs]
    assert len(labels) == 6 and len({r.key for r in study.runs}) == 6
    assert [x["dt"] for x in labels[::2]] == pytest.approx([50e-6, 150e-6, 450e-6])
    assert [(x["n"], x["seed"]) for x in labels[:2]] == [(32, 3), (48, 4)]
    assert study.folder == tmp_path / "results" / "study"


def test_a_range_of_temperatures_in_degc(tmp_path):
    """A scene's temperature swept by a range: its values were bare kelvins (293.15, refused: "a
    temperature needs its unit"), and a step of "20 degC" was 293.15 K (one value)."""
    (tmp_path / "scene.toml").write_text((ROOT / "demos" / "block_on_flat.toml").read_text())
    path = write(tmp_path, """
problem = "scene"
scene = "scene.toml"
metrics = ["max_pressure"]
[fixed]
effects = ["contact", "thermal"]
"materials.block.kappa" = "5 W/(m K)"
"materials.block.chi" = "1e-6 m^2/s"
"materials.flat.kappa" = "50 W/(m K)"
"materials.flat.chi" = "1e-5 m^2/s"
"time.end" = "1 s"
"time.steps" = 1
[sweep]
"time.initial_temperature" = {start = "20 degC", stop = "100 degC", step = "40 degC"}
""")
    runs = load_study(path).runs
    assert [r.raw["time.initial_temperature"] for r in runs] == ["293.15 K", "333.15 K", "373.15 K"]


def test_a_range_with_whole_bounds_keeps_its_fractional_values(tmp_path):
    """{start = 0, stop = 1, num = 11} of a scene's friction gave the two runs 0 and 1, and
    {start = 3, stop = 10, num = 50} of hertz's (real) window the eight 3 ... 10: whole bounds were
    taken for an integer range (a user trial). An integer parameter, or a scene key whose values
    are all whole, still gets integers."""
    (tmp_path / "scene.toml").write_text((ROOT / "demos" / "pin_on_disc_perfect.toml").read_text())
    scene = write(tmp_path, """
problem = "scene"
scene = "scene.toml"
metrics = ["max_pressure"]
[[sweep]]
"loading.friction" = {start = 0, stop = 1, num = 11}
[[sweep]]
"time.steps" = {start = 1, stop = 7, num = 4}
""", "scene_study.toml")
    labels = [r.label for r in load_study(scene).runs]
    assert sorted({x["loading.friction"] for x in labels}) == pytest.approx([i / 10 for i in range(11)])
    assert sorted({x["time.steps"] for x in labels}) == [1, 3, 5, 7]
    assert all(isinstance(x["time.steps"], int) for x in labels)
    log = scene.read_text().replace("{start = 1, stop = 7, num = 4}", "{start = 3, stop = 30, num = 3, log = true}")
    labels = [r.label for r in load_study(write(tmp_path, log, "log_steps.toml")).runs]   # the scene's integer key:
    assert sorted({x["time.steps"] for x in labels}) == [3, 9, 30]    # rounded (refused for 3.0000000000000004, 9.49:
    assert all(isinstance(x["time.steps"], int) for x in labels)     # a user trial)
    one = {r.key for r in load_study(scene).runs}          # ranks name the runs (2 reused the times of 1)
    scene.write_text(scene.read_text() + "[run]\nranks = 2\n")
    assert not one & {r.key for r in load_study(scene).runs}
    window = write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]", "window = {start = 3, stop = 10, num = 50}\n"
                                           "grid = {start = 12, stop = 30, num = 4}"), "hertz.toml")
    labels = [r.label for r in load_study(window).runs]
    assert len({x["window"] for x in labels}) == 50 and sorted({x["grid"] for x in labels}) == [12, 18, 24, 30]


def test_pareto_front():
    times = [1.0, 2.0, 3.0, 4.0, 2.5, 5.0]
    errors = [0.1, 0.2, 0.05, 0.01, 0.05, 0.0]       # the 0 (the reference itself) is left out
    assert pareto(times, errors) == [0, 4, 3]
    assert relative_error(1.1, 1.0) == pytest.approx(0.1) and math.isnan(relative_error(0.2, 0.0)) and relative_error(0.0, 0.0) == 0.0


BAD = [   # (what, replacement applied to HERTZ, the message expected on stderr)
    ("unknown parameter", ("grid = [12", "gird = [12"),
     'sweep.gird: unknown parameter of problem "hertz" (did you mean "grid"?)'),
    ("empty sweep", ("grid = [12, 16, 24, 32]", "grid = []"), "sweep.grid = []: empty sweep: give at least one value"),
    ("integer range of repeated values", ("grid = [12, 16, 24, 32]", "grid = {start = 12, stop = 13, num = 4}"),
     "sweep.grid = {start = 12, stop = 13, num = 4}: its 4 values round to 2 different integers (12, 13): an "
     "integer takes fewer values, or a wider range"),      # (ran 12 and 13, silently: a user trial)
    ("reference not in the sweep", ('kind = "analytic"', 'kind = "run"\nrun = {grid = 64}'),
     "reference.run = {grid = 64}: not in the sweep (swept grid: 12, 16, 24, 32)"),
    ("reference of an unswept parameter", ('kind = "analytic"', 'kind = "run"\nrun = {load = "1 N"}'),
     "reference.run.load: not a swept parameter; swept: grid"),
    ("reference of an unswept parameter and a missing point",           # both at once (they came in rounds)
     ('kind = "analytic"', 'kind = "run"\nrun = {load = "1 N", grid = 64}'),
     "reference.run.load: not a swept parameter; swept: grid\nerror: reference.run = {grid = 64}: not in the sweep"),
    ("unknown problem", ('problem = "hertz"', 'problem = "herz"'),
     'problem = "herz": unknown problem (did you mean "hertz"?)'),
    ("unknown metric", ('"approach"]', '"aproach"]'),
     'metrics item 3 ("aproach"): unknown metric of problem "hertz" (did you mean "approach"?)'),
    ("bad value", ("grid = [12, 16, 24, 32]", "grid = [12, 4]"),
     "sweep.grid = [12, 4]: item 2 (4): must be an integer >= 8"),
    ("unequal zip", ("grid = [12, 16, 24, 32]", 'combine = "zip"\ngrid = [12, 16]\nwindow = [3]'),
     'sweep: combine = "zip" needs lists of equal length (grid: 2, window: 1)'),
    ("swept and fixed", ("grid = [12, 16, 24, 32]", "load = [1, 2]"), "sweep.load: also given in fixed; give it once"),
    ("bad range", ("grid = [12, 16, 24, 32]", "grid = {start = 8, stop = 64}"),
     "sweep.grid = {start = 8, stop = 64}: a range needs start, stop and one of num, step"),
    ("analytic without one", ('problem = "hertz"\nmetrics = ["contact_radius", "max_pressure", "approach"]',
                              'problem = "rough_contact"\nmetrics = ["mean_pressure"]', "grid = [12, 16, 24, 32]",
                              "n = [32, 64]", 'load = "10 N"\nradius = "10 mm"', ""),
     'reference.kind = "analytic": problem "rough_contact" has no analytic reference; use kind = "run"'),
    ("wrong unit", ('load = "10 N"', 'load = "10 mm"'),
     'fixed.load = "10 mm": expected a force (N, kN); the unit "mm" is a length'),
    ("no sweep", ("[sweep]\ngrid = [12, 16, 24, 32]", ""), "sweep: missing; required"),
    ("misspelt sweep and metric", ("[sweep]", "[sweeps]", '"approach"]', '"aproach"]'),     # (the metric came a
     'report\nerror: metrics item 3 ("aproach"): unknown metric of problem "hertz"'),     # pass later: a user trial)
]


@pytest.mark.parametrize("what, change, message", BAD, ids=[b[0] for b in BAD])
def test_bad_study_files_give_clear_errors(tmp_path, capsys, what, change, message):
    text = HERTZ
    for old, new in zip(change[::2], change[1::2]):
        text = text.replace(old, new)
    path = write(tmp_path, text)
    assert main(["study", str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "Traceback" not in err and not (tmp_path / "results").exists()


def test_a_sweep_against_measured_values_finds_where_each_metric_meets_them(tmp_path, made):
    """Calibration from a sweep (user trial M: which k_w gives the measured worn volume). A Hertz
    contact on a grid that follows the contact radius is self-similar: its peak pressure is
    c F^(1/3) exactly, so the log-log interpolation between loads must return the load whose
    closed-form peak pressure was given, divided by the cube of the grid's error ratio."""
    def p0(load):
        a = (3 * load * 10e-3 / (4 * 210e9 / (1 - 0.3**2))) ** (1 / 3)
        return 3 * load / (2 * np.pi * a * a)
    (tmp_path / "measured.json").write_text(json.dumps({"max_pressure": p0(8.0), "contact_radius": 1.0}))
    text = (HERTZ.replace('load = "10 N"', "grid = 16").replace("grid = [12, 16, 24, 32]", 'load = ["5 N", "10 N", "20 N"]')
            .replace('kind = "analytic"', 'kind = "file"\nfile = "measured.json"').replace('"approach"]', ']'))
    assert main(["study", str(write(tmp_path, text))]) == 0
    rows = {float(r["load"]): float(r["max_pressure"]) for r in table(tmp_path / "results" / "hertz" / "results.csv")}
    assert sorted(rows) == [5.0, 10.0, 20.0]
    ratio = rows[10.0] / p0(10.0)                    # the grid's error, the same at every load
    assert rows[5.0] / p0(5.0) == pytest.approx(ratio, rel=1e-7)
    md = (tmp_path / "results" / "hertz" / "hertz.md").read_text()
    line = next(x for x in md.splitlines() if x.startswith("| max_pressure [Pa] | load |"))
    found = float(line.split("|")[4].split()[0])
    assert found == pytest.approx(8.0 / ratio**3, rel=1e-3) and abs(ratio**-3 - 1) > 3e-3   # 4 digits shown
    assert "| 5 N … 10 N |" in line and "N (log-log)" in line
    far = next(x for x in md.splitlines() if x.startswith("| contact_radius [m] | load |"))
    assert "not in the swept range | 5 N … 20 N |" in far
    # a zip group: its first knob with the others alongside (a trial's zip of two pad formulations,
    # whose tables were interpolated as if along the first key alone)
    zipped = text.replace('radius = "10 mm"\n', "", 1).replace('load = ["5 N", "10 N", "20 N"]', 'combine = "zip"\nload = ["5 N", "10 N", "20 N"]\n'
                                                           'radius = ["10 mm", "10 mm", "10 mm"]')
    assert main(["study", str(write(tmp_path, zipped.replace('name = "hertz"', 'name = "zipped"')))]) == 0
    md = (tmp_path / "results" / "zipped" / "zipped.md").read_text()
    assert "| max_pressure [Pa] | load (with radius alongside) |" in md
    _, axes = made[-1]                          # against the load: the values, the measured one, where met
    pressure = axes[0][1]
    measured, = [line for line in pressure.get_lines() if line.get_label() == "measured"]
    star, = [line for line in pressure.get_lines() if line.get_label() == "where the sweep meets it"]
    assert measured.get_ydata()[0] == p0(8.0) and star.get_ydata()[0] == p0(8.0)
    assert star.get_xdata()[0] == pytest.approx(8.0 / ratio**3, rel=1e-9)


@pytest.mark.parametrize("values, message", [
    ('{"contact_radius": 0.0, "max_pressure": 1e9, "approach": 1e-6}', 'metric "contact_radius" is 0.0'),
    ('{"contact_radius": 1e-4, "max_pressure": NaN, "approach": 1e-6}', 'metric "max_pressure" is nan')])
def test_a_reference_file_value_no_error_can_be_relative_to_is_refused(tmp_path, capsys, values, message):
    """A reference of 0 or NaN made every error "n/a" and the figure was left out without a word
    (found by a user trial)."""
    (tmp_path / "ref.json").write_text(values)
    path = write(tmp_path, HERTZ.replace('kind = "analytic"', 'kind = "file"\nfile = "ref.json"'))
    assert main(["study", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{message}: errors are relative to it; give a finite, nonzero number" in err, err


def test_every_problem_of_a_study_file_at_once(tmp_path, capsys):
    """A problem of [run] or [report] hid those of the metrics, [fixed] and [sweep] (and the
    reference): the user fixed them in rounds, the docs say every problem at once."""
    text = HERTZ.replace("processes = 2", "processes = 0").replace('"approach"]', '"aproach"]')
    text = text.replace('load = "10 N"', "load = -10").replace("grid = [12", "gird = [12")
    text = text.replace('kind = "analytic"', 'kind = "run"').replace('errors = ["1 %", "5 %"]', 'errors = ["abc"]')
    assert main(["study", str(write(tmp_path, text))]) == 2
    err = capsys.readouterr().err
    for message in ("run.processes = 0: must be an integer >= 1", "report.errors = [\"abc\"]",
                    'metrics item 3 ("aproach"): unknown metric', "fixed.load = -10: must be > 0 N",
                    'sweep.gird: unknown parameter of problem "hertz"',
                    'reference.run: missing; needed with reference.kind = "run"'):
        assert message in err, err
    assert len(err.strip().splitlines()) == 6 and "Traceback" not in err


def scene_study(tmp_path, demo: str, rest: str) -> Path:
    """A study file of problem "scene" on a demo scene; ``rest``: its metrics and tables."""
    return write(tmp_path, f'problem = "scene"\nscene = "{(ROOT / "demos" / demo).resolve()}"\n{rest}')


def test_bad_scene_study_names_the_scene_path(tmp_path, capsys):
    path = scene_study(tmp_path, "block_on_flat.toml", """
metrics = ["interface_force:last", "max_pressure:sum"]
[sweep]
geometry.mesh_siz = ["2 mm", "3 mm"]
""")
    assert main(["study", str(path)]) == 2
    err = capsys.readouterr().err
    assert 'geometry.mesh_siz: unknown parameter of builder "block_on_flat" (did you mean "mesh_size"?)' in err
    assert 'metrics item 2 ("max_pressure:sum"): a history column, optionally with :last|:first' in err


def test_a_squeal_scene_study_checks_its_metrics_before_running(tmp_path, capsys):
    """A squeal scene's metrics are known before it runs: a misspelt one is refused with the
    others (before: the whole analysis ran, then the run was recorded failed and stayed so)."""
    path = scene_study(tmp_path, "brake_squeal.toml", """
metrics = ["max_growth", "max_growthh"]
[sweep]
loading.friction = [0.3, 0.4]
""")
    assert main(["study", str(path)]) == 2
    err = capsys.readouterr().err
    assert ('metrics item 2 ("max_growthh"): unknown metric of a squeal scene (did you mean "max_growth"?); '
            "allowed: modes, unstable_modes, max_growth") in err
    assert not (tmp_path / "results").exists()
    base = (ROOT / "demos" / "brake_squeal.toml").read_text().replace('"friction", "stability"]', '"friction"]')
    (tmp_path / "base.toml").write_text(base.replace('"../results/', '"results/'))   # (no effect stability)
    fixed = write(tmp_path, f'problem = "scene"\nscene = "{tmp_path / "base.toml"}"\nmetrics = ["max_grwth"]\n'
                  '[fixed]\neffects = ["contact", "friction", "stability"]\n[sweep]\nloading.friction = [0.3, 0.4]\n')
    assert main(["study", str(fixed)]) == 2           # [fixed] makes it a squeal scene (it ran, then failed)
    assert 'metrics item 1 ("max_grwth"): unknown metric of a squeal scene' in capsys.readouterr().err
    ignored = scene_study(tmp_path, "pin_on_disc_perfect.toml", 'metrics = ["wear_volume:last"]\n[sweep]\n'
                          '"wear.k_w" = ["1e-14 1/Pa", "2e-14 1/Pa"]\n')
    assert main(["study", str(ignored)]) == 2           # (it ran both alike, then advised --rerun-failed: a trial)
    assert ('error: wear.k_w: the scene ignores it in every run ([wear] is ignored: effect "wear" is not in effects): '
            "the runs would be alike") in capsys.readouterr().err
    from multiscale.studies.records import metric_problem
    assert "(the run does not write it: " in metric_problem({"time": 1.0}, ["wear_volume:last"], asked=["wear_volume:last"])
    assert "(a run older than the metric: " in metric_problem({"time": 1.0}, ["wear_volume:last"], asked=["time"])
    plain = write(tmp_path, f'problem = "scene"\nscene = "{tmp_path / "base.toml"}"\nmetrics = ["unstable_modes"]\n'
                  '[sweep]\nloading.friction = [0.3, 0.4]\n')
    assert main(["study", str(plain)]) == 2           # no squeal analysis: found after every run before (a trial)
    assert ('metrics item 1 ("unstable_modes"): a squeal metric (of modes.csv), and this scene runs no squeal '
            'analysis (effect "stability")') in capsys.readouterr().err
    folder = scene_study(tmp_path, "brake_squeal.toml", 'metrics = ["max_growth"]\n[fixed]\noutput.folder = "mine"\n'
                                                        "[sweep]\nloading.friction = [0.3, 0.4]\n")
    assert main(["study", str(folder)]) == 2           # (it was replaced by the run's own folder without a word)
    assert "fixed.output.folder: a study writes each run into its own folder" in capsys.readouterr().err


def test_a_scene_study_run_is_named_by_the_files_its_scene_reads(tmp_path):
    """A CAD file rewritten under its name makes new runs (before: the same keys, so the old
    geometry's records were reused as 'recorded before'); a scene reading no file keeps its key."""
    import shutil
    (tmp_path / "cad").mkdir()
    shutil.copy(ROOT / "demos" / "car_brake_stop.toml", tmp_path)
    shutil.copy(ROOT / "demos" / "cad" / "car_brake.step", tmp_path / "cad")
    path = write(tmp_path, 'problem = "scene"\nscene = "car_brake_stop.toml"\nmetrics = ["time"]\n'
                 '[sweep]\nloading.friction = [0.3, 0.4]\n')
    before = [r.key for r in load_study(path).runs]
    with open(tmp_path / "cad" / "car_brake.step", "a") as f:
        f.write("/* another disc */\n")
    after = [r.key for r in load_study(path).runs]
    assert len(set(before + after)) == 4
    plain = scene_study(tmp_path, "block_on_flat.toml", 'metrics = ["time"]\n[sweep]\n"time.steps" = [1]\n')
    scene = (ROOT / "demos" / "block_on_flat.toml").resolve()
    ident = {"problem": "scene", "params": {"scene": str(scene), "overrides": {"time.steps": 1},
                                            "scene_sha256": hashlib.sha256(scene.read_bytes()).hexdigest()}}
    assert load_study(plain).runs[0].key == hashlib.sha256(json.dumps(ident, sort_keys=True).encode()).hexdigest()[:16]

def test_shipped_study_files_are_valid():
    files = sorted((ROOT / "studies").glob("*/*.toml"))
    assert len(files) >= 8
    for f in files:
        study = load_study(f)
        assert study.runs and all(k in study.knobs for k in study.report.cases)
    # the study tutorial's calibration is the shipped file, its reference beside it (a tribologist
    # looked for the file it named: it was not there)
    text = (ROOT / "docs" / "tutorials" / "study.rst").read_text()
    shown = re.search(r'\n((?:    .*\n|\n)*?    name = "k_w_calibration"\n(?:    .*\n|\n)+)', text).group(1)
    calibration = ROOT / "studies" / "macro" / "k_w_calibration.toml"
    assert "\n".join(line[4:] for line in shown.splitlines()).strip() == calibration.read_text().strip()
    assert json.loads((calibration.parent / "measured.json").read_text()) == {"wear_volume:last": 3.8e-11}


def test_scene_problem_errors_are_user_errors(tmp_path):
    with pytest.raises(SceneError, match='scene: missing; problem "scene" needs the base scene file'):
        load_study(write(tmp_path, 'problem = "scene"\nmetrics = ["time"]\n[sweep]\n"time.steps" = [1, 2]\n'))


def test_scene_study_runs_the_macro_scene_with_overrides(tmp_path, capsys):
    """A macro scene swept through its keys: the block-on-flat force is pressure x face area. A
    misspelt history metric fails the run's record; corrected, it is read from the same run."""
    path = scene_study(tmp_path, "block_on_flat.toml", """
metrics = ["interface_forc:last", "max_pressure:max"]
[fixed]
geometry.mesh_size = "5 mm"
geometry.width = "6 mm"
[sweep]
loading.pressure = ["3 MPa"]
[report]
plots = false
""")
    assert main(["study", str(path)]) == 1
    assert 'warning: study: metric "interface_forc:last" (did you mean "interface_force:last"?) not produced' \
        in capsys.readouterr().err                    # when its first run ends, not in the report after the last
    out = tmp_path / "results" / "study"
    for record in (out / "runs").glob("*.json"):      # strict JSON: its history's NaN columns are null
        assert json.loads(record.read_text(), parse_constant=lambda c: pytest.fail(f"{c} in {record.name}"))["ran"]
    row = table(out / "results.csv")[0]
    assert row["status"] == "failed"
    assert ('metric "interface_forc:last" (did you mean "interface_force:last"?) not produced (fix the name: the '
            'runs need not run again)' in row["message"])
    assert "in all: the run's record lists them)" in row["message"] and len(row["message"]) < 800    # not ~180 names
    assert "best of" not in (out / "study.md").read_text()       # no run completed ("best of 0 repetition(s)")
    assert main(["study", str(path)]) == 1             # recorded: the reason is said again (it was "1 failed" alone)
    assert ('\n  1 failed: metric "interface_forc:last" (did you mean "interface_force:last"?) not produced (fix '
            "the name: the runs need not run again) (loading.pressure = 3 MPa)\n") in capsys.readouterr().out
    path.write_text(path.read_text().replace("interface_forc:", "interface_force:"))
    capsys.readouterr()
    assert main(["study", str(path)]) == 0
    assert "1 recorded before, 0 run now" in capsys.readouterr().out
    row = table(out / "results.csv")[0]
    assert float(row["loading.pressure"]) == 3e6
    assert float(row["interface_force:last"]) == pytest.approx(3e6 * 10e-3 * 6e-3, rel=1e-6)
    assert float(row["max_pressure:max"]) == pytest.approx(3e6, rel=1e-3)
    with h5py.File(out / "results.h5") as h5:                   # the swept key's SI unit, from "3 MPa"
        assert h5["loading.pressure"].attrs["unit"] == "Pa" and h5["interface_force:last"].attrs["unit"] == "N"
    assert (out / "runs" / row["run"] / "output" / "history.h5").is_file()


def test_every_misspelt_metric_is_named_at_once():
    """Two misspelt metrics of a run: the message named the first only (a user trial met the
    second after correcting the first)."""
    from multiscale.studies.records import metric_problem
    why = metric_problem({"interface_force:last": 1.0, "time:last": 2.0},
                         ["max_temperature_block:last", "time:last", "interface_forc:last"])
    assert why.startswith('metrics "max_temperature_block:last", "interface_forc:last" (did you mean '
                          '"interface_force:last"?) not produced (fix the name: the runs need not run again)')


def test_the_inputs_warnings_are_said_once_with_their_runs(tmp_path, capsys):
    """Values outside their plausible range warn in a study as in a scene: on the console before
    the runs and in the report, each once with the runs it concerns (before: a scene study at 1 Pa
    said "0 failed" and its warnings stayed in each run's log; a micro study took "approach = 5" as
    5 m without a word: a user trial)."""
    swept = load_study(write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]", 'E = ["1 Pa", "2 Pa", "4 GPa"]')
                             .replace("[fixed]", "[fixed]\ngrid = 12")))
    assert swept.warnings == ('E = "1 Pa": 1 Pa is outside the plausible range 100000 to 1.2e+12 Pa: check the value '
                              'and its unit (run E = 1 Pa; E = 2 Pa; the numbers of E = 1 Pa)',)   # one kind
    path = write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]", "grid = [12, 16]")
                 .replace('radius = "10 mm"', 'radius = "10 mm"\nE = 1').replace("processes = 2", "processes = 1"))
    assert main(["study", str(path)]) == 0
    line = ('E = 1: 1 Pa is outside the plausible range 100000 to 1.2e+12 Pa: check the value and its unit (as "1 MPa" '
            'or "1 GPa" or "1 bar" it would be plausible) (every run)')
    assert f"warning: hertz: {line}" in capsys.readouterr().err
    assert f"- {line}" in (tmp_path / "results" / "hertz" / "hertz.md").read_text()


def test_a_problem_of_every_run_is_said_once(tmp_path):
    """A fixed value wrong with every swept one was said once per run (12 identical lines: a user trial)."""
    with pytest.raises(SceneError) as info:
        load_study(write(tmp_path, 'problem = "rough_contact"\nmetrics = ["mean_pressure"]\n[fixed]\nk_max = 40\n'
                                   "[sweep]\nn = [128, 256, 512]\nseed = [1, 2]\n"))
    assert info.value.problems == ["source_n = 64: must exceed 2 k_max = 80 (the surface must be resolved) (every run)"]
    with pytest.raises(SceneError) as info:
        load_study(write(tmp_path, 'problem = "rough_contact"\nmetrics = ["mean_pressure"]\n[fixed]\nk_max = 40\n'
                                   "source_n = 128\n[sweep]\nn = [64, 72, 80, 128, 256]\n"))
    assert info.value.problems == ["n = 64: must exceed 2 k_max = 80 (the surface must be resolved) (run n = 64)",
                                   "n = 72: must exceed 2 k_max = 80 (the surface must be resolved) (run n = 72)",
                                   "n = 80: must exceed 2 k_max = 80 (the surface must be resolved) (run n = 80)"]


def test_the_knobs_columns_carry_their_units(tmp_path):
    """results.h5 gave the metrics and times a unit, the swept parameters none (a user trial): a
    micro parameter's unit is its kind's, a scene key's too (bare numbers of "wear.k_w" had none: user
    trial M), else that of the values as written."""
    from multiscale.studies.results import knob_unit
    study = load_study(write(tmp_path, HERTZ.replace("grid = [12, 16, 24, 32]", 'grid = [12, 16]\nE = ["1 GPa", 2e9]')))
    assert (knob_unit(study, "grid"), knob_unit(study, "E")) == ("", "Pa")
    (tmp_path / "scene.toml").write_text((ROOT / "demos" / "block_on_flat.toml").read_text())
    scene = load_study(write(tmp_path, 'problem = "scene"\nscene = "scene.toml"\nmetrics = ["max_pressure"]\n[sweep]\n'
                                       '"loading.pressure" = [1e6, 2e6]\n"time.steps" = [1, 2]\n"materials.block.nu" = [0.3, 0.25]\n'
                                       '"geometry.length" = ["10 mm", 9e-3]\n', "s.toml"))
    assert [knob_unit(scene, k) for k in ("loading.pressure", "time.steps", "materials.block.nu",
                                          "geometry.length")] == ["Pa", "", "-", "m"]
    # an entry of an array of tables (it had none: a user trial)
    assert [knob_unit(scene, k) for k in ("boundary[1].temperature", "boundary.2.emissivity")] == ["K", "-"]


def test_a_scene_keys_bare_numbers_get_its_unit_on_the_axis(tmp_path, made):
    """A swept "wear.k_w" of bare numbers was plotted against "wear.k_w" without a unit (user trial
    M): the scene key's SI unit, as results.h5 has it."""
    from multiscale.plots import studies as figures
    (tmp_path / "scene.toml").write_text((ROOT / "demos" / "block_on_flat.toml").read_text())
    study = load_study(write(tmp_path, 'problem = "scene"\nscene = "scene.toml"\nmetrics = ["max_pressure"]\n'
                                       '[sweep]\n"loading.pressure" = [1e6, 2e6]\n'))
    rows = [Row(run, {"status": "ok", "wall_time": 1.0, "metrics": {"max_pressure": 1e6}}) for run in study.runs]
    figures.plot(study, rows, tmp_path)
    assert made[0][1][0][0].get_xlabel() == "loading.pressure [Pa]"


def test_an_interrupted_study_writes_the_table_of_the_runs_that_ended(tmp_path, capfd, monkeypatch):
    """Ctrl-C after the first run: results.csv holds it and names the others missing (it was written
    only at the end, so an interrupted study had none: a user trial), and the report says so (it
    was left as the previous sweep's, beside the new tables: a user trial)."""
    import dataclasses

    from multiscale.studies import driver
    real = driver.execute

    def first_then_interrupted(study, **options):
        real(dataclasses.replace(study, runs=study.runs[:1]), **options)
        raise KeyboardInterrupt
    monkeypatch.setattr(driver, "execute", first_then_interrupted)
    path = write(tmp_path, HERTZ.replace("processes = 2", "processes = 1"))
    assert main(["study", str(path)]) == 130
    md = tmp_path / "results" / "hertz" / "hertz.md"
    assert f"hertz: the runs that ended are in {md.parent / 'results.csv'} and {md} " in capfd.readouterr().err
    rows = table(tmp_path / "results" / "hertz" / "results.csv")
    assert [r["status"] for r in rows] == ["ok", "missing", "missing", "missing"]
    assert float(rows[0]["approach"]) > 0 and rows[1]["message"] == "not run or cut off"
    text = md.read_text()
    assert "- Runs: 1 ok, 0 failed, **3 not run or cut off: the study was stopped** (run it again" in text
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines() if line.startswith("| ")]
    head, missing = next(c for c in cells if c[0] == "grid"), next(c for c in cells if c[-1] == "missing")
    assert missing[head.index("iterations")] == "n/a"   # a run without a count (it said nothing, 0 of a squeal run)
    assert "Failed runs:" not in text
    # into a report folder: its index of the reports written so far too (before: none on Ctrl-C, a review)
    assert main(["study", str(path), "--report", str(tmp_path / "reports")]) == 130
    index = tmp_path / "reports" / "README.md"
    assert f"; index {index} " in capfd.readouterr().err
    text = index.read_text()
    assert "**Stopped during the study hertz**" in text and "## [" in text and "(hertz.md)" in text
    # a second Ctrl-C while they are written is said and held (it left no report, unsaid: a user trial)
    import os
    import signal
    real_collect = driver.collect

    def collect_interrupted(study):
        os.kill(os.getpid(), signal.SIGINT)
        return real_collect(study)
    monkeypatch.setattr(driver, "collect", collect_interrupted)
    md.unlink()
    assert main(["study", str(path)]) == 130
    err = capfd.readouterr().err
    assert "Ctrl-C: still writing the tables and report of the runs that ended; Ctrl-C again abandons it" in err
    assert f"hertz: the runs that ended are in {md.parent / 'results.csv'} and {md} " in err and md.is_file()


def test_a_measured_surface_is_a_micro_study_problem(tmp_path, capsys):
    """measured_contact: an instrument file swept in load (no micro patch from a measured file could
    be run from a study or the command line: a user trial), the numbers of the Python path the
    micro-patch tutorial shows to 1e-12, its contact stiffness (rising with the load), the file's
    bytes in the runs' keys."""
    import shutil

    from multiscale.checkpoint import file_digest
    from multiscale.micro.contact import solve_contact
    from multiscale.micro.topography import condition, read_topography
    from multiscale.schema import Context
    from multiscale.studies.problems import PROBLEMS
    shutil.copy(ROOT / "tests" / "data" / "top-1.top", tmp_path / "afm.top")
    path = write(tmp_path, 'problem = "measured_contact"\nmetrics = ["approach", "area_fraction", "stiffness", "interface_stiffness"]\n[fixed]\n'
                           'file = "afm.top"\n[sweep]\nload = ["1 MPa", "5 MPa"]\n[run]\nprocesses = 1\n'
                           "[report]\nplots = false\n")
    problem = PROBLEMS["measured_contact"]
    for run in load_study(path).runs:                   # a file rewritten under its name: new runs
        params = problem.parse(run.raw, "", Context(directory=tmp_path))
        assert problem.key(params)["files"] == {"file": file_digest(tmp_path / "afm.top")}
        assert "despike" not in problem.key(params)     # added later: the records before it stay valid (a review)
    assert main(["study", str(path)]) == 0
    surface = condition(read_topography(tmp_path / "afm.top"), "plane").surface
    with h5py.File(tmp_path / "results" / "study" / "results.h5") as h5:      # (results.csv: 10 digits)
        assert list(h5["load"][()]) == [1e6, 5e6] and h5["approach"].attrs["unit"] == "m"
        for k, load in enumerate(h5["load"][()]):
            r = solve_contact(surface, kernel=HalfSpace.from_materials(4e9, 0.15), load=load)
            assert h5["approach"][k] == pytest.approx(r.approach, rel=1e-12)
            assert h5["area_fraction"][k] == pytest.approx(r.area_fraction, rel=1e-12) and r.area_fraction > 0
        assert h5["stiffness"].attrs["unit"] == "Pa/m" and 0 < h5["stiffness"][0] < h5["stiffness"][1]
        assert np.all(h5["interface_stiffness"][()] > h5["stiffness"][()])     # the patch's spreading out


def test_an_asperity_model_beyond_its_range_is_said_by_the_run(tmp_path):
    """A rough_contact run with an asperity model records the model's own notes (contacts that
    overlap: ``AsperityResult.notes``) as what it found; the FFT-BEM run of the same patch none."""
    from multiscale.schema import Context
    from multiscale.studies.problems import PROBLEMS
    problem = PROBLEMS["rough_contact"]
    found = {}
    for model in ("fft-bem", "circular"):
        params = problem.parse({"n": 64, "model": model, "approach": "12 um"}, "", Context(directory=tmp_path))
        found[model] = problem.run(params, tmp_path).warnings
    assert found["fft-bem"] == () and len(found["circular"]) == 1
    assert found["circular"][0].startswith("contacts holding") and "FFT-BEM" in found["circular"][0]


def test_what_a_run_finds_is_said_by_the_study_its_report_and_table(tmp_path, capsys):
    """Outliers of a measured file (a smooth map with 3 spikes, written as ISO 25178-71 SDF) are said
    by ``multiscale surface`` and by a scene, but a measured_contact study kept them in its runs' logs
    (a user trial): now the console names them once, the report once with its runs, results.csv per
    run."""
    from multiscale.micro.topography import TopographyWarning, condition, read_topography
    rng = np.random.default_rng(0)
    h = np.cumsum(np.cumsum(rng.normal(size=(48, 64)), 0), 1) * 1e-3      # um, smooth
    h = h - h.mean()
    h[10, 20] += 40 * h.std()
    h[30, 40] -= 40 * h.std()
    h[40, 10] += 40 * h.std()
    head = ("aISO-1.0\nManufacID = test\nCreateDate = 010120260000\nModDate = 010120260000\nNumPoints = 64\n"
            "NumProfiles = 48\nXscale = 1.0E-6\nYscale = 1.0E-6\nZscale = 1.0E-6\nZresolution = 1.0E-9\n"
            "Compression = 0\nDataType = 7\nCheckType = 0\n*\n")
    (tmp_path / "spiky.sdf").write_text(head + "\n".join(" ".join(f"{v:.6f}" for v in row) for row in h) + "\n*\n")
    with pytest.warns(TopographyWarning):
        notes = condition(read_topography(tmp_path / "spiky.sdf"), "plane").notes
    assert len(notes) == 1 and notes[0].startswith("outliers in 'spiky.sdf': 3 points deviating")
    path = write(tmp_path, 'problem = "measured_contact"\nmetrics = ["approach"]\n[fixed]\nfile = "spiky.sdf"\n'
                           '[sweep]\nload = ["1 MPa", "2 MPa"]\n[run]\nprocesses = 1\n[report]\nplots = false\n')
    assert main(["study", str(path)]) == 0
    err, out = capsys.readouterr()[::-1]
    assert err.count(notes[0]) == 1 and f"warning: study: run load = 1 MPa: {notes[0]}" in err
    assert "  2 runs warned of what they found while running: in the report and the warnings column" in out
    assert [json.loads(r["warnings"]) for r in table(tmp_path / "results" / "study" / "results.csv")] == [list(notes)] * 2
    text = (tmp_path / "results" / "study" / "study.md").read_text()
    assert text.count(notes[0]) == 1 and f"- {notes[0]} (load = 1 MPa; load = 2 MPa)" in text
    # the warning's advice, despike = 7, is a parameter of the problem (it was refused: a user trial)
    path.write_text(path.read_text().replace('file = "spiky.sdf"', 'file = "spiky.sdf"\ndespike = 7'))
    assert main(["study", str(path)]) == 0
    assert [r["warnings"] for r in table(tmp_path / "results" / "study" / "results.csv")] == ["", ""]


def test_the_study_package_leaves_its_worker_to_runpy():
    """Importing the package imported ``multiscale.studies.worker``, which each run then executes
    as ``python -m``: every run log began with runpy's RuntimeWarning (a user trial)."""
    import subprocess
    import sys
    done = subprocess.run([sys.executable, "-c", "import sys, multiscale.studies; "
                           "print('multiscale.studies.worker' in sys.modules)"], capture_output=True, text=True)
    assert done.stdout.strip() == "False", done.stderr


def test_records_are_strict_json_and_read_non_finite_numbers_back_as_nan(tmp_path):
    """A scene's history columns of NaN were written as bare NaN, which is no JSON (jq refused the
    records); they are null now, and NaN again when read: the run fails as before."""
    from multiscale.studies.records import metric_problem, read_json, write_json
    path = tmp_path / "record.json"
    write_json(path, {"metrics": {"a": math.nan, "b": np.float32("inf"), "c": 1.5}, "wall_time": 0.25,
                      "wall_times": [0.25, math.nan], "error": None})
    strict = json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(c))
    assert strict["metrics"] == {"a": None, "b": None, "c": 1.5} and strict["wall_times"] == [0.25, None]
    back = read_json(path)
    assert math.isnan(back["metrics"]["a"]) and math.isnan(back["metrics"]["b"]) and back["metrics"]["c"] == 1.5
    assert math.isnan(back["wall_times"][1]) and back["error"] is None and back["wall_time"] == 0.25
    assert metric_problem(back["metrics"], ["c", "a"]) == 'metric "a" is nan (not finite)'


def test_runs_are_shared_out_over_mpi_ranks(tmp_path):
    """`mpiexec -n 2 multiscale study`: each rank runs its share, rank 0 writes the table."""
    import os
    import subprocess
    import sys
    path = write(tmp_path, HERTZ.replace("processes = 2", "processes = 1").replace("[12, 16, 24, 32]", "[12, 16]")
                 + "plots = false\n")
    mpiexec = Path(sys.executable).with_name("mpiexec")
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    done = subprocess.run([str(mpiexec), "-n", "2", sys.executable, "-m", "multiscale.cli", "study", str(path)],
                          capture_output=True, text=True, env=env, timeout=300, start_new_session=True)
    assert done.returncode == 0, done.stderr
    out = tmp_path / "results" / "hertz"
    assert done.stdout.count("hertz: 2 runs (0 recorded before, 2 run now, 0 failed)") == 1   # rank 0 reports all
    ranks = sorted(json.loads(p.read_text())["rank"] for p in (out / "runs").glob("*.json"))
    assert ranks == [0, 1]
    assert [r["status"] for r in table(out / "results.csv")] == ["ok"] * 2
    # a study folder that cannot be made is one error on every rank (rank 1 waited for rank 0 for ever)
    (tmp_path / "afile").write_text("")
    path.write_text(path.read_text().replace("[run]", f'[run]\nfolder = "{tmp_path / "afile" / "sub"}"'))
    done = subprocess.run([str(mpiexec), "-n", "2", sys.executable, "-m", "multiscale.cli", "study", str(path)],
                          capture_output=True, text=True, env=env, timeout=60, start_new_session=True)
    assert done.returncode == 2 and done.stderr.count("error: cannot write the study folder") == 1, done.stderr


def test_a_study_folder_in_use_is_refused(tmp_path, capsys):
    """A second study on the folder of one still running is refused, naming the holder (before: it
    ran every run again beside the first, deleting the records the first had written; adversarial)."""
    import fcntl
    path = write(tmp_path, HERTZ + "plots = false\n")
    runs = tmp_path / "results" / "hertz" / "runs"
    runs.mkdir(parents=True)
    with open(runs / ".lock", "a+") as held:          # as the first study holds it
        fcntl.flock(held, fcntl.LOCK_EX)
        held.write("4242")
        held.flush()
        assert main(["study", str(path)]) == 2
        assert (f"error: {runs.parent} is in use by another multiscale study (process 4242): let it end"
                in capsys.readouterr().err)
    assert not list(runs.glob("*.json"))
    assert main(["study", str(path)]) == 0              # released: it runs


def test_scene_metrics_reduce_over_the_rows_that_have_a_value():
    """coupling_residual is NaN at t = 0 and a partition NaN where nothing touches: their
    :max/:min/:mean were NaN, and a study marked every run failed ('metric "coupling_residual:max"
    is nan (not finite)') and --rerun-failed ran them all again (a user trial). The reductions skip
    NaN rows; a column with none is NaN (that metric alone n/a); :first, :last and :rise are the rows'."""
    from multiscale.io import History
    from multiscale.studies.scene_problem import history_metrics
    history = History()
    for t, r in enumerate([math.nan, 2e-3, 5e-4]):
        history.append(time=float(t), coupling_residual=r, partition_mean=math.nan, zones=np.ones(3))
    got = history_metrics(history)
    assert (got["coupling_residual:max"], got["coupling_residual:min"], got["coupling_residual"]) == (2e-3, 5e-4, 5e-4)
    assert got["coupling_residual:mean"] == pytest.approx(1.25e-3) and math.isnan(got["coupling_residual:rise"])
    assert math.isnan(got["partition_mean:max"]) and "zones:max" not in got


def test_a_scene_run_is_timed_by_its_own_record(tmp_path, monkeypatch):
    """A scene run's wall time is its provenance.json's, not its subprocess's: the start of Python
    and DOLFINx took 10 of 18 s, a coarser grid looked slower than the reference and the cheapest
    setting was the reference itself (a user trial). Its warnings beyond the scene's own are what it
    found (a user trial: zone pressures beyond micro.p_max stayed in the run's log), a failed run's
    too (a review: one that diverged beyond the laws' top kept only its error). Each run starts in an
    empty output folder: what a run killed by Ctrl-C left there was refused by the next one's output
    checks, and the study could not go on (a user trial)."""
    import subprocess
    from multiscale.io import History
    from multiscale.studies import scene_problem
    from multiscale.studies.base import RunFailed
    work, code, found = tmp_path / "run", [0], []

    def ran(command, **options):         # the run's output, as multiscale.studies.scene_run writes it
        found.append(sorted(p.name for p in (work / "output").glob("*")))
        history = History()
        history.append(time=0.0, interface_force=100.0, newton_iterations=4.0)
        history.write((work / "output").mkdir(parents=True, exist_ok=True) or work / "output" / "history.h5")
        (work / "output" / "provenance.json").write_text(json.dumps({"total_wall_time_s": 7.34,
                                                                     "warnings": ["the scene's", "the run's"]}))
        return subprocess.CompletedProcess(command, code[0], "", "ConvergenceError: diverged\n")
    monkeypatch.setattr(scene_problem.subprocess, "run", ran)
    run = scene_problem.SceneRun(ROOT / "demos" / "block_on_flat.toml", warnings=("the scene's",))
    outcome = scene_problem.SceneProblem().run(run, work)
    assert (outcome.wall_time, outcome.iterations, outcome.metrics["interface_force"]) == (7.34, 4, 100.0)
    assert outcome.warnings == ("the run's",)
    (work / "output" / "checkpoint.h5").write_bytes(b"killed")       # a run stopped by Ctrl-C
    code[0] = 1
    with pytest.raises(RunFailed, match=r"^scene run failed \(exit 1\): ConvergenceError: diverged$") as info:
        scene_problem.SceneProblem().run(run, work)
    assert info.value.warnings == ("the run's",) and found == [[], []]


def test_a_scene_study_without_dolfinx_is_refused_before_its_runs(tmp_path, monkeypatch):
    """Without DOLFINx (a micro-only install) a scene study's runs each started and failed on
    petsc4py (a user trial): it is refused once, before any run, saying what to install."""
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "dolfinx" else real(name, *a))
    path = scene_study(tmp_path, "block_on_flat.toml", 'metrics = ["interface_force:last"]\n[sweep]\n'
                                                       '"loading.pressure" = ["1 MPa", "2 MPa"]')
    with pytest.raises(SceneError) as info:
        load_study(path)
    assert [p for p in info.value.problems if "DOLFINx" in p] == [
        "problem = \"scene\" runs each point with multiscale run, which needs DOLFINx: install it with pip install "
        "-e '.[fem]' (every run)"]


def test_a_scene_run_says_its_error_once(capsys):
    """The study's scene subprocess says a MultiscaleError as one ``Kind: message`` line (by rank 0;
    under mpiexec each rank wrote its traceback into the run's log: a user trial) and ends with 2,
    as ``multiscale run`` does; ``failure_line`` reads it."""
    from multiscale.studies.scene_problem import failure_line
    from multiscale.studies.scene_run import main
    task = json.dumps({"scene": str(ROOT / "demos" / "block_on_flat.toml"), "overrides": {"time.end": "-1 s"}})
    assert main(task) == 2
    err = capsys.readouterr().err
    assert err == 'SceneError: time.end = "-1 s": must be > 0 s (got -1 s)\n' and "Traceback" not in err
    assert failure_line(err) == 'time.end = "-1 s": must be > 0 s (got -1 s)'


def test_squeal_scene_metrics_from_the_mode_table(tmp_path):
    """A squeal scene's study metrics, read back from modes.csv, equal those of the eigenvalues."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from multiscale.macro.eigen import ModalResult
    from multiscale.studies.scene_problem import squeal_metrics
    lam = np.array([-3.0 + 2j * np.pi * 900.0, 40.0 + 2j * np.pi * 2500.0, 0.0 + 2j * np.pi * 4000.0,
                    12.0 + 2j * np.pi * 7100.0])
    modes = ModalResult(lam, -lam**2, np.zeros((1, 4), complex), np.full(4, 1e-12), (0.0, 16e3), 0.0, 10,
                        "gnhep", 1, 1, 0.0)
    got = squeal_metrics(modes.write_csv(tmp_path / "modes.csv"))
    assert got["modes"] == 4 and got["unstable_modes"] == 2
    assert got["max_growth"] == pytest.approx(40.0, rel=1e-6)
    assert got["max_growth_frequency"] == pytest.approx(2500.0, rel=1e-9)
    assert got["lowest_unstable_frequency"] == pytest.approx(2500.0, rel=1e-9)
    assert got["min_damping_ratio"] == pytest.approx(-40.0 / abs(lam[1]), rel=1e-6)
    # none grows: no frequency to name (it gave 0 Hz and a stable mode's 900 Hz, plotted: a user trial),
    # and the run is not failed for it
    from multiscale.studies.records import metric_problem
    stable = ModalResult(lam.imag * 1j - 3.0, -lam**2, np.zeros((1, 4), complex), np.full(4, 1e-12), (0.0, 16e3),
                         0.0, 10, "gnhep", 1, 1, 0.0)
    got = squeal_metrics(stable.write_csv(tmp_path / "stable.csv"))
    assert got["unstable_modes"] == 0 and got["max_growth"] == pytest.approx(-3.0, rel=1e-6)
    assert np.isnan(got["max_growth_frequency"]) and np.isnan(got["lowest_unstable_frequency"])
    from multiscale.studies.scene_problem import SceneProblem
    undefined = SceneProblem.undefined
    assert metric_problem(got, list(got), undefined) is None
    assert metric_problem(got, ["lowest_unstable_frequency"]) == 'metric "lowest_unstable_frequency" is nan (not finite)'
    assert metric_problem({**got, "max_growth": np.inf}, ["max_growth"], undefined) == \
        'metric "max_growth" is inf (not finite)'


def test_failed_scene_run_reports_its_exception_not_the_launchers_abort():
    """A scene run that fails under mpiexec is reported by its exception line, which the other
    ranks' abort lines follow; output without one gives its last line."""
    from multiscale.studies.scene_problem import failure_line
    log = """Traceback (most recent call last):
  File "coupling.py", line 481, in step
    raise ConvergenceError(f"step {n}: ...")
multiscale.errors.ConvergenceError: step 18: the partitions did not converge in 30 passes (residual 0.000359 > 1e-05)
Abort(1) on node 1 (rank 1 in comm 0): application called MPI_Abort(MPI_COMM_WORLD, 1) - process 1

"""
    assert failure_line(log) == ("ConvergenceError: step 18: the partitions did not converge "
                                 "in 30 passes (residual 0.000359 > 1e-05)")
    refused = "multiscale.errors.InputError: geometry.max_cells = 30000: the mesh would have 96245 cells (exact)"
    assert failure_line(f"Traceback ...\n{refused}\n") == "geometry.max_cells = 30000: the mesh would have 96245 " \
        "cells (exact)"          # as `multiscale run` says it (a user trial read the Python class path)
    assert failure_line("KeyboardInterrupt\nnothing\n") == "KeyboardInterrupt"
    assert failure_line("segfault in rank 0\n  \n") == "segfault in rank 0"
    assert failure_line("") == "no output"


def test_metric_units_of_every_problem():
    """Every registered problem's metric has a unit in brackets (tables and axes show it); a scene
    study's metric takes its history column's unit, or the squeal metric's."""
    from multiscale.studies.problems import PROBLEMS
    for name, problem in PROBLEMS.items():
        assert all(problem.metric_unit(m) for m in problem.metrics), name
    scene = PROBLEMS["scene"]
    from multiscale.studies.scene_problem import SQUEAL_METRICS
    assert all(scene.metric_unit(m) for m in SQUEAL_METRICS)
    assert [scene.metric_unit(m) for m in ("max_temperature_pin:rise", "wear_volume", "max_growth",
                                           "partition_mean:max")] == ["K", "m^3", "1/s", "-"]


def test_a_scene_study_report_labels_its_metrics_with_units(tmp_path):
    """The plots and tables of a scene study (no reference: value panels and the wall-time panel)
    carry each history column's unit; the wall-time panel has no metric (it crashed on it, the
    units' first version: found by `make report`)."""
    from multiscale.studies.reporting import report
    from multiscale.studies.results import Row
    study = load_study(scene_study(tmp_path, "block_on_flat.toml", """
metrics = ["max_pressure:max", "interface_force"]
[sweep]
loading.pressure = ["1 MPa", "2 MPa"]
"""))
    rows = [Row(r, {"status": "ok", "metrics": {"max_pressure:max": 1e6 * (k + 1), "interface_force": 100.0 * (k + 1)},
                    "wall_time": 1.0 + k, "iterations": 3}) for k, r in enumerate(study.runs)]
    text = report(study, rows).read_text()
    assert "| max_pressure:max [Pa] | interface_force [N] |" in text
    assert any(p.suffix == ".png" for p in study.report_folder.iterdir())


def test_a_sigterm_while_a_worker_starts_ends_that_worker_too(tmp_path, monkeypatch):
    """SIGTERM between a worker's start and its registration (the driver's poll found it running
    and was terminated at once: a 2-core CI machine under load) still kills it before the driver
    ends. Before, the SystemExit left the worker out of the running set: it ran on until its
    watchdog noticed the driver gone (test_a_terminated_study_ends_its_workers failed in CI)."""
    import os
    import signal
    import subprocess
    import sys
    from multiscale.studies import running
    started = []

    def spawn(*args):           # a worker that would run for a minute, then the signal, as it starts
        started.append(subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
                                        start_new_session=True))
        os.kill(os.getpid(), signal.SIGTERM)
        return started[-1]
    monkeypatch.setattr(running, "_spawn", spawn)
    study = load_study(write(tmp_path, 'name = "term"\nproblem = "wear_steps"\nmetrics = ["area_fraction"]\n'
                                       '[fixed]\nn = 64\n[sweep]\nsteps = [1, 2]\n'))
    handler = signal.getsignal(signal.SIGTERM)
    try:
        with pytest.raises(SystemExit) as exc:
            running.execute(study, progress=False)
        assert exc.value.code == 128 + signal.SIGTERM
        assert len(started) == 1 and started[0].returncode == -signal.SIGKILL     # killed and waited for
    finally:
        for proc in started:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    assert signal.getsignal(signal.SIGTERM) is handler          # the caller's handler back


def test_a_terminated_study_ends_its_workers(tmp_path):
    """SIGTERM to `multiscale study` (a batch time limit, `timeout`) kills the running workers and
    exits 143; before, the driver died at once and its workers, each in a session of its own, ran on
    orphaned (adversarial test)."""
    proc, workers = _slow_study(tmp_path)
    _terminated(proc, workers)


def test_a_study_under_nohup_outlives_its_terminal(tmp_path):
    """A study started with SIGHUP ignored (`nohup multiscale study ... &`, then the terminal
    closed) runs on, workers and all; SIGTERM still ends it and them. Before, the driver's SIGTERM
    and SIGHUP handler replaced nohup's SIG_IGN: the closed terminal killed the workers and ended
    the study with 129."""
    import signal
    proc, workers = _slow_study(tmp_path, preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    try:
        proc.send_signal(signal.SIGHUP)
        time.sleep(1.0)
        assert proc.poll() is None and all(_cmdline(Path(f"/proc/{pid}")) for pid in workers)
    finally:
        _terminated(proc, workers)


def test_a_study_killed_by_sigkill_ends_its_workers(tmp_path):
    """SIGKILL to `multiscale study` (`kill -9`, the OOM killer, a scheduler's hard limit) cannot be
    caught; its workers read the end of the driver's lifeline pipe and kill their process groups:
    both gone within 10 s (measured 0.13 s during their runs, 0.5-0.6 s while they still load their
    modules). Before, they ran on orphaned (here: 100000 wear steps each), a known problem of the
    thirty-first session."""
    import signal
    proc, workers = _slow_study(tmp_path)
    try:
        proc.send_signal(signal.SIGKILL)
        assert proc.wait(timeout=10) == -signal.SIGKILL
        assert _gone(workers, within=10.0) == []
    finally:
        _end(proc, workers)


def test_a_worker_whose_driver_is_gone_ends_its_process_group(tmp_path):
    """The watchdog of a worker (`worker.watch_driver`) kills the process group it leads, not only
    itself: what it started there, as a scene run's `mpiexec -n 2`, ends with it (hydra's proxy ends
    the ranks, in sessions of their own, when `mpiexec` goes). Here a stand-in worker, in a session
    of its own as `running._spawn` starts one, watches a pipe and runs `mpiexec -n 2 sleep`; the
    pipe's write end closed (the driver's end), the worker and both ranks are gone within 10 s."""
    import os
    import signal
    import subprocess
    import sys
    mpiexec = Path(sys.executable).with_name("mpiexec")
    if not mpiexec.exists():
        pytest.skip("no mpiexec beside the interpreter")
    mark = f"{time.time() % 1000:.6f}"                         # the ranks' `sleep 9xx.xxxxxx`, found in /proc
    read, write = os.pipe()
    code = ("import subprocess, sys, time\nfrom multiscale.studies.worker import watch_driver\n"
            f"watch_driver({read})\nsubprocess.Popen([{str(mpiexec)!r}, '-n', '2', 'sleep', '9{mark}'])\n"
            "time.sleep(60)\n")
    worker = subprocess.Popen([sys.executable, "-c", code], pass_fds=(read,), start_new_session=True)
    os.close(read)
    ranks = []
    try:
        for _ in range(300):
            time.sleep(0.05)
            ranks = [int(p.name) for p in Path("/proc").iterdir() if p.name.isdigit()
                     and _cmdline(p) == b"sleep\x009" + mark.encode() + b"\x00"]
            if len(ranks) == 2:
                break
        assert len(ranks) == 2 and worker.poll() is None
        os.close(write)                                         # the driver is gone
        write = None
        assert worker.wait(timeout=10) == -signal.SIGKILL
        assert _gone(ranks, within=10.0) == []
    finally:
        if write is not None:
            os.close(write)
        _end(worker, ranks)


def test_workers_holding_the_gil_end_with_their_driver(tmp_path):
    """The end of the driver reaches a worker busy in a call that holds the GIL (numba compiling its
    kernels for seconds under load: a watchdog thread waited for them, likely why the SIGKILL test
    failed once at load 4.5). Two stand-in workers on one shared pipe, as `running._spawn` starts them, each
    watch it and then hold the GIL in a regular expression that backtracks for minutes; the pipe's
    write end closed, both are SIGKILLed within 10 s. A third, started after the driver's end, ends
    at once."""
    import os
    import signal
    import subprocess
    import sys
    read, write = os.pipe()
    code = (f"import re, sys\nfrom multiscale.studies.worker import watch_driver\nwatch_driver({read})\n"
            "print('watching', flush=True)\nre.match(r'(a+)+$', 'a' * 40 + 'b')\n")
    start = lambda: subprocess.Popen([sys.executable, "-c", code], pass_fds=(read,), start_new_session=True,
                                     stdout=subprocess.PIPE, text=True)
    workers = [start(), start()]
    try:
        assert [w.stdout.readline() for w in workers] == ["watching\n"] * 2
        os.close(write)                                         # the driver is gone
        write = None
        assert [w.wait(timeout=10) for w in workers] == [-signal.SIGKILL] * 2
        workers.append(start())
        assert workers[-1].wait(timeout=30) == -signal.SIGKILL
    finally:
        os.close(read)
        if write is not None:
            os.close(write)
        for w in workers:
            w.kill()
            w.wait()
            w.stdout.close()


def _gone(pids, within: float) -> list:
    """The processes of ``pids`` still running after ``within`` seconds at most (polled)."""
    deadline = time.monotonic() + within
    while True:
        alive = [pid for pid in pids if _cmdline(Path(f"/proc/{pid}"))]
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.05)


def _terminated(proc, workers):
    """SIGTERM ends the study ``proc`` with 143 and its ``workers`` with it (both killed in any case)."""
    import signal
    import subprocess
    try:
        proc.send_signal(signal.SIGTERM)
        try:
            code = proc.wait(timeout=30)
        except subprocess.TimeoutExpired:        # once in a CI run at d7c81dd, not seen since: say where it hung
            raise AssertionError(f"the driver did not end within 30 s of SIGTERM: {_states([proc.pid, *workers])}")
        assert code == 128 + signal.SIGTERM
        time.sleep(0.5)
        assert [pid for pid in workers if _cmdline(Path(f"/proc/{pid}"))] == []
    finally:
        _end(proc, workers)


def _states(pids) -> dict:
    """Each process's state, kernel wait channel and signal masks (/proc), to say where one hung."""
    out = {}
    for pid in pids:
        try:
            status = Path(f"/proc/{pid}/status").read_text().splitlines()
            wchan = Path(f"/proc/{pid}/wchan").read_text()
        except OSError:
            out[pid] = "gone"
            continue
        out[pid] = [line for line in status if line.startswith(("State", "SigPnd", "ShdPnd", "SigBlk", "SigIgn",
                                                                 "SigCgt", "Threads"))] + [f"wchan {wchan}"]
    return out


def _slow_study(tmp_path, **popen):
    """`multiscale study` of two long wear_steps runs in a process of its own, and its two workers'
    pids (from /proc) once both run."""
    import subprocess
    import sys
    path = write(tmp_path, 'name = "slow"\nproblem = "wear_steps"\nmetrics = ["area_fraction"]\n'
                 '[fixed]\nn = 64\n[sweep]\nsteps = [100000, 100001]\n[run]\nprocesses = 2\n')
    proc = subprocess.Popen([Path(sys.executable).with_name("multiscale"), "study", str(path)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **popen)
    workers = []
    for _ in range(300):
        time.sleep(0.05)
        workers = [int(p.name) for p in Path("/proc").iterdir() if p.name.isdigit()
                   and b"multiscale.studies.worker" in _cmdline(p) and str(path.parent).encode() in _cmdline(p)]
        if len(workers) == 2:
            break
    if len(workers) != 2:
        _end(proc, workers)
    assert len(workers) == 2
    return proc, workers


def _end(proc, workers) -> None:
    """Kill what a failed test left running: the driver, then its workers (orphans of the old code)."""
    import os
    import signal
    if proc.poll() is None:
        proc.kill()
        proc.wait()
    for pid in workers:
        if _cmdline(Path(f"/proc/{pid}")):
            os.kill(pid, signal.SIGKILL)


def _cmdline(proc: Path) -> bytes:
    try:
        return (proc / "cmdline").read_bytes()
    except OSError:
        return b""


def test_records_of_another_shape_are_run_again(hertz_study, tmp_path, capsys):
    """Run records that are valid JSON of another shape (a list, a metric "x", a wall time "x"):
    the study ended in an AttributeError, TypeError or ValueError traceback and wrote no table (a
    trial of odd files). A list, a wall time of text or warnings that are no list of texts (a review)
    are taken as not done, like a torn file, and
    runs again; a metric that is no number fails that run, saying so (--rerun-failed reruns it)."""
    import shutil

    from multiscale.studies.expand import load_study
    path, out = hertz_study
    runs = tmp_path / "runs"
    shutil.copytree(out / "runs", runs)
    other = write(tmp_path, HERTZ.replace("[run]", f'[run]\nfolder = "{tmp_path}"') + "plots = false\n")
    study = load_study(other)
    bad = [lambda r: [1, 2, 3], lambda r: {**r, "metrics": {k: "x" for k in r["metrics"]}},
           lambda r: {**r, "wall_time": "x"}, lambda r: {**r, "warnings": None}]       # (a review: warnings null)
    for run, spoil in zip(study.runs, bad):
        p = runs / f"{run.key}.json"
        p.write_text(json.dumps(spoil(json.loads(p.read_text()))))
    capsys.readouterr()
    assert main(["study", str(other)]) == 1
    assert "1 recorded before, 3 run now, 1 failed" in capsys.readouterr().out
    rows = table(tmp_path / "results.csv")
    assert [r["status"] for r in rows] == ["ok", "failed", "ok", "ok"]
    assert rows[1]["message"] == 'metric "contact_radius" is \'x\' (not a number)'


def test_a_study_given_for_a_scene_and_a_scene_for_a_study_name_the_right_command(tmp_path, capsys):
    """`check` of a study file and `study` of a scene file answered with a "did you mean" for each of
    its keys (a user trial): now one line naming the command the file is for."""
    path = write(tmp_path, HERTZ)
    for command in ("check", "run"):
        assert main([command, str(path)]) == 2
        assert capsys.readouterr().err.startswith("error: study.toml: a study file (problem = ..., [sweep]), not a "
                                                  "scene: give it to `multiscale study` (Python: "
                                                  "multiscale.studies.driver.run_studies)\n")
    assert main(["study", str(ROOT / "demos" / "block_on_flat.toml")]) == 2
    assert capsys.readouterr().err == ("error: block_on_flat.toml: a scene file (effects = [...], [geometry]), not a "
                                       "study: give it to `multiscale check` or `multiscale run`\n")


def test_warnings_that_differ_in_their_numbers_are_one_kind(tmp_path, capsys):
    """The zone-pressure warning of each run of a sweep has its own number: a 30-run sweep said it
    30 times (a review). One kind, said with its first run; the report lists the runs of each kind."""
    from multiscale.studies.formatting import warning_kind
    from multiscale.studies.reporting import report
    assert warning_kind("reached 4.3 times p_max = 2e+05 Pa, -1.5e-3 and .5") == "reached # times p_max = # Pa, # and #"
    assert warning_kind("outliers in 'scan_01.sdf' of pad2") != warning_kind("outliers in 'scan_02.sdf' of pad2") \
        != warning_kind("outliers in 'scan_02.sdf' of pad1")       # names keep their digits (a review)
    study = load_study(write(tmp_path, HERTZ + "plots = false\n"))
    said = ["the zone pressures reached {} times micro.p_max", "outliers in 'a.x3p'"]
    rows = [Row(run, {"status": "ok", "wall_time": 1.0, "metrics": {m: 1.0 for m in study.metrics},
                      "warnings": [said[0].format(k + 1.5)] + [said[1]] * (k == 2)})
            for k, run in enumerate(study.runs)]
    text = report(study, rows).read_text()
    assert ("- the zone pressures reached 1.5 times micro.p_max (grid = 12; grid = 16; grid = 24 and 1 more) (the "
            "numbers of the first; each run's in results.csv)") in text
    assert "- outliers in 'a.x3p' (grid = 24)\n" in text and text.count("zone pressures") == 1


def test_a_study_stopped_before_its_reference_run_says_so(tmp_path, made):
    """A study stopped before its reference run: the rows said "reference run failed", the figure
    "error 0 in every run: equal to the reference" and the cost table "none of the runs" at every
    error (a user trial). Now the reference run is "not run", and there is no error to judge."""
    from multiscale.studies.records import record_path, write_json
    from multiscale.studies.reporting import report
    from multiscale.studies.results import collect
    study = load_study(write(tmp_path, HERTZ.replace('kind = "analytic"', 'kind = "run"\nrun = {grid = 32}')))
    (study.folder / "runs").mkdir(parents=True)
    for run in study.runs[:2]:                               # grids 12 and 16 ended, 24 and 32 did not
        write_json(record_path(study, run), {"key": run.key, "status": "ok", "wall_time": 1.0, "label": run.label,
                                             "metrics": {m: 1.0 for m in study.metrics}})
    rows = collect(study)
    assert [(r.record["status"], r.note) for r in rows] == [("ok", "reference run not run")] * 2 + [("missing", "")] * 2
    text = report(study, rows).read_text()
    assert "## What accuracy costs\n\nNo run has an error to judge: reference run not run.\n" in text
    assert "none of the runs" not in text and "**2 not run or cut off: the study was stopped**" in text
    texts = [t.get_text() for fig, axes in made for ax in axes.ravel() for t in ax.texts]
    assert "no error: the reference\nhas no value of it" in texts and not any("equal to the reference" in t for t in texts)


def test_files_swept_without_being_cases_are_warned_of(tmp_path):
    """Measured files swept beside a tolerance, without [report] cases: the cost table timed a
    setting on one file against another file's reference run (a user trial)."""
    import shutil
    for name in ("a.top", "b.top"):
        shutil.copy(ROOT / "tests" / "data" / "top-1.top", tmp_path / name)
    text = ('problem = "measured_contact"\nmetrics = ["approach"]\n[[sweep]]\nfile = ["a.top", "b.top"]\n[[sweep]]\n'
            'tol = [1e-3, 1e-6]\n[reference]\nkind = "run"\nrun = {tol = 1e-6}\n')
    assert load_study(write(tmp_path, text)).warnings == (
        'file is swept but not a [report] case: the cheapest settings compare runs on different files; give cases = '
        '["file"] to judge each file by its own',)
    assert load_study(write(tmp_path, text + '[report]\ncases = ["file"]\n')).warnings == ()
    assert load_study(write(tmp_path, text + '[report]\naverage_over = ["file"]\n')).warnings == ()  # (a review)


def test_the_figure_against_a_knob_wraps_its_panels_and_draws_power_laws_straight(tmp_path, made):
    """Three metrics and the wall time against a load swept over two decades: 2 rows of 3 panels (a
    study of 9 metrics drew one row 4400 px wide); a metric proportional to the load on log-log axes (on a log x axis and a
    linear y one, a linear wear looked exponential: a tribologist's trial), a constant one linear."""
    from multiscale.plots import studies as figures
    text = (HERTZ.replace('load = "10 N"', "grid = 16").replace("grid = [12, 16, 24, 32]", 'load = ["1 N", "10 N", "100 N"]')
            .replace('[reference]\nkind = "analytic"\n', "").replace('errors = ["1 %", "5 %"]', ""))
    study = load_study(write(tmp_path, text))
    rows = [Row(run, {"status": "ok", "wall_time": 1.0 + k, "metrics": {
        "contact_radius": 1.0, "max_pressure": float(run.label["load"]), "approach": 2.0}})
        for k, run in enumerate(study.runs)]
    figures.plot(study, rows, tmp_path)
    fig, axes = next((f, a) for f, a in made if a.size > 1)
    assert axes.shape == (2, 3) and [ax.get_visible() for ax in axes[1]] == [True, False, False]
    assert axes[0][1].get_title() == "max_pressure" and axes[0][1].get_yscale() == "log"
    assert axes[0][0].get_yscale() == "linear" and axes[0][1].get_xscale() == "log"


def test_a_zip_group_holding_a_table_is_not_interpolated():
    """``results.crossings`` along a zip group: the first knob with its partners alongside where all
    are numbers; a group holding a table (a trial's two pad formulations: E and a fade table
    zipped) has no value between its runs, so no crossing is offered."""
    from types import SimpleNamespace as NS
    from multiscale.studies.results import crossings

    def row(label, volume):
        return NS(ok=True, run=NS(label=label, shown={k: str(v) for k, v in label.items()}),
                  record={"metrics": {"wear_volume": volume}}, reference={"wear_volume": 2.0})
    study = NS(reference=NS(kind="file"), axes=(("E", "table"),), averaged=(), knobs=("E", "table"),
               judged=("wear_volume",))
    numbers = [row({"E": 1.0, "table": 10.0}, 1.0), row({"E": 4.0, "table": 20.0}, 4.0)]
    (c,) = crossings(study, numbers)
    assert (c.knob, c.partners, c.log) == ("E", ("table",), True) and c.value == pytest.approx(2.0, rel=1e-12)
    tables = [row({"E": 1.0, "table": ((293.15, 0.4),)}, 1.0), row({"E": 4.0, "table": ((293.15, 0.3),)}, 4.0)]
    assert crossings(study, tables) == []

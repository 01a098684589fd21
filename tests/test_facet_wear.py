"""Archard wear of the interface facets in perfect contact (``multiscale.macro.facet_wear``; effect
"wear" without "roughness"): the volumes Archard's law gives for the work and the load done, the
worn-in pressure of a pin on a rotating disc (uniform wear: p proportional to 1/r), a resumed run
equal to a straight one, and the scene's checks."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from multiscale.errors import InputError, SceneError  # noqa: E402
from multiscale.io import History, solver_statistic  # noqa: E402
from multiscale.outputs import plan  # noqa: E402
from multiscale.scene import loads  # noqa: E402
from multiscale.workflows.transient import run  # noqa: E402

from test_macro_run import pin_on_disc  # noqa: E402

WEAR = ("contact", "friction", "wear")


def scene(folder, steps: int = 3, end: str = "9 s", wear: str = 'k_w = "1e-14 1/Pa"', **more):
    """The coarse test pin-on-disc (200 N, 200 rpm, mu 0.4), wearing, without heat."""
    text = pin_on_disc(folder, effects=WEAR).replace("partition = ", "# partition = ") + f"\n[wear]\n{wear}\n"
    return loads(text, overrides={"time.steps": steps, "time.end": end, **more})


def test_the_facets_wear_archards_volume_of_the_work_and_of_the_load(tmp_path):
    """One increment an update (c K below ``STABLE``): the pin loses k_w times the frictional work
    (k_w mu p ds dA summed over its facets) to round-off; a specific rate k per normal load k times
    the work over mu (mu = 0.4 throughout); a disc whose material gives k_w loses its k_w times the
    same work, spread round its track. The work is the friction moment's: mu F r_eff omega t within
    its variation over the run (0.2 %)."""
    h = run(scene(tmp_path / "w", **{"materials.disc.k_w": "2e-14 1/Pa"}), verbose=False).history
    assert list(h["wear_substeps"]) == [0, 1, 1, 1] and h["wear_implicit_updates"][-1] == 0   # c K_n = 0.9 / 3
    work = h["frictional_work"]
    np.testing.assert_allclose(h["wear_volume"], 1e-14 * work, rtol=1e-12, atol=0)
    np.testing.assert_allclose(h["counter_wear_volume"], 2e-14 * work, rtol=1e-12, atol=0)
    moment = h["friction_moment"]
    assert work[-1] == pytest.approx(np.mean(moment) * 200 * np.pi / 30 * 9.0, rel=2e-3)
    assert h["wear_max_depth"][-1] > h["wear_volume"][-1] / 4e-4               # deeper than its mean somewhere
    per_load = run(scene(tmp_path / "k", wear='specific_rate = "4e-15 1/Pa"'), verbose=False).history
    np.testing.assert_allclose(per_load["wear_volume"], 4e-15 * per_load["frictional_work"] / 0.4, rtol=1e-12)


def test_an_implicit_update_under_fade_wears_at_the_sliding_s_friction(tmp_path):
    """With a fade table (mu 0.4 at 20 degC to 0.1 at 23 degC) an implicit update's depth per pressure
    takes the mu of the sliding it wears for, the exposure's work over its load: k_w x work within 1 %
    whether the update falls at the release (the pin hot, mu 0.1) or after a dwell. With the mu at
    the update it wore 45 % and 10 % short (a review)."""
    from test_macro_run import THERMAL
    text = pin_on_disc(tmp_path / "f", effects=THERMAL + ("wear",)) + '\n[wear]\nk_w = "3e-13 1/Pa"\n'
    for every in (1, 3):
        h = run(loads(text, overrides={"time.steps": 6, "time.end": "18 s", "wear.update_every": every,
                                       "loading.load_profile": [["0 s", 1.0], ["2.9 s", 1.0], ["2.91 s", 0.0],
                                                                ["14.99 s", 0.0], ["15 s", 1.0]],
                                       "loading.friction_temperature": [["20 degC", 0.4], ["23 degC", 0.1]]}),
                resume=False, overwrite=True, verbose=False).history
        assert h["wear_implicit_updates"][-1] == 2
        assert h["wear_volume"][-1] == pytest.approx(3e-13 * h["frictional_work"][-1], rel=1e-2), every


def test_a_worn_in_pin_carries_its_load_as_one_over_the_radius(tmp_path):
    """Archard wear at k_w mu p omega r settles where every point wears alike (the worn face recedes
    as a whole): p r uniform, p = C / r. The coarse pin (20 mm at 80-100 mm, 2.5 mm facets), k_w =
    3e-13 /Pa, 120 s at 200 rpm in 40 steps (17 um worn): its mean pressure in five bands of radius
    follows 1/r within 2 % (measured 0.43 %; 3.9 % without the updates' corrections; at the start
    0.84 to 0.43 MPa inside out, against 1/r's 0.55 to 0.46), the peak of the fresh pin's edge worn
    from 2.5 to 0.61 MPa. Every update is linearly implicit (c K_n about 27, ``STABLE`` 0.5: the
    explicit update, taken with an elastic estimate of the stiffness, failed in a stiffer case; a
    review): the volume is k_w times the work within 0.2 % (its pressure is the step's end's, the
    work's the step's)."""
    import meshio
    h = run(scene(tmp_path / "in", steps=40, end="120 s", wear='k_w = "3e-13 1/Pa"',
                  **{"output.every": 40, "output.fields": ["contact_pressure", "wear_depth"]}), verbose=False).history
    assert h["max_pressure"][0] > 2e6 and h["max_pressure"][-1] < 0.65e6
    assert h["wear_volume"][-1] == pytest.approx(3e-13 * h["frictional_work"][-1], rel=2e-3)
    assert h["wear_implicit_updates"][-1] == 40 and list(h["wear_substeps"]) == [0] + [1] * 40
    series = meshio.xdmf.TimeSeriesReader(str(tmp_path / "in" / "interface.xdmf"))
    points, cells = series.read_points_cells()
    middle = points[cells[0].data].mean(axis=1)
    radius, area = np.hypot(middle[:, 0], middle[:, 1]), 0.5 * np.linalg.norm(np.cross(
        *(points[cells[0].data[:, k]] - points[cells[0].data[:, 0]] for k in (1, 2))), axis=1)
    p = series.read_data(series.num_steps - 1)[2]["contact pressure [Pa]"][0]
    edges = np.linspace(0.08, 0.1, 6)
    band = np.digitize(radius, edges) - 1
    mean = np.array([p[band == b] @ area[band == b] / area[band == b].sum() for b in range(5)])
    r = 0.5 * (edges[1:] + edges[:-1])
    np.testing.assert_allclose(mean * r / np.mean(mean * r), 1.0, atol=0.02)


def test_a_stiff_penalty_a_release_and_a_pad_without_its_rate(tmp_path):
    """K_n = 1e14 Pa/m with k_w = 1e-13 /Pa (c K_n about 9: the explicit update, with an elastic
    estimate of the stiffness, failed its contact Newton there; a review) runs linearly implicit,
    worn volume k_w x work within 0.2 %. An update falling in a release (update_every = 3 over a
    release from 4.5 to 8 s) wears from the exposure, k_w x work to round-off (it lost 89 % of it,
    re-reading the pressure of the opened gaps; a review); one that would be implicit, released
    with a loaded step to come, is solved at the load it was released from, and the run re-engages
    from that worn state (worn explicitly, the re-engaging Newton failed; waiting for the next loaded
    step left the work and the wear, and a wear limit, a dwell late: a user trial). A
    load ramp from 0.1 to 1 in the first step wears k_w x work within 0.5 % an update (10 times
    it: the implicit depth per pressure took the ramp's sliding at the full load). A worn body whose material gives no k_w
    beside one that does is refused unless [wear] gives a rate (the thesis' sintered table wore it)."""
    stiff = run(scene(tmp_path / "s", wear='k_w = "1e-13 1/Pa"', **{"interface.penalty": "1e14 Pa/m"}),
                verbose=False).history
    assert stiff["wear_implicit_updates"][-1] == 3
    assert stiff["wear_volume"][-1] == pytest.approx(1e-13 * stiff["frictional_work"][-1], rel=2e-3)
    cycle = {"wear.update_every": 3, "time.steps": 3, "time.end": "9 s",
             "loading.load_profile": [["0 s", 1.0], ["4.5 s", 1.0], ["4.51 s", 0.0], ["9 s", 0.0]]}
    released = run(scene(tmp_path / "r", wear='k_w = "3e-13 1/Pa"', **cycle), verbose=False).history
    assert released["interface_force"][-1] == 0.0 and released["frictional_work"][-1] > 0
    assert released["wear_volume"][-1] == pytest.approx(3e-13 * released["frictional_work"][-1], rel=1e-12)
    again = {"time.steps": 3, "time.end": "9 s", "loading.load_profile": [   # released at the update, loaded again
        ["0 s", 1.0], ["2.9 s", 1.0], ["2.91 s", 0.0], ["5.99 s", 0.0], ["6 s", 1.0]]}
    back = run(scene(tmp_path / "b", wear='k_w = "3e-13 1/Pa"', **again), verbose=False).history   # (Newton failed)
    assert list(back["wear_substeps"]) == [0, 1, 1, 1] and list(back["wear_implicit_updates"]) == [0, 1, 1, 2]
    assert back["interface_force"][1] == 0.0 and back["wear_volume"][1] == pytest.approx(   # booked in the release
        3e-13 * back["frictional_work"][1], rel=5e-3)
    assert back["wear_volume"][-1] == pytest.approx(3e-13 * back["frictional_work"][-1], rel=5e-3)
    ramp = run(scene(tmp_path / "p", wear='k_w = "1e-13 1/Pa"', **{"loading.load_profile": [["0 s", 0.1], ["3 s", 1.0]],
                                                                  "interface.penalty": "1e14 Pa/m"}), verbose=False).history
    np.testing.assert_allclose(np.diff(ramp["wear_volume"]) / np.diff(ramp["frictional_work"]), 1e-13, rtol=5e-3)
    from pathlib import Path
    from multiscale.scene import load
    from multiscale.workflows.model import build_model, facet_wear
    pads = load(Path(__file__).parents[1] / "demos" / "brake_squeal.toml", overrides={
        "effects": list(WEAR), "time.end": "1 s", "loading.rotation_speed": "100 rpm",
        "geometry.part_materials": {"outer_pad": "pad2"},
        "materials.pad2": {"E": "5 GPa", "nu": 0.25, "rho": "2500 kg/m^3", "k_w": "1e-14 1/Pa"}})
    with pytest.raises(InputError, match=r"wear: a rate for interface\(s\) inner_pad, whose worn material gives no k_w"):
        facet_wear(pads, build_model(pads))


def test_a_resumed_wearing_run_is_the_straight_one(tmp_path):
    """Stopped after step 2 of 4 (depths, volumes and the exposure since the last update in its
    checkpoint: wear.update_every = 3) and resumed: the history of the straight run to the solvers'
    tolerance."""
    more = {"wear.update_every": 3, "time.steps": 4, "time.end": "12 s"}
    straight = run(scene(tmp_path / "a", **more), verbose=False).history
    stopped = scene(tmp_path / "b", **more)
    run(stopped, verbose=False, stop_after=2)
    resumed = History.read(run(stopped, resume=True, verbose=False).history_file)
    assert list(straight["wear_volume"][1:3]) == [0.0, 0.0] and straight["wear_volume"][-1] > 0
    for key in (k for k in straight.columns if not solver_statistic(k)):
        np.testing.assert_allclose(resumed[key], straight[key], rtol=1e-9, atol=1e-15, err_msg=key)


def test_a_table_reads_the_temperatures_of_the_whole_interval(tmp_path):
    """k_w(T) over the heating pin's faces (the face 20 -> 25 degC in 9 s), linear (1e-18 to 1e-16
    /Pa from 20 to 120 degC) and kinked (1e-18 /Pa to 21.5 degC, 1e-16 from 22 degC): one update
    after three steps wears what three updates wear, within 2e-5 (measured 1.3e-6 and 6.7e-6: the
    wear's own feedback on the pressure), as the exposure rates each substep at its own face
    temperatures. Read at the update, the one update wore 14 % more on the linear table (the whole
    interval at its end's temperature); read at the interval's work-weighted mean temperature, 25 %
    more on the kinked one (a review)."""
    from test_macro_run import pin_on_disc
    for n, table in enumerate(('k_w_table = [["20 degC", "1e-18 1/Pa"], ["120 degC", "1e-16 1/Pa"]]',
                               'k_w_table = [["20 degC", "1e-18 1/Pa"], ["21.5 degC", "1e-18 1/Pa"], '
                               '["22 degC", "1e-16 1/Pa"]]')):
        volumes = []
        for every in (1, 3):
            text = pin_on_disc(tmp_path / f"u{n}{every}", effects=("contact", "friction", "thermal", "heat_partition",
                                                                   "wear"))
            h = run(loads(text + f"\n[wear]\n{table}\nupdate_every = {every}\n",
                          overrides={"time.steps": 3, "time.end": "9 s"}), verbose=False).history
            assert h["max_temperature_pin"][-1] > 298.0
            volumes.append(h["wear_volume"][-1])
        assert volumes[1] == pytest.approx(volumes[0], rel=2e-5)


def test_a_pin_worn_through_ends_the_run_with_its_results(tmp_path):
    """k_w = 1e-8 /Pa wears the coarse pin (15 mm long behind every facet) 11.3 mm deep at its
    deepest facet in the first 3 s step and 22.6 mm in the second: the run ends after step 2 of 4,
    said, with that step's history row, fields and checkpoint (--resume steps no further and keeps
    that step's fields; its provenance says how it ended);
    ``wear_remaining_min`` is the length less the deepest wear. With ``wear.limit`` = 5 mm it ends
    after step 1 (3.7 mm left), and resumed without the limit (not part of the checkpoint's
    fingerprint) it goes on to the straight run's end; each part's record keeps its limit."""
    s = scene(tmp_path / "t", steps=4, end="12 s", wear='k_w = "1e-8 1/Pa"', **{"output.every": 4})
    r = run(s, verbose=False)
    h = r.history
    assert list(h["time"]) == [0.0, 3.0, 6.0]
    np.testing.assert_allclose(h["wear_remaining_min"], 15e-3 - h["wear_max_depth"], rtol=1e-12)
    assert h["wear_remaining_min"][1] > 0 > h["wear_remaining_min"][2]
    (note,) = [w for w in r.warnings if "worn through" in w]
    assert note.startswith("pin worn through: 22.58 mm worn of its 15 mm at (") and "the run ended after step 2 of 4" in note
    import meshio
    assert meshio.xdmf.TimeSeriesReader(str(tmp_path / "t" / "interface.xdmf")).num_steps == 2    # t = 0 and the end
    again = run(s, resume=True, verbose=False)
    assert list(again.history["time"]) == [0.0, 3.0, 6.0] and again.ended == "ended by wear after step 2 of 4"
    assert meshio.xdmf.TimeSeriesReader(str(tmp_path / "t" / "interface.xdmf")).num_steps == 2    # kept (a review)
    import json
    from multiscale.workflows import run as run_scene
    kept = scene(tmp_path / "k", steps=4, end="12 s", wear='k_w = "1e-8 1/Pa"\nlimit = "5 mm"', **{"output.every": 4})
    r = run_scene(kept, verbose=False)
    assert list(r.history["time"]) == [0.0, 3.0]
    assert any(w.startswith("pin at its wear limit: 11.29 mm worn of its 15 mm at (") for w in r.warnings)
    assert json.loads((tmp_path / "k" / "provenance.json").read_text())["status"] == "ended by wear after step 1 of 4"
    on = run(scene(tmp_path / "k", steps=4, end="12 s", wear='k_w = "1e-8 1/Pa"', **{"output.every": 4}),
             resume=True, verbose=False).history
    np.testing.assert_allclose(on["wear_remaining_min"], h["wear_remaining_min"], rtol=1e-6)   # (solver tolerances)
    parts = json.loads((tmp_path / "k" / "provenance.json").read_text())["parts"]     # each part's own limit
    assert [p["free"]["wear.limit"] for p in parts] == [0.005, 0.0]


def test_the_scene_takes_wear_in_perfect_contact(tmp_path):
    """Wear needs no roughness: the run marches, checkpoints and writes the worn depths of both bodies;
    a table reads the faces' macro temperatures (check says so; its end is warned of at the worn
    body's hottest); it needs friction."""
    s = scene(tmp_path / "s")
    p = plan(s)
    assert "checkpoint.h5" in p.files and {"wear_depth", "counter_wear_depth"} <= set(p.interface_fields)
    assert len(p.times) == 4
    from multiscale.scene_summary import summary
    from multiscale.workflows import run_warnings
    table = scene(tmp_path / "t", wear='k_w_table = [["20 degC", "1e-14 1/Pa"], ["22 degC", "2e-14 1/Pa"]]')
    assert "a table's T each face's macro temperature" in next(x for x in summary(table) if x.startswith("    wear"))
    h = History()
    h.append(time=0.0, max_temperature_pin=298.2)           # a review: the pin at 25 degC, a table to 22, unsaid
    assert run_warnings(table, h) == ["wear.k_w_table: the worn body's largest macro temperature, 25.05 degC, is "
                                      "above its last point 22 degC: the facets wear with k_w held at 2e-14 1/Pa there"]
    with pytest.raises(SceneError, match='effects: "wear" needs effect "friction" too'):
        loads(pin_on_disc(tmp_path / "x", effects=("contact", "wear")))


def test_a_failed_update_is_undone(tmp_path, monkeypatch):
    """A contact solve failing inside an implicit update (its third) raises, with the worn depths,
    the facets' gaps, the exposure and the displacements as they were before it: a caller that goes
    on (a smaller step, other settings) starts from a consistent state: the update then wears what
    it wears in a model where nothing failed, to the solver's tolerance (its Newton refreshes its
    factors on timed decisions: round-off apart)."""
    from multiscale.errors import ConvergenceError
    from multiscale.macro.facet_wear import FacetWear
    from multiscale.workflows.model import build_model, facet_wear
    s = scene(tmp_path / "f", wear='k_w = "3e-13 1/Pa"')
    model = build_model(s)
    wear = facet_wear(s, model)
    model.start()
    model.macro_step(3.0)
    iface = model.tm.interface
    gap, exposure = iface.values(model.contact.initial_gap), model.exposure.sums.copy()
    u = [x.copy() for x in model.mechanics.displacements()]
    solve, calls = FacetWear._solve, []

    def failing(self):
        calls.append(1)
        if len(calls) == 3:
            raise ConvergenceError("a test's failed solve")
        solve(self)
    monkeypatch.setattr(FacetWear, "_solve", failing)
    with pytest.raises(ConvergenceError, match="a test's failed solve"):
        wear.update()
    assert not wear.depth.any() and wear.implicit == 0 and wear.volume.sum() == 0.0
    np.testing.assert_array_equal(iface.values(model.contact.initial_gap), gap)
    np.testing.assert_array_equal(model.exposure.sums, exposure)
    for x, y in zip(model.mechanics.displacements(), u):
        np.testing.assert_array_equal(x, y)
    monkeypatch.setattr(FacetWear, "_solve", solve)
    volume, work = wear.update()
    model.close()
    straight = build_model(s)                  # the same update, never failed
    again = facet_wear(s, straight)
    straight.start()
    straight.macro_step(3.0)
    expected, expected_work = again.update()
    straight.close()
    assert wear.implicit == again.implicit == 1 and work == pytest.approx(expected_work, rel=1e-7)
    np.testing.assert_allclose(volume, expected, rtol=1e-7)
    np.testing.assert_allclose(wear.depth, again.depth, rtol=1e-7, atol=1e-7 * again.depth.max())


def test_a_disc_that_wears_far_faster_than_the_pin(tmp_path):
    """A disc k_w 1e4 and 1e5 times the pin's (1e-16 /Pa): its track's depth per pressure at the pin,
    c_1 K_n about 0.8 and 8 (the pin covers 3-4 % of its circles). At 0.8 the track wears explicitly,
    k_1 W to round-off; at 8 (explicitly: a contact Newton failure) the updates are implicit with it,
    its volume k_1 W within 1 % (measured 0.36 %: the pressures found, not the exposure's)."""
    for k1, implicit in (("1e-12", 0), ("1e-11", 6)):
        h = run(scene(tmp_path / k1, steps=6, end="18 s", wear='k_w = "1e-16 1/Pa"',
                      **{"materials.disc.k_w": f"{k1} 1/Pa"}), verbose=False).history
        assert h["wear_implicit_updates"][-1] == implicit
        assert h["counter_wear_volume"][-1] == pytest.approx(float(k1) * h["frictional_work"][-1],
                                                             rel=1e-12 if not implicit else 1e-2)
        assert h["max_pressure"][-1] < h["max_pressure"][0]              # the edge's peak worn off, stably

"""Archard wear of the interface facets in perfect contact (``multiscale.macro.facet_wear``; effect
"wear" without "roughness"): the volumes Archard's law gives for the work and the load done, the
worn-in pressure of a pin on a rotating disc (uniform wear: p proportional to 1/r), a resumed run
equal to a straight one, and the scene's checks."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from multiscale.errors import SceneError  # noqa: E402
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
    assert list(h["wear_substeps"][1:]) == [1, 1, 1]
    work = h["frictional_work"]
    np.testing.assert_allclose(h["wear_volume"], 1e-14 * work, rtol=1e-12, atol=0)
    np.testing.assert_allclose(h["counter_wear_volume"], 2e-14 * work, rtol=1e-12, atol=0)
    moment = h["friction_moment"]
    assert work[-1] == pytest.approx(np.mean(moment) * 200 * np.pi / 30 * 9.0, rel=2e-3)
    assert h["wear_max_depth"][-1] > h["wear_volume"][-1] / 4e-4               # deeper than its mean somewhere
    per_load = run(scene(tmp_path / "k", wear='specific_rate = "4e-15 1/Pa"'), verbose=False).history
    np.testing.assert_allclose(per_load["wear_volume"], 4e-15 * per_load["frictional_work"] / 0.4, rtol=1e-12)


def test_a_worn_in_pin_carries_its_load_as_one_over_the_radius(tmp_path):
    """Archard wear at k_w mu p omega r settles where every point wears alike (the worn face recedes
    as a whole): p r uniform, p = C / r. The coarse pin (20 mm at 80-100 mm, 2.5 mm facets), k_w =
    3e-13 /Pa, 120 s at 200 rpm (17 um worn): its mean pressure in five bands of radius follows
    1/r within 3 % (measured 2.3 %; at the start 0.84 to 0.43 MPa inside out, against 1/r's
    0.55 to 0.46), the peak of the fresh pin's edge worn from 2.5 to 0.56 MPa. Five increments an
    update (c K about 1.6 / ``STABLE``): the volume is k_w times the work within 0.2 %, each
    increment on the pressure re-solved after the last."""
    import meshio
    h = run(scene(tmp_path / "in", steps=40, end="120 s", wear='k_w = "3e-13 1/Pa"',
                  **{"output.every": 40, "output.fields": ["contact_pressure", "wear_depth"]}), verbose=False).history
    assert h["max_pressure"][0] > 2e6 and h["max_pressure"][-1] < 0.6e6
    assert h["wear_volume"][-1] == pytest.approx(3e-13 * h["frictional_work"][-1], rel=2e-3)
    assert set(h["wear_substeps"][1:]) == {5}       # c K = 3e-13 x 0.4 x 62.8 rad x 90 mm x ~2.3e12 Pa/m over STABLE
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
    np.testing.assert_allclose(mean * r / np.mean(mean * r), 1.0, atol=0.03)


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


def test_the_scene_takes_wear_in_perfect_contact(tmp_path):
    """Wear needs no roughness: the run marches, checkpoints and writes the worn depths of both bodies;
    it needs friction."""
    s = scene(tmp_path / "s")
    p = plan(s)
    assert "checkpoint.h5" in p.files and {"wear_depth", "counter_wear_depth"} <= set(p.interface_fields)
    assert len(p.times) == 4
    with pytest.raises(SceneError, match='effects: "wear" needs effect "friction" too'):
        loads(pin_on_disc(tmp_path / "x", effects=("contact", "wear")))

"""A duty cycle's applications (``multiscale.applications``, applications.csv): synthetic
histories of two stops with closed-form values (a constant braking torque, speeds linear in
time), a run stopped inside a stop, a run without heat columns, the CSV; and one real run of
two applications, stopped inside the second and resumed."""
import csv
import dataclasses
import json

import numpy as np
import pytest

from multiscale.applications import applications, summary, table, write_csv
from multiscale.io import History
from multiscale.scene_sections import Loading

TORQUE, CLAMP, WEAR = 30.0, 1000.0, 1e-12          # N m while applied, N at load factor 1, m^3 per rad slid
# stop 1 from 40 rad/s to rest over [0, 2] s; released at rest, spun up to 40 rad/s, applied over
# 0.1 s at that speed and stopped over [2.3, 4.3] s: heated [0, 2] and [2.2, 4.3]
SPEED = ((0.0, 40.0), (2.0, 0.0), (2.1, 0.0), (2.2, 40.0), (2.3, 40.0), (4.3, 0.0))     # s, rad/s
LOAD = ((0.0, 1.0), (2.0, 1.0), (2.1, 0.0), (2.2, 0.0), (2.3, 1.0))                    # s, -
END = 4.5
# closed forms: int factor x omega dt (the torque's work / TORQUE) and int omega dt of each stop [rad]
SLID, ANGLE = (40.0, 0.5 * 40.0 * 0.1 + 40.0), (40.0, 40.0 * 0.1 + 40.0)
RTOL = 1e-12                                        # where the bookkeeping is exact: round-off
ALIGNED = np.round(np.arange(46) * 0.1, 12)         # rows on every knot: the power linear between rows
SHARED = np.round(np.arange(11) * 0.45, 12)         # step (1.8, 2.25] holds the end of one stop and the start of the next


def cycle() -> Loading:
    return Loading(speed_profile=SPEED, load_profile=LOAD, braking_torque=TORQUE)


def sliding(t0: float, t1: float) -> float:
    """int factor x omega dt over [t0, t1]: Simpson's rule between the knots (exact: quadratic there)."""
    ld = cycle()
    ts = sorted({t0, t1, *(t for t, _ in SPEED + LOAD if t0 < t < t1)})
    g = [ld.factor(t) * ld.angular_speed(t) for t in ts]
    mid = [ld.factor(0.5 * (a + b)) * ld.angular_speed(0.5 * (a + b)) for a, b in zip(ts, ts[1:])]
    return sum((b - a) * (ga + 4 * gm + gb) / 6 for a, b, ga, gm, gb in zip(ts, ts[1:], g, mid, g[1:]))


def history(times, mu=(0.4, 0.3), heat=True, interfaces=False, wear_every=None) -> History:
    """The rows a torque-controlled run of ``cycle`` records at ``times``: friction_moment TORQUE x
    factor while sliding, mu ``mu[0]`` in the first stop and ``mu[1]`` after; with ``heat`` each
    step's heat TORQUE x int factor x omega dt (30 % into the pin), the pin at 300 K + t, the disc
    at 400 K - t; ``interfaces``: two, inner and outer, with 60/40 % of the heat, mu +- 0.1 and
    their faces' temperatures; ``wear_every``: a wear update every that many steps (and at the
    last row), the worn volume WEAR per rad of loaded sliding, 70 % on the inner interface."""
    ld, h = cycle(), History()
    for n, t in enumerate(times):
        f, w = ld.factor(t), ld.angular_speed(t)
        m, on = mu[0] if t <= 2.1 else mu[1], float(w > 0)
        row = {"time": t, "interface_force": CLAMP * f, "friction_force": m * CLAMP * f * on,
               "friction_moment": TORQUE * f * on, "angular_speed": w}
        q = TORQUE * sliding(times[n - 1], t) if n else 0.0
        if heat:
            row.update(heat_step_pin=0.3 * q, heat_step_disc=0.7 * q, max_temperature_pin=300.0 + t,
                       max_temperature_disc=400.0 - t)
        if interfaces:
            for name, share, dmu in (("inner", 0.6, 0.1), ("outer", 0.4, -0.1)):
                row.update({f"interface_force_{name}": 0.5 * CLAMP * f,
                            f"friction_force_{name}": (m + dmu) * 0.5 * CLAMP * f * on,
                            f"frictional_heat_step_{name}": share * q})
            row.update(face_max_temperature_inner_on_pin=310.0 + t, face_max_temperature_inner_on_disc=305.0 + t,
                       face_max_temperature_outer_on_pin=320.0 - t, face_max_temperature_outer_on_disc=300.0)
        if wear_every:
            update = n and (n % wear_every == 0 or n == len(times) - 1)
            worn = WEAR * sliding(0.0, t) if update else (h["wear_volume"][-1] if n else 0.0)
            row.update(wear_substeps=2 * bool(update), wear_volume=worn, wear_volume_inner=0.7 * worn,
                       wear_volume_outer=0.3 * worn)
        h.append(**row)
    return h


def test_two_stops_by_the_heat_of_each_step():
    """Rows every 0.45 s: a step straddles each stop's start or end, and step (1.8, 2.25] holds the
    end of the first and the start of the second, split by their loaded sliding in it (0.4 and
    0.5 rad). The energies are TORQUE x the sliding of each stop to round-off (the per-step heat
    is exact where the rows' trapezoids are not: without heat the first stop's is 5 % high), so is
    the wear updated every 3 steps across the stops; the mean torque is the energy over the angle
    swept; the peaks are over each stop's rows and the end row of its last step."""
    apps = applications(history(SHARED, mu=(0.4, 0.4), interfaces=True, wear_every=3), cycle(), "rotation", END)
    assert [(a.number, a.start, a.end, a.partial) for a in apps] == [(1, 0.0, 2.0, False), (2, 2.2, 4.3, False)]
    assert [(a.speed_start, a.speed_end) for a in apps] == [(40.0, 0.0), (40.0, 0.0)]
    for a, slid, angle in zip(apps, SLID, ANGLE):
        assert a.energy == pytest.approx(TORQUE * slid, rel=RTOL)
        assert a.torque_mean == pytest.approx(TORQUE * slid / angle, rel=RTOL)
        assert a.torque_peak == TORQUE and a.friction == pytest.approx(0.4, rel=RTOL)
        assert a.wear_volume == pytest.approx(WEAR * slid, rel=RTOL)
        inner, outer = a.interfaces["inner"], a.interfaces["outer"]
        assert (inner.energy, outer.energy) == pytest.approx((0.6 * a.energy, 0.4 * a.energy), rel=RTOL)
        assert (inner.friction, outer.friction) == pytest.approx((0.5, 0.3), rel=RTOL)
        assert (inner.wear_volume, outer.wear_volume) == pytest.approx((0.7 * a.wear_volume, 0.3 * a.wear_volume),
                                                                       rel=RTOL)
    # rows [0, 2] and 2.25 (the end of the shared step), then [2.2, 4.3] and 4.5
    assert apps[0].temperatures == {"pin": 302.25, "disc": 400.0}
    assert apps[1].temperatures == {"pin": 304.5, "disc": 397.75}
    assert [(a.interfaces["inner"].temperature, a.interfaces["outer"].temperature) for a in apps] == \
        [(312.25, 320.0), (314.5, 317.75)]
    # the rows' trapezoids: exact to 1.8 s (39.6 rad), then (4 + 20)/2 x 0.45 rad x 0.4 / (0.4 + 0.5)
    trapezoid = applications(history(SHARED, heat=False), cycle(), "rotation", END)
    assert trapezoid[0].energy == pytest.approx(TORQUE * (39.6 + 2.4), rel=RTOL)


@pytest.mark.parametrize("heat", [None, "zero"])
def test_without_frictional_heat_the_power_is_integrated_over_the_rows(heat):
    """No heat columns (a run without effect thermal), or all 0 (thermal without heat_partition):
    the torque x speed of the rows by the trapezoidal rule, exact with rows on every knot (the power
    linear between them); mu 0.4 in the first stop, 0.3 in the second, each exact (the same
    weights above and below); no temperatures, wear or interfaces."""
    h = history(ALIGNED, heat=heat == "zero")
    if heat == "zero":
        for body in ("pin", "disc"):
            h.columns[f"heat_step_{body}"] = [0.0] * len(h)
    apps = applications(h, cycle(), "rotation", END)
    assert [a.energy for a in apps] == pytest.approx([TORQUE * s for s in SLID], rel=RTOL)
    assert [a.friction for a in apps] == pytest.approx([0.4, 0.3], rel=RTOL)
    assert [a.torque_mean for a in apps] == pytest.approx([TORQUE * s / g for s, g in zip(SLID, ANGLE)], rel=RTOL)
    assert all(a.wear_volume is None and a.interfaces == {} for a in apps)
    assert [sorted(a.temperatures) for a in apps] == [[] if heat is None else ["disc", "pin"]] * 2


def test_a_run_stopped_inside_a_stop_gives_the_stops_it_reached_the_last_partial():
    """Cut at 3.15 s (a Ctrl-C after step 7): the second stop from 2.2 s to there, partial, its
    energy TORQUE x (2 + int_2.3^3.15 omega dt = 26.775) rad, the speed at the cut 23 rad/s; its
    wear that of the updates written (to 2.7 s: 16.4 rad). Cut inside the first stop: one, partial;
    cut at its end: whole, and no second; before any row after t = 0: none."""
    full = history(SHARED, wear_every=3)
    cut = History()
    cut.columns = {k: v[:8] for k, v in full.columns.items()}
    first, second = applications(cut, cycle(), "rotation", END)
    assert not first.partial and first.energy == pytest.approx(TORQUE * SLID[0], rel=RTOL)
    assert second.partial and (second.start, second.end, second.speed_end) == (2.2, 3.15, pytest.approx(23.0))
    assert second.duration == pytest.approx(0.95, rel=RTOL)
    assert second.energy == pytest.approx(TORQUE * 28.775, rel=RTOL)
    assert second.wear_volume == pytest.approx(WEAR * 16.4, rel=RTOL)
    for rows, expected in ((5, [(1.8, True)]), (21, [(2.0, False)]), (1, [])):
        part = History()
        part.columns = {k: v[:rows] for k, v in history(ALIGNED if rows == 21 else SHARED).columns.items()}
        assert [(a.end, a.partial) for a in applications(part, cycle(), "rotation", END)] == expected


def test_the_csv_has_its_units_in_the_header_and_the_rows_numbers(tmp_path, documented):
    """applications.csv: a column per quantity the history has, its SI unit in its name (each one
    in docs/results.rst), the numbers to 10 digits; a translating body's speeds in m/s and no
    torque."""
    apps = applications(history(SHARED, interfaces=True, wear_every=1), cycle(), "rotation", END)
    path = write_csv(apps, "rotation", tmp_path / "applications.csv")
    with path.open() as f:
        header, *rows = list(csv.reader(f))
    assert header == ["application", "start_s", "end_s", "duration_s", "partial", "speed_start_rad_per_s",
                      "speed_end_rad_per_s", "energy_J", "mean_friction_coefficient", "mean_torque_N_m",
                      "peak_torque_N_m", "peak_temperature_disc_K", "peak_temperature_pin_K", "wear_volume_m3",
                      "energy_inner_J", "mean_friction_coefficient_inner", "peak_face_temperature_inner_K",
                      "wear_volume_inner_m3", "energy_outer_J", "mean_friction_coefficient_outer",
                      "peak_face_temperature_outer_K", "wear_volume_outer_m3"]
    assert all(documented(name) for name in header)
    assert rows[0][:5] == ["1", "0", "2", "2", "0"] and rows[1][:5] == ["2", "2.2", "4.3", "2.1", "0"]
    np.testing.assert_allclose(np.array(rows, float), np.array(table(apps, "rotation")[1], float), rtol=5e-10)
    block = Loading(sliding_speed=2.0, load_profile=((0.0, 1.0), (1.0, 1.0), (1.1, 0.0), (1.3, 0.0), (1.4, 1.0)))
    h = History()
    for t in ALIGNED[:21]:
        f = block.factor(t)
        h.append(time=t, interface_force=CLAMP * f, friction_force=0.4 * CLAMP * f, sliding_speed=2.0)
    slid = applications(h, block, "translation", 2.0)
    assert [a.energy for a in slid] == pytest.approx([0.4 * CLAMP * 2.0 * 1.05, 0.4 * CLAMP * 2.0 * 0.65], rel=RTOL)
    assert table(slid, "translation")[0] == ["application", "start_s", "end_s", "duration_s", "partial",
                                             "speed_start_m_per_s", "speed_end_m_per_s", "energy_J",
                                             "mean_friction_coefficient"]


def test_the_summary_lists_a_line_per_application_the_first_and_last_of_many():
    """A table of the stops, aligned, a partial one marked; of more than 12, the first and last 6."""
    apps = applications(history(SHARED[:8], mu=(0.4, 0.4)), cycle(), "rotation", END)
    lines = summary(apps, "rotation")
    assert lines[0] == "  applications (applications.csv):"
    assert lines[1].split("  ")[-3:] == ["torque mean/peak [N m]", "disc [degC]", "pin [degC]"]
    assert lines[2].split() == ["1", "0-2", "40", "->", "0", "1200", "0.400", "30", "/", "30", "126.9", "29.1"]
    assert lines[3].split()[:2] == ["2*", "2.2-3.15"] and len({len(line) for line in lines[1:4]}) == 1   # aligned
    assert lines[-1] == "    * partial: the run stopped inside it"
    many = [dataclasses.replace(apps[0], number=k) for k in range(1, 16)]
    numbers = [line.split()[0] for line in summary(many, "rotation")[2:]]
    assert numbers == ["1", "2", "3", "4", "5", "6", "...", "10", "11", "12", "13", "14", "15"]


def test_a_cycle_run_stopped_in_its_second_stop_and_resumed_writes_its_applications(tmp_path, monkeypatch, capsys,
                                                                                  documented):
    """The braking-torque cycle of tests/test_duty_cycle.py (a real perfect-contact run, two
    applications, [0.25, 1.26] and [1.75, 2.75] s, 11 steps of 0.25 s) stopped by Ctrl-C after step
    8 (t = 2 s): applications.csv holds the first whole and the second to 2 s, partial; resumed,
    the run ends with both whole, the same columns, and prints them. Each energy is the torque x the integral of load
    factor x angular speed over it (trapezoids on 1 us, as that test's heat) within 1e-9, and the
    energies add up to the history's frictional heat to round-off; the mean torque is the energy
    over the angle swept (to 1e-12 of the 1 us trapezoids, their error), the peak the torque held
    (``TORQUE_TOL``); mu lies within the rows' friction over normal force; the file holds the rows
    to its 10 digits, and the folder what ``check`` promised."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    from test_duty_cycle import CYCLE_LOAD, CYCLE_SPEED, TORQUE, torque_cycle
    from multiscale.errors import Interrupted
    from multiscale.io import StepStop
    from multiscale.macro.preload import TORQUE_TOL
    from multiscale.outputs import plan
    from multiscale.workflows import run
    folder = tmp_path / "cycle"
    scene = torque_cycle(folder)
    t = np.linspace(0.0, 2.75, 2_750_001)                     # 1 us
    omega = np.interp(t, *zip(*CYCLE_SPEED))
    power = np.interp(t, *zip(*CYCLE_LOAD)) * omega

    def integral(y, a, b):                                    # trapezoids over [a, b]
        k0, k1 = round(a * 1e6), round(b * 1e6) + 1
        return float(np.sum(0.5 * (y[k0 + 1:k1] + y[k0:k1 - 1])) * 1e-6)

    def read():
        with (folder / "applications.csv").open() as f:
            return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    with monkeypatch.context() as patch:
        patch.setattr(StepStop, "requested", lambda self: self.done >= 7)     # asked at step 8's end
        with pytest.raises(Interrupted, match="after step 8 of 11"):
            run(scene, verbose=False)
    stopped = read()
    assert [(r["start_s"], r["end_s"], r["partial"]) for r in stopped] == [(0.25, 1.26, 0), (1.75, 2.0, 1)]
    assert "applications.csv" in json.loads((folder / "provenance.json").read_text())["files"]    # (--overwrite's)
    assert stopped[1]["energy_J"] == pytest.approx(TORQUE * integral(power, 1.75, 2.0), rel=1e-9)
    result = run(scene, resume=True)
    h, rows = result.history, read()
    assert list(rows[0]) == list(stopped[0])
    assert sorted(f.name for f in folder.iterdir()) == sorted(plan(scene).files)
    assert "applications.csv" in {f.name for f in result.files} and all(documented(k) for k in rows[0])
    apps = applications(h, scene.loading, "rotation", scene.time.end)
    np.testing.assert_allclose([list(r.values()) for r in rows], np.array(table(apps, "rotation")[1], float),
                               rtol=5e-10)                                  # the file's 10 digits
    assert [(a.start, a.end, a.partial) for a in apps] == [(0.25, 1.26, False), (1.75, 2.75, False)]
    assert sum(a.energy for a in apps) == pytest.approx(h["heat_total_pin"][-1] + h["heat_total_disc"][-1], rel=RTOL)
    braked = h["friction_force"] > 0
    ratio = h["friction_force"][braked] / h["interface_force"][braked]
    for a in apps:
        assert a.energy == pytest.approx(TORQUE * integral(power, a.start, a.end), rel=1e-9)
        assert a.torque_mean == pytest.approx(a.energy / integral(omega, a.start, a.end), rel=RTOL)
        assert a.torque_peak == pytest.approx(TORQUE, rel=TORQUE_TOL)
        assert (a.speed_start, a.speed_end) == tuple(np.interp([a.start, a.end], *zip(*CYCLE_SPEED)))
        assert ratio.min() * (1 - RTOL) <= a.friction <= ratio.max() * (1 + RTOL)
        assert a.friction == pytest.approx(0.4, rel=1e-4)     # (the sliding direction's turn over a facet)
    out = capsys.readouterr().out
    printed = out[out.index("  applications (applications.csv):"):].splitlines()
    assert [line.split()[:2] for line in printed[2:4]] == [["1", "0.25-1.26"], ["2", "1.75-2.75"]]

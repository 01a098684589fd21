"""The history (``multiscale.io.History``, ``multiscale.plots.history``): units per column, every curve visible and named once."""
import h5py
import numpy as np
import pytest
from matplotlib.colors import to_hex

from multiscale.io import History
from multiscale.plots import history as plots


@pytest.fixture
def drawn(keep_figures):
    """The figures the plotting functions make, kept to be inspected."""
    return keep_figures(plots)


def test_a_body_of_several_materials_has_one_visible_named_curve_per_material(tmp_path, drawn):
    """The pin-on-disc's pin (material pin, its holder of material disc) has the columns
    max_temperature_pin (the whole body), ..._pin_in_pin and ..._pin_in_disc: history.png drew the
    first hidden under the second (the same values), with the legends "pin" and "pin in pin" (an
    adversarial review). The whole-body curve is the highest of its materials': it is left out."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_pin=300.0 + t,
                       max_temperature_pin_in_pin=300.0 + t, max_temperature_pin_in_disc=295.0 + t,
                       max_temperature_disc=298.0 + t, heat_total_pin=t, heat_total_disc=2 * t,
                       micro_max_temperature=310.0 + t)
    plots.history_figure(history, tmp_path / "history.png")
    plots.multiscale_figure(history, tmp_path / "multiscale.png")
    for figure, prefix in zip(drawn, ("", "macro ")):
        axis = next(ax for ax in figure.axes if ax.get_ylabel() == "max temperature [°C]")
        curves = {line.get_label(): tuple(line.get_ydata()) for line in axis.get_lines()}
        names = [prefix + n for n in ("pin, pin material", "pin, disc material", "disc")]
        assert [n for n in curves if not n.startswith("micro")] == names
        assert len(set(curves.values())) == len(curves)          # no curve drawn over another
        np.testing.assert_allclose(curves[prefix + "pin, disc material"], [21.85, 22.85, 23.85])


def test_a_body_of_several_parts_has_one_curve_per_part(tmp_path, drawn):
    """A brake's fixed body of pads and backplates (two materials): its parts' columns
    max_temperature_fixed_part_<part> are drawn, named by the part, instead of the body's and its
    materials' (before, the pads' bulk temperatures were not in the history: only per material)."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        parts = {f"max_temperature_fixed_part_{p}": 300.0 + k * t
                 for k, p in enumerate(("inner_pad", "inner_backplate", "outer_pad"), 1)}
        history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_fixed=303.0 + 3 * t,
                       max_temperature_fixed_in_pad=303.0 + 3 * t, max_temperature_fixed_in_steel=302.0 + 2 * t,
                       max_temperature_disc=305.0 + t, heat_total_fixed=t, heat_total_disc=2 * t, **parts)
    plots.history_figure(history, tmp_path / "history.png")
    axis = next(ax for ax in drawn[0].axes if ax.get_ylabel() == "max temperature [°C]")
    curves = {line.get_label(): tuple(line.get_ydata()) for line in axis.get_lines()}
    assert list(curves) == ["disc", "inner pad", "inner backplate", "outer pad"]     # in the columns' order
    np.testing.assert_allclose(curves["outer pad"], [26.85, 29.85, 32.85])


def test_the_pads_heat_and_face_temperatures_have_their_own_panels(tmp_path, drawn):
    """A brake's per-pad columns: the frictional heat of each pad in a panel of its own (not among
    the bodies' heat_total_<body>, which they would double), the hottest facet of each face in
    another, named "<pad> on <body>"; six panels in two rows."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        pads = {f"frictional_heat_total_{p}": k * t for k, p in ((1, "inner_pad"), (2, "outer_pad"))}
        faces = {f"face_max_temperature_{p}_on_{b}": 300.0 + k * t
                 for k, (p, b) in enumerate([(p, b) for p in ("inner_pad", "outer_pad") for b in ("brake", "disc")])}
        history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_brake=310.0 + t,
                       max_temperature_disc=305.0 + t, heat_total_brake=t, heat_total_disc=2 * t, **pads, **faces)
    plots.history_figure(history, tmp_path / "history.png")
    shown = [ax for ax in drawn[0].axes if ax.get_visible()]
    assert len(shown) == 6 and len(drawn[0].axes) == 6
    curves = {ax.get_ylabel(): [line.get_label() for line in ax.get_lines()] for ax in shown}
    assert curves["heat of each body [J]"] == ["brake", "disc"]
    assert curves["frictional heat per interface [J]"] == ["inner pad", "outer pad"]
    assert curves["max face temperature [°C]"] == ["inner pad on brake", "inner pad on disc", "outer pad on brake",
                                                   "outer pad on disc"]


def test_each_bodys_heat_in_stored_and_lost_and_each_parts_stored_heat_are_drawn(tmp_path, drawn):
    """The heat of each body: into it (heat_total_<body>, solid), conducted into it from the other
    (heat_conducted_total_<body>, dashed), stored in it (stored_heat_<body>, dotted) and lost by it
    (heat_lost_total_<body>, dash-dotted), a colour per body, each named once
    in the legend; a body of several parts has each part's stored heat in a panel of its own
    (before, only the heat into each body was drawn)."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_fixed=310.0 + t,
                       max_temperature_disc=305.0 + t, heat_total_fixed=t, heat_total_disc=9 * t,
                       stored_heat_fixed=0.8 * t, stored_heat_disc=7 * t, heat_lost_total_fixed=0.2 * t,
                       heat_lost_total_disc=2 * t, stored_heat_fixed_part_pad=0.6 * t,
                       stored_heat_fixed_part_backplate=0.2 * t, heat_conducted_total_fixed=-0.1 * t,
                       heat_conducted_total_disc=0.1 * t, heat_exchanged_total=0.1 * t)
    plots.history_figure(history, tmp_path / "history.png")
    axes = {ax.get_ylabel(): ax for ax in drawn[0].axes if ax.get_visible()}
    heat = axes["heat of each body [J]"]
    drawn_as = {(line.get_label(), line.get_linestyle()): tuple(line.get_ydata()) for line in heat.get_lines()}
    assert drawn_as == {("fixed", "-"): (0, 1, 2), ("fixed", "--"): (0, -0.1, -0.2), ("fixed", ":"): (0, 0.8, 1.6),
                        ("fixed", "-."): (0, 0.2, 0.4), ("disc", "-"): (0, 9, 18), ("disc", "--"): (0, 0.1, 0.2),
                        ("disc", ":"): (0, 7, 14), ("disc", "-."): (0, 2, 4)}   # (conducted: not drawn, a trial)
    colours = {line.get_label(): {str(other.get_color()) for other in heat.get_lines()
                                  if other.get_label() == line.get_label()} for line in heat.get_lines()}
    assert all(len(c) == 1 for c in colours.values()) and colours["fixed"] != colours["disc"]
    assert [t.get_text() for t in heat.get_legend().get_texts()] == ["fixed", "disc", "into", "conducted in", "stored",
                                                                     "lost"]
    parts = axes["heat stored in each part [J]"]
    assert {line.get_label(): tuple(line.get_ydata()) for line in parts.get_lines()} == \
        {"pad": (0, 0.6, 1.2), "backplate": (0, 0.2, 0.4)}
    assert [t.get_text() for t in parts.get_legend().get_texts()] == ["pad", "backplate"]


def test_a_body_or_part_has_one_colour_in_every_panel_of_both_figures(tmp_path, drawn):
    """The pin-on-disc's pin (parts housing, pin, plate) beside the disc: each panel numbered its
    curves' colours itself, so the pin was green among the temperatures, orange in the heat of each
    body and in the stored heat of each part, and the micro temperature took the disc's blue (a
    user trial). Now a name has one colour in both figures; the micro curve is black."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_disc=300.0 + t,
                       max_temperature_pin_part_housing=293.0 + t, max_temperature_pin_part_pin=299.0 + t,
                       max_temperature_pin_part_plate=293.0, heat_total_disc=9 * t, heat_total_pin=t,
                       stored_heat_pin_part_housing=0.1 * t, stored_heat_pin_part_pin=0.8 * t,
                       stored_heat_pin_part_plate=0.0, micro_max_temperature=340.0 + t, max_zone_pressure=1e6)
    plots.history_figure(history, tmp_path / "history.png")
    plots.multiscale_figure(history, tmp_path / "multiscale.png")
    seen = {}
    for figure in drawn:
        for ax in figure.axes:
            for line in ax.get_lines():
                name = line.get_label().removeprefix("macro ").partition(":")[0]      # "micro: zone mean + ..."
                if ax.get_ylabel() in ("max temperature [°C]", "heat of each body [J]", "heat stored in each part [J]"):
                    seen.setdefault(name, set()).add(to_hex(line.get_color()))
    assert set(seen) == {"disc", "housing", "pin", "plate", "micro"}
    assert all(len(c) == 1 for c in seen.values()), seen
    assert len({c for cs in seen.values() for c in cs}) == 5 and seen["micro"] == {"#000000"}


def test_nine_pads_have_distinct_curves_and_legends_inside_their_panels(tmp_path, drawn):
    """The railway disc's 9 pucks (demos/railway_drag.toml): history.png drew the 18 face curves in
    matplotlib's 10 colours (puck 1 on disc and puck 6 on disc alike) with a legend of 18 lines
    taller than its panel, over the panel above and its curves. Now each curve of a panel differs in
    colour or line style (the pad's colour, the body's style) and every legend lies within its panel."""
    history = History()
    pads = [f"puck_{k}" for k in range(1, 10)]
    for t in (0.0, 10.0, 20.0):
        history.append(time=t, interface_force=6e3, max_pressure=3e6, max_temperature_disc=300.0 + t,
                       max_temperature_fixed=300.0 + t, heat_total_disc=t, heat_total_fixed=2 * t,
                       **{f"frictional_heat_total_{p}": k * t for k, p in enumerate(pads)},
                       **{f"face_max_temperature_{p}_on_{b}": 300.0 + k * t + j
                          for k, p in enumerate(pads) for j, b in enumerate(("disc", "fixed"))})
    plots.history_figure(history, tmp_path / "history.png")
    figure = drawn[0]
    figure.canvas.draw()
    for ax in figure.axes:
        lines = ax.get_lines()
        assert len({(str(line.get_color()), line.get_linestyle()) for line in lines}) == len(lines), ax.get_ylabel()
        legend = ax.get_legend()
        if legend is not None:
            inside, box = legend.get_window_extent(), ax.get_window_extent()
            assert (inside.x0 >= box.x0 - 1 and inside.x1 <= box.x1 + 1 and inside.y0 >= box.y0 - 1
                    and inside.y1 <= box.y1 + 1), ax.get_ylabel()


def test_a_unit_word_in_a_body_or_interface_name_does_not_set_the_unit(tmp_path):
    """A clutch's rotating "pressure_plate" or a pad "force_pad": each column keeps the unit of its
    quantity (the name comes after it), in ``history.h5`` as in ``unit_of``."""
    h = History()
    h.append(time=0.0, max_temperature_pressure_plate=300.0, frictional_heat_total_force_pad=1.0,
             face_mean_temperature_force_pad_on_pressure_plate=300.0, interface_force_heat_pad=5.0,
             max_pressure_time_pad=1e6, friction_coefficient_pressure_pad=0.4)
    with h5py.File(h.write(tmp_path / "history.h5"), "r") as f:
        units = {key: f[key].attrs["unit"] for key in f}
    assert units == {"time": "s", "max_temperature_pressure_plate": "K", "frictional_heat_total_force_pad": "J",
                     "face_mean_temperature_force_pad_on_pressure_plate": "K", "interface_force_heat_pad": "N",
                     "max_pressure_time_pad": "Pa", "friction_coefficient_pressure_pad": "-"}   # (was Pa)


def test_the_wear_map_of_a_round_face_leaves_its_corners_blank(tmp_path, drawn):
    """A round face (a 48-gon of radius 3 mm, fan-triangulated) under 4 x 4 zones of 8 x 8 cells:
    the micro cells drawn are those whose centre is on the face, their area that of the 48-gon to
    the cells' quantisation (2 %), and a corner zone with no cell on it is blank. Before, the map
    drew every patch over its whole box, wear outside the pin included (a user trial). An L-shaped
    face (non-convex) keeps its notch blank."""
    from multiscale.micro.zones import ZoneGrid
    r, n = 3e-3, 48
    a = 2 * np.pi * np.arange(n + 1) / n
    rim = r * np.column_stack([np.cos(a), np.sin(a)])
    disc = np.stack([np.zeros((n, 2)), rim[:-1], rim[1:]], axis=1)
    grid = ZoneGrid((-r, -r), (4, 4), (r / 2, r / 2))
    plots.wear_map(grid, np.full((16, 8, 8), 1e-6), tmp_path / "wear.png", face=disc)
    zones, cells = (ax.images[0].get_array() for ax in drawn[-1].axes[:2])
    drawn_zones, drawn_cells = (~np.ma.getmaskarray(a) & np.isfinite(np.ma.getdata(a)) for a in (zones, cells))
    area = 0.5 * n * r**2 * np.sin(2 * np.pi / n)
    assert np.count_nonzero(drawn_cells) * (r / 16)**2 == pytest.approx(area, rel=2e-2)
    assert not drawn_cells[0, 0] and cells[16, 16] == pytest.approx(1.0)          # µm
    assert drawn_zones.all()                                  # each corner zone holds a sliver of the face
    plots.wear_map(ZoneGrid((-2 * r, -r), (5, 4), (r / 2, r / 2)), np.full((20, 8, 8), 1e-6), tmp_path / "w.png",
                   face=disc)
    assert not (~np.ma.getmaskarray(drawn[-1].axes[0].images[0].get_array())).reshape(4, 5)[:, 0].any()   # none
    ell = np.array([[[0, 0], [2, 0], [2, 1]], [[0, 0], [2, 1], [0, 1]], [[0, 1], [1, 1], [1, 2]], [[0, 1], [1, 2], [0, 2]]])
    on = plots.cells_on_face(ZoneGrid((0, 0), (2, 2), (1e-3, 1e-3)), (2, 2), 1e-3 * ell)
    np.testing.assert_array_equal(on, [[1, 1, 1, 1], [1, 1, 1, 1], [1, 1, 0, 0], [1, 1, 0, 0]])


def test_a_log_axis_of_pressures_ends_on_labelled_ticks(tmp_path, drawn):
    """The multiscale figure's pressure panel: facets at 12.6-15.1 MPa beside micro peaks of
    99 MPa had no labelled tick near the facets' curves (a user trial). Its limits are now the
    1, 2 or 5 x 10^k around the values, ticks labelled in plain numbers. A released row (pressures 0) leaves a gap: its curves dropped off the
    log axis (a user trial). The worn volume is in mm³ however small (µm³ below 0.001 mm³ puzzled a
    user trial: a tribologist reads mm³)."""
    assert plots.nice_range([12.6, 99.0]) == (10.0, 100.0)
    assert plots.nice_range([0.03, 0.7]) == (0.02, 1.0) and plots.nice_range([2.0, 5.0]) == (2.0, 5.0)
    assert plots.nice_range([5.0, 5.0]) == (2.0, 10.0)
    history = History()
    for t, (facet, micro, volume) in enumerate([(12.6e6, 99e6, 0.0), (15.1e6, 40e6, 1.2e-11)]):
        history.append(time=float(t), max_pressure=facet, micro_max_pressure=micro, wear_volume=volume)
    plots.multiscale_figure(history, tmp_path / "m.png")
    pressure, worn = drawn[-1].axes[:2]
    assert pressure.get_ylim() == pytest.approx((10.0, 100.0))
    assert {t.get_text() for t in pressure.get_yticklabels()} >= {"10", "20", "50", "100"}
    assert worn.get_ylabel() == "wear volume [mm³]"
    history.append(time=2.0, max_pressure=0.0, micro_max_pressure=0.0, wear_volume=1.2e-11)     # released
    plots.multiscale_figure(history, tmp_path / "m.png")
    curves = [line.get_ydata() for line in drawn[-1].axes[0].get_lines()]
    assert all(np.isnan(y[-1]) and np.isfinite(y[:2]).all() for y in curves)     # a gap (it dropped off the axis)
    small = History()
    for t, volume in enumerate([0.0, 1.2e-15]):
        small.append(time=float(t), max_pressure=1e6, wear_volume=volume)
    plots.multiscale_figure(small, tmp_path / "m.png")
    worn = drawn[-1].axes[1]
    assert worn.get_ylabel() == "wear volume [mm³]"
    assert worn.get_lines()[0].get_ydata()[-1] == pytest.approx(1.2e-6)


def test_the_multiscale_figure_shows_the_real_contact_area_and_the_plastic_share(tmp_path, drawn):
    """The real contact area (mm² or µm², each rough interface's beside the total) and the largest
    plastic share of a zone have panels (a plastic contact run showed the pressures alone, the main
    results nowhere; a user trial), and a one-panel figure's title is not cut off at both ends."""
    history = History()
    for t, (a, b) in enumerate([(2e-6, 1e-6), (3e-6, 1.5e-6)]):
        history.append(time=float(t), max_pressure=1e6, real_contact_area=a + b, real_contact_area_inner=a,
                       real_contact_area_outer=b, micro_plastic_fraction=0.1 * (t + 1))
    plots.multiscale_figure(history, tmp_path / "m.png", "brake")
    area = next(ax for ax in drawn[-1].axes if ax.get_ylabel() == "real contact area [mm²]")
    curves = {line.get_label(): tuple(line.get_ydata()) for line in area.get_lines()}
    assert curves == {"all interfaces": pytest.approx((3.0, 4.5)), "inner": pytest.approx((2.0, 3.0)),
                      "outer": pytest.approx((1.0, 1.5))}
    plastic = next(ax for ax in drawn[-1].axes if ax.get_ylabel() == "largest plastic share\nof a zone's cells [%]")
    np.testing.assert_allclose(plastic.get_lines()[0].get_ydata(), [10.0, 20.0])
    small = History()
    small.append(time=0.0, real_contact_area=1.07e-9)
    plots.multiscale_figure(small, tmp_path / "s.png", "bof_x3p")
    (ax,) = [a for a in drawn[-1].axes if a.axison]
    assert ax.get_ylabel() == "real contact area [µm²]" and ax.get_lines()[0].get_ydata()[0] == pytest.approx(1070.0)
    assert drawn[-1]._suptitle.get_text() == "bof_x3p:\nboth scales of the multiscale loop against time"


def test_a_run_with_fade_draws_its_friction_coefficient(tmp_path, drawn):
    """``friction_coefficient`` (a run with a ``friction_temperature`` table) has a panel of its own,
    its values as recorded (NaN at rest: a gap); a run without the column has no such panel; with
    several interfaces the panel also draws each one's ``friction_coefficient_<name>``."""
    for fade in (True, False):
        history = History()
        for t, mu in ((0.0, 0.4), (1.0, 0.37), (2.0, float("nan"))):
            history.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_pin=300.0 + t,
                           max_temperature_disc=298.0 + t, heat_total_pin=t, heat_total_disc=2 * t,
                           **({"friction_coefficient": mu} if fade else {}))
        plots.history_figure(history, tmp_path / "history.png")
        axes = [ax for ax in drawn[-1].axes if ax.get_ylabel() == "friction coefficient [-]"]
        assert len(axes) == fade
        if fade:
            np.testing.assert_allclose(axes[0].get_lines()[0].get_ydata(), [0.4, 0.37, np.nan])
    pads = History()                    # several interfaces: each one's curve beside all of them together
    for t, mu in ((0.0, 0.4), (1.0, 0.37)):
        pads.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_disc=298.0 + t,
                    heat_total_disc=t, friction_coefficient=mu, friction_coefficient_inner_pad=mu + 0.01,
                    friction_coefficient_outer_pad=mu - 0.01)
    plots.history_figure(pads, tmp_path / "history.png")
    (ax,) = [ax for ax in drawn[-1].axes if ax.get_ylabel() == "friction coefficient [-]"]
    assert {line.get_label(): tuple(line.get_ydata()) for line in ax.get_lines()} == {
        "all interfaces": pytest.approx((0.4, 0.37)), "inner pad": pytest.approx((0.41, 0.38)),
        "outer pad": pytest.approx((0.39, 0.36))}
    # a pad has its part's colour in the friction panel too, all of them black (the "all interfaces" curve
    # shifted the colours: orange was one pad there and another among the temperatures, a user trial)
    parts = History()
    for t, mu in ((0.0, 0.4), (1.0, 0.37)):
        parts.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_disc=298.0 + t,
                     max_temperature_fixed_part_inner_pad=300.0 + t, max_temperature_fixed_part_outer_pad=301.0 + t,
                     heat_total_disc=t, friction_coefficient=mu, friction_coefficient_inner_pad=mu + 0.01,
                     friction_coefficient_outer_pad=mu - 0.01)
    plots.history_figure(parts, tmp_path / "history.png")
    assert "braking torque [N m]" not in [ax.get_ylabel() for ax in drawn[-1].axes]     # no rotating body
    colour = {}
    for ax in drawn[-1].axes:
        for line in ax.get_lines():
            colour.setdefault(line.get_label(), set()).add(to_hex(line.get_color()))
    assert colour["all interfaces"] == {"#000000"} and all(len(colour[n]) == 1 for n in ("inner pad", "outer pad", "disc"))
    torque = History()                  # a rotating body's braking torque has its panel (wanted there: a trial)
    for t in (0.0, 1.0):
        torque.append(time=t, interface_force=200.0, max_pressure=1e6, max_temperature_disc=298.0, heat_total_disc=t,
                      friction_moment=30.0 - t)
    plots.history_figure(torque, tmp_path / "history.png")
    (ax,) = [ax for ax in drawn[-1].axes if ax.get_ylabel() == "braking torque [N m]"]
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), [30.0, 29.0])


def test_the_multiscale_figures_legends_cover_no_panel(tmp_path, drawn):
    """The legends of multiscale.png lay over the curves (the pressures' and the partition's: a user
    trial); they now stand above their panels, over none of the figure's axes."""
    history = History()
    for t in (0.0, 1.0, 2.0):
        history.append(time=t, max_pressure=2e6, max_zone_pressure=1.3e6, micro_max_pressure=4.6e6 - 1e5 * t,
                       max_temperature_disc=300.0 + t, max_temperature_pin=299.0 + 2 * t, micro_max_temperature=310.0,
                       partition_max=0.09, partition_mean=0.04, partition_min=0.035, wear_volume=1e-12 * t)
    plots.multiscale_figure(history, tmp_path / "multiscale.png")
    figure = drawn[-1]
    figure.canvas.draw()
    legends = [ax.get_legend().get_window_extent() for ax in figure.axes if ax.get_legend() is not None]
    assert len(legends) == 3
    pressures = next(ax for ax in figure.axes if ax.get_ylabel() == "max contact pressure [MPa]")
    assert [t.get_text() for t in pressures.get_legend().get_texts()] == [      # a row's two states (a zone
        "macro facet (after wear)", "macro zone mean (before wear)", "micro local (before wear)"]  # above every facet: a trial)
    for box in legends:
        for ax in figure.axes:
            assert not box.overlaps(ax.get_window_extent()), ax.get_ylabel()


def test_a_runs_totals_are_its_headline_numbers():
    """``workflows.output.totals``: the last console line of a run (a trial found only file paths
    there): the rough interfaces' frictional work, else the heat into the bodies, each body's
    highest temperature over the run (not its parts' or materials'), the worn volume in mm^3."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")      # workflows import it
    from multiscale.workflows.output import totals
    history = History()
    for t, hot in ((0.0, 295.15), (1.0, 338.2), (2.0, 330.0)):
        history.append(time=t, frictional_work=27.0 * t, max_temperature_pin=hot, max_temperature_pin_in_disc=300.0,
                       max_temperature_pin_part_plate=299.0, max_temperature_disc=hot - 20, heat_total_pin=2.0 * t,
                       wear_volume=1.5e-13 * t)
    assert totals(history) == ("frictional work 54 J, hottest pin 65.05 degC, hottest disc 45.05 degC, "
                               "wear volume 0.0003 mm^3")
    heat = History()
    for t in (0.0, 1.0):
        heat.append(time=t, heat_total_pin=2.0 * t, heat_total_disc=40.0 * t)
    assert totals(heat) == "frictional heat 42 J" and totals(History()) == ""
    named = History()                             # bodies named with _in_ or _part_ (they were left out)
    for t in (0.0, 1.0):
        named.append(time=t, max_temperature_disc_in_front=300.0 + 10 * t, max_temperature_pad_part_a=310.0,
                     max_temperature_pad_part_a_in_steel=305.0)
    assert totals(named) == "hottest disc_in_front 36.85 degC, hottest pad_part_a 36.85 degC"


def test_the_speed_of_a_cycle_is_drawn(tmp_path, drawn):
    """``angular_speed`` [rad/s] in rpm, ``sliding_speed`` [m/s] as it is: a cycle's speed was drawn
    nowhere, so it had to be read off the torque (a user trial)."""
    for column, label, factor in (("angular_speed", "rotation speed [rpm]", 30 / np.pi),
                                  ("sliding_speed", "sliding speed [m/s]", 1.0)):
        history = History()
        for t, v in ((0.0, 80.0), (1.0, 40.0), (2.0, 0.0)):
            history.append(time=t, interface_force=30.0, max_pressure=1e7, **{column: v})
        plots.history_figure(history, tmp_path / "history.png")
        axes = {ax.get_ylabel(): ax for ax in drawn[-1].axes if ax.get_visible()}
        np.testing.assert_allclose(axes[label].get_lines()[0].get_ydata(), np.array([80.0, 40.0, 0.0]) * factor)


def test_interface_names_ending_in_in_keep_their_names():
    """A brake's pads named padA_in / padA_out (a trial): the face-temperature legend read
    "padA, on fixed material" (the name split at "_in_" as a body's material)."""
    assert plots.column_label("face_max_temperature_padA_in_on_fixed") == "padA in on fixed"
    assert plots.column_label("face_max_temperature_inner_pad_on_disc") == "inner pad on disc"
    assert plots.column_label("max_temperature_fixed_part_padA_in") == "padA in"
    assert plots.column_label("max_temperature_pin_in_disc") == "pin, disc material"
    assert plots.column_label("frictional_heat_total_padA_in") == "padA in"

"""Temperature probes (``multiscale.macro.probes``, scene key output.probes): a thermocouple reads the
temperature field at its point, a turning one the mean round its circle, and a point outside its
body is refused with where the bodies are."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from multiscale.errors import InputError, InputErrors, SceneError  # noqa: E402
from multiscale.macro.probes import RING, Probes, ProbeSpec, ring  # noqa: E402
from multiscale.geometry import Rotation  # noqa: E402
from multiscale.references.thermal import slab_convection  # noqa: E402
from multiscale.scene import loads  # noqa: E402
from multiscale.workflows import run  # noqa: E402
from multiscale.workflows.transient import run as march  # noqa: E402
from multiscale.workflows.model import build_model  # noqa: E402

from test_macro_run import pin_on_disc  # noqa: E402
from test_macro_thermal import BLOCK, STEEL, block_scene  # noqa: E402


def linear(x):
    return 300.0 + 1e3 * x[0] - 2e3 * x[1] + 5e3 * x[2]


def test_a_probe_reads_the_field_at_its_point():
    """A field linear in space (exact in P1): each probe reads it to round-off, inside a body, on its
    outer face and 1e-9 m outside it (``TOUCH``: said in ``located``); on the interface (z = 0, the
    block on the flat) only with its body named, and each body's own field there. Points outside
    are refused all together, with how far out they are. Those a worn face reached are named
    (``worn``: a trial's thermocouple 2 mm into a pad worn 4.5 mm read on)."""
    model = build_model(block_scene())
    T = model.thermal.T
    T[0].interpolate(linear)
    T[1].interpolate(lambda x: linear(x) + 50.0)
    points = {"inside": (2e-3, 3e-3, 1.7e-3), "top": (4e-3, 1e-3, 5e-3), "above": (4e-3, 1e-3, 5e-3 + 1e-9),
              "below": (7e-3, 6e-3, -0.3e-3)}
    specs = [ProbeSpec(k, p) for k, p in points.items()] + [ProbeSpec("face0", (3e-3, 3e-3, 0.0), 0),
                                                            ProbeSpec("face1", (3e-3, 3e-3, 0.0), 1)]
    probes = Probes(model.tm, T, specs)
    got = probes.temperatures()
    for name, p in points.items():
        assert got[name] == pytest.approx(linear(p) + (50.0 if p[2] < 0 else 0.0), abs=1e-9), name
    assert got["face0"] == pytest.approx(linear((3e-3, 3e-3, 0.0)), abs=1e-9)
    assert got["face1"] == pytest.approx(linear((3e-3, 3e-3, 0.0)) + 50.0, abs=1e-9)
    assert [(w.body, round(w.depth * 1e3, 9)) for w in probes.located[:2]] == [(0, 1.7), (0, 5.0)]
    assert [w.outside for w in probes.located[1:3]] == [0.0, pytest.approx(1e-9, rel=1e-6)]
    n = model.tm.interface.n_facets                            # the block worn 2 mm deep, the flat not
    assert probes.worn((np.full(n, 2e-3), np.zeros(n))) == [
        "probe inside: 1.7 mm from the interface, where block wore 2 mm: it read material worn away (the bodies "
        "keep their shapes)"]                               # (not face0: it reads the face, a review)
    below = np.linalg.norm(model.tm.interface.midpoints[probes.located[0].facet, :2] - [2e-3, 3e-3])
    assert below == np.linalg.norm(model.tm.interface.midpoints[:, :2] - [2e-3, 3e-3], axis=1).min()
    with pytest.raises(InputError, match=r"output.probes.edge.point: \[3.0, 3.0, 0.0\] mm lies on the faces of both "
                                         r"'block' and 'flat': give output.probes.edge.body"):
        Probes(model.tm, T, [ProbeSpec("edge", (3e-3, 3e-3, 0.0))])
    with pytest.raises(InputError, match=r"output.probes.far.point: \[3.0, 3.0, 9.0\] mm is in neither 'block' nor "
                                         r"'flat': 4 mm outside its meshed surface \('block' spans \[0.0, 0.0, 0.0\] to "
                                         r"\[10.0, 10.0, 5.0\] mm; 'flat'"):
        Probes(model.tm, T, [ProbeSpec("far", (3e-3, 3e-3, 9e-3))])
    with pytest.raises(InputErrors) as both:                  # every probe's problem at once (a review)
        Probes(model.tm, T, [ProbeSpec("far", (3e-3, 3e-3, -0.5e-3), 0),         # in the flat, not the block
                             ProbeSpec("off", (3e-3, 3e-3, 5.5e-3))])            # 0.5 mm above 2.5 mm cells
    assert [e.name for e in both.value.errors] == ["output.probes.far.point", "output.probes.off.point"]
    assert "[3.0, 3.0, -0.5] mm is not in 'block': 0.5 mm outside its meshed surface ('block' spans" in \
        str(both.value.errors[0])
    with pytest.raises(InputError, match="output.probes.spin.turns = True: a rotating body to turn with"):
        Probes(model.tm, T, [ProbeSpec("spin", (3e-3, 3e-3, 1e-3), turns=True)])


def test_a_turning_probe_reads_the_mean_round_its_circle(tmp_path):
    """In the pin-on-disc's rotating disc (P2 temperatures, axis z through the origin) the field
    x^2 + 3 y^2 + 10 z [K per m^2, m] is exact; round the circle of radius r its mean is 2 r^2 + 10 z
    (the 64 points' trapezoidal rule is exact for it) against 1 r^2 + 10 z at the point (r, 0, z)
    fixed in space. One 1 mm below the pin's track, a quarter turn away, is 1 mm from the interfaces'
    track. A point on the true rim, outside the faceted one, is read (how far out is said); a point
    where two parts of a body meet is read in the part named. A turning probe of the pin is refused."""
    model = build_model(loads(pin_on_disc(tmp_path / "pod")))
    T = model.thermal.T
    T[1].interpolate(lambda x: 300.0 + 1e4 * (x[0] ** 2 + 3 * x[1] ** 2) + 10 * x[2])
    r, z = 0.06, -4e-3
    probes = Probes(model.tm, T, [ProbeSpec("embedded", (r, 0.0, z), turns=True), ProbeSpec("rubbing", (r, 0.0, z))],
                    Rotation())
    got = probes.temperatures()
    assert got["embedded"] == pytest.approx(300.0 + 1e4 * 2 * r**2 + 10 * z, abs=1e-9)
    assert got["rubbing"] == pytest.approx(300.0 + 1e4 * r**2 + 10 * z, abs=1e-9)
    assert [w.body for w in probes.located] == [1, 1]
    under = Probes(model.tm, T, [ProbeSpec("under", (0.0, 0.09, -1e-3), turns=True)], Rotation()).located[0]
    assert under.depth == pytest.approx(1e-3, rel=1e-9)          # the track under the pin at (90 mm, 0), its circle's
    rim = 0.1075 * np.array([np.cos(0.17), np.sin(0.17), 0.0]) + [0.0, 0.0, -5e-3]     # on the true rim, between
    where = Probes(model.tm, T, [ProbeSpec("rim", tuple(rim))]).located[0]             # the facets' corners
    assert where.body == 1 and 1e-6 < where.outside < 0.3e-3            # the facets' chords lie inside the circle
    sides = [Probes(model.tm, T, [ProbeSpec("side", (0.08, 0.0, 0.01), 0, part=part)]).located[0].part
             for part in ("pin", "housing")]                 # on the pin's side face in its sleeve: either part's
    assert sides == ["pin", "housing"]
    assert np.linalg.norm(ring((r, 0.0, z), Rotation())[:, :2], axis=1) == pytest.approx(np.full(RING, r))
    with pytest.raises(InputError, match="output.probes.pin.turns = True: a probe of the rotating body 'disc' "
                                         r"\(this one is of 'pin', which does not turn\)"):
        Probes(model.tm, T, [ProbeSpec("pin", (0.09, 0.0, 2e-3), 0, turns=True)], Rotation())


def test_a_probe_in_a_cooling_column_follows_the_series(tmp_path, capsys):
    """The column of ``test_slab_with_convection_on_one_face_against_the_series`` (20 mm, h = 500
    W/(m^2 K) on its top, Bi = 1) with thermocouples 1.3 and 10.3 mm below the top, between nodes:
    their history columns follow Carslaw & Jaeger's series within 0.1 % of T_i - T_a at each of the
    run's steps from Fo = 0.05 to 0.125 (the nodes' own bound at Fo = 0.125; measured 0.09 % at Fo =
    0.05 falling to 0.043 %: backward Euler's error of the first steps, 0.14 % at Fo = 0.0075), and the
    run says where each reads. A resume with a probe moved is refused."""
    values = dict(effects='["contact", "thermal"]', geometry='length = "1 mm"\nwidth = "1 mm"\nheight = "20 mm"\n'
                  'flat_thickness = "1 mm"\nmesh_size = "0.5 mm"', block=STEEL.replace('"50 W', '"10 W'), flat=STEEL,
                  interface="", pressure="1 MPa", end=5.0, steps=100, T0=400.0,
                  boundary='[[boundary]]\nsurfaces = ["block_top"]\nconvection = "500 W/(m^2 K)"\n'
                  'ambient = "300 K"\n[output]\nfigures = false\nfolder = "{folder}"\n'
                  '[output.probes.shallow]\npoint = ["0.4 mm", "0.3 mm", "18.7 mm"]\n'
                  '[output.probes.deep]\npoint = ["0.4 mm", "0.3 mm", "9.7 mm"]\n')
    text = BLOCK.format(**values).replace("{{folder}}", "{folder}")
    h = run(loads(text.format(folder=tmp_path / "col")), verbose=True).history
    late = h["time"] >= 2.0                              # Fo >= 0.05: the first steps carry backward Euler's error
    for name, z in (("shallow", 18.7e-3), ("deep", 9.7e-3)):
        exact = slab_convection(np.array([z]), h["time"][late][:, None], 20e-3, 10.0, 1e-5, 500.0, 400.0, 300.0)
        assert np.abs(h[f"probe_temperature_{name}"][late] - exact.ravel()).max() < 1e-3 * 100, name
    out = capsys.readouterr().out
    assert "probe shallow: in block, 18.7 mm from the interface" in out
    assert "probe deep: in block, 9.7 mm from the interface" in out
    short = text.replace("steps = 100", "steps = 4").format(folder=tmp_path / "stop")
    march(loads(short), verbose=False, stop_after=2)
    moved = loads(short.replace('"9.7 mm"]', '"8.7 mm"]'))   # a column of two places (a review): refused
    with pytest.raises(InputError, match=r"--resume = .*changed since this checkpoint was written \(output.probes.deep"
                                         r".point"):
        march(moved, resume=True, verbose=False)



def test_the_scene_checks_the_probes():
    """A probe's body must be one of the geometry's, only the rotating body's probe turns, its name
    names a history column, and without effect "thermal" or in a squeal analysis the probes are
    ignored with a warning."""
    probe = '[output.probes.{name}]\npoint = ["1 mm", "1 mm", "1 mm"]\n{more}\n'
    text = BLOCK.format(effects="{effects}", geometry='mesh_size = "2.5 mm"', block=STEEL, flat=STEEL, interface="",
                        pressure="1 MPa", end=1.0, steps=1, T0=400.0, boundary="[output]\n{probes}")
    bad = probe.format(name="a", more='body = "pad"') + probe.format(name="b", more="turns = true") + \
        probe.format(name='"c/d"', more="")
    with pytest.raises(SceneError) as e:
        loads(text.format(effects='["contact", "thermal"]', probes=bad))
    assert e.value.problems == ['output.probes.a.body = "pad": not a body or a part; allowed: block, flat',
                                "output.probes.b.turns: the geometry has no rotating body to turn with",
                                "output.probes.c/d: the name must be letters, digits, _ - only (it names files, "
                                "history columns and scene keys)"]
    scene = loads(text.format(effects='["contact"]', probes=probe.format(name="a", more="")))
    assert 'output.probes is ignored: effect "thermal" is not in effects' in scene.warnings
    from multiscale.schema import FrozenMap
    from multiscale.scene_output import Output, Probe, output_problems
    squeal = Output(probes=FrozenMap({"a": Probe(point=(0.0, 0.115, 0.026))}))
    assert output_problems(squeal, ("fixed", "disc"), {}, True, {"contact", "friction", "stability", "thermal"}) == \
        ([], ["output.probes is ignored: the squeal analysis writes no history"])

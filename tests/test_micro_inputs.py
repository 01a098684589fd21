"""Every public argument of the micro API is checked (issue 21): a wrong type, shape, string,
NaN/inf, negative value, float count or seed raises ``InputError`` naming the argument, never a
numpy/Python TypeError, ValueError or AttributeError, and never passes silently (a bool for a
flag, a truncated float for a count). Each case below raised a raw error or was accepted before."""
from pathlib import Path

import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro import fft
from multiscale.micro.asperity import AsperityModel
from multiscale.micro.conduction import ConductionSolver, SeriesKernel, conductance_law
from multiscale.micro.contact import ContactSolver
from multiscale.micro.heat_kernels import Rotation, SpeedProfile, ThermalMaterial, Translation
from multiscale.micro.heating import InterfaceLayer, SteadyHeating, TransientHeating, partition_law
from multiscale.micro.kernels import HalfSpace, ThermalHalfSpace
from multiscale.micro.layered import LayeredElastic, LayeredThermal
from multiscale.micro.laws import LawSpec
from multiscale.micro.layered_asperity import LayeredAsperity, layered_law
from multiscale.micro.plasticity import Hardness
from multiscale.micro.post_analysis import Heating, PostAnalysis
from multiscale.micro.spectrum import fit_power_law, power_spectrum, surface_statistics
from multiscale.micro.surface import Surface, find_asperities, fractal_surface, statistics
from multiscale.micro.wear import simulate_wear, wear_step
from multiscale.micro.zones import cut_zones, generate_zones

DISC, PIN = ThermalMaterial(50.0, 1e-5), ThermalMaterial(5.0, 3.5e-6)
E = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)
S = fractal_surface(16, 1e-4, 0.8, 2, 4, 1e-6, seed=1)
P = np.where(S.heights > S.heights.max() - 1e-6, 1e7, 0.0)       # a pressure field with contact
THERMAL = (ThermalHalfSpace(10.0), ThermalHalfSpace(50.0))
LAYERED = LayeredElastic((1e-6,), (1e9,), (0.3,), 2e9, 0.3)
STEADY = Translation.steady(1.0)


def transient(**k):
    return TransientHeating(**{**dict(shape=(8, 8), dx=1e-5, body1=DISC, body2=PIN, motion=STEADY, dt=1e-4,
                                      n_steps=2), **k})


def run(**k):
    return TransientHeating(S.shape, S.dx, DISC, PIN, STEADY, 1e-4, 2).run(**{**dict(pressure=P, mu=0.4), **k})


def steady(**k):
    return SteadyHeating(**{**dict(shape=(8, 8), dx=1e-5, body1=DISC, body2=PIN, speed=1.0), **k})


def steady_solve(**k):
    return SteadyHeating(S.shape, S.dx, DISC, PIN, 1.0).solve(**{**dict(pressure=P, mu=0.4), **k})


def conduction(**k):
    return ConductionSolver(*THERMAL, S.shape, S.dx).solve(**{**dict(contact=P > 0), **k})


def law(**k):
    return conductance_law(**{**dict(surface=S, elastic=E, thermal=THERMAL, pressures=[1e6]), **k})


def wear(**k):
    return wear_step(**{**dict(surface=S, pressure=P, k_w=1e-15, mu=0.4, distance=1e-3), **k})


def worn(**k):
    return simulate_wear(**{**dict(surface=S, contact=E, load=1e7, mu=0.4, distance=1e-3, steps=1, k_w=1e-15), **k})


def asperities(**k):
    return AsperityModel.from_surface(**{**dict(surface=S, solid=E), **k})


def asperity_solve(**k):
    return AsperityModel.from_surface(S, E).solve(**{**dict(delta=1e-7), **k})


CASES = [
    # heating: motions, layers, solvers
    (lambda **k: SpeedProfile.constant(**{"value": 1.0, **k}), dict(value="1"), "value"),
    (lambda **k: SpeedProfile.ramp(**{**dict(start=1.0, end=0.0, duration=1.0), **k}), dict(start=None), "start"),
    (lambda **k: SpeedProfile(**{**dict(times=(0.0, 1.0), values=(1.0, 2.0)), **k}), dict(times=("0", "a")), "times"),
    (lambda **k: Translation(**{**dict(profile=SpeedProfile.constant(1.0)), **k}), dict(profile=1.0), "profile"),
    (lambda **k: Translation(**{**dict(profile=SpeedProfile.constant(1.0)), **k}), dict(angle=np.nan), "angle"),
    (lambda **k: Translation.steady(**{"speed": 1.0, **k}), dict(speed="fast"), "speed"),
    (lambda **k: Rotation(**{**dict(centre=(0.0, -0.1), profile=SpeedProfile.constant(1.0)), **k}), dict(centre="x"),
     "centre"),
    (lambda **k: InterfaceLayer(**k), dict(n=2.5), "n"),
    (lambda **k: InterfaceLayer(**k), dict(resistance="x"), "resistance"),
    (lambda **k: InterfaceLayer(**k), dict(plane="middle"), "plane"),
    (transient, dict(shape=(8, 8.5)), "shape"),
    (transient, dict(body1="steel"), "body1"),
    (transient, dict(body2=None), "body2"),
    (transient, dict(motion=1.0), "motion"),
    (transient, dict(n_steps=2.5), "n_steps"),
    (run, dict(pressure="x"), "pressure"),
    (run, dict(max_iter=np.nan), "max_iter"),
    (run, dict(n_steps="2"), "n_steps"),
    (run, dict(partial="no"), "partial"),
    (run, dict(field_times=["a"]), "field_times"),
    (run, dict(interface="thin"), "interface"),
    (steady, dict(body1=1.0), "body1"),
    (steady, dict(angle="x"), "angle"),
    (run, dict(remote_temperatures=(300.0, 310.0, 320.0)), "remote_temperatures"),
    (run, dict(remote_temperatures=300.0), "remote_temperatures"),
    (run, dict(remote_temperatures=("300", "310")), "remote_temperatures"),
    (steady_solve, dict(remote_temperatures=(0.0,)), "remote_temperatures"),
    (steady_solve, dict(max_iter=10.5), "max_iter"),
    (steady_solve, dict(partial=None), "partial"),
    (lambda **k: partition_law(**{**dict(source=S, body1=DISC, body2=PIN, speed=[1.0], pressures=[1e7], mu=0.4,
                                         elastic=E), **k}), dict(elastic="steel"), "elastic"),
    # conductance
    (lambda **k: ConductionSolver(**{**dict(kernel_1=THERMAL[0], kernel_2=THERMAL[1], shape=(8, 8), dx=1e-5), **k}),
     dict(kernel_1=10.0), "kernel_1"),
    (conduction, dict(contact="x"), "contact"),
    (conduction, dict(resistance=["a"]), "resistance"),
    (conduction, dict(theta_1="hot"), "theta_1"),
    (conduction, dict(max_iter=np.inf), "max_iter"),
    (conduction, dict(partial="yes"), "partial"),
    (law, dict(surface=S.heights), "surface"),
    (law, dict(elastic=None), "elastic"),
    (law, dict(pressures="1e6"), "pressures"),
    (law, dict(thermal_tol=np.nan), "thermal_tol"),
    # wear
    (wear, dict(surface=None), "surface"),
    (wear, dict(pressure="x"), "pressure"),
    (worn, dict(steps=np.nan), "steps"),
    (worn, dict(load="1e7"), "load"),
    (worn, dict(contact="steel"), "contact"),
    (worn, dict(progress="no"), "progress"),
    # asperity models
    (asperities, dict(surface=S.heights), "surface"),
    (asperities, dict(solid="steel"), "solid"),
    (asperities, dict(shape=np.ones(2)), "shape"),
    (asperity_solve, dict(route=["energy"]), "route"),
    (asperity_solve, dict(max_iter="50"), "max_iter"),
    (asperity_solve, dict(partial=np.nan), "partial"),
    (lambda **k: AsperityModel(find_asperities(S), AsperityModel.from_surface(S, E).law, surface=S, **k),
     dict(interaction="no"), "interaction"),
    (lambda **k: LayeredAsperity(**{**dict(kernel=LAYERED, a_max=1e-5), **k}), dict(nodes=8.5), "nodes"),
    (lambda **k: layered_law(**{**dict(table=find_asperities(S), kernel=LAYERED, a_max=1e-5, r_max=1e-4), **k}),
     dict(table=None), "table"),
    # surfaces, layered solids, zones, threads
    (lambda **k: Surface(**{**dict(heights=S.heights, dx=S.dx, dy=S.dy), **k}), dict(heights="x"), "heights"),
    (lambda **k: Surface(**{**dict(heights=S.heights, dx=S.dx, dy=S.dy), **k}), dict(periodic="no"), "periodic"),
    (lambda **k: statistics(**k), dict(surface=np.zeros((8, 8))), "surface"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(points_per_decade="10"), "points_per_decade"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(points_per_decade=np.nan), "points_per_decade"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(surface=S.heights), "surface"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(surface=Surface(np.stack([S.heights] * 2), S.dx, S.dy)),
     "surface"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(edges="x"), "edges"),
    (lambda **k: power_spectrum(**{"surface": S, **k}), dict(edges=[1e5, 1e4, 1e6]), "edges"),
    (lambda **k: surface_statistics(**k), dict(surface=S.heights), "surface"),
    (lambda **k: fit_power_law(**{"spectrum": power_spectrum(S), **k}), dict(spectrum=np.ones(8)), "spectrum"),
    (lambda **k: fit_power_law(**{"spectrum": power_spectrum(S), **k}), dict(step=0), "step"),
    (lambda **k: fit_power_law(**{"spectrum": power_spectrum(S), **k}), dict(full_weight=0), "full_weight"),
    (lambda **k: find_asperities(**k), dict(surface=None), "surface"),
    (lambda **k: fractal_surface(**{**dict(n=16, size=1e-3, hurst=0.8, k_min=2, k_max=4, rms=1e-6), **k}),
     dict(hurst="0.8"), "hurst"),
    (lambda **k: fractal_surface(**{**dict(n=16, size=1e-3, hurst=0.8, k_min=2, k_max=4, rms=1e-6), **k}),
     dict(size=(1e-3, 1e-3, 1e-3)), "size"),
    (lambda **k: LayeredElastic(**{**dict(thickness=(1e-6,), E=(1e9,), nu=(0.3,)), **k}), dict(E=("a",)), "E"),
    (lambda **k: LayeredElastic(**{**dict(thickness=(1e-6,), E=(1e9,), nu=(0.3,)), **k}), dict(substrate_nu="x"),
     "substrate_nu"),
    (lambda **k: LayeredThermal(**{**dict(thickness=(1e-6,), kappa=(1.0,)), **k}), dict(substrate_kappa=None),
     "substrate_kappa"),
    (lambda **k: LayeredElastic.graded(**{**dict(E=1e9, nu=0.3, depth=1e-5, n_layers=2), **k}), dict(n_layers=np.inf),
     "n_layers"),
    (lambda **k: LayeredElastic.graded(**{**dict(E=1e9, nu=0.3, depth=1e-5, n_layers=2), **k}), dict(n_layers=None),
     "n_layers"),
    (lambda **k: LayeredElastic.graded(**{**dict(E=1e9, nu=0.3, depth=1e-5, n_layers=2), **k}), dict(nu="0.3"), "nu"),
    (lambda **k: cut_zones(**{**dict(surface=S, counts=(2, 2)), **k}), dict(counts=(2, 2.5)), "counts"),
    (lambda **k: cut_zones(**{**dict(surface=S, counts=(2, 2)), **k}), dict(origin=np.nan), "origin"),
    (lambda **k: generate_zones(**{**dict(grid=cut_zones(S, (2, 2))[0], n=8, hurst=0.8, k_min=1, k_max=3,
                                          rms=1e-6), **k}), dict(seed=1.5), "seed"),
    (lambda **k: generate_zones(**{**dict(grid=cut_zones(S, (2, 2))[0], n=8, hurst=0.8, k_min=1, k_max=3,
                                          rms=1e-6), **k}), dict(grid=(2, 2)), "grid"),
    (lambda **k: fft.set_threads(**k), dict(n="2"), "n"),
    (lambda **k: Surface(**{**dict(heights=S.heights, dx=1e-6, dy=1e-6), **k}), dict(heights=S.heights > 0),
     "heights"),                                      # (read as 1 m and 0 m: a user trial)
    # a kernel of the other kind: a thermal one taken as elastic put a patch in full contact, an elastic one
    # taken as thermal gave K_t 18750 for 17046 W/(m^2 K), without a word (a user trial)
    (lambda **k: ContactSolver(**{**dict(kernel=E, shape=(8, 8), dx=1e-5), **k}), dict(kernel=THERMAL[0]), "kernel"),
    (lambda **k: ConductionSolver(**{**dict(kernel_1=THERMAL[0], kernel_2=THERMAL[1], shape=(8, 8), dx=1e-5), **k}),
     dict(kernel_1=E), "kernel_1"),
    (lambda **k: SeriesKernel(**{**dict(first=E, second=E), **k}), dict(second=THERMAL[1]), "second"),
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(kernel=THERMAL[0]), "kernel"),
    (lambda **k: AsperityModel.from_surface(**{**dict(surface=S, solid=E), **k}), dict(solid=THERMAL[0]), "solid"),
    # zone laws
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(kernel="steel"), "kernel"),
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(n_points=4.5), "n_points"),
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(max_iter=np.nan), "max_iter"),
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(batch_cells="many"), "batch_cells"),
    (lambda **k: LawSpec(**{**dict(kernel=E, p_max=1e6), **k}), dict(love=["average"]), "love"),
    # post-analysis
    (lambda **k: Heating(**{**dict(moving=DISC, fixed=PIN), **k}), dict(moving=50.0), "moving"),
    (lambda **k: Heating(**{**dict(moving=DISC, fixed=PIN), **k}), dict(speed_step=np.nan), "speed_step"),
    (lambda **k: PostAnalysis(**{**dict(kernel=E, shape=(8, 8), dx=1e-5, dy=1e-5, mu=0.4), **k}), dict(heating="hot"),
     "heating"),
    (lambda **k: PostAnalysis(**{**dict(kernel=E, shape=(8, 8), dx=1e-5, dy=1e-5, mu=0.4), **k}), dict(max_iter=np.nan),
     "max_iter"),
    (lambda **k: PostAnalysis(**{**dict(kernel=E, shape=(8, 8), dx=1e-5, dy=1e-5, mu=0.4), **k}), dict(substeps="2"),
     "substeps"),
]


@pytest.mark.parametrize("make, bad, name", CASES, ids=[f"{i}-{c[2]}" for i, c in enumerate(CASES)])
def test_every_public_argument_is_checked_and_named(make, bad, name):
    with pytest.raises(InputError) as info:
        make(**bad)
    assert info.value.name.split(".")[0] == name


def test_the_valid_calls_of_the_cases_work():
    """The base arguments of the cases above are valid (a case fails on its bad argument only)."""
    transient()
    steady()
    run(n_steps=1, field_times=[1e-4])
    steady_solve()
    conduction()
    wear()
    asperity_solve()
    assert fft.get_threads() >= 1
    fft.set_threads(fft.get_threads())


def test_post_analysis_without_friction_has_no_heat():
    """mu = 0 (a scene's loading.friction = 0) is no frictional heat, as a zone at rest: the bulk
    temperatures, zero heat, no partition (NaN) and no wear; it was an InputError of the heating
    ('mu = np.float64(0.0): must be finite and > 0') after the laws of a rough run."""
    zones = cut_zones(S, (1, 1))[1]
    for conduction_on in (False, True):
        post = PostAnalysis(E, zones[0].shape, S.dx, S.dy, mu=0.0, wear_rate=1e-14,
                            heating=Heating(DISC, PIN, conduction=conduction_on))
        r = post.run(zones, [1e6], speed=2.0, remote=[[300.0, 310.0]], sliding=[1e-3])
        assert r.heat[0] == 0.0 and r.heat_rough[0] == 0.0 and np.isnan(r.partition[0])
        assert r.max_temperature[0] == 310.0 and np.all(r.temperature == 310.0) and np.all(r.counter_temperature == 300.0)
        assert r.volume[0] == 0.0 and np.all(np.isfinite(r.pressure))
    with pytest.raises(InputError, match="mu"):
        post.run(zones, [1e6], speed=2.0, remote=[[300.0, 310.0]], mu=[-0.1])
    for remote in ([[300.0, np.nan]], [300.0, 310.0, 320.0], "hot"):    # before: NaN ran, the others numpy's errors
        with pytest.raises(InputError) as info:
            post.run(zones, [1e6], speed=2.0, remote=remote)
        assert info.value.name.split(".")[0] == "remote"


def test_a_zone_loaded_at_or_above_the_hardness_is_named():
    """A zone mean pressure >= H (laws tabulated to 0.9 H, extrapolated beyond) is refused naming
    the hardness, the zone and the pressures, not as the solver's 'load = array([...])'."""
    zones = cut_zones(S, (2, 1))[1]
    post = PostAnalysis(E, zones[0].shape, S.dx, S.dy, mu=0.4, hardness=Hardness(1e6))
    with pytest.raises(InputError, match=r"hardness: 1 zone\(s\) .*zone 1: 1.2e\+06 Pa against H = 1e\+06 Pa"):
        post.run(zones, [5e5, 1.2e6], speed=1.0)
    assert np.all(post.run(zones, [5e5, 9e5], speed=1.0).max_pressure <= 1e6)


def test_zones_of_two_grids_are_post_analysed_each_on_its_own():
    """Two pads whose zones differ in cell size (a round puck's 352.6 um beside a square pad's
    312.5 um, a user trial): every zone took the first grid's cells, so the second pad's heat and
    worn volume came out 1.27 times too large. ``PostAnalyses`` hands each zone to its grid's
    post-analysis: the results are those of each grid's own to round-off, in the zones' order, and
    the heat rate is mu P A V of each patch; a zone of another grid is refused by a PostAnalysis."""
    from multiscale.micro.post_analysis import PostAnalyses, grid_of
    from multiscale.micro.zones import Zone
    a = cut_zones(S, (2, 1))[1]
    wide = Surface(S.heights, 1.2 * S.dx, 1.2 * S.dy, periodic=False)
    b = [Zone(10 + z.id, z.surface) for z in cut_zones(wide, (2, 1))[1]]
    settings = dict(mu=0.4, heating=Heating(DISC, PIN), wear_rate=1e-14)
    own = {grid_of(z[0]): PostAnalysis(E, z[0].shape, z[0].surface.dx, z[0].surface.dy, **settings) for z in (a, b)}
    posts = PostAnalyses(own)
    zones = [a[0], b[0], a[1], b[1]]
    load, speed, remote = np.array([1e6, 2e6, 3e6, 4e6]), np.array([1.0, 2.0, 1.5, 2.5]), np.full((4, 2), 300.0)
    mixed = posts.run(zones, load, speed=speed, remote=remote)
    worn = posts.wear(zones, mixed, np.full(4, 1e-3), remote)
    for ids, z in (([0, 2], a), ([1, 3], b)):
        alone = own[grid_of(z[0])].run([zones[i] for i in ids], load[ids], speed=speed[ids], remote=remote[ids])
        np.testing.assert_allclose(mixed.heat[ids], alone.heat, rtol=1e-12)
        np.testing.assert_allclose(mixed.pressure[ids], alone.pressure, rtol=1e-12, atol=1e-12 * load.max())
        area = z[0].surface.size[0] * z[0].surface.size[1]
        np.testing.assert_allclose(alone.heat, 0.4 * load[ids] * area * speed[ids], rtol=1e-9)
        np.testing.assert_allclose(worn.volume[ids], own[grid_of(z[0])].wear(
            [zones[i] for i in ids], alone, np.full(2, 1e-3), remote[ids]).volume, rtol=1e-12)
    with pytest.raises(InputError, match="cells"):
        own[grid_of(a[0])].run([b[0]], [1e6], speed=1.0, remote=[[300.0, 300.0]])


@pytest.mark.parametrize("text, threads, said", [("abc", 1, True), ("0", 1, True), ("-3", 1, True),
                                                  ("2.5", 1, True), ("2", 2, False), (" 3 ", 3, False)])
def test_the_threads_of_the_environment_are_a_whole_number_or_said(monkeypatch, recwarn, text, threads, said):
    """MULTISCALE_THREADS=abc made the import a raw ValueError, 0 and -3 were 1 unsaid (a user trial)."""
    monkeypatch.setenv("MULTISCALE_THREADS", text)
    assert fft._environment_threads() == threads
    assert [str(w.message) for w in recwarn] == ([f"MULTISCALE_THREADS = {text!r} is not a whole number of "
                                                  "threads >= 1: FFTs take 1 thread"] if said else [])


def test_a_measurement_given_for_heights_is_told_what_to_give():
    """A Measurement as read, given to solve_contact, was only "must be an array of numbers" (a user trial)."""
    from multiscale.micro.contact import solve_contact
    from multiscale.micro.reading import Measurement
    m = Measurement(S.heights, 1e-6, 1e-6, Path("afm.top"))
    with pytest.raises(InputError, match=r"a measurement as read\? give its conditioned surface, "
                                         r"topography.condition\(m\).surface"):
        solve_contact(m, kernel=E, load=1e6)

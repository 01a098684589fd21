"""Plasticity in the zone machinery (issue 18): the post-analysis keeps the permanent
deformation of the zones (H or H(T)), the laws of a deformed zone are its elastic reloading curve
below the previous maximum and the plastic loading curve above it."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.laws import LawSpec, compute_laws
from multiscale.micro.plasticity import Hardness
from multiscale.micro.post_analysis import PostAnalysis
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.zones import cut_zones

KERNEL = HalfSpace.from_materials(5e9, 0.3, 220e9, 0.3)


@pytest.fixture(scope="module")
def zones():
    s = fractal_surface(32, 1e-3, 0.8, 1, 8, 2e-6, seed=2)
    return cut_zones(Surface(s.heights, s.dx, s.dy, periodic=False), (2, 1))[1]


def test_post_analysis_keeps_the_permanent_deformation(zones):
    z0 = zones[0]
    P = np.array([2e6, 4e6])
    elastic = PostAnalysis(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, mu=0.4).run(zones, P, speed=1.0)
    assert np.all(elastic.plastic_area_fraction == 0)
    np.testing.assert_array_equal(elastic.heights, np.stack([z.surface.heights for z in zones]))
    H = 0.5 * elastic.max_pressure.min()
    post = PostAnalysis(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, mu=0.4, hardness=Hardness(H))
    r = post.run(zones, P, speed=1.0)
    assert np.all(r.plastic_area_fraction > 0) and np.all(r.max_pressure == H)
    before = np.stack([z.surface.heights for z in zones])
    assert np.all(r.heights <= before) and np.all(np.any(r.heights < before, axis=(1, 2)))
    deformed = [z.with_heights(h) for z, h in zip(zones, r.heights)]
    again = post.run(deformed, P, speed=1.0, warm=r.worn_pressure)      # the same load: no new yield
    assert np.abs(again.heights - r.heights).max() < 1e-9 * np.abs(before - r.heights).max()
    np.testing.assert_allclose(again.pressure, r.pressure, rtol=0, atol=1e-7 * H)
    # H(T) at the rough body's temperature: the hotter zone is softer and yields more
    soft = PostAnalysis(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, mu=0.4,
                        hardness=Hardness(([300.0, 600.0], [H, 0.5 * H])))
    hot = soft.run([zones[0]] * 2, [3e6] * 2, speed=1.0, remote=[[300.0, 300.0], [300.0, 500.0]])
    assert hot.plastic_area_fraction[1] > hot.plastic_area_fraction[0]
    assert hot.max_pressure[0] == pytest.approx(H) and hot.max_pressure[1] == pytest.approx(H * (1 - 1 / 3))
    same = soft.run([zones[0]] * 2, [3e6] * 2, speed=1.0, hardness_temperature=[300.0, 500.0])
    np.testing.assert_array_equal(same.pressure, hot.pressure)
    with pytest.raises(InputError, match="remote"):
        soft.run(zones, P, speed=1.0)


def test_laws_of_a_deformed_zone_reload_elastically_then_load_plastically(zones):
    z0 = zones[0]
    spec = LawSpec(KERNEL, p_max=8e6, n_points=8)
    H = 0.3 * PostAnalysis(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, mu=0.4).run(
        zones[:1], [8e6], speed=1.0).max_pressure[0]
    plastic = LawSpec(KERNEL, p_max=8e6, n_points=8, hardness=H)
    virgin_el, virgin_pl = (compute_laws(zones[:1], s).nodes[0] for s in (spec, plastic))
    assert np.all(virgin_pl.gap[1:] < virgin_el.gap[1:])    # yielding: the flat goes further at each load
    peak = 4e6
    post = PostAnalysis(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, mu=0.4, hardness=Hardness(H))
    deformed = z0.with_heights(post.run(zones[:1], [peak], speed=1.0).heights[0])
    reload = compute_laws([deformed], plastic).nodes[0]
    solver = ContactSolver(KERNEL, z0.shape, z0.surface.dx, z0.surface.dy, periodic=False)
    elastic = solver.solve(np.broadcast_to(deformed.surface.heights, (8,) + z0.shape), approach=reload.approach,
                           tol=1e-10).mean_pressure
    below = reload.pressure < 0.99 * peak
    assert below.sum() >= 3 and not below.all()
    np.testing.assert_allclose(reload.pressure[below], elastic[below], rtol=1e-6)    # the elastic reload
    assert np.all(reload.pressure[~below] < 0.99 * elastic[~below])                 # above: new yield
    with pytest.raises(InputError, match="p_max"):
        LawSpec(KERNEL, p_max=8e6, hardness=5e6)


def test_a_zone_whose_touching_cells_all_flow_gets_a_monotone_law():
    """A cell 2 um proud of a smooth dome, H = 3 MPa: it flows alone at H over the first two
    approach-spaced nodes (the same pressure twice: a staircase of the grid, which made no law and
    failed as 'lower p_max'); the repeat is re-solved under load control between its neighbours,
    and every node is a point of the discrete law (a displacement-controlled solve at its approach
    gives its pressure)."""
    n, dx, H = 16, 78e-6, 3e6
    x = (np.arange(n) - n / 2) * dx
    h = -(x[:, None] ** 2 + x[None, :] ** 2) * 100.0
    h[n // 2, n // 2] += 2e-6
    zone = cut_zones(Surface(h, dx, dx, periodic=False), (1, 1))[1][0]
    solver = ContactSolver(KERNEL, zone.shape, dx, dx, periodic=False)
    spec = LawSpec(KERNEL, p_max=0.9 * H, n_points=10, hardness=H)
    nodes = compute_laws([zone], spec).nodes[0]
    cell = H / n**2                                   # one flowing cell's share of the zone pressure
    first_two = solver.solve(np.broadcast_to(h, (2, n, n)), approach=nodes.approach[-1] * np.array([0.01, 0.04]),
                             tol=1e-10, hardness=H).mean_pressure
    np.testing.assert_allclose(first_two, [cell, cell], rtol=1e-12)        # the plateau
    assert np.all(np.diff(nodes.pressure) > 0) and np.all(np.diff(nodes.gap) < 0)
    assert nodes.pressure[0] == pytest.approx(cell, rel=1e-12)
    assert nodes.pressure[1] == pytest.approx(np.sqrt(nodes.pressure[0] * nodes.pressure[2]), rel=1e-6)
    again = solver.solve(np.broadcast_to(h, (10, n, n)), approach=nodes.approach, tol=1e-10, hardness=H)
    np.testing.assert_allclose(again.mean_pressure, nodes.pressure, rtol=1e-8)

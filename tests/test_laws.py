"""Homogenized zone laws (thesis §1.4.2, Eqs. 1.29–1.31): Love/Boussinesq integrals, consistency of
a flat macro interface with the micro model, law smoothness, zones, the serial pool."""
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from numpy.polynomial.legendre import leggauss
from scipy import integrate

from multiscale.errors import InputError
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.law_tables import PressureGapLaw, PressureTable
from multiscale.micro.laws import (RESOLUTION, Conductance, ExtraLaw, HeatPartition, LawError, LawSpec, compute_laws,
                                   resolved_gap)
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.zones import Zone, ZoneGrid, cut_triangles, cut_zones, generate_zones
from multiscale.references.love import (love_rectangle, love_rectangle_mean, love_triangle, love_triangle_mean,
                                        triangle_area)

E = HalfSpace(1e9)


# --------------------------------------------------------------------------- helpers
def gauss_square(n):
    x, w = leggauss(n)
    return x, w


def mean_over_rectangle(f, xc, yc, a, b, n=24, pieces=4):
    """Mean of f(x, y) over |x - xc| < a, |y - yc| < b by composite Gauss-Legendre quadrature."""
    x, w = gauss_square(n)
    edges_x = np.linspace(xc - a, xc + a, pieces + 1)
    edges_y = np.linspace(yc - b, yc + b, pieces + 1)
    total = 0.0
    for x0, x1 in zip(edges_x[:-1], edges_x[1:]):
        for y0, y1 in zip(edges_y[:-1], edges_y[1:]):
            X = (x0 + x1) / 2 + (x1 - x0) / 2 * x
            Y = (y0 + y1) / 2 + (y1 - y0) / 2 * x
            total += np.sum(w[:, None] * w[None, :] * f(X[None, :], Y[:, None])) * (x1 - x0) * (y1 - y0) / 4
    return total / (4 * a * b)


def triangle_rule(V, levels, order=6):
    """Points and weights on a triangle: 4**levels congruent sub-triangles, collapsed Gauss rule."""
    x, w = leggauss(order)
    x, w = (x + 1) / 2, w / 2
    U, W = np.meshgrid(x, x, indexing="ij")
    u, v, ww = U.ravel(), (W * (1 - U)).ravel(), (np.outer(w, w) * (1 - U)).ravel()
    tris = [np.asarray(V, float)]
    for _ in range(levels):
        nxt = []
        for A, B, C in tris:
            ab, bc, ca = (A + B) / 2, (B + C) / 2, (C + A) / 2
            nxt += [np.array(t) for t in ((A, ab, ca), (ab, B, bc), (ca, bc, C), (ab, bc, ca))]
        tris = nxt
    pts, wts = [], []
    for A, B, C in tris:
        J = abs((B - A)[0] * (C - A)[1] - (B - A)[1] * (C - A)[0])
        pts.append(A + u[:, None] * (B - A) + v[:, None] * (C - A))
        wts.append(ww * J)
    return np.concatenate(pts), np.concatenate(wts)


def flat_zone_pressure(law_fn, top, c, delta):
    """Macro model of one flat zone under a rigid approach delta: the uniform pressure p with
    p = law(top - delta + c p), c = L/(pi E*) (Love displacement of the uniformly loaded zone)."""
    delta = np.atleast_1d(delta).astype(float)
    p = np.zeros_like(delta)
    for _ in range(100):
        v = law_fn(top - delta + c * p)
        F = p - v.pressure
        p = np.maximum(p - F / (1 + c * v.stiffness), 0.0)
        if np.all(np.abs(F) <= 1e-14 * np.maximum(p, 1e-300)):
            break
    return p


def flat_interface_pressures(laws, ids, C, s_flat):
    """Macro model of a flat interface of zones with uniform pressures p_i:
    p_i = law_i(s_flat + sum_j C_ij p_j), solved by damped Newton."""
    p = np.zeros(len(ids))
    for _ in range(200):
        v = laws.pressure(s_flat + C @ p, ids)
        F = p - v.pressure
        if np.abs(F).max() <= 1e-12 * max(v.pressure.max(), 1.0):
            break
        dp = np.linalg.solve(np.eye(len(ids)) + v.stiffness[:, None] * C, -F)
        lam = 1.0
        while True:
            trial = np.maximum(p + lam * dp, 0.0)
            if np.linalg.norm(trial - laws.pressure(s_flat + C @ trial, ids).pressure) < np.linalg.norm(F) \
                    or lam < 1e-6:
                break
            lam /= 2
        p = trial
    return p


# --------------------------------------------------------------------------- Love / Boussinesq
def test_love_rectangle_mean_closed_form_vs_quadrature():
    assert love_rectangle_mean(0.5, 0.5) == pytest.approx(2.97320, abs=1e-5)   # unit square
    for a, b in ((1.0, 1.0), (0.3, 1.7), (2e-3, 5e-4)):
        quad = mean_over_rectangle(lambda x, y: love_rectangle(x, y, a, b), 0.0, 0.0, a, b)
        assert love_rectangle_mean(a, b) == pytest.approx(quad, rel=2e-6)
        # the mean lies between the corner and centre values
        assert love_rectangle(a - 1e-15 * a, b - 1e-15 * b, a, b) < love_rectangle_mean(a, b) \
            < love_rectangle(0.0, 0.0, a, b)


def test_love_triangle_field_vs_independent_quadrature():
    V = np.array([[0.0, 0.0], [1.3, 0.2], [0.4, 0.9]])
    J = abs((V[1] - V[0])[0] * (V[2] - V[0])[1] - (V[1] - V[0])[1] * (V[2] - V[0])[0])
    for P in ([2.0, 1.0], [-0.7, 0.4], [0.6, -0.5], [1.0, 0.9]):      # outside: smooth integrand
        f = lambda v, u: J / np.hypot(*(V[0] + u * (V[1] - V[0]) + v * (V[2] - V[0]) - P))  # noqa: E731
        ref, _ = integrate.dblquad(f, 0, 1, 0, lambda u: 1 - u, epsabs=0, epsrel=1e-12)
        assert love_triangle(P[0], P[1], V) == pytest.approx(ref, rel=1e-10)
    # inside: split the triangle at P into three with P as a vertex (polar integral is exact there)
    P = np.array([0.55, 0.35])
    total = 0.0
    for A, B in ((V[0], V[1]), (V[1], V[2]), (V[2], V[0])):
        phi = lambda t: np.hypot(*((1 - t) * A + t * B - P))  # noqa: E731
        h = abs((B - A)[0] * (P - A)[1] - (B - A)[1] * (P - A)[0]) / np.hypot(*(B - A))
        # dA/r in polar coordinates about P: integral of r_max(theta) dtheta, dtheta = h |AB| dt / r²
        total += integrate.quad(lambda t: h * np.hypot(*(B - A)) / phi(t), 0, 1, epsabs=0, epsrel=1e-13)[0]
    assert love_triangle(P[0], P[1], V) == pytest.approx(total, rel=1e-10)
    # two triangles of a rectangle add up to Love's rectangle, at any point, any orientation
    a, b = 0.7, 0.4
    R = np.array([[-a, -b], [a, -b], [a, b], [-a, b]])
    x = np.array([0.1, 1.5, -0.69, 0.0])
    y = np.array([-0.2, 0.3, 0.39, 0.0])
    both = love_triangle(x, y, R[[0, 1, 2]]) + love_triangle(x, y, R[[0, 2, 3]][::-1])
    np.testing.assert_allclose(both, love_rectangle(x, y, a, b), rtol=1e-13)


def test_love_triangle_mean_closed_form_vs_quadrature():
    for V in (np.array([[0.0, 0.0], [1.3, 0.2], [0.4, 0.9]]), np.array([[0, 0], [1, 0], [0, 1e-1]]) * 3e-3):
        q4, q5 = (np.sum(w * love_triangle(pts[:, 0], pts[:, 1], V)) / triangle_area(V)
                  for pts, w in (triangle_rule(V, levels=4), triangle_rule(V, levels=5)))
        assert love_triangle_mean(V) == pytest.approx((4 * q5 - q4) / 3, rel=1e-7)   # O(h²): Richardson
    with pytest.raises(InputError, match="degenerate"):
        love_triangle_mean([[0, 0], [1, 1], [2, 2]])


# --------------------------------------------------------------------------- laws
@pytest.fixture(scope="module")
def tiled():
    """A 128 x 128 surface (many asperities per zone, as in thesis §1.5) cut into 4 x 4 zones."""
    s = fractal_surface(128, 1e-3, 0.8, 16, 32, 1e-6, seed=1)
    grid, zones = cut_zones(s, (4, 4))
    return s, grid, zones


@pytest.fixture(scope="module")
def laws_by_love(tiled):
    _, _, zones = tiled
    return {love: compute_laws(zones, LawSpec(E, p_max=3e6, love=love)) for love in ("average", "centre", "none")}


@pytest.mark.parametrize("love", ["average", "centre"])
def test_one_zone_flat_interface_carries_the_micro_force(tiled, laws_by_love, love):
    """Eq. 1.31 by construction: at every node's rigid approach, the flat zone loaded by its law
    (displacement L p/(pi E*) with the same L) carries the micro force."""
    _, _, zones = tiled
    laws = laws_by_love[love]
    for z in zones[:3]:
        nd = laws.nodes[list(laws.ids).index(z.id)]
        c = z.love(love) / (np.pi * E.E_star)
        assert nd.compliance == c
        p = flat_zone_pressure(lambda g: laws.pressure(g, np.full(np.shape(g), z.id)), z.top, c, nd.approach)
        np.testing.assert_allclose(p * z.area, nd.pressure * z.area, rtol=1e-10)
        # the node pressure is the micro force over the zone area
        r = ContactSolver(E, z.shape, z.surface.dx, periodic=False).solve(
            z.surface.heights, approach=nd.approach[7], tol=1e-8)
        assert r.mean_pressure == pytest.approx(nd.pressure[7], rel=1e-6)


def test_law_between_nodes_follows_the_micro_model(tiled, laws_by_love):
    """Interpolation error of a 20-node law at approaches between the nodes, above 1 % of p_max
    (below, a few grid cells carry the load and p(delta) has kinks at each new contact)."""
    _, _, zones = tiled
    laws = laws_by_love["average"]
    z = zones[5]
    nd = laws.nodes[list(laws.ids).index(z.id)]
    mid = np.sqrt(nd.approach[1:] * nd.approach[:-1])
    r = ContactSolver(E, z.shape, z.surface.dx, periodic=False).solve(
        np.repeat(z.surface.heights[None], len(mid), 0), approach=mid, tol=1e-8)
    p = flat_zone_pressure(lambda g: laws.pressure(g, np.full(np.shape(g), z.id)), z.top, nd.compliance, mid)
    upper = r.mean_pressure > 0.01 * 3e6
    assert upper.sum() >= 12
    assert np.max(np.abs(p[upper] / r.mean_pressure[upper] - 1)) < 0.04


def test_zones_tiling_a_surface_match_one_big_micro_solve(tiled, laws_by_love):
    """Thesis Fig. 1.14: sum of zone forces of the flat macro interface vs the micro solve of the
    whole surface, 0–3 %; without the Love correction the zone's own compliance counts twice."""
    s, grid, zones = tiled
    ids = np.array([z.id for z in zones])
    deltas = np.array([1.0, 1.6, 2.2, 2.8]) * 1e-6
    big = ContactSolver(E, s.shape, s.dx, periodic=False).solve(
        np.repeat(s.heights[None], len(deltas), 0), approach=deltas, tol=1e-8)
    a, b = grid.size[0] / 2, grid.size[1] / 2
    centre = np.array([z.centre for z in zones])
    dx_, dy_ = centre[:, None, 0] - centre[None, :, 0], centre[:, None, 1] - centre[None, :, 1]
    # Galerkin: mean displacement of zone i under unit pressure on zone j; collocation: at its centre
    galerkin = np.array([[mean_over_rectangle(lambda x, y: love_rectangle(x, y, a, b), dx_[i, j], dy_[i, j], a, b,
                                              n=12, pieces=2) for j in range(len(zones))] for i in range(len(zones))])
    np.testing.assert_allclose(np.diag(galerkin), love_rectangle_mean(a, b), rtol=1e-4)
    np.fill_diagonal(galerkin, love_rectangle_mean(a, b))
    collocation = love_rectangle(dx_, dy_, a, b)
    errors = {}
    for love, C in (("average", galerkin), ("centre", collocation), ("none", galerkin)):
        F = [flat_interface_pressures(laws_by_love[love], ids, C / (np.pi * E.E_star), s.heights.max() - d).mean()
             for d in deltas]
        errors[love] = np.array(F) / big.mean_pressure - 1
    assert np.max(np.abs(errors["average"])) < 0.03
    assert np.max(np.abs(errors["centre"])) < 0.03
    assert np.all(errors["none"] < -0.03) and np.min(errors["none"]) < -0.1     # visibly worse


def test_law_is_monotone_c1_and_safe_outside_the_table(laws_by_love):
    laws = laws_by_love["average"]
    for row in range(3):
        law = laws.mechanical
        g_nodes, g_open = law.gap[row], law.g_open[row]
        g = np.concatenate([np.linspace(g_nodes[-1] - 2e-6, g_open + 1e-7, 20001), g_nodes])
        v = law(g, np.full(g.shape, row))
        assert np.all(np.isfinite(v.pressure)) and np.all(np.isfinite(v.stiffness))
        order = np.argsort(g)
        assert np.all(np.diff(v.pressure[order]) <= 0)                       # monotone
        assert np.all(v.stiffness >= 0)
        np.testing.assert_allclose(v.pressure[-20:], law.pressure[row], rtol=1e-13)   # through the nodes
        # derivative vs central differences, where the law is smooth (away from the nodes)
        h = 1e-4 * (g_nodes[0] - g_nodes[-1]) / 20
        gs = np.append(0.5 * (g_nodes[1:] + g_nodes[:-1]), 0.5 * (g_nodes[0] + g_open))   # and the onset
        fd = -(law(gs + h, np.full(gs.shape, row)).pressure - law(gs - h, np.full(gs.shape, row)).pressure) / (2 * h)
        np.testing.assert_allclose(law(gs, np.full(gs.shape, row)).stiffness, fd, rtol=1e-5)
        # C1: one-sided stiffness limits agree at every node, at first touch and at the last node
        eps = 1e-9 * (g_open - g_nodes[-1])
        for gk in g_nodes:
            left, right = law(np.array([gk - eps, gk + eps]), np.array([row, row])).stiffness
            assert abs(left - right) <= 1e-6 * v.stiffness.max()
        touch = law(g_open - np.array([1e-12, 0.0, -1e-12]) * (g_open - g_nodes[-1]), np.full(3, row))
        assert touch.stiffness[0] < 1e-3 * v.stiffness.max() and touch.stiffness[1:].max() == 0
        # outside: open gap -> zero; far beyond the last node -> linear, last stiffness, finite
        far = law(np.array([g_open + 1e-3, g_nodes[-1] - 1.0, -1e3]), np.full(3, row))
        assert far.pressure[0] == 0 and far.stiffness[0] == 0
        K_last = law(np.array([g_nodes[-1] - eps]), np.array([row])).stiffness[0]
        assert far.stiffness[1] == pytest.approx(K_last, rel=1e-6) and far.stiffness[1] > 0
        assert np.all(np.isfinite(far.pressure)) and far.pressure[2] > far.pressure[1]


def test_vectorised_evaluation_over_facets_matches_per_zone(laws_by_love):
    laws = laws_by_love["average"]
    rng = np.random.default_rng(0)
    ids = rng.integers(0, 16, 5000)
    g = rng.uniform(laws.mechanical.gap.min() - 1e-6, laws.mechanical.g_open.max(), 5000)
    v = laws.pressure(g, ids)
    for zid in (0, 7, 15):
        sel = ids == zid
        one = laws.pressure(g[sel], np.full(sel.sum(), zid))
        np.testing.assert_array_equal(v.pressure[sel], one.pressure)
    with pytest.raises(InputError, match="zone_ids"):
        laws.pressure([0.0], [99])
    with pytest.raises(InputError, match="gap"):
        laws.pressure([np.nan], [0])


def test_law_accuracy_on_a_known_power_law():
    """Hertz-like p = k (g_open − g)^1.5 sampled at 20 nodes: the interpolant is within 1 % above
    the first node and exact at the nodes."""
    g_open = 2e-6
    d = 1e-6 * (np.arange(1, 21) / 20) ** 2
    law = PressureGapLaw(g_open - d, 1e12 * d**1.5, g_open)
    dd = np.linspace(d[0], d[-1], 500)
    v = law(g_open - dd)
    assert np.max(np.abs(v.pressure / (1e12 * dd**1.5) - 1)) < 0.01
    assert np.max(np.abs(v.stiffness / (1.5e12 * dd**0.5) - 1)) < 0.05
    with pytest.raises(InputError):
        PressureGapLaw(g_open - d[::-1], 1e12 * d**1.5, g_open)     # gaps must decrease


class PeakPressure(ExtraLaw):
    """Test extra law: the highest local pressure at speeds (1, 2, 4) times a speed factor."""

    tables, axis = {"peak": "hold"}, np.array([1.0, 2.0, 4.0])

    def key(self):
        return ("peak", 1)

    def values(self, result, zones):
        return {"peak": result.pressure.max(axis=(-2, -1))[:, None] * self.axis[None, :]}


def test_a_compliance_in_series_deepens_each_node_by_c_p(tiled, laws_by_love):
    """``ZoneLaws.in_series``: a compliance c [m/Pa] (Archard's depth per pressure over a wear
    interval, ``coupling``'s backward Euler wear) in series with a zone's law. A rigid flat at
    approach delta then carries the p of p = law(top - delta + c p) (``flat_zone_pressure``, a
    spring in series solved on the law itself): exactly at the nodes (delta = top - g_k + c p_k),
    within 1 % between them (0.5 % measured: the law's interpolation through the shifted nodes).
    The pressure tables (real area) are unchanged; c = 0 is the law itself; a negative c is
    refused."""
    laws = laws_by_love["average"]
    c = np.resize([2.0, 0.5, 0.0, 1.0], len(laws)) * 1e-12                # m/Pa: 1-6 um at 1-3 MPa
    series = laws.in_series(c)
    for row, (nd, k) in enumerate(zip(laws.nodes, c)):
        ids = np.full(nd.pressure.shape, nd.zone_id)
        np.testing.assert_allclose(series.pressure(nd.gap - k * nd.pressure, ids).pressure, nd.pressure, rtol=1e-10)
        delta = nd.top - nd.gap + k * nd.pressure
        mid = np.sqrt(delta[1:] * delta[:-1])
        expected = flat_zone_pressure(lambda g: laws.pressure(g, nd.zone_id), nd.top, k, mid)
        np.testing.assert_allclose(series.pressure(nd.top - mid, np.full(mid.shape, nd.zone_id)).pressure, expected,
                                   rtol=0.01)
        np.testing.assert_array_equal(series.area_fraction(nd.pressure, ids), laws.area_fraction(nd.pressure, ids))
    np.testing.assert_array_equal(laws.in_series(np.zeros(len(laws))).mechanical.gap, laws.mechanical.gap)
    with pytest.raises(InputError, match="compliance"):
        laws.in_series(-c)


def test_area_fraction_and_extra_laws_are_tabulated_at_the_nodes(tiled):
    _, _, zones = tiled
    spec = LawSpec(E, p_max=3e6, n_points=8, extras=(PeakPressure(),))
    laws = compute_laws(zones[:2], spec)
    nd = laws.nodes[1]
    r = ContactSolver(E, zones[1].shape, zones[1].surface.dx, periodic=False).solve(
        zones[1].surface.heights, approach=nd.approach[3], tol=1e-8)
    assert laws.area_fraction(nd.pressure[3], 1) == pytest.approx(r.area_fraction, abs=2.5 / 32**2)
    assert nd.extras["peak"].shape == (8, 3)
    np.testing.assert_allclose(nd.extras["peak"][3], r.pressure.max() * np.array([1, 2, 4]), rtol=1e-5)
    np.testing.assert_allclose(laws.extra("peak", nd.pressure, 1, at=2.0), nd.extras["peak"][:, 1], rtol=1e-13)
    np.testing.assert_allclose(laws.extra("peak", nd.pressure[2], 1, at=3.0), 3 * nd.extras["peak"][2, 0],
                               rtol=1e-12)                                       # linear between speeds
    assert laws.area_fraction(0.0, 1) == 0.0                                  # 'zero' below the table
    assert laws.area_fraction(1e9, 1) == pytest.approx(nd.area_fraction[-1])   # held above
    table = PressureTable(nd.pressure, nd.area_fraction, below="zero")
    p = np.geomspace(nd.pressure[0], nd.pressure[-1], 300)
    assert np.all(np.diff(table(p)) >= -1e-15)                                 # no overshoot (PCHIP)


def test_conductance_law_plugs_in_with_the_zone_scale_correction(tiled):
    """h_c(p): K_t of the zone from conduction.py (thesis ch. 5), minus the zone-scale spreading
    resistance of a uniform flux (the thermal analogue of Eq. 1.31)."""
    from multiscale.micro.conduction import conductance_law
    from multiscale.micro.kernels import ThermalHalfSpace
    _, grid, zones = tiled
    k1, k2 = ThermalHalfSpace(50.0), ThermalHalfSpace(35.0)
    laws = compute_laws(zones[:2], LawSpec(E, p_max=3e6, n_points=6, extras=(Conductance(k1, k2),)))
    nd = laws.nodes[1]
    K, h = nd.extras["patch_conductance"], nd.extras["conductance"]
    ref = conductance_law(zones[1].surface, E, (k1, k2), [nd.pressure[3]], tol=1e-10, thermal_tol=1e-10)
    assert K[3] == pytest.approx(ref.conductance[0], rel=1e-4)        # load vs displacement control
    R = love_rectangle_mean(grid.size[0] / 2, grid.size[1] / 2) * (1 / 50.0 + 1 / 35.0) / (2 * np.pi)
    np.testing.assert_allclose(1 / K - 1 / h, R, rtol=5e-3)           # discrete vs Love's mean
    assert np.all(np.diff(h) > 0) and np.all(h > K)
    assert laws.extra("conductance", nd.pressure[3], 1) == pytest.approx(h[3], rel=1e-13)
    assert laws.extra("conductance", 0.0, 1) == 0.0


def test_heat_partition_law_plugs_in_and_matches_heating_module(tiled):
    from multiscale.micro.heat_kernels import ThermalMaterial
    from multiscale.micro.heating import partition_law
    _, _, zones = tiled
    z = zones[2]
    disc, pad = ThermalMaterial(50.0, 1e-5), ThermalMaterial(35.0, 8.3e-6)
    law = HeatPartition(disc, pad, [1.0, 10.0], mu=0.4)
    laws = compute_laws([z], LawSpec(E, p_max=3e6, n_points=5, extras=(law,)))
    nd = laws.nodes[0]
    r = ContactSolver(E, z.shape, z.surface.dx, periodic=False).solve(
        np.repeat(z.surface.heights[None], 2, 0), approach=nd.approach[2:4], tol=1e-10)
    ref = partition_law(r, disc, pad, [1.0, 10.0], mu=0.4, dx=z.surface.dx)
    np.testing.assert_allclose(nd.extras["partition_1"][2:4].T, ref.partition_1, rtol=1e-4)
    np.testing.assert_allclose(nd.extras["max_temperature_1"][2:4].T, ref.max_temperature_1, rtol=1e-4)
    p1 = laws.extra("partition_1", nd.pressure[2], z.id, at=[1.0, 5.5, 10.0])
    assert np.all((0 < p1) & (p1 < 1))
    assert p1[1] == pytest.approx((p1[0] + p1[2]) / 2, rel=1e-12)       # linear between speeds


def test_triangular_zones_carry_the_micro_force(tiled):
    s, _, _ = tiled
    L = s.size[0] / 2
    tris = np.array([[[0, 0], [L, 0], [L, L]], [[0, 0], [L, L], [0, L]]])
    zones = cut_triangles(s, tris, ids=[10, 11])
    masks = [z.mask for z in zones]
    assert masks[0].sum() + masks[1].sum() == 64 * 64          # the cells of the square, each once
    assert zones[0].area == pytest.approx(L * L / 2)
    spec = LawSpec(E, p_max=3e6, n_points=8)
    laws = compute_laws(zones, spec)
    for z in zones:
        nd = laws.nodes[list(laws.ids).index(z.id)]
        assert nd.compliance == love_triangle_mean(z.triangle) / (np.pi * E.E_star)
        p = flat_zone_pressure(lambda g: laws.pressure(g, np.full(np.shape(g), z.id)), z.top, nd.compliance,
                               nd.approach)
        np.testing.assert_allclose(p, nd.pressure, rtol=1e-10)
        # the node force is the micro force of the triangle's cells alone
        h = np.where(z.mask, z.surface.heights, z.surface.heights[z.mask].min() - 1e-4)
        r = ContactSolver(E, z.shape, s.dx, periodic=False).solve(h, approach=nd.approach[4], tol=1e-9)
        assert r.mean_pressure * z.shape[0] * z.shape[1] * s.dx**2 == pytest.approx(nd.pressure[4] * z.area,
                                                                                       rel=1e-5)


def test_failing_zones_are_named_and_the_others_survive(tiled):
    _, _, zones = tiled
    flat = Zone(99, Surface(np.zeros((32, 32)), zones[0].surface.dx, zones[0].surface.dy, periodic=False))
    with pytest.raises(LawError) as info:             # the rough zones need 11-15 iterations at the top nodes
        compute_laws([zones[0], flat, zones[1]], LawSpec(E, p_max=3e6, n_points=6, max_iter=8))
    assert [f.zone_id for f in info.value.failures] == [0, 1]
    assert info.value.failures[0].kind == "ContactConvergenceError"
    assert info.value.result.ids.tolist() == [99]


def test_a_law_falls_at_least_at_the_resolution_floor():
    """``resolved_gap``: from first touch on, a node whose gap falls by less than RESOLUTION c per
    pascal since the node before is lowered to that floor; the nodes before it are untouched, and
    so is a later node that falls far enough; the pressure of the first lowered node is returned."""
    c, top = 2e-13, 5e-6
    p = np.array([1e5, 2e5, 4e5, 8e5, 1.6e6])
    rate = np.array([3.0, 0.5, 0.05, -0.05, 0.2]) * c           # -dg/dp per interval (the 4th rises)
    g = top - np.cumsum(rate * np.diff(p, prepend=0.0))
    out, floored = resolved_gap(g, p, top, c)
    assert floored == 4e5
    np.testing.assert_array_equal(out[[0, 1, 4]], g[[0, 1, 4]])
    falls = -np.diff(np.r_[top, out]) / np.diff(p, prepend=0.0)
    np.testing.assert_allclose(falls[2:4], RESOLUTION * c, rtol=1e-9)
    assert falls[4] > RESOLUTION * c
    assert resolved_gap(g[:2], p[:2], top, c) == (pytest.approx(g[:2], rel=0, abs=0), np.inf)


def test_a_zone_too_smooth_for_its_law_continues_as_nearly_perfect_contact(tiled):
    """A flat isolated patch is stiffer than Love's uniform pressure (the flat punch of the next
    test): its Love-corrected gap rises with p, and its law was refused (a worn-flat or smooth face
    stopped the run). Its law now falls at the floor from first touch, p = (top − g)/(RESOLUTION c):
    the macro model of the flat zone has the compliance (1 + RESOLUTION) c, Love's own plus the
    floor, to 1e-8; the rough zones beside it keep their micro nodes exactly."""
    _, _, zones = tiled
    flat = Zone(99, Surface(np.zeros((32, 32)), zones[0].surface.dx, zones[0].surface.dy, periodic=False))
    laws = compute_laws([zones[0], flat, zones[1]], LawSpec(E, p_max=3e6, n_points=6))
    nodes = {nd.zone_id: nd for nd in laws.nodes}
    nd = nodes[99]
    c = nd.compliance
    assert nd.floored == nd.pressure[0] and np.all(nd.area_fraction == 1.0)
    np.testing.assert_allclose(nd.gap, nd.top - RESOLUTION * c * nd.pressure, rtol=0, atol=1e-12 * c * 3e6)
    delta = np.geomspace(nd.pressure[0], nd.pressure[-1], 7) * (1 + RESOLUTION) * c     # (below the first node
    p = flat_zone_pressure(lambda g: laws.pressure(g, np.full(np.shape(g), 99)), nd.top, c, delta)
    np.testing.assert_allclose(p, delta / ((1 + RESOLUTION) * c), rtol=1e-8)      # K vanishes at first touch)
    for rough in (nodes[0], nodes[1]):
        assert rough.floored == np.inf
        np.testing.assert_array_equal(rough.gap, rough.top - rough.approach + rough.compliance * rough.pressure)


def test_a_flat_patch_in_full_contact_is_stiffer_than_loves_uniform_pressure():
    """Why a smooth zone's law needs a floor (``laws.resolved_gap``): a rigid flat
    pressed on a flat isolated square patch carries a flat punch's edge pressures, whose approach
    per mean pressure is 0.92 of Love's mean displacement under the uniform pressure
    (``love_rectangle_mean``; 0.925 for a circle, Johnson 1985 §3.8: pi/2 against 16/(3 pi)), so the
    roughness must add more than that 8 % of the zone's compliance for the Love-corrected gap to
    fall (``RESOLUTION``). Within 1 % on 64 x 64 cells."""
    n, side = 64, 1e-3
    solver = ContactSolver(E, (n, n), side / n, periodic=False)
    punch = solver.solve(np.zeros((n, n)), load=1e6, tol=1e-10)
    uniform = love_rectangle_mean(side / 2, side / 2) * 1e6 / (np.pi * E.E_star)
    assert punch.approach / uniform == pytest.approx(0.927, rel=1e-2)
    assert 1 - punch.approach / uniform == pytest.approx(RESOLUTION, abs=0.01)      # 0.922: 7.8 %


@pytest.mark.parametrize("kwargs, name", [
    (dict(p_max=-1.0), "p_max"), (dict(p_max=1e6, n_points=3), "n_points"),
    (dict(p_max=1e6, love="edge"), "love"), (dict(p_max=1e6, tol=0), "tol"),
    (dict(p_max=1e6, extras=(1,)), "extras"),
])
def test_bad_law_spec(kwargs, name):
    with pytest.raises(InputError) as info:
        LawSpec(E, **kwargs)
    assert info.value.name == name


# --------------------------------------------------------------------------- zones
def test_cut_zones_grid_and_facet_mapping(tiled):
    s, grid, zones = tiled
    assert grid.counts == (4, 4) and len(zones) == 16
    z = zones[6]                                       # ix = 2, iy = 1
    np.testing.assert_array_equal(z.surface.heights, s.heights[32:64, 64:96])
    assert z.origin == pytest.approx((2 * grid.size[0], grid.size[1]))
    x = np.array([z.centre[0], 0.0, s.size[0], 0.999 * grid.size[0]])
    y = np.array([z.centre[1], 0.0, s.size[1], 3.5 * grid.size[1]])
    np.testing.assert_array_equal(grid.zone_of(x, y), [6, 0, 15, 12])
    border = 2 * grid.size[0]                          # a point on a zone border, as round-off leaves it
    np.testing.assert_array_equal(grid.zone_of(border * (1 + np.array([-1e-15, 0.0, 1e-15])), [0.0] * 3), [2, 2, 2])
    with pytest.raises(InputError, match="outside"):
        grid.zone_of([-1e-3], [0.0])
    with pytest.raises(InputError, match="counts"):
        cut_zones(s, (3, 4))
    worn = z.with_heights(z.surface.heights - 1e-9)
    assert worn.topography_hash != z.topography_hash and worn.id == z.id
    assert Zone(7, z.surface, (5.0, 5.0)).topography_hash == z.topography_hash   # not the place or id


def test_generated_zones_are_seeded_per_zone():
    grid = ZoneGrid((0.0, 0.0), (3, 2), (1e-3, 1e-3))
    a = generate_zones(grid, 32, 0.8, 2, 8, 1e-6, seed=4)
    b = generate_zones(ZoneGrid((0.0, 0.0), (5, 5), (1e-3, 1e-3)), 32, 0.8, 2, 8, 1e-6, seed=4)
    np.testing.assert_array_equal(a[4].surface.heights, b[4].surface.heights)
    assert not np.allclose(a[4].surface.heights, a[3].surface.heights)
    assert a[4].origin == pytest.approx((1e-3, 1e-3)) and not a[4].surface.periodic


def test_cut_triangles_assigns_every_cell_once():
    s = fractal_surface(64, 1e-3, 0.8, 2, 16, 1e-6, seed=2)
    xs = np.linspace(0, 1e-3, 5)
    tris = []
    for i in range(4):
        for j in range(4):
            A, B, C, D = (xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1]), (xs[i], xs[j + 1])
            tris += [[A, B, C], [A, C, D]]
    zones = cut_triangles(s, np.array(tris))
    count = np.zeros(s.shape, dtype=int)
    for z in zones:
        r0, c0 = round(z.origin[1] / s.dy), round(z.origin[0] / s.dx)
        count[r0:r0 + z.shape[0], c0:c0 + z.shape[1]] += z.mask
        np.testing.assert_array_equal(z.surface.heights, s.heights[r0:r0 + z.shape[0], c0:c0 + z.shape[1]])
    np.testing.assert_array_equal(count, 1)
    with pytest.raises(InputError, match="lie on the surface"):
        cut_triangles(s, np.array([[[0, 0], [2e-3, 0], [0, 1e-3]]]))


# --------------------------------------------------------------------------- pool (one process)
class RefusesFlat(ExtraLaw):
    """An extra law that raises for a flat patch (a zone failing inside a batch)."""

    tables = {"refuses_flat": "hold"}

    def key(self):
        return ("refuses_flat",)

    def values(self, result, zones):
        if any(not z.surface.heights.any() for z in zones):
            raise ValueError("a flat patch")
        return {"refuses_flat": result.area_fraction}


def test_pool_caches_unchanged_zones_and_matches_compute_laws(tiled):
    from mpi4py import MPI

    from multiscale.pool import CACHE_CALLS, MicroPool, PoolError
    _, _, zones = tiled
    spec = LawSpec(E, p_max=3e6, n_points=6)
    pool = MicroPool(spec, comm=MPI.COMM_SELF)
    first = pool.laws(zones[:4])
    assert pool.stats.computed == 4 and pool.stats.cached == 0
    ref = compute_laws(zones[:4], spec)
    np.testing.assert_allclose(np.stack([n.pressure for n in first.nodes]),
                               np.stack([n.pressure for n in ref.nodes]), rtol=1e-12)
    worn = [zones[0].with_heights(zones[0].surface.heights - 2e-8)] + zones[1:4]
    again = pool.laws(worn)
    assert pool.stats.computed == 1 and pool.stats.cached == 3
    assert again.nodes[0].top == pytest.approx(first.nodes[0].top - 2e-8, rel=1e-12)   # same datum, worn
    flat = Zone(99, Surface(np.zeros((32, 32)), zones[0].surface.dx, zones[0].surface.dy, periodic=False))
    refusing = MicroPool(replace(spec, extras=(RefusesFlat(),)), comm=MPI.COMM_SELF)
    with pytest.raises(PoolError) as info:
        refusing.laws(zones[:2] + [flat])
    assert [f.zone_id for f in info.value.failures] == [99] and len(info.value.result) == 2
    twin = Zone(98, flat.surface)     # one topography, solved once: both zones fail (before: 99 alone,
    with pytest.raises(PoolError) as info:                    # and 98 had no law and no failure)
        refusing.laws([flat, twin] + zones[:1])
    assert [f.zone_id for f in info.value.failures] == [98, 99] and info.value.result.ids.tolist() == [0]
    assert refusing.stats.computed == refusing.stats.failed == 1      # one solve (zone 0 was cached)
    small = MicroPool(spec, comm=MPI.COMM_SELF, cache_size=2)        # a call returns all it computed
    assert small.laws(zones[:4]).ids.tolist() == [0, 1, 2, 3] and len(small) == 2
    # zone 0 worn at every call, 1-3 unchanged: by default the pool keeps CACHE_CALLS x 4 laws, the
    # unchanged ones among them (a fixed 100 000 grew a long run's memory by every worn law)
    pool = MicroPool(spec, comm=MPI.COMM_SELF)
    pool.laws(zones[:4])
    for k in range(1, 2 * CACHE_CALLS * 4):
        pool.laws([zones[0].with_heights(zones[0].surface.heights - k * 1e-9)] + zones[1:4])
        assert pool.stats.computed == 1 and pool.stats.cached == 3
    assert len(pool) == CACHE_CALLS * 4


def test_the_pools_progress_line_names_a_halved_p_max(tiled):
    """The retry of failed laws at p_max / 2 printed a second "zone laws: 1/1 batches" line, as if
    one line were said twice (a user trial); now it names its p_max."""
    import io as stdio

    from mpi4py import MPI

    from multiscale import io
    from multiscale.pool import MicroPool
    _, _, zones = tiled
    spec = LawSpec(E, p_max=3e6, n_points=6)
    out = stdio.StringIO()
    with io.Reporter(MPI.COMM_SELF, stream=out):
        pool = MicroPool(spec, comm=MPI.COMM_SELF, progress=True)
        pool.laws(zones[:1])
        pool.laws(zones[1:2], replace(spec, p_max=1.5e6))
    lines = out.getvalue().splitlines()
    assert [line.split(":")[0] for line in lines] == ["  zone laws", "  zone laws up to p_max = 1.5e+06 Pa"], lines


def test_pool_worker_never_imports_dolfinx():
    code = ("import sys\n"
            "from multiscale.micro.kernels import HalfSpace\n"
            "from multiscale.micro.laws import LawSpec\n"
            "from multiscale.micro.surface import fractal_surface\n"
            "from multiscale.micro.zones import cut_zones\n"
            "from multiscale.pool import MicroPool\n"
            "_, zones = cut_zones(fractal_surface(32, 1e-3, 0.8, 2, 8, 1e-6, seed=1), (2, 2))\n"
            "MicroPool(LawSpec(HalfSpace(1e9), p_max=1e6, n_points=5)).laws(zones)\n"
            "assert 'dolfinx' not in sys.modules and 'petsc4py' not in sys.modules\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr

"""Steady thermal contact conductance (thesis §5.2–5.4, Eqs. 5.8–5.12)."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro.contact import ContactSolver, solve_contact
from multiscale.micro.conduction import ConductionSolver, SeriesKernel, conductance_law
from multiscale.micro.kernels import HalfSpace, Kernel, ThermalHalfSpace
from multiscale.micro.layered import LayeredElastic, LayeredThermal
from multiscale.micro.surface import fractal_surface
from multiscale.references.conduction import flux_tube_factor, holm_conductance, thermal_layer_compliance
from multiscale.references.love import love_rectangle_mean

K1, K2 = ThermalHalfSpace(10.0), ThermalHalfSpace(50.0)


class Slab(Kernel):
    """Test-only periodic kernel: a layer of thickness h on a base held at fixed temperature,
    F(q) = tanh(q h)/(kappa q), F(0) = h/kappa (independent of the package's layered kernels)."""

    thermal = True      # temperature per heat flux (a kernel of one's own says which)

    def __init__(self, kappa, h):
        self.kappa, self.h = kappa, h

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        qs = np.where(q > 0, q, 1.0)
        return np.where(q > 0, thermal_layer_compliance(qs, self.h, self.kappa), self.h / self.kappa)

    def influence(self, ny, nx, dy, dx):
        raise NotImplementedError("periodic grids only")


def disc(n, a, dx):
    x = (np.arange(n) - n / 2 + 0.5) * dx
    X, Y = np.meshgrid(x, x)
    return X**2 + Y**2 <= a * a


def holm_error(cells_per_diameter, a=1e-4):
    """Isolated isothermal circular spot on two half-spaces vs Holm, 4 a k1 k2/(k1+k2)."""
    n = cells_per_diameter
    dx = 2 * a / n
    spot = disc(n, a, dx)
    res = ConductionSolver(K1, K2, (n, n), dx, periodic=False).solve(spot)
    G = res.conductance * (n * dx) ** 2                   # W/K through the spot
    a_eff = np.sqrt(spot.sum() * dx * dx / np.pi)          # radius of the pixelated spot's area
    return G / holm_conductance(a, K1.kappa, K2.kappa) - 1, G / holm_conductance(a_eff, K1.kappa, K2.kappa) - 1, res


def test_holm_constriction_of_a_circular_spot_with_grid_convergence():
    errors = {n: holm_error(n) for n in (8, 16, 32, 64)}
    nominal = {n: e[0] for n, e in errors.items()}
    same_area = {n: e[1] for n, e in errors.items()}
    assert all(abs(nominal[n]) < 0.03 for n in (16, 32, 64))       # within 3 % once fine enough
    for coarse, fine in ((8, 16), (16, 32), (32, 64)):               # first-order convergence
        assert 1.6 < same_area[coarse] / same_area[fine] < 2.4
    assert abs(same_area[64]) < 0.005
    res = errors[64][2]
    # isothermal spot: both surfaces at T_s = (k2 theta_2 + k1 theta_1)/(k1 + k2) on the contact
    spot = res.contact
    assert np.allclose(res.temperature_1[spot], 50 / 60, atol=1e-8)
    assert np.allclose(res.temperature_2[spot], 50 / 60, atol=1e-8)
    assert res.contact_temperature_1 == pytest.approx(50 / 60, abs=1e-8)
    assert np.all(res.flux[~spot] == 0)
    # K_p: a uniform flux over the whole patch (a square of the spot's diameter) on the half-spaces
    R_u = love_rectangle_mean(1e-4, 1e-4) * (1 / K1.kappa + 1 / K2.kappa) / (2 * np.pi)
    assert 1 / res.perfect_conductance == pytest.approx(R_u, rel=5e-4)     # measured 1.5e-4


def test_an_isolated_patch_follows_barbers_analogy():
    """K_i of an isolated rough patch on half-spaces against the mechanics (Barber's analogy, the
    thermal kernel 1/(kappa_s q) against the elastic 2/(E* q)): K_i = (2 kappa_s / E*) / (1/k - C_u),
    k the incremental stiffness per area by central differences of the contact solver's approach,
    C_u the mean compliance of a uniform pressure on the square (Love's closed form). Before, K_p was
    that of an infinite interface (infinite here), so K_i = K_t: 3x low at 6 % contact, and on
    layers an infinite K_i at 1 % (a user trial)."""
    n, L, E_star = 128, 1e-4, 210e9 / (1 - 0.09) / 2
    s = fractal_surface(n, L, hurst=0.8, k_min=2, k_max=32, rms=1e-7, seed=3)
    mech = ContactSolver(HalfSpace.from_materials(210e9, 0.3, 210e9, 0.3), s.shape, s.dx, periodic=False)
    heat = ConductionSolver(K1, K2, s.shape, s.dx, periodic=False)
    kappa_s = 1 / (1 / K1.kappa + 1 / K2.kappa)
    C_u = love_rectangle_mean(L / 2, L / 2) / (np.pi * E_star)               # m/Pa
    for p in (1e7, 1e8):                                                      # 1 % and 6 % contact
        r = mech.solve(s.heights, load=p, tol=1e-12)
        lo, hi = (mech.solve(s.heights, approach=r.approach * (1 + e), tol=1e-12) for e in (-1e-4, 1e-4))
        k = (hi.mean_pressure - lo.mean_pressure) / (2e-4 * r.approach)       # Pa/m
        K_i = heat.solve(r.contact, tol=1e-12).interface_conductance
        assert K_i == pytest.approx(2 * kappa_s / E_star / (1 / k - C_u), rel=5e-4)   # measured 1.5e-5, 5.4e-5
    layered = ConductionSolver(LayeredThermal((1e-3,), (50.0,)), LayeredThermal((2e-3,), (20.0,)), s.shape, s.dx,
                               periodic=False)
    contact = mech.solve(s.heights, load=1e7).contact
    res = layered.solve(contact)
    assert np.isfinite(res.interface_conductance) and res.conductance < res.perfect_conductance
    full = layered.solve(np.ones(s.shape, bool))               # uniform temperature beats a uniform flux (Thomson)
    assert full.conductance > full.perfect_conductance and full.interface_conductance == np.inf


def test_periodic_spots_match_the_flux_tube_constriction():
    """Square array of spots on half-spaces vs Roess' isothermal flux-tube series, equal-area tube."""
    n, c = 128, 1e-3
    b = c / np.sqrt(np.pi)
    spot = disc(n, 0.2 * b, c / n)
    res = ConductionSolver(K1, K2, (n, n), c / n).solve(spot)
    a = np.sqrt(spot.sum() / np.pi) * c / n
    expected = holm_conductance(a, K1.kappa, K2.kappa) / (c * c * flux_tube_factor(a / b))
    assert res.conductance == pytest.approx(expected, rel=0.03)
    assert res.interface_conductance == res.conductance               # K_p infinite: K_i = K_t
    # temperatures: zero-mean responses about the far-field values theta_1 = 0, theta_2 = 1
    assert res.temperature_1.mean() == pytest.approx(0.0, abs=1e-12)
    assert res.temperature_2.mean() == pytest.approx(1.0, abs=1e-12)


def test_cg_solution_matches_a_dense_solve():
    rng = np.random.default_rng(3)
    n, dx = 12, 5e-6
    mask = rng.random((n, n)) < 0.3
    R = 2e-6
    solver = ConductionSolver(Slab(10.0, 1e-4), K2, (n, n), dx)
    res = solver.solve(mask, resistance=R, tol=1e-13)
    cols = np.eye(n * n).reshape(n * n, n, n)
    T = solver.series(cols).reshape(n * n, n * n).T               # dense (T1 + T2)
    idx = np.flatnonzero(mask)
    A = T[np.ix_(idx, idx)] + R * np.eye(idx.size)
    phi = np.linalg.solve(A, np.ones(idx.size))
    assert np.allclose(res.flux.ravel()[idx], phi, rtol=1e-9)
    assert np.allclose((res.temperature_2 - res.temperature_1)[mask], R * res.flux[mask], rtol=1e-8)


def test_full_contact_gives_K_p_and_resistance_adds_in_series():
    b1, b2 = Slab(10.0, 1e-3), Slab(50.0, 1e-3)                  # thesis Table 5.4 case 1: 1 mm cubes
    solver = ConductionSolver(b1, b2, (16, 16), 1e-3 / 16)
    full = np.ones((16, 16), bool)
    res = solver.solve(full)
    assert solver.perfect_conductance == pytest.approx(1 / (1e-4 + 2e-5), rel=1e-14)   # 8.33e3
    assert res.conductance == pytest.approx(res.perfect_conductance, rel=1e-12)
    assert res.contact_temperature_1 == pytest.approx(1e-4 / 1.2e-4, rel=1e-12)        # T_p = 0.83
    assert res.interface_conductance == np.inf
    for R in (1e-6, 1e-4):
        r = solver.solve(full, resistance=R)
        assert 1 / r.interface_conductance == pytest.approx(R, rel=1e-9)               # 1/K_i = R
        assert 1 / r.conductance == pytest.approx(1 / res.conductance + R, rel=1e-12)


def test_resistance_on_a_partial_contact_is_bounded_by_the_thomson_principle():
    surface = fractal_surface(64, 1e-3, 0.8, 2, 10, 6e-6, seed=2)
    mech = ContactSolver(HalfSpace.from_materials(4e9, 0.15), surface.shape, surface.dx)
    contact = mech.solve(surface.heights, load=3e6).contact
    solver = ConductionSolver(K1, K2, surface.shape, surface.dx)
    base = solver.solve(contact)
    frac = contact.mean()
    for R in (1e-6, 1e-5):
        r = solver.solve(contact, resistance=R)
        extra = 1 / r.conductance - 1 / base.conductance
        # uniform flux on the area is the least R-dissipation; the R = 0 flux is an admissible trial
        lower = R / frac
        upper = R * np.mean(base.flux**2) / np.mean(base.flux) ** 2
        assert lower * (1 - 1e-8) < extra < upper * (1 + 1e-8)
        assert np.allclose((r.temperature_2 - r.temperature_1)[contact], R * r.flux[contact], rtol=1e-7)


def test_conductance_law_is_monotone_and_matches_single_solves():
    surface = fractal_surface(48, 1e-3, 0.8, 2, 10, 6e-6, seed=4, batch=(2,))
    elastic = HalfSpace.from_materials(4e9, 0.15)
    thermal = (Slab(10.0, 1e-3), Slab(50.0, 1e-3))
    law = conductance_law(surface, elastic, thermal, [4e6, 1e6, 2e6])
    assert np.array_equal(law.pressure, [1e6, 2e6, 4e6])
    assert law.conductance.shape == (3, 2)
    assert np.all(np.diff(law.conductance, axis=0) > 0) and np.all(np.diff(law.area_fraction, axis=0) > 0)
    assert np.all(law.conductance < law.perfect_conductance)
    assert np.allclose(1 / law.interface_conductance, 1 / law.conductance - 1 / law.perfect_conductance)
    cold = solve_contact(surface.heights[1], surface.dx, elastic, load=2e6)
    single = ConductionSolver(*thermal, surface.shape, surface.dx).solve(cold.contact)
    assert law.conductance[1, 1] == pytest.approx(single.conductance, rel=1e-6)


L = 1e-3
SOLID_2 = (LayeredElastic((L,), (220e9,), (0.33,)), LayeredThermal((L,), (50.0,)))


def thesis_case(surface, E1, kappa1, h, pressure=3e6):
    """Thesis §5.5 cubes: solid 1 one or two layers to 1 mm on an isothermal rigid base, solid 2 kappa 50."""
    if h is None:
        e1, t1 = LayeredElastic((L,), (E1,), (0.15,)), LayeredThermal((L,), (kappa1,))
    else:
        e1 = LayeredElastic((h, L - h), (E1, 4e9), (0.15, 0.15))
        t1 = LayeredThermal((h, L - h), (kappa1, 10.0))
    law = conductance_law(surface, SeriesKernel(e1, SOLID_2[0]), (t1, SOLID_2[1]), [pressure])
    return law.conductance[0], law.perfect_conductance, law.contact_temperature[0]


@pytest.fixture(scope="module")
def thesis_surface_150():
    return fractal_surface(150, L, 0.8, 2, 10, 6e-6, seed=1)      # the thesis grid: 6.67 um cells


def test_table_5_4_perfect_conductance_exact_and_ratio_falls_with_kappa1(thesis_surface_150):
    cases = [(4e9, 10.0, None), (4e9, 5.0, 5e-4), (4e9, 2.5, 5e-4)]           # Table 5.3
    K_p_thesis = [1 / (1e-3 / 10 + 2e-5), 1 / (5e-4 / 5 + 5e-4 / 10 + 2e-5), 1 / (5e-4 / 2.5 + 5e-4 / 10 + 2e-5)]
    out = [thesis_case(thesis_surface_150, *c) for c in cases]
    ratio = [K_t / K_p for K_t, K_p, _ in out]
    for (K_t, K_p, T_s), exact in zip(out, K_p_thesis):
        assert K_p == pytest.approx(exact, rel=1e-12)                         # 8.33, 5.88, 3.70 e3
    assert ratio[0] > ratio[1] > ratio[2]                                      # Table 5.4: 0.45, 0.38, 0.33
    assert np.allclose(ratio, [0.45, 0.38, 0.33], rtol=0.1)                    # another random surface
    assert [T_s for *_, T_s in out] == sorted(T_s for *_, T_s in out)          # T_s rises: 0.83, 0.88, 0.93


def test_tables_5_6_and_5_8_trends(thesis_surface_150):
    """Softer and less conductive top layer (kappa1/kappa2 = E1/E2): K_t falls but K_t/K_p rises
    (Table 5.6); thicker such layer: K_t falls, K_t/K_p rises (Table 5.8)."""
    for cases in ([(4e9, 10.0, None), (2e9, 5.0, 5e-4), (1e9, 2.5, 5e-4)],
                  [(1e9, 2.5, 1e-4), (1e9, 2.5, 2e-4), (1e9, 2.5, 5e-4)]):
        out = [thesis_case(thesis_surface_150, *c) for c in cases]
        K_t = [o[0] for o in out]
        ratio = [o[0] / o[1] for o in out]
        assert K_t[0] > K_t[1] > K_t[2]
        assert ratio[0] < ratio[1] < ratio[2]


def test_series_kernel_keeps_an_infinite_q0_infinite():
    s = SeriesKernel(Slab(10.0, 1e-3), K2)
    q = np.array([0.0, 1e3, 1e5])
    assert s.compliance(q)[0] == 0.0
    assert np.allclose(s.compliance(q)[1:], Slab(10.0, 1e-3).compliance(q[1:]) + K2.compliance(q[1:]))
    assert ConductionSolver(Slab(10.0, 1e-3), K2, (8, 8), 1e-5).perfect_conductance == np.inf


def test_bad_input_is_named():
    solver = ConductionSolver(K1, K2, (8, 8), 1e-5)
    mask = np.zeros((8, 8), bool)
    mask[2:4, 2:4] = True
    with pytest.raises(InputError, match="resistance"):
        solver.solve(mask, resistance=-1e-6)
    with pytest.raises(InputError, match="theta_2"):
        solver.solve(mask, theta_1=1.0, theta_2=1.0)
    with pytest.raises(InputError, match="contact"):
        solver.solve(np.ones((8, 8), bool))              # semi-infinite bodies, full contact, R = 0
    with pytest.raises(InputError, match="contact.shape"):
        solver.solve(np.ones((4, 8), bool))
    gap = np.where(mask, 0.0, 1e-7)              # a gap field for the mask: its zeros were taken as out of
    with pytest.raises(InputError, match="must be a mask: True"):      # contact, a conductance 4e4x too high
        solver.solve(gap)                        # (a user trial)
    with pytest.raises(InputError, match="masks"):
        solver.uniform_resistance(-2e6 * mask)
    assert solver.solve(mask.astype(int)).conductance == solver.solve(mask).conductance     # 0/1 numbers are a mask
    surface = fractal_surface(16, 1e-3, 0.8, 2, 5, 6e-6)
    with pytest.raises(InputError, match="pressures"):
        conductance_law(surface, HalfSpace(4e9), (K1, K2), [1e6, -1e6])
    with pytest.raises(InputError, match="thermal"):
        conductance_law(surface, HalfSpace(4e9), K1, [1e6])

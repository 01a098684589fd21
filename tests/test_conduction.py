"""Steady thermal contact conductance (thesis §5.2–5.4, Eqs. 5.8–5.12)."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro.contact import ContactSolver, solve_contact
from multiscale.micro.conduction import ConductionSolver, SeriesKernel, conductance_law
from multiscale.micro.kernels import HalfSpace, Kernel, ThermalHalfSpace
from multiscale.micro.surface import fractal_surface

K1, K2 = ThermalHalfSpace(10.0), ThermalHalfSpace(50.0)


class Slab(Kernel):
    """Test-only periodic kernel: a layer of thickness h on a base held at fixed temperature,
    F(q) = tanh(q h)/(kappa q), F(0) = h/kappa (independent of the package's layered kernels)."""

    def __init__(self, kappa, h):
        self.kappa, self.h = kappa, h

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        qs = np.where(q > 0, q, 1.0)
        return np.where(q > 0, np.tanh(qs * self.h) / (self.kappa * qs), self.h / self.kappa)

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
    holm = 4 * K1.kappa * K2.kappa / (K1.kappa + K2.kappa)
    return G / (holm * a) - 1, G / (holm * a_eff) - 1, res


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
    assert np.all(res.flux[~spot] == 0) and res.perfect_conductance == np.inf


def test_periodic_spots_match_the_flux_tube_constriction():
    """Square array of spots on half-spaces vs Roess' isothermal flux-tube series, equal-area tube."""
    n, c = 128, 1e-3
    b = c / np.sqrt(np.pi)
    spot = disc(n, 0.2 * b, c / n)
    res = ConductionSolver(K1, K2, (n, n), c / n).solve(spot)
    a = np.sqrt(spot.sum() / np.pi) * c / n
    e = a / b
    psi = 1 - 1.40925 * e + 0.29591 * e**3 + 0.05254 * e**5 + 0.02105 * e**7
    expected = 1 / (c * c * psi * (1 / (4 * K1.kappa * a) + 1 / (4 * K2.kappa * a)))
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
    surface = fractal_surface(16, 1e-3, 0.8, 2, 5, 6e-6)
    with pytest.raises(InputError, match="pressures"):
        conductance_law(surface, HalfSpace(4e9), (K1, K2), [1e6, -1e6])
    with pytest.raises(InputError, match="thermal"):
        conductance_law(surface, HalfSpace(4e9), K1, [1e6])

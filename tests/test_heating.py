"""Frictional heating (thesis ch. 6): heat-source kernels against closed forms and Jaeger/Rosenthal,
the transient thermal contact (energy, effusivity limit, convergence, velocity profiles, interface
layer) and the steady partition law with remote temperatures."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale import memory
from multiscale.micro import fft, heating
from multiscale.micro.contact import ContactSolver
from multiscale.micro.heat_kernels import (Rotation, SpeedProfile, ThermalMaterial, Translation,
                                           fixed_rectangle_temperature, moving_rectangle_temperature,
                                           pulse_tables)
from multiscale.micro.heating import (HeatingConvergenceError, InterfaceLayer, PartitionLaw, SteadyHeating,
                                      TransientHeating, partition_law)
from multiscale.micro.kernels import HalfSpace, padded_size
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.references.conduction import holm_conductance
from multiscale.references.heat import (fast_square_source, fixed_square_source, point_source_deficit,
                                        uniform_flux_temperature)
from multiscale.references.love import love_rectangle

DISC = ThermalMaterial(50.0, 1e-5)       # thesis Table 6.3, solid S1 (moving)
PIN = ThermalMaterial(5.0, 3.5e-6)       # solid S2 (fixed)
ELASTIC = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)


def steady_square(n, material, motion=None):
    """Cell-centre temperatures [K per W/m²] of a square of n x n heated cells of side 1/n mm."""
    dx = 1e-3 / n
    kernel = pulse_tables((n, n), dx, dx, material, np.inf, 1, motion).coeffs[0]
    T = np.fft.irfft2(np.fft.rfft2(kernel) * np.fft.rfft2(np.ones((n, n)), s=(2 * n, 2 * n)), s=(2 * n, 2 * n))
    return T[:n, :n], 0.5e-3


def rough_contact(n, seed=3, approach=10e-6):
    s = fractal_surface(n, 1e-3, 0.8, 2, min(10, n // 4), 6.49e-6, seed=seed)
    return s, ContactSolver(ELASTIC, s.shape, s.dx, periodic=False).solve(s.heights, approach=approach)


# --- kernels (§6.2) -------------------------------------------------------------------------------

def test_fixed_square_source_centre_and_mean_within_half_percent():
    T, l = steady_square(21, PIN)
    q_l_k = l / PIN.kappa
    ref = fixed_square_source(l, PIN.kappa)
    centre, mean = ref.centre / q_l_k, ref.mean / q_l_k
    assert centre == pytest.approx(1.1222, abs=1e-4) and mean == pytest.approx(0.9464, abs=1e-4)
    assert T[10, 10] / q_l_k == pytest.approx(centre, rel=1e-10)   # union of the cells = the square
    assert T.mean() / q_l_k == pytest.approx(mean, rel=5e-3)
    assert fixed_rectangle_temperature(0.0, 0.0, np.inf, l, l, PIN) / q_l_k == pytest.approx(centre, rel=1e-12)


def test_fixed_transient_tends_to_steady_with_the_point_source_deficit():
    l, k, chi = 1e-4, PIN.kappa, PIN.diffusivity
    steady = fixed_rectangle_temperature(0.0, 0.0, np.inf, l, l, PIN)
    short = 1e-3 * l * l / chi                                      # sqrt(chi t) << l: 1-D heating
    assert fixed_rectangle_temperature(0.0, 0.0, short, l, l, PIN) == pytest.approx(
        uniform_flux_temperature(short, k, chi), rel=1e-6)
    deficits = []
    for tau in (1e2 * l * l / chi, 1e4 * l * l / chi):
        T = fixed_rectangle_temperature(0.0, 0.0, tau, l, l, PIN)
        point = point_source_deficit(tau, 4 * l * l, k, chi)          # (T_ss - T) of a point source
        deficits.append(abs((steady - T) / point - 1))
        assert T < steady
    assert deficits[1] < 1e-3 and deficits[1] < deficits[0] / 10


def test_pulse_tables_sum_to_the_pointwise_step_response():
    n, dx, dt = 8, 1e-5, 2e-5
    tables = pulse_tables((n, n), dx, dx, PIN, dt, 6)
    step = np.cumsum(tables.coeffs, axis=0)                         # heated since 0 … 6 dt
    X, Y = np.array([0.0, 3 * dx, -2 * dx]), np.array([0.0, 0.0, 5 * dx])
    for m in (1, 6):
        ref = fixed_rectangle_temperature(X, Y, m * dt, dx / 2, dx / 2, PIN)
        got = step[m - 1][(Y / dx).round().astype(int) % (2 * n), (X / dx).round().astype(int) % (2 * n)]
        # round-off of the summed tables is relative to the largest value (the far point is 1e-4 of it)
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * ref.max())


def test_fixed_closed_form_route_equals_direct_quadrature_at_rest():
    """Eq. 6.3 (steady closed form minus tail in 1/v) vs the moving-body quadrature with V = 0."""
    n, dx = 12, 1e-5
    fixed = pulse_tables((n, n), dx, dx, DISC, 5e-5, 8)
    still = pulse_tables((n, n), dx, dx, DISC, 5e-5, 8, Rotation((0.0, -0.1), SpeedProfile.constant(0.0)))
    assert np.array_equal(fixed.ages, still.ages)
    assert np.max(np.abs(fixed.coeffs - still.coeffs)) < 1e-9 * fixed.coeffs.max()


def test_moving_kernel_quadrature_is_converged():
    n, dx = 16, 1e-5
    motion = Rotation((0.0, -0.1), SpeedProfile.constant(100.0))      # 10 m/s
    a = pulse_tables((n, n), dx, dx, DISC, 2e-5, 8, motion)
    b = pulse_tables((n, n), dx, dx, DISC, 2e-5, 8, motion, refine=3.0)
    assert np.array_equal(a.ages, b.ages) and a.ages[-1] < 7        # old heat is carried away
    assert np.max(np.abs(a.coeffs - b.coeffs)) < 1e-9 * b.coeffs.max()


def test_far_axis_table_matches_the_exact_rotating_kernel():
    """Eq. 6.5 with the exact rotation vs the translated table at R = 100 mm (thesis geometry)."""
    n, dx = 12, 1e-3 / 12
    motion = Rotation((70.7e-3, 70.7e-3), SpeedProfile.constant(10.0))
    table = pulse_tables((n, n), dx, dx, DISC, 1e-3, 1, motion).coeffs[0]
    off = np.where(np.arange(2 * n) < n, np.arange(2 * n), np.arange(2 * n) - 2 * n) * dx
    exact = moving_rectangle_temperature(off[None, :], off[:, None], 1e-3, dx / 2, dx / 2, DISC, motion)
    assert np.max(np.abs(exact - table)) < 2e-3 * table.max()
    # the disc moves along (-1, 1)/sqrt(2) there: the heat is carried downstream, (dx, dy) = (-1, +1)
    # cells, not upstream (+1, -1) (rows are y offsets, columns x; -1 is index 2n - 1)
    assert table[1, 2 * n - 1] > 100 * table[2 * n - 1, 1]


def rosenthal_square(pe, m=72):
    """Steady moving square source by the spatial integral of Rosenthal's point source,
    T = q/(2 pi kappa) ∫∫ exp(-V (r - dx)/(2 chi))/r (Love closed form for the 1/r part)."""
    l, kappa = 0.5e-3, DISC.kappa
    k = pe / l                                                       # V/(2 chi), Pe = V l/(2 chi)
    h = 2 * l / m
    c = (np.arange(m) + 0.5) * h - l
    off = (np.arange(2 * m - 1) - (m - 1)) * h
    DX, DY = np.meshgrid(off, off)
    r = np.hypot(DX, DY)
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.where(r > 0, np.expm1(-k * (r - DX)) / r, -k)
    size = 3 * m
    conv = np.fft.irfft2(np.fft.rfft2(g, s=(size, size)) * np.fft.rfft2(np.ones((m, m)), s=(size, size)),
                         s=(size, size))[m - 1:2 * m - 1, m - 1:2 * m - 1]
    love = love_rectangle(c[None, :], c[:, None], l, l)
    return (love + conv * h * h) / (2 * np.pi * kappa)


@pytest.mark.parametrize("pe", [0.5, 2.0])
def test_moving_square_source_matches_rosenthal(pe):
    n, l = 24, 0.5e-3
    speed = 2 * DISC.diffusivity * pe / l
    motion = Rotation((0.0, -10.0), SpeedProfile.constant(speed / 10.0))   # far axis: translation +x
    T, _ = steady_square(n, DISC, motion)
    ref = rosenthal_square(pe)[1::3, 1::3]                  # the same points (cell centres)
    assert np.max(np.abs(T - ref)) < 1e-3 * ref.max()        # hence the mean and the maximum too
    assert np.argmax(T.mean(axis=0)) > n // 2               # hottest downstream (+x) of the centre


def test_moving_square_source_high_peclet_mean_approaches_jaeger():
    n, l = 24, 0.5e-3
    ratios = []
    for pe in (10.0, 100.0, 1000.0):
        speed = 2 * DISC.diffusivity * pe / l
        T, _ = steady_square(n, DISC, Rotation((0.0, -10.0), SpeedProfile.constant(speed / 10.0)))
        ratios.append(T.mean() / fast_square_source(l, pe, DISC.kappa).mean)
    errors = np.abs(np.array(ratios) - 1)
    assert errors[-1] < 0.01 and errors[0] > errors[1] > errors[2]
    # maximum (trailing edge, 1-D heating during 2l/V): 2/sqrt(pi) q l/(kappa sqrt(Pe))
    assert T.max() == pytest.approx(fast_square_source(l, pe, DISC.kappa).maximum, rel=0.02)


# --- transient thermal contact (§6.3) --------------------------------------------------------------

def test_energy_balance_every_step_and_flux_only_on_contact():
    s, c = rough_contact(32)
    motion = Rotation((70.7e-3, 70.7e-3), SpeedProfile.constant(50.0))
    dt = 1e-4
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, motion, dt, 12)
    r = sol.run(c.pressure, 0.4, field_times=[6 * dt, 12 * dt])
    reference = 0.4 * motion.radius * 50.0 * c.pressure.sum() * s.dx * s.dy     # mu V F_n
    assert np.allclose(r.heat_1 + r.heat_2, reference, rtol=1e-8, atol=0)
    assert np.all((r.partition_1 > 0.5) & (r.partition_1 < 1)) and np.all(r.converged)
    assert np.all(r.flux_1[:, ~c.contact] == 0) and np.all(r.flux[:, ~c.contact] == 0)
    on = c.contact
    assert np.allclose(r.temperature_1[:, on], r.temperature_2[:, on], rtol=0, atol=1e-6 * r.temperature_2.max())


def test_batched_patches_match_single_runs():
    s, c = rough_contact(16)
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, Translation.steady(2.0), 1e-4, 3)
    both = sol.run(np.stack([c.pressure, 2 * c.pressure[::-1]]), 0.4, field_times=[3e-4])
    for i, p in enumerate((c.pressure, 2 * c.pressure[::-1])):
        one = sol.run(p, 0.4, field_times=[3e-4])
        assert np.allclose(both.partition_1[:, i], one.partition_1, rtol=1e-9)
        assert np.allclose(both.temperature_1[:, i], one.temperature_1, rtol=1e-7, atol=1e-9 * one.temperature_1.max())


def test_fft_grids_padded_to_5_smooth_lengths_give_the_same_heating(monkeypatch):
    """A 22² window is transformed on 48² (``kernels.padded_size``: 22 -> 24), not 44²: the same
    linear convolutions, so the same temperatures (the steady moving tables' quadrature reaches
    the larger table's corners: 3e-11)."""
    assert padded_size(22) == 24 and padded_size(24) == 24
    s, c = rough_contact(22)
    motion = Rotation((70.7e-3, 70.7e-3), SpeedProfile.constant(50.0))
    runs, grids = [], []
    for exact in (True, False):
        if exact:
            monkeypatch.setattr(heating, "padded_size", int)   # the FFT grid exactly 2N
        else:
            monkeypatch.undo()
        fft.reset_fft_counts()
        runs.append((TransientHeating(s.shape, s.dx, DISC, PIN, motion, 1e-4, 6).run(c.pressure, 0.4,
                                                                                      field_times=[6e-4]),
                     SteadyHeating(s.shape, s.dx, DISC, PIN, 3.0).solve(c.pressure, 0.4)))
        grids.append({g for g, counts in fft.fft_counts().items() if any(counts)})
    assert grids == [{(44, 44)}, {(48, 48)}]
    (t_2n, s_2n), (t_pad, s_pad) = runs
    assert np.allclose(t_pad.temperature_1, t_2n.temperature_1, rtol=0, atol=1e-12 * t_2n.temperature_1.max())
    assert np.allclose(t_pad.partition_1, t_2n.partition_1, rtol=1e-12)
    assert np.allclose(s_pad.temperature_1, s_2n.temperature_1, rtol=0, atol=1e-9 * s_2n.temperature_1.max())
    assert s_pad.partition_1 == pytest.approx(s_2n.partition_1, rel=1e-9)


def test_two_stationary_bodies_share_heat_by_effusivity_then_by_conductivity():
    n, dx = 24, 1e-3 / 24
    still = Translation.steady(1e-12)                  # at rest (1e-12 m/s) but generating heat
    p = np.full((n, n), 1e15)
    e_ratio = DISC.effusivity / (DISC.effusivity + PIN.effusivity)
    short = TransientHeating((n, n), dx, DISC, PIN, still, 1e-7, 4).run(p, 0.4, field_times=[4e-7])
    assert short.partition_1 == pytest.approx(e_ratio, rel=1e-9)     # sqrt(chi t) << cell: 1-D everywhere
    assert (short.flux_1[0] / short.flux[0])[n // 2, n // 2] == pytest.approx(e_ratio, rel=1e-9)
    k_ratio = DISC.kappa / (DISC.kappa + PIN.kappa)
    steady = SteadyHeating((n, n), dx, DISC, PIN, 0.0).solve(p, 0.4, remote_temperatures=(0.0, 0.0))
    assert np.isnan(steady.partition_1)                # no heat at rest: partition undefined, says NaN
    fixed = SteadyHeating((n, n), dx, DISC, PIN, 1e-12).solve(p, 0.4)
    assert fixed.partition_1 == pytest.approx(k_ratio, rel=1e-6)
    late = TransientHeating((n, n), dx, DISC, PIN, still, 1.0, 3).run(p, 0.4)
    gaps = np.abs(late.partition_1 - k_ratio)
    assert gaps[-1] < gaps[0] < abs(e_ratio - k_ratio)


def test_transient_tends_to_the_steady_sliding_state():
    s, c = rough_contact(24)
    motion = Translation.steady(5.0)
    steady = SteadyHeating(s.shape, s.dx, DISC, PIN, 5.0).solve(c.pressure, 0.4)
    values = []
    for t in (0.05, 0.2):                               # fixed body 2: deficit ~ 1/sqrt(t)
        r = TransientHeating(s.shape, s.dx, DISC, PIN, motion, t / 4, 4).run(c.pressure, 0.4)
        values.append((r.partition_1[-1], r.max_temperature_2[-1]))
    (p1a, Ta), (p1b, Tb) = values
    assert abs(p1b - steady.partition_1) < abs(p1a - steady.partition_1)
    assert 2 * p1b - p1a == pytest.approx(steady.partition_1, abs=1e-3)      # Richardson in 1/sqrt(t)
    assert 2 * Tb - Ta == pytest.approx(steady.max_temperature_2, rel=2e-2)


def spot_case(cells, n_steps=4, dt=5e-5, speed=2.0):
    """A 100 um square contact spot on a 2x larger window, uniform 50 MPa."""
    n = 2 * cells
    dx = 1e-4 / cells
    p = np.zeros((n, n))
    p[cells // 2: cells // 2 + cells, cells // 2: cells // 2 + cells] = 50e6
    r = TransientHeating((n, n), dx, DISC, PIN, Translation.steady(speed), dt, n_steps).run(p, 0.4)
    return r.partition_1[-1], r.max_temperature_2[-1]


def test_convergence_in_grid_size():
    a, b, c = (np.array(spot_case(cells)) for cells in (4, 8, 16))
    e1, e2 = np.abs(b - a), np.abs(c - b)
    assert np.all(e2 < 0.6 * e1)
    assert e2[0] < 2e-3 and e2[1] < 0.03 * c[1]


def test_convergence_in_time_step():
    s, c = rough_contact(24)
    motion = Translation.steady(1.0)
    t_end = 4e-4
    runs = []
    for steps in (4, 8, 16):
        r = TransientHeating(s.shape, s.dx, DISC, PIN, motion, t_end / steps, steps).run(c.pressure, 0.4)
        runs.append(np.array([r.partition_1[-1], r.max_temperature_1[-1]]))
    e1, e2 = np.abs(runs[1] - runs[0]), np.abs(runs[2] - runs[1])
    assert np.all(e2 < 0.7 * e1)                      # first order in dt (fluxes constant per step)
    assert e2[0] < 5e-3 and e2[1] < 0.05 * runs[2][1]


def test_varying_speed_path_equals_constant_speed_path():
    s, c = rough_contact(16)
    ref = TransientHeating(s.shape, s.dx, DISC, PIN, Translation.steady(3.0), 1e-4, 5).run(c.pressure, 0.4)
    nearly = Translation(SpeedProfile((0.0, 1.0), (3.0, 3.0 * (1 + 1e-12))))
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, nearly, 1e-4, 5)
    assert not sol.toeplitz
    r = sol.run(c.pressure, 0.4)
    assert np.allclose(r.partition_1, ref.partition_1, rtol=1e-9)
    assert np.allclose(r.max_temperature_1, ref.max_temperature_1, rtol=1e-7)


def test_stop_reverses_the_heat_flow_between_the_bodies_without_oscillation():
    """Eq. 6.6 braking to rest (Fig. 6.30-6.33 case): after the stop no heat is generated, one body
    gives heat to the other, smoothly. (The thesis reports Phi_1 < 0 after the stop; here the fixed
    pin, heated at the same spots all along, gives heat back to the disc: Phi_2 < 0 < Phi_1.)"""
    s, c = rough_contact(24)
    t0, dt = 10e-3, 0.5e-3
    motion = Rotation((70.7e-3, 70.7e-3), SpeedProfile.ramp(10.0, 0.0, t0))
    r = TransientHeating(s.shape, s.dx, DISC, PIN, motion, dt, 40).run(c.pressure, 0.4)
    after = r.times > t0 + 1e-12
    assert np.all(r.heat[after] == 0) and np.all(r.heat[~after] > 0)
    assert np.all(np.abs(r.heat_1[after] + r.heat_2[after]) < 1e-12 * r.heat.max())
    assert r.heat_2[0] > 0 and np.all(r.heat_2[after] < 0)        # the sign change
    assert np.all(np.diff(r.heat_1[after]) < 0) and np.all(r.heat_1[after] > 0)   # smooth decay
    assert np.all(np.diff(r.max_temperature_2[after]) < 0)
    assert np.all(np.isnan(r.partition_1[after])) and np.all(np.isfinite(r.partition_1[~after]))


@pytest.mark.parametrize("omega,dt", [(1e3, 1e-7), (1e3, 1e-2), (1.0, 1e-2), (1e3, 1e-5)])
@pytest.mark.parametrize("contact", ["one cell", "full"])
def test_hard_cases_stay_finite(omega, dt, contact):
    n, dx = 16, 1e-3 / 16
    p = np.zeros((n, n))
    if contact == "one cell":
        p[5, 9] = 1e8
    else:
        p[:] = 1e6
    motion = Rotation((70.7e-3, 70.7e-3), SpeedProfile.constant(omega))
    r = TransientHeating((n, n), dx, DISC, PIN, motion, dt, 3).run(p, 0.4)
    assert np.all(r.converged)
    assert np.all(np.isfinite(r.max_temperature_1)) and np.all(np.isfinite(r.max_temperature_2))
    assert np.all((r.partition_1 > 0) & (r.partition_1 < 1))


# --- interface layer (§6.3.3) ----------------------------------------------------------------------

def test_zero_resistance_layer_is_the_perfect_contact():
    s, c = rough_contact(16)
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, Translation.steady(5.0), 1e-4, 4)
    a = sol.run(c.pressure, 0.4)
    b = sol.run(c.pressure, 0.4, interface=InterfaceLayer(0.0, 1e4, n=10, generation="uniform"))
    assert np.allclose(a.partition_1, b.partition_1, rtol=1e-12)


def test_interface_gap_follows_the_rc_history_formula():
    """θ2 − θ1 on the contact = Σ_k Σ_m (1 − exp(−(t_N − t_k)/(R C))) R Δ(φ1 − c_m φ)_k (§6.3.3)."""
    s, c = rough_contact(16)
    dt, steps = 1e-4, 6
    layer = InterfaceLayer((2e-6, 1e-6, 3e-6), (20.0, 50.0, 0.0), n=3, generation="linear")
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, Translation.steady(5.0), dt, steps)
    r = sol.run(c.pressure, 0.4, interface=layer, field_times=dt * np.arange(1, steps + 1))
    R, C = np.array(layer.resistance), np.array(layer.capacitance)
    cm = np.cumsum(layer.weights)[:-1]
    varphi = r.flux_1[:, None] - cm[None, :, None, None] * r.flux[:, None]         # (k, m, ny, nx)
    increments = np.diff(varphi, axis=0, prepend=0.0)
    lag = r.times[-1] - (r.times - dt)                                              # t_N - t_k
    with np.errstate(divide="ignore"):
        memory = np.where(C > 0, 1 - np.exp(-lag[:, None] / (R * C)), 1.0)          # (k, m)
    gap = np.einsum("km,m,kmij->ij", memory, R, increments)
    on = c.contact
    jump = r.temperature_2[-1] - r.temperature_1[-1]
    assert np.allclose(jump[on], gap[on], rtol=0, atol=1e-6 * np.abs(gap[on]).max())
    assert np.all(gap[on] != 0)


def test_heating_plane_next_to_a_body_sends_the_heat_into_it():
    s, c = rough_contact(16)
    sol = SteadyHeating(s.shape, s.dx, DISC, PIN, 5.0)
    near_1 = sol.solve(c.pressure, 0.4, interface=InterfaceLayer(1.0, n=2, generation="plane", plane=0.0))
    near_2 = sol.solve(c.pressure, 0.4, interface=InterfaceLayer(1.0, n=2, generation="plane", plane=1.0))
    middle = sol.solve(c.pressure, 0.4, interface=InterfaceLayer(1e-6, n=2, generation="plane", plane=0.5))
    perfect = sol.solve(c.pressure, 0.4)
    assert near_1.partition_1 > 1 - 1e-4 and near_2.partition_1 < 1e-4
    assert near_2.partition_1 < middle.partition_1 < perfect.partition_1 + 1e-3
    assert InterfaceLayer(n=3, generation="linear").weights == pytest.approx([0.4, 0.3, 0.2, 0.1])


# --- steady sliding with remote temperatures (§6.5) and the partition law --------------------------

def test_remote_temperatures_conduct_through_a_circular_spot_like_two_constrictions():
    n, dx = 40, 1e-5
    y, x = np.mgrid[:n, :n] - (n - 1) / 2
    p = np.where(np.hypot(x, y) < 14, 1e6, 0.0)
    a = np.sqrt(np.count_nonzero(p) / np.pi) * dx
    sol = SteadyHeating((n, n), dx, DISC, PIN, 0.0)
    r = sol.solve(p, 0.4, remote_temperatures=(1.0, 0.0))
    conductance = holm_conductance(a, DISC.kappa, PIN.kappa)                    # isothermal circles
    assert -r.heat_1 == pytest.approx(conductance * 1.0, rel=0.02)
    assert r.heat == 0 and r.heat_2 == pytest.approx(-r.heat_1, rel=1e-12)


def test_remote_temperatures_shift_the_partition_as_in_section_6_5():
    s, c = rough_contact(24)
    sol = SteadyHeating(s.shape, s.dx, DISC, PIN, 1.0)
    base = sol.solve(c.pressure, 0.4)
    hot1 = sol.solve(c.pressure, 0.4, remote_temperatures=(10.0, 0.0))
    hot2 = sol.solve(c.pressure, 0.4, remote_temperatures=(0.0, 10.0))
    conduct = sol.solve(c.pressure * 1e-30, 0.4, remote_temperatures=(10.0, 0.0))   # ~ no heat
    assert hot1.partition_1 < base.partition_1 < hot2.partition_1
    assert hot1.heat_1 == pytest.approx(base.heat_1 + conduct.heat_1, rel=1e-6)   # superposition
    on = c.contact
    assert np.allclose(hot1.temperature_1[on], hot1.temperature_2[on], atol=1e-6 * hot1.temperature_2.max())


def test_partition_law_from_surface_and_from_contact_result_agree():
    s = fractal_surface(32, 1e-3, 0.8, 2, 8, 6.49e-6, seed=5)
    loads = np.array([1e6, 4e6, 16e6])
    law = partition_law(s, DISC, PIN, [1.0, 10.0], loads, mu=0.4, elastic=ELASTIC)
    assert law.partition_1.shape == (2, 3) and np.all(np.diff(law.area_fraction) > 0)
    assert np.all((law.partition_1 > 0.5) & (law.partition_1 < 1))
    assert np.all(law.partition_1[1] > law.partition_1[0])               # faster: more into the disc
    assert law(4e6, 10.0) == pytest.approx(law.partition_1[1, 1], rel=1e-12)
    # linear in log p and in V: 2 MPa and 5.5 m/s are the midpoints of (1, 4) MPa and (1, 10) m/s
    assert law(2e6, 5.5) == pytest.approx(law.partition_1[:, :2].mean(axis=0).mean(), rel=1e-12)
    contact = ContactSolver(ELASTIC, s.shape, s.dx, periodic=True).solve(
        np.broadcast_to(s.heights, (3,) + s.shape), load=loads)
    again = partition_law(contact, DISC, PIN, 10.0, mu=0.4, dx=s.dx)
    assert np.allclose(again.partition_1[0], law.partition_1[1], rtol=1e-9)
    assert again(50e6) == pytest.approx(law.partition_1[1, -1])           # clamped



def test_partition_law_refuses_a_nan_pressure_or_speed():
    """A NaN pressure or speed gave a NaN partition (clipping and interpolation pass NaN through;
    an adversarial test): an InputError naming it."""
    law = PartitionLaw(np.array([1e6, 4e6]), np.array([1.0, 10.0]), np.array([[0.6, 0.7], [0.8, 0.9]]),
                       np.array([0.1, 0.2]), np.zeros((2, 2)), np.zeros((2, 2)), mu=0.4)
    assert law([2e6, 50e6], 10.0) == pytest.approx([0.85, 0.9], rel=1e-12)
    for pressure, speed, name in ((np.nan, 1.0, "pressure"), ([1e6, np.inf], 1.0, "pressure"), (1e6, np.nan, "speed")):
        with pytest.raises(InputError, match=f"^{name} = .*must be finite"):
            law(pressure, speed)


# --- errors -------------------------------------------------------------------------------------

def test_errors_name_the_argument():
    with pytest.raises(InputError, match="end"):
        SpeedProfile.ramp(10.0, -1.0, 0.1)
    with pytest.raises(InputError, match="pressure"):
        TransientHeating((8, 8), 1e-5, DISC, PIN, Translation.steady(1.0), 1e-4, 2).run(-np.ones((8, 8)), 0.4)
    with pytest.raises(InputError, match="dt"):
        TransientHeating((8, 8), 1e-5, DISC, PIN, Translation.steady(1.0), 0.0, 2)
    with pytest.raises(InputError, match="generation"):
        InterfaceLayer(1e-6, n=2, generation="parabolic")
    with pytest.raises(InputError, match="speed"):
        partition_law(Surface(np.zeros((8, 8)), 1e-5, 1e-5), DISC, PIN, 0.0, [1e6], mu=0.4, elastic=ELASTIC)
    # a rotating patch on or near the axis: no heat and NaN partitions, or one speed where the patch's
    # points move at several times it in opposite directions (a user trial); 0.8 mm x 0.8 mm: 0.566 mm
    with pytest.raises(InputError, match=r"^pressures = \[\]: one or more mean pressures > 0"):   # (blamed the
        partition_law(Surface(np.zeros((8, 8)), 1e-5, 1e-5), DISC, PIN, 1.0, [], mu=0.4, elastic=ELASTIC)  # heights)
    for centre in ((0.0, 0.0), (1e-4, 0.0), (0.0, -2.8e-3)):       # half-diagonal: refused within 2.83 mm
        with pytest.raises(InputError, match=r"^motion.centre = .*within 5 x the patch's half-diagonal 0.000566 m"):
            TransientHeating((8, 8), 1e-4, DISC, PIN, Rotation(centre, SpeedProfile.constant(10.0)), 1e-4, 2)
    TransientHeating((8, 8), 1e-4, DISC, PIN, Rotation((0.0, -2.9e-3), SpeedProfile.constant(10.0)), 1e-4, 2)


def test_non_convergence_raises_or_flags():
    s, c = rough_contact(16)
    sol = TransientHeating(s.shape, s.dx, DISC, PIN, Translation.steady(1.0), 1e-4, 2)
    with pytest.raises(HeatingConvergenceError) as info:
        sol.run(c.pressure, 0.4, max_iter=1, tol=1e-14)
    assert info.value.result is not None and info.value.history
    r = sol.run(c.pressure, 0.4, max_iter=1, tol=1e-14, partial=True)
    assert not np.any(r.converged) and np.allclose(r.heat_1 + r.heat_2, r.heat, rtol=1e-12)


def test_the_tables_memory_is_estimated_and_a_run_that_cannot_fit_is_refused(monkeypatch):
    """``TransientHeating.memory`` is the tables' traced peak to 5 % (both bodies' spectra and their
    build); 200 000 steps on 64² (99 GiB) were a raw MemoryError, or tens of GB asked for (a user
    trial): refused at once beyond the machine's memory."""
    import tracemalloc
    b1, b2 = ThermalMaterial(50.0, 1.4e-5), ThermalMaterial(15.0, 5e-6)
    motion = Translation(SpeedProfile.constant(1.0))
    tracemalloc.start()
    try:
        TransientHeating((32, 32), 1e-3 / 32, b1, b2, motion, dt=1e-5, n_steps=300)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak == pytest.approx(TransientHeating.memory((32, 32), 300), rel=0.05)
    monkeypatch.setattr(memory, "memory_limit", lambda: 2.0 ** 30)
    with pytest.raises(InputError, match=r"n_steps = 20000: the pulse tables of 20000 steps on a 32 x 32 grid take "
                                         r"about 2.52 GiB, more than the 1 GiB this process may use \(the machine's, "
                                         r"or its container's or job's limit\)"):
        TransientHeating((32, 32), 1e-3 / 32, b1, b2, motion, dt=1e-5, n_steps=20000)

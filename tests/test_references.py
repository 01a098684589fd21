"""Analytic references (multiscale.references): internal consistency, known values, bad input.

The solvers are checked against these functions in the micro tests; here the functions are checked
against each other and against published numbers."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.references import conduction, heat, hertz, layered, stability, westergaard


def test_sphere_on_flat_load_and_radius_forms_agree():
    R, E = 5e-3, 2e9
    by_load = hertz.sphere_on_flat(0.3, R, E)
    by_radius = hertz.sphere_on_flat_at_radius(by_load.contact_radius, R, E)
    for name in ("load", "contact_radius", "max_pressure", "approach"):
        assert getattr(by_radius, name) == pytest.approx(getattr(by_load, name), rel=1e-12)
    assert hertz.sphere_load(by_load.approach, R, E) == pytest.approx(0.3, rel=1e-12)
    r = np.linspace(0, by_load.contact_radius, 201)                   # P = ∫ p 2πr dr
    p = by_load.pressure(r)
    assert np.trapezoid(p * 2 * np.pi * r, r) == pytest.approx(0.3, rel=1e-3)
    assert by_load.pressure(2 * by_load.contact_radius) == 0.0
    with pytest.raises(InputError, match="load"):
        hertz.sphere_on_flat(-1.0, R, E)


def test_elliptic_coefficients_reduce_to_the_sphere():
    assert hertz.hertz_F1(0.0) == pytest.approx(1.0) and hertz.hertz_A1(0.0) == pytest.approx(1.0)
    assert hertz.curvature_ratio(1.0) == pytest.approx(1.0, rel=1e-14)
    assert hertz.axis_ratio_squared(1.0) == 1.0


def test_westergaard_partial_contact_meets_full_contact():
    p_star = westergaard.complete_contact_pressure(1e-6, 1e-3, 1e9)
    assert p_star == pytest.approx(np.pi * 1e9 * 1e-6 / 1e-3)
    assert westergaard.partial_contact_mean_pressure(1.0, 1e-6, 1e-3, 1e9) == pytest.approx(p_star)
    assert westergaard.full_contact_pressure(0.5e-3, p_star, 1e-6, 1e-3, 1e9) == pytest.approx(0.0, abs=1e-9 * p_star)
    with pytest.raises(InputError, match="mean_pressure"):
        westergaard.full_contact_pressure(0.0, 0.5 * p_star, 1e-6, 1e-3, 1e9)


def test_layer_on_rigid_base_limits():
    h, E, nu = 1e-4, 4e9, 0.3
    assert layered.layer_on_rigid_base_compliance(1e-4 / h, h, E, nu) == pytest.approx(
        layered.oedometric_compliance(h, E, nu), rel=1e-6)                   # long waves: oedometric
    q = 30 / h                                                             # short waves: half-space
    assert q * layered.layer_on_rigid_base_compliance(q, h, E, nu) == pytest.approx(2 * (1 - nu**2) / E)
    thin = layered.thin_layer_sphere(1e-6, 1e-2, h, E, nu)
    assert thin.contact_radius == pytest.approx(np.sqrt(2e-8))


def test_conduction_closed_forms():
    assert conduction.holm_conductance(1e-4, 10.0, 10.0) == pytest.approx(4e-4 * 5.0)
    assert conduction.flux_tube_factor(0.0) == 1.0
    q = np.geomspace(1e2, 1e6, 9)
    same = conduction.thermal_layer_compliance(q, 1e-4, 10.0, 10.0)            # identical half-space
    np.testing.assert_allclose(same, 1 / (10.0 * q), rtol=1e-14)
    uniform = conduction.exponential_graded_compliance(np.array([0.0, 1e3]), 10.0, 1e-3, 1e-3)   # beta H << 1
    np.testing.assert_allclose(uniform, conduction.thermal_layer_compliance(np.array([1e-9, 1e3]), 1e-3, 10.0),
                               rtol=1e-5)


def test_heat_source_closed_forms():
    fixed = heat.fixed_square_source(0.5, 1.0)
    assert fixed.centre == pytest.approx(0.5 * 1.1222, abs=1e-4) and fixed.mean == pytest.approx(0.5 * 0.9464, abs=1e-4)
    fast = heat.fast_square_source(1.0, 100.0, 2.0)
    assert fast.mean == pytest.approx(0.752 / (2.0 * 10.0), rel=1e-3) and fast.centre < fast.maximum
    # the trailing edge has been heated for 2l/V = l²/(Pe chi): the 1-D rise
    chi = 1e-5
    assert fast.maximum == pytest.approx(heat.uniform_flux_temperature(1.0 / (100.0 * chi), 2.0, chi), rel=1e-12)
    assert heat.point_source_deficit(4.0, 1.0, 1.0, 1.0) == pytest.approx(1 / (4 * np.pi**1.5))


def test_hoffmann_model():
    K, M = stability.hoffmann_matrices(0.2)
    np.testing.assert_array_equal(K, [[1.0, 0.3 - 0.2], [0.3, 1.5]])
    np.testing.assert_array_equal(M, np.eye(2))
    mu_c = stability.hoffmann_onset(1.0, 1.5, 0.3, 0.3, 1.0)
    assert mu_c == pytest.approx(0.508333333333, abs=1e-9)
    below, at, above = (stability.hoffmann_eigenvalues(mu) for mu in (0.9 * mu_c, mu_c, 1.1 * mu_c))
    assert np.all(below.imag == 0) and np.ptp(at) == pytest.approx(0.0, abs=1e-7) and np.all(above.imag != 0)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real),
                               stability.hoffmann_eigenvalues(0.2).real, rtol=1e-12)
    with pytest.raises(InputError, match="mu"):
        stability.hoffmann_matrices(-0.1)
    with pytest.raises(InputError, match="mass"):
        stability.hoffmann_matrices(0.1, mass=0.0)
    with pytest.raises(InputError, match="k21"):
        stability.hoffmann_onset(1.0, 1.5, 0.3, 0.0, 1.0)

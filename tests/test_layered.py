"""Layered and graded kernels (thesis §2.2, §3.3.3, §5.3, App. A/B) against closed forms,
a 60-digit evaluation of the thesis' own propagator, and brute-force influence integrals."""
from decimal import Decimal, localcontext

import numpy as np
import pytest
from scipy.special import j0

from multiscale.errors import InputError
from multiscale.micro.kernels import HalfSpace, InfluenceOperator, ThermalHalfSpace
from multiscale.micro.layered import LayeredElastic, LayeredThermal, layer_boundaries, layer_means
from multiscale.micro.surface import fractal_surface
from multiscale.references.conduction import exponential_graded_compliance, thermal_layer_compliance
from multiscale.references.layered import layer_on_rigid_base_compliance, oedometric_compliance
from multiscale.references.love import love_rectangle


# ----------------------------------------------------------------------------- references
def propagator_reference(q, thickness, E, nu, substrate_E=None, substrate_nu=0.3):
    """F(q) from the product of layer propagators exp(-A q h) (thesis Eq. 2.4, App. B), 60 digits."""
    D = Decimal
    with localcontext() as ctx:
        ctx.prec = 60

        def mm(a, b):
            return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(len(b[0]))] for i in range(len(a))]

        def expm(a):
            s = 0
            norm = max(sum(abs(x) for x in row) for row in a)
            while norm > 0.5:
                norm, s = norm / 2, s + 1
            m = [[x / 2**s for x in row] for row in a]
            term = [[D(int(i == j)) for j in range(4)] for i in range(4)]
            out = [row[:] for row in term]
            for k in range(1, 40):
                term = [[x / k for x in row] for row in mm(term, m)]
                out = [[out[i][j] + term[i][j] for j in range(4)] for i in range(4)]
            for _ in range(s):
                out = mm(out, out)
            return out

        P = [[D(int(i == j)) for j in range(4)] for i in range(4)]
        for h, e, n in zip(thickness, E, nu):
            n, mu, t = D(float(n)), D(float(e)) / (2 * (1 + D(float(n)))), -D(float(q)) * D(float(h))
            A = [[0, n / (1 - n), (1 - 2 * n) / (2 * mu * (1 - n)), 0], [-1, 0, 0, 1 / mu], [0, 0, 0, 1],
                 [0, 2 * mu / (1 - n), -n / (1 - n), 0]]
            P = mm(P, expm([[D(x) * t for x in row] for row in A]))
        if substrate_E is None:            # rigid base: bottom displacements vanish
            cols = [row[2:] for row in P]
        else:                              # half-space: decaying modes only
            nb = D(substrate_nu)
            mu = D(float(substrate_E)) / (2 * (1 + nb))
            cols = mm(P, [[-1, -(3 - 4 * nb)], [1, 0], [2 * mu, 4 * mu * (1 - nb)], [-2 * mu, -2 * mu * (1 - 2 * nb)]])
        det = cols[2][0] * cols[3][1] - cols[2][1] * cols[3][0]
        c00 = (cols[0][0] * cols[3][1] - cols[0][1] * cols[3][0]) / det
        return float(-c00 / D(float(q)))


def brute_influence(kernel, offsets, dx, dy, ng=8):
    """Cell integrals of the remainder g(r) = (1/2pi) ∫ excess(q)/q J0(q r) q dq: uniform-panel
    Gauss quadrature in q (250 panels) and ng x ng Gauss points on the cell, no splines."""
    q_cut = kernel.cutoff()
    x, w = np.polynomial.legendre.leggauss(24)
    edges = np.linspace(0, q_cut, 251)
    q = ((edges[:-1, None] + edges[1:, None]) / 2 + np.diff(edges)[:, None] / 2 * x).ravel()
    R = kernel.excess(q) * (np.diff(edges)[:, None] / 2 * w).ravel() / (2 * np.pi)
    xg, wg = np.polynomial.legendre.leggauss(ng)
    out = []
    for i, j in offsets:
        r = np.hypot(i * dx + xg[:, None] * dx / 2, j * dy + xg[None, :] * dy / 2).ravel()
        g = (j0(np.outer(r, q)) @ R).reshape(ng, ng)
        love = love_rectangle(i * dx, j * dy, dx / 2, dy / 2) * kernel.top_coefficient / (2 * np.pi)
        out.append(love + wg @ g @ wg * dx * dy / 4)
    return np.array(out)


# ----------------------------------------------------------------------------- elastic
def test_identical_layers_are_the_homogeneous_half_space():
    E, nu = 4e9, 0.15
    hs = HalfSpace.from_materials(E, nu)
    lay = LayeredElastic([1e-5, 3e-5, 1e-4], [E] * 3, [nu] * 3, substrate_E=E, substrate_nu=nu)
    q = np.geomspace(1e-2, 1e10, 300)
    assert np.max(np.abs(lay.compliance(q) / hs.compliance(q) - 1)) < 1e-8
    assert lay.compliance(np.array([0.0]))[0] == 0.0            # infinite at q = 0, like HalfSpace
    assert np.allclose(lay.influence(8, 6, 2e-6, 3e-6), hs.influence(8, 6, 2e-6, 3e-6), rtol=1e-13, atol=0)
    th = LayeredThermal([1e-5, 2e-5], [10.0, 10.0], 10.0)
    assert np.max(np.abs(th.compliance(q) / ThermalHalfSpace(10.0).compliance(q) - 1)) < 1e-8


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.499])
def test_layer_on_rigid_base_matches_carbone_mangialardi_and_oedometric_limit(nu):
    E, h = 4e9, 1e-4
    lay = LayeredElastic([h], [E], [nu])
    t = np.geomspace(1e-6, 300, 200)
    F = lay.compliance(t / h)
    assert np.max(np.abs(F / layer_on_rigid_base_compliance(t / h, h, E, nu) - 1)) < 1e-8
    oedometric = oedometric_compliance(h, E, nu)
    assert lay.static_compliance == pytest.approx(oedometric, rel=1e-14)
    assert lay.compliance(np.array([0.0]))[0] == lay.static_compliance
    # k h = 1e-6: the limit is approached more slowly as the layer becomes incompressible
    # (measured 1.7e-10 at nu = 0.499, below 1e-12 otherwise)
    assert F[0] == pytest.approx(oedometric, rel=1e-12 / (1 - 2 * nu))


def test_stacks_match_60_digit_propagator():
    rng = np.random.default_rng(3)
    for trial in range(6):
        n = int(rng.integers(1, 4))
        h = 10 ** rng.uniform(-5, -3.5, n)
        E = 10 ** rng.uniform(8, 11, n)
        nu = rng.uniform(0.0, 0.49, n)
        sub = None if trial % 2 else 10 ** rng.uniform(8, 11)
        lay = LayeredElastic(h, E, nu, substrate_E=np.inf if sub is None else sub, substrate_nu=0.25)
        for q in (3e-3 / h.sum(), 0.3 / h.sum(), 4.0 / h.sum()):
            ref = propagator_reference(q, h, E, nu, sub, 0.25)
            assert lay.compliance(np.array([q]))[0] == pytest.approx(ref, rel=1e-9)


def test_hard_cases_finite_positive_monotone():
    """F > 0 and finite everywhere. Monotone where theory says so: q F between its two limits for
    one layer, and the thermal F (decreasing in q). The elastic F itself is not monotone in
    general: a bonded layer on a stiffer base is confined at long wavelengths (slightly for
    nu = 0.3, strongly for nu -> 0.5), so F first rises with q (checked against the closed form)."""
    """F > 0 and finite everywhere; F decreasing for compressible stacks (nearly incompressible
    bonded layers are stiffer at long wavelengths: confined squeeze, F is not monotone there);
    q F monotone between its limits for one layer; q F -> 2/E1* at large q h."""
    q = np.geomspace(1e-6, 1e4, 400)                  # q h for h = 1 (and h_total up to 50)
    cases = [LayeredElastic([1.0], [1.0], [0.499], substrate_E=1e3, substrate_nu=0.499),
             LayeredElastic([1.0], [1.0], [0.3], substrate_E=1e-3),
             LayeredElastic([1.0], [1e3], [0.499]),
             LayeredElastic([1.0], [1e-3], [0.2], substrate_E=1e3),
             LayeredElastic([1.0], [1e3], [0.3], substrate_E=1e-3, substrate_nu=0.3),
             LayeredElastic(np.ones(50), np.geomspace(1e-3, 1e3, 50), np.linspace(0.0, 0.499, 50),
                            substrate_E=1.0, substrate_nu=0.499),
             LayeredElastic(np.geomspace(1e-3, 1.0, 50), np.geomspace(1e3, 1e-3, 50), np.full(50, 0.45)),
             LayeredThermal([1.0], [1.0], 1e-3), LayeredThermal([1.0], [1.0], 1e3),
             LayeredThermal(np.ones(50), np.geomspace(1e-3, 1e3, 50)),
             LayeredThermal(np.geomspace(1e-3, 1.0, 50), np.geomspace(1e3, 1e-3, 50), 1.0)]
    for kernel in cases:
        F = kernel.compliance(q)
        assert np.all(np.isfinite(F)) and np.all(F > 0)
        if isinstance(kernel, LayeredThermal):
            assert np.all(np.diff(F) < 1e-12 * F[:-1]), kernel        # longer waves heat more
        qF = q * F
        A = kernel.top_coefficient
        deep = q * kernel.thickness[0] > 40
        assert np.all(np.abs(qF[deep] / A - 1) < 1e-12)               # short waves see the top layer
        if len(kernel.thickness) == 1:                                 # one layer: monotone between limits
            d = np.diff(qF)
            assert np.all(d >= -1e-14 * A) or np.all(d <= 1e-14 * A), kernel


def test_elastic_trends_stiffer_substrate_and_thinner_layer_lower_compliance():
    q = np.geomspace(1e2, 1e6, 50)
    soft = LayeredElastic([1e-4], [4e9], [0.15], substrate_E=4e9, substrate_nu=0.15).compliance(q)
    stiff = LayeredElastic([1e-4], [4e9], [0.15], substrate_E=40e9, substrate_nu=0.15).compliance(q)
    thin = LayeredElastic([5e-5], [4e9], [0.15], substrate_E=40e9, substrate_nu=0.15).compliance(q)
    assert np.all(stiff <= soft) and np.all(thin <= stiff)
    assert np.all((stiff < soft)[:25]) and np.all((thin < stiff)[:25])


# ----------------------------------------------------------------------------- thermal
def test_thermal_layer_on_half_space_closed_form():
    k1, k2, h = 10.0, 50.0, 2e-4
    q = np.geomspace(1.0, 1e8, 200)
    F = LayeredThermal([h], [k1], k2).compliance(q)
    assert np.max(np.abs(F / thermal_layer_compliance(q, h, k1, k2) - 1)) < 1e-12
    iso = LayeredThermal([h], [k1]).compliance(q)                    # fixed temperature below
    assert np.max(np.abs(iso / thermal_layer_compliance(q, h, k1) - 1)) < 1e-12


@pytest.mark.parametrize("ratio, Kp", [(1.0, 8.33e3), (0.5, 5.88e3), (0.25, 3.70e3)])
def test_series_limit_gives_table_5_4_perfect_contact_conductance(ratio, Kp):
    # Tables 5.1-5.4: S1 = 0.5 mm of kappa1 on 0.5 mm of 10 W/mK, in series with S2 = 1 mm of 50 W/mK
    kernel = LayeredThermal([0.5e-3, 0.5e-3, 1e-3], [10.0 * ratio, 10.0, 50.0])
    assert 1 / kernel.static_compliance == pytest.approx(Kp, abs=5.0)
    assert kernel.compliance(np.array([1e-3, 0.0])) == pytest.approx(kernel.static_compliance, rel=1e-9)


def test_graded_exponential_conductivity_converges_to_exact_at_second_order():
    k0, beta, H = 10.0, 3e3, 1e-3                      # kappa = k0 exp(beta z): e^3 contrast over 1 mm
    q = np.geomspace(1e2, 1e4, 7)
    exact = exponential_graded_compliance(q, k0, beta, H)
    errors = [np.max(np.abs(LayeredThermal.graded(lambda z: k0 * np.exp(beta * z), H, n).compliance(q) / exact - 1))
              for n in (10, 20, 40)]
    assert errors[2] < 5e-3
    assert errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5
    static = LayeredThermal.graded(lambda z: k0 * np.exp(beta * z), H, 7).static_compliance
    assert static == pytest.approx(exponential_graded_compliance(0.0, k0, beta, H), rel=1e-8)   # 1-D series


def test_graded_elastic_profile_converges():
    E = lambda z: 4e9 * (1 + 9 * z / 1e-3)            # noqa: E731 - 4 GPa at the surface, 40 GPa at 1 mm
    q = np.geomspace(1e2, 3e4, 9)
    F = [LayeredElastic.graded(E, 0.15, 1e-3, n, substrate_E=40e9, substrate_nu=0.15).compliance(q)
         for n in (8, 16, 32, 64)]
    d = [np.max(np.abs(F[i + 1] / F[i] - 1)) for i in range(3)]          # second order in 1/n
    assert d[2] < 0.01 and d[0] / d[1] > 3.3 and d[1] / d[2] > 3.3
    graded = LayeredElastic.graded(E, 0.15, 1e-3, 32, growth=1.1, substrate_E=40e9, substrate_nu=0.15)
    assert np.max(np.abs(graded.compliance(q) / F[-1] - 1)) < 0.01     # refined near the surface
    homogeneous = [LayeredElastic([1e-3], [e], [0.15], substrate_E=40e9, substrate_nu=0.15).compliance(q)
                   for e in (4e9, 40e9)]
    assert np.all(F[-1] < homogeneous[0]) and np.all(F[-1] > homogeneous[1])
    static = LayeredElastic.graded(E, 0.15, 1e-3, 5).static_compliance   # harmonic rule: exact
    factor = (1 + 0.15) * (1 - 0.3) / (1 - 0.15)                         # 1/M = factor / E (oedometric)
    assert static == pytest.approx(factor * np.log(10) * 1e-3 / (9 * 4e9), rel=1e-6)


def test_layer_boundaries_rule():
    h, z = layer_boundaries(1e-3, 4, growth=2.0)
    assert h == pytest.approx(1e-3 * np.array([1, 2, 4, 8]) / 15)
    assert z[-1] == pytest.approx(1e-3) and z[0] == 0
    assert layer_means(lambda z: 2 * z, [0.0, 1.0, 3.0]) == pytest.approx([1.0, 4.0])


# ----------------------------------------------------------------------------- influence
@pytest.mark.parametrize("kernel", [
    LayeredElastic([50e-6], [4e9], [0.3], substrate_E=40e9, substrate_nu=0.3),
    LayeredElastic([15e-6, 60e-6], [40e9, 4e9], [0.3, 0.2], substrate_E=1e9),
    LayeredElastic([30e-6, 60e-6], [4e9, 40e9], [0.3, 0.49]),
    LayeredThermal([40e-6], [10.0], 50.0)], ids=["soft-on-stiff", "stiff-on-soft", "rigid-base", "thermal"])
def test_influence_coefficients_match_brute_force(kernel):
    n, dx, dy = 12, 20e-6, 15e-6
    coeffs = kernel.influence(n, n, dy, dx)
    offsets = [(0, 0), (1, 0), (0, 1), (1, 1), (3, 2), (4, 4), (5, 0), (5, -3), (-9, 7), (11, 11), (-12, -12)]
    ref = brute_influence(kernel, offsets, dx, dy)
    got = np.array([coeffs[j % (2 * n), i % (2 * n)] for i, j in offsets])
    assert np.max(np.abs(got - ref)) < 1e-8 * coeffs[0, 0]
    assert abs(coeffs[0, 0] / (love_rectangle(0, 0, dx / 2, dy / 2) * kernel.top_coefficient / (2 * np.pi)) - 1) > 0.01


@pytest.mark.parametrize("kernel", [LayeredElastic([10e-6, 20e-6], [4e9, 40e9], [0.3, 0.3]),
                                    LayeredThermal([10e-6, 20e-6], [10.0, 50.0])], ids=["elastic", "thermal"])
def test_periodic_and_padded_operators_agree_for_a_smooth_compact_load(kernel):
    """Rigid (isothermal) base 30 um deep, patch 320 um: images are negligible, and the spectral
    (periodic) and piecewise-constant (padded) discretisations differ by O((dx / width)^2)."""
    n, dx = 64, 5e-6
    x = (np.arange(n) - n / 2) * dx
    r2 = x[:, None] ** 2 + x[None, :] ** 2
    diff = []
    for width in (15e-6, 25e-6):
        p = 1e6 * np.exp(-r2 / (2 * width**2))
        periodic = InfluenceOperator(kernel, (n, n), dx, periodic=True)(p)
        padded = InfluenceOperator(kernel, (n, n), dx, periodic=False)(p)
        diff.append(np.max(np.abs(periodic - padded)) / padded.max())
    assert diff[1] < 3e-3 and diff[0] / diff[1] > 2.2


def test_bad_input_is_named():
    with pytest.raises(InputError, match="thickness"):
        LayeredElastic([-1e-6], [1e9], [0.3])
    with pytest.raises(InputError, match="nu"):
        LayeredElastic([1e-6], [1e9], [0.6])
    with pytest.raises(InputError, match="E"):
        LayeredElastic([1e-6, 1e-6], [1e9], [0.3, 0.3])
    with pytest.raises(InputError, match="substrate_kappa"):
        LayeredThermal([1e-6], [1.0], substrate_kappa=-1.0)
    with pytest.raises(InputError, match="q"):
        LayeredThermal([1e-6], [1.0]).compliance(np.array([-1.0]))
    with pytest.raises(InputError, match="n_layers"):
        layer_boundaries(1e-3, 0)


def test_a_layer_too_thin_for_a_non_periodic_grid_is_refused():
    """A top layer under a thousandth of a cell is one clear InputError on a non-periodic grid
    (before: 47 s and 1.7 GB at dx/1560, out of memory at dx/1.5e6); the periodic grid takes its
    spectrum, which equals the half-space's to 1e-9 for a layer of the substrate's own material."""
    dx = 1e-4 / 64
    thin = LayeredElastic((1e-12,), (1e9,), (0.3,), 2e11, 0.3)
    with pytest.raises(InputError, match="thickness = 1e-12: the top layer is thinner than 0.001 of a cell"):
        InfluenceOperator(thin, (64, 64), dx, periodic=False)
    same = LayeredElastic((1e-12,), (2e11,), (0.3,), 2e11, 0.3)
    layered = InfluenceOperator(same, (64, 64), dx, periodic=True).multiplier
    np.testing.assert_allclose(layered, InfluenceOperator(HalfSpace.from_materials(2e11, 0.3, np.inf, 0.3), (64, 64),
                                                          dx, periodic=True).multiplier, rtol=1e-9)


@pytest.mark.parametrize("method", ["bccg", "pk"])
def test_displacement_control_of_a_layer_on_a_rigid_base_reaches_full_contact(method):
    """A layer on a rigid base has a finite static compliance F(0): a periodic patch in full contact
    carries a finite load, (delta - mean z) / F(0) + the relief's share. Displacement control gives
    load control's state at partial and full contact (it was refused above max(h) - mean(h), "full
    contact has no finite load": an adversarial test)."""
    from multiscale.micro.contact import ContactSolver
    s = fractal_surface(64, 1e-4, 0.8, 2, 16, 1e-7, seed=3)
    solver = ContactSolver(LayeredElastic((2e-6,), (2e9,), (0.45,)), s.shape, s.dx, method=method)
    for load in (1e7, 1e9):
        by_load = solver.solve(s.heights, load=load, tol=1e-10)
        by_approach = solver.solve(s.heights, approach=by_load.approach, tol=1e-10)
        assert by_approach.mean_pressure == pytest.approx(load, rel=1e-8)
        assert by_approach.area_fraction == by_load.area_fraction
    assert by_load.area_fraction == 1.0
    # an incompressible layer on a rigid base has F(0) = 0 (no uniform compression): full contact has no
    # finite load, refused at once (it ran 5000 iterations to an unexplained failure: a user trial)
    incompressible = ContactSolver(LayeredElastic((2e-6,), (2e9,), (0.5,)), s.shape, s.dx, method=method)
    assert incompressible.kernel.static_compliance == 0.0
    with pytest.raises(InputError, match="full contact has no finite load: an incompressible layer on a rigid "
                                         r"base, F\(0\) = 0"):
        incompressible.solve(s.heights, approach=1.01 * (s.heights.max() - s.heights.mean()))

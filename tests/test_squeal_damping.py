"""Damped linearised systems of the squeal analysis (issue 20): Hoffmann 2-DOF with damping,
Rayleigh damping ratios, the 1-DOF oscillator on a belt with a falling mu(v), stability maps."""
import numpy as np
import pytest
import scipy.linalg

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites before petsc4py)
from petsc4py import PETSc

from multiscale.errors import InputError
from multiscale.macro import damped, eigen
from multiscale.macro.dense import block_solve
from multiscale.macro.friction import StribeckFriction, TableFriction
from multiscale.macro.stability_map import BELOW, build_map
from multiscale.references.stability import (belt_onset_speed, damped_hoffmann_onset, hoffmann_matrices,
                                              hoffmann_onset, rayleigh_damping_ratio, stribeck,
                                              vanishing_damping_onset)

HOFFMANN = dict(k11=1.0, k22=1.5, k12=0.3, k21=0.3, k3=1.0)
MU_C = hoffmann_onset(**HOFFMANN)          # 0.508333...


def petsc_mat(A):
    A = np.atleast_2d(A)
    n = A.shape[0]
    m = PETSc.Mat().createAIJ([n, n], nnz=n, comm=PETSc.COMM_SELF)
    m.setUp()
    for i, j in zip(*np.nonzero(A)):
        m.setValue(i, j, A[i, j])
    m.assemble()
    return m


def hoffmann_system(mu, c1=0.0, c2=0.0):
    K, M = hoffmann_matrices(mu, **HOFFMANN)
    C = petsc_mat(np.diag([c1, c2])) if c1 or c2 else None
    return damped.LinearSystem(petsc_mat(K), petsc_mat(M), C)


def companion_eigenvalues(K, C, M):
    """lambda (omega >= 0) of det(lambda^2 M + lambda C + K) = 0 by numpy's dense eigvals."""
    n = K.shape[0]
    Minv = np.linalg.inv(M)
    lam = np.linalg.eigvals(np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]]))
    lam = lam[lam.imag > 0]
    return lam[np.lexsort((lam.real, lam.imag))]


# ---------------------------------------------------------------- Hoffmann 2-DOF with damping
@pytest.mark.parametrize("c", [(0.05, 0.05), (0.02, 0.08), (0.1, 0.0)])
def test_routh_hurwitz_onset_is_where_the_companion_form_turns_unstable(c):
    mu_c = damped_hoffmann_onset(*c, **HOFFMANN)
    for mu, sign in ((mu_c * (1 - 1e-6), -1), (mu_c * (1 + 1e-6), 1)):
        lam = companion_eigenvalues(hoffmann_matrices(mu, **HOFFMANN)[0], np.diag(c), np.eye(2))
        assert np.sign(lam.real.max()) == sign


def test_equal_damping_raises_and_unequal_damping_can_lower_the_critical_friction():
    c = 0.05
    assert damped_hoffmann_onset(c, c, **HOFFMANN) == pytest.approx(MU_C + 2.5 * c**2 / (2 * 0.3), rel=1e-12)
    assert damped_hoffmann_onset(0.0, 0.0, **HOFFMANN) == MU_C
    # destabilisation paradox: vanishing unequal damping gives a lower onset than the undamped one
    for w in (0.2, 0.5, 1.0):
        small = damped_hoffmann_onset(1e-7 * w, 1e-7 * (1 - w), **HOFFMANN)
        assert small == pytest.approx(vanishing_damping_onset(w, **HOFFMANN), rel=1e-6)
    assert vanishing_damping_onset(0.5, **HOFFMANN) == pytest.approx(MU_C, rel=1e-12)
    assert vanishing_damping_onset(0.2, **HOFFMANN) < MU_C
    assert damped_hoffmann_onset(0.01, 0.04, **HOFFMANN) < MU_C     # smoothing effect lost


@pytest.mark.parametrize("method", ["projection", "quadratic"])
@pytest.mark.parametrize("c", [(0.05, 0.05), (0.02, 0.08)])
def test_damped_hoffmann_onset_by_bisection_matches_the_closed_form(method, c):
    onset = eigen.onset_of_instability(lambda mu: hoffmann_system(mu, *c), 0.0, 2.0, xtol=1e-8,
                                       solve=damped.solve_system, f_max=1.0, method=method)
    # the "unstable" test sigma > 1e-6 |lambda| moves the onset by ~1e-6 |lambda| / (d sigma / d mu)
    assert onset == pytest.approx(damped_hoffmann_onset(*c, **HOFFMANN), rel=1e-4)


def test_undamped_system_takes_the_gnhep_path_bit_for_bit():
    K, M = hoffmann_matrices(0.7, **HOFFMANN)
    a = damped.solve_system(damped.LinearSystem(petsc_mat(K), petsc_mat(M)), f_max=1.0)
    b = eigen.solve_modes(petsc_mat(K), petsc_mat(M), f_max=1.0)
    assert a.method == "gnhep"
    np.testing.assert_array_equal(a.eigenvalues, b.eigenvalues)
    np.testing.assert_array_equal(a.modes, b.modes)


# ---------------------------------------------------------------- Rayleigh damping
def chain(n=30, k=4e6, m=0.01):
    K = 2 * k * np.eye(n) - k * (np.eye(n, k=1) + np.eye(n, k=-1))
    return K, m * np.eye(n)


@pytest.mark.parametrize("method", ["proportional", "projection", "quadratic"])
def test_rayleigh_damping_ratio_of_every_mode(method):
    """zeta = -sigma / |lambda| = alpha / (2 omega) + beta omega / 2 with omega = |lambda| the
    undamped angular frequency: the exact map, the projection and the full quadratic solver."""
    K, M = chain()
    alpha, beta = 200.0, 2e-6
    if method == "proportional":
        system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), damping=eigen.Damping(alpha, beta))
    else:
        system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), petsc_mat(alpha * M + beta * K))
    r = damped.solve_system(system, f_max=4e3, method="auto" if method == "proportional" else method)
    undamped = 2 * np.sqrt(4e6 / 0.01) * np.sin(np.arange(1, 31) * np.pi / 62)
    undamped = undamped[undamped <= 2 * np.pi * 4e3]
    assert len(r) == undamped.size == 13
    assert r.method == {"proportional": "gnhep", "quadratic": "pep"}.get(method, method)
    omega = np.abs(r.eigenvalues)
    np.testing.assert_allclose(-r.growth / omega, rayleigh_damping_ratio(omega, alpha, beta), rtol=1e-8)
    np.testing.assert_allclose(omega, undamped, rtol=1e-8)      # SLEPc PEP tol 1e-10
    if method == "projection":
        assert r.errors.max() < 1e-10                 # exact: the basis holds the damped modes


def test_stiffness_proportional_damping_adds_no_mode_at_the_supports():
    """A support as DOLFINx writes it (its row and column 0, diagonal 1 in K and 0 in M): beta K
    of Rayleigh damping in the quadratic solver gives the modes of the free dofs alone (before, a
    mode lambda = -1/beta at 0 Hz for every supported dof, which filled the requested count; an
    adversarial test)."""
    K, M = chain(12)
    K[0, :] = K[:, 0] = M[0, :] = M[:, 0] = 0.0
    K[0, 0] = 1.0
    beta, C = 2e-6, 50.0 * M
    system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), petsc_mat(C), damping=eigen.Damping(0.0, beta))
    r = damped.solve_system(system, f_max=4e3, method="quadratic")
    ref = companion_eigenvalues(K[1:, 1:], C[1:, 1:] + beta * K[1:, 1:], M[1:, 1:])
    ref = ref[ref.imag / (2 * np.pi) <= 4e3]
    assert len(r) == ref.size == 5
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-8)


def test_loss_factors_with_friction_are_projected_with_the_left_modes():
    """A chain of 40 masses with follower-force couplings (non-symmetric K, as friction makes it)
    and a loss factor of 0.02: the projection on the undamped modes up to 1.5 f_max and on those of
    (K^T, M) gives the 8 modes below 2 kHz of the dense complex solve to 1e-5 (8e-7 measured),
    the unstable lowest one unstable. On the right modes alone it was stable (sigma -2.5 against
    +3.6 1/s) and 1.5e-3 off (an adversarial test found the same on a bar of two prisms)."""
    K, M = chain(40)
    for i in range(0, 37, 3):
        K[i, i + 2] += 0.6e6
        K[i + 2, i] -= 0.3e6
    H = 0.02 * chain(40)[0]
    system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), H=petsc_mat(H))
    r = damped.solve_system(system, f_max=2e3, basis=1.5)
    ref = companion_eigenvalues(K + 1j * H, np.zeros_like(K), M)
    ref = ref[ref.imag / (2 * np.pi) <= 2e3]
    assert len(r) == ref.size == 8 and ref[0].real > 3.0
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-5)


def test_the_left_modes_are_solved_with_the_right_modes_factors_transposed():
    """The modes of (K^T, M) by shift-and-invert through the transposed solves of the factors of
    K - theta_t M (``transpose_of``; no second LU) on a chain with skew couplings strong enough for
    lock-in (complex theta): the eigenvalues of its own factorisation (1e-10) and eigenvectors of
    (K^T, M) (relative residual 1e-9), and the factors solve (K - theta_t M) x = b and the
    transposed system as numpy does (1e-10)."""
    K, M = chain(40)
    for i in range(0, 37, 9):
        K[i, i + 2] += 4e6
        K[i + 2, i] -= 4e6
    band = dict(f_max=3e3, target=1e3)
    own = eigen.solve_modes(petsc_mat(K.T), petsc_mat(M), **band)
    B = np.random.default_rng(1).standard_normal((40, 3))
    A = K - (2 * np.pi * band["target"]) ** 2 * M
    with eigen.shift_invert_modes(petsc_mat(K), petsc_mat(M), **band) as (right, factors):
        np.testing.assert_allclose(block_solve(factors, B), np.linalg.solve(A, B), rtol=1e-10)
        np.testing.assert_allclose(block_solve(factors, B, transpose=True), np.linalg.solve(A.T, B), rtol=1e-10)
        left = eigen.solve_modes(petsc_mat(K.T), petsc_mat(M), **band, transpose_of=factors)
    assert np.iscomplex(left.theta).sum() == 12
    np.testing.assert_allclose(left.eigenvalues, own.eigenvalues, rtol=1e-10)
    np.testing.assert_allclose(left.eigenvalues, right.eigenvalues, rtol=1e-10)
    residual = K.T @ left.modes - M @ left.modes * left.theta
    assert np.all(np.linalg.norm(residual, axis=0) < 1e-9 * np.linalg.norm(K.T @ left.modes, axis=0))


def segment_stiffness(n, k, first, last):
    """Stiffness of the springs k between masses first..last of a chain of n (a part of it)."""
    S = np.zeros((n, n))
    for i in range(first, last):
        S[i:i + 2, i:i + 2] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return S


@pytest.mark.parametrize("friction", [True, False])
def test_a_loss_factor_on_a_part_of_the_model_is_projected_with_its_static_responses(friction):
    """A loss factor of 0.05 on the last 9 springs of the chain (a lossy pad on a steel part): the
    damping forces eta K_b phi of a basis mode load the part's boundary, which no mode below
    1.5 f_max balances. With the static responses (K - theta_t M)^-1 H phi of the right and
    (K^T - theta_t M)^-1 H psi of the left modes in the basis, the 8 modes below 2 kHz are within
    1e-6 of the dense complex solve (measured 1.7e-11 with friction, 2.3e-7 without) and their
    relative residuals below 5e-3 (3.9e-5, 7.8e-4). Without them: 4.2e-5 and 8.9e-5 off, residuals
    3.5e-2 and 8.1e-2 (on the demo brake 0.15 to 0.23, docs/squeal.md)."""
    K, M = chain(40)
    if friction:
        for i in range(0, 37, 3):
            K[i, i + 2] += 0.6e6
            K[i + 2, i] -= 0.3e6
    H = 0.05 * segment_stiffness(40, 4e6, 30, 39)
    r = damped.solve_system(damped.LinearSystem(petsc_mat(K), petsc_mat(M), H=petsc_mat(H)), f_max=2e3, basis=1.5)
    ref = companion_eigenvalues(K + 1j * H, np.zeros_like(K), M)
    ref = ref[ref.imag / (2 * np.pi) <= 2e3]
    assert len(r) == ref.size == 8 and r.method == "projection"
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-6)
    assert r.errors.max() < 5e-3


@pytest.mark.parametrize("friction", [True, False])
def test_viscous_damping_on_a_part_of_the_model_is_projected_with_its_static_responses(friction):
    """Dashpots on the last 9 springs of the chain and a negative one at mass 35 (a falling friction
    law at the interface: a mode grows at 5.6 1/s): the projection on the modes up to 1.5 f_max,
    the left ones and the static responses (K - theta_t M)^-1 C phi, (K^T - theta_t M)^-1 C^T psi
    gives the 8 modes below 2 kHz of the dense quadratic solve within 1e-7 (measured 1e-11 with
    friction, 4.7e-9 without), residuals below 1e-3 (1.2e-5, 1.1e-4). Without the responses:
    7.2e-7 and 1.3e-6 off, residuals 6.7e-3 (on the demo brake with a steep Stribeck law the
    growth rates 0.14 1/s off against 3e-4, docs/squeal.md). The responses are of the order of
    C/K (1e-7 s here): the basis judges their parts outside the modes against their own norms."""
    K, M = chain(40)
    if friction:
        for i in range(0, 37, 3):
            K[i, i + 2] += 0.6e6
            K[i + 2, i] -= 0.3e6
    C = segment_stiffness(40, 2.0, 30, 39)
    C[35, 35] -= 3.0
    r = damped.solve_system(damped.LinearSystem(petsc_mat(K), petsc_mat(M), petsc_mat(C)), f_max=2e3, basis=1.5,
                            method="projection")
    ref = companion_eigenvalues(K, C, M)
    ref = ref[ref.imag / (2 * np.pi) <= 2e3]
    assert len(r) == ref.size == 8 and ref.real.max() > 5.0
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-7)
    assert r.errors.max() < 1e-3


def test_auto_projects_a_band_above_0_hz_that_the_quadratic_solver_cannot_reach():
    """Viscous damping in a band from 1.2 to 2 kHz (the chain's modes 6 to 9): the real PEP
    converges from 0 Hz up, so that 3 modes asked for lie below the band ("cover the band from
    0 Hz"; a user trial on the demo brake with gyroscopic terms); "auto" takes the projection,
    whose GNHEP shifts to the band: the band's 4 modes of the dense quadratic solve within 5e-6,
    the lowest unstable as there. A target alone does the same; a band from 0 Hz keeps the PEP."""
    K, M = chain(40)
    C = segment_stiffness(40, 2.0, 30, 39)
    C[35, 35] -= 3.0
    system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), petsc_mat(C))
    ref = companion_eigenvalues(K, C, M)
    ref = ref[(ref.imag / (2 * np.pi) >= 1.2e3) & (ref.imag / (2 * np.pi) <= 2e3)]
    with pytest.raises(InputError, match="the quadratic solver finds the lowest modes first"):
        damped.solve_system(system, f_min=1.2e3, f_max=2e3, n_modes=3, method="quadratic")
    r = damped.solve_system(system, f_min=1.2e3, f_max=2e3)
    assert r.method == "projection" and len(r) == ref.size == 4
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=5e-6)       # measured 9.5e-7: no modes below 800 Hz
    assert np.array_equal(r.growth > 0, ref.real > 0) and ref[0].real > 3.0
    assert damped.solve_system(system, f_max=2e3, n_modes=3, target=1.5e3).method == "projection"
    assert damped.solve_system(system, f_max=2e3, n_modes=3).method == "pep"


def test_a_value_of_the_projected_problem_that_is_no_mode_is_left_out():
    """A basis of the chain's 3 lowest modes and mode 6 plus 0.3 x mode 40: the reduced problem has
    a fourth value (2296 Hz, between the chain's modes) whose vector is no mode of the model
    (relative residual 0.62 in it). A user trial met such a value with a target: 3524 Hz, unstable,
    residual 0.9, reported as a squeal mode. It is left out (``ModalResult.spurious``, warned about
    by the run); the 3 modes stay. (Modes of a poor basis have had residuals up to 0.23 with
    eigenvalues within 1e-4: ``SPURIOUS`` is 0.5.)"""
    K, M = chain(40)
    w, X = scipy.linalg.eigh(K, M)
    system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), petsc_mat(0.005 * np.eye(40)))
    sub = damped.Subspace([X[:, :3], (X[:, 5] + 0.3 * X[:, 39])[:, None]], system.M)
    r = damped.solve_projected(system, sub, band=(0.0, 1e5))[0]
    np.testing.assert_allclose(r.frequency, np.sqrt(w[:3]) / (2 * np.pi), rtol=1e-7)    # damped: 1.3e-8
    assert len(r.spurious) == 1 and 2290 < r.spurious[0] < 2300 and r.errors.max() < 1e-12
    red, AV = damped.project(system, sub)
    lam, Q = red.eigenpairs()
    assert damped.residuals(lam, Q, AV, None, None).max() > damped.SPURIOUS


def test_hysteretic_damping_needs_the_projection():
    K, M = chain(8)
    system = damped.LinearSystem(petsc_mat(K), petsc_mat(M), H=petsc_mat(0.02 * K))
    with pytest.raises(InputError, match="stability.method"):
        damped.solve_system(system, f_max=2e4, method="quadratic")
    r = damped.solve_system(system, f_max=2e4, basis=5.0)
    ref = companion_eigenvalues(K * (1 + 0.02j), np.zeros_like(K), M)     # loss factor: zeta ~ eta / 2
    np.testing.assert_allclose(r.eigenvalues, ref[ref.imag / (2 * np.pi) <= 2e4], rtol=1e-10)


# ---------------------------------------------------------------- mu(v) slope: a 1-DOF oscillator on a belt
def test_friction_laws_values_and_slopes():
    law = StribeckFriction(0.6, 0.4, 0.1)
    v = np.array([0.0, 0.05, 0.1, 1.0])
    mu, slope = stribeck(v, 0.6, 0.4, 0.1)
    np.testing.assert_allclose(law.value(v), mu, rtol=1e-14)
    np.testing.assert_allclose(law.slope(v), slope, rtol=1e-14)
    h = 1e-7                                         # central difference of the law itself
    np.testing.assert_allclose(law.slope(v[1:]), (law.value(v[1:] + h) - law.value(v[1:] - h)) / (2 * h), rtol=1e-6)
    table = TableFriction(((0.0, 0.5), (1.0, 0.4), (2.0, 0.4)))
    np.testing.assert_allclose(table.value([0.5, 3.0]), [0.45, 0.4])
    np.testing.assert_allclose(table.slope([0.5, 1.5, 3.0]), [-0.1, 0.0, 0.0])
    with pytest.raises(InputError, match="friction_curve"):
        TableFriction(((1.0, 0.5), (0.5, 0.4)))


def test_an_interface_of_its_own_friction_keeps_it_constant_under_a_speed_law():
    """``workflows.squeal.friction_laws`` with [loading]'s mu(v): the car brake's inner pad takes it,
    the outer pad with its own fade table its mu at the initial temperature (30 degC: 0.4), constant
    (before, only an own constant friction was kept)."""
    from pathlib import Path
    from types import SimpleNamespace

    from multiscale.macro.friction import ConstantFriction
    from multiscale.scene import loads
    from multiscale.workflows.squeal import friction_laws
    demos = Path(__file__).parents[1] / "demos"
    if not (demos / "cad" / "car_brake.step").exists():
        pytest.skip("demos/cad/car_brake.step not built (make demos/cad/car_brake.step)")
    text = (demos / "car_brake_stop.toml").read_text().replace('"heat_partition"]', '"heat_partition", "stability"]')
    text = text.replace("friction = 0.4", 'friction_curve = [["0 m/s", 0.5], ["10 m/s", 0.4]]') + "\n[stability]\nmodes = 4\n"
    scene = loads(text + '[interfaces.outer_pad]\nfriction_temperature = [["10 degC", 0.5], ["50 degC", 0.3]]\n', demos)
    laws = friction_laws(scene, SimpleNamespace(interface=SimpleNamespace(tags=("inner_pad", "outer_pad"))))
    assert laws == {"inner_pad": TableFriction(((0.0, 0.5), (10.0, 0.4))), "outer_pad": ConstantFriction(0.4)}


def test_a_squeal_scene_of_the_pads_own_friction_alone_reads_as_given():
    """``workflows.model.friction_coefficient`` of the brake whose pads each give their friction and
    [loading] none: each pad's own (before: a TypeError, a placeholder mu taken from a
    friction_curve that was not there, in every such squeal run); with a mu(v) law in [loading],
    the mean of the law's static and kinetic mu, the first guess the clamp force divides by."""
    from pathlib import Path

    from multiscale.scene import loads
    from multiscale.workflows.model import friction_coefficient
    demos = Path(__file__).parents[1] / "demos"
    text = (demos / "brake_squeal.toml").read_text().replace("\nfriction = 0.4\n", "\n", 1)
    own = loads(text, demos, overrides={"interfaces.inner_pad.friction": 0.35, "interfaces.outer_pad.friction": 0.3})
    assert [friction_coefficient(own, n) for n in ("inner_pad", "outer_pad")] == [0.35, 0.3]
    law = loads(text, demos, overrides={"loading.stribeck": {"static": 0.5, "kinetic": 0.4, "speed": "1 m/s"}})
    assert friction_coefficient(law, "inner_pad") == pytest.approx(0.45)     # the mean of static and kinetic mu


def test_belt_oscillator_negative_damping_onset():
    """m x'' + (c + N mu'(V)) x' + k x = 0: unstable below the belt speed where N mu'(V) = -c."""
    m, k, c, N = 1.0, 1e4, 0.5, 100.0
    law = StribeckFriction(0.6, 0.4, 0.1)

    def system(v):
        return damped.LinearSystem(petsc_mat(k), petsc_mat(m), petsc_mat(c + N * law.slope(v)))

    def unstable(v):
        return damped.solve_system(system(v), f_max=100.0, method="quadratic").unstable().any()

    v_star = belt_onset_speed(c, N, 0.6, 0.4, 0.1)
    assert v_star == pytest.approx(0.1 * np.log(400.0), rel=1e-12)
    assert unstable(0.5 * v_star) and not unstable(1.5 * v_star)
    lo, hi = 0.5 * v_star, 1.5 * v_star
    while hi - lo > 1e-6 * v_star:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if unstable(mid) else (lo, mid)
    assert 0.5 * (lo + hi) == pytest.approx(v_star, rel=1e-4)
    r = damped.solve_system(system(0.2), f_max=100.0, method="projection")
    assert r.growth[0] == pytest.approx(-(c + N * law.slope(0.2)) / (2 * m), rel=1e-9)


# ---------------------------------------------------------------- stability map of the Hoffmann model
def hoffmann_points(values):
    """The modes and reduced systems of the Hoffmann model at each friction coefficient of ``values``."""
    sub = damped.Subspace([np.eye(2)], petsc_mat(np.eye(2)))
    points = [damped.solve_projected(hoffmann_system(mu), sub, band=(0.0, 1.0), expand=False) for mu in values]
    return [r for r, _ in points], [red for _, red in points]


def test_map_tracks_the_hoffmann_pair_and_bisects_its_lock_in(tmp_path):
    values = np.linspace(0.0, 1.0, 6)
    results, reduced = hoffmann_points(values)
    smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0), xtol=1e-9)
    assert smap.n_tracks == 2 and (smap.mode >= 0).all()
    assert len(smap.onsets) == 1
    onset = smap.onsets[0]
    assert onset.value == pytest.approx(MU_C, rel=1e-6) and onset.kind == "lock-in"
    theta = (1.0 + 1.5) / 2                           # coalescence at the mean theta
    assert onset.frequency == pytest.approx(np.sqrt(theta) / (2 * np.pi), rel=1e-3)
    smap.write_csv(tmp_path / "map.csv"), smap.write_onsets_csv(tmp_path / "onsets.csv")
    smap.write_h5(tmp_path / "map.h5")
    rows = (tmp_path / "map.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * values.size
    import h5py
    with h5py.File(tmp_path / "map.h5") as f:
        np.testing.assert_allclose(f["onsets/value"][:], [onset.value])
        assert f["growth"].shape == (6, 2)
        assert (f["frequency"].attrs["unit"], f["growth"].attrs["unit"], f["values"].attrs["unit"]) == ("Hz", "1/s", "-")


def test_the_map_table_writes_no_negative_zero(tmp_path):
    """A neutral mode of a map (sigma -0.0) is written with sigma and damping ratio 0, as in
    modes.csv (map.csv read -0.000000e+00; an adversarial test)."""
    import csv
    from multiscale.macro.stability_map import StabilityMap
    one = np.ones((1, 1))
    smap = StabilityMap("friction", "-", np.array([0.0]), 250.0 * one, -0.0 * one, np.zeros((1, 1), int),
                        np.full((1, 1), np.nan), 1e-9 * one, [], 2, 1e-6, 0.0)
    rows = list(csv.reader(smap.write_csv(tmp_path / "map.csv").open()))
    assert rows[1][5] == rows[1][6] == "0.000000e+00"


def test_map_bisects_the_onset_of_a_lock_in_branch_that_fails_the_mac_test(tmp_path):
    """With a strict MAC threshold and the single MAC only (``subspace=False``) the coalesced pair
    starts new tracks at mu = 0.6; the unstable one's onset is still bisected (from its stable best
    match at 0.4), once; a map starting above the onset lists the unstable track as below the
    sweep. By default the pair's two-mode subspace (here the whole space) keeps both tracks."""
    values = np.linspace(0.0, 1.0, 6)
    results, reduced = hoffmann_points(values)
    for mac_min in (0.9, 0.999):
        smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0), xtol=1e-9, mac_min=mac_min)
        assert smap.n_tracks == 2 and len(smap.onsets) == 1
        assert smap.onsets[0].value == pytest.approx(MU_C, rel=1e-6) and smap.onsets[0].kind == "lock-in"
    for mac_min in (0.9, 0.999):                     # 0.999: the branch is new at every point
        smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0), xtol=1e-9, mac_min=mac_min,
                         subspace=False)
        assert smap.n_tracks > 2 and len(smap.onsets) == 1
        assert smap.onsets[0].value == pytest.approx(MU_C, rel=1e-6) and smap.onsets[0].kind == "lock-in"
    smap = build_map("friction", "-", values[3:], results[3:], reduced[3:], (0.0, 1.0))
    assert [(o.kind, o.track) for o in smap.onsets] == [(BELOW, int(np.nanargmax(smap.growth[0])) + 1)]
    assert np.isnan(smap.onsets[0].value) and "below the sweep" in smap.summary()
    assert {smap.onsets[0].track, smap.onsets[0].partner} == {1, 2}      # its partner, as above (it was none)
    rows = smap.write_onsets_csv(tmp_path / "onsets.csv").read_text().splitlines()
    assert rows[1].split(",")[1] == "" and rows[1].split(",")[6] == "0.6"       # unstable_value


def test_a_band_of_instability_is_bisected_at_both_ends(tmp_path):
    """K(v) = [[1 + v, m], [-m, 2 - v]], M = I: the squared frequencies are complex (flutter) for
    |2 v - 1| < 2 m, unstable only for v in (0.5 - m, 0.5 + m). The summary said "stable again
    between 0.5 and 0.65" (sampled; an NVH trial's 4.4 kHz pair); the end is now bisected as the
    onset is, and written to onsets.csv and map.h5."""
    m, values = 0.1, np.linspace(0.05, 0.95, 7)

    def system(v):
        return damped.LinearSystem(petsc_mat(np.array([[1.0 + v, m], [-m, 2.0 - v]])), petsc_mat(np.eye(2)))
    sub = damped.Subspace([np.eye(2)], petsc_mat(np.eye(2)))
    points = [damped.solve_projected(system(v), sub, band=(0.0, 1.0), expand=False) for v in values]
    smap = build_map("friction", "-", values, [r for r, _ in points], [red for _, red in points], (0.0, 1.0),
                     xtol=1e-9)
    assert smap.unstable().any(axis=1).tolist() == [False, False, False, True, False, False, False]
    assert len(smap.onsets) == 1 and smap.onsets[0].kind == "lock-in"
    assert smap.onsets[0].value == pytest.approx(0.5 - m, rel=1e-6)
    assert smap.onsets[0].end == pytest.approx(0.5 + m, rel=1e-6)
    assert "; stable again at 0.6\n" in smap.summary() + "\n"
    row = smap.write_onsets_csv(tmp_path / "onsets.csv").read_text().splitlines()
    assert row[0].endswith(",stable_again_friction,full_analyses") and row[1].endswith(",0")
    assert float(row[1].split(",")[-2]) == pytest.approx(0.6)
    import h5py
    with h5py.File(smap.write_h5(tmp_path / "map.h5"), "r") as f:
        assert f["onsets/stable_again"][0] == pytest.approx(0.6) and f["onsets/stable_again"].attrs["unit"] == "-"
    ends = build_map("friction", "-", values[:4], [r for r, _ in points[:4]], [red for _, red in points[:4]],
                     (0.0, 1.0))
    assert np.isnan(ends.onsets[0].end) and "stable again" not in ends.summary()     # unstable to the end


class NonlinearHoffmann:
    """Stands in for ``squeal_map.MapModel``: the Hoffmann model at mu = 3 p (1 - p) of the swept
    value p, so that K is not affine in p and the blend of two points is not the system between
    them; records the values it linearises at and the states it is put back in."""

    def __init__(self):
        self.linearised, self.restored, self.p = [], [], None

    def linearise(self, p):
        from multiscale.macro.preload import Linearised
        self.linearised.append(p)
        self.p = p
        K, M = hoffmann_matrices(3 * p * (1 - p), **HOFFMANN)
        return Linearised(damped.LinearSystem(petsc_mat(K), petsc_mat(M)))

    def state(self):
        return self.p

    def restore(self, state):
        self.restored.append(state)


def test_an_each_map_narrows_its_onsets_by_full_analyses(tmp_path):
    """An "each" map bisects an onset on the blend of its two neighbouring points; with K not affine
    in the swept value that is not the system between them (user trials: 8-9 % low on the demo
    brake). Here mu = 3 p (1 - p) turns the Hoffmann pair unstable at p* = (1 - sqrt(1 - 4 mu_c / 3)) / 2
    and stable again at 1 - p*; the blend of p = 0 and 0.5 puts the onset at 0.5 mu_c / 0.75, 57 %
    high (the end at 1 - p* 16 % low). Four full analyses per onset (``stability.sweep.refine``)
    bracket p* and 1 - p* between full analyses (at most 0.8 of the bracket kept per analysis,
    0.5 for the third, whose two before replaced the same end) and land within 1 % of them
    (measured 0.36 % and 0.1 %); the map's own points are unchanged and the model is put back in
    each point's state after its refinement. Its progress is a line per point."""
    import io as text
    from types import SimpleNamespace as NS
    from mpi4py import MPI
    from multiscale import io
    from multiscale.macro.stability_map import MapBuilder
    from multiscale.workflows.squeal_map import KEEP, _per_point
    onset = (1 - np.sqrt(1 - 4 * MU_C / 3)) / 2                # 0.2162
    maps = {}
    for refine in (0, 4):
        model = NonlinearHoffmann()
        st = NS(band=(0.0, 1.0), modes=None, target=None,
                sweep=NS(values=(0.0, 0.5, 1.0), onsets=True, refine_steps=refine))
        builder, out = MapBuilder("friction", "-", st.band), text.StringIO()
        with io.Reporter(MPI.COMM_SELF, stream=out):
            _per_point(model, builder, st, NS(method="auto", basis=1.5))
        def said(a, b):
            return [f"  1 onset(s) between {a:g} and {b:g}: narrowed by up to 4 full analyses each"] * bool(refine)
        assert [line.split(",")[0] for line in out.getvalue().splitlines()] == [    # (said: the bar's time left
            "  map points: 1/3 points", *said(0, 0.5), "  map points: 2/3 points", *said(0.5, 1),   # leaves them
            "  map points: 3/3 points"]                                                    # out: a user trial)
        maps[refine] = smap = builder.finish()
        assert len(smap.onsets) == 1
        assert model.linearised[:2] == [0.0, 0.5] and len(model.linearised) == 3 + 2 * refine
        assert model.restored == [0.5, 1.0]
    blend, full = maps[0].onsets[0], maps[4].onsets[0]
    assert blend.value == pytest.approx(0.5 * MU_C / 0.75, rel=1e-3) and blend.analyses == 0
    assert blend.end == pytest.approx(1 - 0.5 * MU_C / 0.75, rel=1e-3)
    assert full.analyses == 4 and full.kind == "lock-in"
    assert full.bracket[0] < onset < full.bracket[1]
    assert full.bracket[1] - full.bracket[0] <= 0.5 * (1 - KEEP) ** 3 * 0.5
    assert full.value == pytest.approx(onset, rel=1e-2) and full.end == pytest.approx(1 - onset, rel=1e-2)
    np.testing.assert_array_equal(maps[4].growth, maps[0].growth)         # the points themselves
    assert f"between full analyses at {full.bracket[0]:.6g} and {full.bracket[1]:.6g})" in maps[4].summary()
    rows = maps[4].write_onsets_csv(tmp_path / "onsets.csv").read_text().splitlines()
    assert rows[0].endswith(",full_analyses") and rows[1].endswith(",4")


def hoffmann_spectator_points(values, spectator=4.0, coupling=0.1):
    """``hoffmann_points`` of the Hoffmann pair plus a third mode (stiffness ``spectator``, coupled
    to the second dof by ``coupling``), so that the pair's two-mode subspace is not the whole space."""
    def system(mu):
        K = np.zeros((3, 3))
        K[:2, :2] = hoffmann_matrices(mu, **HOFFMANN)[0]
        K[2, 2], K[1, 2], K[2, 1] = spectator, coupling, coupling
        return damped.LinearSystem(petsc_mat(K), petsc_mat(np.eye(3)))
    sub = damped.Subspace([np.eye(3)], petsc_mat(np.eye(3)))
    points = [damped.solve_projected(system(mu), sub, band=(0.0, 1.0), expand=False) for mu in values]
    return [r for r, _ in points], [red for _, red in points]


def test_a_lock_in_between_two_points_keeps_both_tracks_by_the_pairs_subspace():
    """A pair that locks in between two sweep points: both conjugate members have the same MAC with a
    given parent, 0.82 with one and 0.18 with the other, so the single-MAC pairing (mac 0.5) ended
    the second parent's track and started the partner as a new track, named as the onset's partner
    (found by a user trial on the 12-mm demo brake: 0.916 / 0.42). The pair's two-mode subspace
    has the parents' one (subspace MAC 1.0): both tracks go on, the partner is the other parent."""
    from multiscale.macro.modal import mac_matrix, subspace_mac
    values = np.array([0.0, 0.6, 1.0])
    results, reduced = hoffmann_spectator_points(values)
    a, b = results[0], results[1]
    mac = mac_matrix(a, b)
    np.testing.assert_allclose(mac[:2, 0], mac[:2, 1], rtol=1e-12)     # conjugate members, real parents
    assert mac[1, :2].max() < 0.5 < mac[0, :2].min()
    np.testing.assert_allclose(b.modes[:, 1], b.modes[:, 0].conj() * np.exp(1j * np.angle(
        np.vdot(b.modes[:, 0].conj(), b.modes[:, 1]))), atol=1e-12)
    assert subspace_mac(a, b, [0, 1], [0, 1]) == pytest.approx(1.0, abs=1e-6)
    assert subspace_mac(a, b, [1], [0]) == pytest.approx(mac[1, 0])     # one mode each: the MAC
    assert subspace_mac(a, b, [1, 2], [0, 1]) < 0.5                     # not the pair's subspace
    old = build_map("friction", "-", values, results, reduced, (0.0, 1.0), xtol=1e-9, subspace=False)
    assert old.n_tracks == 4 and old.onsets[0].track == 4               # the former behaviour
    smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0), xtol=1e-9)
    assert smap.n_tracks == 3 and (smap.mode >= 0).all()
    assert [(o.kind, o.partner) for o in smap.onsets] == [("lock-in", 3 - smap.onsets[0].track)]
    assert smap.onsets[0].value == pytest.approx(old.onsets[0].value, rel=1e-12)
    assert np.nanmin(smap.mac[1, :2]) < 0.5                            # the pair's own MAC is kept


def check_map_files(folder, smap, documented) -> None:
    """``map.csv``, ``onsets.csv`` and ``map.h5`` in ``folder`` hold the numbers of ``smap`` (the csv
    rounded as written), every column, dataset and attribute is in docs/results.rst, every dataset
    has a unit, and each onset lies in its bracket, the bracket between the two points around it
    where the track was stable (or absent) and unstable."""
    import csv

    import h5py
    names = []
    with h5py.File(folder / "map.h5", "r") as f:
        names += list(f.attrs)
        f.visititems(lambda name, obj: names.append(name.split("/")[-1]) if isinstance(obj, h5py.Dataset) else None)
        f.visititems(lambda name, obj: assert_unit(name, obj) if isinstance(obj, h5py.Dataset) else None)
        assert (f.attrs["parameter"], f.attrs["unit"], f.attrs["rtol"]) == (smap.parameter, smap.unit, smap.rtol)
        for name in ("values", "frequency", "growth", "mode", "mac", "residual"):
            np.testing.assert_array_equal(f[name][...], getattr(smap, name), err_msg=name)
        h5_onsets = {name: f["onsets"][name][...] for name in f["onsets"]}
    with open(folder / "map.csv", newline="") as f:
        rows = list(csv.reader(f))
    names += rows[0]
    column = {"friction": "friction", "pressure": "pressure_Pa", "speed": "speed_rad_per_s", "rms": "rms_m"}[smap.parameter]
    bad = smap.unstable()
    assert len(rows) - 1 == int((smap.mode >= 0).sum())
    for row in (dict(zip(rows[0], r)) for r in rows[1:]):
        k, t = int(row["point"]) - 1, int(row["track"]) - 1
        assert float(row[column]) == float(f"{smap.values[k]:.8g}") and int(row["mode"]) == smap.mode[k, t]
        assert float(row["frequency_Hz"]) == pytest.approx(smap.frequency[k, t], abs=5e-7)
        assert float(row["sigma_1_per_s"]) == pytest.approx(smap.growth[k, t], rel=5e-7, abs=1e-300)
        assert int(row["unstable"]) == bad[k, t]
        assert row["mac_previous"] == "" if np.isnan(smap.mac[k, t]) else \
            float(row["mac_previous"]) == pytest.approx(smap.mac[k, t], abs=5e-5)
    with open(folder / "onsets.csv", newline="") as f:
        rows = list(csv.reader(f))
    names += rows[0]
    assert len(rows) - 1 == len(smap.onsets) == h5_onsets["track"].size
    for j, (o, row) in enumerate(zip(smap.onsets, (dict(zip(rows[0], r)) for r in rows[1:]))):
        lo, hi = o.bracket
        assert (int(row["track"]), row["kind"], row["partner_track"]) == (o.track, o.kind, str(o.partner or ""))
        assert float(row["frequency_Hz"]) == pytest.approx(o.frequency, abs=5e-7)
        for key, v in ((f"onset_{column}", o.value), ("stable_value", lo), ("unstable_value", hi)):
            assert row[key] == ("" if np.isnan(v) else f"{v:.8g}")
        h5_row = {name: h5_onsets[name][j] for name in h5_onsets}
        assert h5_row["kind"].decode() == o.kind and h5_row["partner"] == (o.partner or -1)
        np.testing.assert_array_equal([h5_row[n] for n in ("track", "value", "frequency", "stable_value",
                                                           "unstable_value")], [o.track, o.value, o.frequency, lo, hi])
        if np.isfinite(o.value):
            k = int(np.searchsorted(smap.values, o.value))         # values[k - 1] < onset <= values[k]
            assert smap.values[k - 1] <= lo <= o.value <= hi <= smap.values[k]
            assert bad[k, o.track - 1] and not bad[k - 1, o.track - 1]
        else:
            assert hi == smap.values[0] and bad[0, o.track - 1]
    assert [n for n in names if not documented(n)] == []


def assert_unit(name, dataset) -> None:
    assert "unit" in dataset.attrs, f"map.h5: {name} has no unit"


def test_the_map_files_hold_the_map_and_say_it_in_documented_terms(tmp_path, documented):
    """map.csv, onsets.csv and map.h5 of the Hoffmann map agree with each other and the map (before:
    map.h5 held no onset bracket, which onsets.csv gives, and no unit for the onsets' track,
    partner and kind; none of the three files was documented)."""
    values = np.linspace(0.0, 1.0, 6)
    results, reduced = hoffmann_points(values)
    smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0))
    smap.write_csv(tmp_path / "map.csv"), smap.write_onsets_csv(tmp_path / "onsets.csv")
    smap.write_h5(tmp_path / "map.h5")
    check_map_files(tmp_path, smap, documented)
    below = build_map("friction", "-", values[3:], results[3:], reduced[3:], (0.0, 1.0))    # onset below the sweep
    below.write_csv(tmp_path / "map.csv"), below.write_onsets_csv(tmp_path / "onsets.csv")
    below.write_h5(tmp_path / "map.h5")
    check_map_files(tmp_path, below, documented)


@pytest.fixture
def drawn(keep_figures):
    """The figures ``multiscale.plots.squeal`` makes, kept to be inspected."""
    from multiscale.plots import squeal as plots
    return keep_figures(plots)


def test_a_track_of_one_point_is_seen_in_the_tracks_figure(tmp_path, drawn):
    """map_tracks.png drew each track as a line through its points: an unstable track present at one
    point only (a branch that fails the MAC test at every point) was named in the legend and not
    drawn (found on the 20-mm brake's friction map, tracks 31 and 37). Every point has a marker now."""
    from multiscale.plots import squeal as plots
    values = np.linspace(0.0, 1.0, 6)
    results, reduced = hoffmann_points(values)
    smap = build_map("friction", "-", values, results, reduced, (0.0, 1.0), mac_min=0.999, subspace=False)
    alone = [t for t in range(smap.n_tracks) if smap.unstable()[:, t].any() and (smap.mode[:, t] >= 0).sum() == 1]
    assert alone
    plots.plot_tracks(smap, tmp_path / "map_tracks.png")
    for axis in drawn[0].axes:
        lines = [line for line in axis.get_lines() if np.size(line.get_xdata()) == values.size]    # the tracks
        assert len(lines) == smap.n_tracks
        for t in alone:
            assert lines[t].get_marker() not in (None, "None", "", " "), f"track {t + 1}"


@pytest.mark.parametrize("split, panels", [(None, 1), (("inner", "outer"), 2)])
def test_the_energy_figure_has_a_split_panel_only_with_two_pads(tmp_path, drawn, split, panels):
    """energy.png: the strain-energy shares (Fig. 4.20) and, for two pads, the share of one in both
    (Fig. 4.21). With three pads (no split) the second panel was drawn empty but for the unstable
    modes' markers (found by a user trial); the markers go on the last panel drawn."""
    from types import SimpleNamespace as NS

    from multiscale.macro.modal import EnergyShares
    from multiscale.plots import squeal as plots
    energy = np.array([[1.0, 2.0, 3.0], [2.0, 1.0, 1.0], [0.5, 0.5, 3.0]])
    shares = EnergyShares(["inner", "outer", "disc"], energy, energy / energy.sum(axis=1, keepdims=True))
    case = NS(name="three pads", modes=np.zeros(3), energy=shares, report=NS(unstable=np.array([2])))
    plots.plot_energy(case, tmp_path / "energy.png", split)
    axes = drawn[0].axes
    assert len(axes) == panels and all(ax.patches for ax in axes)         # every panel has bars
    assert [line.get_xdata()[0] for line in axes[-1].get_lines() if line.get_linestyle() == ":"] == [2]


def test_the_squeal_figures_compare_like_with_like(tmp_path, drawn):
    """Found by a user trial: pressure.png gave each pad its own colour scale (0-1.26 and 0-2.44
    MPa in the same colours); energy.png drew the inner/outer split as a full bar for modes whose
    pads hold next to none of the energy (the unstable pair among them); re_im.png did not mark the
    unstable modes and had a one-entry legend. Now one scale and one colour bar for every pad, the
    split of modes whose two pads hold under SPLIT_FLOOR of the energy hatched, the unstable modes
    circled in red."""
    from types import SimpleNamespace as NS

    from multiscale.macro.modal import EnergyShares
    from multiscale.plots import squeal as plots
    x, y = np.meshgrid(np.linspace(0, 0.02, 6), np.linspace(0, 0.01, 4))
    mid = np.column_stack([np.r_[x.ravel(), x.ravel()], np.r_[y.ravel(), y.ravel() + 0.05], np.zeros(48)])
    masks = {"inner": np.arange(48) < 24, "outer": np.arange(48) >= 24}
    pressure = np.r_[np.linspace(0, 1.26e6, 24), np.linspace(0, 2.44e6, 24)]
    plots.plot_pressure(mid, masks, pressure, "brake", tmp_path / "pressure.png")
    inner, outer, *bars = drawn[-1].axes
    assert len(bars) == 1 and bars[0].get_ylabel() == "contact pressure [MPa]"           # one colour bar
    np.testing.assert_array_equal(inner.collections[0].levels, outer.collections[0].levels)
    assert outer.collections[0].levels[-1] == pytest.approx(2.44)
    r, t = np.meshgrid(np.linspace(0.088, 0.126, 5), np.linspace(-0.35, 0.35, 8))   # four pads of a brake in a
    angles = [t.ravel() + c for c in (1.95, 1.19, -1.95, -1.19)]                      # row: no panel's labels
    ring = np.column_stack([np.concatenate([r.ravel() * np.cos(a) for a in angles]),  # over its neighbour's
                            np.concatenate([r.ravel() * np.sin(a) for a in angles]), np.zeros(160)])   # (a CAD
    four = {f"pad_{k}": np.arange(160) // 40 == k for k in range(4)}                  # trial)
    plots.plot_pressure(ring, four, np.linspace(0.0, 5e6, 160), "brake", tmp_path / "pressure.png")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    renderer = FigureCanvasAgg(drawn[-1]).get_renderer()
    boxes = [ax.get_tightbbox(renderer) for ax in drawn[-1].axes[:4]]
    assert all(left.x1 <= right.x0 for left, right in zip(boxes, boxes[1:])), [(b.x0, b.x1) for b in boxes]
    from multiscale.geometry import Rotation            # the disc's motion across each pad (an NVH user trial)
    plots.plot_pressure(ring, four, np.linspace(0.0, 5e6, 160), "brake", tmp_path / "pressure.png",
                        ("disc", Rotation().velocity(ring)))
    for ax, mask in zip(drawn[-1].axes[:4], four.values()):
        (arrow,) = [t for t in ax.texts if t.get_text() == ""]
        c = ring[mask, :2].mean(axis=0) * 1e3
        along = (np.asarray(arrow.xy) - np.asarray(arrow.xyann)) @ np.array([-c[1], c[0]])   # e_z x (x - 0)
        assert along > 0 and [t.get_text() for t in ax.texts if t.get_text()] == ["disc slides"]
    energy = np.array([[1.0, 2.0, 3.0], [0.001, 0.002, 10.0], [0.5, 0.5, 3.0]])
    shares = EnergyShares(["inner", "outer", "disc"], energy, energy / energy.sum(axis=1, keepdims=True))
    class Modes(NS):
        def __len__(self):
            return len(self.frequency)
    modes = Modes(frequency=np.array([800.0, 1500.0, 1500.0]), growth=np.array([0.0, 3.0, -3.0]))
    case = NS(name="brake", modes=modes, energy=shares, report=NS(unstable=np.array([2])))
    plots.plot_energy(case, tmp_path / "energy.png", ("inner", "outer"))
    split = drawn[-1].axes[1]
    hatched = [round(p.get_x() + p.get_width() / 2) for p in split.patches if p.get_hatch() == "//"]
    assert hatched == [2]                                  # 0.03 % of mode 2's energy in the pads
    plots.plot_re_im([case], tmp_path / "re_im.png")
    ax = drawn[-1].axes[0]
    circled = [line for line in ax.get_lines() if line.get_markeredgecolor() == "r"]
    assert len(circled) == 1 and list(circled[0].get_xdata()) == [1500.0] and list(circled[0].get_ydata()) == [3.0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["brake", "unstable"]
    assert [(t.get_text(), t.xy) for t in ax.texts] == [("1500 Hz", (1500.0, 3.0))]   # (unlabelled: an NVH trial)


# ---------------------------------------------------------------- ties in the mode pairing
def lock_in_tie(seed=0):
    """Real parents x1, x2 (stable, lambda on the imaginary axis) and the two members y, conj(y)
    (sigma -+) of the pair they lock into: each parent has the same MAC with both members and the
    same eigenvalue jump to both, so the two assignments of the pairing tie exactly."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((8, 2))
    y = 0.9 * x[:, 0] + 0.7j * x[:, 1] + 0.05 * rng.standard_normal(8)
    lam_a = 1j * np.array([1.00, 1.04])
    lam_b = np.array([-0.01 + 1.02j, 0.01 + 1.02j])           # numbered stable first (eigen.by_frequency)
    return x.astype(complex), np.column_stack([y, y.conj()]), lam_a, lam_b


@pytest.mark.parametrize("noise", [(0, 0), (0, 1), (1, 0), (1, 1)])
@pytest.mark.parametrize("split", [False, True])
def test_the_pairing_breaks_a_lock_in_tie_by_the_mode_numbers_not_by_round_off(noise, split):
    """On the demo brake (30 mm, friction 0.1 to 0.6) the map's tracks of a pair that locks in (or
    splits) swapped between 1 and 2 ranks, and between two serial runs: the MACs and eigenvalue
    jumps of the two assignments were equal to 1e-16, the solver's choice followed the round-off
    (here: 1e-15 added to one entry). Now a tie keeps the order: the lower parent continues into
    the stable member; at a split the stable member into the lower child."""
    from multiscale.macro.modal import mac_matrix, pair_modes
    parents, members, lam_a, lam_b = lock_in_tie()
    if split:                                  # the pair splits again: members before, parents after
        parents, members, lam_a, lam_b = members, parents, lam_b, lam_a
    mac = mac_matrix(parents, members)
    assert np.ptp(mac, axis=1 if not split else 0).max() < 1e-14       # the tie
    mac[noise] += 1e-15
    assert pair_modes(mac, lam_a, lam_b, 0.1) == [(0, 0), (1, 1)]
    assert pair_modes(mac, lam_a, lam_b, 0.1, subspace=lambda rows, cols: 1.0) == [(0, 0), (1, 1)]


def test_the_pairing_keeps_a_crossing_that_is_not_a_tie():
    """Only ties are uncrossed: two modes that exchange their order (a veering pair's shapes
    followed across) stay crossed."""
    from multiscale.macro.modal import pair_modes
    mac = np.array([[0.2, 0.9], [0.9, 0.2]])
    lam = 1j * np.array([1.0, 1.01])
    assert pair_modes(mac, lam, lam, 0.5) == [(0, 1), (1, 0)]
    mac, lam = np.array([[0.8, 0.8 + 1e-6], [0.7, 0.7]]), 1j * np.ones(2)     # 1e-6: not round-off
    assert pair_modes(mac, lam, lam, 0.5) == [(0, 1), (1, 0)]

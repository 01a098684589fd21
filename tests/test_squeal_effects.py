"""Squeal-analysis options on finite-element models (issue 20): prestress (pre-tensioned beam),
gyroscopic terms (spinning disc), per-material damping, friction-slope damping, scene sweeps."""
import csv
import dataclasses
import re
from pathlib import Path
from types import SimpleNamespace as NS

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

import gmsh  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem, io, mesh as dmesh  # noqa: E402
from dolfinx.fem import petsc as fpetsc  # noqa: E402
from mpi4py import MPI  # noqa: E402

from meshes import disc_brake  # noqa: E402
from multiscale import scene as scenes  # noqa: E402
from multiscale.errors import InputError, SceneError  # noqa: E402
from multiscale.geometry import Rotation, builder  # noqa: E402
from multiscale.macro import damped, eigen  # noqa: E402
from multiscale.macro import mesh as two_body  # noqa: E402
from multiscale.macro.friction import StribeckFriction, facet_slip_speed, friction_damping  # noqa: E402
from multiscale.outputs import plan  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.macro.operators import geometric_form, rotation_forms, rotation_velocity  # noqa: E402
from multiscale.macro.preload import linearise, linearise_system, preload  # noqa: E402
from multiscale.references.stability import spinning_disc_split, tensioned_beam_frequency  # noqa: E402
from multiscale.workflows import squeal  # noqa: E402
from test_squeal_damping import check_map_files  # noqa: E402

DEMO = Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml"
STEEL = NS(E=210e9, nu=0.3, rho=7850.0)
MATERIALS = {"disc": NS(E=125e9, nu=0.25, rho=7200.0), "pad": NS(E=5e9, nu=0.25, rho=2500.0),
             "backplate": STEEL, "piston": STEEL, "caliper": STEEL}
PRESSURE = 1e6
NO_FIGURES = {"output.figures": False}     # the runs' figures are looked at in test_outputs and the map test


def elasticity(V, m):
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    lam, mu = m.E * m.nu / ((1 + m.nu) * (1 - 2 * m.nu)), m.E / (2 * (1 + m.nu))
    eps = ufl.sym(ufl.grad(u))
    k = (lam * ufl.tr(eps) * ufl.div(v) + 2 * mu * ufl.inner(eps, ufl.sym(ufl.grad(v)))) * ufl.dx
    return u, v, k, m.rho * ufl.inner(u, v) * ufl.dx


def assemble(form, bcs=(), diag=1.0):
    A = fpetsc.assemble_matrix(fem.form(form), bcs=list(bcs), diag=diag)
    A.assemble()
    return A


# ---------------------------------------------------------------- prestress
def test_pre_tensioned_beam_frequency_shift_matches_the_closed_form():
    """Pinned-pinned beam (transverse displacements fixed on the end faces) under an axial stress
    sigma_0 = T / A: omega^2 rises by T k^2 / (rho A), k = n pi / L, whatever the bending stiffness."""
    L, h, m = 1.0, 0.04, STEEL
    msh = dmesh.create_box(MPI.COMM_SELF, [[0, 0, 0], [L, h, h]], [24, 2, 2], dmesh.CellType.hexahedron)
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    u, v, k, mass = elasticity(V, m)
    ends = dmesh.locate_entities_boundary(msh, 2, lambda x: np.isclose(x[0], 0) | np.isclose(x[0], L))
    bcs = [fem.dirichletbc(0.0, fem.locate_dofs_topological(V.sub(i), 2, ends), V.sub(i)) for i in (1, 2)]
    stress0 = 20e6                                   # Pa, T = 32 kN (3 % of the Euler load of mode 1)
    sigma = ufl.as_matrix([[stress0, 0, 0], [0, 0, 0], [0, 0, 0]])
    K, M = assemble(k, bcs), assemble(mass, bcs, diag=0.0)
    Ks = assemble(geometric_form(sigma, u, v, ufl.dx), bcs, diag=0.0)
    f0 = eigen.solve_modes(K, M, f_min=5.0, f_max=200.0, target=5.0).frequency
    K.axpy(1.0, Ks)
    f1 = eigen.solve_modes(K, M, f_min=5.0, f_max=200.0, target=5.0).frequency
    # first bending doublet (y and z): the shift of omega^2 against the closed form
    A, inertia = h * h, h**4 / 12
    ref = tensioned_beam_frequency(1, L, m.E, inertia, m.rho, A, stress0 * A) ** 2 \
        - tensioned_beam_frequency(1, L, m.E, inertia, m.rho, A) ** 2
    shift = (2 * np.pi) ** 2 * (f1[:2] ** 2 - f0[:2] ** 2)
    np.testing.assert_allclose(shift, ref, rtol=1e-5)              # measured 4e-7
    assert f0[0] == pytest.approx(tensioned_beam_frequency(1, L, m.E, inertia, m.rho, A) / (2 * np.pi), rel=5e-3)   # 2.5e-3: shear, h/L = 0.04


# ---------------------------------------------------------------- rotating disc
@pytest.mark.parametrize("method", ["quadratic", "projection"])
def test_spinning_disc_splits_two_nodal_diameter_doublet_by_n_omega(method):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.add("disc")
        disc_brake.generate_disc(gmsh.model, {"mesh_size": 0.032, "disc_thickness": 0.008}, hat=False)
        msh = io.gmsh.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=3).mesh
    finally:
        gmsh.finalize()
    m = MATERIALS["disc"]
    V = fem.functionspace(msh, ("Lagrange", 2, (3,)))
    u, v, k, mass = elasticity(V, m)
    K, M = assemble(k), assemble(mass)
    base = eigen.solve_modes(K, M, f_min=20.0, f_max=2000.0, target=20.0, n_modes=2)
    f_r = base.frequency.mean()
    omega = 2 * np.pi * 0.02 * f_r / 2               # split n Omega / pi = 4 % of f_r
    w = rotation_velocity(Rotation((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)), ufl.SpatialCoordinate(msh), omega)
    g, kw = rotation_forms(m.rho, w, u, v, ufl.dx)
    Kt = assemble(k)
    Kt.axpy(1.0, assemble(kw, diag=0.0))
    system = damped.LinearSystem(Kt, M, assemble(g, diag=0.0))
    r = damped.solve_system(system, f_min=20.0, f_max=1.3 * f_r, target=20.0, basis=2.0, method=method)
    pair = r.frequency[np.argsort(np.abs(r.frequency - f_r))[:2]]
    low, high = np.sort(pair)
    b, f = spinning_disc_split(f_r, 2, omega)
    assert high - low == pytest.approx(f - b, rel=0.01)          # measured 1.1e-3 (in-plane motion)
    assert 0.5 * (low + high) == pytest.approx(f_r, rel=1e-5)     # measured 1e-7
    assert np.abs(r.growth).max() < 1e-6 * np.abs(r.eigenvalues).max()   # gyroscopic: conservative
    assert r.errors.max() < 1e-3                                     # projection: measured 6e-4


# ---------------------------------------------------------------- the brake model
@pytest.fixture(scope="module")
def brake():
    tm = two_body.build(builder("disc_brake"), {"mesh_size": 0.02})
    mech = Mechanics(tm, MATERIALS, stiffness=1e13, friction=0.4, speed=5.0, load_kind="fluid",
                     prefix="brake_effects_")
    return tm, mech


@pytest.fixture(scope="module")
def undamped(brake):
    """The brake's undamped analysis with the default options (12 modes, preloaded from rest): the
    next two tests check it and shift it."""
    return squeal.squeal_case(brake[1], MATERIALS, "mu0.4", load=PRESSURE, n_modes=12, energy=False)


def test_default_options_give_the_undamped_analysis_bit_for_bit(brake, undamped):
    tm, mech = brake
    case = undamped
    preload(mech, PRESSURE, 1)
    ref = eigen.solve_modes(*linearise(mech, MATERIALS), n_modes=12, f_max=16e3)
    assert case.terms == () and case.modes.method == "gnhep"
    np.testing.assert_array_equal(case.modes.eigenvalues, ref.eigenvalues)


def test_material_mass_damping_shifts_every_eigenvalue_exactly(brake, undamped):
    """alpha_b = alpha on every body: C = alpha M, so lambda^2 + alpha lambda + theta = 0 maps
    the undamped theta exactly; the full quadratic solver must reproduce it."""
    tm, mech = brake
    alpha = 40.0
    lossy = {n: NS(**vars(m), damping_alpha=alpha) for n, m in MATERIALS.items()}
    plain = undamped                # the same call as before (preloaded from rest: no state carried)
    case = squeal.squeal_case(mech, lossy, "alpha", load=PRESSURE, n_modes=12, energy=False)
    assert case.terms == ("material viscous damping",) and case.modes.method == "pep"
    ref = eigen.lambda_from_theta(plain.modes.theta, eigen.Damping(alpha=alpha))
    np.testing.assert_allclose(case.modes.eigenvalues, ref, rtol=1e-6)        # measured 1.1e-7 (PEP)


def test_friction_slope_damping_of_a_rigid_disc_rotation(brake):
    """C_f of a uniform slope k [s/m] on the disc's rigid rotation (unit rad/s) is int p k r^2 dS."""
    tm, mech = brake
    preload(mech, PRESSURE, 1)
    k = -0.05
    C = friction_damping(mech, np.full(tm.interface.n_facets, k))
    rot = fem.Function(mech.spaces[1])
    rot.interpolate(lambda x: np.vstack([-x[1], x[0], 0 * x[2]]))
    x, y = C.createVecs()
    x.set(0.0)
    off = mech.spaces[0].dofmap.index_map.size_local * 3
    n1 = mech.spaces[1].dofmap.index_map.size_local * 3
    x.array[off:off + n1] = rot.x.array[:n1]
    C.mult(x, y)
    xs = ufl.SpatialCoordinate(tm.parent)
    ref = fem.assemble_scalar(fem.form(k * mech.contact.pressure * (xs[0] ** 2 + xs[1] ** 2) * tm.interface.dS,
                                       entity_maps=tm.entity_maps))
    assert x.dot(y) == pytest.approx(ref, rel=1e-10)
    assert ref < 0


def scipy_matrix(A):
    import scipy.sparse      # local: this test alone reads the assembled matrices
    indptr, indices, values = A.getValuesCSR()
    return scipy.sparse.csr_matrix((values, indices, indptr), shape=A.getSize())


def test_a_pad_loss_factor_is_projected_as_the_full_complex_solve_gives_it(brake):
    """materials.pad.loss_factor = 0.05 on the coarse brake: the projection's 8 lowest modes against
    the full problem (K + i H) phi = -lambda^2 M phi (ARPACK shift-and-invert on the LU of K + i H
    over the free dofs, tol 1e-12): within 1e-6 (measured 9.3e-8; growth rates within 1.6e-4 1/s),
    residuals below the run's warning threshold (measured 2.4e-3). Before the static responses to
    the pad's damping forces joined the basis: 9e-5 off (1097 Hz: 0.62 Hz and 0.03 1/s) and
    residuals up to 0.18."""
    import scipy.sparse.linalg as sla     # local: this test alone needs ARPACK
    tm, mech = brake
    lossy = dict(MATERIALS, pad=NS(**vars(MATERIALS["pad"]), loss_factor=0.05))
    preload(mech, PRESSURE, 1)
    system = linearise_system(mech, lossy).system
    r = damped.solve_system(system, n_modes=8)
    K, M, H = (scipy_matrix(A) for A in (system.K, system.M, system.H))
    free = M.diagonal() > 0
    K, M, H = ((A[free][:, free]).tocsc() for A in (K, M, H))
    lu = sla.splu(K + 1j * H)
    mu = sla.eigs(sla.LinearOperator(K.shape, matvec=lambda x: lu.solve(M @ x), dtype=complex), k=12, tol=1e-12,
                  return_eigenvectors=False)
    lam = 1j * np.sqrt(1.0 / mu)                          # omega > 0: the principal root
    ref = lam[np.argsort(lam.imag)][:8]
    assert r.method == "projection" and len(r) == 8
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-6)
    assert r.errors.max() < squeal.MODE_RESIDUAL


def test_modes_with_large_residuals_are_warned_about():
    """A run's modes with relative residuals above squeal.MODE_RESIDUAL are named in a warning with
    the key that widens the projection basis (before: no word; modes.csv of the coarse demo brake
    with a pad loss factor showed 0.15 for its first mode); without loss factors the exact
    quadratic solver is named too, unless the band starts above 0 Hz or a target is set, which it
    cannot reach."""
    lam = np.array([-28.8 + 4714.0j, -40.4 + 9688.0j, -1.1 + 9884.0j])
    modes = eigen.ModalResult(lam, -lam**2, np.zeros((1, 3)), np.array([0.22, 0.031, 1e-3]), (0.0, 16e3), 0.0, 1,
                              "projection", 0, 0, 0.0)
    scene = NS(stability=NS(basis=1.5, damping=0.0, method="auto", band=(0.0, 16e3), target=None))
    lossy = squeal.approximate_modes(scene, NS(modes=modes, terms=("material loss factors",)))
    assert lossy == ["modes 1 (750 Hz, 2.2e-01), 2 (1542 Hz, 3.1e-02) have relative residuals above 0.03: their "
                     "frequencies and growth rates are approximate (projected on the modes up to stability.basis x "
                     "f_max; a larger stability.basis, now 1.5, widens the basis)"]
    viscous = squeal.approximate_modes(scene, NS(modes=modes, terms=("friction slope",)))
    subspace = NS(stability=NS(basis=1.5, damping=0.0, method="subspace", band=(0.0, 16e3), target=None))
    assert squeal.approximate_modes(subspace, NS(modes=modes, terms=("material loss factors",)))[0].endswith(
        "widens the basis; stability.method = \"projection\" adds the static responses to the loss factors' forces)")
    assert viscous[0].endswith('widens the basis; stability.method = "quadratic" solves viscous damping exactly)')
    for band, target in (((1e3, 16e3), None), ((0.0, 16e3), 2e3)):   # out of the quadratic solver's reach
        above = NS(stability=NS(basis=1.5, damping=0.0, method="auto", band=band, target=target))
        assert squeal.approximate_modes(above, NS(modes=modes, terms=("friction slope",)))[0].endswith("widens the basis)")
    modes.errors[:] = [1e-3, 0.05, 1e-3]
    assert squeal.approximate_modes(scene, NS(modes=modes, terms=("material loss factors",))) == [
        "mode 2 (1542 Hz, 5.0e-02) has a relative residual above 0.03: its frequency and growth rate are approximate "
        "(projected on the modes up to stability.basis x f_max; a larger stability.basis, now 1.5, widens the basis)"]
    modes.errors[:] = 1e-3
    assert squeal.approximate_modes(scene, NS(modes=modes, terms=())) == []


def test_values_of_the_projected_problem_left_out_among_the_modes_are_said():
    """A value that is no mode of the model (relative residual above damped.SPURIOUS) took a place
    among the modes nearest the target: the run says it was left out (a user trial saw it reported
    as an unstable squeal mode, 3524 Hz); one outside the modes' window displaced none, unsaid."""
    lam = np.array([2.7 + 2915.5j, 28.7 + 2986.7j, 6.0 + 3542.6j, 15.2 + 3800.7j]) * 2 * np.pi
    modes = eigen.ModalResult(lam, -lam**2, np.zeros((1, 4)), np.full(4, 1e-3), (0.0, 6e3), 3500.0, 1, "projection",
                              0, 0, 0.0, spurious=(3524.3, 5931.0))
    scene = NS(stability=NS(basis=1.5, damping=0.0, method="auto", band=(0.0, 6e3), target=3500.0, modes=4, sweep=None),
               materials=None)
    case = NS(modes=modes, terms=(), mech=NS(tm=NS(notes=())), facet_pressure=np.zeros(1),
              preload=NS(normal_force={}), slip_speed=None,
              report=NS(divergent=np.zeros(0, dtype=int), unstable=np.zeros(0, dtype=int)))
    said = squeal._left_out(scene, case, None)
    assert said[0] == ("1 value(s) of the projected problem among the modes found (3524 Hz) had relative residuals "
                       "above 0.5 in the full model: not modes of it, left out (a larger stability.basis, now 1.5, "
                       "widens the basis)")
    assert said[1].startswith("stability.modes = 4: the modes found span 2916 to 3801 Hz around stability.target = "
                              "3500 Hz; the band below 2916 Hz, from 0 Hz, and above 4084 Hz")
    # a map preloaded at each point without refinement: its onsets come from blended systems (8 % low in a
    # user trial), said
    modes = dataclasses.replace(modes, spurious=())
    smap = NS(onsets=[object()], parameter="friction", residual=np.zeros(1), max_pressure=0.0)
    for refine, warned in ((0, True), (3, False)):              # narrowed by full analyses: nothing to say
        each = NS(stability=NS(**{**vars(scene.stability), "sweep": NS(preload_mode="each", refine_steps=refine)}),
                  materials=None)
        said = squeal._left_out(each, NS(**{**vars(case), "modes": modes}), smap)
        assert [w for w in said if "blended" in w] == warned * [
            "the stability map's onsets are bisected between its points on systems blended from the two "
            "neighbouring points' (stability.sweep.refine = 0), not narrowed by full analyses: the bracket in "
            "onsets.csv is the blend's, and such onsets were up to 9 % low against direct runs in trials (demo "
            "brake 4.3 kHz pair: 0.543 against 0.585-0.593); stability.sweep.refine = 3 (the default) brackets "
            "each between full analyses"]


# ---------------------------------------------------------------- scene options and sweeps
def test_scene_friction_sweep_writes_the_map(tmp_path, documented):
    overrides = {"geometry.mesh_size": "20 mm", "stability.modes": 30, "output.folder": str(tmp_path / "out"),
                 "stability.sweep.friction": [0.0, 0.6], "stability.sweep.points": 4,
                 "stability.sweep.preload": "once"}                  # (a friction map's default is "each")
    scene = scenes.load(DEMO, overrides)
    run = squeal.run(scene, degree=1, verbose=False)
    names = {p.name for p in run.files}
    assert {"map.csv", "onsets.csv", "map.h5", "map.png", "map_tracks.png"} <= names
    # what check promised (and a later --overwrite deletes; before, the map's files were missing)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(set(plan(scene).files) - {"open_in_paraview.py"})
    smap = run.map
    np.testing.assert_allclose(smap.values, [0.0, 0.2, 0.4, 0.6])
    assert f"(common basis of {smap.basis_size})" in smap.summary() and smap.basis_size > 0
    assert not smap.unstable()[0].any()                       # no friction: stable
    assert smap.unstable()[-1].any() and smap.onsets
    assert np.nanmax(smap.residual) < 0.05                    # measured 0.023
    assert any(w.startswith("the stability map's modes have relative residuals up to") for w in run.warnings)
    # its onsets are those of the nominal preload's state, said (a user trial found one 77 % off full analyses)
    assert any(w.startswith("the stability map's onsets are for the preloaded state of the nominal analysis")
               for w in run.warnings)
    # mu = 0.4 in the map against the nominal analysis (same preload, projected)
    f_map = np.sort(smap.frequency[2][~np.isnan(smap.frequency[2])])
    assert f_map[:8] == pytest.approx(run.case.modes.frequency[:8], rel=1e-4)    # measured 8e-6
    check_map_files(tmp_path / "out", smap, documented)      # the files hold the map, its onsets in their brackets


def test_a_mode_count_never_cuts_a_lock_in_pair_in_two(tmp_path):
    """With stability.modes ending inside a lock-in pair (sigma +-57.7 1/s at 2670 Hz, modes 8 and 9
    of the 20-mm demo brake), the direct analysis kept both (9 modes) but the projected solves kept
    the stable member only: a friction map over [0.1, 0.6] said "0 unstable somewhere" where the
    nominal mu = 0.4 is unstable. Now ``damped.select`` keeps every mode as near the target as the
    last one (1e-8 relative)."""
    w = 2 * np.pi * np.array([750.0, 2670.0, 2670.0, 2701.0])
    lam = np.array([0, -57.7, 57.7, 0]) + 1j * w            # stable member first, as the solver gave
    assert sorted(damped.select(lam, (0.0, 6e3), 2, 0.0)) == [0, 1, 2]
    assert sorted(damped.select(lam, (0.0, 6e3), 1, 0.0)) == [0]
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "20 mm", "stability.modes": 8, "stability.band": ["0 Hz", "3 kHz"],
                 "output.folder": str(tmp_path / "out"), "stability.sweep.friction": [0.1, 0.6],
                 "stability.sweep.preload": "once"}
    run = squeal.run(scenes.load(DEMO, overrides), verbose=False)          # quadratic elements, as the CLI
    assert run.case.modes.frequency.size == 9 and run.case.modes.unstable().sum() == 1
    assert run.map.unstable()[-1].sum() == 1                  # sigma = +79 1/s at mu = 0.6 (measured)
    assert [o.kind for o in run.map.onsets] == ["lock-in"]    # bisected: mu = 0.127


def test_a_lock_in_pair_is_numbered_stable_first_whatever_the_rounding():
    """The members of a lock-in pair have one frequency up to rounding; sorting on the exact
    frequency numbered them by the rounding: map.csv of a friction sweep of the 20-mm demo brake
    gave modes 8 and 9 of the pair at mu = 0.433 swapped between 1 and 2 ranks. Now frequencies within
    1e-9 relative sort by growth rate."""
    w = 2 * np.pi * 2670.513161
    lam = np.array([61.45 + 1j * w, -61.45 + 1j * w * (1 + 1e-13), 1j * 2 * np.pi * 750.0])
    assert list(damped.select(lam, (0.0, 6e3), None, 0.0)) == [2, 1, 0]
    assert list(eigen.by_frequency(lam[::-1])) == [0, 1, 2]


def test_scene_roughness_sweep_rebuilds_the_laws_and_frees_the_models(tmp_path):
    """An rms sweep rebuilds the zone laws and the mechanics at every point: its first point (the
    nominal R_q) gives the nominal analysis' modes; a rougher surface is more compliant (a lower
    first mode). Every model the run built is closed and freed after it (before, each stayed
    alive with ~35 MPI communicators of MPICH's 2048: a long sweep aborted the process)."""
    import gc      # local: this test alone looks at the collector
    overrides = {**NO_FIGURES,
                 "effects": ["contact", "friction", "stability", "roughness"], "roughness.body": "brake",
                 "roughness.rms": "0.05 um", "roughness.hurst": 0.8, "roughness.k_min": 1, "roughness.k_max": 16,
                 "roughness.patch": "zone", "micro.zones": [4, 2], "micro.grid": [32, 32], "micro.law_points": 10,
                 "micro.p_max": "30 kPa", "geometry.mesh_size": "20 mm", "stability.modes": 20,
                 "stability.sweep.rms": ["0.05 um", "2 um"], "stability.sweep.points": 2,
                 "output.folder": str(tmp_path / "out")}
    scene = scenes.load(DEMO, overrides)

    def models():
        gc.collect()
        return sum(isinstance(o, Mechanics) for o in gc.get_objects())
    before = models()
    run = squeal.run(scene, degree=1, verbose=False)
    smap, nominal = run.map, run.case.modes.frequency
    np.testing.assert_allclose(smap.values, [5e-8, 2e-6])
    assert "basis" not in smap.summary()                      # every point solved on its own (was "basis 0")
    f = [np.sort(smap.frequency[k][~np.isnan(smap.frequency[k])]) for k in range(2)]
    assert f[0][:8] == pytest.approx(nominal[:8], rel=1e-6)
    assert f[1][0] < 0.9 * f[0][0]                             # measured 830 against 1089 Hz
    del run
    assert models() == before


def test_a_roughness_sweep_that_fails_closes_the_model_it_rebuilt(tmp_path, monkeypatch):
    """The preload of the first rebuilt point fails (simulated): the run's error passes on and the
    mechanics the map rebuilt is closed and freed with the nominal one (one rank; before: it stayed
    alive with its MPI communicators)."""
    import gc      # local: this test alone looks at the collector
    from multiscale.errors import ConvergenceError
    from multiscale.workflows import squeal_map
    overrides = {**NO_FIGURES,
                 "effects": ["contact", "friction", "stability", "roughness"], "roughness.body": "brake",
                 "roughness.rms": "0.05 um", "roughness.hurst": 0.8, "roughness.k_min": 1, "roughness.k_max": 16,
                 "roughness.patch": "zone", "micro.zones": [4, 2], "micro.grid": [32, 32], "micro.law_points": 10,
                 "micro.p_max": "30 kPa", "geometry.mesh_size": "30 mm", "stability.modes": 6,
                 "stability.sweep.rms": ["0.05 um", "2 um"], "output.folder": str(tmp_path / "out")}

    def failing(*args, **kwargs):
        raise ConvergenceError("the preload fails (simulated)")
    monkeypatch.setattr(squeal_map, "preload", failing)

    def models():
        gc.collect()
        return sum(isinstance(o, Mechanics) for o in gc.get_objects())
    before = models()
    with pytest.raises(ConvergenceError, match="simulated"):
        squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False)
    assert models() == before


def test_a_speed_sweep_that_changes_nothing_is_warned_about(tmp_path):
    """Speed sweep with a constant friction and no gyroscopic terms: identical points, said at
    check (before: OK and a flat map; found by an adversarial test); with them, no warning."""
    sweep = {"stability.sweep.speed": ["1 rad/s", "100 rad/s"], "output.folder": str(tmp_path / "out")}
    warned = [w for w in scenes.load(DEMO, sweep).warnings if "depends on the speed" in w]
    assert warned == ["stability.sweep.speed: nothing of the linearised system depends on the speed (a constant "
                      "friction, stability.gyroscopic = false): every point of the map is the same"]
    assert not any("depends on the speed" in w
                   for w in scenes.load(DEMO, {**sweep, "stability.gyroscopic": True}).warnings)


def test_the_instability_threshold_is_the_users(tmp_path):
    """``stability.threshold``: a mode is unstable when its damping ratio is below minus it. The demo
    brake's lock-in mode (mu = 0.4, 20 mm mesh, P1: 8507 Hz; P2: 2670 Hz, -3.4e-3) grows at a
    damping ratio of -2.9e-3: unstable by the default 1e-6, not by 1e-2, in the report, modes.csv
    and a map alike (before: 1e-6, fixed, which flagged modes at damping ratios of -6e-6 that
    industrial practice leaves out)."""
    overrides = {**NO_FIGURES, "geometry.mesh_size": "20 mm", "stability.band": ["0 Hz", "9 kHz"],
                 "output.folder": str(tmp_path / "out"), "stability.threshold": 1e-2,
                 "stability.sweep.friction": [0.35, 0.4], "stability.sweep.preload": "once"}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False)     # P1: the lock-in at 8507 Hz
    modes, report = run.case.modes, run.case.report
    ratio = -modes.growth / np.abs(modes.eigenvalues)
    assert ratio.min() == pytest.approx(-2.9e-3, rel=0.3)     # the lock-in mode: unstable by the default
    assert modes.unstable(1e-6).any() and report.rtol == 1e-2 and report.unstable.size == 0
    with open(tmp_path / "out" / "modes.csv") as f:
        assert {row["unstable"] for row in csv.DictReader(f)} == {"0"}
    assert run.map.rtol == 1e-2 and not run.map.unstable().any()


def test_a_pressure_sweep_that_changes_nothing_is_warned_about(tmp_path):
    """Pressure sweep of a perfect-contact brake without prestress: linear elasticity, penalty
    contact without initial gaps and Coulomb friction scale with the load, so the tangent and every
    point of the map are the same (a helper's 5-15 bar sweep: 750.210388 Hz at each point; before, no
    warning); with the prestress stiffness or rough laws the points differ, no warning."""
    sweep = {"stability.sweep.pressure": ["5 bar", "15 bar"], "output.folder": str(tmp_path / "out")}
    warned = [w for w in scenes.load(DEMO, sweep).warnings if "depends on the pressure" in w]
    assert warned == ["stability.sweep.pressure: nothing of the linearised system depends on the pressure (penalty "
                      "contact without initial gaps scales with the load, stability.prestress = false): every point "
                      "of the map is the same"]
    rough = {"effects": ["contact", "friction", "stability", "roughness"], "roughness.body": "brake",
             "roughness.rms": "0.05 um", "roughness.hurst": 0.8, "roughness.k_min": 1, "roughness.k_max": 16,
             "roughness.patch": "zone", "micro.zones": [4, 2], "micro.grid": [32, 32]}
    for other in ({"stability.prestress": True}, rough):
        assert not any("depends on the pressure" in w for w in scenes.load(DEMO, {**sweep, **other}).warnings)


def test_scene_damping_and_stribeck_options(tmp_path, documented):
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "20 mm", "stability.modes": 10, "output.folder": str(tmp_path / "out"),
                 "stability.rayleigh_alpha": "20 1/s", "stability.prestress": True,
                 "materials.pad.loss_factor": 0.05}
    scene = scenes.load(DEMO, overrides)
    run = squeal.run(scene, degree=1, verbose=False)
    assert {"material loss factors", "prestress", "proportional damping"} <= set(run.case.terms)
    assert run.case.modes.errors.max() < squeal.MODE_RESIDUAL           # measured 1.9e-3 (0.15 before)
    assert not [w for w in run.warnings if "relative residuals" in w]
    assert (tmp_path / "out" / "prestress.csv").exists()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(set(plan(scene).files) - {"open_in_paraview.py"})
    assert np.all(np.abs(run.case.prestress.shift) < 0.01 * run.case.prestress.frequency)
    with open(tmp_path / "out" / "prestress.csv", newline="") as f:
        table = list(csv.DictReader(f))
    with open(tmp_path / "out" / "modes.csv", newline="") as f:
        modes = list(csv.DictReader(f))
    assert not [n for n in table[0] if not documented(n)]
    effect = run.case.prestress
    assert [r["frequency_Hz"] for r in table] == [r["frequency_Hz"] for r in modes]    # one row per mode
    for name, column, rtol, atol in (("frequency_without", "frequency_without_prestress_Hz", 0, 5e-7),
                                     ("shift", "shift_Hz", 0, 5e-7), ("mac", "mac", 0, 5e-5),
                                     ("growth_without", "sigma_without_prestress_1_per_s", 5e-7, 1e-300)):
        np.testing.assert_allclose([float(r[column]) for r in table], getattr(effect, name), rtol=rtol, atol=atol,
                                   err_msg=column)            # as written: 6 decimals, 4 for the MAC, 7 digits
    with pytest.raises(InputError, match="quadratic"):
        scenes.load(DEMO, dict(overrides, **{"stability.method": "quadratic"}))


def test_a_floating_caliper_pressed_on_the_piston_alone_is_refused_before_its_modes(tmp_path):
    """The fluid load on the piston alone (loading.faces without the caliper bore): the outer pad
    carries nothing (5e-10 N against 1.6 kN), and its contact is all that holds the floating caliper
    along z. Its tangent is then singular or not by round-off: at 16 mm, 2 of 7 identical runs gave
    a 0 Hz "unstable" mode of residual 0.15 (a user trial). The run stops after writing the preload,
    naming the interface and what it alone holds; with the bore loaded too, the same mesh passes."""
    overrides = {**NO_FIGURES, "geometry.mesh_size": "20 mm", "stability.modes": 2,
                 "output.folder": str(tmp_path / "out")}
    scene = scenes.load(DEMO, {**overrides, "loading.faces": ["piston_back"]})
    assert "loading.faces = ['piston_back']: leaves out caliper_bore, where builder \"disc_brake\"'s fluid pressure " \
        "acts too; a part pressed only there (a floating caliper) is then held by no force" in scene.warnings[0]
    with pytest.raises(InputError, match=r"interface = 'outer_pad': it carried no force \(.* N, against 1\.6\de\+03 N\), "
                                         r"yet without it 1 part\(s\) could move as rigid bodies \(one of region "
                                         r"'outer_pad' \(with 'outer_backplate', 'caliper'\) around .* mm: "
                                         r"translation along z\)"):
        squeal.run(scene, degree=1, verbose=False)
    assert {"brake.xdmf", "interface.xdmf"} <= {p.name for p in (tmp_path / "out").iterdir()}   # the preload, kept
    from multiscale.workflows import transient
    static = scenes.load(DEMO, {**overrides, "loading.faces": ["piston_back"], "effects": ["contact", "friction"],
                                "output.folder": str(tmp_path / "static")})
    with pytest.raises(InputError, match=r"interface = 'outer_pad': it carried no force .* translation along z"):
        transient.run(static, verbose=False)          # a braking run: refused after its first solve is written
    assert {"brake.xdmf", "history.h5"} <= {p.name for p in (tmp_path / "static").iterdir()}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1, overwrite=True, verbose=False)
    assert not [w for w in run.warnings if "carried no force" in w]
    assert run.case.modes.errors.max() < squeal.MODE_RESIDUAL
    # --overwrite of these results by a run that finds no mode: they stay (an empty band, found only after
    # the preload, had deleted them: a user trial)
    before = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "out").iterdir()}
    with pytest.raises(InputError, match="no eigenvalue in this frequency band"):
        squeal.run(scenes.load(DEMO, {**overrides, "stability.band": ["2990 Hz", "3000 Hz"]}), degree=1,
                   overwrite=True, verbose=False)
    assert {p.name: p.stat().st_mtime_ns for p in (tmp_path / "out").iterdir()} == before


def test_a_mode_cap_beyond_the_dofs_is_refused_by_check_and_before_the_preload(tmp_path, capsys):
    """stability.modes = 100000 on the 20-mm brake (49 005 quadratic displacement dofs): the run said so
    after meshing, a 438 GB memory warning and the preload; check --cells estimated 440 GB and said OK
    (a user trial). Both refuse it now, check with the count it estimates, the run before its preload."""
    from multiscale.cli import main
    sets = ["--set", "geometry.mesh_size=20 mm", "--set", "stability.modes=100000",
            "--set", f"output.folder={tmp_path / 'out'}"]
    assert main(["check", str(DEMO), "--cells", *sets]) == 2
    err = capsys.readouterr().err
    assert "error: stability.modes = 100000: more than the model's 49,005 displacement dofs on this mesh" in err
    scene = scenes.load(DEMO, {**NO_FIGURES, "geometry.mesh_size": "20 mm", "stability.modes": 100000,
                               "output.folder": str(tmp_path / "out")})
    with pytest.raises(InputError, match=r"^stability.modes = 100000: must not exceed the number of dofs \(49005\)"):
        squeal.run(scene, verbose=False)
    assert not (tmp_path / "out" / "brake.xdmf").exists()


def test_a_large_mode_cap_asks_the_eigen_solver_for_the_band_not_for_the_cap(tmp_path, monkeypatch):
    """stability.modes = 300 on a band that holds fewer: the first solve asks at most
    ``eigen.FIRST_MODES`` pairs (it asked 301: 51.6 s for the 20-mm brake's 71 modes against 14.0 s;
    a user trial), the same modes as a cap of 100."""
    from multiscale.macro import eigen
    asked, set_up = [], eigen._set_up
    monkeypatch.setattr(eigen, "_set_up", lambda solver, want, failure: (asked.append(want),
                                                                         set_up(solver, want, failure))[1])
    runs = {}
    for cap in (100, 300):
        scene = scenes.load(DEMO, {**NO_FIGURES, "geometry.mesh_size": "20 mm", "stability.modes": cap,
                                   "output.folder": str(tmp_path / f"cap{cap}")})
        runs[cap] = squeal.run(scene, degree=1, verbose=False).case.modes
    assert asked == [eigen.FIRST_MODES] * 2 and runs[300].eigenvalues.size < 100
    np.testing.assert_array_equal(runs[300].eigenvalues, runs[100].eigenvalues)


def test_scene_stribeck_friction_sets_mu_per_facet_and_its_slope_damping(tmp_path):
    text = DEMO.read_text().replace("friction = 0.4\n", "") + (
        '\n[loading.stribeck]\nstatic = 0.5\nkinetic = 0.35\nspeed = "1 m/s"\n')
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "20 mm", "stability.modes": 20, "output.folder": str(tmp_path / "out")}
    scene = scenes.loads(text, DEMO.parent, overrides=overrides)
    run = squeal.run(scene, degree=1, verbose=False)
    case, law = run.case, StribeckFriction(0.5, 0.35, 1.0)
    assert case.terms == ("friction slope",) and case.modes.method == "pep"
    tm = case.mech.tm
    V = facet_slip_speed(case.mech)
    assert 0.2 < V.min() and V.max() < 1.0                      # 5 rad/s at the pad radii
    np.testing.assert_allclose(tm.interface.values(case.mech.contact.friction), law.value(V), rtol=1e-12)
    assert case.modes.errors.max() < 1e-6                      # measured 1.8e-8
    steady = scenes.loads(text, DEMO.parent, overrides=dict(overrides, **{"stability.friction_damping": False,
                                                                          "output.folder": str(tmp_path / "o2")}))
    plain = squeal.run(steady, degree=1, verbose=False).case
    assert plain.terms == () and plain.modes.method == "gnhep"
    # the falling mu(v) damps negatively: on average the growth rates rise
    assert np.mean(case.modes.growth - plain.modes.growth) > 0


def test_a_band_cut_short_by_the_number_of_modes_is_said(tmp_path):
    """6 modes of a 0-16 kHz band reach ~3 kHz: the run says the rest of the band was not searched
    (before: "6 modes up to 3017 Hz" and nothing else; found by an adversarial test)."""
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "30 mm", "stability.modes": 6, "output.folder": str(tmp_path / "out")}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False)
    top = run.case.modes.frequency.max()
    band = tuple(w for w in run.warnings if w.startswith("stability."))      # (the mesh's notes besides)
    assert top < 8e3 and band == (f"stability.modes = 6: the modes found reach {top:.0f} Hz; the band above, "
                                  "up to 16000 Hz, was not searched (raise stability.modes)",)


def test_a_pressure_beyond_small_strains_is_warned_about_also_at_a_map_point(tmp_path):
    """A squeal run warns of a contact pressure above workflows.strain.STRAINED (2 %) of the softer
    side's E, as the transient runs do: at 10 bar nothing, at a pressure sweep's 1000 bar point
    (its own preload) the warning. Before, a squeal run had none: the coarse demo at 5000 bar
    carried 1.2 GPa on its 5 GPa pads silently. Penalty contact without gaps scales with the
    load, so the map's peak is 100 times the nominal one."""
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "30 mm", "stability.modes": 6, "stability.band": ["0 Hz", "3 kHz"],
                 "stability.sweep.pressure": ["10 bar", "1000 bar"], "stability.sweep.onsets": False,
                 "output.folder": str(tmp_path / "out")}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False)
    nominal = run.case.facet_pressure.max()
    assert nominal < 0.02 * 5e9 < run.map.max_pressure
    assert run.map.max_pressure == pytest.approx(100 * nominal, rel=1e-6)
    written = {p.name for p in (tmp_path / "out").iterdir()}       # onsets = false: no header-only onsets.csv
    assert "map.csv" in written and "onsets.csv" not in written  # (read as "no track turns unstable")
    strained = [w for w in run.warnings if w.startswith("the contact pressure reached")]
    assert strained == [f"the contact pressure reached {run.map.max_pressure:.3g} Pa, "
                        f"{100 * run.map.max_pressure / 5e9:.2g} % of the softer side's E (5e+09 Pa): beyond the small "
                        "strains of the linear elastic model; check the load (a vehicle stop asks mu F r of the brake: "
                        "a small mu needs a large clamp) and E's unit (a bare number is Pa: 310000 for 310 GPa is "
                        "310 kPa)"]


def test_a_braking_torque_preloads_the_squeal_analysis_at_that_friction_moment(tmp_path):
    """loading.braking_torque (or vehicle.mass) instead of a pressure: the preload's first guess
    (each pad at its mean radius) is scaled until the friction moment is the torque
    (``preload.hold_moment``; before, the squeal analysis took the guess: 260.5 N m for 243.3).
    Penalty contact without gaps is linear in the load: 1.5 times the 10 bar moment is 15 bar."""
    from multiscale.macro.preload import TORQUE_TOL
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "30 mm", "stability.modes": 6, "stability.band": ["0 Hz", "3 kHz"],
                 "output.folder": str(tmp_path / "p")}
    nominal = squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False).case
    torque = 1.5 * abs(nominal.mech.contact.friction_moment())
    text = DEMO.read_text().replace('pressure = "10 bar"', f'braking_torque = "{torque} N m"')
    case = squeal.run(scenes.loads(text, DEMO.parent, overrides=dict(overrides, **{"output.folder": str(
        tmp_path / "t")})), degree=1, verbose=False).case
    assert abs(case.mech.contact.friction_moment()) == pytest.approx(torque, rel=TORQUE_TOL)
    assert case.preload.pressure == pytest.approx(1.5e6, rel=TORQUE_TOL)
    assert sum(case.preload.load_force.values()) == pytest.approx(1.5 * sum(nominal.preload.load_force.values()),
                                                                  rel=TORQUE_TOL)
    # with mu(v) (a Stribeck law) the first guess divides by the law's kinetic mu (it took the
    # placeholder mu = 0: "braking needs friction")
    stribeck = text.replace("friction = 0.4\n", "") + ('\n[loading.stribeck]\nstatic = 0.5\nkinetic = 0.35\n'
                                                        'speed = "1 m/s"\n')
    case = squeal.run(scenes.loads(stribeck, DEMO.parent, overrides=dict(overrides, **{"output.folder": str(
        tmp_path / "s")})), degree=1, verbose=False).case
    assert case.terms == ("friction slope",)
    assert abs(case.mech.contact.friction_moment()) == pytest.approx(torque, rel=TORQUE_TOL)


def test_eigen_solver_errors_name_the_scene_keys(tmp_path):
    """A band below the first mode: the error names stability.band (it named the solver's f_max).
    The failed run's Mechanics is closed (one rank) and freed (before: it stayed alive with its MPI
    communicators, and a script going on after failed runs ran out of them). The preloaded state
    was written before the eigen solve and stays (a user trial's failed or stopped eigen solve had
    thrown away a preload of minutes)."""
    import gc      # local: this test alone looks at the collector
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "30 mm", "stability.modes": 6, "output.folder": str(tmp_path / "out"),
                 "stability.band": ["10 Hz", "500 Hz"]}

    def models():
        gc.collect()
        return sum(isinstance(o, Mechanics) for o in gc.get_objects())
    before = models()
    scene = scenes.load(DEMO, overrides)
    with pytest.raises(InputError, match=r"^stability\.band = \['10 Hz', '500 Hz'\]: no eigenvalue in this frequency band"):
        squeal.run(scene, degree=1, verbose=False)
    assert models() == before
    written = {p.name for p in (tmp_path / "out").iterdir()}
    fields = {n for f in plan(scene).field_files for n in (f, f.replace(".xdmf", ".h5"))}
    assert fields <= written and "modes.csv" not in written and "provenance.json" in written


def test_the_quadratic_solver_is_not_asked_for_what_it_cannot_reach():
    """method = "quadratic" converges from 0 Hz up (real arithmetic): with a target it returned the
    lowest modes, the target unsaid (a user trial), so the scene refuses it; with a band above 0 Hz
    check warns (the solve refuses a band its modes do not cover, test_stability)."""
    base = {"stability.method": "quadratic", "stability.gyroscopic": True}
    with pytest.raises(SceneError, match=r'stability.target = 3500 Hz: method = "quadratic" cannot shift to a '
                                         r'frequency in real arithmetic .* use method = "auto"'):
        scenes.load(DEMO, {**base, "stability.target": "3.5 kHz"})
    scene = scenes.load(DEMO, {**base, "stability.band": ["2 kHz", "6 kHz"]})
    assert [w for w in scene.warnings if "quadratic" in w] == [
        'stability.method = "quadratic" with a band from 2000 Hz: it finds the lowest modes first, stability.modes '
        'of them from 0 Hz, and refuses a band they do not cover; method = "auto" projects on the band']
    assert not [w for w in scenes.load(DEMO, {**base, "stability.band": ["0 Hz", "6 kHz"]}).warnings if "quadratic" in w]


def test_a_band_cut_short_below_a_target_is_said(tmp_path, capsys):
    """stability.target mid-band: the 6 modes nearest 8 kHz span 7.4-8.2 kHz and the band from 0 Hz
    below them was not searched (before: only 'the band above ... was not searched'; with the
    target at 15.5 kHz, 'above' though the search reached 17.9 kHz, and not a word on the 0-12.8 kHz
    left out; found by an adversarial test)."""
    overrides = {**NO_FIGURES,
                 "geometry.mesh_size": "30 mm", "stability.modes": 6, "output.folder": str(tmp_path / "out"),
                 "stability.target": "8 kHz"}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1)
    f = run.case.modes.frequency
    (band,) = [w for w in run.warnings if w.startswith("stability.")]      # (the mesh's notes besides)
    assert f.min() > 5e3
    # the console says which solver gave the modes (a user trial could not tell)
    out = capsys.readouterr().out
    assert "\n  modes by the generalized eigenproblem K phi = theta M phi (exact)\n" in out
    # and the preload's braking torque (in no file and unsaid: a user trial), here against the sum of
    # mu p A r over the facets of interface.h5 (centroid radii)
    import h5py
    with h5py.File(tmp_path / "out" / "interface.h5") as h5:
        x, cells = h5["mesh/geometry"][()], h5["mesh/topology"][()]
        p, mu = (h5[f"data/0/{k}"][()].ravel() for k in ("contact_pressure", "friction_coefficient"))
    motion = run.case.mech.tm.spec.motion
    axis, tri = np.asarray(motion.axis) / np.linalg.norm(motion.axis), x[cells]
    arm = tri.mean(axis=1) - np.asarray(motion.centre)
    radius = np.linalg.norm(arm - np.outer(arm @ axis, axis), axis=1)
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    assert float(re.search(r"; braking torque (\S+) N m\n", out).group(1)) == pytest.approx(
        (mu * p * area * radius).sum(), rel=0.01)
    assert band.startswith(f"stability.modes = 6: the modes found span {f.min():.0f} to {f.max():.0f} Hz "
                           "around stability.target = 8000 Hz; the band below ")
    assert "from 0 Hz, and above" in band and band.endswith("move stability.target)")


def test_a_friction_curve_the_preload_misses_is_said(tmp_path, capsys):
    """A friction_curve from 2 m/s on pads sliding at 0.4-0.6 m/s (5 rad/s): mu is held at its first
    row on every facet, its slope (the friction damping) 0, and the run says so (it was silent, while
    a transient run warned: a user trial); the speeds are the preload's, omega r. Its summary gives
    the preload's mu and slip speeds (they were only in interface.xdmf: the trial)."""
    text = DEMO.read_text().replace("friction = 0.4\n", 'friction_curve = [["2 m/s", 0.5], ["5 m/s", 0.4]]\n')
    scene = scenes.loads(text, DEMO.parent, overrides={**NO_FIGURES, "geometry.mesh_size": "30 mm", "stability.modes": 6,
                                                      "loading.rotation_speed": "5 rad/s",
                                                      "output.folder": str(tmp_path / "out")})
    run = squeal.run(scene, degree=1)
    case = run.case
    V = case.slip_speed[case.facet_pressure > 0]
    assert (f"  friction: mu 0.5 on inner_pad, 0.5 on outer_pad (facet means) at slip speeds of {V.min():.3g} to "
            f"{V.max():.3g} m/s\n") in capsys.readouterr().out
    (line,) = [w for w in run.warnings if w.startswith("loading.friction_curve")]
    assert line == (f"loading.friction_curve: every slip speed in contact at the preload ({V.min():.4g} to {V.max():.4g} "
                    "m/s) is below its first row, 2 m/s: mu was held at 0.5 throughout, the curve's slope unused (a "
                    "curve over the run's slip speeds says what mu is)")
    assert 0.3 < V.min() < V.max() < 0.7 and case.terms == ()        # no slope: no friction damping term


def test_marginal_instabilities_of_an_undamped_structure_are_said(tmp_path):
    """The demo brake with gyroscopic terms at 5 rad/s: most of its unstable modes grow at damping
    ratios of -1e-5 to -1e-4 that any damping removes (10 of 24 at 25 mm, said nowhere: an NVH user
    trial; here, linear elements at 30 mm, all 9 of 24). The run says which."""
    overrides = {**NO_FIGURES, "geometry.mesh_size": "30 mm", "stability.modes": 24, "stability.band": ["0 Hz", "6 kHz"],
                 "stability.gyroscopic": True, "output.folder": str(tmp_path / "out")}
    run = squeal.run(scenes.load(DEMO, overrides), degree=1, verbose=False)
    zeta, bad = run.case.modes.damping_ratio, run.case.report.unstable
    weak = bad[zeta[bad - 1] > -1e-4]
    assert weak.size >= 3
    (said,) = [w for w in run.warnings if "which a loss factor of 0.0002 would damp" in w]
    assert said.startswith(f"all {bad.size} unstable modes grow at damping ratios above -0.0001 (") \
        if weak.size == bad.size else said.startswith(f"{weak.size} of the {bad.size} unstable modes grow")
    f = run.case.modes.frequency
    assert all(f"{f[j - 1]:.0f} Hz" in said for j in weak[:6])
    damped = squeal.run(scenes.load(DEMO, {**overrides, "stability.damping": 0.002}), degree=1, verbose=False,
                        overwrite=True)
    assert not [w for w in damped.warnings if "would damp" in w]          # a damped structure: its own to weigh

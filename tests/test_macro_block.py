"""Block pressed on a flat through the penalty interface (thesis §1.4, §7.3.1): exact checks."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from multiscale.errors import ConvergenceError, InputError  # noqa: E402
from multiscale.geometry import builder  # noqa: E402
from multiscale.macro import mesh  # noqa: E402
from multiscale.macro.kept_cells import jacobian  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.scene import Material  # noqa: E402

MATERIALS = {"block": Material(E=4e9, nu=0.15, alpha=1e-5), "flat": Material(E=210e9, nu=0.3, alpha=1.2e-5)}
K_N = 1e13          # Pa/m


@pytest.fixture(scope="module")
def tm():
    return mesh.build(builder("block_on_flat"), {"mesh_size": 2.5e-3})


def test_uniform_load_gives_uniform_pressure_and_penalty_gap(tm):
    p0 = 1e6
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_a_")
    r = m.ramp(p0, 2)
    assert r.converged and r.iterations <= 3
    p = m.contact.facet_pressure()
    assert np.abs(p / p0 - 1).max() < 1e-6                         # load / area
    assert r.normal_force == pytest.approx(p0 * 10e-3 * 10e-3, rel=1e-6)
    assert np.abs(m.contact.facet_gap() / (-p0 / K_N) - 1).max() < 1e-6   # g = -p / K_n


def test_a_solve_that_reaches_its_round_off_floor_stops_there(tm):
    """A block 1e6 x stiffer than before (E = 4e15 Pa): its round-off floor eps ||diag(K) x||
    is 0 at the start and ~1e-9 N at the answer; the residual stalled there from iteration 5
    to the cap of 30 before the solve was accepted. The floor is now that of the current iterate."""
    stiff = dict(MATERIALS, block=Material(E=4e15, nu=0.15, alpha=1e-5))
    p0 = 1e6
    m = Mechanics(tm, stiff, stiffness=K_N, load_kind="pressure", prefix="block_r_")
    r = m.solve(p0)
    assert r.converged and r.iterations <= 6, r.residuals
    assert r.residuals[-1] <= m._roundoff()
    assert np.abs(m.contact.facet_pressure() / p0 - 1).max() < 1e-6
    assert np.abs(m.contact.facet_gap() / (-p0 / K_N) - 1).max() < 1e-6


def test_a_newton_failure_at_absurd_friction_names_the_friction(tm, petsc_options):
    """A Newton that fails (here held to 2 iterations) at mu = 100 says why a sliding equilibrium
    may not exist (a squeal run at mu = 5 failed after 30 iterations with no word of it: a user
    trial; alone, this block's Newton fails at mu = 100 too, but not after others' solves)."""
    petsc_options(block_mu_snes_max_it=2)
    m = Mechanics(tm, MATERIALS, stiffness=K_N, friction=100.0, speed=1.0, load_kind="pressure", prefix="block_mu_")
    with pytest.raises(ConvergenceError, match=r"the friction coefficient reaches 100, far above a dry sliding "
                                               r"pair's .* a sliding equilibrium may not exist"):
        m.ramp(1e6, 2)


def test_per_facet_stiffness_field_roundtrip_and_effect(tm):
    iface = tm.interface
    assert iface.n_facets == len(iface.areas) and iface.areas.sum() == pytest.approx(1e-4, rel=1e-12)
    k = K_N * (1 + iface.midpoints[:, 0] / 10e-3)                    # stiffer towards +x
    m = Mechanics(tm, MATERIALS, stiffness=k, load_kind="force", prefix="block_b_")
    np.testing.assert_array_equal(iface.values(m.contact.stiffness), k)
    r = m.solve(100.0)
    assert r.normal_force == pytest.approx(100.0, rel=1e-9)
    # the load is still uniform (exact uniform stress) but the gap follows 1/K_n per facet
    gap = m.contact.facet_gap()
    assert np.corrcoef(gap, -1 / k)[0, 1] > 0.99


def test_friction_resultant_is_mu_times_normal_force(tm):
    m = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="force", prefix="block_c_")
    m.ramp(100.0, 2)
    f = m.contact.force()
    np.testing.assert_allclose(f, [0.3 * 100.0, 0.0, 100.0], rtol=0, atol=1e-8)


def test_reused_factorisations_give_the_fresh_newton_answer(tm, petsc_options):
    """LU factors kept across Newton iterations and solves (the default) as GMRES preconditioner,
    with inexact Newton, in single precision (the default): the same displacements as a fresh
    factorisation in double precision every iteration, to the Newton tolerance (1e-9 of the
    largest displacement), over a friction load sequence, with fewer factorisations."""
    kept = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="pressure", prefix="block_k_")
    petsc_options(block_l_factor_pc_precision="double")
    fresh = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="pressure", prefix="block_l_",
                      refresh=0)
    assert (kept.factors.precision, fresh.factors.precision) == ("single", "double")
    newton = 0
    for p in (0.5e6, 1e6, 2e6, 1.5e6):
        a, b = kept.solve(p), fresh.solve(p)
        assert a.converged and b.converged
        newton += b.iterations
        for u, v in zip(kept.u, fresh.u):
            scale = np.abs(v.x.array).max()
            np.testing.assert_allclose(u.x.array, v.x.array, rtol=0, atol=1e-9 * scale)
    assert fresh.factorisations == newton and kept.factorisations < newton


def test_a_solve_that_fails_with_old_factors_is_repeated_with_fresh_ones(tm):
    """A Newton solve that went astray (NaN state, not converged) is restarted from the state
    before it with a fresh factorisation every iteration, in double precision from then on: the
    answer of an undisturbed solve."""
    from multiscale.macro.mechanics import SolveResult
    reference = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_m_")
    reference.solve(1e6)
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_n_")
    real, calls = m._newton, []

    def astray():
        calls.append(1)
        if len(calls) == 1:
            for u in m.u:
                u.x.array[:] = np.nan
            return SolveResult(False, -3, 1, [1.0])
        return real()
    m._newton = astray
    assert m.factors.precision == "single"
    assert m.solve(1e6).converged and len(calls) == 2 and m.factors.precision == "double"
    for u, v in zip(m.u, reference.u):
        np.testing.assert_allclose(u.x.array, v.x.array, rtol=0, atol=1e-9 * np.abs(v.x.array).max())


def test_pulling_the_block_off_raises_convergence_error(tm):
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_d_")
    with pytest.raises(ConvergenceError, match="did not converge"):
        m.solve(-1e6)


def test_a_failed_factorisation_is_named_in_the_error(tm, petsc_options):
    """MUMPS refusing the factors (here its working memory capped at 1 MB: INFOG(1) = -19) ends the
    solve with a ConvergenceError that names MUMPS' status, not only the SNES reason. The user's
    precision option fixes double factors (single ones of this small mesh fit in 1 MB)."""
    petsc_options(block_f_factor_mat_mumps_icntl_23=1, block_f_factor_pc_precision="double")
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_f_")
    assert m.factors.precision == "double"
    with pytest.raises(ConvergenceError, match=r"MUMPS INFOG\(1\) = -19 \(more memory than ICNTL\(23\) allows\)") as info:
        m.solve(1e6)
    # memory, not rigid motions (the run advised supports: a user trial)
    assert "the factors did not fit in memory: a coarser mesh (geometry.mesh_size)" in str(info.value)
    assert "rigid body" not in str(info.value)


def test_a_mechanics_problem_leaves_no_solver_options_to_the_next(tm):
    """Our Newton options are removed from PETSc's database once the solver has them (DOLFINx 0.11
    leaves them there: all 15 were left before). As the user's options win, a later problem with
    the prefix would take them for the user's: a line search "chosen" is kept on a failed solve,
    and the second problem here would not retry with backtracking. It tries as the first would:
    as it was, fresh double factors, backtracking (the line search restored after)."""
    from petsc4py import PETSc

    from multiscale.macro.mechanics import NEWTON_OPTIONS, SolveResult
    ours = {"block_o_" + k for k in NEWTON_OPTIONS}
    Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_o_")
    assert not ours & set(PETSc.Options().getAll())
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_o_")
    assert not ours & set(PETSc.Options().getAll())
    real, tries = m._newton, []

    def said_to_fail():                     # every solve runs, and reports a failure
        tries.append(m.problem.solver.getLineSearch().getType())
        real()
        return SolveResult(False, -9, 10, [5.0, 7.0]) if len(tries) == 1 else SolveResult(False, -3, 0, [8.36])
    m._newton = said_to_fail
    with pytest.raises(ConvergenceError, match=r"did not converge .*SNES reason -3, 0 iterations, residuals \['8.36'\]; "
                                               r"the first of its attempts: SNES reason -9, 10 iterations, residuals "
                                               r"\['5', '7'\]"):   # (the last alone told little: a user trial)
        m.solve(1e6)
    assert tries == ["basic", "basic", "bt"] and m.problem.solver.getLineSearch().getType() == "basic"


def test_the_users_newton_options_win(tm, petsc_options):
    """Options the user set under the prefix (PETSC_OPTIONS="-mech_...", here block_u_) are the
    solver's, not ours (DOLFINx overwrote them before): 5 Newton iterations at most, GMRES instead
    of FGMRES, an absolute tolerance of 1e-3 N instead of 1e-10 N as the floors' base (the solve
    stops after 1 iteration at 2.7e-5 N; with ours 2 iterations, 2e-11 N), and the l2 line search,
    kept on a failed solve (tried as it was and with fresh factors, no backtracking, not restored
    to basic). The user's options stay in the database."""
    from petsc4py import PETSc

    from multiscale.macro.mechanics import SolveResult
    petsc_options(block_u_snes_max_it=5, block_u_ksp_type="gmres", block_u_snes_atol=1e-3,
                  block_u_snes_linesearch_type="l2")
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_u_")
    snes = m.problem.solver
    assert (snes.getTolerances()[3], snes.getKSP().getType(), snes.getLineSearch().getType()) == (5, "gmres", "l2")
    r = m.solve(1e6)
    assert r.iterations == 1 and 1e-9 < r.residuals[-1] < 1e-3 and snes.getTolerances()[1] == 1e-3
    real, tries = m._newton, []

    def said_to_fail():
        tries.append(snes.getLineSearch().getType())
        real()
        return SolveResult(False, -9, 1, [1.0])
    m._newton = said_to_fail
    with pytest.raises(ConvergenceError, match="did not converge"):
        m.solve(1.1e6)
    assert tries == ["l2", "l2"] and snes.getLineSearch().getType() == "l2"
    assert PETSc.Options().getInt("block_u_snes_max_it") == 5


@pytest.mark.parametrize("option", [{"block_v_ksp_type": "nonsense"}, {"block_v_snes_linesearch_type": "nonsense"},
                                    {"block_v_pc_type": "nonsense"}])
def test_a_solver_option_petsc_refuses_is_an_input_error(tm, petsc_options, option):
    """A value PETSc refuses among the user's options (PETSC_OPTIONS="-mech_ksp_type nonsense") is
    an InputError naming them (before: petsc4py's Error 86 with PETSc's traceback, from inside
    DOLFINx's set-up); the process goes on, and a problem built after, with good options, solves."""
    petsc_options(**option)
    [(name, value)] = option.items()
    with pytest.raises(InputError, match=rf"PETSC_OPTIONS = '-{name} {value}': PETSc refused .*error 86"):
        Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_v_")
    m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_w_")
    assert m.solve(1e6).converged


@pytest.mark.parametrize("option", [{"block_x_factor_pc_factor_mat_solver_type": "superlu"},
                                    {"block_x_pc_type": "lu", "block_x_pc_factor_mat_solver_type": "superlu"}])
def test_a_factorisation_package_petsc_lacks_is_an_input_error(tm, petsc_options, option):
    """A solver package this PETSc does not have (superlu; the wheel's has mumps, superlu_dist and
    PETSc's own), for the Newton's own factors (``-mech_factor_...``) or for a PC of the user's, is
    an InputError naming the option and the packages there are, before any solve (before: PETSc's
    error 92 with its traceback at the first solve)."""
    petsc_options(**option)
    with pytest.raises(InputError, match=r"PETSC_OPTIONS = '-block_x_\w*pc_factor_mat_solver_type superlu.*: "
                       r"this PETSc cannot factorise \(pc_type lu\) .*; it has .*mumps.*superlu_dist"):
        Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_x_")


def test_a_users_preconditioner_replaces_the_newtons_own(tm, petsc_options):
    """A user's ``-mech_pc_type`` is the Newton's preconditioner (read back from its PC) in place of
    its own kept factors (never set up): Jacobi solves the block to the same contact force, 1e-9
    (before: a segmentation fault attaching our PC context to the user's PC). ``none`` fails, and
    the error names the user's preconditioner."""
    default = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="force", prefix="block_y_")
    petsc_options(block_z_pc_type="jacobi", block_n_pc_type="none")
    m = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="force", prefix="block_z_")
    assert not m.own_pc and m.problem.solver.getKSP().getPC().getType() == "jacobi"
    np.testing.assert_allclose(m.solve(100.0).normal_force, default.solve(100.0).normal_force, rtol=1e-9)
    assert m.factors.analyses == 0 and default.factors.analyses > 0
    none = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="force", prefix="block_n_")
    with pytest.raises(ConvergenceError, match=r"preconditioned by the user's PC \(PETSC_OPTIONS = '-block_n_pc_type "
                       r"none'\) instead of the contact Newton's own factorisation \(leave pc_type unset for it\)"):
        none.solve(100.0)


def test_pc_options_beside_the_newtons_own_preconditioner_are_said_to_have_no_effect(tm, petsc_options):
    """``-mech_pc_...`` options without ``-mech_pc_type`` reach no PC (the Newton's own factors take
    ``-mech_factor_...``): a SolverOptionWarning says so, and the model's notes (the run's
    warnings). Before: silent, only PETSc's "Option left" at exit."""
    from multiscale.macro.kept_cells import SolverOptionWarning
    petsc_options(block_o_pc_factor_mat_solver_type="superlu_dist")
    with pytest.warns(SolverOptionWarning, match="-block_o_pc_factor_mat_solver_type had no effect: the contact "
                      "Newton's preconditioner is its own kept factorisation, whose options are under -block_o_factor_"):
        m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="block_o_")
    assert m.own_pc and len(m.notes) == 1


def test_missing_material_and_unknown_builder_are_input_errors(tm):
    with pytest.raises(InputError, match="materials.flat"):
        Mechanics(tm, {"block": MATERIALS["block"]}, prefix="block_e_")
    with pytest.raises(InputError, match="geometry.builder"):
        builder("teapot")
    with pytest.raises(InputError, match="geometry.height"):
        builder("block_on_flat").describe({"height": -1.0})


def test_the_tangent_of_kept_cell_and_fresh_facet_parts_is_the_full_assembly(tm):
    """The Newton tangent is composed of its cell part (assembled once) and its facet part (every
    iteration): at a sliding, loaded state it equals a direct assembly of the whole block
    Jacobian (compiled here: the model compiles the parts only) to round-off (1e-12 of its largest
    entry)."""
    from dolfinx import fem
    from dolfinx.fem import petsc as fpetsc
    from petsc4py import PETSc
    m = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="pressure", prefix="block_t_")
    m.solve(1e6)
    assert abs(m.contact.normal_force()) > 0
    direct = fpetsc.assemble_matrix(fem.form(jacobian(m.residuals, m.u), entity_maps=tm.entity_maps), bcs=m.bcs)
    direct.assemble()
    difference = m.tangent().copy()
    difference.axpy(-1.0, direct)
    scale = direct.norm(PETSc.NormType.NORM_INFINITY)
    assert difference.norm(PETSc.NormType.NORM_INFINITY) <= 1e-12 * scale


def test_the_residual_of_kept_cell_matrix_and_fresh_facet_part_is_the_full_assembly(tm):
    """The Newton residual is K_cell u + offset (the thermal expansion, once per solve) + its facet
    part: with a non-uniform temperature, at a perturbed state off equilibrium, it equals DOLFINx's
    assembly of the whole residual (with lifting) to round-off (1e-12 of its norm)."""
    from dolfinx import fem
    from dolfinx.fem import petsc as fpetsc
    temperatures = []
    for body in tm.bodies:
        T = fem.Function(fem.functionspace(body.mesh, ("Lagrange", 1)))
        T.interpolate(lambda x: 293.15 + 40.0 + 2e4 * x[0] - 1e4 * x[2])      # K, up to ~100 K of gradient
        temperatures.append(T)
    m = Mechanics(tm, MATERIALS, stiffness=K_N, friction=0.3, speed=0.5, load_kind="pressure", prefix="block_r_",
                  temperatures=temperatures)
    m.solve(1e6)
    blocks = m.problem.b.getAttr("_blocks")
    x = m.problem.x.copy()
    x.setAttr("_blocks", blocks)
    rng = np.random.default_rng(1)
    x.setArray(x.getArray() * (1.0 + 0.01 * rng.standard_normal(x.getLocalSize())))   # supports stay 0
    ours, reference = m.problem.b.duplicate(), m.problem.b.duplicate()
    m.problem.solver.computeFunction(x, ours)
    F, J = (fem.form(f, entity_maps=tm.entity_maps) for f in (m.residuals, jacobian(m.residuals, m.u)))
    fpetsc.assemble_residual(m.problem.solver, x, reference, m.u, F, J, m.bcs, blocks)
    assert reference.norm() > abs(m.contact.normal_force())   # N; off equilibrium (measured 1546 vs 135 N)
    ours.axpy(-1.0, reference)
    assert ours.norm() <= 1e-12 * reference.norm()               # measured 1.7e-14


def test_a_force_load_compiles_the_same_forms_on_another_mesh():
    """A force's traction is the force over the load faces' area, a number of the mesh: as a
    literal in the form each mesh compiled its forms anew (7 of the coarse pin-on-disc's 45 at
    another interface mesh size, about 0.5 s each on a cold cache). Blocks of 10 and 12 mm (load
    face 1e-4 and 1.44e-4 m^2) give the same residual forms (UFL signatures)."""
    def signatures(size):
        m = Mechanics(mesh.build(builder("block_on_flat"), {"length": size, "width": size, "mesh_size": 2.5e-3}),
                      MATERIALS, stiffness=K_N, load_kind="force", prefix="block_sig_")
        out = [F.signature() for F in m.residuals]
        m.close()
        return out
    assert signatures(10e-3) == signatures(12e-3)


def test_a_derivative_block_that_expands_to_zero_is_none(tm):
    """``nonzero``: a Jacobian block is None where it is zero once its derivatives are expanded
    (the cell part of an off-diagonal block: compiled, an empty form of no kernel that still cost a
    compilation for every new scene); ``integrals`` splits a block into its cell and other
    integrals."""
    import ufl
    from dolfinx import fem

    from multiscale.macro.kept_cells import integrals, nonzero
    V = fem.functionspace(tm.parent, ("Lagrange", 1))
    u, w, v = fem.Function(V), fem.Function(V), ufl.TestFunction(V)
    F = u * u * v * ufl.dx + w * v * ufl.ds
    by_u, by_w = ufl.derivative(F, u), ufl.derivative(F, w)
    assert nonzero(integrals(by_u, True)) is not None and nonzero(integrals(by_u, False)) is None
    assert nonzero(integrals(by_w, True)) is None and nonzero(integrals(by_w, False)) is not None
    assert [i.integral_type() for i in integrals(by_w, False).integrals()] == ["exterior_facet"]
    assert integrals(by_w, True) is not None and nonzero(None) is None      # not expanded: a zero form


def check_face_vector_areas(comm, names=("piston_back", "piston_wall", "disc_mount")) -> None:
    """The disc brake's (20 mm) faces: ``face_vector_areas`` summed over the ranks of ``comm`` are
    DOLFINx's integrals of 1 and of n over ``ds(tag)``, to 1e-12 of the area: a flat face
    (piston_back), a cylinder's wall whose normals nearly cancel (piston_wall), a mount. The
    interface facets' areas (global order) are the integrals of 1 over each."""
    import ufl
    from dolfinx import fem
    from mpi4py import MPI
    tm = mesh.build(builder("disc_brake"), {"mesh_size": 0.02}, comm=comm)
    per_facet = mesh.FormCache(tm).facet_integrals(None, lambda: ufl.as_ufl(1.0))
    np.testing.assert_allclose(tm.interface.areas, per_facet, rtol=1e-12)
    n, e = ufl.FacetNormal(tm.parent), fem.Constant(tm.parent, np.zeros(3))
    for name in names:
        ds = tm.ds(tm.face(name))
        vector = tm.face_vector_areas(name)
        area = comm.allreduce(np.linalg.norm(vector, axis=1).sum(), op=MPI.SUM)
        resultant = comm.allreduce(vector.sum(axis=0), op=MPI.SUM)
        assert area > 0 and area == pytest.approx(tm.assemble_scalar(1.0 * ds), rel=1e-12), name
        along = fem.form(ufl.dot(n, e) * ds)
        for i in range(3):
            e.value[:] = np.eye(3)[i]
            expected = comm.allreduce(fem.assemble_scalar(along), op=MPI.SUM)
            assert resultant[i] == pytest.approx(expected, abs=1e-12 * area), (name, i)
        flat = name != "piston_wall"                  # |resultant| / area: 1 on a plane, 0 round a cylinder
        assert np.linalg.norm(resultant) / area == pytest.approx(float(flat), abs=1e-9), name


def test_a_faces_vector_areas_are_the_integrals_of_its_normal():
    """``TwoBodyMesh.face_vector_areas`` sums the facets' areas and outward normals (exact on the
    linear tetrahedra) where a form per face and component was compiled before (~0.4 s each); the
    interface's facet areas likewise (a form per set of interface tags before)."""
    from mpi4py import MPI
    check_face_vector_areas(MPI.COMM_WORLD)


def test_interface_forms_do_not_depend_on_the_geometrys_interface_tag(tm):
    """A tag is a number of the compiled form: the interface measure's ids are the interfaces'
    positions (0, 1, ...), so the same mesh with its interface tagged 21 instead of 10 gives the
    same interface forms (UFL signatures), and the same integrals."""
    import dataclasses
    import ufl
    from dolfinx import fem
    from dolfinx import mesh as dmesh
    (name, tag), = tm.spec.interfaces.items()
    ft = tm.facet_tags
    values = np.where(ft.values == tag, 21, ft.values).astype(ft.values.dtype)
    other = mesh.from_mesh(dataclasses.replace(tm.spec, interfaces={name: 21}), tm.parent, tm.cell_tags,
                           dmesh.meshtags(tm.parent, ft.dim, ft.indices, values))

    def per_facet(t):
        x = ufl.SpatialCoordinate(t.parent)
        form = ufl.inner(x[0] ** 2, ufl.TestFunction(t.interface.space)("+")) * t.interface.dS
        return form.signature(), mesh.FormCache(t).facet_integrals(None, lambda: x[0] ** 2)
    (signature, values), (other_signature, other_values) = per_facet(tm), per_facet(other)
    assert other.interface.tags == {name: 21} and signature == other_signature
    np.testing.assert_allclose(other_values, values, rtol=1e-14)
    assert values.sum() > 0


def test_body_forms_do_not_depend_on_the_geometrys_region_tags(tm):
    """The bodies' volume measure has ids 0 and 1 (``body_dx``), not the region tags: the same mesh
    with its regions tagged 41, 42 instead of 1, 2 gives the same body forms (UFL signatures) and
    integrals; the region measure ``dx(tag)`` integrates the same body."""
    import dataclasses
    import ufl
    from dolfinx import fem
    from dolfinx import mesh as dmesh
    from mpi4py import MPI
    ct, shift = tm.cell_tags, 40
    bodies = tuple(dataclasses.replace(b, regions=tuple(dataclasses.replace(r, tag=r.tag + shift) for r in b.regions))
                   for b in tm.spec.bodies)
    other = mesh.from_mesh(dataclasses.replace(tm.spec, bodies=bodies), tm.parent,
                           dmesh.meshtags(tm.parent, ct.dim, ct.indices, ct.values + shift), tm.facet_tags)

    def body_integrals(t):
        x = ufl.SpatialCoordinate(t.parent)
        forms = [x[0] ** 2 * t.body_dx(i) for i in range(2)]
        return ([f.signature() for f in forms],
                [t.comm.allreduce(fem.assemble_scalar(fem.form(f)), op=MPI.SUM) for f in forms])
    (signatures, values), (other_signatures, other_values) = body_integrals(tm), body_integrals(other)
    assert signatures == other_signatures and min(values) > 0
    np.testing.assert_allclose(other_values, values, rtol=1e-14)
    x = ufl.SpatialCoordinate(tm.parent)
    by_region = sum(fem.assemble_scalar(fem.form(x[0] ** 2 * tm.dx(r.tag))) for r in tm.spec.bodies[1].regions)
    assert tm.comm.allreduce(by_region, op=MPI.SUM) == pytest.approx(values[1], rel=1e-12)


def test_wear_through_a_coating_is_named(tm):
    """A 3 um wear depth through a 2 um coating is named (a materials trial's wear rate took a 2 um
    coating 15.6 um deep: the layered kernel kept it), 1 um is not. (The body itself worn through
    ends the run: tests/test_thickness.py.)"""
    from types import SimpleNamespace
    from multiscale.workflows.multiscale import through_layers
    name = next(iter(tm.interface.masks()))

    def ms(depth):
        rough = SimpleNamespace(names=[name], zone_of=lambda n: np.arange(2), wear_depth=lambda: np.full((2, 4, 4), depth))
        return SimpleNamespace(rough=rough)
    assert through_layers(ms(1e-6), layers=2e-6) == () and through_layers(ms(6e-3)) == ()
    (line,) = through_layers(ms(3e-6), "materials.block.k_w", layers=2e-6)
    assert line.startswith(f"the wear on interface {name!r} reached 3 um deep, through its layers (2 um)")
    assert line.endswith("check the wear rate (materials.block.k_w)")

"""The bodies' thermo-elastic state without contact and load (``macro.unloaded``, what a released
step writes with thermal expansion): exact checks on the block on a flat.

The block is held along x on x = 0 and along y on y = 0 (symmetry planes), so without the contact
it is free along z alone; the flat is held along z on its bottom as well (nothing free). The tests
run on any number of ranks (tests/mpi/test_macro_mpi.py calls them on two)."""
import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

import ufl  # noqa: E402
from dolfinx import fem, mesh as dmesh  # noqa: E402
from dolfinx.fem.petsc import LinearProblem  # noqa: E402

from multiscale.geometry import builder  # noqa: E402
from multiscale.macro import mesh  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.macro.unloaded import Unloaded  # noqa: E402
from multiscale.scene import Material  # noqa: E402

MATERIALS = {"block": Material(E=4e9, nu=0.15, alpha=1e-5), "flat": Material(E=210e9, nu=0.3, alpha=1.2e-5)}
T_REF, HF, H = 293.15, 5e-3, 5e-3        # K; m, the flat's and the block's thickness (builder defaults)


@pytest.fixture(scope="module")
def tm():
    return mesh.build(builder("block_on_flat"), {"mesh_size": 2.5e-3})


def loaded(tm, temperature, prefix, degree=1):
    """Mechanics at the bodies' temperatures ``temperature[i](x)`` [K], solved at 1 MPa on the
    block's top (the last loaded state), and its von Mises stress per body as a callable."""
    T = [fem.Function(fem.functionspace(b.mesh, ("Lagrange", 1))) for b in tm.bodies]
    for f, g in zip(T, temperature):
        f.interpolate(lambda x, g=g: g(x) + 0.0 * x[0])
    m = Mechanics(tm, MATERIALS, temperatures=T, reference_temperature=T_REF, load_kind="pressure",
                  prefix=prefix, degree=degree)
    assert m.solve(1e6).converged
    return m


def von_mises(m, i) -> np.ndarray:
    """Von Mises stress [Pa] of body i of ``m`` per cell (DG0 interpolation, at the cell's midpoint)."""
    V = fem.functionspace(m.tm.bodies[i].mesh, ("DG", 0))
    s = fem.Function(V)
    s.interpolate(fem.Expression(m.von_mises(i), V.element.interpolation_points))
    return s.x.array


def mean_z(V, u) -> float:
    """Mean of the z components of displacements ``u`` (n, 3) over the nodes of V (all ranks)."""
    n = V.dofmap.index_map.size_local
    return V.mesh.comm.allreduce(u[:n, 2].sum()) / V.mesh.comm.allreduce(n)


def unloaded(m):
    """The unloaded state set into ``m.u``; the loaded displacements before it."""
    before = [u.x.array.copy() for u in m.u]
    state = Unloaded(m)
    out = state.solve()
    assert out is not None and state.passes <= 5
    for u, x in zip(m.u, before):       # the solve leaves the loaded state alone
        np.testing.assert_array_equal(u.x.array, x)
    for u, x in zip(m.u, out):
        u.x.array[:] = x
    return before, state


def test_a_uniform_rise_expands_the_bodies_freely(tm):
    """50 K everywhere: both bodies expand about their supports' planes without stress, u = alpha dT
    (x, y, z - z_0) to 1e-9 of alpha dT L; the block's free z translation (its only free motion) is
    the loaded state's mean (nodes' mean of u_z), the flat's z_0 its held bottom. Before (e0f52fe)
    the released fields were NaN."""
    m = loaded(tm, [lambda x: T_REF + 50.0] * 2, "unl_a_")
    before, state = unloaded(m)
    assert len(state.free_motions(None)) == 1
    for i, (V, u) in enumerate(zip(m.spaces, m.u)):
        x, u = V.tabulate_dof_coordinates(), u.x.array.reshape(-1, 3)
        e = MATERIALS[tm.bodies[i].name].alpha * 50.0
        scale = e * 10e-3
        np.testing.assert_allclose(u[:, :2], e * x[:, :2], rtol=0, atol=1e-9 * scale)
        if i == 0:
            shift = u[:, 2] - e * x[:, 2]
            assert np.ptp(shift) < 1e-9 * scale
            assert mean_z(V, u) == pytest.approx(mean_z(V, before[0].reshape(-1, 3)), rel=1e-9)
        else:
            np.testing.assert_allclose(u[:, 2], e * (x[:, 2] + HF), rtol=0, atol=1e-9 * scale)
        assert von_mises(m, i).max() < 1e-6 * MATERIALS[tm.bodies[i].name].E * e


def test_a_linear_temperature_bends_the_free_block_without_stress(tm):
    """T = T_ref + g z in the block (free along z: thermal bending) on quadratic elements: u_x =
    alpha g x z, u_y = alpha g y z exactly (to 1e-9 of alpha g H^2) and no stress (below 1e-6 of E
    alpha g H); the flat at T_ref stays at 0 (to round-off)."""
    g = 1e4                                   # K/m: 50 K over the block's height
    m = loaded(tm, [lambda x: T_REF + g * x[2], lambda x: T_REF + 0.0 * x[2]], "unl_b_", degree=2)
    unloaded(m)
    x, u = m.spaces[0].tabulate_dof_coordinates(), m.u[0].x.array.reshape(-1, 3)
    a = MATERIALS["block"].alpha
    for k in (0, 1):
        np.testing.assert_allclose(u[:, k], a * g * x[:, k] * x[:, 2], rtol=0, atol=1e-9 * a * g * H ** 2)
    assert von_mises(m, 0).max() < 1e-6 * MATERIALS["block"].E * a * g * H
    assert np.abs(m.u[1].x.array).max() < 1e-12 * a * g * H ** 2           # round-off of the block's solve
    assert von_mises(m, 1).max() < 1e-6 * MATERIALS["block"].E * a * g * H


def test_a_held_flat_is_stressed_as_the_linear_elasticity_solved_directly(tm):
    """The flat, held along z on its bottom (and its symmetry planes), heated by T_ref + g (z + HF)
    (its top 50 K): its bending is held, so it has stress (von Mises above 0.1 E alpha 50 K
    somewhere), and its displacement is that of the same linear thermo-elasticity written here
    with DOLFINx directly (LinearProblem, MUMPS LU) to 1e-8 of its largest value."""
    g = 1e4
    m = loaded(tm, [lambda x: T_REF + 0.0 * x[2], lambda x: T_REF + g * (x[2] + HF)], "unl_c_")
    unloaded(m)
    flat = tm.bodies[1].mesh
    mat = MATERIALS["flat"]
    V = fem.functionspace(flat, ("Lagrange", 1, (3,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    x = ufl.SpatialCoordinate(flat)
    lam, mu = mat.E * mat.nu / ((1 + mat.nu) * (1 - 2 * mat.nu)), mat.E / (2 * (1 + mat.nu))
    dT = g * (x[2] + HF)

    def sigma(w):
        eps = ufl.sym(ufl.grad(w))
        return lam * ufl.tr(eps) * ufl.Identity(3) + 2 * mu * eps

    a = ufl.inner(sigma(u), ufl.sym(ufl.grad(v))) * ufl.dx
    L = (3 * lam + 2 * mu) * mat.alpha * dT * ufl.div(v) * ufl.dx
    fdim = flat.topology.dim - 1
    bcs = []
    for k, where in ((0, lambda p: np.isclose(p[0], 0.0)), (1, lambda p: np.isclose(p[1], 0.0)),
                     (2, lambda p: np.isclose(p[2], -HF))):
        dofs = fem.locate_dofs_topological(V.sub(k), fdim, dmesh.locate_entities_boundary(flat, fdim, where))
        bcs.append(fem.dirichletbc(0.0, dofs, V.sub(k)))
    direct = LinearProblem(a, L, bcs=bcs, petsc_options_prefix="unl_direct_",
                           petsc_options={"ksp_type": "preonly", "pc_type": "lu",
                                          "pc_factor_mat_solver_type": "mumps"}).solve()
    ours = m.u[1].x.array
    np.testing.assert_allclose(ours, direct.x.array, rtol=0, atol=1e-8 * np.abs(direct.x.array).max())
    assert von_mises(m, 1).max() > 0.1 * mat.E * mat.alpha * 50.0

"""Squeal analysis on 2 ranks equals the serial one (preload forces, complex modes, MAC, energies,
the disc's nodal diameters)."""
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace as NS

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

from multiscale.geometry import builder  # noqa: E402
from multiscale.macro import mesh as two_body  # noqa: E402
from multiscale.macro import eigen, modal  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.macro.output import orientation, write_modes  # noqa: E402
from multiscale.mode_pairs import pair, read_modes  # noqa: E402
from multiscale.references.stability import spring_chain, spring_chain_frequencies  # noqa: E402
from multiscale.workflows.squeal import squeal_case  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_stability import dense_quadratic  # noqa: E402

STEEL = NS(E=210e9, nu=0.3, rho=7850.0)
MATERIALS = {"disc": NS(E=125e9, nu=0.25, rho=7200.0), "pad": NS(E=5e9, nu=0.25, rho=2500.0),
             "backplate": STEEL, "piston": STEEL, "caliper": STEEL}


def case(comm, prefix):
    tm = two_body.build(builder("disc_brake"), {"mesh_size": 0.02}, comm)
    mech = Mechanics(tm, MATERIALS, stiffness=1e13, friction=0.4, speed=5.0, load_kind="fluid", prefix=prefix)
    return squeal_case(mech, MATERIALS, "mpi", load=1e6, n_modes=20)


def test_two_ranks_reproduce_the_serial_squeal_analysis():
    comm = MPI.COMM_WORLD
    assert comm.size == 2
    par = case(comm, "squeal_mpi_par_")
    ser = None if comm.rank else case(MPI.COMM_SELF, "squeal_mpi_ser_")
    ref = comm.bcast(None if comm.rank else _summary(ser), root=0)
    got = _summary(par)
    np.testing.assert_allclose(got["eigenvalues"], ref["eigenvalues"], rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(got["forces"], ref["forces"], rtol=1e-10)
    np.testing.assert_allclose(got["energy"], ref["energy"], atol=1e-6)
    assert got["unstable"] == ref["unstable"]
    assert got["nodal_diameters"] == ref["nodal_diameters"]           # the disc's, over the ranks' nodes
    np.testing.assert_allclose(got["out_of_plane"], ref["out_of_plane"], atol=1e-6)
    # the written shapes' signs (``orientation``) are the partition's no more: a signed sum with another
    # weight agrees (the eigensolver's own signs differed in 6 of these 20 modes)
    np.testing.assert_allclose(got["signed"], ref["signed"], rtol=1e-5, atol=1e-9 * np.abs(ref["signed"]).max())
    np.testing.assert_allclose(np.diag(modal.mac_matrix(par.modes, par.modes)), 1.0, rtol=1e-12)
    # the mode files hold each cell once: VTX wrote the ghost cells too, unmarked (a user audit: 122 of
    # the brake's 5877 cells twice, a mass integral of a mode read from the files up to 1.053 for 1)
    adios2 = pytest.importorskip("adios2")
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.rank == 0 else None, root=0))
    files = write_modes(folder, par.modes, par.mech.u, ["brake", "disc"], modes=[2])
    cells = [V.mesh.topology.index_map(3).size_global for V in par.mech.spaces]
    peak = [comm.allreduce(float(np.abs(m).max(initial=0.0)), op=MPI.MAX) for m in np.split(
        par.modes.modes[:, 1], [par.mech.u[0].x.index_map.size_local * 3])]
    if comm.rank == 0:
        for path, count, top in zip(files, cells, peak):
            with adios2.Stream(str(path), "r") as stream:
                for _ in stream.steps():
                    blocks = range(len(stream.engine.blocks_info("connectivity", stream.current_step())))
                    conn = [stream.read("connectivity", block_id=b).ravel() for b in blocks]   # (n, n nodes) a cell
                    centres = np.concatenate([stream.read("geometry", block_id=b).reshape(-1, 3)[
                        c.reshape(-1, int(c[0]) + 1)[:, 1:5]].mean(axis=1) for b, c in zip(blocks, conn)])
                    real = np.concatenate([stream.read("mode shape real part [1/kg^0.5]", block_id=b) for b in blocks])
            assert len(blocks) == 2 and len(centres) == count
            assert len(np.unique(np.round(centres / 1e-9), axis=0)) == count, path.name
            assert np.abs(real).max() == pytest.approx(top, rel=1e-12)
    # `multiscale modes` reads a parallel run's files (each rank's block, its shared nodes once): its
    # modes pair with the serial run's one to one
    runs = [folder / "serial", folder / "parallel"]
    if comm.rank == 0:
        runs[0].mkdir(), runs[1].mkdir()
        write_modes(runs[0], ser.modes, ser.mech.u, ["brake", "disc"], modes=range(1, 9))
    write_modes(runs[1], par.modes, par.mech.u, ["brake", "disc"], modes=range(1, 9))
    if comm.rank == 0:
        for run, c in zip(runs, (ser, par)):
            rows = [f"{k + 1},{lam.imag / (2 * np.pi)},{lam.real}" for k, lam in enumerate(c.modes.eigenvalues)]
            (run / "modes.csv").write_text("\n".join(["mode,frequency_Hz,sigma_1_per_s", *rows]) + "\n")
        pairs = pair(read_modes(runs[0]), read_modes(runs[1]))
        assert list(pairs.best) == list(range(8)) and np.diag(pairs.mac).min() > 1 - 1e-9, np.diag(pairs.mac)
    comm.barrier()


def _summary(c):
    u, modes = c.mech.u, c.modes.modes
    sizes = [f.x.index_map.size_local * 3 for f in u]
    x = np.concatenate([np.repeat(f.function_space.tabulate_dof_coordinates()[:n // 3], 3, axis=0)
                        for f, n in zip(u, sizes)])
    weight = np.cos(x @ np.array([13.2, -32.4, 54.8]) + 0.7 * (np.arange(len(x)) % 3))
    signed = orientation(modes, u, sizes) * c.mech.tm.comm.allreduce(weight @ modes.real)
    return {"eigenvalues": c.modes.eigenvalues, "forces": list(c.preload.normal_force.values()),
            "energy": c.energy.share, "unstable": c.report.unstable.tolist(), "signed": signed,
            "nodal_diameters": c.disc.nodal_diameters.tolist(), "out_of_plane": c.disc.out_of_plane}


def test_the_quadratic_modes_with_a_rank_that_owns_no_row():
    """``eigen.solve_quadratic`` (SLEPc PEP, the default with viscous damping or gyroscopic terms)
    with every row on rank 0 and none on rank 1 (a rank that holds no cell of the mesh): SLEPc's
    eigenvector normalisation called LAPACK with a zero leading dimension there ("lascl: info=-9",
    PEPSolve failed on that rank alone). Now the eigenvalues of a damped 38-mass chain are those of
    its companion form (1e-7, as the serial test in tests/test_stability.py)."""
    comm = MPI.COMM_WORLD
    K, M = spring_chain(n=40, drift=0.05)
    K, M = K[1:-1, 1:-1], M[1:-1, 1:-1]
    C = 30.0 * M + 2e-7 * K
    n, rows = K.shape[0], K.shape[0] if comm.rank == 0 else 0

    def distributed(A):
        m = PETSc.Mat().createAIJ([(rows, n), (rows, n)], nnz=3, comm=comm)
        m.setUp()
        for i, j in zip(*np.nonzero(A)) if rows else ():
            m.setValue(i, j, A[i, j])
        m.assemble()
        return m

    f_max = 0.4 * spring_chain_frequencies(40).max()
    ref = dense_quadratic(K, C, M)
    ref = ref[ref.imag / (2 * np.pi) <= f_max]
    q = eigen.solve_quadratic(distributed(K), distributed(C), distributed(M), f_max=f_max,
                              n_modes=len(ref) + 4, target=1.0)
    np.testing.assert_allclose(q.eigenvalues, ref, rtol=1e-7)


@pytest.mark.parametrize("kind", ["hysteretic", "viscous"])
def test_damping_on_a_part_is_projected_alike_on_two_ranks(kind):
    """The projection with the static responses to the forces of a part's loss factor or dashpots
    (the serial tests in tests/test_squeal_damping.py) with the rows split over 2 ranks: the LU's
    transposed block solves for the left modes and the products C^T psi run distributed; the 8
    modes below 2 kHz are within 1e-6 (1e-7 viscous) of the dense solve, as in serial."""
    from multiscale.macro import damped     # local: only this test projects
    from test_squeal_damping import chain, companion_eigenvalues, segment_stiffness
    comm = MPI.COMM_WORLD
    K, M = chain(40)
    for i in range(0, 37, 3):
        K[i, i + 2] += 0.6e6
        K[i + 2, i] -= 0.3e6
    H = 0.05 * segment_stiffness(40, 4e6, 30, 39)
    C = segment_stiffness(40, 2.0, 30, 39)
    C[35, 35] -= 3.0
    n, rows = K.shape[0], (15, 25)[comm.rank]
    start = (0, 15)[comm.rank]

    def distributed(A):
        m = PETSc.Mat().createAIJ([(rows, n), (rows, n)], nnz=5, comm=comm)
        m.setUp()
        for i, j in zip(*np.nonzero(A[start:start + rows])):
            m.setValue(start + i, j, A[start + i, j])
        m.assemble()
        return m

    if kind == "hysteretic":
        system, ref = damped.LinearSystem(distributed(K), distributed(M), H=distributed(H)), \
            companion_eigenvalues(K + 1j * H, np.zeros_like(K), M)
    else:
        system, ref = damped.LinearSystem(distributed(K), distributed(M), distributed(C)), companion_eigenvalues(K, C, M)
    r = damped.solve_system(system, f_max=2e3, method="projection")
    ref = ref[ref.imag / (2 * np.pi) <= 2e3]
    assert len(r) == ref.size == 8
    np.testing.assert_allclose(r.eigenvalues, ref, rtol=1e-6 if kind == "hysteretic" else 1e-7)
    assert r.errors.max() < (5e-3 if kind == "hysteretic" else 1e-3)

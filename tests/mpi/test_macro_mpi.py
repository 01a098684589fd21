"""Two MPI ranks give the same pin-on-disc history as one, and the same heated disc brake's (two
interfaces: per-pad heat and face temperatures); run: mpiexec -n 2 python -m pytest tests/mpi."""
import json
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

import h5py  # noqa: E402
from mpi4py import MPI  # noqa: E402

from multiscale.io import solver_statistic  # noqa: E402
from multiscale.outputs import plan  # noqa: E402
from multiscale.workflows import run  # noqa: E402
from multiscale.scene import loads  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_macro_run import pin_on_disc  # noqa: E402
from test_duty_cycle import PADS, heated_brake  # noqa: E402
from test_macro_block import check_face_vector_areas  # noqa: E402


def scene(folder):
    return loads(pin_on_disc(folder, name="pod_mpi", partition="0.14"), overrides={"loading.ramp_steps": 2})


def histories(make, base: str):
    """The history columns of the scene ``make(folder)`` run on both ranks (in ``base``/parallel)
    and on rank 0 alone (``base``/serial), the latter broadcast: (parallel, serial)."""
    world = MPI.COMM_WORLD
    assert world.size == 2, "run under mpiexec -n 2"
    parallel = run(make(f"{base}/parallel"), comm=world, verbose=False).history
    serial = None
    if world.rank == 0:
        serial = run(make(f"{base}/serial"), comm=MPI.COMM_SELF, verbose=False).history
    serial = world.bcast(serial.columns if serial is not None else None, root=0)
    assert set(serial) == set(parallel.columns)
    return parallel, serial


def test_two_ranks_give_the_serial_history(tmp_path):
    world = MPI.COMM_WORLD
    base = world.bcast(str(tmp_path), root=0)
    parallel, serial = histories(scene, base)
    assert parallel["interface_force"] == pytest.approx(200.0, rel=1e-6)
    for key in (k for k in serial if not solver_statistic(k)):
        np.testing.assert_allclose(parallel[key], serial[key], rtol=1e-8, atol=1e-8, err_msg=key)
    # the field files: the same mesh (rank-independent order), values and times; exactly the plan
    if world.rank == 0:
        p = plan(scene(f"{base}/parallel"))
        assert sorted(f.name for f in Path(f"{base}/parallel").iterdir()) == sorted(p.files)
        for name in p.field_files:
            h5 = Path(name).with_suffix(".h5").name
            with h5py.File(f"{base}/parallel/{h5}", "r") as a, h5py.File(f"{base}/serial/{h5}", "r") as b:
                assert list(a["times"][...]) == list(b["times"][...]) == list(p.times)
                np.testing.assert_array_equal(a["mesh/geometry"][...], b["mesh/geometry"][...])
                for k in a["data"]:
                    for field in a[f"data/{k}"]:
                        # the two runs' Newton paths differ (timed refactorisation, MUMPS' round-off
                        # on 2 ranks): a small heat flux once differed by 1.4e-9 of the field's
                        # largest value (CI 2026-11-24), hence 1e-8 of it
                        x, y = a[f"data/{k}/{field}"][...], b[f"data/{k}/{field}"][...]
                        np.testing.assert_allclose(x, y, rtol=1e-7, atol=1e-8 * np.abs(y).max(), err_msg=field)
        assert json.loads(Path(f"{base}/parallel/provenance.json").read_text())["ranks"] == 2


def test_the_unloaded_state_on_two_ranks():
    """The exact checks of tests/test_unloaded.py with the block on a flat split over two ranks:
    the parts and the free motion are found across the ranks (the released state of a run with
    thermal expansion)."""
    import test_unloaded as t
    from multiscale.geometry import builder
    from multiscale.macro import mesh
    tm = mesh.build(builder("block_on_flat"), {"mesh_size": 2.5e-3}, comm=MPI.COMM_WORLD)
    assert tm.comm.size == 2 and all(b.mesh.topology.index_map(3).size_local > 0 for b in tm.bodies)
    t.test_a_uniform_rise_expands_the_bodies_freely(tm)
    t.test_a_linear_temperature_bends_the_free_block_without_stress(tm)
    t.test_a_held_flat_is_stressed_as_the_linear_elasticity_solved_directly(tm)


def test_the_parts_of_a_body_whose_cells_are_all_on_one_rank():
    """``unloaded.cell_parts`` on a mesh of which rank 1 holds no cell (the pin of the pin-on-disc
    demo on two ranks: its first released step, with expansion, stopped with a reshape error on
    that rank): the cells of two slabs of a cube that rank 0 owns get parts 0 .. count-1 there,
    both ranks the same count."""
    from dolfinx import mesh as dmesh
    from multiscale.macro.unloaded import cell_parts
    world = MPI.COMM_WORLD
    whole = dmesh.create_unit_cube(world, 5, 5, 5, ghost_mode=dmesh.GhostMode.shared_facet)
    owned = np.arange(whole.topology.index_map(3).size_local if world.rank == 0 else 0, dtype=np.int32)
    x = dmesh.compute_midpoints(whole, 3, owned)[:, 0]
    slabs = dmesh.create_submesh(whole, 3, owned[(x < 0.2) | (x > 0.8)])[0]
    cells = slabs.topology.index_map(3)
    assert cells.size_global > 0 and (cells.size_local + cells.num_ghosts == 0) == (world.rank == 1)
    label, count = cell_parts(slabs)
    assert label.size == cells.size_local + cells.num_ghosts and world.allgather(count) == [count] * 2
    assert count >= 1 and (world.rank == 1 or set(label) == set(range(count)))


def test_two_ranks_give_the_serial_per_pad_heat(tmp_path):
    """The heated disc brake's history on two ranks is the serial one (1e-8), and its per-pad
    columns (frictional heat, face temperatures: from global facet arrays) are the same on both
    ranks to the last bit."""
    world = MPI.COMM_WORLD
    parallel, serial = histories(heated_brake, world.bcast(str(tmp_path), root=0))
    pads = [k for k in serial if k.startswith(("frictional_heat_", "face_"))]
    # per pad: heat of the step and in all, max and mean temperature on each body's face
    assert len(pads) == len(PADS) * (2 + 2 * 2) and parallel["frictional_heat_total_inner_pad"][-1] > 100.0
    for key in (k for k in serial if not solver_statistic(k)):
        np.testing.assert_allclose(parallel[key], serial[key], rtol=1e-8, atol=1e-8, err_msg=key)
    on_rank_0 = world.bcast({k: parallel[k] for k in pads}, root=0)
    for key in pads:
        np.testing.assert_array_equal(parallel[key], on_rank_0[key], err_msg=key)


def test_a_faces_vector_areas_on_two_ranks():
    """Each owned facet counted once: the sums over both ranks are DOLFINx's integrals."""
    check_face_vector_areas(MPI.COMM_WORLD)


def test_interface_midpoints_do_not_depend_on_the_ranks(tmp_path):
    """Bit for bit on 1 and 2 ranks (55 of the coarse pin face's 162 differed in the last bit:
    DOLFINx sums a facet's vertices in the partition's order). Zones are assigned by them: on the
    thesis pin face a facet on a zone border went to the next zone on 2 ranks, and its zone's
    partition, wear and flash temperature with it (a rank-consistency audit)."""
    from multiscale.workflows.model import build_mesh
    s = scene(str(tmp_path))
    world = build_mesh(s, MPI.COMM_WORLD).interface
    alone = build_mesh(s, MPI.COMM_SELF).interface
    np.testing.assert_array_equal(world.midpoints, alone.midpoints)


def test_two_ranks_give_the_serial_facet_wear(tmp_path):
    """Wear in perfect contact (``macro.facet_wear``: global per-facet arrays, a re-solve after each
    update) and a wearing disc on two ranks: the serial history."""
    def wearing(folder):
        text = pin_on_disc(folder, name="wear_mpi", effects=("contact", "friction", "wear")).replace(
            "partition = ", "# partition = ") + '\n[wear]\nk_w = "3e-13 1/Pa"\n'
        return loads(text, overrides={"time.steps": 3, "time.end": "9 s", "materials.disc.k_w": "1e-14 1/Pa"})
    parallel, serial = histories(wearing, MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    assert serial["wear_implicit_updates"][-1] >= 2 and serial["counter_wear_volume"][-1] > 0
    for key in (k for k in serial if not solver_statistic(k)):
        np.testing.assert_allclose(parallel[key], serial[key], rtol=1e-8, atol=1e-15, err_msg=key)


def test_a_pin_worn_through_ends_the_run_on_both_ranks(tmp_path):
    """The thickness behind the facets (rays cut by each rank's share, ``macro.thickness``) and the
    decision to end (rank 0's, broadcast): the pin worn through at step 2 of 4 on two ranks as on one."""
    def through(folder):
        text = pin_on_disc(folder, name="through_mpi", effects=("contact", "friction", "wear")).replace(
            "partition = ", "# partition = ") + '\n[wear]\nk_w = "1e-8 1/Pa"\n'
        return loads(text, overrides={"time.steps": 4, "time.end": "12 s"})
    parallel, serial = histories(through, MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    assert list(parallel["time"]) == list(serial["time"]) == [0.0, 3.0, 6.0]
    # (11 mm worn in a step by implicit updates: the solvers' tolerances on 1 and 2 ranks reach 1.2e-8 of it)
    np.testing.assert_allclose(parallel["wear_remaining_min"], serial["wear_remaining_min"], rtol=1e-6)
    assert serial["wear_remaining_min"][0] == pytest.approx(15e-3, rel=1e-12) and serial["wear_remaining_min"][-1] < 0

"""Files written by several ranks (run by ``mpiexec -n 2 python -m pytest tests/mpi``; also passes
on one process): ``io.on_ranks`` spreads the jobs over the ranks, each run once, and a failure on
one rank is an OutputError on every rank, without deadlock."""
import errno
import os

import pytest
from mpi4py import MPI

from multiscale import io
from multiscale.errors import OutputError

comm = MPI.COMM_WORLD


def test_jobs_are_spread_over_the_ranks_and_each_runs_once():
    ran = []
    io.on_ranks(comm, [lambda k=k: ran.append(k) for k in range(5)], "five files")
    assert ran == list(range(comm.rank, 5, comm.size))
    assert sorted(k for done in comm.allgather(ran) for k in done) == list(range(5))


def test_a_failure_on_one_rank_is_an_output_error_on_every_rank():
    """Job 1 (rank 1 on two ranks, rank 0 alone) meets a full disk: every rank raises, with the
    system's reason (HDF5's long text cut to it)."""
    def full():
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    with pytest.raises(OutputError, match="cannot write the wear maps: No space left on device"):
        io.on_ranks(comm, [lambda: None, full, lambda: None], "the wear maps")
    comm.Barrier()                      # both ranks got here: no rank is left waiting

    def hdf5():                         # h5py's text of a full disk: its reason alone (it took two lines)
        raise OSError("Can't close file (file write failed: time = Sun Dec  6 14:19:02 2026\n, filename = "
                      "'checkpoint.h5', file descriptor = 5, errno = 28, error message = 'No space left on device', "
                      "buf = 0x5a1, total write size = 8)")
    with pytest.raises(OutputError, match=r"^cannot write the checkpoint: No space left on device$"):
        io.on_ranks(comm, [lambda: None, hdf5, lambda: None], "the checkpoint")


def test_a_field_mesh_refused_on_rank_0_is_refused_on_every_rank():
    """The field files' layout is ordered on rank 0 (``output.MeshLayout``): its refusal of a mesh
    with two nodes at one place reaches every rank (it once left rank 1 waiting in the next write)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    import basix.ufl
    import numpy as np
    import ufl
    from dolfinx import mesh

    from multiscale.errors import MultiscaleError
    from multiscale.macro.output import MeshLayout
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]] * 2) if comm.rank == 0 else np.zeros((0, 2))
    cells = np.array([[0, 1, 2], [3, 4, 5]], dtype=np.int64) if comm.rank == 0 else np.zeros((0, 3), dtype=np.int64)
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
    twice = mesh.create_mesh(comm, cells, domain, x)     # two triangles on top of each other, not sharing nodes
    with pytest.raises(MultiscaleError, match="distinct coordinates"):
        MeshLayout(twice)
    comm.Barrier()


def test_a_checkpoint_that_one_rank_cannot_match_is_refused_on_every_rank(tmp_path_factory):
    """``checkpoint.load`` of a checkpoint whose dofs the last rank's part of the mesh does not hold
    (its nodes moved there alone) raises on every rank: the test was each rank's, and the other
    waited for ever in the scatter that followed (a review, 2026-12-06)."""
    pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")
    import numpy as np
    from dolfinx import fem, mesh

    from multiscale import checkpoint
    from multiscale.errors import InputError
    path = comm.bcast(tmp_path_factory.mktemp("ckpt") / "checkpoint.h5" if comm.rank == 0 else None, root=0)
    square = mesh.create_unit_square(comm, 4, 4)
    f = fem.Function(fem.functionspace(square, ("Lagrange", 1)))
    f.x.array[:] = 1.0
    checkpoint.save(path, comm, attrs={"step": 1}, arrays={}, functions={"u": f})
    attrs, _ = checkpoint.load(path, comm, {"u": f})          # the same mesh: read back
    assert attrs["step"] == 1 and np.all(f.x.array == 1.0)
    if comm.rank == comm.size - 1:
        square.geometry.x[:, 0] += 0.5
    with pytest.raises(InputError, match="the mesh changed: field 'u' has dofs the checkpoint does not know"):
        checkpoint.load(path, comm, {"u": f})
    comm.Barrier()                      # both ranks got here: no rank is left waiting

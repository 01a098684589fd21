"""Two MPI ranks give the multiscale pin-on-disc history of one (mpiexec -n 2 python -m pytest tests/mpi):
zones, laws (pool) and post-analyses are spread over the ranks, the macro mesh is partitioned."""
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402

from multiscale.io import solver_statistic  # noqa: E402
from multiscale.workflows.multiscale import run  # noqa: E402
from multiscale.scene import loads  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_coupling import POD  # noqa: E402


def test_two_ranks_give_the_serial_multiscale_history(tmp_path):
    world = MPI.COMM_WORLD
    assert world.size == 2, "run under mpiexec -n 2"
    base = world.bcast(str(tmp_path), root=0)
    columns = {}
    for name, comm in (("parallel", world), ("serial", MPI.COMM_SELF if world.rank == 0 else None)):
        if comm is not None:                      # the serial run on rank 0 alone
            columns[name] = run(loads(POD.format(folder=f"{base}/{name}")), comm=comm, verbose=False).history.columns
    serial, parallel = world.bcast(columns.get("serial"), root=0), columns["parallel"]
    assert set(serial) == set(parallel)
    np.testing.assert_allclose(parallel["interface_force"], 200.0, rtol=1e-6)
    assert parallel["wear_volume"][-1] > 0 and parallel["zones_in_contact"][-1] >= 2
    for key in (k for k in serial if not solver_statistic(k)):
        # MUMPS' parallel factorisation differs from the serial one in the last bits (~4e-15); the
        # iterative micro solves and the coupling loop amplify that to 1.3e-6 relative (the coupling
        # residual and the heat exchanged, measured in CI; docs/architecture.md §7), far below the
        # loop's own tolerance (coupling_tol 1e-3): every column is held to 1e-5
        np.testing.assert_allclose(parallel[key], serial[key], rtol=1e-5, atol=1e-12, err_msg=key)

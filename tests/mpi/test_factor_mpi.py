"""The 2-rank MUMPS LU of the indefinite matrix of tests/test_mumps.py overflows its workspace at
the default margin and at twice it (INFOG(1) = -9, measured): ``macro.mumps.factorise`` retries
until it fits, on both ranks alike, also inside SLEPc's shift-and-invert (mpiexec -n 2 python -m pytest tests/mpi)."""
import sys
from pathlib import Path

import multiscale.macro  # noqa: F401,I001  (DOLFINx's prerequisites before petsc4py)
from mpi4py import MPI

from multiscale.macro import mumps

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_mumps import direct, indefinite, nearest_eigenvalues_against_dense, petsc, residual  # noqa: E402


def test_two_rank_lu_is_retried_until_the_workspace_fits():
    assert MPI.COMM_WORLD.size == 2, "run under mpiexec -n 2"
    A = petsc(indefinite())
    pc = direct(A, "lu")
    workspace, retries = mumps.factorise(pc)
    assert retries >= 2 and workspace == 20 * 2 ** retries
    assert MPI.COMM_WORLD.allgather((workspace, retries, mumps.status(pc))) == [(workspace, retries, 0)] * 2
    assert residual(A, pc) <= 1e-8


def test_two_rank_slepc_shift_invert_survives_the_workspace_error():
    nearest_eigenvalues_against_dense()

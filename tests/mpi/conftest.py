"""Under ``mpiexec -n 2 python -m pytest tests/mpi``: a test that fails on one rank ends the whole
job, with its report, instead of hanging it.

A failure on one rank alone leaves the other rank waiting in a collective of that test for ever
(CI at 8a694ab hung 38 minutes until killed). So a rank whose test fails prints the report and
calls ``MPI.COMM_WORLD.Abort``: the run stops at its first failure (as ``-x``), on one rank or
all. A test that hangs without failing (a deadlock) is ended by pyproject.toml's
``faulthandler_timeout``: the process dumps its threads' stacks and exits, and mpiexec ends the
other ranks. A test skipped or xfailed on some ranks only would still desynchronise them: skip
on every rank alike.
"""
import sys


def pytest_runtest_logreport(report):
    if not report.failed:
        return
    from mpi4py import MPI          # on use: after h5py (tests/conftest.py)
    from multiscale.io import abort
    world = MPI.COMM_WORLD
    if world.size == 1:
        return                      # one process: pytest reports as usual
    sys.stderr.write(f"\n[rank {world.rank}] FAILED {report.nodeid} ({report.when})\n"
                     f"{report.longreprtext}\n[rank {world.rank}] aborting the MPI job\n")
    abort(world, 1)                 # after a grace: an immediate Abort lost the report (1 in 12 runs)

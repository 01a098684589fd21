"""The user's solver options (PETSC_OPTIONS) on two ranks: a note on options without effect is said
once (run: mpiexec -n 2 python -m pytest tests/mpi)."""
import sys
import warnings
from pathlib import Path

import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402

from multiscale.macro.kept_cells import SolverOptionWarning  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_macro_block import K_N, MATERIALS  # noqa: E402


def test_pc_options_without_effect_are_said_once_on_two_ranks(petsc_options):
    """``-<prefix>pc_...`` beside the contact Newton's own factorisation: the SolverOptionWarning
    comes from rank 0 alone, as the heat's notes (``Thermal._say``), and every rank keeps the note
    for the run's warnings (before: the warning on every rank, twice under mpiexec -n 2)."""
    from multiscale.geometry import builder
    from multiscale.macro import mesh
    comm = MPI.COMM_WORLD
    assert comm.size == 2, "run under mpiexec -n 2"
    tm = mesh.build(builder("block_on_flat"), {"mesh_size": 5e-3})
    petsc_options(mpi_o_pc_factor_mat_solver_type="superlu_dist")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = Mechanics(tm, MATERIALS, stiffness=K_N, load_kind="pressure", prefix="mpi_o_")
    said = [str(c.message) for c in caught if c.category is SolverOptionWarning]
    notes = m.notes
    m.close()
    assert comm.allgather(said) == [notes, []] and comm.allgather(notes) == [notes] * 2
    assert len(notes) == 1 and "-mpi_o_pc_factor_mat_solver_type had no effect" in notes[0]


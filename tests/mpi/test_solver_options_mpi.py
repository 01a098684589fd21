"""The user's solver options (PETSC_OPTIONS) on two ranks: a note on options without effect is said
once, a factorisation package PETSc lacks is one InputError on every rank, without PETSc's
traceback (run: mpiexec -n 2 python -m pytest tests/mpi). A rank that met no error would leave
this process waiting: test_faults.py runs the same through ``multiscale run`` under a timeout."""
import sys
import warnings
from pathlib import Path

import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from mpi4py import MPI  # noqa: E402

from multiscale.errors import InputError  # noqa: E402
from multiscale.macro.kept_cells import SolverOptionWarning  # noqa: E402
from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.workflows.model import build_model  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_macro_block import K_N, MATERIALS  # noqa: E402
from test_macro_thermal import block_scene  # noqa: E402


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


def test_a_factorisation_package_petsc_lacks_is_an_input_error_on_both_ranks(petsc_options, capfd):
    """``PETSC_OPTIONS="-heat_pc_factor_mat_solver_type superlu"`` (a package this PETSc lacks,
    ``kept_cells.check_user_options``): building the model ends in the same InputError on both
    ranks, naming the packages there are on 2 ranks, with no PETSc error printed."""
    comm = MPI.COMM_WORLD
    assert comm.size == 2, "run under mpiexec -n 2"
    petsc_options(heat_pc_factor_mat_solver_type="superlu")
    boundary = '[[boundary]]\nsurfaces = ["free:block"]\nconvection = "20 W/(m^2 K)"\nambient = "300 K"'
    try:
        build_model(block_scene(boundary=boundary))
        message = None
    except InputError as exc:
        message = str(exc)
    assert comm.allgather(message) == [message] * 2 and message is not None
    assert message.startswith("PETSC_OPTIONS = '-heat_pc_factor_mat_solver_type superlu': this PETSc cannot "
                              "factorise (pc_type lu)") and "mumps" in message and message.endswith(" on 2 ranks")
    err = capfd.readouterr().err
    assert "PETSC ERROR" not in err and "Traceback" not in err, err[-2000:]

"""The user's PETSc options for the heat solver (PETSC_OPTIONS="-heat_..."): they win over ours,
leave nothing to the next problem, are refused as one InputError when PETSc cannot take them, and
are said to have no effect where they have none (a linear heat problem and Newton's options).

A module of its own: every model built stays alive with its MPI communicators (docs/architecture.md
§7), and test_macro_thermal.py with these tests in it ran out of MPICH's 2048 in one process.
"""
import json
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

from multiscale.errors import ConvergenceError

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from multiscale.macro import thermal  # noqa: E402
from multiscale.workflows import run  # noqa: E402
from multiscale.workflows.model import build_model  # noqa: E402
from multiscale.references.thermal import STEFAN_BOLTZMANN  # noqa: E402
from test_macro_thermal import AREA, HEAT_UP, VOLUME, block_scene, march  # noqa: E402


@pytest.mark.parametrize("search", ["basic", "bt"])
def test_the_users_line_search_for_the_heat_newton_wins(petsc_options, search):
    """A line search set under the heat prefix (PETSC_OPTIONS="-heat_snes_linesearch_type ...") is
    the one used: "basic" keeps full steps even on a failed step, and the 1000 s step above fails,
    saying to shorten it; "bt" converges at the first solve (single factors kept, nothing redone)."""
    petsc_options(heat_snes_linesearch_type=search)
    scene = block_scene(T0=300.0, end=1000.0, steps=1, boundary=HEAT_UP)
    if search == "basic":
        with pytest.raises(ConvergenceError, match=r"SNES reason -9.*with radiation a step of 1000 s can take "
                                                   r"Newton far off: more time.steps or substeps"):
            march(scene)
        return
    th = march(scene).thermal
    assert th.problem.solver.getLineSearch().getType() == "bt"
    assert (th.redone, th.backtracked, th.precision) == (0, 0, "single")
    # one backward-Euler step of the lumped block (Bi ~ 1e-3): rho c V (T - 300)/dt = sigma A (2000^4 - T^4)
    lumped = brentq(lambda T: 5e6 * VOLUME * (T - 300) / 1000 - STEFAN_BOLTZMANN * AREA * (2000**4 - T**4), 300, 2000)
    assert 300 + th.stored_heat()[0] / (5e6 * VOLUME) == pytest.approx(lumped, rel=1e-3)    # 1987.3 vs 1988.3 K


def test_a_heat_problem_leaves_no_solver_options_to_the_next():
    """Our solver options are removed from PETSc's database once the solver has them (DOLFINx 0.11
    leaves them there): as the user's options win, a later heat problem would take them for the
    user's; here a radiating block built after a linear one ran as a linear solve (ksponly)."""
    from petsc4py import PETSc
    ours = {"heat_" + k for k in {**thermal.NEWTON_OPTIONS, **thermal.KEPT_OPTIONS}}
    linear = march(block_scene(boundary='[[boundary]]\nsurfaces = ["free:block"]\nconvection = "20 W/(m^2 K)"'))
    assert not linear.thermal.nonlinear and not ours & set(PETSc.Options().getAll())
    th = march(block_scene(T0=800.0, end=1.0, steps=1, boundary=HEAT_UP.replace("2000 K", "300 K"))).thermal
    assert th.problem.solver.getType() == "newtonls" and not ours & set(PETSc.Options().getAll())


COOLED = '[[boundary]]\nsurfaces = ["free:block"{flat}]\nconvection = "20 W/(m^2 K)"\nambient = "300 K"'


def cooled_block(petsc_options, flat: str, steps=(1.0, 1.0), **options):
    """The temperatures of a 400 K block cooled by convection (a linear heat problem; ``flat``: the
    flat's bottom cooled too, else insulated) after steps of ``steps`` [s], solved with the solver
    ``options`` under the heat prefix (in PETSc's database from now on: the plain solve first), and
    its heat problem."""
    petsc_options(**options)
    model = march(block_scene(boundary=COOLED.format(flat=', "flat_bottom"' if flat == "cooled" else "")), 0)
    for dt in steps:
        model.macro_step(dt, 1)
    return np.concatenate([T.x.array for T in model.thermal.T]), model.thermal


def test_the_kept_heat_tangent_with_an_empty_block_is_the_whole_jacobian():
    """The flat held at a fixed temperature has no term but its cells' in the heat Jacobian: its
    diagonal block of the rest is ``kept_cells.empty_block`` (over nothing), with a Dirichlet
    condition. The kept cell part plus the rest equals DOLFINx's assembly of the whole Jacobian
    (compiled here: the model compiles the parts only), the fixed rows' unit diagonal included, to
    round-off (1e-12 of its largest entry); the blocks between the bodies, zero, are left out."""
    from dolfinx import fem
    from dolfinx.fem import petsc as fpetsc
    from petsc4py import PETSc
    from multiscale.macro.kept_cells import jacobian
    fixed = '\n[[boundary]]\nsurfaces = ["flat_bottom"]\ntemperature = "300 K"'
    th = march(block_scene(boundary=COOLED.format(flat="") + fixed), 1).thermal
    J = fem.form(jacobian(th.residuals, th.T), entity_maps=th.tm.entity_maps)
    assert J[0][1] is None and J[1][0] is None and th.bcs
    direct = fpetsc.assemble_matrix(J, bcs=th.bcs)
    direct.assemble()
    difference = th._tangent.compose(direct.duplicate())
    difference.axpy(-1.0, direct)
    assert difference.norm(PETSc.NormType.NORM_INFINITY) <= 1e-12 * direct.norm(PETSc.NormType.NORM_INFINITY)


@pytest.mark.parametrize("flat", ["insulated", "cooled"])
def test_the_users_krylov_solver_for_a_linear_heat_problem_wins(petsc_options, flat):
    """KSP and PC options under the heat prefix (PETSC_OPTIONS="-heat_ksp_type cg -heat_pc_type
    jacobi") are those of a linear heat problem's solve (read back from its KSP), to our tolerance:
    the temperatures of our LU solve within 1e-9 K (measured 1e-13 K) and the heat balance to 1e-9
    of the heat lost. "insulated": the flat without boundary terms (its block of the terms other
    than the cells' is ``kept_cells.empty_block``; until 2026-11-30 it took one LU solve a step, and
    before that its KSP was set back to preonly after set-up, so one Jacobi sweep stood for the
    solve: 0.52 K off, 1.10 J of the 1.20 J lost missing from the store). "cooled": the kept
    factors' GMRES (the user's options already won there)."""
    reference, _ = cooled_block(petsc_options, flat)
    T, th = cooled_block(petsc_options, flat, heat_ksp_type="cg", heat_pc_type="jacobi")
    ksp = th.problem.solver.getKSP()
    assert not th.nonlinear and (ksp.getType(), ksp.getPC().getType()) == ("cg", "jacobi")
    assert th._tangent is not None                        # its cell part kept, the flat's too
    assert np.abs(T - reference).max() < 1e-9
    assert th.stored_heat()[0] + th.heat_lost[0] == pytest.approx(0.0, abs=1e-9 * th.heat_lost[0])


def test_a_users_direct_linear_heat_solve_factorises_every_step(petsc_options):
    """A user's ``-heat_ksp_type preonly`` (a direct solve) on a linear heat problem with a kept cell
    part does not solve on the factors of an earlier step's matrix (GMRES does, to 1e-12): after a
    change of dt the temperatures are those of our solve within 1e-9 K (measured 2e-13 K), every
    step factorised. Before: the 3 s step solved with the factors of the 1 s step's matrix, 0.48 K
    off, the heat balance 1.19 J off (of 1.20 J lost)."""
    reference, _ = cooled_block(petsc_options, "cooled", (1.0, 3.0))
    T, th = cooled_block(petsc_options, "cooled", (1.0, 3.0), heat_ksp_type="preonly")
    assert th.problem.solver.getKSP().getType() == "preonly" and th.factorisations == 2
    assert np.abs(T - reference).max() < 1e-9
    assert th.stored_heat()[0] + th.heat_lost[0] == pytest.approx(0.0, abs=1e-9 * th.heat_lost[0])


@pytest.mark.parametrize("option", ["ksp_type", "pc_type"])
def test_a_krylov_option_petsc_refuses_for_a_linear_heat_problem_is_an_input_error(petsc_options, option):
    """A value PETSc refuses under the heat prefix of a linear heat problem is an InputError naming
    PETSC_OPTIONS (``kept_cells.check_user_options``, as for the Newtons)."""
    from multiscale.errors import InputError
    petsc_options(**{f"heat_{option}": "nonsense"})
    with pytest.raises(InputError, match=rf"PETSC_OPTIONS = '-heat_{option} nonsense': PETSc refused one of these"):
        build_model(block_scene(boundary=COOLED.format(flat="")))


@pytest.mark.parametrize("boundary", [COOLED.format(flat=""), HEAT_UP])
def test_a_factorisation_package_petsc_lacks_for_the_heat_is_an_input_error(petsc_options, boundary):
    """``PETSC_OPTIONS="-heat_pc_factor_mat_solver_type superlu"`` (a package this PETSc does not
    have) for a linear heat problem and for the radiation Newton is an InputError naming the
    option and the packages there are, building the model (before: PETSc's error 92 with its
    traceback at the first heat step)."""
    from multiscale.errors import InputError
    petsc_options(heat_pc_factor_mat_solver_type="superlu")
    with pytest.raises(InputError, match=r"PETSC_OPTIONS = '-heat_pc_factor_mat_solver_type superlu': this PETSc "
                       r"cannot factorise \(pc_type lu\) .*; it has .*mumps.* for this factorisation on 1 rank$"):
        march(block_scene(boundary=boundary), 1)


def test_a_heat_step_failing_with_the_users_preconditioner_names_it(petsc_options):
    """The user's ``-heat_pc_type jacobi`` is the radiation Newton's PC (no PC of ours replaces it);
    with our ``preonly`` one Jacobi sweep a step cannot converge, and the error names the user's
    options (before: only "more time.steps or substeps")."""
    from multiscale.errors import ConvergenceError
    petsc_options(heat_pc_type="jacobi")
    scene = block_scene(T0=800.0, end=1.0, steps=2, boundary='[[boundary]]\nsurfaces = ["free:block"]\n'
                        'emissivity = 1.0\nambient = "300 K"')
    with pytest.raises(ConvergenceError, match=r"heat step .* failed .*; PETSC_OPTIONS = '-heat_pc_type jacobi'\)"):
        march(scene)


def test_newton_options_for_a_linear_heat_problem_are_said_to_have_no_effect(petsc_options, tmp_path):
    """Newton's options under the heat prefix (line search, tolerances) have no effect on a linear
    heat problem (one KSP solve a step, SNES "ksponly"; PETSc reads some of them, so its "option
    left" notice does not list them): said once, as a SolverOptionWarning building the model and as
    a line of the run's warnings and provenance (not also a Python warning there). Before: silent."""
    import warnings

    from multiscale.macro.kept_cells import SolverOptionWarning
    petsc_options(heat_snes_linesearch_type="bt", heat_snes_rtol="1e-3", heat_ksp_type="gmres")
    said = (r"PETSC_OPTIONS: -heat_snes_linesearch_type -heat_snes_rtol had no effect: the heat problem is "
            r"linear \(no radiation, no temperature tables\), one linear solve a step, not Newton's method")
    with pytest.warns(SolverOptionWarning, match=said) as caught:
        th = build_model(block_scene(boundary=COOLED.format(flat=""))).thermal
    assert len(caught) == 1 and th.notes == [str(caught[0].message)]
    folder = tmp_path / "out"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run(block_scene(boundary=COOLED.format(flat="") + f'\n[output]\nfolder = "{folder}"'), verbose=False)
    assert not [c for c in caught if c.category is SolverOptionWarning]
    assert [w for w in result.warnings if "had no effect" in w] == th.notes
    assert th.notes[0] in json.loads((folder / "provenance.json").read_text())["warnings"]


def test_a_failed_run_says_and_records_the_warnings_it_had_so_far(petsc_options, tmp_path, monkeypatch, capsys):
    """The run's notes (here the heat's Newton options that have no effect, from the model's build)
    were said with its results only: a run that failed in a later step lost them from its report
    and its provenance, the failing step's own notes with the rest. Now the error carries the notes
    so far (PEP 678 ``__notes__``): said as warnings before the error, and recorded."""
    petsc_options(heat_snes_rtol="1e-3")
    solve, calls = thermal.Thermal._solve, []
    monkeypatch.setattr(thermal.Thermal, "_solve", lambda self: calls.append(1) or (solve(self) and len(calls) < 2))
    folder = tmp_path / "out"
    with pytest.raises(ConvergenceError, match="heat step") as info:     # the second step's solves fail
        run(block_scene(boundary=COOLED.format(flat="") + f'\n[output]\nfolder = "{folder}"', steps=3, end=3.0),
            verbose=False)
    said = "PETSC_OPTIONS: -heat_snes_rtol had no effect: the heat problem is linear"
    assert [n for n in info.value.__notes__ if n.startswith(said)] and len(calls) > 2
    assert f"warning: {said}" in capsys.readouterr().err
    record = json.loads((folder / "provenance.json").read_text())
    assert record["status"].startswith("failed: ConvergenceError: heat step")
    assert [w for w in record["warnings"] if w.startswith(said)]

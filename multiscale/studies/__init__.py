"""Parametric studies: what accuracy costs in time (``multiscale study STUDY.toml``).

A study file (TOML, validated by ``multiscale.schema`` like a scene: every problem at once, with
did-you-mean) names a problem of ``multiscale.studies.problems`` (a micro problem, or ``scene``
with a base scene whose keys it overrides), the parameters to sweep, the metrics and the
reference::

    name = "hertz_grid"
    problem = "hertz"                 # or problem = "scene" with scene = "pin_on_disc.toml"
    metrics = ["contact_radius", "max_pressure"]
    [fixed]                           # held constant (scene problems: dotted scene paths)
    load = "10 N"
    [[sweep]]                         # groups combine as a product; inside a group:
    combine = "product"               # "product" (default) or "zip" (lists of equal length)
    grid = [16, 32, 64, 128]          # a list, or a range {start, stop, num | step, log = true}
    [reference]
    kind = "analytic"                 # the problem's exact values; "run" with run = {grid = 128}
                                      # (per run: the run with these values, others unchanged,
                                      # zip partners following);
                                      # "file" with file = "ref.json" ({metric: value};
                                      # a metric without a value is tabulated, not judged)
    [run]                             # processes, timeout, repeat (best-of wall time), folder
    [report]                          # errors = ["1 %", "5 %"], cases (physical parameters, not
                                      # knobs), average_over (e.g. seeds), folder, title, plots

Runs: each run is a fresh worker process (``python -m multiscale.studies.worker``), so its peak
memory (``ru_maxrss``, children included) is its own; ``[run] processes`` of them at a time, or
under ``mpiexec -n N`` the runs are shared out over the ranks. A run's record (wall time, CPU
time, peak memory, iterations, convergence, status, error message, metrics, analytic reference)
is one JSON file ``runs/<key>.json``, ``key`` = hash of the problem and its validated parameters:
finished runs are never recomputed (``--rerun-failed`` retries the failed ones, a longer
``run.timeout`` the timed-out ones); a failing, crashing or timed-out run is recorded as failed and
the others go on. A run that completed keeps every metric it produced and is judged by the study's
metrics when read: a misspelt history metric, corrected, is read from the same run.

Output: ``results.csv`` and ``results.h5`` (one row per run; a column's SI unit, a swept
parameter's included, is its ``unit`` attribute in results.h5 and in its header in results.csv,
``wall_time [s]``; ``iterations`` is −1 where there is nothing to count: a squeal run, a run that
failed or did not run, whose ``converged`` is false), PNGs of each metric's relative error
|m − m_ref| / |m_ref| against wall time (Pareto front highlighted) and against each knob (against
measured values: the metric, its measured value and where the sweep meets it), and a
Markdown report stating the cheapest setting meeting each stated error; against a reference file
of measured values, also where along each swept knob each metric meets its measured value
(calibration from a sweep: which k_w gives the measured worn volume; ``results.crossings``).
What a run found while running (a scene's zone pressures beyond the laws' top, a measured file's
outliers: beyond its inputs' warnings, said before the runs) is said on the console once per kind
(warnings differing in their numbers only are one), with the first run that found it, listed in the
report with its runs and in the ``warnings`` column (a JSON list). Ctrl-C stops the runs under way
and writes the tables and the report of those that ended (the others with status ``missing``, "not
run or cut off" in the report); run again, the study runs those anew.

Modules, in import order: ``spec`` (the file schema), ``problems`` (the registry; ``base``,
``micro_problems``, ``scene_problem``), ``expand`` (validation, runs), ``records`` (run records on
disk), ``running`` (``execute``: worker processes, MPI), ``worker`` (one run), ``results`` (rows,
errors, tables), ``reporting`` (Markdown; figures in ``multiscale.plots.studies``), ``driver``
(``run_studies``).
"""
from __future__ import annotations

from multiscale.studies.driver import run_studies
from multiscale.studies.expand import Study, StudyRun, load_study, reference_run
from multiscale.studies.problems import PROBLEMS, problem, problems_text
from multiscale.studies.reporting import report
from multiscale.studies.results import Row, cheapest, collect, pareto, relative_error, write_tables
from multiscale.studies.running import ExecStats, execute

__all__ = ["PROBLEMS", "ExecStats", "Row", "Study", "StudyRun", "cheapest", "collect", "execute", "load_study",
           "pareto", "problem", "problems_text", "reference_run", "relative_error", "report", "run_studies",
           "write_tables"]

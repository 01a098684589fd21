"""``multiscale study``: several studies end to end (load all, run, tables, reports, index)."""
from __future__ import annotations

import collections
import dataclasses
import sys
from pathlib import Path

from multiscale.errors import SceneError
from multiscale.io import holding_ctrl_c
from multiscale.studies.expand import load_study
from multiscale.studies.records import foreign_records
from multiscale.studies.reporting import report, write_index
from multiscale.studies.results import collect, write_tables
from multiscale.studies.running import execute, world

__all__ = ["run_studies"]


def run_studies(paths, *, rerun_failed: bool = False, report_folder=None, processes: int | None = None,
                progress: bool = True, command: str = "") -> int:
    """Load every study first (all problems reported at once), run them, write tables and reports;
    with ``report_folder`` every report goes there, with an index README.md. Returns the number of
    failed runs."""
    comm = world()
    studies, problems = [], []
    for path in paths:
        try:
            studies.append(load_study(path))
        except SceneError as exc:
            problems += [f"{path}: {line}" for line in exc.problems] if len(paths) > 1 else exc.problems
    if problems:
        raise SceneError(problems if comm is None or comm.rank == 0 else [])   # one rank speaks
    if report_folder is not None:
        studies = [dataclasses.replace(s, report_folder=Path(report_folder).resolve()) for s in studies]
    if processes is not None:
        studies = [dataclasses.replace(s, options=dataclasses.replace(s.options, processes=processes)) for s in studies]
    rank = comm.rank if comm is not None else 0
    for study in studies if rank == 0 else ():
        for line in study.warnings:
            print(f"warning: {study.name}: {line}", file=sys.stderr)
    failed, summaries = 0, []
    for study in studies:
        try:
            stats = execute(study, rerun_failed=rerun_failed, progress=progress, comm=comm)
        except KeyboardInterrupt:       # Ctrl-C: the tables and report of the runs that ended (it waited for the
            if rank == 0:               # end before; then the old report stayed beside the new tables: a user trial)
                with holding_ctrl_c("the tables and report of the runs that ended"):   # (a second Ctrl-C
                    _write_stopped(study, summaries, command, report_folder)         # left none, unsaid: a trial)
            raise
        if rank != 0:
            continue
        rows = collect(study)
        write_tables(study, rows)
        md = report(study, rows, command)
        bad = sum(not r.ok for r in rows)
        failed += bad
        summaries.append((study, rows, md))
        other = foreign_records(study)        # a changed study ran anew with nothing said
        print(f"{study.name}: {len(rows)} runs ({stats.done} recorded before, {stats.started} run now, "
              f"{bad} failed); table {study.folder / 'results.csv'}; report {md}" + (
                  f"\n{study.name}: {other} other record{'s' if other > 1 else ''} in {study.folder / 'runs'} (runs "
                  "not in this study: its file changed since they ran, or another study shares the folder): kept, "
                  "not in the tables" if other else ""))
        reasons = collections.defaultdict(list)       # (before: "2 failed" alone once the runs were recorded)
        for r in rows:
            if not r.ok:
                reasons[r.record.get("error", "").split("; available:")[0]].append(r.run.text)
        for why, runs in sorted(reasons.items(), key=lambda item: -len(item[1])):   # which runs (an MPI trial)
            print(f"  {len(runs)} failed: {why} ({'; '.join(runs[:3])}{'; ...' if len(runs) > 3 else ''})")
        warned = sum(bool(r.record.get("warnings")) for r in rows)
        if warned:                                    # (also of runs recorded before, not said as they ran)
            print(f"  {warned} run{'s' if warned > 1 else ''} warned of what {'they' if warned > 1 else 'it'} found "
                  "while running: in the report and the warnings column")
    if rank == 0 and report_folder is not None:
        index = write_index(summaries, Path(report_folder).resolve(), command)
        print(f"index {index}")
    return failed


def _write_stopped(study, summaries: list, command: str, report_folder) -> None:
    """The tables and report (and index, into ``report_folder``) of a study stopped by Ctrl-C: the
    runs that ended, the others missing."""
    rows = collect(study)
    csv_path, _ = write_tables(study, rows)
    try:                    # (an error of the report replaced the interrupt, its exit code 130: a review)
        page = report(study, rows, command)
        md = f" and {page}"
        if report_folder is not None:     # the index too: the reports written so far (a review)
            index = write_index(summaries + [(study, rows, page)], study.report_folder, command, study.name)
            md += f"; index {index}"
    except Exception as exc:      # the tables are written; the interrupt goes on
        md = f" (no report: {type(exc).__name__}: {exc})"
    print(f"{study.name}: the runs that ended are in {csv_path}{md} (the others: status missing)",
          file=sys.stderr, flush=True)

"""The Markdown report of a study (tables of the cheapest settings, averages, every run; links
to the figures of ``multiscale.plots.studies``) and the index of a report folder."""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from multiscale.io import duration
from multiscale.studies.expand import Study
from multiscale.studies.formatting import by_kind, metric_heading, now, number_text, percent, value_text
from multiscale.studies.problems import PROBLEMS
from multiscale.studies.records import JIT_SHARE
from multiscale.studies.results import MISSING, Row, case_key, cheapest, crossings, knob_unit, reference_text, sample_std

__all__ = ["report", "write_index"]


def elapsed(seconds: float) -> str:
    """A run time for the report: "0.022 s", "4.2 s", "4 min 10 s" (``io.duration`` from 1 s on)."""
    return f"{seconds:.2g} s" if seconds < 1 else duration(seconds)


def report(study: Study, rows: list[Row], command: str = "") -> Path:
    """Markdown report and PNGs in ``study.report_folder``; returns the Markdown path."""
    folder = study.report_folder
    folder.mkdir(parents=True, exist_ok=True)
    from multiscale.plots.studies import plot  # local: matplotlib only when reporting; it imports this package
    pngs = plot(study, rows, folder)
    problem = PROBLEMS[study.problem]
    ok = [r for r in rows if r.ok]
    failed = [r for r in rows if not r.ok and r.record.get("status") != MISSING]
    missing = len(rows) - len(ok) - len(failed)
    timing = (f" Wall time: best of {_repeats(ok)} repetition(s) in a fresh process ({_processes(study)}; a run "
              f"whose first timing spent over {JIT_SHARE:.0%} of it loading or compiling numba code is timed once "
              "more); peak memory: the largest process's maximum resident set (interpreter and libraries included; "
              "in brackets what the run added to the process's baseline).") if ok else ""   # ("best of 0 ...")
    lines = [f"# {study.report.title or study.name}", ""]
    if study.description:
        lines += [study.description, ""]
    metric_doc = problem.metrics
    lines += [f"- Problem: `{study.problem}` — {problem.doc}",
              *[f"- Swept: {text}" for text in study.sweep_text],
              f"- Fixed: {', '.join(f'{k} = {value_text(v)}' for k, v in study.fixed.items()) or 'problem defaults'}",
              "- Metrics: " + "; ".join(f"`{m}`" + (f" ({metric_doc[m]})" if m in metric_doc else "")
                                         for m in study.metrics),
              f"- Reference: {reference_text(study)}"
              + ("; error = |m − m_ref| / |m_ref|" if study.reference else ""),
              f"- Runs: {len(ok)} ok, {len(failed)} failed"
              + (f", **{missing} not run or cut off: the study was stopped** (run it again for them; the runs "
                 "that ended are kept)" if missing else "") + f"; {elapsed(sum(r.record.get('wall_time', 0) for r in rows))} "
              f"of run wall time in all (failed runs included).{timing}",
              _code_line(rows),
              f"- Generated {now()} on a {os.cpu_count()}-core machine by `{command or 'multiscale study ' + study.source.name}`.",
              ""]
    if study.warnings:
        lines += ["Warnings of the runs' inputs:", ""] + [f"- {line}" for line in study.warnings] + [""]
    lines += _found_warnings(rows)
    if study.reference is not None and ok:
        lines += _cheapest_table(study, rows, missing)
    found = crossings(study, rows)
    if found:
        lines += _crossing_table(study, found)
    if study.averaged and ok:
        lines += _average_table(study, ok)
    lines += ["## Runs", ""] + _runs_table(study, rows)
    if failed:
        lines += ["", "Failed runs:", ""] + [f"- {r.run.text}: {r.record.get('error', '')}" for r in failed]
    if pngs:
        lines += ["", "## Plots", ""] + [f"![{p.stem}]({p.name})" for p in pngs]
    path = folder / f"{study.name}.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def _found_warnings(rows, shown: int = 3) -> list[str]:
    """What the runs warned of while running (zone pressures beyond the laws' top, outliers of a
    measured file), each kind once (``warning_kind``: the runs' own numbers aside) as its first run
    gave it, with the runs that gave it (the first ``shown`` of them)."""
    found = by_kind((line, r.run.text) for r in rows for line in r.record.get("warnings", ()))
    if not found:
        return []
    lines = ["Warnings of the runs (what they found while running; column `warnings` of results.csv):", ""]
    for line, runs, varied in found:
        more = f" and {len(runs) - shown} more" if len(runs) > shown else ""
        own = " (the numbers of the first; each run's in results.csv)" if varied else ""
        lines.append(f"- {line} ({'; '.join(runs[:shown])}{more}){own}")
    return lines + [""]


def _code_line(rows) -> str:
    """Which code made the runs (their records' SHA-1 of the package): a record is reused whatever
    code made it, so a table of several versions says so."""
    versions = {}
    for r in rows:
        if "ran" in r.record:
            made = r.record.get("code") or {}
            versions.setdefault(made.get("sha1", "not recorded")[:12], made.get("commit", "")[:12])
    if not versions:
        return "- Code: no run recorded"
    if len(versions) == 1:
        (sha1, commit), = versions.items()
        return f"- Code: package SHA-1 {sha1}" + (f" (commit {commit})" if commit else "")
    return (f"- Code: **the runs were made by {len(versions)} versions of the package** (SHA-1 "
            f"{', '.join(versions)}; column `code` of results.csv): a record is reused whatever code made it; "
            "delete the records of runs/ to run them again with this code.")


def _processes(study: Study) -> str:
    """How the runs ran: one thread, or a scene on its ranks."""
    ranks = study.options.ranks if study.problem == "scene" else 1
    how = "one thread" if ranks == 1 else f"{ranks} MPI ranks of one thread each"
    return how + ("; a scene run's own time, its provenance.json's, without its process's start-up"
                  if study.problem == "scene" else "")


def _repeats(rows) -> str:
    """How many times the runs were timed, as their records say (a record timed more often than the
    study asks now is kept: '1-3')."""
    counts = sorted({int(r.record.get("repeat", 1)) for r in rows})
    return f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"


def _iterations(record) -> str:
    """A run's iteration count; "n/a" where it has none (-1: a squeal run's, a run not run)."""
    n = record.get("iterations", -1)
    return str(n) if isinstance(n, int) and n >= 0 else "n/a"


def _memory(record: dict) -> str:
    """Peak memory [MB] and, in brackets, what the run added to its process's baseline."""
    peak, base = record.get("peak_memory_mb", math.nan), record.get("base_memory_mb", math.nan)
    return "n/a" if not math.isfinite(peak) else f"{peak:.0f}" + (f" (+{peak - base:.0f})" if math.isfinite(base) else "")


def _cheapest_table(study, rows, missing: int = 0) -> list[str]:
    """The cheapest setting meeting each stated error (``results.cheapest``), of the runs that ended
    (``missing``: those a stopped study did not run); the reason where a case's runs have no error
    (it said "none of the runs" at every error, the reference run not run: a user trial)."""
    judged = {case_key(study, r) for r in rows if r.ok and math.isfinite(r.max_error)}
    why = {}
    for r in (r for r in rows if r.ok):
        why.setdefault(case_key(study, r), r.note or "a reference value of 0 has no relative error")
    if not judged:
        return ["## What accuracy costs", "", f"No run has an error to judge: {next(iter(why.values()), '')}.", ""]
    knobs = [k for k in study.knobs if k not in study.cases]
    head = ["error ≤"] + list(study.cases) + knobs + ["wall time [s]", "peak memory [MB]", "worst error", "time / base"]
    samples = (f" over every sample of {', '.join(study.averaged)} (its wall time their mean)"
               if study.averaged else "")
    lines = ["## What accuracy costs", "",
             (f"Of the runs that ended ({missing} not run): t" if missing else "T") + "he cheapest setting (least "
             f"wall time) whose worst error over the metrics"
             f"{' with a reference' if study.unjudged else ''}{samples} meets each "
             "stated error; 'time / base' compares it with " + ("the reference run" if study.reference.kind == "run"
                                                                else "the most expensive setting") + ".", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for c in cheapest(study, rows):
        g, base = c["setting"], c["base"]
        if g is None:
            cells = ["none of the runs" if c["case"] in judged else f"no error to judge: {why.get(c['case'], '')}"] \
                + [""] * (len(knobs) + 3)
        else:
            speed = g.wall_time / base.wall_time if base else math.nan
            cells = [g.shown(study, k) for k in knobs] + [f"{g.wall_time:.3g}", _memory(g.record("peak_memory_mb")),
                                                           percent(g.max_error), f"{speed:.2g}"]
            if g.is_reference:
                cells[-1] += " (only the reference)"
        lines.append("| " + " | ".join([percent(c["error"]), *c["case"], *cells]) + " |")
    return lines + [""]


def _crossing_table(study, found) -> list[str]:
    unit = PROBLEMS[study.problem].metric_unit
    lines = ["## Where the metrics meet the reference", "",
             f"Along each swept parameter, the other parameters held: the value at which a metric equals its "
             f"value in {study.reference.file.name}, interpolated between the two runs around it (log-log where "
             "both are positive: exact for a power law, as Archard's worn volume against k_w); run the value "
             "found to check it.", "",
             "| metric | parameter | held | value | between | metric there |", "|---|---|---|---|---|---|"]
    for c in found:
        u = knob_unit(study, c.knob)
        value = "not in the swept range" if c.value is None else \
            f"{c.value:.4g}" + (f" {u}" if u and u != "-" else "") + (" (log-log)" if c.log else " (linear)")
        along = c.knob + (f" (with {', '.join(c.partners)} alongside)" if c.partners else "")
        lines.append(f"| {metric_heading(c.metric, unit(c.metric))} | {along} | "
                     f"{', '.join(f'{k} = {v}' for k, v in c.held) or '–'} | {value} | {c.between[0]} … {c.between[1]} | "
                     f"{number_text(c.span[0])} … {number_text(c.span[1])} |")
    return lines + [""]


def _average_table(study, rows) -> list[str]:
    keep = [k for k in study.knobs if k not in study.averaged]
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r.run.shown[k] for k in keep), []).append(r)
    unit = PROBLEMS[study.problem].metric_unit
    head = keep + [f"{metric_heading(m, unit(m))} mean ± sample std (min … max)" for m in study.metrics] + ["samples"]
    lines = [f"## Averaged over {', '.join(study.averaged)}", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, group in groups.items():
        cells = list(label)
        for m in study.metrics:
            v = np.array([r.record["metrics"][m] for r in group])
            cells.append(f"{v.mean():.4g} ± {sample_std(v):.2g} ({v.min():.4g} … {v.max():.4g})")
        lines.append("| " + " | ".join(cells + [str(len(group))]) + " |")
    return lines + [""]


def _runs_table(study, rows) -> list[str]:
    head, unit = list(study.knobs), PROBLEMS[study.problem].metric_unit
    for m in study.metrics:
        head += [metric_heading(m, unit(m))] + (["error"] if m in study.judged else [])
    head += ["wall time [s]", "peak memory [MB]", "iterations", "status"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r.run.shown[k] for k in study.knobs]
        for m in study.metrics:
            cells.append(number_text(r.record.get("metrics", {}).get(m, math.nan)))
            if m in study.judged:
                cells.append(percent(r.errors.get(m, math.nan)))
        rec = r.record
        status = rec.get("status", "")
        if r.ok and not rec.get("converged", True):
            status += " (not converged)"
        if r.note:
            status += f" ({r.note})"
        cells += [number_text(float(rec.get("wall_time", math.nan))), _memory(rec),
                  _iterations(rec), status]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def write_index(summaries, folder: Path, command: str, stopped: str | None = None) -> Path:
    """README.md of a report folder: per study, its cheapest settings at each stated error
    (``stopped``: the study during which the command was stopped, the last of ``summaries``)."""
    lines = ["# What accuracy costs", "",
             f"Generated {now()} on a {os.cpu_count()}-core machine by `{command}`. Each study has its own "
             "page (tables of every run, plots of error against wall time with the Pareto front, and against "
             "each knob).", ""]
    if stopped is not None:
        lines += [f"**Stopped during the study {stopped}**: its page has the runs that ended; the studies after it "
                  "did not run.", ""]
    for study, rows, md in summaries:
        lines += [f"## [{study.report.title or study.name}]({md.name})", ""]
        if study.description:
            lines += [study.description, ""]
        if study.reference is None:
            lines += ["Parametric study (no reference).", ""]
            continue
        lines += [f"Reference: {reference_text(study)}. Cheapest setting meeting each error "
                  "(wall time, worst error):", ""]
        found = cheapest(study, rows)
        cases = list(dict.fromkeys(c["case"] for c in found))
        head = ["error ≤"] + ([", ".join(f"{k} = {v}" for k, v in zip(study.cases, case)) for case in cases]
                             if study.cases else ["setting"])
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for tol in study.report.errors:
            cells = [percent(tol)]
            for c in (c for c in found if c["error"] == tol):
                g = c["setting"]
                cells.append("none" if g is None else ", ".join(
                    f"{k} = {g.shown(study, k)}" for k in study.knobs if k not in study.cases)
                    + f" ({g.wall_time:.3g} s, {percent(g.max_error)})" + (" (the reference)" * g.is_reference))
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    path = folder / "README.md"
    path.write_text("\n".join(lines) + "\n")
    return path

"""Results of a study: its records as rows with reference values and relative errors, the tables
(``results.csv``, ``results.h5``), the cheapest run meeting each stated error, the Pareto front."""
from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from multiscale.schema import Either, ListOf, Quantity, TableOr
from multiscale.studies.expand import Study, StudyRun, normalise, parser_of, reference_run
from multiscale.studies.formatting import value_text
from multiscale.studies.problems import PROBLEMS
from multiscale.studies.records import read_records
from multiscale.studies.scene_problem import scene_key_spec
from multiscale.units import KINDS, VALUE, parse_unit

__all__ = ["MISSING", "Crossing", "Row", "Setting", "case_key", "cheapest", "collect", "crossings", "pareto", "reference_text",
           "relative_error", "sample_std", "write_tables"]


@dataclass
class Row:
    """One run in the results table."""

    run: StudyRun
    record: dict
    reference: dict = field(default_factory=dict)    # metric -> reference value (may be missing)
    errors: dict = field(default_factory=dict)       # metric -> relative error (NaN if unknown)
    note: str = ""                                   # why an error is missing
    is_reference: bool = False                       # the reference run of its own errors

    @property
    def ok(self) -> bool:
        return self.record.get("status") == "ok"

    @property
    def max_error(self) -> float:
        values = list(self.errors.values())
        return max(values) if values and all(math.isfinite(v) for v in values) else math.nan


@dataclass
class Setting:
    """The runs of one setting of a case: equal in every knob but those averaged over (seeds), one
    run when nothing is averaged."""

    rows: list

    @property
    def wall_time(self) -> float:
        """Mean wall time [s] of its runs."""
        return float(np.mean([r.record["wall_time"] for r in self.rows]))

    @property
    def max_error(self) -> float:
        """Worst error over the metrics and the runs; NaN if a run failed or has no error."""
        errors = [r.max_error if r.ok else math.nan for r in self.rows]
        return max(errors) if all(math.isfinite(e) for e in errors) else math.nan

    @property
    def is_reference(self) -> bool:
        return any(r.is_reference for r in self.rows)

    def shown(self, study: Study, knob: str) -> str:
        """The knob's value as the study wrote it; of an averaged knob, how many samples."""
        return f"{len(self.rows)} samples" if knob in study.averaged else self.rows[0].run.shown[knob]

    def record(self, name: str) -> dict:
        """The record of its most expensive run in ``name`` ("peak_memory_mb": the largest)."""
        return max((r.record for r in self.rows), key=lambda rec: rec.get(name, -math.inf))


MISSING = "missing"        # the status of a run without a record (a study stopped before it ran)


def relative_error(value: float, ref: float) -> float:
    """|value − ref| / |ref|; against ref = 0, 0 for value = 0 and NaN (no relative error, shown
    "n/a") otherwise: |value| shown as a percentage read as 6e3 % for a growth rate of 60 1/s."""
    if ref == 0:
        return 0.0 if value == 0 else math.nan
    return abs(value - ref) / abs(ref)


def collect(study: Study) -> list[Row]:
    """Rows of the recorded runs, with reference values and relative errors."""
    records = read_records(study)
    rows = [Row(r, records.get(r.key, {"status": MISSING, "error": "not run or cut off", "metrics": {}})) for r in study.runs]
    ref = study.reference
    if ref is None:
        return rows
    by_key = {row.run.key: row for row in rows}
    fixed = json.loads(ref.file.read_text()) if ref.kind == "file" else None
    want = {k: normalise(v, parser_of(PROBLEMS[study.problem], k)) for k, v in (ref.run or {}).items()}
    for row in rows:
        if not row.ok:
            continue
        if ref.kind == "analytic":
            values = row.record.get("reference") or {}
        elif ref.kind == "file":
            values = fixed
        else:
            target = by_key[reference_run(study.runs, row.run.label, want, study.axes).key]
            values = target.record["metrics"] if target.ok else {}
            if not target.ok:
                row.note = "reference run not run" if target.record.get("status") == MISSING else "reference run failed"
            elif target is row:
                row.note, row.is_reference = "reference run", True
        for m in study.judged:
            if m in values:
                row.reference[m] = float(values[m])
                row.errors[m] = relative_error(row.record["metrics"][m], float(values[m]))
            else:
                row.errors[m] = math.nan
                row.note = row.note or "no reference value"
    return rows


def _columns(study: Study, rows: list[Row]) -> dict:
    """The tidy table, column -> list (one entry per run)."""
    cols = {"run": [r.run.key for r in rows], "status": [r.record.get("status", "") for r in rows]}
    for k in study.knobs:
        cols[k] = [_cell(r.run.label[k]) for r in rows]
    for m in study.metrics:
        cols[m] = [r.record.get("metrics", {}).get(m, math.nan) for r in rows]
        if m in study.judged:
            cols[f"{m}_reference"] = [r.reference.get(m, math.nan) for r in rows]
            cols[f"{m}_error"] = [r.errors.get(m, math.nan) for r in rows]
    if study.reference is not None:
        cols["max_error"] = [r.max_error for r in rows]
    for name in ("wall_time", "cpu_time", "peak_memory_mb"):
        cols[name] = [float(r.record.get(name, math.nan)) for r in rows]
    cols["iterations"] = [int(r.record.get("iterations", -1)) for r in rows]     # -1: none (a squeal run's)
    cols["converged"] = [bool(r.record.get("converged", False)) for r in rows]
    cols["code"] = [(r.record.get("code") or {}).get("sha1", "")[:12] for r in rows]    # the package that ran it
    cols["message"] = [r.record.get("error", "") or r.note for r in rows]
    cols["warnings"] = [json.dumps(r.record["warnings"], ensure_ascii=False) if r.record.get("warnings") else ""
                        for r in rows]   # what the run found, a JSON list (its texts hold "; " themselves: a review)
    return cols


def _cell(value):
    return json.dumps(value) if isinstance(value, list) else value


def csv_header(name: str, unit: str | None) -> str:
    """results.csv's header of column ``name``: "name [unit]" where its SI unit is known ("-"
    dimensionless; the CSV had none, only results.h5: a user trial), else the name."""
    return f"{name} [{unit}]" if unit else name


def write_tables(study: Study, rows: list[Row]) -> tuple[Path, Path]:
    """results.csv and results.h5 (one dataset per column, one row per run; a metric's, its
    reference's and the times' with their ``unit`` attribute, as history.h5's)."""
    cols = _columns(study, rows)
    study.folder.mkdir(parents=True, exist_ok=True)
    csv_path, h5_path = study.folder / "results.csv", study.folder / "results.h5"
    units = {"wall_time": "s", "cpu_time": "s", "peak_memory_mb": "MB"}    # (said by the report alone; a user trial)
    units.update((k, knob_unit(study, k)) for k in study.knobs)              # (none before: a user trial)
    for m in study.metrics:
        units[m] = PROBLEMS[study.problem].metric_unit(m)
        units[f"{m}_reference"] = units[m] if m in study.judged else None
    with open(csv_path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow([csv_header(c, units.get(c)) for c in cols])
        for i in range(len(rows)):
            w.writerow([_csv(cols[c][i]) for c in cols])
    with h5py.File(h5_path, "w") as h5:
        for name, values in cols.items():
            if all(isinstance(v, (int, float, bool)) for v in values):
                h5.create_dataset(name, data=np.asarray(values))
            else:
                h5.create_dataset(name, data=[str(v) for v in values], dtype=h5py.string_dtype())
            if units.get(name):
                h5[name].attrs["unit"] = units[name]
        h5.attrs.update(study=study.name, problem=study.problem, source=str(study.source),
                        reference=reference_text(study), metrics=list(study.metrics), knobs=list(study.knobs))
    return csv_path, h5_path


def knob_unit(study: Study, name: str) -> str:
    """The SI unit of swept knob ``name``'s column: its kind's for a micro problem's parameter or a
    scene key ("-" dimensionless; bare numbers of a scene key are in it, user trial M), else that
    of the unit its values were written in ("3 MPa": Pa); "" if not known (a count)."""
    spec = scene_key_spec(name) if study.problem == "scene" else parser_of(PROBLEMS[study.problem], name)
    parser = spec.parser if spec is not None else None
    while isinstance(parser, (ListOf, TableOr, Either)):
        parser = parser.item if isinstance(parser, ListOf) else parser.value if isinstance(parser, TableOr) \
            else next((p for p in parser.parsers if isinstance(p, Quantity)), None)
    if isinstance(parser, Quantity):
        return parser.kind.si or "-"
    for run in study.runs:
        match = VALUE.match(run.raw[name]) if isinstance(run.raw.get(name), str) else None
        if match and match.group(2):
            dim = parse_unit(match.group(2))[2]
            return next((k.si or "-" for k in KINDS.values() if k.dim == dim), "")
    return ""


def _csv(value):
    return f"{value:.10g}" if isinstance(value, float) else value


def reference_text(study: Study) -> str:
    """What the errors are measured against, in words."""
    ref = study.reference
    if ref is None:
        return "none (a parametric study)"
    alone = f" (of {', '.join(study.judged)}; {', '.join(study.unjudged)} tabulated without one)" \
        if study.unjudged else ""
    if ref.kind == "analytic":
        doc = (PROBLEMS[study.problem].exact.__doc__ or "").strip().splitlines()
        return "the problem's own reference" + (f": {doc[0].rstrip('.')}" if doc else "") + alone
    if ref.kind == "file":
        return f"stored result {ref.file.name}{alone}"
    return "the run with " + ", ".join(f"{k} = {value_text(v)}" for k, v in ref.run.items()) + \
        (" (other parameters unchanged)" if len(ref.run) < len(study.knobs) else "")


def case_key(study: Study, row: Row) -> tuple:
    """The row's values of the study's cases (physical parameters), as shown."""
    return tuple(row.run.shown[k] for k in study.cases)


def cheapest(study: Study, rows: list[Row]) -> list[dict]:
    """Per stated error and case: the ``Setting`` of least mean wall time whose worst error, over the
    metrics and the samples averaged over (``report.average_over``: every seed, not one lucky
    seed), meets it ("setting"), and the base it is compared with ("base": the reference runs, else
    the most expensive setting)."""
    out, chosen = [], [k for k in study.knobs if k not in study.cases and k not in study.averaged]
    cases = list(dict.fromkeys(case_key(study, r) for r in rows))
    for case in cases:
        groups = {}
        for r in (r for r in rows if case_key(study, r) == case):
            groups.setdefault(tuple(r.run.shown[k] for k in chosen), []).append(r)
        settings = [Setting(g) for g in groups.values() if all(r.ok for r in g)]
        refs = [r for g in settings for r in g.rows if r.is_reference]
        base = Setting(refs) if refs else max(settings, key=lambda g: g.wall_time, default=None)
        for tol in study.report.errors:
            good = [g for g in settings if g.max_error <= tol]
            out.append({"error": tol, "case": case, "setting": min(good, key=lambda g: g.wall_time, default=None),
                        "base": base})
    return sorted(out, key=lambda c: study.report.errors.index(c["error"]))


@dataclass(frozen=True)
class Crossing:
    """Where a metric meets its measured value along one swept knob, the other knobs held."""

    metric: str
    knob: str
    held: tuple            # (knob, value as shown) of the other knobs
    value: float | None    # the knob's value [its SI unit] at which the metric equals the reference; None: not met
    between: tuple         # the two swept values (as shown) around it; not met: the first and last swept
    span: tuple            # the metric at ``between`` (mean over the averaged knobs); not met: its least and most
    log: bool              # interpolated linearly in log(metric) against log(knob)
    partners: tuple = ()   # the knobs of its zip group, varied alongside


def measured_value(rows: list[Row], metric: str) -> float:
    """The measured value of judged ``metric`` (a calibration's reference, the same in every run)
    from the first successful row that has it."""
    return next(r.reference[metric] for r in rows if r.ok and metric in r.reference)


def crossings(study: Study, rows: list[Row]) -> list[Crossing]:
    """Calibration from a sweep against measured values (``reference.kind = "file"``): along each
    numeric knob, for each setting of the other knobs and each judged metric, the knob values at
    which the metric equals its reference, interpolated between neighbouring swept values where
    metric − reference changes sign: in log-log when the knob's and the metric's values are
    positive (exact for a power law: Archard's worn volume ∝ k_w), else linearly. Along a zip
    group, its first knob with the others varied alongside (``Crossing.partners``), and
    only where all of them are numbers (a zip of two pad formulations' tables was interpolated
    along its first key: a trial). The metric is the mean over the averaged knobs; a setting with
    a failed run is left out. [] for other references."""
    if study.reference is None or study.reference.kind != "file":
        return []
    out = []
    for axis in (a for a in study.axes if a[0] not in study.averaged):
        knob, held = axis[0], [k for k in study.knobs if k not in axis and k not in study.averaged]
        groups = {}
        for r in rows:
            groups.setdefault(tuple(r.run.shown[k] for k in held), []).append(r)
        for setting, group in groups.items():
            if any(not r.ok for r in group):
                continue
            xs = list({r.run.label[knob] for r in group})
            if len(xs) < 2 or not all(isinstance(r.run.label[k], (int, float)) and not isinstance(r.run.label[k], bool)
                                      for r in group for k in axis):
                continue
            xs.sort()
            shown = {r.run.label[knob]: r.run.shown[knob] for r in group}
            for m in study.judged:
                ref = measured_value(rows, m)
                y = [float(np.mean([r.record["metrics"][m] for r in group if r.run.label[knob] == x])) for x in xs]
                log = min(xs) > 0 and min(y) > 0 and ref > 0
                f = (lambda v: math.log(v)) if log else (lambda v: v)
                found = [i for i in range(len(xs) - 1) if (y[i] - ref) * (y[i + 1] - ref) < 0 or y[i + 1] == ref
                         or i == 0 and y[0] == ref]          # (a swept value that meets it: once)
                for i in found:
                    t = 0.0 if y[i] == ref else (f(ref) - f(y[i])) / (f(y[i + 1]) - f(y[i]))
                    value = f(xs[i]) + t * (f(xs[i + 1]) - f(xs[i]))
                    out.append(Crossing(m, knob, tuple(zip(held, setting)), math.exp(value) if log else value,
                                        (shown[xs[i]], shown[xs[i + 1]]), (y[i], y[i + 1]), log, axis[1:]))
                if not found:
                    out.append(Crossing(m, knob, tuple(zip(held, setting)), None, (shown[xs[0]], shown[xs[-1]]),
                                        (min(y), max(y)), log, axis[1:]))
    return out


def sample_std(values) -> float:
    """The sample standard deviation (n − 1 in the denominator) of ``values``; 0 for one value."""
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


def pareto(times, errors) -> list[int]:
    """Indices of the runs not beaten in both wall time and error, by increasing time."""
    order = sorted((i for i in range(len(times)) if math.isfinite(errors[i]) and errors[i] > 0),
                   key=lambda i: (times[i], errors[i]))
    front, best = [], math.inf
    for i in order:
        if errors[i] < best:
            front.append(i)
            best = errors[i]
    return front

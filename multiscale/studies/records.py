"""Run records on disk: one JSON file ``<folder>/runs/<key>.json`` per run, written atomically by
the worker (or by ``running`` for a run that crashed or timed out). A run that completed
(``"ran": true``) keeps every metric it produced and is judged by the study's metrics when read:
a misspelt metric of a scene's history, corrected in the study file, needs no new run."""
from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from multiscale.schema import FrozenMap, suggest
from multiscale.studies.expand import Study, StudyRun
from multiscale.studies.problems import PROBLEMS

__all__ = ["FAILED", "JIT_SHARE", "NUMBERS", "foreign_records", "json_default", "metric_problem", "read_json",
           "read_records", "record_path", "write_json"]

FAILED = "failed"              # a record's status when the run did not produce its metrics
JIT_SHARE = 0.05               # a first timing with more than this share in numba's compiler is timed again
MAX_LISTED = 12                # metrics named in the message of a run that lacks one
NUMBERS = ("wall_time", "cpu_time", "peak_memory_mb", "base_memory_mb", "jit_time", "iterations", "repeat")


def record_path(study: Study, run: StudyRun) -> Path:
    """Where the record of ``run`` lives."""
    return study.folder / "runs" / f"{run.key}.json"


def metric_problem(metrics: dict, names, undefined=frozenset(), asked=()) -> str | None:
    """Why a run's ``metrics`` (name -> value) do not give the study's metric ``names``; None if they do.
    Names every metric missing (before: the first; a user trial's second misspelt one came a run later).
    A metric in ``undefined`` (``Problem.undefined``) may be NaN: what it measures is absent. ``asked``:
    the metrics the run was asked for when it ran; missing, they are not of a run older than the
    metric (--rerun-failed was advised for them, and ran them alike: a user trial)."""
    missing = {name: suggest(name, metrics) for name in names if name not in metrics}    # misspelt: fix them,
    if missing:                                                                          # records are judged on read
        available = sorted(metrics)           # a scene's history: ~180 names, in every failed run's line
        shown = ", ".join(available[:MAX_LISTED]) + (f", ... ({len(available)} in all: the run's record lists them)"
                                                     if len(available) > MAX_LISTED else "")
        listed = ", ".join('"' + name + '"' + hint for name, hint in missing.items())
        return (f"metric{'s' if len(missing) > 1 else ''} {listed} not produced"
                + (" (fix the name: the runs need not run again)" if any(missing.values()) else
                   " (the run does not write it: an effect or output it needs is not in the scene?)"
                   if set(missing) <= set(asked)
                   else " (a run older than the metric: --rerun-failed recomputes it)") + f"; available: {shown}")
    for name in names:
        value = metrics[name]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return f'metric "{name}" is {value!r} (not a number)'
        if not math.isfinite(value) and not (name in undefined and math.isnan(value)):
            return f'metric "{name}" is {value} (not finite)'
    return None


def _well_formed(record) -> bool:
    """Whether a record read back has the shape a run writes: a table whose metrics are a table and
    whose times, memory and iterations are numbers, whose warnings a list of texts (a record edited
    or written by hand may not be)."""
    if not isinstance(record, dict) or not isinstance(record.get("metrics", {}), dict):
        return False
    if not (isinstance(found := record.get("warnings", []), list) and all(isinstance(w, str) for w in found)):
        return False
    return all(isinstance(record.get(k, 0), (int, float)) and not isinstance(record.get(k, 0), bool) for k in NUMBERS)


def read_records(study: Study) -> dict:
    """key -> record of the runs of ``study`` recorded on disk; a run that completed is ok or failed
    by the study's metrics now; one timed fewer times than the study's ``repeat`` now is left out
    (it runs again: its wall time would not be the best of that many)."""
    out = {}
    for run in study.runs:
        p = record_path(study, run)
        if p.is_file():
            try:
                record = read_json(p)
            except ValueError:
                continue                  # a torn file: treat the run as not done
            if not _well_formed(record):
                continue                  # valid JSON of another shape: the same
            if record.get("ran") or record.get("status") == "ok":
                if record.get("repeat", 1) < study.options.repeat:
                    continue
                why = metric_problem(record.get("metrics", {}), study.metrics, PROBLEMS[study.problem].undefined,
                                     record["asked"] if isinstance(record.get("asked"), list) else ())
                record.update(status=FAILED if why else "ok", error=why or "")
            out[run.key] = record
    return out


def foreign_records(study: Study) -> int:
    """Records in the study's folder of runs it does not have: the study file changed since they
    ran (a fixed value, a swept one taken out) or another study shares the folder. Kept (a change
    undone finds them again) and left out of the tables."""
    keys = {run.key for run in study.runs}
    return sum(p.stem not in keys for p in (study.folder / "runs").glob("*.json"))


def write_json(path: Path, data) -> None:
    """Atomic write (a reader never sees half a record) of strict JSON: a number that is not finite
    (a scene's history column of NaN) is written null, which ``read_json`` reads back as NaN
    (``NaN`` itself is no JSON: jq and JavaScript refused the records; a user trial)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(_strict(data), indent=1, sort_keys=True, default=json_default, allow_nan=False))
    os.replace(tmp, path)


def read_json(path: Path):
    """A record or cached reference written by ``write_json``: null in its number fields, its
    metrics, reference values and wall times is NaN again (earlier records' bare NaN reads too)."""
    data = json.loads(Path(path).read_text())
    if isinstance(data, dict):
        for key in NUMBERS:
            if key in data and data[key] is None:
                data[key] = math.nan
        for key in ("metrics", "reference", "values"):
            if isinstance(data.get(key), dict):
                data[key] = {k: math.nan if v is None else v for k, v in data[key].items()}
        if isinstance(data.get("wall_times"), list):
            data["wall_times"] = [math.nan if v is None else v for v in data["wall_times"]]
    return data


def _strict(value):
    """``value`` with every non-finite float (numpy's included) replaced by None, tables and lists walked."""
    if isinstance(value, Mapping):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict(v) for v in value]
    if isinstance(value, (float, np.floating)) and not math.isfinite(value):
        return None
    return value


def json_default(value):
    """JSON form of numpy scalars, paths, tuples and ``FrozenMap`` (``json.dumps(default=...)``)."""
    if hasattr(value, "item"):
        return value.item()
    if isinstance(value, (Path, tuple, FrozenMap)):
        return str(value) if isinstance(value, Path) else list(value) if isinstance(value, tuple) else dict(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


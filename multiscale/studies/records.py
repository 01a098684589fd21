"""Run records on disk: one JSON file ``<folder>/runs/<key>.json`` per run, written atomically by
the worker (or by ``running`` for a run that crashed or timed out)."""
from __future__ import annotations

import json
import os
from pathlib import Path

from multiscale.schema import FrozenMap
from multiscale.studies.expand import Study, StudyRun

__all__ = ["FAILED", "json_default", "read_records", "record_path", "write_json"]

FAILED = "failed"              # a record's status when the run did not produce its metrics


def record_path(study: Study, run: StudyRun) -> Path:
    """Where the record of ``run`` lives."""
    return study.folder / "runs" / f"{run.key}.json"


def read_records(study: Study) -> dict:
    """key -> record of the runs of ``study`` recorded on disk."""
    out = {}
    for run in study.runs:
        p = record_path(study, run)
        if p.is_file():
            try:
                out[run.key] = json.loads(p.read_text())
            except ValueError:
                continue                  # a torn file: treat the run as not done
    return out


def write_json(path: Path, data) -> None:
    """Atomic write (a reader never sees half a record)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True, default=json_default))
    os.replace(tmp, path)


def json_default(value):
    """JSON form of numpy scalars, paths, tuples and ``FrozenMap`` (``json.dumps(default=...)``)."""
    if hasattr(value, "item"):
        return value.item()
    if isinstance(value, (Path, tuple, FrozenMap)):
        return str(value) if isinstance(value, Path) else list(value) if isinstance(value, tuple) else dict(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


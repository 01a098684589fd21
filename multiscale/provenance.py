"""Provenance of a results folder: the scene as given, the scene resolved with every default, and a
record of the run (versions, command line, ranks, start and end, wall time per stage).

``resolved_toml(scene)`` writes a validated scene back as TOML, every key the schema knows with its
value (defaults filled in, SI numbers, the unit as a comment; temperatures as "... K" strings,
since the scene format refuses bare temperatures): loading it gives the same scene. ``versions()``
lists the software of the process (DOLFINx, PETSc and SLEPc when they are loaded). ``write`` puts
``scene.toml``, ``scene_resolved.toml`` and ``provenance.json`` into a folder (rank 0); the
record identifies the code (``code``: its files' digest, a git commit), the environment variables
that change a run (``environment``) and the bytes of every input file (``input_digests``). A run
stopped and resumed (``--resume``) is recorded part by part: ``parts`` lists each part's command,
ranks, start, end, status and stage wall times, and the record's stage and total wall times are
their sums (``parts_of`` reads the parts recorded before).
"""
from __future__ import annotations

import dataclasses
import datetime
import functools
import hashlib
import json
import math
import os
import platform
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import multiscale
from multiscale import __version__
from multiscale.checkpoint import file_digest
from multiscale.geometry import Rotation
from multiscale.io import replacing
from multiscale.outputs import plan
from multiscale.schema import (Choice, Curve, Either, FilePath, ListOf, Named, OnlyWith, Quantity, Section, TableOr,
                               Tables, fields_of)
from multiscale.scene import EFFECTS, FIG_7_9_CALIBRATION, FIG_7_9_WEAR_RATE, Scene, default_wear_rate
from multiscale.scene_geometry import FileGeometry, LengthUnit, Points

RUNNING = "running (or killed: no end was recorded)"      # status of a run's first record
LENGTH_UNITS = {1.0: "m", 1e-3: "mm", 1e-2: "cm", 1e-6: "um", 0.0254: "in", 0.3048: "ft"}


# ------------------------------------------------------------------ the resolved scene
def _scalar(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "inf" if v == math.inf else "-inf" if v == -math.inf else "nan" if math.isnan(v) else repr(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_scalar(x) for x in v) + "]"
    return json.dumps(str(v), ensure_ascii=False)


def _value(parser, v):
    """(TOML-ready value, unit comment) of a parsed value."""
    if isinstance(v, frozenset):
        return [e for e in EFFECTS if e in v], ""
    if isinstance(parser, Quantity):
        if parser.kind.needs_unit or parser.kind.unit_advised:     # (a bare number would be refused, warned of)
            return f"{v!r} {parser.kind.si}", ""
        return float(v), parser.kind.si
    if isinstance(parser, Either):
        for p in parser.parsers:
            if isinstance(p, Choice) and v in p.options or isinstance(p, Quantity) and not isinstance(v, str):
                return _value(p, v)
    if isinstance(parser, TableOr):
        return _value(parser.table if isinstance(v, tuple) else parser.value, v)
    if isinstance(parser, Curve):
        rows = [[_value(parser.x, x)[0], _value(parser.y, y)[0]] for x, y in v]
        return rows, f"[{parser.x_name}, {parser.y_name}] in [{_column_unit(parser.x, v[0][0])}, " \
                     f"{_column_unit(parser.y, v[0][1])}]"
    if isinstance(parser, Points):
        return [[float(c) for c in point] for point in v], "m"
    if isinstance(parser, ListOf):           # also Pair, Vector
        items = [_value(parser.item, x) for x in v]
        return [x for x, _ in items], (items[0][1] if items else "")
    if isinstance(parser, FilePath):
        return str(v), ""
    if isinstance(parser, LengthUnit):
        return next((n for size, n in LENGTH_UNITS.items() if math.isclose(size, v)), f"{v!r} m"), ""
    return v, ""


def _column_unit(parser, v) -> str:
    """The unit of a table column for its comment: a temperature's K (its values carry it), "-" if none."""
    if isinstance(parser, Quantity) and (parser.kind.needs_unit or parser.kind.unit_advised):
        return parser.kind.si
    return _value(parser, v)[1] or "-"


def _table(cls, obj) -> dict:
    """{key: (value, comment) or sub-table dict or list of sub-table dicts} of a schema dataclass."""
    out = {}
    unused = {k for rule in getattr(cls, "rules", ()) if isinstance(rule, OnlyWith)
              and all(getattr(obj, a) is None for a in rule.key)
              for k in rule.keys}            # defaults of keys allowed only with an absent one
    for name, spec in fields_of(cls):
        v = getattr(obj, name)
        if v is None or (isinstance(v, str) and v == "") or name in unused:     # "": no description
            continue
        parser = spec.parser
        if isinstance(parser, Named):      # [interfaces.<name>] with their merged sub-tables (before: dropped)
            if v:
                out[name] = _section(name, parser, v) if name == "interfaces" else \
                    {n: _table(parser.cls, t) for n, t in v.items()}
        elif isinstance(parser, Tables):
            if v:
                out[name] = [_table(parser.cls, t) for t in v]
        elif isinstance(parser, Section):
            out[name] = _section(name, parser, v)
        else:
            out[name] = _value(parser, v)
    return out


def _section(name, parser, v) -> dict:
    if name == "geometry":
        limit = {"max_cells": (v.max_cells, "")}
        if isinstance(v.params, FileGeometry):
            return {**_table(FileGeometry, v.params), **limit}
        params = {k: (x if isinstance(x, int) else float(x), "") for k, x in v.resolved().items()}
        motion = v.spec.motion       # the axis as turned (geometry.axis) and every part's material
        axis = {"axis": ([float(a) + 0.0 for a in motion.axis], "")} if isinstance(motion, Rotation) else {}   # not -0
        materials = {"part_materials": {r.name: (r.material, "") for b in v.spec.bodies for r in b.regions}}
        return {"builder": (v.builder, ""), **params, **axis, **limit, **materials}
    if name == "interfaces":
        out = {}
        for n, s in v.items():
            table = _table(type(s), s)
            for sub in ("roughness", "micro"):
                if getattr(s, sub) is not None:
                    table[sub] = _table(type(getattr(s, sub)), getattr(s, sub))
            out[n] = table
        return out
    return _table(parser.cls, v)


def _emit(table: dict, path: tuple = ()) -> list[str]:
    lines, subs = [], []
    for k, v in table.items():
        if isinstance(v, tuple):
            value, unit = v
            text = f"{_key(k)} = {_scalar(value)}"
            lines.append(text + (f"   # {unit}" if unit else ""))
        else:
            subs.append((k, v))
    for k, v in subs:
        where = path + (k,)
        if isinstance(v, list):
            for item in v:
                lines += ["", f"[[{'.'.join(map(_key, where))}]]"] + _emit(item, where)
        elif v and all(isinstance(x, dict) for x in v.values()) and not any(isinstance(x, tuple) for x in v.values()):
            for n, item in v.items():                       # named tables ([materials.pin])
                lines += ["", f"[{'.'.join(map(_key, where + (n,)))}]"] + _emit(item, where + (n,))
        else:
            lines += ["", f"[{'.'.join(map(_key, where))}]"] + _emit(v, where)
    return lines


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def resolved_toml(scene: Scene) -> str:
    """The scene as TOML with every key the schema knows (see module docstring)."""
    head = ["# The scene as multiscale read it: every default filled in, SI units (unit in the comment).",
            f"# Read from {scene.source}" if scene.source else "# Read from text (no file)."]
    filled = default_wear_rate(scene)          # the default k_w(T) table that runs: written out, and said
    head += [f"# warning: {w}" for w in scene.warnings if w not in filled]
    if filled:
        scene = dataclasses.replace(scene, wear=dataclasses.replace(scene.wear, k_w_table=FIG_7_9_WEAR_RATE))
    if scene.wear is not None and scene.wear.k_w_table == FIG_7_9_WEAR_RATE:
        head.append(f"# wear.k_w_table is the default table: {FIG_7_9_CALIBRATION}")
    return "\n".join(head + [""] + _emit(_table(Scene, scene))) + "\n"


# ------------------------------------------------------------------ versions and the record
def versions() -> dict:
    """Versions of Python, multiscale and the libraries of this process."""
    out = {"python": platform.python_version(), "multiscale": __version__}
    for name in ("numpy", "scipy", "h5py", "mpi4py", "numba", "matplotlib", "gmsh"):
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    loaded = sys.modules
    if "dolfinx" in loaded:
        out["dolfinx"] = loaded["dolfinx"].__version__
    if "petsc4py" in loaded:
        out["petsc"] = ".".join(map(str, loaded["petsc4py"].PETSc.Sys.getVersion()))
        try:
            from slepc4py import SLEPc   # optional (fem extra); loaded with PETSc, versioned in every run
        except ImportError:
            pass
        else:
            out["slepc"] = ".".join(map(str, SLEPc.Sys.getVersion()))
    if "mpi4py.MPI" in loaded:
        out["mpi"] = loaded["mpi4py.MPI"].Get_library_version().strip().splitlines()[0]
    out["platform"] = platform.platform()
    return out


@functools.cache
def code() -> dict:
    """The code that runs: ``path`` (the package's folder), ``sha1`` of its Python files (relative
    names and bytes, sorted: two copies of one version that differ in a file differ here) and, when
    the package is the ``multiscale`` folder of a git checkout, the ``commit`` checked out (its
    files may differ from it; ``sha1`` is of those that ran). Git's files are read, not git run
    (no process forked from an MPI rank)."""
    package = Path(multiscale.__file__).resolve().parent
    digest = hashlib.sha1()
    for path in sorted(package.rglob("*.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    out = {"path": str(package), "sha1": digest.hexdigest()}
    try:
        commit = git_commit(package.parent / ".git")
    except (OSError, ValueError, UnicodeDecodeError):
        commit = None
    return out | ({"commit": commit} if commit else {})


def git_commit(dot: Path) -> str | None:
    """The commit checked out in the git folder (or worktree file) ``dot``, None without one."""
    if not dot.exists():
        return None
    gitdir = dot if dot.is_dir() else (dot.parent / dot.read_text().split("gitdir:", 1)[1].strip()).resolve()
    head = (gitdir / "HEAD").read_text().strip()
    if not head.startswith("ref: "):
        return head                                            # a detached head
    common = (gitdir / (gitdir / "commondir").read_text().strip()).resolve() if (gitdir / "commondir").is_file() \
        else gitdir
    ref = head[5:]
    for folder in (gitdir, common):
        if (folder / ref).is_file():
            return (folder / ref).read_text().strip()
    packed = common / "packed-refs"
    lines = packed.read_text().splitlines() if packed.is_file() else []
    return next((line.split()[0] for line in lines if line.endswith(" " + ref)), None)


# the environment variables that change a run's numbers or speed, recorded as set
ENVIRONMENT = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "PETSC_OPTIONS", "UCX_TLS",
               "PYTHONHASHSEED")


def environment() -> dict:
    """Those of ``ENVIRONMENT`` and every ``MULTISCALE_*`` variable set in this process."""
    return {k: v for k, v in sorted(os.environ.items()) if k in ENVIRONMENT or k.startswith("MULTISCALE_")}


@functools.lru_cache(maxsize=64)
def _digest(path: str, mtime_ns: int, size: int) -> str:
    return file_digest(path)


def input_digests(scene: Scene) -> dict:
    """{path: SHA-1 of its bytes} of every file the scene reads (``Scene.inputs``: the scene file,
    a geometry file, measured surfaces), each read once per process while unchanged; the scene
    file's are those of the text the run read (``Scene.text``, as scene.toml)."""
    source = scene.source.resolve() if scene.source is not None else None
    out = {}
    for path in sorted(scene.inputs):
        if path == source:
            out[str(path)] = hashlib.sha1(scene.text.encode("utf-8")).hexdigest()
        elif path.is_file():
            stat = path.stat()
            out[str(path)] = _digest(str(path), stat.st_mtime_ns, stat.st_size)
    return out


def now() -> str:
    """The local time, ISO 8601 with its offset."""
    return datetime.datetime.now().astimezone().isoformat(timespec="seconds")


def write(folder: Path, scene: Scene, *, ranks: int, started: str, stages: dict, wall_time: float,
          status: str = "finished", command: list[str] | None = None, analysis: str = "",
          warnings: list[str] = (), earlier: list[dict] = ()) -> list[Path]:
    """``scene.toml`` (the file's text as read when the run began, ``Scene.text``: an edit of the
    file during the run is not the scene that ran; the resolved scene when it came from text),
    ``scene_resolved.toml`` and ``provenance.json`` in ``folder``; call on rank 0. The record names
    the overrides given over the scene file (``scene.load``: a study's point), and lists
    every entry the run writes (``multiscale.outputs.plan``), so that ``results_of`` knows them
    when the folder is overwritten (a failed or interrupted run: those it wrote; its record named a
    script and figures it never wrote, an interrupted squeal analysis its modes); ``warnings``:
    the scene's and the run's (e.g. temperatures
    beyond a material table); status ``RUNNING`` (written as the run begins) has no end time.
    ``earlier``: the parts of the run before this one (a resumed run: ``parts_of`` the folder
    before it wrote); the record's ``parts`` are those and this one (each with the scene's keys it
    ran with that a resume may change, ``free``), its ``start`` the first
    part's, its ``command``, ``ranks``, ``end`` and ``status`` this part's, its stage and total
    wall times [s] the sums over the parts; each part names the code that ran it (``code``'s sha1)."""
    folder, resolved = Path(folder), resolved_toml(scene)
    given = scene.text if scene.source else \
        "# The scene came from text, not a file: here it is as resolved.\n" + resolved
    ran = code()                     # each part's own (a run resumed after a change of the code: a user trial)
    part = {"status": status, "command": list(sys.argv if command is None else command), "directory": os.getcwd(),
            "ranks": ranks,
            "code": ran["sha1"], "start": started, "end": None if status == RUNNING else now(),
            "stage_wall_time_s": {k: round(v, 3) for k, v in stages.items()},
            "total_wall_time_s": None if status == RUNNING else round(wall_time, 3),
            "free": free(tomllib.loads(resolved))}
    parts = [*earlier, part]
    total: dict[str, float] = {}
    for p in parts:
        for k, v in p["stage_wall_time_s"].items():
            total[k] = total.get(k, 0.0) + v
    record = {"status": status, "analysis": analysis, "scene": str(scene.source or scene.name),
              "overrides": {k: v for k, v in scene.overrides}, "command": part["command"],
              "directory": part["directory"], "ranks": ranks,
              "start": parts[0]["start"], "end": part["end"],
              "stage_wall_time_s": {k: round(v, 3) for k, v in total.items()},
              "total_wall_time_s": round(sum(p["total_wall_time_s"] or 0.0 for p in parts), 3), "parts": parts,
              "process": process(),
              "versions": versions(), "code": ran, "environment": environment(), "inputs": input_digests(scene),
              "files": sorted(plan(scene).files), "warnings": list(warnings)}
    texts = {"scene.toml": given, "scene_resolved.toml": resolved}
    if status.startswith(("failed", "interrupted")):     # (a finished run writes its script after the record)
        record["files"] = [n for n in record["files"] if n in texts or n == "provenance.json" or (folder / n).exists()]
    texts["provenance.json"] = json.dumps(record, indent=2, default=str) + "\n"
    for name, text in texts.items():              # each replaced whole: a killed run leaves the earlier one
        with replacing(folder / name) as part:
            part.write_text(text, encoding="utf-8")
    return [folder / name for name in texts]


# a part's keys ("code": the SHA-1 of the package's files, ``code``; "free": ``free``'s keys as it ran)
PART = ("status", "command", "directory", "ranks", "code", "start", "end", "stage_wall_time_s", "total_wall_time_s",
        "free")


def dotted(table: dict, prefix: str = "") -> dict:
    """A TOML table's values by dotted key (arrays of tables as one value)."""
    out = {}
    for key, value in table.items():
        if isinstance(value, dict):
            out.update(dotted(value, f"{prefix}{key}."))
        else:
            out[prefix + key] = value
    return out


def free(resolved: dict) -> dict:
    """Takes out of a resolved scene (``resolved_toml`` read back) the keys a resumed run may change,
    which the checkpoint's fingerprint leaves out (``workflows.output.fingerprint``), and returns them
    by dotted key: ``name``, ``description``, ``geometry.max_cells`` (a limit on the mesh),
    ``wear.limit`` (it ends a run and may be lowered to resume it) and ``output`` but its probes
    (whose history columns a resumed run continues). Each part of a run's record keeps its own."""
    out = {k: resolved.pop(k) for k in ("name", "description") if k in resolved}
    for section, key in (("geometry", "max_cells"), ("wear", "limit")):
        if key in resolved.get(section, {}):
            out[f"{section}.{key}"] = resolved[section].pop(key)
    output = resolved.pop("output", {})
    if "probes" in output:
        resolved["output"] = {"probes": output.pop("probes")}
    return dotted({**out, **({"output": output} if output else {})})


def parts_of(folder: Path) -> list[dict]:
    """The parts of the run recorded in ``folder``'s ``provenance.json`` (``write``), for the record
    of a run that resumes it; a record written before parts were kept is one part; empty when there
    is no readable record."""
    try:
        record = json.loads((Path(folder) / "provenance.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return []
    if not isinstance(record, dict) or "start" not in record:
        return []
    parts = record.get("parts") if isinstance(record.get("parts"), list) else [record]
    return [_part(p) for p in parts if isinstance(p, dict)]


def _part(record: dict) -> dict:
    """A part read back: the keys of ``PART``, its wall times numbers [s] (0 for what is not; the
    total of a part that was killed stays null)."""
    def seconds(v) -> float:
        return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else 0.0
    stages, total = record.get("stage_wall_time_s"), record.get("total_wall_time_s")
    return {**{k: record.get(k) for k in PART}, "total_wall_time_s": None if total is None else seconds(total),
            "stage_wall_time_s": {str(k): seconds(v) for k, v in stages.items()} if isinstance(stages, dict) else {}}


def process(pid: int | None = None) -> dict:
    """The writing process: host name, pid and its start (clock ticks since boot, Linux's
    /proc/<pid>/stat; None elsewhere, and for a process that has ended but was not yet reaped, a
    zombie: ``--resume`` right after a SIGKILL was refused for a moment): with the pid it names one
    process, a reused pid another."""
    pid = os.getpid() if pid is None else int(pid)
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        started = None if fields[0] in ("Z", "X") else int(fields[19])
    except (OSError, IndexError, ValueError):
        started = None
    return {"host": platform.node(), "pid": pid, "started": started}


def writer(folder: Path) -> dict | None:
    """The record of the run writing into ``folder`` now, if another process of this host is
    (its ``provenance.json`` says ``RUNNING`` and that process lives: not a run that was killed);
    else None. Two runs in one folder ended with both failing and one record lost (a long-run
    trial). A process of another host cannot be told alive: None."""
    record = _record_of(folder)
    owner = record.get("process") if record.get("status") == RUNNING else None
    if not isinstance(owner, dict) or owner.get("host") != platform.node() or not isinstance(owner.get("pid"), int):
        return None
    if owner["pid"] == os.getpid():
        return None                   # this process: the Python API's runs, one after another
    if owner.get("started") is not None:
        return record if process(owner["pid"])["started"] == owner["started"] else None
    try:                              # no /proc: the pid alone
        os.kill(owner["pid"], 0)
    except ProcessLookupError:
        return None
    except PermissionError:
        pass
    return record


def entries(n: int) -> str:
    """A count of folder entries for people: "1 entry", "3 entries"."""
    return f"{n} entry" if n == 1 else f"{n} entries"


def record_problem(folder: Path) -> str | None:
    """Why ``folder``'s ``provenance.json`` cannot be read as a run's record ("not JSON: ..."), None if
    it is absent or reads (a user trial's corrupted record: --resume lost the earlier parts without a
    word, --overwrite called the results "not written by a run")."""
    path = Path(folder) / "provenance.json"
    if not path.is_file():
        return None
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return f"{path} cannot be read ({exc})"
    return None if isinstance(record, dict) else f"{path} is not a run's record (a JSON {type(record).__name__})"


def _record_of(folder: Path) -> dict:
    """The earlier run's ``provenance.json`` in ``folder``, {} if none is readable."""
    try:
        record = json.loads((Path(folder) / "provenance.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return record if isinstance(record, dict) else {}


def finished(folder: Path) -> bool:
    """Whether ``folder`` holds the results of a run that finished (its ``provenance.json``)."""
    return str(_record_of(folder).get("status", "")).endswith("finished")


def inputs_in(folder: Path) -> list[str]:
    """Names of the entries of ``folder`` that the earlier run there read as inputs (its scene file,
    when it ran in its own folder: recorded as the copy ``scene.toml`` too)."""
    record = _record_of(folder)
    inputs = {Path(str(p)).resolve() for p in record.get("inputs", {})} if isinstance(record.get("inputs"), dict) \
        else set()
    return sorted(p.name for p in Path(folder).iterdir() if p.resolve() in inputs) if inputs else []


def results_of(folder: Path) -> list[str]:
    """Names of the entries an earlier run recorded writing into ``folder`` (its
    ``provenance.json``, the record itself included), with the ``.part`` files a killed run can
    leave beside them, its own inputs left out (a scene in its own output folder: another scene's
    --overwrite deleted it); empty when there is no readable record (another program's folder)."""
    record = _record_of(folder)
    names = [str(n) for n in record.get("files", [])] if isinstance(record.get("files"), list) else []
    read = set(inputs_in(folder))
    names = [n for n in names if Path(n).name == n and n not in ("", ".", "..") and n not in read]
    return sorted({*names, *(n + ".part" for n in names)} | ({"provenance.json"} if names else set()))


def unrecorded_results(scene, existing) -> list[str]:
    """The entries ``existing`` (names in the scene's output folder) named as one of its run's results
    (``outputs.plan``) that no run recorded writing (``results_of``): the user's own files, which a
    run would write over (before, --overwrite replaced them, saying that the user's entries stay;
    a user trial's own scene.toml and history.h5)."""
    planned, recorded = set(plan(scene).files), set(results_of(scene.output.folder))
    return [n for n in existing if n in planned and n not in recorded]


__all__ = ["RUNNING", "inputs_in", "now", "parts_of", "process", "record_problem", "resolved_toml", "results_of",
           "unrecorded_results",
           "versions", "write", "writer"]

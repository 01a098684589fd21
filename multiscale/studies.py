"""Parametric studies: what accuracy costs in time (``multiscale study STUDY.toml``).

A study file (TOML, validated by ``multiscale.schema`` like a scene: every problem at once, with
did-you-mean) names a problem of ``multiscale.study_problems`` (a micro problem, or ``scene`` with
a base scene whose keys it overrides), the parameters to sweep, the metrics and the reference::

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
                                      # "file" with file = "ref.json" ({metric: value})
    [run]                             # processes, timeout, repeat (best-of wall time), folder
    [report]                          # errors = ["1 %", "5 %"], cases (physical parameters, not
                                      # knobs), average_over (e.g. seeds), folder, title, plots

Runs: each run is a fresh worker process (``python -m multiscale.studies``), so its peak memory
(``ru_maxrss``, children included) is its own; ``[run] processes`` of them at a time, or under
``mpiexec -n N`` the runs are shared out over the ranks. A run's record (wall time, CPU time, peak
memory, iterations, convergence, status, error message, metrics, analytic reference) is one JSON
file ``runs/<key>.json``, ``key`` = hash of the problem and its validated parameters: finished
runs are never recomputed (``--rerun-failed`` retries the failed ones); a failing, crashing or
timed-out run is recorded as failed and the others go on.

Output: ``results.csv`` and ``results.h5`` (one row per run), PNGs of each metric's relative error
|m − m_ref| / |m_ref| against wall time (Pareto front highlighted) and against each knob, and a
Markdown report stating the cheapest run meeting each stated error.
"""
from __future__ import annotations

import csv
import hashlib
import itertools
import json
import math
import os
import platform
import resource
import signal
import subprocess
import sys
import time
import tomllib
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from multiscale.errors import MultiscaleError, SceneError
from multiscale.schema import (Bad, Choice, Context, FilePath, Flag, FrozenMap, Integer, ListOf, Quantity,
                               Section, Text, fields_of, key, read, show, suggest)
from multiscale.units import VALUE, UnitError, parse_unit

__all__ = ["Study", "StudyRun", "load_study", "execute", "collect", "report", "run_studies"]

_RANGE_KEYS = ("start", "stop", "num", "step", "log")
_FAILED = "failed"


# ----------------------------------------------------------------------------- study file schema
class _Values:
    """A TOML table of parameter = value (nested tables become dotted paths, for scene keys)."""

    def describe(self) -> str:
        return "a table of parameter = value"

    def __call__(self, raw, ctx):
        if not isinstance(raw, dict):
            raise Bad(f"must be {self.describe()}")
        return FrozenMap(_flatten(raw))


class _Sweep:
    """``[sweep]`` (one group) or ``[[sweep]]`` (groups combined as a product)."""

    def describe(self) -> str:
        return ('a table [sweep] or tables [[sweep]] of parameter = [values] or {start, stop, num | step, '
                'log}, with combine = "product" | "zip"')

    def __call__(self, raw, ctx):
        groups = [raw] if isinstance(raw, dict) else raw
        if not isinstance(groups, list) or not groups or not all(isinstance(g, dict) for g in groups):
            raise Bad(f"must be {self.describe()}")
        return tuple(FrozenMap(_flatten(g)) for g in groups)


def _is_range(value) -> bool:
    return isinstance(value, dict) and ("start" in value or "stop" in value)


def _flatten(raw: dict, prefix: str = "") -> dict:
    out = {}
    for name, value in raw.items():
        if isinstance(value, dict) and not _is_range(value):
            out.update(_flatten(value, f"{prefix}{name}."))
        else:
            out[prefix + name] = value
    return out


@dataclass(frozen=True)
class Reference:
    """What errors are measured against."""

    kind: str | None = key(Choice(("analytic", "run", "file")), required=True)
    run: FrozenMap | None = key(_Values())          # kind "run": parameter values of the reference run
    file: Path | None = key(FilePath())             # kind "file": JSON {metric: value}

    def problems(self, path, ctx):
        needs = {"run": "run", "file": "file"}.get(self.kind)
        out = [f"{path}.{needs}: missing; needed with {path}.kind = \"{self.kind}\""] \
            if needs and getattr(self, needs) is None else []
        for name in ("run", "file"):
            if name != needs and getattr(self, name) is not None:
                out.append(f"{path}.{name}: only used with {path}.kind = \"{name}\"")
        return out


@dataclass(frozen=True)
class RunOptions:
    processes: int = key(Integer(ge=1), default=1)                  # runs at a time (per MPI rank)
    timeout: float | None = key(Quantity("time", gt=0))             # s per run; none by default
    repeat: int = key(Integer(ge=1), default=1)                     # wall time = best of repeats
    ranks: int = key(Integer(ge=1), default=1)                      # MPI ranks of each scene run
    folder: Path | None = key(FilePath(folder=True))                # default results/<name>


@dataclass(frozen=True)
class ReportOptions:
    errors: tuple = key(ListOf(Quantity("dimensionless", gt=0), min_len=1, unique=True), default=(0.01, 0.05))
    cases: tuple = key(ListOf(Text(), unique=True), default=())         # swept physical parameters
    average_over: tuple = key(ListOf(Text(), unique=True), default=())  # e.g. seeds: mean ± std
    folder: Path | None = key(FilePath(folder=True))                    # default: the run folder
    title: str | None = key(Text())
    plots: bool = key(Flag(), default=True)                             # PNGs (matplotlib)


@dataclass(frozen=True)
class StudyFile:
    name: str | None = key(Text(r"[A-Za-z0-9_.-]+", "a name of letters, digits, _ . -"))
    description: str = key(Text(), default="")
    problem: str | None = key(Text(), required=True)
    scene: Path | None = key(FilePath())
    metrics: tuple | None = key(ListOf(Text(), unique=True, min_len=1), required=True)
    fixed: FrozenMap = key(_Values(), default=FrozenMap())
    sweep: tuple | None = key(_Sweep(), required=True)
    reference: Reference | None = key(Section(Reference))
    run: RunOptions | None = key(Section(RunOptions, always=True))
    report: ReportOptions | None = key(Section(ReportOptions, always=True))


# ----------------------------------------------------------------------------- the validated study
@dataclass(frozen=True)
class StudyRun:
    """One point of the sweep."""

    key: str          # hash of the problem and its validated parameters (the record's name)
    label: dict       # swept knob -> value (SI number, string or list), in sweep order
    raw: dict         # fixed and swept raw values, as the problem parses them
    shown: dict       # swept knob -> the value as the study file wrote it (for tables and plots)


@dataclass(frozen=True)
class Study:
    name: str
    description: str
    source: Path
    problem: str
    scene: Path | None
    metrics: tuple
    knobs: tuple                      # swept parameters, in file order
    axes: tuple                       # knobs varied together: a zip group, or one knob of a product
    fixed: dict
    sweep_text: tuple                 # one line per sweep group, for the report
    runs: tuple                       # StudyRun
    reference: Reference | None
    options: RunOptions
    report: ReportOptions
    folder: Path
    report_folder: Path

    def _with_partners(self, names) -> tuple:
        return tuple(k for axis in self.axes if any(n in axis for n in names) for k in axis)

    @property
    def cases(self) -> tuple:
        """Swept physical parameters (``report.cases`` and their zip partners): not accuracy knobs."""
        return self._with_partners(self.report.cases)

    @property
    def averaged(self) -> tuple:
        """Knobs averaged over in tables and plots (``report.average_over`` and partners)."""
        return self._with_partners(self.report.average_over)


def load_study(path) -> Study:
    """Read, validate and expand a study file; raises SceneError listing every problem."""
    from multiscale.study_problems import PROBLEMS
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot read the study file ({getattr(exc, 'strerror', None) or exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None
    ctx = Context(directory=path.resolve().parent)
    f = read(StudyFile, raw, "", ctx)
    if f.problem is not None and f.problem not in PROBLEMS:
        ctx.problems.append(f"problem = {show(f.problem)}: unknown problem{suggest(f.problem, PROBLEMS)}; "
                            f"known: {', '.join(PROBLEMS)}")
    if ctx.problems:
        raise SceneError(ctx.problems)
    problem = PROBLEMS[f.problem]
    scene_problem = f.problem == "scene"
    if scene_problem != (f.scene is not None):
        raise SceneError("scene: missing; problem \"scene\" needs the base scene file" if scene_problem else
                         f"scene: only used with problem = \"scene\" (problem is \"{f.problem}\")")
    for i, name in enumerate(f.metrics, 1):
        why = problem.check_metric(name)
        if why:
            ctx.problems.append(f"metrics item {i} ({show(name)}): {why}")
    before = len(ctx.problems)
    knobs, values, lines, axes = _expand_groups(f, problem, ctx)
    name = f.name or path.stem
    extra = {"scene": f.scene, "ranks": f.run.ranks} if scene_problem else {}
    runs = _runs(f, problem, knobs, values, extra, ctx) if len(ctx.problems) == before else ()
    if f.reference is not None and runs:
        _check_reference(f, problem, knobs, axes, runs, ctx)
    for option in ("cases", "average_over"):
        for k in getattr(f.report, option):
            if k not in knobs:
                ctx.problems.append(f"report.{option}: \"{k}\" is not a swept parameter{suggest(k, knobs)}; "
                                    f"swept: {', '.join(knobs)}")
    if ctx.problems:
        raise SceneError(list(dict.fromkeys(ctx.problems)))
    folder = f.run.folder or ctx.directory / "results" / name
    return Study(name=name, description=f.description, source=path.resolve(), problem=f.problem, scene=f.scene,
                 metrics=f.metrics, knobs=knobs, axes=axes, fixed=dict(f.fixed), sweep_text=tuple(lines), runs=runs,
                 reference=f.reference, options=f.run, report=f.report, folder=folder,
                 report_folder=f.report.folder or folder)


def _parser_of(problem, name):
    """The schema parser of a micro problem's parameter (None: unknown kind, e.g. scene keys)."""
    params = getattr(problem, "params", None)
    return dict(fields_of(params)).get(name) if params is not None else None


def _names(problem) -> list | None:
    params = getattr(problem, "params", None)
    return [n for n, _ in fields_of(params)] if params is not None else None


def _expand_groups(f: StudyFile, problem, ctx):
    """Swept knobs (file order), one list of value-tuples per group, a text per group, the axes."""
    names = _names(problem)
    where_of = {}
    for name, value in f.fixed.items():
        where_of[name] = "fixed"
        if names is not None and name not in names:
            ctx.problems.append(f"fixed.{name}: unknown parameter of problem \"{f.problem}\"{suggest(name, names)}; "
                                f"allowed: {', '.join(names)}")
        elif names is not None:
            try:
                _parser_of(problem, name).parser(value, ctx)
            except Bad as exc:
                ctx.problems.append(f"fixed.{name} = {show(value)}: {exc}")
    knobs, groups, lines, axes = [], [], [], []
    single = len(f.sweep) == 1
    for i, group in enumerate(f.sweep, 1):
        path = "sweep" if single else f"sweep[{i}]"
        combine = group.get("combine", "product")
        if combine not in ("product", "zip"):
            ctx.problems.append(f"{path}.combine = {show(combine)}: unknown{suggest(str(combine), ('product', 'zip'))}; "
                                "allowed: product, zip")
            continue
        params = {k: v for k, v in group.items() if k != "combine"}
        if not params:
            ctx.problems.append(f"{path}: empty sweep: give at least one parameter = [values]")
            continue
        lists = {}
        for name, value in params.items():
            where = f"{path}.{name}"
            if names is not None and name not in names:
                ctx.problems.append(f"{where}: unknown parameter of problem \"{f.problem}\"{suggest(name, names)}; "
                                    f"allowed: {', '.join(names)}")
                continue
            if name in where_of:
                ctx.problems.append(f"{where}: also given in {where_of[name]}; give it once")
                continue
            where_of[name] = path
            items = _values(value, where, _parser_of(problem, name), ctx, unique=combine == "product")
            if items is not None:
                lists[name] = items
                knobs.append(name)
        if len(lists) != len(params):
            continue
        if combine == "zip":
            sizes = {k: len(v) for k, v in lists.items()}
            if len(set(sizes.values())) > 1:
                ctx.problems.append(f"{path}: combine = \"zip\" needs lists of equal length "
                                    f"({', '.join(f'{k}: {n}' for k, n in sizes.items())})")
                continue
            groups.append([dict(zip(lists, combo)) for combo in zip(*lists.values())])
            axes.append(tuple(lists))
        else:
            groups.append([dict(zip(lists, combo)) for combo in itertools.product(*lists.values())])
            axes += [(k,) for k in lists]
        lines.append(f"{' x '.join(lists) if combine == 'product' else ' with '.join(lists)} "
                     f"({combine}): " + "; ".join(f"{k} = {', '.join(_text(v) for v in vals)}"
                                                  for k, vals in lists.items()))
    return tuple(knobs), groups, lines, tuple(axes)


def _values(value, where, parser, ctx, unique: bool = True) -> list | None:
    """The values of one swept parameter: a list, or a range table (SI numbers)."""
    if isinstance(value, list):
        if not value:
            ctx.problems.append(f"{where} = []: empty sweep: give at least one value")
            return None
        items = value
    elif _is_range(value):
        items = _range(value, where, parser, ctx)
        if items is None:
            return None
    else:
        ctx.problems.append(f"{where} = {show(value)}: must be a list of values or a range "
                            "{start, stop, num | step, log}; a single value goes in [fixed]")
        return None
    if parser is not None:
        bad = []
        for i, item in enumerate(items, 1):
            try:
                parser.parser(item, ctx)
            except Bad as exc:
                bad.append(f"item {i} ({show(item)}): {exc}")
        if bad:
            ctx.problems.append(f"{where} = {show(value)}: " + "; ".join(bad))
            return None
    if unique and len({json.dumps(_norm(v, parser)) for v in items}) != len(items):
        ctx.problems.append(f"{where} = {show(value)}: values must not repeat")
        return None
    return list(items)


def _range(spec: dict, where, parser, ctx) -> list | None:
    unknown = [k for k in spec if k not in _RANGE_KEYS]
    if unknown:
        ctx.problems.append(f"{where}.{unknown[0]}: unknown key of a range{suggest(unknown[0], _RANGE_KEYS)}; "
                            f"allowed: {', '.join(_RANGE_KEYS)}")
        return None
    text = f"{where} = {{{', '.join(f'{k} = {show(v)}' for k, v in spec.items())}}}"
    if "start" not in spec or "stop" not in spec or ("num" in spec) == ("step" in spec):
        ctx.problems.append(f"{text}: a range needs start, stop and one of num, step")
        return None
    log = spec.get("log", False)
    if not isinstance(log, bool):
        ctx.problems.append(f"{text}: log must be true or false")
        return None
    try:
        start, stop = (_si(spec[k], parser) for k in ("start", "stop"))
        step = _si(spec["step"], parser) if "step" in spec else None
    except (Bad, UnitError) as exc:
        ctx.problems.append(f"{text}: {exc}")
        return None
    integer = (parser is not None and isinstance(parser.parser, Integer)) or \
        all(isinstance(spec[k], int) and not isinstance(spec[k], bool) for k in ("start", "stop", "step") if k in spec)
    num = spec.get("num")
    if num is not None and (isinstance(num, bool) or not isinstance(num, int) or num < 1):
        ctx.problems.append(f"{text}: num must be an integer >= 1")
        return None
    if log and (start <= 0 or stop <= 0):
        ctx.problems.append(f"{text}: a log range needs start and stop > 0")
        return None
    if step is not None:
        if log:
            ctx.problems.append(f"{text}: a log range takes num, not step")
            return None
        if step == 0 or (stop - start) * step < 0:
            ctx.problems.append(f"{text}: step must be non-zero and go from start towards stop")
            return None
        count = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
        values = [start + i * step for i in range(count)]
    elif num == 1:
        values = [start]
    elif log:
        values = [start * (stop / start) ** (i / (num - 1)) for i in range(num)]
    else:
        values = [start + (stop - start) * i / (num - 1) for i in range(num)]
    if integer:
        values = list(dict.fromkeys(int(round(v)) for v in values))
    else:
        values = [float(f"{v:.12g}") for v in values]
    if len(values) > 10000:
        ctx.problems.append(f"{text}: more than 10000 values")
        return None
    return values


def _si(value, parser=None):
    """A number or "<number> <unit>" in SI (by the parameter's kind when known)."""
    if parser is not None and isinstance(parser.parser, Quantity):
        return parser.parser(value, Context())
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise Bad("range bounds must be numbers or \"<number> <unit>\" strings")
    if isinstance(value, str):
        match = VALUE.match(value)
        if not match:
            raise Bad(f"cannot read {show(value)} as a number with a unit")
        factor, offset, _ = parse_unit(match.group(2))
        return float(float(match.group(1)) * factor + offset)
    return value


def _norm(value, parser=None):
    """A value in comparable form: SI number, string, or list of these."""
    if isinstance(value, list):
        return [_norm(v) for v in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value
    try:
        v = _si(value, parser)
    except (Bad, UnitError):
        return value
    return list(v) if isinstance(v, tuple) else v


def _text(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    return str(value)


def _runs(f, problem, knobs, groups, extra, ctx) -> tuple:
    runs, seen = [], {}
    for combo in itertools.product(*groups):
        swept = {k: v for part in combo for k, v in part.items()}
        raw = {**dict(f.fixed), **swept}
        label = {k: _norm(swept[k], _parser_of(problem, k)) for k in knobs}
        local = Context(directory=ctx.directory)
        params = problem.parse(raw, "", local, **extra)
        where = ", ".join(f"{k} = {_text(swept[k])}" for k in knobs)
        ctx.problems.extend(f"{line} (run {where})" for line in local.problems)
        if local.problems:
            continue
        ident = json.dumps({"problem": f.problem, "params": problem.key(params)}, sort_keys=True)
        digest = hashlib.sha256(ident.encode()).hexdigest()[:16]
        if digest in seen:
            ctx.problems.append(f"runs ({seen[digest]}) and ({where}) have the same parameters")
            continue
        seen[digest] = where
        runs.append(StudyRun(digest, label, raw, {k: _text(swept[k]) for k in knobs}))
    return tuple(runs)


def reference_run(runs, label: dict, want: dict, axes) -> StudyRun | None:
    """The run with the values ``want`` and, for the other knobs, those of ``label`` (zip partners
    of a wanted knob follow it)."""
    free = {k for axis in axes if any(w in axis for w in want) for k in axis}
    hits = [r for r in runs if all(r.label[k] == v for k, v in want.items())
            and all(r.label[k] == label[k] for k in label if k not in free)]
    return hits[0] if len(hits) == 1 else None


def _check_reference(f: StudyFile, problem, knobs, axes, runs, ctx):
    ref = f.reference
    if ref.kind == "analytic":
        if not getattr(problem, "exact", None):
            ctx.problems.append(f'reference.kind = "analytic": problem "{f.problem}" has no analytic reference; '
                                'use kind = "run" (a run of the sweep) or "file"')
            return
        missing = [m for m in f.metrics if m not in problem.exact_metrics]
        if missing:
            ctx.problems.append(f'reference.kind = "analytic": no analytic value of {", ".join(missing)} '
                                f'(the problem gives {", ".join(problem.exact_metrics)})')
    elif ref.kind == "run":
        bad = [k for k in ref.run if k not in knobs]
        for k in bad:
            ctx.problems.append(f"reference.run.{k}: not a swept parameter{suggest(k, knobs)}; swept: {', '.join(knobs)}")
        if bad:
            return
        want = {k: _norm(v, _parser_of(problem, k)) for k, v in ref.run.items()}
        for r in runs:
            if reference_run(runs, r.label, want, axes) is None:
                swept = "; ".join(f"{k}: {', '.join(dict.fromkeys(x.shown[k] for x in runs))}" for k in ref.run)
                ctx.problems.append(f"reference.run = {{{', '.join(f'{k} = {_text(v)}' for k, v in ref.run.items())}}}: "
                                    f"not in the sweep (swept {swept})")
                return
    else:
        try:
            values = json.loads(ref.file.read_text())
        except (OSError, ValueError) as exc:
            ctx.problems.append(f"reference.file = \"{ref.file}\": cannot read a JSON object ({exc})")
            return
        if not isinstance(values, dict):
            ctx.problems.append(f"reference.file = \"{ref.file}\": must hold a JSON object {{metric: value}}")
            return
        for m in f.metrics:
            if not isinstance(values.get(m), (int, float)) or isinstance(values.get(m), bool):
                ctx.problems.append(f"reference.file = \"{ref.file}\": no number for metric \"{m}\""
                                    f"{suggest(m, values)}")


# ----------------------------------------------------------------------------- running
@dataclass
class ExecStats:
    """What ``execute`` did on this process (rank)."""

    total: int            # runs in the study
    done: int             # already recorded, skipped
    started: int          # run now
    failed: int           # of those, failed
    wall_time: float      # s


def _record_path(study: Study, run: StudyRun) -> Path:
    return study.folder / "runs" / f"{run.key}.json"


def read_records(study: Study) -> dict:
    """key -> record of the runs of ``study`` recorded on disk."""
    out = {}
    for run in study.runs:
        p = _record_path(study, run)
        if p.is_file():
            try:
                out[run.key] = json.loads(p.read_text())
            except ValueError:
                continue                  # a torn file: treat the run as not done
    return out


def _write_json(path: Path, data) -> None:
    """Atomic write (a reader never sees half a record)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=True, default=_json_default))
    os.replace(tmp, path)


def _json_default(value):
    if hasattr(value, "item"):
        return value.item()
    if isinstance(value, (Path, tuple, FrozenMap)):
        return str(value) if isinstance(value, Path) else list(value) if isinstance(value, tuple) else dict(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def _child_env() -> dict:
    """The worker's environment: an MPI singleton (no launcher variables), one thread."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PMI_", "PMIX_", "HYDRA_", "OMPI_", "MPI_LOCAL", "MPIR_"))}
    env.setdefault("OMP_NUM_THREADS", "1")
    env.setdefault("MPLBACKEND", "Agg")
    return env


def _world():
    """MPI.COMM_WORLD when launched by mpiexec with several ranks, else None (no MPI init)."""
    if not any(k in os.environ for k in ("PMI_SIZE", "PMI_RANK", "OMPI_COMM_WORLD_SIZE", "PMIX_RANK")):
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        return None
    return MPI.COMM_WORLD if MPI.COMM_WORLD.size > 1 else None


def execute(study: Study, *, rerun_failed: bool = False, progress: bool = True, comm=None) -> ExecStats:
    """Run the study's runs that have no record (and failed ones with ``rerun_failed``), each in a
    fresh worker process, ``options.processes`` at a time; with ``comm``, runs are shared out
    round-robin over its ranks (collective)."""
    start = time.perf_counter()
    rank, size = (comm.rank, comm.size) if comm is not None else (0, 1)
    if rank == 0:
        (study.folder / "runs").mkdir(parents=True, exist_ok=True)
    if comm is not None:
        comm.barrier()
    records = read_records(study)
    todo = [r for r in study.runs if not _done(records.get(r.key), study.metrics, rerun_failed)]
    mine = todo[rank::size]
    bar = None
    if progress and rank == 0 and mine:
        from tqdm import tqdm
        bar = tqdm(total=len(mine), desc=study.name, unit="run")
    failed = 0
    queue, running = list(mine), {}
    try:
        while queue or running:
            while queue and len(running) < study.options.processes:
                run = queue.pop(0)
                running[_spawn(study, run, rank)] = (run, time.monotonic())
            time.sleep(0.05)
            for proc, (run, t0) in list(running.items()):
                timeout = study.options.timeout
                if proc.poll() is None and not (timeout and time.monotonic() - t0 > timeout):
                    continue
                if proc.poll() is None:
                    _kill(proc)
                    _failed_record(study, run, f"timed out after {timeout:g} s (run.timeout)")
                elif proc.returncode != 0 or not _record_path(study, run).is_file():
                    _failed_record(study, run, _crash_message(study, run, proc.returncode))
                del running[proc]
                failed += json.loads(_record_path(study, run).read_text()).get("status") == _FAILED
                log = study.folder / "runs" / f"{run.key}.log"
                if log.is_file() and not log.stat().st_size:
                    log.unlink()
                if bar is not None:
                    bar.update()
    finally:
        for proc in running:
            _kill(proc)
        if bar is not None:
            bar.close()
    if comm is not None:
        comm.barrier()
    return ExecStats(len(study.runs), len(study.runs) - len(todo), len(mine), failed, time.perf_counter() - start)


def _done(record, metrics, rerun_failed: bool) -> bool:
    """A run is done if it failed (unless retried) or recorded every metric the study asks for
    (a study may ask for a new metric of a scene history after its runs were made)."""
    if record is None:
        return False
    if record.get("status") == _FAILED:
        return not rerun_failed
    return all(m in record.get("metrics", {}) for m in metrics)


def _spawn(study: Study, run: StudyRun, rank: int) -> subprocess.Popen:
    workdir = study.folder / "runs" / run.key
    task = {"problem": study.problem, "raw": run.raw, "label": run.label, "key": run.key,
            "metrics": list(study.metrics), "repeat": study.options.repeat,
            "exact": study.reference is not None and study.reference.kind == "analytic",
            "record": str(_record_path(study, run)), "workdir": str(workdir),
            "references": str(study.folder / "references"), "directory": str(study.source.parent), "rank": rank}
    if study.problem == "scene":
        task.update(scene=str(study.scene), ranks=study.options.ranks)
    _record_path(study, run).unlink(missing_ok=True)          # a failed run being retried
    log = open(study.folder / "runs" / f"{run.key}.log", "w")
    try:
        return subprocess.Popen([sys.executable, "-m", "multiscale.studies", json.dumps(task, default=_json_default)],
                                stdout=log, stderr=subprocess.STDOUT, env=_child_env(), start_new_session=True)
    finally:
        log.close()


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.wait()


def _crash_message(study, run, code) -> str:
    log = study.folder / "runs" / f"{run.key}.log"
    lines = [line for line in (log.read_text(errors="replace").splitlines() if log.is_file() else []) if line.strip()]
    if code is not None and code < 0:
        name = signal.Signals(-code).name if -code in signal.Signals._value2member_map_ else str(-code)
        why = f"worker killed by {name}" + (" (out of memory?)" if -code == signal.SIGKILL else "")
    else:
        why = f"worker exited with code {code} without a record"
    return why + (f": {lines[-1].strip()}" if lines else "")


def _failed_record(study, run, message) -> None:
    _write_json(_record_path(study, run), {"key": run.key, "problem": study.problem, "label": run.label,
                                           "status": _FAILED, "error": message, "metrics": {},
                                           "finished": _now()})


def _now() -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S")


def _peak_mb() -> float:
    """Peak resident memory [MB] of this process and of its finished children (ru_maxrss)."""
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(own, kids) / 1024.0


def _cpu() -> float:
    total = 0.0
    for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN):
        u = resource.getrusage(who)
        total += u.ru_utime + u.ru_stime
    return total


def _worker(task: dict) -> int:
    """One run in this (fresh) process: parse, run ``repeat`` times, write the record."""
    import multiscale
    from multiscale.study_problems import problem as get_problem
    record = {"key": task["key"], "problem": task["problem"], "label": task["label"], "status": _FAILED,
              "metrics": {}, "started": _now(), "repeat": task["repeat"], "python": platform.python_version(),
              "multiscale": multiscale.__version__, "cpus": os.cpu_count(), "rank": task["rank"]}
    try:
        problem = get_problem(task["problem"])
        ctx = Context(directory=Path(task["directory"]))
        extra = {"scene": task["scene"], "ranks": task["ranks"]} if "scene" in task else {}
        params = problem.parse(task["raw"], "", ctx, **extra)
        if ctx.problems:
            raise SceneError(ctx.problems)
        record["params"] = problem.key(params)
        workdir = Path(task["workdir"])
        problem.prepare()
        record["base_memory_mb"] = _peak_mb()
        times, cpu0 = [], _cpu()
        for _ in range(task["repeat"]):
            t0 = time.perf_counter()
            outcome = problem.run(params, workdir)
            times.append(time.perf_counter() - t0)
        record.update(wall_time=min(times), wall_times=times, cpu_time=(_cpu() - cpu0) / len(times),
                      peak_memory_mb=_peak_mb(), iterations=int(outcome.iterations),
                      converged=bool(outcome.converged))
        metrics = {k: float(v) for k, v in outcome.metrics.items()}
        record["metrics"] = metrics
        for name in task["metrics"]:
            if name not in metrics:
                raise MultiscaleError(f"metric \"{name}\" not produced{suggest(name, metrics)}; "
                                      f"available: {', '.join(sorted(metrics))}")
            if not math.isfinite(metrics[name]):
                raise MultiscaleError(f"metric \"{name}\" is {metrics[name]} (not finite)")
        record.update(status="ok", error="")
        if task["exact"]:
            record["reference"] = _exact(problem, params, Path(task["references"]))
    except Exception as exc:       # recorded, never raised: the study goes on
        text = str(exc).strip().splitlines()
        record.update(status=_FAILED, error=f"{type(exc).__name__}: {text[0] if text else ''}".strip(),
                      traceback=traceback.format_exc())
    record["finished"] = _now()
    record.setdefault("peak_memory_mb", _peak_mb())
    _write_json(Path(task["record"]), record)
    return 0


def _exact(problem, params, folder: Path) -> dict:
    """The problem's analytic reference, cached on disk by the parameters it depends on."""
    ident = json.dumps(problem.exact_key(params), sort_keys=True)
    path = folder / f"{problem.name}-{hashlib.sha256(ident.encode()).hexdigest()[:16]}.json"
    if path.is_file():
        return json.loads(path.read_text())["values"]
    values = {k: float(v) for k, v in problem.exact(params).items()}
    folder.mkdir(parents=True, exist_ok=True)
    _write_json(path, {"params": json.loads(ident), "values": values})
    return values


# ----------------------------------------------------------------------------- results
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


def relative_error(value: float, ref: float) -> float:
    """|value − ref| / |ref| (|value − ref| when ref = 0)."""
    return abs(value - ref) / abs(ref) if ref != 0 else abs(value - ref)


def collect(study: Study) -> list[Row]:
    """Rows of the recorded runs, with reference values and relative errors."""
    records = read_records(study)
    rows = [Row(r, records.get(r.key, {"status": "missing", "error": "not run", "metrics": {}})) for r in study.runs]
    ref = study.reference
    if ref is None:
        return rows
    by_key = {row.run.key: row for row in rows}
    fixed = json.loads(ref.file.read_text()) if ref.kind == "file" else None
    from multiscale.study_problems import PROBLEMS
    want = {k: _norm(v, _parser_of(PROBLEMS[study.problem], k)) for k, v in (ref.run or {}).items()}
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
                row.note = "reference run failed"
            elif target is row:
                row.note, row.is_reference = "reference run", True
        for m in study.metrics:
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
        if study.reference is not None:
            cols[f"{m}_reference"] = [r.reference.get(m, math.nan) for r in rows]
            cols[f"{m}_error"] = [r.errors.get(m, math.nan) for r in rows]
    if study.reference is not None:
        cols["max_error"] = [r.max_error for r in rows]
    for name in ("wall_time", "cpu_time", "peak_memory_mb"):
        cols[name] = [float(r.record.get(name, math.nan)) for r in rows]
    cols["iterations"] = [int(r.record.get("iterations", -1)) for r in rows]
    cols["converged"] = [bool(r.record.get("converged", False)) for r in rows]
    cols["message"] = [r.record.get("error", "") or r.note for r in rows]
    return cols


def _cell(value):
    return json.dumps(value) if isinstance(value, list) else value


def write_tables(study: Study, rows: list[Row]) -> tuple[Path, Path]:
    """results.csv and results.h5 (one dataset per column, one row per run)."""
    import h5py
    import numpy as np
    cols = _columns(study, rows)
    study.folder.mkdir(parents=True, exist_ok=True)
    csv_path, h5_path = study.folder / "results.csv", study.folder / "results.h5"
    with open(csv_path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for i in range(len(rows)):
            w.writerow([_csv(cols[c][i]) for c in cols])
    with h5py.File(h5_path, "w") as h5:
        for name, values in cols.items():
            if all(isinstance(v, (int, float, bool)) for v in values):
                h5.create_dataset(name, data=np.asarray(values))
            else:
                h5.create_dataset(name, data=[str(v) for v in values], dtype=h5py.string_dtype())
        h5.attrs.update(study=study.name, problem=study.problem, source=str(study.source),
                        reference=_reference_text(study), metrics=list(study.metrics), knobs=list(study.knobs))
    return csv_path, h5_path


def _csv(value):
    return f"{value:.10g}" if isinstance(value, float) else value


# ----------------------------------------------------------------------------- report
def _reference_text(study: Study) -> str:
    ref = study.reference
    if ref is None:
        return "none (a parametric study)"
    if ref.kind == "analytic":
        from multiscale.study_problems import PROBLEMS
        doc = (PROBLEMS[study.problem].exact.__doc__ or "").strip().splitlines()
        return "the problem's own reference" + (f": {doc[0].rstrip('.')}" if doc else "")
    if ref.kind == "file":
        return f"stored result {ref.file.name}"
    return "the run with " + ", ".join(f"{k} = {_text(v)}" for k, v in ref.run.items()) + \
        (" (other parameters unchanged)" if len(ref.run) < len(study.knobs) else "")


def _case_key(study: Study, row: Row) -> tuple:
    return tuple(row.run.shown[k] for k in study.cases)


def cheapest(study: Study, rows: list[Row]) -> list[dict]:
    """Per stated error and case: the run of least wall time whose worst error meets it."""
    out = []
    cases = list(dict.fromkeys(_case_key(study, r) for r in rows))
    for tol in study.report.errors:
        for case in cases:
            pool = [r for r in rows if r.ok and _case_key(study, r) == case]
            good = [r for r in pool if math.isfinite(r.max_error) and r.max_error <= tol]
            best = min(good, key=lambda r: r.record["wall_time"]) if good else None
            refs = [r for r in pool if r.is_reference]
            base = refs[0] if refs else (max(pool, key=lambda r: r.record["wall_time"]) if pool else None)
            out.append({"error": tol, "case": case, "row": best, "base": base})
    return out


def _pct(v: float) -> str:
    return "n/a" if not math.isfinite(v) else f"{100 * v:.3g} %"


def _num(v) -> str:
    return _text(v) if not isinstance(v, float) or math.isfinite(v) else "n/a"


def report(study: Study, rows: list[Row], command: str = "") -> Path:
    """Markdown report and PNGs in ``study.report_folder``; returns the Markdown path."""
    folder = study.report_folder
    folder.mkdir(parents=True, exist_ok=True)
    pngs = plot(study, rows, folder)
    from multiscale.study_problems import PROBLEMS
    problem = PROBLEMS[study.problem]
    ok = [r for r in rows if r.ok]
    failed = [r for r in rows if not r.ok]
    lines = [f"# {study.report.title or study.name}", ""]
    if study.description:
        lines += [study.description, ""]
    metric_doc = problem.metrics
    lines += [f"- Problem: `{study.problem}` — {problem.doc}",
              *[f"- Swept: {text}" for text in study.sweep_text],
              f"- Fixed: {', '.join(f'{k} = {_text(v)}' for k, v in study.fixed.items()) or 'problem defaults'}",
              f"- Metrics: " + "; ".join(f"`{m}`" + (f" ({metric_doc[m]})" if m in metric_doc else "")
                                         for m in study.metrics),
              f"- Reference: {_reference_text(study)}"
              + ("; error = |m − m_ref| / |m_ref|" if study.reference else ""),
              f"- Runs: {len(ok)} ok, {len(failed)} failed; {sum(r.record.get('wall_time', 0) for r in ok):.1f} s "
              f"of run wall time in all. Wall time: best of {study.options.repeat} repetition(s) in a fresh "
              "process (one thread); peak memory: the run process's maximum resident set (interpreter and "
              "libraries included; in brackets what the run added to the process's baseline).",
              f"- Generated {_now()} on a {os.cpu_count()}-core machine by `{command or 'multiscale study ' + study.source.name}`.",
              ""]
    if study.reference is not None and ok:
        lines += _cheapest_table(study, rows)
    if study.averaged and ok:
        lines += _average_table(study, ok)
    lines += ["## Runs", ""] + _runs_table(study, rows)
    if failed:
        lines += ["", "Failed runs:", ""] + [f"- {_label_text(r)}: {r.record.get('error', '')}" for r in failed]
    if pngs:
        lines += ["", "## Plots", ""] + [f"![{p.stem}]({p.name})" for p in pngs]
    path = folder / f"{study.name}.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def _memory(record: dict) -> str:
    """Peak memory [MB] and, in brackets, what the run added to its process's baseline."""
    peak, base = record.get("peak_memory_mb", math.nan), record.get("base_memory_mb", math.nan)
    return "n/a" if not math.isfinite(peak) else f"{peak:.0f}" + (f" (+{peak - base:.0f})" if math.isfinite(base) else "")


def _label_text(row: Row) -> str:
    return ", ".join(f"{k} = {v}" for k, v in row.run.shown.items())


def _cheapest_table(study, rows) -> list[str]:
    knobs = [k for k in study.knobs if k not in study.cases]
    head = ["error ≤"] + list(study.cases) + knobs + ["wall time [s]", "peak memory [MB]", "worst error", "time / base"]
    lines = ["## What accuracy costs", "",
             "The cheapest run (least wall time) whose worst error over the metrics meets each stated error; "
             "'time / base' compares it with " + ("the reference run" if study.reference.kind == "run"
                                                  else "the most expensive run") + ".", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for c in cheapest(study, rows):
        r, base = c["row"], c["base"]
        if r is None:
            cells = ["none of the runs"] + [""] * (len(knobs) + 3)
        else:
            speed = r.record["wall_time"] / base.record["wall_time"] if base else math.nan
            cells = [r.run.shown[k] for k in knobs] + [f"{r.record['wall_time']:.3g}", _memory(r.record),
                                                                _pct(r.max_error), f"{speed:.2g}"]
            if r.is_reference:
                cells[-1] += " (only the reference)"
        lines.append("| " + " | ".join([_pct(c["error"]), *c["case"], *cells]) + " |")
    return lines + [""]


def _average_table(study, rows) -> list[str]:
    import numpy as np
    keep = [k for k in study.knobs if k not in study.averaged]
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r.run.shown[k] for k in keep), []).append(r)
    head = keep + [f"{m} mean ± std (min … max)" for m in study.metrics] + ["samples"]
    lines = [f"## Averaged over {', '.join(study.averaged)}", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for label, group in groups.items():
        cells = list(label)
        for m in study.metrics:
            v = np.array([r.record["metrics"][m] for r in group])
            cells.append(f"{v.mean():.4g} ± {v.std():.2g} ({v.min():.4g} … {v.max():.4g})")
        lines.append("| " + " | ".join(cells + [str(len(group))]) + " |")
    return lines + [""]


def _runs_table(study, rows) -> list[str]:
    head = list(study.knobs)
    for m in study.metrics:
        head += [m] + (["error"] if study.reference else [])
    head += ["wall time [s]", "peak memory [MB]", "iterations", "status"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r.run.shown[k] for k in study.knobs]
        for m in study.metrics:
            cells.append(_num(r.record.get("metrics", {}).get(m, math.nan)))
            if study.reference:
                cells.append(_pct(r.errors.get(m, math.nan)))
        rec = r.record
        status = rec.get("status", "")
        if r.ok and not rec.get("converged", True):
            status += " (not converged)"
        if r.note:
            status += f" ({r.note})"
        cells += [_num(float(rec.get("wall_time", math.nan))), _memory(rec),
                  str(rec.get("iterations", "")), status]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


# ----------------------------------------------------------------------------- plots
def _numeric(values) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


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


def plot(study: Study, rows: list[Row], folder: Path) -> list[Path]:
    """PNGs: error vs wall time per metric (Pareto front; with many runs only the front is
    labelled), and per knob: error (or metric) and wall time vs the knob."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = [r for r in rows if r.ok]
    if not ok or not study.report.plots:
        return []
    out = []
    if study.reference is not None:
        out.append(_plot_pareto(plt, study, ok, folder))
    for axis in study.axes:
        if axis[0] not in study.averaged:
            out.append(_plot_axis(plt, study, ok, axis, folder))
    return [p for p in out if p is not None]


def _short(run: StudyRun, skip=()) -> str:
    return ", ".join(v for k, v in run.shown.items() if k not in skip)


def _plot_pareto(plt, study, ok, folder):
    n = len(study.metrics)
    fig, axes = plt.subplots(1, n, figsize=(5.2 * n, 4.3), squeeze=False)
    cases = list(dict.fromkeys(_case_key(study, r) for r in ok))
    drawn = False
    for ax, m in zip(axes[0], study.metrics):
        t = [r.record["wall_time"] for r in ok]
        e = [r.errors.get(m, math.nan) for r in ok]
        front = pareto(t, e)
        labelled = set(range(len(ok))) if len(ok) <= 16 else set(front)
        for c, case in enumerate(cases):
            idx = [i for i, r in enumerate(ok) if _case_key(study, r) == case and math.isfinite(e[i]) and e[i] > 0]
            ax.scatter([t[i] for i in idx], [e[i] for i in idx], color=f"C{c}", s=28, zorder=3,
                       label=", ".join(f"{k} = {v}" for k, v in zip(study.cases, case)) or None)
            for i in (i for i in idx if i in labelled):
                ax.annotate(_short(ok[i].run, study.cases), (t[i], e[i]), fontsize=6,
                            xytext=(3, 3), textcoords="offset points")
        refs = sorted(r.record["wall_time"] for r in ok if r.is_reference)
        if refs:
            ax.axvspan(refs[0], refs[-1], color="green", alpha=0.15, lw=0)
            ax.axvline(refs[len(refs) // 2], color="green", ls=":", label="reference run" + "s" * (len(refs) > 1))
        if front:
            drawn = True
            ax.step([t[i] for i in front], [e[i] for i in front], where="post", color="red", lw=2, alpha=0.6,
                    zorder=2, label="Pareto front")
            ax.set(xscale="log", yscale="log")
        for tol in study.report.errors:
            ax.axhline(tol, color="gray", ls="--", lw=0.8)
            ax.annotate(_pct(tol), (1, tol), xycoords=("axes fraction", "data"), fontsize=7, ha="right",
                        va="bottom", color="gray")
        ax.set(xlabel="wall time [s]", ylabel=f"relative error of {m}", title=m)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=7)
    if not drawn:
        plt.close(fig)
        return None
    fig.suptitle(f"{study.name}: error vs wall time")
    fig.tight_layout()
    path = folder / f"{study.name}_error_vs_time.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _plot_axis(plt, study, ok, axis, folder):
    """Errors (or metric values) and wall time against one axis (a knob, or zipped knobs plotted
    against the first), one line per setting of the other knobs (mean ± std over averaged ones)."""
    import numpy as np
    def point(r):
        return json.dumps([r.run.label[k] for k in axis])
    values = list(dict.fromkeys(point(r) for r in ok))
    raw = [json.loads(v)[0] for v in values]
    numeric = _numeric(raw) and len(set(raw)) == len(raw)    # else categorical, one tick per setting
    xs = {v: (x if numeric else i) for i, (v, x) in enumerate(zip(values, raw))}
    ticks = {point(r): ", ".join(r.run.shown[k] for k in axis) for r in ok}
    log_x = numeric and min(raw) > 0 and max(raw) / min(raw) > 5
    averaged = set(study.averaged)
    others = [k for k in study.knobs if k not in axis and k not in averaged]
    lines = {}
    for r in ok:
        lines.setdefault(tuple(r.run.shown[k] for k in others), []).append(r)
    with_ref = study.reference is not None
    panels = ([("error", m) for m in study.metrics] if with_ref else [("value", m) for m in study.metrics]) \
        + [("time", None)]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.4 * len(panels), 3.9), squeeze=False)
    for ax, (kind, m) in zip(axes[0], panels):
        for c, (other, group) in enumerate(lines.items()):
            pts = {}
            for r in group:
                y = (r.errors.get(m, math.nan) or math.nan if kind == "error" else     # 0: the reference
                     r.record["metrics"][m] if kind == "value" else r.record["wall_time"])
                pts.setdefault(xs[point(r)], []).append(y)
            x = sorted(pts)
            mean = np.array([np.mean(pts[v]) for v in x])
            label = ", ".join(f"{k} = {v}" for k, v in zip(others, other)) if others else None
            if averaged and kind != "error":
                std = np.array([np.std(pts[v]) for v in x])
                ax.errorbar(x, mean, yerr=std, marker="o", ms=4, color=f"C{c % 10}", capsize=3, label=label)
            else:
                ax.plot(x, mean, "o-", ms=4, color=f"C{c % 10}", label=label)
        if kind == "error":
            for tol in study.report.errors:
                ax.axhline(tol, color="gray", ls="--", lw=0.8)
            ax.set_yscale("log")
        if kind == "time":
            ax.set_yscale("log")
        ax.set(xlabel=" / ".join(axis), ylabel={"error": f"relative error of {m}", "value": m, "time": "wall time [s]"}[kind],
               title=m or "cost")
        if log_x:
            ax.set_xscale("log")
        if not numeric:
            ax.set_xticks(range(len(values)), [ticks[v] for v in values], rotation=30, ha="right", fontsize=7)
        ax.grid(True, which="both", alpha=0.25)
        if others and len(lines) <= 8:
            ax.legend(fontsize=6)
    fig.suptitle(f"{study.name}: {' / '.join(axis)}" + (f" (mean ± std over {', '.join(averaged)})" if averaged else ""))
    fig.tight_layout()
    path = folder / f"{study.name}_{axis[0].replace('.', '_')}.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


# ----------------------------------------------------------------------------- several studies
def problems_text() -> str:
    """The registered problems: parameters (``multiscale.schema.reference``) and metrics."""
    from multiscale.schema import reference
    from multiscale.study_problems import PROBLEMS
    lines = []
    for name, problem in PROBLEMS.items():
        lines += ["", f"problem = \"{name}\": {problem.doc}"]
        if getattr(problem, "params", None) is not None:
            lines += ["  parameters ([fixed] and [sweep] keys):"] + ["  " + line for line in reference(problem.params)]
        else:
            lines.append("  parameters: dotted keys of the base scene (scene = \"file.toml\"), e.g. geometry.mesh_size")
        lines += ["  metrics:"] + [f"    {m:<22} {doc}" for m, doc in problem.metrics.items()]
        if getattr(problem, "exact", None):
            lines.append(f"  analytic reference of: {', '.join(problem.exact_metrics)}")
    return "\n".join(lines[1:])


def run_studies(paths, *, rerun_failed: bool = False, report_folder=None, processes: int | None = None,
                progress: bool = True, command: str = "") -> int:
    """Load every study first (all problems reported at once), run them, write tables and reports;
    with ``report_folder`` every report goes there, with an index README.md. Returns the number of
    failed runs."""
    comm = _world()
    studies, problems = [], []
    for path in paths:
        try:
            studies.append(load_study(path))
        except SceneError as exc:
            problems += [f"{path}: {line}" for line in exc.problems] if len(paths) > 1 else exc.problems
    if problems:
        raise SceneError(problems if comm is None or comm.rank == 0 else [])   # one rank speaks
    import dataclasses
    if report_folder is not None:
        studies = [dataclasses.replace(s, report_folder=Path(report_folder).resolve()) for s in studies]
    if processes is not None:
        studies = [dataclasses.replace(s, options=dataclasses.replace(s.options, processes=processes)) for s in studies]
    rank = comm.rank if comm is not None else 0
    failed, summaries = 0, []
    for study in studies:
        stats = execute(study, rerun_failed=rerun_failed, progress=progress, comm=comm)
        if rank != 0:
            continue
        rows = collect(study)
        write_tables(study, rows)
        md = report(study, rows, command)
        bad = sum(not r.ok for r in rows)
        failed += bad
        summaries.append((study, rows, md))
        print(f"{study.name}: {len(rows)} runs ({stats.done} recorded before, {stats.started} run now, "
              f"{bad} failed); table {study.folder / 'results.csv'}; report {md}")
    if rank == 0 and report_folder is not None:
        index = _index(summaries, Path(report_folder).resolve(), command)
        print(f"index {index}")
    return failed


def _index(summaries, folder: Path, command: str) -> Path:
    """README.md of a report folder: per study, its cheapest settings at each stated error."""
    lines = ["# What accuracy costs", "",
             f"Generated {_now()} on a {os.cpu_count()}-core machine by `{command}`. Each study has its own "
             "page (tables of every run, plots of error against wall time with the Pareto front, and against "
             "each knob).", ""]
    for study, rows, md in summaries:
        lines += [f"## [{study.report.title or study.name}]({md.name})", ""]
        if study.description:
            lines += [study.description, ""]
        if study.reference is None:
            lines += ["Parametric study (no reference).", ""]
            continue
        lines += [f"Reference: {_reference_text(study)}. Cheapest setting meeting each error "
                  "(wall time, worst error):", ""]
        found = cheapest(study, rows)
        cases = list(dict.fromkeys(c["case"] for c in found))
        head = ["error ≤"] + ([", ".join(f"{k} = {v}" for k, v in zip(study.cases, case)) for case in cases]
                             if study.cases else ["setting"])
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for tol in study.report.errors:
            cells = [_pct(tol)]
            for c in (c for c in found if c["error"] == tol):
                r = c["row"]
                cells.append("none" if r is None else ", ".join(
                    f"{k} = {r.run.shown[k]}" for k in study.knobs if k not in study.cases)
                    + f" ({r.record['wall_time']:.3g} s, {_pct(r.max_error)})" + (" (the reference)" * r.is_reference))
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    path = folder / "README.md"
    path.write_text("\n".join(lines) + "\n")
    return path


if __name__ == "__main__":  # the worker process of one run
    sys.exit(_worker(json.loads(sys.argv[1])))

"""A validated study: the study file checked against its problem (every problem at once) and the
sweep expanded into runs, each named by the hash of its validated parameters."""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from multiscale.errors import SceneError, read_toml_text, toml_problem
from multiscale.scene_keys import key_parts
from multiscale.schema import Bad, Context, FilePath, Integer, Quantity, fields_of, read, show, suggest
from multiscale.studies.formatting import by_kind, value_text
from multiscale.studies.problems import PROBLEMS
from multiscale.studies.spec import RANGE_KEYS, ReportOptions, Reference, RunOptions, StudyFile, is_range
from multiscale.units import KINDS, VALUE, UnitError, parse_unit

__all__ = ["MAX_RUNS", "Study", "StudyRun", "load_study", "normalise", "parser_of", "reference_run"]

MAX_RUNS = 100_000        # runs a study may make (a range may give 10 000 values)


@dataclass(frozen=True)
class StudyRun:
    """One point of the sweep."""

    key: str          # hash of the problem and its validated parameters (the record's name)
    label: dict       # swept knob -> value (SI number, string or list), in sweep order
    raw: dict         # fixed and swept raw values, as the problem parses them
    shown: dict       # swept knob -> the value as the study file wrote it (for tables and plots)

    @property
    def text(self) -> str:
        """The run in messages and reports: "load = 1 MPa, grid = 64" (its key without knobs)."""
        return ", ".join(f"{k} = {v}" for k, v in self.shown.items()) or self.key


@dataclass(frozen=True)
class Study:
    """A study file validated against its problem and expanded into runs (values in SI)."""

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
    warnings: tuple = ()              # the runs' inputs' warnings (implausible values, ...), one line each
    judged: tuple = ()                # the metrics with a reference value: their errors are computed

    @property
    def unjudged(self) -> tuple:
        """Metrics tabulated without a reference value (a reference file that measured only some)."""
        return tuple(m for m in self.metrics if m not in self.judged) if self.reference is not None else ()

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
    path = Path(path)
    text = read_toml_text(path, "study")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise toml_problem(path, exc, text) from None
    if "effects" in raw and "problem" not in raw:     # (answered with "did you mean" per key: a user trial)
        raise SceneError([f"{path.name}: a scene file (effects = [...], [geometry]), not a study: give it to "
                          "`multiscale check` or `multiscale run`"])
    ctx = Context(directory=path.resolve().parent)
    f = read(StudyFile, raw, "", ctx)
    if f.problem is not None and f.problem not in PROBLEMS:
        ctx.problems.append(f"problem = {show(f.problem)}: unknown problem{suggest(f.problem, PROBLEMS)}; "
                            f"known: {', '.join(PROBLEMS)}")
    scene_problem = f.problem == "scene"
    if f.problem in PROBLEMS and scene_problem != ("scene" in raw):
        ctx.problems.append("scene: missing; problem \"scene\" needs the base scene file" if scene_problem else
                            f"scene: only used with problem = \"scene\" (problem is \"{f.problem}\")")
    known = f.problem in PROBLEMS and not (scene_problem and f.scene is None)
    for i, name in enumerate(f.metrics or () if known else (), 1):     # (before: only once the sweep was right)
        why = PROBLEMS[f.problem].check_metric(name, f.scene, dict(f.fixed))
        if why:
            ctx.problems.append(f"metrics item {i} ({show(name)}): {why}")
    if not known or f.sweep is None:
        raise SceneError(ctx.problems)        # nothing to check the rest against; else every problem at once
    problem = PROBLEMS[f.problem]
    before = len(ctx.problems)
    knobs, values, lines, axes = _expand_groups(f, problem, ctx)
    name = f.name or path.stem
    extra = {"scene": f.scene, "ranks": f.run.ranks} if scene_problem else {}
    runs, warned = _runs(f, problem, knobs, values, extra, ctx) if len(ctx.problems) == before else ((), ())
    ref, judged = f.reference, ()      # checked against the runs when the schema found it whole
    if runs and f.metrics and ref is not None and ref.kind is not None and not ref.problems("reference", ctx):
        judged = _check_reference(f, problem, knobs, axes, runs, ctx)
    for option in ("cases", "average_over"):
        for k in getattr(f.report, option):
            if k not in knobs:
                ctx.problems.append(f"report.{option}: \"{k}\" is not a swept parameter{suggest(k, knobs)}; "
                                    f"swept: {', '.join(knobs)}")
    if ctx.problems:
        raise SceneError(list(dict.fromkeys(ctx.problems)))
    files = [k for k in knobs if k not in f.report.cases and k not in f.report.average_over and (
        isinstance(getattr(parser_of(problem, k), "parser", None), FilePath) or k.split(".")[-1] == "file")]
    if files and f.reference is not None:   # (a setting on one file was timed against another's reference run:
        one = len(files) == 1                                                                   # a user trial)
        warned += (f"{', '.join(files)} {'is' if one else 'are'} swept but not {'a [report] case' if one else '[report] cases'}: "
                   "the cheapest settings compare runs on different files; give cases = ["
                   + ", ".join(f'"{k}"' for k in files) + "] to judge each file by its own",)
    folder = f.run.folder or ctx.directory / "results" / name
    return Study(name=name, description=f.description, source=path.resolve(), problem=f.problem, scene=f.scene,
                 metrics=f.metrics, knobs=knobs, axes=axes, fixed=dict(f.fixed), sweep_text=tuple(lines), runs=runs,
                 reference=f.reference, options=f.run, report=f.report, folder=folder,
                 report_folder=f.report.folder or folder, warnings=warned, judged=judged)


def parser_of(problem, name):
    """The schema Spec of a problem's parameter (``Problem.knob_spec``; None: unknown kind)."""
    return problem.knob_spec(name)


def _names(problem) -> list | None:
    """A micro problem's parameter names (None: any, e.g. scene keys)."""
    params = getattr(problem, "params", None)
    return [n for n, _ in fields_of(params)] if params is not None else None


def _expand_groups(f: StudyFile, problem, ctx):
    """Swept knobs (file order), one list of value-tuples per group, a text per group, the axes."""
    names = _names(problem)
    where_of = {}
    for name, value in f.fixed.items():
        where_of[name] = "fixed"
        if f.problem == "scene" and name == "output.folder":      # (it was replaced without a word; a user trial)
            ctx.problems.append("fixed.output.folder: a study writes each run into its own folder, "
                                "<study folder>/runs/<run key>/output; remove it")
        elif names is not None and name not in names:
            ctx.problems.append(f"fixed.{name}: unknown parameter of problem \"{f.problem}\"{suggest(name, names)}; "
                                f"allowed: {', '.join(names)}")
        elif names is not None:
            try:
                parser_of(problem, name).parser(value, ctx)
            except Bad as exc:
                ctx.problems.append(f"fixed.{name} = {show(value)}: {exc}")
    knobs, groups, lines, axes, total = [], [], [], [], 1
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
            items = _values(value, where, parser_of(problem, name), ctx, unique=combine == "product")
            if items is not None:
                lists[name] = items
                knobs.append(name)
        if len(lists) != len(params):
            continue
        total *= len(next(iter(lists.values()))) if combine == "zip" else math.prod(map(len, lists.values()))
        if total > MAX_RUNS:      # counted before the runs are made: 10 M runs expanded for 35 min, silent
            ctx.problems.append(f"{path}: the sweep makes {total:,} runs or more, over {MAX_RUNS:,}: sweep fewer "
                                "values or split the study")
            break
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
                     f"({combine}): " + "; ".join(f"{k} = {', '.join(value_text(v) for v in vals)}"
                                                  for k, vals in lists.items()))
    return tuple(knobs), groups, lines, tuple(axes)


def _values(value, where, parser, ctx, unique: bool = True) -> list | None:
    """The values of one swept parameter: a list, or a range table (SI numbers)."""
    if isinstance(value, list):
        if not value:
            ctx.problems.append(f"{where} = []: empty sweep: give at least one value")
            return None
        items = value
    elif is_range(value):
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
    if unique and len({json.dumps(normalise(v, parser)) for v in items}) != len(items):
        ctx.problems.append(f"{where} = {show(value)}: values must not repeat")
        return None
    return list(items)


def _range(spec: dict, where, parser, ctx) -> list | None:
    """The values of a range table: integers for an integer parameter (or whole bounds and values of a
    scene key), "<number> <unit>" in the start's unit when it has one, else SI numbers."""
    unknown = [k for k in spec if k not in RANGE_KEYS]
    if unknown:
        ctx.problems.append(f"{where}.{unknown[0]}: unknown key of a range{suggest(unknown[0], RANGE_KEYS)}; "
                            f"allowed: {', '.join(RANGE_KEYS)}")
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
        kelvin = _is_temperature(spec["start"])    # the values keep their unit: a bare 293.15 is refused
        step = _si(spec["step"], parser, difference=kelvin) if "step" in spec else None
    except (Bad, UnitError) as exc:
        ctx.problems.append(f"{text}: {exc}")
        return None
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
    # whole numbers for an integer parameter (rounded), or for a scene key (no parser) given whole
    # bounds whose values are all whole; {start = 0, stop = 1, num = 11} of a friction gave [0, 1]
    if (parser is not None and isinstance(parser.parser, Integer)) or parser is None and all(
            isinstance(spec[k], int) and not isinstance(spec[k], bool) for k in ("start", "stop", "step") if k in spec) \
            and all(float(v).is_integer() for v in values):
        whole = list(dict.fromkeys(int(round(v)) for v in values))
        if len(whole) < len(values):           # {start = 1, stop = 2, num = 4} of a seed ran 1 and 2 (a user trial)
            ctx.problems.append(f"{text}: its {len(values)} values round to {len(whole)} different integers "
                                f"({', '.join(map(str, whole))}): an integer takes fewer values, or a wider range")
            return None
        values = whole
    elif kelvin:
        values = [f"{v:.12g} K" for v in values]
    elif isinstance(spec["start"], str):       # in the start's unit, shown so ("104.7 rpm", not 10.47)
        unit = VALUE.match(spec["start"]).group(2)
        factor, offset, _ = parse_unit(unit)
        values = [f"{(v - offset) / factor:.12g} {unit}" for v in values]
    else:
        values = [float(f"{v:.12g}") for v in values]
    if len(values) > 10000:
        ctx.problems.append(f"{text}: more than 10000 values")
        return None
    return values


def _is_temperature(value) -> bool:
    """True for a "<number> <unit>" string of a temperature ("20 degC", "300 K")."""
    match = VALUE.match(value) if isinstance(value, str) else None
    return bool(match and match.group(2)) and parse_unit(match.group(2))[2] == KINDS["temperature"].dim


def _si(value, parser=None, difference: bool = False):
    """A number or "<number> <unit>" in SI (by the parameter's kind when known); a temperature
    ``difference`` (a range's step) takes degC as a kelvin: "20 degC" is 20 K, not 293.15 K."""
    if parser is not None and isinstance(parser.parser, Quantity) and not difference:
        return parser.parser(value, Context())
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise Bad("range bounds must be numbers or \"<number> <unit>\" strings")
    if isinstance(value, str):
        match = VALUE.match(value)
        if not match:
            raise Bad(f"cannot read {show(value)} as a number with a unit")
        factor, offset, _ = parse_unit(match.group(2))
        return float(float(match.group(1)) * factor + (0 if difference else offset))
    return value


def normalise(value, parser=None):
    """A value in comparable form: SI number, string, or list of these."""
    if isinstance(value, list):
        return [normalise(v) for v in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return value
    try:
        v = _si(value, parser)
    except (Bad, UnitError):
        return value
    return list(v) if isinstance(v, tuple) else v


def _runs(f, problem, knobs, groups, extra, ctx) -> tuple[tuple, tuple]:
    """The runs of the product of the groups, each parsed by the problem and named by its hash, and
    the warnings of their inputs; the problems and warnings each once with the runs they concern
    (before: the warnings only in each run's log, a scene study at 1 Pa reported "0 failed"; a
    problem of the fixed values once per run, 12 times: a user trial); a warning whose runs differ in
    its numbers only, once too (``formatting.warning_kind``: the p_max warning of each load of a
    sweep; a user trial), as its first run gives it."""
    runs, seen, wrong, warned, count = [], {}, {}, [], 0
    for count, combo in enumerate(itertools.product(*groups), 1):
        swept = {k: v for part in combo for k, v in part.items()}
        raw = {**dict(f.fixed), **swept}
        label = {k: normalise(swept[k], parser_of(problem, k)) for k in knobs}
        local = Context(directory=ctx.directory)
        params = problem.parse(raw, "", local, **extra)
        where = ", ".join(f"{k} = {value_text(swept[k])}" for k in knobs)
        for line in local.problems:
            wrong.setdefault(line, []).append(where)
        warned += [(line, where) for line in local.warnings]
        if local.problems:
            continue
        ident = json.dumps({"problem": f.problem, "params": problem.key(params)}, sort_keys=True)
        digest = hashlib.sha256(ident.encode()).hexdigest()[:16]
        if digest in seen:
            ctx.problems.append(f"runs ({seen[digest]}) and ({where}) have the same parameters")
            continue
        seen[digest] = where
        runs.append(StudyRun(digest, label, raw, {k: value_text(swept[k]) for k in knobs}))
    ctx.problems.extend(_with_runs(wrong, count))
    for knob in knobs if runs else ():   # (a sweep of wear.k_w without effect "wear" ran alike runs: a user trial)
        said = {where: line for line, where in warned if _ignores(line, knob)}
        if len(said) == len(runs):
            ctx.problems.append(f"{knob}: the scene ignores it in every run ({next(iter(said.values()))}): the "
                                "runs would be alike; give what it needs ([fixed]) or sweep another key")
    kinds = by_kind(warned)
    return tuple(runs), tuple(_with_runs({line: where for line, where, _ in kinds}, count,
                                         {line for line, _, varied in kinds if varied}))


def _ignores(line: str, knob: str) -> bool:
    """Whether a scene's warning ``line`` says that the scene key ``knob`` is ignored: the key itself
    or a table holding it ("[wear] is ignored: ...", "wear.k_w is ignored: ...")."""
    what, said, _ = line.partition(" is ignored")
    parts = key_parts(knob)
    held = {".".join(parts[:i]) for i in range(1, len(parts) + 1)}
    return bool(said) and what.strip("[]").replace("[", ".").replace("]", "") in held


def _with_runs(lines: dict, total: int, varied=()) -> list[str]:
    """Each of ``lines`` (line -> the runs it concerns, of ``total``) once, naming its runs: every
    run, or up to three; of a line in ``varied`` (a kind whose runs differ in its numbers), whose
    numbers it gives."""
    return [f"{line} (" + ("every run" if len(where) == total > 1 else "run " + "; ".join(where[:3])
                           + (f" and {len(where) - 3} more" if len(where) > 3 else ""))
            + (f"; the numbers of {where[0]}" if line in varied else "") + ")"
            for line, where in lines.items()]


def reference_run(runs, label: dict, want: dict, axes) -> StudyRun | None:
    """The run with the values ``want`` and, for the other knobs, those of ``label`` (zip partners
    of a wanted knob follow it)."""
    free = {k for axis in axes if any(w in axis for w in want) for k in axis}
    hits = [r for r in runs if all(r.label[k] == v for k, v in want.items())
            and all(r.label[k] == label[k] for k in label if k not in free)]
    return hits[0] if len(hits) == 1 else None


def _check_reference(f: StudyFile, problem, knobs, axes, runs, ctx) -> tuple:
    """Problems of [reference] into ``ctx``; returns the metrics it gives values of (judged). A
    metric without one is tabulated, not judged (a file that measured some of them: user trial M),
    unless no metric has one, or the file has a key that looks like a misspelling of it."""
    ref = f.reference
    if ref.kind == "analytic":
        if not getattr(problem, "exact", None):
            ctx.problems.append(f'reference.kind = "analytic": problem "{f.problem}" has no analytic reference; '
                                'use kind = "run" (a run of the sweep) or "file"')
            return ()
        judged = tuple(m for m in f.metrics if m in problem.exact_metrics)
        if not judged:
            ctx.problems.append(f'reference.kind = "analytic": no analytic value of {", ".join(f.metrics)} '
                                f'(the problem gives {", ".join(problem.exact_metrics)})')
        return judged
    if ref.kind == "run":
        for k in (k for k in ref.run if k not in knobs):
            ctx.problems.append(f"reference.run.{k}: not a swept parameter{suggest(k, knobs)}; swept: {', '.join(knobs)}")
        given = {k: v for k, v in ref.run.items() if k in knobs}     # the swept ones are checked too
        want = {k: normalise(v, parser_of(problem, k)) for k, v in given.items()}
        for r in runs if want else ():
            if reference_run(runs, r.label, want, axes) is None:
                swept = "; ".join(f"{k}: {', '.join(dict.fromkeys(x.shown[k] for x in runs))}" for k in given)
                ctx.problems.append(f"reference.run = {{{', '.join(f'{k} = {value_text(v)}' for k, v in given.items())}}}: "
                                    f"not in the sweep (swept {swept})")
                break
        return tuple(f.metrics)
    try:
        values = json.loads(ref.file.read_text())
    except (OSError, ValueError) as exc:
        ctx.problems.append(f"reference.file = \"{ref.file}\": cannot read a JSON object ({exc})")
        return ()
    if not isinstance(values, dict):
        ctx.problems.append(f"reference.file = \"{ref.file}\": must hold a JSON object {{metric: value}}")
        return ()
    judged, others = tuple(m for m in f.metrics if m in values), [k for k in values if k not in f.metrics]
    for m in f.metrics:
        if m in values and (not isinstance(values[m], (int, float)) or isinstance(values[m], bool)):
            ctx.problems.append(f"reference.file = \"{ref.file}\": metric \"{m}\" is {values[m]!r}: give a "
                                "number in SI units (the metric's own unit)")
        elif m in values and not (math.isfinite(values[m]) and values[m] != 0):
            ctx.problems.append(f"reference.file = \"{ref.file}\": metric \"{m}\" is {values[m]!r}: errors are "
                                "relative to it; give a finite, nonzero number")
    misspelt = {k: hint for k in others if (hint := suggest(k, f.metrics))}   # said of the file's key (it was of
    for k, hint in misspelt.items():                                         # the metrics, the right one: a trial)
        ctx.problems.append(f"reference.file = \"{ref.file}\": \"{k}\" is no metric of the study{hint}")
    if not judged and not misspelt:
        ctx.problems.append(f"reference.file = \"{ref.file}\": holds no number for any metric of the study "
                            f"({', '.join(f.metrics)}); it holds {', '.join(map(str, values)) or 'nothing'}")
    return judged

"""Declarative validation of TOML tables into frozen dataclasses (scene and study files).

A table is a frozen dataclass whose fields carry a ``key(...)`` spec: how the TOML value is read
(``Quantity("pressure", gt=0)``, ``Integer(ge=1)``, ``Choice(...)``, ``Section(Cls)`` ...), its
default, and whether it is required always or only when some effect is on (``needed_by``).
Class-level ``rules`` (``OneOf``, ``Requires``, ``OnlyWith``) relate keys of one table (``ELSEWHERE``:
where keys given there belong); ``problems(self, path, ctx)`` checks the built table. ``read`` walks a
raw table and collects EVERY problem as one line naming the path, the value and what is allowed: a
new section is a dataclass, not a code path. Paths are dotted (``materials.pin.E``), list items
numbered from 1 (``layers.layer[2].E``).
"""
from __future__ import annotations

import dataclasses
import difflib
import json
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from stat import S_ISDIR, S_ISREG
from typing import Any

from multiscale.units import KINDS, UnitError, plausible_in, to_si, unit_advice

__all__ = ["Bad", "Choice", "Context", "Curve", "Either", "FilePath", "Flag", "FrozenMap", "Integer", "ListOf", "Named",
           "OneOf", "OnlyWith", "Pair", "Quantity", "Requires", "Section", "TableOr", "Tables", "Text", "Vector",
           "fields_of", "key", "parse", "read", "reference", "show", "suggest", "unknown_keys"]


class Bad(ValueError):
    """A raw value that cannot be read; the message says what is allowed."""


@dataclass
class Context:
    """What a table is read against: active effects, the scene directory; collected problems and
    warnings (keys given but unused by the active effects, values outside their plausible range)."""

    effects: frozenset = frozenset()
    directory: Path = Path(".")
    root: dict = field(default_factory=dict)        # the whole raw file (tables that merge others)
    problems: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    implausible: list[str] = field(default_factory=list)   # of the value being read: warnings with its path


class FrozenMap(Mapping):
    """Read-only, hashable, picklable mapping (named sub-tables such as ``materials``)."""

    def __init__(self, data=()):
        self._data = dict(data)

    def __getitem__(self, name):
        return self._data[name]

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)

    def __hash__(self):
        return hash(tuple(self._data.items()))

    def __repr__(self):
        return f"FrozenMap({self._data!r})"

    def __reduce__(self):
        return FrozenMap, (self._data,)


def show(value) -> str:
    """A raw value as the user wrote it (TOML-like: strings in double quotes)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (str, int, float)):
        return json.dumps(value, ensure_ascii=False) if isinstance(value, str) else repr(value)
    if isinstance(value, (list, tuple)):
        items = [show(v) for v in value]
        text = ", ".join(items)
        while len(text) > 60 and len(items) > 1:
            items.pop()
            text = ", ".join(items) + ", ..."
        return f"[{text}]"
    if isinstance(value, dict):
        return "{" + ", ".join(value)[:60] + "}"
    return repr(value)


def suggest(name: str, options) -> str:
    """' (did you mean "x"?)' for the closest option (or one that the name starts with), or ''."""
    options = [str(o) for o in options]
    near = difflib.get_close_matches(str(name), options, n=1, cutoff=0.6) or [
        o for o in options if len(o) > 2 and str(name).startswith(o)][:1]
    return f' (did you mean "{near[0]}"?)' if near else ""


# ---------------------------------------------------------------- value parsers
class Quantity:
    """A physical quantity of a units.KINDS kind, converted to SI, with an optional range (outside
    it: a problem) and an optional ``plausible`` range (lo, hi) in SI (outside it: a warning, e.g. a
    load of 1e9 N on a pin; the value is still used). ``outside``: said with a value out of range."""

    def __init__(self, kind: str, *, gt=None, ge=None, lt=None, le=None, plausible=None, outside: str = ""):
        self.name, self.kind, self.gt, self.ge, self.lt, self.le = kind, KINDS[kind], gt, ge, lt, le
        self.plausible, self.outside = plausible, outside

    def range_text(self) -> str:
        """The allowed range with its unit (">= 0 Pa", "in (0, 1]"), or ""."""
        unit = f" {self.kind.si}" if self.kind.si else ""
        low = f"> {self.gt:g}" if self.gt is not None else f">= {self.ge:g}" if self.ge is not None else None
        high = f"< {self.lt:g}" if self.lt is not None else f"<= {self.le:g}" if self.le is not None else None
        if low and high:
            lb, rb = "(" if self.gt is not None else "[", ")" if self.lt is not None else "]"
            lo, hi = (self.gt if self.gt is not None else self.ge), (self.lt if self.lt is not None else self.le)
            return f"in {lb}{lo:g}, {hi:g}{rb}{unit}"
        return f"{low or high}{unit}" if (low or high) else ""

    def describe(self) -> str:
        rng = self.range_text()
        examples = f" ({self.kind.examples})" if self.kind.examples not in ("", self.kind.si) and self.kind.si else ""
        article = "an " if self.kind.name[0] in "aeiou" else "a "
        return f"{article}{self.kind.name}{' ' + rng if rng else ''}{examples}{self._plausible()}"

    def _plausible(self) -> str:
        if self.plausible is None:
            return ""
        unit = f" {self.kind.si}" if self.kind.si else ""
        return f", plausibly {self.plausible[0]:g} to {self.plausible[1]:g}{unit}"

    def __call__(self, raw, ctx):
        try:
            v = to_si(raw, self.name)
        except UnitError as exc:
            raise Bad(str(exc)) from None
        ok = ((self.gt is None or v > self.gt) and (self.ge is None or v >= self.ge)
              and (self.lt is None or v < self.lt) and (self.le is None or v <= self.le))
        if not ok:
            shown = "" if not isinstance(raw, str) else f" (got {v:g} {self.kind.si})".replace(" )", ")")
            raise Bad(f"must be {self.range_text()}{shown}{': ' * bool(self.outside)}{self.outside}")
        ctx.implausible.extend(unit_advice(raw, self.kind))
        if self.plausible is not None and not self.plausible[0] <= v <= self.plausible[1]:
            unit = f" {self.kind.si}" if self.kind.si else ""
            ctx.implausible.append(f"{v:g}{unit} is outside the plausible range {self.plausible[0]:g} to "
                                   f"{self.plausible[1]:g}{unit}: check the value and its unit"
                                   + plausible_in(raw, self.kind, *self.plausible))
        return v


class Integer:
    def __init__(self, *, ge=None, le=None):
        self.ge, self.le = ge, le

    def describe(self) -> str:
        rng = [f">= {self.ge}" if self.ge is not None else "", f"<= {self.le}" if self.le is not None else ""]
        return "an integer " + " and ".join(r for r in rng if r)

    def __call__(self, raw, ctx):
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise Bad(f"must be {self.describe()}")
        if (self.ge is not None and raw < self.ge) or (self.le is not None and raw > self.le):
            raise Bad(f"must be {self.describe()}")
        return raw


class Flag:
    def describe(self) -> str:
        return "true or false"

    def __call__(self, raw, ctx):
        if not isinstance(raw, bool):
            raise Bad("must be true or false")
        return raw


class Text:
    def __init__(self, pattern: str = r"(?s).*\S.*", what: str = "a non-empty string"):   # (lines; not blank)
        self.pattern, self.what = re.compile(pattern), what

    def describe(self) -> str:
        return self.what

    def __call__(self, raw, ctx):
        if not isinstance(raw, str) or not self.pattern.fullmatch(raw):
            raise Bad(f"must be {self.what}")
        return raw


class Choice:
    def __init__(self, options):
        self.options = tuple(options)

    def describe(self) -> str:
        return "one of " + ", ".join(f'"{o}"' for o in self.options)

    def __call__(self, raw, ctx):
        if raw not in self.options:
            hint = suggest(raw, self.options) if isinstance(raw, str) else ""
            raise Bad(f"unknown{hint}; allowed: {', '.join(self.options)}")
        return raw


class Either:
    """The first of several parsers that accepts the value (e.g. a number or "effusivity")."""

    def __init__(self, *parsers):
        self.parsers = parsers

    def describe(self) -> str:
        return " or ".join(p.describe() for p in self.parsers)

    def __call__(self, raw, ctx):
        for parser in self.parsers:
            try:
                return parser(raw, ctx)
            except Bad:
                continue
        raise Bad(f"must be {self.describe()}")


class ListOf:
    """A TOML array of items of one parser, as a tuple."""

    def __init__(self, item, *, unique: bool = False, min_len: int = 0):
        self.item, self.unique, self.min_len = item, unique, min_len

    def describe(self) -> str:
        return f"a list of {self.item.describe()}"

    def __call__(self, raw, ctx):
        if not isinstance(raw, list):
            raise Bad(f"must be {self.describe()}")
        if len(raw) < self.min_len:
            raise Bad(f"needs at least {self.min_len} item(s); allowed: {self.item.describe()}")
        out, errors = [], []
        for i, v in enumerate(raw, 1):
            try:
                out.append(self.item(v, ctx))
            except Bad as exc:
                errors.append(f"item {i} ({show(v)}): {exc}")
        if self.unique and len(set(out)) != len(out):
            errors.append("items must not repeat")
        if errors:
            raise Bad("; ".join(errors))
        return tuple(out)


class Pair(ListOf):
    """A pair [a, b] (tuple of two); with ``single`` also one value meaning (v, v)."""

    def __init__(self, item, *, single: bool = True, names: str = "[x, y]"):
        super().__init__(item)
        self.single, self.names = single, names

    def describe(self) -> str:
        pair = f"a pair {self.names} of {self.item.describe()}"
        return f"{self.item.describe()}, or {pair}" if self.single else pair

    def __call__(self, raw, ctx):
        if isinstance(raw, list):
            if len(raw) != 2:
                raise Bad(f"a pair needs exactly 2 values; allowed: {self.describe()}")
            return super().__call__(raw, ctx)
        if not self.single:
            raise Bad(f"must be {self.describe()}")
        v = self.item(raw, ctx)
        return (v, v)


class Curve:
    """A table of [x, y] rows with strictly increasing x (at least ``min_rows``): (x, y) tuples."""

    def __init__(self, x, y, x_name: str, y_name: str, *, min_rows: int = 1):
        self.x, self.y, self.x_name, self.y_name, self.min_rows = x, y, x_name, y_name, min_rows

    def describe(self) -> str:
        rows = "rows" if self.min_rows < 2 else f"at least {self.min_rows} rows"
        return (f"{rows} [{self.x_name}, {self.y_name}] with increasing {self.x_name}; "
                f"{self.x_name}: {self.x.describe()}; {self.y_name}: {self.y.describe()}")

    def __call__(self, raw, ctx):
        if not isinstance(raw, list) or not raw or not all(isinstance(r, list) and len(r) == 2 for r in raw):
            raise Bad(f"must be a non-empty list of {self.describe()}")
        if len(raw) < self.min_rows:
            raise Bad(f"needs {self.describe()} (got {len(raw)} row)")
        rows, errors = [], []
        for i, (x, y) in enumerate(raw, 1):
            try:
                rows.append((self.x(x, ctx), self.y(y, ctx)))
            except Bad as exc:
                errors.append(f"row {i} ({show([x, y])}): {exc}")
        back = next((i for i in range(1, len(rows)) if rows[i][0] <= rows[i - 1][0]), None) if not errors else None
        if back is not None:     # in SI: "100 degC" then "300 K" goes back, which the raw values hide
            unit = f" {self.x.kind.si}" if isinstance(self.x, Quantity) and self.x.kind.si else ""
            errors.append(f"{self.x_name} must increase strictly from row to row (row {back + 1}: "
                          f"{rows[back][0]:.6g}{unit} after {rows[back - 1][0]:.6g}{unit})")
        if errors:
            raise Bad("; ".join(errors))
        return tuple(rows)


class TableOr:
    """A constant, or a table of [x, y] rows (``Curve``) when the value is a list."""

    def __init__(self, value, table: Curve):
        self.value, self.table = value, table

    def describe(self) -> str:
        return f"{self.value.describe()}, or a table of {self.table.describe()}"

    def __call__(self, raw, ctx):
        return self.table(raw, ctx) if isinstance(raw, list) else self.value(raw, ctx)


class Vector(ListOf):
    """Exactly ``n`` items of one parser (a point or a direction), as a tuple."""

    def __init__(self, item, n: int = 3, names: str = "[x, y, z]"):
        super().__init__(item)
        self.n, self.names = n, names

    def describe(self) -> str:
        return f"{self.names}, each {self.item.describe()}"

    def __call__(self, raw, ctx):
        if not isinstance(raw, list) or len(raw) != self.n:
            raise Bad(f"must be {self.describe()}")
        return super().__call__(raw, ctx)


class FilePath:
    """A path relative to the scene file: an existing file, or a folder (need not exist) with ``folder``."""
    WRITES = r"\.(?:write|save\w*|export\w*|to_\w+)\s*\(.*(?<![\w.-]){}(?![\w.-])"   # a call writing the file

    def __init__(self, *, folder: bool = False, base: str = "the scene file"):
        self.folder, self.base = folder, base

    def describe(self) -> str:
        what = "a folder path" if self.folder else "the path of an existing file"
        return f"{what} (relative to {self.base})"

    def __call__(self, raw, ctx):
        if not isinstance(raw, str) or not raw or "\x00" in raw:
            raise Bad("holds a NUL character; a path cannot" if isinstance(raw, str) and raw else f"must be {self.describe()}")
        try:                             # (a name part over 255 bytes: "File name too long")
            path = (ctx.directory / Path(raw).expanduser()).resolve()
            mode = path.stat().st_mode   # one stat (is_dir, then exists, took a folder rank 0 made between as a file)
        except (FileNotFoundError, NotADirectoryError):
            mode = 0
        except OSError as exc:
            raise Bad(f"cannot be used as a path ({exc.strerror or exc})") from None
        if self.folder and mode and not S_ISDIR(mode):
            raise Bad(f"exists and is not a folder ({path})")
        if not self.folder and not S_ISREG(mode):
            kind = "is a folder, not a file" if S_ISDIR(mode) else "is no regular file (a FIFO, device or socket)" \
                if mode else "no such file"
            made = re.compile(self.WRITES.format(re.escape(path.name)))     # (a reading line naming it, or a
            maker = [] if mode else [s.name for s in sorted(ctx.directory.glob("*.py"))[:50]  # longer name, was
                                     if s.is_file() and made.search(s.read_text(errors="replace"))]   # named: a review)
            raise Bad(f"{kind} ({path})" + (f"; {maker[0]} beside {self.base} writes it: run it first?" if maker else ""))
        return path


class Section:
    """A sub-table read into the dataclass ``cls`` (absent -> defaults when ``always``)."""

    def __init__(self, cls, *, always: bool = False):
        self.cls, self.always = cls, always

    def describe(self) -> str:
        return "a table"

    def read(self, raw, path, ctx):
        return read(self.cls, raw, path, ctx)


class Tables(Section):
    """An array of tables ``[[path]]``, each read into ``cls``; a tuple."""

    def __init__(self, cls, *, min_len: int = 1):
        super().__init__(cls)
        self.min_len = min_len

    def describe(self) -> str:
        return f"an array of tables (at least {self.min_len})"

    def read(self, raw, path, ctx):
        if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw) or len(raw) < self.min_len:
            ctx.problems.append(f"{path}: must be {self.describe()}, written [[{path}]]")
            return None
        return tuple(read(self.cls, t, f"{path}[{i}]", ctx) for i, t in enumerate(raw, 1))


class Named(Section):
    """A table of named sub-tables (``[materials.pin]``); a FrozenMap name -> cls."""

    def describe(self) -> str:
        return "a table of named tables"

    def read(self, raw, path, ctx):
        if not isinstance(raw, dict):
            ctx.problems.append(f"{path} = {show(raw)}: must be {self.describe()} ([{path}.<name>])")
            return None
        return FrozenMap({name: read(self.cls, t, f"{path}.{name}", ctx) for name, t in raw.items()})


# ---------------------------------------------------------------- keys and rules
@dataclass(frozen=True)
class Spec:
    parser: Any
    required: bool = False
    needed_by: tuple[str, ...] = ()       # effects that need this key
    unless: tuple[str, ...] = ()          # ... except when one of these effects is on
    warn_unused: bool = False             # warn when given while none of needed_by is on
    absent: str = ""                      # what an optional key without default means when not given


def key(parser, *, default=None, required: bool = False, needed_by=(), unless=(), warn_unused=False, absent=""):
    """A dataclass field read from the TOML key of the same name (``absent``: what no value means)."""
    spec = Spec(parser, required, tuple(needed_by), tuple(unless), warn_unused, absent)
    return field(default=default, metadata={"spec": spec})


def _needing(needed_by, unless, effects) -> str | None:
    """The first active effect that needs something, or None."""
    if any(e in effects for e in unless):
        return None
    return next((e for e in needed_by if e in effects), None)


@dataclass(frozen=True)
class OneOf:
    """At most one of ``keys`` (``vehicle.mass``: a sub-table's; ``meaning``: what they are); exactly one
    when required or needed_by."""

    keys: tuple[str, ...]
    required: bool = False
    needed_by: tuple[str, ...] = ()
    meaning: str = ""

    def text(self) -> str:
        return f"one of {', '.join(self.keys)}" + (" (required)" if self.required else
                                                     f" (needed by {', '.join(self.needed_by)})" if self.needed_by else "")

    def check(self, present, path, ctx):
        given = [k for k in self.keys if k in present]
        names = " or ".join(f"{path}.{k}" for k in self.keys)
        if len(given) > 1:
            return [f"{names}: give only one of them{self.meaning and ': ' + self.meaning} (got {', '.join(given)})"]
        effect = _needing(self.needed_by, (), ctx.effects)
        if not given and (self.required or effect):
            why = f'effect "{effect}" needs it' if effect else "required"
            return [f"{names}: missing; {why}"]
        return []


@dataclass(frozen=True)
class Requires:
    """If ``key`` is given, ``then`` keys are required too (optionally only when an effect is on)."""

    key: str
    then: tuple[str, ...]
    needed_by: tuple[str, ...] = ()

    def text(self) -> str:
        return f"{self.key} needs {', '.join(self.then)}" + (
            f" (with {', '.join(self.needed_by)})" if self.needed_by else "")

    def check(self, present, path, ctx):
        effect = _needing(self.needed_by, (), ctx.effects)
        if self.key not in present or self.needed_by and not effect:
            return []
        why = f' (effect "{effect}")' if effect else ""
        return [f"{path}.{k}: missing; needed with {path}.{self.key}{why}"
                for k in self.then if k not in present]


@dataclass(frozen=True)
class OnlyWith:
    """``keys`` make sense only together with one of ``key`` (e.g. hurst only for a generated surface, rms)."""

    key: tuple[str, ...]
    keys: tuple[str, ...]

    def text(self) -> str:
        return f"{', '.join(self.keys)} only with {' or '.join(self.key)}"

    def check(self, present, path, ctx):
        return [] if present & set(self.key) else [f"{path}.{k}: only used with {' or '.join(f'{path}.{a}' for a in self.key)}"
                                                   for k in self.keys if k in present]


# ---------------------------------------------------------------- the reader
def unknown_keys(raw, allowed, path: str, ctx: Context, what: str = "key", elsewhere=()) -> set[str]:
    """Report keys of ``raw`` not in ``allowed`` ("did you mean", also a plain section's key a level too high:
    ``--set ramp_steps=1``; one of ``elsewhere``, {name: where it belongs}, with that); the suggested names."""
    prefix, typos = f"{path}." if path else "", set()
    inner = {s: dict(fields_of(p.parser.cls)) for s, p in (allowed.items() if isinstance(allowed, dict) else ())
             if isinstance(getattr(p, "parser", None), Section) and not isinstance(p.parser, (Tables, Named))
             and dataclasses.is_dataclass(p.parser.cls)} if set(raw) - set(allowed) else {}
    for name in raw:
        if name in elsewhere:
            ctx.problems.append(f"{prefix}{name}: {elsewhere[name]}")
        elif name not in allowed:
            hint = suggest(name, allowed) or next((f' (did you mean "{s}.{name}"?)' for s, keys in inner.items()
                                                   if name in keys), "")
            typos.update(hint.split('"')[1:2])
            ctx.problems.append(f"{prefix}{name}: unknown {what}{hint}; allowed: {', '.join(allowed) or 'none'}")
    return typos


def parse(parser, raw, where: str, ctx: Context):
    """``raw`` read by ``parser``: the value, or None with a problem naming ``where``; values outside
    their plausible range become warnings naming ``where``."""
    try:
        return parser(raw, ctx)
    except Bad as exc:
        ctx.problems.append(f"{where} = {show(raw)}: {exc}")
        return None
    finally:
        ctx.warnings.extend(f"{where} = {show(raw)}: {note}" for note in dict.fromkeys(ctx.implausible))
        ctx.implausible.clear()


def fields_of(cls):
    """(name, Spec) of the TOML keys of a table class."""
    return [(f.name, f.metadata["spec"]) for f in dataclasses.fields(cls) if "spec" in f.metadata]


def read(cls, raw, path: str, ctx: Context):
    """Validate the raw table ``raw`` against ``cls``, appending one line per problem to
    ``ctx.problems``. Returns an instance (keys that failed keep their default, so later
    cross-checks still run: use it only if no problem was added), or None if ``raw`` is no table.
    The instance's ``problems(path, ctx)`` consistency check runs only on a clean table."""
    prefix = f"{path}." if path else ""
    if not isinstance(raw, dict):
        ctx.problems.append(f"{path} = {show(raw)}: must be a table [{path}]")
        return None
    before, specs, values = len(ctx.problems), dict(fields_of(cls)), {}
    typos = unknown_keys(raw, specs, path, ctx, elsewhere=getattr(cls, "ELSEWHERE", ()))
    for name, spec in specs.items():
        where = prefix + name
        effect = _needing(spec.needed_by, spec.unless, ctx.effects)
        missing = name not in raw and name not in typos   # a typo was already reported
        why = f'effect "{effect}" needs it' if effect else "required"
        if isinstance(spec.parser, Section):
            if name in raw:
                values[name] = spec.parser.read(raw[name], where, ctx)
            elif spec.required or (effect and isinstance(spec.parser, (Tables, Named))):
                if missing:
                    ctx.problems.append(f"{where}: missing; {why}: {spec.parser.describe()}")
            elif spec.parser.always or effect:       # absent: defaults, and name what is missing
                values[name] = spec.parser.read({}, where, ctx)
        elif name in raw:
            n = len(ctx.problems)
            value = parse(spec.parser, raw[name], where, ctx)
            if len(ctx.problems) == n:
                values[name] = value
            if spec.warn_unused and not any(e in ctx.effects for e in spec.needed_by):
                users = " or ".join(f'"{e}"' for e in spec.needed_by)
                ctx.warnings.append(f"{where} is ignored: effect {users} is not in effects")
        elif (spec.required or effect) and missing:
            ctx.problems.append(f"{where}: missing; {why}: {spec.parser.describe()}")
    present, rules = {k for k in raw if k in specs}, getattr(cls, "rules", ())
    present |= {f"{k}.{s}" for k in present if isinstance(raw[k], dict) for s in raw[k]}   # a sub-table's key
    clash = {k for r in rules if isinstance(r, OneOf) and len(present & set(r.keys)) > 1 for k in r.keys}
    for rule in (r for r in rules if getattr(r, "key", None) not in clash):   # alternatives given together:
        ctx.problems.extend(rule.check(present, path or "scene", ctx))        # one problem, not what each needs
    obj = cls(**values)
    if len(ctx.problems) == before and hasattr(obj, "problems"):
        ctx.problems.extend(obj.problems(path, ctx))
    return obj


def reference(cls, path: str = "") -> list[str]:
    """Every key of ``cls`` (recursively) with what it accepts and when it is needed: the scene
    format reference printed by ``multiscale check --keys``."""
    lines, nested = [], []          # a table's own keys and rules first, then its sub-tables
    for name, spec in fields_of(cls):
        where = f"{path}.{name}" if path else name
        when = ("required" if spec.required else
                f"needed by {', '.join(spec.needed_by)}" + (f" unless {', '.join(spec.unless)}" if spec.unless else "")
                if spec.needed_by else "optional")
        if isinstance(spec.parser, Section):
            header = f"[[{where}]]" if isinstance(spec.parser, Tables) else \
                f"[{where}.<name>]" if isinstance(spec.parser, Named) else f"[{where}]"
            sub = spec.parser.reference(where) if hasattr(spec.parser, "reference") else \
                reference(spec.parser.cls, where + (".<name>" if isinstance(spec.parser, Named) else ""))
            nested += ["", f"{header}  ({when})"] + sub
            continue
        default = next(f.default for f in dataclasses.fields(cls) if f.name == name)
        if default is not None and not spec.required:
            shown = spec.parser.show_default(default) if hasattr(spec.parser, "show_default") else show(default)
            when = f"default {shown}" + ("" if when == "optional" else f"; {when}")
        when += f"; without it: {spec.absent}" if spec.absent and default is None else ""
        lines.append(f"  {name:<20}  {spec.parser.describe()}  [{when}]")
    for rule in getattr(cls, "rules", ()):
        lines.append(f"  rule: {rule.text()}")
    return lines + nested

"""The study-file schema (``multiscale.schema`` keys): sections and their parsers, read as is;
``expand`` checks them against the problem and expands the sweep (format: the package docstring)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from multiscale.schema import Bad, Choice, FilePath, Flag, FrozenMap, Integer, ListOf, Quantity, Section, Text, key

__all__ = ["RANGE_KEYS", "ReportOptions", "Reference", "RunOptions", "StudyFile", "is_range"]

RANGE_KEYS = ("start", "stop", "num", "step", "log")
STUDY = "the study file"     # what a study's paths are relative to


class _Values:
    """A TOML table of parameter = value (nested tables become dotted paths, for scene keys)."""

    def describe(self) -> str:
        return "a table of parameter = value"

    def __call__(self, raw, ctx):
        if not isinstance(raw, dict):
            raise Bad(f"must be {self.describe()}")
        return FrozenMap(_flatten(raw))

    @staticmethod
    def show_default(value) -> str:
        return "none" if not value else str(dict(value))      # (the reference showed "FrozenMap({})")


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


def is_range(value) -> bool:
    """True for a range table {start, stop, ...} (a swept value, not a nested scene table)."""
    return isinstance(value, dict) and ("start" in value or "stop" in value)


def _flatten(raw: dict, prefix: str = "") -> dict:
    out = {}
    for name, value in raw.items():
        if isinstance(value, dict) and not is_range(value):
            out.update(_flatten(value, f"{prefix}{name}."))
        else:
            out[prefix + name] = value
    return out


@dataclass(frozen=True)
class Reference:
    """What errors are measured against. A metric the reference has no value of (a file of
    measured values, or an analytic reference, that gives some metrics only) is tabulated without
    an error; at least one metric needs a value."""

    kind: str | None = key(Choice(("analytic", "run", "file")), required=True)
    run: FrozenMap | None = key(_Values())          # kind "run": parameter values of the reference run
    file: Path | None = key(FilePath(base=STUDY))   # kind "file": JSON {metric: value}, SI, some metrics or all

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
    """How the runs run: how many at a time, each on how many MPI ranks, how long at most, timed
    how often, and where their records go."""

    processes: int = key(Integer(ge=1), default=1)                  # runs at a time (per MPI rank)
    timeout: float | None = key(Quantity("time", gt=0))             # s per run; none by default
    repeat: int = key(Integer(ge=1), default=1)                     # wall time = best of repeats
    ranks: int = key(Integer(ge=1), default=1)                      # MPI ranks of each scene run
    folder: Path | None = key(FilePath(folder=True, base=STUDY), absent="results/<name> beside the study file")


@dataclass(frozen=True)
class ReportOptions:
    """What the report shows: the error levels it marks, the swept knobs that are cases (each its
    own cheapest setting) or averaged over, its folder, title and plots."""

    errors: tuple = key(ListOf(Quantity("dimensionless", gt=0), min_len=1, unique=True), default=(0.01, 0.05))
    cases: tuple = key(ListOf(Text(), unique=True), default=())         # swept physical parameters
    average_over: tuple = key(ListOf(Text(), unique=True), default=())  # e.g. seeds: mean ± std
    folder: Path | None = key(FilePath(folder=True, base=STUDY), absent="the run folder ([run] folder)")
    title: str | None = key(Text())
    plots: bool = key(Flag(), default=True)                             # PNGs (matplotlib)


@dataclass(frozen=True)
class StudyFile:
    name: str | None = key(Text(r"[A-Za-z0-9_.-]+", "a name of letters, digits, _ . -"))
    description: str = key(Text(), default="")
    problem: str | None = key(Text(), required=True)
    scene: Path | None = key(FilePath(base=STUDY))
    metrics: tuple | None = key(ListOf(Text(), unique=True, min_len=1), required=True)
    fixed: FrozenMap = key(_Values(), default=FrozenMap())
    sweep: tuple | None = key(_Sweep(), required=True)
    reference: Reference | None = key(Section(Reference))
    run: RunOptions | None = key(Section(RunOptions, always=True))
    report: ReportOptions | None = key(Section(ReportOptions, always=True))

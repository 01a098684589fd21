"""How study values are shown in messages, tables, reports and plots."""
from __future__ import annotations

import math
import re
import time

__all__ = ["by_kind", "metric_heading", "now", "number_text", "percent", "value_text", "warning_kind"]


# unit spellings of the study files -> their symbols in tables and plots
SYMBOLS = ((re.compile(r"(?<=[\d\s])um\b"), "µm"), (re.compile(r"(?<=[\d\s])us\b"), "µs"),
           (re.compile(r"\bdegC\b"), "°C"))


def value_text(value) -> str:
    """A parameter value: floats to 4 significant digits, lists in brackets, unit strings with
    their symbols ("2 um" is shown "2 µm")."""
    if isinstance(value, str):
        for pattern, symbol in SYMBOLS:
            value = pattern.sub(symbol, value)
        return value
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    return str(value)


def number_text(v) -> str:
    """A metric value, "n/a" when not finite."""
    return value_text(v) if not isinstance(v, float) or math.isfinite(v) else "n/a"


def metric_heading(name: str, unit: str) -> str:
    """A metric's table heading or axis label: "max_pressure [Pa]" ("max_pressure" without a unit)."""
    return f"{name} [{unit}]" if unit else name


def percent(v: float) -> str:
    """A relative error in %, "n/a" when not finite."""
    return "n/a" if not math.isfinite(v) else f"{100 * v:.3g} %"


def now() -> str:
    """The local time, as records and reports show it."""
    return time.strftime("%Y-%m-%d %H:%M:%S")


NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?!\w)")   # not in names (scan_01.sdf)


def warning_kind(line: str) -> str:
    """A warning with its numbers as "#": the runs of a sweep warn alike with their own numbers
    ("the zone pressures reached 4.3 times micro.p_max"), said and listed once as one kind."""
    return NUMBER.sub("#", line)


def by_kind(found) -> list[tuple[str, list, bool]]:
    """(warning, run) pairs grouped by ``warning_kind``, in the order they first came: per kind its
    first text, the runs that gave it (each once) and whether their texts differ (in numbers)."""
    kinds = {}
    for line, run in found:
        lines, runs = kinds.setdefault(warning_kind(line), ([], {}))
        lines.append(line)
        runs[run] = None
    return [(lines[0], list(runs), len(set(lines)) > 1) for lines, runs in kinds.values()]

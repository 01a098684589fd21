"""How study values are shown in messages, tables, reports and plots."""
from __future__ import annotations

import math
import time

__all__ = ["now", "number_text", "percent", "value_text"]


def value_text(value) -> str:
    """A parameter value: floats to 4 significant digits, lists in brackets."""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    return str(value)


def number_text(v) -> str:
    """A metric value, "n/a" when not finite."""
    return value_text(v) if not isinstance(v, float) or math.isfinite(v) else "n/a"


def percent(v: float) -> str:
    """A relative error in %, "n/a" when not finite."""
    return "n/a" if not math.isfinite(v) else f"{100 * v:.3g} %"


def now() -> str:
    """The local time, as records and reports show it."""
    return time.strftime("%Y-%m-%d %H:%M:%S")

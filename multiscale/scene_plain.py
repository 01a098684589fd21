"""Plain numbers in a scene are SI (lengths in metres); a length in another unit is a string
("105 mm", "10 um"). Where a plain number was likely meant in another unit, the scene says so:
``PixelSize`` (and ``pixel_problem``, for the command line) refuses a measured surface's pixel from
``PIXEL_LIMIT`` up (``pixel_size = 10`` is
a 10 m pixel), and ``contains_hint`` adds to a geometry file's point that hits nothing the same
numbers in the file's unit (``contains = [0, 105, 12]`` with ``unit = "mm"``), and
``plain_speeds`` questions a convection table's plain speeds (rad/s) far beyond the run's.
"""
from __future__ import annotations

import math
import numbers

from multiscale.errors import InputError
from multiscale.schema import Bad, Quantity
from multiscale.units import to_si

PIXEL_LIMIT = 1e-3   # m: a measured surface's pixel (optical, stylus, AFM: 1 nm to some 50 um) lies far below


def plain(value) -> bool:
    """True for a plain number (not a bool, not a string with a unit)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


class PixelSize(Quantity):
    """The pixel size [m] of a measured surface: > 0 and below ``PIXEL_LIMIT``, refused above with
    the hint that plain numbers are metres."""

    def __init__(self):
        super().__init__("length", gt=0)

    def describe(self) -> str:
        return f"{super().describe()}, below {PIXEL_LIMIT * 1e3:g} mm"

    def __call__(self, raw, ctx):
        v = super().__call__(raw, ctx)
        if problem := pixel_problem(v, raw):
            raise Bad(problem)
        return v


def pixel_problem(v: float, raw) -> str:
    """Why a pixel size of ``v`` [m], written ``raw`` (a plain number in metres or a string with a
    unit), cannot be a measured surface's; "" if it can (below ``PIXEL_LIMIT``)."""
    if v < PIXEL_LIMIT:
        return ""
    hint = f'; plain numbers are metres: did you mean "{raw:g} um"?' if plain(raw) else ""
    return (f"{v:g} m per pixel; a measured surface's pixel is far below {PIXEL_LIMIT * 1e3:g} mm "
            f"(refused from {PIXEL_LIMIT * 1e3:g} mm up){hint}")


def contains_hint(raw: dict, path: str, exc: InputError) -> str:
    """For ``exc`` about a point ``contains`` of [geometry.bodies.<name>] or [geometry.surfaces.<name>]
    (``raw``: the [geometry] table as written, at ``path``): '; plain numbers are metres: did you
    mean ["0 mm", "105 mm", "12 mm"]?' when that point was written as plain numbers and the file's
    ``unit`` is not metres; else ""."""
    unit = raw.get("unit")     # valid: the file was read with it
    if not isinstance(unit, str) or to_si(f"1 {unit}", "length") == 1.0 or not exc.name.endswith(".contains"):
        return ""
    for section in ("bodies", "surfaces"):
        for name, table in (raw.get(section) or {}).items():
            if f"{path}.{section}.{name}.contains" != exc.name or not isinstance(table, dict):
                continue
            given = table.get("contains")
            points = given if isinstance(given, list) and given and all(isinstance(p, list) for p in given) else [given]
            for point in points:
                if isinstance(point, list) and all(plain(v) for v in point) and list(map(float, point)) == exc.value:
                    return "; plain numbers are metres: did you mean [" + ", ".join(
                        f'"{v:g} {unit}"' for v in point) + "]?"
    return ""


PLAIN_REACH = 4.0    # a plain-number speed table reaching this many times the run's top speed is questioned


def plain_speeds(raw: dict, top: float) -> list[str]:
    """Warnings of h(speed) convection tables of [[boundary]] written in plain numbers (rad/s) that
    reach beyond ``PLAIN_REACH`` times the run's largest speed ``top`` [rad/s]: such tables are most
    often thought of in rpm, 9.55 times the number in rad/s ([[1700, 110]] meant h at 1700 rpm and
    gave it at 16 234 rpm; from the review list). A table written as the run reads it (the resolved
    scene's, in rad/s) spans its speeds and is not questioned."""
    out = []
    boundary = raw.get("boundary") if isinstance(raw.get("boundary"), list) else []
    for i, b in enumerate(boundary, 1):
        rows = b.get("convection") if isinstance(b, dict) else None
        speeds = [r[0] for r in (rows if isinstance(rows, list) else ()) if isinstance(r, list) and r and plain(r[0])]
        if speeds and top > 0 and max(speeds) > PLAIN_REACH * top:
            out.append(f"boundary[{i}].convection: plain speeds are rad/s: the table reaches {max(speeds):g} rad/s "
                       f"({max(speeds) * 30 / math.pi:.0f} rpm), {max(speeds) / top:.3g} times the run's largest "
                       f"speed ({top:.4g} rad/s); if meant in rpm, give the unit (\"{max(speeds):g} rpm\")")
    return out

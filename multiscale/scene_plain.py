"""Plain numbers in a scene are SI (lengths in metres); a length in another unit is a string
("105 mm", "10 um"). Where a plain number was likely meant in another unit, the scene says so:
``PixelSize`` (and ``pixel_problem``, for the command line) refuses a measured surface's pixel from
``PIXEL_LIMIT`` up (``pixel_size = 10`` is
a 10 m pixel), and ``contains_hint`` adds to a geometry file's point that hits nothing the same
numbers in the file's unit (``contains = [0, 105, 12]`` with ``unit = "mm"``), and
``plain_speeds`` warns of a speed table's plain speeds, rad/s.
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


def plain_speeds(raw: dict) -> list[str]:
    """Warnings of speed tables written in plain numbers other than 0: an h(speed) convection of
    [[boundary]] and ``loading.speed_profile``. Plain speeds are rad/s, where such tables are most
    often thought of in rpm (``[[1700, 110]]`` is h at 16 234 rpm; from the review list)."""
    out = []
    boundary = raw.get("boundary") if isinstance(raw.get("boundary"), list) else []
    loading = raw.get("loading") if isinstance(raw.get("loading"), dict) else {}
    tables = [(f"boundary[{i}].convection", b.get("convection"), 0) for i, b in enumerate(boundary, 1)
              if isinstance(b, dict)] + [("loading.speed_profile", loading.get("speed_profile"), 1)]
    for where, rows, column in tables:
        speeds = [r[column] for r in (rows if isinstance(rows, list) else ())
                  if isinstance(r, list) and len(r) > column and plain(r[column])]
        if any(v != 0 for v in speeds):
            top = max(speeds)
            out.append(f'{where}: plain speeds are rad/s ({top:g} rad/s = {top * 30 / math.pi:.0f} rpm); give '
                       f'a unit, e.g. "{top:g} rpm"')
    return out

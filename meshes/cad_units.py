"""The length unit a STEP or IGES file declares, which OpenCASCADE converts from when it reads the
file: its lengths reach gmsh in millimetres whatever the file's unit (``xstep.cascade.unit``), so
``meshes.from_file`` scales them by the unit of the file's numbers over the declared unit. That unit
(``file_unit``) is ``geometry.unit`` if the scene gives it, else the declared one, as any CAD
importer reads the file. A file that declares no unit, or several, counts as millimetres
(OpenCASCADE's default); a .brep holds no unit and is read as it is (``scaling``), in metres like a
.msh or .geo unless ``geometry.unit`` says otherwise. Not gmsh's
``Geometry.OCCTargetUnit``: it converts to a chosen unit but does not tell which unit the file
declared, and ``geometry.unit`` (the unit of the file's numbers) needs that.
"""
from __future__ import annotations

import re
from pathlib import Path

MILLIMETRE = 1e-3
STEP, IGES = (".step", ".stp"), (".iges", ".igs")
STEP_PREFIXES = {"$": 1.0, "KILO": 1e3, "DECI": 1e-1, "CENTI": 1e-2, "MILLI": 1e-3, "MICRO": 1e-6, "NANO": 1e-9}
STEP_NAMED = {"INCH": 0.0254, "FOOT": 0.3048, "MIL": 2.54e-5, "MILE": 1609.344}
# IGES global parameter 14, the model's units flag (IGES 5.3, section 2.2.4.3)
IGES_FLAGS = {1: 0.0254, 2: 1e-3, 4: 0.3048, 5: 1609.344, 6: 1.0, 7: 1e3, 8: 2.54e-5, 9: 1e-6, 10: 1e-2,
              11: 2.54e-8}
_CONTEXT = re.compile(r"GLOBAL_UNIT_ASSIGNED_CONTEXT\s*\(\s*\(([^)]*)\)")
_LENGTH_UNIT = re.compile(r"#(\d+)\s*=\s*([^;]*\bLENGTH_UNIT\s*\([^;]*);")
_SI = re.compile(r"\bSI_UNIT\s*\(\s*(\$|\.(\w+)\.)\s*,\s*\.METRE\.\s*\)")
_NAMED = re.compile(r"\bCONVERSION_BASED_UNIT\s*\(\s*'([^']*)'")


def declared(path: Path) -> float | None:
    """Metres per length unit that the STEP or IGES file at ``path`` declares (None if it declares
    none, several, or one not known here, and for any other file)."""
    suffix = Path(path).suffix.lower()
    text = Path(path).read_text(errors="replace") if suffix in STEP + IGES else ""
    units = set(_step(text) if suffix in STEP else _iges(text) if text else [])
    return units.pop() if len(units) == 1 else None


def file_unit(path: Path, unit: float | None) -> tuple[float, str]:
    """Metres per unit of the numbers of the file at ``path``, and where it comes from: ``unit``
    (``geometry.unit``) if given; else the unit a STEP or IGES file declares (mm if none); else m."""
    if unit is not None:
        return unit, "geometry.unit"
    if Path(path).suffix.lower() not in STEP + IGES:
        return 1.0, "no geometry.unit: metres"
    own = declared(path)
    return (own, "declared by the file") if own else (MILLIMETRE, "the file declares none: millimetres")


def scaling(path: Path, unit: float) -> float:
    """The factor that takes the lengths OpenCASCADE reads from the CAD file at ``path`` to metres,
    when the file's numbers are in ``unit`` [m]: unit over the declared unit in millimetres."""
    return unit * MILLIMETRE / (declared(path) or MILLIMETRE)


def _step(text: str) -> list[float]:
    """The length units of the representation contexts (GLOBAL_UNIT_ASSIGNED_CONTEXT): an SI unit
    with its prefix, or a conversion-based one by name (its own SI unit is only its factor)."""
    units, out = dict(_LENGTH_UNIT.findall(text)), []
    for ref in {r for refs in _CONTEXT.findall(text) for r in re.findall(r"#(\d+)", refs)} & set(units):
        si, named = _SI.search(units[ref]), _NAMED.search(units[ref])
        out.append(STEP_NAMED.get(named.group(1).strip().upper()) if named
                   else STEP_PREFIXES.get(si.group(2) or "$") if si else None)
    return [u for u in out if u is not None]


def _iges(text: str) -> list[float]:
    """The units flag of the global section (lines marked G in column 73; Hollerith strings nH...)."""
    chars = "".join(line[:72] for line in text.splitlines() if len(line) > 72 and line[72] == "G")
    delimiter = chars[2] if chars.startswith("1H") else ","
    fields, k = [], 0
    while k < len(chars) and len(fields) < 14:
        hollerith = re.match(r"\s*(\d+)H", chars[k:])
        if hollerith:
            start = k + hollerith.end()
            end = start + int(hollerith.group(1))
            fields.append(chars[start:end])
            k = chars.find(delimiter, end)
        else:
            end = chars.find(delimiter, k)
            fields.append(chars[k:end if end >= 0 else len(chars)].strip())
            k = end
        if k < 0:
            break
        k += 1
    flag = fields[13].strip() if len(fields) >= 14 else ""
    return [IGES_FLAGS[int(flag)]] if flag.isdigit() and int(flag) in IGES_FLAGS else []

"""The scene and study file formats as reStructuredText, generated from their schemas (the user
guide's reference pages; ``docs/_ext/multiscale_docs.py`` puts them into Sphinx).

Every key of every table: what it accepts, its unit (SI, the unit a bare number is read in), its
default, its allowed range, and the effects that need it (its own ``needed_by``, else its table's);
the builders' parameters; the effects and the output fields. ``key_paths`` lists the dotted path
of every key, as the pages name them (a test checks that every key appears).
"""
from __future__ import annotations

import dataclasses
import re

from multiscale.geometry import MAX_CELLS, builder
from multiscale.outputs import WRITES, array_name
from multiscale.schema import (Curve, Either, Integer, ListOf, Named, Quantity, Section, TableOr, Tables, fields_of,
                               show)
from multiscale.scene import EFFECTS, OUTPUT_FIELDS, Scene
from multiscale.scene_geometry import (BUILDER_AXIS_TEXT, BUILDER_MATERIALS_TEXT, MAX_CELLS_TEXT, FileGeometry,
                                       GeometrySection, parameter_kind)
from multiscale.scene_sections import InterfaceSettings

OWN_TABLES = ("Sub-tables ``[interfaces.<name>.roughness]`` and ``[interfaces.<name>.micro]`` take the keys of "
              "``[roughness]`` and ``[micro]`` for that interface, over theirs; a surface of its own (``rms`` or "
              "``file``) replaces the other, and a file does not take ``[roughness]``'s file keys (``channel``, "
              "``pixel_size``, ``height_unit``). ``[roughness]`` may be left out when every rough interface gives a surface "
              "of its own.")


def _quantities(parser) -> list[Quantity]:
    if isinstance(parser, Quantity):
        return [parser]
    if isinstance(parser, Either):
        return [q for p in parser.parsers for q in _quantities(p)]
    if isinstance(parser, TableOr):
        return _quantities(parser.value) + _quantities(parser.table)
    if isinstance(parser, Curve):
        return _quantities(parser.x) + _quantities(parser.y)
    if isinstance(parser, ListOf):
        return _quantities(parser.item)
    return []


def _unit(parser) -> str:
    units = list(dict.fromkeys(q.kind.si or "-" for q in _quantities(parser)))
    return ", ".join(units)


def _range(parser) -> str:
    ranges = [q.range_text() for q in _quantities(parser) if q.range_text()]
    return "; ".join(dict.fromkeys(ranges))


def _cell(text: str) -> str:
    return _paragraph(text).replace("`", "'") or " "


def _paragraph(text: str) -> str:
    """A section's text as RST: its ``literals`` kept (they showed as ''literals'': a user trial)."""
    return text.replace("|", "/").replace("*", "\\*")


def _table_rows(cls, path: str, section_effects: tuple) -> tuple[list, list]:
    """(rows of this table, [(path, cls, effects, parser)] of its sub-tables)."""
    rows, subs = [], []
    defaults = {f.name: f.default for f in dataclasses.fields(cls)}
    for name, spec in fields_of(cls):
        where = f"{path}.{name}" if path else name
        effects = spec.needed_by or section_effects
        if isinstance(spec.parser, Section):
            subs.append((where, spec.parser, effects, spec))
            continue
        default = defaults[name]
        shown = spec.parser.show_default if hasattr(spec.parser, "show_default") else show
        default = "required" if spec.required else shown(default) if default is not None else spec.absent or (
            f"required with {' or '.join(spec.needed_by)}" if spec.needed_by else "none")
        needed = ", ".join(effects) + (f" (unless {', '.join(spec.unless)})" if spec.unless else "")
        rows.append((f"``{where}``", _cell(spec.parser.describe()), _cell(_unit(spec.parser)), _cell(default),
                     _cell(_range(spec.parser)), _cell(needed or "any")))
    for rule in getattr(cls, "rules", ()):
        rows.append((f"rule ({path or 'top level'})", _cell(rule.text()), " ", " ", " ", " "))
    return rows, subs


def _list_table(rows) -> list[str]:
    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 18 40 8 10 12 12", "",
             "   * - key", "     - accepts", "     - unit", "     - default", "     - range", "     - needed by"]
    for row in rows:
        lines.append(f"   * - {row[0]}")
        lines += [f"     - {cell}" for cell in row[1:]]
    return lines + [""]


def _doc(cls) -> str:
    return " ".join((cls.__doc__ or "").split())


def _tables(cls, path: str, effects: tuple, title: str, level: str = "-") -> list[str]:
    rows, subs = _table_rows(cls, path, effects)
    lines = [title, level * len(title), "", _paragraph(_doc(cls)) or " ", ""] + (_list_table(rows) if rows else [])
    for where, parser, sub_effects, spec in subs:
        if isinstance(parser, GeometrySection):
            continue                      # its own section
        if where == "interfaces":
            lines += _tables(InterfaceSettings, "interfaces.<name>", sub_effects, "[interfaces.<name>]", "~")
            lines += [OWN_TABLES, ""]
            continue
        header = f"[[{where}]]" if isinstance(parser, Tables) else f"[{where}.<name>]" if isinstance(parser, Named) \
            else f"[{where}]"
        sub_path = where + (".<name>" if isinstance(parser, Named) else "")
        lines += _tables(parser.cls, sub_path, sub_effects, header, "~" if level == "-" else "^")
    return lines


def _sentences(text: str, words: int) -> str:
    """The leading whole sentences of ``text`` within ``words`` words (at least the first sentence)."""
    out = []
    for sentence in re.split(r"(?<=\.)\s+(?=[A-Z])", " ".join(text.split())):
        if out and len(" ".join(out + [sentence]).split()) > words:
            break
        out.append(sentence)
    return " ".join(out)


def _geometry() -> list[str]:
    section = GeometrySection()
    rows = [("``geometry.builder``", _cell(section.builders.describe()), " ", "required (or file)", " ", "any"),
            ("``geometry.max_cells``", _cell(f"{Integer(ge=1).describe()}: {MAX_CELLS_TEXT}"), "-", show(MAX_CELLS),
             " ", "any"),
            ("``geometry.axis``", _cell(f"[x, y, z]: {BUILDER_AXIS_TEXT}"), "-", " ", " ", "any"),
            ("``geometry.part_materials``", _cell(BUILDER_MATERIALS_TEXT), "-", " ", " ", "any")]
    lines = ["[geometry]", "-" * 10, "", _paragraph(" ".join(GeometrySection.__doc__.split())), ""] + _list_table(rows)
    for name in section.builders.options:
        module = builder(name)
        title = f'builder = "{name}"'
        doc = _sentences(module.__doc__ or "", 60)
        lines += [title, "~" * len(title), "", _cell(doc), "", ".. list-table::", "   :header-rows: 1", "",
                  "   * - key", "     - kind", "     - default (SI)"]
        for key, value in module.DEFAULTS.items():
            lines += [f"   * - ``geometry.{key}``", f"     - {parameter_kind(module, key)}", f"     - {value:g}"]
        lines.append("")
    return lines + _tables(FileGeometry, "geometry", (), 'file = "..." (your own geometry)', "~")


def scene_rst() -> str:
    """The scene format (see module docstring)."""
    lines = ["Effects", "-------", "", "``effects`` lists what a scene simulates; only those are computed.", "",
             ".. list-table::", "   :header-rows: 1", "", "   * - effect", "     - what", "     - needs"]
    for name, e in EFFECTS.items():
        lines += [f"   * - ``{name}``", f"     - {_cell(e.doc)}", f"     - {', '.join(e.requires) or ' '}"]
    lines += ["", "Output fields", "-------------", "",
              "``output.fields`` (default: every field the effects produce); the name of each array in the "
              "field files, with its unit, and the analyses that write it.", "",
              ".. list-table::", "   :header-rows: 1", "", "   * - field", "     - array in the files",
              "     - needs effects", "     - written by"]
    for name, needs in OUTPUT_FIELDS.items():
        writers = ", ".join(k for k, fields in WRITES.items() if name in fields)
        lines += [f"   * - ``{name}``", f"     - ``{array_name(name)}``", f"     - {', '.join(needs) or ' '}",
                  f"     - {writers}"]
    lines.append("")
    rows, subs = _table_rows(Scene, "", ())
    lines += ["Top level", "---------", ""] + _list_table(rows) + _geometry()
    for where, parser, effects, spec in subs:
        if isinstance(parser, GeometrySection):
            continue
        header = f"[[{where}]]" if isinstance(parser, Tables) else f"[{where}.<name>]" if isinstance(parser, Named) \
            else f"[{where}]"
        if where == "interfaces":
            lines += _tables(InterfaceSettings, "interfaces.<name>", effects, "[interfaces.<name>]")
            lines += [OWN_TABLES, ""]
            continue
        sub_path = where + (".<name>" if isinstance(parser, Named) else "")
        lines += _tables(parser.cls, sub_path, effects, header)
    return "\n".join(lines) + "\n"


def study_rst() -> str:
    """The study file format, from its schema."""
    from multiscale.studies.spec import StudyFile   # studies: loads the micro problems (numba)
    rows, subs = _table_rows(StudyFile, "", ())
    lines = ["Top level", "---------", ""] + _list_table(rows)
    for where, parser, effects, spec in subs:
        lines += _tables(parser.cls, where, effects, f"[{where}]")
    return "\n".join(lines) + "\n"


def key_paths(cls=Scene, path: str = "") -> list[str]:
    """Dotted path of every key of ``cls`` and its tables, as the reference names them."""
    out = []
    for name, spec in fields_of(cls):
        where = f"{path}.{name}" if path else name
        parser = spec.parser
        if isinstance(parser, GeometrySection):
            out += ["geometry.builder", "geometry.max_cells", "geometry.part_materials"]
            out += [f"geometry.{k}" for b in parser.builders.options for k in builder(b).DEFAULTS]
            out += key_paths(FileGeometry, "geometry")
        elif where == "interfaces":
            out += key_paths(InterfaceSettings, "interfaces.<name>")
        elif isinstance(parser, Section):
            out += key_paths(parser.cls, where + (".<name>" if isinstance(parser, Named) else ""))
        else:
            out.append(where)
    return out


__all__ = ["key_paths", "scene_rst", "study_rst"]

"""Dotted scene keys as TOML reads them (``--set``, a study's knobs): ``interfaces.inner_pad.friction``
or with quoted parts, ``interfaces."inner_pad".friction``; an entry of an array of tables by its
number from 1, ``boundary.2.emissivity`` or as messages name it, ``boundary[2].emissivity``; the
alternatives a key given over a file replaces (``alternatives``)."""
from __future__ import annotations

import dataclasses
import tomllib

from multiscale.schema import Named, OneOf, Section, Tables, fields_of


def key_parts(dotted: str) -> list[str]:
    """The table path of the dotted key ``dotted`` (TOML's quoting: a quoted part is one part, its
    quotes not in it); a text that is no TOML key is split at its dots, for the scene's "unknown
    key" message to name."""
    try:
        table = tomllib.loads(f"{dotted} = 0")
    except tomllib.TOMLDecodeError:
        parts = []
        for part in dotted.split("."):       # "boundary[2]": ["boundary", "2"]
            name, bracket, rest = part.partition("[")
            parts += [name, rest[:-1]] if bracket and rest.endswith("]") else [part]
        return parts
    parts = []
    while isinstance(table, dict) and len(table) == 1:
        (part, table), = table.items()
        parts.append(part)
    return parts if table == 0 else dotted.split(".")


def alternatives(cls, parts: list[str]) -> tuple[str, ...]:
    """The keys of the same table that the key at ``parts`` (``key_parts``) excludes by a ``OneOf``
    rule of the schema ``cls`` (``loading.pressure``: ``normal_force``), so that a key given over a
    file replaces the file's alternative (``--set loading.pressure=...`` was refused, "give only one
    of them", with no way to remove the file's normal_force: a user trial). () where none or unknown."""
    *tables, last = parts
    k = 0
    while k < len(tables) and dataclasses.is_dataclass(cls):
        spec = dict(fields_of(cls)).get(tables[k])
        if spec is None or not isinstance(spec.parser, Section):
            return ()
        cls = spec.parser.cls
        k += 2 if isinstance(spec.parser, (Named, Tables)) else 1      # a table's name, an entry's number
    if k != len(tables) or not dataclasses.is_dataclass(cls):
        return ()
    return tuple(other for rule in getattr(cls, "rules", ()) if isinstance(rule, OneOf) and last in rule.keys
                 for other in rule.keys if other != last)

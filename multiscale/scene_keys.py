"""Dotted scene keys as TOML reads them (``--set``, a study's knobs): ``interfaces.inner_pad.friction``
or with quoted parts, ``interfaces."inner_pad".friction``; an entry of an array of tables by its
number from 1, ``boundary.2.emissivity`` or as messages name it, ``boundary[2].emissivity``; the
keys a key given over a file replaces (``replaced``)."""
from __future__ import annotations

import dataclasses
import tomllib

from multiscale.schema import Named, OneOf, OnlyWith, Section, Tables, fields_of


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


def replaced(cls, parts: list[str]) -> tuple[str, ...]:
    """The keys of the same table that the key at ``parts`` (``key_parts``) replaces, by the rules of
    the schema ``cls``: its alternatives (``OneOf``: ``loading.pressure`` replaces ``normal_force``)
    and the keys used only with those (``OnlyWith``: ``roughness.file`` replaces ``rms`` and its
    ``hurst``, ``k_min``, ...), so that a key given over a file replaces the file's (``--set
    loading.pressure=...`` was refused, "give only one of them", and --set cannot remove a key: a
    user trial). () where none or the table is unknown."""
    *tables, last = parts
    k = 0
    while k < len(tables) and dataclasses.is_dataclass(cls):
        spec = dict(fields_of(cls)).get(tables[k])
        if spec is None or not isinstance(spec.parser, Section):
            return ()
        cls = getattr(spec.parser, "key_schema", spec.parser.cls)      # [geometry]: a geometry file's tables
        k += 2 if isinstance(spec.parser, (Named, Tables)) else 1      # a table's name, an entry's number
    if k != len(tables) or not dataclasses.is_dataclass(cls):
        return ()
    rules = getattr(cls, "rules", ())
    others = [o for r in rules if isinstance(r, OneOf) and last in r.keys for o in r.keys if o != last]
    return tuple(others + [key for r in rules if isinstance(r, OnlyWith) and set(r.key) <= set(others)
                           for key in r.keys])

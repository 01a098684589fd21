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


def replaced(cls, parts: list[str]) -> tuple[tuple[str, ...], ...]:
    """The keys (as table paths from the root) that the key at ``parts`` (``key_parts``) replaces, by
    the rules of the schema ``cls`` on its way: the alternatives (``OneOf``: ``loading.pressure``
    replaces ``normal_force``; a rule's key may lie in a sub-table, ``loading.vehicle.mass``, and a key
    inside an alternative gives it, ``loading.vehicle.speed`` replaces ``rotation_speed``) and the
    keys used only with those (``OnlyWith``: ``roughness.file`` replaces ``rms`` and its ``hurst``,
    ``k_min``, ...), so that a key given over a file replaces the file's (``--set
    loading.pressure=...`` was refused, "give only one of them", and --set cannot remove a key: a
    user trial). () where none or a table is unknown."""
    out, k, nested = [], 0, {}
    while dataclasses.is_dataclass(cls):
        rest, rules = ".".join(parts[k:]), getattr(cls, "rules", ())
        mine = [r for r in rules if isinstance(r, OneOf) and any(f"{rest}.".startswith(f"{o}.") for o in r.keys)]
        others = [o for r in mine for o in r.keys if not f"{rest}.".startswith(f"{o}.")]
        others += [key for r in rules if isinstance(r, OnlyWith) and set(r.key) <= set(others) for key in r.keys]
        out += [(*parts[:k], *o.split(".")) for o in others]
        part = parts[k] if k < len(parts) - 1 else None
        if part in nested:                  # a table read beside the schema's keys ([interfaces.<name>.roughness])
            cls, k, nested = nested[part], k + 1, {}
            continue
        spec = dict(fields_of(cls)).get(part)
        if spec is None or not isinstance(spec.parser, Section):
            break
        nested = getattr(spec.parser, "nested", {})
        cls = getattr(spec.parser, "key_schema", spec.parser.cls)      # [geometry]: a geometry file's tables
        k += 2 if isinstance(spec.parser, (Named, Tables)) else 1      # a table's name, an entry's number
    return tuple(out)


def table_at(raw: dict, parts) -> dict:
    """The table of the raw scene ``raw`` at the path ``parts`` (an array's entry by its number from
    1); {} where there is none."""
    table = raw
    for part in parts:
        if isinstance(table, list):
            table = table[int(part) - 1] if part.isdigit() and 1 <= int(part) <= len(table) else {}
        else:
            table = table.get(part, {}) if isinstance(table, dict) else {}
    return table if isinstance(table, dict) else {}


def given_paths(parts, value) -> list[tuple]:
    """The key paths that ``value`` given at the path ``parts`` gives: its own and, for a table given
    whole, each of its keys' (recursively)."""
    paths = [tuple(parts)]
    for k, v in (value.items() if isinstance(value, dict) else ()):
        paths += given_paths([*parts, k], v)
    return paths


def drop_replaced(cls, raw: dict, parts, value, given) -> list[str]:
    """Deletes from the raw scene ``raw`` the keys that ``value`` given at ``parts`` replaces by the
    schema ``cls`` (``replaced``; for a table given whole, what each of its keys replaces: a vehicle
    with a mass replaces a force), except the keys given too (``given``: key paths, ``given_paths``);
    returns the keys deleted, as messages name them (``boundary[3].ambient``)."""
    dropped = []
    for path in given_paths(parts, value):
        for *where, other in replaced(cls, list(path)):
            holder = table_at(raw, where)
            if other in holder and not any(g[:len(where) + 1] == (*where, other) for g in given):   # (a key of
                del holder[other]                                   # it given too: it dropped stribeck.kinetic)
                dropped.append("".join(f"[{p}]" if p.isdigit() else f".{p}" for p in [*where, other]).lstrip("."))
    return dropped

"""Dotted scene keys as TOML reads them (``--set``, a study's knobs): ``interfaces.inner_pad.friction``
or with quoted parts, ``interfaces."inner_pad".friction``; an entry of an array of tables by its
number from 1, ``boundary.2.emissivity`` or as messages name it, ``boundary[2].emissivity``."""
from __future__ import annotations

import tomllib


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

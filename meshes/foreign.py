"""Geometry files that gmsh would take badly, refused by name before it reads them: a ``.geo``
script with an ``Exit`` command (gmsh ends the process with status 0: ``check`` and ``run`` said
nothing and wrote nothing) and an MSH 2 mesh (no entity topology: the volumes' boundary nodes
are not found). Used by ``meshes.from_file``."""
from __future__ import annotations

import re

from multiscale.errors import InputError


def refuse_foreign(g) -> None:
    """An InputError naming ``g.file`` (a ``FileGeometry``'s) if it is one of those files."""
    if g.file.suffix.lower() == ".geo":
        code = re.sub(r"//[^\n]*|/\*.*?\*/", "", g.file.read_text(encoding="utf-8", errors="replace"), flags=re.S)
        if re.search(r"(^|[;\s])Exit\s*;", code):
            raise InputError("geometry.file", g.file.name, "the script has an Exit command, which would end this "
                             "process (gmsh exits); remove it")
    elif g.file.suffix.lower() == ".msh" and re.match(rb"\s*\$MeshFormat\s+2\.", g.file.read_bytes()[:64]):
        raise InputError("geometry.file", g.file.name, "an MSH 2 file (no entity topology for the volumes' "
                         "boundaries): save it as MSH 4.1 (gmsh -save -format msh41, or File > Export)")


__all__ = ["refuse_foreign"]

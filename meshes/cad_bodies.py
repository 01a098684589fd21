"""Assigning the volumes of a geometry file to the scene's bodies ([geometry.bodies.<name>]): by
physical-group name or CAD label (``volumes``), by the file's volume number (``index``) or as the
volume containing a point (``contains``); every volume in exactly one body. Every body that names
no volume is reported at once (``InputErrors``). Used by ``meshes.from_file``."""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, InputErrors


def assign_bodies(model, g, order: list[int], labels: dict) -> dict:
    """Body name -> sorted volume tags of the gmsh ``model`` for the FileGeometry ``g``; ``order``:
    the volume tags in the file's numbering (``index`` 1..n), ``labels``: tag -> CAD label."""
    groups = {model.getPhysicalName(3, t): list(model.getEntitiesForPhysicalGroup(3, t))
              for _, t in model.getPhysicalGroups(3)}
    out, owner, problems = {}, {}, []
    for name, sel in g.bodies.items():
        where = f"geometry.bodies.{name}"
        tags = []
        if sel.volumes is not None:
            for v in sel.volumes:
                hit = groups.get(v) or [t for t, label in labels.items()
                                        if v in (label, label.rsplit("/", 1)[-1]) or label.endswith("/" + v)]
                if not hit:
                    known = sorted(set(groups) | {lab for lab in labels.values() if lab})
                    problems.append(InputError(f"{where}.volumes", v, f"no volume of {g.file.name} has this name; "
                                               f"known: {', '.join(known) or 'none (use index or contains)'}"))
                tags += hit
        elif sel.index is not None:
            bad = [i for i in sel.index if i > len(order)]
            if bad:
                problems.append(InputError(f"{where}.index", bad, f"{g.file.name} has {len(order)} volumes "
                                           f"(1..{len(order)})"))
            tags = [order[i - 1] for i in sel.index if i <= len(order)]
        else:
            for point in sel.contains:
                inside = [t for t in labels if model.isInside(3, t, list(point))]
                if not inside:
                    problems.append(InputError(f"{where}.contains", list(point), f"no volume of {g.file.name} "
                                               "contains this point [m]"))
                tags += inside
        for t in tags:
            if t in owner and owner[t] != name:
                problems.append(InputError(where, name, f"volume {t} ({labels[t] or 'no label'}) also belongs to "
                                           f"body \"{owner[t]}\""))
            owner.setdefault(t, name)
        out[name] = sorted(set(tags))
    left = [t for t in labels if t not in owner]
    if left and not problems:          # (a body that named nothing leaves its volumes over)
        centres = [np.round(model.occ.getCenterOfMass(3, t), 4).tolist() if model.occ.getEntities(3) else "" for t in left]
        problems.append(InputError("geometry.bodies", sorted(g.bodies), "every volume must belong to a body; not "
                                   "assigned: " + "; ".join(f"volume {t} ({labels[t] or 'no label'}) at {c} m"
                                                            for t, c in zip(left, centres))))
    if problems:
        raise problems[0] if len(problems) == 1 else InputErrors(problems)
    return out

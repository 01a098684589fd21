"""Assigning the volumes of a geometry file to the scene's bodies ([geometry.bodies.<name>]): by
physical-group name or CAD label (``volumes``), by the file's volume number (``index``) or as the
volume containing a point (``contains``); every volume in exactly one body. Every body that names
no volume is reported at once (``InputErrors``). Used by ``meshes.from_file``."""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, InputErrors

CURVE_POINTS = 65           # points along each curve for a box of curves (``curve_box``)


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
                                               f"contains this point [m]{_outside(model, labels, point, g)}"))
                elif len(inside) > 1:        # on a face the volumes share: it took both, and the other body's
                    problems.append(InputError(f"{where}.contains", list(point), "the point lies on the boundary of "
                                               f"volumes {', '.join(f'{t} ({labels[t] or 'no label'})' for t in inside)}"
                                               f" of {g.file.name}: move it inside the one you mean [m]"))
                    continue
                tags += inside
        for t in tags:
            if t in owner and owner[t] != name:
                problems.append(InputError(where, name, f"volume {t} ({labels[t] or 'no label'}) also belongs to "
                                           f"body \"{owner[t]}\""))
            owner.setdefault(t, name)
        out[name] = sorted(set(tags))
    points = [p for sel in g.bodies.values() if sel.volumes is None and sel.index is None for p in sel.contains]
    missed = [p for p in problems if p.name.endswith(".contains") and "no volume of" in p.allowed]
    inside = [p for p in missed if "outside all of them" not in p.allowed]      # (those outside say it themselves)
    if len(points) > 1 and len(missed) == len(points) and inside:   # every point missed: the unit, likely (said nothing
        read = f"geometry.unit = {g.unit:g} m" if g.unit is not None else "the file's own unit (no geometry.unit)"
        problems.append(InputError("geometry.unit", g.unit, f"no point of geometry.bodies lies in a volume of "
                                   f"{g.file.name}, whose volumes span {_span(model, labels)} mm read in {read}: "
                                   "is it the file's length unit?"))     # (said nothing when inside the box: a trial)
    left = [t for t in labels if t not in owner]
    if left and not problems:          # (a body that named nothing leaves its volumes over)
        centres = [np.round(model.occ.getCenterOfMass(3, t), 4).tolist() if model.occ.getEntities(3) else "" for t in left]
        problems.append(InputError("geometry.bodies", sorted(g.bodies), "every volume must belong to a body; not "
                                   "assigned: " + "; ".join(f"volume {t} ({labels[t] or 'no label'}) at {c} m"
                                                            for t, c in zip(left, centres))))
    if problems:
        raise problems[0] if len(problems) == 1 else InputErrors(problems)
    return out


def curve_box(model, curves: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners [model units] of the box of the ``curves``, each at ``CURVE_POINTS``
    points (tight where gmsh's box of a B-spline, a scaled script's, is its control net's: a disc
    100 mm across spanned x -200..100 mm)."""
    x = np.concatenate([np.reshape(model.getValue(1, c, np.linspace(*model.getParametrizationBounds(1, c),
                                                                     CURVE_POINTS).ravel()), (-1, 3))
                        for c in dict.fromkeys(curves)])
    return x.min(axis=0), x.max(axis=0)


def _outside(model, labels: dict, point, g) -> str:
    """Words for a point outside the box of every volume (``labels``' tags): where the volumes lie,
    in mm (a file in cm read in mm put every point of a scene outside, with no word of the unit)."""
    low, high = _box(model, labels)
    if np.all(np.asarray(point) >= low) and np.all(np.asarray(point) <= high):
        return ""
    unit = f"geometry.unit = {g.unit:g} m: is it the file's?" if g.unit is not None else "is the file's unit right?"
    return f"; it lies outside all of them, which span {_span(model, labels)} mm ({unit})"


def _box(model, labels: dict) -> tuple[np.ndarray, np.ndarray]:
    """The box of the volumes ``labels``' tags (``curve_box`` of their curves) [m]."""
    faces = model.getBoundary([(3, t) for t in labels], combined=False, oriented=False)
    return curve_box(model, [c for _, c in model.getBoundary(faces, combined=False, oriented=False)])


def _span(model, labels: dict) -> str:
    """The box of the volumes in words, "x -140..140, y ..." [mm]."""
    return ", ".join(f"{axis} {a * 1e3:.4g}..{b * 1e3:.4g}" for axis, a, b in zip("xyz", *_box(model, labels)))

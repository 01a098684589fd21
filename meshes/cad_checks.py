"""Checks of the bodies of an OpenCASCADE geometry file (``meshes.from_file``) against the scene's
[geometry]: the rotating body one of revolution about its axis (``check_revolution``, by the mass
properties ``inertia``; the share of its surface its rotation crosses, ``crossed_share``), bodies not much thinner than their elements (``thin_bodies``), bodies
that nearly touch the rotating one (``near_misses``)."""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import CROSSES, Rotation, crossed, thin_warning

REVOLUTION = 1e-3           # the rotating body's centre of mass off its axis (of its extent), its axis of inertia (rad)
EQUAL_MOMENTS = 0.01        # principal moments of inertia this close (of the largest) are those of a body of revolution
NEAR = 0.01                 # a body without an interface this close to the rotating one (of the model's extent)
OTHER = "; or, if it is not the body that turns, name the one that does (geometry.rotating)"   # (a pad named: a trial)


def box_extent(boxes) -> float:
    """The largest side of the box holding ``boxes`` (rows of gmsh's xmin, ymin, zmin, xmax, ymax, zmax)."""
    boxes = np.asarray(boxes, dtype=float)
    return float((boxes[:, 3:].max(axis=0) - boxes[:, :3].min(axis=0)).max())


def inertia(model, scale: float) -> dict:
    """Volume tag -> (volume [m^3], centre of mass [m], inertia tensor about it [m^5], bounding box
    [m]) of the OpenCASCADE volumes, the model's lengths times ``scale`` [m per unit]. Measured before
    a script is scaled: its scaled faces are B-splines, whose mass properties OpenCASCADE integrates
    coarsely (a disc 200 mm across off its axis by 0.14 mm)."""
    return {t: (model.occ.getMass(3, t) * scale ** 3, np.asarray(model.occ.getCenterOfMass(3, t)) * scale,
                np.reshape(model.occ.getMatrixOfInertia(3, t), (3, 3)) * scale ** 5,
                np.asarray(model.getBoundingBox(3, t)) * scale) for _, t in model.getEntities(3)}


def thin_bodies(model, g, bodies: dict, volume: dict, pairs: dict) -> list[str]:
    """The warning (a list of one, or none) of bodies thinner than a third of their elements: a mean
    thickness 2 V / S (V the body's volume [m^3], ``volume`` per tag; S its outer surface's area; a
    plate's thickness) below a third of the element size it is meshed at (``interface_mesh_size`` if
    finer and it touches an interface of ``pairs``, else ``mesh_size``).
    A caliper trial's 30 mm elements on 10 mm pads and 6 mm backplates passed check: the peak
    pressure came out 3.9 MPa against 6.7 MPa at 5 mm, said by a generic undershoot warning only.
    (The demos' coarse meshes reach 2.4 times a backplate's or a holder's thickness.)"""
    touching = {n for pair in pairs.values() for n in pair}
    sized = []
    for name, volumes in bodies.items():
        faces = model.getBoundary([(3, v) for v in volumes], combined=True, oriented=False)
        thickness = 2 * sum(volume[v] for v in volumes) / sum(model.occ.getMass(2, f) for _, f in faces)
        sized.append((name, thickness, min(g.interface_mesh_size, g.mesh_size) if name in touching and
                      g.interface_mesh_size else g.mesh_size))     # (a coarser interface size is not used)
    return thin_warning(sized, " (thickness 2 x volume / surface)")


def near_misses(model, g, bodies: dict, pairs: dict, extent: float, named=()) -> list[str]:
    """Warnings of the fixed bodies that share no face with the rotating one yet come within ``NEAR``
    times the model's ``extent`` [m] of it: a pad drawn in its released position, 0.5 mm off the
    disc, was left out without a word while its bonded neighbour took the whole clamp force (a CAD
    trial). ``pairs``: the interfaces' (fixed, rotating) bodies; ``named``: bodies warned of already
    (touching nothing, nor a body bonded to them)."""
    touching = {fixed for fixed, _ in pairs.values()} | set(named)
    out = []
    for name in (n for n in bodies if n != g.rotating and n not in touching):
        gap = min(model.occ.getDistance(3, s, 3, t)[0] for s in bodies[name] for t in bodies[g.rotating])
        if 0 < gap < NEAR * extent:
            out.append(f"geometry.bodies.{name} comes within {gap * 1e3:.3g} mm of {g.rotating} without sharing a "
                       f"face with it: no contact interface there, no load or heat through it (a pad in its "
                       f"released position? a pad must share a face with {g.rotating} in the file)")
    return out


def surface_samples(model, face: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and normals of a face's surface on a ``count`` x ``count`` grid of its parameter
    range, from 0.1 to 0.9 of it along each parameter."""
    lo, hi = (np.asarray(b, dtype=float) for b in model.getParametrizationBounds(2, face))
    t = np.linspace(0.1, 0.9, count)
    uv = np.array([[a, b] for a in lo[0] + t * (hi[0] - lo[0]) for b in lo[1] + t * (hi[1] - lo[1])]).ravel()
    return np.reshape(model.getValue(2, face, uv), (-1, 3)), np.reshape(model.getNormal(face, uv), (-1, 3))


def crossed_share(model, g, volumes) -> float:
    """The share of the rotating body's surface (its ``volumes``' boundary; the model in m) that its
    rotation crosses, weighted by the speed as the run's check of its mesh weighs it
    (``macro.mesh.crossing``): |w.n| > ``CROSSES`` |w| (w = e x (x - c)) at the points of a 5 x 5
    grid of each face's parameters, each face's points standing for its area. A plane normal to the
    axis or a coaxial cylinder is never crossed; vanes, holes, slots and the flats of a square bore
    are (a face judged whole, by its median, missed the flats: a review). The heat problem needs
    none (``macro.thermal``)."""
    motion, across, total = Rotation(tuple(g.axis), tuple(g.centre)), 0.0, 0.0
    for _, f in model.getBoundary([(3, v) for v in volumes], combined=True, oriented=False):
        x, n = surface_samples(model, f, 5)
        cos, weight = crossed(x, n, np.full(len(x), model.occ.getMass(2, f) / len(x)), motion)
        total += weight.sum()
        across += weight[cos > CROSSES].sum()
    return across / total if total > 0 else 0.0


def check_revolution(g, volumes: list[tuple]) -> None:
    """Refuse an axis about which the rotating body (its ``volumes``' ``inertia``) is not one of
    revolution, by its mass properties: no two principal moments of inertia within
    ``EQUAL_MOMENTS``, its axis (of the moment that differs from the two equal ones) off the axis
    direction by more than ``REVOLUTION`` rad, or its centre of mass off the axis by more than
    ``REVOLUTION`` of its extent. A body of revolution, or of n >= 3 equal sectors (a vented or
    cross-drilled disc), passes all three; the rotating body's material (its sliding velocity, its
    temperature) moves round the axis, and a disc 2 mm off it ran 58 K hotter, tilted by 1.15
    degrees 165 K, with nothing said (a caliper trial). Checked on OpenCASCADE geometry (CAD,
    OpenCASCADE scripts) only. With three equal moments (a cylinder 1.7 times as tall as its
    radius) the direction is not judged."""
    masses, centres = np.array([v[0] for v in volumes]), np.array([v[1] for v in volumes])
    c = masses @ centres / masses.sum()
    inertia = sum(i + m * ((d @ d) * np.eye(3) - np.outer(d, d)) for (m, _, i, _), d in zip(volumes, centres - c))
    extent = box_extent([v[3] for v in volumes])
    e = np.asarray(g.axis, dtype=float) / np.linalg.norm(g.axis)
    r = c - np.asarray(g.centre, dtype=float)
    off = float(np.linalg.norm(r - (r @ e) * e))
    what = ("turns about {}, so it must be a body of revolution about it (or of n >= 3 equal sectors, as a vented "
            "disc): the run moves its material, and with it the sliding and the heat, round that axis")
    moments, vectors = np.linalg.eigh(inertia)                    # ascending
    equal = np.abs(np.diff(moments)) <= EQUAL_MOMENTS * moments[-1]   # (0, 1) and (1, 2)
    if not equal.any():
        raise InputError("geometry.rotating", g.rotating, f"the rotating body {g.rotating!r} {what.format('an axis')}, "
                         "but no axis of it is one: its principal moments of inertia differ by more than "
                         f"{EQUAL_MOMENTS:.0%} ({', '.join(f'{m / moments[-1]:.3g}' for m in moments)} of the largest)"
                         f"{OTHER}")
    if not equal.all():              # the moment that differs from the two equal ones is about its axis
        axis = vectors[:, 2 if equal[0] else 0]
        axis = -axis if axis @ e < 0 else axis
        angle = float(np.arccos(min(1.0, axis @ e)))
        if angle > REVOLUTION:
            raise InputError("geometry.axis", list(g.axis), f"the rotating body {g.rotating!r} "
                             f"{what.format('this axis')}, but its own axis is {np.degrees(angle):.3g} degrees off it, "
                             f"along {(np.round(axis, 4) + 0.0).tolist()}: give that axis")
    if off > REVOLUTION * extent:
        raise InputError("geometry.centre", list(g.centre), f"the rotating body {g.rotating!r} "
                         f"{what.format('the axis through this point')}, but its centre of mass lies {off * 1e3:.3g} "
                         f"mm from that axis, at {(np.round(c * 1e3, 2) + 0.0).tolist()} mm: give a point of its axis"
                         f"{OTHER}")

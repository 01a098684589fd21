"""Geometry from the user's file, read through gmsh: a mesh (``.msh``), a gmsh script (``.geo``) or
CAD through OpenCASCADE (``.step``/``.stp``, ``.iges``/``.igs``, ``.brep``). Registered as the
builder "file"; its parameters are a ``multiscale.scene_geometry.FileGeometry`` ([geometry] of a
scene).

Reading (``describe``, run when the scene is read, so that ``multiscale check`` reports what it
found; and ``generate``, on the meshing rank):

1. load the file into a gmsh model and scale it to metres (``unit``, else the unit a STEP or IGES
   file declares: ``cad_units.file_unit``); CAD and OpenCASCADE scripts
   are fragmented (``occ.fragment``) so that faces where two volumes touch become one shared face
   and the mesh is conforming there (a ``.msh`` must be conforming already: gmsh writes shared
   faces as one entity);
2. assign every volume to one body (``meshes.cad_bodies``): by physical-group name or CAD label
   (``volumes``), by the file's volume number (``index``), or as the volume containing a point
   (``contains``);
3. find the contact interfaces: faces shared by a fixed body and the rotating one (given pairs,
   or every such pair, one interface per fixed body named after it), with their area, and their
   normal and extent in their plane when planar;
4. find the named surfaces: the file's physical surface groups and [geometry.surfaces].

CAD is meshed with gmsh's HXT unless ``mesh_algorithm`` says "delaunay"; a ``.geo`` script keeps
its own choice unless told, and its own ``Mesh.MeshSizeFactor``; a script's options that make other
elements than linear tetrahedra are refused (``TETRAHEDRA``), and so is a mesh that holds any. A
failed 3-D meshing is an InputError naming the other algorithm.

The macro model's body 0 ("fixed") holds every fixed body as a material region (bodies that touch
are bonded: one conforming mesh), body 1 the rotating body. Tags: body k -> cell tag 1 + k,
interface k -> facet tag 1001 + k, surface k -> facet tag 2001 + k.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from meshes import cad_checks, cad_units
from meshes.cad_bodies import assign_bodies, curve_box
from meshes.foreign import refuse_foreign
from multiscale.errors import InputError, InputErrors
from multiscale.geometry import (FIXED_BODY, BodySpec, GeometrySpec, Region, Rotation, add_group, loose_bodies,
                                 plane_extent, start_gmsh)

NAME = "file"
DEFAULTS: dict = {}          # no numeric parameters: [geometry] of the scene is a FileGeometry
PLAUSIBLE = (1e-3, 10.0)     # m, smallest and largest extent of a brake or tribometer model
NORMAL_TOLERANCE = np.cos(np.radians(5.0))
# CAD is scaled to metres by gmsh's Geometry.OCCScaling at import, a similarity that keeps planes
# and cylinders analytic; occ.dilate (a general affine map) turns every surface into a B-spline:
# the fragment then took 1.1 s instead of 0.03 s on the railway disc and HXT meshed 1.4-1.8x slower
# (benchmarks/README, car brake). Scripts and meshes are scaled after reading, an OpenCASCADE script
# after its fragment (0.26 -> 0.02 s for the pin-on-disc script of tests/test_geometry_files.py).
# A script's own Mesh.MeshSizeFactor (or its alias CharacteristicLengthFactor) scales every element
# size of its mesh, as gmsh does. Options are global in gmsh and a script sets them when it is read,
# so the factor is read from the script and kept on the model, and the option stays the caller's:
# geometry.estimate_cells meshes its trials at its factor times the script's, and a kept session
# remeshed at factor 1 gives the script's mesh.
SIZE_FACTOR = "Mesh.MeshSizeFactor"
# gmsh options a script could set that make other elements than linear tetrahedra (quadratic ones,
# quadrangles, pyramids, hexahedra), with the values that do not: refused when the script is read
# (after a 3-D meshing with recombined quadrangles failed, gmsh 4.15's finalize crashed the process)
TETRAHEDRA = {"Mesh.ElementOrder": 1, "Mesh.RecombineAll": 0, "Mesh.Recombine3DAll": 0, "Mesh.SubdivisionAlgorithm": 0}
ALGORITHM_3D = {"delaunay": 1, "hxt": 10}   # gmsh's Mesh.Algorithm3D by mesh_algorithm; CAD takes HXT
#   (Marot, Pellerin & Remacle 2019, Int. J. Numer. Methods Eng. 117, 967-990) unless told: on one
#   thread 6x faster than gmsh's default Delaunay on the car brake, of better worst quality
#   (benchmarks/README, car brake)


@dataclass
class Found:
    """What a file holds, in metres (see module docstring)."""

    bodies: dict                              # body name -> volume tags
    labels: dict                              # volume tag -> label (physical names or CAD label)
    volume: dict                              # volume tag -> m^3
    interfaces: dict = field(default_factory=dict)   # name -> face tags
    pairs: dict = field(default_factory=dict)        # name -> (fixed body, rotating body)
    areas: dict = field(default_factory=dict)        # name -> m^2
    flat_areas: dict = field(default_factory=dict)   # named surface that is one plane -> m^2 (a load face's)
    normals: dict = field(default_factory=dict)      # name -> unit normal (fixed towards rotating), None if not planar
    extents: dict = field(default_factory=dict)      # planar interface -> size (u, v) [m] in its plane
    sizes: dict = field(default_factory=dict)        # a .msh's interface -> mean edge of its triangles [m]
    cell_size: float | None = None                   # a .msh's: its bodies' largest mean tetrahedron edge [m]
    surfaces: dict = field(default_factory=dict)     # name -> face tags
    extent: float = 0.0                              # m, largest side of the bounding box
    loose: list = field(default_factory=list)        # warnings: fixed bodies that touch no interface, thin ones
    size_factor: float = 1.0                         # a script's own Mesh.MeshSizeFactor (SIZE_FACTOR)
    unit: tuple = (1.0, "")                          # m per unit of the file's numbers, where it comes from
    crossed: float | None = None                     # OpenCASCADE: the rotating body's share crossed by its rotation


def parameters(params) -> dict:
    """The file's mesh sizes [m] (for the scene summary)."""
    return {k: getattr(params, k) for k in ("mesh_size", "interface_mesh_size") if getattr(params, k) is not None}


@contextmanager
def _model():
    """A gmsh model of its own (gmsh initialised here if it is not already)."""
    import gmsh   # only when a file is read: scenes with a builder never load gmsh
    started = not gmsh.isInitialized()
    if started:
        start_gmsh()
    previous = gmsh.model.getCurrent() if not started else None
    gmsh.model.add("multiscale_file_inspection")
    try:
        yield gmsh.model
    finally:
        gmsh.model.remove()
        if started:
            gmsh.finalize()
        elif previous:
            gmsh.model.setCurrent(previous)


def describe(params) -> GeometrySpec:
    """Inspect the file (see module docstring) and describe the macro model."""
    with _model() as model:
        found = _load(model, params)
    return _spec(params, found)


def generate(model, params) -> None:
    """Load, tag and (CAD, scripts) mesh the file in the gmsh ``model`` (on one rank)."""
    found = _load(model, params)
    model.removePhysicalGroups()
    for k, name in enumerate(params.bodies):
        add_group(model, 3, found.bodies[name], 1 + k, name)
    for k, (name, faces) in enumerate(found.interfaces.items()):
        add_group(model, 2, faces, 1001 + k, name)
    for k, (name, faces) in enumerate(found.surfaces.items()):
        add_group(model, 2, faces, 2001 + k, name)
    if params.kind != "mesh":
        _sizes(model, params, [f for faces in found.interfaces.values() for f in faces])
        remesh(model, params)


def remesh(model, params) -> None:
    """Mesh the loaded file's model in 3-D (again, after ``model.mesh.clear()``): CAD with HXT unless
    ``mesh_algorithm`` says otherwise, a script by its own choice unless told. Trial meshes coarser
    than the mesh (``Mesh.MeshSizeFactor`` > 1, ``geometry.estimate_cells``; a script's own factor
    multiplies it, ``SIZE_FACTOR``) take Delaunay instead of HXT: on thin parts HXT fails on coarse
    meshes or takes seconds (the railway disc's coarse trials: 0.6-1.2 s each against 0.1 s;
    benchmarks/README), and the count they estimate does not depend on the algorithm. A failed
    meshing at the mesh's own size is an InputError naming the other algorithm."""
    import gmsh   # mesh options are global in gmsh
    algorithm = params.mesh_algorithm or ("hxt" if params.kind == "cad" else None)   # else the script's
    factor = gmsh.option.getNumber(SIZE_FACTOR)
    trial = factor > 1.0
    if algorithm is not None:
        gmsh.option.setNumber("Mesh.Algorithm3D", ALGORITHM_3D["delaunay" if trial else algorithm])
    gmsh.option.setNumber(SIZE_FACTOR, factor * _script_factor(model))
    try:
        model.mesh.generate(3)
    except Exception as exc:
        if trial:
            raise
        other = " or ".join(f'"{a}"' for a in ALGORITHM_3D if a != algorithm)
        raise InputError("geometry.mesh_algorithm", algorithm or "the script's choice",
                         f"gmsh could not mesh {params.file.name} ({exc}): try mesh_algorithm = {other}, "
                         "or other mesh sizes") from None
    finally:
        gmsh.option.setNumber(SIZE_FACTOR, factor)
    others = [model.mesh.getElementProperties(t)[0] for t in model.mesh.getElementTypes(3)
              if model.mesh.getElementProperties(t)[0] != "Tetrahedron 4"]
    if others and not trial:
        raise InputError("geometry.file", params.file.name, f"its mesh holds {', '.join(others)} elements: the macro "
                         "model needs linear tetrahedra (a Recombine or Transfinite constraint of the script?)")


def _script_factor(model) -> float:
    """The ``Mesh.MeshSizeFactor`` the loaded script set for its mesh (1: none, or not a script)."""
    return float(model.getAttribute(SIZE_FACTOR)[0]) if SIZE_FACTOR in model.getAttributeNames() else 1.0


# ---------------------------------------------------------------- reading
def _load(model, g) -> Found:
    import gmsh   # the module-level functions (merge, option) of the model's gmsh
    path, unit = str(g.file), cad_units.file_unit(g.file, g.unit)
    scale = unit[0]
    if g.kind == "cad":          # scaled to metres as it is imported (the note above ALGORITHM_3D), from the
        #                          millimetres OpenCASCADE converts a STEP or IGES file to (meshes.cad_units)
        gmsh.option.setNumber("Geometry.OCCScaling", cad_units.scaling(g.file, scale))
        try:
            shapes = model.occ.importShapes(path)
        except Exception as exc:                    # an empty, truncated or foreign file
            raise InputError("geometry.file", g.file.name, f"OpenCASCADE cannot read it ({exc}): is it a whole "
                             f"{g.file.suffix.lstrip('.').upper()} file?") from None
        finally:
            gmsh.option.setNumber("Geometry.OCCScaling", 1.0)
        model.occ.synchronize()
        order = [t for d, t in shapes if d == 3]
    else:
        refuse_foreign(g)
        factor = gmsh.option.getNumber(SIZE_FACTOR)   # a trial's (geometry.estimate_cells), else 1
        gmsh.option.setNumber(SIZE_FACTOR, 1.0)
        try:
            gmsh.merge(path)
        except Exception as exc:
            raise InputError("geometry.file", g.file.name, f"gmsh cannot read it ({exc})") from None
        finally:
            own = gmsh.option.getNumber(SIZE_FACTOR)  # set by the script, or 1
            gmsh.option.setNumber(SIZE_FACTOR, factor)
        model.setAttribute(SIZE_FACTOR, [repr(own)])
        changed = [f"{k} = {gmsh.option.getNumber(k):g}" for k, v in TETRAHEDRA.items() if gmsh.option.getNumber(k) != v]
        if changed:
            raise InputError("geometry.file", g.file.name, f"sets {', '.join(changed)}: the macro model is meshed with "
                             "linear tetrahedra; remove it from the script")
        order = [t for _, t in model.getEntities(3)]
    if not order:
        raise InputError("geometry.file", g.file.name, "holds no volume (3-D solid)")
    occ = bool(model.occ.getEntities(3))
    split, after = [], {}         # solids of the file that the fragment cut into pieces: they overlap
    groups = _physical_groups(model) if occ and g.kind == "script" else []
    if occ and g.kind != "mesh":  # before a script's scaling: fast on its analytic faces
        volumes = model.occ.getEntities(3)
        boxes = {t: model.getBoundingBox(2, t) for dim, _, _, tags in groups if dim == 2 for t in tags}
        _, mapping = model.occ.fragment(volumes, [])
        model.occ.synchronize()
        after = {t: [b for d, b in m if d == 3] for (_, t), m in zip(volumes, mapping)}
        order = [t for old in order for t in after.get(old, [old])]
        split = sorted(old for old, pieces in after.items() if len(pieces) > 1)
        _check_surface_groups(model, g, groups, boxes)
    # the extent before a script's or a mesh's scaling, scaled: gmsh's bounding box of some OpenCASCADE
    # surfaces is stale after occ.dilate (a partial Sphere 80 mm off the origin in mm spanned 80 m)
    extent = _extent(model, g, scale if g.kind != "cad" else 1.0, unit)
    inertia = cad_checks.inertia(model, scale if g.kind != "cad" else 1.0) if occ else {}   # before B-splines
    if scale != 1.0 and g.kind != "cad":
        if g.kind == "mesh":
            s = scale
            model.mesh.affineTransform([s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0])
        elif occ:
            model.occ.dilate(model.occ.getEntities(), 0, 0, 0, scale, scale, scale)
            model.occ.synchronize()
        else:
            model.geo.dilate(model.getEntities(), 0, 0, 0, scale, scale, scale)
            model.geo.synchronize()
    if groups:                    # gmsh dropped those of remade entities (the fragment), or all (occ.dilate)
        model.removePhysicalGroups()
        for dim, group, name, tags in groups:
            model.removePhysicalName(name)         # (else the name stays with the dropped group)
            model.addPhysicalGroup(dim, [p for t in tags for p in after.get(t, [t])] if dim == 3 else tags, group,
                                   name=name)
    labels = {t: _label(model, t) for _, t in model.getEntities(3)}
    try:
        bodies = assign_bodies(model, g, order, labels)
    except InputError as exc:
        if not split:
            raise
        note = (f"(the file's solids {split} overlap: gmsh cut them into pieces where they intersect; make the "
                "parts touch without overlapping)")
        raise InputErrors([InputError(e.name, e.value, f"{e.allowed} {note}") for e in InputErrors.each(exc)]) from None
    found = Found(bodies, labels, {t: _volume(model, t, occ) for t in labels},
                  extent=extent, size_factor=_script_factor(model), unit=unit)
    _interfaces(model, g, found, occ)
    _surfaces(model, g, found, occ)
    for name, faces in found.surfaces.items() if occ or g.kind == "mesh" else ():   # (check said no pressure's
        area, normal = _plane(model, faces, order[:1], occ)                     # force on a file's faces: a trial)
        found.flat_areas.update({name: area} if normal is not None else {})
    if g.kind == "mesh":
        found.cell_size = max(_mean_edge(_simplices(model, 3, tags)) for tags in bodies.values())
    if occ and g.mesh_size is not None:
        found.loose += cad_checks.thin_bodies(model, g, found.bodies, found.volume, found.pairs)
    if occ:
        found.loose += cad_checks.near_misses(model, g, found.bodies, found.pairs, found.extent,
                                              loose_bodies(found.loose))
        cad_checks.check_revolution(g, [inertia[v] for v in bodies[g.rotating]])
        found.crossed = cad_checks.crossed_share(model, g, bodies[g.rotating])
    return found


def _physical_groups(model) -> list[tuple[int, int, str, list[int]]]:
    """(dimension, tag, name, entity tags) of the model's physical volumes and surfaces."""
    return [(d, t, model.getPhysicalName(d, t), [int(e) for e in model.getEntitiesForPhysicalGroup(d, t)])
            for d, t in model.getPhysicalGroups() if d >= 2]


def _check_surface_groups(model, g, groups, boxes: dict) -> None:
    """Refuse a script's physical surface that the fragment cut or renumbered (its faces before it:
    ``boxes``, tag -> bounding box): its group would name other faces than the script's."""
    there = {t for _, t in model.getEntities(2)}
    moved = sorted({name for dim, _, name, tags in groups if dim == 2 for t in tags
                    if t not in there or not np.allclose(model.getBoundingBox(2, t), boxes[t], rtol=0, atol=1e-9
                                                         * max(1.0, float(np.abs(boxes[t]).max())))})
    if moved:
        raise InputError("geometry.file", g.file.name, f"the physical surface(s) {', '.join(moved)} lie where "
                         "solids touch: joining the solids (OpenCASCADE fragment) remade those faces; put "
                         "Coherence; (or BooleanFragments) before the Physical Surface lines of the script")


def _extent(model, g, scale: float, unit: tuple) -> float:
    """The largest side [m] of the model's bounding box times ``scale`` (m per model unit),
    refused if implausible (``unit``: the file's, ``cad_units.file_unit``)."""
    # the volumes' boxes: the model's (-1, -1) is stale after a scaled import of a spherical face (a
    # crowned pad 0.28 m across spanned 134 m)
    extent = cad_checks.box_extent([model.getBoundingBox(3, t) for _, t in model.getEntities(3)]) * scale
    if not PLAUSIBLE[0] <= extent <= PLAUSIBLE[1]:
        raise InputError("geometry.unit", g.unit, f"the geometry of {g.file.name} spans {extent:.4g} m, implausible for "
                         f"a brake or tribometer ({PLAUSIBLE[0]:g}..{PLAUSIBLE[1]:g} m): is the file's length unit "
                         f"right? (read in {unit[0]:g} m per file unit: {unit[1]}{_declared(g, unit[0])})")
    return extent


def _declared(g, read: float) -> str:
    unit = cad_units.declared(g.file) if g.kind == "cad" else None
    return "" if unit in (None, read) else f"; the file declares {unit:g} m per unit"


def _label(model, tag: int) -> str:
    names = [model.getPhysicalName(3, p) for p in model.getPhysicalGroupsForEntity(3, tag)]
    return ", ".join([n for n in names if n] + ([model.getEntityName(3, tag)] if model.getEntityName(3, tag) else []))


def _volume(model, tag: int, occ: bool) -> float:
    if occ:
        return float(model.occ.getMass(3, tag))
    node_tags, coords, _ = model.mesh.getNodes(3, tag, includeBoundary=True, returnParametricCoord=False)
    x = dict(zip(node_tags, np.reshape(coords, (-1, 3))))
    types, _, conn = model.mesh.getElements(3, tag)
    total = 0.0
    for etype, c in zip(types, conn):
        if model.mesh.getElementProperties(etype)[0] != "Tetrahedron 4":
            raise InputError("geometry.file", "elements", "a .msh of linear tetrahedra")
        tets = np.array([x[n] for n in c]).reshape(-1, 4, 3)
        total += np.abs(np.einsum("ij,ij->i", tets[:, 1] - tets[:, 0],
                                  np.cross(tets[:, 2] - tets[:, 0], tets[:, 3] - tets[:, 0]))).sum() / 6
    return total


def _shared_faces(model, a: list[int], b: list[int]) -> list[int]:
    """Faces bounding a volume of ``a`` and a volume of ``b``."""
    faces = []
    for _, f in model.getEntities(2):
        up = set(model.getAdjacencies(2, f)[0].tolist())
        if up & set(a) and up & set(b):
            faces.append(f)
    return faces


def _interfaces(model, g, found: Found, occ: bool) -> None:
    rotating = found.bodies[g.rotating]
    pairs = {n: tuple(p.between) for n, p in g.interfaces.items()} or \
        {name: (name, g.rotating) for name in g.bodies if name != g.rotating}
    for name, (a, b) in pairs.items():
        fixed = a if b == g.rotating else b
        faces = _shared_faces(model, found.bodies[fixed], rotating)
        if not faces:
            if g.interfaces:
                gap = _gap(model, found.bodies[fixed], rotating, occ)
                raise InputError(f"geometry.interfaces.{name}", [a, b], f"these bodies do not touch (gap {gap})")
            continue
        found.interfaces[name], found.pairs[name] = faces, (fixed, g.rotating)
        found.areas[name], found.normals[name] = _plane(model, faces, found.bodies[fixed], occ)
        if found.normals[name] is not None:
            found.extents[name] = plane_extent(found.normals[name], *_box(model, faces, g.kind == "mesh"))
        if g.kind == "mesh":
            found.sizes[name] = _mean_edge(_simplices(model, 2, faces))
    if not found.interfaces:
        raise InputError("geometry.rotating", g.rotating, f"no fixed body of {g.file.name} touches it: no contact "
                         "interface (bodies must share a face; give [geometry.interfaces] to see the gaps)")
    touching = {found.pairs[name][0] for name in found.interfaces}
    for group in _groups(model, {n: v for n, v in found.bodies.items() if n != g.rotating}):
        if not touching & set(group):
            gap = _gap(model, [t for n in group for t in found.bodies[n]], rotating, occ)
            found.loose.append(f"geometry.bodies: {', '.join(group)} share no face with {g.rotating}, nor a body bonded "
                               f"to them (gap {gap}): no contact interface holds them, no friction or heat reaches "
                               f"them; a pad must share a face with {g.rotating} in the file")


def _groups(model, bodies: dict) -> list[list[str]]:
    """The bodies in groups that touch (share a face, an edge or a vertex), in ``bodies``' order."""
    ends = {n: {e for v in vs for e in model.getBoundary([(3, v)], combined=False, oriented=False)}
            | set(model.getBoundary([(3, v) for v in vs], combined=False, oriented=False, recursive=True))
            for n, vs in bodies.items()}
    groups: list[list[str]] = []
    for name in bodies:
        joined = [grp for grp in groups if any(ends[name] & ends[m] for m in grp)]
        groups = [grp for grp in groups if grp not in joined] + [[m for grp in joined for m in grp] + [name]]
    return [sorted(grp, key=list(bodies).index) for grp in groups]


def _gap(model, a: list[int], b: list[int], occ: bool) -> str:
    if not occ:
        return "unknown for a mesh file: the bodies share no face entity"
    d = min(model.occ.getDistance(3, s, 3, t)[0] for s in a for t in b)
    return f"{d:.4g} m" if d > 0 else "0 m: they overlap or touch at an edge, not along a shared face"


def _simplices(model, dim: int, entities: list[int]) -> np.ndarray:
    """The corners (n, dim + 1, 3) [m] of the meshed entities' triangles (dim 2) or tetrahedra
    (dim 3) (a .msh; a quadratic element's corners only)."""
    out = []
    for e in entities:
        tags, coords, _ = model.mesh.getNodes(dim, e, includeBoundary=True)
        x = dict(zip(tags, np.reshape(coords, (-1, 3))))
        for etype, conn in zip(*model.mesh.getElements(dim, e)[::2]):
            per = model.mesh.getElementProperties(etype)[3]
            out.append(np.array([x[n] for n in conn]).reshape(-1, per, 3)[:, :dim + 1])
    return np.concatenate(out)


def _mean_edge(simplices: np.ndarray) -> float:
    """Mean edge length [m] of ``simplices`` (n, k, 3)."""
    k = simplices.shape[1]
    return float(np.mean([np.linalg.norm(simplices[:, i] - simplices[:, j], axis=1)
                          for i in range(k) for j in range(i + 1, k)]))


def _box(model, faces: list[int], mesh: bool) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners [m] of the faces' bounding box: of their nodes in a .msh (the box a
    run takes), else of their boundary curves (``curve_box``: a flat face's box is its boundary's;
    gmsh's boxes of OpenCASCADE shapes are larger by its tolerance, 1e-7 m)."""
    if mesh:
        x = _simplices(model, 2, faces).reshape(-1, 3)
        return x.min(axis=0), x.max(axis=0)
    return curve_box(model, [c for _, c in model.getBoundary([(2, f) for f in faces], combined=False, oriented=False)])


def _coplanar(model, faces: list[int]) -> bool:
    """True for one face, or flat faces of one plane (the pieces of a face that fragmenting split)."""
    if len(faces) == 1:
        return True
    flats = [_flat(model, f) for f in faces]
    if any(f is None for f in flats):
        return False
    (n0, p0), size = flats[0], max(np.ptp([p for _, p in flats], axis=0).max(), np.finfo(float).tiny)
    return all(abs(n @ n0) > 1 - 1e-9 and abs((p - p0) @ n0) <= 1e-9 * max(size, 1.0) for n, p in flats)


def _flat(model, face: int):
    """(unit normal, a point) of a flat face, or None: normals and points sampled over the face's
    parameter range (a scaled CAD face is a B-spline surface, so its type says nothing)."""
    x, n = cad_checks.surface_samples(model, face, 4)
    n0 = n[0] / np.linalg.norm(n[0])
    size = max(np.ptp(x, axis=0).max(), np.finfo(float).tiny)
    if np.all(np.abs(n @ n0) / np.linalg.norm(n, axis=1) > 1 - 1e-9) and np.abs((x - x[0]) @ n0).max() <= 1e-9 * size:
        return n0, x[0]
    return None


def _plane(model, faces: list[int], fixed: list[int], occ: bool):
    """Area [m^2] and unit normal (from the fixed body outwards) of a face set; normal None if
    the faces are not one plane."""
    if occ:
        area = sum(model.occ.getMass(2, f) for f in faces)
        flat = [_flat(model, f) for f in faces]
        if any(f is None for f in flat):
            return area, None
        normals, points = [n for n, _ in flat], [p for _, p in flat]
        n = normals[0]
        planar = all(abs(abs(m @ n) - 1) < 1e-9 for m in normals) and \
            all(abs((p - points[0]) @ n) < 1e-9 * max(1.0, np.abs(points[0]).max()) for p in points)
        centre = np.asarray(model.occ.getCenterOfMass(3, fixed[0]))
    else:
        tri = _simplices(model, 2, faces)
        cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        area = 0.5 * np.linalg.norm(cross, axis=1).sum()
        pts = tri.reshape(-1, 3)
        mean = pts.mean(axis=0)
        _, sv, vt = np.linalg.svd(pts - mean)
        n = vt[-1]
        size = np.ptp(pts, axis=0).max()
        planar = np.abs((pts - mean) @ n).max() <= 1e-6 * size
        points = [mean]
        centre = np.asarray(model.getBoundingBox(3, fixed[0])).reshape(2, 3).mean(axis=0)
    if (centre - points[0]) @ n > 0:      # point from the fixed body towards the rotating one
        n = -n
    return float(area), (tuple(float(c) for c in n) if planar else None)


def _on_face(model, face: int, point, tol: float, occ: bool) -> bool:
    """True if ``point`` [m] lies within ``tol`` of the face: of its surface, at a point inside its
    trimmed region or within ``tol`` of its boundary curves. gmsh's closest point on a face is on
    its whole, untrimmed surface (a point 100 mm from a backplate, in the plane of its back, selected
    that back and the other pads' backs); OpenCASCADE classifies it against the face (``isInside``),
    the built-in kernel's box test stands in for it there (its ``isInside`` knows planes only)."""
    point = np.asarray(point, dtype=float)
    closest = np.asarray(model.getClosestPoint(2, face, list(point))[0])
    if np.linalg.norm(closest - point) > tol:
        return False
    if not occ:
        box = np.reshape(model.getBoundingBox(2, face), (2, 3))
        return bool(np.all(point >= box[0] - tol) and np.all(point <= box[1] + tol))
    if model.isInside(2, face, list(closest)):
        return True
    return any(np.linalg.norm(np.asarray(model.getClosestPoint(1, c, list(point))[0]) - point) <= tol
               for c in model.getAdjacencies(2, face)[1])


def _surfaces(model, g, found: Found, occ: bool) -> None:
    groups = {model.getPhysicalName(2, t): list(model.getEntitiesForPhysicalGroup(2, t))
              for _, t in model.getPhysicalGroups(2)}
    found.surfaces.update({n: f for n, f in groups.items() if n and n not in found.interfaces})
    for name, sel in g.surfaces.items():
        where = f"geometry.surfaces.{name}"
        if sel.group is not None:
            if sel.group not in groups:
                raise InputError(f"{where}.group", sel.group, f"no physical surface of {g.file.name} has this name; "
                                 f"known: {', '.join(n for n in groups if n) or 'none'}")
            found.surfaces[name] = groups[sel.group]
            continue
        candidates = _faces_of(model, found.bodies[sel.body]) if sel.body else [t for _, t in model.getEntities(2)]
        if sel.normal is not None:
            faces = [f for f in candidates if _outward(model, f, found.bodies[sel.body], np.asarray(sel.normal))]
        else:
            faces = []
            for point in sel.contains:
                near = [f for f in candidates if _on_face(model, f, point, 1e-4 * found.extent, occ)]
                if not near:
                    raise InputError(f"{where}.contains", list(point), f"no face of {g.file.name} passes through "
                                     "this point [m]")
                if not _coplanar(model, near):   # an edge or a corner: it selected every face there, silently
                    raise InputError(f"{where}.contains", list(point), f"the point lies on {len(near)} faces of "
                                     f"{g.file.name} that meet at an edge or a corner: move it inside the face you "
                                     "mean [m]")
                faces += [f for f in near if f not in faces]
        if not faces:
            raise InputError(where, name, f"selects no face of {g.file.name}")
        inner = sorted({n for n, fs in found.interfaces.items() if set(fs) & set(faces)})
        if inner:                    # e.g. a pad's face by its normal towards the disc
            raise InputError(where, name, f"selects the face of interface {', '.join(inner)}: an interface "
                             "carries no load or boundary condition; select a free face")
        taken = sorted(n for n in g.surfaces if n in found.surfaces and set(found.surfaces[n]) & set(faces))
        if taken:                    # a face carries one name (the mesh tags it once)
            raise InputError(where, name, f"selects a face that geometry.surfaces.{taken[0]} already selects; "
                             "a face can carry one surface name")
        found.surfaces[name] = faces
    named = {f for n in g.surfaces for f in found.surfaces[n]}      # the scene's names win over the file's
    for n in [n for n in groups if n in found.surfaces and n not in g.surfaces and set(groups[n]) & named]:
        del found.surfaces[n]


def _faces_of(model, volumes: list[int]) -> list[int]:
    return sorted({int(f) for v in volumes for f in model.getAdjacencies(3, v)[1]})


def _outward(model, face: int, volumes: list[int], direction: np.ndarray) -> bool:
    """True if ``face`` is planar with its outward normal (from ``volumes``) along ``direction``."""
    flat = _flat(model, face)
    if flat is None:
        return False
    n, p = flat
    inside = [v for v in volumes if face in model.getAdjacencies(3, v)[1]]
    centre = np.asarray(model.occ.getCenterOfMass(3, inside[0]))
    if (p - centre) @ n < 0:
        n = -n
    return float(n @ direction) / (np.linalg.norm(n) * np.linalg.norm(direction)) >= NORMAL_TOLERANCE


def _sizes(model, g, interface_faces: list[int]) -> None:
    """Element size ``mesh_size``, refined to ``interface_mesh_size`` on the interfaces."""
    model.mesh.setSize(model.getEntities(0), g.mesh_size)
    import gmsh   # mesh options are global in gmsh
    gmsh.option.setNumber("Mesh.MeshSizeMax", g.mesh_size)
    fine = g.interface_mesh_size
    if fine is None or fine >= g.mesh_size or not interface_faces:
        return
    field = model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "SurfacesList", interface_faces)
    near = field.add("Threshold")
    for key, value in (("InField", dist), ("SizeMin", fine), ("SizeMax", g.mesh_size),
                       ("DistMin", fine), ("DistMax", 4 * g.mesh_size)):
        field.setNumber(near, key, value)
    field.setAsBackgroundMesh(near)
    model.mesh.setSize(model.getBoundary([(2, f) for f in interface_faces], combined=False, recursive=True), fine)


# ---------------------------------------------------------------- the spec
def _spec(g, found: Found) -> GeometrySpec:
    fixed = [n for n in g.bodies if n != g.rotating]
    tag = {n: 1 + k for k, n in enumerate(g.bodies)}
    regions = tuple(Region(n, tag[n], g.bodies[n].material) for n in fixed)
    report = [f"file {g.file.name}: {len(found.labels)} volume(s), extent {found.extent:.4g} m, read in "
              f"{found.unit[0]:g} m per file unit ({found.unit[1]})"]
    if found.size_factor != 1.0:
        report.append(f"the script's Mesh.MeshSizeFactor {found.size_factor:g} scales every element size")
    report += [f"body {n}: {len(found.bodies[n])} volume(s), {sum(found.volume[t] for t in found.bodies[n]) * 1e6:.4g} cm^3, "
               f"material {g.bodies[n].material}" + (" (rotating)" if n == g.rotating else "") for n in g.bodies]
    for name, faces in found.interfaces.items():
        n = found.normals[name]
        normal = f"normal ({', '.join(f'{round(c, 3) + 0.0:.3f}' for c in n)})" if n is not None else "not planar"
        report.append(f"interface {name}: {found.pairs[name][0]} on {g.rotating}, {len(faces)} face(s), "
                      f"{found.areas[name] * 1e6:.4g} mm^2, {normal}")
    report += [f"surface {n}: {len(f)} face(s)" for n, f in found.surfaces.items()]
    return GeometrySpec(
        bodies=(BodySpec(FIXED_BODY, regions), BodySpec(g.rotating, (Region(g.rotating, tag[g.rotating],
                                                                       g.bodies[g.rotating].material),))),
        interfaces={n: 1001 + k for k, n in enumerate(found.interfaces)},
        faces={n: 2001 + k for k, n in enumerate(found.surfaces)},
        supports=(), load_faces=(), motion=Rotation(tuple(g.axis), tuple(g.centre)), load_areas=found.flat_areas,
        length_scale=found.extent, fluid_load=True, interface_areas=dict(found.areas), crossed=found.crossed,
        interface_normals=dict(found.normals), interface_extents=dict(found.extents), report=tuple(report),
        interface_sizes=found.sizes if g.kind == "mesh" else
        dict.fromkeys(found.interfaces, min(g.mesh_size, g.interface_mesh_size or g.mesh_size)),
        warnings=tuple(found.loose), element_size=found.cell_size if g.kind == "mesh" else g.mesh_size,
        interface_regions={name: fixed for name, (fixed, _) in found.pairs.items()})

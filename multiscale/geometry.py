"""What a mesh builder tells the macro model (bodies, material regions, tagged faces, motion), and
the registry of builders.

A builder (the modules of ``meshes/``: ``block_on_flat``, ``pin_on_disc``, ``disc_brake``, or a
user's own) is a module providing ``DEFAULTS`` (its parameters in SI units), optionally
``PARAMETER_KINDS`` (unit kind of a parameter, default "length", or "angle" when the name says so),
``parameters(params) -> dict`` (defaults updated and checked), ``describe(params) ->
GeometrySpec`` (pure Python: tags, bodies, supports; the interfaces' extents, without which
``check`` cannot compare a measured surface with its face) and ``generate(model, params)`` (builds the
gmsh model on one rank and ends by meshing it with ``model.mesh.generate(3)``: ``estimate_cells``
remeshes that model at other sizes, and ``macro.mesh.build`` takes the real mesh from it), and
optionally ``remesh(model, params)`` (meshes the built model again in 3-D, after
``model.mesh.clear()``, with the options the builder chooses for the current
``Mesh.MeshSizeFactor``; default ``model.mesh.generate(3)``).
Builders are found by name in the ``multiscale.builders`` entry-point group (``pyproject.toml``:
the registry is package metadata, so a scene never imports ``meshes`` and a user's package can add
builders). This module holds the spec dataclasses, the
registry lookup and small gmsh helpers; it imports neither DOLFINx nor gmsh.

Conventions: body 0 is the "+" side of the interface (the stationary body: pin, pads, block),
body 1 the "−" side (the sliding body: disc, flat). The interface normal n points from body 1
into body 0; the gap g_n = g_0 + (u_0 − u_1)·n is positive when open (thesis §1.4).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from importlib import import_module
from importlib.metadata import entry_points
from types import ModuleType
from typing import Mapping, Sequence

import numpy as np

from multiscale.errors import InputError, check_positive
from multiscale.signals import keep_python_handlers


@dataclass(frozen=True)
class Region:
    """A material region of a body: its cell tag and the name of its material table."""

    name: str
    tag: int
    material: str


@dataclass(frozen=True)
class BodySpec:
    """One deformable body (one submesh), made of one or more material regions."""

    name: str
    regions: tuple[Region, ...]


@dataclass(frozen=True)
class Support:
    """Displacement components (0=x, 1=y, 2=z) held at zero on a named face."""

    face: str
    components: tuple[int, ...] = (0, 1, 2)


@dataclass(frozen=True)
class Rotation:
    """Rigid rotation of body 1 about ``axis`` through ``centre``: w = omega e x (x − c) [m/s]."""

    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def velocity(self, points) -> np.ndarray:
        """w per unit angular speed at ``points`` (n, 3) [m]: e x (x − c) [m per rad]."""
        e = np.asarray(self.axis, dtype=float) / np.linalg.norm(self.axis)
        return np.cross(e, np.asarray(points, dtype=float) - np.asarray(self.centre, dtype=float))


CROSSES = 0.5     # |w.n|/|w| above which a rotation w crosses a surface (vanes, holes: ``macro.mesh.crossing``)


def crossed(points, normals, weights, motion) -> tuple[np.ndarray, np.ndarray]:
    """Where the rigid ``motion`` crosses a surface sampled at ``points`` (n, 3) [m] with ``normals``
    (any length) standing for ``weights`` (n,) of it (areas): per point |w.n| / (|w| |n|) (0 where w
    = 0; crossed above ``CROSSES``) and the weight times the speed |w|, the weight of its share
    (``macro.mesh.crossing`` on a mesh, ``meshes.cad_checks.crossed_share`` on CAD faces)."""
    w = motion.velocity(points)
    n = np.asarray(normals, dtype=float)
    speed = np.linalg.norm(w, axis=1)
    cos = np.abs((w * n).sum(axis=1)) / np.maximum(speed * np.linalg.norm(n, axis=1), np.finfo(float).tiny)
    return cos, np.asarray(weights, dtype=float) * speed


@dataclass(frozen=True)
class Translation:
    """Rigid translation of body 1 along the unit vector ``direction``: w = v e [m/s]."""

    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)

    def velocity(self, points) -> np.ndarray:
        """w per unit speed at ``points`` (n, 3): the unit direction at every point [-]."""
        e = np.asarray(self.direction, dtype=float) / np.linalg.norm(self.direction)
        return np.tile(e, (len(points), 1))


@dataclass(frozen=True)
class GeometrySpec:
    """Everything the macro model needs to know about a built geometry (tags are gmsh physical tags).

    ``bodies[0]`` is the "+" (stationary) side, ``bodies[1]`` the "−" (sliding) side.
    ``interfaces`` maps interface names to facet tags (all between body 0 and body 1);
    ``faces`` maps named boundary faces to facet tags; the normal load acts on ``load_faces``
    as a uniform traction along ``load_direction`` whose resultant is the scene's normal force,
    or, with ``fluid_load``, as a fluid pressure p: traction −p n on every load face (n outward).
    """

    bodies: tuple[BodySpec, BodySpec]
    interfaces: Mapping[str, int]
    faces: Mapping[str, int]
    supports: tuple[Support, ...]
    load_faces: tuple[str, ...]
    load_direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    motion: Rotation | Translation = field(default_factory=Rotation)
    length_scale: float = 1.0          # m, a typical size (tolerances for facet keys)
    fluid_load: bool = False           # load faces loaded by a fluid pressure (−p n)
    interface_normals: Mapping[str, tuple | None] = field(default_factory=dict)   # unit normal of a
    #                                    planar interface (None: not planar; absent: not inspected)
    report: tuple[str, ...] = ()       # what the builder found (bodies, volumes, interfaces), for check
    warnings: tuple[str, ...] = ()     # what the builder found suspect (a pad off the disc), one line each
    interface_regions: Mapping[str, str] = field(default_factory=dict)   # interface -> region of
    #                                    body 0 along it (default: body 0's first region)
    symmetry: Mapping[str, tuple] = field(default_factory=dict)   # face -> unit normal of a symmetry
    #                                    plane there (the model is a part of a symmetric whole)
    interface_extents: Mapping[str, tuple] = field(default_factory=dict)   # planar interface -> size
    #                                    (u, v) [m] of its face in its plane's frame (``plane_extent``),
    #                                    known before meshing (absent: known from the mesh only)
    interface_areas: Mapping[str, float] = field(default_factory=dict)   # interface -> its face's area
    #                                    [m^2], known before meshing (absent: known from the mesh only)
    crossed: float | None = None       # share of the rotating body's surface area that its rotation crosses
    #                                    (vanes, holes: > 0; a body of revolution: 0), None: known from the mesh only
    interface_sizes: Mapping[str, float] = field(default_factory=dict)   # interface -> element size [m]
    #                                    the mesher aims at on it (absent: unknown before meshing)
    load_areas: Mapping[str, float] = field(default_factory=dict)   # load face -> the area [m^2] whose
    #                                    product with a pressure is its resultant, known before meshing (a
    #                                    builder's; absent: known from the mesh only, ``load_face_areas``)
    element_size: float | None = None    # m, a mesh file's: the largest of its bodies' mean tetrahedron
    #                                    edges (a builder's or CAD's: its mesh_size)

    @property
    def materials(self) -> tuple[str, ...]:
        """Names of the material tables the geometry needs, in first-use order."""
        names = [r.material for b in self.bodies for r in b.regions]
        return tuple(dict.fromkeys(names))

    def interface_materials(self, interface: str | None = None) -> tuple[str, str]:
        """Names of the materials on both sides of an interface (default: the first one): body 0's
        region along it, and body 1's first region."""
        interface = interface if interface is not None else next(iter(self.interfaces))
        name = self.interface_regions.get(interface, self.bodies[0].regions[0].name)
        region = next(r for r in self.bodies[0].regions if r.name == name)
        return region.material, self.bodies[1].regions[0].material


def plane_frame(normal) -> np.ndarray:
    """The frame (3, 3) of a plane, rows e_u, e_v, n, of its unit ``normal``: (x, y, z) itself for a
    normal along ±z; otherwise e_u is x projected on the plane (or y, if x is nearly normal to it)
    and e_v = n x e_u (the frame of rough interfaces' zones)."""
    n = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    if abs(n[2]) > 1 - 1e-12:
        return np.eye(3)
    e_u = np.array([1.0, 0.0, 0.0]) - n[0] * n
    e_u = e_u if np.linalg.norm(e_u) > 1e-6 else np.array([0.0, 1.0, 0.0]) - n[1] * n
    e_u /= np.linalg.norm(e_u)
    return np.array([e_u, np.cross(n, e_u), n])


def plane_extent(normal, lo, hi) -> tuple[float, float]:
    """Size (u, v) [m] of the box [lo, hi] (3-D corners [m]) along e_u, e_v of ``plane_frame(normal)``:
    the spread of its corners there, sum_i |e_i| (hi_i - lo_i)."""
    span = np.abs(plane_frame(normal)[:2]) @ (np.asarray(hi, dtype=float) - np.asarray(lo, dtype=float))
    return float(span[0]), float(span[1])


BUILDER_GROUP = "multiscale.builders"
FIXED_BODY = "fixed"         # body 0 of a geometry file: every fixed body of it, each a material region


@cache
def _registered() -> dict[str, str]:
    """{name: module} of the builders registered in the entry-point group ``multiscale.builders``,
    read once per process: the lookup reads every installed distribution's metadata (13-20 ms),
    and a scene asks for its builder a few times per run (241 times in test_duty_cycle: 4.9 s)."""
    return {ep.name: ep.value for ep in entry_points(group=BUILDER_GROUP)}


def builder_names() -> tuple[str, ...]:
    """Names of the registered mesh builders."""
    return tuple(sorted(_registered()))


def builder(name: str) -> ModuleType:
    """The builder module registered as ``name`` (InputError naming the known builders)."""
    module = _registered().get(name)
    if module is None:
        raise InputError("geometry.builder", name, f"one of {', '.join(builder_names())}")
    return import_module(module)


def resolve_parameters(defaults: Mapping[str, object], params: Mapping[str, object] | None,
                       builder: str) -> dict:
    """Defaults updated by ``params``; unknown keys and bad sizes raise InputError.

    Every parameter is a float that must be > 0, or >= 0 when its default is 0 (0 meaning
    "use the documented fallback").
    """
    params = dict(params or {})
    unknown = sorted(set(params) - set(defaults))
    if unknown:
        raise InputError(f"geometry.{unknown[0]}", params[unknown[0]],
                         f"unknown parameter of builder {builder!r}; known: {', '.join(sorted(defaults))}")
    out = dict(defaults)
    out.update(params)
    for key, value in out.items():
        out[key] = check_positive(f"geometry.{key}", value, allow_zero=float(defaults[key]) == 0.0)
    return out


THIN = 3.0      # element size over a body's thickness beyond which check warns (``thin_warning``)


def loose_bodies(warnings) -> dict[str, str]:
    """The bodies a file's builder found sharing no face with the rotating body (its "geometry.bodies:
    ... share no face" warnings, ``meshes.from_file``), each with its warning's text (whole names: "pad"
    is not "pad_b", a review)."""
    out = {}
    for w in warnings:
        text = w.removeprefix("geometry.bodies: ")
        group, found, _ = text.partition(" share no face")
        if found and text != w:
            out.update(dict.fromkeys(group.split(", "), text))
    return out


def thin_warning(bodies, how: str = "") -> list[str]:
    """The warning (a list of one, or none) of the bodies of ``bodies``, (name, thickness [m],
    element size [m]) each, meshed at elements more than ``THIN`` times as thick as they are (``how``
    the thickness was found, said after them): about one element across them, their bending and
    temperatures unresolved (a 1 mm disc under 12 mm elements deflected 44 um, under 4 mm 329 um,
    and a 0.1 mm one 5 um: a lab-geometry trial)."""
    thin = [f"{name} (about {t * 1e3:.3g} mm, meshed at {size * 1e3:.3g} mm)" for name, t, size in bodies
            if size > THIN * t]
    return [f"geometry.mesh_size: elements more than {THIN:g} times as thick as the bodies {', '.join(thin)}{how}: "
            "about one element across them, their stresses and temperatures unresolved; smaller mesh sizes "
            "resolve them"] if thin else []


def named_key(given: Mapping | None, keys: tuple[str, str], default: str) -> str:
    """Which of two builder parameters an error about both names: the one the user's parameters
    ``given`` hold, ``default`` if they hold both or neither."""
    held = [k for k in keys if k in (given or {})]
    return held[0] if len(held) == 1 else default


def require_below(p: Mapping[str, float], given: Mapping | None, small: str, large: str, *, strict: bool = True,
                  why: str = "", dependent: str | None = None) -> None:
    """InputError unless p[small] < p[large] (<= unless ``strict``), naming the key of the two that
    the user's parameters ``given`` hold (``named_key``; ``dependent`` if both or neither, default
    ``small``), with the other's value [m]."""
    if p[small] < p[large] or (not strict and p[small] == p[large]):
        return
    named = named_key(given, (small, large), dependent or small)
    name, other, relation = (large, small, ">") if named == large else (small, large, "<")
    raise InputError(f"geometry.{name}", p[name], f"must be {relation}{'' if strict else '='} {other} "
                     f"({p[other]:g} m){why}")


MAX_CELLS = 1_000_000        # default refusal limit of estimate_cells (geometry.max_cells, run --max-cells)
OVER = 2.5     # the largest over-estimate of a trial's count times factor^3 (tests: 0.9-2.1x; 1.1-1.5x from 20k cells)
LARGEST_TRIAL = 1.5   # a trial refined on near the limit has at most about this times the limit's cells


@dataclass(frozen=True)
class CellEstimate:
    """Cells (tetrahedra) a builder's mesh will have: ``trial`` cells of a trial mesh with every
    element size multiplied by ``factor`` (gmsh ``Mesh.MeshSizeFactor``), scaled as a volume mesh:
    ``cells = trial * factor**3``. Exact for factor 1; above, mostly an over-estimate (features
    that a coarse mesh cannot coarsen keep cells): from 0.9x to 2x the count for the built-in
    builders (tests; measured 1.0-1.3x from trials of 20 000 cells)."""

    cells: int
    trial: int
    factor: float
    nodes: int = 0     # the bodies' vertices, each body a mesh of its own (``mesh_counts``); 0: not counted
    edges: int = 0     # the bodies' edges, likewise

    @property
    def exact(self) -> bool:
        return self.factor == 1.0


def mesh_counts(model, bodies: Sequence[Sequence[int]]) -> tuple[int, int]:
    """Vertices and edges of the tetrahedra of ``model``'s mesh, summed over ``bodies`` (each the
    cell tags, 3-D physical groups, of one body) as the run's bodies are meshes of their own (a face
    two bodies share counted in each); (0, 0) where a body has cells other than linear tetrahedra."""
    nodes = edges = 0
    for tags in bodies:
        tets = []
        for entity in (e for t in tags for e in model.getEntitiesForPhysicalGroup(3, t)):
            types, _, node_tags = model.mesh.getElements(3, entity)
            if any(kind != 4 for kind in types):
                return 0, 0
            tets += [np.asarray(n, dtype=np.int64).reshape(-1, 4) for n in node_tags]
        if not tets:
            continue
        t = np.concatenate(tets)
        pairs = np.sort(np.stack([t[:, [0, 0, 0, 1, 1, 2]].ravel(), t[:, [1, 2, 3, 2, 3, 3]].ravel()]), axis=0)
        nodes += np.unique(t).size
        edges += np.unique(pairs[0] * (int(t.max()) + 1) + pairs[1]).size
    return nodes, edges


def _extrapolated(counted: list[tuple[int, int, int]], cells: float) -> tuple[int, int]:
    """Vertices and edges of a mesh of ``cells`` cells from trials' (cells, vertices, edges): as
    a C + b C^(2/3) (volume and surface) through the last two, or in proportion to the last one's
    cells when it alone is there or the fit is not increasing."""
    c1, *last = counted[-1]
    ratio = [round(x * cells / c1) for x in last]
    if len(counted) < 2 or counted[-2][0] >= c1:
        return tuple(ratio)
    c0, *first = counted[-2]
    out = []
    for x0, x1, guess in zip(first, last, ratio):
        a, b = np.linalg.solve([[c0, c0 ** (2 / 3)], [c1, c1 ** (2 / 3)]], [x0, x1])
        fit = a * cells + b * cells ** (2 / 3)
        out.append(round(fit) if a > 0 and fit >= x1 else guess)
    return tuple(out)


def start_gmsh() -> None:
    """``gmsh.initialize``, quiet, without its Ctrl-C handler, and with Python's handlers of SIGPIPE,
    SIGTERM and SIGHUP kept (``signals.keep_python_handlers``: gmsh sets them to the default)."""
    import gmsh   # local: this module stays importable without gmsh's library (scene reading)
    gmsh.initialize(interruptible=False)
    keep_python_handlers()
    gmsh.option.setNumber("General.Terminal", 0)


def gmsh_session(module: ModuleType) -> None:
    """Start gmsh for a run of the builder ``module`` on the calling rank: quiet, one thread (the
    same mesh on every run), an empty model; the caller ends it with ``gmsh.finalize()``."""
    import gmsh   # local: as in start_gmsh
    start_gmsh()
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.model.add(f"multiscale_{getattr(module, 'NAME', module.__name__)}")


def estimate_cells(module: ModuleType, params, target: int = 20_000, start: float = 64.0,
                   enough: int = 0, keep: bool = False, length_scale: float | None = None,
                   bodies: Sequence[Sequence[int]] = (), inspect=None) -> CellEstimate:
    """Estimate the cell count of ``module.generate(params)`` without meshing it at its size: trial
    meshes from ``start`` times coarser, refined until one has ``target`` cells or is the real mesh
    (a trial the CAD kernel cannot mesh that coarse is skipped), or until the estimate is at most
    ``enough`` (an over-estimate below a limit settles the question). An estimate above ``enough``
    but within ``OVER`` times it is refined on while the finer trial would have at most about
    ``LARGEST_TRIAL`` times ``enough`` cells (by the same factor^3 rule: its real count is lower),
    so that a mesh within the limit is not refused for the over-estimate (the car
    brake at 3 / 1.5 mm was estimated from a 25 000-cell trial at 1.32x its count, 429 315 cells;
    at 2.5 / 1.2 mm at 1.008M cells, above the default limit). The trials share one gmsh
    session on the calling rank: the builder runs once and later trials remesh its model (the same
    mesh as a fresh run's, tested), so a CAD file is read and fragmented once; a failed meshing
    ends the session (gmsh cannot mesh again after a failed 3-D meshing) and the next trial runs
    the builder anew. A mesh read from a file is counted as it is. gmsh must not be initialised by
    the caller; the builder's errors at factor 1 propagate. With ``keep`` and an estimate of at
    most ``enough``, the session is left open holding the real mesh (factor 1) for the caller to
    read and end with ``gmsh.finalize()``; otherwise it is ended. With the geometry's
    ``length_scale`` [m], the first trial's elements are at least length_scale / 16 (a mesh size
    of 12 um on a 300 mm brake made the first trial, 64 times coarser, mesh for minutes). With
    ``bodies`` (each body's cell tags), its vertices and edges too (``mesh_counts`` of the trials,
    ``_extrapolated``; exact with the mesh; from trials, quadratic dofs a cell within 3 % of the
    mesh's on the built-in brake and pin-on-disc, 7 % on the car brake at 5 / 3 mm: the cells'
    over-estimate is the larger error). ``inspect(gmsh.model)`` is called on the mesh the estimate
    comes from (the last trial's), its errors propagated (``check --cells`` runs ``held.check_held``
    there: a part nothing holds was refused by the run alone, at meshing: a user trial)."""
    import gmsh   # local, as in gmsh_session
    if gmsh.isInitialized():
        raise RuntimeError("estimate_cells runs gmsh sessions of its own: call it before gmsh.initialize")
    factor = float(start)
    sizes = [v for k, v in module.parameters(params).items() if k.endswith("mesh_size") and v] \
        if length_scale and hasattr(module, "parameters") else []
    if sizes:
        factor = max(factor, length_scale / (16 * min(sizes)))
    counted = []      # (cells, vertices, edges) of the trials, with bodies
    try:
        while True:
            trial = _trial(module, params, factor)
            if trial and all(gmsh.model.getType(3, t) == "Discrete volume" for _, t in gmsh.model.getEntities(3)):
                factor = 1.0           # a mesh read from a file: no size factor changes it
            if trial and bodies:
                counted.append((trial, *mesh_counts(gmsh.model, bodies)))
            grow = (target / trial) ** (1 / 3) if trial else 4.0     # a failed trial: its session is gone, skip ahead
            finer = factor / max(2.0, min(grow, 8.0))
            finer = 1.0 if finer < 1.25 else finer         # nearly the mesh: mesh it
            cells = trial * factor ** 3
            # near the limit, refine on while the finer trial (about cells / finer^3) stays small enough
            near = 0 < enough < cells <= OVER * enough and cells / finer ** 3 <= LARGEST_TRIAL * enough
            if factor == 1.0 or (trial >= target and not near) or 0 < cells <= enough:
                known = counted and counted[-1][0] == trial and all(counted[-1])
                estimate = CellEstimate(int(round(cells)), trial, factor,
                                        *(_extrapolated(counted, cells) if known else ()))
                break
            factor = finer
        if inspect is not None and gmsh.isInitialized():
            inspect(gmsh.model)
        if keep and estimate.cells <= enough:
            if not estimate.exact:
                _trial(module, params, 1.0)
            return estimate
    except BaseException:
        if gmsh.isInitialized():
            gmsh.finalize()
        raise
    gmsh.finalize()
    return estimate


def _trial(module: ModuleType, params, factor: float) -> int:
    """Tetrahedra of the builder's mesh with every size times ``factor``: the open session's model
    remeshed, or the builder run in a new session; 0 for a failed trial above factor 1 (its
    session ended); at factor 1, the error of the builder's own run."""
    import gmsh   # local, as in gmsh_session
    built = gmsh.isInitialized()
    try:
        if built:
            gmsh.model.mesh.clear()
        else:
            gmsh_session(module)
        gmsh.option.setNumber("Mesh.MeshSizeFactor", factor)
        if built:
            getattr(module, "remesh", lambda model, params: model.mesh.generate(3))(gmsh.model, params)
        else:
            module.generate(gmsh.model, params)
    except Exception:        # e.g. "PLC Error": too coarse for the geometry's features
        gmsh.finalize()
        if factor == 1.0:
            if built:            # the builder's own run, whose error says what to change
                return _trial(module, params, factor)
            raise
        return 0
    return sum(len(t) for t in gmsh.model.mesh.getElements(3)[1])


def check_cells(module: ModuleType, params, max_cells: int, keep: bool = False,
                length_scale: float | None = None) -> CellEstimate:
    """``estimate_cells`` against a limit: InputError (naming geometry.max_cells, the estimate and
    what to change) if the mesh would have more than ``max_cells`` cells. With ``keep``, a mesh
    within the limit is left meshed in the open gmsh session (``estimate_cells``)."""
    estimate = estimate_cells(module, params, enough=max_cells, keep=keep, length_scale=length_scale)
    if estimate.cells > max_cells:
        raise too_many_cells(estimate, max_cells)
    return estimate


def too_many_cells(estimate: CellEstimate, max_cells: int) -> InputError:
    """The error of a mesh estimated above ``max_cells`` (what to change)."""
    size = f"{estimate.cells} cells (exact)" if estimate.exact else \
        f"about {estimate.cells:.3g} cells (a trial mesh {estimate.factor:.3g}x coarser has {estimate.trial})"
    return InputError("geometry.max_cells", max_cells,
                      f"the mesh would have {size}: coarsen the geometry's mesh sizes (geometry.mesh_size "
                      "and the other *mesh_size), or allow it with the scene key geometry.max_cells (also "
                      "multiscale run --max-cells)")


# ---- gmsh helpers shared by the builders (model is ``gmsh.model``) ----------------------------

OCC_BOX = 1e-7      # OpenCASCADE enlarges every entity's bounding box by this (Precision::Confusion) [m]


def entities_in_box(model, dim: int, lo: Sequence[float], hi: Sequence[float]) -> list[int]:
    """Tags of the dim-entities whose bounding box lies inside [lo, hi] (OCC, synchronized), the
    box taken 2 ``OCC_BOX`` wider on every side: a selection whose own margin was below OCC's
    enlargement selected nothing (a pin face of 1.5 mm with a margin of 1e-4 of it)."""
    pad = 2 * OCC_BOX
    return [tag for _, tag in model.getEntitiesInBoundingBox(*(x - pad for x in lo), *(x + pad for x in hi), dim)]


def entities_where(model, dim: int, predicate) -> list[int]:
    """Tags of the dim-entities whose centre of mass c (x, y, z) satisfies ``predicate(c)``."""
    return [tag for _, tag in model.getEntities(dim)
            if predicate(np.asarray(model.occ.getCenterOfMass(dim, tag)))]


def add_group(model, dim: int, tags: Sequence[int], tag: int, name: str) -> None:
    """Physical group ``tag`` named ``name``; an empty selection is a builder bug."""
    if not tags:
        raise RuntimeError(f"builder selected no entities for physical group {name!r}")
    model.addPhysicalGroup(dim, list(tags), tag, name=name)

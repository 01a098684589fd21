"""What a mesh builder tells the macro model (bodies, material regions, tagged faces, motion), and
the registry of builders.

A builder (the modules of ``meshes/``: ``block_on_flat``, ``pin_on_disc``, ``disc_brake``, or a
user's own) is a module providing ``DEFAULTS`` (its parameters in SI units), optionally
``PARAMETER_KINDS`` (unit kind of a parameter, default "length", or "angle" when the name says so),
``parameters(params) -> dict`` (defaults updated and checked), ``describe(params) ->
GeometrySpec`` (pure Python: tags, bodies, supports) and ``generate(model, params)`` (builds and
meshes the gmsh model on one rank). Builders are found by name in the ``multiscale.builders``
entry-point group (``pyproject.toml``: the registry is package metadata, so a scene never imports
``meshes`` and a user's package can add builders). This module holds the spec dataclasses, the
registry lookup and small gmsh helpers; it imports neither DOLFINx nor gmsh.

Conventions: body 0 is the "+" side of the interface (the stationary body: pin, pads, block),
body 1 the "−" side (the sliding body: disc, flat). The interface normal n points from body 1
into body 0; the gap g_n = g_0 + (u_0 − u_1)·n is positive when open (thesis §1.4).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from importlib import import_module
from importlib.metadata import entry_points
from types import ModuleType
from typing import Mapping, Sequence

import numpy as np

from multiscale.errors import InputError, check_positive


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


@dataclass(frozen=True)
class Translation:
    """Rigid translation of body 1 along the unit vector ``direction``: w = v e [m/s]."""

    direction: tuple[float, float, float] = (1.0, 0.0, 0.0)


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
    interface_regions: Mapping[str, str] = field(default_factory=dict)   # interface -> region of
    #                                    body 0 along it (default: body 0's first region)

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


BUILDER_GROUP = "multiscale.builders"


def builder_names() -> tuple[str, ...]:
    """Names of the registered mesh builders (entry-point group ``multiscale.builders``)."""
    return tuple(sorted(ep.name for ep in entry_points(group=BUILDER_GROUP)))


def builder(name: str) -> ModuleType:
    """The builder module registered as ``name`` (InputError naming the known builders)."""
    found = [ep for ep in entry_points(group=BUILDER_GROUP) if ep.name == name]
    if not found:
        raise InputError("geometry.builder", name, f"one of {', '.join(builder_names())}")
    return import_module(found[0].value)


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


# ---- gmsh helpers shared by the builders (model is ``gmsh.model``) ----------------------------

def entities_in_box(model, dim: int, lo: Sequence[float], hi: Sequence[float]) -> list[int]:
    """Tags of the dim-entities whose bounding box lies inside [lo, hi] (OCC, synchronized)."""
    return [tag for _, tag in model.getEntitiesInBoundingBox(*lo, *hi, dim)]


def entities_where(model, dim: int, predicate) -> list[int]:
    """Tags of the dim-entities whose centre of mass c (x, y, z) satisfies ``predicate(c)``."""
    return [tag for _, tag in model.getEntities(dim)
            if predicate(np.asarray(model.occ.getCenterOfMass(dim, tag)))]


def add_group(model, dim: int, tags: Sequence[int], tag: int, name: str) -> None:
    """Physical group ``tag`` named ``name``; an empty selection is a builder bug."""
    if not tags:
        raise RuntimeError(f"builder selected no entities for physical group {name!r}")
    model.addPhysicalGroup(dim, list(tags), tag, name=name)

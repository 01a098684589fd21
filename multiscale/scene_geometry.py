"""[geometry] of a scene: a registered mesh builder with its parameters, or the user's own file.

A builder (``builder = "pin_on_disc"``; the registry of ``multiscale.geometry``) takes its
parameters as keys of [geometry]. A file (``file = "brake.step"``: a gmsh mesh ``.msh``, a gmsh
script ``.geo``, or CAD through OpenCASCADE: ``.step``/``.stp``, ``.iges``/``.igs``, ``.brep``) names
its bodies in [geometry.bodies.<name>] (volumes chosen by physical-group name or CAD label, by
index, or as "the volume containing a point"; each with its material), the rotating body and its
axis, named surfaces for boundary conditions and loads in [geometry.surfaces.<name>], and
optionally the contact interfaces in [geometry.interfaces.<name>] (default: every face where a
fixed body touches the rotating one, one interface per fixed body, named after it). The file
builder (``meshes.from_file``, registered as "file") inspects the file when the scene is read, so
that ``multiscale check`` reports bodies, volumes, interfaces, areas and normals before meshing.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from multiscale.errors import InputError, InputErrors
from multiscale.geometry import FIXED_BODY, MAX_CELLS, GeometrySpec, Rotation, Support, builder, builder_names
from multiscale.outputs import name_problem
from multiscale.schema import (Bad, Choice, FilePath, FrozenMap, Integer, ListOf, Named, OneOf, OnlyWith, Quantity,
                               Section, Text, Vector, key, parse, read, show, suggest, unknown_keys)
from multiscale.schema import reference as schema_reference
from multiscale.scene_plain import contains_hint
from multiscale.units import UnitError, to_si

_LENGTH = Quantity("length", gt=0)


class Direction(Vector):
    """Three numbers [x, y, z], not all zero: a direction (normalised where it is used)."""

    def __call__(self, raw, ctx):
        value = super().__call__(raw, ctx)
        if not any(value):
            raise Bad("must not be zero: it is a direction")
        return value


POINT = Vector(Quantity("length"))
_DIRECTION = Direction(Quantity("dimensionless"))
# plausible builder parameters by kind (SI; warned outside): lengths of a tribometer or brake part
_PLAUSIBLE = {"length": (1e-5, 10.0), "angle": (0.0, 6.2832)}
MESH_ALGORITHMS = ("hxt", "delaunay")     # gmsh's 3-D algorithms a file can be meshed with
FILE_TYPES = {".msh": "mesh", ".geo": "script", ".step": "cad", ".stp": "cad", ".iges": "cad", ".igs": "cad",
              ".brep": "cad"}


class Points:
    """One point [x, y, z] or a list of points, as a tuple of points."""

    def describe(self) -> str:
        return f"a point {POINT.describe()}, or a list of such points"

    def __call__(self, raw, ctx):
        if isinstance(raw, list) and raw and all(isinstance(r, list) for r in raw):
            return tuple(POINT(r, ctx) for r in raw)
        return (POINT(raw, ctx),)


class LengthUnit:
    """The name of a length unit ("mm", "m", "in"), as its size in metres."""

    def describe(self) -> str:
        return 'a length unit such as "m", "mm", "in"'

    def __call__(self, raw, ctx):
        try:
            return to_si(f"1 {raw}", "length") if isinstance(raw, str) else None
        except UnitError as exc:
            raise Bad(str(exc)) from None


@dataclass(frozen=True)
class BodySelection:
    """[geometry.bodies.<name>]: the volumes of one body, picked by ``volumes`` (physical names or
    CAD labels), ``index`` (the file's volume numbers) or ``contains`` (points inside them), and its
    ``material`` (a [materials.<name>])."""

    volumes: tuple | None = key(ListOf(Text(), unique=True, min_len=1),   # physical names or CAD labels
                                absent="index or contains picks the volumes")
    index: tuple | None = key(ListOf(Integer(ge=1), unique=True, min_len=1),   # volume numbers of the file
                              absent="volumes or contains picks the volumes")
    contains: tuple | None = key(Points(), absent="volumes or index picks the volumes")   # m, points inside them
    material: str | None = key(Text(), required=True)

    rules = (OneOf(("volumes", "index", "contains"), required=True),)


@dataclass(frozen=True)
class SurfaceSelection:
    """[geometry.surfaces.<name>]: a named surface: a physical surface ``group`` of the file, or the
    faces of ``body`` whose outward ``normal`` is the given direction (within 5 degrees), or the
    faces through the points ``contains`` (of ``body`` if given; within 1e-4 of the model's size)."""

    group: str | None = key(Text(), absent="normal or contains picks the faces")
    body: str | None = key(Text(), absent="the faces of any body (normal needs it)")
    normal: tuple | None = key(_DIRECTION, absent="group or contains picks the faces")
    contains: tuple | None = key(Points(), absent="group or normal picks the faces")   # m, a point on each face

    rules = (OneOf(("group", "normal", "contains"), required=True), OnlyWith(("normal", "contains"), ("body",)))

    def problems(self, path, ctx):
        return [f"{path}.body: missing; needed with {path}.normal"] if self.normal is not None and self.body is None else []


@dataclass(frozen=True)
class ContactPair:
    """[geometry.interfaces.<name>]: a contact interface between a fixed body and the rotating one."""

    between: tuple | None = key(ListOf(Text(), unique=True, min_len=2), required=True)

    def problems(self, path, ctx):
        return [] if len(self.between) == 2 else [f"{path}.between: give two bodies"]


@dataclass(frozen=True)
class FileGeometry:
    """[geometry] from the user's file (see module docstring). The file's lengths are in ``unit`` if
    given; else a STEP or IGES file's are in the unit it declares (millimetres if it declares none,
    as OpenCASCADE reads it) and a .msh, .geo or .brep file's in metres. Every length of the scene
    is in SI (or a unit string)."""

    file: Path | None = key(FilePath(), required=True)
    unit: float | None = key(LengthUnit(), absent="a STEP/IGES file's declared unit (mm if it declares none); "
                             "metres for .msh, .geo, .brep")       # m per unit of the file's numbers
    mesh_size: float | None = key(_LENGTH, absent="a .msh file's own mesh; needed for the other files")   # m
    interface_mesh_size: float | None = key(_LENGTH, absent="mesh_size on the interfaces too")   # m
    mesh_algorithm: str | None = key(Choice(MESH_ALGORITHMS), absent='"hxt" for CAD files; a .geo script\'s own '
                                     "choice")                     # gmsh's 3-D mesher
    rotating: str | None = key(Text(), required=True)          # the body that rotates, one of revolution about
    axis: tuple = key(_DIRECTION, default=(0.0, 0.0, 1.0))     # its axis (or of n >= 3 equal sectors: checked on
    centre: tuple = key(POINT, default=(0.0, 0.0, 0.0))       # CAD, meshes.from_file); m, a point on the axis
    bodies: FrozenMap | None = key(Named(BodySelection), required=True)
    surfaces: FrozenMap = key(Named(SurfaceSelection), default=FrozenMap())
    interfaces: FrozenMap = key(Named(ContactPair), default=FrozenMap())

    @property
    def kind(self) -> str:
        """"mesh", "script" or "cad"."""
        return FILE_TYPES[self.file.suffix.lower()]

    def problems(self, path, ctx):
        out = []
        if self.file.suffix.lower() not in FILE_TYPES:
            out.append(f"{path}.file = \"{self.file.name}\": unknown type; allowed: {', '.join(FILE_TYPES)}")
        elif self.kind != "mesh" and self.mesh_size is None:
            out.append(f"{path}.mesh_size: missing; needed to mesh a {self.file.suffix} file")
        elif self.kind == "mesh":
            out += [f"{path}.{k}: not used with a {self.file.suffix} file (it is meshed already)"
                    for k in ("mesh_size", "interface_mesh_size", "mesh_algorithm") if getattr(self, k) is not None]
        elif (fine := self.interface_mesh_size) is not None and fine >= self.mesh_size:
            ctx.warnings.append(f"{path}.interface_mesh_size = {fine * 1e3:.4g} mm: not finer than mesh_size, "
                                f"{self.mesh_size * 1e3:.4g} mm, so the interfaces are meshed at mesh_size (it only "
                                "refines)")                                     # (it was silent: a user trial)
        if self.rotating not in self.bodies:
            out.append(f"{path}.rotating = \"{self.rotating}\": not a body; bodies: {', '.join(self.bodies)}")
        elif self.rotating == FIXED_BODY:
            out.append(f"{path}.rotating = \"{FIXED_BODY}\": is taken: the fixed bodies together are the body "
                       f"\"{FIXED_BODY}\" of the results (name the rotating body otherwise)")
        elif problem := name_problem(self.rotating, body=True):
            out.append(f"{path}.bodies.{self.rotating}: the rotating body's name {problem}")
        out += [f"{path}.{kind}.{name}: the name {problem}" for kind, names in (("bodies", self.bodies),
                                                                                ("interfaces", self.interfaces))
                for name in names if name != self.rotating and (problem := name_problem(name))]
        out += [f"{path}.bodies.{name}.material = \"{b.material}\": {problem}" for name, b in self.bodies.items()
                if b is not None and b.material is not None and (problem := name_problem(b.material))]
        if len(self.bodies) < 2:
            out.append(f"{path}.bodies: give at least two bodies (a fixed one and the rotating one)")
        for name, pair in self.interfaces.items():
            for b in pair.between:
                if b not in self.bodies:
                    out.append(f"{path}.interfaces.{name}.between: \"{b}\" is not a body; bodies: "
                               f"{', '.join(self.bodies)}")
            if self.rotating not in pair.between:
                out.append(f"{path}.interfaces.{name}.between: one of the two must be the rotating body "
                           f"\"{self.rotating}\"")
        for name, s in self.surfaces.items():
            if s.body is not None and s.body not in self.bodies:
                out.append(f"{path}.surfaces.{name}.body = \"{s.body}\": not a body; bodies: {', '.join(self.bodies)}")
        return out


@dataclass(frozen=True)
class Geometry:
    """[geometry]: a registered builder and its parameters (SI; the builder's ``DEFAULTS`` fill the
    rest), or a ``FileGeometry`` (``builder == "file"``). ``spec`` names the bodies (body 0 the
    stationary "+" side, body 1 the sliding side), material regions, faces, interfaces and motion."""

    builder: str
    params: object                    # FrozenMap of builder parameters, or a FileGeometry
    spec: GeometrySpec
    max_cells: int = MAX_CELLS        # a mesh estimated larger is refused before meshing

    def module(self):
        """The builder module (parameters, describe, generate)."""
        return builder(self.builder)

    def interface_size_key(self) -> str:
        """The geometry key that sets the interfaces' element size: a file's and most builders'
        interface_mesh_size, the built-in brake's pad_mesh_size, else mesh_size."""
        sizes = ("interface_mesh_size",) if self.builder == "file" else getattr(self.module(), "DEFAULTS", {})
        return next((k for k in ("interface_mesh_size", "pad_mesh_size") if k in sizes), "mesh_size")

    def resolved(self) -> dict:
        """Every builder parameter [SI] (the mesh sizes of a file)."""
        if isinstance(self.params, FileGeometry):
            return {k: getattr(self.params, k) for k in ("mesh_size", "interface_mesh_size")
                    if getattr(self.params, k) is not None}
        return self.module().parameters(dict(self.params))

    @property
    def bodies(self) -> tuple[str, str]:
        return tuple(b.name for b in self.spec.bodies)

    @property
    def regions(self) -> tuple[str, ...]:
        """Names of the material regions of both bodies."""
        return tuple(r.name for b in self.spec.bodies for r in b.regions)

    @property
    def materials(self) -> tuple[str, ...]:
        """Names of the [materials.<name>] tables the geometry needs."""
        return self.spec.materials

    @property
    def motion(self) -> str:
        """"rotation" (of body 1 about an axis) or "translation"."""
        return "rotation" if isinstance(self.spec.motion, Rotation) else "translation"

    @property
    def surfaces(self) -> tuple[str, ...]:
        """Names a boundary condition or a load can use: the named faces and "free:<region or body>"."""
        return tuple(self.spec.faces) + tuple(f"free:{n}" for n in dict.fromkeys(self.bodies + self.regions))


BUILDER_AXIS_TEXT = ("a rotating builder's axis (as it is) or its opposite, which turns the body the other way "
                     "(a brake's reverse run); default the builder's")
BUILDER_MATERIALS_TEXT = ('a table of part = "material" (a builder\'s parts: pin, housing, plate, disc, ...): those '
                          "parts take that [materials.<name>] table; default the builder's own material names")
MAX_CELLS_TEXT = ("a mesh estimated larger (trial meshes before meshing) is refused; multiscale run --max-cells "
                  "overrides it")


def parameter_kind(module, name: str) -> str:
    """Unit kind of a builder parameter: the module's PARAMETER_KINDS ("count": a whole number),
    else angle/length by name."""
    kinds = getattr(module, "PARAMETER_KINDS", {})
    return kinds.get(name, "angle" if "angle" in name else "length")


class GeometrySection(Section):
    """[geometry]: ``builder`` picks a built-in geometry (pin_on_disc, disc_brake, block_on_flat),
    whose parameters (lengths in m, SI defaults below) are the allowed keys, ``mesh_size`` and the
    other ``*_mesh_size`` the cell sizes; or ``file`` gives the user's own geometry (CAD or gmsh:
    the keys under file = "..."). ``max_cells`` bounds the mesh, ``axis`` turns a rotating body the
    other way, ``part_materials`` gives a builder's parts other materials than its own."""

    def __init__(self):
        super().__init__(Geometry)
        self.builders = Choice(tuple(n for n in builder_names() if n != "file"))
        self.key_schema = FileGeometry        # its keys' tables ([geometry.bodies.<name>], ...): --keys, --set

    def describe(self) -> str:
        return f"a table with builder = {self.builders.describe()} and its parameters, or file = \"...\""

    def reference(self, path) -> list[str]:
        lines = [f"  {'builder':<20}  {self.builders.describe()}  [or file]",
                 f"  {'max_cells':<20}  integer >= 1, default {MAX_CELLS}: {MAX_CELLS_TEXT}",
                 f"  {'axis':<20}  [x, y, z]: {BUILDER_AXIS_TEXT}",
                 f"  {'part_materials':<20}  {BUILDER_MATERIALS_TEXT}"]
        for name in self.builders.options:
            module = builder(name)
            lines.append(f"  builder = \"{name}\" parameters (SI defaults; 0 = the builder's fallback):")
            lines += [f"    {k:<22} {parameter_kind(module, k):<8} {v:g}" for k, v in module.DEFAULTS.items()]
        lines.append("  file = \"...\" (.msh, .geo, .step/.stp, .iges/.igs, .brep) with:")
        return lines + ["  " + line for line in schema_reference(FileGeometry, path)]

    def read(self, raw, path, ctx):
        if not isinstance(raw, dict):
            ctx.problems.append(f"{path} = {show(raw)}: must be {self.describe()}")
            return None
        limit = parse(Integer(ge=1), raw["max_cells"], f"{path}.max_cells", ctx) if "max_cells" in raw else MAX_CELLS
        raw = {k: v for k, v in raw.items() if k != "max_cells"}
        geometry = self._read(raw, path, ctx)
        return None if geometry is None else dataclasses.replace(geometry, max_cells=limit)

    def _read(self, raw, path, ctx):
        if "file" in raw:
            return self._read_file(raw, path, ctx)
        if "builder" not in raw:
            ctx.problems.append(f"{path}.builder: missing; required: {self.builders.describe()} (or file)")
            return None
        try:
            name = self.builders(raw["builder"], ctx)
            module = builder(name)
        except Bad as exc:
            ctx.problems.append(f"{path}.builder = {show(raw['builder'])}: {exc}")
            return None
        before = len(ctx.problems)
        given = {k: v for k, v in raw.items() if k not in ("builder", "axis", "part_materials")}
        axis = parse(_DIRECTION, raw["axis"], f"{path}.axis", ctx) if "axis" in raw else None
        unknown_keys(given, module.DEFAULTS, path, ctx, f'parameter of builder "{name}"')
        params = {}
        for param, value in given.items():
            if param in module.DEFAULTS:
                zero_ok = float(module.DEFAULTS[param]) == 0.0    # 0 means "builder's fallback"
                kind = parameter_kind(module, param)
                parser = Integer(ge=0 if zero_ok else 1) if kind == "count" else \
                    Quantity(kind, **({"ge": 0} if zero_ok else {"gt": 0}), plausible=_PLAUSIBLE.get(kind))
                params[param] = parse(parser, value, f"{path}.{param}", ctx)
        if len(ctx.problems) > before:
            return None
        geometry = self._describe(name, module, FrozenMap(params), params, ctx)
        if geometry is not None and "part_materials" in raw:
            geometry = self._materials(geometry, raw["part_materials"], f"{path}.part_materials", ctx)
        return geometry if geometry is None or axis is None else self._turned(geometry, axis, path, ctx)

    @staticmethod
    def _materials(geometry, raw, where, ctx):
        """A builder's geometry whose parts take the materials ``raw`` gives ({part: material name}; the
        others keep the builder's): a pin-on-disc's housing and plate took the disc's material, with
        no key to give them their own (a trial)."""
        parts = geometry.regions
        if not isinstance(raw, dict) or not all(isinstance(v, str) for v in raw.values()):
            ctx.problems.append(f'{where} = {show(raw)}: must be a table of part = "material" '
                                f'(parts: {", ".join(parts)})')
            return None
        bad = [f'{where}.{k}: not a part of builder "{geometry.builder}"; parts: {", ".join(parts)}'
               for k in raw if k not in parts]
        bad += [f'{where}.{k} = "{m}": the name {problem}' for k, m in raw.items() if (problem := name_problem(m))]
        if bad:
            ctx.problems.extend(bad)
            return None
        spec = geometry.spec
        bodies = tuple(dataclasses.replace(b, regions=tuple(dataclasses.replace(r, material=raw.get(r.name, r.material))
                                                            for r in b.regions)) for b in spec.bodies)
        return dataclasses.replace(geometry, spec=dataclasses.replace(spec, bodies=bodies))

    @staticmethod
    def _turned(geometry, axis, path, ctx):
        """A builder's geometry whose body turns about ``axis``: the builder's axis (as it is) or its
        opposite (the other sense of rotation: a brake's forward and reverse runs); any other axis,
        or a sliding body, is a problem."""
        motion = geometry.spec.motion
        if not isinstance(motion, Rotation):
            ctx.problems.append(f'{path}.axis: not used by builder "{geometry.builder}", whose body slides')
            return None
        def unit(v):
            return tuple(float(a) / sum(float(b) ** 2 for b in v) ** 0.5 for a in v)
        own, given = unit(motion.axis), unit(axis)
        if max(abs(a - b) for a, b in zip(given, own)) < 1e-9:
            return geometry
        if max(abs(a + b) for a, b in zip(given, own)) < 1e-9:
            spec = dataclasses.replace(geometry.spec, motion=dataclasses.replace(motion, axis=tuple(-a for a in own)))
            return dataclasses.replace(geometry, spec=spec)
        ctx.problems.append(f'{path}.axis = {list(axis)}: builder "{geometry.builder}" turns its body about '
                            f"{list(own)}: give that axis or its opposite {[-a or 0.0 for a in own]} (the other "
                            "sense of rotation)")
        return None

    def _read_file(self, raw, path, ctx):
        before = len(ctx.problems)
        if "builder" in raw:
            ctx.problems.append(f"{path}.builder: give either builder or file")
        params = read(FileGeometry, {k: v for k, v in raw.items() if k != "builder"}, path, ctx)
        if len(ctx.problems) > before:
            return None
        return self._describe("file", builder("file"), params, params, ctx, lambda exc: contains_hint(raw, path, exc))

    @staticmethod
    def _describe(name, module, params, arguments, ctx, hint=lambda exc: ""):
        try:
            spec = module.describe(arguments)        # the builder's consistency checks; a file is inspected
        except InputError as exc:
            ctx.problems += [str(e) + hint(e) for e in InputErrors.each(exc)]
            return None
        return Geometry(name, params, spec)


def scene_spec(scene) -> GeometrySpec:
    """The geometry's spec with the scene's supports, load faces and load direction."""
    spec, ld = scene.geometry.spec, scene.loading
    supports = spec.supports + tuple(Support(s, b.components) for b in scene.boundary if b.fix for s in b.surfaces)
    changes = {"supports": supports}
    if ld.faces:
        changes["load_faces"] = tuple(ld.faces)
    if ld.direction is not None:
        changes.update(load_direction=tuple(ld.direction), fluid_load=False)
    return dataclasses.replace(spec, **changes)


def material_problems(g: Geometry, materials, where: str, ctx) -> list[str]:
    """The [materials] tables ``materials`` against those the geometry ``g`` needs (``where``: its
    name in messages): problems appended to ``ctx.problems``, the warnings returned. A name the
    scene wrote on a body (``geometry.bodies.<body>.material``) with no table is that key's problem,
    with the table it likely means (a misspelt "cast_iorn" was said of the right table, advising
    the misspelling: a user trial); a builder's name missing is the table's, or a misspelt table's;
    a spare table (a library's) is warned unused, its own problems with it."""
    problems, warnings = ctx.problems, []
    missing = [m for m in g.materials if m not in materials]
    spare = [n for n in materials if n not in g.materials]
    bodies = g.params.bodies if isinstance(g.params, FileGeometry) and g.params.bodies else {}
    written = {}
    for body, selection in bodies.items():
        if selection is not None and selection.material in missing:
            written.setdefault(selection.material, []).append(body)
    meant = set()
    for m, names in written.items():
        hint = suggest(m, spare)
        meant.update(hint.split('"')[1:2])
        problems.extend(f'geometry.bodies.{b}.material = "{m}": no [materials.{m}] table{hint}; tables: '
                        f'{", ".join(materials) or "none"}' for b in names)
    missing = [m for m in missing if m not in written]
    near = {name: suggest(name, missing) for name in spare if name not in meant}
    typos = unknown_keys({n: 0 for n, hint in near.items() if hint}, g.materials, "materials", ctx, f"material of {where}")
    for name in (n for n, hint in near.items() if not hint):     # a library's spare tables: their problems
        own = [p for p in problems if p.startswith((f"materials.{name}.", f"materials.{name}:"))]  # warned
        problems[:] = [p for p in problems if p not in own]
        warnings.append(f"materials.{name} is not used: {where} has the materials {', '.join(g.materials)}"
                        + (f" (ignored with its problems: {', '.join(p.split(': ')[0] for p in own)})" if own else ""))
    problems.extend(f'materials.{name}: missing; {where} needs the materials {", ".join(g.materials)}'
                    for name in missing if name not in typos)
    return warnings


def fluid_faces_left_out(g: Geometry, faces, where: str) -> list[str]:
    """The warning if ``faces`` (loading.faces) leave out some of a builder's fluid-loaded faces
    (``GeometrySpec.fluid_load``): the fluid pushes on all of them, and a part whose face is left
    out (the built-in brake's floating caliper, its bore) is held by an unpressed contact alone,
    which the run refuses after its first solve (said only then: a user trial)."""
    out = [f for f in g.spec.load_faces if f not in (faces or g.spec.load_faces)] if g.spec.fluid_load else []
    return [f"loading.faces = {list(faces)}: leaves out {', '.join(out)}, where {where}'s fluid pressure acts too; "
            "a part pressed only there (a floating caliper) is then held by no force, and the run stops after its "
            "first solve"] if out else []

"""The scene: a TOML file -> validated, frozen dataclasses in SI units (thesis §7.3.1 set-up).

``load(path) -> Scene``; ``multiscale check scene.toml`` lists every problem at once. The schema is
declarative: each table is a frozen dataclass whose fields say how their TOML key is read (unit
kind, range, default, which effects need it; see ``multiscale.schema``): [geometry] in
``multiscale.scene_geometry``, the other tables in ``multiscale.scene_sections``. A new section is
one dataclass and one field of ``Scene``, a new effect one ``EFFECTS`` entry. Values are numbers
(SI) or unit strings ("200 rpm", "4 GPa", "20 degC"; ``multiscale.units``); relative paths are
taken from the scene file's directory. Code asks ``scene.has("thermal")``.

Sections: geometry (a builder and its parameters, or a file with its bodies), materials (one table
per material the geometry names), interface (defaults) and interfaces (per interface), boundary
(supports, convection, radiation, fixed temperatures), loading (load, speed, duty cycle), time,
output; roughness, micro, wear and layers (the multiscale loop); stability (the squeal analysis).
"""
from __future__ import annotations

import dataclasses
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multiscale.errors import InputError, SceneError, read_toml_text, toml_problem
from multiscale.geometry import loose_bodies
from multiscale.schema import (Choice, Context, FrozenMap, ListOf, Named, Section, Tables, Text, fields_of, key,
                               read, reference, show)
from multiscale.scene_geometry import FileGeometry, Geometry, GeometrySection, fluid_faces_left_out, material_problems
from multiscale.scene_plain import plain_speeds
from multiscale.scene_rough import (law_top_warnings, measured_cover, micro_constants, nyquist, own_surface_tables,
                                    own_tables, penalty_range, perfect_contact, plastic_everywhere, pressure_range,
                                    rough_rules,
                                    roughness_over, thin_layer, zone_sizes)
from multiscale.scene_output import OUTPUT_FIELDS, Output, output_problems
from multiscale.scene_sections import (COUPLING_DEFAULT, Boundary, Interface, InterfaceSettings, Layers, Loading,
                                       Material, Micro, Roughness, Time)
from multiscale.scene_cycle import convection_coverage, cycle_coverage, short_phases, speed_range, thin_heated_layers
from multiscale.scene_keys import drop_replaced, given_paths, key_parts
from multiscale.scene_friction import fade_coverage, fade_tables, friction_checks, speed_law_zeros, torque_problems
from multiscale.scene_stability import Stability, stability_warnings
from multiscale.scene_vehicle import Vehicle
from multiscale.scene_wear import FIG_7_9_CALIBRATION, FIG_7_9_WEAR_RATE, Wear

__all__ = ["COUPLING_DEFAULT", "EFFECTS", "FIG_7_9_CALIBRATION", "FIG_7_9_WEAR_RATE", "OUTPUT_FIELDS", "Boundary",
           "Geometry", "Interface", "InterfaceSettings", "Loading", "Material", "Scene", "Vehicle", "default_wear_rate",
           "load", "loads"]


# ------------------------------------------------------------------ effects
@dataclass(frozen=True)
class Effect:
    doc: str
    requires: tuple[str, ...] = ()   # other effects it builds on


EFFECTS: dict[str, Effect] = {
    "contact": Effect("normal contact through the interface: penalty p_n = K_n <-g_n>_+ "
                      "(perfect contact), or the rough per-facet laws with 'roughness'"),
    "friction": Effect("Coulomb sliding friction mu p_n along the sliding direction", ("contact",)),
    "thermal": Effect("transient heat conduction in every body (the disc in its Eulerian frame), with the "
                      "[[boundary]] conditions (convection, radiation, fixed temperatures)"),
    "heat_partition": Effect("frictional heat mu p_n |v| split between the two interface bodies "
                             "by interface.partition", ("thermal", "friction")),
    "conductance": Effect("heat conduction across the interface, h_c = interface.conductance",
                          ("thermal", "contact")),
    "expansion": Effect("thermal expansion alpha (T - T0) in the mechanics", ("thermal",)),
    "roughness": Effect("rough interface: per-zone homogenized laws from micro patches "
                        "([roughness], [micro])", ("contact",)),
    "layers": Effect("layered near-surface material in the micro models ([layers])", ("roughness",)),
    "wear": Effect("Archard wear ([wear]) of the rough zones (a step's wear held in series with the zone laws, the "
                   "topographies worn after it) or, in perfect contact, of the interface facets (their gaps opened), "
                   "and of a counter-face whose material gives k_w", ("friction",)),
    "plasticity": Effect("elastic-perfectly-plastic asperities: micro pressures bounded by the hardness of the "
                         "softer body of each rough interface (materials.<name>.hardness, constant or H(T)); "
                         "yielded zones keep their permanent deformation", ("roughness",)),
    "stability": Effect("complex eigenvalue (squeal) analysis at the sliding state ([stability])",
                        ("contact",)),
}
_EFFECT_CHOICE = Choice(EFFECTS)


class InterfacesSection(Named):
    """[interfaces.<name>]: ``InterfaceSettings``; a sub-table [interfaces.<name>.roughness] or
    [interfaces.<name>.micro] overrides keys of [roughness] or [micro] for that interface, a surface
    of its own replacing the other's (``scene_rough.roughness_over``; the merged table is validated
    as a whole)."""

    nested = {"roughness": Roughness, "micro": Micro}       # its sub-tables beside InterfaceSettings' keys

    def __init__(self):
        super().__init__(InterfaceSettings)

    def reference(self, path: str) -> list[str]:
        """The keys of ``multiscale check --keys``, with the override sub-tables."""
        return reference(InterfaceSettings, f"{path}.<name>") + [
            f"  [{path}.<name>.roughness], [{path}.<name>.micro]: [roughness], [micro] keys for it (own rms/file replace)"]

    def read(self, raw, path, ctx):
        if not isinstance(raw, dict):
            ctx.problems.append(f"{path} = {show(raw)}: must be {self.describe()} ([{path}.<name>])")
            return FrozenMap()         # (None crashed the cross-checks)
        out = {}
        for name, table in raw.items():
            where = f"{path}.{name}"
            if not isinstance(table, dict):
                ctx.problems.append(f"{where} = {show(table)}: must be a table [{where}]")
                continue
            merged = {}
            for section, cls in self.nested.items():
                own = table.get(section)
                if own is not None and not isinstance(own, dict):   # (a file's path was taken as {}: ignored)
                    ctx.problems.append(f"{where}.{section} = {show(own)}: must be a table [{where}.{section}]")
                elif own is not None:
                    base = ctx.root.get(section) if isinstance(ctx.root.get(section), dict) else {}
                    over = roughness_over(base, own) if section == "roughness" else {**base, **own}
                    merged[section] = read(cls, over, f"{where}.{section}", ctx)
            settings = read(InterfaceSettings, {k: v for k, v in table.items() if k not in ("roughness", "micro")},
                            where, ctx)
            out[name] = dataclasses.replace(settings, **merged) if settings is not None else None
        return FrozenMap(out)


class RoughnessSection(Section):
    """[roughness], left out where the interfaces give their own surfaces: absent while an
    [interfaces.<name>.roughness] gives rms or file, it is None (``scene_rough.rough_rules`` then
    wants a surface on every rough interface; before, [roughness] was required beside them, "rms or
    file: missing", its keys unread; a user trial)."""

    def read(self, raw, path, ctx):
        if path not in ctx.root and any({"rms", "file"} & t.keys() for t in own_surface_tables(ctx.root)):
            return None
        return super().read(raw, path, ctx)


# ------------------------------------------------------------------ the scene
@dataclass(frozen=True)
class Scene:
    """A validated scene (SI units). ``effects`` is a frozenset; ask ``scene.has(effect)``."""

    name: str | None = key(Text(r"[A-Za-z0-9_.-]+", "a name of letters, digits, _ . -"), absent="the scene file's name")
    description: str = key(Text(), default="")
    effects: frozenset = key(ListOf(_EFFECT_CHOICE, unique=True, min_len=1), required=True)
    geometry: Geometry | None = key(GeometrySection(), required=True)
    materials: FrozenMap | None = key(Named(Material), required=True)
    interface: Interface | None = key(Section(Interface, always=True))
    interfaces: FrozenMap = key(InterfacesSection(), default=FrozenMap())
    boundary: tuple = key(Tables(Boundary), default=())
    loading: Loading | None = key(Section(Loading, always=True))
    time: Time | None = key(Section(Time, always=True))
    output: Output | None = key(Section(Output, always=True))
    roughness: Roughness | None = key(RoughnessSection(Roughness), needed_by=("roughness",))
    micro: Micro | None = key(Section(Micro), needed_by=("roughness",))
    wear: Wear | None = key(Section(Wear), needed_by=("wear",))
    layers: Layers | None = key(Section(Layers), needed_by=("layers",))
    stability: Stability | None = key(Section(Stability), needed_by=("stability",))
    source: Path | None = None                   # the scene file (None for loads without a path)
    text: str = field(default="", repr=False, compare=False)   # its TOML text as read (provenance's scene.toml)
    overrides: tuple = field(default=())        # ((dotted key, raw value), ...) given over the file (``load``)
    warnings: tuple = field(default=())         # things accepted but ignored (one line each)

    def has(self, effect: str) -> bool:
        """True if the scene asks for ``effect`` (raises on an unknown effect name)."""
        if effect not in EFFECTS:
            raise InputError("effect", effect, f"unknown; known effects: {', '.join(EFFECTS)}")
        return effect in self.effects

    @property
    def bodies(self) -> tuple[str, str]:
        """Names of the two bodies: the stationary one (body 0: pin, pads) and the moving one."""
        return self.geometry.bodies

    @property
    def inputs(self) -> frozenset[Path]:
        """Every file the scene reads, resolved: the scene file, a geometry file, measured surfaces."""
        found = {self.source.resolve()} if self.source is not None else set()

        def walk(value):
            if isinstance(value, Path):
                found.add(value.resolve())
            elif dataclasses.is_dataclass(value) and not isinstance(value, type):
                for f in dataclasses.fields(value):
                    walk(getattr(value, f.name))
            elif isinstance(value, (tuple, list, FrozenMap)):
                for item in value.values() if isinstance(value, FrozenMap) else value:
                    walk(item)
        for f in dataclasses.fields(self):
            if f.name not in ("output", "source", "overrides"):
                walk(getattr(self, f.name))
        return frozenset(found)

    def earlier_results(self) -> list[str]:
        """Names of the entries already in the output folder (what ``run`` must not overwrite
        silently), the scene's own inputs left out (a scene may sit in its output folder)."""
        folder = self.output.folder if self.output is not None else None
        if folder is None or not folder.is_dir():
            return []
        inputs = self.inputs          # a walk over the whole scene: once, not per entry
        return sorted(p.name for p in folder.iterdir() if p.resolve() not in inputs)

    @property
    def partition(self) -> float | None:
        """Share of frictional heat into body 0 (pin, pads, block) at the first interface (see
        ``partition_at``)."""
        return self.partition_at(None)

    def partition_at(self, interface: str | None, areas: tuple[float, float] = (1.0, 1.0)) -> float | None:
        """Share of frictional heat into body 0 at an interface: the constant, or the effusivity
        partition e_0 A_0 / (e_0 A_0 + e_1 A_1), e = sqrt(kappa rho c) of the materials on both
        sides at the initial temperature, ``areas`` (A_0, A_1) [m^2] the interface's face and the
        part of body 1's surface it heats: the track a rotating body 1 sweeps (Newcomb & Spurr
        1967, Limpert 1975: equal mean surface temperatures of two semi-infinite bodies, the
        track's flux averaged over a revolution; ``workflows.model.partitions``), default equal
        areas (two stationary bodies, Carslaw & Jaeger §2.9). None if unset."""
        value = self.interface.partition
        if value != "effusivity":
            return value
        T0 = self.time.initial_temperature
        e0, e1 = (self.materials[m].at(T0).effusivity for m in self.geometry.spec.interface_materials(interface))
        return e0 * areas[0] / (e0 * areas[0] + e1 * areas[1])

    def interface_settings(self, name: str) -> InterfaceSettings:
        """The settings of interface ``name``: its [interfaces.<name>] table, defaults filled
        (friction or its fade table from [loading] unless it gives one, roughness and micro from
        [roughness] and [micro])."""
        own = self.interfaces.get(name) or InterfaceSettings()
        ld = self.loading if own.friction is None and own.friction_temperature is None else own
        return dataclasses.replace(own, friction=ld.friction, friction_temperature=ld.friction_temperature,
                                   roughness=own.roughness or self.roughness, micro=own.micro or self.micro)

    def roughness_key(self, name: str) -> str:
        """Where interface ``name``'s roughness is given: "interfaces.<name>.roughness" or "roughness"."""
        own = self.interfaces.get(name)
        return f"interfaces.{name}.roughness" if own is not None and own.roughness is not None else "roughness"

    @property
    def rough_interfaces(self) -> tuple[str, ...]:
        """Names of the interfaces carrying zone laws (effect "roughness" and ``rough`` not false)."""
        if not self.has("roughness"):
            return ()
        return tuple(n for n in self.geometry.spec.interfaces if self.interface_settings(n).rough)

    @property
    def rough_material(self) -> str | None:
        """The worn body's material: at the first rough interface (one pair over them all,
        ``scene_rough.rough_rules``), or with wear in perfect contact at the first interface; else None."""
        worn = self.rough_interfaces or (tuple(self.geometry.spec.interfaces) if self.has("wear") else ())
        return self.geometry.spec.interface_materials(worn[0])[0] if worn else None

    @property
    def rough_material_wears(self) -> bool:
        """True if the rough body's material gives its own k_w: the zones wear by it, not by
        [wear]'s k_w, its k_w(T) table or the default table."""
        return getattr((self.materials or {}).get(self.rough_material), "k_w", None) is not None

    @property
    def softer_hardness(self) -> str | None:
        """Of the rough interfaces' two materials that give a hardness, the one with the lower value
        at the initial temperature (the micro solves' H, at the rough body's temperatures); None
        without one."""
        if not self.rough_interfaces or self.materials is None or self.time is None:
            return None
        given = [m for m in self.geometry.spec.interface_materials(self.rough_interfaces[0])
                 if m in self.materials and self.materials[m].hardness is not None]
        T0 = self.time.initial_temperature
        return min(given, key=lambda m: self.materials[m].value("hardness", T0)) if given else None


def load(path, overrides=None) -> Scene:
    """Read and validate a scene file; raises SceneError listing every problem.

    ``overrides`` maps dotted key paths to raw values applied before validation (a study's sweep:
    ``{"loading.friction": 0.2, "geometry.mesh_size": "6 mm"}``); they are validated like the file
    (numpy scalars and arrays, tuples and paths are read as the TOML values they stand for). A key
    replaces the file's alternatives to it and the keys used only with those (``loading.pressure``
    its ``normal_force``; ``roughness.file`` its ``rms``, ``hurst``, ...), unless they are given too."""
    if not isinstance(path, (str, os.PathLike)):
        raise InputError("path", path, "a scene file name (str or Path)")
    path = Path(path)
    text = read_toml_text(path, "scene")
    return loads(text, path.resolve().parent, name=path.stem, source=path.resolve(), overrides=overrides)


def loads(text: str, directory=".", *, name: str = "scene", source: Path | None = None, overrides=None) -> Scene:
    """Validate scene TOML text; relative paths are taken from ``directory``; ``name`` is the
    default scene name (the file stem for ``load``); ``overrides`` as in ``load``."""
    if not isinstance(text, str):
        raise InputError("text", text, "the scene's TOML text (a str; load(path) reads a file)")
    if overrides is not None and not (isinstance(overrides, Mapping) and all(isinstance(k, str) for k in overrides)):
        raise InputError("overrides", overrides, 'a mapping of dotted keys to values, e.g. {"loading.friction": 0.2}')
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise toml_problem(source or "scene", exc, text) from None
    if "problem" in raw and "effects" not in raw:     # (answered with "did you mean" per key: a user trial)
        raise SceneError([f"{source.name if source else name}: a study file (problem = ..., [sweep]), not a scene: "
                          "give it to `multiscale study` (Python: multiscale.studies.driver.run_studies)"])
    overrides = {dotted: _toml_value(value) for dotted, value in (overrides or {}).items()}
    given, dropped = {p for dotted, value in overrides.items() for p in given_paths(key_parts(dotted), value)}, []
    for dotted, value in overrides.items():
        *parents, last = key_parts(dotted)
        table = raw
        for part in parents:
            if isinstance(table, list):          # an entry of an array of tables: boundary[2] or boundary.2
                if not (part.isdigit() and 1 <= int(part) <= len(table)):
                    raise SceneError(f"{dotted}: cannot override, {part} is not one of the {len(table)} entries "
                                     "(1, 2, ...: boundary[2].emissivity or boundary.2.emissivity)")
                table = table[int(part) - 1]
            elif part.isdigit() and not table:      # (an array the file has not: "must be an array", a trial)
                raise SceneError(f"{dotted}: the file has no entry {part}; give the array whole: "
                                 f"{'.'.join(parents[:parents.index(part)])} = [{{...}}]")
            else:
                table = table.setdefault(part, {})
            if not isinstance(table, (dict, list)):
                raise SceneError(f"{dotted}: cannot override, {part} is not a table")
        if isinstance(table, list):       # of tables, or plain (it was called one of tables: a review)
            raise SceneError(f"{dotted}: cannot override " + ("an array of tables whole; give a key of one of its "
                             "entries (boundary[2].emissivity)" if table and all(isinstance(e, dict) for e in table) else
                             "one item of an array; give the whole array (geometry.axis = [0, 0, 1])"))
        table[last] = value                 # the file's alternatives go, unless given too
        dropped += [f"{dotted} replaces the file's {key}" for key in drop_replaced(Scene, raw, [*parents, last], value,
                                                                                     given)]
    effects = raw.get("effects")
    active = frozenset(e for e in effects if isinstance(e, str) and e in EFFECTS) \
        if isinstance(effects, list) else frozenset()      # the known effects decide what is needed
    ctx = Context(effects=active, directory=Path(directory).resolve(), root=raw)
    scene = read(Scene, raw, "", ctx)
    warnings = dropped + _cross_checks(scene, raw, ctx)        # (said nowhere: a stop became a drag, a trial)
    if ctx.problems:
        raise SceneError(ctx.problems)
    name = scene.name or name
    output = dataclasses.replace(
        scene.output,
        folder=scene.output.folder or (ctx.directory / "results" / name),
        fields=scene.output.fields if scene.output.fields is not None else tuple(
            f for f, needs in OUTPUT_FIELDS.items() if all(e in active for e in needs)))
    return dataclasses.replace(scene, name=name, effects=frozenset(scene.effects), output=output,
                               source=source, text=text, overrides=tuple(overrides.items()),
                               warnings=tuple(warnings))


def _toml_value(value):
    """An override as TOML would give it: numpy scalars as Python numbers and bools, arrays and
    tuples as lists, paths as strings, tables item by item (a loop over ``np.arange(5, 30, 5)``
    gave "time.steps = np.int64(10): must be an integer >= 1", a tuple (4, 4) for micro.zones the
    same)."""
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()                       # Python numbers, bools and nested lists
    if isinstance(value, (tuple, list)):
        return [_toml_value(v) for v in value]
    if isinstance(value, Mapping):
        return {k: _toml_value(v) for k, v in value.items()}
    return os.fspath(value) if isinstance(value, os.PathLike) else value


def _cross_checks(scene: Scene, raw: dict, ctx: Context) -> list[str]:
    """Checks across sections (effects, bodies, motion, surfaces, interfaces, outputs); appends
    problems to ctx and returns warnings. Runs on a possibly partial scene, so every part is guarded."""
    problems, warnings, effects = ctx.problems, [], ctx.effects
    for missing in EFFECTS:
        users = [f'"{e}"' for e in EFFECTS if e in effects and missing in EFFECTS[e].requires]
        if users and missing not in effects:
            problems.append(f'effects: {", ".join(users)} need{"s" if len(users) == 1 else ""} effect '
                            f'"{missing}" too (add it to effects)')
    g = scene.geometry
    where = f'builder "{g.builder}"' if g is not None and g.builder != "file" else "the geometry"
    if g is not None and scene.materials is not None:
        warnings += material_problems(g, scene.materials, where, ctx)
    if g is not None and scene.loading is not None:
        warnings += fluid_faces_left_out(g, scene.loading.faces, where)
    loading = raw.get("loading") if isinstance(raw.get("loading"), dict) else {}
    if g is not None:
        moving = ("rotation_speed", "speed_profile", "vehicle") if g.motion == "rotation" else ("sliding_speed",)
        wrong = ("sliding_speed",) if g.motion == "rotation" else ("rotation_speed", "speed_profile", "vehicle")
        for k in wrong:
            if k in loading:
                problems.append(f'loading.{k}: not used by {where} ({g.motion}); '
                                f'use {" or ".join("loading." + m for m in moving)}')
        if "braking_torque" in loading and g.motion != "rotation":
            problems.append(f"loading.braking_torque: a moment about the axis of a rotating body; {where} has a "
                            f"{g.motion}: give loading.normal_force or loading.pressure")
        if "friction" in effects and not any(k in loading for k in moving + wrong):
            problems.append(f'{" or ".join("loading." + m for m in moving)}: missing; effect "friction" '
                            f'needs the sliding speed')
        for section in ("roughness", "layers"):
            table = getattr(scene, section)
            if table is not None and table.body is not None and table.body not in g.bodies:
                problems.append(f'{section}.body = "{table.body}": not a body of {where}; allowed: '
                                f'{", ".join(g.bodies)}')
            elif table is not None and table.body not in (None, g.bodies[0]):      # layers: on the rough body
                problems.append(f'{section}.body = "{table.body}": the rough body must be the stationary one, '
                                f'"{g.bodies[0]}" (zones do not move)')
        if "contact" not in effects and not any("contact" in EFFECTS[e].requires for e in effects):
            problems.append(f'effects: {where} is a macro contact model: add effect "contact"')
        if "thermal" in effects and g.motion == "rotation" and (g.spec.crossed or 0.0) > 0:   # (after meshing: a trial)
            problems.append(f'effects: "thermal" solves the heat of {g.bodies[1]} in a fixed frame, which needs a body of '
                            f"revolution, but its rotation crosses about {100 * g.spec.crossed:.2g} % of its surface (vanes, holes, "
                            f"slots): fill them{' (geometry.vanes = 0)' if 'vanes' in g.resolved() else ' in the geometry'}"
                            ' or run without effect "thermal"')
        if "thermal" in effects and g.motion != "rotation" and (scene.loading is not None
                                                               and scene.loading.sliding_speed):
            problems.append(f'loading.sliding_speed = {scene.loading.sliding_speed:g} m/s: heat transport needs a '
                            f'rotating body ({where} translates; with effect "thermal" it slides only at '
                            "sliding_speed = 0)")
        ld = scene.loading
        along = float(np.dot(ld.direction, g.spec.load_direction)) if ld is not None and ld.direction else 1.0
        if along <= 0.0 and not g.spec.fluid_load and not isinstance(g.params, FileGeometry):   # (it passed check)
            problems.append(f"loading.direction = {list(ld.direction)}: " + ("pulls the loaded body away from" if along
                            < 0 else "has no component towards") + f" the contact ({where} presses along "
                            f"{list(g.spec.load_direction)}): no contact would hold it")
        if ld is not None and ld.normal_force is not None and ld.direction is None and g.spec.fluid_load \
                and not isinstance(g.params, FileGeometry):
            problems.append(f"loading.normal_force: {where} is loaded by a fluid pressure on its load faces, whose "
                            "forces cancel: give loading.pressure (or loading.direction for a force along it)")
        if "friction" in effects:
            more, unused = friction_checks(loading, scene.interfaces, g.spec.interfaces)
            problems += more
            warnings += unused
        problems += _surface_checks(scene, g, where, effects)
        problems += _symmetry_checks(scene, g, where, effects)
        given = raw.get("geometry") if isinstance(raw.get("geometry"), dict) else {}
        warnings += [f'geometry.{key} = {size:g} m is larger than the geometry ({g.spec.length_scale:g} m across): '
                     'a bare number is in metres; give a unit ("12 mm")' for key, size in g.resolved().items()
                     if key.endswith("mesh_size") and isinstance(given.get(key), (int, float))
                     and size > g.spec.length_scale]
        problems += _hardness_checks(scene, g, raw, effects)
        warnings += penalty_range(scene, g.spec, effects) + list(g.spec.warnings) + pressure_range(scene)
        if "wear" in effects and scene.wear is not None and scene.materials is not None and not problems:
            rough = {scene.geometry.spec.interface_materials(n)[0] for n in scene.geometry.spec.interfaces}
            for name in sorted(rough):      # (a specific_rate too: the material's k_w won silently, a review)
                if scene.wear.given and name in scene.materials and scene.materials[name].k_w is not None:
                    problems.append(f"wear.{scene.wear.given}: the worn body's material gives k_w "
                                    f"(materials.{name}.k_w): give one of them")
        if not problems:
            problems += [str(e) for e in rough_rules(scene)] + (torque_problems(scene, g.spec.interfaces)
                                                                 if "friction" in effects else [])
        if not problems:
            problems += (nyquist(scene) + thin_layer(scene) + measured_cover(scene, warnings)
                         + perfect_contact(scene, warnings) + own_tables(scene, warnings))
            warnings += micro_constants(scene) + zone_sizes(scene) + law_top_warnings(scene) + (
                speed_law_zeros(scene) if "friction" in effects else [])
    if scene.output is not None:
        more, unused = output_problems(scene.output, g.bodies if g is not None else None, {} if g is None else {
            r.name: b.name for b in g.spec.bodies for r in b.regions}, g is not None and g.motion == "rotation", effects)
        problems += more
        warnings += unused
    for section, spec in fields_of(Scene):
        if section in raw and spec.needed_by and not any(e in effects for e in spec.needed_by):
            warnings.append(f'[{section}] is ignored: effect "{spec.needed_by[0]}" is not in effects')
    timing = raw.get("time") if isinstance(raw.get("time"), dict) else {}
    defaults = {f.name: f.default for f in dataclasses.fields(Time)}      # as written back by resolved_toml
    unused = [f"time.{k}" for k in ("end", "steps", "substeps") if k in timing and
              getattr(scene.time, k) != defaults[k]] + \
             [f"loading.{k}" for k in ("load_profile", "speed_profile") if k in loading]
    if unused and "contact" in effects and not {"thermal", "wear", "stability"} & set(effects):
        warnings.append(f'{", ".join(unused)}: ignored without effect "thermal" or "wear": the run is one contact '
                        "solve at t = 0")
    if problems:            # what follows only warns, and reads values that a problem left unset
        return ctx.warnings + warnings
    if "stability" in effects and scene.loading is not None and g is not None:
        warnings += stability_warnings(scene, g, effects, (scene.time or Time()).initial_temperature)
    end = scene.time.end if scene.time is not None else None
    if scene.loading is not None and end is not None:
        fades = fade_tables(scene.loading, scene.interfaces, g.spec.interfaces if g is not None else None) \
            if "friction" in effects else {}
        warnings += cycle_coverage(scene.loading, end) + fade_coverage(fades, scene.time.initial_temperature)
        if g is not None and {"friction", "thermal", "heat_partition"} <= effects:
            warnings += short_phases(scene.loading, g.motion, end, scene.time.dt)
            if scene.materials is not None:
                warnings += thin_heated_layers(scene.loading, g.motion, end, g.spec, scene.materials,
                                               scene.time.initial_temperature, g.interface_size_key())
        if g is not None and g.motion == "rotation" and "thermal" in effects:
            warnings += convection_coverage(scene.boundary or (), scene.loading, end)
            warnings += plain_speeds(raw, speed_range(scene.loading, end)[1])
    profile = scene.loading.load_profile if scene.loading is not None else None
    if profile is not None and not any(factor > 0 for _, factor in profile):
        warnings.append("loading.load_profile is 0 throughout: the load is released for the whole run (no "
                        "contact, no frictional heat)")
    if g is not None and scene.materials is not None and scene.time is not None:
        T0 = scene.time.initial_temperature       # every property of a run starts there
        warnings += [f"materials.{name}.{phrase} (the initial temperature)" for name in g.materials
                     if scene.materials.get(name) is not None
                     for phrase in scene.materials[name].beyond(T0).values()]
    if "wear" in effects and scene.wear is not None and g is not None and scene.materials is not None \
            and scene.time is not None and not scene.rough_material_wears:
        warnings += default_wear_rate(scene) + scene.wear.held_ends(T0=scene.time.initial_temperature,
                                                                    rough=scene.has("roughness"))
    for i, b in enumerate(scene.boundary or (), 1):
        given = [k for k in Boundary.THERMAL if b is not None and getattr(b, k) is not None]
        if given and "thermal" not in effects:
            warnings.append(f'boundary[{i}].{given[0]} is ignored: effect "thermal" is not in effects')
    if {"friction", "thermal"} <= effects and "heat_partition" not in effects:
        warnings.append('effects "friction" and "thermal" without "heat_partition": no frictional heat '
                        "enters the bodies")
    return ctx.warnings + warnings


def default_wear_rate(scene: Scene) -> list[str]:
    """The warning of a wear by the default k_w(T) table (user trial M calibrated on it unawares)."""
    w = scene.wear
    if "wear" not in scene.effects or w is None or w.given is not None or scene.rough_material_wears:
        return []
    return ["wear: no k_w given (wear.k_w, wear.k_w_table, a specific_rate or the rough material's k_w): the zones "
            f"wear by the default k_w(T) table, the {FIG_7_9_CALIBRATION}"]


def _hardness_checks(scene: Scene, g: Geometry, raw: dict, effects) -> list[str]:
    """Effect "plasticity" needs a hardness on one side (at least) of every rough interface (a
    hardness given but refused is reported by the material's table itself)."""
    tables = raw.get("materials") if isinstance(raw.get("materials"), dict) else {}
    if scene.materials is None or "plasticity" not in effects:
        return []
    problems = []
    for name in g.spec.interfaces:
        try:
            rough = scene.interface_settings(name).rough
            sides = [m for m in g.spec.interface_materials(name) if m in scene.materials]
        except (AttributeError, KeyError, StopIteration, TypeError):   # a partial scene: reported elsewhere
            continue
        given = [m for m in sides if isinstance(tables.get(m), dict) and "hardness" in tables[m]]
        if rough and sides and not given:
            problems.append(f'materials.{sides[0]}.hardness: missing; effect "plasticity" needs the hardness of '
                            f'the softer body of interface "{name}" ({" or ".join(sides)})')
    problems += plastic_everywhere(scene)
    return problems


def _symmetry_checks(scene: Scene, g: Geometry, where: str, effects) -> list[str]:
    """Friction with a moving body on a part model: a symmetry plane that the sliding does not
    respect (a translation with a component along its normal; a rotation about an axis not normal
    to it) mirrors the friction, holding two halves pulled against each other (found by an
    adversarial test: the block's pressure peaked at its symmetry plane, 1.35 MPa for 1 MPa). So does
    a load direction with a component along a plane's normal (the block's 0.26 to 1.75 MPa for 1 MPa)."""
    motion, given = g.spec.motion, scene.loading.direction if scene.loading is not None else None
    problems = [f"loading.direction = {list(given)}: has a component along the normal {list(normal)} of {where}'s "
                f"symmetry plane {face}, which mirrors the load, pushing the halves apart or together: load along the "
                "plane, or use a whole model (a geometry file)" for face, normal in g.spec.symmetry.items()
                if given is not None and abs(float(np.dot(given, normal))) > 1e-9 * float(np.linalg.norm(given))]
    moving = scene.loading is not None and (g.motion == "rotation" or bool(scene.loading.sliding_speed))
    if "friction" not in effects or not moving or ("thermal" in effects and g.motion != "rotation"):
        return problems                      # (with "thermal" a translation is refused at any speed)
    along = np.asarray(motion.axis if g.motion == "rotation" else motion.direction, dtype=float)
    along /= np.linalg.norm(along)
    for face, normal in g.spec.symmetry.items():
        c = abs(float(np.dot(along, normal)))
        if (c < 1 - 1e-9) if g.motion == "rotation" else (c > 1e-9):
            problems.append(f'effects: "friction" with a sliding body on {where}: its face {face} is a symmetry '
                            f"plane (normal {list(normal)}) that the sliding does not respect, so the model would "
                            "mirror the friction; use a whole model (a geometry file) or no sliding speed")
    return problems


def _surface_checks(scene: Scene, g: Geometry, where: str, effects) -> list[str]:
    """Names of surfaces and interfaces used by [[boundary]], [loading] and [interfaces] exist; rough
    interfaces are planar; a file's load faces are given."""
    problems, known = [], g.surfaces
    for i, b in enumerate(scene.boundary or (), 1):
        if b is not None and isinstance(b.convection, tuple) and g.motion != "rotation":   # was read at speed 0
            problems.append(f"boundary[{i}].convection: a table against the rotating body's speed; {where} has a "
                            f"{g.motion}: give a constant h")
        for s in ((b.surfaces or ()) if b is not None else ()):
            if s not in known:
                problems.append(f'boundary[{i}].surfaces: "{s}" is not a surface of {where}; known: {", ".join(known)}')
            elif b.fix and s not in g.spec.faces:        # a support holds named faces (its facets' dofs)
                problems.append(f'boundary[{i}].surfaces: "{s}" cannot be fixed (boundary[{i}].fix): supports hold '
                                f'named faces ({", ".join(g.spec.faces)}); "free:" surfaces take thermal conditions')
    faces = scene.loading.faces if scene.loading is not None else None
    for s in faces or ():
        if s not in g.spec.faces:
            problems.append(f'loading.faces: "{s}" is not a surface of {where}; known: {", ".join(g.spec.faces)}')
    if isinstance(g.params, FileGeometry) and not faces and "contact" in effects:
        problems.append("loading.faces: missing; a geometry file needs the surfaces where the load acts "
                        f"(known: {', '.join(g.spec.faces) or 'none: name some in [geometry.surfaces]'})")
    for name in scene.interfaces:
        if name not in g.spec.interfaces:      # a pad off the disc has none: its gap was not said (a user trial)
            apart = loose_bodies(g.spec.warnings).get(name)
            problems.append(f'interfaces.{name}: not an interface of {where}; interfaces: {", ".join(g.spec.interfaces)}'
                            + (f" ({apart})" if apart else ""))
    ld = scene.loading
    direction = ld.direction if ld is not None and ld.direction is not None else \
        None if g.spec.fluid_load else g.spec.load_direction        # (a fluid load: along each face's normal)
    for i, b in enumerate(scene.boundary or (), 1):     # a support that holds a load face along the load
        held = [s for s in ((b.surfaces or ()) if b is not None and b.fix else ()) if s in (faces or g.spec.load_faces)]
        free = [c for c in range(3) if c not in (b.components if b is not None else ())]
        along = "normal to each face" if direction is None else f"along {list(direction)}"   # (a fixed bore loaded
        if held and (not free if direction is None else np.linalg.norm(np.asarray(direction, float)[free]) < 1e-9):
            problems.append(f"boundary[{i}].fix = {list(b.fix)} on {', '.join(held)}, where the load pushes {along}: "
                            "the support would take the load and the contact none; hold another face or leave that "
                            "component free")                              # normal to it said nothing: a user trial)
    if "roughness" in effects and scene.roughness is not None and scene.effects is not None and not problems:
        for name in scene.rough_interfaces:
            normal = g.spec.interface_normals.get(name, ())
            if normal is None:
                problems.append(f'interfaces.{name}: a rough interface must be planar (it is not: set '
                                f"interfaces.{name}.rough = false, or make the face flat)")
    return problems

"""The scene: a TOML file -> validated, frozen dataclasses in SI units (thesis §7.3.1 set-up).

``load(path) -> Scene``; ``multiscale check scene.toml`` lists every problem at once. The schema is
declarative: each table below is a frozen dataclass whose fields say how their TOML key is read
(unit kind, range, default, which effects need it; see ``multiscale.schema``). A later issue adds a
section by declaring its dataclass and one field of ``Scene``, an effect by one ``EFFECTS`` entry.
Values are numbers (SI) or unit strings ("200 rpm", "4 GPa", "20 degC"; ``multiscale.units``);
relative paths are taken from the scene file's directory. Code asks ``scene.has("thermal")``.

Sections: geometry (builder + its parameters), materials (one table per body of the builder),
interface, loading, time, output; roughness, micro, wear and layers (the multiscale loop,
``multiscale.coupling``); stability (the squeal analysis).
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from multiscale.errors import InputError, SceneError
from multiscale.geometry import GeometrySpec, Rotation, builder, builder_names
from multiscale.micro.topography import COVER, DETREND, MAX_UNDEFINED, probe_topography
from multiscale.schema import (Bad, Choice, Context, Curve, Either, FilePath, Flag, FrozenMap,
                               Integer, ListOf, Named, OneOf, OnlyWith, Pair, Quantity, Requires,
                               Section, Tables, Text, fields_of, key, read, show, unknown_keys)

__all__ = ["EFFECTS", "FIG_7_9_WEAR_RATE", "OUTPUT_FIELDS", "Geometry", "Material", "Scene", "load",
           "loads"]


# ------------------------------------------------------------------ effects
@dataclass(frozen=True)
class Effect:
    doc: str
    requires: tuple[str, ...] = ()   # other effects it builds on


EFFECTS: dict[str, Effect] = {
    "contact": Effect("normal contact through the interface: penalty p_n = K_n <-g_n>_+ "
                      "(perfect contact), or the rough per-facet laws with 'roughness'"),
    "friction": Effect("Coulomb sliding friction mu p_n along the sliding direction", ("contact",)),
    "thermal": Effect("transient heat conduction in every body (the disc in its Eulerian frame)"),
    "heat_partition": Effect("frictional heat mu p_n |v| split between the two interface bodies "
                             "by interface.partition", ("thermal", "friction")),
    "conductance": Effect("heat conduction across the interface, h_c = interface.conductance",
                          ("thermal", "contact")),
    "expansion": Effect("thermal expansion alpha (T - T0) in the mechanics", ("thermal",)),
    "roughness": Effect("rough interface: per-zone homogenized laws from micro patches "
                        "([roughness], [micro])", ("contact",)),
    "layers": Effect("layered near-surface material in the micro models ([layers])", ("roughness",)),
    "wear": Effect("Archard wear of the rough zones between macro steps ([wear])",
                   ("roughness", "friction")),
    "stability": Effect("complex eigenvalue (squeal) analysis at the sliding state ([stability])",
                        ("contact",)),
}
_EFFECT_CHOICE = Choice(EFFECTS)

# output field -> effects it needs
OUTPUT_FIELDS: dict[str, tuple[str, ...]] = {
    "displacement": (), "von_mises": (), "contact_pressure": ("contact",),
    "temperature": ("thermal",), "heat_flux": ("thermal",),
    "contact_stiffness": ("roughness",), "partition": ("heat_partition",), "wear_depth": ("wear",),
}

# shared specs
_MODULUS = Quantity("pressure", gt=0)
_POISSON = Quantity("dimensionless", gt=-1, lt=0.5)
_CONDUCTIVITY = Quantity("conductivity", gt=0)
_LENGTH = Quantity("length", gt=0)


# ------------------------------------------------------------------ geometry builders
_BUILDER_CHOICE = Choice(builder_names())      # the registry: entry points multiscale.builders


@dataclass(frozen=True)
class Geometry:
    """[geometry]: a registered mesh builder (``multiscale.geometry.builder``) and the parameters
    the scene sets (SI; the builder's ``DEFAULTS`` fill the rest). ``spec`` (the builder's
    ``describe``) names the bodies (body 0 the stationary "+" side, body 1 the sliding side),
    material regions and motion."""

    builder: str
    params: FrozenMap
    spec: GeometrySpec

    def module(self):
        """The builder module (DEFAULTS, parameters, describe, generate)."""
        return builder(self.builder)

    def resolved(self) -> dict:
        """Every builder parameter [SI]: DEFAULTS updated by the scene's values."""
        return self.module().parameters(dict(self.params))

    @property
    def bodies(self) -> tuple[str, str]:
        return tuple(b.name for b in self.spec.bodies)

    @property
    def materials(self) -> tuple[str, ...]:
        """Names of the [materials.<name>] tables the builder needs."""
        return self.spec.materials

    @property
    def motion(self) -> str:
        """"rotation" (of body 1 about an axis) or "translation"."""
        return "rotation" if isinstance(self.spec.motion, Rotation) else "translation"


def _parameter_kind(module, name: str) -> str:
    """Unit kind of a builder parameter: the module's PARAMETER_KINDS, else angle/length by name."""
    kinds = getattr(module, "PARAMETER_KINDS", {})
    return kinds.get(name, "angle" if "angle" in name else "length")


class _Geometry(Section):
    """[geometry]: ``builder`` picks a registered builder, whose DEFAULTS are the allowed keys."""

    def __init__(self):
        super().__init__(Geometry)

    def describe(self) -> str:
        return f"a table with builder = {_BUILDER_CHOICE.describe()} and its parameters"

    def reference(self, path) -> list[str]:
        lines = [f"  {'builder':<20} {_BUILDER_CHOICE.describe()}  [required]"]
        for name in builder_names():
            try:
                module = builder(name)
            except ImportError:
                lines.append(f"  builder = \"{name}\": not available")
                continue
            lines.append(f"  builder = \"{name}\" parameters (SI defaults; 0 = the builder's fallback):")
            lines += [f"    {k:<22} {_parameter_kind(module, k):<8} {v:g}" for k, v in module.DEFAULTS.items()]
        return lines

    def read(self, raw, path, ctx):
        if not isinstance(raw, dict):
            ctx.problems.append(f"{path} = {show(raw)}: must be {self.describe()}")
            return None
        if "builder" not in raw:
            ctx.problems.append(f"{path}.builder: missing; required: {_BUILDER_CHOICE.describe()}")
            return None
        try:
            name = _BUILDER_CHOICE(raw["builder"], ctx)
            module = builder(name)
        except Bad as exc:
            ctx.problems.append(f"{path}.builder = {show(raw['builder'])}: {exc}")
            return None
        except ImportError as exc:
            ctx.problems.append(f"{path}.builder = {show(raw['builder'])}: not available ({exc})")
            return None
        before = len(ctx.problems)
        given = {k: v for k, v in raw.items() if k != "builder"}
        unknown_keys(given, module.DEFAULTS, path, ctx, f'parameter of builder "{name}"')
        params = {}
        for param, value in given.items():
            if param in module.DEFAULTS:
                zero_ok = float(module.DEFAULTS[param]) == 0.0    # 0 means "builder's fallback"
                parser = Quantity(_parameter_kind(module, param), **({"ge": 0} if zero_ok else {"gt": 0}))
                try:
                    params[param] = parser(value, ctx)
                except Bad as exc:
                    ctx.problems.append(f"{path}.{param} = {show(value)}: {exc}")
        if len(ctx.problems) > before:
            return None
        try:
            spec = module.describe(params)       # runs the builder's consistency checks
        except InputError as exc:
            ctx.problems.append(str(exc))
            return None
        return Geometry(name, FrozenMap(params), spec)


# ------------------------------------------------------------------ materials and interface
@dataclass(frozen=True)
class Material:
    """One body's material (Table 7.2). Thermal needs kappa and c (with rho) or chi."""

    E: float = key(_MODULUS, required=True)                                  # Pa, Young's modulus
    nu: float = key(_POISSON, required=True)                                 # Poisson's ratio
    rho: float | None = key(Quantity("density", gt=0), needed_by=("stability",))   # kg/m^3
    kappa: float | None = key(_CONDUCTIVITY, needed_by=("thermal",))         # W/(m K)
    c: float | None = key(Quantity("specific_heat", gt=0))                   # J/(kg K)
    chi: float | None = key(Quantity("diffusivity", gt=0))                   # m^2/s, kappa/(rho c)
    alpha: float | None = key(Quantity("expansion"), needed_by=("expansion",), warn_unused=True)  # 1/K

    rules = (OneOf(("c", "chi"), needed_by=("thermal",)), Requires("c", ("rho",), needed_by=("thermal",)))

    @property
    def heat_capacity(self) -> float:
        """Volumetric heat capacity rho c [J/(m^3 K)] (= kappa/chi when chi is given)."""
        if self.c is not None and self.rho is not None:
            return self.rho * self.c
        if self.chi is not None and self.kappa is not None:
            return self.kappa / self.chi
        raise InputError("material", self, "needs rho and c, or kappa and chi")

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity chi = kappa/(rho c) [m^2/s]."""
        return self.chi if self.chi is not None else self.kappa / self.heat_capacity

    @property
    def effusivity(self) -> float:
        """Thermal effusivity e = kappa/sqrt(chi) = sqrt(kappa rho c) [W s^0.5/(m^2 K)]."""
        return self.kappa / math.sqrt(self.diffusivity)


@dataclass(frozen=True)
class Interface:
    """The contact interface (perfect-contact baseline, §7.3.1)."""

    penalty: float | None = key(Quantity("stiffness", gt=0), needed_by=("contact",),
                                unless=("roughness",))          # Pa/m, normal penalty stiffness K_n
    partition: float | str | None = key(Either(Quantity("dimensionless", ge=0, le=1),
                                               Choice(("effusivity",))),
                                        needed_by=("heat_partition",), warn_unused=True)  # into body 0
    conductance: float | None = key(Quantity("conductance", gt=0), needed_by=("conductance",),
                                    unless=("roughness",), warn_unused=True)   # W/(m^2 K), h_c


# ------------------------------------------------------------------ loading, time, output
@dataclass(frozen=True)
class Loading:
    """Normal load (force or pressure on the builder's loaded face), motion, friction."""

    normal_force: float | None = key(Quantity("force", gt=0))                 # N
    pressure: float | None = key(Quantity("pressure", gt=0))                  # Pa
    rotation_speed: float | None = key(Quantity("angular_speed", ge=0))       # rad/s (rotation builders)
    speed_profile: tuple | None = key(Curve(Quantity("time", ge=0), Quantity("angular_speed", ge=0),
                                            "time", "speed"))                 # ((s, rad/s), ...)
    sliding_speed: float | None = key(Quantity("speed", ge=0))                # m/s (translation builders)
    friction: float | None = key(Quantity("dimensionless", ge=0), needed_by=("friction",),
                                 warn_unused=True)                            # mu
    ramp_steps: int = key(Integer(ge=1), default=1)       # load increments of the first mechanical solve

    rules = (OneOf(("normal_force", "pressure"), needed_by=("contact",)),
             OneOf(("rotation_speed", "speed_profile")))

    def angular_speed(self, t: float) -> float:
        """omega(t) [rad/s]: constant, or the speed profile interpolated linearly in time and held
        constant beyond its ends; 0 without rotation."""
        if self.speed_profile is None:
            return self.rotation_speed or 0.0
        times, speeds = zip(*self.speed_profile)
        if t <= times[0]:
            return speeds[0]
        for (t0, w0), (t1, w1) in zip(self.speed_profile, self.speed_profile[1:]):
            if t <= t1:
                return w0 + (w1 - w0) * (t - t0) / (t1 - t0)
        return speeds[-1]


@dataclass(frozen=True)
class Time:
    """Staggered time loop (Fig. 7.4): ``steps`` macro steps Δt over ``end``, each in ``substeps``."""

    end: float | None = key(Quantity("time", gt=0), needed_by=("thermal", "wear"))  # s
    steps: int = key(Integer(ge=1), default=1)
    substeps: int = key(Integer(ge=1), default=1)
    initial_temperature: float = key(Quantity("temperature", gt=0), default=293.15)  # K

    @property
    def dt(self) -> float | None:
        """Macro time step Δt [s] (None without an end time)."""
        return None if self.end is None else self.end / self.steps


@dataclass(frozen=True)
class Output:
    """Where and what to write. Defaults: folder results/<name> next to the scene file; every
    field the scene's effects produce."""

    folder: Path | None = key(FilePath(folder=True))
    every: int = key(Integer(ge=1), default=1)            # write fields every n macro steps
    fields: tuple = key(ListOf(Choice(OUTPUT_FIELDS), unique=True))

    def existing_results(self) -> list[Path]:
        """Entries already in the output folder (what ``run`` must not overwrite silently)."""
        return sorted(self.folder.iterdir()) if self.folder is not None and self.folder.is_dir() else []


# ------------------------------------------------------------------ later effects (validated only)
@dataclass(frozen=True)
class Roughness:
    """Rough face of one body (§7.3.1: only the pin is rough): generated (fractal, Eqs. 1.24–1.25)
    or measured. Cut-offs are wavelengths per generated patch; ``patch`` says whether one surface
    is generated for the whole face and cut into zones, or one per zone (per-zone seeds).

    A measured ``file`` (issue 17; ``multiscale.micro.topography``): any format SurfaceTopography
    reads (x3p, sur, plu, opd, ...) with its own units and pixel sizes (``pixel_size`` and
    ``height_unit`` override them, with a warning), or a plain height matrix (.npy, .txt, .csv,
    .asc: ``pixel_size`` needed, ``height_unit`` default 1 m). It is conditioned (``detrend``,
    undefined points filled up to ``max_undefined``, Gaussian filter at ``cutoff``), then
    ``cover``s the face: the measurement itself ("measured": it must cover the face), copies
    ("mirror", "tile": warned) or a statistically equivalent surface from its PSD ("equivalent",
    drawn with ``seed``). ``multiscale check`` reads the file's header and heights, nothing more."""

    body: str | None = key(Text(), required=True)
    rms: float | None = key(_LENGTH)                                          # m
    hurst: float | None = key(Quantity("dimensionless", gt=0, le=1))
    k_min: tuple | None = key(Pair(Quantity("dimensionless", gt=0)))          # wavelengths, (x, y)
    k_max: tuple | None = key(Pair(Quantity("dimensionless", gt=0)))
    seed: int = key(Integer(ge=0), default=0)
    patch: str = key(Choice(("face", "zone")), default="face")
    file: Path | None = key(FilePath())                                       # measured topography
    channel: int | None = key(Integer(ge=0))                                  # default: the file's default
    pixel_size: tuple | None = key(Pair(_LENGTH))                             # m, (dx, dy): overrides the file's
    height_unit: float | None = key(_LENGTH)                                  # m per file height unit
    detrend: str = key(Choice(tuple(DETREND)), default="plane")               # form removal
    cutoff: float | None = key(_LENGTH)                                       # m, Gaussian filter λc
    max_undefined: float = key(Quantity("dimensionless", ge=0, le=1), default=MAX_UNDEFINED)
    cover: str = key(Choice(COVER), default="measured")

    rules = (OneOf(("rms", "file"), required=True), Requires("rms", ("hurst", "k_min", "k_max")),
             OnlyWith("rms", ("hurst", "k_min", "k_max", "patch")),
             OnlyWith("file", ("channel", "pixel_size", "height_unit", "detrend", "cutoff", "max_undefined", "cover")))

    def problems(self, path, ctx):
        if self.rms is not None and any(hi <= lo for lo, hi in zip(self.k_min, self.k_max)):
            return [f"{path}.k_max = {list(self.k_max)}: must exceed k_min = {list(self.k_min)}"]
        if self.file is None:
            return []
        problems, notes = probe_topography(self.file, self.channel, pixel_size=self.pixel_size,
                                           height_unit=self.height_unit, max_undefined=self.max_undefined,
                                           prefix=f"{path}.")
        ctx.warnings.extend(notes)
        return problems


@dataclass(frozen=True)
class Micro:
    """How the rough interface is solved (issue 7): zone grid on the interface, grid per zone
    (default 50 x 50; a measured surface's own pixel size, rounded, unless it is replaced by a
    statistically equivalent one), micro model, points of each p_n(g_n) law (top node at ``p_max``, default 20 x the nominal
    interface pressure; contact solver tolerance ``tol``), micro partition law (ch. 6) or the
    constant one."""

    zones: tuple | None = key(Pair(Integer(ge=1)), required=True)             # (nx, ny) zones
    grid: tuple | None = key(Pair(Integer(ge=8)))                             # (nx, ny) per zone
    model: str = key(Choice(("fft-bem", "asperity", "asperity-interacting")), default="fft-bem")
    law_points: int = key(Integer(ge=4), default=20)
    partition_law: bool = key(Flag(), default=False)
    p_max: float | None = key(Quantity("pressure", gt=0))                     # Pa, top node of the laws
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)     # micro contact solves

    def problems(self, path, ctx):
        if self.partition_law and "heat_partition" not in ctx.effects:
            return [f'{path}.partition_law = true: needs effect "heat_partition"']
        return []


# Default k_w(T) [(K, 1/Pa)]: the shape of thesis Fig. 7.9 (sintered pad material, [Mann 2017]):
# slowly rising up to 200 degC, steeply above. The figure's numbers are not in the text; the level
# at 20-100 degC (~8e-15 1/Pa) is what reproduces the worn volume of §7.3.2 (3.8e7 um^3 in 30 s
# of 200 N at 1.9 m/s with mu = 0.4: V / (mu F s) = 8.4e-15 1/Pa).
FIG_7_9_WEAR_RATE = ((293.15, 6e-15), (373.15, 8e-15), (473.15, 1.5e-14), (573.15, 6e-14), (673.15, 2e-13))


@dataclass(frozen=True)
class Wear:
    """Archard wear dh = k_w mu p ds (Eq. 3.10), k_w constant or a table k_w(T) (default: the
    shape of thesis Fig. 7.9, ``FIG_7_9_WEAR_RATE``). Every ``update_every`` macro steps the zones
    wear over the sliding of those steps in ``substeps`` load-controlled increments."""

    k_w: float | None = key(Quantity("wear_rate", gt=0))                      # 1/Pa
    k_w_table: tuple | None = key(Curve(Quantity("temperature", gt=0), Quantity("wear_rate", ge=0),
                                        "temperature", "k_w"))                # ((K, 1/Pa), ...)
    update_every: int = key(Integer(ge=1), default=1)                         # macro steps per update
    substeps: int = key(Integer(ge=1), default=1)                             # wear increments per update

    rules = (OneOf(("k_w", "k_w_table")),)

    @property
    def rate(self):
        """k_w [1/Pa]: the constant, else the table ((temperatures [K]), (rates [1/Pa]))."""
        if self.k_w is not None:
            return self.k_w
        return tuple(zip(*(self.k_w_table or FIG_7_9_WEAR_RATE)))


@dataclass(frozen=True)
class Layer:
    thickness: float = key(_LENGTH, required=True)                            # m
    E: float = key(_MODULUS, required=True)                                   # Pa
    nu: float = key(_POISSON, required=True)
    kappa: float | None = key(_CONDUCTIVITY, needed_by=("thermal",))          # W/(m K)


@dataclass(frozen=True)
class Layers:
    """Layers on one body's face, top first ([[layers.layer]]), on the body's material as a
    half-space or on a rigid base (ch. 2, §5.3)."""

    body: str | None = key(Text(), required=True)
    base: str = key(Choice(("half-space", "rigid")), default="half-space")
    layer: tuple | None = key(Tables(Layer), required=True)


@dataclass(frozen=True)
class Stability:
    """Complex eigenvalue analysis (§4.3): modes in a frequency band, shift target, damping."""

    band: tuple = key(Pair(Quantity("frequency", ge=0), single=False, names="[low, high]"),
                      default=(0.0, 16e3))                                    # Hz
    modes: int | None = key(Integer(ge=1), required=True)
    target: float | None = key(Quantity("frequency", ge=0))                   # Hz; default: the band's lower edge
    damping: float = key(Quantity("dimensionless", ge=0), default=0.0)        # structural loss factor

    def problems(self, path, ctx):
        low, high = self.band
        if high <= low:
            return [f"{path}.band = [{low:g}, {high:g}] Hz: the upper bound must exceed the lower"]
        if self.target is not None and not low <= self.target <= high:
            return [f"{path}.target = {self.target:g} Hz: must lie in the band [{low:g}, {high:g}] Hz"]
        return []


# ------------------------------------------------------------------ the scene
@dataclass(frozen=True)
class Scene:
    """A validated scene (SI units). ``effects`` is a frozenset; ask ``scene.has(effect)``."""

    name: str | None = key(Text(r"[A-Za-z0-9_.-]+", "a name of letters, digits, _ . -"))
    description: str = key(Text(), default="")
    effects: frozenset = key(ListOf(_EFFECT_CHOICE, unique=True, min_len=1), required=True)
    geometry: Geometry | None = key(_Geometry(), required=True)
    materials: FrozenMap | None = key(Named(Material), required=True)
    interface: Interface | None = key(Section(Interface, always=True))
    loading: Loading | None = key(Section(Loading, always=True))
    time: Time | None = key(Section(Time, always=True))
    output: Output | None = key(Section(Output, always=True))
    roughness: Roughness | None = key(Section(Roughness), needed_by=("roughness",))
    micro: Micro | None = key(Section(Micro), needed_by=("roughness",))
    wear: Wear | None = key(Section(Wear), needed_by=("wear",))
    layers: Layers | None = key(Section(Layers), needed_by=("layers",))
    stability: Stability | None = key(Section(Stability), needed_by=("stability",))
    source: Path | None = None                   # the scene file (None for loads without a path)
    warnings: tuple = field(default=())         # things accepted but ignored (one line each)

    def has(self, effect: str) -> bool:
        """True if the scene asks for ``effect`` (raises on an unknown effect name)."""
        if effect not in EFFECTS:
            raise InputError("effect", effect, f"unknown; known effects: {', '.join(EFFECTS)}")
        return effect in self.effects

    @property
    def bodies(self) -> tuple[str, str]:
        return self.geometry.bodies

    @property
    def partition(self) -> float | None:
        """Share of frictional heat into body 0 (pin, pads, block): the constant, or the effusivity
        ratio e_0/(e_0 + e_1), e = sqrt(kappa rho c), of each body's first material region (the
        one at the interface). None if unset."""
        value = self.interface.partition
        if value != "effusivity":
            return value
        e0, e1 = (self.materials[b.regions[0].material].effusivity for b in self.geometry.spec.bodies)
        return e0 / (e0 + e1)


def load(path, overrides=None) -> Scene:
    """Read and validate a scene file; raises SceneError listing every problem.

    ``overrides`` maps dotted key paths to raw values applied before validation (a study's sweep:
    ``{"loading.friction": 0.2, "geometry.mesh_size": "6 mm"}``); they are validated like the file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot read the scene file ({getattr(exc, 'strerror', None) or exc})") from None
    return loads(text, path.resolve().parent, name=path.stem, source=path.resolve(), overrides=overrides)


def loads(text: str, directory=".", *, name: str = "scene", source: Path | None = None,
          overrides=None) -> Scene:
    """Validate scene TOML text; relative paths are taken from ``directory``; ``name`` is the
    default scene name (the file stem for ``load``); ``overrides`` as in ``load``."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source or 'scene'}: not valid TOML: {exc}") from None
    for dotted, value in (overrides or {}).items():
        *parents, last = dotted.split(".")
        table = raw
        for part in parents:
            table = table.setdefault(part, {})
            if not isinstance(table, dict):
                raise SceneError(f"{dotted}: cannot override, {part} is not a table")
        table[last] = value
    effects = raw.get("effects")
    active = frozenset(e for e in effects if isinstance(e, str) and e in EFFECTS) \
        if isinstance(effects, list) else frozenset()      # the known effects decide what is needed
    ctx = Context(effects=active, directory=Path(directory).resolve())
    scene = read(Scene, raw, "", ctx)
    warnings = _cross_checks(scene, raw, ctx)
    if ctx.problems:
        raise SceneError(ctx.problems)
    name = scene.name or name
    output = dataclasses.replace(
        scene.output,
        folder=scene.output.folder or (ctx.directory / "results" / name),
        fields=scene.output.fields if scene.output.fields is not None else tuple(
            f for f, needs in OUTPUT_FIELDS.items() if all(e in active for e in needs)))
    return dataclasses.replace(scene, name=name, effects=frozenset(scene.effects), output=output,
                               source=source, warnings=tuple(warnings))


def _cross_checks(scene: Scene, raw: dict, ctx: Context) -> list[str]:
    """Checks across sections (effects, bodies, motion, outputs); appends problems to ctx and
    returns warnings. Runs on a possibly partial scene, so every part is guarded."""
    problems, warnings, effects = ctx.problems, [], ctx.effects
    for missing in EFFECTS:
        users = [f'"{e}"' for e in EFFECTS if e in effects and missing in EFFECTS[e].requires]
        if users and missing not in effects:
            problems.append(f'effects: {", ".join(users)} need{"s" if len(users) == 1 else ""} effect '
                            f'"{missing}" too (add it to effects)')
    g = scene.geometry
    if g is not None and scene.materials is not None:
        typos = unknown_keys(scene.materials, g.materials, "materials", ctx,
                             f'material of builder "{g.builder}"')
        for name in g.materials:
            if name not in scene.materials and name not in typos:
                problems.append(f'materials.{name}: missing; builder "{g.builder}" needs the materials '
                                f'{", ".join(g.materials)}')
    loading = raw.get("loading") if isinstance(raw.get("loading"), dict) else {}
    if g is not None:
        moving = ("rotation_speed", "speed_profile") if g.motion == "rotation" else ("sliding_speed",)
        wrong = ("sliding_speed",) if g.motion == "rotation" else ("rotation_speed", "speed_profile")
        for k in wrong:
            if k in loading:
                problems.append(f'loading.{k}: not used by builder "{g.builder}" ({g.motion}); '
                                f'use {" or ".join("loading." + m for m in moving)}')
        if "friction" in effects and not any(k in loading for k in moving + wrong):
            problems.append(f'{" or ".join("loading." + m for m in moving)}: missing; effect "friction" '
                            f'needs the sliding speed')
        for section in ("roughness", "layers"):
            table = getattr(scene, section)
            if table is not None and table.body is not None and table.body not in g.bodies:
                problems.append(f'{section}.body = "{table.body}": not a body of builder '
                                f'"{g.builder}"; allowed: {", ".join(g.bodies)}')
    if scene.output is not None and scene.output.fields is not None:
        for f in scene.output.fields:
            missing = [e for e in OUTPUT_FIELDS[f] if e not in effects]
            if missing:
                problems.append(f'output.fields: "{f}" needs effect "{missing[0]}" (not in effects)')
    for section, spec in fields_of(Scene):
        if section in raw and spec.needed_by and not any(e in effects for e in spec.needed_by):
            warnings.append(f'[{section}] is ignored: effect "{spec.needed_by[0]}" is not in effects')
    if {"friction", "thermal"} <= effects and "heat_partition" not in effects:
        warnings.append('effects "friction" and "thermal" without "heat_partition": no frictional heat '
                        "enters the bodies")
    return ctx.warnings + warnings

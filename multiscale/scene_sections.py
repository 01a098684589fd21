"""The tables of a scene (``multiscale.scene``): frozen dataclasses read by ``multiscale.schema``.

Materials (constants or temperature tables), the interface defaults and per-interface settings,
boundary conditions (supports, convection, radiation, fixed temperatures), the loading and its duty
cycle (load and speed against time, a braking torque; a vehicle stop or drag: ``scene_vehicle``), time
(the output in ``scene_output``), and the sections of the multiscale loop (roughness, micro, wear, layers); the squeal analysis' in
``scene_stability``. Values are SI numbers or unit strings (``multiscale.units``)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from multiscale.curves import interpolate, mean, piecewise_mean
from multiscale.errors import InputError
from multiscale.micro.outliers import DESPIKE
from multiscale.micro.topography import COVER, DETREND, MAX_UNDEFINED, probe_topography
from multiscale.scene_friction import FRICTION, law_problems
from multiscale.scene_geometry import Direction, LengthUnit
from multiscale.scene_plain import PixelSize
from multiscale.scene_stability import Stribeck
from multiscale.scene_values import ANGULAR_SPEED, LOAD_PRESSURE, MU, ROUGHNESS, TEMPERATURE
from multiscale.scene_vehicle import Vehicle
from multiscale.schema import (Choice, Curve, Either, FilePath, Flag, Integer, ListOf, OneOf, OnlyWith, Pair,
                               Quantity, Requires, Section, TableOr, Tables, Text, key)

# Plausible ranges (SI) are documented per key (``multiscale check --keys``); a value outside its
# range is warned, not refused: foams, diamond, cryogenic tests exist, but 1e9 N on a pin is a typo.
MODULUS = Quantity("pressure", gt=0, plausible=(1e5, 1.2e12))           # rubber to diamond
_POISSON = Quantity("dimensionless", gt=-1, lt=0.5, plausible=(0.0, 0.5))
_CONDUCTIVITY = Quantity("conductivity", gt=0, plausible=(0.01, 2500.0))  # foam to diamond
_DENSITY = Quantity("density", gt=0, plausible=(100.0, 23e3))            # cork to osmium
_SPECIFIC_HEAT = Quantity("specific_heat", gt=0, plausible=(50.0, 5e3))
_DIFFUSIVITY = Quantity("diffusivity", gt=0, plausible=(1e-8, 1.2e-3))
_EXPANSION = Quantity("expansion", plausible=(-1e-5, 5e-4))
_FADE = Curve(TEMPERATURE, MU, "temperature", "mu", min_rows=2)     # mu against the interface temperature
_CONVECTION = Quantity("conductance", ge=0, plausible=(0.0, 1e4))         # still air to boiling water
_HARDNESS = Quantity("pressure", gt=0, plausible=(1e6, 1e11))            # soft polymer to diamond
_WITH_RMS = "needed with rms (a generated surface)"


def _property(value: Quantity, name: str) -> TableOr:
    """A material property: a constant, or a table [[temperature, value], ...] (>= 2 rows)."""
    return TableOr(value, Curve(TEMPERATURE, value, "temperature", name, min_rows=2))


# ------------------------------------------------------------------ materials and interfaces
@dataclass(frozen=True)
class Material:
    """One body's material (Table 7.2). Every property is a constant or a table against the
    temperature ((K, value), ...), interpolated linearly and held constant beyond its ends (warned
    about when the initial temperature, or after a run a body's largest one, leaves it); ``alpha``
    is the mean (secant) expansion coefficient from the initial temperature, ``k_w`` the Archard wear
    rate (effect "wear"). The squeal analysis reads the material damping: a structural loss factor eta
    (complex stiffness E (1 + i eta)) and Rayleigh alpha M + beta K (this material's mass, stiffness)."""

    E: float | tuple = key(_property(MODULUS, "E"), required=True)                          # Pa
    nu: float | tuple = key(_property(_POISSON, "nu"), required=True)
    rho: float | tuple | None = key(_property(_DENSITY, "rho"), needed_by=("stability",))  # kg/m^3
    kappa: float | tuple | None = key(_property(_CONDUCTIVITY, "kappa"), needed_by=("thermal",))  # W/(m K)
    c: float | tuple | None = key(_property(_SPECIFIC_HEAT, "c"), absent="with thermal: rho c = kappa/chi")  # J/(kg K)
    chi: float | tuple | None = key(_property(_DIFFUSIVITY, "chi"), absent="with thermal: kappa/(rho c)")    # m^2/s
    alpha: float | tuple | None = key(_property(_EXPANSION, "alpha"), needed_by=("expansion",), warn_unused=True)  # 1/K
    k_w: float | tuple | None = key(_property(Quantity("wear_rate", ge=0, plausible=(0.0, 1e-9)), "k_w"),
                                    absent="rough body: [wear]'s rate; counter-face: no wear")     # 1/Pa, Archard
    hardness: float | tuple | None = key(_property(_HARDNESS, "hardness"), absent="with plasticity: the other side's")
    loss_factor: float | None = key(Quantity("dimensionless", ge=0), absent="0: no structural damping")
    damping_alpha: float | None = key(Quantity("rate", ge=0), absent="0: no alpha M damping")   # 1/s
    damping_beta: float | None = key(Quantity("time", ge=0), absent="0: no beta K damping")           # s

    rules = (OneOf(("c", "chi"), needed_by=("thermal",)), Requires("c", ("rho",), needed_by=("thermal",)))

    PROPERTIES = ("E", "nu", "rho", "kappa", "c", "chi", "alpha", "hardness")
    STRAIN = ("E", "nu", "alpha")       # read at the temperatures only with effect "expansion"
    DAMPING = ("loss_factor", "damping_alpha", "damping_beta")

    def problems(self, path, ctx):
        if self.k_w is not None and "wear" not in ctx.effects:
            ctx.warnings.append(f'{path}.k_w is ignored: effect "wear" is not in effects')
        if self.hardness is not None and "plasticity" not in ctx.effects:
            ctx.warnings.append(f'{path}.hardness is ignored: effect "plasticity" is not in effects (the asperities '
                                "stay elastic)")
        tables = [k for k in self.STRAIN if self.tabulated(k) and k != "alpha"]   # (alpha: ignored, said)
        if tables and "thermal" in ctx.effects and "expansion" not in ctx.effects:
            ctx.warnings.append(f'{path}.{tables[0]} depends on the temperature, but without effect "expansion" the '
                                "mechanics takes it at the initial temperature (add \"expansion\" to follow the "
                                "temperatures)")
        given = [k for k in self.DAMPING if getattr(self, k) is not None]
        if given and "stability" not in ctx.effects:
            ctx.warnings.append(f'{path}.{given[0]} is ignored: effect "stability" is not in effects')
        return []

    @property
    def wear_rate(self):
        """k_w [1/Pa] for ``micro.wear.WearRate``: the constant, or ((temperatures [K]), (rates))."""
        return self.k_w if not isinstance(self.k_w, tuple) else tuple(zip(*self.k_w))

    def tabulated(self, name: str) -> bool:
        """True if property ``name`` is a temperature table."""
        return isinstance(getattr(self, name), tuple)

    def beyond(self, T: float) -> dict[str, str]:
        """The tables (E, ..., hardness, k_w) that the temperature T [K] leaves, each with a phrase:
        {"kappa": "kappa: at 300 degC, above its last point 250 degC, held at 6 there"}."""
        out = {}
        for name in (*self.PROPERTIES, "k_w"):
            table = getattr(self, name)
            if isinstance(table, tuple) and not table[0][0] <= T <= table[-1][0]:
                (end, y), side = (table[0], "below its first") if T < table[0][0] else (table[-1], "above its last")
                out[name] = f"{name}: at {T - 273.15:.4g} degC, {side} point {end - 273.15:.4g} degC, held at {y:.4g} there"
        return out

    @property
    def constant(self) -> bool:
        """True if no property depends on the temperature."""
        return not any(self.tabulated(n) for n in self.PROPERTIES)

    def value(self, name: str, T: float) -> float | None:
        """Property ``name`` at the temperature T [K] (None if not given)."""
        v = getattr(self, name)
        return interpolate(v, T) if isinstance(v, tuple) else v

    def at(self, T: float) -> "Material":
        """The material with every property taken at T [K] (constants)."""
        return replace(self, **{n: self.value(n, T) for n in self.PROPERTIES})

    def _constant(self, what: str) -> None:
        if not self.constant:
            raise InputError("material", what, "a temperature-dependent material: take .at(T) first")

    @property
    def heat_capacity(self) -> float:
        """Volumetric heat capacity rho c [J/(m^3 K)] (= kappa/chi when chi is given)."""
        self._constant("heat_capacity")
        if self.c is not None and self.rho is not None:
            return self.rho * self.c
        if self.chi is not None and self.kappa is not None:
            return self.kappa / self.chi
        raise InputError("material", self, "needs rho and c, or kappa and chi")

    @property
    def diffusivity(self) -> float:
        """Thermal diffusivity chi = kappa/(rho c) [m^2/s]."""
        self._constant("diffusivity")
        return self.chi if self.chi is not None else self.kappa / self.heat_capacity

    @property
    def effusivity(self) -> float:
        """Thermal effusivity e = kappa/sqrt(chi) = sqrt(kappa rho c) [W s^0.5/(m^2 K)]."""
        return self.kappa / math.sqrt(self.diffusivity)

@dataclass(frozen=True)
class Interface:
    """[interface]: the defaults of every contact interface (perfect-contact baseline, §7.3.1).
    ``partition``: the share of the frictional heat into body 0, or "effusivity": e_0 A_0 /
    (e_0 A_0 + e_1 A_1) with e = sqrt(kappa rho c) at the initial temperature, A_0 the interface's
    area and A_1 the track it sweeps on a rotating body 1 (equal areas under a translation). With
    effect "roughness" the zone laws replace penalty and conductance except where rough = false."""

    penalty: float | None = key(Quantity("stiffness", gt=0, plausible=(1e8, 1e19)), needed_by=("contact",),
                                unless=("roughness",))          # Pa/m, normal penalty stiffness K_n
    partition: float | str | None = key(Either(Quantity("dimensionless", ge=0, le=1), Choice(("effusivity",))),
                                        needed_by=("heat_partition",), warn_unused=True)  # into body 0
    conductance: float | None = key(Quantity("conductance", gt=0, plausible=(1.0, 1e8)), needed_by=("conductance",),
                                    unless=("roughness",), warn_unused=True)   # W/(m^2 K), h_c

@dataclass(frozen=True)
class InterfaceSettings:
    """[interfaces.<name>]: one contact interface's own settings (names: the geometry's interfaces).
    ``roughness`` and ``micro`` override keys of the [roughness] and [micro] tables for this
    interface (its own surface, zones, laws); ``rough = false`` keeps it in perfect contact when
    the scene has effect "roughness". Its own ``friction`` or ``friction_temperature`` (fade, as
    [loading]'s) replaces [loading]'s friction, whichever key that gives."""

    friction: float | None = key(MU, absent="loading.friction (or any of its rule's keys)")   # mu
    friction_temperature: tuple | None = key(_FADE, absent="loading's friction")     # ((K, -), ...)
    rough: bool = key(Flag(), default=True)                           # with effect "roughness"
    ELSEWHERE = dict.fromkeys(("friction_curve", "stribeck"), "a mu(v) law is [loading]'s, for every interface "
                              "without a friction of its own (loading.friction_curve or [loading.stribeck]); an "
                              "interface's own friction is a constant (friction) or a fade table "
                              "(friction_temperature)")                                  # (it was "unknown")
    roughness: object = None          # Roughness of this interface (the merged [roughness] table)
    micro: object = None              # Micro of this interface (the merged [micro] table)

    rules = (OneOf(("friction", "friction_temperature")),)

    def problems(self, path, ctx):
        return law_problems(path, [k for k in FRICTION[:2] if getattr(self, k) is not None], ctx)   # as [loading]'s


_COMPONENTS = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Boundary:
    """[[boundary]]: conditions on named surfaces of the geometry (a builder's faces, the file's
    physical surfaces or [geometry.surfaces]; "free:<part or body>": its surfaces that touch nothing
    else, symmetry planes left out, a part's name before a body's). ``fix``: displacement components
    held at zero (with the interfaces' normals, friction holding nothing, they must hold every part
    against its six rigid motions: ``multiscale.held``); ``convection`` h [W/(m^2 K)], constant or a table
    against the rotating body's speed [rad/s], towards ``ambient``; ``emissivity``: radiation eps
    sigma (T^4 - T_ambient^4); ``temperature``: fixed. A face named in one entry takes its kinds of
    condition instead of a "free:" surface's of another; two of one kind on a face are refused otherwise."""

    surfaces: tuple | None = key(ListOf(Text(), unique=True, min_len=1), required=True)
    fix: tuple | None = key(ListOf(Choice(_COMPONENTS), unique=True, min_len=1), absent="no component held here")
    convection: float | tuple | None = key(TableOr(_CONVECTION, Curve(
        Quantity("angular_speed", ge=0), _CONVECTION, "speed", "h", min_rows=2)), absent="no convection")
    emissivity: float | None = key(Quantity("dimensionless", gt=0, le=1), absent="no radiation")
    ambient: float | None = key(TEMPERATURE, absent="time.initial_temperature")            # K
    temperature: float | None = key(TEMPERATURE, absent="not fixed (no condition at all: insulated)")   # K

    THERMAL = ("convection", "emissivity", "temperature")

    rules = (OneOf(("temperature", "convection")), OneOf(("temperature", "emissivity")),
             OnlyWith(("convection", "emissivity"), ("ambient",)))

    @property
    def components(self) -> tuple[int, ...]:
        """The fixed components as indices (0 = x, 1 = y, 2 = z)."""
        return tuple(_COMPONENTS[c] for c in self.fix or ())

    def problems(self, path, ctx):
        if not any(getattr(self, k) is not None for k in ("fix", "convection", "emissivity", "temperature")):
            return [f"{path}: give a condition: fix, convection, emissivity or temperature"]
        return []

    def h(self, speed: float) -> float:
        """Convection coefficient [W/(m^2 K)] at the rotating body's speed [rad/s] (0 without)."""
        if self.convection is None:
            return 0.0
        return interpolate(self.convection, speed) if isinstance(self.convection, tuple) else self.convection

# ------------------------------------------------------------------ loading, time
@dataclass(frozen=True)
class Loading:
    """Normal load (force or pressure on the load faces), sliding speed, friction, duty cycle.

    The load acts on ``faces`` (a builder's own: a pin-on-disc's holder plate ends, a brake's piston back and
    caliper bore, a block's top; not the contact: check and the run say a pressure's force on each): on a
    geometry file's a pressure normal to each face, -p n (a force is spread as
    a uniform pressure whose resultants on the faces sum to it; a curved face counts with its projected area);
    with ``direction`` a traction along it whose resultant is the force, or the pressure itself.
    ``normal_force`` is the total over all the load faces: two faces of equal areas given 4000 N take 2000 N
    each (give the clamp force times the number of faces, or ``pressure``, which acts on the whole face: a brake
    line's pressure on a backplate's back is not the piston's force, line pressure x piston area: give that as
    the force per face), scaled in time by ``load_profile`` (factor, 0 = released: no contact, no frictional
    heat). ``braking_torque`` (a rotating body) gives the load instead: the clamp force is scaled during the
    run so that the friction moment about the axis is the torque times the load factor while sliding (a cycle
    of stops under a vehicle's torque; ``vehicle.mass`` does it for one stop). The speed of the rotating body:
    ``rotation_speed``, a ``speed_profile`` against time, or a ``vehicle`` stop or drag; a translating body
    slides at ``sliding_speed``. Friction: a constant ``friction``; ``friction_temperature``, mu against the
    interface temperature (fade, effect "thermal": each facet's at the mean of its faces' macro temperatures,
    without the micro flash rise, a heat step late); an
    interface's own [interfaces.<name>] friction or table replaces them there; or mu against the slip speed,
    ``friction_curve`` or ``stribeck``, per facet at its slip speed (a run: at each contact solve's speed, the
    heat of a step with the mu of its start; the squeal: at the steady slip speed). ``ramp_steps``: the
    first contact solve (and the squeal's preload) applies the load in that many equal increments, 1/n, 2/n, ...,
    1 of it, each from the last: more where one Newton solve from rest does not converge (a stiff penalty, a
    contact that closes from a gap)."""

    normal_force: float | None = key(Quantity("force", gt=0, plausible=(1e-3, 1e6)),                 # N
                                     absent="pressure, braking_torque or vehicle.mass gives the load")
    pressure: float | None = key(LOAD_PRESSURE, absent="normal_force, braking_torque or vehicle.mass gives the load")
    braking_torque: float | None = key(Quantity("torque", gt=0, plausible=(1e-3, 1e6)),              # N m
                                       absent="normal_force, pressure or vehicle.mass gives the load")
    faces: tuple | None = key(ListOf(Text(), unique=True, min_len=1), absent="the builder's load faces (files: needed)")
    direction: tuple | None = key(Direction(Quantity("dimensionless")),
                                  absent="-p n on each face (disc_brake, files); else -z")
    load_profile: tuple | None = key(Curve(Quantity("time", ge=0), Quantity("dimensionless", ge=0, plausible=(
        0.0, 10.0)), "time", "factor"), absent="factor 1 throughout")   # ((s, -), ...): a factor of the load, not N
    rotation_speed: float | None = key(ANGULAR_SPEED, absent="speed_profile or vehicle; else at rest")  # rad/s
    speed_profile: tuple | None = key(Curve(Quantity("time", ge=0), ANGULAR_SPEED, "time", "speed"),
                                      absent="rotation_speed or vehicle gives the speed")   # ((s, rad/s), ...)
    vehicle: Vehicle | None = key(Section(Vehicle))
    sliding_speed: float | None = key(Quantity("speed", ge=0, plausible=(0.0, 200.0)), absent="at rest")  # m/s
    friction: float | None = key(MU, absent="another key of the rule below, or each interface's own")  # mu
    friction_temperature: tuple | None = key(_FADE, absent="friction, constant (no fade)")   # ((K, -), ...)
    ramp_steps: int = key(Integer(ge=1, le=10**4), default=1)   # load increments of the first mechanical solve
    friction_curve: tuple | None = key(Curve(Quantity("speed", ge=0), MU, "slip speed",
                                             "mu", min_rows=2), absent="friction or stribeck gives mu")  # ((m/s, -),..)
    stribeck: Stribeck | None = key(Section(Stribeck))

    rules = (OneOf(("normal_force", "pressure", "braking_torque", "vehicle.mass"),
                   meaning="each gives the load (a torque or a vehicle's mass: the clamp force that brakes)"),
             OneOf(FRICTION), OneOf(("rotation_speed", "speed_profile", "vehicle"),
                                    meaning="a vehicle is one stop or drag; several stops: speed and load profiles"))

    def problems(self, path, ctx):
        wrong = law_problems(path, [k for k in FRICTION if getattr(self, k) is not None], ctx)
        if wrong:
            return wrong
        if self.vehicle is not None and self.load_profile is not None:
            ctx.warnings.append(f"{path}.load_profile with {path}.vehicle: the speed follows the vehicle's "
                                "deceleration (or slope) whatever the load factor; a release does not stop it")
        given = [k for k in ("normal_force", "pressure") if getattr(self, k) is not None]
        by_mass = self.vehicle is not None and self.vehicle.mass is not None
        if (self.braking_torque is not None or by_mass) and "friction" not in ctx.effects:   # (a vehicle's: check
            key = "braking_torque" if self.braking_torque is not None else "vehicle.mass"   # said OK: a user trial)
            return [f'{path}.{key}: the clamp force follows from the friction moment: needs effect "friction"']
        if self.braking_torque is None and not given and not by_mass and "contact" in ctx.effects:
            return [f"{path}.normal_force or {path}.pressure: missing; effect \"contact\" needs it "
                    f"(or {path}.braking_torque, {path}.vehicle.mass)"]
        return []

    @property
    def torque(self) -> float | None:
        """Braking torque [N m] the friction moment is held at (times the load factor, while sliding):
        ``braking_torque``, or a vehicle's braking force times its wheel radius; None: a load is given."""
        if self.braking_torque is not None:
            return self.braking_torque
        v = self.vehicle
        return None if v is None or v.mass is None else v.braking_force * v.wheel_radius

    def angular_speed(self, t: float) -> float:
        """omega(t) [rad/s]: constant, the speed profile (linear in time, held constant beyond its
        ends) or the vehicle's; 0 without rotation."""
        if self.vehicle is not None:
            return self.vehicle.angular_speed(t)
        if self.speed_profile is not None:
            return interpolate(self.speed_profile, t)
        return self.rotation_speed or 0.0

    @property
    def steady_speed(self) -> bool:
        """True if the speed never changes."""
        return self.speed_profile is None and (self.vehicle is None or self.vehicle.deceleration is None)

    def factor(self, t: float) -> float:
        """Load factor at t [s] (1 without a load profile; 0: released)."""
        return 1.0 if self.load_profile is None else interpolate(self.load_profile, t)

    def mean_factor(self, t0: float, t1: float) -> float:
        """Mean load factor over [t0, t1] [s]."""
        return 1.0 if self.load_profile is None else mean(self.load_profile, t0, t1)

    def knots(self) -> tuple:
        """Times [s] where the load factor or the angular speed may change slope (linear between)."""
        out = [t for table in (self.load_profile, self.speed_profile) if table is not None for t, _ in table]
        stop = None if self.vehicle is None else self.vehicle.stop_time
        return tuple(out + ([stop] if stop is not None else []))

    def mean_angular_speed(self, t0: float, t1: float) -> float:
        """Mean of omega(t) over [t0, t1] [rad/s] (exact, a stop inside the interval included)."""
        return piecewise_mean(self.angular_speed, self.knots(), t0, t1)

    def mean_sliding_factor(self, t0: float, t1: float) -> float:
        """Mean of factor(t) omega(t) over [t0, t1] [rad/s]: the loaded sliding of the interval
        (exact for the piecewise-linear profiles and a stop; frictional heat and wear follow it)."""
        return piecewise_mean(lambda t: self.factor(t) * self.angular_speed(t), self.knots(), t0, t1)


@dataclass(frozen=True)
class Time:
    """Staggered time loop (Fig. 7.4): ``steps`` macro steps Δt = ``end``/``steps`` from t = 0 to
    ``end``. Each macro step solves the heat conduction (backward Euler) in ``substeps`` heat steps
    of Δt/``substeps``, the contact solved again after each where the load, the friction or the
    expansion changed; a rough scene's zone laws, heat partition and wear are updated once per
    macro step. ``initial_temperature``: every body's uniform temperature at t = 0, and the
    reference of thermal expansion."""

    end: float | None = key(Quantity("time", gt=0, plausible=(1e-6, 1e6)), needed_by=("thermal", "wear"))  # s
    steps: int = key(Integer(ge=1, le=10**6), default=1)        # (1e9 steps: check's plan took ~30 min)
    substeps: int = key(Integer(ge=1, le=10**4), default=1)
    initial_temperature: float = key(TEMPERATURE, default=293.15)  # K

    @property
    def dt(self) -> float | None:
        """Macro time step Δt [s] (None without an end time)."""
        return None if self.end is None else self.end / self.steps


# ------------------------------------------------------------------ later effects (validated only)
@dataclass(frozen=True)
class Roughness:
    """Rough face of one body (§7.3.1: only the pin is rough): generated (fractal, Eqs. 1.24–1.25;
    cut-offs are wavelengths per patch: the whole face cut into zones, or each zone, ``patch``) or
    a measured ``file`` (issue 17; ``multiscale.micro.topography``): any format SurfaceTopography
    reads with its units and pixel sizes (``pixel_size``, ``height_unit`` override them, warned) or
    a plain height matrix (.npy, .txt, .csv, .asc; rows along y: (ny, nx), the transpose of
    SurfaceTopography's ``heights()``), conditioned (``detrend``, outliers warned of or
    removed at ``despike``, undefined points filled up to ``max_undefined``, ``cutoff``), then
    ``cover``ing the face: itself ("measured": it must cover it; checked when the scene is read),
    copies ("mirror", "tile": warned) or a surface from its PSD ("equivalent", ``seed``)."""

    body: str | None = key(Text(), absent="the stationary body, the only one allowed")
    rms: float | None = key(ROUGHNESS, absent="file gives the surface")                     # m
    hurst: float | None = key(Quantity("dimensionless", gt=0, le=1, plausible=(0.1, 1.0)), absent=_WITH_RMS)
    k_min: tuple | None = key(Pair(Quantity("dimensionless", gt=0)), absent=_WITH_RMS)   # wavelengths, (x, y)
    k_max: tuple | None = key(Pair(Quantity("dimensionless", gt=0)), absent=_WITH_RMS)
    seed: int = key(Integer(ge=0), default=0)
    patch: str = key(Choice(("face", "zone")), default="face")
    file: Path | None = key(FilePath(), absent="rms: a generated fractal surface")     # measured topography
    channel: int | None = key(Integer(ge=0), absent="the file's default channel")
    pixel_size: tuple | None = key(Pair(PixelSize()), absent="the file's (needed if it has none)")   # m, (dx, dy)
    height_unit: float | None = key(Either(Quantity("length", gt=0), LengthUnit()),   # m per height unit ("um")
                                    absent="the file's unit; metres for a plain height matrix")
    detrend: str = key(Choice(tuple(DETREND)), default="plane")               # form removal
    cutoff: float | None = key(Quantity("length", gt=0, plausible=(1e-7, 0.1)), absent="no filter")  # m, Gaussian λc,
    #                                                                    of 2 pixels and 2 micro cells at least
    max_undefined: float = key(Quantity("dimensionless", ge=0, le=1), default=MAX_UNDEFINED)
    despike: float | None = key(Quantity("dimensionless", gt=0), absent=f"outliers warned of (k = {DESPIKE:g}), kept")
    cover: str = key(Choice(COVER), default="measured")

    rules = (OneOf(("rms", "file"), required=True, meaning="a generated fractal surface or a measured file"),
             Requires("rms", ("hurst", "k_min", "k_max")), OnlyWith(("rms",), ("hurst", "k_min", "k_max", "patch")),
             OnlyWith(("file",), ("channel", "pixel_size", "height_unit", "detrend", "cutoff", "max_undefined", "despike",
                               "cover")))

    def problems(self, path, ctx):
        if self.rms is not None and any(hi <= lo for lo, hi in zip(self.k_min, self.k_max)):
            return [f"{path}.k_max = {list(self.k_max)}: must exceed k_min = {list(self.k_min)}"]
        if self.file is None:
            return []
        problems, notes = probe_topography(self.file, self.channel, pixel_size=self.pixel_size,
                                           height_unit=self.height_unit, max_undefined=self.max_undefined,
                                           detrend=self.detrend, despike=self.despike, cutoff=self.cutoff,
                                           prefix=f"{path}.")
        ctx.warnings.extend(notes)
        return problems


DEFAULT_GRID = (50, 50)    # cells per zone without micro.grid (generated surfaces)
P_MAX_FACTOR = 20.0        # without micro.p_max, the laws' top node is this x the nominal interface pressure
P_MAX_PLASTIC = 0.9        # with plasticity, it is at most this x the hardness (``LawSpec``: below it)


# Default coupling of partitions and temperatures for each choice of remote temperatures, chosen by
# measurement (docs/accuracy/coupling.md: with "bulk" the implicit scheme is within 1 % in one pass
# per step; the explicit one was 6 % off while the disc's temperatures were P1, and the fixed point
# can fail to converge at tight tolerances). With "rough" the partition does not depend on the
# temperatures: nothing to iterate.
COUPLING_DEFAULT = {"rough": "explicit", "bulk": "implicit"}


@dataclass(frozen=True)
class Micro:
    """How the rough interface is solved (issue 7): zone grid on the interface (zones no smaller than
    its facets), grid per zone (a measured surface's pixel size rounded), micro model, points of each
    p_n(g_n) law (top node at ``p_max``; contact solver tolerance ``tol``), micro partition law (ch. 6)
    or the constant one. The micro heating of the loop (issue 19): ``heating`` "steady" (§6.5) or
    "transient" over each macro step in ``heating_steps`` = N_t steps (§6.3, Table 7.1: 10);
    ``remote_temperatures`` "rough" (both bodies' at the rough body's macro surface temperature; with
    effect "conductance" h_c conducts between the bodies already) or "bulk" (each body's own: §7.2.2,
    §6.5); ``coupling`` of partitions and temperatures "explicit" (from the previous step),
    "fixed-point" (iterated within the step to ``coupling_tol`` in at most ``coupling_iterations``
    passes) or "implicit" (bulk only: the partition at equal temperatures and the zone's exchange G,
    its own bulk's spreading out, as an interface conductance); defaults: ``remote``, ``coupling_scheme``."""

    zones: tuple | None = key(Pair(Integer(ge=1)), required=True)             # (nx, ny) zones
    grid: tuple | None = key(Pair(Integer(ge=8)),                             # (nx, ny) per zone
                             absent='50 x 50; a measured file\'s pixels (not with cover "equivalent")')
    model: str = key(Choice(("fft-bem", "asperity", "asperity-interacting")), default="fft-bem")
    law_points: int = key(Integer(ge=4), default=20)
    partition_law: bool = key(Flag(), default=False)
    p_max: float | None = key(Quantity("pressure", gt=0, plausible=(1e3, 5e10)),   # Pa, top node of the laws
                              absent=f"{P_MAX_FACTOR:g} x the nominal interface pressure")
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)     # micro contact solves
    flash_softening: bool = key(Flag(), default=False)   # H(T) of each zone at its last flash temperature
    heating: str = key(Choice(("steady", "transient")), default="steady")
    heating_steps: int = key(Integer(ge=1), default=10)                       # N_t per macro step (transient)
    remote_temperatures: str | None = key(Choice(("rough", "bulk")), absent='"bulk"; "rough" with effect conductance')
    coupling: str | None = key(Choice(("explicit", "fixed-point", "implicit")),
                               absent='"implicit" with "bulk" remote temperatures, else "explicit"')
    coupling_tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-3)   # max |dp| per pass
    coupling_iterations: int = key(Integer(ge=1), default=30)

    def problems(self, path, ctx):
        if self.partition_law and "heat_partition" not in ctx.effects:
            return [f'{path}.partition_law = true: needs effect "heat_partition"']
        if self.flash_softening and not {"plasticity", "heat_partition"} <= ctx.effects:
            return [f'{path}.flash_softening = true: needs effects "plasticity" and "heat_partition" (the micro '
                    "heating gives the flash temperature)"]
        if self.coupling == "implicit" and self.remote(ctx.effects) != "bulk":
            return [f'{path}.coupling = "implicit": conducts between the bulk temperatures; needs '
                    f'{path}.remote_temperatures = "bulk" (and no effect "conductance")']
        if self.remote_temperatures == "bulk" and "conductance" in ctx.effects:
            return [f'{path}.remote_temperatures = "bulk": the micro heating conducts between the two bodies '
                    f'already; effect "conductance" would conduct twice (drop one)']
        return []

    def remote(self, effects) -> str:
        """``remote_temperatures``, or its default for the scene's ``effects``: "bulk" (thesis
        §7.2.2), "rough" with effect "conductance"."""
        return self.remote_temperatures or ("rough" if "conductance" in effects else "bulk")

    def coupling_scheme(self, effects) -> str:
        """``coupling``, or its default for the remote temperatures (``COUPLING_DEFAULT``)."""
        return self.coupling or COUPLING_DEFAULT[self.remote(effects)]


@dataclass(frozen=True)
class Layer:
    """One layer of [[layers.layer]] (top first), bonded to the next: its ``thickness``, Young's
    modulus ``E`` and Poisson ratio ``nu`` (the micro contact's layered kernel, ch. 2), and its
    conductivity ``kappa`` (effect "conductance": the layered conduction kernel, §5.3)."""

    thickness: float = key(Quantity("length", gt=0, plausible=(1e-9, 0.1)), required=True)  # m
    E: float = key(MODULUS, required=True)                                   # Pa
    nu: float = key(_POISSON, required=True)
    kappa: float | None = key(_CONDUCTIVITY, needed_by=("conductance",))      # W/(m K)


@dataclass(frozen=True)
class Layers:
    """Layers on one body's face, top first ([[layers.layer]]), on the body's material as a
    half-space or on a rigid base (ch. 2, §5.3)."""

    body: str | None = key(Text(), absent="the stationary body, the only one allowed")
    base: str = key(Choice(("half-space", "rigid")), default="half-space")
    layer: tuple | None = key(Tables(Layer), required=True)

"""The squeal-analysis tables of a scene (``multiscale.scene``): [stability], [stability.sweep] and the
speed-dependent friction law [loading.stribeck] (issue 20; docs/squeal.md). Values are SI numbers or
unit strings (``multiscale.units``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from multiscale.scene_cycle import squeal_state
from multiscale.scene_friction import bare_interfaces, initial_friction, speed_law_guess
from multiscale.scene_values import ANGULAR_SPEED, LOAD_PRESSURE, MU, ROUGHNESS
from multiscale.schema import Choice, Flag, Integer, ListOf, OneOf, Pair, Quantity, Section, key


@dataclass(frozen=True)
class Stribeck:
    """[loading.stribeck]: friction falling with the slip speed v, mu(v) = kinetic + (static -
    kinetic) exp(-(v / speed)^exponent) (exponent 1: the exponential static-to-kinetic decay law).
    Not with a friction sweep ([stability.sweep] friction sets a constant mu at each point)."""

    static: float | None = key(MU, required=True)      # (52 passed: a trial)
    kinetic: float | None = key(MU, required=True)
    speed: float | None = key(Quantity("speed", gt=0), required=True)            # m/s, Stribeck speed
    exponent: float = key(Quantity("dimensionless", gt=0), default=1.0)

    def problems(self, path, ctx):
        if self.static <= self.kinetic:     # (a swapped pair passed unsaid: a user trial)
            ctx.warnings.append(f"{path}: static mu {self.static:g} is not above kinetic mu {self.kinetic:g}: mu "
                                + (f"is constant (loading.friction = {self.static:g} says so)" if self.static ==
                                   self.kinetic else "rises with the slip speed (its slope damps a squeal analysis's "
                                   "modes); static and kinetic swapped?"))
        return []


SWEEP_PARAMETERS = {"friction": "-", "pressure": "Pa", "speed": "rad/s", "rms": "m"}
_OTHER = "another of friction, pressure, speed, rms is swept"


LOWEST_BAND_TOP = 100.0     # Hz: a stability.band ending below is warned of (a unit left out?)


@dataclass(frozen=True)
class Sweep:
    """[stability.sweep]: a stability map over one parameter: the friction coefficient of every
    interface, the brake pressure, the speed of the rotating body or the R_q of the rough surfaces
    (effect "roughness"). The listed values, or with ``points`` that many from the first to the
    last. ``preload = "once"`` (default for speed) keeps the sliding state of the nominal analysis
    and projects every point on the undamped modes of the first and last points (fast, approximate:
    docs/squeal.md); ``"each"`` (friction, pressure, roughness) preloads and solves every point.
    The modes are tracked by MAC
    (``mac``: the lowest MAC of a pair) and the onset of every unstable mode is bisected
    (``onsets``); an "each" map narrows each onset's bracket by up to ``refine`` full analyses
    (preload and eigen solve); see ``multiscale.workflows.squeal_map``."""

    friction: tuple | None = key(ListOf(MU, min_len=2), absent=_OTHER)       # each value read as loading's
    pressure: tuple | None = key(ListOf(LOAD_PRESSURE, min_len=2), absent=_OTHER)     # Pa  (bare 10 and 20 Pa
    speed: tuple | None = key(ListOf(ANGULAR_SPEED, min_len=2), absent=_OTHER)        # rad/s  passed unwarned:
    rms: tuple | None = key(ListOf(ROUGHNESS, min_len=2), absent=_OTHER)              # m  a trial)
    points: int | None = key(Integer(ge=2), absent="the values listed")
    preload: str | None = key(Choice(("each", "once")), absent='"once" for speed, "each" for friction, pressure '
                              "and rms")
    mac: float = key(Quantity("dimensionless", gt=0, le=1), default=0.5)
    onsets: bool = key(Flag(), default=True)
    refine: int | None = key(Integer(ge=0), absent='3 with preload = "each"')

    rules = (OneOf(tuple(SWEEP_PARAMETERS), required=True),)

    @property
    def parameter(self) -> str | None:
        """The swept key; None on a table whose values failed validation (the problem is reported)."""
        return next((k for k in SWEEP_PARAMETERS if getattr(self, k) is not None), None)

    @property
    def preload_mode(self) -> str:
        """"once" (keep the nominal sliding state) or "each" (preload every point)."""
        return self.preload or ("once" if self.parameter == "speed" else "each")      # (friction: "once" missed
        #   the strongest instability of a 0-0.6 map and put an onset at 0.087 for 0.063: a user trial, 2026-12-04)

    @property
    def refine_steps(self) -> int:
        """Full analyses that narrow each onset's bracket (0 with preload "once")."""
        return 0 if self.preload_mode == "once" else 3 if self.refine is None else self.refine

    @property
    def values(self) -> tuple:
        """The swept values (SI), increasing."""
        given = getattr(self, self.parameter)
        if self.points is None:
            return tuple(given)
        lo, hi = given
        return tuple(lo + (hi - lo) * k / (self.points - 1) for k in range(self.points))

    def problems(self, path, ctx):
        name = self.parameter
        given = getattr(self, name)
        where = f"{path}.{name}"
        if self.points is not None and len(given) != 2:
            return [f"{where}: with {path}.points give the range [first, last] (2 values, got {len(given)})"]
        if any(b <= a for a, b in zip(given, given[1:])):
            return [f"{where}: the values must increase"]
        loading = ctx.root.get("loading") if isinstance(ctx.root.get("loading"), dict) else {}
        if name == "rms" and "roughness" not in ctx.effects:
            return [f'{where}: sweeps the rough surfaces: needs effect "roughness"']
        tables = ctx.root.get("interfaces") if isinstance(ctx.root.get("interfaces"), dict) else {}
        surfaces = [ctx.root.get("roughness")] + [t.get("roughness") for t in tables.values() if isinstance(t, dict)]
        if name == "rms" and not any(isinstance(r, dict) and "rms" in r for r in surfaces):
            return [f"{where}: sweeps roughness.rms of a generated surface; the scene gives no roughness.rms"]
        if self.preload == "once" and name in ("pressure", "rms"):
            return [f'{path}.preload = "once": a {name} sweep changes the preloaded state; use "each"']
        if self.refine is not None and self.preload_mode == "once":
            return [f'{path}.refine: narrows the onsets of a preload = "each" map by full analyses; a "once" map '
                    "bisects them on its common basis (set preload = \"each\" or remove refine)"]
        if name == "friction" and ("friction_curve" in loading or "stribeck" in loading):
            return [f"{where}: sets a constant friction; remove loading.friction_curve / loading.stribeck"]
        if name == "friction" and "friction" not in ctx.effects:     # (the map had friction, the analysis none)
            return [f'{where}: sweeps the friction of effect "friction", which the scene does not have']
        own = [f"interfaces.{n}.{k}" for n, t in tables.items() if isinstance(t, dict)
               for k in ("friction", "friction_temperature") if k in t]
        if name == "friction" and own:
            given = ", ".join(own)
            ctx.warnings.append(f"{where}: sets every interface's friction, {given} too: no point of the map is "
                                "the scene's analysis")
        if name == "pressure" and "pressure" not in loading:
            return [f"{where}: sweeps loading.pressure; the scene gives no loading.pressure"]
        if name == "speed" and "sliding_speed" in loading:
            return [f"{where}: an angular speed of the rotating body; this geometry translates"]
        stability = ctx.root.get("stability") if isinstance(ctx.root.get("stability"), dict) else {}
        if name == "speed" and not ({"friction_curve", "stribeck"} & set(loading) or stability.get("gyroscopic")):
            ctx.warnings.append(f"{where}: nothing of the linearised system depends on the speed (a constant "
                                "friction, stability.gyroscopic = false): every point of the map is the same")
        if name == "pressure" and not ("roughness" in ctx.effects or stability.get("prestress")):
            ctx.warnings.append(f"{where}: nothing of the linearised system depends on the pressure (penalty contact "
                                "without initial gaps scales with the load, stability.prestress = false): every point "
                                "of the map is the same")
        return []


@dataclass(frozen=True)
class Stability:
    """Complex eigenvalue analysis (§4.3): modes in a frequency band, shift target, damping.

    ``modes``: how many complex modes to find in the ``band`` [low, high] (Hz), nearest the
    ``target`` (default: the band's lower edge) first: all of the band's when it holds fewer; when it
    holds more, those nearest the target, and the run warns which part of the band was not searched
    (raise ``modes`` until that warning goes).

    ``damping`` (loss factor eta), ``rayleigh_alpha`` / ``rayleigh_beta`` (alpha M + beta K) act on
    the whole system, mapped exactly from the undamped modes. Per-material damping, the friction
    slope (``friction_damping``) and the gyroscopic terms are solved as a full quadratic
    eigenproblem (``method = "quadratic"``, viscous only, from 0 Hz up) or by projection on the
    undamped modes up to ``basis`` x the band's top (``"projection"``, needed for loss factors and
    for a band above 0 Hz or a target); ``"auto"`` picks.
    ``"subspace"``: projection on the real modes of the frictionless tangent and their static
    corrections, for models whose LU does not fit in memory (docs/squeal.md).
    ``prestress``: the initial-stress stiffness of the preload, its effect on every frequency
    reported; ``gyroscopic``: the rotating body's Coriolis and centrifugal terms (docs/squeal.md).
    A mode is unstable when its damping ratio -sigma/|lambda| is below -``threshold`` (default 1e-6:
    any growth beyond round-off; e.g. 1e-3 reports only modes growing faster than 0.1 % of critical)."""

    band: tuple = key(Pair(Quantity("frequency", ge=0), single=False, names="[low, high]"),
                      default=(0.0, 16e3))                                    # Hz
    modes: int | None = key(Integer(ge=1), required=True)
    target: float | None = key(Quantity("frequency", ge=0), absent="the band's lower edge")   # Hz
    damping: float = key(Quantity("dimensionless", ge=0, plausible=(0.0, 0.5)), default=0.0)  # structural loss factor
    rayleigh_alpha: float = key(Quantity("rate", ge=0, plausible=(0.0, 1e4)), default=0.0)     # 1/s: zeta = alpha / 2 omega
    rayleigh_beta: float = key(Quantity("time", ge=0, plausible=(0.0, 1e-5)), default=0.0)   # s: zeta = beta omega / 2
    #                      (1e-5 s: zeta 0.3 at 10 kHz; 1e-3 s left every mode overdamped, said nowhere: an NVH trial)
    prestress: bool = key(Flag(), default=False)
    gyroscopic: bool = key(Flag(), default=False)
    friction_damping: bool = key(Flag(), default=True)
    method: str = key(Choice(("auto", "projection", "quadratic", "subspace")), default="auto")
    basis: float = key(Quantity("dimensionless", ge=1), default=1.5)
    threshold: float = key(Quantity("dimensionless", gt=0, plausible=(1e-9, 0.05)), default=1e-6)   # damping ratio
    sweep: Sweep | None = key(Section(Sweep))

    def problems(self, path, ctx):
        low, high = self.band
        if high <= low:
            return [f"{path}.band = [{low:g}, {high:g}] Hz: the upper bound must exceed the lower"]
        if self.target is not None and not low <= self.target <= high:
            return [f"{path}.target = {self.target:g} Hz: must lie in the band [{low:g}, {high:g}] Hz"]
        if high < LOWEST_BAND_TOP:        # ([0, 6] read as Hz failed only after the preload: a user trial)
            ctx.warnings.append(f"{path}.band = [{low:g}, {high:g}] Hz: ends below {LOWEST_BAND_TOP:g} Hz, where no "
                                'squeal lies (1-16 kHz); a number without a unit is Hz: "6 kHz"')
        materials = ctx.root.get("materials") if isinstance(ctx.root.get("materials"), dict) else {}
        lossy = [m for m, t in materials.items() if isinstance(t, dict) and t.get("loss_factor")]
        if self.method == "quadratic" and (self.damping or lossy):
            what = f"{path}.damping" if self.damping else f"materials.{lossy[0]}.loss_factor"
            return [f'{path}.method = "quadratic": takes viscous damping only; {what} (complex stiffness) '
                    'needs method = "projection"']
        if self.method == "quadratic" and self.target:    # (a user trial got the lowest modes, the target unsaid)
            return [f'{path}.target = {self.target:g} Hz: method = "quadratic" cannot shift to a frequency in real '
                    'arithmetic (it finds the lowest modes first); use method = "auto", which projects on the modes '
                    "around the target, or leave the target out"]
        if self.method == "quadratic" and low > 0:
            ctx.warnings.append(f'{path}.method = "quadratic" with a band from {low:g} Hz: it finds the lowest modes '
                                f"first, {path}.modes of them from 0 Hz, and refuses a band they do not cover; "
                                'method = "auto" projects on the band')
        if self.method == "subspace" and self.sweep is not None:
            return [f'{path}.method = "subspace": one big analysis, not a sweep (use "auto" with [{path}.sweep])']
        loading = ctx.root.get("loading") if isinstance(ctx.root.get("loading"), dict) else {}
        if self.gyroscopic and "sliding_speed" in loading:
            return [f"{path}.gyroscopic = true: needs a rotating body; this geometry translates"]
        return []


def unresolved_band(stability, h: float | None, materials, names, T0: float) -> list[str]:
    """A warning if a material's (``names``: the geometry's) shear wavelength at the band's top,
    sqrt(E / (2 (1 + nu) rho)) / f at ``T0`` [K], is shorter than one element of the mesh (``h``
    [m]: its mesh_size, a mesh file's own element size): modes there are the mesh's, not the
    structure's (a 1 MHz band on a 12 mm brake gave 10 modes at residuals of 1e-17 without a word:
    an adversarial trial; a .msh file's mesh was not checked)."""
    top = stability.band[1]
    waves = {}
    for name in names:
        m = materials.get(name)
        if h and top > 0 and m is not None and m.rho is not None:
            p = m.at(T0)
            waves[name] = math.sqrt(p.E / (2 * (1 + p.nu) * p.rho)) / top
    short = {name: wave for name, wave in waves.items() if wave < h}
    if not short:
        return []
    return [f"stability.band: at its top ({top:.4g} Hz) the shear wavelengths in "
            + ", ".join(f"{name} ({wave * 1e3:.3g} mm)" for name, wave in short.items())
            + f" are shorter than the mesh's elements ({h * 1e3:.3g} mm): modes there are the mesh's, not the "
            f"structure's; elements of {min(short.values()) / 2 * 1e3:.2g} mm or less (geometry.mesh_size), or a "
            "lower band"]


def undamped_falling_law(scene, materials, interfaces) -> list[str]:
    """A warning if [loading]'s mu(v) law falls with the slip speed (a Stribeck law of static above
    kinetic mu, a curve with a falling segment) on some of the ``interfaces`` (those without a
    friction of their own), ``stability.friction_damping`` turns its slope into (negative) damping,
    and nothing damps the structure (no ``stability`` damping, no loss factor or Rayleigh damping of
    the ``materials``): that alone flags nearly every mode moving the pads along the disc (9 of 10
    car-brake modes; 1 of 10 with rayleigh_beta = 1e-7 s, as without the slope: a user trial)."""
    stability, loading, law = scene.stability, scene.loading, scene.loading.stribeck
    falls = law.static > law.kinetic if law is not None else \
        loading.friction_curve is not None and any(b[1] < a[1] for a, b in zip(loading.friction_curve,
                                                                                loading.friction_curve[1:]))
    if not (falls and stability.friction_damping and bare_interfaces(scene.interfaces, interfaces)) or \
            structurally_damped(scene, materials):
        return []
    return ["stability.friction_damping: the mu(v) law falls with the slip speed and nothing damps the structure, "
            "so its negative damping flags as unstable nearly every mode that moves the pads along the disc, "
            "however slightly: give the damping the brake has (stability.damping or rayleigh_alpha/beta, or the "
            "materials' loss_factor or damping_alpha/beta) to weigh it, or friction_damping = false to see the "
            "mode coupling alone"]


def structurally_damped(scene, materials) -> bool:
    """Whether anything damps the structure: [stability] damping or Rayleigh coefficients, or a loss
    factor or Rayleigh damping of one of the ``materials`` (the geometry's material names)."""
    st = scene.stability
    return bool(st.damping or st.rayleigh_alpha or st.rayleigh_beta or any(
        getattr(m, k) for m in (scene.materials.get(n) for n in materials) if m is not None for k in m.DAMPING))


def stability_warnings(scene, g, effects, T0: float) -> list[str]:
    """What a squeal analysis of ``scene`` (geometry ``g``, initial temperature ``T0`` [K]) cannot
    show: the state it linearises (``squeal_state``), no friction at all (effect "friction" missing,
    or mu 0 on every interface and no friction sweep: nothing couples the modes, no flutter can be
    found; it passed unsaid, an NVH user trial), a band the mesh does not resolve
    (``unresolved_band``) and a falling mu(v) law left undamped (``undamped_falling_law``)."""
    sweep = scene.stability.sweep if scene.stability is not None else None
    swept = sweep.parameter if sweep is not None else None
    friction = "friction" in effects
    out = squeal_state(scene.loading, g.motion, friction and swept != "speed")
    guess = speed_law_guess(scene.loading)        # a mu(v) law's (0 everywhere passed unsaid: a review)
    mu = [initial_friction(scene.interface_settings(n), T0) for n in g.spec.interfaces] if friction else []
    if swept != "friction" and not any((guess if m is None else m) > 0 for m in mu):
        why = "mu = 0 on every interface" if friction else 'no effect "friction"'
        out.append(f"the squeal analysis has no friction ({why}): no friction-induced instability can be found")
    if scene.stability is not None and scene.materials is not None:
        h = g.resolved().get("mesh_size") or g.spec.element_size
        out += unresolved_band(scene.stability, h, scene.materials, g.materials, T0)
        out += undamped_falling_law(scene, g.materials, g.spec.interfaces) if friction else []
    return out

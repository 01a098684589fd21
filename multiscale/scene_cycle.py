"""The duty cycle against the analysis that runs it (``multiscale.scene``'s cross-checks): what a
load or speed profile, a vehicle stop and a speed-dependent convection table leave out of the run
[0, time.end], and what the squeal analysis, which linearises one state, ignores of a cycle.
The checks return one warning line per finding; ``braking_phases`` and ``largest_load_factor``
read the cycle over the run's knots (``run_knots``), ``loaded_sliding`` integrates it."""
from __future__ import annotations

import math

from multiscale.curves import interpolate
from multiscale.scene_vehicle import GRAVITY


def cycle_coverage(ld, end: float) -> list[str]:
    """How the duty cycle and the run [0, end] [s] differ: a profile held at its ends inside the run,
    one that changes after ``end`` (a second stop the run never reaches), a vehicle stop still
    running at ``end`` (its share 1 - (v(end)/v0)^2 of the kinetic energy braked)."""
    out = []
    for key in ("load_profile", "speed_profile"):
        table = getattr(ld, key)
        if table is None:
            continue
        unit = " rad/s" if key == "speed_profile" else ""
        held = ([f"at {table[0][1]:g}{unit} before {table[0][0]:g} s"] if table[0][0] > 0 else []) + \
               ([f"at {table[-1][1]:g}{unit} from {table[-1][0]:g} s to time.end = {end:g} s"]
                if table[-1][0] < end else [])
        if held:
            out.append(f"loading.{key} is held {' and '.join(held)} (it does not cover the run)")
        if any(t > end and value != interpolate(table, end) for t, value in table):
            out.append(f"loading.{key} changes after time.end = {end:g} s (its rows to {table[-1][0]:g} s): the run "
                       "ends before that part of the cycle; a longer time.end runs it")
    v = ld.vehicle
    if v is not None and v.stop_time is not None and v.stop_time > end:
        left = v.speed - v.deceleration * end                     # m/s at the run's end
        out.append(f"loading.vehicle: the stop from {v.speed * 3.6:.3g} km/h at {v.deceleration:.3g} m/s^2 "
                   f"({v.deceleration / GRAVITY:.3g} g) takes "
                   f"{v.stop_time:.3g} s, beyond time.end = {end:g} s: the run ends at {left * 3.6:.3g} km/h, having "
                   f"braked {100 * (1 - (left / v.speed) ** 2):.0f} % of the kinetic energy; a longer time.end "
                   "brakes the rest" + (' (a deceleration in g is written "0.6 gn")' if v.deceleration < 1.0 else ""))
    return out


def run_knots(ld, end: float) -> list[float]:
    """The times [s] of [0, ``end``] where the duty cycle may change slope, both ends included:
    between them the load factor and the speed are linear."""
    return sorted({0.0, end, *(t for t in ld.knots() if 0 < t < end)})


def largest_load_factor(ld, end: float) -> float:
    """The largest load factor of the run [0, ``end``] [s] (1 without a load profile): at a knot, the
    factor being linear between them."""
    return max(ld.factor(t) for t in run_knots(ld, end))


def cycle_keys(ld) -> list[str]:
    """The keys that make [loading] a duty cycle: a load or a speed profile, a vehicle that slows
    (a stop; a drag keeps its speed)."""
    keys = [f"loading.{k}" for k in ("load_profile", "speed_profile") if getattr(ld, k) is not None]
    return keys + (["loading.vehicle"] if ld.vehicle is not None and not ld.steady_speed else [])


def speed(ld, motion: str, t: float) -> float:
    """Body 1's speed at ``t`` [s]: rotating (``motion`` "rotation"), its angular speed [rad/s];
    translating, ``sliding_speed`` [m/s] (0 at rest)."""
    return ld.angular_speed(t) if motion == "rotation" else ld.sliding_speed or 0.0


def loaded_sliding(ld, motion: str, t0: float, t1: float) -> float:
    """The integral of load factor x ``speed`` over [t0, t1] [s] (rad or m; 0 if t1 <= t0): the
    sliding that frictional heat and wear follow, exact for the piecewise-linear cycle."""
    if t1 <= t0:
        return 0.0
    if motion == "rotation":
        return ld.mean_sliding_factor(t0, t1) * (t1 - t0)
    return ld.mean_factor(t0, t1) * (ld.sliding_speed or 0.0) * (t1 - t0)


def braking_phases(ld, motion: str, end: float) -> list[tuple[float, float]]:
    """Intervals [t0, t1] of [0, ``end``] [s] with frictional heat: loaded (load factor > 0) and
    sliding (the rotating body's speed, or ``sliding_speed`` of a translating one, > 0). Both are
    piecewise linear and non-negative between the cycle's knots, so a piece is heated when their
    product is positive at its midpoint."""
    def heated(t):
        return ld.factor(t) * speed(ld, motion, t) > 0

    ts = run_knots(ld, end)
    phases = []
    for a, b in zip(ts, ts[1:]):
        if heated(0.5 * (a + b)):
            if phases and phases[-1][1] == a:
                phases[-1] = (phases[-1][0], b)
            else:
                phases.append((a, b))
    return phases


def short_phases(ld, motion: str, end: float, dt: float) -> list[str]:
    """Braking phases shorter than the macro step ``dt`` [s]. A step takes the mean frictional heat
    over its length (``Loading.mean_sliding_factor``), so such a phase's heat is spread over the
    step and its temperatures come out low: a 0.2 s application on the coarse pin-on-disc test
    scene raised the pin by 0.38 K with one 1.6 s step, 1.15 K with 0.2 s steps, 1.25 K with 0.1 s."""
    short = [(a, b) for a, b in braking_phases(ld, motion, end) if b - a < dt * (1 - 1e-9)]
    if not short:
        return []
    a, b = min(short, key=lambda ab: ab[1] - ab[0])
    which = (f"{len(short)} braking phases (loaded and sliding), the shortest from {a:g} to {b:g} s, are"
             if len(short) > 1 else f"the braking phase (loaded and sliding) from {a:g} to {b:g} s is")
    return [f"loading: {which} shorter than the time step time.end / time.steps = {dt:g} s: a step takes the "
            "mean frictional heat over its length, so the phase's heat is spread over the step and its "
            f"temperatures come out too low; give time.steps >= {math.ceil(end / (b - a) - 1e-9)} (a step no "
            "longer than the phase; finer for its peak)"]


RESOLVED = 0.9   # a braking's heat depth below this share of the interface's elements is warned about


def thin_heated_layers(ld, motion: str, end: float, spec, materials, T0: float,
                       size_key: str = "interface_mesh_size") -> list[str]:
    """The fixed body's materials along the interfaces (``spec``: the ``GeometrySpec``) into which
    the heat of the shortest braking phase t reaches less deep, sqrt(pi chi t) at the initial
    temperature ``T0`` [K], than the interface's elements (``GeometrySpec.interface_sizes`` [m]; its
    P1 temperatures) by more than
    ``RESOLVED`` (before: any, "about 99 % of the rise" said; and the disc brake's pads at its
    mesh_size, twice theirs; a user trial). 1-D: a linear element of size h under a flux q holds the heat
    q t in rho c h/2, where the exact surface rise is 2 q sqrt(t/(pi kappa rho c)); it reaches
    sqrt(pi chi t)/h of it. The demo car pad's face rose 34 K at 0.96 s with 4 mm elements, 58 K
    with 2 mm, 103 K by the semi-infinite solid (a user trial). Elements between half the depth and
    the warning's bound still read low: the car pad's first-stop peak 509 °C with 2 mm, 529 °C with
    1.5 mm (a user trial, 2026-12-03; the message says so). ``size_key``: the geometry key that sets
    those elements (the built-in brake's is pad_mesh_size: interface_mesh_size was advised, which
    its builder refuses; a user trial)."""
    phases = braking_phases(ld, motion, end)
    elements = {}                                   # material along an interface -> its largest size
    for n in spec.interfaces:
        name = spec.interface_materials(n)[0]
        elements[name] = max(elements.get(name, 0.0), spec.interface_sizes.get(n, 0.0))
    if not phases:
        return []
    t = min(b - a for a, b in phases)
    out = []
    for name, h in elements.items():
        m = materials.get(name)
        if m is None or m.kappa is None or not h:
            continue
        chi = m.at(T0).diffusivity
        depth = math.sqrt(math.pi * chi * t)
        if depth < RESOLVED * h:
            out.append(f"materials.{name}: the heat of the shortest braking ({t:.3g} s) reaches about sqrt(pi chi t) = "
                       f"{depth * 1e3:.2g} mm into it (chi {chi:.3g} m^2/s), less than the interface's elements "
                       f"({h * 1e3:.3g} mm): its surface temperatures come out low, about {depth / h:.0%} of the rise "
                       f"by the phase's end (1-D, under a constant flux: less before, and less under a falling flux: "
                       f"a user trial's pad read 70 % where this said 85 %); geometry.{size_key} = "
                       f"\"{depth / 2 * 1e3:.2g} mm\" or less resolves them (this warning stops at "
                       f"{depth / RESOLVED * 1e3:.2g} mm, where they still come out a few per cent low)")
    return out


def speed_range(ld, end: float) -> tuple[float, float]:
    """The rotating body's lowest and highest speed [rad/s] over the run to ``end`` [s] (piecewise
    linear between the cycle's knots: the extremes lie at knots or at 0 and ``end``)."""
    speeds = [ld.angular_speed(t) for t in (0.0, end, *(t for t in ld.knots() if 0 < t < end))]
    return min(speeds), max(speeds)


def convection_coverage(boundaries, ld, end: float) -> list[str]:
    """A convection table h [W/(m^2 K)] against the rotating body's speed [rad/s] is held at its
    ends: said where the run's speeds (``speed_range``) leave it."""
    low, high = speed_range(ld, end)
    out = []
    for i, b in enumerate(boundaries, 1):
        if b is None or not isinstance(b.convection, tuple):
            continue
        (x0, h0), (x1, h1) = b.convection[0], b.convection[-1]
        below, above = low < x0, high > x1
        reach = [f"falls to {low:.5g} rad/s"] * below + [f"reaches {high:.5g} rad/s"] * above
        held = [f"{h0:g} W/(m^2 K) below {x0:.5g} rad/s"] * below + [f"{h1:g} W/(m^2 K) above {x1:.5g} rad/s"] * above
        if held:
            out.append(f"boundary[{i}].convection covers {x0:.5g} to {x1:.5g} rad/s of the rotating body's speed, "
                       f"which {' and '.join(reach)} in the run: h is held at {' and at '.join(held)} (extend the "
                       "table)")
    return out


def squeal_state(ld, motion: str, friction: bool) -> list[str]:
    """The squeal analysis linearises one sliding state, the full load at the speed at t = 0: a duty
    cycle's rest is ignored, and at rest the preload has no friction (a speed profile from 0 rpm
    gave 0 unstable modes of the demo brake where 5 rad/s gives 4, silently: an adversarial test)."""
    cycle, start = cycle_keys(ld), speed(ld, motion, 0.0)
    unit = "rad/s" if motion == "rotation" else "m/s"
    out = [f"{', '.join(cycle)}: the squeal analysis is of one state, the full load at the speed at t = 0 "
           f"({start:g} {unit}); the rest of the cycle is ignored"] if cycle else []
    if friction and start == 0.0:
        out.append(f"the squeal analysis is at rest (speed 0 {unit} at t = 0): the preload has no friction, so no "
                   "friction-induced instability can be found; give the speed of the sliding state to analyse")
    return out

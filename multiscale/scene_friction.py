"""Friction across [loading] and [interfaces.<name>] (``multiscale.scene``'s checks): which
interfaces need [loading]'s law and whether any takes it, the fade tables by their keys and their
first points against the initial temperature (their last against the run's: ``workflows``), mu at
the start against a braking torque."""
from __future__ import annotations

from multiscale.curves import interpolate

FRICTION = ("friction", "friction_temperature", "friction_curve", "stribeck")   # [loading]'s laws, one at most


def bare_interfaces(interfaces, names) -> list[str]:
    """Of the interfaces ``names``, those without a friction of their own (``interfaces``: name ->
    InterfaceSettings or None): they take [loading]'s."""
    own = interfaces or {}
    return [n for n in names if getattr(own.get(n), "friction", None) is None
            and getattr(own.get(n), "friction_temperature", None) is None]


def law_problems(path: str, law: list[str], ctx) -> list[str]:
    """The friction keys ``law`` given in table ``path`` ([loading] or [interfaces.<name>]; in
    ``FRICTION`` order): ignored without effect "friction" (a warning in ``ctx``), else a fade table
    needs effect "thermal"."""
    if law and "friction" not in ctx.effects:
        ctx.warnings.append(f'{path}.{law[0]} is ignored: effect "friction" is not in effects')
    elif law[:1] == ["friction_temperature"] and "thermal" not in ctx.effects:
        return [f'{path}.friction_temperature: needs effect "thermal" (its temperatures); give {path}.friction']
    return []


def friction_checks(loading: dict, interfaces, names) -> tuple[list[str], list[str]]:
    """(problems, warnings) of effect "friction" on interfaces ``names``: [loading] (its raw table)
    gives no law while some interface has none of its own; it gives one that every interface
    replaces by its own (unused: a sweep of it would change nothing)."""
    given, bare = [k for k in FRICTION if k in loading], bare_interfaces(interfaces, names)
    if not given and bare:
        return [f'{" or ".join("loading." + k for k in FRICTION)}: missing; effect "friction" needs it'
                + (f" for {', '.join(f'interfaces.{n}' for n in bare)} (the others give their own friction)"
                   if len(bare) < len(names) else "")], []
    if given and not bare and names:
        return [], [f"loading.{given[0]} is unused: every interface gives its own friction (interfaces."
                    f"{', interfaces.'.join(names)})"]
    return [], []


def fade_tables(ld, interfaces, names=None) -> dict[str, tuple]:
    """The fade tables (``friction_temperature``) of the [interfaces.<name>] (``interfaces``: name ->
    InterfaceSettings or None) and of [loading] if an interface of ``names`` takes it (None: not
    known), by their keys."""
    own = {f"interfaces.{n}.friction_temperature": s.friction_temperature for n, s in (interfaces or {}).items()
           if s is not None and s.friction_temperature is not None}
    taken = ld.friction_temperature and (names is None or bare_interfaces(interfaces, names))
    return ({"loading.friction_temperature": ld.friction_temperature} if taken else {}) | own


def fade_coverage(tables: dict[str, tuple], T0: float) -> list[str]:
    """Fade tables (``fade_tables``) held below their first point at the initial temperature T0 [K]
    (their last point against the run's temperatures: ``workflows.run_warnings``, after the run)."""
    return [f"{where}: the initial temperature, {T0 - 273.15:.4g} degC, is below its first point, "
            f"{table[0][0] - 273.15:.4g} degC: mu is held at {table[0][1]:g} below it"
            for where, table in tables.items() if T0 < table[0][0]]


def initial_friction(settings, T0: float) -> float | None:
    """mu [-] at the initial temperature T0 [K] of an interface's settings (``Scene.interface_settings``):
    its constant, else its fade table's; None with [loading]'s mu(v) law (``speed_law_guess``)."""
    if settings.friction is None and settings.friction_temperature is not None:
        return interpolate(settings.friction_temperature, T0)
    return settings.friction


def speed_law_guess(ld) -> float | None:
    """The constant mu [-] standing for [loading]'s mu(v) law (``Loading``) until the law sets each
    facet's (a run's first solve, the squeal preload: ``workflows.model.friction_coefficient``): the
    mean of its static and kinetic mu, or of its curve's; None without one."""
    if ld.stribeck is not None:       # (its kinetic alone, 0, refused a law of mu 0.47-0.52 in a stop: a user trial)
        return 0.5 * (ld.stribeck.static + ld.stribeck.kinetic)
    return sum(mu for _, mu in ld.friction_curve) / len(ld.friction_curve) if ld.friction_curve else None


def torque_problems(scene, names) -> list[str]:
    """A braking torque (or a vehicle's stop) on interfaces ``names`` that all start without friction
    (mu 0 at the initial temperature): no clamp force gives it a friction moment (the run refused it
    only after meshing, ``workflows.model.drive``)."""
    ld, T0 = scene.loading, scene.time.initial_temperature
    if ld.torque is None or not names:
        return []
    mus = [initial_friction(scene.interface_settings(n), T0) for n in names]
    if any(mu is None or mu > 0 for mu in (speed_law_guess(ld) if m is None else m for m in mus)):
        return []            # (a mu(v) law counts with the squeal preload's first guess)
    key = "loading.braking_torque" if ld.braking_torque is not None else "loading.vehicle"
    law = "friction_curve" if ld.friction_curve is not None else "stribeck" if ld.stribeck is not None else None
    if law and all(mu is None for mu in mus):       # (it said "at the initial temperature": a user trial)
        return [f"{key}: braking at {ld.torque:.6g} N m needs friction, but loading.{law} gives mu 0 at every slip "
                "speed: give mu > 0 there"]
    return [f"{key}: braking at {ld.torque:.6g} N m needs friction, but mu is 0 at the initial temperature, "
            f"{T0 - 273.15:.4g} degC, on every interface ({', '.join(names)}): give mu > 0 there "
            "([loading]'s friction or table, or the interfaces' own)"]


def zero_spans(curve) -> str:
    """Where a friction curve (((v [m/s], mu), ...)) gives mu 0: "from 1 m/s up", "up to 2 m/s",
    "from 1 to 5 m/s", "at 3 m/s" (linear between rows, held beyond the ends; it listed the rows: a
    user trial), joined by "and"; "" if nowhere."""
    spans, k = [], 0
    while k < len(curve):
        if curve[k][1] != 0:
            k += 1
            continue
        j = k
        while j + 1 < len(curve) and curve[j + 1][1] == 0:
            j += 1
        a, b = curve[k][0], curve[j][0]
        first, last = k == 0, j == len(curve) - 1
        spans.append("at every slip speed" if first and last else f"from {a:g} m/s up" if last else
                     f"up to {b:g} m/s" if first and b > 0 else f"at {b:g} m/s" if first or j == k else
                     f"from {a:g} to {b:g} m/s")
        k = j + 1
    return " and ".join(spans)


def speed_law_zeros(scene) -> list[str]:
    """A braking torque (or a vehicle's stop) over [loading]'s mu(v) law where it gives mu 0: the run
    stops where the facets slide at those speeds (its first solve, if there: check said OK to a curve
    that was 0 at the stop's starting speed, a review)."""
    ld = scene.loading
    if ld is None or ld.torque is None:
        return []
    if ld.friction_curve is not None:
        where, key = zero_spans(ld.friction_curve), "loading.friction_curve"
    else:
        st = ld.stribeck
        where = "" if st is None or (st.kinetic > 0 and st.static > 0) else \
            "at rest" if st.static == 0 else "at high slip speeds (its kinetic mu)"
        key = "loading.stribeck"
    return [f"{key}: mu is 0 {where}: where the facets slide so, the clamp force that gives the braking torque "
            f"({ld.torque:.6g} N m) grows without bound (the run stops where every facet has mu 0)"] if where else []


def curve_left(curve, fastest: tuple, slowest: tuple, when: str = "") -> list[str]:
    """Warnings of slip speeds in contact beyond ``curve``'s rows (((v [m/s], mu), ...), held at its
    end rows there): ``fastest`` and ``slowest`` are (v [m/s], where: " at t = 2 s" or ""), the
    extremes over the run; a curve left on one side by every speed is said unused (it was said
    as one speed out of range: a user trial). ``when``: what the speeds are of (" at the preload")."""
    (v0, mu0), (v1, mu1) = curve[0], curve[-1]
    if fastest[0] < v0 or slowest[0] > v1:
        side, (v, mu) = ("below its first", (v0, mu0)) if fastest[0] < v0 else ("above its last", (v1, mu1))
        return [f"loading.friction_curve: every slip speed in contact{when} ({slowest[0]:.4g} to {fastest[0]:.4g} "
                f"m/s) is {side} row, {v:.4g} m/s: mu was held at {mu:g} throughout, the curve's slope unused (a "
                "curve over the run's slip speeds says what mu is)"]
    return [f"loading.friction_curve: the slip speed in contact{when} reached {s:.4g} m/s{at}, {side} row, "
            f"{v:.4g} m/s: mu was held at {mu:g} there (a curve over the run's slip speeds says what mu is)"
            for (s, at), beyond, side, (v, mu) in ((fastest, fastest[0] > v1, "above its last", (v1, mu1)),
                                                 (slowest, slowest[0] < v0, "below its first", (v0, mu0))) if beyond]

"""The load warnings of a run: a contact pressure far beyond the small strains of the softer side of
an interface (every model here is linear elastic), and an interface that carried no force while
others did. Read by the transient and multiscale runs from their history (``max_pressure``,
``interface_force_<name>``) and by the squeal analysis from its preloads."""
from __future__ import annotations

from collections.abc import Mapping

from multiscale import io
from multiscale.errors import InputError

STRAINED = 0.02   # a contact pressure above this share of the softer side's E is warned about
UNLOADED = 1e-6   # an interface carrying less than this share of the largest one's force is warned about


def least_E(material, T0: float, T1: float) -> float:
    """The least E [Pa] of ``material`` between the temperatures T0 and T1 [K] (a table is linear
    between its points)."""
    lo, hi = min(T0, T1), max(T0, T1)
    inside = [T for T, _ in material.E if lo < T < hi] if material.tabulated("E") else []
    return min(material.value("E", T) for T in (lo, hi, *inside))


def overloaded(scene, p: float, hottest=None) -> list[str]:
    """The warning if the largest contact pressure ``p`` [Pa] of a run exceeds ``STRAINED`` times
    the least E of the interfaces' materials: a stop with mu 0.02 asked 184 MPa of a 3 GPa pad,
    silently (an adversarial test). E is the least over the temperatures a material saw
    (``hottest``: material -> (its largest temperature [K], body), read with effect "expansion",
    which reads E(T)): a pin softening from 5 GPa to 1 MPa carried 1.0 MPa with no word."""
    if scene.materials is None:
        return []
    T0, spec, hottest = scene.time.initial_temperature, scene.geometry.spec, hottest or {}
    soft = min(least_E(scene.materials[m], T0, hottest[m][0] if m in hottest and scene.has("expansion") else T0)
               for n in spec.interfaces for m in spec.interface_materials(n))
    return [f"the contact pressure reached {p:.3g} Pa, {100 * p / soft:.2g} % of the softer side's E ({soft:.3g} Pa): "
            "beyond the small strains of the linear elastic model; check the load (a vehicle stop asks mu F r of "
            "the brake: a small mu needs a large clamp) and E's unit (a bare number is Pa: 310000 for 310 GPa "
            "is 310 kPa)"] if p > STRAINED * soft else []


def say_at_once(scene, history, comm) -> None:
    """``overloaded`` of the first contact solve's largest pressure and ``unloaded`` of its interface
    forces (``history``'s last record, the start's), said at once on rank 0 (stderr), for a run with
    steps to go: an impossible load (a 20 um pin under 200 N), or a pad left out of the load faces (a
    user trial), was said only after the whole run. The run's warnings say it again, over the run."""
    if comm.rank != 0 or "max_pressure" not in history.columns:
        return
    for line in overloaded(scene, float(history["max_pressure"][-1])) + unloaded(last_forces(scene, history)):
        io.reporter().warn(f"at the first contact solve, {line}; the run goes on (Ctrl-C stops it after a step, "
                           "with its results written)", keep=False)       # (the run's end says it again)


def last_forces(scene, history) -> dict[str, float]:
    """The interfaces' normal forces [N] (magnitudes) of ``history``'s last record."""
    return {n: abs(float(history[f"interface_force_{n}"][-1])) for n in scene.geometry.spec.interfaces
            if f"interface_force_{n}" in history}


def refuse_floating(scene, tm, history) -> None:
    """``idle_holder``'s error at the first contact solve (``history``'s last record; its forces are
    every rank's), raised on every rank: a part held by an unpressed contact alone has a position
    that round-off decides, and its fields with it (the squeal analysis refuses it too)."""
    error = idle_holder(tm.sole_holds, last_forces(scene, history))
    if error is not None:
        raise error


def idle(forces: Mapping[str, float]) -> tuple[dict[str, float], float]:
    """The interfaces whose normal force [N] (``forces``, per interface) stayed below ``UNLOADED``
    times the largest one's, and that largest force: nothing presses them."""
    top = max(forces.values(), default=0.0)
    return {n: f for n, f in forces.items() if top > 0 and f < UNLOADED * top}, top


def unloaded(forces: Mapping[str, float]) -> list[str]:
    """The warnings of the interfaces ``idle`` finds in ``forces`` (their largest normal forces
    [N]; a pad whose load face was put on the disc ran at 7e-12 N beside two loaded pads, silently:
    an adversarial test)."""
    none, top = idle(forces)
    return [f"interface {n} carried no force ({f:.3g} N at most, against {top:.3g} N): nothing presses it; check "
            "loading.faces and the supports" for n, f in none.items()]


def idle_holder(sole_holds: Mapping[str, str], forces: Mapping[str, float]) -> InputError | None:
    """The error if an interface that carried no force (``idle`` of ``forces`` [N]) is the only
    thing that holds some parts (``sole_holds``: interface -> what moves without it, ``held.check_held``): a
    contact that presses nothing holds them by round-off or not at all, so a tangent built there is
    singular or not from run to run (a floating caliper loaded on the piston alone: 2 of 7 runs
    gave a 0 Hz "unstable" mode; a user trial)."""
    none, top = idle(forces)
    for name, f in none.items():
        if name in sole_holds:
            return InputError("interface", name,
                              f"it carried no force ({f:.3g} N, against {top:.3g} N), yet "
                              f"{sole_holds[name]}: unpressed, it holds them by round-off or not at all, and their "
                              "rigid motions would be modes of some runs and not of others; load what presses it "
                              "(loading.faces: a floating caliper takes the fluid pressure on its bore too) or hold "
                              "those parts ([[boundary]] fix)")
    return None

"""A duty cycle's braking applications as a dynamometer reports them, one row each, from a run's
history (``io.History``, its rows as written: a finished, a stopped and a resumed run alike;
``applications.csv`` of the results folder, ``multiscale.outputs.plan``). No DOLFINx.

An application is a heated interval [t0, t1] of the cycle (``scene_cycle.braking_phases``:
loaded and sliding), clipped to the history's last time; one the run stopped inside is
``partial``. Macro step n (rows n - 1 and n, the interval (t_{n-1}, t_n]) belongs to the
applications it overlaps: to one whole (outside them nothing slides under load, so nothing heats
or wears), and a step holding parts of two (a pause shorter than the step) is split between them
by their loaded sliding in it (``scene_cycle.loaded_sliding``: the weight of the model's heat
step and wear, exact at the step's pressure). What a row holds, and how:

- ``energy`` [J]: the frictional work of its steps, ``frictional_work_step``: the model's exact
  per-step increments (each substep at its own pressure and the exact mean of load factor x
  speed, as the heat put in, ``heat_step_<body>`` summed; the trapezoidal rule over rows would miss
  a stop or a release inside a step: a review found 6.7 % too much in a wearing run without heat).
  A history without the column (written before it) takes the heat, or without it the friction
  power over the rows by the trapezoidal rule (``friction_moment`` x ``angular_speed``, or
  ``friction_force`` x ``sliding_speed``): exact where the power is linear between rows.
- ``friction``: the mean friction coefficient, int F_f v dt / int F_n v dt (``friction_force``,
  ``interface_force``, the speed): the time mean of mu = F_f / F_n weighted by normal force x
  speed, each integral by the trapezoidal rule over the rows (the same weights in both: exact for
  a constant mu); NaN if never loaded and sliding at a row.
- ``torque_mean`` [N m] (a rotating body 1): the energy over the angle swept, int omega dt of the
  cycle (exact): the constant torque that does the application's work; ``torque_peak``: the
  largest ``friction_moment`` of its rows.
- ``temperatures`` [K]: each body's largest ``max_temperature_<body>`` over its rows: those in
  [t0, t1] and the end row of its last step (where that step's heat shows; a step shared with the
  next application counts its end row in both).
- ``wear_volume`` [m^3]: the increments of ``wear_volume`` between wear updates (rows with
  ``wear_substeps`` > 0, every row without that column), each update's (the loaded sliding since
  the one before, at one pressure) split between applications as a step is.
- ``interfaces``: with several interfaces, each one's energy (``frictional_heat_step_<name>``),
  mean mu (``friction_force_<name>``, ``interface_force_<name>``), hottest face
  (``face_max_temperature_<name>_on_<body>``) and worn volume (``wear_volume_<name>``), where the
  history has them.
"""
from __future__ import annotations

import csv
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multiscale.outputs import APPLICATIONS
from multiscale.scene_cycle import braking_phases, loaded_sliding, speed

TIME_TOL = 1e-9        # relative to the run's end: row times and the cycle's knots that agree to it are equal
SPEED = {"rotation": "angular_speed", "translation": "sliding_speed"}     # the history's column of body 1's speed
SHOWN = 12             # applications the run's summary lists (the first and last half of them beyond)


@dataclass(frozen=True)
class Interface:
    """One interface's part of an application (a history of several interfaces); None: not in it."""

    energy: float | None            #: J, the frictional heat generated on it
    friction: float                 #: the mean friction coefficient [-]
    temperature: float | None       #: K, the hottest facet of its two faces
    wear_volume: float | None       #: m^3


@dataclass(frozen=True)
class Application:
    """One braking application (module docstring); speeds in rad/s (rotation) or m/s (translation);
    None: not in the run (no torque of a translating body, no wear without effect "wear")."""

    number: int                     #: 1, 2, ... in time
    start: float                    #: s
    end: float                      #: s (the run's last time, if partial)
    partial: bool                   #: the run stopped inside it
    speed_start: float
    speed_end: float
    energy: float                   #: J
    friction: float                 #: mean friction coefficient [-]
    torque_mean: float | None       #: N m
    torque_peak: float | None       #: N m
    temperatures: dict = field(default_factory=dict)    #: body -> its peak temperature [K]
    wear_volume: float | None = None                     #: m^3
    interfaces: dict = field(default_factory=dict)      #: name -> Interface

    @property
    def duration(self) -> float:
        """s"""
        return self.end - self.start


def hottest_columns(columns) -> list[str]:
    """The ``max_temperature_<body>`` columns among ``columns``, one per body (not those of a body's
    materials, ``_in_``, or parts, ``_part_``)."""
    hot = [k for k in columns if k.startswith("max_temperature_")]
    return [k for k in hot if not any(k.startswith(j + s) for j in hot for s in ("_in_", "_part_"))]


def applications(history, ld, motion: str, end: float) -> list[Application]:
    """The applications of the cycle ``ld`` ([loading]; ``motion``: "rotation" or "translation")
    over the run [0, ``end``] [s] that ``history`` reached (module docstring); [] before the first."""
    t = np.asarray(history["time"], float)
    tol = TIME_TOL * max(end, t[-1])
    reached = [(a, b) for a, b in braking_phases(ld, motion, end) if t[-1] > a + tol]
    if len(t) < 2 or not reached:
        return []
    cut = t[-1] < reached[-1][1] - tol                  # the run stopped inside the last one
    phases = [(a, min(b, t[-1])) for a, b in reached]
    weigh = functools.partial(loaded_sliding, ld, motion)
    steps = shares(t[:-1], t[1:], phases, weigh, tol)
    rows = [rows_of(t, a, b, tol) for a, b in phases]
    step, heated = step_energy(history, motion)
    energy = [weighted(part, step) for part in steps]
    v = np.asarray(history[SPEED[motion]], float)
    friction = mean_ratios(steps, t, history["friction_force"], history["interface_force"], v)
    torque = [(e / (ld.mean_angular_speed(a, b) * (b - a)), float(np.max(history["friction_moment"][r])))
              if motion == "rotation" else (None, None) for e, (a, b), r in zip(energy, phases, rows)]
    bodies = sorted(hottest_columns(history))        # (by name: a history read back has its columns so)
    hottest = [{c.removeprefix("max_temperature_"): float(np.max(history[c][r])) for c in bodies} for r in rows]
    wear = worn(history, "wear_volume", phases, weigh, tol)
    parts = [{} for _ in phases]
    for name in sorted(k.removeprefix("interface_force_") for k in history if k.startswith("interface_force_")):
        own = worn(history, f"wear_volume_{name}", phases, weigh, tol)
        for k, part in enumerate(interface_parts(history, name, steps, rows, v, heated, bodies, own)):
            parts[k][name] = part
    return [Application(k + 1, a, b, cut and k == len(phases) - 1, speed(ld, motion, a), speed(ld, motion, b),
                        energy[k], friction[k], *torque[k], hottest[k], wear[k], parts[k])
            for k, (a, b) in enumerate(phases)]


def interface_parts(history, name: str, steps: list, rows: list, v: np.ndarray, heated: bool,
                    bodies: list[str], wear: list) -> list[Interface]:
    """Interface ``name``'s part of each application (``steps``: its ``shares`` of the steps, ``rows``:
    its rows, ``v``: the rows' speeds; ``heated``: the energy is the heat put in; ``bodies``: the
    ``hottest_columns``; ``wear``: its worn volumes)."""
    t, heat = np.asarray(history["time"], float), f"frictional_heat_step_{name}"
    energy = [weighted(part, np.asarray(history[heat])[1:]) if heated and heat in history else None
              for part in steps]
    friction = mean_ratios(steps, t, history[f"friction_force_{name}"], history[f"interface_force_{name}"], v)
    faces = [c for c in (f"face_max_temperature_{name}_on_{b.removeprefix('max_temperature_')}" for b in bodies)
             if c in history]
    return [Interface(energy[k], friction[k], max(float(np.max(history[c][r])) for c in faces) if faces else None,
                      wear[k]) for k, r in enumerate(rows)]


def shares(t0: np.ndarray, t1: np.ndarray, phases, weigh, tol: float) -> list[tuple[slice, np.ndarray]]:
    """Each phase [a, b]'s part of the spans (t0[n], t1[n]] [s] (contiguous, ascending): the slice of
    those it overlaps and its share of each: 1 where it alone overlaps one, else its loaded sliding
    there (``weigh(t0, t1)``) over that of every phase overlapping it (only a phase's first and last
    span can hold another's part)."""
    lo = np.searchsorted(t1, [a + tol for a, _ in phases], side="right")
    hi = np.searchsorted(t0, [b - tol for _, b in phases], side="left")
    count = np.cumsum(np.bincount(lo, minlength=len(t0) + 1) - np.bincount(hi, minlength=len(t0) + 1))
    total, out = np.zeros(len(t0)), []
    for (a, b), first, stop in zip(phases, lo, hi):
        w = np.ones(stop - first)
        for n in {first, stop - 1} if stop > first else ():
            if count[n] > 1:
                w[n - first] = weigh(max(t0[n], a), min(t1[n], b))
                total[n] += w[n - first]
        out.append((slice(first, stop), w))
    for part, w in out:
        shared = count[part] > 1
        w[shared] /= total[part][shared]
    return out


def weighted(part: tuple[slice, np.ndarray], values) -> float:
    """A phase's part (``shares``) of the spans' ``values``."""
    where, w = part
    return float(w @ np.asarray(values, float)[where])


def trapezoids(t: np.ndarray, y) -> np.ndarray:
    """The trapezoidal rule's integral of the rows' ``y`` over each step (t_{n-1}, t_n]."""
    y = np.asarray(y, float)
    return 0.5 * (y[1:] + y[:-1]) * np.diff(t)


def step_energy(history, motion: str) -> tuple[np.ndarray, bool]:
    """Each step's frictional energy [J] and whether it is the frictional heat put in (module
    docstring), not the friction power's trapezoidal rule."""
    if "frictional_work_step" in history:       # each step's own (a release inside a step: a review)
        return np.asarray(history["frictional_work_step"][1:], dtype=float), True
    heat = [k for k in history if k.startswith("heat_step_")]
    put = np.sum([history[k][1:] for k in heat], axis=0) if heat else np.zeros(0)
    if np.any(put):
        return put, True
    force = history["friction_moment"] if motion == "rotation" else history["friction_force"]
    return trapezoids(np.asarray(history["time"], float), force * np.asarray(history[SPEED[motion]])), False


def mean_ratios(steps: list, t: np.ndarray, friction, normal, v: np.ndarray) -> list[float]:
    """Per phase (``steps``: its ``shares`` of the steps) int friction v dt / int normal v dt, each
    by the trapezoidal rule over the rows; NaN where the second is 0."""
    above, below = (trapezoids(t, np.asarray(f, float) * v) for f in (friction, normal))
    return [weighted(part, above) / weighted(part, below) if weighted(part, below) > 0 else math.nan
            for part in steps]


def rows_of(t: np.ndarray, a: float, b: float, tol: float) -> slice:
    """The rows of the application [a, b]: those in it and the end row of its last step."""
    return slice(np.searchsorted(t, a - tol), min(np.searchsorted(t, b - tol) + 1, len(t)))


def worn(history, column: str, phases, weigh, tol: float) -> list:
    """Each phase's part of the increments of the cumulative ``column`` (a worn volume [m^3]) between
    wear updates (module docstring); None each without the column."""
    if column not in history:
        return [None] * len(phases)
    t = np.asarray(history["time"], float)
    updated = np.asarray(history["wear_substeps"]) > 0 if "wear_substeps" in history else np.ones(len(t), bool)
    rows = [0, *(n for n in range(1, len(t)) if updated[n])]
    increments = np.diff(np.asarray(history[column], float)[rows])
    return [weighted(part, increments) for part in shares(t[rows[:-1]], t[rows[1:]], phases, weigh, tol)]


def table(apps: list[Application], motion: str) -> tuple[list[str], list[list]]:
    """The header of ``applications.csv`` (units in the names: SI) and its rows, from ``apps`` (not
    empty; one history's: the same parts in each)."""
    unit = "rad_per_s" if motion == "rotation" else "m_per_s"
    first = apps[0]
    columns = [("application", lambda a: a.number), ("start_s", lambda a: a.start), ("end_s", lambda a: a.end),
               ("duration_s", lambda a: a.duration), ("partial", lambda a: int(a.partial)),
               (f"speed_start_{unit}", lambda a: a.speed_start), (f"speed_end_{unit}", lambda a: a.speed_end),
               ("energy_J", lambda a: a.energy), ("mean_friction_coefficient", lambda a: a.friction)]
    if first.torque_mean is not None:
        columns += [("mean_torque_N_m", lambda a: a.torque_mean), ("peak_torque_N_m", lambda a: a.torque_peak)]
    columns += [(f"peak_temperature_{b}_K", lambda a, b=b: a.temperatures[b]) for b in first.temperatures]
    columns += [("wear_volume_m3", lambda a: a.wear_volume)] if first.wear_volume is not None else []
    for name, part in first.interfaces.items():
        own = [("energy_{}_J", "energy"), ("mean_friction_coefficient_{}", "friction"),
               ("peak_face_temperature_{}_K", "temperature"), ("wear_volume_{}_m3", "wear_volume")]
        columns += [(label.format(name), lambda a, n=name, key=key: getattr(a.interfaces[n], key))
                    for label, key in own if getattr(part, key) is not None]
    return [c for c, _ in columns], [[get(a) for _, get in columns] for a in apps]


def write_csv(apps: list[Application], motion: str, path: Path) -> Path:
    """``applications.csv`` (``table``) at ``path``: numbers to 10 significant digits, a NaN empty."""
    header, rows = table(apps, motion)
    with Path(path).open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows([[v if isinstance(v, int) else "" if math.isnan(v) else f"{v:.10g}" for v in row]
                     for row in rows])
    return Path(path)


def summary(apps: list[Application], motion: str) -> list[str]:
    """The run's summary lines of ``apps`` (not empty; temperatures in degC, wear in mm^3): a table of
    up to ``SHOWN`` applications, the first and last ones of more."""
    shown = apps if len(apps) <= SHOWN else apps[:SHOWN // 2] + apps[-(SHOWN // 2):]
    first = apps[0]
    columns = [("#", [f"{a.number}{'*' if a.partial else ''}" for a in shown]),
               ("start-end [s]", [f"{a.start:.4g}-{a.end:.4g}" for a in shown]),
               (f"speed [{'rad/s' if motion == 'rotation' else 'm/s'}]",
                [f"{a.speed_start:.4g} -> {a.speed_end:.4g}" for a in shown]),
               ("energy [J]", [f"{a.energy:.4g}" for a in shown]), ("mean mu", [f"{a.friction:.3f}" for a in shown])]
    if first.torque_mean is not None:
        columns.append(("torque mean/peak [N m]", [f"{a.torque_mean:.4g} / {a.torque_peak:.4g}" for a in shown]))
    columns += [(f"{b} [degC]", [f"{a.temperatures[b] - 273.15:.4g}" for a in shown]) for b in first.temperatures]
    if first.wear_volume is not None:
        columns.append(("wear [mm^3]", [f"{a.wear_volume * 1e9:.4g}" for a in shown]))
    widths = [max(len(head), *map(len, cells)) for head, cells in columns]
    rows = [[head for head, _ in columns]] + [list(row) for row in zip(*(cells for _, cells in columns))]
    lines = ["    " + "  ".join(cell.rjust(w) for cell, w in zip(row, widths)) for row in rows]
    if len(apps) > SHOWN:
        lines.insert(1 + SHOWN // 2, f"    ... {len(apps) - SHOWN} more")
    return [f"  applications ({APPLICATIONS}):", *lines] + \
        (["    * partial: the run stopped inside it"] if any(a.partial for a in apps) else [])

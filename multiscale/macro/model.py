"""A macro model: mechanics, an optional heat problem, the drive, and the sequential step of thesis
Fig. 7.4.

``MacroModel.macro_step`` advances one macro step Δt in ``substeps`` times {heat step over δt with
the current contact state; contact solve with the new temperatures (thermal expansion) or the new
load}. The drive gives the load and the speed of the sliding body against time: while the load
factor is 0 the contact is released (no solve, no frictional heat, no interface conductance) and
the bodies only exchange heat with their surroundings. The sliding direction does not depend on the
speed's magnitude, so a changing speed needs no contact solve (only its heat changes: a heat step
takes the mean of the speeds at its ends, exact for a speed linear in time); a step sliding from
rest solves with friction before its heat step (``start_sliding``). ``start``
makes the first (ramped) contact solve; ``record`` gives one history row. The model is built from
plain objects (``multiscale.workflows.model.build_model`` makes one from a scene).
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable

import numpy as np

from multiscale.outputs import step_time
from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.macro.friction import FacetFriction
from multiscale.macro.load_faces import clamp_imbalance, load_face_forces
from multiscale.macro.mechanics import Mechanics, SolveResult
from multiscale.macro.mesh import TwoBodyMesh
from multiscale.macro.preload import hold_moment
from multiscale.macro.probes import Probes
from multiscale.macro.thermal import Thermal


CARRIED = 0.01       # the first solve's contact must carry this share of a force or pressure load at least


@dataclass(frozen=True)
class Drive:
    """What drives the sliding contact: the normal load and the sliding speed of body 1.

    ``load``: N (mechanics ``load_kind="force"``) or Pa (pressure or fluid pressure), reached in
    ``ramp_steps`` increments by the first solve, times ``factor(t)`` (0: released); ``speed(t)``:
    rad/s (rotation) or m/s (translation) at time t [s]. With ``torque`` [N m] the load is a first
    guess: after every solve while sliding it is scaled so that the friction moment about the
    rotation axis is the torque times the load factor (the brake delivers what the vehicle needs,
    whatever the pressure distribution and its drift by thermal expansion).
    """

    load: float
    speed: Callable[[float], float]
    ramp_steps: int = 1
    factor: Callable[[float], float] = lambda t: 1.0
    mean_factor: Callable[[float, float], float] = lambda t0, t1: 1.0   # mean of factor over [t0, t1]
    steady: bool = True              # the speed never changes
    torque: float | None = None      # N m, braking torque the friction must give
    # with a changing speed (not ``steady``): the exact means over [t0, t1] of speed(t) and of
    # factor(t) speed(t) (``scene_sections.Loading.mean_angular_speed``, ``mean_sliding_factor``)
    speed_mean: Callable[[float, float], float] | None = None
    sliding_mean: Callable[[float, float], float] | None = None

    def mean_speed(self, t0: float, t1: float) -> float:
        """Mean sliding speed over [t0, t1] (rad/s or m/s)."""
        return self.speed(t0) if self.steady else self.speed_mean(t0, t1)

    def mean_sliding(self, t0: float, t1: float) -> float:
        """Mean of factor(t) speed(t) over [t0, t1]: frictional heat and wear go with it."""
        return self.mean_factor(t0, t1) * self.speed(t0) if self.steady else self.sliding_mean(t0, t1)


@dataclass
class MacroModel:
    """Mechanics, heat problem (None without heat) and drive of one macro run."""

    tm: TwoBodyMesh
    mechanics: Mechanics
    thermal: Thermal | None
    drive: Drive
    time: float = 0.0                                  # s
    heat_total: np.ndarray = field(default_factory=lambda: np.zeros(2))   # J, frictional heat in
    # J, frictional heat generated on each interface (``tm.interface.tags``, into both bodies): the last step's
    # and since the start
    interface_heat: np.ndarray = field(init=False)
    interface_heat_total: np.ndarray = field(init=False)
    heat_lost_recorded: np.ndarray = field(default_factory=lambda: np.zeros(2))   # J, lost at the last record
    heat_exchanged: float = 0.0                        # J, body 0 -> body 1 through the conductance, last step
    heat_exchanged_total: float = 0.0                  # J, since the start
    work_step: float = 0.0                             # J, frictional work of the last step (the heat's quadrature)
    last_solve: SolveResult | None = None
    solved_speed: float = 0.0                          # the speed of the last contact solve (friction on if > 0)
    load: float | None = None                          # N or Pa at factor 1 (the drive's, or scaled to its torque)
    partitions: dict = field(default_factory=dict)     # share of frictional heat into body 0 per interface [-]
    # mu per interface facet against the facets' temperatures [K] and slip speeds [m/s] (``friction.FacetFriction``):
    # set after every heat step (fade) and, with a mu(v) law, at the speed of every contact solve
    friction_law: FacetFriction | None = None
    # a heat step changed mu (a friction_law) or the thermal strain since the last contact solve: a loaded
    # substep solves after its heat step, and a loaded slide first (the first step of a stop after a dwell)
    stale: bool = False
    notes: list = field(default_factory=list)          # what the run's warnings add (an unbalanced clamp, Mechanics.notes)
    probes: Probes | None = None                       # thermocouples: ``probe_temperature_<name>`` columns
    # what the facets' wear sums since its last update (a ``facet_wear.Exposure``, which ``FacetWear`` sets; None:
    # not summed): each loaded substep's work and load per facet, rated at its faces' temperatures
    exposure: object | None = None

    @property
    def contact(self):
        return self.mechanics.contact

    def __post_init__(self):
        self.interface_heat, self.interface_heat_total = np.zeros((2, len(self.tm.interface.tags)))

    def close(self) -> None:
        """Destroy the PETSc objects of the mechanics, then of the heat problem (collective: call it
        on every rank; ``Mechanics.close``). The fields stay readable; nothing can be solved after.
        A model not closed is never freed (docs/architecture.md §7)."""
        self.mechanics.close()
        if self.thermal is not None:
            self.thermal.close()

    @property
    def problems(self) -> tuple[str, ...]:
        return ("mechanics",) + (("heat",) if self.thermal is not None else ())

    def speed(self, t: float) -> float:
        """Sliding speed of body 1 at time t: rad/s (rotation) or m/s (translation)."""
        return self.drive.speed(t)

    @property
    def released(self) -> bool:
        """True while the load factor is 0 (no contact)."""
        return self.contact.engaged.value == 0.0

    def start(self) -> SolveResult:
        """First contact solve from rest with the drive's load ramp (at the initial load factor;
        a start in a released phase solves at the full load, factor 1, then releases); with a
        torque, the load is scaled to it and solved again (from rest: once sliding starts)."""
        self.contact.speed.value = self.speed(0.0)
        self.update_friction(self.speed(0.0))
        self.load = self.drive.load
        factor = self.drive.factor(0.0) or 1.0
        self.last_solve = self.mechanics.ramp(self.load * factor, self.drive.ramp_steps)
        self.keep_torque(factor)
        self.contact.engaged.value = float(self.drive.factor(0.0) > 0)
        self.solved_speed = float(self.contact.speed.value)
        mech = self.mechanics
        # the sum of the faces' resultants' magnitudes (a fluid's on facing faces do not cancel)
        applied = sum(load_face_forces(self.tm, float(mech.load.value), mech.load_kind).values())
        carried = self.last_solve.normal_force
        if not applied > 0 or carried < CARRIED * applied:
            raise InputError("loading.faces", list(self.tm.spec.load_faces),
                             f"the contact carries {carried:.3g} N of the {applied:.3g} N applied: a support "
                             "takes the load (load a face of a body that the supports leave free to move "
                             "towards the contact; loading.direction along the contact normal; a pressure "
                             "normal to a face whose normals cancel, a cylinder's wall, has no resultant)")
        clamp = clamp_imbalance(self.tm, float(mech.load.value)) if mech.load_kind == "fluid" else None
        self.notes = [*self.tm.notes, *mech.notes, *([clamp] if clamp is not None else [])]
        return self.last_solve

    @cached_property
    def facet_reach(self) -> np.ndarray:
        """|w| per interface facet (global) at unit speed of body 1 [m per rad: its distance from the
        axis of a rotation; 1 for a translation]."""
        return np.linalg.norm(self.tm.spec.motion.velocity(self.tm.interface.midpoints), axis=1)

    def face_temperatures(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(T_0, T_1) per interface facet [K], the mean temperatures of body 0's and body 1's faces;
        None without heat."""
        return None if self.thermal is None else (self.thermal.facet_temperature(0), self.thermal.facet_temperature(1))

    def macro_step(self, dt: float, substeps: int = 1) -> np.ndarray:
        """Advance by one macro step dt [s] in ``substeps`` (Fig. 7.4); returns the heat [J] put
        into each body during the step. ``work_step`` [J] is the step's frictional work mu ∫ p |w| dA
        dt summed as the heat is: each substep's pressure at its start over its load-weighted sliding
        (before, the multiscale loop took the pressure at the step's end: a one-step vehicle stop
        worked 0.5 % more than the heat it put in). The time after the step is rounded to 12
        significant digits (``outputs.step_time``): output times are exact decimals, not sums of
        rounded steps."""
        heat, self.heat_exchanged, self.work_step = np.zeros(2), 0.0, 0.0
        facet_heat = np.zeros(self.tm.interface.n_facets)        # J, into both bodies
        delta, start = dt / substeps, self.time
        for k in range(substeps):
            t0, t1 = self.time, self.time + delta
            speed = self.drive.mean_speed(t0, t1)   # the mean speed of the step (transport, convection)
            self.contact.speed.value = speed
            # from rest, or ``stale`` (through a release under fade the first loaded step heated with the
            # pressure of before the dwell and the new mu: 2.6 % above the torque's work on a test pin-on-disc)
            if speed and (self.solved_speed == 0.0 or self.stale) and self.drive.mean_sliding(t0, t1):
                self.start_sliding(speed, float(self.mechanics.load.value) / self.load)
            # the frictional work of the substep with the pressure and the sliding its heat step takes
            slid = self.sliding(t0, t1)
            if slid:                                # (at rest or released: no work, no assembly)
                power = self.facet_sliding_power()
                self.work_step += power.sum() * slid
                if self.exposure is not None:       # (p |w| dA as the work integrates it; where mu = 0, at the midpoint)
                    mu = self.tm.interface.values(self.contact.friction)
                    load = np.divide(power, mu, out=np.zeros(mu.shape), where=mu > 0)
                    if not (mu > 0).all():          # (an assembly: only where a facet has no friction)
                        load = np.where(mu > 0, load, self.contact.facet_pressure() * self.tm.interface.areas
                                        * self.facet_reach)
                    self.exposure.add(slid * power, slid * load, slid * float(self.mechanics.load.value),
                                      self.face_temperatures())
            if self.thermal is not None:
                # the pressure was solved at the load factor of the step's start: the conductance
                # scales with the mean factor over the step (a release inside it, a load ramp), the
                # frictional heat with the mean of factor x speed (exact for a stop inside the step)
                solved = float(self.mechanics.load.value)
                scale = self.load / solved if solved > 0 else 0.0
                self.contact.engaged.value = self.drive.mean_factor(t0, t1) * scale
                self.contact.heating.value = self.drive.mean_sliding(t0, t1) / speed * scale if speed else 0.0
                done = self.thermal.step(delta)
                if slid and self.exposure is not None:      # (the substep's end: its rates' mean)
                    self.exposure.end(self.face_temperatures())
                # (kept if set before: a reload after a dwell of two steps skipped its solve, 27 % off: a review)
                self.stale = self.update_friction() or self.stale or self.mechanics.temperatures is not None
                heat += done.heat_in
                facet_heat += done.facet_heat.sum(axis=1)
                self.heat_exchanged += done.heat_exchanged
            self.time = step_time(start, dt) if k == substeps - 1 else start + (k + 1) * delta
            self.contact.speed.value = self.speed(self.time)
            factor = self.drive.factor(self.time)
            self.contact.engaged.value = self.contact.heating.value = float(factor > 0)
            load = self.load * factor
            # friction acts while sliding: a start or a stop changes it; a stop inside the macro step
            # keeps the friction of the sliding that ended it (the pressure the step's wear and work take)
            speed = float(self.contact.speed.value)
            moving = speed or self.drive.mean_speed(start, start + (k + 1) * delta)
            if factor > 0:                # mu(v) at the speed of the solve; released, it stays the last solve's
                self.stale = self.update_friction(moving) or self.stale   # (what restore and resume rebuild)
            if factor > 0 and (self.stale or load != self.mechanics.load.value
                               or (moving == 0.0) != (self.solved_speed == 0.0)):
                self.contact.speed.value = moving
                self.last_solve = self.mechanics.solve(load)
                self.solved_speed, self.stale = moving, False
                self.keep_torque(factor)
                self.contact.speed.value = speed
        self.heat_total += heat
        iface = self.tm.interface
        self.interface_heat = np.bincount(iface.tag_index, facet_heat, minlength=len(iface.tags))
        self.interface_heat_total += self.interface_heat
        self.heat_exchanged_total += self.heat_exchanged
        return heat

    def update_friction(self, speed: float | None = None) -> bool:
        """With a ``friction_law``: each interface facet's mu at the mean of its two faces' temperatures
        and (a mu(v) law) its slip speed at the sliding ``speed`` of the next solve (rad/s or m/s; None:
        that of the last, ``solved_speed``), for the solve and the heat steps that follow (explicit in
        the temperatures: those of the step's end); with a ``speed``, only if the law reads it.
        Returns whether mu changed (collective)."""
        law = self.friction_law
        if law is None or (speed is not None and not law.reads_speed):
            return False
        T = None if self.thermal is None else \
            0.5 * (self.thermal.facet_temperature(0) + self.thermal.facet_temperature(1))
        V = None
        if law.reads_speed:
            now = float(self.contact.speed.value)
            self.contact.speed.value = self.solved_speed if speed is None else speed
            V = self.contact.facet_means("slip")
            self.contact.speed.value = now
        mu = law(T, V)
        changed = not np.array_equal(mu, self.tm.interface.values(self.contact.friction))
        if changed:
            self.tm.interface.set_field(self.contact.friction, mu)
        return changed

    def start_sliding(self, speed: float, factor: float) -> None:
        """Solve the contact with friction at the sliding ``speed`` (rad/s or m/s; its sign the
        direction) and the load last solved (at load ``factor``), before a heat step that slides from
        rest, also one that starts released and engages inside it: the step heats with the
        frictional pressure (before, with the frictionless one of the solve at rest: the test
        pin-on-disc restarting from a stop, 0 to 200 rpm over a 0.6 s step, 1.24e-3 off in the
        step's heat; a start released at rest, engaging within 10 ms, as much)."""
        self.update_friction(speed)
        self.last_solve = self.mechanics.solve()
        self.solved_speed, self.stale = speed, False
        self.keep_torque(factor)

    def keep_torque(self, factor: float) -> None:
        """With the drive's torque and while sliding: scale the load until the friction moment is
        the torque times ``factor`` (``preload.hold_moment``; before, scaled once at the start, the
        moment of a car stop with thermal expansion drifted 2.5 % above the torque and the work
        0.95 % above the kinetic energy)."""
        load, solved = hold_moment(self.mechanics, self.load * factor, (self.drive.torque or 0.0) * factor)
        if solved is not None:                   # (only with a positive target: factor > 0)
            self.load, self.last_solve = load / factor, solved

    def interface_heat_row(self, masks: dict) -> dict:
        """Per interface (``masks``: its facets): the frictional heat generated on it [J] in the last
        step and since the start (into both bodies: the interfaces' sum is the bodies'
        ``heat_step_<body>`` and ``heat_total_<body>``), and on each body's face of it the largest
        facet-mean temperature and the area-weighted mean temperature [K] (``Thermal.facet_temperature``:
        global arrays, the same on every rank)."""
        row, areas = {}, self.tm.interface.areas
        faces = [self.thermal.facet_temperature(side) for side in (0, 1)]
        for k, (name, m) in enumerate(masks.items()):
            row[f"frictional_heat_step_{name}"] = float(self.interface_heat[k])
            row[f"frictional_heat_total_{name}"] = float(self.interface_heat_total[k])
            for body, T in zip(self.tm.bodies, faces):
                row[f"face_max_temperature_{name}_on_{body.name}"] = float(T[m].max())
                row[f"face_mean_temperature_{name}_on_{body.name}"] = float(T[m] @ areas[m] / areas[m].sum())
        return row

    def sliding(self, t0: float, t1: float) -> float:
        """Sliding of body 1 over [t0, t1] weighted by the load (rad or m): the integral of
        factor(t) speed(t) over the factor of the pressure last solved, so that the frictional work
        or wear of that pressure field over it is the interval's (0 while released)."""
        solved = float(self.mechanics.load.value)
        return self.drive.mean_sliding(t0, t1) * (t1 - t0) * self.load / solved if solved > 0 and t1 > t0 else 0.0

    def sliding_power(self) -> float:
        """mu ∫ p |w| dA [W] of the last solved pressure at unit speed of body 1 (per rad/s or m/s)."""
        return float(self.facet_sliding_power().sum())

    def facet_sliding_power(self) -> np.ndarray:
        """mu p |w| dA [W] per interface facet of the last solved pressure at unit speed of body 1,
        whatever the speed and the load factor now (at rest or released the heat flux is 0)."""
        c = self.contact
        kept = float(c.speed.value), float(c.heating.value)     # copies: .value is a view of the Constant
        c.speed.value, c.heating.value = 1.0, 1.0
        try:
            return c.facet_heat_flux() * self.tm.interface.areas
        finally:
            c.speed.value, c.heating.value = kept

    # ---- state (a fixed point restarts a step from it; checkpoints store it) ----------------
    @property
    def functions(self) -> dict:
        """The fields by checkpoint name: displacements u0, u1 [m], temperatures T0, T1 [K]."""
        return {**{f"u{i}": u for i, u in enumerate(self.mechanics.u)},
                **({f"T{i}": T for i, T in enumerate(self.thermal.T)} if self.thermal is not None else {})}

    @property
    def drive_constants(self) -> list:
        """The contact's speed, engagement and heating constants and the mechanics' load."""
        return [*(getattr(self.contact, k) for k in ("speed", "engaged", "heating")), self.mechanics.load]

    def snapshot(self) -> tuple[dict, dict, list]:
        """The state a step starts from, in memory (a pass of a fixed point that solved at a start or
        a stop is undone): ``checkpoint_state`` and the values of the ``functions``."""
        attrs, arrays = self.checkpoint_state()
        return attrs, {k: v.copy() for k, v in arrays.items()}, [f.x.array.copy() for f in self.functions.values()]

    def restore(self, state: tuple[dict, dict, list]) -> None:
        """Back to a ``snapshot``."""
        attrs, arrays, values = state
        for f, array in zip(self.functions.values(), values):
            f.x.array[:] = array
        self.restore_checkpoint(attrs, arrays)

    def checkpoint_state(self) -> tuple[dict, dict]:
        """(attributes, arrays) of the state a checkpoint keeps beside the ``functions``: time, heat
        counters, drive constants, the load and speed of the last solve, its statistics and the
        warnings said so far (``restore_checkpoint`` reads them back)."""
        last, thermal = self.last_solve, self.thermal
        arrays = {"heat_total": self.heat_total, "interface_heat_total": self.interface_heat_total,
                  "heat_lost_recorded": self.heat_lost_recorded,
                  **({"lost_total": thermal.lost_total} if thermal is not None else {})}
        attrs = {"time": self.time, "heat_exchanged": [self.heat_exchanged, self.heat_exchanged_total],
                 "load": self.load, "solved_speed": self.solved_speed, "stale": self.stale,
                 "constants": [float(c.value) for c in self.drive_constants],
                 "solve": [last.reason, last.iterations, last.normal_force, last.max_pressure],
                 "notes": json.dumps([self.notes, thermal.notes if thermal is not None else []])}   # said once a run
        return attrs, arrays

    def restore_checkpoint(self, attrs: dict, arrays: dict) -> None:
        """Back to a ``checkpoint_state`` (the ``functions`` restored by the caller); mu at the
        temperatures and the speed last solved. The run's warnings before are not said again."""
        self.heat_exchanged, self.heat_exchanged_total = (float(v) for v in attrs["heat_exchanged"])
        self.heat_total, self.interface_heat_total = arrays["heat_total"].copy(), arrays["interface_heat_total"].copy()
        self.heat_lost_recorded = arrays["heat_lost_recorded"].copy()
        self.time = float(attrs["time"])
        if self.thermal is not None:
            self.thermal.lost_total, self.thermal.time = arrays["lost_total"].copy(), self.time
        for holder, said in zip((self, self.thermal), json.loads(attrs["notes"])):
            if holder is not None:
                holder.notes = said + [n for n in holder.notes if n not in said]
        reason, its, force, max_p = attrs["solve"]
        self.last_solve = SolveResult(True, int(reason), int(its), [], float(force), float(max_p))
        self.load, self.solved_speed = float(attrs["load"]), float(attrs["solved_speed"])
        self.stale = bool(attrs["stale"])
        for c, value in zip(self.drive_constants, attrs["constants"]):   # speed, engagement, load last solved
            c.value = value
        self.update_friction()                  # fade and mu(v): at the temperatures and the speed last solved

    def record(self, heat_step=(0.0, 0.0)) -> dict:
        """One history row at the current state (units: see ``multiscale.io.UNITS``). With thermal
        boundary conditions, ``heat_lost_step_<body>`` is the heat lost since the previous record.
        ``friction_force`` (in all and per interface) sums the friction forces' magnitudes over the
        facets, mu times the normal force where all slides (less by the turn of the sliding direction
        across a facet of a rotating body: 2.5e-5 on the car brake): opposite pads do not cancel;
        ``friction_moment`` [N m], with a rotating body 1, is the magnitude of their moment about its axis. With several
        interfaces and heat, ``interface_heat_row`` gives each one's heat and face temperatures. With a
        ``friction_law``, ``friction_coefficient`` [-] is ``friction_force`` over ``interface_force`` (NaN
        while released or at rest), and with several interfaces each one's too; with a mu(v) law,
        ``max_slip_speed`` and ``min_slip_speed`` [m/s] over its facets in contact (NaN as mu).
        ``frictional_work_step`` [J]: the last step's frictional work (``work_step``, the heat's quadrature).
        ``angular_speed`` [rad/s] of a rotating body 1 or ``sliding_speed`` [m/s] of a translating one,
        at the row's time (a cycle's speed was drawn nowhere: a user trial). With ``probes``,
        ``probe_temperature_<name>`` [K], each thermocouple's reading (``macro.probes``)."""
        on = not self.released
        friction = np.linalg.norm(self.contact.facet_friction(), axis=1) * on     # N per facet, magnitudes
        row = {"time": self.time, "interface_force": self.last_solve.normal_force * on,
               "friction_force": float(friction.sum()), "frictional_work_step": self.work_step,
               "max_pressure": self.last_solve.max_pressure * on,
               "newton_iterations": self.last_solve.iterations}
        moving = float(self.contact.speed.value)          # (now: a stop inside the step solved at its speed)

        def ratio(force: float, normal: float) -> float:  # mu as a dynamometer reads it; NaN at rest or released
            return force / normal if normal > 0 and moving else np.nan
        if self.friction_law is not None:               # fade: the friction over the normal force
            row["friction_coefficient"] = ratio(row["friction_force"], row["interface_force"])
        if self.friction_law is not None and self.friction_law.reads_speed:    # the slip speeds mu(v) read
            V = []                      # (assembled only while loaded and sliding)
            if on and moving:
                read = np.logical_or.reduce([m for m, _ in self.friction_law.speeds])
                V = self.contact.facet_means("slip")[read & (self.contact.facet_pressure() > 0)]
            row["max_slip_speed"], row["min_slip_speed"] = (float(V.max()), float(V.min())) if len(V) else (np.nan,) * 2
        if isinstance(self.tm.spec.motion, Rotation):   # the braking torque: frictional heat power = it x omega
            row["friction_moment"] = abs(self.contact.friction_moment()) * on
            row["angular_speed"] = self.speed(self.time)
        else:
            row["sliding_speed"] = self.speed(self.time)
        masks = self.tm.interface.masks()
        if len(masks) > 1:                        # per interface (a brake's pads, a disc's pucks)
            p = self.contact.facet_pressure() * on
            for name, m in masks.items():
                row[f"interface_force_{name}"] = float(p[m] @ self.tm.interface.areas[m])
                row[f"friction_force_{name}"] = float(friction[m].sum())
                row[f"max_pressure_{name}"] = float(p[m].max(initial=0.0))
                if self.friction_law is not None:       # each pad's own (its own table, its temperatures)
                    row[f"friction_coefficient_{name}"] = ratio(row[f"friction_force_{name}"],
                                                                row[f"interface_force_{name}"])
            if self.thermal is not None:
                row.update(self.interface_heat_row(masks))
        if self.thermal is not None:
            stored, hottest, coldest = self.thermal.stored_heat(), self.thermal.max_temperature(), \
                self.thermal.min_temperature()
            for i, body in enumerate(self.tm.bodies):
                row[f"max_temperature_{body.name}"] = hottest[i]
                if len({r.material for r in body.spec.regions}) > 1:     # per material (their tables)
                    for material, T in self.thermal.region_temperature(i).items():
                        row[f"max_temperature_{body.name}_in_{material}"] = T
                    for material, T in self.thermal.region_temperature(i, lowest=True).items():
                        row[f"min_temperature_{body.name}_in_{material}"] = T
                if len(body.spec.regions) > 1:                          # per part (a brake's pads)
                    for part, T in self.thermal.region_temperature(i, "name").items():
                        row[f"max_temperature_{body.name}_part_{part}"] = T
                    for part, Q in self.thermal.region_stored_heat(i).items():
                        row[f"stored_heat_{body.name}_part_{part}"] = Q
                row[f"min_temperature_{body.name}"] = coldest[i]
                row[f"heat_step_{body.name}"] = heat_step[i]
                row[f"heat_total_{body.name}"] = self.heat_total[i]
                row[f"stored_heat_{body.name}"] = stored[i]
            if self.probes is not None:
                row.update({f"probe_temperature_{name}": T for name, T in self.probes.temperatures().items()})
            if self.thermal.conductance:      # conducted through the interface conductance (body 0 -> 1)
                row.update(heat_exchanged_step=self.heat_exchanged, heat_exchanged_total=self.heat_exchanged_total)
                for i, body in enumerate(self.tm.bodies):       # each body's, by name (history.png draws it)
                    row[f"heat_conducted_total_{body.name}"] = (2 * i - 1) * self.heat_exchanged_total
            if self.thermal.boundaries:       # heat lost through convection, radiation, fixed temperatures
                lost = self.thermal.heat_lost
                for i, body in enumerate(self.tm.bodies):
                    row[f"heat_lost_step_{body.name}"] = lost[i] - self.heat_lost_recorded[i]
                    row[f"heat_lost_total_{body.name}"] = lost[i]
                self.heat_lost_recorded = lost.copy()
        return row

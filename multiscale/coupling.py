"""The multiscale loop: a macro model whose rough interface carries per-zone laws, the micro
post-analysis of the zones, wear and checkpoints (thesis §1.4–1.5, ch. 7, Figs. 7.2–7.5).

One macro step Δt (Fig. 7.2) runs:

1. the macro transient over Δt in ``substeps`` thermo-mechanical sub-steps δt with the current
   laws and partitions (Fig. 7.4; ``macro.model.MacroModel.macro_step``);
2. per zone, the macro loading at the end of the step (``loading``): zone pressure P = (contact
   force on the zone's facets) / (zone area) — so that the micro patch carries the macro force —,
   the facet temperatures of both bodies, the sliding speed and direction at the zone centre;
3. the micro post-analysis of the loaded zones (Fig. 7.5, ``micro.post_analysis``): local pressure
   under P, local surface temperature and partition (steady sliding heating, both bodies' remote
   temperatures at the rough body's macro surface temperature: the macro field already holds the
   zone-scale heating, and feeding the macro temperature difference of the two surfaces back into
   the micro partition double counts it and makes the explicit coupling oscillate), and, every
   ``wear_every`` steps, the Archard wear of the patch over the sliding of those steps with k_w(T);
   the zones are spread over the MPI ranks and the worn topographies shared;
4. the laws of the zones whose topography changed are recomputed (``rough.RoughInterface``: the
   others come from the pool's cache), the facet laws updated and the mechanics re-solved at the
   same time: the macro temperature field carries over to the next step unchanged.

The initial laws are computed before the first solve; the rigid datum gap starts Newton close to
equilibrium. The partitions of step n + 1 come from the heating of step n's post-analysis
(explicit coupling). ``save``/``restore`` write and read the whole state (``checkpoint``), so that
a killed run continues to the same history (to solver tolerance: a resumed run recomputes its
zone laws). This module reads no scene: ``multiscale.workflows.multiscale`` builds and runs it.
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from multiscale import checkpoint, io
from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.macro.mechanics import SolveResult
from multiscale.macro.model import MacroModel
from multiscale.micro.post_analysis import PostAnalysis
from multiscale.rough import RoughInterface

LOADED = 1e-9              # zones below this fraction of the nominal pressure are unloaded


@dataclass(frozen=True)
class LoopSettings:
    """Time and update rules of the loop."""

    dt: float                     # s, macro step
    substeps: int                 # thermo-mechanical sub-steps per macro step
    initial_temperature: float    # K, also the temperature of zones without a heat problem
    partition: float              # share of the frictional heat into the rough body until the first heating (NaN: none)
    partition_law: bool = False   # micro partition per zone (ch. 6) instead of the constant
    wear: bool = False            # Archard wear of the zones
    wear_every: int = 1           # macro steps per wear update
    flash_softening: bool = False  # H(T) of each zone at its last micro flash temperature (plasticity)
    forces: dict = field(default_factory=dict)   # N, per interface: the load it nominally carries
    friction: np.ndarray | None = None            # mu of every zone (its interface's; None: the post-analysis')


@dataclass
class ZoneLoading:
    """Macro loading of every zone at the current state (arrays over zone ids)."""

    force: np.ndarray          # N, contact force on the zone's facets
    pressure: np.ndarray       # Pa, force / zone area
    speed: np.ndarray          # m/s, sliding speed of the counter-face at the zone centre
    angle: np.ndarray          # rad, its direction in the interface plane (from +x)
    temperature: np.ndarray    # K, (Z, 2): facet-mean surface temperatures (counter-face, rough body)


@dataclass
class MicroStep:
    """What one post-analysis did (scalars for the history)."""

    loaded: int                # zones in contact
    zone_pressure: float       # Pa, largest zone pressure of the macro model
    max_pressure: float        # Pa, largest local pressure (before wear)
    max_temperature: float     # K, largest local surface temperature of the rough body (NaN without)
    partition: tuple           # (min, mean, max) share into the rough body over the loaded zones
    work: float                # J, mu ∫ p |v| dA over the wear interval (0 without wear)
    seconds: float
    plastic_fraction: float = 0.0  # largest share of a zone's cells at the hardness (0 without plasticity)


@dataclass
class StepResult:
    """One macro step of the loop (or the start, step 0)."""

    step: int
    heat: np.ndarray           # J, frictional heat put into body 0 and body 1 during the step
    micro: MicroStep
    time_macro: float          # s, wall time of the macro solves
    time_micro: float          # s, of the post-analysis
    time_laws: float           # s, of the law updates


@dataclass
class Restored:
    """State read back from a checkpoint."""

    step: int                  # last macro step done
    history: io.History
    fields_written: int        # last step whose fields were written (-1: none)


class Multiscale:
    """The loop over a ``MacroModel`` whose contact law is ``rough.law`` (see module docstring)."""

    def __init__(self, model: MacroModel, rough: RoughInterface, post: PostAnalysis, settings: LoopSettings,
                 fingerprint: str = ""):
        self.model, self.rough, self.post, self.settings = model, rough, post, settings
        self.tm, self.comm = model.tm, model.tm.comm
        self.fingerprint = fingerprint
        self.nominal = sum(settings.forces.values()) / self.tm.interface.areas.sum()
        Z = len(rough.zones)
        self.partition = np.full(Z, float(settings.partition))
        self.conductance = np.zeros(Z)
        self.warm = np.zeros(rough.initial.shape)     # previous local pressures (warm starts)
        self.flash = np.full(len(rough.zones), np.nan)  # K, last micro max temperature of each zone
        self.work = 0.0                               # J, frictional work over the wear intervals
        self.datum_gap = np.zeros(self.tm.interface.n_facets)   # m, uniform initial gap g_0 per facet

    @property
    def partition_law(self) -> bool:
        return self.settings.partition_law and self.post.heating is not None

    # ---- macro <-> micro -------------------------------------------------------------------
    def loading(self) -> ZoneLoading:
        """Per-zone macro loading at the current state (every rank gets the same arrays)."""
        iface, model, Z = self.tm.interface, self.model, len(self.rough.zones)
        rough = self.rough.zone_of_facet >= 0
        zone_of, areas = self.rough.zone_of_facet[rough], iface.areas[rough]
        force = np.bincount(zone_of, (model.contact.facet_pressure() * iface.areas)[rough], minlength=Z)
        area = np.bincount(zone_of, areas, minlength=Z)
        T = np.full((Z, 2), self.settings.initial_temperature)
        if model.thermal is not None:
            for col, side in ((0, 1), (1, 0)):
                total = np.bincount(zone_of, model.thermal.facet_temperature(side)[rough] * areas, minlength=Z)
                T[:, col] = np.where(area > 0, total / np.where(area > 0, area, 1.0), T[:, col])
        centres, axes = self.rough.zone_frames()
        motion = self.tm.spec.motion
        speed = model.speed(model.time)
        if isinstance(motion, Rotation):
            axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis)
            w = speed * np.cross(axis, centres - np.asarray(motion.centre, float))
        else:
            e = np.asarray(motion.direction, float) / np.linalg.norm(motion.direction)
            w = np.tile(speed * e, (Z, 1))
        w = np.einsum("zij,zj->zi", axes, w)             # in each zone's plane coordinates
        return ZoneLoading(force, force / self.rough.zone_area, np.hypot(w[:, 0], w[:, 1]),
                           np.arctan2(w[:, 1], w[:, 0]), T)

    def micro_step(self, wear: bool, duration: float = 0.0) -> MicroStep:
        """Post-analysis of the loaded zones at the current macro state; with ``wear`` the zones
        wear over ``duration`` [s] of sliding (their topographies change)."""
        t0 = _time.perf_counter()
        comm, load, zones = self.comm, self.loading(), self.rough.zones
        loaded = np.flatnonzero(load.pressure > LOADED * self.nominal)
        mine = loaded[comm.rank::comm.size]
        sliding = load.speed[mine] * duration if wear else None
        rough = load.temperature[mine, 1]
        mu = None if self.settings.friction is None else self.settings.friction[mine]
        res = self.post.run([zones[i] for i in mine], load.pressure[mine], speed=load.speed[mine],
                            angle=load.angle[mine], remote=np.column_stack([rough, rough]), sliding=sliding,
                            warm=self.warm[mine], mu=mu, hardness_temperature=self._hardness_temperature(mine, rough))
        changed = wear or self.post.hardness is not None          # worn or plastically deformed
        plastic = self.post.hardness is not None
        parts = comm.allgather((mine, res.worn_pressure, res.heights if changed else None, res.max_pressure,
                                res.max_temperature, res.partition, res.conductance,
                                res.plastic if plastic else None, res.plastic_area_fraction))
        max_p, max_T, flow = [], [], []
        for ids, warm, heights, mp, mT, part, h_c, w, fraction in parts:
            self.warm[ids] = warm
            self.flash[ids] = mT
            if heights is not None:
                self.rough.set_heights(ids, heights)
            if w is not None:
                self.rough.plastic[ids] += w
            if self.partition_law:
                self.partition[ids] = part
            if self.post.conductance is not None:
                self.conductance[ids] = h_c
            max_p.append(mp)
            max_T.append(mT)
            flow.append(fraction)
        if self.post.conductance is not None:
            self.conductance[np.setdiff1d(np.arange(len(zones)), loaded)] = 0.0
        work = sum(self.model.contact.heat_power()) * duration if wear else 0.0   # mu ∫ p |w| dA Δt
        self.work += work
        max_p, max_T = np.concatenate(max_p), np.concatenate(max_T)
        used = self.partition[loaded] if len(loaded) else np.full(1, np.nan)
        return MicroStep(len(loaded), float(load.pressure.max()), float(max_p.max(initial=0.0)),
                         float(max_T.max()) if len(max_T) and np.isfinite(max_T).any() else np.nan,
                         (float(used.min()), float(used.mean()), float(used.max())), work,
                         _time.perf_counter() - t0, float(np.concatenate(flow).max(initial=0.0)))

    def _hardness_temperature(self, ids, rough_temperature) -> np.ndarray | None:
        """Where the zones ``ids`` take H(T): with ``settings.flash_softening``, their flash
        temperature of the previous post-analysis (the rough body's macro temperature before the
        first, or if higher): the fixed point H = H(T_flash(H)) is reached explicitly over the macro
        steps, lagged by one step like the micro partition; else None (the macro temperature)."""
        if not self.settings.flash_softening:
            return None
        return np.fmax(self.flash[ids], rough_temperature)

    def apply_zone_fields(self) -> None:
        """Per-facet partition (micro partition law) and conductance from the zones."""
        contact, iface, zone_of = self.model.contact, self.tm.interface, self.rough.zone_of_facet
        rough = zone_of >= 0                       # the other interfaces keep their scene values
        if self.partition_law:
            iface.set_field(contact.partition, np.where(rough, self.partition[zone_of], iface.values(contact.partition)))
        if self.post.conductance is not None:
            iface.set_field(contact.conductance,
                            np.where(rough, self.conductance[zone_of], iface.values(contact.conductance)))

    def facet_fields(self) -> dict:
        """Interface output fields of the loop: name -> per-facet array maker."""
        iface, contact, rough = self.tm.interface, self.model.contact, self.rough
        return {"contact_stiffness": lambda: rough.law.evaluate(contact.facet_gap())[1],
                "partition": lambda: iface.values(contact.partition),
                "wear_depth": lambda: np.where(rough.zone_of_facet >= 0,
                                               rough.wear_depth().mean(axis=(-2, -1))[rough.zone_of_facet], 0.0)}

    # ---- the run ---------------------------------------------------------------------------
    def start(self) -> StepResult:
        """Initial laws, rigid datum gap, first (ramped) solve and the initial post-analysis."""
        t0 = _time.perf_counter()
        self.rough.update_laws()
        t1 = _time.perf_counter()
        self.datum_gap = self.rough.datum_gap(self.settings.forces)
        self.tm.interface.set_field(self.model.contact.initial_gap, self.datum_gap)
        self.model.start()
        t2 = _time.perf_counter()
        micro = self.micro_step(wear=False)
        self.apply_zone_fields()
        return StepResult(0, np.zeros(2), micro, t2 - t1, micro.seconds, t1 - t0)

    def step(self, n: int) -> StepResult:
        """Macro step n (1, 2, ...): the macro transient, the post-analysis, the new laws."""
        s = self.settings
        t0 = _time.perf_counter()
        heat = self.model.macro_step(s.dt, s.substeps)
        t1 = _time.perf_counter()
        wear = s.wear and n % s.wear_every == 0
        micro = self.micro_step(wear, s.dt * s.wear_every if wear else 0.0)
        self.apply_zone_fields()
        t2 = _time.perf_counter()
        self.rough.laws_computed = 0
        changed = wear or self.post.hardness is not None   # new topographies: their laws (cached if unchanged)
        if changed:
            self.rough.update_laws()
        t3 = _time.perf_counter()
        if changed:
            self.model.last_solve = self.model.mechanics.solve()
        return StepResult(n, heat, micro, t1 - t0 + _time.perf_counter() - t3, t2 - t1, t3 - t2)

    def record(self, result: StepResult) -> dict:
        """One history row (units: ``io.UNITS``)."""
        micro = result.micro
        row = self.model.record(result.heat)
        row.update(zones_in_contact=micro.loaded, laws_computed=self.rough.laws_computed,
                   max_zone_pressure=micro.zone_pressure, micro_max_pressure=micro.max_pressure)
        if self.post.heating is not None:
            row.update(micro_max_temperature=micro.max_temperature, partition_min=micro.partition[0],
                       partition_mean=micro.partition[1], partition_max=micro.partition[2])
        if self.post.hardness is not None:
            row.update(micro_plastic_fraction=micro.plastic_fraction,
                       plastic_max_depth=float(self.rough.plastic.max(initial=0.0)))
        if self.settings.wear:
            heights = self.rough.heights()
            depth = self.rough.wear_depth()
            row.update(wear_volume=float(self.rough.zone_wear_volume(depth).sum()), wear_max_depth=float(depth.max()),
                       rms_height=float(np.sqrt(np.mean((heights - heights.mean()) ** 2))),
                       frictional_work=self.work)
        row.update(time_macro=result.time_macro, time_micro=result.time_micro, time_laws=result.time_laws)
        return row

    # ---- checkpoints -----------------------------------------------------------------------
    def _functions(self) -> dict:
        m = self.model
        out = {f"u{i}": u for i, u in enumerate(m.mechanics.u)}
        if m.thermal is not None:
            out.update({f"T{i}": T for i, T in enumerate(m.thermal.T)})
        return out

    def save(self, path: Path, step: int, history: io.History) -> None:
        """Checkpoint after macro step ``step`` (collective)."""
        m, last = self.model, self.model.last_solve
        arrays = {"heights": self.rough.heights(), "plastic": self.rough.plastic, "flash": self.flash, "warm": self.warm,
                  "partition": self.partition,
                  "conductance": self.conductance, "levels": self.rough.levels, "heat_total": m.heat_total,
                  "heat_lost_recorded": m.heat_lost_recorded,
                  **({"lost_total": m.thermal.lost_total} if m.thermal is not None else {}),
                  "datum_gap": self.datum_gap,
                  **{f"history/{k}": np.asarray(v) for k, v in history.columns.items()}}
        attrs = {"step": step, "time": m.time, "work": self.work, "scene": self.fingerprint, "load": m.load,
                 "ranks": self.comm.size, "fields_written": -1,
                 "solve": [last.reason, last.iterations, last.normal_force, last.max_pressure]}
        checkpoint.save(path, self.comm, attrs=attrs, arrays=arrays, functions=self._functions(),
                        scale=self.tm.spec.length_scale)

    def restore(self, path: Path) -> Restored:
        """State of the checkpoint ``path`` (collective)."""
        attrs, arrays = checkpoint.load(path, self.comm, self._functions())
        if attrs["scene"] != self.fingerprint:
            raise InputError("--resume", str(path), "the scene changed since this checkpoint was written; "
                             "run it with --overwrite")
        m = self.model
        self.rough.set_heights(range(len(arrays["heights"])), arrays["heights"])
        self.rough.plastic, self.flash = arrays["plastic"].copy(), arrays["flash"].copy()
        self.warm, self.partition = arrays["warm"], arrays["partition"]
        self.conductance, self.rough.levels = arrays["conductance"], arrays["levels"]
        self.datum_gap = arrays["datum_gap"]
        m.heat_total = arrays["heat_total"].copy()
        m.heat_lost_recorded = arrays["heat_lost_recorded"].copy()
        if m.thermal is not None:
            m.thermal.lost_total = arrays["lost_total"].copy()
        m.time, self.work = float(attrs["time"]), float(attrs["work"])
        if m.thermal is not None:
            m.thermal.time = m.time
        reason, its, force, max_p = attrs["solve"]
        m.last_solve = SolveResult(True, int(reason), int(its), [], float(force), float(max_p))
        self.tm.interface.set_field(m.contact.initial_gap, self.datum_gap)
        m.contact.speed.value = m.speed(m.time)
        m.load = float(attrs["load"])
        m.mechanics.load.value = m.load * m.drive.factor(m.time)
        self.rough.update_laws()
        self.apply_zone_fields()
        history = io.History()
        history.columns = {k[len("history/"):]: list(v) for k, v in arrays.items() if k.startswith("history/")}
        return Restored(int(attrs["step"]), history, int(attrs["fields_written"]))

    @staticmethod
    def mark_fields(path: Path, step: int, comm) -> None:
        """Record in the checkpoint that the fields of ``step`` are written (collective)."""
        if comm.rank == 0:
            with h5py.File(path, "r+") as h5:
                h5.attrs["fields_written"] = step
        comm.barrier()

"""The multiscale loop: a macro model whose rough interface carries per-zone laws, the micro post-analysis of
the zones, wear and checkpoints (thesis §1.4–1.5, ch. 7, Figs. 7.2–7.5).

One macro step Δt (Fig. 7.2) runs:

1. the macro transient over Δt in ``substeps`` thermo-mechanical sub-steps δt with the current laws and
   partitions (Fig. 7.4; ``macro.model.MacroModel.macro_step``); a step that wears holds its Archard depth per
   pressure k_w mu s in series with the laws (``ZoneLaws.in_series``, solved first): backward Euler, stable at
   any Δt (the explicit update flip-flopped the facet pressures once a step's depth passed the laws' compliance);
2. per zone, the macro loading at the end of the step (``loading``): zone pressure P = (contact force on the
   zone's facets) / (their area), the patch's results counted over it (``cover``), the facet temperatures of
   both bodies, the sliding speed (force-weighted over the zone) and direction;
3. the micro post-analysis of the loaded zones (Fig. 7.5, ``micro.post_analysis``): local pressure under P,
   local surface temperatures, flash temperature and partition (steady sliding heating, or with
   ``PostAnalysis.heating.transient_steps`` the transient heating over Δt, Table 7.1), and, every
   ``wear_every`` steps (and at the last step), the Archard wear of the patch over the load-weighted sliding
   of those steps with k_w(T) (and the counter-face's, spread over its wear track: ``rough.track_depth``), in
   increments raised until their step-doubling error is within ``micro.wear.WEAR_TOL``; the zones are spread
   over the MPI ranks and the worn topographies shared; a facet wears D (p − P) / P more than its zone's patch
   (``form_depth``, D the patch's mean worn depth, p the facet's pressure: Archard's at the facet, never
   negative; c (p − P) with the step's series compliance c, D / P where the micro wear took c, left
   facets unloaded with less depth than before, down to −0.12 um on a brake pad: a user trial);
4. the laws of the zones whose topography changed are recomputed (``rough.RoughInterface``: the others come
   from the pool's cache), the facet laws updated and the mechanics re-solved at the same time (from the state
   plus the previous step's change by this solve, ``law_increment``, if its residual is lower; where that
   fails, by ``macro.continuation``): the temperatures carry over.

Remote temperatures of the micro heating (``LoopSettings.remote``). "bulk": each body's own macro surface
temperature at the zone (thesis §7.2.2, §6.5: the heat conducted from the hotter body through the contact
spots is part of the heat into the rough body, whose share of the frictional heat may then leave [0, 1]).
"rough": both at the rough body's (the partition then depends on the contact and the speed only); the loop's
behaviour before issue 19, kept as an option (and the default with an interface conductance, which conducts
between the bulk temperatures itself). The scenes' default is "bulk" with the implicit coupling (below).

Coupling of partitions and temperatures (``LoopSettings.coupling``); residual of a step: max over the loaded
zones of |heat into the rough body by the post-analysis at the end of the step − the heat the zone's partition
and exchange G put into it at that state| / mean zone frictional heat (or mean |heat into the rough body|
nearly at rest; ``heat_residual``; a light zone's partition counts for the heat it moves; the implicit
scheme's macro model conducts G_i, not G: the residual checks the micro model's own split). Schemes:

- "explicit": the partitions of step n + 1 come from the post-analysis of step n (thesis Fig. 7.2).
- "fixed-point" (thesis form, converged): the partitions p of step n solve p = G(p), G = the post-analysis'
  partitions at the end of a macro step run with p: the step is restarted from its initial state
  (``MacroModel.snapshot``/``restore``) with the next p of Anderson's acceleration (``anderson``: a
  multisecant quasi-Newton on the per-zone partitions, residuals weighted by the zones' heat, first step p +
  ``relaxation`` (G(p) − p)) until the residual is <= ``coupling_tol``; wear is then done once, at the
  converged state. (A scalar relaxation stalls: the zones' gains differ by orders of magnitude.)
- "implicit" (bulk temperatures only): the micro problem is linear in the frictional heat and the remote
  temperatures, so the post-analysis returns, per zone, the partition at equal remote temperatures and the
  exchange G [W/K] (``PostAnalysis`` with ``Heating.conduction``); the macro model splits the frictional heat
  with the first and conducts G (T_rough − T_counter) through the interface conductance h_c = G_i / (facet
  area of the zone), G_i = 1/(1/G − 1/G_full) (``post_analysis.interface_exchange``: G without the zone's own
  bulk spreading, which the macro model resolves: G_full the zone's exchange in full contact; with G itself a
  zone in nearly full contact conducted only its bulk's conductance), inside its own backward-Euler heat solve.
  With G itself this was a Newton step on the per-zone heat with the micro model's exact derivative (the micro
  heat at the end of the step the macro one up to the change of the contact during the step, in one pass);
  with G_i the macro model resolves the zone-scale spreading the micro patch holds too, so the two differ by
  (G_i − G) times the faces' difference, by design. It departs from the thesis' form (the conduction hidden
  in the partition) without its failure (docs/architecture.md, the decision on the coupling; §7 on G_i).

The default (``scene_sections.COUPLING_DEFAULT``) was chosen by measurement (docs/accuracy/coupling.md); the
rigid datum gap starts Newton close to equilibrium.
``save``/``restore`` write and read the whole state (``checkpoint``): a killed run continues to the same
history (to solver tolerance: a resumed run recomputes its zone laws). This module reads no scene:
``multiscale.workflows.multiscale`` builds and runs it."""
from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multiscale import checkpoint, io
from multiscale.anderson import anderson
from multiscale.errors import ConvergenceError
from multiscale.loop_settings import LoopSettings
from multiscale.macro.continuation import solve_on_new_laws
from multiscale.macro.model import MacroModel
from multiscale.macro.thickness import WearLimit
from multiscale.micro.post_analysis import PostAnalysis, interface_exchange
from multiscale.micro.wear import WEAR_TOL
from multiscale.rough import RoughInterface

LOADED = 1e-9              # zones below this fraction of the nominal pressure are unloaded
ANDERSON_MEMORY = 8        # past passes the fixed point's acceleration uses


@dataclass
class ZoneLoading:
    """Macro loading of every zone at the current state (arrays over zone ids)."""

    force: np.ndarray          # N, contact force on the zone's facets
    pressure: np.ndarray       # Pa, force / zone area
    speed: np.ndarray          # m/s, sliding speed of the counter-face, force-weighted over the zone
    angle: np.ndarray          # rad, its direction in the interface plane (from +x)
    temperature: np.ndarray    # K, (Z, 2): facet-mean surface temperatures (counter-face, rough body)
    reach: np.ndarray          # m per unit of body 1's sliding (rad or m): the zone's sliding distance
    friction: np.ndarray | None  # -, mu: the zone's (its facets' area mean with a friction law); None: the post's


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
    real_area: np.ndarray = None  # m^2, per zone: real contact area over its facets (before wear; 0 unloaded)
    law_reach: float = 0.0     # largest zone pressure over micro.p_max, the top of the laws (> 1: extrapolated)
    law_reach_halved: float = 0.0  # the same over the zones whose law failed, against their halved top
    near_perfect: int = 0      # zones loaded beyond their law's floor (nearly perfect contact)
    wear_error: float = 0.0    # estimated relative error of the worn depth, from the increments (step doubling)
    wear_substeps: int = 0     # wear increments of the update (wear.substeps, or more: WEAR_TOL, stability)


@dataclass
class StepResult:
    """One macro step of the loop (or the start, step 0)."""

    step: int
    heat: np.ndarray           # J, frictional heat put into body 0 and body 1 during the step
    micro: MicroStep
    time_macro: float          # s, wall time of the macro solves
    time_micro: float          # s, of the post-analysis
    time_laws: float           # s, of the law updates
    residuals: list = field(default_factory=list)   # max |G(p) - p| of each pass (empty: no partition law)


class Multiscale:
    """The loop over a ``MacroModel`` whose contact law is ``rough.law`` (see module docstring)."""

    def __init__(self, model: MacroModel, rough: RoughInterface, post: PostAnalysis, settings: LoopSettings,
                 fingerprint: checkpoint.Fingerprint = checkpoint.Fingerprint()):
        self.model, self.rough, self.post, self.settings = model, rough, post, settings
        self.tm, self.comm, self.fingerprint = model.tm, model.tm.comm, fingerprint
        self.nominal = sum(settings.forces.values()) / self.tm.interface.areas.sum()
        Z = len(rough.zones)
        self.partition = np.broadcast_to(np.asarray(settings.partition, dtype=float), (Z,)).copy()
        self.proposed = np.full(Z, np.nan)            # partitions of the last post-analysis (NaN: unloaded)
        self.flash = np.full(Z, np.nan)               # K, flash temperature of each zone (NaN: unloaded)
        self.rates = np.full(Z, np.nan)               # 1/Pa, k_w as the last analysis' wear takes it (NaN: unloaded)
        self.conductance = np.zeros(Z)
        self.warm = np.zeros(rough.initial.shape)     # previous local pressures (warm starts)
        self.work = 0.0                               # J, frictional work over the wear intervals
        self.interval_work = 0.0                      # J, that of the steps since the last wear
        self.datum_gap = np.zeros(self.tm.interface.n_facets)   # m, uniform initial gap g_0 per facet
        self.counter_depth = np.zeros(self.tm.interface.n_facets)   # m, counter-face worn along its track
        self.form_depth = np.zeros(self.tm.interface.n_facets)   # m, the rough body's wear beyond its zone's mean
        self.series = np.zeros(Z)                     # m/Pa, the wearing step's Archard depth per pressure (archard)
        self.counter_volume = 0.0                     # m^3, lost by the counter-face
        self.exchange, self.proposed_exchange = np.zeros(Z), np.zeros(Z)   # W/K, rough body -> counter-face (implicit)
        self.exchange_full, self.proposed_full = np.full(Z, np.nan), np.full(Z, np.nan)   # W/K, in full contact
        self.micro_heat = np.full(Z, np.nan)          # W, Phi of the last post-analysis
        self.micro_heat_rough = np.full(Z, np.nan)    # W, heat into the rough body by it
        self.remote_difference = np.zeros(Z)          # K, T_rough − T_counter of the macro surfaces
        self._last = None                             # this rank's zones, their post-analysis, loading, remote
        self.law_increment = None                     # m, displacement change of the last solve after new laws
        self.increments = post.substeps               # the most wear increments an update took (said as it grows)
        self.limit = WearLimit(self.tm, settings.wear_limit) if settings.wear else None   # against the rough body

    @property
    def partition_law(self) -> bool:
        return self.settings.partition_law and self.post.heating is not None

    @property
    def iterating(self) -> bool:
        """True if the partitions are iterated within each step (fixed point)."""
        return self.settings.coupling == "fixed-point" and self.partition_law and self.model.thermal is not None

    # ---- macro <-> micro -------------------------------------------------------------------
    def loading(self) -> ZoneLoading:
        """Per-zone macro loading at the current state (every rank gets the same arrays)."""
        iface, model, Z = self.tm.interface, self.model, len(self.rough.zones)
        rough = self.rough.zone_of_facet >= 0
        zone_of, areas = self.rough.zone_of_facet[rough], iface.areas[rough]
        pressure_area = model.contact.facet_pressure() * iface.areas          # N per facet
        force, area = (np.bincount(zone_of, f[rough], minlength=Z) for f in (pressure_area, iface.areas))

        def mean(values, default):               # the zones' area means of a facet field, ``default`` without facets
            total = np.bincount(zone_of, values[rough] * areas, minlength=Z)
            return np.where(area > 0, total / np.where(area > 0, area, 1.0), default)
        T = np.full((Z, 2), self.settings.initial_temperature)
        if model.thermal is not None:
            for col, side in ((0, 1), (1, 0)):
                T[:, col] = mean(model.thermal.facet_temperature(side), T[:, col])
        mu = self.settings.friction
        if mu is not None and model.friction_law is not None:     # fade: mu of the facets' temperatures
            mu = mean(iface.values(model.contact.friction), mu)
        reach, angle = self.rough.zone_sliding(self.tm.spec.motion, pressure_area)
        # the speed now; at a standstill the mean of the next step (these fields act on it), else of
        # the last (the zones' heating needs a speed; a restart from rest had no exchange for a step)
        speed, dt = model.speed(model.time), self.settings.dt
        if speed == 0.0 and dt:
            speed = model.drive.mean_speed(model.time, model.time + dt) or \
                model.drive.mean_speed(max(model.time - dt, 0.0), model.time)
        return ZoneLoading(force, self.rough.per_facet_area(force), reach * abs(speed),   # their mean pressure
                           angle + (np.pi if speed < 0 else 0.0), T, reach, mu)

    def analyse(self) -> MicroStep:
        """Post-analysis (local contact, heating, conductance) of the loaded zones at the current
        macro state, spread over the ranks; the partitions (and exchanges) it finds are
        ``proposed`` (made the zones' by ``accept``)."""
        t0 = _time.perf_counter()
        comm, load, zones = self.comm, self.loading(), self.rough.zones
        loaded = np.flatnonzero(load.pressure > LOADED * self.nominal)
        mine = loaded[comm.rank::comm.size]
        T = load.temperature[mine]
        remote = np.column_stack([T[:, 0] if self.settings.remote == "bulk" else T[:, 1], T[:, 1]])
        mu = None if load.friction is None else load.friction[mine]
        res = io.collective(comm, lambda: self.post.run(
            [zones[i] for i in mine], load.pressure[mine], speed=load.speed[mine], angle=load.angle[mine],
            remote=remote, warm=self.warm[mine], mu=mu, duration=self.settings.dt,
            hardness_temperature=self._hardness_temperature(mine, T[:, 1])))
        self._last = (mine, res, load, remote, loaded)
        implicit = self.settings.coupling == "implicit"
        cover = self.rough.cover[mine]              # the patches' heat and area over their facets'
        parts = comm.allgather((mine, res.pressure, res.max_pressure, res.max_temperature,
                                res.partition_equal if implicit else res.partition, res.conductance, res.heat * cover,
                                res.heat_rough * cover, res.exchange * cover, res.exchange_full * cover,
                                remote[:, 1] - remote[:, 0],
                                res.plastic_area_fraction, res.area_fraction * self.rough.covered_area[mine],
                                self.post.zone_rates(res, remote)))
        for a in (self.proposed, self.flash, self.micro_heat, self.micro_heat_rough, self.rates):
            a[:] = np.nan
        self.proposed_exchange[:], self.proposed_full[:] = 0.0, np.nan
        max_p, flow, real = [], [np.zeros(0)], np.zeros(len(zones))
        for ids, warm, mp, mT, part, h_c, heat, rough, exchange, full, diff, fraction, area, rates in parts:
            flow.append(fraction)
            real[ids], self.rates[ids] = area, rates
            self.warm[ids], self.proposed[ids], self.flash[ids] = warm, part, mT
            self.micro_heat[ids], self.micro_heat_rough[ids], self.remote_difference[ids] = heat, rough, diff
            if implicit:
                self.proposed_exchange[ids], self.proposed_full[ids] = exchange, full
            if self.post.conductance is not None:
                self.conductance[ids] = h_c
            max_p.append(mp)
        if self.post.conductance is not None:
            self.conductance[np.setdiff1d(np.arange(len(zones)), loaded)] = 0.0
        if self.model.released:         # no contact, no flash (the zones' last loads stay analysed for wear)
            self.flash[:] = np.nan
        hot, max_p = self.flash[loaded], np.concatenate(max_p)
        return MicroStep(len(loaded), float(load.pressure.max()), float(max_p.max(initial=0.0)),
                         float(np.nanmax(hot)) if np.isfinite(hot).any() else np.nan, (np.nan,) * 3, 0.0,
                         _time.perf_counter() - t0, float(np.concatenate(flow).max(initial=0.0)), real,
                         *self.rough.law_reach(load.pressure, loaded))

    def _hardness_temperature(self, ids, rough_temperature) -> np.ndarray | None:
        """Where the zones ``ids`` take H(T): with ``settings.flash_softening``, their flash
        temperature of the previous post-analysis (the rough body's macro temperature before the
        first, or if higher): the fixed point H = H(T_flash(H)) is reached explicitly over the macro
        steps (and the passes of the fixed-point coupling); else None (the macro temperature)."""
        if not self.settings.flash_softening:
            return None
        return np.fmax(self.flash[ids], rough_temperature)

    @property
    def plastic(self) -> bool:
        """True if the zones are elastic-perfectly plastic (their topographies change when they yield)."""
        return self.post.hardness is not None

    def deform(self) -> None:
        """The zones of the last ``analyse`` keep their permanent deformation (without wear; ``wear``
        keeps it with the worn topographies)."""
        mine, res = self._last[:2]
        for ids, heights, w in self.comm.allgather((mine, res.heights, res.plastic)):
            self.rough.set_heights(ids, heights)
            self.rough.plastic[ids] += w

    def archard(self, m: int, n: int) -> np.ndarray:
        """Archard's depth per pressure [m/Pa] of every zone over steps m + 1 ... n for the load at n's end
        (``wear``'s sliding, ``MacroModel.sliding``), with k_w as the last analysis' wear took it
        (``PostAnalysis.zone_rates``: its local temperatures), at the macro temperature elsewhere."""
        t0, t1 = (float(f"{k * self.settings.dt:.12g}") for k in (m, n))     # the model's times (step_time)
        f, load = self.model.drive.factor(t1), self.loading()
        sliding = self.model.drive.mean_sliding(t0, t1) * (t1 - t0) / f if f > 0 else 0.0
        return self.post.archard_compliance(load.reach * sliding, load.temperature[:, 1], load.friction, self.rates)

    def wear(self, duration: float) -> tuple[float, float, int]:
        """Wear of the zones of the last ``analyse`` over the last ``duration`` [s] (their topographies change; a
        wearing counter-face recedes along its track): the pressure fields of the last analysis slide over the
        interval's load-weighted sliding (``MacroModel.sliding``: none while released, exact for a stop or a release
        inside it), in increments raised from the fewest while the step-doubling estimate of the worn depth's error
        is above ``WEAR_TOL`` (up to an explicit scheme's stable count). Returns the interval's frictional work [J]
        (the macro steps' ``work_step``: the frictional heat put in), that estimate (the zones' relative errors
        weighted by their worn volumes) and the increments taken."""
        mine, start, load, remote, _ = self._last
        zones, m, cover = self.rough.zones, self.model, self.rough.cover
        sliding = m.sliding(m.time - duration, m.time)
        own, slides = [zones[i] for i in mine], load.reach[mine] * sliding
        n, most = np.max(self.comm.allgather(io.collective(     # one count on every rank: the answer of any split
            self.comm, lambda: self.post.increments(own, start, slides, remote))), axis=0)
        while True:                                      # first order: n e / WEAR_TOL meets it, if it holds
            res = io.collective(self.comm, lambda: self.post.wear(own, start, slides, remote, int(n)))
            parts = self.comm.allgather((mine, res.worn_pressure, res.heights, res.counter_volume, res.plastic,
                                         res.volume * cover[mine], res.wear_error))
            total = sum(float(worn.sum()) for *_, worn, _ in parts)          # the depth errors weighted by volume
            error = sum(float(worn @ off) for *_, worn, off in parts) / total if total > 0 else 0.0
            if n >= most or error <= WEAR_TOL:
                break
            n = min(most, max(2 * n, int(np.ceil(n * error / WEAR_TOL))))
        volume, before = np.zeros(len(zones)), self.rough.wear_depth().mean(axis=(-2, -1))
        for ids, warm, heights, lost, w, *_ in parts:
            self.warm[ids] = warm
            self.rough.set_heights(ids, heights)
            volume[ids] = lost * cover[ids]
            if self.plastic:
                self.rough.plastic[ids] += w
        on = self.rough.zone_of_facet >= 0          # each facet's Archard depth at its own pressure, backward Euler:
        zone_of = self.rough.zone_of_facet[on]      # the zone's topography took its mean D, the facet D p / P
        gained, P = (self.rough.wear_depth().mean(axis=(-2, -1)) - before)[zone_of], load.pressure[zone_of]
        self.form_depth[on] += gained * np.divide(m.contact.facet_pressure()[on] - P, P, out=np.zeros(P.shape), where=P > 0)
        if self.post.counter_rate is not None:
            self.counter_depth += self.rough.track_depth(volume, m.facet_sliding_power())    # (its flux now: 0 at rest)
            self.counter_volume += volume.sum()
        self.set_gap()
        work, self.interval_work = self.interval_work, 0.0                 # mu ∫ p |w| dA dt
        self.work += work
        if n > self.increments:
            self.increments = n
            io.reporter().say(f"  wear updates in {n} increments (wear.substeps = {self.post.substeps}), raised while "
                              f"their step-doubling error exceeded {100 * WEAR_TOL:g} % of the worn depth (micro.wear.WEAR_TOL)")
        return work, error, int(n)

    def set_gap(self) -> None:
        """The facets' initial gap: the datum, opened by the counter-face's wear and by the rough body's
        beyond its zones' means."""
        self.tm.interface.set_field(self.model.contact.initial_gap, self.datum_gap + self.counter_depth + self.form_depth)

    def accept(self, micro: MicroStep) -> MicroStep:
        """The partitions (and exchanges) of the last ``analyse`` become the zones' (partition law);
        ``micro`` with their (min, mean, max) over the loaded zones with friction."""
        loaded = self._last[-1]
        if self.partition_law:                  # a zone that did not slide (no heat) keeps its partition
            proposed = self.proposed[loaded]
            self.partition[loaded] = np.where(np.isfinite(proposed), proposed, self.partition[loaded])
        if self.settings.coupling == "implicit":
            self.exchange[:], self.exchange_full[:] = 0.0, np.nan
            self.exchange[loaded], self.exchange_full[loaded] = self.proposed_exchange[loaded], self.proposed_full[loaded]
        heated = loaded if self.settings.friction is None else loaded[self.settings.friction[loaded] > 0]
        used = self.partition[heated] if len(heated) else np.full(1, np.nan)     # (without friction, no heat)
        micro.partition = (float(used.min()), float(used.mean()), float(used.max()))
        return micro

    def micro_step(self) -> MicroStep:
        """Post-analysis of the loaded zones at the current state (no wear), its partitions accepted."""
        micro = self.analyse()
        if self.plastic:
            self.deform()
        return self.accept(micro)

    def residual(self) -> np.ndarray:
        """G(p) − p per zone: the last post-analysis' partitions minus those used (0 where unloaded)."""
        return np.where(np.isfinite(self.proposed), self.proposed - self.partition, 0.0)

    def heat_residual(self) -> float:
        """The coupling residual: max over the loaded zones of |heat into the rough body by the last
        post-analysis − heat the zone's partition of Phi and exchange put into it at the same state
        (minus G (T_rough − T_counter), the micro model's own G, not the macro's G_i: module docstring)|
        / the zones' mean Phi, or mean |heat into the rough
        body| if larger (near rest the conduction outweighs a vanishing Phi: 1.8e12 at a stop's end before);
        0 while released (no contact, no heat: the zones' last loads are analysed, nothing couples).
        A heat that is not finite is a ``ConvergenceError`` (it was a residual of 0: converged)."""
        loaded = self._last[-1]
        if not len(loaded) or self.model.released:
            return 0.0
        Q, into = self.micro_heat[loaded], self.micro_heat_rough[loaded]
        with np.errstate(invalid="ignore", over="ignore"):     # (what is not finite is said next)
            given = np.where(Q > 0, self.partition[loaded] * Q, 0.0) - self.exchange[loaded] * self.remote_difference[loaded]
        finite = np.isfinite(Q) & np.isfinite(into) & np.isfinite(given)
        if not finite.all():
            bad = np.asarray(loaded)[~finite]
            raise ConvergenceError(f"the post-analysis gave a heat rate that is not finite in {io.counted(len(bad), 'zone')} "
                                   f"(the first: {bad[:5].tolist()}): the coupling cannot be checked")
        if Q.mean() <= 0.0:                     # no frictional heat (no sliding): nothing to couple
            return 0.0
        return float(np.abs(into - given).max() / max(Q.mean(), np.abs(into).mean()))

    def zone_heat(self) -> np.ndarray:
        """Frictional heat rate Phi of each zone loaded in the last ``analyse`` over their mean (0 on the
        others): the weights of the partitions in the fixed point (a partition's change counts as the heat it moves)."""
        loaded, Q = self._last[-1], np.zeros(len(self.rough.zones))
        Q[loaded] = self.micro_heat[loaded]
        return Q / Q[loaded].mean() if len(loaded) and Q[loaded].mean() > 0 else Q

    def apply_zone_fields(self) -> None:
        """Per-facet partition (micro partition law) and conductance from the zones."""
        contact, iface, zone_of = self.model.contact, self.tm.interface, self.rough.zone_of_facet
        rough = zone_of >= 0                       # the other interfaces keep their scene values
        if self.partition_law:
            iface.set_field(contact.partition, np.where(rough, self.partition[zone_of], iface.values(contact.partition)))
        if self.settings.coupling == "implicit":   # the exchange G of each zone over its facets, its bulk's out
            self.conductance = self.rough.per_facet_area(interface_exchange(self.exchange, self.exchange_full))
        if self.post.conductance is not None or self.settings.coupling == "implicit":
            iface.set_field(contact.conductance,
                            np.where(rough, self.conductance[zone_of], iface.values(contact.conductance)))

    def facet_fields(self) -> dict:
        """Interface output fields of the loop: name -> per-facet array maker."""
        iface, contact, rough = self.tm.interface, self.model.contact, self.rough
        fields = {"contact_stiffness": lambda: rough.facet_stiffness(contact.facet_gap(), iface.values(contact.stiffness))
                  * (not self.model.released),
                  "partition": lambda: iface.values(contact.partition),
                  "wear_depth": self.facet_wear_depth}
        if self.post.heating is not None:
            fields["flash_temperature"] = self.facet_flash
        if self.settings.wear:      # zero where body 1 does not wear (no k_w of its material)
            fields["counter_wear_depth"] = lambda: self.counter_depth.copy()
        return fields

    def facet_wear_depth(self) -> np.ndarray:
        """The rough body's worn depth [m] per facet: its zone's mean and the form beyond it (0 off the zones)."""
        zone_of = self.rough.zone_of_facet
        return np.where(zone_of >= 0, np.maximum(self.form_depth + self.rough.wear_depth().mean(axis=(-2, -1))[zone_of],
                                                 0.0), 0.0)              # (round-off)

    def worn_through(self) -> str | None:
        """What the rough body wore through (``WearLimit.through``), or None (collective)."""
        return self.limit.through(self.facet_wear_depth()) if self.limit is not None else None

    def facet_flash(self) -> np.ndarray:
        """Flash temperature [K] per facet: its zone's, or the rough body's macro surface
        temperature where the zone is not loaded (or off the rough interfaces)."""
        zone_of = self.rough.zone_of_facet
        macro = self.model.thermal.facet_temperature(0) if self.model.thermal is not None else \
            np.full(self.tm.interface.n_facets, self.settings.initial_temperature)
        flash = np.where(zone_of >= 0, self.flash[zone_of], np.nan)
        return np.where(np.isfinite(flash), flash, macro)

    # ---- the run ---------------------------------------------------------------------------
    def start(self) -> StepResult:
        """Initial laws, rigid datum gap, first (ramped) solve and the initial post-analysis."""
        t0 = _time.perf_counter()
        self.rough.update_laws()
        t1 = _time.perf_counter()
        self.datum_gap = self.rough.datum_gap(self.settings.forces)
        self.set_gap()
        self.model.start()
        t2 = _time.perf_counter()
        micro = self.micro_step()
        self.apply_zone_fields()
        return StepResult(0, np.zeros(2), micro, t2 - t1, micro.seconds, t1 - t0)

    def stops(self, n: int) -> bool:
        """True if body 1 slid in step n and is at rest at its end: the step wears whatever
        ``wear_every`` (the next steps at rest are solved without friction: a wear over them took
        that pressure for the sliding before, 22 % off in a zone's share of the test pin's wear)."""
        t0, t1 = (float(f"{m * self.settings.dt:.12g}") for m in (n - 1, n))    # the model's times (step_time)
        return self.model.speed(t1) == 0.0 and self.model.drive.mean_speed(t0, t1) > 0.0

    def step(self, n: int) -> StepResult:
        """Macro step n (1, 2, ...): the macro transient and the post-analysis (iterated to the
        fixed point of the partitions with ``coupling = "fixed-point"``), wear, the new laws."""
        s = self.settings
        first = n - (n % s.wear_every or s.wear_every) + 1          # the wear interval holding step n
        interval = n - max([m for m in range(first, n) if self.stops(m)], default=first - 1)   # steps since the last wear
        wear = s.wear and self.post.wears and (n % s.wear_every == 0 or n == s.steps or self.stops(n))
        t_series = _time.perf_counter()
        self.series = self.archard(n - interval, n) if wear else np.zeros(len(self.rough.zones))
        if self.series.any():                                   # its wear at the step's end pressure, in series
            self.rough.wear_in_series(self.series)              # with the laws (backward Euler)
            self.resolve(None)
        state = self.model.snapshot() if self.iterating else None
        residuals, passes, time_macro, time_micro = [], [], _time.perf_counter() - t_series, 0.0
        while True:
            t0 = _time.perf_counter()
            heat = self.model.macro_step(s.dt, s.substeps)
            t1 = _time.perf_counter()
            micro = self.analyse()
            time_macro, time_micro = time_macro + t1 - t0, time_micro + _time.perf_counter() - t1
            if self.partition_law:
                residuals.append(self.heat_residual())
            if state is None or residuals[-1] <= s.coupling_tol:
                break
            if len(residuals) >= s.coupling_iterations:
                raise ConvergenceError(f"step {n}: the partitions did not converge in {len(residuals)} passes "
                                       f"(residual {residuals[-1]:.3g} > {s.coupling_tol:g})", residuals)
            passes.append((self.partition.copy(), self.residual()))
            self.model.restore(state)
            self.partition = anderson(passes[-ANDERSON_MEMORY - 1:], self.zone_heat(), s.relaxation)
            self.apply_zone_fields()
        self.interval_work += self.model.work_step          # the last pass's
        t2 = _time.perf_counter()
        if wear:
            micro.work, micro.wear_error, micro.wear_substeps = self.wear(s.dt * interval)
        elif self.plastic:
            self.deform()
        self.accept(micro)
        self.apply_zone_fields()
        t3 = _time.perf_counter()
        self.rough.laws_computed = 0
        changed = wear or self.plastic           # new topographies: their laws (cached if unchanged)
        if changed:
            self.rough.update_laws()
        t4 = _time.perf_counter()
        if changed:
            self.law_increment = self.resolve(self.law_increment)
        return StepResult(n, heat, micro, time_macro + _time.perf_counter() - t4, time_micro + t3 - t2, t4 - t3,
                          residuals)

    def resolve(self, guess: list | None) -> list:
        """The mechanics re-solved on the facet laws just set (``macro.continuation``; ``guess``: per-body
        displacement increments to try first), the torque kept; returns the increments of this solve."""
        mech = self.model.mechanics
        before = mech.displacements()
        self.model.last_solve = solve_on_new_laws(mech, self.rough.law, guess, self.model.released)
        self.model.keep_torque(self.model.drive.factor(self.model.time))   # the new laws moved the pressure
        self.model.stale &= self.model.released
        return [u - x for u, x in zip(mech.displacements(), before)]

    def record(self, result: StepResult) -> dict:
        """One history row (units: ``io.UNITS``)."""
        micro, on = result.micro, not self.model.released      # released: no contact (the last loads kept)
        row = self.model.record(result.heat)
        row.update(zones_in_contact=micro.loaded * on, laws_computed=self.rough.laws_computed,
                   max_zone_pressure=micro.zone_pressure * on, micro_max_pressure=micro.max_pressure * on,
                   real_contact_area=float(micro.real_area.sum()) * on, law_reach=micro.law_reach * on,
                   law_reach_halved=micro.law_reach_halved * on, near_perfect_zones=micro.near_perfect * on)
        row.update({f"real_contact_area_{n}": a * on for n, a in self.rough.interface_sums(micro.real_area).items()})
        if self.post.heating is not None:           # released: no heat to share (NaN, as the flash)
            low, mean, high = micro.partition if on else (np.nan,) * 3
            row.update(micro_max_temperature=micro.max_temperature, partition_min=low, partition_mean=mean,
                       partition_max=high, zone_flash_temperature=self.flash.copy())
        if self.partition_law:
            row.update(coupling_residual=result.residuals[-1] if result.residuals else np.nan,
                       coupling_iterations=len(result.residuals))
        if self.plastic:
            row.update(micro_plastic_fraction=micro.plastic_fraction,
                       plastic_max_depth=float(self.rough.plastic.max(initial=0.0)))
        if self.settings.wear:
            heights, depth = self.rough.heights(), self.rough.wear_depth()
            volume = self.rough.zone_wear_volume(depth)
            row.update({f"wear_volume_{n}": v for n, v in self.rough.interface_sums(volume).items()})
            row.update(wear_volume=float(volume.sum()), wear_max_depth=float(depth.max()),
                       rms_height=self.rough.rms_height(heights), frictional_work=self.work,
                       wear_rate_mean=float(volume.sum()) / self.work if self.work > 0 else np.nan,   # (user trial M)
                       wear_substep_error=result.micro.wear_error,
                       wear_substeps=result.micro.wear_substeps, **self.limit.row(self.facet_wear_depth()))
            if self.post.counter_rate is not None:
                row.update(counter_wear_volume=self.counter_volume,
                           counter_wear_max_depth=float(self.counter_depth.max(initial=0.0)))
        row.update(time_macro=result.time_macro, time_micro=result.time_micro, time_laws=result.time_laws)
        return row

    # ---- checkpoints -----------------------------------------------------------------------
    def save(self, path: Path, step: int, history: io.History) -> None:
        """Checkpoint after macro step ``step`` (collective; ``checkpoint.save_step``)."""
        model_attrs, model_arrays = self.model.checkpoint_state()
        arrays = {"heights": self.rough.heights(), "warm": self.warm, "partition": self.partition,
                  **({"plastic": self.rough.plastic} if self.plastic else {}),    # else zero: not stored
                  "conductance": self.conductance, "flash": self.flash, "rates": self.rates, "counter_depth": self.counter_depth,
                  "form_depth": self.form_depth, "exchange": self.exchange, "exchange_full": self.exchange_full,
                  "levels": self.rough.levels,
                  "datum_gap": self.datum_gap, **model_arrays}
        attrs = {"work": self.work, "interval_work": self.interval_work, "counter_volume": self.counter_volume,
                 **model_attrs}
        checkpoint.save_step(path, self.comm, step, history, self.fingerprint, attrs, arrays, self.model)

    def restore(self, path: Path) -> checkpoint.Restored:
        """State of the checkpoint ``path`` (collective)."""
        attrs, arrays = checkpoint.load(path, self.comm, self.model.functions, self.fingerprint)
        self.model.restore_checkpoint(attrs, arrays)
        self.rough.set_heights(range(len(arrays["heights"])), arrays["heights"])
        if self.plastic:
            self.rough.plastic = arrays["plastic"].copy()
        self.warm, self.partition = arrays["warm"], arrays["partition"]
        self.conductance, self.rough.levels = arrays["conductance"], arrays["levels"]
        self.datum_gap, self.flash, self.counter_depth = arrays["datum_gap"], arrays["flash"], arrays["counter_depth"]
        self.form_depth, self.rates = arrays["form_depth"], arrays["rates"]
        self.counter_volume = float(attrs["counter_volume"])
        self.exchange, self.exchange_full = arrays["exchange"], arrays["exchange_full"]
        self.work = float(attrs["work"])
        self.interval_work = float(attrs["interval_work"])
        self.set_gap()
        self.rough.update_laws()
        self.apply_zone_fields()
        return checkpoint.restored(attrs, arrays)

"""Micro-contact post-analysis of the interface zones after a macro step (thesis Fig. 7.5, §7.2).

For each zone loaded by the macro model (zone mean pressure P = macro force on the zone / zone
area, sliding speed V and direction, macro surface temperatures of both bodies):

1. local pressure: the zone's patch pressed by a rigid flat to the mean pressure P (FFT-BEM,
   isolated patch, warm-started from the zone's previous local pressure);
2. local surface temperatures and heat partition, with given remote temperatures of the two bodies
   (thesis §7.2.2: "remote temperatures are also considered as boundary conditions"; the caller
   chooses them from the macro temperatures): steady sliding heating of that contact (§6.5,
   ``SteadyHeating``) at speed V along the sliding direction, or (``Heating.transient_steps`` =
   N_t > 0, thesis Table 7.1) the transient heating of §6.3 (``TransientHeating``) over the macro
   step in N_t steps, both bodies starting uniform at their remote temperatures; its partition is
   the share of the step's heat, its temperatures those at the end of the step, its flash
   temperature the largest of the step. The share of the frictional heat into the rough body
   (``partition``) is what the macro heat split uses next; with equal remote temperatures it lies
   in [0, 1] and is clipped there (``Heating.bounded``); with different ones the heat conducted
   from the hotter body is part of it and it may leave [0, 1]. Speeds and directions are rounded
   to a relative step (``Heating``) so that the kernel tables are shared between zones; the heat
   rates are scaled back to the true speed (mu p V is linear in it; the partition is unchanged);
3. optionally the thermal contact conductance h_c of the zone at that contact
   (``laws.Conductance``, the zone-scale spreading resistance taken out);
4. Archard wear over the sliding distance s = V Δt (Eq. 3.10, dh = k_w(T) mu p ds, or k(T) p ds by a specific
   wear rate, ``per_load``; T the local surface temperature of step 2, or with ``wear_at_macro`` the
   remote one): ``substeps`` increments, each a load-controlled solve of the
   worn patch warm-started from the previous pressure (§3.5.1), linearly implicit: the depth of
   the pressure after the increment acts as a Winkler layer in that solve (stable at any wear
   rate, where the explicit increments of the thesis amplify grid-scale relief beyond
   ``wear.stable_substeps``); a temperature-dependent k_w's excess over each zone's least is
   explicit (as many increments as keep it stable). ``run`` does it
   when given the sliding; ``wear`` does it later on a ``run`` made without (the coupled loop
   iterates steps 1–3 and wears once, at the converged state).

The rough body's topography wears; with ``counter_rate`` the counter-face (the rigid flat of
``contact.py``, the sliding body 1) loses the volume ∫ k_w,c(T_1) mu p ds dA of the same contact,
T_1 its own surface temperature (returned per zone: the caller spreads it over the counter-face's
track; it stays flat at the micro scale). The thesis wears one surface only (§7.2.1). Heights
point to the counter-face (wear lowers them), pressures are positive in compression,
temperatures in K. The worn volume of a zone is exactly ∫ k_w mu p ds over its patch: for
constant k_w it equals k_w mu P A s.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from multiscale.errors import InputError, check_count, check_field, check_instance, check_positive
from multiscale.micro.contact import ContactConvergenceError, ContactSolver
from multiscale.micro.heat_kernels import ThermalMaterial, Translation
from multiscale.micro.heating import SteadyHeating, TransientHeating
from multiscale.micro.kernels import Kernel, Winkler
from multiscale.micro.laws import Conductance
from multiscale.micro.plasticity import Hardness
from multiscale.micro.surface import Surface
from multiscale.micro.wear import WearRate, stable_substeps, wear_step
from multiscale.micro.zones import Zone

WARM_ITERATIONS = 300     # a warm-started local solve that needs more starts again from uniform


@dataclass(frozen=True)
class Heating:
    """Thermal set-up: ``moving`` (the sliding counter-face) and ``fixed`` (the rough body)
    materials; sliding speeds are rounded to a relative step ``speed_step`` and directions to
    ``angle_step`` [rad] (kernel tables are built once per rounded pair); ``transient_steps``: 0
    for steady sliding heating (§6.5), N_t > 0 for the transient heating over the macro step in
    N_t steps (§6.3, Table 7.1); ``bounded``: clip the partition to [0, 1] (for equal remote
    temperatures, where it lies there up to the solver tolerance); ``conduction``: also the
    zone's exchange G [W/K], the heat the contact conducts from the rough body to the counter-face
    per kelvin of remote difference, and the partition at equal remote temperatures (a second
    solve with the rough body's remote temperature 1 K higher: the problem is linear in the
    frictional heat and the remote temperatures, so that heat into the rough body =
    partition_equal Phi − G (theta_rough − theta_counter) exactly)."""

    moving: ThermalMaterial
    fixed: ThermalMaterial
    speed_step: float = 0.01
    angle_step: float = np.radians(2.0)
    transient_steps: int = 0
    bounded: bool = True
    conduction: bool = False

    def __post_init__(self):
        for name in ("moving", "fixed"):
            check_instance(name, getattr(self, name), ThermalMaterial, "a ThermalMaterial(kappa, diffusivity)")
        for name in ("speed_step", "angle_step"):
            object.__setattr__(self, name, check_positive(name, getattr(self, name)))

    def rounded(self, speed, angle) -> tuple[np.ndarray, np.ndarray]:
        """Speeds [m/s] and angles [rad] rounded to the table grid."""
        v = np.exp(np.round(np.log(speed) / self.speed_step) * self.speed_step)
        return v, np.round(np.asarray(angle, dtype=float) / self.angle_step) * self.angle_step


@dataclass
class ZoneResult:
    """Post-analysis of a batch of B zones (one macro step)."""

    pressure: np.ndarray          # Pa, (B, ny, nx): local pressure at the macro load, before wear
    worn_pressure: np.ndarray     # Pa, (B, ny, nx): local pressure on the worn patch (next warm start)
    heights: np.ndarray           # m, (B, ny, nx): worn topography
    depth: np.ndarray             # m, (B, ny, nx): wear depth of this step, >= 0
    volume: np.ndarray            # m^3, (B,): worn volume of this step
    max_pressure: np.ndarray      # Pa, (B,): largest local pressure before wear
    area_fraction: np.ndarray     # (B,): real contact area / zone area before wear
    max_temperature: np.ndarray   # K, (B,): largest rough-body surface temperature (NaN without heating)
    partition: np.ndarray         # (B,): share of the frictional heat into the rough body (NaN: no heating,
    #                               or a zone at zero speed or friction: no heat)
    conductance: np.ndarray       # W/(m^2 K), (B,): zone conductance h_c (NaN without)
    iterations: np.ndarray        # (B,): contact-solver iterations of the step
    load: np.ndarray = None       # Pa, (B,): the zone mean pressures
    mu: np.ndarray = None         # (B,): friction coefficients
    temperature: np.ndarray = None          # K, (B, ny, nx): rough body's surface temperature (None without heating)
    counter_temperature: np.ndarray = None  # K, (B, ny, nx): the counter-face's (None without heating)
    counter_volume: np.ndarray = None       # m^3, (B,): volume the counter-face lost (0 without its wear)
    heat: np.ndarray = None                 # W, (B,): frictional heat rate Phi of the zone (NaN without heating)
    heat_rough: np.ndarray = None           # W, (B,): heat rate into the rough body (Phi_2, with the conduction)
    exchange: np.ndarray = None             # W/K, (B,): G of ``Heating.conduction`` (NaN without)
    partition_equal: np.ndarray = None      # (B,): share into the rough body at equal remote temperatures (NaN without)
    plastic_area_fraction: np.ndarray = None  # (B,): cells at the hardness / zone cells at the macro load (0 if elastic)
    plastic: np.ndarray = None              # m, (B, ny, nx): permanent deformation of this step, >= 0 (0 if elastic)
    hardness: np.ndarray | None = None      # Pa, (B,): the hardness of each zone's solves (None: elastic)
    exchange_full: np.ndarray = None        # W/K, (B,): G of the zone in full contact, its own bulk's (NaN without)
    worn_area_fraction: np.ndarray = None   # (B,): real contact area / zone area after the wear (None: no wear)
    wear_error: np.ndarray = None           # (B,): estimated relative L2 error of the worn depth field
    #                                         (step doubling, ``PostAnalysis.wear``; 0 without wear)


class PostAnalysis:
    """The post-analysis of zones sharing one grid (see module docstring).

    ``kernel``: elastic kernel of the rough body against the counter-face (``HalfSpace`` or
    layered); ``shape`` (ny, nx) and ``dx``, ``dy`` [m] of the zone patches (isolated, not
    periodic); ``mu``: friction coefficient; ``heating``: a ``Heating`` or None (no local
    temperature: k_w is then taken at the macro temperature of the rough body); ``conductance``: a
    ``laws.Conductance`` or None; ``wear_rate``: anything ``WearRate`` accepts (temperatures in K),
    or None for no wear; ``counter_rate``: the same for the counter-face (None: it does not wear);
    ``per_load``: ``wear_rate`` is a specific wear rate k per normal load (dh = k p ds: mu out of
    the rough body's wear, not of the counter-face's); ``wear_at_macro``: the wear rates' tables read
    each body's remote (macro) temperature, not its local surface's with heating (the temperature a
    dynamometer's k(T) and mu(T) were measured against); ``substeps``: wear increments per step;
    ``tol``: contact tolerance; ``hardness``: a ``plasticity.Hardness`` (H, or H(T) at the rough
    body's remote temperature of each zone) for elastic-perfectly-plastic asperities, whose permanent
    deformation goes into the returned heights (before wear; the wear re-solves too), or None."""

    def __init__(self, kernel: Kernel, shape, dx: float, dy: float, *, mu: float, heating: Heating | None = None,
                 conductance: Conductance | None = None, wear_rate=None, counter_rate=None, substeps: int = 1,
                 tol: float = 1e-8, max_iter: int = 5000, hardness: Hardness | None = None, per_load: bool = False,
                 wear_at_macro: bool = False):
        self.solver = ContactSolver(kernel, shape, dx, dy, periodic=False)
        self.shape, self.dx, self.dy = tuple(shape), float(dx), float(dy)
        self.mu = check_positive("mu", mu, allow_zero=True)
        if heating is not None:
            check_instance("heating", heating, Heating, "a Heating or None")
        if conductance is not None:
            check_instance("conductance", conductance, Conductance, "a laws.Conductance or None")
        if hardness is not None:
            check_instance("hardness", hardness, Hardness, "a plasticity.Hardness or None")
        self.hardness = hardness
        self.heating, self.conductance = heating, conductance
        if heating is not None and (int(heating.transient_steps) != heating.transient_steps
                                    or heating.transient_steps < 0):
            raise InputError("transient_steps", heating.transient_steps, "0 (steady) or an integer >= 1")
        self.rate = WearRate(wear_rate) if wear_rate is not None else None
        self.per_load, self.wear_at_macro = bool(per_load), bool(wear_at_macro)
        self.counter_rate = WearRate(counter_rate) if counter_rate is not None else None
        self.substeps, self.tol = check_count("substeps", substeps), check_positive("tol", tol)
        self.max_iter = check_count("max_iter", max_iter)
        self._heaters, self._full = {}, {}      # heaters, and G_full [W/K] (``_full_exchange``), by their keys

    @property
    def wears(self) -> bool:
        """True if a body wears (the rough one or the counter-face)."""
        return self.rate is not None or self.counter_rate is not None

    def run(self, zones: list[Zone], load, *, speed, angle=0.0, remote=None, sliding=None,
            warm=None, mu=None, duration: float | None = None, hardness_temperature=None) -> ZoneResult:
        """Post-analysis of ``zones`` at zone mean pressures ``load`` [Pa] > 0 (B,).

        speed [m/s] and angle [rad from +x] of the counter-face over each zone (B,); remote (B, 2)
        [K]: remote temperatures (counter-face, rough body) — needed with heating or a
        temperature-dependent k_w (without heating, k_w is taken at each body's own); sliding
        (B,) [m]: distance worn over (None: no wear this call; see ``wear``);
        warm (B, ny, nx): previous local pressures (warm start; rows summing to 0 start cold);
        mu (B,): friction coefficient of each zone (default: the post-analysis' ``mu``);
        duration [s]: the macro step, heated over by the transient heating; hardness_temperature
        (B,) [K]: where H(T) is taken (default: the rough body's remote temperature; the loop's
        flash softening passes each zone's last flash temperature).
        """
        B = len(zones)
        triangles = [z.id for z in zones if z.triangle is not None]
        if triangles:        # its load and wear would spread over the bounding box (twice the load: a test)
            raise InputError("zones", triangles, "the post-analysis takes rectangular zones (cut_zones, "
                             "generate_zones): a triangular zone's patch covers its bounding box")
        H = np.stack([z.surface.heights for z in zones]) if B else np.zeros((0,) + self.shape)
        off = [z.id for z in zones if not np.allclose((z.surface.dx, z.surface.dy), (self.dx, self.dy), rtol=1e-9)]
        if H.shape[1:] != self.shape or off:       # (another grid's zones: ``PostAnalyses``)
            raise InputError("zones", off or H.shape[1:], f"patches of the post-analysis grid {self.shape} of "
                             f"{self.dx:.4g} x {self.dy:.4g} m cells")
        load = _per_zone("load", load, B)
        if np.any(load <= 0):
            raise InputError("load", load, "zone pressures must be > 0 (skip unloaded zones)")
        speed, angle = _per_zone("speed", speed, B), _per_zone("angle", angle, B)
        mu = np.full(B, self.mu) if mu is None else _per_zone("mu", mu, B)
        if np.any(mu < 0):
            raise InputError("mu", mu, "friction coefficients must be >= 0")
        remote = None if remote is None else _per_zone("remote", remote, B, (2,))
        nan = np.full(B, np.nan)
        if B == 0:
            empty = np.zeros((0,) + self.shape)
            arrays = {f.name: np.zeros(0) for f in fields(ZoneResult)}
            return ZoneResult(**{**arrays, **dict.fromkeys(("pressure", "worn_pressure", "heights", "depth"), empty),
                                 "iterations": np.zeros(0, dtype=int), "temperature": None,
                                 "counter_temperature": None, "plastic": empty, "hardness": None})
        hard = None
        if self.hardness is not None:
            if self.hardness.depends_on_temperature and remote is None and hardness_temperature is None:
                raise InputError("remote", None, "a temperature-dependent hardness needs temperatures")
            at = remote[:, 1] if hardness_temperature is None and remote is not None else hardness_temperature
            hard = np.broadcast_to(self.hardness(at), (B,))
            over = np.flatnonzero(load >= hard)
            if len(over):             # a fully plastic zone has no finite approach (nor a law beyond 0.9 H)
                b = over[np.argmax(load[over] / hard[over])]
                raise InputError("hardness", None, f"{len(over)} zone(s) carry a mean pressure at or above the "
                                 f"hardness of the rough body (zone {zones[b].id}: {load[b]:.3g} Pa against H = "
                                 f"{hard[b]:.3g} Pa): such a zone would be fully plastic; raise the hardness "
                                 "(materials.<name>.hardness) or lower the load")
        r = self._solve(zones, H, load, _warm(warm, H.shape), hard)
        T = T1 = None
        max_T, partition, heat, heat_rough, exchange, equal, full = (nan.copy() for _ in range(7))
        if self.heating is not None:
            if remote is None:
                raise InputError("remote", None, "heating needs the remote temperatures of both bodies")
            T, T1 = np.empty(H.shape), np.empty(H.shape)
            for b in range(B):
                if speed[b] == 0.0 or mu[b] == 0.0:     # no sliding or no friction, no heat: the bulk temperatures
                    T1[b], T[b], max_T[b], heat[b], heat_rough[b], exchange[b] = *remote[b], remote[b, 1], 0, 0, 0
                    continue
                T1[b], T[b], max_T[b], heat[b], heat_rough[b] = self._heat(r.pressure[b], speed[b], angle[b],
                                                                           mu[b], remote[b], duration)
                if self.heating.conduction:
                    warmer = remote[b] + np.array([0.0, 1.0])      # the rough body 1 K warmer
                    exchange[b] = heat_rough[b] - self._heat(r.pressure[b], speed[b], angle[b], mu[b], warmer,
                                                             duration)[-1]
                    full[b] = self._full_exchange(zones[b], speed[b], angle[b], mu[b], remote[b], duration)
            with np.errstate(divide="ignore", invalid="ignore"):
                partition = heat_rough / heat
                if self.heating.conduction:
                    equal = np.clip((heat_rough + exchange * (remote[:, 1] - remote[:, 0])) / heat, 0.0, 1.0)
            if self.heating.bounded:
                partition = np.clip(partition, 0.0, 1.0)
        h_c = nan.copy()
        if self.conductance is not None:
            h_c = np.asarray(self.conductance.values(r, zones)["conductance"], dtype=float)
        result = ZoneResult(r.pressure, r.pressure, H - r.plastic, np.zeros(H.shape), np.zeros(B),
                            r.pressure.max(axis=(-2, -1)), np.asarray(r.area_fraction, dtype=float), max_T, partition,
                            h_c, np.asarray(r.iterations).copy(), load, mu, T, T1, np.zeros(B), heat, heat_rough,
                            exchange, equal, np.asarray(r.plastic_area_fraction, dtype=float), r.plastic.copy(), hard,
                            exchange_full=full)
        if sliding is not None and self.wears:
            result = self.wear(zones, result, sliding, remote)
        return result

    def wear(self, zones: list[Zone], result: ZoneResult, sliding, remote=None,
             increments: int | None = None) -> ZoneResult:
        """Archard wear of the zones of ``result`` (``run`` of these zones without sliding) over
        ``sliding`` [m] (B,) in ``increments`` >= 2 linearly implicit increments (``_substeps``;
        default the fewest of ``increments``; pass one count agreed over the ranks of a batch split
        between them, so that the answer does not depend on the split); remote (B, 2) [K] gives
        k_w's temperatures without heating. Returns ``result`` with the worn heights, depth, volumes,
        pressures. Their error is estimated against the same wear in m = n // 2 increments, from the
        same start, discarded: ``wear_error`` = ||d_m − d_n|| m / ((n − m) ||d_n||), the first-order
        Richardson estimate of the worn depth field's relative L2 error (1.5 n contact solves
        instead of n), which the coupled loop keeps within ``wear.WEAR_TOL``. (Estimated on the real
        area fraction, as before, it was blind on coarse grids, whose cells change together: the test
        pin-on-disc's area 2.4 % off with an estimate of 0.)"""
        heights, p, load, mu = result.heights, result.pressure, result.load, result.mu
        B = len(zones)
        if B == 0:                 # a rank that holds no loaded zone
            return result
        T1 = self._wear_temperatures(result, remote)[1]
        sliding = _per_zone("sliding", sliding, B)
        start = (heights, p, result.plastic, result.area_fraction)
        n = self.increments(zones, result, sliding, remote)[0] if increments is None else \
            check_count("increments", increments, minimum=1 if self.rate is None else 2)
        C = (np.zeros(heights.shape), np.zeros(B)) if self.rate is None else \
            self._wear_compliance(result, sliding, remote)
        heights, p, depth, counter, plastic, iterations, area = self._substeps(
            zones, start, load, mu, sliding, C, T1, result.hardness, n)
        error = np.zeros(B)
        if self.rate is not None:   # the same wear in half the increments, discarded
            m = n // 2
            off = np.sqrt(((self._substeps(zones, start, load, mu, sliding, C, T1, result.hardness, m)[2]
                            - depth) ** 2).sum(axis=(-2, -1))) * m / (n - m)
            scale = np.sqrt((depth ** 2).sum(axis=(-2, -1)))
            error = np.divide(off, scale, out=np.zeros(B), where=scale > 0)
        return replace(result, worn_pressure=p, heights=heights, depth=depth,
                       volume=depth.sum(axis=(-2, -1)) * self.dx * self.dy,
                       iterations=result.iterations + iterations, counter_volume=counter,
                       plastic=plastic, worn_area_fraction=area, wear_error=error)

    def increments(self, zones: list[Zone], result: ZoneResult, sliding, remote=None) -> tuple[int, int]:
        """The fewest and the most increments of the rough body's wear of ``zones`` over ``sliding``
        [m] (B,): ``substeps`` (at least 2: ``wear`` estimates its error with half), or the more
        that keep each increment's explicit part stable (``wear.stable_substeps`` of k_w mu ds
        above each zone's implicit part, ``_wear_compliance``; k_w at the temperatures ``wear``
        takes); and those that would keep the whole of k_w mu ds stable, an explicit scheme's count
        (the most the coupled loop takes for ``wear.WEAR_TOL``: its cost stays about an explicit
        update's)."""
        if self.rate is None or not len(zones):
            return self.substeps, self.substeps
        C, c = self._wear_compliance(result, _per_zone("sliding", sliding, len(zones)), remote)
        fewest = max(2, self.substeps, stable_substeps(self.solver.operator, C - c[:, None, None]))
        return fewest, max(fewest, stable_substeps(self.solver.operator, C))

    def _wear_compliance(self, result: ZoneResult, sliding, remote) -> tuple[np.ndarray, np.ndarray]:
        """The rough body's Archard depth per pressure over the whole ``sliding`` (B,) [m], C =
        k_w(T) mu s [m/Pa] per cell (B, ny, nx), and each zone's implicit part c (B,): the least C
        over the cells in contact at the start (0 without any), so that C − c >= 0 there (the
        explicit part, taken >= 0 elsewhere too: a cell cooler than those wears at c once it
        touches; 0 for a constant k_w)."""
        T = self._wear_temperatures(result, remote)[0]
        k_w = self.rate(T) if self.rate.depends_on_temperature else self.rate()
        C = np.broadcast_to(k_w * (self._wear_mu(result.mu) * sliding)[:, None, None], result.pressure.shape)
        touching = result.pressure > 0
        least = np.min(C, axis=(-2, -1), where=touching, initial=np.inf)
        return C, np.where(touching.any(axis=(-2, -1)), least, 0.0)

    def archard_compliance(self, sliding, temperature, mu=None, rates=None) -> np.ndarray:
        """The rough body's Archard depth per pressure k_w mu s [m/Pa] of zones sliding ``sliding``
        (B,) [m]: k_w ``rates`` (B,) [1/Pa] where finite (``zone_rates``), else k_w(T) at its
        temperatures ``temperature`` (B,) [K] (read by a k_w(T) only); ``mu`` (B,) or the
        post-analysis' own; 0 without its wear."""
        s = np.asarray(sliding, dtype=float)
        if self.rate is None:
            return np.zeros(s.shape)
        k_w = self.rate(np.asarray(temperature, dtype=float))
        if rates is not None:
            k_w = np.where(np.isfinite(rates), rates, k_w)
        return k_w * self._wear_mu(self.mu if mu is None else np.asarray(mu)) * s

    def _wear_mu(self, mu):
        """The factor mu of the rough body's dh = k_w mu p ds: 1 for a rate ``per_load``."""
        return np.ones_like(mu, dtype=float) if self.per_load else mu

    def zone_rates(self, result: ZoneResult, remote=None) -> np.ndarray:
        """Each zone's k_w [1/Pa] as its wear takes it: k_w(T) at its cells' temperatures (those of
        ``wear``: the heating's fields, else ``remote``) weighted by their pressure; NaN for a zone
        without pressure or a body that does not wear. With flash heating a k_w(T) at the macro
        temperature was 4.4 times too low (a user trial: 64 against 22 degC)."""
        p = np.asarray(result.pressure, dtype=float)
        total = p.sum(axis=(-2, -1))
        if self.rate is None:
            return np.full(total.shape, np.nan)
        T = self._wear_temperatures(result, remote)[0]
        k_w = self.rate(T) if self.rate.depends_on_temperature else self.rate()
        return np.divide((k_w * p).sum(axis=(-2, -1)), total, out=np.full(total.shape, np.nan), where=total > 0)

    def _wear_temperatures(self, result: ZoneResult, remote):
        """(rough body's, counter-face's) temperatures of k_w: the heating's fields (not ``wear_at_macro``),
        else the remote temperatures spread over the zones, where a temperature-dependent rate needs them."""
        T, T1 = (None, None) if self.wear_at_macro else (result.temperature, result.counter_temperature)
        shape = result.heights.shape
        for rate, field, col in ((self.rate, "T", 1), (self.counter_rate, "T1", 0)):
            if rate is not None and rate.depends_on_temperature and (T if field == "T" else T1) is None:
                if remote is None:
                    raise InputError("remote", None, "a temperature-dependent wear rate needs temperatures")
                value = np.broadcast_to(np.broadcast_to(np.asarray(remote, float), (shape[0], 2))[:, col, None, None],
                                        shape)
                T, T1 = (value, T1) if field == "T" else (T, value)
        return T, T1

    def _substeps(self, zones, start, load, mu, sliding, compliance, T1, hardness, n):
        """Wear from ``start`` = (heights, pressure, permanent deformation, real area fraction)
        over ``sliding`` (B,) [m] in ``n`` increments of Eq. 3.10, linearly implicit: of the depth
        per pressure C = (C_cells, c) (``_wear_compliance``) over n, the part c / n takes the pressure
        after the increment (backward Euler: the contact of the heights on the solid under a
        ``Winkler`` layer c / n, one solve, stable at any c), the rest the pressure before it
        (forward Euler, stable by ``increments``). Returns (heights, pressure, depth, counter-face
        volume, permanent deformation, solver iterations, real area fraction of the last solve)."""
        heights, p, plastic, area = start
        B = len(zones)
        depth, counter, iterations = np.zeros(heights.shape), np.zeros(B), 0
        ds = sliding / n
        explicit, implicit = np.maximum(compliance[0] - compliance[1][:, None, None], 0.0) / n, compliance[1] / n
        solvers = [self._winkler(c) for c in implicit] if self.rate is not None else []
        for _ in range(n):
            if self.counter_rate is not None:       # the counter-face's volume, with the pressure before
                work = mu[:, None, None] * p * ds[:, None, None]      # mu p ds [J/m^2]
                counter += wear_step(Surface(heights, self.dx, self.dy, periodic=False), work,
                                     self.counter_rate, 1.0, 1.0, T1).volume
            if self.rate is None:
                continue
            before = explicit * p
            again = [self._solve([z], (heights[b] - before[b])[None], load[b:b + 1], p[b][None],
                                 None if hardness is None else hardness[b:b + 1], solvers[b])
                     for b, z in enumerate(zones)]
            p = np.concatenate([r.pressure for r in again])
            worn = before + implicit[:, None, None] * p
            step_plastic = np.concatenate([r.plastic for r in again])
            heights, depth = heights - worn - step_plastic, depth + worn
            plastic = plastic + step_plastic
            iterations = iterations + np.concatenate([np.atleast_1d(r.iterations) for r in again])
            area = np.concatenate([np.atleast_1d(r.area_fraction) for r in again]).astype(float)
        return heights, p, depth, counter, plastic, iterations, area

    def _winkler(self, c: float) -> ContactSolver:
        """A solver of this grid on the kernel under a ``Winkler`` layer of compliance ``c`` [m/Pa]."""
        return ContactSolver(Winkler(self.solver.kernel, float(c)), self.shape, self.dx, self.dy, periodic=False)

    def _heat(self, pressure, speed, angle, mu, remote, duration):
        """(counter-face field, rough-body field, flash temperature, Phi, Phi_2) of one zone: the
        transient heating's fields at the end of the step, its flash temperature the largest of
        the step, its heat rates the means over the step."""
        heater = self._heater(speed, angle, duration)
        remote = tuple(float(v) for v in remote)
        rounded = float(self.heating.rounded(speed, angle)[0])
        scale = speed / rounded if rounded > 0 else 1.0     # heat rates at the true speed (mu p V: linear)
        if isinstance(heater, SteadyHeating):
            h = heater.solve(pressure, mu, tol=self.tol, remote_temperatures=remote)
            return (h.temperature_1, h.temperature_2, h.temperature_2.max(), scale * float(h.heat),
                    scale * float(h.heat_2))
        h = heater.run(pressure, mu, tol=self.tol, remote_temperatures=remote, field_times=[duration])
        return (h.temperature_1[-1], h.temperature_2[-1], h.max_temperature_2.max(), scale * float(h.heat.mean()),
                scale * float(h.heat_2.mean()))

    def _full_exchange(self, zone: Zone, speed, angle, mu, remote, duration) -> float:
        """The exchange G [W/K] of ``zone`` in full contact (every cell of its mask): its bodies' own
        spreading, which the macro model resolves (``interface_exchange``); kept per mask, rounded
        speed and direction and step (linear: the frictional heat cancels), scaled to ``speed`` as
        ``_heat`` scales G (G / G_full was off by the rounding, up to 0.5 %: a review)."""
        v, a = (float(x) for x in self.heating.rounded(speed, angle))
        key = (hash(zone.mask.tobytes()), v, a, duration)
        if key not in self._full:
            if len(self._full) >= 4096:
                self._full.pop(next(iter(self._full)))
            touching = zone.mask.astype(float)                     # 1 Pa on every cell of the zone
            warmer = np.asarray(remote, float) + np.array([0.0, 1.0])
            self._full[key] = self._heat(touching, v, a, mu, remote, duration)[-1] - \
                self._heat(touching, v, a, mu, warmer, duration)[-1]
        return self._full[key] * speed / v

    def _solve(self, zones, heights, load, warm, hardness=None, solver: ContactSolver | None = None):
        """Load-controlled contact of the batch (on ``solver``, default this grid's); patches that do
        not converge within ``WARM_ITERATIONS`` from the warm start (warm starts converge in tens of
        iterations; one supported by a single cell was seen to stall for ever) are solved again from
        a uniform start with 4 x max_iter; ``ContactConvergenceError`` names those that still fail."""
        solver = solver or self.solver
        r = solver.solve(heights, load=load, initial_pressure=warm, tol=self.tol,
                         max_iter=min(self.max_iter, WARM_ITERATIONS), partial=True, hardness=hardness)
        bad = np.flatnonzero(~np.asarray(r.converged))
        if len(bad):
            again = solver.solve(heights[bad], load=load[bad], tol=self.tol, max_iter=4 * self.max_iter,
                                 partial=True, hardness=None if hardness is None else hardness[bad])
            for f in fields(r):
                if f.name not in ("history", "iterations"):
                    getattr(r, f.name)[bad] = getattr(again, f.name)
            r.iterations[bad] += again.iterations
            if not np.all(again.converged):
                failed = [zones[b].id for b in bad[~np.asarray(again.converged)]]
                raise ContactConvergenceError(f"local contact of zone(s) {failed} did not converge "
                                              f"(residual {np.max(again.residual):.3e} > {self.tol:.1e})",
                                              again.history, r)
        return r

    def _heater(self, speed: float, angle: float, duration: float | None):
        v, a = self.heating.rounded(speed, angle)
        n = int(self.heating.transient_steps)
        if n and (duration is None or not duration > 0):
            raise InputError("duration", duration, "the transient heating needs the macro step [s] > 0")
        key = (float(v), float(a)) + ((float(duration),) if n else ())
        if key not in self._heaters:
            if len(self._heaters) >= 256:
                self._heaters.pop(next(iter(self._heaters)))
            h = self.heating
            self._heaters[key] = SteadyHeating(self.shape, self.dx, h.moving, h.fixed, key[0], self.dy, key[1]) \
                if not n else TransientHeating(self.shape, self.dx, h.moving, h.fixed, Translation.steady(*key[:2]),
                                               key[2] / n, n, self.dy)
        return self._heaters[key]


SPREAD_CAP = 1e3    # the interface exchange at most this x the zone's own bulk's (in full contact: infinite)


def interface_exchange(exchange, full) -> np.ndarray:
    """The exchange G [W/K] of zones without their own bulks' spreading, which the macro model conducts
    itself: 1/(1/G − 1/G_full), G_full the zone's in full contact (``ZoneResult.exchange_full``), as
    ``laws.Conductance`` takes R_zone out of K_t (Eq. 1.31's analogue); at most ``SPREAD_CAP`` G_full;
    G where G_full is not known (with G, a trial's pads at 94-98 % real area were 100-180 K apart)."""
    G, full = np.asarray(exchange, dtype=float), np.asarray(full, dtype=float)
    known = np.isfinite(full) & (full > 0)
    share = np.where(known, G / np.where(known, full, 1.0), 0.0)
    capped = np.minimum(G / np.maximum(1.0 - share, 1.0 / SPREAD_CAP), SPREAD_CAP * np.where(known, full, 0.0))
    return np.where(known, capped, G)


def _per_zone(name, value, B, each=()) -> np.ndarray:
    """``value`` broadcast to (B, *each): finite numbers, else InputError naming it."""
    v = check_field(name, value)
    try:
        v = np.broadcast_to(v, (B, *each)).copy()
    except ValueError:
        raise InputError(f"{name}.shape", v.shape, f"an array broadcasting to {(B, *each)}, one row per zone" if each
                         else f"a scalar or one value per zone ({B})") from None
    return v


def _warm(warm, shape):
    """Warm-start pressures (None, or rows without load replaced by a uniform start)."""
    if warm is None:
        return None
    w = np.array(np.broadcast_to(np.asarray(warm, dtype=float), shape))
    cold = w.sum(axis=(-2, -1)) <= 0
    w[cold] = 1.0
    return w


def grid_of(zone: Zone) -> tuple:
    """The grid of a zone's patch: (shape, dx, dy) [-, m, m]."""
    s = zone.surface
    return s.shape, s.dx, s.dy


class PostAnalyses:
    """One ``PostAnalysis`` per zone grid, used as one (interfaces whose zones differ in cell size:
    a round pad beside a square one; the zones of all took the first one's cells, so the second
    pad's worn volume and heat came out (352.6/312.5)² = 1.27 times too large, a user trial).
    ``posts``: grid (``grid_of``) -> its ``PostAnalysis``, made with the same settings. ``run`` and
    ``wear`` hand each zone to its grid's and return one ``ZoneResult`` in the zones' order; the
    settings (``heating``, ``rate``, ...) are read from the first."""

    def __init__(self, posts: dict):
        self.posts = dict(posts)
        self.first = next(iter(self.posts.values()))

    def __getattr__(self, name):
        return getattr(self.first, name)

    def _groups(self, zones) -> list[tuple[PostAnalysis, np.ndarray]]:
        keys = [grid_of(z) for z in zones]
        unknown = sorted({k for k in keys if k not in self.posts})
        if unknown:
            raise InputError("zones", unknown, f"patches of the grids {list(self.posts)}")
        return [(p, np.flatnonzero([k == key for k in keys])) for key, p in self.posts.items()
                if key in keys] or [(self.first, np.zeros(0, dtype=int))]

    def run(self, zones: list[Zone], load, **kwargs) -> ZoneResult:
        """``PostAnalysis.run`` of each grid's zones (per-zone arguments split alike)."""
        B, groups = len(zones), self._groups(zones)
        if len(groups) == 1:
            return groups[0][0].run(zones, load, **kwargs)
        parts = [p.run([zones[i] for i in ids], _part(load, ids, B), **{k: _part(v, ids, B) for k, v in kwargs.items()})
                 for p, ids in groups]
        return _merged(parts, [ids for _, ids in groups], B)

    def increments(self, zones: list[Zone], result: ZoneResult, sliding, remote=None) -> tuple[int, int]:
        """The most of each grid's ``PostAnalysis.increments``: one range for all the zones."""
        B = len(zones)
        spans = [p.increments([zones[i] for i in ids], _result_part(result, ids, B), _part(sliding, ids, B),
                              _part(remote, ids, B)) for p, ids in self._groups(zones)]
        return max(a for a, _ in spans), max(b for _, b in spans)

    def wear(self, zones: list[Zone], result: ZoneResult, sliding, remote=None,
             increments: int | None = None) -> ZoneResult:
        """``PostAnalysis.wear`` of each grid's zones, in one count of increments (default the fewest
        of ``increments``)."""
        B, groups = len(zones), self._groups(zones)
        if increments is None:
            increments = self.increments(zones, result, sliding, remote)[0]
        if len(groups) == 1:
            return groups[0][0].wear(zones, result, sliding, remote, increments)
        parts = [p.wear([zones[i] for i in ids], _result_part(result, ids, B), _part(sliding, ids, B),
                        _part(remote, ids, B), increments) for p, ids in groups]
        return _merged(parts, [ids for _, ids in groups], B)


def _part(value, ids, B):
    """The zones ``ids`` of a per-zone argument (first axis of length B); others as they are."""
    return np.asarray(value)[ids] if value is not None and np.ndim(value) >= 1 and len(value) == B else value


def _result_part(result: ZoneResult, ids, B) -> ZoneResult:
    return replace(result, **{f.name: _part(getattr(result, f.name), ids, B) for f in fields(ZoneResult)})


def _merged(parts: list[ZoneResult], groups: list, B: int) -> ZoneResult:
    """One ``ZoneResult`` of B zones from those of the groups of zone indices ``groups``."""
    out = {}
    for f in fields(ZoneResult):
        values = [getattr(r, f.name) for r in parts]
        if all(v is None for v in values):
            out[f.name] = None
            continue
        first = np.asarray(next(v for v in values if v is not None))
        merged = np.empty((B,) + first.shape[1:], dtype=first.dtype)
        for v, ids in zip(values, groups):
            merged[ids] = v
        out[f.name] = merged
    return ZoneResult(**out)

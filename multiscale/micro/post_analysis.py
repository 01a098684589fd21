"""Micro-contact post-analysis of the interface zones after a macro step (thesis Fig. 7.5, §7.2).

For each zone loaded by the macro model (zone mean pressure P = macro force on the zone / zone
area, sliding speed V and direction, macro surface temperatures of both bodies):

1. local pressure: the zone's patch pressed by a rigid flat to the mean pressure P (FFT-BEM,
   isolated patch, warm-started from the zone's previous local pressure);
2. local surface temperature and heat partition: steady sliding heating of that contact (§6.5,
   ``SteadyHeating``) at speed V along the sliding direction, with given remote temperatures of the
   two bodies (thesis §7.2.2: "remote temperatures are also considered as boundary conditions";
   the caller chooses them from the macro temperatures); the share of the frictional heat into
   the rough body (``partition``, clipped to [0, 1]) is what the macro heat split uses next.
   Speeds and directions are rounded to a relative step (``Heating``) so that the kernel tables
   are shared between zones;
3. optionally the thermal contact conductance h_c of the zone at that contact
   (``laws.Conductance``, the zone-scale spreading resistance taken out);
4. Archard wear over the sliding distance s = V Δt (Eq. 3.10, dh = k_w(T) mu p ds, T the local
   surface temperature of step 2): ``substeps`` increments, each followed by a load-controlled
   re-solve of the worn patch warm-started from the previous pressure (§3.5.1).

Only the rough body wears; the counter-face is the rigid flat of ``contact.py``. Heights point to
the counter-face (wear lowers them), pressures are positive in compression, temperatures in K.
The worn volume of a zone is exactly ∫ k_w mu p ds over its patch: for constant k_w it equals
k_w mu P A s.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from multiscale.errors import InputError, check_count, check_instance, check_positive
from multiscale.micro.contact import ContactConvergenceError, ContactSolver
from multiscale.micro.heat_kernels import ThermalMaterial
from multiscale.micro.heating import SteadyHeating
from multiscale.micro.kernels import Kernel
from multiscale.micro.laws import Conductance
from multiscale.micro.plasticity import Hardness
from multiscale.micro.surface import Surface
from multiscale.micro.wear import WearRate, wear_step
from multiscale.micro.zones import Zone


WARM_ITERATIONS = 300     # a warm-started local solve that needs more starts again from uniform


@dataclass(frozen=True)
class Heating:
    """Thermal set-up: ``moving`` (the sliding counter-face) and ``fixed`` (the rough body)
    materials; sliding speeds are rounded to a relative step ``speed_step`` and directions to
    ``angle_step`` [rad] (steady kernel tables are built once per rounded pair)."""

    moving: ThermalMaterial
    fixed: ThermalMaterial
    speed_step: float = 0.01
    angle_step: float = np.radians(2.0)

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
    heights: np.ndarray           # m, (B, ny, nx): worn (and plastically deformed) topography
    depth: np.ndarray             # m, (B, ny, nx): wear depth of this step, >= 0
    volume: np.ndarray            # m^3, (B,): worn volume of this step
    max_pressure: np.ndarray      # Pa, (B,): largest local pressure before wear
    area_fraction: np.ndarray     # (B,): real contact area / zone area before wear
    max_temperature: np.ndarray   # K, (B,): largest rough-body surface temperature (NaN without heating)
    partition: np.ndarray         # (B,): share of the frictional heat into the rough body (NaN without)
    conductance: np.ndarray       # W/(m^2 K), (B,): zone conductance h_c (NaN without)
    iterations: np.ndarray        # (B,): contact-solver iterations of the step
    plastic_area_fraction: np.ndarray  # (B,): cells at the hardness / zone cells at the macro load (0 if elastic)
    plastic: np.ndarray           # m, (B, ny, nx): permanent deformation of this step, >= 0 (0 if elastic)


class PostAnalysis:
    """The post-analysis of zones sharing one grid (see module docstring).

    ``kernel``: elastic kernel of the rough body against the counter-face (``HalfSpace`` or
    layered); ``shape`` (ny, nx) and ``dx``, ``dy`` [m] of the zone patches (isolated, not
    periodic); ``mu``: friction coefficient; ``heating``: a ``Heating`` or None (no local
    temperature: k_w is then taken at the macro temperature of the rough body); ``conductance``: a
    ``laws.Conductance`` or None; ``wear_rate``: anything ``WearRate`` accepts (temperatures in K),
    or None for no wear; ``substeps``: wear increments per step; ``tol``: contact tolerance;
    ``hardness``: a ``plasticity.Hardness`` (H, or H(T) at the rough body's remote temperature of
    each zone) for elastic-perfectly-plastic asperities, whose permanent deformation goes into the
    returned heights (before wear; the wear re-solves are bounded too), or None (elastic).
    """

    def __init__(self, kernel: Kernel, shape, dx: float, dy: float, *, mu: float, heating: Heating | None = None,
                 conductance: Conductance | None = None, wear_rate=None, substeps: int = 1,
                 tol: float = 1e-8, max_iter: int = 5000, hardness: Hardness | None = None):
        self.solver = ContactSolver(kernel, shape, dx, dy, periodic=False)
        self.shape, self.dx, self.dy = tuple(shape), float(dx), float(dy)
        self.mu = check_positive("mu", mu, allow_zero=True)
        if heating is not None:
            check_instance("heating", heating, Heating, "a Heating or None")
        if conductance is not None:
            check_instance("conductance", conductance, Conductance, "a laws.Conductance or None")
        if hardness is not None:
            check_instance("hardness", hardness, Hardness, "a plasticity.Hardness or None")
        self.heating, self.conductance = heating, conductance
        self.rate = WearRate(wear_rate) if wear_rate is not None else None
        self.substeps, self.tol = check_count("substeps", substeps), check_positive("tol", tol)
        self.max_iter = check_count("max_iter", max_iter)
        self._heaters: dict[tuple, SteadyHeating] = {}
        self.hardness = hardness

    def run(self, zones: list[Zone], load, *, speed, angle=0.0, remote=None, sliding=None,
            warm=None, mu=None, hardness_temperature=None) -> ZoneResult:
        """Post-analysis of ``zones`` at zone mean pressures ``load`` [Pa] > 0 (B,).

        speed [m/s] and angle [rad from +x] of the counter-face over each zone (B,); remote (B, 2)
        [K]: remote temperatures (counter-face, rough body) — needed with heating or a
        temperature-dependent k_w (without heating, k_w is taken at the rough body's); sliding
        (B,) [m]: distance worn over (None: no wear this call);
        warm (B, ny, nx): previous local pressures (warm start; rows summing to 0 start cold);
        mu (B,): friction coefficient of each zone (default: the post-analysis' ``mu``);
        hardness_temperature (B,) [K]: where H(T) is taken (default: the rough body's remote
        temperature; the loop's flash softening passes each zone's last flash temperature).
        """
        B = len(zones)
        H = np.stack([z.surface.heights for z in zones]) if B else np.zeros((0,) + self.shape)
        if H.shape[1:] != self.shape:
            raise InputError("zones", H.shape[1:], f"patches of the post-analysis grid {self.shape}")
        load = _per_zone("load", load, B)
        if np.any(load <= 0):
            raise InputError("load", load, "zone pressures must be > 0 (skip unloaded zones)")
        speed, angle = _per_zone("speed", speed, B), _per_zone("angle", angle, B)
        mu = np.full(B, self.mu) if mu is None else _per_zone("mu", mu, B)
        remote = None if remote is None else np.broadcast_to(np.asarray(remote, dtype=float), (B, 2))
        nan = np.full(B, np.nan)
        if B == 0:
            empty = np.zeros((0,) + self.shape)
            return ZoneResult(empty, empty, empty, empty, np.zeros(0), *(np.zeros(0) for _ in range(6)),
                              np.zeros(0, dtype=int), np.zeros(0), empty)
        hard = None
        if self.hardness is not None:
            if self.hardness.depends_on_temperature and remote is None and hardness_temperature is None:
                raise InputError("remote", None, "a temperature-dependent hardness needs temperatures")
            at = remote[:, 1] if hardness_temperature is None and remote is not None else hardness_temperature
            hard = np.broadcast_to(self.hardness(at), (B,))
        r = self._solve(zones, H, load, _warm(warm, H.shape), hard)
        iterations = np.asarray(r.iterations).copy()
        T, max_T, partition = None, nan.copy(), nan.copy()
        if self.heating is not None:
            if remote is None:
                raise InputError("remote", None, "heating needs the remote temperatures of both bodies")
            T = np.empty(H.shape)
            for b in range(B):
                heat = self._heater(speed[b], angle[b]).solve(r.pressure[b], mu[b], tol=self.tol,
                                                              remote_temperatures=tuple(remote[b]))
                T[b] = heat.temperature_2
                max_T[b] = T[b].max()
                partition[b] = np.clip(heat.partition_2, 0.0, 1.0)
        h_c = nan.copy()
        if self.conductance is not None:
            h_c = np.asarray(self.conductance.values(r, zones)["conductance"], dtype=float)
        plastic = r.plastic.copy()
        heights, depth, p = H - plastic, np.zeros(H.shape), r.pressure
        if self.rate is not None and sliding is not None:
            if self.rate.depends_on_temperature and T is None:
                if remote is None:
                    raise InputError("remote", None, "a temperature-dependent wear rate needs temperatures")
                T = np.broadcast_to(remote[:, 1, None, None], H.shape)
            ds = _per_zone("sliding", sliding, B) / self.substeps
            for _ in range(self.substeps):
                # Archard with the per-zone sliding folded into the work density mu p ds [J/m^2]
                worn = wear_step(Surface(heights, self.dx, self.dy, periodic=False),
                                 mu[:, None, None] * p * ds[:, None, None], self.rate, 1.0, 1.0, T)
                heights, depth = worn.surface.heights, depth + worn.depth
                again = self._solve(zones, heights, load, p, hard)
                p, heights = again.pressure, heights - again.plastic
                plastic += again.plastic
                iterations += np.asarray(again.iterations)
        return ZoneResult(r.pressure, p, heights, depth, depth.sum(axis=(-2, -1)) * self.dx * self.dy,
                          r.pressure.max(axis=(-2, -1)), np.asarray(r.area_fraction, dtype=float),
                          max_T, partition, h_c, iterations, np.asarray(r.plastic_area_fraction, dtype=float),
                          plastic)

    def _solve(self, zones, heights, load, warm, hardness=None):
        """Load-controlled contact of the batch; patches that do not converge within
        ``WARM_ITERATIONS`` from the warm start (warm starts converge in tens of iterations; one
        supported by a single cell was seen to stall for ever) are solved again from a uniform
        start with 4 x max_iter; ``ContactConvergenceError`` names those that still fail."""
        r = self.solver.solve(heights, load=load, initial_pressure=warm, tol=self.tol,
                              max_iter=min(self.max_iter, WARM_ITERATIONS), partial=True, hardness=hardness)
        bad = np.flatnonzero(~np.asarray(r.converged))
        if len(bad):
            again = self.solver.solve(heights[bad], load=load[bad], tol=self.tol, max_iter=4 * self.max_iter,
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

    def _heater(self, speed: float, angle: float) -> SteadyHeating:
        v, a = self.heating.rounded(speed, angle)
        key = (float(v), float(a))
        if key not in self._heaters:
            if len(self._heaters) >= 256:
                self._heaters.pop(next(iter(self._heaters)))
            self._heaters[key] = SteadyHeating(self.shape, self.dx, self.heating.moving, self.heating.fixed,
                                               key[0], self.dy, key[1])
        return self._heaters[key]


def _per_zone(name, value, B) -> np.ndarray:
    v = np.asarray(value, dtype=float)
    try:
        v = np.broadcast_to(v, (B,)).copy()
    except ValueError:
        raise InputError(f"{name}.shape", v.shape, f"a scalar or one value per zone ({B})") from None
    if not np.all(np.isfinite(v)):
        raise InputError(name, "array with NaN/inf", "must be finite")
    return v


def _warm(warm, shape):
    """Warm-start pressures (None, or rows without load replaced by a uniform start)."""
    if warm is None:
        return None
    w = np.array(np.broadcast_to(np.asarray(warm, dtype=float), shape))
    cold = w.sum(axis=(-2, -1)) <= 0
    w[cold] = 1.0
    return w

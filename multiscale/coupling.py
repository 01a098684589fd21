"""The multiscale loop: rough per-zone laws in the macro model, wear, checkpoints (thesis §1.4–1.5,
ch. 7, Figs. 7.2–7.5).

The interface face of the rough body (body 0: pin, pads, block) is cut into a grid of zones
([micro] zones), each carrying its own micro patch ([roughness]: one generated or measured surface
cut into zones, or one generated patch per zone). Effect ``roughness`` replaces the perfect-contact
penalty by the zones' homogenized laws, embedded per facet (a facet follows the zone holding its
midpoint): the nonlinear p_n(g_n) of each zone inside the UFL contact form with its consistent
tangent (``macro.laws_ufl.FacetLaw``); with ``heat_partition`` and ``micro.partition_law`` the
share p_1 of the frictional heat into the rough body per facet from the micro heating; with
``conductance`` h_c per facet from the micro conduction; with ``layers`` the rough body's micro
solid is layered.

One macro step Δt (Fig. 7.2) runs:

1. the macro transient over Δt in ``time.substeps`` thermo-mechanical sub-steps δt with the
   current laws and partitions (Fig. 7.4; ``macro.runner.MacroModel.macro_step``);
2. per zone, the macro loading at the end of the step: zone pressure P = (contact force on the
   zone's facets) / (zone area) — so that the micro patch carries the macro force —, the facet
   temperatures of both bodies, the sliding speed and direction at the zone centre;
3. the micro post-analysis of the loaded zones (Fig. 7.5, ``micro.post_analysis``): local pressure
   under P, local surface temperature and partition (steady sliding heating, both bodies' remote
   temperatures at the rough body's macro surface temperature: the macro field already holds the
   zone-scale heating, and feeding the macro temperature difference of the two surfaces back into
   the micro partition double counts it and makes the explicit coupling oscillate), and with
   ``wear`` every ``wear.update_every`` steps the Archard wear of the
   patch over the sliding of those steps with k_w(T) (default table: the shape of thesis Fig. 7.9);
   the zones are spread over the MPI ranks and the worn topographies shared;
4. the laws of the zones whose topography changed are recomputed (``pool.MicroPool``: the others
   come from its cache), the facet laws updated and the mechanics re-solved at the same time: the
   macro temperature field carries over to the next step unchanged.

The initial laws are computed before the first solve; the rigid datum gap (the uniform initial
gap g_0 at which the rigid rough body carries the load) starts Newton close to equilibrium. The
partitions of step n + 1 come from the heating of step n's post-analysis (explicit coupling).

Every step writes a checkpoint (``checkpoint.h5``: macro fields, zone topographies, per-zone state,
history), so that ``multiscale run --resume`` continues a killed run and ends with the same history
as an uninterrupted one (to solver tolerance: the resumed run recomputes its zone laws); then the
fields of output steps. Results: ``history.h5`` and ``history.png`` (macro), ``multiscale.png``
(max pressure and temperature at both scales, partition min/mean/max, wear volume, max wear depth,
RMS of the worn surface: Figs. 7.12, 7.14–7.18), ``wear_map.png`` (Fig. 7.13), ``zones.h5`` (final
per-zone state) and XDMF fields (the interface adds per-facet stiffness, partition and wear depth).
"""
from __future__ import annotations

from multiscale.macro import _dolfinx  # noqa: F401,I001  (before DOLFINx)
import dataclasses
import gc
import time as _time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from multiscale import checkpoint, io
from multiscale.errors import InputError
from multiscale.macro import mesh as _mesh
from multiscale.macro.geometry import Rotation
from multiscale.macro.laws_ufl import FacetLaw
from multiscale.macro.mechanics import SolveResult
from multiscale.macro.runner import RunResult, _FieldOutput, build_model, prepare_folder
from multiscale.micro.conduction import SeriesKernel
from multiscale.micro.heat_kernels import ThermalMaterial
from multiscale.micro.kernels import HalfSpace, ThermalHalfSpace
from multiscale.micro.laws import Conductance, LawError, LawSpec, ZoneLaws
from multiscale.micro.post_analysis import Heating, PostAnalysis
from multiscale.micro.surface import Surface, fractal_surface, load_surface
from multiscale.micro.zones import ZoneGrid, cut_zones, generate_zones
from multiscale.pool import MicroPool

P_MAX_FACTOR = 20.0        # default top node of the laws: 20 x the nominal interface pressure
P_MAX_HALVINGS = 4         # a zone whose law fails is retried with p_max / 2, ... / 16
LOADED = 1e-9              # zones below this fraction of the nominal pressure are unloaded
CHECKPOINT = "checkpoint.h5"


# ------------------------------------------------------------------ set-up from the scene
def interface_box(tm) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (x, y) [m] of the interface; it must lie in a plane z = const."""
    x = tm.interface.mesh.geometry.x
    comm = tm.comm
    lo, hi = np.empty(3), np.empty(3)
    comm.Allreduce(x.min(axis=0) if len(x) else np.full(3, np.inf), lo, op=MPI.MIN)
    comm.Allreduce(x.max(axis=0) if len(x) else np.full(3, -np.inf), hi, op=MPI.MAX)
    if hi[2] - lo[2] > 1e-9 * max(hi[0] - lo[0], hi[1] - lo[1]):
        raise InputError("geometry.builder", tm.spec, "the rough interface must lie in a plane z = const")
    return lo[:2], hi[:2]


def make_zones(scene, lo, hi) -> tuple[ZoneGrid, list]:
    """The zone grid over the interface box [lo, hi] and each zone's initial patch ([roughness],
    [micro]): a measured surface or one generated for the whole face cut into zones (one datum:
    the face's mean plane), or one generated patch per zone (``patch = "zone"``)."""
    r, m = scene.roughness, scene.micro
    counts = tuple(int(c) for c in m.zones)
    size = np.asarray(hi, float) - np.asarray(lo, float)
    if r.file is not None:
        surface = load_surface(r.file, *r.pixel_size, scale=r.height_unit)
        if np.any(np.array(surface.size) < size * (1 - 1e-6)):
            raise InputError("roughness.pixel_size", r.pixel_size, f"the surface ({surface.size[0]:.4g} x "
                             f"{surface.size[1]:.4g} m) must cover the interface ({size[0]:.4g} x {size[1]:.4g} m)")
        return cut_zones(surface, counts, origin=tuple(lo))
    cells = (counts[0] * m.grid[0], counts[1] * m.grid[1])
    if r.patch == "face":
        s = fractal_surface(cells, tuple(size), r.hurst, r.k_min, r.k_max, r.rms, seed=r.seed)
        return cut_zones(Surface(s.heights, s.dx, s.dy, periodic=False), counts, origin=tuple(lo))
    grid = ZoneGrid(tuple(lo), counts, tuple(size / np.array(counts)))
    return grid, generate_zones(grid, tuple(m.grid), r.hurst, r.k_min, r.k_max, r.rms, seed=r.seed)


def _materials(scene):
    """Materials at the interface: (rough body 0, counter-face body 1)."""
    return tuple(scene.materials[b.regions[0].material] for b in scene.geometry.spec.bodies)


def contact_kernel(scene):
    """Elastic micro kernel of the rough body against the counter-face (layered with ``layers``)
    and the composite modulus E* of the macro bodies for Love's correction (Eq. 1.31)."""
    rough, counter = _materials(scene)
    E_star = HalfSpace.from_materials(rough.E, rough.nu, counter.E, counter.nu).E_star
    if not scene.has("layers"):
        return HalfSpace(E_star), E_star
    from multiscale.micro.layered import LayeredElastic
    L = scene.layers
    substrate = rough.E if L.base == "half-space" else np.inf
    layered = LayeredElastic(tuple(x.thickness for x in L.layer), tuple(x.E for x in L.layer),
                             tuple(x.nu for x in L.layer), substrate, rough.nu)
    return SeriesKernel(layered, HalfSpace.from_materials(counter.E, counter.nu)), E_star


def thermal_kernels(scene):
    """Steady thermal kernels (rough body, counter-face) for the zone conductance (layered with
    ``layers``: each layer's kappa on the rough body, or on an isothermal base)."""
    rough, counter = _materials(scene)
    first = ThermalHalfSpace(rough.kappa)
    if scene.has("layers"):
        from multiscale.micro.layered import LayeredThermal
        L = scene.layers
        if any(x.kappa is None for x in L.layer):
            raise InputError("layers.layer.kappa", None, 'every layer needs kappa with effect "conductance"')
        first = LayeredThermal(tuple(x.thickness for x in L.layer), tuple(x.kappa for x in L.layer),
                               rough.kappa if L.base == "half-space" else np.inf)
    return first, ThermalHalfSpace(counter.kappa)


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


# ------------------------------------------------------------------ the loop
class Multiscale:
    """A scene with effect ``roughness``: macro model, zones, laws and their evolution."""

    def __init__(self, scene, comm=MPI.COMM_WORLD, progress: bool = False):
        if not scene.has("roughness"):
            raise InputError("effects", sorted(scene.effects), 'the multiscale loop needs effect "roughness"')
        self.scene, self.comm = scene, comm
        bodies = scene.geometry.bodies
        if scene.roughness.body != bodies[0]:
            raise InputError("roughness.body", scene.roughness.body,
                             f'the rough body must be the stationary one, "{bodies[0]}" (zones do not move)')
        if scene.micro.model != "fft-bem":
            raise InputError("micro.model", scene.micro.model, 'the multiscale loop computes its zone laws by '
                             'FFT-BEM: "fft-bem"')
        if scene.has("layers") and scene.layers.body != bodies[0]:
            raise InputError("layers.body", scene.layers.body, f'the layers belong to the rough body "{bodies[0]}"')
        tm = _mesh.build(scene.geometry.builder, dict(scene.geometry.params), comm)
        self.tm = tm
        lo, hi = interface_box(tm)
        self.grid, zones = make_zones(scene, lo, hi)
        self.zones = list(zones)
        self.initial = np.stack([z.surface.heights for z in zones])
        mid = tm.interface.midpoints
        self.zone_of_facet = self.grid.zone_of(mid[:, 0], mid[:, 1])
        self.zone_area = np.array([z.area for z in zones])
        Z = len(zones)
        kernel, E_star = contact_kernel(scene)
        self.law = FacetLaw(tm, scene.micro.law_points)
        self.model = build_model(scene, comm, law=self.law, tm=tm)
        self.total_force = self._total_force()
        self.nominal = self.total_force / tm.interface.areas.sum()
        p_max = scene.micro.p_max or P_MAX_FACTOR * self.nominal
        self.spec = LawSpec(kernel, p_max, n_points=scene.micro.law_points, tol=scene.micro.tol, E_star=E_star)
        self.pool = MicroPool(self.spec, comm, progress=progress)
        self.levels = np.zeros(Z, dtype=int)          # p_max halvings of each zone's law
        s = zones[0].surface
        thermal = scene.has("thermal")
        rough, counter = _materials(scene)
        heating = None
        if thermal and scene.has("heat_partition"):
            heating = Heating(ThermalMaterial(counter.kappa, counter.diffusivity),
                              ThermalMaterial(rough.kappa, rough.diffusivity))
        self.partition_law = heating is not None and scene.micro.partition_law
        wear_rate = scene.wear.rate if scene.has("wear") else None
        mu = scene.loading.friction if scene.has("friction") else 0.0
        self.post = PostAnalysis(kernel, s.shape, s.dx, s.dy, mu=mu, heating=heating,
                                 conductance=Conductance(*thermal_kernels(scene)) if scene.has("conductance") else None,
                                 wear_rate=wear_rate, substeps=scene.wear.substeps if scene.has("wear") else 1,
                                 tol=scene.micro.tol)
        self.partition = np.full(Z, float(scene.partition)) if scene.has("heat_partition") else np.full(Z, np.nan)
        self.conductance = np.zeros(Z)
        self.warm = np.zeros(self.initial.shape)      # previous local pressures (warm starts)
        self.work = 0.0                               # J, frictional work over the wear intervals
        self.datum_gap = 0.0                          # m, uniform initial gap g_0
        self.laws_computed = 0

    # ---- laws ------------------------------------------------------------------------------
    def _total_force(self) -> float:
        """The load the interface carries [N] (normal force, or pressure times the loaded area)."""
        ld, tm = self.scene.loading, self.tm
        if ld.normal_force is not None:
            return ld.normal_force
        return ld.pressure * sum(tm.assemble_scalar(1.0 * tm.ds(tm.face(f))) for f in tm.spec.load_faces)

    def _spec(self, level: int) -> LawSpec:
        return dataclasses.replace(self.spec, p_max=self.spec.p_max / 2**level)

    def update_laws(self) -> int:
        """Laws of every zone (cached ones reused), loaded into the facet law; returns how many
        were computed. A zone whose law fails (close to full contact below p_max) is retried with
        a halved p_max, up to ``P_MAX_HALVINGS`` times (remembered for its later laws)."""
        comm, nodes, computed = self.comm, [], 0
        for level in range(P_MAX_HALVINGS + 1):
            todo = [z for z in self.zones if self.levels[z.id] == level]
            if not todo:
                continue
            try:
                laws = self.pool.laws(todo[comm.rank::comm.size], self._spec(level), gather="all")
            except LawError as exc:
                if level == P_MAX_HALVINGS:
                    raise
                laws = exc.result
                self.levels[[f.zone_id for f in exc.failures]] = level + 1
            computed += self.pool.stats.computed - self.pool.stats.failed
            nodes += laws.nodes if laws is not None else []
        self.law.set_laws(ZoneLaws(nodes, self.spec), self.zone_of_facet)
        self.laws_computed = computed
        return computed

    def rigid_gap(self) -> float:
        """Uniform gap g_0 [m] at which the rigid rough body carries the load (bisection)."""
        areas = self.tm.interface.areas
        laws = self.law.laws
        rows = laws.rows(self.zone_of_facet)
        g_open = laws.mechanical.g_open[rows]
        force = lambda G: float(areas @ self.law.evaluate(np.full(len(areas), G))[0])  # noqa: E731
        hi = g_open.max()
        step = max(np.median(g_open - laws.mechanical.gap[rows, -1]), 1e-12)
        lo = hi - step
        while force(lo) < self.total_force:
            step *= 2
            lo = hi - step
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if force(mid) > self.total_force else (lo, mid)
            if hi - lo <= 1e-13 * step:
                break
        return 0.5 * (lo + hi)

    # ---- macro <-> micro -------------------------------------------------------------------
    def loading(self) -> ZoneLoading:
        """Per-zone macro loading at the current state (every rank gets the same arrays)."""
        iface, model, Z = self.tm.interface, self.model, len(self.zones)
        facet_force = model.contact.facet_pressure() * iface.areas
        force = np.bincount(self.zone_of_facet, facet_force, minlength=Z)
        area = np.bincount(self.zone_of_facet, iface.areas, minlength=Z)
        T = np.full((Z, 2), self.scene.time.initial_temperature)
        if model.thermal is not None:
            for col, side in ((0, 1), (1, 0)):
                total = np.bincount(self.zone_of_facet, model.thermal.facet_temperature(side) * iface.areas,
                                    minlength=Z)
                T[:, col] = np.where(area > 0, total / np.where(area > 0, area, 1.0), T[:, col])
        centres = np.array([z.centre for z in self.zones])
        motion = self.tm.spec.motion
        speed = model.speed(model.time)
        if isinstance(motion, Rotation):
            axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis)
            r = np.column_stack([centres, np.zeros(Z)]) - np.asarray(motion.centre, float)
            w = speed * np.cross(axis, r)[:, :2]
        else:
            e = np.asarray(motion.direction, float) / np.linalg.norm(motion.direction)
            w = np.tile(speed * e[:2], (Z, 1))
        return ZoneLoading(force, force / self.zone_area, np.hypot(w[:, 0], w[:, 1]),
                           np.arctan2(w[:, 1], w[:, 0]), T)

    def micro_step(self, wear: bool, duration: float = 0.0) -> MicroStep:
        """Post-analysis of the loaded zones at the current macro state; with ``wear`` the zones
        wear over ``duration`` [s] of sliding (their topographies change)."""
        t0 = _time.perf_counter()
        comm, load = self.comm, self.loading()
        loaded = np.flatnonzero(load.pressure > LOADED * self.nominal)
        mine = loaded[comm.rank::comm.size]
        sliding = load.speed[mine] * duration if wear else None
        rough = load.temperature[mine, 1]
        res = self.post.run([self.zones[i] for i in mine], load.pressure[mine], speed=load.speed[mine],
                            angle=load.angle[mine], remote=np.column_stack([rough, rough]), sliding=sliding,
                            warm=self.warm[mine])
        parts = comm.allgather((mine, res.worn_pressure, res.heights if wear else None, res.max_pressure,
                                res.max_temperature, res.partition, res.conductance))
        max_p, max_T, partition = [], [], []
        for ids, warm, heights, mp, mT, part, h_c in parts:
            self.warm[ids] = warm
            for i, zid in enumerate(ids):
                if heights is not None:
                    self.zones[zid] = self.zones[zid].with_heights(heights[i])
            if self.partition_law:
                self.partition[ids] = part
            if self.post.conductance is not None:
                self.conductance[ids] = h_c
            max_p.append(mp)
            max_T.append(mT)
        if self.post.conductance is not None:
            self.conductance[np.setdiff1d(np.arange(len(self.zones)), loaded)] = 0.0
        work = sum(self.model.contact.heat_power()) * duration if wear else 0.0   # mu ∫ p |w| dA Δt
        self.work += work
        max_p, max_T = np.concatenate(max_p), np.concatenate(max_T)
        used = self.partition[loaded] if len(loaded) else np.full(1, np.nan)
        return MicroStep(len(loaded), float(load.pressure.max()), float(max_p.max(initial=0.0)),
                         float(max_T.max()) if len(max_T) and np.isfinite(max_T).any() else np.nan,
                         (float(used.min()), float(used.mean()), float(used.max())), work,
                         _time.perf_counter() - t0)

    def apply_zone_fields(self) -> None:
        """Per-facet partition (micro partition law) and conductance from the zones."""
        contact, iface = self.model.contact, self.tm.interface
        if self.partition_law:
            iface.set_field(contact.partition, self.partition[self.zone_of_facet])
        if self.post.conductance is not None:
            iface.set_field(contact.conductance, self.conductance[self.zone_of_facet])

    def heights(self) -> np.ndarray:
        """Current zone topographies (Z, ny, nx) [m]."""
        return np.stack([z.surface.heights for z in self.zones])

    def wear_depth(self) -> np.ndarray:
        """Accumulated wear depth fields (Z, ny, nx) [m]."""
        return self.initial - self.heights()

    def zone_wear_volume(self, depth: np.ndarray) -> np.ndarray:
        """Worn volume of each zone [m^3] from its depth field (Z, ny, nx) [m]."""
        s = self.zones[0].surface
        return depth.sum(axis=(-2, -1)) * s.dx * s.dy

    def facet_fields(self) -> dict:
        """Interface output fields of the multiscale loop: name -> per-facet array maker."""
        iface, contact = self.tm.interface, self.model.contact
        return {"contact_stiffness": lambda: self.law.evaluate(contact.facet_gap())[1],
                "partition": lambda: iface.values(contact.partition),
                "wear_depth": lambda: self.wear_depth().mean(axis=(-2, -1))[self.zone_of_facet]}

    # ---- the run ---------------------------------------------------------------------------
    def start(self) -> tuple[MicroStep, dict]:
        """Initial laws, rigid datum gap, first (ramped) solve and the initial post-analysis;
        returns the post-analysis and wall times [s]."""
        t0 = _time.perf_counter()
        self.update_laws()
        t1 = _time.perf_counter()
        self.datum_gap = self.rigid_gap()
        self.tm.interface.set_field(self.model.contact.initial_gap, self.datum_gap)
        self.model.start()
        t2 = _time.perf_counter()
        micro = self.micro_step(wear=False)
        self.apply_zone_fields()
        return micro, {"time_macro": t2 - t1, "time_micro": micro.seconds, "time_laws": t1 - t0}

    def step(self, n: int) -> tuple[np.ndarray, MicroStep, dict]:
        """Macro step n (1, 2, ...): the macro transient, the post-analysis, the new laws.
        Returns the heat put into each body [J], the post-analysis and wall times [s]."""
        t = self.scene.time
        t0 = _time.perf_counter()
        heat = self.model.macro_step(t.dt, t.substeps)
        t1 = _time.perf_counter()
        wear = self.scene.has("wear") and n % self.scene.wear.update_every == 0
        micro = self.micro_step(wear, t.dt * self.scene.wear.update_every if wear else 0.0)
        self.apply_zone_fields()
        t2 = _time.perf_counter()
        self.laws_computed = 0
        if wear:
            self.update_laws()
        t3 = _time.perf_counter()
        if wear:
            self.model.last_solve = self.model.mechanics.solve()
        return heat, micro, {"time_macro": t1 - t0 + _time.perf_counter() - t3, "time_micro": t2 - t1,
                             "time_laws": t3 - t2}

    def record(self, heat, micro: MicroStep, timing: dict) -> dict:
        """One history row (units: ``io.UNITS``)."""
        row = self.model.record(heat)
        row.update(zones_in_contact=micro.loaded, laws_computed=self.laws_computed,
                   max_zone_pressure=micro.zone_pressure, micro_max_pressure=micro.max_pressure)
        if self.post.heating is not None:
            row.update(micro_max_temperature=micro.max_temperature, partition_min=micro.partition[0],
                       partition_mean=micro.partition[1], partition_max=micro.partition[2])
        if self.scene.has("wear"):
            heights = self.heights()
            depth = self.initial - heights
            row.update(wear_volume=float(self.zone_wear_volume(depth).sum()), wear_max_depth=float(depth.max()),
                       rms_height=float(np.sqrt(np.mean((heights - heights.mean()) ** 2))),
                       frictional_work=self.work)
        row.update(timing)
        return row

    # ---- checkpoints -----------------------------------------------------------------------
    def _functions(self) -> dict:
        m = self.model
        out = {f"u{i}": u for i, u in enumerate(m.mechanics.u)}
        if m.thermal is not None:
            out.update({f"T{i}": T for i, T in enumerate(m.thermal.T)})
        return out

    def fingerprint(self) -> str:
        """Hash of what the results depend on (not the output section; effects sorted: a set's
        order changes between processes)."""
        s = dataclasses.replace(self.scene, output=None, source=None, warnings=(),
                                effects=tuple(sorted(self.scene.effects)))
        return checkpoint.fingerprint(repr(s))

    def save(self, path: Path, step: int, history: io.History) -> None:
        m, last = self.model, self.model.last_solve
        arrays = {"heights": self.heights(), "warm": self.warm,
                  "partition": self.partition, "conductance": self.conductance, "levels": self.levels,
                  "heat_total": m.heat_total, **{f"history/{k}": np.asarray(v) for k, v in history.columns.items()}}
        attrs = {"step": step, "time": m.time, "work": self.work, "datum_gap": self.datum_gap,
                 "scene": self.fingerprint(), "ranks": self.comm.size, "fields_written": -1,
                 "solve": [last.reason, last.iterations, last.normal_force, last.max_pressure]}
        checkpoint.save(path, self.comm, attrs=attrs, arrays=arrays, functions=self._functions(),
                        scale=self.tm.spec.length_scale)

    def restore(self, path: Path) -> tuple[int, io.History, int]:
        """State of the checkpoint ``path``; returns (step, history, last step whose fields were written)."""
        attrs, arrays = checkpoint.load(path, self.comm, self._functions())
        if attrs["scene"] != self.fingerprint():
            raise InputError("--resume", str(path), "the scene changed since this checkpoint was written; "
                             "run it with --overwrite")
        m = self.model
        for zid, h in enumerate(arrays["heights"]):
            self.zones[zid] = self.zones[zid].with_heights(h)
        self.warm, self.partition = arrays["warm"], arrays["partition"]
        self.conductance, self.levels = arrays["conductance"], arrays["levels"]
        m.heat_total = arrays["heat_total"].copy()
        m.time, self.work, self.datum_gap = float(attrs["time"]), float(attrs["work"]), float(attrs["datum_gap"])
        if m.thermal is not None:
            m.thermal.time = m.time
        reason, its, force, max_p = attrs["solve"]
        m.last_solve = SolveResult(True, int(reason), int(its), [], float(force), float(max_p))
        self.tm.interface.set_field(m.contact.initial_gap, self.datum_gap)
        m.contact.speed.value = m.speed(m.time)
        m.mechanics.load.value = m.load()
        self.update_laws()
        self.apply_zone_fields()
        history = io.History()
        history.columns = {k[len("history/"):]: list(v) for k, v in arrays.items() if k.startswith("history/")}
        return int(attrs["step"]), history, int(attrs["fields_written"])


def _mark_fields(path: Path, step: int, comm) -> None:
    if comm.rank == 0:
        import h5py
        with h5py.File(path, "r+") as h5:
            h5.attrs["fields_written"] = step
    comm.barrier()


@dataclass
class MultiscaleResult(RunResult):
    """``RunResult`` plus the multiscale plots and the final per-zone state."""

    multiscale_plot: Path | None = None
    wear_map: Path | None = None
    zones_file: Path | None = None
    steps_done: int = 0


def run(scene, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True,
        stop_after: int | None = None) -> MultiscaleResult:
    """Run a scene with effect ``roughness`` (``multiscale run``): see the module docstring.

    ``resume`` continues from ``checkpoint.h5`` in the output folder; ``stop_after`` ends the run
    after that macro step's checkpoint (as if it had been killed then; for tests).
    """
    start = _time.perf_counter()
    io.abort_on_exception(comm)
    folder = prepare_folder(scene, overwrite, resume, comm)
    ckpt = folder / CHECKPOINT
    if resume and not comm.bcast(ckpt.is_file() if comm.rank == 0 else None, root=0):
        raise InputError("--resume", str(folder), f"no {CHECKPOINT} in the output folder to resume from")
    ms = Multiscale(scene, comm, progress=verbose and comm.rank == 0)
    steps = scene.time.steps if (ms.model.thermal is not None or scene.has("wear")) else 0
    every = scene.output.every
    if resume:
        done, history, written = ms.restore(ckpt)
    else:
        micro, timing = ms.start()
        done, history, written = 0, io.History(), -1
        history.append(**ms.record((0.0, 0.0), micro, timing))
        ms.save(ckpt, 0, history)
    ms.pool.progress = False
    writer = _FieldOutput(ms.model, folder, scene.output.fields, extra=ms.facet_fields(), append=resume)
    if written < done and (done % every == 0 or done == steps):
        writer.write()
        _mark_fields(ckpt, done, comm)
    todo = range(done + 1, steps + 1) if stop_after is None else range(done + 1, min(steps, stop_after) + 1)
    for n in io.progress(todo, comm, desc=scene.name, unit="step", initial=done, total=steps):
        heat, micro, timing = ms.step(n)
        history.append(**ms.record(heat, micro, timing))
        ms.save(ckpt, n, history)
        if n % every == 0 or n == steps:
            writer.write()
            _mark_fields(ckpt, n, comm)
        done = n
    writer.close()
    files = _write_results(ms, folder, history, comm)
    result = MultiscaleResult(folder, history, files["history"], files["plot"], writer.files,
                              _time.perf_counter() - start, files["multiscale"], files["wear_map"],
                              files["zones"], done)
    del ms, writer            # the model holds reference cycles of PETSc objects: free them on every
    gc.collect()              # rank at the same point (collected later, ranks could hang at exit)
    if verbose and comm.rank == 0:
        print(f"{scene.name}: {len(history)} records ({done}/{steps} steps) in {result.wall_time:.1f} s "
              f"on {comm.size} rank(s)")
        print(f"  ParaView: {', '.join(str(f) for f in result.field_files)}")
        print(f"  history:  {files['history']}  plots: {files['plot']}, {files['multiscale']}"
              + (f", {files['wear_map']}" if files["wear_map"] else ""))
    return result


def _write_results(ms: Multiscale, folder: Path, history: io.History, comm) -> dict:
    """history.h5/.png, multiscale.png, wear_map.png (with wear) and zones.h5 (rank 0 writes)."""
    from multiscale import coupling_plots
    files = {"history": folder / "history.h5", "plot": folder / "history.png",
             "multiscale": folder / "multiscale.png", "zones": folder / "zones.h5",
             "wear_map": folder / "wear_map.png" if ms.scene.has("wear") else None}
    depth = ms.wear_depth()
    if comm.rank == 0:
        import h5py
        history.write(files["history"], {"scene": ms.scene.name, "ranks": comm.size})
        history.plot(files["plot"], title=ms.scene.name)
        coupling_plots.history_figure(history, files["multiscale"], ms.scene.name)
        with h5py.File(files["zones"], "w") as h5:
            h5.create_dataset("centre", data=np.array([z.centre for z in ms.zones])).attrs["unit"] = "m"
            h5.create_dataset("mean_wear_depth", data=depth.mean(axis=(-2, -1))).attrs["unit"] = "m"
            h5.create_dataset("max_wear_depth", data=depth.max(axis=(-2, -1))).attrs["unit"] = "m"
            h5.create_dataset("wear_volume", data=ms.zone_wear_volume(depth)).attrs["unit"] = "m^3"
            h5.create_dataset("partition", data=ms.partition)
            h5.create_dataset("conductance", data=ms.conductance).attrs["unit"] = "W/(m^2 K)"
            h5.attrs["counts"] = ms.grid.counts
        if files["wear_map"] is not None:
            coupling_plots.wear_map(ms.grid, depth, files["wear_map"], ms.scene.name)
    comm.barrier()
    return files


__all__ = ["Multiscale", "MultiscaleResult", "ZoneLoading", "contact_kernel", "interface_box", "make_zones",
           "run", "thermal_kernels"]

"""Homogenized interface laws of the zones of a macro contact interface (thesis §1.4.2, Eqs.
1.29–1.31; §4.2.1; §7.2).

For each zone (``multiscale.micro.zones.Zone``: a rectangle 2a × 2b or a triangle with its own
roughness patch) the FFT-BEM contact solver gives the micro mean pressure p_n(δ) at rigid approaches
δ (displacement control, an isolated non-periodic patch as in the thesis). The macro model sees a
flat interface: loading the zone by the uniform pressure p_n moves its surface by
U = L p_n/(π E*) (Love, Eq. 1.29–1.30; Boussinesq on a triangle), so the law is tabulated against
the *macro gap* left once that elastic part is taken out (Eq. 1.31):

    g_n = (z_top − δ) + L p_n / (π E*)            [m]

where z_top − δ is the height of the rigid flat above the zones' common datum (see zones.py).
Sign: g_n > 0 is an open macro gap; the zone first touches at g_n = z_top ('g_open') and the
pressure grows as g_n decreases; the thesis's gap of Eq. 1.31 (an interpenetration) is
z_top − g_n. Stiffness K_n = −dp_n/dg_n ≥ 0. A macro model whose interface meshes start
conforming (mesh gap 0) passes g_n = g_mesh + g_ref, with g_ref the height above the datum of
its initial contact plane (e.g. the highest zone top: the first zone then touches at once).

Where L is evaluated (``LawSpec.love``): 'average' (default) uses the mean of Love's integral over
the footprint, i.e. the mean displacement of the uniformly loaded zone: the displacement that is
work-conjugate to a uniform pressure, hence what a facet law integrated over the facet (a
Galerkin/penalty form) sees; 'centre' uses its value at the centroid (a collocation macro model);
'none' drops the correction (for comparison only: the macro model then counts the zone's own
elastic compliance twice). Either way, a flat macro zone loaded by its law with the same L carries
exactly the micro force at every node not floored (below; tests/test_laws.py). For 4 x 4 zones tiling a surface with
many asperities per zone, a flat half-space loaded zone by zone (Galerkin for 'average',
collocation for 'centre') carries the force of the micro solve of the whole surface within 1 %
('average') and 2 % ('centre'); without the correction it is 4–16 % short (thesis Fig. 1.14:
0–3 %). Triangular zones solve the bounding box of their patch with the cells outside the
triangle sunk out of reach, and use Boussinesq's triangle integral. Close to full contact the
isolated patch is 8 % stiffer than Love's uniform pressure (a flat punch's edge pressures): where
the roughness adds less compliance than that, the law falls at that floor (``resolved_gap``), so
that worn-flat and smooth faces continue as nearly perfect contact: there the law's stiffness is a
lower bound, its extra laws (area, conductance...) still the micro solves' (a measured face of a
few nm Sq reaches the floor at a few % of real contact area: a user trial, 2026-12-06).

The law p_n(g_n) is a C¹ monotone table (``law_tables.PressureGapLaw``: PCHIP in log-log
variables); extra laws (real contact area, thermal conductance, heat partition…) are tabulated at
the same nodes against p_n (``law_tables.PressureTable``).
"""
from __future__ import annotations

import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field, replace

import numpy as np

from multiscale.errors import ConvergenceError, InputError, check_count, check_positive
from multiscale.micro.conduction import ConductionSolver
from multiscale.micro.contact import ContactResult, ContactSolver
from multiscale.micro.heat_kernels import ThermalMaterial
from multiscale.micro.heating import InterfaceLayer, SteadyHeating
from multiscale.micro.kernels import Kernel, check_kernel
from multiscale.micro.law_tables import LawValue, PressureGapLaw, PressureTable
from multiscale.micro.zones import Zone


# --------------------------------------------------------------------------- specification
class ExtraLaw(ABC):
    """Laws tabulated at the mechanical nodes against the zone pressure p_n (thermal laws…).

    ``tables``: the names of the tables it fills and, for each, its value below the first node:
    'zero' (linear in p_n down to 0 at p_n = 0) or 'hold' (the first node's). ``values(result,
    zones)`` receives the contact solution of a batch of zone patches at one node (a
    ``ContactResult`` of batch shape (B,)) and returns {table: (B,) values}, or (B, len(axis))
    values with one per point of ``axis`` (e.g. sliding speeds). Subclasses are deterministic
    and define ``key()`` (their parameters, for the caches).
    """

    tables: dict = {}
    axis: np.ndarray | None = None

    @abstractmethod
    def key(self) -> tuple:
        """Hashable identity of the law and its parameters."""

    @abstractmethod
    def values(self, result: ContactResult, zones: list[Zone]) -> dict:
        """Per-zone values of each table at one node (see the class docstring)."""


@dataclass(frozen=True)
class LawSpec:
    """What to compute for every zone.

    kernel: the micro solids (e.g. ``HalfSpace``); E_star [Pa]: composite modulus of the macro
    half-space in Love's correction (default: ``kernel.E_star``); p_max [Pa]: highest tabulated
    zone pressure (the top node, by a load-controlled solve); n_points: nodes per law (the others
    at approaches δ_max (k/n)², k = 1 … n−1: dense near first touch, where ln p changes fastest,
    so that 20 nodes span about four decades of pressure); love: 'average' | 'centre' | 'none'; tol, max_iter: contact
    solver (relative gap residual); extras: ``ExtraLaw`` objects; batch_cells: cells per batched
    solve (several equal zones are solved together up to this size); hardness [Pa]: the
    elastic-perfectly-plastic micro solve (p <= H, ``ContactSolver.solve``; None: elastic), so
    that the law of a zone's current (deformed) topography is its elastic reloading curve up to
    its previous maximum pressure and the plastic loading curve beyond (p_max < H); nodes that
    repeat a pressure there (every touching cell flowing) are re-solved under load control
    (``_plateau_targets``).
    """

    kernel: Kernel
    p_max: float
    n_points: int = 20
    love: str = "average"
    tol: float = 1e-8
    max_iter: int = 2000
    E_star: float | None = None
    extras: tuple = ()
    batch_cells: int = 20000
    hardness: float | None = None

    def __post_init__(self):
        check_kernel("kernel", self.kernel, thermal=False)
        check_positive("p_max", self.p_max)
        if self.hardness is not None and not check_positive("hardness", self.hardness) > self.p_max:
            raise InputError("p_max", self.p_max, f"the top node must lie below the hardness {self.hardness:.3g} Pa")
        check_positive("tol", self.tol)
        object.__setattr__(self, "n_points", check_count("n_points", self.n_points, minimum=4))
        object.__setattr__(self, "max_iter", check_count("max_iter", self.max_iter))
        object.__setattr__(self, "batch_cells", check_count("batch_cells", self.batch_cells))
        if not isinstance(self.love, str) or self.love not in ("average", "centre", "none"):
            raise InputError("love", self.love, "one of 'average', 'centre', 'none'")
        if self.E_star is None:
            if not hasattr(self.kernel, "E_star"):
                raise InputError("E_star", None, "give the macro composite modulus for this kernel")
            object.__setattr__(self, "E_star", float(self.kernel.E_star))
        check_positive("E_star", self.E_star)
        extras = tuple(self.extras)
        if not all(isinstance(e, ExtraLaw) and e.tables for e in extras):
            raise InputError("extras", extras, "ExtraLaw objects, each filling at least one table")
        names = [name for e in extras for name in e.tables]
        if len(set(names)) != len(names) or any(b not in ("zero", "hold") for e in extras for b in e.tables.values()):
            raise InputError("extras", names, "distinct table names, each 'zero' or 'hold' below the table")
        object.__setattr__(self, "extras", extras)

    def key(self) -> tuple:
        """Everything a zone's law depends on besides its topography (for caches)."""
        return (self.kernel.key(), self.E_star, self.p_max, self.n_points, self.love, self.tol,
                self.max_iter, tuple(e.key() for e in self.extras)) + (() if self.hardness is None else (self.hardness,))

    def approach_fractions(self) -> np.ndarray:
        """δ_k / δ_max of the nodes, k = 1 … n."""
        k = np.arange(1, self.n_points + 1)
        return (k / self.n_points) ** 2


# --------------------------------------------------------------------------- micro solves
@dataclass
class ZoneNodes:
    """The micro results behind one zone's laws (what caches keep and ranks exchange)."""

    zone_id: int
    topography_hash: str
    approach: np.ndarray       # m, rigid approach δ_k from the zone's first touch, (n,)
    pressure: np.ndarray       # Pa, zone mean pressure p_k = force / zone area, (n,)
    gap: np.ndarray            # m, macro gap g_k (Eq. 1.31, module docstring), (n,), decreasing
    area_fraction: np.ndarray  # real contact area / zone area, (n,)
    iterations: np.ndarray     # contact-solver iterations per node, (n,)
    top: float                 # m, highest point of the zone above the datum (g at first touch)
    compliance: float          # m/Pa, L/(π E*) used for the gap (0 for love='none')
    extras: dict = field(default_factory=dict)   # table name -> (n,) or (n, m) values
    seconds: float = 0.0       # wall time of this zone's share of its batched solves
    cells: int = 0             # grid cells of the zone's patch
    floored: float = np.inf    # Pa, lowest node pressure whose gap fell at the resolution floor (``resolved_gap``)


@dataclass
class ZoneFailure:
    """A zone whose laws could not be computed."""

    zone_id: int
    kind: str       # exception class name
    message: str


class LawError(ConvergenceError):
    """Laws of some zones could not be computed; ``failures`` lists them (zone ids, reasons) and
    ``result`` holds the ``ZoneLaws`` of the others (or None)."""

    def __init__(self, failures: list[ZoneFailure], result=None, note: str = ""):
        self.failures, self.note = list(failures), note
        lines = [f"zone {f.zone_id}: {f.kind}: {f.message}" for f in self.failures[:10]]
        more = len(self.failures) - len(lines)
        text = f"laws failed for {len(self.failures)} zone(s):\n  " + "\n  ".join(lines) \
            + (f"\n  ... and {more} more" if more > 0 else "") + (f"\n{note}" if note else "")
        super().__init__(text, history=None, result=result)


_SOLVERS: dict[tuple, ContactSolver] = {}


def _solver(kernel: Kernel, shape, dx, dy) -> ContactSolver:
    """One solver (FFT plans) per kernel and grid, reused across calls and time steps."""
    key = (kernel.key(), tuple(shape), float(dx), float(dy))
    if key not in _SOLVERS:
        if len(_SOLVERS) >= 16:
            _SOLVERS.pop(next(iter(_SOLVERS)))
        _SOLVERS[key] = ContactSolver(kernel, shape, dx, dy, periodic=False)
    return _SOLVERS[key]


def zone_nodes(zones: list[Zone], spec: LawSpec) -> tuple[list[ZoneNodes], list[ZoneFailure]]:
    """Micro solves of the zones' nodes; equal patches are batched ``spec.batch_cells`` at a time.

    Returns the nodes of the zones that succeeded and the failures (non-convergence, a gap that
    is not monotone below p_max, any other exception), each with its zone id. Results do not
    depend on how zones are grouped beyond FFT round-off.
    """
    nodes, failures = [], []
    for group in batches([batch_signature(z) for z in zones], spec.batch_cells):
        n, f = _isolated([zones[i] for i in group], spec)
        nodes += n
        failures += f
    return nodes, failures


def _isolated(group: list[Zone], spec: LawSpec):
    """A batch's nodes; an unexpected exception in a batch is retried zone by zone, so that it is
    reported against the zone(s) that raise it, and never reaches the caller (or its MPI peers)."""
    try:
        return _batch_nodes(group, spec)
    except Exception as exc:
        if len(group) == 1:
            return [], [ZoneFailure(group[0].id, type(exc).__name__, str(exc))]
    nodes, failures = [], []
    for z in group:
        n, f = _isolated([z], spec)
        nodes += n
        failures += f
    return nodes, failures


def batch_signature(zone: Zone) -> tuple:
    """Zones with equal signatures share a solver grid and can be solved in one batch."""
    return (zone.shape, zone.surface.dx, zone.surface.dy, zone.triangle is None)


def batches(signatures: list[tuple], batch_cells: int, max_zones: int | None = None) -> list[list[int]]:
    """Indices of consecutive runs of equal signatures, each of at most ``batch_cells`` grid cells
    and ``max_zones`` zones (at least one zone)."""
    limit = max_zones or len(signatures)
    out: list[list[int]] = []
    for i, sig in enumerate(signatures):
        cells = sig[0][0] * sig[0][1]
        if out and signatures[out[-1][-1]] == sig and len(out[-1]) < limit \
                and (len(out[-1]) + 1) * cells <= batch_cells:
            out[-1].append(i)
        else:
            out.append([i])
    return out


def _batch_nodes(zones: list[Zone], spec: LawSpec) -> tuple[list[ZoneNodes], list[ZoneFailure]]:
    """Nodes of equal-grid zones in one batch: a load-controlled solve at p_max fixes δ_max, then
    displacement-controlled solves at δ_max (k/n)² downwards, each warm-started by a secant
    extrapolation of the two nodes above it (about 15 % fewer iterations than upwards)."""
    t0 = time.perf_counter()
    s = zones[0].surface
    solver = _solver(spec.kernel, s.shape, s.dx, s.dy)
    box_area = s.size[0] * s.size[1]
    masks = np.stack([z.mask for z in zones])
    area = np.array([z.area for z in zones])
    heights, tol = _masked_heights(zones, masks, spec)
    n, B = spec.n_points, len(zones)
    failures: dict[int, ZoneFailure] = {}
    alive = np.ones(B, dtype=bool)
    approach, pressure, fraction = (np.full((B, n), np.nan) for _ in range(3))
    iterations = np.zeros((B, n), dtype=int)
    extras: dict[str, np.ndarray] = {}

    def run(k, idx, **control):
        r = solver.solve(heights[idx], tol=tol[idx].min(), max_iter=spec.max_iter, partial=True,
                         hardness=spec.hardness, **control)
        for j, b in enumerate(idx):
            if not r.converged[j]:
                failures[b] = ZoneFailure(zones[b].id, "ContactConvergenceError",
                                          f"no convergence in {spec.max_iter} iterations at node {k + 1} "
                                          f"(residual {r.residual[j]:.2e} > {tol[b]:.1e})")
            elif np.any(r.pressure[j][~masks[b]] > 0):
                failures[b] = ZoneFailure(zones[b].id, "InputError", "cells outside the triangle touched")
        alive[list(failures)] = False
        approach[idx, k] = r.approach
        pressure[idx, k] = r.mean_pressure * box_area / area[idx]
        fraction[idx, k] = r.area_fraction * box_area / area[idx]
        iterations[idx, k] = r.iterations
        for e in spec.extras:
            values = e.values(r, [zones[b] for b in idx])
            for name in e.tables:
                v = np.asarray(values[name], dtype=float)
                if name not in extras:
                    extras[name] = np.full((B, n) + v.shape[1:], np.nan)
                extras[name][idx, k] = v
        return r

    idx = np.arange(B)
    solved = np.zeros((B, 2) + s.shape)          # pressure fields of the last two nodes solved
    solved[:, 0] = run(n - 1, idx, load=spec.p_max * area / box_area).pressure
    delta_max = approach[:, n - 1].copy()
    fractions = spec.approach_fractions()
    for k in range(n - 2, -1, -1):              # downwards: the contact area only shrinks
        idx = idx[alive[idx]]
        if not len(idx):
            break
        warm = solved[idx, 0]
        if k < n - 2:                           # secant predictor through the last two nodes
            step = (fractions[k] - fractions[k + 1]) / (fractions[k + 1] - fractions[k + 2])
            warm = np.maximum(warm + step * (warm - solved[idx, 1]), 0.0)
        solved[idx, 1] = solved[idx, 0]
        solved[idx, 0] = run(k, idx, approach=delta_max[idx] * fractions[k], initial_pressure=warm).pressure
    if spec.hardness is not None:
        targets = _plateau_targets(pressure, alive)
        for k in np.flatnonzero(np.isfinite(targets).any(axis=0)):
            idx = np.flatnonzero(np.isfinite(targets[:, k]) & alive)
            if len(idx):
                run(k, idx, load=targets[idx, k] * area[idx] / box_area)

    seconds = (time.perf_counter() - t0) / B
    nodes = []
    for b, z in enumerate(zones):
        if not alive[b]:
            continue
        extra = {name: values[b] for name, values in extras.items()}
        c = 0.0 if spec.love == "none" else z.love(spec.love) / (np.pi * spec.E_star)
        gap, floored = resolved_gap(z.top - approach[b] + c * pressure[b], pressure[b], z.top, c)
        problem = _monotone_problem(gap, pressure[b])
        if problem:
            failures[b] = ZoneFailure(z.id, "InputError", problem + f"; lower p_max (this law's: {spec.p_max:.3g} Pa)")
            continue
        nodes.append(ZoneNodes(z.id, z.topography_hash, approach[b], pressure[b], gap, fraction[b],
                               iterations[b], z.top, c, extra, seconds, z.shape[0] * z.shape[1], floored))
    return nodes, [failures[b] for b in sorted(failures)]


def _plateau_targets(pressure, alive) -> np.ndarray:
    """Zone pressures [Pa] at which to re-solve nodes under load control (NaN: keep the node).

    With a hardness H, a zone whose touching cells all flow carries H × their area whatever the
    approach until another cell touches: approach-spaced nodes then repeat a pressure (one 32²
    zone at H = 3 MPa: 2929.7 Pa at two or three nodes, a staircase of the grid, not of the
    surface), which makes no monotone law. Each run of nodes at or below an earlier node's
    pressure gets pressures spaced geometrically between that pressure and the next higher node's;
    the load-controlled solves place them at the approach where the zone's load reaches them."""
    targets = np.full(pressure.shape, np.nan)
    for b in np.flatnonzero(alive):
        p = pressure[b]
        k = 1
        while k < len(p) - 1:
            low = p[:k].max()
            if p[k] > low:
                k += 1
                continue
            end = k
            while end < len(p) and p[end] <= low:
                end += 1
            if end < len(p) and low > 0:        # otherwise the law fails as before, named
                m = np.arange(1, end - k + 1) / (end - k + 1)
                targets[b, k:end] = low * (p[end] / low) ** m
            k = end + 1
    return targets


def _masked_heights(zones, masks, spec):
    """Heights of the batch with cells outside triangular zones sunk far below reach, and the
    solver tolerance per zone rescaled so the residual stays relative to the zone's own RMS."""
    h = np.stack([z.surface.heights for z in zones])
    tol = np.full(len(zones), spec.tol)
    if masks.all():
        return h, tol
    h = h.copy()
    for b, z in enumerate(zones):
        inside = h[b][masks[b]]
        reach = (inside.max() - inside.min()) + spec.p_max * z.love("centre") / (np.pi * spec.E_star)
        h[b][~masks[b]] = inside.min() - 4 * reach - 1e-12
        rms_in = inside.std() or 1.0
        tol[b] = spec.tol * rms_in / (h[b].std() or 1.0)
    return h, tol


RESOLUTION = 0.08    # share of a zone's compliance L/(pi E*) its law cannot resolve (a flat punch's edge pressures)


def resolved_gap(gap, pressure, top: float, compliance: float) -> tuple[np.ndarray, float]:
    """Node gaps [m] whose compliance −Δg/Δp is at least ``RESOLUTION`` × ``compliance`` [m/Pa] from
    first touch (gap ``top`` [m], p = 0) on, and the pressure [Pa] of the first node raised to that
    floor (inf if none).

    An isolated patch pressed flat carries a flat punch's edge pressures: its approach per mean
    pressure is 0.955, 0.927, 0.922, 0.918 of Love's uniform-pressure mean displacement on a square
    of 8², 32², 64², 256² cells (about 0.917 converged; 0.925 on a circle: pi/2 against 16/(3 pi),
    Johnson 1985 §3.8), so the Love-corrected gap of a patch close to full contact is too high by
    up to 8 % of c p, and rises with p once the roughness adds less compliance than that. The zone
    law cannot resolve such compliance; where the nodes show less, their gaps fall at the floor
    instead (−dg/dp = RESOLUTION c): the face continues as nearly perfect contact, its extra
    compliance within the law's own uncertainty (before, such a law was refused: a worn-flat or
    smooth face stopped the run)."""
    gap, pressure = np.asarray(gap, dtype=float), np.asarray(pressure, dtype=float)
    floor, out, floored = RESOLUTION * compliance, gap.copy(), np.inf
    last_gap, last_p = top, 0.0
    for k in range(len(gap)):
        limit = last_gap - floor * (pressure[k] - last_p)
        if out[k] > limit:
            out[k] = limit
            floored = min(floored, float(pressure[k]))
        last_gap, last_p = out[k], pressure[k]
    return out, floored


def _monotone_problem(gap, pressure) -> str:
    """Why nodes (gap [m], pressure [Pa]) make no monotone law ("" if they do)."""
    if not np.all(np.isfinite(gap)) or not np.all(np.isfinite(pressure)):
        return "non-finite node values"
    if pressure[0] <= 0:
        return "the lowest node carries no pressure"
    if not np.all(np.diff(pressure) > 0):
        return "the zone pressure does not grow with the approach"
    if not np.all(np.diff(gap) < 0):
        return "the macro gap does not fall with the approach"
    return ""


# --------------------------------------------------------------------------- container
class ZoneLaws:
    """The laws of a set of zones, evaluated per point from zone ids (e.g. one per facet).

    ``pressure(gap, zone_ids)`` -> ``LawValue`` (p_n, K_n); ``area_fraction(p, zone_ids)``;
    ``extra(name, p, zone_ids, at=None)``. ``nodes`` keeps the micro results, in ``ids`` order.
    """

    def __init__(self, nodes: list[ZoneNodes], spec: LawSpec | None = None):
        self.nodes = list(nodes)
        self.ids = np.array([nd.zone_id for nd in nodes], dtype=int)
        order = np.argsort(self.ids, kind="stable")
        if np.any(np.diff(self.ids[order]) == 0):
            raise InputError("nodes", "zone ids", "each zone once")
        self._sorted_ids, self._order = self.ids[order], order
        self.spec = spec
        self.mechanical = self._area = None
        self.extras: dict[str, PressureTable] = {}
        if not nodes:                      # e.g. a rank without interface facets
            return
        self.mechanical = PressureGapLaw(np.stack([nd.gap for nd in nodes]),
                                         np.stack([nd.pressure for nd in nodes]),
                                         np.array([nd.top for nd in nodes]))
        pressure = self.mechanical.pressure
        self._area = PressureTable(pressure, np.stack([nd.area_fraction for nd in nodes]), below="zero")
        for e in (spec.extras if spec is not None else ()):
            for name, below in e.tables.items():
                self.extras[name] = PressureTable(pressure, np.stack([nd.extras[name] for nd in nodes]),
                                                  below=below, axis=e.axis)

    def __len__(self) -> int:
        return len(self.ids)

    def in_series(self, compliance) -> ZoneLaws:
        """These laws with a compliance c [m/Pa] per zone (``ids`` order, >= 0) in series: at each
        node the interpenetration d + c p for the same pressure (a node's gap lowered by c p; the
        tables of the pressure, e.g. the area fraction, unchanged). With c Archard's depth per
        pressure over a wear interval, the laws of the pressure at its end (``coupling``'s backward
        Euler wear)."""
        c = np.asarray(compliance, dtype=float)
        if c.shape != self.ids.shape or not np.all(c >= 0):
            raise InputError("compliance", c.shape, f"one compliance >= 0 [m/Pa] per zone ({len(self.ids)})")
        return ZoneLaws([replace(nd, gap=nd.gap - k * nd.pressure) for nd, k in zip(self.nodes, c)],
                        self.spec)

    def rows(self, zone_ids) -> np.ndarray:
        """Row of each zone id (raises for an unknown id)."""
        z = np.asarray(zone_ids, dtype=int)
        if not len(self.ids):
            if z.size:
                raise InputError("zone_ids", np.unique(z)[:5].tolist(), "no law for these zones")
            return z
        i = np.clip(np.searchsorted(self._sorted_ids, z), 0, len(self._sorted_ids) - 1)
        if np.any(self._sorted_ids[i] != z):
            missing = np.unique(z[self._sorted_ids[i] != z])[:5]
            raise InputError("zone_ids", missing.tolist(), "no law for these zones")
        return self._order[i]

    def _evaluate(self, table, values, zone_ids, *args):
        rows = self.rows(zone_ids)
        if table is None:                  # no zones: only empty requests get here
            return np.zeros(np.broadcast(np.asarray(values), rows).shape)
        return table(values, rows, *args)

    def pressure(self, gap, zone_ids) -> LawValue:
        """Zone pressure p_n [Pa] and stiffness K_n [Pa/m] at macro gaps ``gap`` [m]."""
        if self.mechanical is None:
            empty = self._evaluate(None, gap, zone_ids)
            return LawValue(empty, empty.copy())
        return self.mechanical(gap, self.rows(zone_ids))

    def area_fraction(self, pressure, zone_ids) -> np.ndarray:
        """Real contact area / nominal area at zone pressures ``pressure`` [Pa]."""
        return self._evaluate(self._area, pressure, zone_ids)

    def extra(self, name: str, pressure, zone_ids, at=None) -> np.ndarray:
        """Extra law ``name`` at zone pressures [Pa] (and axis points ``at``)."""
        if name not in self.extras and self.mechanical is not None:
            raise InputError("name", name, f"one of {sorted(self.extras)}")
        return self._evaluate(self.extras.get(name), pressure, zone_ids, at)


# --------------------------------------------------------------------------- thermal laws
class Conductance(ExtraLaw):
    """Thermal contact conductance h_c(p_n) of a zone for the macro interface (thesis ch. 5).

    At each node, steady conduction through the zone's real contact area between two solids
    (thermal kernels ``kernel_1``, ``kernel_2``, local resistance ``resistance`` [m² K/W];
    ``ConductionSolver`` on the isolated patch) gives K_t = heat flow / (zone area ΔT) (Eq. 5.9):
    table 'patch_conductance' [W/(m² K)]. As for the mechanical gap (Eq. 1.31), the macro model
    spreads the zone's heat through its own bulk: a uniform flux q on the zone raises the mean
    surface temperature difference by q R_zone (R_zone: mean over the zone of the series kernels'
    response to a uniform unit flux on it), so the interface conductance is
    h_c = 1/(1/K_t − R_zone): table 'conductance'. Both vanish with p_n ('zero' below the table).
    """

    tables = {"conductance": "zero", "patch_conductance": "zero"}

    def __init__(self, kernel_1: Kernel, kernel_2: Kernel, resistance: float = 0.0, tol: float = 1e-10):
        self.kernels = (kernel_1, kernel_2)
        self.resistance = check_positive("resistance", resistance, allow_zero=True)
        self.tol = check_positive("tol", tol)
        self._solvers: dict[tuple, ConductionSolver] = {}

    def key(self) -> tuple:
        return ("Conductance", self.kernels[0].key(), self.kernels[1].key(), self.resistance, self.tol)

    def values(self, result: ContactResult, zones: list[Zone]) -> dict:
        s = zones[0].surface
        grid = (s.shape, s.dx, s.dy)
        if grid not in self._solvers:
            self._solvers[grid] = ConductionSolver(*self.kernels, s.shape, s.dx, s.dy, periodic=False)
        solver = self._solvers[grid]
        heat = solver.solve(result.contact, resistance=self.resistance, theta_1=0.0, theta_2=1.0, tol=self.tol)
        area = np.array([z.area for z in zones])
        K_t = heat.conductance * (s.size[0] * s.size[1]) / area
        R_zone = solver.uniform_resistance(np.stack([z.mask for z in zones]))
        excess = 1.0 / K_t - R_zone
        if np.any(excess <= 0):
            raise InputError("p_max", result.mean_pressure.max(), "the zone's conductance exceeds its "
                             "uniform-flux bulk conductance (close to full contact): lower p_max")
        return {"conductance": 1.0 / excess, "patch_conductance": K_t}


class HeatPartition(ExtraLaw):
    """Steady frictional heat partition p_1(p_n, V) and flash temperatures of a zone (thesis ch. 6,
    §7.2; ``SteadyHeating``).

    Body 1 (``body1``, the counter-face) slides at each of ``speeds`` [m/s] along ``angle`` over
    the zone (body 2, ``body2``), friction ``mu``, optional ``interface`` layer. Tables over the
    speed axis: 'partition_1' (share of the heat into body 1; held below the table) and
    'max_temperature_1', 'max_temperature_2' [K] (steady maximum surface temperature rise of the
    isolated patch, zone-scale rise included; zero below the table).
    """

    tables = {"partition_1": "hold", "max_temperature_1": "zero", "max_temperature_2": "zero"}

    def __init__(self, body1: ThermalMaterial, body2: ThermalMaterial, speeds, mu: float, *,
                 angle: float = 0.0, interface: InterfaceLayer | None = None, tol: float = 1e-8):
        v = np.atleast_1d(np.asarray(speeds, dtype=float))
        if v.ndim != 1 or len(v) < 2 or not np.all(np.isfinite(v)) or np.any(v <= 0) or np.any(np.diff(v) <= 0):
            raise InputError("speeds", speeds, "at least two increasing sliding speeds > 0 [m/s]")
        self.body1, self.body2, self.axis = body1, body2, v
        self.mu, self.angle = check_positive("mu", mu), float(angle)
        self.interface, self.tol = interface, check_positive("tol", tol)
        self._solvers: dict[tuple, SteadyHeating] = {}

    def key(self) -> tuple:
        return ("HeatPartition", repr(self.body1), repr(self.body2), tuple(self.axis), self.mu, self.angle,
                repr(self.interface), self.tol)

    def values(self, result: ContactResult, zones: list[Zone]) -> dict:
        s = zones[0].surface
        rows = []
        for v in self.axis:
            key = (s.shape, s.dx, s.dy, v)
            if key not in self._solvers:
                self._solvers[key] = SteadyHeating(s.shape, s.dx, self.body1, self.body2, v, s.dy, self.angle)
            rows.append(self._solvers[key].solve(result.pressure, self.mu, interface=self.interface, tol=self.tol))
        return {name: np.stack([getattr(r, name) for r in rows], axis=-1) for name in self.tables}


def compute_laws(zones: list[Zone], spec: LawSpec) -> ZoneLaws:
    """Laws of the zones in this process (see ``multiscale.pool.MicroPool`` for MPI).

    Raises ``LawError`` naming every failed zone (its ``result`` holds the others' laws)."""
    ids = [z.id for z in zones]
    if len(set(ids)) != len(ids):
        raise InputError("zones", "ids", "zone ids must be unique")
    nodes, failures = zone_nodes(list(zones), spec)
    if failures:
        raise LawError(failures, ZoneLaws(nodes, spec) if nodes else None)
    return ZoneLaws(nodes, spec)

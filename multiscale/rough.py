"""A rough contact interface of a macro model: zones of micro patches -> laws through the pool ->
per-facet laws, and the rigid datum gap (thesis §1.4.2, §4.2, §7.2.1).

Each interface of the mesh (one face of the stationary body 0, in a plane z = const) is covered by
a grid of zones, each carrying its own micro patch. A facet follows the law p_n(g_n) of the zone
holding its midpoint, embedded exactly in the UFL contact form (``macro.laws_ufl.FacetLaw``: the
Newton matrix holds the laws' consistent tangent, for the multiscale loop and the squeal analysis
alike). Only zones that hold a facet get a law. Zone ids run over the interfaces in order (those
of interface k follow those of interface k − 1), so per-zone arrays are indexed by id.

``update_laws`` computes the laws of the zones whose topography changed (the pool's cache keeps
the others) and loads them into the facet law; a zone whose law fails (close to full contact
below p_max) is retried with p_max halved, up to ``P_MAX_HALVINGS`` times (remembered for its
later laws). ``datum_gap`` is the per-facet uniform initial gap at which the rigid rough bodies
carry given forces, one bisection per interface: it starts Newton close to equilibrium.

This module reads no scene: ``multiscale.workflows.rough`` builds a ``RoughInterface`` from one.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import InputError
from multiscale.macro.laws_ufl import FacetLaw
from multiscale.macro.mesh import TwoBodyMesh
from multiscale.micro.laws import LawError, LawSpec, ZoneLaws
from multiscale.micro.zones import Zone, ZoneGrid
from multiscale.pool import MicroPool

P_MAX_HALVINGS = 4         # a zone whose law fails is retried with p_max / 2, ... / 16


def interface_plane(tm: TwoBodyMesh, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (x, y) [m] of interface ``name``, which must lie in a plane z = const."""
    lo, hi = tm.interface.box(name)
    if hi[2] - lo[2] > 1e-9 * max(hi[0] - lo[0], hi[1] - lo[1]):
        raise InputError("geometry", name, "a rough interface must lie in a plane z = const")
    return lo[:2], hi[:2]


@dataclass
class RoughInterface:
    """Zones, laws and facet law of the rough interfaces of ``tm`` (see module docstring).

    ``grids[k]``: the zone grid of interface k, whose zones have ids ``offsets[k] + local id``;
    ``zones[i]`` has id i. ``spec``: the laws' ``LawSpec`` (p_max of level 0).
    """

    tm: TwoBodyMesh
    grids: list[ZoneGrid]
    zones: list[Zone]
    spec: LawSpec
    pool: MicroPool
    law: FacetLaw = field(init=False)
    zone_of_facet: np.ndarray = field(init=False)       # zone id of every global facet
    initial: np.ndarray = field(init=False)              # (Z, ny, nx) initial topographies [m]
    levels: np.ndarray = field(init=False)               # p_max halvings of each zone's law
    used: np.ndarray = field(init=False)                 # ids of the zones holding a facet
    laws_computed: int = 0                               # laws computed by the last update

    def __post_init__(self):
        iface = self.tm.interface
        offsets = np.cumsum([0] + [g.n_zones for g in self.grids])
        if [z.id for z in self.zones] != list(range(offsets[-1])):
            raise InputError("zones", len(self.zones), "one zone per grid cell, ids in grid order")
        mid = iface.midpoints
        self.zone_of_facet = np.empty(iface.n_facets, dtype=int)
        for k, mask in enumerate(iface.masks().values()):
            self.zone_of_facet[mask] = offsets[k] + self.grids[k].zone_of(mid[mask, 0], mid[mask, 1])
        self.used = np.unique(self.zone_of_facet)
        self.initial = np.stack([z.surface.heights for z in self.zones])
        self.levels = np.zeros(len(self.zones), dtype=int)
        self.law = FacetLaw(self.tm, self.spec.n_points)

    @property
    def zone_area(self) -> np.ndarray:
        """Nominal area of every zone [m^2]."""
        return np.array([z.area for z in self.zones])

    def heights(self) -> np.ndarray:
        """Current zone topographies (Z, ny, nx) [m]."""
        return np.stack([z.surface.heights for z in self.zones])

    def set_heights(self, ids, heights) -> None:
        """New topographies of the zones ``ids`` (worn or restored)."""
        for zid, h in zip(ids, heights):
            self.zones[zid] = self.zones[zid].with_heights(h)

    def wear_depth(self) -> np.ndarray:
        """Accumulated wear depth fields (Z, ny, nx) [m]."""
        return self.initial - self.heights()

    def zone_wear_volume(self, depth: np.ndarray) -> np.ndarray:
        """Worn volume of each zone [m^3] from its depth field (Z, ny, nx) [m]."""
        s = self.zones[0].surface
        return depth.sum(axis=(-2, -1)) * s.dx * s.dy

    def update_laws(self) -> int:
        """Laws of every used zone (cached ones reused), loaded into the facet law (collective);
        returns how many were computed."""
        comm, nodes, computed = self.pool.comm, [], 0
        for level in range(P_MAX_HALVINGS + 1):
            todo = [self.zones[i] for i in self.used if self.levels[i] == level]
            if not todo:
                continue
            spec = dataclasses.replace(self.spec, p_max=self.spec.p_max / 2**level)
            try:
                laws = self.pool.laws(todo[comm.rank::comm.size], spec, gather="all")
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

    def datum_gap(self, forces) -> np.ndarray:
        """Per-facet uniform gap g_0 [m] of each interface at which its rigid rough body carries
        ``forces[k]`` [N] (interface k, in the order of ``tm.interface.tags``; bisection)."""
        areas, laws = self.tm.interface.areas, self.law.laws
        out = np.zeros(len(areas))
        for mask, target in zip(self.tm.interface.masks().values(), forces):
            rows = laws.rows(self.zone_of_facet[mask])
            g_open = laws.mechanical.g_open[rows]

            def force(G):
                gap = np.zeros(len(areas))
                gap[mask] = G
                return float(areas[mask] @ self.law.evaluate(gap)[0][mask])

            hi = g_open.max()
            step = max(np.median(g_open - laws.mechanical.gap[rows, -1]), 1e-12)
            lo = hi - step
            while force(lo) < target:
                step *= 2
                lo = hi - step
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if force(mid) > target else (lo, mid)
                if hi - lo <= 1e-13 * step:
                    break
            out[mask] = 0.5 * (lo + hi)
        return out

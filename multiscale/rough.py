"""A rough contact interface of a macro model: zones of micro patches -> laws through the pool ->
per-facet laws, and the rigid datum gap (thesis §1.4.2, §4.2, §7.2.1).

Each rough interface of the mesh (a planar face of the stationary body 0) is covered by a grid of
zones in its plane, each carrying its own micro patch. A facet follows the law p_n(g_n) of the zone
holding its midpoint, embedded exactly in the UFL contact form (``macro.laws_ufl.FacetLaw``: the
Newton matrix holds the laws' consistent tangent, for the multiscale loop and the squeal analysis
alike); facets of the other interfaces have no law (their perfect-contact penalty law is added by
the caller). Only zones that hold a facet get a law. Zone ids run over the rough interfaces in
order (those of interface k follow those of interface k − 1), so per-zone arrays are indexed by
id. Zone coordinates (u, v) are those of the interface plane's frame (``interface_plane``): for a
plane z = const, (u, v) = (x, y).

``update_laws`` computes the laws of the zones whose topography changed (the pool's cache keeps
the others) and loads them into the facet law; a zone whose law fails (no convergence, a pressure
that stops growing) is retried with p_max halved, up to ``P_MAX_HALVINGS`` times (remembered for
its later laws). Zones whose roughness adds less compliance than their laws resolve (worn flat,
smooth) continue as nearly perfect contact (``micro.laws.resolved_gap``). ``datum_gap`` is the
per-facet uniform initial gap at which the rigid rough bodies carry given forces, one bisection per
interface: it starts Newton close to equilibrium.

``track_depth`` spreads the volume the counter-face (a rotating body 1) loses in each zone over its
circular wear track: the counter-face stays flat at the zone scale and its surface recedes by a
depth that depends on the radius only (every point of the track passes under the zones many times
per macro step), which widens the macro gap of the facets at that radius.

This module reads no scene: ``multiscale.workflows.rough`` builds a ``RoughInterface`` from one.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import Rotation, plane_frame
from multiscale.macro.facet_wear import track_spread
from multiscale.macro.laws_ufl import FacetLaw, gap_at
from multiscale.macro.mesh import TwoBodyMesh
from multiscale.micro.laws import LawError, LawSpec, ZoneLaws
from multiscale.micro.zones import Zone, ZoneGrid
from multiscale.pool import MicroPool

P_MAX_HALVINGS = 4         # a zone whose law fails is retried with p_max / 2, ... / 16


@dataclass(frozen=True)
class Plane:
    """The plane of an interface: ``origin`` [m] and the orthonormal frame (e_u, e_v, normal)."""

    origin: np.ndarray
    frame: np.ndarray          # (3, 3): rows e_u, e_v, normal

    def uv(self, x) -> np.ndarray:
        """Plane coordinates (..., 2) [m] of points x (..., 3)."""
        return (np.asarray(x, dtype=float) - self.origin) @ self.frame[:2].T


def interface_plane(tm: TwoBodyMesh, name: str) -> tuple[Plane, np.ndarray, np.ndarray]:
    """The plane of interface ``name`` and the lower and upper corners (u, v) [m] of its facets'
    vertices in it; InputError if the interface is not planar. The frame is ``geometry.plane_frame``'s:
    (x, y, z) itself for a normal along z, the origin on the face's plane (before: at z = 0, and
    zones.h5 put every zone there); otherwise e_u is x projected on the plane (or y)."""
    iface = tm.interface
    mask = iface.masks()[name]
    mid, areas = iface.midpoints[mask], iface.areas[mask]
    centre = (areas[:, None] * mid).sum(axis=0) / areas.sum()
    _, _, vt = np.linalg.svd((mid - centre) * np.sqrt(areas)[:, None], full_matrices=False)
    n = vt[-1] / np.linalg.norm(vt[-1])
    lo3, hi3 = iface.box(name)
    size = max(float((hi3 - lo3).max()), np.finfo(float).tiny)
    if np.abs((mid - centre) @ n).max() > 1e-9 * size:
        raise InputError("geometry", name, "a rough interface must be planar")
    plane = Plane(centre * [0, 0, 1] if abs(n[2]) > 1 - 1e-12 else centre, plane_frame(n))   # (u, v) = (x, y) there
    corners = plane.uv(np.array([[a, b, c] for a in (lo3[0], hi3[0]) for b in (lo3[1], hi3[1])
                                 for c in (lo3[2], hi3[2])]))
    return plane, corners.min(axis=0), corners.max(axis=0)


def check_zone_size(grid, areas, name: str, key: str) -> None:
    """Refuse zones smaller than the facets of interface ``name`` (``areas`` [m^2]; ``key``: the scene
    key of its zones, named by the InputError): a facet loads only
    the zone holding its midpoint, with its force over that zone's area, and the zones between hold
    none (20 x 20 zones of 1 mm^2 on the test pin-on-disc's 2.5 mm facets: 19 of 400 loaded, zone
    pressures 15 times the 5 x 5 grid's, a real contact area 0.57 times its)."""
    zone, facet = grid.size[0] * grid.size[1], float(np.median(areas))
    if zone < facet:
        fit = grid.counts_for(facet)
        raise InputError(key, list(grid.counts), f"zones of {zone * 1e6:.3g} mm^2 on interface {name} are "
                         f"smaller than its facets (median {facet * 1e6:.3g} mm^2): a facet loads only the zone "
                         f"holding its midpoint; use at most {fit[0]} x {fit[1]} zones or a finer interface mesh")


def in_plane_motion(motion, points, axes) -> tuple[np.ndarray, np.ndarray]:
    """Body 1's velocity per unit motion at ``points`` (n, 3) [m] in the planes of ``axes`` (n, 2, 3):
    its magnitude [m per rad, or per m] and direction [rad from the first axis]."""
    w = np.einsum("zij,zj->zi", axes, motion.velocity(points))
    return np.hypot(w[:, 0], w[:, 1]), np.arctan2(w[:, 1], w[:, 0])


@dataclass
class RoughInterface:
    """Zones, laws and facet law of the rough interfaces of ``tm`` (see module docstring).

    ``names[k]``: the k-th rough interface, ``planes[k]`` its plane, ``grids[k]`` its zone grid (in
    plane coordinates), whose zones have ids ``offsets[k] + local id``; ``zones[i]`` has id i.
    ``spec``: the laws' ``LawSpec`` (p_max of level 0).
    """

    tm: TwoBodyMesh
    names: list[str]
    planes: list[Plane]
    grids: list[ZoneGrid]
    zones: list[Zone]
    spec: LawSpec
    pool: MicroPool
    law: FacetLaw = field(init=False)
    zone_of_facet: np.ndarray = field(init=False)       # zone id of every global facet (-1: not rough)
    initial: np.ndarray = field(init=False)              # (Z, ny, nx) initial topographies [m]
    plastic: np.ndarray = field(init=False)              # (Z, ny, nx) accumulated permanent deformation [m]
    levels: np.ndarray = field(init=False)               # p_max halvings of each zone's law
    floors: np.ndarray = field(init=False)               # Pa, where each zone's law reaches its floor (inf: not)
    covered_area: np.ndarray = field(init=False)         # m^2, area of the facets each zone holds
    used: np.ndarray = field(init=False)                 # ids of the zones holding a facet
    laws_computed: int = 0                               # laws computed by the last update

    def __post_init__(self):
        iface = self.tm.interface
        offsets = np.cumsum([0] + [g.n_zones for g in self.grids])
        if [z.id for z in self.zones] != list(range(offsets[-1])):
            raise InputError("zones", len(self.zones), "one zone per grid cell, ids in grid order")
        masks = iface.masks()
        self.zone_of_facet = np.full(iface.n_facets, -1)
        for k, name in enumerate(self.names):
            uv = self.planes[k].uv(iface.midpoints[masks[name]])
            self.zone_of_facet[masks[name]] = offsets[k] + self.grids[k].zone_of(uv[:, 0], uv[:, 1])
        rough = self.zone_of_facet >= 0
        self.used = np.unique(self.zone_of_facet[rough])
        self.covered_area = np.bincount(self.zone_of_facet[rough], iface.areas[rough], minlength=len(self.zones))
        self.initial = np.stack([z.surface.heights for z in self.zones])
        self.plastic = np.zeros_like(self.initial)
        self.levels = np.zeros(len(self.zones), dtype=int)
        self.floors = np.full(len(self.zones), np.inf)
        self.law = FacetLaw(self.tm, self.spec.n_points)

    @property
    def zone_area(self) -> np.ndarray:
        """Nominal area of every zone [m^2]: its patch's (the cells of its footprint)."""
        return np.array([z.area for z in self.zones])

    @property
    def cover(self) -> np.ndarray:
        """Per zone, the area of its facets over its patch's (``covered_area / zone_area``; 0 for a
        zone holding no facet). A zone's patch is a sample of the roughness under its facets: it is
        loaded at their mean pressure, and what it gives per unit of its area (real contact area,
        heat, exchange, worn volume) counts over their area. A zone on the edge of a round face
        covers a part of its box (0.33 for a corner zone of 4 x 4 on a disc face); one inside it about
        1, up to how the facets' midpoints fall."""
        return self.covered_area / self.zone_area

    def per_facet_area(self, values) -> np.ndarray:
        """Per-zone totals ``values`` (a force [N], an exchange [W/K]) over the area of each zone's
        facets (a pressure, a conductance per area); 0 for a zone holding no facet."""
        covered = self.covered_area
        return np.asarray(values, dtype=float) / np.where(covered > 0, covered, 1.0)

    @property
    def law_top(self) -> np.ndarray:
        """Largest pressure of every zone's law [Pa]: p_max, halved where a law failed (beyond it
        the facet law is extrapolated linearly)."""
        return self.spec.p_max / 2.0 ** self.levels

    def law_reach(self, pressure: np.ndarray, ids) -> tuple[float, float, int]:
        """Largest ratio [-] of a zone's pressure (``pressure`` [Pa] per zone) to the top of its law
        among the zones ``ids``: over those with the full p_max, and over those whose law failed (a
        halved top); 0 if none. And how many of them are loaded beyond their law's floor (nearly
        perfect contact, ``micro.laws.resolved_gap``)."""
        reach = pressure[ids] / self.law_top[ids]
        halved = self.levels[ids] > 0
        return (float(reach[~halved].max(initial=0.0)), float(reach[halved].max(initial=0.0)),
                int(np.count_nonzero(pressure[ids] > self.floors[ids])))

    def zone_frames(self) -> tuple[np.ndarray, np.ndarray]:
        """Centre (Z, 3) [m] of every zone in space and the (Z, 2, 3) in-plane directions (e_u, e_v)
        of its interface (zone coordinates and sliding directions are along these)."""
        centres, axes = [], []
        for plane, grid in zip(self.planes, self.grids):
            for zid in range(grid.n_zones):
                u, v = self.zones[len(centres)].centre
                centres.append(plane.origin + u * plane.frame[0] + v * plane.frame[1])
                axes.append(plane.frame[:2])
        return np.array(centres), np.array(axes)

    def zone_sliding(self, motion, weights=None) -> tuple[np.ndarray, np.ndarray]:
        """Per zone, the counter-face's sliding in the zone's plane per unit of body 1's motion
        (``motion``: a Rotation, per rad; else a translation, per m) [m] and its direction [rad
        from the zone's +u axis], at the zone's centre. With ``weights`` per global facet (the
        normal force p A [N]), the sliding is their weighted mean over the zone's facets where
        they sum to > 0, so that a zone's mu F s equals the macro frictional work of its facets
        (at the centre a one-zone pin wore 2.7 % more than k_w W)."""
        centres, axes = self.zone_frames()
        reach, angle = in_plane_motion(motion, centres, axes)
        if weights is not None:
            on = self.zone_of_facet >= 0
            zone = self.zone_of_facet[on]
            at_facet, _ = in_plane_motion(motion, self.tm.interface.midpoints[on], axes[zone])
            total = np.bincount(zone, weights[on], minlength=len(reach))
            moment = np.bincount(zone, (weights[on] * at_facet), minlength=len(reach))
            reach = np.where(total > 0, moment / np.where(total > 0, total, 1.0), reach)
        return reach, angle

    def heights(self) -> np.ndarray:
        """Current zone topographies (Z, ny, nx) [m]."""
        return np.stack([z.surface.heights for z in self.zones])

    def set_heights(self, ids, heights) -> None:
        """New topographies of the zones ``ids`` (worn or restored)."""
        for zid, h in zip(ids, heights):
            self.zones[zid] = self.zones[zid].with_heights(h)

    def wear_depth(self) -> np.ndarray:
        """Accumulated wear depth fields (Z, ny, nx) [m] (the permanent deformation taken out)."""
        return self.initial - self.heights() - self.plastic

    def zone_wear_volume(self, depth: np.ndarray) -> np.ndarray:
        """Worn volume of each zone [m^3] from its depth field (Z, ny, nx) [m]: over its facets'
        area (``cover``)."""
        cell = np.array([z.surface.dx * z.surface.dy for z in self.zones])     # each zone's own (several pads)
        return depth.sum(axis=(-2, -1)) * cell * self.cover

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
                if level == P_MAX_HALVINGS:           # the messages name the last p_max: say how it came
                    raise LawError([dataclasses.replace(f, message=f"{f.message}, reached by {level} halvings of "
                                                        f"micro.p_max = {self.spec.p_max:.3g} Pa") for f in exc.failures],
                                   exc.result) from None
                laws = exc.result
                self.levels[[f.zone_id for f in exc.failures]] = level + 1
            computed += self.pool.stats.computed - self.pool.stats.failed
            nodes += laws.nodes if laws is not None else []
        self.law.set_laws(ZoneLaws(nodes, self.spec), self.zone_of_facet)
        self.laws_computed = computed
        self.floors[:] = np.inf
        self.floors[[nd.zone_id for nd in nodes]] = [nd.floored for nd in nodes]
        return computed

    def wear_in_series(self, compliance) -> None:
        """The facet laws with each zone's compliance ``compliance`` [m/Pa] (one per zone id) in series
        (``ZoneLaws.in_series``), until ``update_laws`` (collective)."""
        laws = self.law.laws
        self.law.set_laws(laws.in_series(np.asarray(compliance, dtype=float)[laws.ids]), self.zone_of_facet)

    def zone_of(self, name: str) -> np.ndarray:
        """Zone ids of rough interface ``name``."""
        k = self.names.index(name)
        start = sum(g.n_zones for g in self.grids[:k])
        return np.arange(start, start + self.grids[k].n_zones)

    def interface_sums(self, values) -> dict:
        """{name: sum of the per-zone ``values`` over its zones} for each rough interface when there
        are several (the history's per-interface columns), else {}."""
        return {} if len(self.names) < 2 else {n: float(np.sum(values[self.zone_of(n)])) for n in self.names}

    def facet_stiffness(self, gap, penalty) -> np.ndarray:
        """Per-facet contact stiffness dp/dg [Pa/m] at the gaps ``gap`` [m]: the zone laws' on the rough
        facets, the ``penalty`` K_n [Pa/m, per facet] where the others touch (before: 0 on an
        interface in perfect contact that carried its pad's force; a user trial)."""
        return np.where(self.zone_of_facet >= 0, self.law.evaluate(gap)[1], penalty * (np.asarray(gap) <= 0))

    def rms_height(self, heights) -> float:
        """RMS [m] of the rough surface: each zone's ``heights`` (Z, ny, nx) about that zone's own mean,
        the zones' mean squares weighted by the area of the facets each holds (``covered_area``: an
        edge zone of a round face counts for its part, a zone of a small pad for its size). The
        roughness a zone's contact sees, not the spread of the zones' worn depths: about one mean for
        all zones (before), the zones' different wear depths made it grow while each zone's roughness
        wore flat (user trial M: 0.401 -> 0.427 um, each zone's 1.25 nm)."""
        spread = heights.var(axis=(1, 2))
        return float(np.sqrt(np.average(spread, weights=self.covered_area)))

    def datum_gap(self, forces) -> np.ndarray:
        """Per-facet uniform gap g_0 [m] of each rough interface at which its rigid rough body
        carries ``forces[name]`` [N] (bisection); 0 on the other facets."""
        areas, laws = self.tm.interface.areas, self.law.laws
        out = np.zeros(len(areas))
        masks = self.tm.interface.masks()
        for name in self.names:
            mask, target = masks[name], forces[name]
            rows = laws.rows(self.zone_of_facet[mask])
            g_open = laws.mechanical.g_open[rows]

            def force(G):
                gap = np.zeros(len(areas))
                gap[mask] = G
                return float(areas[mask] @ self.law.evaluate(gap)[0][mask])

            out[mask] = gap_at(force, target, g_open.max(), np.median(g_open - laws.mechanical.gap[rows, -1]))
        return out

    def track_depth(self, volume, weight) -> np.ndarray:
        """Per-facet depth [m] by which a rotating counter-face recedes when it loses ``volume``
        [m^3] in each zone (Z,): a zone's volume is shared among its facets in proportion to
        ``weight`` (per facet, e.g. the frictional power mu p |w| dA; the facet areas where a zone's
        weights sum to 0), then spread along the circle of each facet's radius r about the rotation
        axis over the counter-face (the rough interfaces in one plane share it): depth(r) =
        Σ_f V_f K(r − r_f) / (2 π r), K a hat of unit integral and half-width one interface
        element, so that the depth integrated over the track is the volume lost. 0 off the rough
        interfaces."""
        motion, iface = self.tm.spec.motion, self.tm.interface
        if not isinstance(motion, Rotation):
            raise InputError("counter-face wear", type(motion).__name__, "needs a rotating counter-face (its "
                             "wear spreads over a circular track)")
        zone_of, areas = self.zone_of_facet, iface.areas
        rough = zone_of >= 0
        w = np.where(rough, np.asarray(weight, dtype=float), 0.0)
        total = np.bincount(zone_of[rough], w[rough], minlength=len(self.zones))
        area = np.bincount(zone_of[rough], areas[rough], minlength=len(self.zones))
        share = np.where(total[zone_of] > 0, w / np.where(total[zone_of] > 0, total[zone_of], 1.0),
                         areas / np.where(area[zone_of] > 0, area[zone_of], 1.0))
        lost = np.where(rough, np.asarray(volume, dtype=float)[zone_of] * share, 0.0)        # m^3 per facet
        radius = np.linalg.norm(motion.velocity(iface.midpoints), axis=1)       # |e x (x - c)|: the distance from the axis
        half = np.sqrt(2.0 * np.median(areas[rough]))                  # the side of a typical facet
        depth = np.zeros(len(areas))
        masks = iface.masks()
        for group in self._planes():
            on = np.any([masks[name] for name in group], axis=0)
            depth[on] = track_spread(radius[on], radius[on], lost[on], half)
        return depth

    def _planes(self) -> list[list[str]]:
        """The rough interfaces grouped by the plane they lie in (one face of the counter-face)."""
        iface, masks, groups = self.tm.interface, self.tm.interface.masks(), []
        size = self.tm.spec.length_scale
        keys = []
        for name, plane in zip(self.names, self.planes):
            n = plane.frame[2]
            offset = float(np.mean(iface.midpoints[masks[name]] @ n))
            for k, (m, c) in enumerate(keys):
                if abs(abs(n @ m) - 1) < 1e-9 and abs(offset * np.sign(n @ m) - c) < 1e-9 * size:
                    groups[k].append(name)
                    break
            else:
                keys.append((n, offset))
                groups.append([name])
        return groups

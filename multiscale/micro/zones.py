"""Zones of a macro contact interface: their footprints, their own roughness patches, and the
Love/Boussinesq integrals of a uniform pressure on a footprint (thesis §1.4.2, §7.2.1).

The interface is the plane (x, y) [m] of the macro model. A zone is a rectangle or a triangle of
that plane carrying its own micro patch (a grid of heights); zones are independent of the macro
facets (a facet uses the law of the zone holding its centroid, ``ZoneGrid.zone_of``) and each
carries its own topography, so wear can update one without touching the others.

Heights are measured from one datum common to all zones of an interface (the mean plane of the
surface they were cut from; the mean plane of each patch for generated zones), positive towards
the counter-face. Keeping that datum fixed is what lets the laws of worn zones stay comparable.

Love's integral: the normal displacement of a half-space under a uniform pressure p on a region
Ω is u(x, y) = p/(π E*) ∫∫_Ω dA'/|x − x'| (Boussinesq); ``Zone.love`` takes it, at the centroid
or averaged, from the closed forms of ``multiscale.references.love``.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace

import numpy as np

from multiscale.errors import InputError, check_count, check_field, check_instance
from multiscale.micro.surface import Surface, check_surface, fractal_surface, whole_numbers
from multiscale.references.love import (love_rectangle, love_rectangle_mean, love_triangle, love_triangle_mean,
                                        triangle_area, triangle_vertices)

# A top layer thinner than this share of a zone's cell is refused on its non-periodic grid
# (``layered.LayeredKernel.influence``; a scene's check, ``scene_rough.thin_layer``): its kernel's
# excess reaches q ~ 1/h, and the Hankel quadratures, whose panels resolve the Bessel oscillations
# up to the grid's extent, grow like (cell / h): 4.8 s at h = dx/156, 47 s and 1.7 GB at dx/1560 on
# 64², out of memory at dx/1.5e6 (a periodic grid takes the spectrum itself: no limit)
THINNEST = 1e-3


# --------------------------------------------------------------------------- footprints
def _inside_triangle(x, y, V) -> np.ndarray:
    """Points strictly inside the (counter-clockwise) triangle, or on its top/left edges.

    The top-left rule of rasterisation: a point on an edge shared by two triangles of a
    conforming triangulation belongs to exactly one of them. The side of an edge is evaluated
    from its lexicographically first vertex, so that two triangles sharing it get exactly
    opposite values (no point is lost or counted twice to round-off).
    """
    inside = np.ones(np.broadcast(x, y).shape, dtype=bool)
    for A, B in ((V[0], V[1]), (V[1], V[2]), (V[2], V[0])):
        P, Q, sign = (A, B, 1.0) if tuple(A) <= tuple(B) else (B, A, -1.0)
        e = Q - P
        side = sign * (e[0] * (y - P[1]) - e[1] * (x - P[0]))   # > 0 on the inner (left) side
        d = B - A
        top_left = (d[1] < 0) or (d[1] == 0 and d[0] < 0)      # left edge, or horizontal top edge
        inside &= (side > 0) | ((side == 0) & top_left)
    return inside


# --------------------------------------------------------------------------- zones
@dataclass(frozen=True)
class Zone:
    """One zone of the interface and its own roughness patch.

    ``surface``: the patch (its grid covers the zone; not periodic: an isolated patch on a
    half-space, as in the thesis). ``origin``: interface coordinates [m] of the patch corner
    (cell (0, 0)'s lower-left corner). ``triangle``: None for a rectangular zone (the whole
    patch), else its (3, 2) vertices [m] in interface coordinates; the patch then covers its
    bounding box and only the cells whose centres lie inside carry roughness.
    """

    id: int
    surface: Surface
    origin: tuple[float, float] = (0.0, 0.0)
    triangle: np.ndarray | None = None
    _hash: str = field(default="", init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.surface.heights.ndim != 2:
            raise InputError("surface", self.surface.heights.shape, "a zone carries one 2-D patch")
        object.__setattr__(self, "origin", tuple(float(v) for v in self.origin))
        if self.triangle is not None:
            V = triangle_vertices(self.triangle)
            object.__setattr__(self, "triangle", V)
            if not self.mask.any():
                raise InputError("triangle", V, "no cell centre of the patch lies inside the triangle")
        digest = hashlib.sha1()
        digest.update(np.ascontiguousarray(self.surface.heights).tobytes())
        digest.update(np.array(self.surface.heights.shape + (self.surface.dx, self.surface.dy)).tobytes())
        if self.triangle is not None:
            digest.update((self.triangle - np.array(self.origin)).tobytes())
        object.__setattr__(self, "_hash", digest.hexdigest())

    @property
    def topography_hash(self) -> str:
        """SHA-1 of the heights, grid and footprint relative to the patch (not of the id/origin)."""
        return self._hash

    @property
    def shape(self) -> tuple[int, int]:
        return self.surface.shape

    @property
    def mask(self) -> np.ndarray:
        """Cells of the patch inside the zone (all of them for a rectangle)."""
        if self.triangle is None:
            return np.ones(self.shape, dtype=bool)
        x, y = self.surface.coordinates()
        return _inside_triangle(x[None, :] + self.origin[0], y[:, None] + self.origin[1], self.triangle)

    @property
    def area(self) -> float:
        """Nominal area [m²] of the zone (the exact triangle for a triangular zone)."""
        if self.triangle is not None:
            return triangle_area(self.triangle)
        Lx, Ly = self.surface.size
        return Lx * Ly

    @property
    def centre(self) -> tuple[float, float]:
        """Centroid [m] in interface coordinates."""
        if self.triangle is not None:
            return tuple(self.triangle.mean(axis=0))
        Lx, Ly = self.surface.size
        return self.origin[0] + Lx / 2, self.origin[1] + Ly / 2

    @property
    def top(self) -> float:
        """Highest point of the zone [m] above the datum (first touch of a rigid flat)."""
        return float(self.surface.heights[self.mask].max())

    def love(self, where: str = "average") -> float:
        """Love's integral of the footprint [m] at its 'centre' (centroid) or its 'average'.

        The mean/centre normal displacement of a uniform pressure p on the zone is p/(π E*)
        times this (Eq. 1.29–1.30; the triangle's Boussinesq integral for triangular zones).
        """
        if where not in ("average", "centre"):
            raise InputError("where", where, "one of 'average', 'centre'")
        if self.triangle is not None:
            if where == "average":
                return love_triangle_mean(self.triangle)
            cx, cy = self.centre
            return float(love_triangle(cx, cy, self.triangle))
        a, b = self.surface.size[0] / 2, self.surface.size[1] / 2
        return love_rectangle_mean(a, b) if where == "average" else float(love_rectangle(0.0, 0.0, a, b))

    def with_heights(self, heights) -> "Zone":
        """The same zone with new heights (e.g. after a wear step), same datum and grid."""
        h = np.asarray(heights, dtype=float)
        if h.shape != self.shape:
            raise InputError("heights", h.shape, f"must keep the zone's grid {self.shape}")
        return replace(self, surface=Surface(h, self.surface.dx, self.surface.dy, periodic=False))


@dataclass(frozen=True)
class ZoneGrid:
    """A rectangular grid of zones over the interface, independent of the macro facet size.

    ``origin`` [m]: lower-left corner; ``counts`` (nx, ny); ``size`` (Lx, Ly) [m] of one zone.
    Zone ids run row by row: id = ix + nx * iy.
    """

    origin: tuple[float, float]
    counts: tuple[int, int]
    size: tuple[float, float]

    def __post_init__(self):
        object.__setattr__(self, "counts", whole_numbers("counts", self.counts, 2))
        size = check_field("size", self.size)
        if size.shape != (2,) or np.any(size <= 0):
            raise InputError("size", self.size, "a pair (Lx, Ly) of sizes > 0 [m]")
        origin = check_field("origin", self.origin)
        if origin.shape != (2,):
            raise InputError("origin", self.origin, "a pair (x, y) of finite numbers [m]")
        object.__setattr__(self, "size", (float(size[0]), float(size[1])))
        object.__setattr__(self, "origin", (float(origin[0]), float(origin[1])))

    @property
    def n_zones(self) -> int:
        return self.counts[0] * self.counts[1]

    def counts_for(self, area: float) -> tuple[int, int]:
        """The most zones per direction over this grid's extent, in its proportions, whose area is at
        least ``area`` [m^2] (at least 1 each)."""
        scale = np.sqrt(self.size[0] * self.size[1] / area)
        return tuple(max(int(np.floor(n * scale)), 1) for n in self.counts)

    def zone_of(self, x, y) -> np.ndarray:
        """Zone id holding each point (e.g. facet centroids) [m]; points outside raise. A point
        within 1e-9 of a zone's size from a border belongs to the zone above it, whatever the
        round-off (facets on zone borders: 180 of 940 on the thesis pin face, assigned by the
        last bit of their midpoints, which the rank count changed)."""
        ix = np.floor(np.round((np.asarray(x, dtype=float) - self.origin[0]) / self.size[0], 9)).astype(int)
        iy = np.floor(np.round((np.asarray(y, dtype=float) - self.origin[1]) / self.size[1], 9)).astype(int)
        nx, ny = self.counts
        # a point on the far border belongs to the last zone
        ix = np.where(ix == nx, nx - 1, ix)
        iy = np.where(iy == ny, ny - 1, iy)
        outside = (ix < 0) | (ix >= nx) | (iy < 0) | (iy >= ny)
        if np.any(outside):
            raise InputError("x, y", "points", f"{int(outside.sum())} point(s) lie outside the zone grid")
        return ix + nx * iy

    def zone_origin(self, zone_id: int) -> tuple[float, float]:
        ix, iy = zone_id % self.counts[0], zone_id // self.counts[0]
        return self.origin[0] + ix * self.size[0], self.origin[1] + iy * self.size[1]


def cut_zones(surface: Surface, counts, origin=(0.0, 0.0)) -> tuple[ZoneGrid, list[Zone]]:
    """Cut a large (generated or measured) surface into counts = (nx, ny) rectangular zones.

    The surface's grid must divide evenly (equal zones share one FFT grid and batch together).
    Heights keep the surface's datum. Returns the grid and the zones, ids row by row.
    """
    h = check_surface(surface).heights
    if h.ndim != 2:
        raise InputError("surface", h.shape, "cut one 2-D surface at a time")
    nx, ny = whole_numbers("counts", counts, 2)
    Ny, Nx = h.shape
    if nx < 1 or ny < 1 or Nx % nx or Ny % ny:
        raise InputError("counts", counts, f"must divide the surface grid {Nx} x {Ny} (columns x rows)")
    mx, my = Nx // nx, Ny // ny
    if mx < 4 or my < 4:
        raise InputError("counts", counts, "zones need at least 4 x 4 cells")
    grid = ZoneGrid(origin, (nx, ny), (mx * surface.dx, my * surface.dy))
    zones = []
    for iy in range(ny):
        for ix in range(nx):
            patch = Surface(h[iy * my:(iy + 1) * my, ix * mx:(ix + 1) * mx].copy(), surface.dx, surface.dy,
                            periodic=False)
            zid = ix + nx * iy
            zones.append(Zone(zid, patch, grid.zone_origin(zid)))
    return grid, zones


def generate_zones(grid: ZoneGrid, n: int, hurst: float, k_min, k_max, rms: float, seed: int = 0) -> list[Zone]:
    """One independent fractal patch of n x n cells per zone of ``grid`` (``fractal_surface``
    parameters; cut-offs in wavelengths per zone). Zone i gets the seed spawned from (seed, i),
    so a zone's patch does not depend on how many zones there are or who generates it."""
    check_instance("grid", grid, ZoneGrid, "a ZoneGrid")
    seed = check_count("seed", seed, minimum=0)
    zones = []
    for zid in range(grid.n_zones):
        zone_seed = np.random.SeedSequence([seed, zid])
        s = fractal_surface(n, grid.size, hurst, k_min, k_max, rms, seed=zone_seed)
        zones.append(Zone(zid, Surface(s.heights, s.dx, s.dy, periodic=False), grid.zone_origin(zid)))
    return zones


def cut_triangles(surface: Surface, triangles, ids=None, origin=(0.0, 0.0)) -> list[Zone]:
    """Triangular zones (e.g. the interface facets of a tetrahedral mesh) cut from a surface.

    ``triangles`` (m, 3, 2) [m] in interface coordinates, the surface's corner at ``origin``.
    Each zone's patch is the bounding box of its triangle on the surface grid; cells are assigned
    by their centres (top-left rule: every cell of a conforming triangulation to exactly one zone).
    """
    T = np.asarray(triangles, dtype=float)
    if T.ndim != 3 or T.shape[1:] != (3, 2):
        raise InputError("triangles", T.shape, "expected an (m, 3, 2) array of vertices")
    ids = np.arange(len(T)) if ids is None else np.asarray(ids, dtype=int)
    if ids.shape != (len(T),):
        raise InputError("ids", ids.shape, f"need one id per triangle ({len(T)})")
    h, dx, dy = surface.heights, surface.dx, surface.dy
    Ny, Nx = h.shape
    x0, y0 = (float(v) for v in origin)
    zones = []
    for zid, V in zip(ids, T):
        if V[:, 0].min() < x0 - 1e-12 * Nx * dx or V[:, 0].max() > x0 + Nx * dx * (1 + 1e-12) \
                or V[:, 1].min() < y0 - 1e-12 * Ny * dy or V[:, 1].max() > y0 + Ny * dy * (1 + 1e-12):
            raise InputError("triangles", V.tolist(), "the triangle must lie on the surface")
        c0, c1 = _cell_range(V[:, 0].min() - x0, V[:, 0].max() - x0, dx, Nx)
        r0, r1 = _cell_range(V[:, 1].min() - y0, V[:, 1].max() - y0, dy, Ny)
        patch = Surface(h[r0:r1, c0:c1].copy(), dx, dy, periodic=False)
        zones.append(Zone(int(zid), patch, (x0 + c0 * dx, y0 + r0 * dy), triangle=V))
    return zones


def _cell_range(lo: float, hi: float, d: float, n: int) -> tuple[int, int]:
    """Cells [i0, i1) whose centres may lie in [lo, hi] (one cell of margin; the zone's mask
    decides), widened to the 4 cells a patch needs."""
    i0 = max(int(np.floor(lo / d - 0.5)), 0)
    i1 = min(int(np.ceil(hi / d - 0.5)) + 1, n)
    if i1 - i0 < 4:
        i1 = min(i0 + 4, n)
        i0 = max(i1 - 4, 0)
    return i0, i1

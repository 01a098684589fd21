"""Temperature probes: a thermocouple's reading [K] at a point of a body, for a history column.

A probe is a point [m] of the geometry's frame in one body, or in one part of it. The heat problem
of a rotating body 1 is solved in a fixed (Eulerian) frame (``macro.thermal``), so a probe there
stays at its place in space (a rubbing thermocouple's or a pyrometer's spot) unless it ``turns``:
a thermocouple embedded in the disc, turning with it (read through slip rings), passes round its
circle about the axis once a revolution; it reads the mean over ``RING`` points equally spaced on
that circle, what a thermocouple whose time constant tau is long against the revolution reads
(omega tau >> 1) of a field that changes little in one. Slower, or at rest, a real one reads its
own angle, which this does not follow (a review: a car-brake disc's circle 0.5 mm deep spanned
119.6 to 140.7 degC round its 127.0 degC mean in a stop). A probe of body 0 reads at its point.

The temperature is the finite-element field's value at the point (``Function.eval`` in the cell
holding it: P1, or P2 in a rotating body). A point on a body's surface belongs to the body; one
outside it by at most ``TOUCH`` times its closest cell's size (a curved face's facets lie inside
it: a car-brake disc's rim 44 um under the true one at 7 mm cells) is read in that cell and the
run says how far out it is. Every rank takes part: each point is read on the lowest rank owning a
cell that holds it and the values are summed over the ranks, so that every rank has them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from dolfinx import fem, geometry
from mpi4py import MPI
from scipy.spatial import cKDTree

from multiscale.errors import InputError, InputErrors

RING = 64          # points on a turning probe's circle
TOUCH = 0.1        # how far outside its body [x its closest cell's size] a probe is still read (in that cell)


@dataclass(frozen=True)
class ProbeSpec:
    """One probe: its ``name``, ``point`` [m], the index of its ``body`` (None: the body holding the
    point), the ``part`` (a region name of that body; None: any) and whether it ``turns`` with the
    rotating body 1 (its circle's mean)."""

    name: str
    point: tuple
    body: int | None = None
    turns: bool = False
    part: str | None = None


@dataclass(frozen=True)
class Located:
    """Where a probe reads: its body's index, the name of the region (part) at its point, its
    distance [m] from the nearest interface facet (how deep below the friction face it sits; in the
    rotating body from the track the interfaces sweep: the least over its circle), how far [m]
    outside the meshed body it lies (0 inside; ``TOUCH``) and ``facet``, the interface facet (global
    index) whose midpoint is nearest (to its circle's points in the rotating body)."""

    name: str
    body: int
    part: str
    depth: float
    outside: float
    facet: int


def ring(point, rotation, n: int = RING) -> np.ndarray:
    """``n`` points (n, 3) [m] equally spaced on the circle of ``point`` about the ``rotation``'s axis
    (the first one the point itself)."""
    e = np.asarray(rotation.axis, dtype=float) / np.linalg.norm(rotation.axis)
    r = np.asarray(point, dtype=float) - np.asarray(rotation.centre, dtype=float)
    along = (r @ e) * e
    a = r - along                                   # Rodrigues' rotation of r about e
    theta = 2 * np.pi * np.arange(n) / n
    return (np.asarray(rotation.centre, dtype=float) + along + np.outer(np.cos(theta), a)
            + np.outer(np.sin(theta), np.cross(e, a)))


class Probes:
    """The probes of a model: ``temperatures()`` reads them [K] (collective), ``located`` says where
    each one is. Raises ``InputError`` (``InputErrors`` for several; on every rank) for a point in
    no body (or not in its part), or, without its ``body``, in both (on the interface); for a
    turning probe outside the rotating body."""

    def __init__(self, tm, temperatures: Sequence[fem.Function], specs: Sequence[ProbeSpec], rotation=None):
        self.tm, self.T, self.comm, self.names = tm, list(temperatures), tm.comm, [s.name for s in specs]
        self.reads: list[list] = [[] for _ in self.T]      # per body: (probe index, points, local cells) on this rank
        self.counts = np.array([RING if s.turns else 1 for s in specs], dtype=float)
        self._trees: dict = {}
        located, errors = [], []
        for k, s in enumerate(specs):
            try:
                located.append(self._locate(k, s, rotation))
            except InputError as exc:
                errors.append(exc)
        if errors:
            raise errors[0] if len(errors) == 1 else InputErrors(errors)
        self.located = tuple(located)

    def _locate(self, k: int, s: ProbeSpec, rotation) -> Located:
        """Where probe ``k`` reads (its points kept in ``reads``; collective)."""
        tm, where = self.tm, f"output.probes.{s.name}"
        if s.turns and rotation is None:
            raise InputError(f"{where}.turns", True, "a rotating body to turn with (this geometry has none)")
        if s.turns and s.body == 0:
            raise InputError(f"{where}.turns", True, f"a probe of the rotating body {tm.bodies[1].name!r} "
                             f"(this one is of {tm.bodies[0].name!r}, which does not turn)")
        points = ring(s.point, rotation) if s.turns else np.asarray([s.point], dtype=float)
        bodies = [s.body] if s.body is not None else ([1] if s.turns else [0, 1])
        found = {i: self._cells(i, points, s.part) for i in bodies}
        inside = [i for i, (owner, _, _) in found.items() if (owner >= 0).all()]
        if len(inside) != 1:
            at = f"{np.round(np.multiply(s.point, 1e3), 4).tolist()} mm"
            names = [repr(s.part or tm.bodies[i].name) for i in bodies]
            if inside:
                raise InputError(f"{where}.point", None, f"{at} lies on the faces of both {names[0]} and "
                                 f"{names[1]}: give {where}.body")
            gap = min(float(found[i][2].max()) for i in bodies)
            among = "in neither " + " nor ".join(names) if len(names) > 1 else "not in " + names[0]
            circle = " all round its circle about the axis" if s.turns else ""
            raise InputError(f"{where}.point", None, f"{at} is {among}{circle}: {gap * 1e3:.3g} mm outside its "
                             f"meshed surface ({self._boxes(bodies)})")
        i = inside[0]
        owner, cells, gaps = found[i]
        mine = owner == self.comm.rank
        self.reads[i].append((k, points[mine], cells[mine]))
        swept = ring(s.point, rotation) if i == 1 and rotation is not None else points    # the track it passes
        depth = tm.interface.distance(swept)
        near, facet = cKDTree(tm.interface.midpoints).query(swept)
        return Located(s.name, i, self._part(tm.bodies[i], owner[0], cells[0]),
                       0.0 if depth < 1e-9 * tm.spec.length_scale else depth, float(gaps.max()),
                       int(facet[np.argmin(near)]))

    def worn(self, depths) -> list[str]:
        """The probes in material worn away: each whose facet's worn depth [m] (``depths``: per body,
        global arrays per facet) reaches its depth below the face (not one on the face: it reads the
        face, which the model keeps where it was; a review found a pyrometer's spot named at 0.14 um).
        The bodies keep their shapes, so such a probe reads on in material that is gone (a user
        trial's thermocouple 2 mm into a pad worn 4.5 mm deep)."""
        out = []
        for where in self.located:
            worn = depths[where.body]
            if where.depth > 0 and worn[where.facet] >= where.depth:
                out.append(f"probe {where.name}: {where.depth * 1e3:.3g} mm from the interface, where "
                           f"{where.part} wore {worn[where.facet] * 1e3:.3g} mm: it read "
                           "material worn away (the bodies keep their shapes)")
        return out

    def temperatures(self) -> dict[str, float]:
        """{probe name: its temperature [K]} now, the same on every rank (collective)."""
        local = np.zeros(len(self.names))
        for T, reads in zip(self.T, self.reads):
            for k, points, cells in reads:
                if len(points):
                    local[k] += T.eval(points, cells).sum()
        total = np.empty_like(local)
        self.comm.Allreduce(local, total, op=MPI.SUM)
        return dict(zip(self.names, total / self.counts))

    def _tree(self, i: int, part: str | None):
        """(cells, bounding-box tree, midpoint tree) of this rank's owned cells of body ``i`` (of its
        region ``part``), made once."""
        if (i, part) not in self._trees:
            body = self.tm.bodies[i]
            mesh, tdim = body.mesh, body.mesh.topology.dim
            cells = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
            if part is not None:
                cells = cells[np.isin(body.region_tags[cells], [r.tag for r in body.spec.regions if r.name == part])]
            trees = (geometry.bb_tree(mesh, tdim, entities=cells), geometry.create_midpoint_tree(mesh, tdim, cells)) \
                if len(cells) else (None, None)
            self._trees[(i, part)] = (cells, *trees)
        return self._trees[(i, part)]

    def _cells(self, i: int, points: np.ndarray, part: str | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(owner rank, this rank's local cell, distance [m] outside the mesh) of each point in body
        ``i`` (its ``part``): the lowest rank whose owned cells hold it, else the one whose closest
        cell is nearest, within ``TOUCH`` of that cell's size; owner -1 if none (collective)."""
        mesh = self.tm.bodies[i].mesh
        tdim = mesh.topology.dim
        cells, tree, middle = self._tree(i, part)
        cell, gap, reach = np.full(len(points), -1, dtype=np.int32), np.full(len(points), np.inf), np.zeros(len(points))
        if len(cells):
            hits = geometry.compute_colliding_cells(mesh, geometry.compute_collisions_points(tree, points), points)
            for j in range(len(points)):
                if len(hits.links(j)):
                    cell[j], gap[j] = hits.links(j)[0], 0.0
            far = np.flatnonzero(cell < 0)
            if len(far):
                near = geometry.compute_closest_entity(tree, middle, mesh, points[far])
                cell[far], gap[far] = near, np.sqrt(geometry.squared_distance(mesh, tdim, near, points[far]))
                reach[far] = TOUCH * mesh.h(tdim, near)
        gaps, reaches = np.array(self.comm.allgather(gap)), np.array(self.comm.allgather(reach))   # (ranks, points)
        best = gaps.min(axis=0)
        first = np.argmax(gaps <= best, axis=0)
        owner = np.where(best <= reaches[first, np.arange(len(points))], first, -1)
        return owner, cell, best

    def _boxes(self, bodies) -> str:
        """The bounding boxes [mm] of ``bodies``, for an error message (collective)."""
        out = []
        for i in bodies:
            lo, hi = self.tm.bodies[i].box()
            out.append(f"{self.tm.bodies[i].name!r} spans {np.round(lo * 1e3, 3).tolist()} to "
                       f"{np.round(hi * 1e3, 3).tolist()} mm")
        return "; ".join(out)

    def _part(self, body, owner: int, cell: int) -> str:
        """The name of ``body``'s region holding local ``cell`` of rank ``owner`` (collective)."""
        tag = int(body.region_tags[cell]) if owner == self.comm.rank else -1
        tag = self.comm.allreduce(tag, op=MPI.MAX)
        return next(r.name for r in body.spec.regions if r.tag == tag)

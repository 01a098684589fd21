"""Temperature probes: a thermocouple's reading [K] at a point of a body, for a history column.

A probe is a point [m] of the geometry's frame in one body. The heat problem of a rotating body 1 is
solved in a fixed (Eulerian) frame (``macro.thermal``), so a probe there stays at its place in space
(a rubbing thermocouple's or a pyrometer's spot) unless it ``turns``: a thermocouple embedded in the
disc, turning with it (read through slip rings), passes round its circle about the axis once a
revolution; it reads the mean over ``RING`` points equally spaced on that circle (the trapezoidal
rule of a periodic function: it converges geometrically with the points for a smooth field; the
thermocouple's own lag, which a fast disc's revolution leaves far behind, is not modelled). A probe
of body 0, which does not move, reads at its point.

The temperature is the finite-element field's value at the point (``Function.eval`` in the cell
holding it: P1, or P2 in a rotating body). A point on a body's surface belongs to the body; one
outside it by at most ``TOUCH`` times the body's extent (a faceted curved face, a rounded coordinate)
is read in its closest cell. Every rank takes part: each point is read on the lowest rank owning a
cell that holds it and the values are summed over the ranks, so that every rank has them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from dolfinx import fem, geometry
from mpi4py import MPI

from multiscale.errors import InputError

RING = 64          # points on a turning probe's circle
TOUCH = 1e-6       # how far outside its body [x the body's extent] a probe is still read (in the closest cell)


@dataclass(frozen=True)
class ProbeSpec:
    """One probe: its ``name``, ``point`` [m], the index of its ``body`` (None: the body holding the
    point) and whether it ``turns`` with the rotating body 1 (its circle's mean)."""

    name: str
    point: tuple
    body: int | None = None
    turns: bool = False


@dataclass(frozen=True)
class Located:
    """Where a probe reads: its body's index, the name of the region (part) at its point and its
    distance [m] from the nearest interface facet (how deep below the friction face it sits); in the
    rotating body from the track the interfaces sweep (the least over its circle)."""

    name: str
    body: int
    part: str
    depth: float


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
    each one is. Raises ``InputError`` (on every rank) for a point in no body, or, without its
    ``body``, in both (on the interface); for a turning probe outside the rotating body."""

    def __init__(self, tm, temperatures: Sequence[fem.Function], specs: Sequence[ProbeSpec], rotation=None):
        self.T, self.comm, self.names = list(temperatures), tm.comm, [s.name for s in specs]
        self.reads: list[list] = [[] for _ in self.T]      # per body: (probe index, points, local cells) on this rank
        self.counts = np.zeros(len(specs))
        located = []
        for k, s in enumerate(specs):
            where = f"output.probes.{s.name}"
            if s.turns and rotation is None:
                raise InputError(f"{where}.turns", True, "a rotating body to turn with (this geometry has none)")
            if s.turns and s.body == 0:
                raise InputError(f"{where}.turns", True, f"a probe of the rotating body {tm.bodies[1].name!r} "
                                 f"(this one is of {tm.bodies[0].name!r}, which does not turn)")
            points = ring(s.point, rotation) if s.turns else np.asarray([s.point], dtype=float)
            bodies = [s.body] if s.body is not None else ([1] if s.turns else [0, 1])
            found = {i: self._cells(tm.bodies[i].mesh, points) for i in bodies}
            inside = [i for i, (owner, _) in found.items() if (owner >= 0).all()]
            if len(inside) != 1:
                at = f"{np.round(np.multiply(s.point, 1e3), 4).tolist()} mm"
                names = [repr(tm.bodies[i].name) for i in bodies]
                raise InputError(f"{where}.point", None, f"{at} lies on the faces of both {names[0]} and {names[1]}: "
                                 f"give {where}.body" if inside else
                                 f"{at} is {'in neither ' + ' nor '.join(names) if len(names) > 1 else 'not in ' + names[0]}"
                                 f"{' all round its circle about the axis' if s.turns else ''} ({self._boxes(tm, bodies)})")
            i = inside[0]
            owner, cells = found[i]
            mine = owner == self.comm.rank
            self.reads[i].append((k, points[mine], cells[mine]))
            self.counts[k] = len(points)
            swept = ring(s.point, rotation) if i == 1 and rotation is not None else points    # the track it passes
            located.append(Located(s.name, i, self._part(tm.bodies[i], owner[0], cells[0]), self._depth(tm, swept)))
        self.located = tuple(located)

    def temperatures(self) -> dict[str, float]:
        """{probe name: its temperature [K]} now, the same on every rank (collective)."""
        local = np.zeros(len(self.names))
        for T, reads in zip(self.T, self.reads):
            for k, points, cells in reads:
                if len(points):
                    local[k] += T.eval(points, cells).sum()
        return dict(zip(self.names, self.comm.allreduce(local, op=MPI.SUM) / np.maximum(self.counts, 1)))

    def _cells(self, mesh, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(owner rank, local cell on it) of each point in ``mesh``: the lowest rank whose owned cells
        hold it, else whose closest cell is within ``TOUCH``; owner -1 if none (collective)."""
        tdim = mesh.topology.dim
        owned = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
        cell, gap = np.full(len(points), -1, dtype=np.int32), np.full(len(points), np.inf)
        if len(owned):
            tree = geometry.bb_tree(mesh, tdim, entities=owned)
            hits = geometry.compute_colliding_cells(mesh, geometry.compute_collisions_points(tree, points), points)
            for j in range(len(points)):
                if len(hits.links(j)):
                    cell[j], gap[j] = hits.links(j)[0], 0.0
            far = np.flatnonzero(cell < 0)
            if len(far):
                near = geometry.compute_closest_entity(tree, geometry.create_midpoint_tree(mesh, tdim, owned), mesh,
                                                       points[far])
                cell[far], gap[far] = near, np.sqrt(geometry.squared_distance(mesh, tdim, near, points[far]))
        gaps = np.array(self.comm.allgather(gap))                   # (ranks, points)
        best = gaps.min(axis=0)
        owner = np.where(best <= TOUCH * self._extent(mesh), np.argmax(gaps <= best, axis=0), -1)
        return owner, cell

    def _extent(self, mesh) -> float:
        """The diagonal [m] of the mesh's bounding box (collective)."""
        lo, hi = self._box(mesh)
        return float(np.linalg.norm(hi - lo))

    def _box(self, mesh) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners [m] of the mesh's vertices (collective)."""
        x, lo, hi = mesh.geometry.x, np.empty(3), np.empty(3)
        self.comm.Allreduce(x.min(axis=0, initial=np.inf), lo, op=MPI.MIN)
        self.comm.Allreduce(x.max(axis=0, initial=-np.inf), hi, op=MPI.MAX)
        return lo, hi

    def _boxes(self, tm, bodies) -> str:
        """The bounding boxes [mm] of ``bodies``, for an error message (collective)."""
        def mm(v):
            return np.round(v * 1e3, 3).tolist()
        return "; ".join(f"{tm.bodies[i].name!r} spans {mm(lo)} to {mm(hi)} mm"
                         for i, (lo, hi) in ((i, self._box(tm.bodies[i].mesh)) for i in bodies))

    def _part(self, body, owner: int, cell: int) -> str:
        """The name of ``body``'s region holding local ``cell`` of rank ``owner`` (collective)."""
        tag = int(body.region_tags[cell]) if owner == self.comm.rank else -1
        tag = self.comm.allreduce(tag, op=MPI.MAX)
        return next(r.name for r in body.spec.regions if r.tag == tag)

    def _depth(self, tm, points: np.ndarray) -> float:
        """The least distance [m] from ``points`` (n, 3) to an interface facet (collective)."""
        m = tm.interface.mesh
        owned = np.arange(len(tm.interface.owned_index), dtype=np.int32)
        d = np.inf
        if len(owned):
            tree = geometry.bb_tree(m, m.topology.dim, entities=owned)
            near = geometry.compute_closest_entity(tree, geometry.create_midpoint_tree(m, m.topology.dim, owned), m,
                                                   points)
            d = float(np.sqrt(geometry.squared_distance(m, m.topology.dim, near, points).min()))
        return self.comm.allreduce(d, op=MPI.MIN)

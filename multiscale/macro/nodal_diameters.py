"""Nodal diameters of a disc's mode shapes: how a brake NVH report names a mode ("6 ND out-of-plane").

A mode of an axisymmetric disc varies around the axis like cos(n θ − φ) (a standing wave, n nodal
diameters) or e^{±i n θ} (a travelling one; friction-coupled modes are such mixes). Its motion at the
nodes of the rotating body is resolved into cylindrical components about the rotation axis (axial:
out-of-plane; radial and tangential: in-plane) and each component into angular harmonics
n = 0 … ``N_MAX`` ring by ring: the nodes are binned by radius into ``RINGS`` rings of equal width,
so that a shape changing sign across the radius (nodal circles) does not cancel itself. Each node
carries a weight w_k, its share of the body's volume (a mesh finer under the pads would otherwise
count that arc more: a uniform motion came out 1 ND on a review's graded mesh). The power of
harmonic n in a ring of weight W is (|Σ w_k a_k e^{−inθ_k}|² + |Σ w_k a_k e^{inθ_k}|²)/W (once for
n = 0), its share of Σ w_k |a_k|² (Parseval, for a ring's volume spread evenly in θ); the mode's
nodal diameters are the harmonic with the most power over all rings and components, its ``share``
that power's share of the motion (near 1 on an axisymmetric disc; lower where the hat, bolts or
pads break the symmetry, or the mesh is too coarse to resolve n), ``out_of_plane`` the axial share,
``axial_nodal_diameters`` the harmonic of the axial component alone (an in-plane mode's axial part,
what radiates and what a test measures, can have other nodal diameters than its radial one).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from multiscale.errors import InputError

N_MAX = 24      # highest angular harmonic resolved (a brake disc's modes below 16 kHz: up to ~14 ND)
RINGS = 12      # radial rings the harmonics are taken in


@dataclass
class DiscShapes:
    """Angular content of each mode on the rotating body (arrays per mode)."""

    nodal_diameters: np.ndarray   # the angular harmonic n with the most power [-], int
    share: np.ndarray             # that harmonic's share of the motion [-]
    out_of_plane: np.ndarray      # share of the motion along the rotation axis [-] (1: bending, 0: in-plane)
    axial_nodal_diameters: np.ndarray   # the harmonic of the axial motion alone (what radiates) [-], int


def nodal_diameters(points, motion, axis, centre, comm=None, weights=None) -> DiscShapes:
    """Classify modes by the angular harmonics of their motion (module docstring).

    ``points`` (n, 3) [m]: the nodes (this rank's, each once); ``motion`` (n, 3, n_modes) complex:
    each mode's displacement there [any unit]; ``axis``, ``centre``: the rotation axis (any length)
    and a point on it [m]; ``comm``: the mpi4py communicator over which the nodes are spread
    (collective: every rank raises a bad argument); ``weights`` (n,): each node's volume [m^3]
    (default: equal)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    motion = np.asarray(motion)
    w = np.ones(len(points)) if weights is None else np.asarray(weights, dtype=float).reshape(-1)
    e = np.asarray(axis, dtype=float)
    bad = [InputError("motion.shape", motion.shape, f"must be ({len(points)}, 3, n_modes)")] \
        if motion.ndim != 3 or motion.shape[:2] != (len(points), 3) else []
    bad += [InputError("weights", f"{w.size} values", f"one >= 0 per node ({len(points)})")] \
        if w.size != len(points) or not np.all(w >= 0) else []
    bad += [InputError("axis", axis, "must be a finite non-zero vector")] \
        if e.shape != (3,) or not np.all(np.isfinite(e)) or np.linalg.norm(e) == 0 else []
    if comm is not None:                                  # (one rank raised, the others waited: a review)
        bad = [b for part in comm.allgather(bad[:1]) for b in part][:1]
    if bad:
        raise bad[0]
    e = e / np.linalg.norm(e)
    x = points - np.asarray(centre, dtype=float)
    radial = x - np.outer(x @ e, e)
    r = np.linalg.norm(radial, axis=1)
    er = radial / np.where(r > 0, r, 1.0)[:, None]
    ex = np.cross(e, np.eye(3)[np.argmin(np.abs(e))])   # a unit vector normal to the axis: theta = 0
    ex /= np.linalg.norm(ex)
    theta = np.arctan2(er @ np.cross(e, ex), er @ ex)
    et = np.cross(e, er)
    parts = np.stack([np.einsum("nc,ncm->nm", np.broadcast_to(b, x.shape), motion) for b in (e, er, et)])
    #                                                                   (3, n, modes): axial, radial, tangential
    reduce = (lambda a, op=MPI.SUM: comm.allreduce(a, op=op)) if comm is not None else (lambda a, op=None: a)
    r_min, r_max = reduce(r.min(initial=np.inf), MPI.MIN), reduce(r.max(initial=-np.inf), MPI.MAX)
    ring = np.minimum(((r - r_min) / max(r_max - r_min, 1e-300) * RINGS).astype(int), RINGS - 1)
    waves = np.exp(-1j * np.outer(np.arange(N_MAX + 1), theta)) * w                # (N_MAX + 1, n), weighted
    sums = np.zeros((2, RINGS, 3, N_MAX + 1, motion.shape[2]), complex)
    for k in range(RINGS):
        on = ring == k
        sums[0, k] = np.einsum("hn,cnm->chm", waves[:, on], parts[:, on])
        sums[1, k] = np.einsum("hn,cnm->chm", waves[:, on].conj(), parts[:, on])
    ring_weight = reduce(np.bincount(ring, weights=w, minlength=RINGS))
    sums = reduce(sums)
    total = reduce(np.einsum("n,cnm->cm", w, np.abs(parts) ** 2))                      # (3, modes)
    power = (np.abs(sums[0]) ** 2 + np.abs(sums[1]) ** 2) / np.where(ring_weight > 0, ring_weight, 1.0)[
        :, None, None, None]
    power[:, :, 0] /= 2                                                                # n = 0 counted once
    per_n = power.sum(axis=(0, 1))                                                     # (N_MAX + 1, modes)
    motion_sq = np.maximum(total.sum(axis=0), np.finfo(float).tiny)
    n = np.argmax(per_n, axis=0)
    axial = np.argmax(power[:, 0].sum(axis=0), axis=0)                                 # (an in-plane mode's axial
    return DiscShapes(n, np.minimum(per_n[n, np.arange(per_n.shape[1])] / motion_sq, 1.0), total[0] / motion_sq,
                      axial)                                                           # part: an NVH trial)

"""Load faces: their areas, the vector areas of their parts, and the resultant of a load on each.

A load is a force shared by area, a traction along the load direction, or a fluid pressure
(traction −p n) whose resultant is −p times the face's vector area ∫ n dA. The geometry is summed
from the facets (``TwoBodyMesh.face_vector_areas``): the model is meshed with linear tetrahedra,
so the sums are exact and need no compiled form.
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from multiscale.errors import InputError
from multiscale.macro.mesh import TwoBodyMesh

# A fluid pressure on a face whose normals (nearly) cancel, a cylinder's wall, has no resultant: the
# faceting of a closed band leaves a few per mille of its area as vector area (a 10 mm radius wall
# meshed at 15 mm: 0.5 %, which the contact then carried). Below this share of the area it counts as
# 0 (a dome has 0.5, a cone of 3 degrees half-angle 0.05).
NO_RESULTANT = 0.05


def check_load_faces(tm: TwoBodyMesh) -> None:
    """InputError, on every rank, naming a load face with facets between two parts (a pad bonded to
    its backplate), which carry no load (before: their share of a force went to the other load
    faces, said only by a pad carrying no force after the run; a user trial)."""
    for f in tm.spec.load_faces:
        inner = tm.inner_facets(f)
        if inner:
            raise InputError("loading.faces", f, f"{inner} of its facets lie between two parts (bonded), where no "
                             "load acts; name outer faces only (the back of a backplate)")


def load_face_areas(tm: TwoBodyMesh, load_kind: str) -> dict:
    """Area [m^2] of each load face whose product with a pressure is the face's resultant: the
    face area for a traction along the load direction; for a fluid pressure (traction -p n) the
    length of its vector area |int n dA|, the area projected normal to the resultant (a flat face:
    its area; a hemisphere of radius R: pi R^2, not 2 pi R^2), 0 below ``NO_RESULTANT`` of the area.
    A face made of flat parts that face opposite ways (one surface naming the backs of an inboard
    and an outboard pad) counts with the sum of the parts' areas (``load_face_parts``): the
    pressure pushes each part with its own resultant, and a force is their sum of magnitudes, as
    over several load faces."""
    if load_kind != "fluid":
        return {f: _sum(tm, np.linalg.norm(tm.face_vector_areas(f), axis=1)) for f in tm.spec.load_faces}
    return {f: float(sum(np.linalg.norm(v) for v in parts)) for f, parts in load_face_parts(tm).items()}


def load_face_parts(tm: TwoBodyMesh) -> dict:
    """Vector areas int n dA [m^2] of the parts of each load face that a fluid pressure pushes as
    one (-p times each is its resultant): the face's, or its two flat parts facing opposite ways
    (``_opposite_parts``); none if it has no resultant (below ``NO_RESULTANT`` of its area)."""
    out = {}
    for f in tm.spec.load_faces:
        vector = tm.face_vector_areas(f)
        area, resultant = _sum(tm, np.linalg.norm(vector, axis=1)), _sum(tm, vector)
        some = bool(np.linalg.norm(resultant) > NO_RESULTANT * area)
        parts = _opposite_parts(tm, vector, resultant if some else None, area)
        out[f] = parts if parts is not None else [resultant] if some else []
    return out


FLAT = 0.9     # a part of a load face is flat if its vector area is at least this share of its area


def _sum(tm: TwoBodyMesh, values: np.ndarray):
    """Sum over the rows of every rank (a float, or an array of the rows' shape)."""
    total = tm.comm.allreduce(np.asarray(values, dtype=float).sum(axis=0), op=MPI.SUM)
    return float(total) if np.ndim(total) == 0 else total


def _opposite_parts(tm: TwoBodyMesh, vector: np.ndarray, resultant, area: float) -> list | None:
    """The vector areas of a face's two parts whose normals point along and against a direction
    (the resultant's, or without one the principal direction of its normals) if both are flat
    (``FLAT``) and each holds more than ``NO_RESULTANT`` of the area; else None (a dome, a
    cylinder's wall). ``vector``: the vector areas of the face's facets on this rank. Measured:
    two pad backs of 400 and 900 mm^2 facing -z and +z as one surface counted as its net 500 mm^2,
    so 1000 N asked put 800 N and 1800 N on the pads."""
    a = np.linalg.norm(vector, axis=1)
    n = vector / np.maximum(a, np.finfo(float).tiny)[:, None]
    if resultant is None:
        moment = _sum(tm, a[:, None, None] * n[:, :, None] * n[:, None, :])
        resultant = np.linalg.eigh(moment)[1][:, -1]
    along = n @ (np.asarray(resultant, dtype=float) / np.linalg.norm(resultant))
    out = []
    for side in (along > 0.0, along < 0.0):
        part, part_vector = _sum(tm, a[side]), _sum(tm, vector[side])
        if not (part > NO_RESULTANT * area and np.linalg.norm(part_vector) >= FLAT * part):
            return None
        out.append(part_vector)
    return out


UNBALANCED = 0.01    # a clamp whose sides' resultants differ by more than this share of their sum is noted


def clamp_imbalance(tm: TwoBodyMesh, pressure: float) -> str | None:
    """A note if a fluid ``pressure`` [Pa] pushes load parts (``load_face_parts``) against each
    other, clamping (an inboard and an outboard pad, a piston and a caliper's bore), with a net
    resultant beyond ``UNBALANCED`` of their sum: the difference goes into the supports (the
    disc's mount), not through both contacts; None otherwise (all parts push one way, a pin on a
    disc: the whole load goes to the mount, as meant). Measured: pads of 400 and 900 mm^2 on both
    sides of a disc under 2 MPa carried 800 N and 1800 N, the mount 1000 N, without a word."""
    forces = [-pressure * v for parts in load_face_parts(tm).values() for v in parts]
    if not any(a @ b < 0 for a in forces for b in forces):
        return None
    net, total = np.linalg.norm(np.sum(forces, axis=0)), sum(np.linalg.norm(f) for f in forces)
    if net <= UNBALANCED * total:
        return None
    return (f"loading.faces = {list(tm.spec.load_faces)}: the load pushes parts against each other (clamping) with "
            f"{', '.join(f'{np.linalg.norm(f):.4g}' for f in forces)} N; the difference, {net:.4g} N, goes into "
            "the supports (the rotating body's mount), not through the contacts on both sides (a floating caliper "
            "would balance them): give the sides equal areas if the clamp is meant to be balanced")


def load_face_forces(tm: TwoBodyMesh, load: float, load_kind: str) -> dict:
    """Resultant [N] of the load on each load face: its area's share of a force ``load`` [N]
    (``load_kind="force"``), or the (fluid) pressure ``load`` [Pa] times its ``load_face_areas``."""
    area = load_face_areas(tm, load_kind)
    total = sum(area.values())
    return {f: float(load) * (a / total if load_kind == "force" else a) for f, a in area.items()}

"""Checkpoints of a run: one HDF5 file rewritten atomically after every macro step.

A checkpoint holds scalar attributes (step, time, a fingerprint of the scene), global numpy
arrays (zone topographies, per-zone state, history columns) and finite-element functions. Functions
are stored by the coordinates of their degrees of freedom (rounded to ``1e-9`` of a length scale),
not by process-local indices, so a run can resume on another number of MPI ranks: every rank reads
the file and picks the values of its own dofs. Only rank 0 writes; the file is written to a
temporary name and renamed, so a run killed while writing keeps its previous checkpoint.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import h5py
import numpy as np

from multiscale.errors import InputError


def fingerprint(text: str) -> str:
    """Short hash of a text (e.g. the repr of a scene) to detect a changed set-up on resume."""
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _dof_table(f, scale: float):
    """(keys, values) of the owned dofs of ``f``: keys (n, 3) rounded coordinates, values (n, bs)."""
    V = f.function_space
    n = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    keys = np.round(V.tabulate_dof_coordinates()[:n] / scale, 9)
    return keys, f.x.array.reshape(-1, bs)[:n]


def save(path, comm, *, attrs: dict, arrays: dict, functions: dict, scale: float = 1.0) -> Path:
    """Write a checkpoint (collective). ``arrays``: name -> numpy array (same on every rank);
    ``functions``: name -> dolfinx Function (gathered by dof coordinates)."""
    path = Path(path)
    tables = {name: comm.gather(_dof_table(f, scale), root=0) for name, f in functions.items()}
    if comm.rank == 0:
        tmp = path.with_name(path.name + ".tmp")
        with h5py.File(tmp, "w") as h5:
            for key, value in attrs.items():
                h5.attrs[key] = value
            h5.attrs["length_scale"] = scale
            for name, value in arrays.items():
                h5.create_dataset(f"arrays/{name}", data=np.asarray(value))
            for name, parts in tables.items():
                h5.create_dataset(f"functions/{name}/keys", data=np.concatenate([k for k, _ in parts]))
                h5.create_dataset(f"functions/{name}/values", data=np.concatenate([v for _, v in parts]))
        os.replace(tmp, path)
    comm.barrier()
    return path


def load(path, comm, functions: dict) -> tuple[dict, dict]:
    """Read a checkpoint: sets ``functions`` (name -> Function, matched by dof coordinates) and
    returns (attrs, arrays). Raises InputError if a function's dofs are not in the file."""
    with h5py.File(path, "r") as h5:
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in h5.attrs.items()}
        arrays = {}
        if "arrays" in h5:
            h5["arrays"].visititems(lambda name, item: arrays.__setitem__(name, item[...])
                                    if isinstance(item, h5py.Dataset) else None)
        stored = {name: (h5[f"functions/{name}/keys"][...], h5[f"functions/{name}/values"][...])
                  for name in functions}
    scale = float(attrs["length_scale"])
    for name, f in functions.items():
        keys, values = _dof_table(f, scale)
        index = _match(stored[name][0], keys)
        if np.any(index < 0):
            raise InputError("--resume", str(path), f"the mesh changed: field {name!r} has dofs the "
                             "checkpoint does not know")
        bs = values.shape[1]
        owned = stored[name][1][index]
        f.x.array.reshape(-1, bs)[:len(keys)] = owned
        f.x.scatter_forward()
    return attrs, arrays


def _match(stored: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Row of ``stored`` equal to each row of ``wanted`` (-1 where none)."""
    both = np.concatenate([stored, wanted])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    where = np.full(inverse.max(initial=-1) + 1, -1)
    where[inverse[:len(stored)]] = np.arange(len(stored))
    return where[inverse[len(stored):]]

"""Scalar histories on disk, MPI-safe entry points and progress bars (no DOLFINx).

``History`` collects one row of scalars per recorded step (units in ``UNITS``) and writes them as
datasets of ``history.h5`` (only rank 0 writes; its figure is ``multiscale.plots.history``).
Fields for ParaView are written by ``multiscale.macro.output``.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import h5py
import numpy as np
from mpi4py import MPI
from tqdm import tqdm

from multiscale.errors import OutputError

UNITS = {"time": "s", "force": "N", "pressure": "Pa", "temperature": "K", "heat": "J", "iterations": "-",
         "volume": "m^3", "depth": "m", "rms": "m", "work": "J"}


def unit_of(name: str) -> str:
    """Unit of a history column from its name (e.g. max_temperature_pin -> K)."""
    for word, unit in UNITS.items():
        if word in name:
            return unit
    return "-"


class History:
    """Scalar time series: ``append(time=..., interface_force=..., ...)``, same keys every row."""

    def __init__(self):
        self.columns: dict[str, list[float]] = {}

    def append(self, **row: float) -> None:
        if self.columns and set(row) != set(self.columns):
            raise KeyError(f"history row keys {sorted(row)} differ from {sorted(self.columns)}")
        for key, value in row.items():
            self.columns.setdefault(key, []).append(float(value))

    def __getitem__(self, key: str) -> np.ndarray:
        return np.asarray(self.columns[key])

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()), []))

    def write(self, path: Path, attrs: dict | None = None) -> Path:
        """Write every column as a dataset (attribute ``unit``) of an HDF5 file."""
        with h5py.File(path, "w") as f:
            for key, values in self.columns.items():
                f.create_dataset(key, data=np.asarray(values)).attrs["unit"] = unit_of(key)
            for key, value in (attrs or {}).items():
                f.attrs[key] = value
        return path

    @classmethod
    def read(cls, path: Path) -> "History":
        h = cls()
        with h5py.File(path, "r") as f:
            h.columns = {key: list(f[key][...]) for key in f.keys()}
        return h


def on_root(comm, write, what: str):
    """Run ``write()`` on rank 0 only (a file every rank needs written once) and make its failure
    collective: an ``OSError`` there (disk full, read-only folder) raises ``OutputError`` naming
    ``what`` on every rank, instead of leaving the others waiting. Returns ``write()``'s value on
    rank 0, None elsewhere."""
    value, failure = None, None
    if comm.rank == 0:
        try:
            value = write()
        except OSError as exc:
            failure = f"cannot write {what}: {exc.strerror or exc}"
    failure = comm.bcast(failure, root=0)
    if failure:
        raise OutputError(failure)
    return value


def ended_together(comm, timeout: float = 10.0) -> bool:
    """Called by a rank that met an error: True if every rank of ``comm`` reaches this call within
    ``timeout`` [s] (the error was collective: each can end cleanly), False if not (another rank is
    waiting in a collective operation that will never complete: the caller must abort the job)."""
    if comm.size == 1:
        return True
    request, start = comm.Ibarrier(), time.monotonic()
    while not request.Test():
        if time.monotonic() - start > timeout:
            return False
        time.sleep(0.01)
    return True


def abort_on_exception(comm=None) -> None:
    """Make an uncaught exception on one MPI rank abort every rank (instead of a hang)."""
    comm = comm or MPI.COMM_WORLD
    if comm.size == 1 or getattr(sys.excepthook, "_multiscale_abort", False):
        return
    previous = sys.excepthook

    def hook(kind, value, tb):
        previous(kind, value, tb)
        sys.stderr.flush()
        comm.Abort(1)

    hook._multiscale_abort = True
    sys.excepthook = hook


def progress(iterable, comm, **kwargs):
    """tqdm progress bar on rank 0, the plain iterable elsewhere."""
    if comm.rank != 0:
        return iterable
    return tqdm(iterable, **kwargs)

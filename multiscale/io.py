"""Results on disk: XDMF time series for ParaView, an HDF5 history, PNG plots, MPI-safe entry points.

``History`` collects one row of scalars per recorded step (units in ``UNITS``) and writes them as
datasets of ``history.h5`` and as ``history.png``. ``FieldWriter`` writes one XDMF file per body
(displacement, temperature, von Mises stress) and one for the interface (per-facet contact
pressure and frictional heat flux). Only rank 0 writes HDF5 and PNG files; XDMF is collective.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

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
        import h5py
        with h5py.File(path, "w") as f:
            for key, values in self.columns.items():
                f.create_dataset(key, data=np.asarray(values)).attrs["unit"] = unit_of(key)
            for key, value in (attrs or {}).items():
                f.attrs[key] = value
        return path

    @classmethod
    def read(cls, path: Path) -> "History":
        import h5py
        h = cls()
        with h5py.File(path, "r") as f:
            h.columns = {key: list(f[key][...]) for key in f.keys()}
        return h

    def plot(self, path: Path, title: str = "") -> Path:
        """PNG of the history: force, max pressure, max temperatures, heat per body vs time."""
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = self["time"]
        groups = [("interface force [N]", ["interface_force"], 1.0, 0.0),
                  ("max contact pressure [MPa]", ["max_pressure"], 1e-6, 0.0),
                  ("max temperature [°C]", [k for k in self.columns if k.startswith("max_temperature")], 1.0, -273.15),
                  ("heat into body [J]", [k for k in self.columns if k.startswith("heat_total")], 1.0, 0.0)]
        groups = [g for g in groups if g[1] and all(k in self.columns for k in g[1])]
        fig, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 3.4), squeeze=False)
        for ax, (label, keys, scale, shift) in zip(axes[0], groups):
            for key in keys:
                ax.plot(t, self[key] * scale + shift, "o-", ms=3, label=key.split("_")[-1] if len(keys) > 1 else None)
            ax.set_xlabel("time [s]")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            values = np.concatenate([self[k] * scale + shift for k in keys])
            if np.ptp(values) <= 1e-6 * np.abs(values).max(initial=0.0):     # constant to round-off
                centre = values.mean()
                ax.set_ylim(centre - 0.05 * abs(centre) - 1e-30, centre + 0.05 * abs(centre) + 1e-30)
            if len(keys) > 1:
                ax.legend()
        fig.suptitle(title)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return path


class FieldWriter:
    """XDMF time series: ``<folder>/<body>.xdmf`` per body and ``<folder>/interface.xdmf``.

    The files are closed after every write, so that a run killed between two writes leaves them
    readable; ``append`` continues existing files (a resumed run: no new mesh)."""

    def __init__(self, folder: Path, tm, body_functions, interface_functions, append: bool = False):
        from dolfinx.io import XDMFFile
        self.files = []
        self.groups = []
        self.append = append
        self._XDMFFile, self._comm = XDMFFile, tm.comm
        for body, functions in zip(tm.bodies, body_functions):
            self._open(Path(folder) / f"{body.name}.xdmf", body.mesh, functions)
        self._open(Path(folder) / "interface.xdmf", tm.interface.mesh, interface_functions)

    def _open(self, path, mesh, functions):
        if not self.append:
            f = self._XDMFFile(self._comm, str(path), "w")
            f.write_mesh(mesh)
            f.close()
        self.files.append(path)
        self.groups.append((path, list(functions)))

    def write(self, time: float) -> None:
        for path, functions in self.groups:
            with self._XDMFFile(self._comm, str(path), "a") as f:
                for u in functions:
                    f.write_function(u, time)

    def close(self) -> None:
        self.groups = []


def abort_on_exception(comm=None) -> None:
    """Make an uncaught exception on one MPI rank abort every rank (instead of a hang)."""
    from mpi4py import MPI
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
    from tqdm import tqdm
    return tqdm(iterable, **kwargs)

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
import json
import shutil
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from multiscale import __version__
from multiscale.arrays import unique_rows
from multiscale.errors import InputError
from multiscale.io import History, on_root, replacing

FORMAT = 14   # what a checkpoint holds; 2: P2 temperatures in a rotating body, min_temperature_* history columns;
#               3: the drive's state (speed, engagement, load last solved) and the area-weighted effusivity partition;
#               4: the law_reach_halved history column, quadratic cells in the field files beside it;
#               5: min_temperature_<body>_in_<material> history columns; 6: wear_substeps, near_perfect_zones;
#               7: form_depth (the rough body's wear at its facets beyond their zones' means), the zones' rates;
#               8: max_slip_speed, min_slip_speed history columns (a mu(v) law); 9: no fields_written (a step's
#               fields are written before its checkpoint, ``workflows.stepping``); 10: the zones' exchange_full;
#               11: the facets' wear in perfect contact (exposure per facet, its sliding x load, pending);
#               12: the exposure's temperature-weighted rows; 13: its rows rated at each substep's temperatures;
#               14: no pending facet wear (a released implicit update solves at the held load)


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


def _digest(datasets: dict) -> str:
    """SHA-256 of the datasets (name -> array) in name order: a checkpoint's checksum."""
    h = hashlib.sha256()
    for name in sorted(datasets):
        value = np.ascontiguousarray(datasets[name])
        h.update(name.encode())
        h.update(str(value.dtype).encode())
        h.update(value.tobytes())
    return h.hexdigest()


def save(path, comm, *, attrs: dict, arrays: dict, functions: dict, scale: float = 1.0) -> Path:
    """Write a checkpoint (collective). ``arrays``: name -> numpy array (same on every rank);
    ``functions``: name -> dolfinx Function (gathered by dof coordinates). A failure to write
    (disk full, ...) is an ``OutputError`` on every rank; the previous checkpoint stays."""
    path = Path(path)
    tables = {name: comm.gather(_dof_table(f, scale), root=0) for name, f in functions.items()}

    def write():
        data = {f"arrays/{name}": np.asarray(value) for name, value in arrays.items()}
        for name, parts in tables.items():
            data[f"functions/{name}/keys"] = np.concatenate([k for k, _ in parts])
            data[f"functions/{name}/values"] = np.concatenate([v for _, v in parts])
        with replacing(path) as part, h5py.File(part, "w") as h5:
            for key, value in attrs.items():
                h5.attrs[key] = value
            h5.attrs["length_scale"] = scale
            h5.attrs["format"], h5.attrs["version"] = FORMAT, __version__
            h5.attrs["checksum"] = _digest(data)
            for name, value in data.items():
                h5.create_dataset(name, data=value)
    on_root(comm, write, f"the checkpoint {path}")
    return path


def save_step(path, comm, step: int, history: History, fingerprint: "Fingerprint", attrs: dict, arrays: dict,
              model) -> Path:
    """The checkpoint of a run after macro step ``step`` (collective): ``attrs`` and ``arrays`` (the
    run's state), the history so far, the scene's ``fingerprint``, and the fields of ``model`` (a
    ``macro.model.MacroModel``: its ``functions``, by coordinates at its mesh's length scale)."""
    arrays = {**arrays, **{f"history/{k}": np.asarray(v) for k, v in history.columns.items()}}
    attrs = {"step": step, **fingerprint.attrs(), "ranks": comm.size, **attrs}
    return save(path, comm, attrs=attrs, arrays=arrays, functions=model.functions, scale=model.tm.spec.length_scale)


@dataclass
class Restored:
    """What a run resumes from: its last macro step and history."""

    step: int                  # last macro step done
    history: History


def restored(attrs: dict, arrays: dict) -> Restored:
    """The ``Restored`` of a checkpoint read by ``load`` (written by ``save_step``)."""
    history = History()
    history.columns = {k[len("history/"):]: list(v) for k, v in arrays.items() if k.startswith("history/")}
    return Restored(int(attrs["step"]), history)


def load(path, comm, functions: dict, fingerprint: "Fingerprint | None" = None) -> tuple[dict, dict]:
    """Read a checkpoint: sets ``functions`` (name -> Function, matched by dof coordinates) and
    returns (attrs, arrays). Raises InputError on every rank (each reads the whole file) if the
    file is unreadable, truncated or corrupted (its checksum), of another ``FORMAT``, not of the
    scene whose ``fingerprint`` is given (``same_scene``; None: not checked), or a function's dofs
    are not in it (on any rank: the mesh changed)."""
    data = {}
    try:
        with h5py.File(path, "r") as h5:
            attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in h5.attrs.items()}
            h5.visititems(lambda name, item: data.__setitem__(name, item[...]) if isinstance(item, h5py.Dataset)
                          else None)
        scale, checksum = float(attrs["length_scale"]), attrs["checksum"]
        stored = {name: (data[f"functions/{name}/keys"], data[f"functions/{name}/values"]) for name in functions}
    except (OSError, KeyError, ValueError) as exc:
        raise InputError("--resume", str(path), f"the checkpoint cannot be read ({exc}): the file is truncated "
                         "or damaged; start again with --overwrite") from None
    if _digest(data) != checksum:
        raise InputError("--resume", str(path), "the checkpoint is corrupted (its checksum does not match its "
                         "data); start again with --overwrite")
    if int(attrs.get("format", 1)) != FORMAT:
        raise InputError("--resume", str(path), f"written by another version of multiscale (checkpoint format "
                         f"{int(attrs.get('format', 1))}, this one reads {FORMAT}); start again with --overwrite")
    if fingerprint is not None:
        same_scene(attrs, fingerprint, path)
    arrays = {name[len("arrays/"):]: value for name, value in data.items() if name.startswith("arrays/")}
    tables = {name: _dof_table(f, scale) for name, f in functions.items()}
    index = {name: _match(stored[name][0], keys) for name, (keys, _) in tables.items()}
    unknown = comm.allgather([name for name, i in index.items() if np.any(i < 0)])   # (one rank's: all raise)
    if any(unknown):
        raise InputError("--resume", str(path), f"the mesh changed: field {sorted(set(sum(unknown, [])))[0]!r} "
                         "has dofs the checkpoint does not know")
    for name, f in functions.items():
        keys, values = tables[name]
        f.x.array.reshape(-1, values.shape[1])[:len(keys)] = stored[name][1][index[name]]
        f.x.scatter_forward()
    return attrs, arrays


def mark(path, comm, **attrs) -> None:
    """Set scalar attributes of the checkpoint ``path`` (e.g. that the run finished); outside the checksum, which covers the data (collective).
    All or nothing: a copy is marked and replaces the checkpoint (HDF5 edits in place are not
    crash-safe: a run killed while its only checkpoint was being edited could lose it)."""
    path = Path(path)

    def write():
        with replacing(path) as part:
            shutil.copyfile(path, part)
            with h5py.File(part, "r+") as h5:
                for key, value in attrs.items():
                    h5.attrs[key] = value
    on_root(comm, write, f"the checkpoint {path}")


def file_digest(path) -> str:
    """SHA-1 of a file's bytes (read in blocks)."""
    digest = hashlib.sha1()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@dataclass(frozen=True)
class Fingerprint:
    """What a run's results depend on: ``digest``, compared on ``--resume``, and ``inputs``, the
    same named (a scene key or "file <path>" -> its value or its bytes' SHA-1), to say what changed."""

    digest: str = ""
    inputs: Mapping[str, str] = field(default_factory=dict)

    def attrs(self) -> dict:
        """The checkpoint attributes that hold it."""
        return {"scene": self.digest, "inputs": json.dumps(dict(self.inputs))}


CHANGES_NAMED = 6    # at most this many changes are named in a refused --resume


def changes(before: Mapping[str, str], after: Mapping[str, str]) -> list[str]:
    """The inputs that differ between two ``Fingerprint.inputs``, in words."""
    out = []
    for key in sorted(set(before) | set(after)):
        old, new = before.get(key), after.get(key)
        if old == new:
            continue
        if key.startswith("file "):
            out.append(f"{key} ({'new' if old is None else 'gone' if new is None else 'other bytes'})")
        else:
            out.append(f"{key} = {new}" if old is None else f"{key} (was {old}, gone)" if new is None
                       else f"{key}: {old} -> {new}")
    return out


def same_scene(attrs: dict, fingerprint: Fingerprint, path) -> None:
    """InputError unless the checkpoint attributes ``attrs`` (of ``path``) are of the scene whose
    ``fingerprint`` is given (``--resume`` of a changed scene or of changed input files); the error
    names what changed when the checkpoint says (it holds ``Fingerprint.inputs``)."""
    if attrs.get("scene") != fingerprint.digest:
        written = attrs.get("version", __version__)       # (older checkpoints did not say)
        other = "" if written == __version__ else f", or multiscale (it was written by {written}, this is {__version__})"
        named = changes(json.loads(attrs["inputs"]), fingerprint.inputs) if "inputs" in attrs else []
        more = f" and {len(named) - CHANGES_NAMED} more" if len(named) > CHANGES_NAMED else ""
        what = f" ({'; '.join(named[:CHANGES_NAMED])}{more})" if named else ""
        raise InputError("--resume", str(path), f"the scene or a file it reads (geometry, measured surface){other} "
                         f"changed since this checkpoint was written{what}; run it with --overwrite")


def peek(path, comm) -> dict:
    """The scalar attributes of a checkpoint, read by rank 0 for every rank without loading its
    data ({} if there is none or it cannot be read: ``load`` then says why)."""
    def read():
        try:
            with h5py.File(path, "r") as h5:
                return {k: (v.decode() if isinstance(v, bytes) else v) for k, v in h5.attrs.items()}
        except (OSError, KeyError, ValueError):
            return {}
    return comm.bcast(read() if comm.rank == 0 else None, root=0)


def _match(stored: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Row of ``stored`` equal to each row of ``wanted`` (-1 where none)."""
    both = np.concatenate([stored, wanted])
    inverse = unique_rows(both).inverse
    where = np.full(inverse.max(initial=-1) + 1, -1)
    where[inverse[:len(stored)]] = np.arange(len(stored))
    return where[inverse[len(stored):]]

"""Mode pairs between two squeal runs of one mesh (``multiscale modes A B``): the modal assurance
criterion MAC_ij = |a_i^H b_j|^2 / (a_i^H a_i  b_j^H b_j) of their complex mode shapes, read from
the runs' ``modes_<part>.bp`` (VTX) and ``modes.csv``, and each mode of A paired with the mode of B
it resembles most. For what an NVH engineer compares: forward against reverse rotation, a finer
mesh of the pads' friction, damping or not, serial against parallel (Allemang 2003, "The modal
assurance criterion, twenty years of use and abuse", Sound and Vibration 37(8)).

The shapes are the nodal displacements [1/kg^0.5] as the files hold them (no mass weighting, as a
test correlation takes them). Nodes are matched by their coordinates, part by part, so runs on any
number of ranks compare (a parallel run's files hold the nodes its ranks share once per rank);
runs on different meshes are refused. A reverse run of a brake symmetric about a plane through its
axis is the forward run's mirror image (``mirrored``): its modes are compared mirrored, taken at
the forward run's nodes from the nearest of its own (``pair(..., transfer=True)``: a mesh that is
not node for node symmetric). No DOLFINx: adios2 reads the files.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multiscale.errors import InputError

SHAPE = "mode shape {} part [1/kg^0.5]"
SAME_POINT = 1e-9        # nodes this share of the mesh's extent apart are one node
PAIRED = 0.9             # a pair whose MAC is below this is said to be weak
AXES = "xyz"


@dataclass
class ModeSet:
    """The modes of one run: number (1, 2, ... as in modes.csv), frequency [Hz], growth rate
    sigma [1/s] (> 0 grows), the nodes (n, 3) [m] and shapes (3 n, modes) [1/kg^0.5] of its parts."""

    folder: Path
    numbers: np.ndarray
    frequency: np.ndarray
    sigma: np.ndarray
    points: np.ndarray
    shapes: np.ndarray
    sizes: tuple = ()            # nodes of each part, in the order of ``points``
    mirror: str = ""             # "x", "y" or "z" when reflected (``mirrored``)


@dataclass
class ModePairs:
    """Each mode of A with the mode of B of the largest MAC: ``best`` (index into B's modes),
    ``mac`` (A's modes x B's), ``shift`` of the frequency [%] (f_B - f_A) / f_A (NaN at f_A = 0:
    a static divergence's mode)."""

    a: ModeSet
    b: ModeSet
    mac: np.ndarray
    best: np.ndarray
    shift: np.ndarray
    distance: np.ndarray | None = None   #: [m] from each node of A to B's nearest node (``transfer``), else None


def _read_part(path: Path) -> tuple[np.ndarray, dict]:
    """(nodes (n, 3), {mode number: shape (n, 3) complex}) of one ``modes_<part>.bp``, each node once."""
    import adios2        # local: the VTX reader, only for this command (the DOLFINx wheel brings it)
    with adios2.FileReader(str(path)) as reader:
        steps = int(reader.available_variables()["step"]["AvailableStepsCount"])
        blocks = range(len(reader.all_blocks_info("geometry")[0]))        # one per writing rank

        def read(name: str, step: int | None = None) -> np.ndarray:
            more = {} if step is None else {"step_selection": [step, 1]}
            return np.concatenate([np.asarray(reader.read(name, block_id=b, **more), float).reshape(-1, 3)
                                   for b in blocks])
        points, shapes = read("geometry"), {}
        for k in range(steps):
            number = int(np.ravel(reader.read("step", step_selection=[k, 1]))[0])
            shapes[number] = read(SHAPE.format("real"), k) + 1j * read(SHAPE.format("imaginary"), k)
    key = np.round(points / max(float(np.ptp(points, axis=0).max()), 1e-300) / SAME_POINT).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)      # sorted by coordinates: the same on any ranks
    return points[first], {n: s[first] for n, s in shapes.items()}


def read_modes(folder: str | Path) -> ModeSet:
    """The modes of the squeal run whose results are in ``folder`` (InputError if it holds none)."""
    folder = Path(folder)
    table, parts = folder / "modes.csv", sorted(folder.glob("modes_*.bp"))
    if not table.is_file() or not parts:        # (a missing folder was not said: a user trial)
        found = "no such folder" if not folder.exists() else "not a folder" if not folder.is_dir() else \
            f"it holds no {'modes.csv' if not table.is_file() else 'modes_<part>.bp'}"
        raise InputError("RUN", str(folder), f"a squeal run's results folder (modes.csv and modes_<part>.bp); {found}")
    with open(table, newline="") as fh:
        rows = {int(r["mode"]): r for r in csv.DictReader(fh)}
    read = [_read_part(p) for p in parts]
    numbers = sorted(set.intersection(*(set(s) for _, s in read)) & set(rows))
    if not numbers:
        raise InputError("RUN", str(folder), "no mode both in modes.csv and in the mode shape files")
    return ModeSet(folder, np.array(numbers), np.array([float(rows[n]["frequency_Hz"]) for n in numbers]),
                   np.array([float(rows[n]["sigma_1_per_s"]) for n in numbers]),
                   np.concatenate([p for p, _ in read]),
                   np.array([np.concatenate([s[n].ravel() for _, s in read]) for n in numbers]).T,
                   tuple(len(p) for p, _ in read))


def mirrored(modes: ModeSet, axis: str) -> ModeSet:
    """``modes`` reflected in the plane normal to ``axis`` ("x", "y" or "z") through the middle of
    its nodes' extent along it: that coordinate of every node and that component of every shape
    mirrored. A brake symmetric about that plane (through its axis and the pads' middle) turning
    the other way is the mirror image of the forward one: its modes, mirrored, are the forward
    modes (the friction's circulation reversed; the built-in brake: x)."""
    if axis not in AXES:
        raise InputError("--mirror", axis, "x, y or z: the normal of the plane of symmetry")
    k = AXES.index(axis)
    points = modes.points.copy()
    points[:, k] = points[:, k].min() + points[:, k].max() - points[:, k]
    shapes = modes.shapes.reshape(len(points), 3, -1).copy()
    shapes[:, k] *= -1
    return ModeSet(modes.folder, modes.numbers, modes.frequency, modes.sigma, points,
                   shapes.reshape(3 * len(points), -1), modes.sizes, axis)


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """MAC (a's columns x b's) of two sets of complex shapes on the same dofs, in [0, 1]."""
    cross = np.abs(a.conj().T @ b) ** 2
    return cross / np.outer(np.einsum("ij,ij->j", a.conj(), a).real, np.einsum("ij,ij->j", b.conj(), b).real)


def pair(a: ModeSet, b: ModeSet, transfer: bool = False) -> ModePairs:
    """A's modes paired with B's by MAC; InputError unless both runs hold the same nodes or, with
    ``transfer``, the same number of parts (B's shapes are then taken at A's nodes, ``at_nodes``)."""
    tol = SAME_POINT * float(np.ptp(a.points, axis=0).max()) * 10
    same = a.points.shape == b.points.shape and np.abs(a.points - b.points).max() <= tol
    if not same and not (transfer and len(a.sizes) == len(b.sizes)):
        mirror = f" mirrored in {b.mirror}" if b.mirror else ""
        raise InputError("RUN", str(b.folder), f"not the mesh of {a.folder}{mirror} ({len(a.points)} against "
                         f"{len(b.points)} nodes, or at other places): MAC compares runs of one mesh")
    shapes, distance = (b.shapes, None) if same else at_nodes(b, a)
    m = mac(a.shapes, shapes)
    best = np.argmax(m, axis=1)
    gap = b.frequency[best] - a.frequency
    shift = np.divide(100 * gap, a.frequency, out=np.full(len(gap), np.nan), where=a.frequency != 0)
    return ModePairs(a, b, m, best, shift, distance)


def at_nodes(b: ModeSet, a: ModeSet) -> tuple[np.ndarray, np.ndarray]:
    """B's shapes (3 n_A, modes) at A's nodes, part by part: the value of B's nearest node of the same
    part, and that node's distance [m]. On the built-in brake (mesh size 16 mm; forward against the
    reverse run mirrored, a median distance of 0.72 mm) 31 of 32 modes paired by number at a median
    MAC of 0.997 (without the mirror 20, 0.74); weighting B's 4 nearest nodes by their inverse
    square distances gave 0.997 too."""
    from scipy.spatial import cKDTree      # local: only this comparison needs it
    shapes, distance = [], []
    bounds_a, bounds_b = np.cumsum((0, *a.sizes)), np.cumsum((0, *b.sizes))
    modes_b = b.shapes.reshape(len(b.points), 3, -1)
    for i in range(len(a.sizes)):
        here, there = slice(*bounds_a[i:i + 2]), slice(*bounds_b[i:i + 2])
        d, j = cKDTree(b.points[there]).query(a.points[here])
        shapes.append(modes_b[there][j])
        distance.append(d)
    return np.concatenate(shapes).reshape(3 * len(a.points), -1), np.concatenate(distance)


def report(pairs: ModePairs) -> list[str]:
    """The pairs as console lines: A's mode, frequency, growth rate; B's; MAC; frequency shift."""
    a, b = pairs.a, pairs.b
    lines = [f"modes of {a.folder} (A, {len(a.numbers)}) against {b.folder} (B, {len(b.numbers)}"
             f"{f', mirrored in {b.mirror}' if b.mirror else ''}) on {len(a.points)} nodes; each A mode with the "
             "B mode of the largest MAC"]
    if pairs.distance is not None:
        lines.append(f"B's shapes taken at A's nodes from its nearest of the same part (distance: median "
                     f"{1e3 * np.median(pairs.distance):.3g} mm, largest {1e3 * pairs.distance.max():.3g} mm): "
                     "the MAC of a pair falls by what the meshes differ")
    lines.append(f"{'A':>4} {'f [Hz]':>10} {'sigma [1/s]':>12} {'B':>4} {'f [Hz]':>10} {'sigma [1/s]':>12} "
                 f"{'MAC':>6} {'shift [%]':>9}")
    for i, j in enumerate(pairs.best):
        weak = "  weak" if pairs.mac[i, j] < PAIRED else ""
        lines.append(f"{a.numbers[i]:>4} {a.frequency[i]:>10.2f} {a.sigma[i]:>12.4g} {b.numbers[j]:>4} "
                     f"{b.frequency[j]:>10.2f} {b.sigma[j]:>12.4g} {pairs.mac[i, j]:>6.3f} {pairs.shift[i]:>9.3f}{weak}")
    taken = np.bincount(pairs.best, minlength=len(b.numbers))
    if (taken > 1).any():
        lines.append("B modes paired with several A modes: " + ", ".join(
            str(b.numbers[j]) for j in np.flatnonzero(taken > 1)) + " (close modes mix: compare the MAC matrix)")
    return lines


def write_pairs(pairs: ModePairs, path: str | Path) -> Path:
    """The MAC matrix as CSV: a row per A mode (its number and frequency), a column per B mode."""
    path = Path(path)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["mode_A", "frequency_A_Hz", *(f"MAC_B{n}" for n in pairs.b.numbers)])
        for i, n in enumerate(pairs.a.numbers):
            w.writerow([n, f"{pairs.a.frequency[i]:.6f}", *(f"{x:.6f}" for x in pairs.mac[i])])
    return path

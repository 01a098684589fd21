"""Stability maps: complex modes against a swept parameter, tracked by MAC (issue 20).

A sweep gives, at each value v_k of a parameter (friction coefficient, brake pressure, speed,
roughness), the reduced system of one common basis (``macro.damped.ReducedSystem``: every point
projected on the same M-orthonormal basis V) and its modes in the band. ``build_map``

- tracks the modes from point to point: one-to-one pairs of maximal MAC (computed in reduced
  coordinates, y^H y = q^H V^T V q) less the relative eigenvalue jump, MAC >= ``mac_min``
  (``modal.pair_modes``), or a pair below ``mac_min`` in a block of two (with the pair of the
  mode nearest in frequency) whose two-mode subspaces have a subspace MAC >= ``mac_min``
  (``modal.subspace_mac``): a pair that locks in (or splits) between two points, whose members
  are each a mix of both parents (at a lock-in both conjugate members have the same MAC with a
  given parent, high with one, low with the other); its ``mac`` is then the pair's own MAC, below
  ``mac_min``. A tie (the two members of a pair that locks in or splits have the same MAC with,
  and eigenvalue jump from, a stable parent) keeps the order of the mode numbers
  (``modal.pair_modes``), whatever the round-off. A mode without a partner starts a new track.
  The tracks are the mode-pairing table (``map.csv``: track, mode number and MAC with the previous point);
- finds where a track turns unstable between v_{k-1} and v_k (a track stable at v_{k-1}, or one
  that starts unstable at v_k because its branch failed the MAC test, e.g. at a lock-in, and whose
  best match at v_{k-1} was stable) and bisects the onset value
  (as ``eigen.onset_of_instability`` does) on the reduced system blended linearly between the two
  points (exact where the operators are affine in the parameter: friction at a fixed preload;
  otherwise the blend is the interpolation of the linearised operators between two preloads).
  The mode of the track at a bisection point is the best match (MAC less the eigenvalue jump) of
  its unstable shape at v_k. The onset's partner is the track nearest in frequency at v_k: a
  "lock-in" when at the onset the two coalesced (frequency gap <= 0.1 %), "mode coupling" when
  damping holds them apart but the partner's growth rate fell while this one's rose, otherwise
  "negative damping" (e.g. the falling mu(v) of ``macro.friction``). A track unstable at the
  first value is recorded as ``BELOW`` (its onset is not in the sweep; value NaN);
- finds where a track turns stable again between v_{k-1} and v_k and bisects that value the same
  way, from the stable end (``Onset.end``: the unstable band of a mode that couples and uncouples).

``MapBuilder`` takes the points one by one (per-point bases: the caller projects the two
neighbouring points on the union of their modes for the bisection); ``build_map`` runs it on
results of one common basis.

Outputs: ``write_csv`` (one row per point and track), ``write_onsets_csv``, ``write_h5``.
"""
from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import h5py
import numpy as np

from multiscale.errors import InputError
from multiscale.macro.damped import ReducedSystem, select
from multiscale.macro.eigen import TWO_PI, ModalResult
from multiscale.macro.modal import mac_matrix, pair_modes, subspace_mac


LOCK_IN_GAP = 1e-3       # relative frequency gap of a coalesced (locked-in) pair
BELOW = "below the sweep"  # kind of a track unstable at the first value: its onset is not in the sweep


@dataclass
class Onset:
    """Where one tracked mode turns unstable."""

    track: int                   # track number (from 1)
    value: float                 # onset value of the parameter (bisected; NaN: unstable at the first value)
    frequency: float             # Hz, of the mode at the onset
    partner: int | None          # track nearest in frequency at the first unstable point
    kind: str                    # "lock-in", "mode coupling" (damped), "negative damping" or BELOW
    bracket: tuple               # (stable value, unstable value): of full analyses when ``analyses`` > 0,
    #                              else the bisection's last on the blended systems
    end: float = np.nan          # value where the track is stable again (bisected; NaN: not in the sweep)
    analyses: int = 0            # full analyses that narrowed the bracket (``MapBuilder.onset``'s ``refine``)


@dataclass
class StabilityMap:
    """Tracked modes over a sweep: arrays (n_points, n_tracks), NaN / -1 where a track is absent."""

    parameter: str
    unit: str
    values: np.ndarray
    frequency: np.ndarray        # Hz
    growth: np.ndarray           # sigma [1/s], > 0 unstable
    mode: np.ndarray             # mode number (from 1, by frequency) at each point, -1: absent
    mac: np.ndarray              # MAC with the track's mode at the previous point (NaN: new)
    residual: np.ndarray         # relative residual of each mode in the full model
    onsets: list = field(default_factory=list)
    basis_size: int = 0
    rtol: float = 1e-6
    time: float = 0.0
    max_pressure: float = 0.0    # Pa, the largest facet pressure of the points' own preloads (0: preload "once")

    @property
    def n_tracks(self) -> int:
        return self.frequency.shape[1]

    def unstable(self) -> np.ndarray:
        """(n_points, n_tracks) mask of unstable modes (sigma > rtol |lambda|)."""
        lam = np.abs(self.growth + 1j * TWO_PI * self.frequency)
        with np.errstate(invalid="ignore"):
            return np.nan_to_num(self.growth) > self.rtol * np.nan_to_num(lam)

    def damping_ratio(self) -> np.ndarray:
        lam = np.abs(self.growth + 1j * TWO_PI * self.frequency)
        with np.errstate(invalid="ignore", divide="ignore"):
            return -self.growth / lam

    def summary(self) -> str:
        """A few lines for the console: size, unstable tracks and onsets."""
        bad = self.unstable().any(axis=0)
        lines = [f"  stability map over {self.parameter} [{self.unit}] from {self.values[0]:g} to {self.values[-1]:g}: "
                 f"{self.values.size} points, {self.n_tracks} tracked modes"
                 + (f" (common basis of {self.basis_size})" if self.basis_size else "")      # preload "once"
                 + f", {int(bad.sum())} unstable somewhere; max residual {np.nanmax(self.residual):.1e}; "
                 f"{self.time:.1f} s"]
        for o in self.onsets:
            again = f"; stable again at {o.end:.6g}" if np.isfinite(o.end) else ""
            if o.kind == BELOW:
                lines.append(f"    track {o.track}: unstable at the first value already ({o.frequency:.0f} Hz): "
                             f"its onset is below the sweep{again}")
                continue
            full = f", between full analyses at {o.bracket[0]:.6g} and {o.bracket[1]:.6g}" if o.analyses else ""
            lines.append(f"    track {o.track}: {o.kind} at {self.parameter} = {o.value:.6g} ({o.frequency:.0f} Hz"
                         + (f", with track {o.partner}" if o.partner is not None else "") + full + ")" + again)
        return "\n".join(lines)

    def column(self) -> str:
        """The swept value's column name: the parameter and its unit as modes.csv writes them
        ("friction", "pressure_Pa", "speed_rad_per_s", "rms_m"; "friction_-" and "speed_rad/s" were
        awkward in a table reader: an NVH user trial)."""
        unit = self.unit.replace("/", "_per_")
        return self.parameter if unit == "-" else f"{self.parameter}_{unit}"

    def write_csv(self, path) -> Path:
        """Mode-pairing table: point, value, track, mode, frequency, sigma, damping ratio,
        unstable, MAC with the previous point, residual."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        bad, zeta = self.unstable(), self.damping_ratio()
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["point", self.column(), "track", "mode", "frequency_Hz", "sigma_1_per_s",
                        "damping_ratio", "unstable", "mac_previous", "residual"])
            for k, v in enumerate(self.values):
                for t in np.nonzero(self.mode[k] >= 0)[0]:
                    w.writerow([k + 1, f"{v:.8g}", t + 1, self.mode[k, t], f"{self.frequency[k, t]:.6f}",
                                f"{self.growth[k, t] + 0.0:.6e}", f"{zeta[k, t] + 0.0:.6e}", int(bad[k, t]),
                                "" if np.isnan(self.mac[k, t]) else f"{self.mac[k, t]:.4f}",
                                f"{self.residual[k, t]:.2e}"])
        return path

    def write_onsets_csv(self, path) -> Path:
        path = Path(path)
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["track", f"onset_{self.column()}", "frequency_Hz", "partner_track", "kind",
                        "stable_value", "unstable_value", f"stable_again_{self.column()}",
                        "full_analyses"])
            for o in self.onsets:
                w.writerow([o.track, _number(o.value), f"{o.frequency:.6f}", "" if o.partner is None else o.partner,
                            o.kind, _number(o.bracket[0]), _number(o.bracket[1]), _number(o.end), o.analyses])
        return path

    def write_h5(self, path) -> Path:
        path = Path(path)
        with h5py.File(path, "w") as f:
            f.attrs.update(parameter=self.parameter, unit=self.unit, basis_size=self.basis_size, rtol=self.rtol,
                           time=self.time)
            units = {"values": self.unit, "frequency": "Hz", "growth": "1/s", "mode": "-", "mac": "-", "residual": "-"}
            for name, unit in units.items():          # a unit per dataset, as in history.h5
                f[name] = getattr(self, name)
                f[name].attrs["unit"] = unit
            g = f.create_group("onsets")         # the columns of onsets.csv
            onsets = {"track": (np.array([o.track for o in self.onsets], int), "-"),
                      "value": (np.array([o.value for o in self.onsets], float), self.unit),
                      "frequency": (np.array([o.frequency for o in self.onsets], float), "Hz"),
                      "partner": (np.array([-1 if o.partner is None else o.partner for o in self.onsets], int), "-"),
                      "kind": (np.array([o.kind for o in self.onsets], dtype=h5py.string_dtype()), "-"),
                      "stable_value": (np.array([o.bracket[0] for o in self.onsets], float), self.unit),
                      "unstable_value": (np.array([o.bracket[1] for o in self.onsets], float), self.unit),
                      "stable_again": (np.array([o.end for o in self.onsets], float), self.unit),
                      "full_analyses": (np.array([o.analyses for o in self.onsets], int), "-")}
            for name, (data, unit) in onsets.items():
                g[name] = data
                g[name].attrs["unit"] = unit
        return path


def _number(x: float) -> str:
    return "" if np.isnan(x) else f"{x:.8g}"


def _unstable(lam: np.ndarray, rtol: float) -> np.ndarray:
    return lam.real > rtol * np.abs(lam)


def best_match(lam: np.ndarray, Q: np.ndarray, q_ref: np.ndarray, lam_ref: complex, gram=None, comm=None) -> int:
    """Index of the mode (lam, Q) that best continues (q_ref, lam_ref): MAC less the relative
    eigenvalue jump (``gram``: of reduced coordinates; else full vectors distributed over ``comm``)."""
    mac = mac_matrix(q_ref[:, None], Q, comm=comm, gram=gram)[0]
    jump = np.minimum(np.abs(lam - lam_ref) / max(abs(lam_ref), np.finfo(float).tiny), 1.0)
    return int(np.argmax(mac - jump))


def bisect_onset(lo: ReducedSystem, hi: ReducedSystem, v_lo: float, v_hi: float, q_ref, lam_ref, gram, band,
                 *, rtol: float = 1e-6, xtol: float = 1e-6, max_steps: int = 60,
                 check_lo: bool = False) -> tuple | None:
    """Bisect the value in [v_lo, v_hi] where the mode continuing (q_ref, lam_ref) (unstable at
    v_hi) turns unstable, on the reduced systems blended linearly; returns (value, frequency at
    the onset [Hz], final bracket, relative frequency gap to the nearest other mode there); with
    ``check_lo`` (a track that starts at v_hi: its mode at v_lo is not known) None when the best
    match at v_lo is unstable already (no onset in the bracket)."""
    if check_lo:
        lam, Q = lo.eigenpairs()
        keep = select(lam, band, None, band[0])
        if _unstable(lam[keep][best_match(lam[keep], Q[:, keep], q_ref, lam_ref, gram)][None], rtol)[0]:
            return None
    a, b, f_b, gap = 0.0, 1.0, lam_ref.imag / TWO_PI, np.inf
    span = abs(v_hi - v_lo)
    for _ in range(max_steps):
        if (b - a) * span <= xtol * max(span, 1e-300):
            break
        t = 0.5 * (a + b)
        lam, Q = lo.blend(hi, t).eigenpairs()
        keep = select(lam, band, None, band[0])
        j = best_match(lam[keep], Q[:, keep], q_ref, lam_ref, gram)
        if _unstable(lam[keep][j:j + 1], rtol)[0]:
            f = lam[keep].imag / TWO_PI
            others = np.delete(np.arange(f.size), j)
            b, f_b = t, f[j]
            gap = np.abs(f[others] - f[j]).min() / max(f[j], 1e-300) if others.size else np.inf
        else:
            a = t
    value = v_lo + 0.5 * (a + b) * (v_hi - v_lo)
    return value, f_b, (v_lo + a * (v_hi - v_lo), v_lo + b * (v_hi - v_lo)), gap


class MapBuilder:
    """Builds a ``StabilityMap`` point by point: ``add`` pairs the modes of a new point with the
    previous one and returns the tracks that turned unstable; ``onset`` bisects one of them on two
    reduced systems of a common basis; ``finish`` returns the map."""

    def __init__(self, parameter: str, unit: str, band, *, mac_min: float = 0.5, rtol: float = 1e-6,
                 xtol: float = 1e-4, subspace: bool = True):
        self.parameter, self.unit, self.band = parameter, unit, tuple(band)
        self.mac_min, self.rtol, self.xtol = mac_min, rtol, xtol
        self.subspace = subspace                             # keep a lock-in pair by its subspace MAC
        self.values, self.rows, self.onsets = [], [], []    # rows: per point, per mode (track, MAC)
        self.prev: ModalResult | None = None
        self.n_tracks = 0
        self.new: set = set()                                # tracks that start at the last point
        self.calmed: list = []        # (track, mode at the point before, mode at the last point): stable again
        self.before: ModalResult | None = None               # the point before the last

    def add(self, value: float, result: ModalResult) -> list[tuple[int, int]]:
        """Pair ``result`` with the previous point; returns (track, mode index) of every mode that
        is unstable here and whose track was stable at the previous point or starts here (a
        branch that failed the MAC test, e.g. at a lock-in); ``calmed`` lists the tracks unstable
        at the previous point and stable here (``end`` bisects where)."""
        value = float(value)
        if self.values and value <= self.values[-1]:
            raise InputError("stability.sweep", value, f"the values must increase (after {self.values[-1]:g})")
        here, mk = [-1] * len(result), np.full(len(result), np.nan)
        if self.prev is not None:
            mac = mac_matrix(self.prev, result, gram=result.gram)
            prev = self.prev
            block = (lambda rows, cols: subspace_mac(prev, result, rows, cols, gram=result.gram)) \
                if self.subspace else None
            for i, j in pair_modes(mac, prev.eigenvalues, result.eigenvalues, self.mac_min, block):
                here[j], mk[j] = self.rows[-1][0][i], mac[i, j]
        first = self.n_tracks
        for j in range(len(result)):
            if here[j] < 0:
                here[j], self.n_tracks = self.n_tracks, self.n_tracks + 1
        self.new = set(range(first, self.n_tracks))
        turned = []
        if self.prev is None:             # (the partner: the nearest in frequency, as above; it was none)
            for j in np.nonzero(_unstable(result.eigenvalues, self.rtol))[0]:
                i = _nearest(result.frequency, j)
                self.onsets.append(Onset(here[j] + 1, np.nan, float(result.frequency[j]),
                                         None if i is None else here[i] + 1, BELOW, (np.nan, value)))
        else:
            was = {t: bool(_unstable(self.prev.eigenvalues[i:i + 1], self.rtol)[0])
                   for i, t in enumerate(self.rows[-1][0])}
            bad = _unstable(result.eigenvalues, self.rtol)
            turned = [(t, j) for j, t in enumerate(here) if bad[j] and not was.get(t, False)]
            self.calmed = [(t, self.rows[-1][0].index(t), j) for j, t in enumerate(here) if not bad[j] and was.get(t)]
        self.before = self.prev
        self.values.append(value)
        self.rows.append((here, mk, result.frequency.copy(), result.growth.copy(), result.errors.copy()))
        self.prev = result
        return turned

    def onset(self, track: int, j: int, lo: ReducedSystem, hi: ReducedSystem, q_ref: np.ndarray,
              gram, refine=None) -> Onset | None:
        """Bisect the onset of ``track`` (mode j of the last point, coordinates ``q_ref`` in the
        basis of ``lo`` and ``hi``, the reduced systems at the last two points) and record it; None
        when the mode continuing it at the previous point was unstable already (a new track that
        continues an unstable one). ``refine(found)``: narrows ``bisect_onset``'s result by full
        analyses, returns it and the number of analyses."""
        r = self.prev
        found = bisect_onset(lo, hi, self.values[-2], self.values[-1], q_ref, r.eigenvalues[j], gram, self.band,
                             rtol=self.rtol, xtol=self.xtol, check_lo=track in self.new)
        if found is None:
            return None
        found, analyses = refine(found) if refine is not None else (found, 0)
        value, freq, bracket, gap = found
        i, partner, kind = _nearest(r.frequency, j), None, "negative damping"
        if i is not None:
            partner = self.rows[-1][0][i] + 1
            before = self.rows[-2][0]
            falling = partner - 1 in before and r.growth[i] < self.rows[-2][3][before.index(partner - 1)]
            if gap <= LOCK_IN_GAP:
                kind = "lock-in"
            elif falling:
                kind = "mode coupling"
        found = Onset(int(track) + 1, value, freq, partner, kind, bracket, analyses=analyses)
        self.onsets.append(found)
        return found

    def end(self, track: int, i: int, lo: ReducedSystem, hi: ReducedSystem, q_ref: np.ndarray, gram,
            refine=None) -> None:
        """Bisect where ``track`` (mode i of the point before the last, unstable there, coordinates
        ``q_ref`` in the basis of ``lo`` and ``hi``, the reduced systems at those two points) turns
        stable again, from the stable end, and record it as the ``end`` of the track's last onset
        (``refine`` as in ``onset``)."""
        found = bisect_onset(hi, lo, self.values[-1], self.values[-2], q_ref, self.before.eigenvalues[i], gram,
                             self.band, rtol=self.rtol, xtol=self.xtol)
        value = (refine(found)[0] if refine is not None else found)[0]
        onset = next((o for o in reversed(self.onsets) if o.track == track + 1), None)
        if onset is not None:
            onset.end = value

    def track(self, values: Sequence[float], results: Sequence[ModalResult], reduced: Sequence[ReducedSystem],
              onsets: bool = True) -> None:
        """``add`` the points ``values`` with their ``results`` (reduced coordinates of one basis,
        ``ModalResult.gram``) and, with ``onsets``, bisect every onset and end on the ``reduced``
        systems of the two points around it."""
        for k, (value, result) in enumerate(zip(values, results)):
            for track, j in self.add(value, result):
                if onsets:
                    self.onset(track, j, reduced[k - 1], reduced[k], result.modes[:, j], result.gram)
            for track, i, _ in self.calmed if onsets else ():
                self.end(track, i, reduced[k - 1], reduced[k], results[k - 1].modes[:, i], result.gram)

    def finish(self, *, basis_size: int = 0, time: float = 0.0, max_pressure: float = 0.0) -> StabilityMap:
        P, T = len(self.values), self.n_tracks
        out = {name: np.full((P, T), np.nan) for name in ("frequency", "growth", "mac", "residual")}
        mode = np.full((P, T), -1, int)
        for k, (tracks, mk, f, g, e) in enumerate(self.rows):
            for j, t in enumerate(tracks):
                out["frequency"][k, t], out["growth"][k, t], out["residual"][k, t] = f[j], g[j], e[j]
                out["mac"][k, t], mode[k, t] = mk[j], j + 1
        return StabilityMap(self.parameter, self.unit, np.array(self.values), out["frequency"], out["growth"], mode,
                            out["mac"], out["residual"],
                            sorted(self.onsets, key=lambda o: (np.nan_to_num(o.value, nan=-np.inf), o.frequency)),
                            basis_size, self.rtol, time, max_pressure)


def build_map(parameter: str, unit: str, values: Sequence[float], results: Sequence[ModalResult],
              reduced: Sequence[ReducedSystem], band, *, mac_min: float = 0.5, xtol: float = 1e-4,
              subspace: bool = True) -> StabilityMap:
    """The map of the points ``values`` with their ``results`` and ``reduced`` systems of one basis
    (``MapBuilder.track``, as a "common" sweep runs it; module docstring). ``xtol`` is relative
    to the step between the two bracketing values; ``subspace`` False: pairs by the single MAC only."""
    if len(values) != len(results) or len(results) != len(reduced) or len(values) < 2:
        raise InputError("stability.sweep", len(values), "at least two points, one result and system each")
    builder = MapBuilder(parameter, unit, band, mac_min=mac_min, xtol=xtol, subspace=subspace)
    builder.track(values, results, reduced)
    return builder.finish()


def _nearest(frequency, j: int) -> int | None:
    """Index of the mode nearest mode ``j`` in frequency, None if it is alone."""
    others = [i for i in range(len(frequency)) if i != j]
    return others[int(np.argmin(np.abs(frequency[others] - frequency[j])))] if others else None

"""Interpolation tables of the zone laws: p_n(g_n) and extra laws y(p_n), one row per zone
(thesis §1.4.2, Eq. 1.31; the gap and node conventions are those of ``multiscale.micro.laws``).

The law p_n(g_n) is C¹ and monotone (``PressureGapLaw``), in log-log variables: with the
interpenetration d = g_open − g_n, Fritsch–Butland (PCHIP) Hermite cubics of ln p_n in ln d
between the nodes. A rough contact starts as a power law p ∝ d^m (m = 3/2 for one Hertzian
asperity, larger as asperities join: a straight line in these variables, exact from the first
node down to first touch, where K = 0) and ends close to exponential in d (Persson), smooth in
ln d; PCHIP keeps ln p, hence p, monotone without overshoot and the table spans decades of
pressure at uniform relative accuracy. Beyond the last node, p_n is linear in g_n with the last
stiffness (finite, positive, never overflows). Extra laws (real contact area, thermal
conductance, heat partition…) are tabulated at the same nodes against p_n (``PressureTable``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.errors import InputError, non_finite


def _pchip_slopes(x, y):
    """Fritsch–Butland (PCHIP) node slopes of y(x) along the last axis; x ascending.

    x: (..., n), y: (..., n) or (..., n, m) (columns interpolated independently)."""
    if y.ndim == x.ndim + 1:
        return np.stack([_pchip_slopes(x, y[..., j]) for j in range(y.shape[-1])], axis=-1)
    h = np.diff(x, axis=-1)
    delta = np.diff(y, axis=-1) / h
    d = np.zeros_like(y)
    h0, h1, d0, d1 = h[..., :-1], h[..., 1:], delta[..., :-1], delta[..., 1:]
    w1, w2 = 2 * h1 + h0, h1 + 2 * h0
    same = d0 * d1 > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        d[..., 1:-1] = np.where(same, (w1 + w2) / (w1 / np.where(same, d0, 1) + w2 / np.where(same, d1, 1)), 0.0)
    d[..., 0] = _edge_slope(h[..., 0], h[..., 1], delta[..., 0], delta[..., 1])
    d[..., -1] = _edge_slope(h[..., -1], h[..., -2], delta[..., -1], delta[..., -2])
    return d


def _edge_slope(h0, h1, d0, d1):
    """Shape-preserving three-point end slope (the end interval has width h0, secant d0)."""
    d = ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
    d = np.where(np.sign(d) != np.sign(d0), 0.0, d)
    return np.where((np.sign(d0) != np.sign(d1)) & (np.abs(d) > 3 * np.abs(d0)), 3 * d0, d)


def _hermite(y0, y1, d0, d1, h, t):
    """Cubic Hermite value and x-derivative on an interval of width h at t = (x − x0)/h."""
    t2, t3 = t * t, t * t * t
    value = y0 * (2 * t3 - 3 * t2 + 1) + h * d0 * (t3 - 2 * t2 + t) + y1 * (3 * t2 - 2 * t3) + h * d1 * (t3 - t2)
    slope = (y0 * (6 * t2 - 6 * t) + y1 * (6 * t - 6 * t2)) / h + d0 * (3 * t2 - 4 * t + 1) + d1 * (3 * t2 - 2 * t)
    return value, slope


@dataclass(frozen=True)
class LawValue:
    """A law evaluated at many points."""

    pressure: np.ndarray   # Pa, p_n >= 0
    stiffness: np.ndarray  # Pa/m, K_n = −dp_n/dg_n >= 0


class PressureGapLaw:
    """A batch of C¹ monotone laws p_n(g_n), one row per zone (module docstring).

    Rows are built from node gaps ``gap`` (Z, n), strictly decreasing, node pressures
    ``pressure`` (Z, n) > 0, strictly increasing, and the first-touch gaps ``g_open`` (Z,) above
    the first node. With the interpenetration d = g_open − g_n: PCHIP Hermite cubics of ln p in
    ln d between nodes; below the first node the power law p_1 (d/d_1)^m that continues them
    (m their slope there; where m < 3/2, a cubic in p with K = 0 at first touch: K always
    vanishes at first touch, at least as fast as Hertz's √d); above the last, p linear in g with
    the last node's stiffness.
    """

    def __init__(self, gap, pressure, g_open):
        g = np.atleast_2d(np.asarray(gap, dtype=float))
        p = np.atleast_2d(np.asarray(pressure, dtype=float))
        g_open = np.atleast_1d(np.asarray(g_open, dtype=float))
        if g.shape != p.shape or g.shape[1] < 3 or g_open.shape != g.shape[:1]:
            raise InputError("gap/pressure", (g.shape, p.shape), "(zones, n >= 3) tables and one g_open per zone")
        if not (np.all(np.diff(g, axis=1) < 0) and np.all(np.diff(p, axis=1) > 0) and np.all(p > 0)
                and np.all(g_open > g[:, 0]) and np.all(np.isfinite(g)) and np.all(np.isfinite(p))):
            raise InputError("gap/pressure", "tables", "need g decreasing below g_open and p > 0 increasing")
        x, y = np.log(g_open[:, None] - g), np.log(p)       # ln d ascending, ln p ascending
        slope = _pchip_slopes(x, y)                           # d ln p / d ln d at the nodes
        secant = np.diff(y, axis=1) / np.diff(x, axis=1)
        slope[:, -1] = np.clip(slope[:, -1], secant[:, -1] / 3, 3 * secant[:, -1])   # K beyond > 0
        self.gap, self.pressure, self.g_open = g, p, g_open
        self._x, self._y, self._slope = x, y, slope

    @property
    def n_zones(self) -> int:
        return self.gap.shape[0]

    @property
    def hermite_nodes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(ln d, ln p, d ln p / d ln d) at the nodes, each (Z, n): the Hermite data of the laws
        (d = g_open − g_n [m], p [Pa])."""
        return self._x, self._y, self._slope

    def __call__(self, gap, rows=None) -> LawValue:
        """p_n and K_n at gaps ``gap`` [m]; ``rows`` picks each point's law (default: point i
        uses row i, or row 0 for a single law). Vectorised; never NaN for finite gaps."""
        g, rows, shape = _points(gap, rows, self.n_zones)
        if not np.all(np.isfinite(g)):
            raise InputError("gap", f"array of shape {g.shape}", f"{non_finite(g)}: gaps must be finite")
        n = self.gap.shape[1]
        d = self.g_open[rows] - g                              # interpenetration, > 0 in contact
        x = np.log(np.where(d > 0, d, 1.0))
        k = np.sum(self.gap[rows] > g[:, None], axis=1)       # nodes with a larger gap (lower p)
        j = np.clip(k - 1, 0, n - 2)
        x0, x1 = self._x[rows, j], self._x[rows, j + 1]
        y, dy = _hermite(self._y[rows, j], self._y[rows, j + 1], self._slope[rows, j], self._slope[rows, j + 1],
                         x1 - x0, np.clip((x - x0) / (x1 - x0), 0.0, 1.0))
        inner = (k >= 1) & (k < n)
        p = np.where(inner, np.exp(np.where(inner, y, 0.0)), 0.0)
        K = p * dy / np.where(d > 0, d, 1.0)
        # onset: power law p1 (d/d1)^m, or a cubic in p with K = 0 at first touch
        p1, d1, m = self.pressure[rows, 0], np.exp(self._x[rows, 0]), self._slope[rows, 0]
        u = np.clip(d / d1, 0.0, 1.0)
        power = m >= 1.5
        p_cubic, K_cubic = _hermite(0.0, p1, 0.0, m * p1 / d1, d1, u)
        u_m1 = u ** np.where(power, m - 1, 1.0)
        onset = (k == 0) & (d > 0)
        p = np.where(onset, np.where(power, p1 * u_m1 * u, p_cubic), p)
        K = np.where(onset, np.where(power, m * p1 * u_m1 / d1, K_cubic), K)
        # beyond the last node: constant stiffness
        beyond = k == n
        pn = self.pressure[rows, -1]
        Kn = pn * self._slope[rows, -1] / np.exp(self._x[rows, -1])
        p = np.where(beyond, pn + Kn * (self.gap[rows, -1] - g), p)
        K = np.where(beyond, Kn, K)
        return LawValue(p.reshape(shape), K.reshape(shape))


def _points(values, rows, n_rows):
    """Flattened evaluation points and their rows (default: one point per row, or row 0)."""
    v = np.asarray(values, dtype=float)
    if rows is None:
        rows = np.zeros(v.shape, dtype=int) if n_rows == 1 else np.arange(n_rows)
    v, rows = np.broadcast_arrays(v, np.asarray(rows, dtype=int))
    if rows.size and (rows.min() < 0 or rows.max() >= n_rows):
        raise InputError("rows", "indices", f"must lie in [0, {n_rows})")
    return v.ravel(), rows.ravel(), v.shape


class PressureTable:
    """A batch of tables y(p_n) (one row per zone), PCHIP in ln p_n between the nodes.

    values (Z, n) or (Z, n, m) with ``axis`` (m,) ascending (e.g. sliding speeds: linear in
    between, clamped). Above the last node the last value holds; below the first, 'zero' scales
    linearly to 0 at p_n = 0, 'hold' keeps the first value.
    """

    def __init__(self, pressure, values, below: str = "hold", axis=None):
        p = np.atleast_2d(np.asarray(pressure, dtype=float))
        v = np.asarray(values, dtype=float)
        if v.shape[:2] != p.shape:                              # a single zone's (n,) or (n, m)
            v = v.reshape(p.shape + v.shape[1:])
        if below not in ("zero", "hold"):
            raise InputError("below", below, "one of 'zero', 'hold'")
        if v.ndim == 3:
            axis = np.asarray(axis, dtype=float)
            if axis.shape != (v.shape[2],) or np.any(np.diff(axis) <= 0):
                raise InputError("axis", axis, f"{v.shape[2]} ascending values")
        elif axis is not None:
            raise InputError("axis", axis, "only for (zones, n, m) values")
        if not np.all(np.isfinite(v)) or not np.all(np.diff(p, axis=1) > 0) or np.any(p <= 0):
            raise InputError("values", "table", "finite values at increasing pressures > 0")
        self.pressure, self.values, self.below, self.axis = p, v, below, axis
        self._x = np.log(p)
        self._v = v if v.ndim == 3 else v[..., None]          # (Z, n, m)
        self._slope = _pchip_slopes(self._x, self._v)

    def __call__(self, pressure, rows=None, at=None) -> np.ndarray:
        """Values at zone pressures ``pressure`` [Pa] (and axis points ``at``), rows as for
        ``PressureGapLaw``."""
        if self.axis is not None:
            if at is None:
                raise InputError("at", None, f"this table also depends on {len(self.axis)} axis values")
            pressure, at = np.broadcast_arrays(np.asarray(pressure, dtype=float), np.asarray(at, dtype=float))
            if rows is not None:
                rows, pressure, at = np.broadcast_arrays(np.asarray(rows, dtype=int), pressure, at)
        p, rows, shape = _points(pressure, rows, self.pressure.shape[0])
        n = self._x.shape[1]
        x = np.log(np.maximum(p, np.finfo(float).tiny))
        j = np.clip(np.sum(self._x[rows] <= x[:, None], axis=1) - 1, 0, n - 2)
        x0, x1 = self._x[rows, j], self._x[rows, j + 1]
        t = np.clip((x - x0) / (x1 - x0), 0.0, 1.0)[:, None]
        value, _ = _hermite(self._v[rows, j], self._v[rows, j + 1], self._slope[rows, j],
                            self._slope[rows, j + 1], (x1 - x0)[:, None], t)
        p_first, first = self.pressure[rows, 0][:, None], self._v[rows, 0]
        below = first * np.maximum(p[:, None], 0.0) / p_first if self.below == "zero" else first
        value = np.where(p[:, None] <= p_first, below, value)
        if self.axis is None:
            return value[:, 0].reshape(shape)
        at = np.broadcast_to(at, shape).ravel()
        i = np.clip(np.searchsorted(self.axis, at) - 1, 0, len(self.axis) - 2)
        w = np.clip((at - self.axis[i]) / (self.axis[i + 1] - self.axis[i]), 0.0, 1.0)
        r = np.arange(len(at))
        return ((1 - w) * value[r, i] + w * value[r, i + 1]).reshape(shape)


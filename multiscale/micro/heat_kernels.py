"""Heat-source kernels of a semi-infinite body heated on a rectangle of its surface (thesis §6.2).

A uniform unit flux (1 W/m²) on the rectangle |x| < a, |y| < b is switched on at time t − τ; the
surface temperature rise [K] at offset (X, Y) from the rectangle centre at time t is

    T = 1/(4 κ √π) ∫_0^{√(4χτ)} E_a(X', v) E_b(Y', v) dv,   E_a(X, v) = erf((X+a)/v) − erf((X−a)/v)

(Eqs. 6.2 and 6.5 with z = 0; v = √(4χ (t − t')) for heat emitted at t'). (X', Y') is where the
material point now at (X, Y) was when that heat was emitted: (X, Y) itself for a fixed body
(Eqs. 6.1–6.3), the point rotated back by s(t') − s(t) for a rotating body (Eqs. 6.4–6.8).

Fixed body: steady value in closed form (Love's integral / (2πκ), Eq. 6.3 with τ → ∞) minus the
transient tail ∫_{√(4χτ)}^∞ by Gauss–Legendre quadrature in w = 1/v (Eq. 6.3).
Moving body: direct Gauss–Legendre quadrature in v on panels fine enough for both the diffusion
length and the material displacement, skipping the stretches where the heat has been carried
farther from the patch than it can diffuse back (exactly negligible contributions).

Tables on an (ny, nx) grid of cells (``pulse_tables``) give, per time step of age k, the response
to a unit flux held during one step (k = 0: the current step), as the (2ny, 2nx) wrap-around
influence coefficients of the zero-padded FFT convolution (thesis Eq. 6.22). Moving-body tables
use the far-axis approximation: the patch translates with its centre (its rotation about its own
centre, of order (patch size)/(radius), is neglected — the approximation behind the thesis'
convolution), which keeps each quadrature node a rank-one (separable) term.

Units: SI. Velocities are non-negative (unidirectional sliding).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
from scipy.special import erf, erfc

from multiscale.errors import InputError, check_field, check_instance, check_positive, check_real
from multiscale.micro.kernels import ThermalHalfSpace, wrap_offsets
from multiscale.references.love import love_rectangle

_GL6 = np.polynomial.legendre.leggauss(6)
_GL8 = np.polynomial.legendre.leggauss(8)


@dataclass(frozen=True)
class ThermalMaterial:
    """Conductivity ``kappa`` [W/(m K)] and diffusivity ``diffusivity`` [m²/s] of a solid."""

    kappa: float
    diffusivity: float

    def __post_init__(self):
        check_positive("kappa", self.kappa)
        check_positive("diffusivity", self.diffusivity)

    @property
    def effusivity(self) -> float:
        """e = κ/√χ [W s^½/(m² K)]: two bodies suddenly heated on a large area share heat as e."""
        return self.kappa / np.sqrt(self.diffusivity)


@dataclass(frozen=True)
class SpeedProfile:
    """Piecewise-linear speed history through (times[i], values[i]), constant after the last knot.

    Angular speed [rad/s] for a ``Rotation``, linear speed [m/s] for a ``Translation``. Values are
    >= 0 (unidirectional sliding). ``constant`` and ``ramp`` (Eq. 6.6) build the thesis' cases.
    """

    times: tuple[float, ...]   # s, strictly increasing, first 0
    values: tuple[float, ...]  # rad/s or m/s, >= 0

    def __post_init__(self):
        t = check_field("times", self.times)
        v = check_field("values", self.values)
        if t.ndim != 1 or t.shape != v.shape or t.size < 1:
            raise InputError("times/values", (self.times, self.values), "two 1-D sequences of equal length")
        if t[0] != 0.0 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
            raise InputError("times", self.times, "must start at 0 and increase strictly")
        if not np.all(np.isfinite(v)) or np.any(v < 0):
            raise InputError("values", self.values, "speeds must be finite and >= 0")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "values", tuple(v.tolist()))

    @classmethod
    def constant(cls, value: float) -> "SpeedProfile":
        return cls((0.0,), (check_positive("value", value, allow_zero=True),))

    @classmethod
    def ramp(cls, start: float, end: float, duration: float) -> "SpeedProfile":
        """Linear change from ``start`` to ``end`` over [0, duration], then constant (Eq. 6.6)."""
        check_positive("duration", duration)
        speeds = (check_positive("start", start, allow_zero=True), check_positive("end", end, allow_zero=True))
        return cls((0.0, float(duration)), speeds)

    @property
    def is_constant(self) -> bool:
        return len(set(self.values)) == 1

    def __call__(self, t) -> np.ndarray:
        """Speed at time(s) t."""
        return np.interp(t, self.times, self.values)

    def integral(self, t) -> np.ndarray:
        """∫_0^t speed (the angle s(t) of Eq. 6.7, or a path length); linear before t = 0."""
        t = np.asarray(t, dtype=float)
        knots, vals = np.asarray(self.times), np.asarray(self.values)
        dt = np.diff(knots)
        cum = np.concatenate(([0.0], np.cumsum(0.5 * (vals[1:] + vals[:-1]) * dt)))
        i = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, knots.size - 1)
        u = t - knots[i]
        slope = np.append(np.diff(vals) / dt, 0.0)[i]
        out = cum[i] + vals[i] * u + 0.5 * slope * u * u
        return np.where(t < 0, vals[0] * t, out)


class Motion(ABC):
    """Motion of body 1 past the fixed heat sources, seen at the patch centre."""

    profile: SpeedProfile

    @abstractmethod
    def path(self, t) -> np.ndarray:
        """Distance [m] travelled by the material at the patch centre from 0 to t."""

    @abstractmethod
    def back_displacement(self, t, lag) -> tuple[np.ndarray, np.ndarray]:
        """(dx, dy) [m]: position at t − lag minus position at t of the material point that is at
        the patch centre at time t."""

    def material_offset(self, t, lag, X, Y) -> tuple[np.ndarray, np.ndarray]:
        """Where (relative to the patch centre) the material now at offset (X, Y) was at t − lag.
        Default: rigid translation with the patch centre (far-axis approximation)."""
        dx, dy = self.back_displacement(t, lag)
        return X + dx, Y + dy

    def mean_speed(self, t0, t1) -> np.ndarray:
        """Average sliding speed [m/s] over [t0, t1] (the frictional heat of a time step)."""
        return (self.path(t1) - self.path(t0)) / (np.asarray(t1) - np.asarray(t0))

    @property
    @abstractmethod
    def direction(self) -> float:
        """Angle [rad] from +x of the velocity at the patch centre."""

    @abstractmethod
    def speed(self, t) -> np.ndarray:
        """Sliding speed [m/s] at the patch centre."""


def _check_profile(profile) -> None:
    check_instance("profile", profile, SpeedProfile, "a SpeedProfile (e.g. SpeedProfile.constant(v))")


@dataclass(frozen=True)
class Translation(Motion):
    """Body 1 translates at speed ``profile`` [m/s] along the direction ``angle`` [rad from +x]."""

    profile: SpeedProfile
    angle: float = 0.0

    def __post_init__(self):
        _check_profile(self.profile)
        if not np.isfinite(check_real("angle", self.angle)):
            raise InputError("angle", self.angle, "must be finite [rad]")
        object.__setattr__(self, "angle", float(self.angle))

    @classmethod
    def steady(cls, speed: float, angle: float = 0.0) -> "Translation":
        return cls(SpeedProfile.constant(check_positive("speed", speed, allow_zero=True)), angle)

    def path(self, t):
        return self.profile.integral(t)

    def back_displacement(self, t, lag):
        d = self.profile.integral(np.asarray(t) - lag) - self.profile.integral(t)
        return d * np.cos(self.angle), d * np.sin(self.angle)

    @property
    def direction(self):
        return self.angle

    def speed(self, t):
        return self.profile(t)


@dataclass(frozen=True)
class Rotation(Motion):
    """Body 1 rotates about the z axis at angular speed ``profile`` [rad/s] (counter-clockwise);
    the patch centre sits at ``centre`` = (x_c, y_c) [m] from the axis (thesis Fig. 6.3)."""

    centre: tuple[float, float]
    profile: SpeedProfile

    def __post_init__(self):
        _check_profile(self.profile)
        c = check_field("centre", self.centre)
        if c.shape != (2,):
            raise InputError("centre", self.centre, "a pair (x_c, y_c) of finite numbers [m]")
        object.__setattr__(self, "centre", (float(c[0]), float(c[1])))

    @property
    def radius(self) -> float:
        return float(np.hypot(*self.centre))

    def path(self, t):
        return self.radius * self.profile.integral(t)

    def _rotate_back(self, t, lag, x, y):
        d = self.profile.integral(np.asarray(t) - lag) - self.profile.integral(t)   # s(t') − s(t) <= 0
        c, s = np.cos(d), np.sin(d)
        return x * c - y * s, y * c + x * s

    def back_displacement(self, t, lag):
        xc, yc = self.centre
        x, y = self._rotate_back(t, lag, xc, yc)
        return x - xc, y - yc

    def material_offset(self, t, lag, X, Y):
        """Exact rotation of Eq. 6.5 (the point rotates about the axis, not with the patch centre)."""
        xc, yc = self.centre
        x, y = self._rotate_back(t, lag, xc + X, yc + Y)
        return x - xc, y - yc

    @property
    def direction(self):
        return float(np.arctan2(self.centre[0], -self.centre[1]))

    def speed(self, t):
        return self.radius * self.profile(t)


def erf_window(X, a, v):
    """E_a(X, v) = erf((X + a)/v) − erf((X − a)/v), written with erfc so that it keeps its relative
    accuracy far from the strip (|X| >> a + v)."""
    u = np.abs(X)
    inside = u <= a
    return np.where(inside, erf((a + u) / v) + erf((a - u) / v),
                    erfc(np.where(inside, 0.0, u - a) / v) - erfc((u + a) / v))


def _gauss(lo, hi, rule):
    x, w = rule
    half = 0.5 * (hi - lo)
    return ((0.5 * (hi + lo))[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def _moving_nodes(motion: Motion, t: float, lag_max: float, chi: float, half: float, reach: float,
                  lag_breaks: np.ndarray, refine: float = 1.0):
    """Gauss–Legendre nodes (v, weight, lag) of the moving-source integral over v in
    [0, √(4χ lag_max)], with panel ends at the lags ``lag_breaks``.

    Panels are at most max(half/4, v/4) wide in v and carry the material at most max(half/8, v)/2;
    panels along which the heat is farther than ``reach`` + 9v from every table point are dropped
    (their contribution is below erfc(6) of the rest).
    """
    v_max = np.sqrt(4 * chi * lag_max)
    h = 0.25 * half / refine
    base = [np.arange(0.0, min(4 * half, v_max), h)]
    if v_max > 4 * half:
        base.append(4 * half * (1 + 0.25 / refine) ** np.arange(np.ceil(np.log(v_max / (4 * half))
                                                                        / np.log1p(0.25 / refine)) + 1))
    breaks = lag_breaks[(lag_breaks > 0) & (lag_breaks < lag_max)]
    edges = np.unique(np.concatenate(base + [np.sqrt(4 * chi * breaks), [v_max]]))
    edges = edges[edges <= v_max]
    lo, hi = edges[:-1], edges[1:]
    now = motion.path(t)
    keep_lo, keep_hi = [], []
    for _ in range(80):
        lag_lo, lag_hi = lo * lo / (4 * chi), hi * hi / (4 * chi)
        p_lo, p_hi = now - motion.path(t - lag_lo), now - motion.path(t - lag_hi)
        moved = p_hi - p_lo
        far = np.hypot(*motion.back_displacement(t, lag_lo)) - moved > reach + 9 * hi
        fine = moved <= 0.5 * np.maximum(0.125 * half, lo) / refine
        ok = fine & ~far
        keep_lo.append(lo[ok])
        keep_hi.append(hi[ok])
        split = ~fine & ~far
        mid = 0.5 * (lo[split] + hi[split])
        lo, hi = np.concatenate((lo[split], mid)), np.concatenate((mid, hi[split]))
        if lo.size == 0:
            break
    else:  # pragma: no cover - would need a displacement of ~2^80 cells
        raise InputError("motion", motion, "moves too far for the quadrature of the moving kernel")
    lo, hi = np.concatenate(keep_lo), np.concatenate(keep_hi)
    order = np.argsort(lo)
    v, w = _gauss(lo[order], hi[order], _GL6)
    return v, w, v * v / (4 * chi)


def _check_rectangle(a, b):
    return check_positive("a", a), check_positive("b", b)


def fixed_rectangle_temperature(X, Y, tau, a: float, b: float, material: ThermalMaterial) -> np.ndarray:
    """Surface temperature rise [K per W/m²] of a fixed half-space at offsets (X, Y) [m] from the
    centre of a 2a × 2b rectangle heated for a time ``tau`` [s] (np.inf: steady), Eqs. 6.1–6.3.

    Steady part: Love's integral / (2πκ) (closed form); transient tail by quadrature in w = 1/v.
    """
    a, b = _check_rectangle(a, b)
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    steady = love_rectangle(X, Y, a, b) / (2 * np.pi * material.kappa)
    tau = float(tau)
    if not tau > 0:
        raise InputError("tau", tau, "heating time must be > 0 (np.inf for the steady state)")
    if np.isinf(tau):
        return steady
    reach = float(np.max(np.hypot(X, Y))) + 2 * max(a, b)
    w, wt = _tail_nodes(reach, np.array([np.sqrt(4 * material.diffusivity * tau)]))
    v = 1.0 / w
    vals = erf_window(X[..., None], a, v) * erf_window(Y[..., None], b, v) * (v * v)
    return steady - (vals @ wt) / (4 * material.kappa * np.sqrt(np.pi))


def _tail_nodes(reach: float, v_breaks: np.ndarray):
    """Gauss–Legendre nodes in w = 1/v on [0, 1/min(v_breaks)] with panel ends at 1/v_breaks."""
    w_lo = 1.0 / (4 * reach)
    w_max = 1.0 / float(np.min(v_breaks))
    geo = w_lo * 1.25 ** np.arange(max(0.0, np.ceil(np.log(w_max / w_lo) / np.log(1.25))) + 1)
    edges = np.unique(np.concatenate(([0.0], geo[geo < w_max], 1.0 / v_breaks)))
    return _gauss(edges[:-1], edges[1:], _GL8)


def moving_rectangle_temperature(X, Y, t: float, a: float, b: float, material: ThermalMaterial,
                                 motion: Motion, t_on: float = 0.0) -> np.ndarray:
    """Surface temperature rise [K per W/m²] at time t of body 1 (moving with ``motion``) at
    offsets (X, Y) [m] from the centre of a fixed 2a × 2b rectangle heated since ``t_on``
    (Eq. 6.5; exact rotation for a ``Rotation``). Pointwise; for grids use ``pulse_tables``."""
    a, b = _check_rectangle(a, b)
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    if not t > t_on >= 0:
        raise InputError("t", t, f"must exceed t_on = {t_on} >= 0")
    reach = float(np.max(np.hypot(X, Y))) + 1.5 * max(a, b)
    v, w, lag = _moving_nodes(motion, t, t - t_on, material.diffusivity, min(a, b), reach, np.empty(0))
    Xp, Yp = motion.material_offset(t, lag, X[..., None], Y[..., None])
    vals = erf_window(Xp, a, v) * erf_window(Yp, b, v)
    return (vals @ w) / (4 * material.kappa * np.sqrt(np.pi))


@dataclass
class PulseTables:
    """Influence coefficients of one time step of unit flux on one cell, per age.

    ``coeffs[k]`` [K per W/m²] ((2ny, 2nx), wrap-around order) is the temperature rise at time t
    of the flux held on the cell at the origin during [t − (k+1) dt, t − k dt]; ``ages`` lists the
    k of the non-zero tables (a moving body carries old heat away: its later tables vanish).
    """

    ages: np.ndarray     # int, ascending
    coeffs: np.ndarray   # K/(W/m²), (len(ages), 2ny, 2nx)


def pulse_tables(shape, dx: float, dy: float, material: ThermalMaterial, dt: float, n_ages: int,
                 motion: Motion | None = None, t: float | None = None, refine: float = 1.0) -> PulseTables:
    """Pulse tables of ages 0 … n_ages−1 for a fixed body (motion None: Eq. 6.3 route) or for
    body 1 moving with ``motion`` observed at time ``t`` (default n_ages·dt, which is all that
    matters for a constant speed). dt = np.inf with n_ages = 1 gives the steady tables. ``refine``
    (> 1) refines the moving-body quadrature panels (used to check its convergence)."""
    ny, nx = (int(s) for s in shape)
    if ny < 1 or nx < 1:
        raise InputError("shape", shape, "at least one cell per side")
    if not (dt > 0 and int(n_ages) >= 1 and (np.isfinite(dt) or n_ages == 1)):
        raise InputError("dt/n_ages", (dt, n_ages), "dt > 0 and n_ages >= 1 (np.inf only with n_ages = 1)")
    check_positive("refine", refine)
    a, b = 0.5 * dx, 0.5 * dy
    X, Y = wrap_offsets(nx) * dx, wrap_offsets(ny) * dy
    reach = float(np.hypot(nx * dx, ny * dy)) + 1.5 * max(a, b)
    norm = 1.0 / (4 * material.kappa * np.sqrt(np.pi))
    steady = np.isinf(dt)
    if motion is None:
        full = ThermalHalfSpace(material.kappa).influence(ny, nx, dy, dx)   # Love / (2πκ)
        if steady:
            return PulseTables(np.zeros(1, dtype=int), full[None])
        v_breaks = np.sqrt(4 * material.diffusivity * dt * np.arange(1, n_ages + 1))
        w, wt = _tail_nodes(reach, v_breaks)
        v = 1.0 / w
        # w-panel between 1/v_breaks[k+1] and 1/v_breaks[k] = heat of age k (k >= 1); beyond = age n
        seg = np.searchsorted(1.0 / v_breaks[::-1], w, side="right")          # 0 … n_ages
        age = n_ages - seg                                                      # n_ages … 0 (0 unused)
        ages, tail = _segment_sums(erf_window(Y[None, :], b, v[:, None]) * (v * v)[:, None],
                                   erf_window(X[None, :], a, v[:, None]), wt, age)     # ages 1 … n_ages
        first = full - norm * tail.sum(axis=0)          # steady minus the whole tail (Eq. 6.3)
        return PulseTables(np.arange(n_ages), np.concatenate((first[None], norm * tail[:n_ages - 1])))
    if steady:
        if not motion.profile.is_constant:
            raise InputError("motion", motion, "a steady state needs a constant speed")
        if motion.profile.values[0] == 0.0:
            return pulse_tables(shape, dx, dy, material, dt, 1)
        motion = Translation.steady(float(motion.speed(0.0)), motion.direction)
        k = motion.profile.values[0] / (4 * material.diffusivity)
        v_end = 2.0 * (9 + np.sqrt(81 + 4 * k * reach)) / (2 * k)   # twice where V v²/4χ = reach + 9v
        t = lag_max = v_end * v_end / (4 * material.diffusivity)
        breaks = np.empty(0)
    else:
        t = n_ages * dt if t is None else float(t)
        lag_max = min(t, n_ages * dt)
        breaks = dt * np.arange(1, n_ages)
    v, w, lag = _moving_nodes(motion, t, lag_max, material.diffusivity, min(a, b), reach, breaks, refine)
    dxs, dys = motion.back_displacement(t, lag)
    age = np.searchsorted(breaks, lag, side="right")
    ages, coeffs = _segment_sums(erf_window(Y[None, :] + dys[:, None], b, v[:, None]),
                                 erf_window(X[None, :] + dxs[:, None], a, v[:, None]), w, age)
    return PulseTables(ages, coeffs * norm)


def _segment_sums(ey, ex, w, seg):
    """(segments present, Σ over each one's nodes of w · outer(ey, ex)): one matrix product each."""
    order = np.argsort(seg, kind="stable")
    seg, ey, ex, w = seg[order], ey[order], ex[order], w[order]
    present, starts = np.unique(seg, return_index=True)
    ends = np.append(starts[1:], seg.size)
    out = np.empty((present.size, ey.shape[1], ex.shape[1]))
    for k, (i, j) in enumerate(zip(starts, ends)):
        out[k] = (ey[i:j] * w[i:j, None]).T @ ex[i:j]
    return present, out

"""Closed forms of transient and steady conduction with boundary conditions (Carslaw & Jaeger 1959;
Incropera & DeWitt, Fundamentals of Heat and Mass Transfer, 6th ed. 2007, ch. 3 and 5).

Temperatures T [K], ambient (fluid or surroundings) T_a [K], time t [s]; conductivity kappa
[W/(m K)], diffusivity chi [m^2/s], volumetric heat capacity rho c [J/(m^3 K)], convection
coefficient h [W/(m^2 K)], emissivity eps, sigma the Stefan–Boltzmann constant. Lumped forms hold
for a Biot number Bi = h (V/A)/kappa << 1 (Incropera §5.1–5.2: Bi < 0.1 for 5 %).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq
from scipy.special import erfc

from multiscale.errors import InputError, check_positive

STEFAN_BOLTZMANN = 5.670374419e-8      # W/(m^2 K^4), CODATA 2018 (exact)


def lumped_convective_cooling(time, T_initial: float, ambient: float, h: float, area: float,
                              capacity: float):
    """T(t) = T_a + (T_i − T_a) exp(−h A t/C) of a lumped body of heat capacity C = rho c V [J/K]
    and surface A [m^2] cooled (or heated) by convection (Newton's law of cooling; Incropera
    Eq. 5.6)."""
    rate = check_positive("h", h) * check_positive("area", area) / check_positive("capacity", capacity)
    return ambient + (T_initial - ambient) * np.exp(-rate * np.asarray(time, dtype=float))


def lumped_frictional_fade(time, mu0: float, slope: float, power: float, shares, capacities):
    """(mu(t), E(t)) of lumped bodies, insulated, heated by a sliding contact whose friction falls
    linearly with their temperatures (brake fade): mu = mu0 − slope u, u = sum_i w_i (T_i − T_0) the
    mean rise (w_i = 1/n: the contact's temperature, the mean of its two faces'), body i taking the
    share a_i of the frictional power mu P [W] (``power`` P per unit mu) into its capacity C_i [J/K].
    Then du/dt = K mu P, K = sum_i w_i a_i / C_i, so mu = mu0 exp(−slope K P t) and the heat put in
    E = (mu0 − mu) / (slope K) [J] (derived here from the lumped balance C_i dT_i/dt = a_i mu P)."""
    a, C = np.asarray(shares, dtype=float), np.asarray(capacities, dtype=float)
    K = float(np.mean(a / C))
    rate = check_positive("slope", slope) * check_positive("K", K) * check_positive("power", power)
    mu = mu0 * np.exp(-rate * np.asarray(time, dtype=float))
    return mu, (mu0 - mu) / (slope * K)


def lumped_cooling_time_linear_capacity(T, T_initial: float, ambient: float, h_area_per_volume: float,
                                        a: float, b: float):
    """Time [s] for a lumped body with rho c(T) = a + b T [J/(m^3 K)] to cool by convection from
    T_i to T: integrating (a + b T) dT/dt = −(h A/V)(T − T_a),

        t = V/(h A) [b (T_i − T) + (a + b T_a) ln((T_i − T_a)/(T − T_a))]."""
    k = check_positive("h_area_per_volume", h_area_per_volume)
    T = np.asarray(T, dtype=float)
    return (b * (T_initial - T) + (a + b * ambient) * np.log((T_initial - ambient) / (T - ambient))) / k


def lumped_cooling_linear_capacity(time, T_initial: float, ambient: float, h_area_per_volume: float,
                                   a: float, b: float):
    """T(t) of ``lumped_cooling_time_linear_capacity`` (its monotone inverse)."""
    return _invert(lambda T: lumped_cooling_time_linear_capacity(T, T_initial, ambient, h_area_per_volume, a, b),
                   time, T_initial, ambient)


def _invert(time_of, time, T_initial: float, ambient: float):
    """T(t) from a monotone t(T) between T_i (t = 0) and T_a (t → ∞), by bisection."""
    if T_initial == ambient:
        return np.full(np.shape(time), float(T_initial))
    eps = 1e-12 * abs(T_initial - ambient)
    lo, hi = (ambient + eps, T_initial) if T_initial > ambient else (T_initial, ambient - eps)
    out = [T_initial if t <= 0 else brentq(lambda T, t=t: time_of(T) - t, lo, hi, xtol=eps, rtol=1e-14)
           for t in np.atleast_1d(np.asarray(time, dtype=float))]
    return np.reshape(out, np.shape(time))


def _radiation_antiderivative(T, ambient: float):
    """G(T) with G' = 1/(T^4 − T_a^4): ln|(T − T_a)/(T + T_a)|/(4 T_a^3) − atan(T/T_a)/(2 T_a^3)."""
    T = np.asarray(T, dtype=float)
    if ambient == 0:
        return -1.0 / (3 * T**3)
    a = float(ambient)
    return np.log(np.abs((T - a) / (T + a))) / (4 * a**3) - np.arctan(T / a) / (2 * a**3)


def radiative_cooling_time(T, T_initial: float, ambient: float, rate: float):
    """Time [s] for a lumped body to go from T_i to T by radiation exchange with surroundings at
    T_a, dT/dt = −K (T^4 − T_a^4) with K = eps sigma A/(rho c V) [1/(K^3 s)]:
    t = [G(T_i) − G(T)]/K with G the antiderivative of 1/(T^4 − T_a^4) (Incropera Eq. 5.18;
    T_a = 0: t = (T^−3 − T_i^−3)/(3K))."""
    K = check_positive("rate", rate)
    return (_radiation_antiderivative(T_initial, ambient) - _radiation_antiderivative(T, ambient)) / K


def radiative_cooling(time, T_initial: float, ambient: float, rate: float):
    """T(t) of the lumped radiating body of ``radiative_cooling_time`` (its monotone inverse)."""
    return _invert(lambda T: radiative_cooling_time(T, T_initial, ambient, rate), time, T_initial, ambient)


def semi_infinite_constant_flux(depth, time, flux: float, kappa: float, diffusivity: float):
    """Temperature rise [K] at ``depth`` [m] below the surface of a semi-infinite solid heated by a
    uniform flux q [W/m^2] since t = 0 (Carslaw & Jaeger §2.9, Eq. 2.9(5)):
    2 q sqrt(chi t) / kappa * ierfc(depth / (2 sqrt(chi t))), ierfc(x) = exp(-x^2)/sqrt(pi) - x erfc(x);
    at the surface 2 q sqrt(t / (pi rho c kappa))."""
    root = np.sqrt(diffusivity * np.asarray(time, float))
    x = np.asarray(depth, float) / (2 * root)
    return 2 * flux * root / kappa * (np.exp(-x * x) / np.sqrt(np.pi) - x * erfc(x))


def slab_eigenvalues(biot: float, terms: int) -> np.ndarray:
    """The first ``terms`` positive roots zeta_n of zeta tan(zeta) = Bi, zeta_n in ((n−1)π, (n−1)π + π/2)
    (Incropera Eq. 5.39c; Carslaw & Jaeger §3.11)."""
    bi = check_positive("biot", biot)
    return np.array([brentq(lambda z: z * np.sin(z) - bi * np.cos(z), n * np.pi, n * np.pi + np.pi / 2,
                            xtol=1e-15, rtol=1e-15) for n in range(int(terms))])


def slab_convection(x, time, thickness: float, kappa: float, diffusivity: float, h: float,
                    T_initial: float, ambient: float, terms: int = 200):
    """T(x, t) in a slab 0 <= x <= L, insulated at x = 0, cooled by convection h towards T_a at
    x = L, uniform T_i at t = 0 (a plane wall of thickness 2L cooled on both faces):

        (T − T_a)/(T_i − T_a) = sum_n C_n exp(−zeta_n^2 Fo) cos(zeta_n x/L),
        C_n = 4 sin zeta_n/(2 zeta_n + sin 2 zeta_n),  Fo = chi t/L^2,  zeta_n tan zeta_n = Bi = h L/kappa

    (Carslaw & Jaeger 1959, §3.11, Eq. (8); Incropera Eqs. 5.39a–c). ``time`` > 0 (the series
    converges slowly as t → 0: give more ``terms``)."""
    L = check_positive("thickness", thickness)
    zeta = slab_eigenvalues(h * L / check_positive("kappa", kappa), terms)
    C = 4 * np.sin(zeta) / (2 * zeta + np.sin(2 * zeta))
    fo = check_positive("diffusivity", diffusivity) * np.asarray(time, dtype=float)[..., None] / L**2
    shape = np.broadcast_shapes(np.shape(x), np.shape(time))
    x = np.broadcast_to(np.asarray(x, dtype=float), shape)[..., None]
    theta = (C * np.exp(-zeta**2 * np.broadcast_to(fo, shape + (1,))) * np.cos(zeta * x / L)).sum(axis=-1)
    return ambient + (T_initial - ambient) * theta


def kirchhoff_transform(T, table, T_ref: float):
    """U(T) = ∫_{T_ref}^{T} kappa(s) ds [W/m] of a conductivity given as a table ((T_k, kappa_k), ...),
    linear between its rows and constant beyond its ends (exact: trapezoids on the breakpoints)."""
    xs, ys = (np.asarray(c, dtype=float) for c in zip(*table))
    if len(xs) < 2 or np.any(np.diff(xs) <= 0):
        raise InputError("table", table, "at least two rows with increasing temperatures")

    knots = np.concatenate([[0.0], np.cumsum((ys[1:] + ys[:-1]) / 2 * np.diff(xs))])

    def primitive(T):            # ∫_{xs[0]}^{T} kappa ds, trapezoids exact on each linear piece
        T = np.asarray(T, dtype=float)
        at = np.clip(T, xs[0], xs[-1])
        k = np.clip(np.searchsorted(xs, at, side="right") - 1, 0, len(xs) - 2)
        inside = knots[k] + (at - xs[k]) * (ys[k] + np.interp(at, xs, ys)) / 2
        return inside + np.minimum(T - xs[0], 0.0) * ys[0] + np.maximum(T - xs[-1], 0.0) * ys[-1]
    return primitive(T) - primitive(T_ref)


def kirchhoff_slab(z, length: float, T_low: float, T_high: float, table):
    """Steady temperature T(z) [K] of a slab 0 <= z <= L with a temperature-dependent conductivity
    (``kirchhoff_transform`` table), T(0) = T_low, T(L) = T_high, insulated sides: the Kirchhoff
    transform U(T) is linear in z, U(T(z)) = (z/L) U(T_high) with U from T_low, inverted here by
    bisection (U increases with T). The heat flux is U(T_high)/L [W/m^2] towards z = 0 (Carslaw &
    Jaeger 1959, §1.7; Incropera §3.2, Eq. 3.24 with q_x constant)."""
    L = check_positive("length", length)
    top = float(kirchhoff_transform(T_high, table, T_low))
    lo, hi = sorted((T_low, T_high))

    def one(zz):
        target = top * zz / L
        if zz <= 0 or zz >= L:
            return T_low if zz <= 0 else T_high
        return brentq(lambda T: float(kirchhoff_transform(T, table, T_low)) - target, lo, hi,
                      xtol=1e-12 * (hi - lo), rtol=1e-14)
    return np.vectorize(one, otypes=[float])(np.asarray(z, dtype=float))

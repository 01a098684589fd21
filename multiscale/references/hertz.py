"""Hertz contact of a sphere or an ellipsoid on an elastic flat (Hertz 1882; Johnson 1985, ch. 4).

Frictionless, small strains; ``E_star`` [Pa] is the composite modulus
1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2. Pressure positive in compression, approach δ [m] positive as
the bodies close.

Sphere (thesis Eqs. 1.1, 1.3, 1.5 with e = 0): P = 4/3 E* R^½ δ^(3/2), a = (3 P R / 4 E*)^(1/3),
δ = a²/R, p0 = 3P/(2π a²), p(r) = p0 √(1 − r²/a²).

Ellipse (thesis §1.2.1 and §1.2.2.3, Eqs. 1.1–1.4, 1.17–1.22): written for a contact ellipse of
semi-axes ``a = 1`` (along X) and ``b = sqrt(bb)`` (along Y), ``bb = b²/a² = 1 − e²``; lengths
scale with ``a``. The potential integrals of Eq. 1.17,

    I0(λ) = ∫_λ^∞ dw / sqrt((1+w)(bb+w) w)
    Ia(λ) = ∫_λ^∞ dw / sqrt((1+w)³(bb+w) w),   Ib(λ) = ∫_λ^∞ dw / sqrt((1+w)(bb+w)³ w),

are Carlson's symmetric integrals: I0 = 2 R_F(1+λ, bb+λ, λ), Ia = ⅔ R_D(bb+λ, λ, 1+λ),
Ib = ⅔ R_D(1+λ, λ, bb+λ). They equal the Legendre forms of Eqs. 1.20–1.22 (thesis L, M, N up to
the factors a², 1/e²) but have no 1/e² cancellation at e → 0 and are well conditioned up to
e → 1. The surface displacement of the Hertz pressure p0 sqrt(1 − X² − Y²/bb) is (Eq. 1.17)

    u(X, Y) = p0 b / (2 E*) · [I0(λ) − X² Ia(λ) − Y² Ib(λ)],

λ the positive root of X²/(1+λ) + Y²/(bb+λ) = 1 outside the ellipse (Eq. 1.18) and 0 inside.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

from multiscale.errors import InputError, check_positive


# ----------------------------------------------------------------------------- sphere on a flat
@dataclass(frozen=True)
class HertzContact:
    """Hertz contact of a sphere on a flat under one load."""

    load: float            # N, P
    contact_radius: float  # m, a
    max_pressure: float    # Pa, p0 = 3P/(2π a²), at the centre
    approach: float        # m, δ = a²/R

    def pressure(self, r) -> np.ndarray:
        """p(r) = p0 √(1 − r²/a²) [Pa] at radii ``r`` [m] (0 outside the contact; thesis Eq. 1.5)."""
        r = np.asarray(r, dtype=float)
        return self.max_pressure * np.sqrt(np.maximum(1.0 - (r / self.contact_radius) ** 2, 0.0))


def sphere_on_flat(load: float, radius: float, E_star: float) -> HertzContact:
    """Contact of a sphere of radius ``radius`` [m] pressed by ``load`` [N] > 0 on a flat (E* [Pa])."""
    P = check_positive("load", load)
    R = check_positive("radius", radius)
    a = (3 * P * R / (4 * check_positive("E_star", E_star))) ** (1 / 3)
    return HertzContact(P, a, 3 * P / (2 * np.pi * a * a), a * a / R)


def sphere_on_flat_at_radius(contact_radius: float, radius: float, E_star: float) -> HertzContact:
    """The same contact given its radius a [m] > 0: P = 4 E* a³/(3R), p0 = 2 E* a/(π R), δ = a²/R."""
    a = check_positive("contact_radius", contact_radius)
    R = check_positive("radius", radius)
    E = check_positive("E_star", E_star)
    return HertzContact(4 * E * a**3 / (3 * R), a, 2 * E * a / (np.pi * R), a * a / R)


def sphere_load(approach, radius: float, E_star: float):
    """Load P = 4/3 E* R^½ δ^(3/2) [N] of a sphere (radius R [m]) at approaches δ [m] >= 0 (Eq. 1.1, e = 0)."""
    d = np.asarray(approach, dtype=float)
    if np.any(d < 0):
        raise InputError("approach", approach, "must be >= 0")
    return 4 / 3 * E_star * np.sqrt(radius) * d**1.5


# ----------------------------------------------------------------------------- ellipsoid on a flat
def potential_integrals(lam, bb):
    """(I0, Ia, Ib) of Eq. 1.17 at λ >= 0 for the ellipse (1, sqrt(bb)), 0 < bb <= 1."""
    lam = np.asarray(lam, dtype=float)
    bb = np.asarray(bb, dtype=float)
    i0 = 2.0 * special.elliprf(1.0 + lam, bb + lam, lam)
    ia = special.elliprd(bb + lam, lam, 1.0 + lam) * (2.0 / 3.0)
    ib = special.elliprd(1.0 + lam, lam, bb + lam) * (2.0 / 3.0)
    return i0, ia, ib


def exterior_lambda(X2, Y2, bb):
    """Root λ >= 0 of X²/(1+λ) + Y²/(bb+λ) = 1 (Eq. 1.18) for X2 = X², Y2 = Y²; 0 inside.

    The quadratic λ² + Bλ + C = 0 (B = 1 + bb − X² − Y², C = bb(1 − X²) − Y²) is solved in the
    cancellation-free form for either sign of B.
    """
    X2, Y2, bb = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (X2, Y2, bb)))
    B = 1.0 + bb - X2 - Y2
    C = bb * (1.0 - X2) - Y2
    outside = C < 0
    root = np.sqrt(np.maximum(B * B - 4.0 * C, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.where(B > 0, -2.0 * C / np.where(B > 0, B + root, 1.0), 0.5 * (root - B))
    return np.where(outside, np.maximum(lam, 0.0), 0.0)


def curvature_ratio(bb):
    """R''/R' = Ia(0)/Ib(0): ratio of the principal relative radii that makes a Hertz contact
    ellipse of axis ratio b/a = sqrt(bb) (exact form of Eq. 1.2). Increasing in bb, 1 at bb = 1."""
    _, ia, ib = potential_integrals(0.0, bb)
    return ia / ib


def axis_ratio_squared(R2_over_R1, *, exact: bool = True):
    """bb = (b/a)² = 1 − e² of the Hertz ellipse for principal radii R'' <= R' (ratio in (0, 1]).

    ``exact``: invert ``curvature_ratio`` by bisection in log(bb) (relative accuracy 1e-13);
    otherwise the approximation e = sqrt(1 − (R''/R')^(4/3)) of Eq. 1.2.
    """
    rho = np.asarray(R2_over_R1, dtype=float)
    if np.any(~np.isfinite(rho)) or np.any(rho <= 0) or np.any(rho > 1 + 1e-12):
        raise InputError("R2/R1", rho, "principal radius ratio must lie in (0, 1]")
    rho = np.minimum(rho, 1.0)
    approx = rho ** (4.0 / 3.0)
    if not exact:
        return approx
    lo = np.log(approx) - 1.0                   # Eq. 1.2 is within a few % of the exact bb
    hi = np.minimum(np.log(approx) + 1.0, 0.0)
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        up = curvature_ratio(np.exp(mid)) < rho
        lo, hi = np.where(up, mid, lo), np.where(up, hi, mid)
    return np.where(rho >= 1.0, 1.0, np.exp(0.5 * (lo + hi)))


def hertz_F1(e):
    """F1(e) of Eq. 1.1 (Legendre form): P = 4/3 E* R^½ F1 δ^(3/2), R = sqrt(R' R''); F1(0) = 1."""
    e = np.asarray(e, dtype=float)
    m = e * e
    K, E = special.ellipk(m), special.ellipe(m)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.pi / (e * np.sqrt(2.0)) * ((E / (1.0 - m) - K) * (K - E)) ** 0.25 * K ** -1.5
    return np.where(e > 1e-3, f, 1.0 + 3.0 * m * m / 256.0)


def hertz_A1(e):
    """A1(e) of Eq. 1.3 (Legendre form): contact area A = π a b = π A1 R δ; A1(0) = 1."""
    e = np.asarray(e, dtype=float)
    K = special.ellipk(e * e)
    return np.sqrt(1.0 - e * e) * (2.0 * K * hertz_F1(e) / np.pi) ** 2

"""Per-asperity contact laws: the API the asperity models solve, and its Hertz implementations
(thesis ch. 1 §1.2.1, §1.2.2.3; §2.4.2 for layered solids, ``layered_asperity.LayeredCircular``).

``AsperityLaw`` API
-------------------
All methods are vectorised: ``a`` [m] is an array of contact sizes (radius, or major semi-axis)
and ``idx`` the matching asperity indices (table order). Sizes may be tiny but never negative.

* ``approach(a, idx) -> (w, dw_da)``  self approach of the summit under its own contact [m]
  (Hertz circular a²/R; layered a² ζ(a)/R, Eq. 2.19 i = k). Increasing, ~a² as a → 0.
* ``force(a, idx) -> (P, dP_da)``  contact force [N] (4E* a³/3R; layered 8/3 |α| χ a³/R, Eq. 2.16).
  Increasing, ~a³ as a → 0.
* ``energy(a, idx) -> (W, dW_da)``  complementary self energy W = ∫_0^a P'(s) w(s) ds [J]
  (default: 16-point Gauss–Legendre of the two methods above; dW/da = P' w).
* ``semi_axes(a, idx) -> (a_major, b_minor)`` [m]; ``area(a, idx)`` [m²] (default π a b).
* ``size_at(w, idx) -> a``  inverse of ``approach`` (non-interacting solution; default bisection).
* ``displacement(a, src, dx, dy, a_ref=None) -> (u, du_da)``  surface displacement [m] caused by
  the contact of asperities ``src`` (size ``a``) at the in-plane offsets (dx, dy) [m] from their
  centres (global axes), and its derivative in a (Eqs. 1.10, 1.17–1.19, 2.18). ``a_ref`` >= a is a
  size fixed during the solve: a law that switches to a far-field series must decide with it, so
  that u stays a smooth function of a (the minimisers need that).
* ``pressure(a, src, dx, dy) -> p``  contact pressure [Pa] at those offsets (Eqs. 1.4, 2.17).
* ``point_response(r) -> g``  surface displacement [m] at distance r per unit normal point force
  [N] (half-space: 1/(π E* r)); the far-field kernel of the interaction sum.
* attributes ``n`` (number of asperities), ``E_star`` [Pa] (modulus used in kappa),
  ``far_field_coefficient`` (bound c on |u − P g| <= c (a/r)² P g for r >= 3a; Hertz 0.211: 0.104 circular, 0.2101 at R2/R1 = 1e-3).

``multiscale.micro.asperity.AsperityModel(table, law, interaction=...)`` solves any such law;
``HertzCircular`` and ``HertzElliptic`` are the homogeneous half-space implementations
(``hertz_law`` builds them from an ``AsperityTable``).
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from multiscale.errors import InputError, check_flag, check_positive
from multiscale.micro.kernels import HalfSpace, Kernel
from multiscale.micro.surface import AsperityTable
from multiscale.references.hertz import axis_ratio_squared, exterior_lambda, potential_integrals

_GL_X, _GL_V = np.polynomial.legendre.leggauss(16)
_GL_T, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_V          # Gauss–Legendre on (0, 1)


class AsperityLaw(ABC):
    """Contact law of a set of asperities on one solid (see the module docstring for the API)."""

    n: int
    E_star: float
    far_field_coefficient: float = 0.211

    @abstractmethod
    def approach(self, a, idx):
        """(w_self [m], dw/da [-]) of asperities ``idx`` at contact sizes ``a`` [m]."""

    @abstractmethod
    def force(self, a, idx):
        """(P [N], dP/da [N/m])."""

    @abstractmethod
    def semi_axes(self, a, idx):
        """(major, minor) semi-axes of the contact [m]."""

    @abstractmethod
    def displacement(self, a, src, dx, dy, a_ref=None):
        """(u [m], du/da [-]) at offsets (dx, dy) [m] from the centres of asperities ``src``.

        ``a_ref`` >= a (per pair, fixed during a solve) may be used to choose between an exact and
        a far-field expression so that the choice does not jump while a varies."""

    @abstractmethod
    def pressure(self, a, src, dx, dy):
        """Contact pressure [Pa] at offsets (dx, dy) [m] from the centres of asperities ``src``."""

    @abstractmethod
    def point_response(self, r):
        """Surface displacement [m] at distance ``r`` [m] > 0 per unit point force [N]."""

    def energy(self, a, idx):
        """(W [J], dW/da [N]) with W = ∫_0^a P'(s) w_self(s) ds (Gauss–Legendre, 16 points)."""
        a = np.asarray(a, dtype=float)
        s = (a[:, None] * _GL_T[None, :]).ravel()
        j = np.repeat(np.asarray(idx), len(_GL_T))
        _, dP = self.force(s, j)
        w, _ = self.approach(s, j)
        W = a * ((dP * w).reshape(len(a), -1) @ _GL_W)
        _, dPa = self.force(a, idx)
        wa, _ = self.approach(a, idx)
        return W, dPa * wa

    def area(self, a, idx):
        """Contact area [m²] (ellipse π a b)."""
        A, B = self.semi_axes(a, idx)
        return np.pi * A * B

    def size_at(self, w, idx):
        """Contact size [m] whose self approach is ``w`` [m] (>= 0), by bisection."""
        w = np.asarray(w, dtype=float)
        idx = np.asarray(idx)
        hi = np.full(w.shape, 1e-9)
        for _ in range(200):
            short = self.approach(hi, idx)[0] < w
            if not short.any():
                break
            hi = np.where(short, 2 * hi, hi)
        lo = np.zeros_like(hi)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            up = self.approach(mid, idx)[0] < w
            lo, hi = np.where(up, mid, lo), np.where(up, hi, mid)
        return np.where(w > 0, 0.5 * (lo + hi), 0.0)


class _HalfSpaceLaw(AsperityLaw):
    """Hertz contacts on a homogeneous half-space: P ∝ a³, w ∝ a², W = 3/5 P w (exact)."""

    def __init__(self, E_star: float, n: int):
        self.E_star = check_positive("E_star", E_star)
        self.n = n

    def energy(self, a, idx):
        P, dP = self.force(a, idx)
        w, _ = self.approach(a, idx)
        return 0.6 * P * w, dP * w

    def point_response(self, r):
        return 1.0 / (np.pi * self.E_star * np.asarray(r, dtype=float))


class HertzCircular(_HalfSpaceLaw):
    """Circular Hertz contacts of radius a on summits of radius R (Eqs. 1.5–1.10, F1 = A1 = 1)."""

    def __init__(self, R, E_star: float):
        self.R = _positive_array("R", R)
        super().__init__(E_star, len(self.R))

    def approach(self, a, idx):
        R = self.R[idx]
        return a * a / R, 2 * a / R

    def force(self, a, idx):
        k = 4 * self.E_star / self.R[idx]
        return k * a**3 / 3, k * a * a

    def semi_axes(self, a, idx):
        return a, a

    def size_at(self, w, idx):
        return np.sqrt(self.R[idx] * np.maximum(w, 0.0))

    def displacement(self, a, src, dx, dy, a_ref=None):
        """Eq. 1.10: (2a² − r²)/2R inside, [(2a² − r²) asin(a/r) + a sqrt(r² − a²)]/πR outside.
        (Closed form: ``a_ref`` is not needed.)"""
        R = self.R[src]
        r2 = dx * dx + dy * dy
        inside = r2 <= a * a
        r = np.sqrt(r2)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(inside, 1.0, a / np.where(r > 0, r, 1.0))
        asn = np.arcsin(np.minimum(s, 1.0))
        out = ((2 * a * a - r2) * asn + a * np.sqrt(np.maximum(r2 - a * a, 0.0))) / (np.pi * R)
        u = np.where(inside, (2 * a * a - r2) / (2 * R), out)
        du = np.where(inside, 2 * a / R, 4 * a * asn / (np.pi * R))
        return u, du

    def pressure(self, a, src, dx, dy):
        return 2 * self.E_star / (np.pi * self.R[src]) * np.sqrt(np.maximum(a * a - dx * dx - dy * dy, 0.0))


class HertzElliptic(_HalfSpaceLaw):
    """Elliptic Hertz contacts (Eqs. 1.1–1.4, 1.17–1.23) on summits of principal radii R1 >= R2.

    The major semi-axis a lies along the R1 axis at ``angle`` [rad] from +x; b = a sqrt(1 − e²).
    ``exact=True`` takes e from the exact Hertz relation between R2/R1 and b/a (see
    ``references.hertz.axis_ratio_squared``); ``exact=False`` uses the approximation of Eq. 1.2.
    All relations are closed forms in Carlson integrals (``references.hertz.potential_integrals``) and equal
    P = 4/3 E* R^½ F1(e) w^(3/2), A = π A1(e) R w of Eqs. 1.1, 1.3 with R = sqrt(R1 R2).
    """

    exact_range = 6.0     # Carlson integrals within this many major semi-axes, multipoles beyond

    def __init__(self, R1, R2, angle, E_star: float, *, exact: bool = True):
        R1, R2 = _positive_array("R1", R1), _positive_array("R2", R2)
        angle = np.asarray(angle, dtype=float).ravel()
        if R1.shape != R2.shape or angle.shape != R1.shape or not np.all(np.isfinite(angle)):
            raise InputError("R1/R2/angle", (R1.shape, R2.shape, angle.shape),
                             "finite arrays of equal length")
        if np.any(R2 > R1 * (1 + 1e-12)):
            raise InputError("R2", R2, "principal radii must be ordered R1 >= R2")
        super().__init__(E_star, len(R1))
        self.bb = axis_ratio_squared(np.minimum(R2 / R1, 1.0), exact=exact)
        self.eccentricity = np.sqrt(1.0 - self.bb)
        i0, ia, ib = potential_integrals(0.0, self.bb)
        R = np.sqrt(R1 * R2)
        Ra = R * np.sqrt(ib / ia)                     # = R1 when exact
        self._k = 1.0 / (2.0 * Ra * ia)               # u = k a² [I0 − X² Ia − Y² Ib] (a = 1 units)
        self._i0 = i0
        self._cos, self._sin = np.cos(angle), np.sin(angle)

    def approach(self, a, idx):
        c = self._k[idx] * self._i0[idx]
        return c * a * a, 2 * c * a

    def force(self, a, idx):
        k = 4 * np.pi * self.E_star * self._k[idx]
        return k * a**3 / 3, k * a * a

    def semi_axes(self, a, idx):
        return a, a * np.sqrt(self.bb[idx])

    def size_at(self, w, idx):
        return np.sqrt(np.maximum(w, 0.0) / (self._k[idx] * self._i0[idx]))

    def _local(self, a, src, dx, dy):
        c, s = self._cos[src], self._sin[src]
        return (c * dx + s * dy) / a, (c * dy - s * dx) / a

    def displacement(self, a, src, dx, dy, a_ref=None):
        """Eq. 1.17 in Carlson form, du/da = 2 k a I0(λ) (the λ-derivative terms vanish by Eq. 1.18),
        within ``exact_range`` · a_ref (default a) of the centre; beyond, the multipole series to the
        quadrupole, u = P/(π E* r) [1 + (3(a² X̂² + b² Ŷ²) − a² − b²)/(10 r²)] (X̂, Ŷ
        direction cosines in the principal axes), relative error < 1e-4 there (tested)."""
        X, Y = self._local(a, src, dx, dy)
        bb = self.bb[src]
        X2, Y2 = X * X, Y * Y
        k = self._k[src]
        r2 = X2 + Y2
        u, du = np.empty_like(r2), np.empty_like(r2)
        near = (dx * dx + dy * dy) < (self.exact_range * (a if a_ref is None else a_ref))**2
        i0, ia, ib = potential_integrals(exterior_lambda(X2[near], Y2[near], bb[near]), bb[near])
        kn, an = k[near], a[near]
        u[near], du[near] = kn * an * an * (i0 - X2[near] * ia - Y2[near] * ib), 2 * kn * an * i0
        far = ~near
        kf, af, rf2 = k[far], a[far], r2[far]
        q = (3 * (X2[far] + bb[far] * Y2[far]) / rf2 - 1 - bb[far]) / 10   # × (a/r)²
        mono = 4 * kf * af * af / (3 * np.sqrt(rf2))                     # P/(π E* r); rf2 = (r/a)²
        u[far], du[far] = mono * (1 + q / rf2), mono * (3 + 5 * q / rf2) / af
        return u, du

    def pressure(self, a, src, dx, dy):
        X, Y = self._local(a, src, dx, dy)
        bb = self.bb[src]
        p0 = 2 * self.E_star * self._k[src] * a / np.sqrt(bb)
        return p0 * np.sqrt(np.maximum(1.0 - X * X - Y * Y / bb, 0.0))


def hertz_law(table: AsperityTable, solid, shape: str = "elliptic", *, exact: bool = True) -> AsperityLaw:
    """Hertz law of the asperities of ``table`` on a homogeneous ``solid`` (``HalfSpace`` or E* [Pa]).

    ``shape="circular"``: radius R = sqrt(R1 R2) (models 2 and 4 of §1.3); ``"elliptic"``: models 1 and 3.
    """
    check_table(table)
    if isinstance(solid, Kernel) and not isinstance(solid, HalfSpace):   # (it said "must be a real number": a trial)
        raise InputError("solid", solid, "a HalfSpace or its E* [Pa] (the Hertz laws are of a homogeneous elastic "
                                         "half-space; layered solids: layered_asperity.layered_law)")
    E_star = solid.E_star if isinstance(solid, HalfSpace) else check_positive("solid", solid)
    if not isinstance(shape, str) or shape not in ("circular", "elliptic"):
        raise InputError("shape", shape, "'circular' or 'elliptic'")
    if shape == "circular":
        return HertzCircular(table.radius, E_star)
    return HertzElliptic(table.R1, table.R2, table.angle, E_star, exact=check_flag("exact", exact))


def check_table(table) -> None:
    """InputError unless ``table`` is a non-empty ``AsperityTable`` of finite positions, heights and
    positive radii."""
    if not isinstance(table, AsperityTable):
        raise InputError("table", table, "an AsperityTable (surface.find_asperities)")
    if len(table) == 0:
        raise InputError("table", "empty AsperityTable", "needs at least one asperity")
    n = len(table)
    for name in ("x", "y", "height", "R1", "R2", "angle"):
        v = np.asarray(getattr(table, name), dtype=float)
        if v.shape != (n,) or not np.all(np.isfinite(v)):
            raise InputError(f"table.{name}", v, f"{n} finite values")
    for name in ("R1", "R2"):
        if np.any(np.asarray(getattr(table, name)) <= 0):
            raise InputError(f"table.{name}", getattr(table, name), "radii must be > 0")


def _positive_array(name, v):
    """``v`` as a flat float array of finite radii > 0 (InputError otherwise)."""
    arr = np.asarray(v, dtype=float).ravel()
    if arr.size == 0:
        raise InputError(name, v, "needs at least one asperity")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(name, v, "radii must be finite and > 0")
    return arr


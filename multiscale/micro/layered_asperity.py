"""Axisymmetric asperity on a multi-layered solid and the layered multi-asperity model (thesis
§2.3–2.4, Eqs. 2.6–2.25).

A paraboloid f(r) = r²/2R on a ``LayeredElastic`` solid is pressed by a rigid flat (approach delta).
With k(u) = q F(q) / (2/E1*) − 1 (the thesis' k_z = alpha F11 − 1, alpha = −E1*/2) the contact
problem reduces to the Fredholm equation of the second kind (Eq. 2.9) for psi = phi_a / alpha:

    psi(s) + ∫_0^1 K_a(s, t) psi(t) dt = delta − a² s² / R,
    K_a(s, t) = (2a/pi) ∫_0^∞ k(u) cos(a u s) cos(a u t) du = (a/pi) [c(a(s−t)) + c(a(s+t))],

with c(y) = ∫_0^∞ k(u) cos(u y) du. It is solved by Nyström quadrature (Gauss–Legendre nodes on
[0, 1]) for a given contact radius a: psi = delta psi_1 − (a²/R) psi_2 is linear in delta, and the
smooth-edge condition psi(1) = 0 (Eq. 2.12) gives delta, so no iteration on a is needed. Force
P = 2 a E1* ∫ psi (Eq. 2.10), pressure from Eq. 2.11. Both reduce to a → functions of the solid
only: delta = (a²/R) zeta_ex(a) and P = (4/3) E1* chi_ex(a) a³/R (Hertz: chi = zeta = 1).

The second-order approximation (§2.4.1, psi = psi(0)(1 − s²), Eqs. 2.14–2.18) gives chi(a), zeta(a)
in closed quadrature form; ``LayeredCircular`` is the per-asperity ``AsperityLaw`` built on them
(force Eq. 2.16, self approach a² zeta/R, pressure Eq. 2.17, displacement Eq. 2.18 with the
layered correction g(a, r)), for ``multiscale.micro.asperity.AsperityModel`` (§2.4.2, with or
without interaction).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline, RectBivariateSpline
from scipy.special import j0

from multiscale.errors import InputError, check_count, check_positive
from multiscale.micro.asperity_laws import AsperityLaw, check_table
from multiscale.micro.layered import LayeredElastic, hankel_nodes, radial_table
from multiscale.micro.surface import AsperityTable
from multiscale.references.hertz import sphere_load

MAX_NODES = 400       # default Nyström nodes at most (memory ~ samples x nodes² of the batched solve)
# Nodes per a_max / h1 at least: the kernel varies on the scale h1/a in s, and too few nodes gave a
# wrong chi without a warning (400 nodes on a soft layer: +0.15 % at a_max = 200 h1, +42 % at 300 h1,
# -90 % at 400 h1 against 2000 nodes and the Winkler limit; 4 per a_max/h1 keeps it below 2e-5, nu = 0.5 too)
NODES_PER_RATIO = 4


@dataclass
class FredholmSolution:
    """Full solution (Eq. 2.9) of a paraboloid of radius ``R`` at contact radii ``radius``."""

    radius: np.ndarray     # m, contact radius a
    approach: np.ndarray   # m, rigid approach delta (Eq. 2.12)
    force: np.ndarray      # N, total force P (Eq. 2.10)
    chi: np.ndarray        # -, P / Hertz force of the top layer at the same a
    zeta: np.ndarray       # -, delta / (a² / R)
    R: float               # m, asperity radius


@dataclass
class ForceCurve:
    """Force against approach of one asperity: full solution and the chi/zeta approximation."""

    approach: np.ndarray       # m
    force: np.ndarray          # N, full Fredholm solution
    radius: np.ndarray         # m, full solution
    approx_force: np.ndarray   # N, second-order model (Eqs. 2.16, zeta)
    approx_radius: np.ndarray  # m
    hertz_force: np.ndarray    # N, top layer as a half-space: 4/3 E1* R^½ delta^(3/2)

    @property
    def approx_error(self) -> np.ndarray:
        """Relative error of the approximate force (thesis Fig. 2.9)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.force > 0, self.approx_force / self.force - 1, 0.0)


class LayeredAsperity:
    """Paraboloidal asperities on a ``LayeredElastic`` solid, contact radii up to ``a_max`` [m].

    ``nodes``: Gauss–Legendre nodes of the Nyström method (default grows with a_max / h1 so that
    the kernel, which varies on the scale h1/a in s, is resolved; results converge exponentially),
    at least ``NODES_PER_RATIO`` a_max / h1 (else ``InputError``: by default a_max <= 100 h1).
    """

    def __init__(self, kernel: LayeredElastic, a_max: float, nodes: int | None = None):
        if not isinstance(kernel, LayeredElastic):
            raise InputError("kernel", kernel, "a LayeredElastic solid")
        self.kernel, self.a_max = kernel, check_positive("a_max", a_max)
        self.E_star = 2.0 / kernel.top_coefficient            # E1* = -2 alpha
        h1 = kernel.thickness[0]
        ratio = self.a_max / h1
        n = check_count("nodes", nodes) if nodes is not None else int(min(MAX_NODES, 32 + 8 * np.ceil(ratio)))
        if n < 4:
            raise InputError("nodes", nodes, "at least 4 Gauss nodes")
        if n < NODES_PER_RATIO * ratio:
            name, value = ("a_max", a_max) if nodes is None else ("nodes", nodes)
            raise InputError(name, value, f"contact radii up to a_max = {self.a_max:.3g} m are {ratio:.0f} times the "
                             f"top layer's thickness {h1:.3g} m: the Nyström method needs at least "
                             f"{int(np.ceil(NODES_PER_RATIO * ratio))} nodes to resolve the layer (has {n}; "
                             f"default at most {MAX_NODES}, memory grows as nodes²); a layer this thin against "
                             "the contact is better modelled by its thin-layer limit or the substrate alone")
        x, w = np.polynomial.legendre.leggauss(n)
        self.s, self.w = (x + 1) / 2, w / 2
        self._c = _CosineTransform(kernel, 2 * self.a_max)

    # -- Fredholm kernel -------------------------------------------------------------------
    def _K(self, a, s, t):
        """K_a(s, t) for arrays a (..., 1, 1) and node vectors (Eq. 2.9)."""
        return (a / np.pi) * (self._c(a * np.abs(s - t)) + self._c(a * (s + t)))

    def _check_a(self, a):
        a = np.atleast_1d(np.asarray(a, dtype=float))
        if not np.all(np.isfinite(a)) or np.any(a < 0) or np.any(a > self.a_max * (1 + 1e-12)):
            raise InputError("a", a, f"contact radii must lie in [0, a_max = {self.a_max:g}] m")
        return a

    def _nystrom(self, a):
        """psi_1, psi_2 at the nodes and at s = 1, for right-hand sides 1 and s² (a >= 0 array)."""
        A = a[:, None, None]
        s, w = self.s, self.w
        K = self._K(A, s[:, None], s[None, :])                       # (na, n, n)
        M = np.eye(len(s)) + K * w[None, None, :]
        rhs = np.stack([np.ones_like(s), s * s], axis=-1)
        psi = np.linalg.solve(M, np.broadcast_to(rhs, (len(a),) + rhs.shape))   # (na, n, 2)
        K1 = self._K(A[..., 0], 1.0, s[None, :])                     # (na, n)
        edge = np.array([1.0, 1.0]) - np.einsum("an,anr->ar", K1 * w, psi)
        return psi, edge

    def exact(self, a, R: float) -> FredholmSolution:
        """Full solution at contact radii ``a`` [m] (array) for an asperity of radius ``R`` [m]."""
        a = self._check_a(a)
        R = check_positive("R", R)
        psi, edge = self._nystrom(a)
        zeta = edge[:, 1] / edge[:, 0]                               # psi(1) = 0
        ints = np.einsum("n,anr->ar", self.w, psi)
        chi = 1.5 * (zeta * ints[:, 0] - ints[:, 1])
        return FredholmSolution(a, a * a / R * zeta, 4 * self.E_star * chi * a**3 / (3 * R), chi, zeta, R)

    def approximate(self, a):
        """(chi(a), zeta(a)) of the second-order model (§2.4.1, Eqs. 2.14–2.15)."""
        a = self._check_a(a)
        A = a[:, None]
        wt = self.w * (1 - self.s**2)
        I0 = (self._K(A, 0.0, self.s[None, :]) * wt).sum(-1)
        I1 = (self._K(A, 1.0, self.s[None, :]) * wt).sum(-1)
        chi = 1.0 / (1.0 + I0 - I1)
        return chi, (1.0 + I0) * chi

    def pressure(self, a: float, R: float, r) -> np.ndarray:
        """Contact pressure [Pa] of the full solution at radii ``r`` [m] (Eq. 2.11, p = −sigma_zz)."""
        a = float(self._check_a(a)[0])
        R = check_positive("R", R)
        if a == 0:
            return np.zeros(np.shape(r))
        psi, edge = self._nystrom(np.array([a]))
        delta = edge[0, 1] / edge[0, 0] * a * a / R
        coeff = delta * psi[0, :, 0] - a * a / R * psi[0, :, 1]     # psi at the nodes
        s = np.clip(np.atleast_1d(np.asarray(r, dtype=float)) / a, 0.0, 1.0)
        x, w = np.polynomial.legendre.leggauss(48)
        top = np.sqrt(1 - s * s)[:, None]
        tau = top * (x + 1) / 2
        t = np.sqrt(s[:, None] ** 2 + tau * tau)                     # t² = s² + tau²: no singularity
        dc = self._c.derivative
        dK = (a * a / np.pi) * (np.sign(t[..., None] - self.s) * dc(a * np.abs(t[..., None] - self.s))
                                + dc(a * (t[..., None] + self.s)))
        dpsi = -2 * a * a / R * t - (dK * (self.w * coeff)).sum(-1)
        integral = (dpsi / t * w).sum(-1) * top[:, 0] / 2
        return (-self.E_star / (np.pi * a) * integral).reshape(np.shape(r))

    def force_curve(self, approach, R: float, samples: int = 64) -> ForceCurve:
        """P(delta) of the full and approximate solutions at ``approach`` [m] (Figs. 2.4–2.6, 2.9),
        by inverting the monotone delta(a) on ``samples`` radii up to a_max (cubic interpolation)."""
        d = np.atleast_1d(np.asarray(approach, dtype=float))
        R = check_positive("R", R)
        a = self.a_max * np.linspace(0, 1, samples) ** 1.5
        full = self.exact(a, R)
        chi, zeta = self.approximate(a)
        d_app = a * a * zeta / R
        for name, delta in (("full", full.approach), ("approximate", d_app)):
            if np.any(np.diff(delta) <= 0):
                raise InputError("a_max", self.a_max, f"delta(a) of the {name} solution is not increasing")
            if d.max() > delta[-1]:
                raise InputError("approach", d.max(), f"a_max = {self.a_max:g} m reaches only {delta[-1]:.4g} m")
        if np.any(d < 0):
            raise InputError("approach", approach, "must be >= 0")
        ra = CubicSpline(full.approach, a)(d)
        rb = CubicSpline(d_app, a)(d)
        P = CubicSpline(a, full.chi)(ra) * 4 * self.E_star * ra**3 / (3 * R)
        Pa = CubicSpline(a, chi)(rb) * 4 * self.E_star * rb**3 / (3 * R)
        return ForceCurve(d, P, ra, Pa, rb, sphere_load(d, R, self.E_star))

    # -- interaction terms -----------------------------------------------------------------
    def interaction_table(self, r_max: float, n_a: int = 48, r_points: int = 240):
        """g(a, r) of Eq. 2.18, g = 4 ∫ k(rho) J0(rho r) (sin a rho − a rho cos a rho)/rho³ d rho,
        as a spline over a in [0, a_max] and r in [r_min, r_max] (r_min = a_max / 100)."""
        kernel = self.kernel
        r_max = check_positive("r_max", r_max)
        q, wq = hankel_nodes(kernel.cutoff(), max(r_max, self.a_max), sum(kernel.thickness))
        k = kernel.excess(q) / kernel.top_coefficient
        a = np.linspace(0, self.a_max, n_a)
        x = np.outer(q, a)
        small = x < 1e-2                                              # series of sin x − x cos x
        with np.errstate(invalid="ignore", divide="ignore"):
            shape = np.where(small, x**3 / 3 - x**5 / 30, np.sin(x) - x * np.cos(x)) / q[:, None] ** 3
        r = np.geomspace(self.a_max / 100, r_max, r_points)
        g = 4 * (j0(np.outer(r, q)) * (k * wq)) @ shape                # (r, a)
        return RectBivariateSpline(a, r, g.T, kx=3, ky=3)


class _CosineTransform:
    """c(y) = ∫_0^∞ k(u) cos(u y) du on [0, Y], k = excess / A: composite Gauss–Legendre in u
    (``hankel_nodes``), tabulated every h1/48 in y and interpolated by a cubic spline (c varies on the
    scale h1: relative interpolation error ~1e-9)."""

    def __init__(self, kernel: LayeredElastic, Y: float):
        u, w = hankel_nodes(kernel.cutoff(), Y, sum(kernel.thickness))
        kw = kernel.excess(u) / kernel.top_coefficient * w
        n = int(min(200000, 64 + 48 * np.ceil(Y / kernel.thickness[0])))
        y = np.linspace(0.0, Y, n)
        values = np.concatenate([np.cos(np.outer(y[i:i + 512], u)) @ kw for i in range(0, n, 512)])
        self.spline = CubicSpline(y, values)
        self.derivative = self.spline.derivative()

    def __call__(self, y):
        return self.spline(y)


class LayeredCircular(AsperityLaw):
    """Circular contacts on paraboloidal summits of radius ``R`` on a layered solid (§2.4.2).

    Built on the second-order chi(a), zeta(a) of ``LayeredAsperity`` (cubic splines over [0, a_max],
    held at their a_max values beyond — a_max must exceed every contact radius of the solve):
    force P = 4/3 E1* chi a³/R (Eq. 2.16), self approach a² zeta/R (Eq. 2.19), pressure Eq. 2.17,
    displacement Eq. 2.18 with g(a, r) tabulated up to ``r_max`` (give the patch diagonal; beyond
    it the point-force far field).
    ``far_field_coefficient`` is measured on the solid's point response G: the quadrupole term
    (a²/10) |lap G| <= c (a/r)² G_1 with G_1 = 1/(pi E1* r), so the bound is relative to the
    interaction on the top layer as a half-space.
    """

    def __init__(self, R, asperity: LayeredAsperity, r_max: float):
        self.R = np.asarray(R, dtype=float).ravel()
        if self.R.size == 0 or not np.all(np.isfinite(self.R)) or np.any(self.R <= 0):
            raise InputError("R", R, "finite positive radii")
        self.n = len(self.R)
        self.asperity = asperity
        self.E_star = asperity.E_star
        self.r_max = check_positive("r_max", r_max)
        a = asperity.a_max * np.linspace(0, 1, 65) ** 1.5
        chi, zeta = asperity.approximate(a)
        self._chi, self._zeta = CubicSpline(a, chi), CubicSpline(a, zeta)
        self._dchi, self._dzeta = self._chi.derivative(), self._zeta.derivative()
        self._g = asperity.interaction_table(self.r_max)
        self._r_min = asperity.a_max / 100
        kernel = asperity.kernel
        A = kernel.top_coefficient
        self._G = radial_table(kernel, kernel.cutoff(), self._r_min, self.r_max, moment=False)
        self._top = A / (2 * np.pi)
        E_s, nu_s = kernel.substrate_E, kernel.substrate_nu
        self._far = 0.0 if np.isinf(E_s) else (1 - nu_s**2) / (np.pi * E_s)
        self.far_field_coefficient = max(0.2, self._quadrupole_bound())

    def _quadrupole_bound(self) -> float:
        """max over r of (r²/10) |lap G(r)| / G_1(r) (G_1 = top layer as a half-space)."""
        kernel = self.asperity.kernel
        r = np.geomspace(self._r_min, self.r_max, 200)
        q, w = hankel_nodes(kernel.cutoff(), self.r_max, sum(kernel.thickness))
        lap = -(j0(np.outer(r, q)) @ (kernel.excess(q) * q * q * w)) / (2 * np.pi)
        lap += self._top / r**3                                      # lap (1/r) = 1/r³ on the surface
        return float(np.max(r**3 * np.abs(lap) / (10 * self._top)) * 2)

    def _cz(self, a):
        a_c = np.minimum(a, self.asperity.a_max)
        beyond = a > self.asperity.a_max
        chi, zeta = self._chi(a_c), self._zeta(a_c)
        dchi = np.where(beyond, 0.0, self._dchi(a_c))
        dzeta = np.where(beyond, 0.0, self._dzeta(a_c))
        return chi, dchi, zeta, dzeta

    def approach(self, a, idx):
        a = np.asarray(a, dtype=float)
        R = self.R[idx]
        _, _, z, dz = self._cz(a)
        return a * a * z / R, (2 * a * z + a * a * dz) / R

    def force(self, a, idx):
        a = np.asarray(a, dtype=float)
        k = 4 * self.E_star / (3 * self.R[idx])
        c, dc, _, _ = self._cz(a)
        return k * c * a**3, k * (3 * c * a * a + dc * a**3)

    def semi_axes(self, a, idx):
        return a, a

    def point_response(self, r):
        """G(r) [m/N]: A/(2 pi r) + the tabulated layered remainder up to r_max; beyond, the
        substrate's far field (2/E_s*)/(2 pi r), or 0 on a rigid base (exponential decay)."""
        r = np.asarray(r, dtype=float)
        near = r <= self.r_max
        out = np.where(near, 0.0, self._far / np.where(near, 1.0, r))
        rn = r[near]
        out[near] = self._top / rn + self._G(np.maximum(rn, self._r_min))
        return out

    def displacement(self, a, src, dx, dy, a_ref=None):
        """Eq. 2.18: (2a² zeta − r²)/2R inside; chi/(pi R) [(2a² − r²) asin(a/r) + a sqrt(r² − a²)
        + g(a, r)] outside; P G(r) beyond r_max."""
        a = np.asarray(a, dtype=float)
        R = self.R[src]
        r2 = dx * dx + dy * dy
        r = np.sqrt(r2)
        c, dc, z, dz = self._cz(a)
        inside = r2 <= a * a
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(inside, 1.0, a / np.where(r > 0, r, 1.0))
        asn = np.arcsin(np.minimum(s, 1.0))
        root = np.sqrt(np.maximum(r2 - a * a, 0.0))
        a_t = np.minimum(a, self.asperity.a_max)
        r_t = np.clip(r, self._r_min, self.r_max)
        g = self._g.ev(a_t, r_t)
        dg = np.where(a > self.asperity.a_max, 0.0, self._g.ev(a_t, r_t, dx=1))
        hertz = (2 * a * a - r2) * asn + a * root
        out = c / (np.pi * R) * (hertz + g)
        dout = (dc * (hertz + g) + c * (4 * a * asn + dg)) / (np.pi * R)
        u = np.where(inside, (2 * a * a * z - r2) / (2 * R), out)
        du = np.where(inside, (2 * a * z + a * a * dz) / R, dout)
        far = r > self.r_max
        if far.any():                                   # beyond the table: point force far field
            P, dP = self.force(a[far], src[far])
            G = self.point_response(r[far])
            u[far], du[far] = P * G, dP * G
        return u, du

    def pressure(self, a, src, dx, dy):
        c, _, _, _ = self._cz(np.asarray(a, dtype=float))
        return 2 * self.E_star * c / (np.pi * self.R[src]) * np.sqrt(np.maximum(a * a - dx * dx - dy * dy, 0.0))


def layered_law(table: AsperityTable, kernel: LayeredElastic, a_max: float, r_max: float) -> LayeredCircular:
    """``LayeredCircular`` law of the summits of ``table`` (radius sqrt(R1 R2)) on ``kernel``:
    contact radii up to ``a_max`` [m], interactions tabulated up to ``r_max`` [m] (the patch
    diagonal)."""
    check_table(table)
    return LayeredCircular(table.radius, LayeredAsperity(kernel, a_max), r_max)

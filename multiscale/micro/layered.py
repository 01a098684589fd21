"""Multi-layered and graded solids: stable layered surface kernels (thesis ch. 2 §2.2, §3.3.3, §5.3,
Appendices A and B).

A stack of N bonded homogeneous layers (top first) rests on a substrate: an elastic (or conducting)
half-space, or a rigid (isothermal) base, given as an infinite modulus (conductivity). The kernels
are ``multiscale.micro.kernels.Kernel`` objects, so the FFT-BEM contact solver, wear, conduction and
heating run unchanged on layered solids, periodic or not.

Stable formulation (recursive compliance / Riccati map, decaying exponentials only)
-----------------------------------------------------------------------------------
For a Fourier mode of wavenumber q the thesis' transfer matrices (Eq. 2.4, App. A) carry exp(+q h)
and lose the decaying solution once q h ~ 18 (overflow near 700). Here the 2 x 2 surface compliance
C (displacements per tractions, Eq. 2.5) is carried from the substrate up, layer by layer, through
the Möbius (Riccati) map of each layer. For q h >= 0.5 that map is written with two modes decaying
downwards from the layer's top face and two decaying upwards from its bottom face, so only
exp(-q h) and q h exp(-q h) ever appear (nothing grows); for q h < 0.5 it uses the Taylor series of
the layer propagator, so that a thin layer changes C by O(q h) without cancellation. The top layer
returns both q F and the *excess* q F - A over its own half-space value A, each free of cancellation
(q F on a thin layer over a rigid base is tiny; the excess at large q h is exponentially small).
Adjacent identical layers are merged, so a homogeneous solid gives exactly zero excess. Checked to
1e-12 against a 60-digit evaluation of the thesis' propagator. Cost: O(N) 2 x 2 operations per
wavenumber (duplicate |k| of a grid are evaluated once). The thermal kernel uses the same recursion
with scalars.

Sign conventions: displacement (temperature rise) positive into the solid, pressure (heat flux)
positive into the solid; ``compliance(q)`` is F(q) = w_z / p (thesis F11 = -q F, Eqs. 2.5, 3.8).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.special import j0, j1

from multiscale.errors import InputError, check_count, check_field, check_positive, check_real
from multiscale.micro.kernels import Kernel, poisson_ratio, wrap_offsets
from multiscale.micro.zones import THINNEST
from multiscale.references.love import love_rectangle

_NEAR = 4        # cells |i|, |j| <= _NEAR around the loaded cell use the exact corner formula
_GAUSS = 4       # Gauss points per direction on the other cells
_EXCESS_TOL = 1e-15


class LayeredKernel(Kernel):
    """Shared machinery of the layered kernels: q F(q) = A + excess(q), with A the top layer's
    half-space value (2/E1* elastic, 1/kappa1 thermal) and an excess that decays like exp(-2 q h1).

    Subclasses provide ``top_coefficient`` (A), ``static_compliance`` (F(0), inf on a half-space),
    ``thickness`` (m, top first) and ``_response(q)`` = (q F, q F - A) for q > 0, each computed
    without cancellation (q F is tiny for a thin layer on a rigid base, the excess at large q h).
    """

    thickness: tuple

    def compliance(self, q):
        """F(q) [m/Pa per unit area, or K m²/W]; at q = 0 the static value on a rigid (isothermal)
        base, 0 on a half-space (infinite, see ``Kernel.compliance``)."""
        q = np.asarray(q, dtype=float)
        if not np.all(np.isfinite(q)) or np.any(q < 0):
            raise InputError("q", "array", "wavenumbers must be finite and >= 0")
        out = np.zeros(q.shape)
        pos = q > 0
        if pos.any():
            qu, inverse = np.unique(q[pos], return_inverse=True)
            out[pos] = (self._chunked(qu)[0] / qu)[inverse]
        static = self.static_compliance
        out[~pos] = static if np.isfinite(static) else 0.0
        return out

    def excess(self, q):
        """q F(q) - A for wavenumbers q > 0 [rad/m] (dimension of A)."""
        q = np.asarray(q, dtype=float)
        if not np.all(np.isfinite(q)) or np.any(q <= 0):
            raise InputError("q", "array", "wavenumbers must be finite and > 0")
        qu, inverse = np.unique(q.ravel(), return_inverse=True)
        return self._chunked(qu)[1][inverse].reshape(q.shape)

    def _chunked(self, q, size: int = 16384):
        """``_response`` over a 1-D array (possibly empty) in cache-sized chunks: (q F, excess)."""
        parts = [self._response(q[i:i + size]) for i in range(0, max(q.size, 1), size)]
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])

    def _excess(self, q):
        return self._response(q)[1]

    def influence(self, ny, nx, dy, dx):
        """Influence coefficients of the (dx × dy) cell, (2 ny, 2 nx) wrap-around order.

        Split G = A/(2 pi r) + g(r): the first part is Love's rectangle (exact); g is the inverse
        Hankel transform of R(q) = excess(q)/q, bounded and exponentially decaying in q. Cells with
        |i|, |j| <= 4 use the exact corner function Phi(X, Y) = ∫∫_[0,X]x[0,Y] g, evaluated in
        polar form from the radial moment M(r) = (r / 2 pi) ∫ R(q) J1(q r) dq; the other cells use
        4 x 4 Gauss points on g(r) = (1 / 2 pi) ∫ R(q) J0(q r) q dq. Both Hankel transforms are
        composite Gauss-Legendre quadratures resolving the Bessel oscillations up to the largest
        radius and R down to exp(-2 q h1) < 1e-15, interpolated by cubic splines on geometric grids
        (ratio 1.02). Accuracy: about 1e-9 of the self-coefficient (checked in tests against a
        brute-force adaptive Hankel quadrature and cell integration); exact (R = 0) for identical
        layers on an identical half-space.
        """
        ny, nx = int(ny), int(nx)
        dx, dy = check_positive("dx", dx), check_positive("dy", dy)
        if self.thickness[0] < THINNEST * min(dx, dy):
            raise InputError("thickness", self.thickness[0], f"the top layer is thinner than {THINNEST:g} of a cell "
                             f"({min(dx, dy):.3g} m) of a non-periodic patch: its kernel would take hours and "
                             "gigabytes; drop the layer (its effect is below the grid's resolution) or refine the grid")
        ox = wrap_offsets(nx) * dx
        oy = wrap_offsets(ny) * dy
        coeffs = love_rectangle(ox[None, :], oy[:, None], dx / 2, dy / 2) * (self.top_coefficient / (2 * np.pi))
        q_cut = self.cutoff()
        if q_cut > 0:
            coeffs += _remainder_influence(self, q_cut, ny, nx, dy, dx)
        return coeffs

    def cutoff(self) -> float:
        """Wavenumber [rad/m] beyond which |excess| < 1e-15 A (0 if the excess vanishes everywhere)."""
        h1 = self.thickness[0]
        q = np.arange(1, 801) * (0.25 / h1)
        big = np.nonzero(np.abs(self._excess(q)) > _EXCESS_TOL * self.top_coefficient)[0]
        return 0.0 if big.size == 0 else float(q[min(big[-1] + 1, q.size - 1)])


def hankel_nodes(q_cut: float, r_max: float, depth: float, per_panel: int = 6):
    """Composite Gauss-Legendre nodes and weights on [0, q_cut]: panels no wider than pi/r_max
    (Bessel oscillations) and max(1/(20 depth), q/20) (variation of the layered transfer function)."""
    edges = [0.0]
    cap, floor = np.pi / r_max, 0.05 / depth
    while edges[-1] < q_cut:
        edges.append(edges[-1] + min(cap, max(floor, 0.05 * edges[-1])))
    edges = np.asarray(edges)
    x, w = np.polynomial.legendre.leggauss(per_panel)
    half = np.diff(edges) / 2
    mid = (edges[1:] + edges[:-1]) / 2
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def radial_table(kernel, q_cut, r_lo, r_hi, moment: bool):
    """Cubic spline of g(r) (moment=False) or M(r) = ∫_0^r g r' dr' (moment=True), r in [r_lo, r_hi]."""
    q, w = hankel_nodes(q_cut, r_hi, sum(kernel.thickness))
    R = kernel._excess(q) / q
    n = int(np.ceil(np.log(r_hi / r_lo) / np.log(1.02))) + 1
    r = r_lo * np.exp(np.linspace(0.0, np.log(r_hi / r_lo), n))
    if moment:
        r = np.concatenate([[0.0], r])
        values = np.array([(ri / (2 * np.pi)) * np.dot(R * w, j1(q * ri)) for ri in r])
    else:
        values = np.array([np.dot(R * q * w, j0(q * ri)) / (2 * np.pi) for ri in r])
    return CubicSpline(r, values)


def _corner(M, X, Y, nodes: int = 48):
    """Phi(X, Y) = ∫_0^X ∫_0^Y g(|x|) for X, Y >= 0, from the radial moment M (polar form)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    phi0 = np.arctan2(Y, X)[..., None]
    a = phi0 / 2 * (x + 1)                     # [0, phi0]: the ray leaves through x = X
    b = phi0 + (np.pi / 2 - phi0) / 2 * (x + 1)  # [phi0, pi/2]: through y = Y
    first = (phi0[..., 0] / 2) * np.sum(w * M(X[..., None] / np.cos(a)), axis=-1)
    second = ((np.pi / 2 - phi0[..., 0]) / 2) * np.sum(w * M(Y[..., None] / np.sin(b)), axis=-1)
    return first + second


def _remainder_influence(kernel, q_cut, ny, nx, dy, dx):
    """Cell integrals of g(r) (see ``LayeredKernel.influence``) in wrap-around order."""
    ix = wrap_offsets(nx)
    iy = wrap_offsets(ny)
    out = np.zeros((2 * ny, 2 * nx))
    h_min = min(kernel.thickness)
    # near zone: exact corner function
    K = _NEAR
    r_near = np.hypot((K + 1) * dx, (K + 1) * dy)
    M = radial_table(kernel, q_cut, min(h_min, dx, dy) / 100, r_near, moment=True)
    cx = (np.arange(K + 1) + 0.5) * dx
    cy = (np.arange(K + 1) + 0.5) * dy
    Phi = _corner(M, cx[None, :] + 0 * cy[:, None], cy[:, None] + 0 * cx[None, :])

    def corner(i, j):  # signed Phi at ((i + 1/2) dx, (j + 1/2) dy) for integer arrays i, j
        si, sj = np.where(i >= 0, 1.0, -1.0), np.where(j >= 0, 1.0, -1.0)
        return si * sj * Phi[np.where(j >= 0, j, -j - 1), np.where(i >= 0, i, -i - 1)]

    near_x = np.abs(ix) <= K
    near_y = np.abs(iy) <= K
    I, J = np.meshgrid(ix[near_x].astype(int), iy[near_y].astype(int))
    block = corner(I, J) - corner(I - 1, J) - corner(I, J - 1) + corner(I - 1, J - 1)
    out[np.ix_(near_y, near_x)] = block
    # far zone: Gauss points on the radial function
    far = ~(near_y[:, None] & near_x[None, :])
    if far.any():
        r_hi = np.hypot((nx + 0.5) * dx, (ny + 0.5) * dy) * 1.001
        g = radial_table(kernel, q_cut, (K + 0.5) * min(dx, dy) * 0.999, r_hi, moment=False)
        x, w = np.polynomial.legendre.leggauss(_GAUSS)
        X = ix[None, :] * dx
        Y = iy[:, None] * dy
        acc = np.zeros(far.shape)
        for xg, wx in zip(x, w):
            for yg, wy in zip(x, w):
                acc += wx * wy * g(np.hypot(X + xg * dx / 2, Y + yg * dy / 2))
        out[far] = (acc * (dx * dy / 4))[far]
    return out


def _mul(a, b):
    """Product of 2 x 2 matrices stored as (m00, m01, m10, m11) of scalars or arrays."""
    return (a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3],
            a[2] * b[0] + a[3] * b[2], a[2] * b[1] + a[3] * b[3])


def _inv(m):
    det = m[0] * m[3] - m[1] * m[2]
    return (m[3] / det, -m[1] / det, -m[2] / det, m[0] / det)


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3])


def _modes(nu: float, mu: float):
    """Displacement and traction rows (q u_z, q u_x | s_zz, s_xz) of the two downward-decaying
    plane-strain modes exp(-q z) b and exp(-q z)(a + q z b) at their origin, and of their mirror
    images z -> -z (upward-decaying modes); App. A system with the shear modulus ``mu``."""
    k = 3.0 - 4.0 * nu
    Bu = (-1.0, -k, 1.0, 0.0)
    BT = (2 * mu, 4 * mu * (1 - nu), -2 * mu, -2 * mu * (1 - 2 * nu))
    JBu = (Bu[0], Bu[1], -Bu[2], -Bu[3])      # mirror: u_x and s_zz change sign
    JBT = (-BT[0], -BT[1], BT[2], BT[3])
    return Bu, BT, JBu, JBT


_THIN = 0.5      # layers with q h below this use the Taylor propagator (no exp(-2 q h) cancellation)
_TAYLOR = 28


def _taylor_propagator(nu: float):
    """Coefficients of P'(t) = exp(-A' t) = sum_k c_k t^k, with A' the App. A system in variables
    (q u_z, q u_x, s_zz/mu, s_xz/mu), shape (_TAYLOR + 1, 4, 4); top state = P' bottom state."""
    A = np.array([[0, nu / (1 - nu), (1 - 2 * nu) / (2 * (1 - nu)), 0], [-1, 0, 0, 1], [0, 0, 0, 1],
                  [0, 2 / (1 - nu), -nu / (1 - nu), 0]])
    c = [np.eye(4)]
    for k in range(1, _TAYLOR + 1):
        c.append(c[-1] @ (-A) / k)
    return np.array(c)


def _thin_step(C, t, nu, mu):
    """Compliance on top of a thin layer (q h < _THIN): Möbius map of the propagator."""
    P = np.polynomial.polynomial.polyval(t, _taylor_propagator(nu))   # (4, 4, n)
    Cs = tuple(mu * c for c in C)                                    # in units of this layer's 1/mu
    num = _mul((P[0, 0], P[0, 1], P[1, 0], P[1, 1]), Cs)
    den = _mul((P[2, 0], P[2, 1], P[3, 0], P[3, 1]), Cs)
    num = (num[0] + P[0, 2], num[1] + P[0, 3], num[2] + P[1, 2], num[3] + P[1, 3])
    den = (den[0] + P[2, 2], den[1] + P[2, 3], den[2] + P[3, 2], den[3] + P[3, 3])
    return tuple(c / mu for c in _mul(num, _inv(den)))


def _thick_step(C, t, nu, mu, top: bool):
    """Compliance on top of a layer from decaying modes only (any q h); for the top layer, the
    excess C_top - C_half-space computed without cancellation."""
    Bu, BT, JBu, JBT = _modes(nu, mu)
    Z = _mul(_inv(_sub(JBu, _mul(C, JBT))), _sub(Bu, _mul(C, BT)))
    e2 = -np.exp(-2 * t)
    a00, a01 = Z[0] + t * Z[2], Z[1] + t * Z[3]          # W = -exp(-2t) T Z T, T = [[1, t], [0, 1]]
    W = (e2 * a00, e2 * (a00 * t + a01), e2 * Z[2], e2 * (Z[2] * t + Z[3]))
    BTW = _mul(JBT, W)
    D = _inv((BT[0] + BTW[0], BT[1] + BTW[1], BT[2] + BTW[2], BT[3] + BTW[3]))
    if top:
        return _mul(_mul(_sub(JBu, _mul(_mul(Bu, _inv(BT)), JBT)), W), D)
    BuW = _mul(JBu, W)
    return _mul((Bu[0] + BuW[0], Bu[1] + BuW[1], Bu[2] + BuW[2], Bu[3] + BuW[3]), D)


def _merge(h, props, substrate):
    """Merge adjacent layers of equal properties and the bottom layers equal to the substrate
    (exact), so that a homogeneous solid has an exactly zero excess."""
    h, props = list(h), list(props)
    i = len(h) - 1
    while i > 0:
        if props[i] == props[i - 1]:
            h[i - 1] += h.pop(i)
            props.pop(i)
        i -= 1
    while h and props[-1] == substrate:
        h.pop()
        props.pop()
    return h, props


def _elastic_response(q, h, mu, nu, sub_mu, sub_nu):
    """(q F(q), q F(q) - (1 - nu1)/mu1) for the elastic stack (Riccati recursion, see module docstring).

    State: the compliance C (2 x 2, displacements per tractions, in units of 1/mu1) on the lower
    face of each layer, carried upwards. Thick layers (q h >= 0.5): decaying modes, the upward
    ones with amplitudes W ~ exp(-2 q h) (q h)^2 times the downward ones, so nothing grows; thin
    layers: Taylor series of the propagator, so C changes by O(q h) without cancellation."""
    mu1 = mu[0]
    h, props = _merge(h, list(zip(np.asarray(mu) / mu1, nu)),
                      None if np.isinf(sub_mu) else (sub_mu / mu1, sub_nu))
    A = (1 - nu[0]) / mu1
    if not h:
        return np.full(q.shape, A), np.zeros(q.shape)
    if np.isinf(sub_mu):
        C = (0.0, 0.0, 0.0, 0.0)                 # rigid base: zero displacement
    else:
        Bu, BT, _, _ = _modes(sub_nu, sub_mu / mu1)
        C = _mul(Bu, _inv(BT))
    C = tuple(np.broadcast_to(np.asarray(c, float), q.shape) for c in C)
    for i in range(len(h) - 1, -1, -1):
        m, n = props[i]
        t = q * h[i]
        thin = t < _THIN
        new = [np.empty(q.shape) for _ in range(4)]
        if i == 0:                               # top layer: q F and excess, each without cancellation
            f, excess = np.empty(q.shape), np.empty(q.shape)
            Ct = _thin_step(tuple(c[thin] for c in C), t[thin], n, m)[0]
            f[thin], excess[thin] = -Ct / mu1, -Ct / mu1 - A
            Ct = _thick_step(tuple(c[~thin] for c in C), t[~thin], n, m, top=True)[0]
            f[~thin], excess[~thin] = A - Ct / mu1, -Ct / mu1
            return f, excess
        if thin.any():
            Ct = _thin_step(tuple(c[thin] for c in C), t[thin], n, m)
            for k in range(4):
                new[k][thin] = Ct[k]
        if not thin.all():
            Ct = _thick_step(tuple(c[~thin] for c in C), t[~thin], n, m, top=False)
            for k in range(4):
                new[k][~thin] = Ct[k]
        C = tuple(new)
    raise AssertionError("unreachable")


def _thermal_response(q, h, kappa, sub_kappa):
    """(q F(q), q F(q) - 1/kappa1) for steady conduction: the same recursion, scalar, with
    exp(-2 q h) and expm1 only (every term of each fraction has one sign: no cancellation)."""
    h, kappa = _merge(h, kappa, None if np.isinf(sub_kappa) else sub_kappa)
    if not h:
        return np.full(q.shape, 1.0 / sub_kappa), np.zeros(q.shape)
    f = np.zeros(q.shape) if np.isinf(sub_kappa) else np.full(q.shape, 1.0 / sub_kappa)
    for i in range(len(h) - 1, -1, -1):
        t = q * h[i]
        e, E = np.exp(-2 * t), -np.expm1(-2 * t)
        g = f * kappa[i]                         # lower compliance in units of this layer's 1/kappa
        den = E * (g + 1) + 2 * e
        f = (E * (g + 1) + 2 * g * e) / den / kappa[i]
        if i == 0:
            return f, 2 * e * (g - 1) / den / kappa[i]
    raise AssertionError("unreachable")


def _as_tuple(name, values, n=None):
    arr = np.atleast_1d(check_field(name, values))
    if arr.ndim != 1 or arr.size == 0 or (n is not None and arr.size != n):
        raise InputError(name, values, f"one value per layer ({n if n else '>= 1'} values)")
    return tuple(float(v) for v in arr)


@dataclass(frozen=True)
class LayeredElastic(LayeredKernel):
    """N bonded elastic layers (top first) on an elastic half-space or a rigid base (§2.2, App. A/B).

    ``thickness`` [m], ``E`` [Pa], ``nu`` per layer; ``substrate_E`` = inf (default) is a rigid
    base. Normal surface compliance w_z / p against a rigid flat, frictionless (F11 of Eq. 3.8 with
    the 1/rho of Eq. 3.7, which the printed Eq. 3.8 drops).
    """

    thickness: tuple
    E: tuple
    nu: tuple
    substrate_E: float = np.inf
    substrate_nu: float = 0.3

    def __post_init__(self):
        h = _as_tuple("thickness", self.thickness)
        set_ = object.__setattr__
        set_(self, "thickness", h)
        set_(self, "E", _as_tuple("E", self.E, len(h)))
        set_(self, "nu", _as_tuple("nu", self.nu, len(h)))
        for name, vals in (("thickness", h), ("E", self.E)):
            if min(vals) <= 0:
                raise InputError(name, vals, "must be > 0")
        for nu in self.nu:
            poisson_ratio("nu", nu)
        if not (check_real("substrate_E", self.substrate_E) > 0):
            raise InputError("substrate_E", self.substrate_E, "must be > 0 (inf for a rigid base)")
        set_(self, "substrate_E", float(self.substrate_E))
        set_(self, "substrate_nu", poisson_ratio("substrate_nu", self.substrate_nu))

    @property
    def mu(self) -> np.ndarray:
        """Shear moduli [Pa] of the layers."""
        return np.array(self.E) / (2 * (1 + np.array(self.nu)))

    @property
    def top_coefficient(self) -> float:
        """2 / E1* [1/Pa]: q F(q) at q -> inf (the top layer as a half-space, thesis alpha = -E1*/2)."""
        return 2 * (1 - self.nu[0] ** 2) / self.E[0]

    @property
    def static_compliance(self) -> float:
        """F(0) [m/Pa]: oedometric compliance sum h_i (1 - 2 nu_i)/(2 mu_i (1 - nu_i)) on a rigid
        base, inf on a half-space."""
        if np.isfinite(self.substrate_E):
            return np.inf
        nu = np.array(self.nu)
        return float(np.sum(np.array(self.thickness) * (1 - 2 * nu) / (2 * self.mu * (1 - nu))))

    def _response(self, q):
        sub_mu = self.substrate_E / (2 * (1 + self.substrate_nu))
        return _elastic_response(q, self.thickness, self.mu, self.nu, sub_mu, self.substrate_nu)

    @classmethod
    def graded(cls, E, nu, depth: float, n_layers: int, growth: float = 1.0,
               substrate_E: float = np.inf, substrate_nu: float = 0.3) -> "LayeredElastic":
        """Graded solid E(z), nu(z) (callables of depth z [m], or constants) over ``depth``,
        discretised into ``n_layers`` (``layer_boundaries``): E_i is the harmonic mean of E
        over the layer (exact static oedometric compliance when nu is constant), nu_i the mean."""
        h, z = layer_boundaries(depth, n_layers, growth)
        return cls(h, layer_means(E, z, harmonic=True, name="E"), layer_means(nu, z, name="nu"), substrate_E,
                   substrate_nu)


@dataclass(frozen=True)
class LayeredThermal(LayeredKernel):
    """Steady conduction in N layers (top first) of conductivity ``kappa`` [W/(m K)] on a
    half-space of ``substrate_kappa``, or on a base at fixed temperature (inf, default) (§5.3).

    Surface temperature rise per surface heat flux, like ``ThermalHalfSpace``.
    """

    thickness: tuple
    kappa: tuple
    substrate_kappa: float = np.inf
    thermal: ClassVar[bool] = True

    def __post_init__(self):
        h = _as_tuple("thickness", self.thickness)
        object.__setattr__(self, "thickness", h)
        object.__setattr__(self, "kappa", _as_tuple("kappa", self.kappa, len(h)))
        for name, vals in (("thickness", h), ("kappa", self.kappa)):
            if min(vals) <= 0:
                raise InputError(name, vals, "must be > 0")
        if not (check_real("substrate_kappa", self.substrate_kappa) > 0):
            raise InputError("substrate_kappa", self.substrate_kappa, "must be > 0 (inf: fixed temperature)")
        object.__setattr__(self, "substrate_kappa", float(self.substrate_kappa))

    @property
    def top_coefficient(self) -> float:
        """1 / kappa1 [m K/W]: q F(q) at q -> inf."""
        return 1.0 / self.kappa[0]

    @property
    def static_compliance(self) -> float:
        """F(0) = sum h_i / kappa_i [m² K/W] (1-D series resistance) on an isothermal base, inf on a
        half-space. Its inverse is the perfect-contact conductance K_p of one body (§5.4.2)."""
        if np.isfinite(self.substrate_kappa):
            return np.inf
        return float(np.sum(np.array(self.thickness) / np.array(self.kappa)))

    def _response(self, q):
        return _thermal_response(q, self.thickness, self.kappa, self.substrate_kappa)

    @classmethod
    def graded(cls, kappa, depth: float, n_layers: int, growth: float = 1.0,
               substrate_kappa: float = np.inf) -> "LayeredThermal":
        """Graded conductivity kappa(z) over ``depth`` in ``n_layers``: kappa_i is the harmonic
        mean over the layer, which keeps the 1-D through-thickness resistance exact."""
        h, z = layer_boundaries(depth, n_layers, growth)
        return cls(h, layer_means(kappa, z, harmonic=True, name="kappa"), substrate_kappa)


def layer_boundaries(depth: float, n_layers: int, growth: float = 1.0):
    """Thicknesses h_i = h_1 growth^(i-1) summing to ``depth`` (growth > 1 refines near the
    surface) and the n+1 interface depths z [m]."""
    depth = check_positive("depth", depth)
    n_layers = check_count("n_layers", n_layers)
    growth = check_positive("growth", growth)
    h = growth ** np.arange(n_layers, dtype=float)
    h *= depth / h.sum()
    return h, np.concatenate([[0.0], np.cumsum(h)])


def layer_means(profile, z, harmonic: bool = False, points: int = 5, name: str = "profile") -> np.ndarray:
    """Mean of ``profile(z)`` (callable, vectorised, or a real number) over each interval of ``z``
    (Gauss-Legendre, ``points`` per layer); harmonic=True gives 1 / mean(1/profile). Errors name
    the profile ``name``."""
    z = np.asarray(z, dtype=float)
    if not callable(profile):
        return np.full(z.size - 1, check_real(name, profile))
    x, w = np.polynomial.legendre.leggauss(points)
    zz = (z[:-1, None] + z[1:, None]) / 2 + (z[1:, None] - z[:-1, None]) / 2 * x
    values = np.asarray(profile(zz), dtype=float) * np.ones_like(zz)
    if not np.all(np.isfinite(values)) or (harmonic and np.any(values <= 0)):
        raise InputError(name, profile, "must give finite (and > 0 for moduli) values over the depth")
    return 1.0 / (np.dot(1.0 / values, w) / 2) if harmonic else np.dot(values, w) / 2

"""Asperity-based micro-contact models (thesis ch. 1 §1.2.2, §2.4.2, §4.2.2).

A rough surface is a set of paraboloidal summits (``AsperityTable`` from
``surface.find_asperities``) pressed by a rigid flat moved down by ``delta`` from the first touch of
the highest summit. Summit k (height z_k) is asked to move ``delta_k = delta − (z_M − z_k)``
(Eqs. 1.6, 2.20). The four models of the thesis are

1. circular, no interaction (Eqs. 1.6–1.9, F1 = A1 = 1, R = sqrt(R1 R2));
2. elliptic, no interaction (Eqs. 1.1–1.8, F1(e), A1(e));
3. circular with interaction (Eqs. 1.10–1.12; Ciavarella-type);
4. elliptic with interaction (Eqs. 1.16–1.23).

With interaction the summit's displacement is its own Hertz approach plus the surface
displacement caused at its centre by every other contact (Eqs. 1.10, 1.23, 2.19):
``w_k = w_self(a_k) + sum_l u_l(a_l; x_k − x_l)``; contact requires w_k >= delta_k, with equality
where a_k > 0 (Eq. 1.11). Two solution routes (unknown: contact size a >= 0 per asperity):

* ``route="kinematic"`` — the least-squares objective of Eq. 1.12, O = ½ sum_k (w_k − delta_k)²,
  minimised by scipy's trust-region Gauss–Newton (``least_squares`` "trf" with LSMR inner solves: a
  truncated Newton method whose Hessian-vector products J^T J v are analytic), or by ``tnc`` /
  ``l-bfgs-b`` on O with the analytic gradient J^T r. One signed variable per summit carries both
  a >= 0 (x > 0) and the gap of a summit out of contact (x < 0), so O vanishes exactly at the
  solution of Eq. 1.11 and no active-set loop is needed (the literal form, O summed over the
  summits "supposed in contact" with a >= 0 bounds, needs one and cycles on summits at the edge).
* ``route="energy"`` — the total complementary energy (§4.2.2, Eqs. 2.21–2.23, 4.1)
  U = sum_j [W_j(a_j) − P_j(a_j) delta_j + ½ P_j sum_{l≠j} u_l(a_l; x_j − x_l)], where
  W = ∫ P'(a) w_self(a) da is the self energy (Hertz: W = 3/5 P w_self, i.e. the 6/5 of §4.2.2;
  Eq. 2.23's 2/5 is a misprint, it does not reproduce Hertz), minimised over a >= 0 (bounds) by
  scipy's ``l-bfgs-b`` or the truncated Newton ``tnc`` (Nash, the thesis' algorithm; its
  Hessian-vector products are gradient differences), both with the analytic gradient. U is
  minimised in a force-like variable ∝ a³, in which it is convex (two contacts: spacing > 2a/π)
  and its gradient is the gap of each summit.

Both routes stop on the complementarity residual max_k |min(P_k/P̄, gap_k/delta)|. They evaluate
the interaction at the receiving summit's centre as the thesis does, so their solutions differ by
the non-reciprocity of that approximation, O((a/r)²) of the interaction (tests: < 0.5 % of force
and area on a fractal surface). A summit lying inside the (non-interacting) contact ellipse of a
higher summit — twin peaks, ~1 % of the summits of a fractal surface — would make both problems
ill-posed (two energy minima, a singular Jacobian); it is absorbed by the higher summit
(``AsperityResult.absorbed``).

Interaction sums (vectorised, no loop over pairs): every contact acts on every other through the
point-force response ``g(r)`` of the solid (``P_l g(r)``, a dense matrix–vector product over the
candidate summits, stored up to ~5600 candidates, rows recomputed beyond), and pairs closer than
``cutoff · a_ref,l`` (``scipy.spatial.cKDTree``) add the near-field correction ``u_l − P_l g``.
a_ref >= a bounds the final contact size: it comes from the warm start or from a screening pass
with point forces only, and is enlarged (and the solve repeated) if a contact outgrows it. For a
Hertz contact of semi-axes a >= b the correction is the quadrupole term,
|u − P g| <= (2a² − b²)/(10 r²) · P g (circular: (a/r)²/10), with the higher orders < 0.21 (a/r)²
P g for r >= 3a, so the neglected part of every interaction sum is at most
``far_field_coefficient / cutoff²`` of it: ``interaction_tol`` (default 1e-3) sets
cutoff = sqrt(0.21 / interaction_tol) ≈ 14.5, and results report the bound. With many candidates
the minimisation runs on the summits in contact after screening or within 5 % of delta of
touching; the final state is checked on every candidate (those that penetrate join, re-solve).

Per-asperity law API (``AsperityLaw``, for Hertz and for layered solids, §2.4.2)
------------------------------------------------------------------------------
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
  ``far_field_coefficient`` (bound c on |u − P g| <= c (a/r)² P g for r >= 3a; Hertz 0.21).

``AsperityModel(table, law, interaction=...)`` solves any such law; ``HertzCircular`` and
``HertzElliptic`` are the homogeneous half-space implementations (``hertz_law`` builds them from
an ``AsperityTable``).
"""
from __future__ import annotations

import inspect
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, sparse
from scipy.sparse.linalg import LinearOperator
from scipy.spatial import cKDTree
from tqdm import tqdm

from multiscale.errors import ConvergenceError, InputError, check_positive
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import AsperityTable, Surface, find_asperities, statistics
from multiscale.references.hertz import axis_ratio_squared, exterior_lambda, potential_integrals

_GL_X, _GL_V = np.polynomial.legendre.leggauss(16)
_GL_T, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_V          # Gauss–Legendre on (0, 1)
_FLOOR = 1e-10          # smallest relative size a/a_ref used where derivatives are divided by a
_DENSE_BYTES = 256e6    # far-field matrix kept in memory up to this size (~5600 candidates)
_LS_CALLBACK = "callback" in inspect.signature(optimize.least_squares).parameters   # scipy >= 1.16
_SCREEN = 400           # more active candidates than this: screening pass with point forces only


# ----------------------------------------------------------------------------- laws
class AsperityLaw(ABC):
    """Contact law of a set of asperities on one solid (see the module docstring for the API)."""

    n: int
    E_star: float
    far_field_coefficient: float = 0.21

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

    ``shape="circular"``: radius R = sqrt(R1 R2) (models 1 and 3); ``"elliptic"``: models 2 and 4.
    """
    _check_table(table)
    E_star = solid.E_star if isinstance(solid, HalfSpace) else solid
    if shape == "circular":
        return HertzCircular(table.radius, E_star)
    if shape == "elliptic":
        return HertzElliptic(table.R1, table.R2, table.angle, E_star, exact=exact)
    raise InputError("shape", shape, "'circular' or 'elliptic'")


# ----------------------------------------------------------------------------- results
@dataclass
class AsperityResult:
    """Contact state of an asperity model at one approach."""

    approach: float            # m, rigid approach delta from the first touch of the highest summit
    force: float               # N, total force F (Eq. 1.7)
    area: float                # m², real contact area A (Eq. 1.8)
    mean_pressure: float       # Pa, F / A0
    area_fraction: float       # -, A / A0
    mean_gap: float            # m, g_n = (z_M − z̄) − delta (Eq. 1.9)
    kappa: float | None        # -, (A/A0) E* sqrt(<|grad h|²>) / p_n (§1.3.2); None without contact/slope
    semi_axes: np.ndarray      # m, (N, 2): major a and minor b of each contact (0, 0 out of contact)
    forces: np.ndarray         # N, force of each asperity
    contact: np.ndarray        # bool, asperity in contact
    pressure: np.ndarray | None  # Pa, (ny, nx) map of Eq. 1.4 on the surface grid (None without grid)
    n_contacts: int
    absorbed: np.ndarray       # indices of summits absorbed by a higher one (interacting models only)
    interaction: bool
    route: str                 # "direct" (no interaction), "kinematic" or "energy"
    method: str                # scipy minimiser
    iterations: int            # minimiser iterations (all active-set passes)
    evaluations: int           # interaction-sum evaluations
    residual: float            # max |min(P_k/P̄, gap_k/delta)| over candidates (route's own gap; P̄ the
    #                            mean non-interacting force): the complementarity of Eq. 1.11
    converged: bool
    truncation: float          # relative bound on the neglected part of each interaction sum
    wall_time: float           # s


@dataclass
class AsperityCurve:
    """Results of one model along increasing approaches (arrays per load step)."""

    approach: np.ndarray       # m
    force: np.ndarray          # N
    area: np.ndarray           # m²
    mean_pressure: np.ndarray  # Pa
    area_fraction: np.ndarray  # -
    mean_gap: np.ndarray       # m
    kappa: np.ndarray          # -, NaN where undefined (no contact)
    n_contacts: np.ndarray
    wall_time: float           # s, whole curve
    results: list = field(default_factory=list, repr=False)


class AsperityConvergenceError(ConvergenceError):
    """The asperity-model minimiser stopped above its tolerance."""


# ----------------------------------------------------------------------------- model
class AsperityModel:
    """One of the four asperity models on a table of summits (thesis §1.2.2).

    ``table``: ``AsperityTable`` (positions, heights; radii are the law's business); ``law``: an
    ``AsperityLaw`` with one entry per asperity; ``interaction``: models 3–4 (True) or 1–2.
    ``surface`` (optional) gives the nominal area A0, the RMS slope for kappa, the mean plane z̄
    of Eq. 1.9 and the grid of the pressure map; without it give ``nominal_area`` (and
    ``rms_slope``); z̄ is then the mean summit height (Eq. 1.9 literally).
    ``interaction_tol``: bound on the relative truncation error of the interaction sums (the
    cut-off is never below 3 contact sizes; ``truncation`` reports the bound in force).
    """

    def __init__(self, table: AsperityTable, law: AsperityLaw, *, interaction: bool = True,
                 surface: Surface | None = None, nominal_area: float | None = None,
                 rms_slope: float | None = None, interaction_tol: float = 1e-3):
        _check_table(table)
        if not isinstance(law, AsperityLaw):
            raise InputError("law", law, "an AsperityLaw (e.g. hertz_law(table, solid))")
        if law.n != len(table):
            raise InputError("law", law.n, f"law has {law.n} asperities, the table {len(table)}")
        if surface is not None and not isinstance(surface, Surface):
            raise InputError("surface", surface, "a multiscale.micro.surface.Surface")
        self.table, self.law, self.interaction, self.surface = table, law, bool(interaction), surface
        if nominal_area is None:
            if surface is None:
                raise InputError("nominal_area", None, "give the nominal area A0 [m²] or the surface")
            Lx, Ly = surface.size
            nominal_area = Lx * Ly
        self.nominal_area = check_positive("nominal_area", nominal_area)
        if rms_slope is None and surface is not None:
            rms_slope = float(statistics(surface).rms_slope)
        self.rms_slope = None if rms_slope is None else check_positive("rms_slope", rms_slope)
        tol = check_positive("interaction_tol", interaction_tol)
        self.cutoff = max(np.sqrt(law.far_field_coefficient / tol), 3.0)
        self.truncation = law.far_field_coefficient / self.cutoff**2
        self.z_max = float(table.height.max())
        self.mean_height = float(surface.heights.mean() if surface is not None else table.height.mean())
        self._cache: _Interactions | None = None

    @classmethod
    def from_surface(cls, surface: Surface, solid, shape: str = "elliptic", *, interaction: bool = True,
                     exact: bool = True, **kwargs) -> "AsperityModel":
        """Detect the summits of ``surface`` and build the Hertz model ``shape`` on ``solid``."""
        table = find_asperities(surface)
        if len(table) == 0:
            raise InputError("surface", "no summits", "the surface has no asperity with finite radii")
        return cls(table, hertz_law(table, solid, shape, exact=exact), interaction=interaction,
                   surface=surface, **kwargs)

    # -- public ---------------------------------------------------------------------------
    def solve(self, delta: float, *, route: str = "energy", method: str | None = None, tol: float = 1e-6,
              max_iter: int = 2000, partial: bool = False, raster: bool = True,
              initial=None) -> AsperityResult:
        """Contact state at rigid approach ``delta`` [m] >= 0.

        ``route``: "energy" (methods "l-bfgs-b" default, "tnc") or "kinematic" ("trf" default,
        "tnc", "l-bfgs-b"); ignored without interaction. ``tol``: bound on the complementarity
        residual (relative to delta). ``initial``: sizes [m] per asperity to start from.
        Raises ``AsperityConvergenceError`` above ``tol`` unless ``partial``.
        """
        delta = _check_delta(delta)
        check_positive("tol", tol)
        route, method = _check_route(route, method)
        if initial is not None:
            initial = np.asarray(initial, dtype=float)
            if initial.shape != (len(self.table),) or not np.all(np.isfinite(initial)):
                raise InputError("initial", initial, f"{len(self.table)} finite contact sizes [m]")
        t0 = time.perf_counter()
        dk = delta - (self.z_max - self.table.height)
        a = np.zeros(len(self.table))
        stats = dict(route="direct", method="closed form", iterations=0, evaluations=0, residual=0.0,
                     converged=True)
        cand = np.nonzero(dk > 0)[0]
        a_free = np.zeros(len(self.table))
        a_free[cand] = self.law.size_at(dk[cand], cand)
        absorbed = np.zeros(0, dtype=int)
        if self.interaction and len(cand) > 1:
            absorbed = self._absorbed(cand, a_free)
            active = dk > 0
            active[absorbed] = False
            a, stats = self._interacting(dk, active, a_free, route, method, tol, max_iter, initial)
            if not stats["converged"] and not partial:
                res = self._result(delta, a, stats, t0, raster, absorbed)
                raise AsperityConvergenceError(
                    f"{route} route ({method}) stopped at residual {stats['residual']:.3g} > tol {tol:g}",
                    [stats["residual"]], res)
        else:
            a = a_free
        return self._result(delta, a, stats, t0, raster, absorbed)

    def _absorbed(self, cand, a_free) -> np.ndarray:
        """Summits lying inside the non-interacting contact of a higher summit (twin peaks).

        The interaction models assume separate contacts; a summit inside another one's contact
        makes them ill-posed (two local minima of the energy, a singular Jacobian of Eq. 1.12), so
        such a summit is absorbed by the higher one and carries no contact of its own."""
        t = self.table
        xy = np.column_stack([t.x[cand], t.y[cand]])
        pairs = cKDTree(xy).query_pairs(float(a_free[cand].max()), output_type="ndarray")
        if not len(pairs):
            return np.zeros(0, dtype=int)
        i, j = cand[pairs[:, 0]], cand[pairs[:, 1]]
        low, high = np.where(t.height[i] < t.height[j], i, j), np.where(t.height[i] < t.height[j], j, i)
        inside = self.law.pressure(a_free[high], high, t.x[low] - t.x[high], t.y[low] - t.y[high]) > 0
        return np.unique(low[inside])

    def curve(self, deltas, *, route: str = "energy", method: str | None = None, tol: float = 1e-6,
              raster: bool = False, progress: bool = False) -> AsperityCurve:
        """Solve at increasing approaches ``deltas`` [m], each step warm-started from the last."""
        d = np.asarray(deltas, dtype=float).ravel()
        if d.size == 0 or not np.all(np.isfinite(d)) or np.any(d < 0) or np.any(np.diff(d) < 0):
            raise InputError("deltas", deltas, "a non-empty increasing sequence of approaches >= 0")
        t0 = time.perf_counter()
        dk = d[-1] - (self.z_max - self.table.height)
        cand = np.nonzero(dk > 0)[0]
        if self.interaction and len(cand) > 1:
            self._interactions(cand)                 # one far-field matrix for the whole curve
        steps = d
        if progress:
            steps = tqdm(d, desc="asperity model", unit="step")
        results, prev = [], None
        for delta in steps:
            init = None
            if prev is not None and prev.approach > 0:
                init = prev.semi_axes[:, 0] * np.sqrt(delta / prev.approach)
            prev = self.solve(delta, route=route, method=method, tol=tol, raster=raster, initial=init)
            results.append(prev)
        kappa = np.array([np.nan if r.kappa is None else r.kappa for r in results])
        return AsperityCurve(
            approach=d, force=np.array([r.force for r in results]), area=np.array([r.area for r in results]),
            mean_pressure=np.array([r.mean_pressure for r in results]),
            area_fraction=np.array([r.area_fraction for r in results]),
            mean_gap=np.array([r.mean_gap for r in results]), kappa=kappa,
            n_contacts=np.array([r.n_contacts for r in results]), wall_time=time.perf_counter() - t0,
            results=results)

    # -- internals ------------------------------------------------------------------------
    def _interactions(self, cand) -> "_Interactions":
        c = self._cache
        if c is None or not np.all(np.isin(cand, c.idx)):
            t = self.table
            c = self._cache = _Interactions(self.law, t.x[cand], t.y[cand], cand)
        return c

    def _interacting(self, dk, active, a_free, route, method, tol, max_iter, initial):
        """Minimise with a near-field list sized by a_ref >= a (from the initial sizes or, for many
        candidates, from a screening pass with point-force interactions only), on the summits in
        contact at the start or within 5 % of delta of touching; a_ref grows, and excluded summits
        that penetrate join, until the solution is verified on every candidate."""
        full = self._interactions(np.nonzero(dk > 0)[0])
        totals = dict(iterations=0, evaluations=0)
        ref = float(dk.max())

        def run(inter, a_ref, start, tol_, route=route, method=method):
            inter.set_near(a_ref[inter.idx], self.cutoff)
            a, st = _minimise(inter, dk, active, a_free, route, method, tol_, max_iter, start)
            totals["iterations"] += st["iterations"]
            totals["evaluations"] += st["evaluations"]
            return a, st

        many = active.sum() > _SCREEN
        if initial is None and many:
            initial, _ = run(full, np.zeros_like(a_free), None, 1e-3, "energy", "l-bfgs-b")
        if initial is None:
            a_ref = a_free
        else:
            initial = np.minimum(np.maximum(np.asarray(initial, dtype=float), 0.0), a_free)
            a_ref = np.minimum(a_free, 1.3 * initial + 0.1 * a_free)
        keep = active.copy()
        if many:
            keep &= (initial > 0) | (self._gaps(full, initial, a_ref, dk) < 0.05 * ref)
        for _ in range(10):
            inter = full if keep.sum() == active.sum() else full.subset(keep[full.idx])
            a, st = run(inter, a_ref, initial, tol)
            over = a > a_ref
            bad = np.zeros_like(keep)
            if inter is not full:
                bad = ~keep & active & (self._gaps(full, a, a_ref, dk) < -tol * ref)
            if not over.any() and not bad.any():
                break
            a_ref = np.where(over, np.minimum(a_free, 1.5 * a), a_ref)
            keep |= bad
            initial = a
        st.update(totals)
        return a, st

    def _gaps(self, inter, a, a_ref, dk):
        """Gap of every summit of ``inter`` (a = 0 there) under the contacts ``a`` (full index)."""
        inter.set_near(a_ref[inter.idx], self.cutoff)
        st = inter.evaluate(a[inter.idx])
        gap = np.full(len(dk), np.inf)
        gap[inter.idx] = st.w + st.u - dk[inter.idx]
        return gap

    def _result(self, delta, a, stats, t0, raster, absorbed) -> AsperityResult:
        law, on = self.law, np.nonzero(a > 0)[0]
        P = np.zeros_like(a)
        axes = np.zeros((len(a), 2))
        F = A = 0.0
        if len(on):
            P[on] = law.force(a[on], on)[0]
            A_on, B_on = law.semi_axes(a[on], on)
            axes[on, 0], axes[on, 1] = A_on, B_on
            F, A = float(P.sum()), float(law.area(a[on], on).sum())
        p_n = F / self.nominal_area
        frac = A / self.nominal_area
        kappa = None
        if F > 0 and self.rms_slope is not None:
            kappa = frac * law.E_star * self.rms_slope / p_n
        pmap = None
        if raster and self.surface is not None:
            pmap = self._raster(a, P, on)
        return AsperityResult(
            approach=delta, force=F, area=A, mean_pressure=p_n, area_fraction=frac,
            mean_gap=(self.z_max - self.mean_height) - delta, kappa=kappa, semi_axes=axes, forces=P,
            contact=a > 0, pressure=pmap, n_contacts=len(on), absorbed=absorbed, interaction=self.interaction,
            truncation=self.truncation if (self.interaction and stats["route"] != "direct") else 0.0,
            wall_time=time.perf_counter() - t0, **stats)

    def _raster(self, a, P, on) -> np.ndarray:
        """Eq. 1.4 sampled at pixel centres, each contact scaled to carry exactly its force
        (a contact smaller than a pixel puts its force on the summit pixel)."""
        s, t, law = self.surface, self.table, self.law
        ny, nx = s.shape
        out = np.zeros((ny, nx))
        if not len(on):
            return out
        reach = np.ceil(law.semi_axes(a[on], on)[0] / min(s.dx, s.dy)).astype(int) + 1
        bucket = np.ceil(np.log2(reach)).astype(int)
        for b in np.unique(bucket):
            m = 2**b
            sel = on[bucket == b]
            o = np.arange(-m, m + 1)
            oy, ox = (v.ravel() for v in np.meshgrid(o, o, indexing="ij"))
            rows, cols = t.row[sel][:, None] + oy[None, :], t.col[sel][:, None] + ox[None, :]
            src = np.repeat(sel, len(o) ** 2)
            p = law.pressure(np.repeat(a[sel], len(o) ** 2), src, np.tile(ox * s.dx, len(sel)),
                             np.tile(oy * s.dy, len(sel))).reshape(len(sel), -1)
            if s.periodic:
                rows, cols = rows % ny, cols % nx
            else:
                p = np.where((rows >= 0) & (rows < ny) & (cols >= 0) & (cols < nx), p, 0.0)
                rows, cols = np.clip(rows, 0, ny - 1), np.clip(cols, 0, nx - 1)
            total = p.sum(axis=1) * s.dx * s.dy
            centre = len(o) ** 2 // 2
            p[total <= 0, centre] = 1.0 / (s.dx * s.dy)
            total = np.where(total > 0, total, 1.0)
            np.add.at(out, (rows, cols), p * (P[sel] / total)[:, None])
        return out


# ----------------------------------------------------------------------------- interaction sums
class _Interactions:
    """Interaction sums among candidate summits ``idx`` (positions x, y).

    u_int = G P + N(a): G the point-response matrix (zero diagonal), N the near-field correction
    u_l − P_l g over pairs with r < cutoff · a_ref[source] (``set_near``), a_ref >= a."""

    def __init__(self, law: AsperityLaw, x, y, idx):
        self.law, self.idx = law, np.asarray(idx)
        n = self.n = len(self.idx)
        self.xy = np.column_stack([x, y])
        self.tree = cKDTree(self.xy)
        self.G = None
        if n * n * 8 <= _DENSE_BYTES:
            self.G = self._rows(np.arange(n))
        self.evaluations = 0
        self.set_near(np.zeros(n), 1.0)

    def subset(self, sel) -> "_Interactions":
        """The same sums restricted to the summits ``sel`` (bool over ``idx``)."""
        sub = object.__new__(_Interactions)
        sub.law, sub.idx = self.law, self.idx[sel]
        sub.n, sub.xy = len(sub.idx), self.xy[sel]
        sub.tree = cKDTree(sub.xy)
        sub.G = None if self.G is None else self.G[np.ix_(sel, sel)]
        sub.evaluations = 0
        sub.set_near(np.zeros(sub.n), 1.0)
        return sub

    def set_near(self, a_ref, cutoff):
        """Near-field pairs (source, receiver) closer than cutoff · a_ref[source]."""
        self.a_ref = np.asarray(a_ref, dtype=float)
        reach = cutoff * self.a_ref
        src = np.nonzero(reach > 0)[0]
        lists = self.tree.query_ball_point(self.xy[src], reach[src], return_sorted=False)
        counts = np.fromiter((len(v) for v in lists), dtype=int, count=len(lists))
        dst = np.fromiter((j for v in lists for j in v), dtype=int, count=int(counts.sum()))
        src = np.repeat(src, counts)
        keep = dst != src
        src, dst = src[keep], dst[keep]
        d = self.xy[dst] - self.xy[src]
        self.src, self.dst, self.ddx, self.ddy = src, dst, d[:, 0], d[:, 1]
        self.g_near = self.law.point_response(np.hypot(d[:, 0], d[:, 1]))

    def _rows(self, rows):
        """Rows ``rows`` of G, computed."""
        x, y = self.xy[:, 0], self.xy[:, 1]
        r = np.subtract.outer(x[rows], x)
        r *= r
        t = np.subtract.outer(y[rows], y)
        t *= t
        r += t
        np.sqrt(r, out=r)
        i = np.arange(len(rows))
        r[i, rows] = 1.0
        g = self.law.point_response(r)
        g[i, rows] = 0.0
        return g

    def far(self, f):
        """G f over the non-zero sources only (G is symmetric); rows computed in blocks when G is
        not stored."""
        nz = np.nonzero(f)[0]
        if self.G is None:
            out = np.zeros(self.n)
            step = max(1, int(_DENSE_BYTES / (8 * self.n)))
            for i0 in range(0, len(nz), step):
                rows = nz[i0:i0 + step]
                out += f[rows] @ self._rows(rows)
            return out
        if len(nz) < 0.6 * self.n:
            return f[nz] @ self.G[nz]
        return self.G @ f

    def evaluate(self, a, a_low=None):
        """Interaction state at sizes ``a`` (>= 0, one per candidate); derivatives are taken at
        max(a, a_low) (their limits for contacts about to open)."""
        self.evaluations += 1
        law, idx = self.law, self.idx
        ad = a if a_low is None else np.maximum(a, a_low)
        P, dP = law.force(a, idx)
        w, dw = law.approach(a, idx)
        if a_low is not None:
            dP, dw = law.force(ad, idx)[1], law.approach(ad, idx)[1]
        live = a[self.src] > 0
        src, dst, g = self.src[live], self.dst[live], self.g_near[live]
        u, du = law.displacement(a[src], idx[src], self.ddx[live], self.ddy[live], self.a_ref[src])
        corr, dcorr = u - P[src] * g, du - dP[src] * g
        far = self.far(P)
        near = np.bincount(dst, corr, minlength=self.n)
        return _State(a, P, dP, w, dw, far, near, src, dst, corr, dcorr)


@dataclass
class _State:
    a: np.ndarray
    P: np.ndarray
    dP: np.ndarray
    w: np.ndarray
    dw: np.ndarray
    far: np.ndarray      # G P
    near: np.ndarray     # near-field corrections summed per receiver
    src: np.ndarray
    dst: np.ndarray
    corr: np.ndarray
    dcorr: np.ndarray    # d corr / d a[src]

    @property
    def u(self):
        return self.far + self.near


def _minimise(inter: _Interactions, dk_all, active_all, a_free, route, method, tol, max_iter, initial):
    """Run one route on the active summits of the structure; returns sizes for every asperity
    and statistics. ``a_free``: non-interacting sizes (start and upper bound)."""
    idx = inter.idx
    dk = dk_all[idx]
    cand = active_all[idx]                          # the structure may hold a superset of candidates
    a0 = a_free[idx] if initial is None else np.minimum(
        np.maximum(np.asarray(initial, dtype=float)[idx], 0.0), a_free[idx])
    a0 = np.where(cand, a0, 0.0)
    ev0 = inter.evaluations
    if route == "energy":
        a, its, res = _energy_route(inter, dk, cand, a_free[idx], a0, method, tol, max_iter)
    else:
        a, its, res = _kinematic_route(inter, dk, cand, a_free[idx], a0, method, tol, max_iter)
    out = np.zeros(len(dk_all))
    out[idx] = a
    return out, dict(route=route, method=method, iterations=its, evaluations=inter.evaluations - ev0,
                     residual=res, converged=bool(res <= tol))


def _complementarity(P, P_unit, gap, delta):
    """max_k |min(P_k / P_unit, gap_k / delta)| over candidate summits: zero iff every summit either
    carries no force or has no gap (Eq. 1.11); P_unit is the mean non-interacting force."""
    return float(np.max(np.abs(np.minimum(P / P_unit, gap / delta)), initial=0.0))


def _drop_negligible(a, P, P_unit, tol):
    """Contacts carrying less than tol · P_unit are zero within the solver tolerance."""
    return np.where(P > tol * P_unit, a, 0.0)


class _Stop:
    """Callback that ends a scipy minimiser once the complementarity residual is below ``tol``
    (TNC cannot be stopped from a callback; it runs to its own tolerances)."""

    def __init__(self, measure, tol):
        self.measure, self.tol = measure, tol

    def __call__(self, x, *args):
        if self.measure(np.asarray(x)) <= self.tol:
            raise StopIteration


def _energy_route(inter, dk, cand, a_top, a_init, method, tol, max_iter):
    """Minimise the complementary energy over z = c (P_top/P_u)(a/a_top)³ >= 0 (a_top, P_top the
    non-interacting size and force, P_u their mean: z ∝ force for Hertz), U in units P_u max(delta_k);
    c_k makes d²U/dz_k² = 1 at the non-interacting state. dU/dz_k is the gap of summit k (energy
    route) over delta, divided by c_k; the minimiser stops on the complementarity residual."""
    law, idx = inter.law, inter.idx
    am = np.where(cand, a_top, 1.0)
    Pm = law.force(am, idx)[0]
    ref = float(dk.max())
    Pu = float(np.mean(Pm[cand]))
    dPm, dwm = law.force(am, idx)[1], law.approach(am, idx)[1]
    s = Pm / Pu * np.sqrt(dwm / dPm * Pu / ref)        # unit curvature at the non-interacting state
    t_floor = _FLOOR**3
    last = {}

    def sizes(z):
        t = np.maximum(z / s, t_floor)
        a = am * np.cbrt(t)
        return np.where(cand & (z > 0), a, 0.0), a / (3 * t * s)

    def fun(z):
        a, dadz = sizes(z)
        st = inter.evaluate(a, np.where(cand, _FLOOR * am, 0.0))
        W, dW = law.energy(a, idx)
        U = np.sum(W - st.P * dk + 0.5 * st.P * st.u)
        grad = _energy_gradient(st, dW, dk, inter.n)
        gap = np.divide(grad, st.dP, out=np.zeros_like(grad), where=st.dP > 0)
        last.update(z=z.copy(), a=a, P=st.P, gap=gap)
        return U / (Pu * ref), np.where(cand, grad * dadz / (Pu * ref), 0.0)

    def measure(z):
        if "z" not in last or not np.array_equal(z, last["z"]):
            fun(z)
        return _complementarity(last["P"][cand], Pu, last["gap"][cand], ref)

    z0 = s * (np.where(cand, a_init, 0.0) / am) ** 3
    bounds = [(0.0, None) if c else (0.0, 0.0) for c in cand]
    opts = {"maxfun": max_iter * 10, "gtol": 1e-3 * tol}
    if method == "tnc":
        opts.update(xtol=-1, ftol=-1, maxCGit=-1, accuracy=1e-14)
    else:
        opts.update(ftol=0.0, maxcor=20, maxiter=max_iter, maxls=50)
    res = optimize.minimize(fun, z0, jac=True, method=method.upper(), bounds=bounds, options=opts,
                            callback=None if method == "tnc" else _Stop(measure, tol))
    resid = measure(res.x)
    return _drop_negligible(last["a"], last["P"], Pu, tol), int(getattr(res, "nit", 0)), resid


def _energy_gradient(st: _State, dW, dk, n):
    """dU/da: dW − P' delta_k + P' (G P) + ½ P' N + ½ sum_k P_k d corr_(m→k)/da_m."""
    back = np.bincount(st.src, st.P[st.dst] * st.dcorr, minlength=n)
    return dW - st.dP * dk + st.dP * st.far + 0.5 * st.dP * st.near + 0.5 * back


def _kinematic_route(inter, dk, cand, a_top, a_init, method, tol, max_iter):
    """Eq. 1.12 as a square least-squares problem in one signed variable per candidate summit.

    x >= 0: in contact, a = a_top sqrt(x/s) (a_top the non-interacting size, s = delta_k/max(delta_k);
    Hertz: x = self approach / max delta_k); x < 0: out of contact, a = 0 and x · max(delta_k) is
    minus its gap. The residual r_k = w_k − delta_k (w_k = self approach, or x · max(delta_k) out of
    contact, plus interactions) vanishes exactly at the solution of Eq. 1.11 with a >= 0, so no
    active-set loop is needed (the literal bound-constrained form needs one and cycles on summits
    at the edge of contact)."""
    law, idx, n = inter.law, inter.idx, inter.n
    C = np.nonzero(cand)[0]
    am = np.where(cand, a_top, 1.0)
    ref = float(dk.max())
    s = np.where(cand, np.maximum(dk, 0.0) / ref, 1.0)
    cache = {}

    def state(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            full = np.zeros(n)
            full[C] = x
            on = full > 0
            t = np.maximum(full / s, _FLOOR**2)
            a = np.where(on, am * np.sqrt(t), 0.0)
            dadx = np.where(on, am * np.sqrt(t) / (2 * t * s), 0.0)
            st = inter.evaluate(a)
            w = np.where(on, st.w, full * ref)
            cache[key] = (st, a, w, dadx, np.where(on, st.dw * dadx, ref))
        return cache[key]

    def resid(x):
        st, _, w, _, _ = state(x)
        return (w + st.u - dk)[C] / ref

    def jac(x):
        st, _, _, dadx, diag = state(x)
        near = sparse.csr_matrix((st.dcorr * dadx[st.src] / ref, (st.dst, st.src)), shape=(n, n))[C][:, C]
        d, c = diag[C] / ref, st.dP * dadx / ref

        def mv(v):
            f = np.zeros(n)
            f[C] = v
            return d * v + inter.far(c * f)[C] + near @ v

        def rmv(y):
            f = np.zeros(n)
            f[C] = y
            return d * y + (c * inter.far(f))[C] + near.T @ y

        return LinearOperator((len(C), len(C)), matvec=mv, rmatvec=rmv, dtype=float)

    Pu = float(np.mean(law.force(am[C], idx[C])[0]))

    def measure(x):
        st, a, w, _, _ = state(x)
        gap = np.where(a > 0, w + st.u - dk, st.u - dk)    # out of contact: the true gap
        return _complementarity(np.where(a > 0, st.P, 0.0)[C], Pu, gap[C], ref)

    stop = _Stop(measure, tol)
    x0 = s[C] * (a_init[C] / am[C]) ** 2
    if method == "trf":
        early = {"callback": lambda intermediate_result: stop(intermediate_result.x)} if _LS_CALLBACK else {}
        r = optimize.least_squares(resid, x0, jac=jac, method="trf", tr_solver="lsmr", x_scale=1.0,
                                   ftol=None, xtol=1e-3 * tol, gtol=None, max_nfev=max_iter, **early)
        x, its = r.x, r.nfev
    else:
        def obj(x):
            res = resid(x)
            return 0.5 * res @ res, jac(x).rmatvec(res)
        opts = {"maxfun": max_iter * 10, "gtol": 1e-3 * tol**2}
        if method == "tnc":
            opts.update(xtol=-1, ftol=-1, maxCGit=-1, accuracy=1e-14)
        else:
            opts.update(ftol=0.0, maxiter=max_iter, maxcor=20, maxls=50)
        r = optimize.minimize(obj, x0, jac=True, method=method.upper(), options=opts,
                              callback=None if method == "tnc" else stop)
        x, its = r.x, int(getattr(r, "nit", 0))
    resid = measure(x)
    st, a = state(x)[:2]
    return _drop_negligible(a, st.P, Pu, tol), its, resid


# ----------------------------------------------------------------------------- checks
def _positive_array(name, v):
    arr = np.asarray(v, dtype=float).ravel()
    if arr.size == 0:
        raise InputError(name, v, "needs at least one asperity")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(name, v, "radii must be finite and > 0")
    return arr


def _check_table(table):
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


def _check_delta(delta) -> float:
    try:
        d = float(delta)
    except (TypeError, ValueError):
        raise InputError("delta", delta, "approach must be a real number [m]") from None
    if not np.isfinite(d) or d < 0:
        raise InputError("delta", delta, "approach must be finite and >= 0")
    return d


_METHODS = {"energy": ("l-bfgs-b", "tnc"), "kinematic": ("trf", "tnc", "l-bfgs-b")}


def _check_route(route, method):
    if route not in _METHODS:
        raise InputError("route", route, "'energy' or 'kinematic'")
    method = _METHODS[route][0] if method is None else str(method).lower()
    if method not in _METHODS[route]:
        raise InputError("method", method, f"one of {_METHODS[route]} for the {route} route")
    return route, method

"""Tabulated per-facet pressure–gap laws inside the UFL contact form (thesis §1.4.2, §4.2.1, §7.2.1).

The micro zone laws (``multiscale.micro.laws.PressureGapLaw``: C¹ monotone p_n(g_n), PCHIP Hermite
cubics of ln p_n in ln d between the nodes, d = g_open − g_n the interpenetration; a power law or
a cubic with K = 0 at first touch below the first node; linear beyond the last) are embedded
exactly, pointwise, in the macro residual: ``FacetLaw(g)`` is a UFL expression of the gap and of
one vector-valued DG0 field on the interface that holds, per facet, the coefficients of its
zone's law. Newton's tangent is the exact UFL derivative of that expression (the consistent
tangent K_n = −dp_n/dg_n), so the nonlinear laws need no outer linearisation loop.

A C¹ piecewise cubic with knots x_0 < … < x_{n−1} is written in the truncated-power basis

    s(X) = c_0 + c_1 t + c_2 t² + c_3 t³ + Σ_{k=1}^{n−2} [α_k (X − x_k)_+² + β_k (X − x_k)_+³],
    t = X − x_0,

with (c_0…c_3) the first interval's cubic and α_k, β_k the jumps of its second and third
derivatives at the inner knots: a sum of n − 2 small terms instead of a chain of n − 1
conditionals (compact forms, fast compilation), equal to the Hermite table to ~1e-13 relative.
Updating laws (wear) only rewrites the field: the compiled forms are reused.

After new laws (wear) the facets can be shifted, L(g − s), by offsets s that let them carry the
pressures of the laws they replaced at the same gaps (``carried_offsets``, ``shift``): the start of
``macro.continuation``.

Sign conventions follow ``interface.py``: g_n > 0 open, p_n >= 0 in compression.
"""
from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem

from multiscale.errors import InputError
from multiscale.micro.law_tables import PressureGapLaw
from multiscale.micro.laws import ZoneLaws

# layout of a law's coefficient vector (n = nodes of the law): scalars, then 3 (n − 2) knot terms;
# _SCALE multiplies the pressure (set per facet by FacetLaw, 1 in law_coefficients)
_G_OPEN, _D1, _P1, _M, _POWER, _DN, _PN, _KN, _X0, _XN, _SCALE, _C = range(12)   # _C: 4 cubic terms
_KNOTS = _C + 4


def coefficient_size(n_points: int) -> int:
    """Length of one law's coefficient vector for laws of ``n_points`` nodes."""
    if int(n_points) != n_points or n_points < 3:
        raise InputError("n_points", n_points, "an integer >= 3")
    return _KNOTS + 3 * (int(n_points) - 2)


def law_coefficients(law: PressureGapLaw) -> np.ndarray:
    """(zones, coefficient_size(n)) vectors of the batch of laws ``law`` (module docstring)."""
    x, y, slope = law.hermite_nodes               # ln d, ln p and d ln p/d ln d at the nodes
    n = x.shape[1]
    h = np.diff(x, axis=1)
    secant = np.diff(y, axis=1) / h
    d0, d1 = slope[:, :-1], slope[:, 1:]
    c2 = (3 * secant - 2 * d0 - d1) / h               # Taylor coefficients of each interval's cubic
    c3 = (d0 + d1 - 2 * secant) / h**2                # about its left knot
    alpha = (2 * c2[:, 1:] - (2 * c2[:, :-1] + 6 * c3[:, :-1] * h[:, :-1])) / 2
    beta = c3[:, 1:] - c3[:, :-1]
    out = np.zeros((x.shape[0], coefficient_size(n)))
    out[:, _G_OPEN] = law.g_open
    out[:, _D1], out[:, _DN] = np.exp(x[:, 0]), np.exp(x[:, -1])
    out[:, _P1], out[:, _PN] = law.pressure[:, 0], law.pressure[:, -1]
    out[:, _M] = slope[:, 0]
    out[:, _POWER] = slope[:, 0] >= 1.5
    out[:, _KN] = law.pressure[:, -1] * slope[:, -1] / np.exp(x[:, -1])
    out[:, _X0], out[:, _XN] = x[:, 0], x[:, -1]
    out[:, _SCALE] = 1.0
    out[:, _C:_C + 4] = np.stack([y[:, 0], d0[:, 0], c2[:, 0], c3[:, 0]], axis=1)
    k = n - 2
    out[:, _KNOTS:_KNOTS + k] = x[:, 1:-1]
    out[:, _KNOTS + k:_KNOTS + 2 * k] = alpha
    out[:, _KNOTS + 2 * k:] = beta
    return out


def pressure_expression(c, g, n_points: int):
    """UFL p_n(g) [Pa] from a coefficient vector ``c`` (a restricted vector coefficient)."""
    k = int(n_points) - 2
    d = c[_G_OPEN] - g                                                 # interpenetration [m]
    d1, dn = c[_D1], c[_DN]
    X = ufl.ln(ufl.min_value(ufl.max_value(d, d1), dn))               # clamped: always finite
    t = X - c[_X0]
    s = c[_C] + t * (c[_C + 1] + t * (c[_C + 2] + t * c[_C + 3]))
    for j in range(k):
        r = ufl.max_value(X - c[_KNOTS + j], 0.0)
        s = s + r * r * (c[_KNOTS + k + j] + r * c[_KNOTS + 2 * k + j])
    inner = ufl.exp(s)
    u = ufl.min_value(ufl.max_value(d / d1, 1e-12), 1.0)             # onset variable in (0, 1]
    m, p1 = c[_M], c[_P1]
    onset = ufl.conditional(ufl.gt(c[_POWER], 0.5), p1 * u**m,
                            p1 * (3 * u**2 - 2 * u**3 + m * (u**3 - u**2)))
    beyond = c[_PN] + c[_KN] * (d - dn)
    return c[_SCALE] * ufl.conditional(ufl.le(d, 0), 0.0,
                                       ufl.conditional(ufl.lt(d, d1), onset,
                                                       ufl.conditional(ufl.le(d, dn), inner, beyond)))


def gap_at(pressure_of, target, top, span) -> np.ndarray:
    """Gaps g <= ``top`` [m] at which ``pressure_of(g)``, decreasing in g and 0 at ``top``, equals
    ``target`` (elementwise; arrays or scalars alike), by bisection to 1e-13 of the bracket: its low
    end is moved below top by span, 2 span, 4 span ... until it carries the target (``InputError``
    after 2^64 span: a pressure bounded below it; the zone laws grow linearly beyond their top)."""
    top, target = np.asarray(top, dtype=float), np.asarray(target, dtype=float)
    step = np.broadcast_to(np.maximum(span, 1e-12), top.shape).copy()
    for _ in range(65):
        if not np.any(short := pressure_of(top - step) < target):
            break
        step = np.where(short, 2 * step, step)
    else:
        raise InputError("target", float(np.max(target[short] if target.ndim else target)),
                         "a pressure these laws do not reach at any gap")
    lo, hi = top - step, top.copy()
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        above = pressure_of(mid) > target
        lo, hi = np.where(above, mid, lo), np.where(above, hi, mid)
        if np.all(hi - lo <= 1e-13 * step):
            break
    return 0.5 * (lo + hi)


class FacetLaw:
    """Per-facet nonlinear pressure–gap laws p_n(g_n) for ``ContactInterface(law=...)``.

    ``FacetLaw(tm, n_points)``; ``set_laws(laws, zone_of_facet, zone_area)`` gives facet i the
    law of zone ``zone_of_facet[i]`` (a ``ZoneLaws``, global facet order; -1: no law, p_n = 0 on
    that facet, e.g. an interface in perfect contact whose penalty law is added separately);
    calling the object with the UFL gap returns p_n. With ``zone_area`` (one per zone id) each
    facet's law is scaled by A_zone / (area of the facets assigned to the zone), so that a zone
    carries exactly its micro force at a uniform gap even when facets do not tile the zones
    exactly (scale 1 when they do). ``laws``, ``zone_of_facet`` and ``scale`` are kept for numpy
    evaluations (``evaluate``), ``previous`` the laws the last ``set_laws`` replaced.
    """

    def __init__(self, tm, n_points: int):
        self.tm, self.n_points = tm, int(n_points)
        self.size = coefficient_size(n_points)
        iface = tm.interface
        self.space = fem.functionspace(iface.mesh, ("DG", 0, (self.size,)))
        self.coefficients = fem.Function(self.space, name="law_coefficients")
        self.laws: ZoneLaws | None = None
        self.previous: ZoneLaws | None = None
        self.zone_of_facet: np.ndarray | None = None

    def __call__(self, g):
        return pressure_expression(self.coefficients("+"), g, self.n_points)

    def set_laws(self, laws: ZoneLaws, zone_of_facet, zone_area=None) -> None:
        """Load the laws of every facet's zone (collective; same arguments on every rank)."""
        zones = np.asarray(zone_of_facet, dtype=int)
        iface = self.tm.interface
        if zones.shape != (iface.n_facets,):
            raise InputError("zone_of_facet", zones.shape, f"one zone id per interface facet ({iface.n_facets})")
        if laws.mechanical is None or laws.mechanical.gap.shape[1] != self.n_points:
            raise InputError("laws", getattr(laws.mechanical, "gap", None), f"laws of {self.n_points} nodes")
        lawless = zones < 0
        self.scale = np.where(lawless, 0.0, 1.0)
        if zone_area is not None:
            covered = np.bincount(zones[~lawless], iface.areas[~lawless], minlength=len(zone_area))
            self.scale[~lawless] = np.asarray(zone_area, dtype=float)[zones[~lawless]] / covered[zones[~lawless]]
        owned = iface.owned_index
        values = law_coefficients(laws.mechanical)[laws.rows(self._lawful(laws, zones)[owned])]
        values[:, _SCALE] = self.scale[owned]
        self.coefficients.x.array.reshape(-1, self.size)[self._blocks()] = values
        self.coefficients.x.scatter_forward()
        self.previous, self.laws, self.zone_of_facet = self.laws, laws, zones

    @staticmethod
    def _lawful(laws: ZoneLaws, zones: np.ndarray) -> np.ndarray:
        """``zones`` with any law's id where a facet has none (-1; it is scaled by 0)."""
        return np.where(zones < 0, laws.ids[0] if len(laws.ids) else 0, zones)

    def _blocks(self) -> np.ndarray:
        """The owned facets' rows in the coefficient field's array."""
        return self.space.dofmap.list[:len(self.tm.interface.owned_index), 0]

    def shift(self, offset=None) -> None:
        """Every facet's law moved to L(g − s) by its offset s [m] (global facet order; None: the
        laws themselves): its first-touch gap raised by s (collective)."""
        owned = self.tm.interface.owned_index
        rows = self.laws.rows(self._lawful(self.laws, self.zone_of_facet)[owned])
        self.coefficients.x.array.reshape(-1, self.size)[self._blocks(), _G_OPEN] = (
            self.laws.mechanical.g_open[rows] + (0.0 if offset is None else offset[owned]))
        self.coefficients.x.scatter_forward()

    def carried_offsets(self, gap) -> np.ndarray:
        """Per-facet offsets s [m] with which the laws, L(g − s), carry at the facet gaps ``gap``
        [m] the pressures of the ``previous`` laws there (0 where those are 0)."""
        gap = np.asarray(gap, dtype=float)
        zones = self._lawful(self.laws, self.zone_of_facet)
        target = self.previous.pressure(gap, zones).pressure * (self.scale > 0)
        mechanical, rows = self.laws.mechanical, self.laws.rows(zones)
        top = mechanical.g_open[rows]
        carrying = gap_at(lambda g: self.laws.pressure(g, zones).pressure, target, top, top - mechanical.gap[rows, -1])
        return np.where(target > 0, gap - carrying, 0.0)

    def depths(self, gap, offset) -> np.ndarray:
        """Per-facet interpenetration [m] of the laws shifted by ``offset`` at the gaps ``gap``:
        g_open + s − g (> 0 in contact; global facet order)."""
        rows = self.laws.rows(self._lawful(self.laws, self.zone_of_facet))
        return self.laws.mechanical.g_open[rows] + np.asarray(offset, dtype=float) - np.asarray(gap, dtype=float)

    def evaluate(self, gap) -> tuple[np.ndarray, np.ndarray]:
        """Per-facet (p_n [Pa], K_n [Pa/m]) of the numpy laws (scaled) at per-facet gaps [m]
        (0 on facets without a law)."""
        v = self.laws.pressure(np.asarray(gap, dtype=float), self._lawful(self.laws, self.zone_of_facet))
        return self.scale * v.pressure, self.scale * v.stiffness

"""Velocity-dependent friction mu(v_slip) and the damping of its slope (issue 20); the per-facet
friction of a run (``FacetFriction``: fade tables and mu(v) laws as the run goes).

A friction law gives mu and dmu/dv at a slip speed v [m/s]: ``ConstantFriction``,
``TableFriction`` (rows (v, mu), linear in between, constant beyond the ends) or
``StribeckFriction`` mu(v) = mu_k + (mu_s - mu_k) exp(-(v / v_s)^delta) (delta = 1 is the
exponential decay law of commercial codes, static to kinetic). At the preload every interface
facet slides at its own steady slip speed V (the facet mean of |w_t|, ``facet_slip_speed``): its
friction coefficient is mu(V) and its slope mu'(V).

Linearised about steady sliding, the friction traction on body 0, mu(|v_rel|) p_n s with
v_rel = w_t + u_1' - u_0', changes along the sliding direction s by p_n mu'(V) s.(u_1' - u_0'):
a damping term (``friction_damping``)

    C_f(du', v) = int p_n mu'(V) [s.(du_1' - du_0')] [s.(v_1 - v_0)] dS,

negative (destabilising) where mu falls with speed. With mu constant it vanishes and nothing
changes. Not included: the change of the friction direction by the transverse slip velocity
(a positive damping mu p_n / V across the sliding direction) and the convective part
Omega d/dtheta u_1 of the disc surface velocity (smaller than u_1' by n Omega / omega).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import ufl
from petsc4py import PETSc

from multiscale.errors import InputError, check_positive
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.operators import assemble_block


@dataclass(frozen=True)
class ConstantFriction:
    mu: float

    def value(self, v) -> np.ndarray:
        return np.full(np.shape(v), float(self.mu))

    def slope(self, v) -> np.ndarray:
        return np.zeros(np.shape(v))

    @property
    def constant(self) -> bool:
        return True


@dataclass(frozen=True)
class TableFriction:
    """mu against slip speed: rows ((v [m/s], mu), ...), v increasing, linear in between and
    constant beyond the ends (slope 0 there; at a breakpoint the slope of the segment above)."""

    rows: tuple

    def __post_init__(self):
        v = [r[0] for r in self.rows]
        if len(v) < 2 or any(b <= a for a, b in zip(v, v[1:])):
            raise InputError("friction_curve", self.rows, "at least 2 rows with increasing slip speed")

    def value(self, v) -> np.ndarray:
        x, y = np.array(self.rows, float).T
        return np.interp(np.asarray(v, float), x, y)

    def slope(self, v) -> np.ndarray:
        x, y = np.array(self.rows, float).T
        v = np.asarray(v, float)
        k = np.clip(np.searchsorted(x, v, side="right") - 1, 0, len(x) - 2)
        s = np.diff(y)[k] / np.diff(x)[k]
        return np.where((v < x[0]) | (v >= x[-1]), 0.0, s)

    @property
    def constant(self) -> bool:
        return len({r[1] for r in self.rows}) == 1


@dataclass(frozen=True)
class StribeckFriction:
    """mu(v) = kinetic + (static - kinetic) exp(-(v / speed)^exponent)."""

    static: float
    kinetic: float
    speed: float            # m/s, Stribeck speed v_s
    exponent: float = 1.0

    def __post_init__(self):
        check_positive("stribeck.speed", self.speed)
        check_positive("stribeck.exponent", self.exponent)

    def value(self, v) -> np.ndarray:
        x = np.asarray(v, float) / self.speed
        return self.kinetic + (self.static - self.kinetic) * np.exp(-x ** self.exponent)

    def slope(self, v) -> np.ndarray:
        x = np.maximum(np.asarray(v, float) / self.speed, 0.0)
        d = self.exponent
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.where(x > 0, d * x ** (d - 1), 1.0 if d == 1 else (0.0 if d > 1 else -math.inf))
        return -(self.static - self.kinetic) / self.speed * g * np.exp(-x ** d)

    @property
    def constant(self) -> bool:
        return self.static == self.kinetic


@dataclass(frozen=True)
class FacetFriction:
    """mu of every interface facet as a run goes (``MacroModel.friction_law``): ``constant`` (n_facets,)
    where an interface has a constant; on the facets of each ``fades`` entry (mask, temperatures [K],
    mu) mu of the mean of its two faces' temperatures (a fade table, linear in between, held beyond its
    ends); on those of each ``speeds`` entry (mask, law) the law's mu at the facet's slip speed [m/s]."""

    constant: np.ndarray
    fades: tuple = ()
    speeds: tuple = ()

    @property
    def reads_speed(self) -> bool:
        return bool(self.speeds)

    def __call__(self, T: np.ndarray | None, V: np.ndarray | None) -> np.ndarray:
        """mu [-] per facet at facet temperatures T [K] (None: no fade table) and slip speeds V
        [m/s] (None: no speed law)."""
        mu = self.constant.copy()
        for on, temperatures, values in self.fades:
            mu[on] = np.interp(T[on], temperatures, values)
        for on, law in self.speeds:
            mu[on] = law.value(V[on])
        return mu


def facet_slip_speed(mech: Mechanics) -> np.ndarray:
    """Mean steady slip speed |w_t| [m/s] of every interface facet (global order)."""
    return mech.contact.facet_means("slip")


def set_friction(mech: Mechanics, laws: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Set the per-facet friction coefficient mu(V) of every interface from ``laws`` {interface
    name: law} at the facets' slip speeds V; returns the per-facet (mu, mu', V) [-, s/m, m/s]."""
    iface = mech.tm.interface
    V = facet_slip_speed(mech)
    mu, slope = np.zeros(iface.n_facets), np.zeros(iface.n_facets)
    for name, mask in iface.masks().items():
        law = laws[name]
        mu[mask], slope[mask] = law.value(V[mask]), law.slope(V[mask])
    iface.set_field(mech.contact.friction, mu)
    return mu, slope, V


def friction_damping(mech: Mechanics, slope: np.ndarray) -> PETSc.Mat:
    """C_f of the per-facet friction slope mu'(V) [s/m] (module docstring)."""
    c, iface = mech.contact, mech.tm.interface
    k = iface.field("friction_slope", slope)("+")
    s, p, dS = c.slip_direction, c.pressure, iface.dS
    du = [ufl.TrialFunction(V) for V in mech.spaces]
    v = [ufl.TestFunction(V) for V in mech.spaces]
    sd = [ufl.dot(s, du[0]("+")), ufl.dot(s, du[1]("-"))]
    sv = [ufl.dot(s, v[0]("+")), ufl.dot(s, v[1]("-"))]
    sign = ((1.0, -1.0), (-1.0, 1.0))
    blocks = [[sign[i][j] * p * k * sd[j] * sv[i] * dS for j in range(2)] for i in range(2)]
    return assemble_block(mech, blocks)

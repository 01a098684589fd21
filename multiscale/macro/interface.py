"""Contact, friction and heat on the flat macro interface (thesis §1.4, §7.2.1, Fig. 7.4).

Sign conventions. Body 0 is the "+" side, body 1 the "−" side; n = n("−") points from body 1
into body 0. The normal gap is g_n = g_0 + (u_0 − u_1)·n [m] (> 0 open); the contact pressure
p_n = law(g_n) [Pa] is >= 0 in compression. The traction on body 0 is t = p_n n + mu p_n s, on
body 1 it is −t, where s is the unit tangential velocity of body 1 relative to body 0 (steady
Coulomb sliding: friction drags body 0 along with body 1). The frictional heat flux is
q = mu p_n |w_t| [W/m^2]; body 0 receives p_1 q and body 1 (1 − p_1) q; with a conductance
h_c [W/(m^2 K)] a flux h_c (T_0 − T_1) flows from body 0 to body 1.

The pressure law is the seam of the multiscale coupling: any callable ``law(g_n) -> p_n`` built
from UFL operations and per-facet DG0 fields (restricted with ("+")). Newton's tangent is the
exact UFL derivative of the law. ``PenaltyLaw`` is the perfect-contact law p_n = K_n <−g_n>_+.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import ufl
from dolfinx import fem

from multiscale.geometry import Rotation, Translation
from multiscale.macro.mesh import FormCache, TwoBodyMesh

PressureLaw = Callable[[ufl.core.expr.Expr], ufl.core.expr.Expr]
VELOCITY_FLOOR = 1e-9    # m/s, regularises the sliding direction at zero speed (s -> 0, no friction)
# the columns of ``ContactInterface.facet_integrals``: the pressure p_n, the gap g_n, the heat flux
# q, the slip speed |w_t|, the traction t (3) and the friction traction mu p_n s (3) on body 0
COLUMNS = {"p": 0, "g": 1, "q": 2, "slip": 3, "t": slice(4, 7), "f": slice(7, 10)}


def penetration(g):
    """<−g>_+ with derivative −1 at g = 0, so a touching start already carries contact stiffness."""
    return ufl.conditional(ufl.le(g, 0), -g, 0)


class PenaltyLaw:
    """Perfect-contact penalty p_n = K_n <−g_n>_+ (thesis Eq. 1.28, §1.4.1; the perfect-contact model of
    §7.3.1) with K_n a per-facet field [Pa/m]."""

    def __init__(self, stiffness: fem.Function):
        self.stiffness = stiffness

    def __call__(self, g):
        return self.stiffness("+") * penetration(g)


class SumLaw:
    """The sum of pressure laws (e.g. zone laws on the rough interfaces, each zero elsewhere, plus
    a penalty law whose stiffness is zero on them)."""

    def __init__(self, *laws):
        self.laws = laws

    def __call__(self, g):
        return sum((law(g) for law in self.laws[1:]), self.laws[0](g))


def rigid_velocity(motion: Rotation | Translation, x, speed: fem.Constant):
    """Velocity of body 1 [m/s]: omega e x (x − c) for a rotation (speed in rad/s), v e for a translation."""
    if isinstance(motion, Rotation):
        axis = ufl.as_vector(np.asarray(motion.axis, float) / np.linalg.norm(motion.axis))
        return speed * ufl.cross(axis, x - ufl.as_vector(motion.centre))
    e = np.asarray(motion.direction, float)
    return speed * ufl.as_vector(e / np.linalg.norm(e))


class ContactInterface:
    """Interface forms between the displacement fields ``u0`` (body 0) and ``u1`` (body 1).

    Per-facet fields (DG0 on the interface, set with ``tm.interface.set_field`` from a scalar or
    global per-facet arrays): ``stiffness`` K_n [Pa/m], ``initial_gap`` g_0 [m], ``friction`` mu
    (one value per interface, or per facet), ``partition`` p_1 (share of the frictional heat into
    body 0) and ``conductance`` h_c [W/(m^2 K)]. ``speed`` (rad/s or m/s, see ``rigid_velocity``)
    ``engaged`` (1: in contact; 0: released, no conductance) and ``heating`` (the factor of the
    frictional heat: 1 in contact, 0 released; over a step, the mean of load factor x speed over
    the mean speed) are Constants. ``law`` defaults to ``PenaltyLaw(stiffness)``; pass ``law=`` a callable to use another
    pressure–gap law.
    """

    def __init__(self, tm: TwoBodyMesh, u0: fem.Function, u1: fem.Function, *, stiffness=1e13,
                 friction: float = 0.0, speed: float = 0.0, law: PressureLaw | None = None,
                 velocity=None):
        iface = tm.interface
        self.tm = tm
        self.u = (u0, u1)
        self.stiffness = iface.field("contact_stiffness", stiffness)
        self.initial_gap = iface.field("initial_gap", 0.0)
        self.partition = iface.field("heat_partition", 0.5)
        self.conductance = iface.field("conductance", 0.0)
        self.law = law if law is not None else PenaltyLaw(self.stiffness)
        self.friction = iface.field("friction", friction)
        self.speed = fem.Constant(tm.parent, float(speed))
        self.engaged = fem.Constant(tm.parent, 1.0)
        self.heating = fem.Constant(tm.parent, 1.0)
        self.normal = ufl.FacetNormal(tm.parent)("-")
        x = ufl.SpatialCoordinate(tm.parent)
        w = velocity if velocity is not None else rigid_velocity(tm.spec.motion, x, self.speed)
        w = w("-") if _needs_restriction(w) else w
        self.slip_velocity = w - ufl.dot(w, self.normal) * self.normal          # tangential part
        self.slip_speed = ufl.sqrt(ufl.dot(self.slip_velocity, self.slip_velocity))
        self.slip_direction = self.slip_velocity / ufl.sqrt(self.slip_speed**2 + VELOCITY_FLOOR**2)
        self.gap = self.initial_gap("+") + ufl.dot(u0("+") - u1("-"), self.normal)
        self.pressure = self.law(self.gap)
        mu = self.friction("+")
        self.traction = self.pressure * self.normal + mu * self.pressure * self.slip_direction
        self.friction_traction = mu * self.pressure * self.slip_direction
        self.heat_flux = self.heating * mu * self.pressure * self.slip_speed
        self.cache = FormCache(tm)

    # ---- mechanics -------------------------------------------------------------------------
    def residuals(self, v0, v1):
        """Interface terms of the residuals of body 0 and body 1 (virtual work of −t resp. +t)."""
        dS = self.tm.interface.dS
        return -ufl.dot(self.traction, v0("+")) * dS, ufl.dot(self.traction, v1("-")) * dS

    def facet_integrals(self, name: str) -> np.ndarray:
        """Integral over each interface facet (global order, every rank) of the quantity ``name``
        (a key of ``COLUMNS``: p [N], g [m^3], q [W], slip [m^3/s], t and f [N], (n_facets, 3)),
        with the residual's quadrature. All are assembled from one compiled form: a form each cost
        ~0.6 s of compilation on a cold cache, for every new scene."""
        def integrands():
            vectors = (self.traction, self.friction_traction)
            return ufl.as_vector([self.pressure, self.gap, self.heat_flux, self.slip_speed,
                                  *(v[k] for v in vectors for k in range(3))])
        return self.cache.facet_integrals("per facet", integrands, components=10)[:, COLUMNS[name]]

    def facet_means(self, name: str) -> np.ndarray:
        """Mean of the quantity ``name`` over each interface facet (``facet_integrals`` / area)."""
        values, areas = self.facet_integrals(name), self.tm.interface.areas
        return values / (areas if values.ndim == 1 else areas[:, None])

    def normal_force(self) -> float:
        """Total normal contact force [N] (integral of p_n, same quadrature as the residual)."""
        return float(self.facet_normal_force().sum())

    def facet_normal_force(self) -> np.ndarray:
        """Normal contact force per interface facet [N] (integral of p_n; global order, every rank)."""
        return self.facet_integrals("p")

    def force(self) -> np.ndarray:
        """Resultant interface force on body 0 [N] (3-vector: normal pressure plus friction)."""
        return self.facet_integrals("t").sum(axis=0)

    def friction_force(self) -> np.ndarray:
        """Resultant friction force on body 0 [N] (3-vector, mu p_n s integrated)."""
        return self.facet_friction().sum(axis=0)

    def friction_moment(self) -> float:
        """Moment [N m] about the rotation axis of the friction on body 0 (the same integrand and
        quadrature as the frictional heat: heat power = moment x angular speed)."""
        motion = self.tm.spec.motion
        axis = ufl.as_vector(np.asarray(motion.axis, float) / np.linalg.norm(motion.axis))
        arm = ufl.SpatialCoordinate(self.tm.parent) - ufl.as_vector(motion.centre)
        return float(self.cache.facet_integrals(
            "m", lambda: ufl.dot(ufl.cross(arm, self.friction_traction), axis)).sum())

    def facet_friction(self) -> np.ndarray:
        """Friction force on body 0 per interface facet [N] (n_facets, 3), global order."""
        return self.facet_integrals("f")

    def facet_pressure(self) -> np.ndarray:
        """Mean contact pressure per interface facet [Pa] (global order, every rank)."""
        return self.facet_means("p")

    def facet_gap(self) -> np.ndarray:
        """Mean normal gap per interface facet [m] (negative: interpenetration of the penalty)."""
        return self.facet_means("g")

    # ---- heat ------------------------------------------------------------------------------
    def heat_residuals(self, T0, T1, r0, r1, *, frictional_heat: bool = True, conductance: bool = False):
        """Interface terms of the heat residuals of both bodies (thesis Fig. 7.4); None if empty.

        Frictional heat q split by p_1; with ``conductance`` the flux h_c (T_0 − T_1) couples the
        two temperature fields (otherwise they are disconnected, as in the thesis' perfect model).
        """
        dS = self.tm.interface.dS
        F0 = F1 = None
        if frictional_heat:
            p1 = self.partition("+")
            F0 = -p1 * self.heat_flux * r0("+") * dS
            F1 = -(1 - p1) * self.heat_flux * r1("-") * dS
        if conductance:
            exchange = self.engaged * self.conductance("+") * (T0("+") - T1("-"))
            G0, G1 = exchange * r0("+") * dS, -exchange * r1("-") * dS
            F0, F1 = (G0, G1) if F0 is None else (F0 + G0, F1 + G1)
        return F0, F1

    def facet_heat_power(self) -> np.ndarray:
        """Frictional heat power [W] per interface facet (global order, every rank) into body 0 and
        into body 1 at the current state, (n_facets, 2)."""
        Q = self.facet_integrals("q")                                    # W per facet
        p1 = self.tm.interface.values(self.partition)                    # constant per facet
        return np.column_stack((p1 * Q, (1 - p1) * Q))

    def facet_heat_flux(self) -> np.ndarray:
        """Mean frictional heat flux per interface facet [W/m^2] (global order)."""
        return self.facet_means("q")


def _needs_restriction(expr) -> bool:
    """True if ``expr`` contains coefficients that must be restricted on an interior facet."""
    return any(not isinstance(c, fem.Constant) for c in ufl.algorithms.extract_coefficients(expr))

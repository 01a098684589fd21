"""Steady conduction: constriction through circular spots and the surface response of layered and
graded conductors (thesis ch. 5).

Conductivities κ [W/(m K)]; F(q) [m² K/W] is the Fourier transfer function from surface heat flux
to surface temperature rise (thesis §5.3), the thermal counterpart of an elastic compliance.
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import check_positive


def holm_conductance(radius: float, kappa_1: float, kappa_2: float) -> float:
    """Conductance [W/K] of an isothermal circular spot of radius a [m] between two half-spaces:
    4 a κ1 κ2 / (κ1 + κ2), each body's constriction resistance being 1/(4 κ a) (Holm 1967,
    Electric Contacts)."""
    a = check_positive("radius", radius)
    k1, k2 = check_positive("kappa_1", kappa_1), check_positive("kappa_2", kappa_2)
    return 4 * a * k1 * k2 / (k1 + k2)


def flux_tube_factor(ratio):
    """ψ(ε) = 1 − 1.40925 ε + 0.29591 ε³ + 0.05254 ε⁵ + 0.02105 ε⁷: constriction resistance of an
    isothermal spot of radius a centred on a circular flux tube of radius b (ε = a/b < 1), relative
    to the isolated spot's 1/(4 κ a) (Roess 1950; Cooper, Mikic, Yovanovich 1969, Int. J. Heat Mass
    Transfer 12, 279–300)."""
    e = np.asarray(ratio, dtype=float)
    return 1 - 1.40925 * e + 0.29591 * e**3 + 0.05254 * e**5 + 0.02105 * e**7


def thermal_layer_compliance(q, thickness: float, kappa: float, substrate_kappa: float = np.inf):
    """F(q) [m² K/W] at q > 0 [rad/m] of a layer (h [m], κ1) on a half-space of κ2, or on a base
    at fixed temperature (κ2 = inf): (1/κ1 q)(1 + c e^(−2qh))/(1 − c e^(−2qh)), c = (κ1 − κ2)/(κ1 + κ2);
    tanh(q h)/(κ1 q) on the isothermal base (steady heat equation in one Fourier mode)."""
    q = np.asarray(q, dtype=float)
    if np.isinf(substrate_kappa):
        return np.tanh(q * thickness) / (kappa * q)
    c = (kappa - substrate_kappa) / (kappa + substrate_kappa)
    e = np.exp(-2 * q * thickness)
    return (1 / (kappa * q)) * (1 + c * e) / (1 - c * e)


def exponential_graded_compliance(q, kappa_0: float, rate: float, depth: float):
    """F(q) [m² K/W] at q >= 0 of a conductor κ(z) = κ0 e^(β z) (β = ``rate`` [1/m]) over a depth H
    [m] on a base at fixed temperature. With m± = (−β ± sqrt(β² + 4q²))/2 the mode is
    T ∝ e^(m+ (z−H)) − e^(m− (z−H)) (T(H) = 0), F = T(0) / (−κ0 T'(0)); at q = 0,
    (1 − e^(−βH))/(κ0 β), the 1-D series resistance ∫ dz/κ."""
    q = np.asarray(q, dtype=float)
    mp, mm = (-rate + np.sqrt(rate**2 + 4 * q**2)) / 2, (-rate - np.sqrt(rate**2 + 4 * q**2)) / 2
    T0 = np.exp(-mp * depth) - np.exp(-mm * depth)
    return T0 / (-kappa_0 * (mp * np.exp(-mp * depth) - mm * np.exp(-mm * depth)))

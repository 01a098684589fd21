"""One elastic layer bonded to a rigid base: surface compliance, oedometric limit and the thin-layer
(Winkler) contact of a sphere.

Layer of thickness h [m], Young's modulus E [Pa] and Poisson ratio ν; frictionless normal load,
displacement positive into the solid. F(q) = w_z/p [m/Pa per unit area] is the Fourier transfer
function of the surface (thesis Eqs. 2.5 and 3.7: F11 = −q F; the printed Eq. 3.8 drops the 1/rho).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.errors import check_positive


def layer_on_rigid_base_compliance(q, thickness: float, E: float, nu: float):
    """F(q) [m/Pa] of a layer bonded to a rigid base at wavenumbers q > 0 [rad/m].

    Carbone, G., Mangialardi, L. (2008), J. Mech. Phys. Solids 56, 684–706, Eq. A.30:
    1/F = (E q / 2(1 − ν²)) [k cosh 2t + 2t² + 8ν² − 12ν + 5] / [k sinh 2t − 2t], k = 3 − 4ν, t = q h.
    """
    k, t = 3 - 4 * nu, np.asarray(q, dtype=float) * thickness
    stiffness = (E / (1 - nu**2) * np.asarray(q, dtype=float) / 2) \
        * (k * np.cosh(2 * t) + 2 * t * t + 8 * nu**2 - 12 * nu + 5) / (k * np.sinh(2 * t) - 2 * t)
    return 1 / stiffness


def oedometric_modulus(E: float, nu: float) -> float:
    """M = E (1 − ν) / ((1 + ν)(1 − 2ν)) [Pa]: uniaxial-strain modulus."""
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def oedometric_compliance(thickness: float, E: float, nu: float) -> float:
    """h / M [m/Pa]: F(0) of a layer on a rigid base (uniform pressure, no lateral strain)."""
    return thickness / oedometric_modulus(E, nu)


@dataclass(frozen=True)
class ThinLayerContact:
    """Sphere on a thin layer (contact radius >> thickness)."""

    load: float            # N, P = π M R δ² / h
    contact_radius: float  # m, a = sqrt(2 R δ)


def thin_layer_sphere(approach: float, radius: float, thickness: float, E: float, nu: float) -> ThinLayerContact:
    """Winkler limit of a sphere (radius R [m]) pressed by δ [m] into a thin layer on a rigid base:
    p = (M/h)(δ − r²/2R), a² = 2Rδ, P = π M R δ²/h (elastic foundation model; Johnson 1985,
    Contact Mechanics, ch. 5)."""
    d, R = check_positive("approach", approach), check_positive("radius", radius)
    h = check_positive("thickness", thickness)
    return ThinLayerContact(np.pi * oedometric_modulus(E, nu) * R * d * d / h, np.sqrt(2 * R * d))

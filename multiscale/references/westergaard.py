"""Contact of a rigid flat and an elastic half-space with a one-dimensional sinusoidal surface
h(x) = Δ cos(2π x/λ) (Westergaard 1939; Johnson 1985, §13.2).

Heights point towards the flat, pressure is positive in compression; E* [Pa] is the composite
modulus. Full contact needs a mean pressure p̄ >= p* = π E* Δ/λ; below it the contact is a
strip of width 2a per period about each crest, with p̄ = p* sin²(π a/λ).

Westergaard, H. M. (1939), J. Appl. Mech. 6, A49–A53.
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, check_positive


def complete_contact_pressure(amplitude: float, wavelength: float, E_star: float) -> float:
    """p* = π E* Δ/λ [Pa]: the mean pressure that just flattens the sinusoid (Δ, λ [m])."""
    return np.pi * check_positive("E_star", E_star) * check_positive("amplitude", amplitude) \
        / check_positive("wavelength", wavelength)


def full_contact_pressure(x, mean_pressure: float, amplitude: float, wavelength: float, E_star: float):
    """p(x) = p̄ + p* cos(2π x/λ) [Pa] in full contact (p̄ >= p*), x [m] from a crest."""
    p_star = complete_contact_pressure(amplitude, wavelength, E_star)
    if not mean_pressure >= p_star:
        raise InputError("mean_pressure", mean_pressure, f"full contact needs >= p* = {p_star:.6g} Pa")
    return mean_pressure + p_star * np.cos(2 * np.pi * np.asarray(x, dtype=float) / wavelength)


def partial_contact_mean_pressure(contact_fraction, amplitude: float, wavelength: float, E_star: float):
    """p̄ = p* sin²(π a/λ) [Pa] that makes the contact cover ``contact_fraction`` = 2a/λ in [0, 1]."""
    f = np.asarray(contact_fraction, dtype=float)
    if np.any(f < 0) or np.any(f > 1):
        raise InputError("contact_fraction", contact_fraction, "must lie in [0, 1]")
    return complete_contact_pressure(amplitude, wavelength, E_star) * np.sin(np.pi * f / 2) ** 2

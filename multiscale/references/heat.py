"""Surface temperature rise of heat sources on a half-space (Carslaw & Jaeger 1959; thesis ch. 6).

Conductivity κ [W/(m K)], diffusivity χ [m²/s], flux q [W/m²] into the body, power Q [W];
temperatures are rises [K] above the initial one. Sliding speed V [m/s] enters through the Péclet
number Pe = V l / (2χ) of a source of half-width l [m] (Jaeger's; thesis §6.2.3 writes Pe = R ω a / χ
for the same half-width a, twice this).

The fixed and moving rectangular sources of thesis Eqs. 6.1–6.8 are evaluated by quadrature in
``multiscale.micro.heat_kernels`` (they share its tables' quadrature); these are the closed forms
that check them.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.errors import check_positive


def uniform_flux_temperature(time, kappa: float, diffusivity: float, flux: float = 1.0):
    """T = 2 q sqrt(χ t/π) / κ [K]: surface rise of a half-space under a uniform flux switched on at
    t = 0 (1-D heating; Carslaw & Jaeger 1959, ch. 2). ``time`` [s] >= 0."""
    t = np.asarray(time, dtype=float)
    return 2 * flux * np.sqrt(diffusivity * t / np.pi) / kappa


def point_source_deficit(time, power: float, kappa: float, diffusivity: float):
    """T_steady − T(t) [K] at a continuous surface point source Q switched on at t = 0:
    Q / (2 π^(3/2) κ sqrt(χ t)), the limit r → 0 of Q/(2π κ r) erf(r/sqrt(4 χ t)) (Carslaw & Jaeger
    1959, ch. 10; thesis Eq. 6.1 with its area shrunk to a point). Also the far-field (t → ∞) deficit of any
    compact source of total power Q."""
    t = np.asarray(time, dtype=float)
    return power / (2 * np.pi**1.5 * kappa * np.sqrt(diffusivity * t))


@dataclass(frozen=True)
class SourceTemperatures:
    """Surface temperature rises of a square source (flux q, half-width l)."""

    centre: float   # K, at the centre of the square (the maximum for a fixed source)
    mean: float     # K, average over the square
    maximum: float  # K


def fixed_square_source(half_width: float, kappa: float, flux: float = 1.0) -> SourceTemperatures:
    """Steady square source on a fixed half-space: centre 4 ln(1 + √2)/π · q l/κ (1.1222), mean
    2/π [2 ln(1 + √2) − (2/3)(√2 − 1)] · q l/κ (0.9464) (Love's integral / 2π κ; thesis Eq. 6.3
    with τ → ∞)."""
    scale = flux * check_positive("half_width", half_width) / check_positive("kappa", kappa)
    centre = 4 * np.log(1 + np.sqrt(2)) / np.pi * scale
    mean = 2 / np.pi * (2 * np.log(1 + np.sqrt(2)) - 2 / 3 * (np.sqrt(2) - 1)) * scale
    return SourceTemperatures(float(centre), float(mean), float(centre))


def fast_square_source(half_width: float, peclet: float, kappa: float, flux: float = 1.0) -> SourceTemperatures:
    """Square source sliding at high Péclet number (Pe >> 1): every point heats as a 1-D body for
    the time x/V it has spent under the source, T(x) = 2 q sqrt(χ x/(π V))/κ, so the maximum (trailing
    edge) is 2/√π · q l/(κ √Pe) and the mean (2/3 of it) 4/(3√π) · q l/(κ √Pe) = 0.752 q l/(κ √Pe)
    (Jaeger 1942, J. Proc. R. Soc. N.S.W. 76, 203–224). ``centre``: the rise at x = l."""
    scale = flux * check_positive("half_width", half_width) / (check_positive("kappa", kappa)
                                                               * np.sqrt(check_positive("peclet", peclet)))
    maximum = float(2 / np.sqrt(np.pi) * scale)
    return SourceTemperatures(maximum / np.sqrt(2), 2 / 3 * maximum, maximum)

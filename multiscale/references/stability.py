"""Hoffmann's 2-DOF minimal model of mode-coupling (flutter) instability in friction.

A mass on a moving belt held by springs k11, k22 and the coupling k12, k21; the normal contact
spring k3 and Coulomb friction mu k3 x2 add a circulatory (non-symmetric) stiffness term:

    K = [[k11, k12 − mu k3], [k21, k22]],   M = mass I.

The squared angular frequencies θ = ω² are the eigenvalues of K/mass,
θ± = (k11 + k22)/2 ± sqrt(((k11 − k22)/2)² + k21 (k12 − mu k3)) (per unit mass); the two modes
coalesce (lock-in) where the root vanishes, at mu_c = [(k11 − k22)² + 4 k12 k21] / (4 k21 k3),
and one of them grows beyond.

Hoffmann, N., Fischer, M., Allgaier, R., Gaul, L. (2002), Mech. Res. Commun. 29, 197–205
(not in the thesis: the closed-form check of the package's ch. 4 complex eigenvalue analysis).
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, check_positive


def hoffmann_matrices(mu: float, k11: float = 1.0, k22: float = 1.5, k12: float = 0.3, k21: float = 0.3,
                      k3: float = 1.0, mass: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(K [N/m], M [kg]) as dense 2 x 2 arrays at friction coefficient ``mu`` >= 0."""
    mu = check_positive("mu", mu, allow_zero=True)
    for name, v in (("k11", k11), ("k22", k22), ("k3", k3), ("mass", mass)):
        check_positive(name, v)
    K = np.array([[k11, k12 - mu * k3], [k21, k22]], dtype=float)
    return K, mass * np.eye(2)


def hoffmann_onset(k11: float, k22: float, k12: float, k21: float, k3: float) -> float:
    """Friction coefficient mu_c = [(k11 − k22)² + 4 k12 k21] / (4 k21 k3) at which the modes
    coalesce (stable below, one growing mode above). Needs k21 > 0: otherwise friction never
    couples the modes."""
    for name, v in (("k11", k11), ("k22", k22), ("k3", k3)):
        check_positive(name, v)
    if not (np.isfinite(k12) and np.isfinite(k21)):
        raise InputError("k12/k21", (k12, k21), "must be finite")
    if k21 <= 0:
        raise InputError("k21", k21, "must be > 0 for a mode-coupling onset")
    return ((k11 - k22) ** 2 + 4 * k12 * k21) / (4 * k21 * k3)


def hoffmann_eigenvalues(mu: float, k11: float = 1.0, k22: float = 1.5, k12: float = 0.3, k21: float = 0.3,
                         k3: float = 1.0, mass: float = 1.0) -> np.ndarray:
    """θ = ω² [rad²/s²] of (K, M) at ``mu`` (complex, the '−' root first): real below mu_c, a
    complex-conjugate pair above."""
    K, M = hoffmann_matrices(mu, k11, k22, k12, k21, k3, mass)
    d = complex(((K[0, 0] - K[1, 1]) / 2) ** 2 + K[1, 0] * K[0, 1])
    mean = (K[0, 0] + K[1, 1]) / 2
    return np.array([mean - np.sqrt(d), mean + np.sqrt(d)]) / M[0, 0]

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


# ---------------------------------------------------------------- damping of the 2-DOF model
def damped_hoffmann_onset(c1: float, c2: float, k11: float = 1.0, k22: float = 1.5, k12: float = 0.3,
                          k21: float = 0.3, k3: float = 1.0) -> float:
    """Onset friction of the Hoffmann model with unit mass and the damping C = diag(c1, c2)
    (Hoffmann & Gaul 2003, ZAMM 83, 524–534) by the Routh–Hurwitz criterion.

    det(lambda^2 I + lambda C + K(mu)) = lambda^4 + a1 lambda^3 + a2 lambda^2 + a3 lambda + a4 with
    a1 = c1 + c2, a2 = k11 + k22 + c1 c2, a3 = c1 k22 + c2 k11, a4 = k11 k22 − k21 (k12 − mu k3);
    stable while a1 a2 a3 − a3² − a1² a4 > 0, which is linear in mu:

        mu_c = [a1 a2 a3 − a3² − a1² (k11 k22 − k12 k21)] / (a1² k21 k3).

    Equal damping c raises the undamped mu_c by (k11 + k22) c² / (2 k21 k3); unequal damping
    lowers it in the limit of vanishing damping (``vanishing_damping_onset``)."""
    for name, v in (("c1", c1), ("c2", c2)):
        check_positive(name, v, allow_zero=True)
    if c1 + c2 <= 0:
        return hoffmann_onset(k11, k22, k12, k21, k3)
    if k21 <= 0:
        raise InputError("k21", k21, "must be > 0 for a mode-coupling onset")
    a1, a2, a3 = c1 + c2, k11 + k22 + c1 * c2, c1 * k22 + c2 * k11
    return (a1 * a2 * a3 - a3**2 - a1**2 * (k11 * k22 - k12 * k21)) / (a1**2 * k21 * k3)


def vanishing_damping_onset(ratio: float, k11: float = 1.0, k22: float = 1.5, k12: float = 0.3, k21: float = 0.3,
                            k3: float = 1.0) -> float:
    """Limit of ``damped_hoffmann_onset`` for c1, c2 -> 0 with c1 / (c1 + c2) = ``ratio``:
    mu = [w (1 − w) (k11 − k22)² + k12 k21] / (k21 k3), w = ratio. Equal to the undamped onset for
    w = 1/2 only: any unequal damping, however small, destabilises (the destabilisation paradox)."""
    if not 0 <= ratio <= 1:
        raise InputError("ratio", ratio, "must lie in [0, 1]")
    return (ratio * (1 - ratio) * (k11 - k22) ** 2 + k12 * k21) / (k21 * k3)


def rayleigh_damping_ratio(omega, alpha: float, beta: float):
    """Damping ratio of a mode at omega [rad/s] under C = alpha M + beta K: alpha/(2 omega) + beta omega/2."""
    omega = np.asarray(omega, float)
    return alpha / (2 * omega) + beta * omega / 2


# ---------------------------------------------------------------- prestress, rotation, mu(v)
def tensioned_beam_frequency(n: int, length: float, E: float, I: float, rho: float, area: float,
                             tension: float = 0.0) -> float:
    """omega_n [rad/s] of a pinned–pinned Euler–Bernoulli beam under the axial force T [N]:
    omega² = (EI k⁴ + T k²) / (rho A), k = n pi / L. The prestress shifts omega² by T k² / (rho A)
    whatever the bending stiffness."""
    k = n * np.pi / length
    w2 = (E * I * k**4 + tension * k**2) / (rho * area)
    if w2 <= 0:
        raise InputError("tension", tension, "at or beyond the buckling load (omega² <= 0)")
    return float(np.sqrt(w2))


def spinning_disc_split(frequency: float, n: int, omega: float) -> tuple[float, float]:
    """Backward and forward travelling-wave frequencies [Hz] seen from the fixed frame of an
    n-nodal-diameter mode of a thin disc spinning at omega [rad/s], frequency f_r [Hz] in the
    rotating frame: f_r − n Omega / 2 pi and f_r + n Omega / 2 pi (splitting n Omega / pi,
    proportional to the speed; e.g. Mote 1970, Iwan & Moeller 1976)."""
    d = n * omega / (2 * np.pi)
    return frequency - d, frequency + d


def stribeck(v, static: float, kinetic: float, speed: float, exponent: float = 1.0):
    """mu(v) = kinetic + (static − kinetic) exp(−(v / speed)^exponent) and its slope dmu/dv [s/m]."""
    x = np.asarray(v, float) / speed
    e = np.exp(-x**exponent)
    mu = kinetic + (static - kinetic) * e
    slope = -(static - kinetic) / speed * exponent * x ** (exponent - 1) * e
    return mu, slope


def belt_onset_speed(damping: float, normal_force: float, static: float, kinetic: float, speed: float) -> float:
    """Belt speed [m/s] below which a mass–spring–damper (damping c [N s/m]) pressed with N on a
    belt with the exponential Stribeck law (exponent 1) has negative net damping
    c + N mu'(v) < 0 and oscillates with a growing amplitude:
    v* = v_s ln(N (mu_s − mu_k) / (c v_s)) (no onset, 0, if the steepest slope cannot beat c)."""
    check_positive("damping", damping)
    drop = normal_force * (static - kinetic) / (damping * speed)
    return float(speed * np.log(drop)) if drop > 1 else 0.0


def spring_chain(n: int = 200, k: float = 4e6, m: float = 0.01, drift: float = 0.0) -> tuple:
    """Dense (K, M) of a fixed-fixed chain of n masses m [kg] joined by springs k [N/m], with both
    end dofs as Dirichlet rows (size n + 2: rows 0 and n + 1 identity in K, zero in M: constrained
    modes at infinity). ``drift`` adds a circulatory (follower-like) coupling: K non-symmetric."""
    N = n + 2
    K, M = np.zeros((N, N)), np.zeros((N, N))
    i = np.arange(1, n + 1)
    K[i, i], M[i, i] = 2 * k, m
    K[i[1:], i[1:] - 1] = -k + drift * k
    K[i[:-1], i[:-1] + 1] = -k - drift * k
    K[0, 0] = K[-1, -1] = 1.0
    return K, M


def spring_chain_frequencies(n: int = 200, k: float = 4e6, m: float = 0.01) -> np.ndarray:
    """Natural frequencies [Hz] of ``spring_chain`` without drift, ascending:
    f_j = sqrt(k/m) sin(j pi / (2 (n + 1))) / pi, j = 1..n."""
    j = np.arange(1, n + 1)
    return 2 * np.sqrt(k / m) * np.sin(j * np.pi / (2 * (n + 1))) / (2 * np.pi)

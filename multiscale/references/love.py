"""Uniform normal pressure on a rectangle or a triangle of a half-space's surface (Love 1929).

Boussinesq: a uniform pressure p [Pa] on a region Ω of the surface of an elastic half-space moves
the surface point (x, y) by u = p/(π E*) ∫∫_Ω dA'/|x − x'| [m] into the solid (E* the composite
modulus). The functions here give that integral [m] (``love_rectangle``, ``love_triangle``) and its
mean over Ω (``*_mean``). A uniform flux q on a conducting half-space raises the surface
temperature by q/(2π κ) times the same integral.

Love, A. E. H. (1929), Phil. Trans. R. Soc. A 228, 377–420; thesis Eqs. 1.29–1.30, 3.2.
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError, check_positive


def love_rectangle(x, y, a, b):
    """∫∫ dξ dη / r [m] over the rectangle |ξ| < a, |η| < b seen from (x, y) [m] (thesis Eq. 1.30).

    Written with asinh so that it is accurate far from the rectangle; (x ± a, y ± b) must not
    vanish (true at cell centres). Vectorised over x, y.
    """
    def corner(X, Y):
        with np.errstate(divide="ignore", invalid="ignore"):
            fx = np.where(X != 0, X * np.arcsinh(Y / np.abs(np.where(X != 0, X, 1))), 0.0)
            fy = np.where(Y != 0, Y * np.arcsinh(X / np.abs(np.where(Y != 0, Y, 1))), 0.0)
        return fx + fy

    return corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) + corner(x - a, y - b)


def love_rectangle_mean(a: float, b: float) -> float:
    """Mean over the rectangle |x| < a, |y| < b of ``love_rectangle(x, y, a, b)`` [m].

    Closed form of (1/4ab) ∫∫_R ∫∫_R dA dA'/|x − x'|: with A = 2a, B = 2b, D = √(A² + B²),
    ∫∫_R∫∫_R = 4 [A²B/2 asinh(B/A) + AB²/2 asinh(A/B) + (A³ + B³ − D³)/6]
    (the 1-D identity ∫∫ f(x − x') = ∫ (A − |s|) f(s) ds in x and y). A unit square gives 2.9732.
    The mean displacement of the uniformly loaded rectangle is p/(π E*) times this.
    """
    A, B = 2 * check_positive("a", a), 2 * check_positive("b", b)
    D = np.hypot(A, B)
    total = 4 * (A * A * B / 2 * np.arcsinh(B / A) + A * B * B / 2 * np.arcsinh(A / B)
                 + (A**3 + B**3 - D**3) / 6)
    return float(total / (A * B))


def love_triangle(x, y, vertices) -> np.ndarray:
    """∫∫_T dA'/|x − x'| [m] over the triangle T (``vertices`` (3, 2) [m]) seen from (x, y) [m].

    T is the signed sum of the three triangles (P, edge); the one on an edge at signed distance h
    from P, whose ends sit at abscissae s1 < s2 along the edge from the foot of the perpendicular,
    contributes h [asinh(s2/|h|) − asinh(s1/|h|)] (polar coordinates about P: ∫ h sec θ dθ).
    Exact at any point, inside or outside; vectorised over x, y.
    """
    V = triangle_vertices(vertices)
    px, py = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    total = np.zeros(px.shape)
    for A, B in ((V[0], V[1]), (V[1], V[2]), (V[2], V[0])):
        length = np.hypot(*(B - A))
        t = (B - A) / length
        outward = np.array([t[1], -t[0]])          # counter-clockwise vertices: right of the edge
        h = (A[0] - px) * outward[0] + (A[1] - py) * outward[1]   # > 0: P on the inner side
        s1 = (A[0] - px) * t[0] + (A[1] - py) * t[1]
        ah = np.where(h != 0, np.abs(h), 1.0)
        total += np.where(h != 0, h * (np.arcsinh((s1 + length) / ah) - np.arcsinh(s1 / ah)), 0.0)
    return total


def love_triangle_mean(vertices) -> float:
    """Mean over the triangle of ``love_triangle`` [m]: (1/A) ∫∫_T∫∫_T dA dA'/|x − x'|.

    Closed form (4A/3) Σ_i ln(P/(P − 2 l_i)) / l_i over the edge lengths l_i, P the perimeter.
    """
    V = triangle_vertices(vertices)
    lengths = np.hypot(*(np.roll(V, -1, axis=0) - V).T)
    perimeter = lengths.sum()
    return float(4 * triangle_area(V) / 3 * np.sum(np.log(perimeter / (perimeter - 2 * lengths)) / lengths))


def triangle_area(vertices) -> float:
    """Area [m²] of a triangle (vertices (3, 2) [m])."""
    V = np.asarray(vertices, dtype=float)
    e1, e2 = V[1] - V[0], V[2] - V[0]
    return float(abs(e1[0] * e2[1] - e1[1] * e2[0]) / 2)


def triangle_vertices(vertices) -> np.ndarray:
    """Vertices as a (3, 2) float array in counter-clockwise order; InputError if degenerate."""
    V = np.array(vertices, dtype=float)
    if V.shape != (3, 2) or not np.all(np.isfinite(V)):
        raise InputError("vertices", vertices, "a triangle needs 3 finite (x, y) vertices")
    e1, e2 = V[1] - V[0], V[2] - V[0]
    cross = e1[0] * e2[1] - e1[1] * e2[0]
    if abs(cross) <= 1e-12 * max(np.dot(e1, e1), np.dot(e2, e2)):
        raise InputError("vertices", vertices, "the triangle is degenerate (zero area)")
    return V if cross > 0 else V[[0, 2, 1]]

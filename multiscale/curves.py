"""Piecewise-linear tables ((x, y), ...) of a scene: a material property against temperature, a
load factor or a speed against time, mu against temperature. Held constant beyond their ends;
means over an interval exact."""
from __future__ import annotations


def mean(table, x0: float, x1: float) -> float:
    """Mean over [x0, x1] of the piecewise-linear ``interpolate(table, .)`` (exact)."""
    if x1 <= x0:
        return interpolate(table, x0)
    xs = sorted({x0, x1, *(x for x, _ in table if x0 < x < x1)})
    ys = [interpolate(table, x) for x in xs]
    return sum(0.5 * (a + b) * (x1_ - x0_) for a, b, x0_, x1_ in zip(ys, ys[1:], xs, xs[1:])) / (x1 - x0)


def piecewise_mean(fn, knots, x0: float, x1: float) -> float:
    """Mean over [x0, x1] of ``fn``, a function that is quadratic (or linear) between its ``knots``:
    Simpson's rule on each piece, exact for it. ``fn`` at x0 if the interval is empty."""
    if x1 <= x0:
        return fn(x0)
    xs = sorted({x0, x1, *(x for x in knots if x0 < x < x1)})
    return sum((b - a) * (fn(a) + 4.0 * fn(0.5 * (a + b)) + fn(b)) / 6.0 for a, b in zip(xs, xs[1:])) / (x1 - x0)


def interpolate(table, x: float) -> float:
    """Piecewise-linear interpolation of ((x, y), ...) rows at ``x``, held constant beyond the ends."""
    xs, ys = zip(*table)
    if x <= xs[0]:
        return ys[0]
    for (x0, y0), (x1, y1) in zip(table, table[1:]):
        if x <= x1:         # (the fraction first: exact at the knots, a stop's 0 rpm is 0, not 7e-15 rad/s)
            return y0 + (y1 - y0) * ((x - x0) / (x1 - x0))
    return ys[-1]

"""Anderson acceleration of a fixed point (the partitions of ``coupling``'s fixed-point scheme)."""
from __future__ import annotations

import numpy as np


def anderson(passes, weight, mixing: float) -> np.ndarray:
    """The next partitions of Anderson's acceleration (Walker & Ni 2011, type II) of the fixed point
    p = G(p): ``passes`` [(p_j, r_j = G(p_j) − p_j), ...], the last one current; the residuals
    are compared weighted by ``weight`` (the zones' heat): p + m r − (ΔP + m ΔR) γ, γ minimising
    |W (r − ΔR γ)|; with one pass, the relaxed step p + m r."""
    p, r = passes[-1]
    if len(passes) == 1:
        return p + mixing * r
    dP = np.column_stack([b[0] - a[0] for a, b in zip(passes, passes[1:])])
    dR = np.column_stack([b[1] - a[1] for a, b in zip(passes, passes[1:])])
    gamma = np.linalg.lstsq(weight[:, None] * dR, weight * r, rcond=None)[0]
    return p + mixing * r - (dP + mixing * dR) @ gamma

"""Compiled (numba) cell loops of one Polonsky–Keer iteration on a chunk of patches.

``ContactSolver._run`` calls ``gap_statistics`` and ``direction`` before the FFT of the
direction and ``step`` after it; each fuses what would be a dozen numpy passes and gathers into
one or two sweeps over the grid. Arrays: ``p``, ``u``, ``z`` are (B, ny, nx) [Pa, m, m]; the
direction ``t`` and its response ``r = L t`` are the whole FFT buffers (B, Fy, Fx) of a
``ConvolutionWorkspace`` (Fy, Fx >= ny, nx: zero padding beyond). Contact set: p > 0.
"""
from __future__ import annotations

import numpy as np
from numba import njit

_FAST = {"reassoc", "contract", "nsz"}   # reductions may be reordered (vectorised); no NaN/inf tricks


@njit(cache=True, fastmath=_FAST, nogil=True)
def gap_statistics(p, u, z, delta, load_control, scale, d, G, count, gmin, Gneg, pnorm):
    """Per patch b: first p and u times the pending load-balance factor ``scale[b]`` (left by
    ``step``; reset to 1), then the contact cell count, approach ``d`` (load control: mean of
    u + z on the contact, else ``delta``), G = Σ_contact g², the minimum over all cells of
    g = u + z − d, Gneg = Σ g² over the cells off the contact with g < 0 and pnorm = Σ p²."""
    B, ny, nx = p.shape
    for b in range(B):
        c = scale[b]
        scale[b] = 1.0
        if c != 1.0:
            for i in range(ny):
                for j in range(nx):
                    p[b, i, j] *= c
                    u[b, i, j] *= c
        n, s, pp = 0, 0.0, 0.0
        for i in range(ny):
            for j in range(nx):
                q = p[b, i, j]
                on = q > 0.0
                n += on
                s += u[b, i, j] + z[b, i, j] if on else 0.0
                pp += q * q
        count[b] = n
        pnorm[b] = pp
        db = s / max(n, 1) if load_control else delta[b]
        d[b] = db
        ss, sn, low = 0.0, 0.0, np.inf
        for i in range(ny):
            for j in range(nx):
                g = u[b, i, j] + z[b, i, j] - db
                low = min(low, g)
                if p[b, i, j] > 0.0:
                    ss += g * g
                elif g < 0.0:
                    sn += g * g
        G[b] = ss
        Gneg[b] = sn
        gmin[b] = low


@njit(cache=True, fastmath=_FAST, nogil=True)
def direction(p, u, z, d, active, beta, t):
    """New conjugate direction t = g + beta t_old on the contact of active patches, 0 elsewhere."""
    B, ny, nx = p.shape
    for b in range(B):
        if not active[b]:
            t[b, :ny, :nx] = 0.0
            continue
        db, bb = d[b], beta[b]
        for i in range(ny):
            for j in range(nx):
                new = u[b, i, j] + z[b, i, j] - db + bb * t[b, i, j]
                t[b, i, j] = new if p[b, i, j] > 0.0 else 0.0


@njit(cache=True, fastmath=_FAST, nogil=True)
def step(p, u, z, d, count, target, load_control, active, t, r, scale, corrected, lost, conjugate):
    """Step p -= tau t with tau = (g, t) / (t, L t) (load control: L t made mean-free on the
    contact), projection p >= 0, overlapping cells (zero pressure, negative gap) entering with
    -tau g, and u <- u − tau L t; the factor c restoring the target mean pressure is left in
    ``scale`` (p <- c p and u <- c u happen in the next ``gap_statistics``). Flags per patch:
    ``corrected`` where p was projected or overlaps entered (the update of u is then inexact:
    recompute it), ``lost`` where every cell left the contact, ``conjugate`` False after an
    overlap correction (restart CG)."""
    B, ny, nx = p.shape
    for b in range(B):
        corrected[b], lost[b], conjugate[b] = False, False, True
        if not active[b]:
            continue
        db = d[b]
        rt, rs, ts, gt = 0.0, 0.0, 0.0, 0.0      # t = 0 off the contact: full sums are contact sums
        for i in range(ny):
            for j in range(nx):
                tk, rk = t[b, i, j], r[b, i, j]
                on = p[b, i, j] > 0.0
                rt += rk * tk
                rs += rk if on else 0.0
                ts += tk
                gt += (u[b, i, j] + z[b, i, j] - db) * tk
        if load_control:
            rt -= rs * ts / max(count[b], 1)
        tau = gt / rt if rt > 0.0 else 0.0
        touched, overlap, total = False, False, 0.0
        for i in range(ny):
            for j in range(nx):
                g = u[b, i, j] + z[b, i, j] - db
                q = p[b, i, j]
                if q > 0.0:
                    q -= tau * t[b, i, j]
                    if q < 0.0:
                        touched, q = True, 0.0
                    if q == 0.0 and g < 0.0:
                        overlap, q = True, -tau * g
                elif g < 0.0:
                    overlap, q = True, -tau * g
                p[b, i, j] = q
                total += q
                u[b, i, j] -= tau * r[b, i, j]
        if load_control:
            if total <= 0.0:
                lost[b] = True
            else:
                scale[b] = target[b] * (ny * nx) / total
        corrected[b] = touched or overlap or lost[b]
        conjugate[b] = not overlap

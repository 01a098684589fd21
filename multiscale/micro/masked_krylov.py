"""Krylov solves of a linear system restricted to a mask, batched over leading axes: A x = b on the
cells of ``mask`` with x zero elsewhere. ``apply`` maps a batch of fields to A x (e.g. an FFT
convolution).

``masked_cg``: conjugate gradients for a symmetric positive definite A (the conduction of a contact,
thesis Eqs. 5.10–5.12, ``micro.conduction``; the incremental contact of a fixed contact set,
``micro.stiffness``).

``masked_solve``: any A, stopping per patch at |Ax − b| <= tol · scale (thesis §6.3.5, Eq. 6.21:
the micro heat systems on the contacting cells, ``micro.heating``). It runs ``bicgstab`` and hands the patches it leaves unconverged to ``cgls``, the
thesis' conjugate gradients on the normal equations (Eqs. 6.19–6.20), slower (its condition number
is the square of the system's, two products per iteration) but without breakdowns.
"""
from __future__ import annotations

import numpy as np


def masked_cg(apply, b, mask, tol, max_iter, x0, diagonal=0.0):
    """Conjugate gradients for (A + D) x = b on the cells of ``mask`` (..., ny, nx), x zero
    elsewhere, A + D symmetric positive definite there; D = diag(``diagonal``). ``b``, ``x0`` and
    ``diagonal``: scalars or fields broadcastable to the mask. The vectors hold the mask's cells
    only (gathered); per-patch dot products are segment sums, and a patch is frozen once its
    recursive residual |r| <= tol |b|. Returns x (mask's shape), iterations, the true relative
    residual |(A + D) x − b| / |b| on the mask and converged (the batch's shape)."""
    shape, batch = mask.shape, mask.shape[:-2]
    B, N = int(np.prod(batch, dtype=int)), shape[-2] * shape[-1]
    idx = np.flatnonzero(mask)
    seg = idx // N                                   # patch of each cell
    gather = lambda a: np.ascontiguousarray(np.broadcast_to(a, shape)).ravel()[idx]
    Dc, b = gather(diagonal), gather(b)
    work = np.zeros(shape)

    def A(x):                                        # (A + D) x restricted to the mask
        work.ravel()[idx] = x
        out = apply(work).ravel()[idx]
        work.ravel()[idx] = 0.0
        return out + Dc * x

    def dot(x, y):
        return np.bincount(seg, weights=x * y, minlength=B)

    x = gather(x0).astype(float)
    bnorm = np.sqrt(dot(b, b))
    safe = np.where(bnorm > 0, bnorm, 1.0)
    r = b - A(x)
    d = r.copy()
    rr = dot(r, r)
    active = np.sqrt(rr) / safe > tol
    its = np.zeros(B, dtype=int)
    for _ in range(max_iter):
        if not active.any():
            break
        Ad = A(d)
        dAd = dot(d, Ad)
        alpha = np.where(active & (dAd > 0), rr / np.where(dAd > 0, dAd, 1.0), 0.0)[seg]
        x += alpha * d
        r -= alpha * Ad
        rr_new = dot(r, r)
        d = r + np.where(active, rr_new / np.where(rr > 0, rr, 1.0), 0.0)[seg] * d
        rr = np.where(active, rr_new, rr)
        its += active
        active &= np.sqrt(rr) / safe > tol
    true = b - A(x)
    res = np.sqrt(dot(true, true)) / safe
    out = np.zeros(shape)
    out.ravel()[idx] = x
    return out, its.reshape(batch), res.reshape(batch), ~active.reshape(batch)


def masked_solve(apply, apply_t, b, mask, scale, tol, max_iter, x0=None):
    """x supported on ``mask`` with A x = b on the mask (|Ax − b| <= tol · scale per patch): by
    BiCGSTAB (``bicgstab``), the patches where it breaks down or does not converge again by the
    least-squares CG of the thesis (``cgls``, Eqs. 6.19–6.21) from x0. Returns (x, iterations,
    residual, history: the largest residual per iteration, BiCGSTAB's then CGLS's)."""
    x, iterations, res, history = bicgstab(apply, b, mask, scale, tol, max_iter, x0)
    again = np.flatnonzero(~(res <= tol).reshape(-1))
    if len(again):
        pick = lambda a: a.reshape((-1,) + a.shape[-2:])[again]       # (B, ny, nx) or (B, 1, 1) rows
        xa, ia, ra, ha = cgls(_rows(apply, again, b.shape), _rows(apply_t, again, b.shape), pick(b), pick(mask),
                               pick(scale), tol, max_iter, None if x0 is None else pick(x0))
        x = x.reshape((-1,) + b.shape[-2:]).copy()
        iterations, res = np.asarray(iterations).reshape(-1).copy(), np.asarray(res, float).reshape(-1).copy()
        x[again], res[again] = xa, ra
        iterations[again] += ia
        x, iterations, res = x.reshape(b.shape), iterations.reshape(b.shape[:-2]), res.reshape(b.shape[:-2])
        history = history + ha
    return x, iterations, res, history


def _rows(apply, rows, shape):
    """``apply`` (of a batch of ``shape``) on the patches ``rows`` of the flattened batch only."""
    def on_rows(x):
        full = np.zeros((int(np.prod(shape[:-2], dtype=int)),) + shape[-2:])
        full[rows] = x
        return apply(full.reshape(shape)).reshape(full.shape)[rows]
    return on_rows


def bicgstab(apply, b, mask, scale, tol, max_iter, x0=None):
    """BiCGSTAB (van der Vorst 1992, SIAM J. Sci. Stat. Comput. 13, 631–644) for A x = b on the
    cells of ``mask``, batched over leading axes: one convolution per half step instead of the two
    of the normal equations, 2–3x fewer in all on contact patches (benchmarks/README). A patch stops
    when its true residual |Ax − b| <= tol · scale (checked with one product more when the
    recursive one says so); a breakdown (a zero inner product) or max_iter leaves it unconverged."""
    axes = (-2, -1)
    dot = lambda u, v: np.sum(u * v, axis=axes, keepdims=True)
    op = lambda x: np.where(mask, apply(x), 0.0)
    x = np.zeros_like(b) if x0 is None else np.where(mask, x0, 0.0)
    r = np.where(mask, b - (op(x) if x0 is not None else 0.0), 0.0)
    shadow = r.copy()
    one = np.ones(b.shape[:-2] + (1, 1))
    rho, alpha, omega = one, one, one
    v, d = np.zeros_like(b), np.zeros_like(b)
    res = np.sqrt(dot(r, r)) / scale
    active, iterations = res > tol, np.zeros(res.shape, dtype=int)
    history = [float(res.max())]
    for _ in range(max_iter):
        if not active.any():
            break
        rho_new = dot(shadow, r)
        beta = np.where(active, rho_new / np.where(rho * omega != 0, rho * omega, 1.0) * alpha, 0.0)
        d = r + beta * (d - omega * v)
        v = op(d)
        sv = dot(shadow, v)
        alpha = rho_new / np.where(sv != 0, sv, 1.0)
        h = r - alpha * v
        t = op(h)
        tt = dot(t, t)
        omega = dot(t, h) / np.where(tt != 0, tt, 1.0)
        half = tt == 0                         # h = 0 (one or two cells): x + alpha d solves it, omega = 0
        broken = active & ((rho_new == 0) | (sv == 0) | ((omega == 0) & ~half))
        step = active & ~broken
        x = np.where(step, x + alpha * d + omega * h, x)
        r = np.where(step, h - omega * t, r)
        rho = rho_new
        iterations += step
        res = np.where(step, np.sqrt(dot(r, r)) / scale, res)
        done = step & (res <= tol)
        if done.any():                         # the recursive residual drifts: confirm with the true one
            e = np.where(mask, b - op(x), 0.0)
            res = np.where(done, np.sqrt(dot(e, e)) / scale, res)
        active = step & (res > tol)
        history.append(float(res.max()))
    return x, iterations[..., 0, 0], res[..., 0, 0], history


def cgls(apply, apply_t, b, mask, scale, tol, max_iter, x0=None):
    """Minimise ½|A x − b|² over x supported on ``mask`` (Eqs. 6.19–6.21) by conjugate gradients on
    the normal equations (gradient Aᵀ(Ax − b), Eq. 6.20) from ``x0`` (default 0). Batched over
    leading axes; stops per patch when |Ax − b| <= tol · scale."""
    axes = (-2, -1)
    x = np.zeros_like(b) if x0 is None else np.where(mask, x0, 0.0)
    r = np.where(mask, b - (apply(x) if x0 is not None else 0.0), 0.0)
    s = np.where(mask, apply_t(r), 0.0)
    p = s.copy()
    gamma = np.sum(s * s, axis=axes, keepdims=True)
    res = np.sqrt(np.sum(r * r, axis=axes, keepdims=True)) / scale
    iterations = np.zeros(res.shape, dtype=int)
    history = [float(res.max())]
    for _ in range(max_iter):
        active = res > tol
        if not active.any():
            break
        q = np.where(mask, apply(p), 0.0)
        qq = np.sum(q * q, axis=axes, keepdims=True)
        alpha = np.where(active & (qq > 0), gamma / np.where(qq > 0, qq, 1.0), 0.0)
        x += alpha * p
        r -= alpha * q
        res = np.sqrt(np.sum(r * r, axis=axes, keepdims=True)) / scale
        s = np.where(mask, apply_t(r), 0.0)
        gamma_new = np.sum(s * s, axis=axes, keepdims=True)
        p = s + np.where(gamma > 0, gamma_new / np.where(gamma > 0, gamma, 1.0), 0.0) * p
        gamma = gamma_new
        iterations += active
        history.append(float(res.max()))
    return x, iterations[..., 0, 0], res[..., 0, 0], history

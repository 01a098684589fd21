"""Compiled (numba) loops of one preconditioned constrained CG iteration (``bccg_solver``).

Arrays of a chunk of B patches on a grid (ny, nx), flattened to (B, ny * nx): ``p``, ``u``, ``z``
[Pa, m, m], ``label`` and the work vectors; the FFT buffers ``X`` (input), ``Y`` (output) are
(B, Fy * Fx) with Fy, Fx >= ny, nx (cell (i, j) at i * Fx + j, zero padding beyond); the
spectrum ``S`` (B, Fy, Fx // 2 + 1). The preconditioner has its own buffers ``XP``, ``YP``
(of the same layout, possibly float32) and spectrum. Free set F: contact cells (p > 0) and cells with
p = 0 and a negative gap (they may enter). ``label`` marks F (0), the rings 1..R of gap cells
around it into which the residual is extended (k), and the other cells (-1); ``fi``/``fj`` and
``bi``/``bj`` list the rows and columns of the cells of F and of the rings (ring by ring,
``ring_end``), so that the sweeps over them need no integer division. Free sets of
``DENSE_FROM`` of the grid and more build and fold the rings by row sweeps instead (unlisted):
at 30 % contact F and its rings cover 70 % of the grid, and the scatter from the listed cells
took 40 % of an iteration.

Bounded pressure 0 <= p <= H (``upper``, H per patch; +inf: elastic, then every loop computes
exactly what it computes without the bound): the contact cells are then the elastic ones (0 < p
< H) and the saturated ones (p = H, plastic flow, gap <= 0). F adds the saturated cells with a
gap >= 0 (they may leave the bound); the other saturated cells are held at H (``fixed`` counts
them) like the cells with p = 0 and a gap >= 0 are held at 0. See ``bounded_update``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

_FAST = {"reassoc", "contract", "nsz"}   # reductions may be reordered (vectorised); no NaN/inf tricks
DENSE_FROM = 0.15                         # free sets of this fraction of the grid and more: rings by row sweeps


@njit(cache=True, fastmath=_FAST, nogil=True)
def contact_sums(p, u, z, upper, active, ccount, csum, pnorm):
    """Per active patch: elastic contact cells (0 < p < H), their Σ (u + z), and ||p||²."""
    B, N = p.shape
    for b in range(B):
        if not active[b]:
            continue
        n, sc, pp, H = 0, 0.0, 0.0, upper[b]
        for f in range(N):
            q = p[b, f]
            pp += q * q
            if q > 0.0 and q < H:
                n += 1
                sc += u[b, f] + z[b, f]
        ccount[b], csum[b], pnorm[b] = n, sc, pp


@njit(cache=True, fastmath=_FAST, nogil=True)
def free_set(u, z, p, delta, load_control, active, ccount, csum, d, label, fi, fj, nf, r, s_old, t, XP, X, upper,
             fixed, nx, Fx):
    """Per active patch: the approach ``d`` (load control: mean of u + z on the elastic contact,
    from ``contact_sums``; with none but saturated cells, their largest u + z; else ``delta``),
    the free set F (``label`` 0, listed in ``fi``/``fj``/``nf``; ``fixed`` the cells held at H),
    the residual r = g = u + z - d on F (mean-free on F under load control: the gradient
    projected on Σ p = const) and XP = r on F. XP, X, ``s_old`` and ``t`` are zeroed on the cells
    that left F (a cell entering F starts without history); elsewhere XP and X are zero already
    (X holds the increments p_new - p on F since ``update_pressure``, XP held r on F;
    ``back_extend`` cleared the rings) and r is never read."""
    B, N = p.shape
    ny = N // nx
    for b in range(B):
        if not active[b]:
            continue
        H = upper[b]
        db = (csum[b] / ccount[b] if ccount[b] > 0 else 0.0) if load_control else delta[b]
        if load_control and ccount[b] == 0 and H < np.inf:
            db = saturated_top(u[b], z[b], p[b], H)
        d[b] = db
        k, sf, nfix = 0, 0.0, 0
        for i in range(ny):
            for j in range(nx):
                f = i * nx + j
                g = u[b, f] + z[b, f] - db
                q = p[b, f]
                held = q >= H and g < 0.0
                nfix += held
                if (q > 0.0 or g < 0.0) and not held:
                    label[b, f] = 0
                    fi[b, k], fj[b, k] = i, j
                    k += 1
                    r[b, f] = g
                    XP[b, i * Fx + j] = g
                    sf += g
                elif label[b, f] != -1:
                    if label[b, f] == 0:
                        XP[b, i * Fx + j] = 0.0
                        X[b, i * Fx + j] = 0.0
                        s_old[b, f] = 0.0
                        t[b, f] = 0.0
                    label[b, f] = -1
        nf[b] = k
        fixed[b] = nfix
        if load_control and k > 0:
            mean = sf / k
            for m in range(k):
                i, j = fi[b, m], fj[b, m]
                r[b, i * nx + j] -= mean
                XP[b, i * Fx + j] -= mean


@njit(cache=True, nogil=True)
def saturated_top(u, z, p, H):
    """Largest u + z over the saturated cells (p >= H) of one patch (flat arrays), 0 if none:
    the approach under load control when no cell is in elastic contact (fully plastic)."""
    top, found = 0.0, False
    for f in range(p.shape[0]):
        if p[f] >= H:
            v = u[f] + z[f]
            if not found or v > top:
                top, found = v, True
    return top


@njit(cache=True, inline="always")
def _wrap(i, n, periodic):
    """Index i along an axis of n cells: wrapped around (periodic) or -1 outside."""
    if 0 <= i < n:
        return i
    if not periodic:
        return -1
    return i + n if i < 0 else i - n


@njit(cache=True, inline="always")
def by_rows(n, ny, nx):
    """Whether a free set of n cells of an (ny, nx) grid takes the row sweeps (``extend_rows``,
    ``back_rows``: F covers ``DENSE_FROM`` of the grid or more) or the listed cells; ``extend`` and
    ``back_extend`` must choose alike (the listed rings exist only after ``extend_cells``)."""
    return n >= DENSE_FROM * ny * nx


@njit(cache=True, nogil=True)
def extend(label, fi, fj, nf, bi, bj, ring_end, count, X, gammas, periodic, active, ny, nx, Fx):
    """X = E r on the physical grid (X holds r on F from ``free_set``): ring by ring
    (8-neighbourhood), gamma_k (``gammas[b, k - 1]`` of patch b) times the mean of the values of
    the neighbouring cells of ring k - 1. Builds the rings (``label`` k) and ``count``, the
    neighbours of each ring cell in the ring inside it: by scattering from the listed cells (``bi``/``bj``/``ring_end`` list the
    rings), or by row sweeps when F covers ``DENSE_FROM`` of the grid or more (then F and its
    rings cover most of it and the scatter would visit each ring cell from up to 8 sides)."""
    for b in range(label.shape[0]):
        if not active[b]:
            continue
        if by_rows(nf[b], ny, nx):
            extend_rows(label[b], X[b], count[b], gammas[b], periodic, ny, nx, Fx)
        else:
            extend_cells(label[b], fi[b], fj[b], nf[b], bi[b], bj[b], ring_end[b], count[b], X[b], gammas[b],
                         periodic, ny, nx, Fx)


@njit(cache=True, nogil=True)
def extend_cells(label, fi, fj, n, bi, bj, ring_end, count, X, gammas, periodic, ny, nx, Fx):
    """``extend`` of one patch (flat arrays) by scattering from the cells of F, then of each ring."""
    k = 0
    for ring in range(1, gammas.shape[0] + 1):
        lo = 0 if ring <= 2 else ring_end[ring - 3]
        hi = n if ring == 1 else ring_end[ring - 2]
        new = k
        for m in range(lo, hi):                # scatter the values of ring - 1 to their neighbours
            i0, j0 = (fi[m], fj[m]) if ring == 1 else (bi[m], bj[m])
            v = X[i0 * Fx + j0]
            for di in range(-1, 2):            # the 8-neighbourhood (wrapped, or cut at the edge)
                i = _wrap(i0 + di, ny, periodic)
                if i < 0:
                    continue
                for dj in range(-1, 2):
                    j = _wrap(j0 + dj, nx, periodic)
                    if j < 0:
                        continue
                    g = i * nx + j
                    lg = label[g]
                    if lg == -1:
                        label[g] = ring
                        bi[k], bj[k] = i, j
                        k += 1
                        count[g] = 1
                        X[i * Fx + j] = v
                    elif lg == ring:
                        count[g] += 1
                        X[i * Fx + j] += v
        ring_end[ring - 1] = k
        gam = gammas[ring - 1]
        for m in range(new, k):
            i, j = bi[m], bj[m]
            X[i * Fx + j] *= gam / count[i * nx + j]


@njit(cache=True, fastmath=_FAST, nogil=True)
def extend_rows(label, X, count, gammas, periodic, ny, nx, Fx):
    """``extend`` of one patch (flat arrays) by row sweeps: for each ring, the 3 x 3 sums of the
    indicator of ring - 1 and of X on it, from the column sums of three rows (``_row_sums``)."""
    A = np.zeros((3, nx + 2))                  # rows r - 1, r, r + 1 in slots (row + 1) % 3
    V = np.zeros((3, nx + 2))
    ca, cv = np.zeros(nx + 2), np.zeros(nx + 2)
    for ring in range(1, gammas.shape[0] + 1):
        gam = gammas[ring - 1]
        for r in range(-2, ny):                # row r + 1 loaded, then row r swept
            ii = _wrap(r + 1, ny, periodic)
            a, v = A[(r + 2) % 3], V[(r + 2) % 3]
            if ii < 0:                         # beyond the edge of an isolated patch
                a[:] = 0.0
                v[:] = 0.0
            else:                              # the indicator of ring - 1 and X on it, row r + 1
                base, xb = ii * nx, ii * Fx
                for j in range(nx):
                    on = label[base + j] == ring - 1
                    a[j + 1] = 1.0 if on else 0.0
                    v[j + 1] = X[xb + j] if on else 0.0
            if r < 0:
                continue
            _row_sums(A, ca, periodic, nx)
            _row_sums(V, cv, periodic, nx)
            base, xb = r * nx, r * Fx          # ring cells of row r: unlabelled with a neighbour in ring - 1
            for j in range(nx):
                c = ca[j] + ca[j + 1] + ca[j + 2]
                if c > 0.0 and label[base + j] == -1:
                    label[base + j] = ring
                    count[base + j] = np.int8(c + 0.5)
                    X[xb + j] = gam * (cv[j] + cv[j + 1] + cv[j + 2]) / c


@njit(cache=True, fastmath=_FAST, nogil=True)
def _row_sums(rows, out, periodic, nx):
    """out[1:nx + 1] = the sums of the three row slots (values in [1:nx + 1]); out[0], out[nx + 1]
    the wrapped (periodic) or zero neighbours beyond the edges."""
    for j in range(1, nx + 1):
        out[j] = rows[0, j] + rows[1, j] + rows[2, j]
    out[0] = out[nx] if periodic else 0.0
    out[nx + 1] = out[1] if periodic else 0.0


@njit(cache=True, fastmath=_FAST, nogil=True)
def back_extend(label, fi, fj, nf, bi, bj, ring_end, count, Y, s, gammas, periodic, X, load_control, active, pnorm,
                eps, ny, nx, Fx):
    """From Y = M E r: the preconditioned residual s = E^T Y on F (mean-free on F under load
    control; ``s`` is scratch on the rings, whose cells are cleared from X), and the error
    estimate ``eps`` = ||s|| / ||p||, the relative L2 error of the pressure when the
    preconditioner is exact (0 when s = 0). By the listed cells or by row sweeps, as ``extend``."""
    for b in range(label.shape[0]):
        if not active[b]:
            continue
        n = nf[b]
        if by_rows(n, ny, nx):
            total = back_rows(label[b], count[b], Y[b], s[b], X[b], gammas[b], periodic, ny, nx, Fx)
        else:
            total = back_cells(label[b], fi[b], fj[b], n, bi[b], bj[b], ring_end[b], count[b], Y[b], s[b], X[b],
                               gammas[b], periodic, ny, nx, Fx)
        mean = total / n if load_control and n > 0 else 0.0
        ss = 0.0
        for m in range(n):
            g = fi[b, m] * nx + fj[b, m]
            v = s[b, g] - mean
            s[b, g] = v
            ss += v * v
        eps[b] = np.sqrt(ss / pnorm[b]) if pnorm[b] > 0.0 else (0.0 if ss == 0.0 else np.inf)


@njit(cache=True, fastmath=_FAST, nogil=True)
def back_cells(label, fi, fj, n, bi, bj, ring_end, count, Y, s, X, gammas, periodic, ny, nx, Fx):
    """s = E^T Y of one patch (flat arrays) over the listed cells of F and of the rings; returns Σ_F s."""
    R = gammas.shape[0]
    total = 0.0
    for m in range(ring_end[R - 1]):
        i, j = bi[m], bj[m]
        s[i * nx + j] = Y[i * Fx + j]
        X[i * Fx + j] = 0.0
    for m in range(n):
        i, j = fi[m], fj[m]
        v = Y[i * Fx + j]
        s[i * nx + j] = v
        total += v
    for ring in range(R, 0, -1):               # adjoint of ``extend``: outermost ring first
        first = 0 if ring == 1 else ring_end[ring - 2]
        gam = gammas[ring - 1]
        for m in range(first, ring_end[ring - 1]):
            i0, j0 = bi[m], bj[m]
            g0 = i0 * nx + j0
            v = s[g0] * gam / count[g0]
            for di in range(-1, 2):
                i = _wrap(i0 + di, ny, periodic)
                if i < 0:
                    continue
                for dj in range(-1, 2):
                    j = _wrap(j0 + dj, nx, periodic)
                    if j >= 0:                             # no branch on the label: 18-20 % faster
                        g = i * nx + j
                        w = v if label[g] == ring - 1 else 0.0
                        s[g] += w
                        total += w if ring == 1 else 0.0
    return total


@njit(cache=True, fastmath=_FAST, nogil=True)
def back_rows(label, count, Y, s, X, gammas, periodic, ny, nx, Fx):
    """s = E^T Y of one patch (flat arrays) by row sweeps: for each ring, outermost first, its
    weighted values gamma s / count summed over the 3 x 3 neighbourhoods of the cells of ring - 1.
    s is scratch off F and the rings: the sweeps write it everywhere (selects, no branches: 2x
    faster). Returns Σ_F s."""
    for i in range(ny):                        # s = Y; the rings cleared from X
        base, xb = i * nx, i * Fx
        for j in range(nx):
            s[base + j] = Y[xb + j]
            X[xb + j] = 0.0 if label[base + j] > 0 else X[xb + j]
    W = np.zeros((3, nx + 2))                  # rows r - 1, r, r + 1 in slots (row + 1) % 3
    cw = np.zeros(nx + 2)
    total = 0.0
    for ring in range(gammas.shape[0], 0, -1):
        gam = gammas[ring - 1]
        for r in range(-2, ny):                # row r + 1 loaded, then row r swept
            ii = _wrap(r + 1, ny, periodic)
            w = W[(r + 2) % 3]
            if ii < 0:
                w[:] = 0.0
            else:
                base = ii * nx
                for j in range(nx):
                    w[j + 1] = gam * s[base + j] / max(count[base + j], 1) if label[base + j] == ring else 0.0
            if r < 0:
                continue
            _row_sums(W, cw, periodic, nx)
            base = r * nx
            for j in range(nx):
                on = label[base + j] == ring - 1
                v = s[base + j] + (cw[j] + cw[j + 1] + cw[j + 2] if on else 0.0)
                s[base + j] = v
                total += v if on and ring == 1 else 0.0
    return total


@njit(cache=True, nogil=True)
def check(eps, tol, iterations, max_iter, active, XP, X):
    """Stopping test after ``back_extend``: patches with eps <= tol, or at ``max_iter``, leave
    ``active`` (their FFT inputs are zeroed). Returns (largest eps of the patches that were
    active, patches still active, non-finite eps found)."""
    B = eps.shape[0]
    top, left, bad = 0.0, 0, False
    for b in range(B):
        if not active[b]:
            continue
        e = eps[b]
        if not np.isfinite(e):
            bad = True
        top = max(top, e)
        if e <= tol or iterations[b] >= max_iter:
            active[b] = False
            XP[b] = 0.0
            X[b] = 0.0
        else:
            left += 1
    return top, left, bad


@njit(cache=True, fastmath=_FAST, nogil=True)
def direction(fi, fj, nf, r, s, s_old, t, X, load_control, active, conj, rho_old, rt, iterations, nx, Fx):
    """New direction t = s + beta t on F with the Polak–Ribière(+) factor (beta = 0 when
    ``conj`` is False, then set; restart from s when t is not a descent direction), mean-free on F
    under load control; (r, t) in ``rt``; X = t on F (zero elsewhere after ``back_extend``);
    s_old = s; one more iteration counted."""
    B = r.shape[0]
    for b in range(B):
        if not active[b]:
            continue
        n = nf[b]
        rho, mixed = 0.0, 0.0
        for m in range(n):
            g = fi[b, m] * nx + fj[b, m]
            rho += r[b, g] * s[b, g]
            mixed += r[b, g] * s_old[b, g]
        beta = max(0.0, (rho - mixed) / rho_old[b]) if conj[b] and rho_old[b] > 0.0 else 0.0
        rho_old[b] = rho
        tm = 0.0
        for m in range(n):
            g = fi[b, m] * nx + fj[b, m]
            v = s[b, g]
            s_old[b, g] = v
            w = v + beta * t[b, g]
            t[b, g] = w
            tm += w
        tm = tm / n if load_control and n > 0 else 0.0
        dot = 0.0
        for m in range(n):
            i, j = fi[b, m], fj[b, m]
            g = i * nx + j
            w = t[b, g] - tm
            t[b, g] = w
            X[b, i * Fx + j] = w
            dot += r[b, g] * w
        if beta > 0.0 and not dot > 0.0:      # not a descent direction: restart from s
            dot = 0.0
            for m in range(n):
                i, j = fi[b, m], fj[b, m]
                g = i * nx + j
                w = s_old[b, g]
                t[b, g] = w
                X[b, i * Fx + j] = w
                dot += r[b, g] * w
        rt[b] = dot
        conj[b] = True
        iterations[b] += 1


@njit(cache=True, fastmath=_FAST, nogil=True)
def step_length(S, lmul, Fx, rt, active, tau):
    """tau = (r, t) / (t, L t) per patch from S, the rfft2 of t on a real grid of width Fx:
    (t, L t) = Σ_k lmul_k |T_k|² over the full spectrum (Parseval; lmul is the real transfer
    function / (Fy Fx)). Returns whether every tau is finite."""
    B, Fy, Fh = S.shape
    for b in range(B):
        acc = 0.0
        for i in range(Fy):
            for j in range(Fh):
                w = 1.0 if j == 0 or 2 * j == Fx else 2.0
                v = S[b, i, j]
                acc += w * lmul[i, j] * (v.real * v.real + v.imag * v.imag)
        tau[b] = rt[b] / acc if active[b] and acc > 0.0 else 0.0
    return np.all(np.isfinite(tau))


@njit(cache=True, fastmath=_FAST, nogil=True)
def update_pressure(p, t, fi, fj, nf, tau, X, active, load_control, target, pending, clipped, lost, upper, fixed,
                    steps, scratch, nx, Fx):
    """p <- max(p - tau t, 0) on F (cells outside F keep p = 0) and X = p_new - p on F, the
    increment whose L updates u (it is -tau t where nothing was clipped), ||X||² in ``steps``;
    under load control the factor restoring the mean pressure goes to ``pending`` (applied to p
    and u next). Patches with a finite bound H take ``bounded_update`` instead (``scratch``: its
    (B, ny * nx) float64 work array; X may be float32).
    Returns the numbers of patches with clipped cells and of patches that lost every contact."""
    B, N = p.shape
    nclip, nlost = 0, 0
    for b in range(B):
        clipped[b], lost[b], steps[b] = False, False, 0.0
        if not active[b]:
            continue
        if upper[b] < np.inf:
            rest = max(target[b] * N - upper[b] * fixed[b], 0.0)
            clipped[b], steps[b] = bounded_update(p[b], t[b], fi[b], fj[b], nf[b], tau[b], X[b], scratch[b], upper[b],
                                                  load_control, rest, nx, Fx)
            nclip += clipped[b]
            continue
        tb, total, ss = tau[b], 0.0, 0.0
        for m in range(nf[b]):
            i, j = fi[b, m], fj[b, m]
            g = i * nx + j
            q = p[b, g] - tb * t[b, g]
            if q < 0.0:
                clipped[b] = True
                q = 0.0
            dq = q - p[b, g]
            X[b, i * Fx + j] = dq
            ss += dq * dq
            p[b, g] = q
            total += q
        steps[b] = ss
        if load_control:
            if total > 0.0:
                pending[b] = target[b] * N / total
            else:
                lost[b] = True
        nclip += clipped[b]
        nlost += lost[b]
    return nclip, nlost


@njit(cache=True, fastmath=_FAST, nogil=True)
def bounded_update(p, t, fi, fj, n, tau, X, q, H, load_control, rest, nx, Fx):
    """One patch (flat arrays) with the bound H: p <- P(p - tau t) on F, P the Euclidean
    projection on {0 <= p <= H; Σ_F p = ``rest``} under load control (``rest``: the load less
    what the cells held at H carry), i.e. p = clip(q + a, 0, H) with the shift a found by a
    safeguarded Newton search on the piecewise-linear Σ clip(q + a) (exact on the final linear
    piece); the box alone under displacement control. The bound is the hardness cut-off of
    Almqvist et al. (2007, Tribol. Int. 40, 574-579), also ContactMechanics'
    ``constrained_conjugate_gradients(hardness=...)``; the load is kept by the shift (the exact
    projection) instead of a rescaling, which would push saturated cells above H.
    X = p_new - p on F, as in ``update_pressure``; ``q`` (flat, of p's layout) holds the
    unbounded step p - tau t on F. Returns whether any cell moved off it, and ||p_new - p||²."""
    for m in range(n):
        g = fi[m] * nx + fj[m]
        q[g] = p[g] - tau * t[g]
    a = 0.0
    if load_control:
        qmin, qmax = np.inf, -np.inf
        for m in range(n):
            v = q[fi[m] * nx + fj[m]]
            qmin, qmax = min(qmin, v), max(qmax, v)
        lo, hi = -qmax, H - qmin                # phi(lo) = -rest <= 0 <= phi(hi) = n H - rest
        for _ in range(200):
            phi, slope = -rest, 0
            for m in range(n):
                v = q[fi[m] * nx + fj[m]] + a
                if v >= H:
                    phi += H
                elif v > 0.0:
                    phi += v
                    slope += 1
            if abs(phi) <= 1e-14 * max(rest, H) or hi - lo <= 1e-15 * H:
                break
            if phi < 0.0:
                lo = a
            else:
                hi = a
            a = a - phi / slope if slope > 0 else 0.5 * (lo + hi)
            if not lo < a < hi:
                a = 0.5 * (lo + hi)
    moved, ss = False, 0.0
    for m in range(n):
        i, j = fi[m], fj[m]
        g = i * nx + j
        v = min(max(q[g] + a, 0.0), H)
        dv = v - p[g]
        moved = moved or v != q[g]
        p[g] = v
        X[i * Fx + j] = dv
        ss += dv * dv
    return moved, ss


@njit(cache=True, fastmath=_FAST, nogil=True)
def add_response(u, Y, factor, p, z, fi, fj, nf, pending, active, ccount, csum, pnorm, upper, fixed, nx, Fx):
    """u <- c (u + factor Y) and p <- c p (p is zero off F, or H on the ``fixed`` cells, where
    c = 1) with c the pending load-balance factor (then reset to 1), and the ``contact_sums`` of
    the new state, on active patches."""
    B, N = u.shape
    ny = N // nx
    for b in range(B):
        if not active[b]:
            continue
        c, f = pending[b], factor[b]
        pending[b] = 1.0
        cf = c * f
        for i in range(ny):
            for j in range(nx):
                u[b, i * nx + j] = c * u[b, i * nx + j] + cf * Y[b, i * Fx + j]
        n, sc, pp, H = 0, 0.0, 0.0, upper[b]
        for m in range(nf[b]):
            g = fi[b, m] * nx + fj[b, m]
            q = c * p[b, g]
            p[b, g] = q
            pp += q * q
            if q > 0.0 and q < H:
                n += 1
                sc += u[b, g] + z[b, g]
        if fixed[b] > 0:
            pp += fixed[b] * H * H
        ccount[b], csum[b], pnorm[b] = n, sc, pp

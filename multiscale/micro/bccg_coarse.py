"""Balancing two-level coarse correction of the contact solver's preconditioner (``bccg_solver``).

The one-level preconditioner P1 = Eᵀ M E leaves the coarse modes of the free set F (pressures
nearly constant over patches of F of tens to hundreds of cells) badly scaled, and the iterations
grow with the grid (13, 14, 18, 25 at N = 256 ... 2048 on the benchmark surfaces). The balancing
(BNN) preconditioner of Mandel (1993, Commun. Numer. Methods Eng. 9, 233-241) in the form of
Tang, Nabben, Vuik & Erlangga (2009, J. Sci. Comput. 39, 340-370, eq. 2.10),

    P r = Z Ẽ⁻¹ Zᵀ r + Qᵀ P1 Q r,   Q = I - K Ẽ⁻¹ Zᵀ,

takes those modes out: Z restricts to aggregates (the cells of F in one cell of a coarse grid of
``CELLS`` x ``CELLS``), K = A Z and Ẽ = Zᵀ A Z for the stiffness A of F. P is symmetric positive
definite for any K when Ẽ is, so the discrete answer is untouched; only the iterations change.

A is not L_FF (whose K would cost an FFT pair per product) but a cheap symmetric approximation:
the exact influence coefficients between cells of F in the same or neighbouring coarse cells
(``near_coefficients``: C[i, s] the influence on cell i of the cells of F in slot s of the 3 x 3
coarse cells around its own), and between farther coarse cells the coefficient of their centres
times their cell counts (monopoles). K y costs 9 products per cell of F and a dense m x m product
(m <= CELLS² non-empty aggregates), Ẽ a Cholesky factorisation. Built for one F, the operator is
reused while F differs from it by at most ``REBUILD`` of its cells (new cells then have no near
coefficients, cells of aggregates empty at the build no coarse component): still a symmetric
positive definite P, slightly weaker. On the benchmark surfaces the iterations become 14 and 14
(16 for another realisation) at N = 1024 and 2048, against 18 and 25 (23) one-level, with 6-11
builds of 0.7-0.8 of an FFT pair each; the solve takes 0.69-0.88x the one-level time at 2048²,
0.95-0.98x at 1024² (benchmarks/README, ``bench_contact.py --only levels``).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg
from numba import njit

CELLS = 32             # coarse grid cells per side (fewer on grids of fewer than 4 * CELLS cells)
SUB = 8                # sub-blocks of SUB x SUB cells: exact influence between neighbouring ones
SPARSE_TO = 0.10       # free sets of more than this fraction of the grid: no coarse correction (one-level)
REBUILD = 0.005        # rebuild the coarse operator when F changed by more than this fraction of its cells
FORWARD_Y = np.array([0, 0, 1, 1, 1])  # the sub-block itself and 4 of its 8 neighbours: each pair once
FORWARD_X = np.array([0, 1, -1, 0, 1])
FAST = {"reassoc", "contract", "nsz"}  # reductions may be reordered (vectorised); no NaN/inf tricks


@njit(cache=True, nogil=True)
def coarse_cells(fi, fj, n, row_of, col_of, cx, ncoarse):
    """Coarse cell of each cell of F, and the cumulative cell counts of the coarse cells."""
    cell = np.empty(n, dtype=np.int32)
    for m in range(n):
        cell[m] = row_of[fi[m]] * cx + col_of[fj[m]]
    return cell, buckets(cell, ncoarse)[0]


@njit(cache=True, nogil=True)
def buckets(key, nb):
    """Counting sort of ``key`` (values 0..nb-1): the cumulative counts ``start`` (nb + 1) and the
    indices ``order`` sorted by key (stable), so bucket k holds order[start[k]:start[k + 1]]."""
    start = np.zeros(nb + 1, dtype=np.int64)
    for m in range(key.shape[0]):
        start[key[m] + 1] += 1
    for k in range(nb):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    order = np.empty(key.shape[0], dtype=np.int64)
    for m in range(key.shape[0]):
        order[fill[key[m]]] = m
        fill[key[m]] += 1
    return start, order


@njit(cache=True, inline="always")
def _neighbour(p, d, n, agg, cn, periodic):
    """Sub-block p + d along an axis of n sub-blocks (``agg`` the coarse cell of each, cn of
    them): its index, the shift of its cells in axis lengths (wrapped across a periodic edge) and
    the slot 0..2 of its coarse cell around p's; index -1 beyond an isolated grid's edge or when
    not in a neighbouring coarse cell."""
    q, shift = p + d, 0
    if q < 0 or q >= n:
        if not periodic:
            return -1, 0, 0
        shift = 1 if q < 0 else -1
        q += shift * n
    a = agg[q] - agg[p]
    if periodic and a > 1:
        a -= cn
    elif periodic and a < -1:
        a += cn
    if a < -1 or a > 1:
        return -1, 0, 0
    return q, shift, a + 1


@njit(cache=True, nogil=True)
def near_coefficients(fi, fj, n, S, sy, sx, agg_y, agg_x, cy, cx, slots, table, hy, hx, periodic, ny, nx):
    """C[m, s]: the influence on cell m of F of the cells of F in coarse cell slot
    s = 3 (dy + 1) + dx + 1 around its own, under A: exact coefficients (``table``, offsets -hy..hy,
    -hx..hx) from the cells of the 3 x 3 sub-blocks (S x S cells) around its own, the coefficient of
    the sub-block centres times the cell count from the farther sub-blocks of those coarse cells.
    Wrapped across the edges of a periodic grid, none beyond an isolated one; the kernel is even
    (each pair of cells is visited once)."""
    sub = np.empty(n, dtype=np.int64)
    for m in range(n):
        sub[m] = (fi[m] // S) * sx + fj[m] // S
    start, order = buckets(sub, sy * sx)
    si, sj = fi[order], fj[order]                      # the cells sorted by sub-block
    T = np.zeros((9, n))                               # T[s, a]: C of the a-th sorted cell
    for py in range(sy):                               # exact: each pair of neighbouring sub-blocks once
        for px in range(sx):
            k = py * sx + px
            if start[k] == start[k + 1]:
                continue
            for e in range(5):
                qy, wy, ay = _neighbour(py, FORWARD_Y[e], sy, agg_y, cy, periodic)
                qx, wx, ax = _neighbour(px, FORWARD_X[e], sx, agg_x, cx, periodic)
                if qy < 0 or qx < 0:
                    continue
                q = qy * sx + qx
                s = ay * 3 + ax                        # slot of q around k; of k around q: 8 - s
                for a in range(start[k], start[k + 1]):
                    i0, j0 = si[a] + hy + wy * ny, sj[a] + hx + wx * nx
                    acc = 0.0
                    if q == k:
                        acc = table[hy, hx]
                    for b in range(a + 1 if q == k else start[q], start[q + 1]):
                        v = table[i0 - si[b], j0 - sj[b]]     # the kernel is even
                        acc += v
                        T[8 - s, b] += v
                    T[s, a] += acc
    M = monopoles(start, S, sy, sx, agg_y, agg_x, cx, slots, table, hy, hx, periodic)
    C = np.empty((n, 9))
    for a in range(n):
        m = order[a]
        for s in range(9):
            C[m, s] = T[s, a] + M[sub[m], s]
    return C


@njit(cache=True, nogil=True)
def monopoles(start, S, sy, sx, agg_y, agg_x, cx, slots, table, hy, hx, periodic):
    """M[k, s]: the influence on a cell of sub-block k of the cells of F in the sub-blocks q of
    coarse slot s around k's coarse cell that are not next to k, each taken at q's centre
    (``start``: cumulative cell counts of the sub-blocks; ``slots``: the coarse cells around each,
    -1 beyond an isolated grid). Only the non-empty sub-blocks are visited, listed by coarse cell."""
    nsub = sy * sx
    filled = np.flatnonzero(start[1:] > start[:-1])    # the non-empty sub-blocks, by coarse cell
    first, by_cell = buckets(agg_y[filled // sx] * cx + agg_x[filled % sx], slots.shape[0])
    listed = filled[by_cell]
    M = np.zeros((nsub, 9))
    for a in range(first[-1]):
        k = listed[a]
        py, px = k // sx, k % sx
        around = slots[agg_y[py] * cx + agg_x[px]]
        for e in range(9):
            c = around[e]
            if c < 0:
                continue
            acc = 0.0
            for b in range(first[c], first[c + 1]):
                q = listed[b]
                dy, dx = q // sx - py, q % sx - px
                if periodic:                            # the image in the neighbouring coarse cell
                    dy = (dy + sy // 2) % sy - sy // 2
                    dx = (dx + sx // 2) % sx - sx // 2
                if abs(dy) > 1 or abs(dx) > 1:
                    acc += (start[q + 1] - start[q]) * table[hy - dy * S, hx - dx * S]
            M[k, e] = acc
    return M


@njit(cache=True, nogil=True)
def add_near(E, C, agg, slots):
    """E[a, b] += the near coefficients C of the cells of aggregate a towards aggregate b."""
    for m in range(C.shape[0]):
        a = agg[m]
        for s in range(9):
            b = slots[a, s]
            if b >= 0:
                E[a, b] += C[m, s]


@njit(cache=True, nogil=True)
def locate(fi, fj, n, nx, where, aggregate, row_of, col_of, cx, agg, rows):
    """For the cells of the current F: their aggregate (``agg``, -1: none) and their row of the
    build's near coefficients (``rows``, -1: not in the build's F); returns how many cells of F
    were in the build's F."""
    kept = 0
    for m in range(n):
        i, j = fi[m], fj[m]
        agg[m] = aggregate[row_of[i] * cx + col_of[j]]
        w = where[i * nx + j]
        rows[m] = w
        kept += w >= 0
    return kept


@njit(cache=True, fastmath=FAST, nogil=True)
def restrict(fi, fj, n, nx, v, agg, m_coarse):
    """Zᵀ v: Σ of v over the cells of F of each aggregate."""
    out = np.zeros(m_coarse)
    for m in range(n):
        a = agg[m]
        if a >= 0:
            out[a] += v[fi[m] * nx + fj[m]]
    return out


@njit(cache=True, fastmath=FAST, nogil=True)
def subtract_k(fi, fj, n, Fx, X, agg, rows, C, slots, y, far):
    """X -= K y on the cells of F (layout of the FFT buffer, row length Fx): 9 near products and
    the far part ``far`` (per aggregate)."""
    for m in range(n):
        a = agg[m]
        if a < 0:
            continue
        acc = far[a]
        w = rows[m]
        if w >= 0:
            for s in range(9):
                b = slots[a, s]
                if b >= 0:
                    acc += C[w, s] * y[b]
        X[fi[m] * Fx + fj[m]] -= acc


@njit(cache=True, fastmath=FAST, nogil=True)
def apply_kt(fi, fj, n, nx, v, agg, rows, C, slots, near, sums):
    """The near part of Kᵀ v (``near``) and the aggregate sums of v (``sums``, for the far part)."""
    near[:] = 0.0
    sums[:] = 0.0
    for m in range(n):
        a = agg[m]
        if a < 0:
            continue
        x = v[fi[m] * nx + fj[m]]
        sums[a] += x
        w = rows[m]
        if w >= 0:
            for s in range(9):
                b = slots[a, s]
                if b >= 0:
                    near[b] += C[w, s] * x


@njit(cache=True, fastmath=FAST, nogil=True)
def prolong(fi, fj, n, nx, s, agg, y, load_control):
    """s += Z y on F, then mean-free on F under load control; returns ||s||²."""
    total = 0.0
    for m in range(n):
        g = fi[m] * nx + fj[m]
        a = agg[m]
        if a >= 0:
            s[g] += y[a]
        total += s[g]
    mean = total / n if load_control and n > 0 else 0.0
    ss = 0.0
    for m in range(n):
        g = fi[m] * nx + fj[m]
        v = s[g] - mean
        s[g] = v
        ss += v * v
    return ss


class CoarseGrid:
    """What the coarse correction of every patch on an operator's grid shares: the coarse cell of
    each row and column, the influence coefficients near a cell (``table``) and between coarse
    cell centres (``far``, zero between neighbours)."""

    def __init__(self, operator):
        ny, nx = operator.shape
        Fy, Fx = operator.fft_shape
        self.shape, self.periodic = (ny, nx), operator.periodic
        S = self.S = SUB
        self.sy, self.sx = -(-ny // S), -(-nx // S)
        self.cy, self.cx = min(CELLS, self.sy // 2), min(CELLS, self.sx // 2)
        self.agg_y = (np.arange(self.sy) * self.cy // self.sy).astype(np.int64)
        self.agg_x = (np.arange(self.sx) * self.cx // self.sx).astype(np.int64)
        self.row_of = self.agg_y[np.arange(ny) // S].astype(np.int32)
        self.col_of = self.agg_x[np.arange(nx) // S].astype(np.int32)
        kernel = np.fft.irfft2(operator.spectrum, s=operator.fft_shape)
        self.hy = 2 * S * -(-self.sy // self.cy)             # two coarse cells
        self.hx = 2 * S * -(-self.sx // self.cx)
        dy, dx = np.arange(-self.hy, self.hy + 1), np.arange(-self.hx, self.hx + 1)
        self.table = np.ascontiguousarray(kernel[np.ix_(dy % Fy, dx % Fx)])
        centre_y = np.bincount(self.row_of, np.arange(ny)) / np.bincount(self.row_of)
        centre_x = np.bincount(self.col_of, np.arange(nx)) / np.bincount(self.col_of)
        ay, ax = np.divmod(np.arange(self.cy * self.cx), self.cx)
        centre_y, centre_x = np.round(centre_y[ay]).astype(int), np.round(centre_x[ax]).astype(int)
        Dy, Dx = ay[:, None] - ay[None, :], ax[:, None] - ax[None, :]
        if self.periodic:
            Dy, Dx = np.abs((Dy + 1) % self.cy - 1), np.abs((Dx + 1) % self.cx - 1)
        near = (np.abs(Dy) <= 1) & (np.abs(Dx) <= 1)
        coefficient = kernel[(centre_y[:, None] - centre_y[None, :]) % Fy, (centre_x[:, None] - centre_x[None, :]) % Fx]
        self.far = np.where(near, 0.0, coefficient)
        slots = np.full((self.cy * self.cx, 9), -1, dtype=np.int64)
        for s, (sy, sx) in enumerate((a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)):
            by, bx = ay + sy, ax + sx
            if self.periodic:
                by, bx = by % self.cy, bx % self.cx
            inside = (by >= 0) & (by < self.cy) & (bx >= 0) & (bx < self.cx)
            slots[inside, s] = (by * self.cx + bx)[inside]
        self.slots = slots

    def near_coefficients(self, fi, fj, n):
        """``near_coefficients`` of the free set F = (fi, fj)[:n] on this grid: (n, 9)."""
        return near_coefficients(fi, fj, n, self.S, self.sy, self.sx, self.agg_y, self.agg_x, self.cy, self.cx,
                                 self.slots, self.table, self.hy, self.hx, self.periodic, *self.shape)

    @staticmethod
    def fits(operator) -> bool:
        """Whether the grid has at least 8 coarse cells per side (each of 2 x 2 sub-blocks or more)."""
        return min(operator.shape) >= 16 * SUB


class CoarseCorrection:
    """The coarse operator of one patch and its application (``balance``, then ``complete``);
    ``active`` is False when the last build's Ẽ was not positive definite (one-level then)."""

    def __init__(self, grid: CoarseGrid):
        self.grid = grid
        self.built = 0                       # cells of F at the last build (0: none)
        self.active = False
        self.where = np.full(grid.shape[0] * grid.shape[1], -1, dtype=np.int32)
        self.builds = 0

    def reset(self):
        """Forget the build (a new solve)."""
        if self.built:
            self.where[self.flat] = -1
        self.built, self.active = 0, False

    def prepare(self, fi, fj, n):
        """Locate the cells of F (n of them) on the coarse operator; rebuild it when F changed by
        more than ``REBUILD`` of the build's cells since the last build."""
        g = self.grid
        ny, nx = g.shape
        if self.built:
            self.agg = np.empty(n, dtype=np.int32)
            self.rows = np.empty(n, dtype=np.int32)
            kept = locate(fi, fj, n, nx, self.where, self.aggregate, g.row_of, g.col_of, g.cx, self.agg, self.rows)
            if (n - kept) + (self.built - kept) <= REBUILD * self.built:
                return
        self.build(fi, fj, n)

    def build(self, fi, fj, n):
        """The coarse operator of the free set F = (fi, fj)[:n]."""
        g = self.grid
        ny, nx = g.shape
        self.reset()
        self.builds += 1
        if n == 0 or n > SPARSE_TO * ny * nx:
            self.built, self.active = 0, False
            return
        cell, start = coarse_cells(fi, fj, n, g.row_of, g.col_of, g.cx, g.cy * g.cx)
        C = g.near_coefficients(fi, fj, n)
        counts = np.diff(start)
        ids = np.flatnonzero(counts)
        aggregate = np.full(g.cy * g.cx, -1, dtype=np.int32)
        aggregate[ids] = np.arange(ids.size)
        slots = aggregate[np.maximum(g.slots[ids], 0)]
        slots[g.slots[ids] < 0] = -1
        self.counts = counts[ids].astype(float)
        self.far = g.far[np.ix_(ids, ids)]
        E = self.counts[:, None] * self.far * self.counts[None, :]
        agg = aggregate[cell]
        add_near(E, C, agg, slots)
        E = 0.5 * (E + E.T)                  # exact in exact arithmetic
        try:
            self.factor = scipy.linalg.cho_factor(E, lower=True, check_finite=False)
            self.active = bool(np.all(np.isfinite(self.factor[0])))
        except np.linalg.LinAlgError:
            self.active = False
        self.C, self.slots, self.aggregate, self.agg = C, slots, aggregate, agg
        self.rows = np.arange(n, dtype=np.int32)
        self.flat = fi[:n].astype(np.int64) * nx + fj[:n]
        self.where[self.flat] = self.rows
        self.built = n
        self.near, self.sums = np.zeros(ids.size), np.zeros(ids.size)

    def solve(self, g):
        """Ẽ⁻¹ g."""
        return scipy.linalg.cho_solve(self.factor, g, check_finite=False)

    def balance(self, fi, fj, n, r, X, Fx):
        """First half: y1 = Ẽ⁻¹ Zᵀ r, and X = Q r = r - K y1 on F (X holds r there)."""
        nx = self.grid.shape[1]
        y1 = self.y1 = self.solve(restrict(fi, fj, n, nx, r, self.agg, self.counts.size))
        subtract_k(fi, fj, n, Fx, X, self.agg, self.rows, self.C, self.slots, y1, self.far @ (self.counts * y1))

    def complete(self, fi, fj, n, s, load_control) -> float:
        """Second half, from s = P1 Q r on F: s <- s + Z (y1 - Ẽ⁻¹ Kᵀ s) (mean-free on F under load
        control); returns ||s||²."""
        nx = self.grid.shape[1]
        apply_kt(fi, fj, n, nx, s, self.agg, self.rows, self.C, self.slots, self.near, self.sums)
        y2 = self.solve(self.near + self.counts * (self.far @ self.sums))
        return prolong(fi, fj, n, nx, s, self.agg, self.y1 - y2, load_control)

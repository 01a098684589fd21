"""Interacting asperities: the interaction sums and the two minimisation routes of the
interacting asperity models (thesis §1.2.2.2–1.2.2.3, Eqs. 1.10–1.12, 1.23; §4.2.2, Eqs. 2.21–2.23,
4.1). ``multiscale.micro.asperity.AsperityModel`` drives them.

With interaction the summit's displacement is its own approach plus the surface displacement
caused at its centre by every other contact (Eqs. 1.10, 1.23, 2.19):
``w_k = w_self(a_k) + sum_l u_l(a_l; x_k − x_l)``; contact requires w_k >= delta_k, with equality
where a_k > 0 (Eq. 1.11). Two solution routes (unknown: contact size a >= 0 per asperity):

* ``route="kinematic"`` — the least-squares objective of Eq. 1.12, O = ½ sum_k (w_k − delta_k)²,
  minimised by scipy's trust-region Gauss–Newton (``least_squares`` "trf" with LSMR inner solves: a
  truncated Newton method whose Hessian-vector products J^T J v are analytic), or by ``tnc`` /
  ``l-bfgs-b`` on O with the analytic gradient J^T r. One signed variable per summit carries both
  a >= 0 (x > 0) and the gap of a summit out of contact (x < 0), so O vanishes exactly at the
  solution of Eq. 1.11 and no active-set loop is needed (the literal form, O summed over the
  summits "supposed in contact" with a >= 0 bounds, needs one and cycles on summits at the edge).
* ``route="energy"`` — the total complementary energy (§4.2.2, Eqs. 2.21–2.23, 4.1)
  U = sum_j [W_j(a_j) − P_j(a_j) delta_j + ½ P_j sum_{l≠j} u_l(a_l; x_j − x_l)], where
  W = ∫ P'(a) w_self(a) da is the self energy (Hertz: W = 3/5 P w_self, i.e. the 6/5 of §4.2.2;
  Eq. 2.23's 2/5 is a misprint, it does not reproduce Hertz), minimised over a >= 0 (bounds) by
  scipy's ``l-bfgs-b`` or the truncated Newton ``tnc`` (Nash, the thesis' algorithm; its
  Hessian-vector products are gradient differences), both with the analytic gradient. U is
  minimised in a force-like variable ∝ a³, in which it is convex (two contacts: spacing > 2a/π)
  and its gradient is the gap of each summit.

Both routes stop on the complementarity residual max_k |min(P_k/P̄, gap_k/delta)|. They evaluate
the interaction at the receiving summit's centre as the thesis does, so their solutions differ by
the non-reciprocity of that approximation, O((a/r)²) of the interaction (tests: < 0.5 % of force
and area on a fractal surface).

Interaction sums (vectorised, no loop over pairs): every contact acts on every other through the
point-force response ``g(r)`` of the solid (``P_l g(r)``, a dense matrix–vector product over the
candidate summits, stored up to ~5600 candidates, rows recomputed beyond), and pairs closer than
``cutoff · a_ref,l`` (``scipy.spatial.cKDTree``) add the near-field correction ``u_l − P_l g``.
a_ref >= a bounds the final contact size: it comes from the warm start or from a screening pass
with point forces only, and is enlarged (and the solve repeated) if a contact outgrows it. For a
Hertz contact of semi-axes a >= b the correction is the quadrupole term,
|u − P g| <= (2a² − b²)/(10 r²) · P g (circular: (a/r)²/10), with the higher orders < 0.211 (a/r)²
P g for r >= 3a (measured over r = 3a … 60a: 0.104 circular, 0.2101 at R2/R1 = 1e-3), so the neglected part of every interaction sum is at most
``far_field_coefficient / cutoff²`` of it: ``interaction_tol`` (default 1e-3) sets
cutoff = sqrt(0.211 / interaction_tol) ≈ 14.5, and results report the bound. With many candidates
the minimisation runs on the summits in contact after screening or within 5 % of delta of
touching; the final state is checked on every candidate (those that penetrate join, re-solve).
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass

import numpy as np
from scipy import optimize, sparse
from scipy.sparse.linalg import LinearOperator
from scipy.spatial import cKDTree

from multiscale.micro.asperity_laws import AsperityLaw

_FLOOR = 1e-10          # smallest relative size a/a_ref used where derivatives are divided by a
_DENSE_BYTES = 256e6    # far-field matrix kept in memory up to this size (~5600 candidates)
_LS_CALLBACK = "callback" in inspect.signature(optimize.least_squares).parameters   # scipy >= 1.16
# TNC stops where the energy stalls in its last digits ("|f_n - f_(n-1)| ~= 0"), which with scipy
# 1.18 left the thesis set-2 surface at a complementarity residual of 1.1e-6 > tol 1e-6; a restart
# from there (TNC rescales its variables) goes on, up to this many times
TNC_RESTARTS = 3


class Interactions:
    """Interaction sums among candidate summits ``idx`` (positions x, y).

    u_int = G P + N(a): G the point-response matrix (zero diagonal), N the near-field correction
    u_l − P_l g over pairs with r < cutoff · a_ref[source] (``set_near``), a_ref >= a."""

    def __init__(self, law: AsperityLaw, x, y, idx):
        self.law, self.idx = law, np.asarray(idx)
        n = self.n = len(self.idx)
        self.xy = np.column_stack([x, y])
        self.tree = cKDTree(self.xy)
        self.G = None
        if n * n * 8 <= _DENSE_BYTES:
            self.G = self._rows(np.arange(n))
        self.evaluations = 0
        self.set_near(np.zeros(n), 1.0)

    def subset(self, sel) -> "Interactions":
        """The same sums restricted to the summits ``sel`` (bool over ``idx``)."""
        sub = object.__new__(Interactions)
        sub.law, sub.idx = self.law, self.idx[sel]
        sub.n, sub.xy = len(sub.idx), self.xy[sel]
        sub.tree = cKDTree(sub.xy)
        sub.G = None if self.G is None else self.G[np.ix_(sel, sel)]
        sub.evaluations = 0
        sub.set_near(np.zeros(sub.n), 1.0)
        return sub

    def set_near(self, a_ref, cutoff):
        """Near-field pairs (source, receiver) closer than cutoff · a_ref[source]."""
        self.a_ref = np.asarray(a_ref, dtype=float)
        reach = cutoff * self.a_ref
        src = np.nonzero(reach > 0)[0]
        lists = self.tree.query_ball_point(self.xy[src], reach[src], return_sorted=False)
        counts = np.fromiter((len(v) for v in lists), dtype=int, count=len(lists))
        dst = np.fromiter((j for v in lists for j in v), dtype=int, count=int(counts.sum()))
        src = np.repeat(src, counts)
        keep = dst != src
        src, dst = src[keep], dst[keep]
        d = self.xy[dst] - self.xy[src]
        self.src, self.dst, self.ddx, self.ddy = src, dst, d[:, 0], d[:, 1]
        self.g_near = self.law.point_response(np.hypot(d[:, 0], d[:, 1]))

    def _rows(self, rows):
        """Rows ``rows`` of G, computed."""
        x, y = self.xy[:, 0], self.xy[:, 1]
        r = np.subtract.outer(x[rows], x)
        r *= r
        t = np.subtract.outer(y[rows], y)
        t *= t
        r += t
        np.sqrt(r, out=r)
        i = np.arange(len(rows))
        r[i, rows] = 1.0
        g = self.law.point_response(r)
        g[i, rows] = 0.0
        return g

    def far(self, f):
        """G f over the non-zero sources only (G is symmetric); rows computed in blocks when G is
        not stored."""
        nz = np.nonzero(f)[0]
        if self.G is None:
            out = np.zeros(self.n)
            step = max(1, int(_DENSE_BYTES / (8 * self.n)))
            for i0 in range(0, len(nz), step):
                rows = nz[i0:i0 + step]
                out += f[rows] @ self._rows(rows)
            return out
        if len(nz) < 0.6 * self.n:
            return f[nz] @ self.G[nz]
        return self.G @ f

    def evaluate(self, a, a_low=None):
        """Interaction state at sizes ``a`` (>= 0, one per candidate); derivatives are taken at
        max(a, a_low) (their limits for contacts about to open)."""
        self.evaluations += 1
        law, idx = self.law, self.idx
        ad = a if a_low is None else np.maximum(a, a_low)
        P, dP = law.force(a, idx)
        w, dw = law.approach(a, idx)
        if a_low is not None:
            dP, dw = law.force(ad, idx)[1], law.approach(ad, idx)[1]
        live = a[self.src] > 0
        src, dst, g = self.src[live], self.dst[live], self.g_near[live]
        u, du = law.displacement(a[src], idx[src], self.ddx[live], self.ddy[live], self.a_ref[src])
        corr, dcorr = u - P[src] * g, du - dP[src] * g
        far = self.far(P)
        near = np.bincount(dst, corr, minlength=self.n)
        return _State(a, P, dP, w, dw, far, near, src, dst, corr, dcorr)


@dataclass
class _State:
    """Contact state of the candidates at sizes ``a`` (``Interactions.evaluate``); per candidate."""

    a: np.ndarray
    P: np.ndarray
    dP: np.ndarray
    w: np.ndarray
    dw: np.ndarray
    far: np.ndarray      # G P
    near: np.ndarray     # near-field corrections summed per receiver
    src: np.ndarray
    dst: np.ndarray
    corr: np.ndarray
    dcorr: np.ndarray    # d corr / d a[src]

    @property
    def u(self):
        return self.far + self.near


def minimise(inter: Interactions, dk_all, active_all, a_free, route, method, tol, max_iter, initial):
    """Run one route on the active summits of the structure; returns sizes for every asperity
    and statistics. ``a_free``: non-interacting sizes (start and upper bound)."""
    idx = inter.idx
    dk = dk_all[idx]
    cand = active_all[idx]                          # the structure may hold a superset of candidates
    a0 = a_free[idx] if initial is None else np.minimum(
        np.maximum(np.asarray(initial, dtype=float)[idx], 0.0), a_free[idx])
    a0 = np.where(cand, a0, 0.0)
    ev0 = inter.evaluations
    if route == "energy":
        a, its, res = _energy_route(inter, dk, cand, a_free[idx], a0, method, tol, max_iter)
    else:
        a, its, res = _kinematic_route(inter, dk, cand, a_free[idx], a0, method, tol, max_iter)
    out = np.zeros(len(dk_all))
    out[idx] = a
    return out, dict(route=route, method=method, iterations=its, evaluations=inter.evaluations - ev0,
                     residual=res, converged=bool(res <= tol))


def _complementarity(P, P_unit, gap, delta):
    """max_k |min(P_k / P_unit, gap_k / delta)| over candidate summits: zero iff every summit either
    carries no force or has no gap (Eq. 1.11); P_unit is the mean non-interacting force."""
    return float(np.max(np.abs(np.minimum(P / P_unit, gap / delta)), initial=0.0))


def _drop_negligible(a, P, P_unit, tol):
    """Contacts carrying less than tol · P_unit are zero within the solver tolerance."""
    return np.where(P > tol * P_unit, a, 0.0)


class _Stop:
    """Callback that ends a scipy minimiser once the complementarity residual is below ``tol``
    (TNC cannot be stopped from a callback; it runs to its own tolerances)."""

    def __init__(self, measure, tol):
        self.measure, self.tol = measure, tol

    def __call__(self, x, *args):
        if self.measure(np.asarray(x)) <= self.tol:
            raise StopIteration


def _energy_route(inter, dk, cand, a_top, a_init, method, tol, max_iter):
    """Minimise the complementary energy over z = c (P_top/P_u)(a/a_top)³ >= 0 (a_top, P_top the
    non-interacting size and force, P_u their mean: z ∝ force for Hertz), U in units P_u max(delta_k);
    c_k makes d²U/dz_k² = 1 at the non-interacting state. dU/dz_k is the gap of summit k (energy
    route) over delta, divided by c_k; the minimiser stops on the complementarity residual."""
    law, idx = inter.law, inter.idx
    am = np.where(cand, a_top, 1.0)
    Pm = law.force(am, idx)[0]
    ref = float(dk.max())
    Pu = float(np.mean(Pm[cand]))
    dPm, dwm = law.force(am, idx)[1], law.approach(am, idx)[1]
    s = Pm / Pu * np.sqrt(dwm / dPm * Pu / ref)        # unit curvature at the non-interacting state
    t_floor = _FLOOR**3
    last = {}

    def sizes(z):
        t = np.maximum(z / s, t_floor)
        a = am * np.cbrt(t)
        return np.where(cand & (z > 0), a, 0.0), a / (3 * t * s)

    def fun(z):
        a, dadz = sizes(z)
        st = inter.evaluate(a, np.where(cand, _FLOOR * am, 0.0))
        W, dW = law.energy(a, idx)
        U = np.sum(W - st.P * dk + 0.5 * st.P * st.u)
        grad = _energy_gradient(st, dW, dk, inter.n)
        gap = np.divide(grad, st.dP, out=np.zeros_like(grad), where=st.dP > 0)
        last.update(z=z.copy(), a=a, P=st.P, gap=gap)
        return U / (Pu * ref), np.where(cand, grad * dadz / (Pu * ref), 0.0)

    def measure(z):
        if "z" not in last or not np.array_equal(z, last["z"]):
            fun(z)
        return _complementarity(last["P"][cand], Pu, last["gap"][cand], ref)

    z0 = s * (np.where(cand, a_init, 0.0) / am) ** 3
    bounds = [(0.0, None) if c else (0.0, 0.0) for c in cand]
    opts = {"maxfun": max_iter * 10, "gtol": 1e-3 * tol}
    if method == "tnc":
        opts.update(xtol=-1, ftol=-1, maxCGit=-1, accuracy=1e-14)
    else:
        opts.update(ftol=0.0, maxcor=20, maxiter=max_iter, maxls=50)
    res = optimize.minimize(fun, z0, jac=True, method=method.upper(), bounds=bounds, options=opts,
                            callback=None if method == "tnc" else _Stop(measure, tol))
    resid, nit = measure(res.x), int(getattr(res, "nit", 0))
    for _ in range(TNC_RESTARTS if method == "tnc" else 0):      # TNC stops where f stalls in its last digits
        if resid <= tol:
            break
        res = optimize.minimize(fun, res.x, jac=True, method="TNC", bounds=bounds, options=opts)
        resid, nit = measure(res.x), nit + int(getattr(res, "nit", 0))
    return _drop_negligible(last["a"], last["P"], Pu, tol), nit, resid


def _energy_gradient(st: _State, dW, dk, n):
    """dU/da: dW − P' delta_k + P' (G P) + ½ P' N + ½ sum_k P_k d corr_(m→k)/da_m."""
    back = np.bincount(st.src, st.P[st.dst] * st.dcorr, minlength=n)
    return dW - st.dP * dk + st.dP * st.far + 0.5 * st.dP * st.near + 0.5 * back


def _kinematic_route(inter, dk, cand, a_top, a_init, method, tol, max_iter):
    """Eq. 1.12 as a square least-squares problem in one signed variable per candidate summit.

    x >= 0: in contact, a = a_top sqrt(x/s) (a_top the non-interacting size, s = delta_k/max(delta_k);
    Hertz: x = self approach / max delta_k); x < 0: out of contact, a = 0 and x · max(delta_k) is
    minus its gap. The residual r_k = w_k − delta_k (w_k = self approach, or x · max(delta_k) out of
    contact, plus interactions) vanishes exactly at the solution of Eq. 1.11 with a >= 0, so no
    active-set loop is needed (the literal bound-constrained form needs one and cycles on summits
    at the edge of contact)."""
    law, idx, n = inter.law, inter.idx, inter.n
    C = np.nonzero(cand)[0]
    am = np.where(cand, a_top, 1.0)
    ref = float(dk.max())
    s = np.where(cand, np.maximum(dk, 0.0) / ref, 1.0)
    cache = {}

    def state(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            full = np.zeros(n)
            full[C] = x
            on = full > 0
            t = np.maximum(full / s, _FLOOR**2)
            a = np.where(on, am * np.sqrt(t), 0.0)
            dadx = np.where(on, am * np.sqrt(t) / (2 * t * s), 0.0)
            st = inter.evaluate(a)
            w = np.where(on, st.w, full * ref)
            cache[key] = (st, a, w, dadx, np.where(on, st.dw * dadx, ref))
        return cache[key]

    def resid(x):
        st, _, w, _, _ = state(x)
        return (w + st.u - dk)[C] / ref

    def jac(x):
        st, _, _, dadx, diag = state(x)
        near = sparse.csr_matrix((st.dcorr * dadx[st.src] / ref, (st.dst, st.src)), shape=(n, n))[C][:, C]
        d, c = diag[C] / ref, st.dP * dadx / ref

        def mv(v):
            f = np.zeros(n)
            f[C] = v
            return d * v + inter.far(c * f)[C] + near @ v

        def rmv(y):
            f = np.zeros(n)
            f[C] = y
            return d * y + (c * inter.far(f))[C] + near.T @ y

        return LinearOperator((len(C), len(C)), matvec=mv, rmatvec=rmv, dtype=float)

    Pu = float(np.mean(law.force(am[C], idx[C])[0]))

    def measure(x):
        st, a, w, _, _ = state(x)
        gap = np.where(a > 0, w + st.u - dk, st.u - dk)    # out of contact: the true gap
        return _complementarity(np.where(a > 0, st.P, 0.0)[C], Pu, gap[C], ref)

    stop = _Stop(measure, tol)
    x0 = s[C] * (a_init[C] / am[C]) ** 2
    if method == "trf":
        early = {"callback": lambda intermediate_result: stop(intermediate_result.x)} if _LS_CALLBACK else {}
        r = optimize.least_squares(resid, x0, jac=jac, method="trf", tr_solver="lsmr", x_scale=1.0,
                                   ftol=None, xtol=1e-3 * tol, gtol=None, max_nfev=max_iter, **early)
        x, its = r.x, r.nfev
    else:
        def obj(x):
            res = resid(x)
            return 0.5 * res @ res, jac(x).rmatvec(res)
        opts = {"maxfun": max_iter * 10, "gtol": 1e-3 * tol**2}
        if method == "tnc":
            opts.update(xtol=-1, ftol=-1, maxCGit=-1, accuracy=1e-14)
        else:
            opts.update(ftol=0.0, maxiter=max_iter, maxcor=20, maxls=50)
        r = optimize.minimize(obj, x0, jac=True, method=method.upper(), options=opts,
                              callback=None if method == "tnc" else stop)
        x, its = r.x, int(getattr(r, "nit", 0))
    resid = measure(x)
    st, a = state(x)[:2]
    return _drop_negligible(a, st.P, Pu, tol), its, resid


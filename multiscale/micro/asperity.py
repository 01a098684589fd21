"""Asperity-based micro-contact models (thesis ch. 1 §1.2.2, §2.4.2, §4.2.2).

A rough surface is a set of paraboloidal summits (``AsperityTable`` from
``surface.find_asperities``) pressed by a rigid flat moved down by ``delta`` from the first touch of
the highest summit. Summit k (height z_k) is asked to move ``delta_k = delta − (z_M − z_k)``
(Eqs. 1.6, 2.20). The four models of the thesis, numbered as in §1.3 (and ``demos/ch1_asperity_models.py``):

1. elliptic with interaction (Eqs. 1.16–1.23);
2. circular with interaction (Eqs. 1.10–1.12; Ciavarella-type);
3. elliptic, no interaction (Eqs. 1.1–1.8, F1(e), A1(e));
4. circular, no interaction (Eqs. 1.6–1.9, F1 = A1 = 1, R = sqrt(R1 R2)).

Models 1–2 add the surface displacement of every other contact at each summit (Eqs. 1.10, 1.23,
2.19) and are solved by the kinematic (Eq. 1.12) or the energy (§4.2.2) route of
``asperity_interaction``. A summit lying inside the (non-interacting) contact ellipse of a higher
summit — twin peaks, ~1 % of the summits of a fractal surface — would make both problems ill-posed
(two energy minima, a singular Jacobian); it is absorbed by the higher summit
(``AsperityResult.absorbed``). The contact law of each summit (Hertz circular or elliptic, or a
layered solid) is an ``asperity_laws.AsperityLaw``.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree
from tqdm import tqdm

from multiscale.errors import (ConvergenceError, InputError, check_count, check_field, check_flag, check_positive,
                               check_real)
from multiscale.micro.asperity_interaction import Interactions, minimise
from multiscale.micro.asperity_laws import AsperityLaw, check_table, hertz_law
from multiscale.micro.surface import AsperityTable, Surface, find_asperities, statistics

_SCREEN = 400           # more active candidates than this: screening pass with point forces only
MAX_ITER = 2000         # minimiser iterations of a solve
OVERLAP = 0.1           # share of the real area in overlapping contacts beyond which a result is warned of


# ----------------------------------------------------------------------------- results
@dataclass
class AsperityResult:
    """Contact state of an asperity model at one approach."""

    approach: float            #: m, rigid approach delta from the first touch of the highest summit
    force: float               #: N, total force F (Eq. 1.7)
    area: float                #: m², real contact area A (Eq. 1.8)
    mean_pressure: float       #: Pa, F / A0
    area_fraction: float       #: -, A / A0
    #: m, g_n = (z_M − z̄) − delta (Eq. 1.9): the flat's height above the mean plane of the undeformed
    #: surface (negative once below it), not the deformed mean gap of ``contact.ContactResult.mean_gap``
    mean_gap: float
    kappa: float | None        #: -, (A/A0) E* sqrt(<|grad h|²>) / p_n (§1.3.2); None without contact/slope
    semi_axes: np.ndarray      #: m, (N, 2): major a and minor b of each contact (0, 0 out of contact)
    forces: np.ndarray         #: N, force of each asperity
    contact: np.ndarray        #: bool, asperity in contact
    pressure: np.ndarray | None  #: Pa, (ny, nx) map of Eq. 1.4 on the surface grid (None without grid)
    n_contacts: int
    absorbed: np.ndarray       #: indices of summits absorbed by a higher one (interacting models only)
    interaction: bool
    route: str                 #: "direct" (no interaction), "kinematic" or "energy"
    method: str                #: scipy minimiser
    iterations: int            #: minimiser iterations (all active-set passes)
    evaluations: int           #: interaction-sum evaluations
    #: max |min(P_k/P̄, gap_k/delta)| over candidates (route's own gap; P̄ the mean non-interacting
    #: force): the complementarity of Eq. 1.11
    residual: float
    converged: bool
    truncation: float          #: relative bound on the neglected part of each interaction sum
    wall_time: float           #: s
    overlap: float = 0.0       #: -, share of ``area`` in contacts whose area-equivalent circles overlap another's
    notes: tuple = ()          #: where the result leaves the models' range (separate contacts), warned of by ``solve``


@dataclass
class AsperityCurve:
    """Results of one model along increasing approaches (arrays per load step)."""

    approach: np.ndarray       # m
    force: np.ndarray          # N
    area: np.ndarray           # m²
    mean_pressure: np.ndarray  # Pa
    area_fraction: np.ndarray  # -
    mean_gap: np.ndarray       # m
    kappa: np.ndarray          # -, NaN where undefined (no contact)
    n_contacts: np.ndarray
    wall_time: float           # s, whole curve
    results: list = field(default_factory=list, repr=False)


class AsperityConvergenceError(ConvergenceError):
    """The asperity-model minimiser stopped above its tolerance."""


class AsperityWarning(UserWarning):
    """A result beyond the asperity models' range: contacts that overlap, a real area above the nominal."""


# ----------------------------------------------------------------------------- model
class AsperityModel:
    """One of the four asperity models on a table of summits (thesis §1.2.2).

    ``table``: ``AsperityTable`` (positions, heights; radii are the law's business); ``law``: an
    ``AsperityLaw`` with one entry per asperity; ``interaction``: models 3–4 (True) or 1–2.
    ``surface`` (optional) gives the nominal area A0, the RMS slope for kappa, the mean plane z̄
    of Eq. 1.9 and the grid of the pressure map; without it give ``nominal_area`` (and
    ``rms_slope``); z̄ is then the mean summit height (Eq. 1.9 literally).
    ``interaction_tol``: bound on the relative truncation error of the interaction sums (the
    cut-off is never below 3 contact sizes; ``truncation`` reports the bound in force).
    """

    def __init__(self, table: AsperityTable, law: AsperityLaw, *, interaction: bool = True,
                 surface: Surface | None = None, nominal_area: float | None = None,
                 rms_slope: float | None = None, interaction_tol: float = 1e-3):
        check_table(table)
        if not isinstance(law, AsperityLaw):
            raise InputError("law", law, "an AsperityLaw (e.g. hertz_law(table, solid))")
        if law.n != len(table):
            raise InputError("law", law.n, f"law has {law.n} asperities, the table {len(table)}")
        if surface is not None and not isinstance(surface, Surface):
            raise InputError("surface", surface, "a multiscale.micro.surface.Surface")
        self.table, self.law, self.surface = table, law, surface
        self.interaction = check_flag("interaction", interaction)
        if nominal_area is None:
            if surface is None:
                raise InputError("nominal_area", None, "give the nominal area A0 [m²] or the surface")
            Lx, Ly = surface.size
            nominal_area = Lx * Ly
        self.nominal_area = check_positive("nominal_area", nominal_area)
        if rms_slope is None and surface is not None:
            rms_slope = float(statistics(surface).rms_slope)
        self.rms_slope = None if rms_slope is None else check_positive("rms_slope", rms_slope)
        tol = check_positive("interaction_tol", interaction_tol)
        self.cutoff = max(np.sqrt(law.far_field_coefficient / tol), 3.0)
        self.truncation = law.far_field_coefficient / self.cutoff**2
        self.z_max = float(table.height.max())
        self.mean_height = float(surface.heights.mean() if surface is not None else table.height.mean())
        self._cache: Interactions | None = None

    @classmethod
    def from_surface(cls, surface: Surface, solid, shape: str = "elliptic", *, interaction: bool = True,
                     exact: bool = True, **kwargs) -> "AsperityModel":
        """Detect the summits of ``surface`` and build the Hertz model ``shape`` on ``solid``."""
        table = find_asperities(surface)
        if len(table) == 0:
            raise InputError("surface", "no summits", "the surface has no asperity with finite radii")
        return cls(table, hertz_law(table, solid, shape, exact=exact), interaction=interaction,
                   surface=surface, **kwargs)

    # -- public ---------------------------------------------------------------------------
    def solve(self, delta: float, *, route: str = "energy", method: str | None = None, tol: float = 1e-6,
              max_iter: int = MAX_ITER, partial: bool = False, raster: bool = True,
              initial=None) -> AsperityResult:
        """Contact state at rigid approach ``delta`` [m] >= 0.

        ``route``: "energy" (methods "l-bfgs-b" default, "tnc") or "kinematic" ("trf" default,
        "tnc", "l-bfgs-b"); ignored without interaction. ``tol``: bound on the complementarity
        residual (relative to delta). ``initial``: sizes [m] per asperity to start from.
        Raises ``AsperityConvergenceError`` above ``tol`` unless ``partial``. The models hold for
        separate contacts (low loads): a result whose overlapping contacts hold more than ``OVERLAP``
        of the real area, or whose real area exceeds the nominal one, is warned of
        (``AsperityWarning``, ``AsperityResult.notes``).
        """
        result = self._solve(delta, route, method, tol, max_iter, partial, raster, initial)
        for note in result.notes:
            warnings.warn(note, AsperityWarning, stacklevel=2)
        return result

    def _solve(self, delta, route, method, tol, max_iter, partial, raster, initial) -> AsperityResult:
        delta = _check_delta(delta)
        check_positive("tol", tol)
        max_iter = check_count("max_iter", max_iter)
        for name, flag in (("partial", partial), ("raster", raster)):
            check_flag(name, flag)
        route, method = _check_route(route, method)
        if initial is not None:
            initial = check_field("initial", initial)
            if initial.shape != (len(self.table),):
                raise InputError("initial", initial, f"{len(self.table)} finite contact sizes [m]")
        t0 = time.perf_counter()
        dk = delta - (self.z_max - self.table.height)
        a = np.zeros(len(self.table))
        stats = dict(route="direct", method="closed form", iterations=0, evaluations=0, residual=0.0,
                     converged=True)
        cand = np.nonzero(dk > 0)[0]
        a_free = np.zeros(len(self.table))
        a_free[cand] = self.law.size_at(dk[cand], cand)
        absorbed = np.zeros(0, dtype=int)
        if self.interaction and len(cand) > 1:
            absorbed = self._absorbed(cand, a_free)
            active = dk > 0
            active[absorbed] = False
            a, stats = self._interacting(dk, active, a_free, route, method, tol, max_iter, initial)
            if not stats["converged"] and not partial:
                res = self._result(delta, a, stats, t0, raster, absorbed)
                raise AsperityConvergenceError(
                    f"{route} route ({method}) stopped at residual {stats['residual']:.3g} > tol {tol:g}",
                    [stats["residual"]], res)
        else:
            a = a_free
        return self._result(delta, a, stats, t0, raster, absorbed)

    def _absorbed(self, cand, a_free) -> np.ndarray:
        """Summits lying inside the non-interacting contact of a higher summit (twin peaks).

        The interaction models assume separate contacts; a summit inside another one's contact
        makes them ill-posed (two local minima of the energy, a singular Jacobian of Eq. 1.12), so
        such a summit is absorbed by the higher one and carries no contact of its own."""
        t = self.table
        xy = np.column_stack([t.x[cand], t.y[cand]])
        pairs = cKDTree(xy).query_pairs(float(a_free[cand].max()), output_type="ndarray")
        if not len(pairs):
            return np.zeros(0, dtype=int)
        i, j = cand[pairs[:, 0]], cand[pairs[:, 1]]
        low, high = np.where(t.height[i] < t.height[j], i, j), np.where(t.height[i] < t.height[j], j, i)
        inside = self.law.pressure(a_free[high], high, t.x[low] - t.x[high], t.y[low] - t.y[high]) > 0
        return np.unique(low[inside])

    def curve(self, deltas, *, route: str = "energy", method: str | None = None, tol: float = 1e-6,
              raster: bool = False, progress: bool = False) -> AsperityCurve:
        """Solve at increasing approaches ``deltas`` [m], each step warm-started from the last."""
        d = check_field("deltas", deltas).ravel()
        check_flag("progress", progress)
        if d.size == 0 or np.any(d < 0) or np.any(np.diff(d) < 0):
            raise InputError("deltas", deltas, "a non-empty increasing sequence of approaches >= 0")
        t0 = time.perf_counter()
        dk = d[-1] - (self.z_max - self.table.height)
        cand = np.nonzero(dk > 0)[0]
        if self.interaction and len(cand) > 1:
            self._interactions(cand)                 # one far-field matrix for the whole curve
        steps = d
        if progress:
            steps = tqdm(d, desc="asperity model", unit="step")
        results, prev = [], None
        for delta in steps:
            init = None
            if prev is not None and prev.approach > 0:
                init = prev.semi_axes[:, 0] * np.sqrt(delta / prev.approach)
            prev = self._solve(delta, route, method, tol, MAX_ITER, False, raster, init)
            results.append(prev)
        beyond = [r for r in results if r.notes]
        if beyond:                    # once: where first, and the notes of the last step that has them
            warnings.warn(f"at approaches from {beyond[0].approach:.3g} m: {'; '.join(beyond[-1].notes)}",
                          AsperityWarning, stacklevel=2)
        kappa = np.array([np.nan if r.kappa is None else r.kappa for r in results])
        return AsperityCurve(
            approach=d, force=np.array([r.force for r in results]), area=np.array([r.area for r in results]),
            mean_pressure=np.array([r.mean_pressure for r in results]),
            area_fraction=np.array([r.area_fraction for r in results]),
            mean_gap=np.array([r.mean_gap for r in results]), kappa=kappa,
            n_contacts=np.array([r.n_contacts for r in results]), wall_time=time.perf_counter() - t0,
            results=results)

    # -- internals ------------------------------------------------------------------------
    def _interactions(self, cand) -> "Interactions":
        c = self._cache
        if c is None or not np.all(np.isin(cand, c.idx)):
            t = self.table
            c = self._cache = Interactions(self.law, t.x[cand], t.y[cand], cand)
        return c

    def _interacting(self, dk, active, a_free, route, method, tol, max_iter, initial):
        """Minimise with a near-field list sized by a_ref >= a (from the initial sizes or, for many
        candidates, from a screening pass with point-force interactions only), on the summits in
        contact at the start or within 5 % of delta of touching; a_ref grows, and excluded summits
        that penetrate join, until the solution is verified on every candidate."""
        full = self._interactions(np.nonzero(dk > 0)[0])
        totals = dict(iterations=0, evaluations=0)
        ref = float(dk.max())

        def run(inter, a_ref, start, tol_, route=route, method=method):
            inter.set_near(a_ref[inter.idx], self.cutoff)
            a, st = minimise(inter, dk, active, a_free, route, method, tol_, max_iter, start)
            totals["iterations"] += st["iterations"]
            totals["evaluations"] += st["evaluations"]
            return a, st

        many = active.sum() > _SCREEN
        if initial is None and many:
            initial, _ = run(full, np.zeros_like(a_free), None, 1e-3, "energy", "l-bfgs-b")
        if initial is None:
            a_ref = a_free
        else:
            initial = np.minimum(np.maximum(np.asarray(initial, dtype=float), 0.0), a_free)
            a_ref = np.minimum(a_free, 1.3 * initial + 0.1 * a_free)
        keep = active.copy()
        if many:
            keep &= (initial > 0) | (self._gaps(full, initial, a_ref, dk) < 0.05 * ref)
        for _ in range(10):
            inter = full if keep.sum() == active.sum() else full.subset(keep[full.idx])
            a, st = run(inter, a_ref, initial, tol)
            over = a > a_ref
            bad = np.zeros_like(keep)
            if inter is not full:
                bad = ~keep & active & (self._gaps(full, a, a_ref, dk) < -tol * ref)
            if not over.any() and not bad.any():
                break
            a_ref = np.where(over, np.minimum(a_free, 1.5 * a), a_ref)
            keep |= bad
            initial = a
        st.update(totals)
        return a, st

    def _gaps(self, inter, a, a_ref, dk):
        """Gap of every summit of ``inter`` (a = 0 there) under the contacts ``a`` (full index)."""
        inter.set_near(a_ref[inter.idx], self.cutoff)
        st = inter.evaluate(a[inter.idx])
        gap = np.full(len(dk), np.inf)
        gap[inter.idx] = st.w + st.u - dk[inter.idx]
        return gap

    def _result(self, delta, a, stats, t0, raster, absorbed) -> AsperityResult:
        law, on = self.law, np.nonzero(a > 0)[0]
        P = np.zeros_like(a)
        axes = np.zeros((len(a), 2))
        F = A = 0.0
        if len(on):
            P[on] = law.force(a[on], on)[0]
            A_on, B_on = law.semi_axes(a[on], on)
            axes[on, 0], axes[on, 1] = A_on, B_on
            F, A = float(P.sum()), float(law.area(a[on], on).sum())
        p_n = F / self.nominal_area
        frac = A / self.nominal_area
        kappa = None
        if F > 0 and self.rms_slope is not None:
            kappa = frac * law.E_star * self.rms_slope / p_n
        pmap = None
        if raster and self.surface is not None:
            pmap = self._raster(a, P, on)
        overlap = self._overlap(law.area(a[on], on), on) if len(on) > 1 else 0.0
        notes = ()
        if overlap > OVERLAP:
            notes += (f"contacts holding {100 * overlap:.0f} % of the real area overlap another (A/A0 {frac:.3g} at "
                      f"approach {delta:.3g} m): the asperity model assumes separate contacts, its area and force are "
                      "unreliable here (over-estimated without interaction); the FFT-BEM (contact.solve_contact) "
                      "holds at any load",)
        if frac > 1.0:
            notes += (f"real contact area {frac:.3g} times the nominal area at approach {delta:.3g} m: impossible, "
                      "far beyond the asperity model's range",)
        return AsperityResult(
            approach=delta, force=F, area=A, mean_pressure=p_n, area_fraction=frac,
            mean_gap=(self.z_max - self.mean_height) - delta, kappa=kappa, semi_axes=axes, forces=P,
            contact=a > 0, pressure=pmap, n_contacts=len(on), absorbed=absorbed, interaction=self.interaction,
            truncation=self.truncation if (self.interaction and stats["route"] != "direct") else 0.0,
            wall_time=time.perf_counter() - t0, overlap=overlap, notes=notes, **stats)

    def _overlap(self, area: np.ndarray, on: np.ndarray) -> float:
        """Share of the real area (``area`` [m²] of the contacts ``on``) in contacts whose
        area-equivalent circles overlap another's (across a periodic surface's edges too)."""
        t, r = self.table, np.sqrt(area / np.pi)
        xy = np.column_stack([t.x[on], t.y[on]])
        box = None
        if self.surface is not None and self.surface.periodic:
            box = np.array(self.surface.size)
            xy = np.mod(xy, box)
            xy[xy >= box] = 0.0                      # (a tiny negative coordinate rounds to the box's side)
        pairs = cKDTree(xy, boxsize=box).query_pairs(2.0 * float(r.max()), output_type="ndarray")
        if not len(pairs):
            return 0.0
        i, j = pairs.T
        d = xy[i] - xy[j]
        if box is not None:
            d -= box * np.round(d / box)
        hit = np.hypot(d[:, 0], d[:, 1]) < r[i] + r[j]
        touched = np.zeros(len(on), dtype=bool)
        touched[i[hit]] = touched[j[hit]] = True
        return float(area[touched].sum() / area.sum())

    def _raster(self, a, P, on) -> np.ndarray:
        """Eq. 1.4 sampled at pixel centres, each contact scaled to carry exactly its force
        (a contact smaller than a pixel puts its force on the summit pixel)."""
        s, t, law = self.surface, self.table, self.law
        ny, nx = s.shape
        out = np.zeros((ny, nx))
        if not len(on):
            return out
        reach = np.ceil(law.semi_axes(a[on], on)[0] / min(s.dx, s.dy)).astype(int) + 1
        bucket = np.ceil(np.log2(reach)).astype(int)
        for b in np.unique(bucket):
            m = 2**b
            sel = on[bucket == b]
            o = np.arange(-m, m + 1)
            oy, ox = (v.ravel() for v in np.meshgrid(o, o, indexing="ij"))
            rows, cols = t.row[sel][:, None] + oy[None, :], t.col[sel][:, None] + ox[None, :]
            src = np.repeat(sel, len(o) ** 2)
            p = law.pressure(np.repeat(a[sel], len(o) ** 2), src, np.tile(ox * s.dx, len(sel)),
                             np.tile(oy * s.dy, len(sel))).reshape(len(sel), -1)
            if s.periodic:
                rows, cols = rows % ny, cols % nx
            else:
                p = np.where((rows >= 0) & (rows < ny) & (cols >= 0) & (cols < nx), p, 0.0)
                rows, cols = np.clip(rows, 0, ny - 1), np.clip(cols, 0, nx - 1)
            total = p.sum(axis=1) * s.dx * s.dy
            centre = len(o) ** 2 // 2
            p[total <= 0, centre] = 1.0 / (s.dx * s.dy)
            total = np.where(total > 0, total, 1.0)
            np.add.at(out, (rows, cols), p * (P[sel] / total)[:, None])
        return out


# ----------------------------------------------------------------------------- checks
def _check_delta(delta) -> float:
    d = check_real("delta", delta)
    if not np.isfinite(d) or d < 0:
        raise InputError("delta", delta, "approach must be finite and >= 0")
    return d


_METHODS = {"energy": ("l-bfgs-b", "tnc"), "kinematic": ("trf", "tnc", "l-bfgs-b")}


def _check_route(route, method):
    if not isinstance(route, str) or route not in _METHODS:
        raise InputError("route", route, "'energy' or 'kinematic'")
    method = _METHODS[route][0] if method is None else (method.lower() if isinstance(method, str) else method)
    if method not in _METHODS[route]:
        raise InputError("method", method, f"one of {_METHODS[route]} for the {route} route")
    return route, method

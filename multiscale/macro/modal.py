"""Post-processing of complex modes (thesis §4.4): unstable and potentially unstable modes
(Fig. 4.14), MAC between two cases, MMAC and its cumulative moving average (Figs. 4.16–4.19),
strain-energy shares per component (Figs. 4.20–4.21), from matrices (``MatrixEnergy``) or per
material region of a DOLFINx model (``RegionEnergy``).

Modes are ``multiscale.macro.eigen.ModalResult`` (rank-owned entries of the PETSc layout); inner
products are reduced over the modes' communicator.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem, la
from scipy.optimize import linear_sum_assignment

from multiscale.errors import InputError, check_positive
from multiscale.macro.eigen import ModalResult, locked_window, mat_apply, matrix_comm, reduce_sum


@dataclass
class StabilityReport:
    """Unstable and potentially unstable modes of one case (thesis Fig. 4.14)."""

    unstable: np.ndarray              # mode numbers (1-based) with sigma > rtol |lambda|
    potentially_unstable: np.ndarray  # stable modes with a stable neighbour closer than close_tol
    frequency: np.ndarray             # [Hz] of all modes
    growth: np.ndarray                # sigma [1/s] of all modes
    rtol: float                       # instability threshold on sigma / |lambda| [-]
    close_tol: float                  # relative frequency gap of a potentially unstable pair [-]
    flutter_partner: np.ndarray       # per mode: the number of its flutter pair's other half (0: none)

    @property
    def divergent(self) -> np.ndarray:
        """The unstable modes that grow without oscillating (a real eigenvalue > 0, 0 Hz): a static
        divergence of the state linearised about, not flutter (mode numbers, 1-based)."""
        return self.unstable[self.frequency[self.unstable - 1] <= STATIC * max(float(self.frequency.max(initial=0.0)),
                                                                                1.0)]


@dataclass
class EnergyShares:
    """Strain-energy share of each component per mode (thesis Figs. 4.20–4.21)."""

    names: list[str]        # component names
    energy: np.ndarray      # (n_modes, n_components) 1/2 phi^H K_c phi [J per unit modal mass]
    share: np.ndarray       # energy / sum over components [-]

    def split(self, a: str, b: str) -> np.ndarray:
        """Share of component ``a`` in the energy of ``a`` and ``b`` (e.g. inner vs outer pad) [-]."""
        ia, ib = self._index(a), self._index(b)
        tot = self.energy[:, ia] + self.energy[:, ib]
        return self.energy[:, ia] / np.where(tot > 0, tot, 1.0)

    def _index(self, name: str) -> int:
        if name not in self.names:
            raise InputError("component", name, f"one of {self.names}")
        return self.names.index(name)


CLOSE = 1e-3     # relative frequency gap of two stable modes that are "potentially unstable" (Fig. 4.14)
STATIC = 1e-9    # a mode below this share of the highest frequency (or of 1 Hz) does not oscillate


def flutter_pairs(f: np.ndarray, sigma: np.ndarray, bad: np.ndarray) -> np.ndarray:
    """Per mode, the number (1-based) of the other half of its flutter pair, 0 for none: each unstable
    mode (``bad``) taken in frequency order with the unused stable mode within ``locked_window`` of its
    frequency [Hz] whose growth rate ``sigma`` [1/s] is nearest its opposite (a doublet's two pairs,
    or a stable mode beside a pair, were paired across by neighbours alone: a review)."""
    partner = np.zeros(f.size, int)
    for u in np.nonzero(bad & (f > 0))[0]:
        near = np.nonzero(~bad & (partner == 0) & (np.abs(f - f[u]) <= locked_window(f[u], sigma[u])))[0]
        if near.size:
            s = near[np.lexsort((np.abs(f[near] - f[u]), np.abs(sigma[near] + sigma[u])))[0]]
            partner[u], partner[s] = s + 1, u + 1
    return partner


def stability_report(result: ModalResult, rtol: float = 1e-6, close_tol: float = CLOSE) -> StabilityReport:
    """Unstable modes (sigma > rtol |lambda|) and potentially unstable ones (Fig. 4.14).

    A stable mode is potentially unstable when a neighbouring stable mode lies within
    ``close_tol`` relative frequency: the pair is close to coalescence but not yet locked in
    (``close_tol`` 0: none, as without friction, where nothing couples two modes). Overdamped roots
    (0 Hz) do not oscillate and pair with nothing (five of them were flagged; a user trial); nor does
    the stable half of a lock-in pair, at the frequency of an unstable mode within ``locked_window`` (it
    was flagged beside a stable mode 0.095 % away: an NVH user trial). ``flutter_partner`` pairs those
    halves (found by equal frequencies alone before: an NVH user trial).
    """
    check_positive("rtol", rtol)
    check_positive("close_tol", close_tol, allow_zero=True)
    f = result.frequency
    bad = result.unstable(rtol)
    close, partner = np.zeros(f.size, bool), flutter_pairs(f, result.growth, bad)
    if f.size > 1 and close_tol > 0:
        gap = np.diff(f) <= close_tol * np.maximum(f[1:], np.finfo(float).tiny)
        free = ~bad & (partner == 0)              # not a stable half locked in with an unstable mode
        both_stable = free[1:] & free[:-1] & (f[:-1] > 0)
        pair = gap & both_stable
        close[1:] |= pair
        close[:-1] |= pair
    number = np.arange(1, f.size + 1)
    return StabilityReport(number[bad], number[close], f.copy(), result.growth.copy(), rtol, close_tol, partner)


def _modes(x) -> np.ndarray:
    return x.modes if isinstance(x, ModalResult) else np.asarray(x)


def _metric(a, b, comm, gram):
    """(gram, comm) of ``mac_matrix``: the reduced coordinates' Gram matrix, or the communicator."""
    gram = gram if gram is not None else getattr(a, "gram", None)
    comm = None if gram is not None else comm or getattr(a, "comm", None) or getattr(b, "comm", None)
    return gram, comm


def mac_matrix(a: ModalResult | np.ndarray, b: ModalResult | np.ndarray, comm=None, gram=None) -> np.ndarray:
    """MAC_ij = |y_i^H y_j|^2 / (y_i^H y_i  y_j^H y_j) between modes of two cases (§4.4).

    Both sets must live on the same dof layout (same mesh and spaces), or be reduced coordinates q
    of one basis V (``ModalResult.gram`` = V^T V, or ``gram``): y^H y = q^H (V^T V) q. Returns
    (n_a, n_b) in [0, 1].
    """
    gram, comm = _metric(a, b, comm, gram)
    ya, yb = _modes(a), _modes(b)
    if ya.shape[0] != yb.shape[0]:
        raise InputError("modes", (ya.shape, yb.shape), "the two cases must share the dof layout")
    gb = yb if gram is None else gram @ yb
    cross = ya.conj().T @ gb
    na = np.einsum("ij,ij->j", ya.conj(), ya if gram is None else gram @ ya).real
    nb = np.einsum("ij,ij->j", yb.conj(), gb).real
    cross, na, nb = reduce_sum(cross, comm), reduce_sum(na, comm), reduce_sum(nb, comm)
    return np.abs(cross) ** 2 / np.maximum(np.outer(na, nb), np.finfo(float).tiny)


def subspace_mac(a: ModalResult | np.ndarray, b: ModalResult | np.ndarray, ia, ib, comm=None, gram=None,
                 rank_tol: float = 1e-12) -> float:
    """MAC of two subspaces: cos^2 of the largest principal angle between the span of modes ``ia``
    of ``a`` and the span of modes ``ib`` of ``b`` (inner product as in ``mac_matrix``); 1 when they
    coincide, the MAC for one mode each, 0 when their dimensions differ (numerical rank, relative
    ``rank_tol``). Collective over ``comm`` like ``mac_matrix``.

    A pair of modes that coalesces (a lock-in) or splits passes an exceptional point, where the
    single eigenvectors are not continuous in the parameter (they go as its square root) but the
    pair's invariant subspace is (Kato's total projection): each member of the coalesced pair is a
    mix of both parents, and only the two-mode subspace compares with the parents' one.
    """
    gram, comm = _metric(a, b, comm, gram)
    ya, yb = _modes(a)[:, list(ia)], _modes(b)[:, list(ib)]
    G = (lambda y: y) if gram is None else (lambda y: gram @ y)
    gaa, gbb, gab = (reduce_sum(x.conj().T @ G(y), comm) for x, y in ((ya, ya), (yb, yb), (ya, yb)))

    def whiten(g):                     # T with T^H g T = I on the numerical range of g
        w, U = np.linalg.eigh(0.5 * (g + g.conj().T))
        keep = w > rank_tol * max(w.max(initial=0.0), np.finfo(float).tiny)
        return U[:, keep] / np.sqrt(w[keep])

    ta, tb = whiten(gaa), whiten(gbb)
    if ta.shape[1] != tb.shape[1] or ta.shape[1] == 0:
        return 0.0
    s = np.linalg.svd(ta.conj().T @ gab @ tb, compute_uv=False)
    return float(min(s.min() ** 2, 1.0))


PAIR_TIE = 1e-8   # sums of MAC less eigenvalue jump that differ by less are a tie (round-off: ~1e-10)


def pair_modes(mac: np.ndarray, lam_a: np.ndarray, lam_b: np.ndarray, mac_min: float = 0.5,
               subspace=None, tie: float = PAIR_TIE) -> list[tuple[int, int]]:
    """One-to-one pairs (i, j) of modes of two neighbouring cases that maximise the sum of
    MAC_ij - |lambda_j - lambda_i| / |lambda_i| (the eigenvalue distance tells apart the two
    members of a locked-in pair, whose shapes are complex conjugates); pairs with MAC < ``mac_min``
    are dropped, unless ``subspace`` (a callable (rows, cols) -> ``subspace_mac`` of those modes)
    is given and the pair forms, with the pair of the mode nearest in frequency to j (to i), a
    block of two whose subspaces have a subspace MAC >= ``mac_min``: a pair that coalesces (splits)
    between the two cases, whose members are each a mix of both parents (``subspace_mac``).

    Ties (sums within ``tie``) keep the order of the mode numbers: two crossed pairs are uncrossed.
    Where a pair locks in (splits), its two members y and conj(y), sigma -+, have the same MAC with
    a stable (real-shaped) parent and the same eigenvalue jump from a parent on the imaginary axis:
    the two assignments tie exactly, and the solver's choice followed the round-off (it differed
    between 1 and 2 ranks, and between two serial runs). Now the lower parent continues into the
    stable member (numbered first, ``eigen.by_frequency``) and, at a split, the stable member
    into the lower child."""
    if mac.size == 0:
        return []
    dist = np.abs(lam_b[None, :] - lam_a[:, None]) / np.maximum(np.abs(lam_a)[:, None], np.finfo(float).tiny)
    score = mac - np.minimum(dist, 1.0)
    rows, cols = linear_sum_assignment(-score)
    pairs = _uncross([(int(i), int(j)) for i, j in zip(rows, cols)], score, tie)
    if subspace is None:
        return [(i, j) for i, j in pairs if mac[i, j] >= mac_min]
    to_b, to_a = dict(pairs), {j: i for i, j in pairs}

    def nearest(lam, k):
        gap = np.abs(lam.imag - lam[k].imag)
        gap[k] = np.inf
        return int(np.argmin(gap)) if gap.size > 1 else None

    kept = []
    for i, j in pairs:
        if mac[i, j] < mac_min:
            jn, i_n = nearest(lam_b, j), nearest(lam_a, i)
            blocks = ({(to_a[jn], jn)} if jn in to_a else set()) | ({(i_n, to_b[i_n])} if i_n in to_b else set())
            if not any(subspace([i, i2], [j, j2]) >= mac_min for i2, j2 in sorted(blocks) if i2 != i):
                continue
        kept.append((i, j))
    return kept


def _uncross(pairs: list, score: np.ndarray, tie: float) -> list[tuple[int, int]]:
    """``pairs`` (an optimal assignment of ``score``) with every two crossed pairs (i1 < i2,
    j1 > j2) whose uncrossing lowers the sum by at most ``tie`` uncrossed: one result for all
    the optimal assignments that differ by such swaps (each swap removes an inversion: it ends)."""
    pairs = sorted(pairs)
    changed = True
    while changed:
        changed = False
        for a in range(len(pairs)):
            for b in range(a + 1, len(pairs)):
                (i1, j1), (i2, j2) = pairs[a], pairs[b]
                if j1 > j2 and score[i1, j2] + score[i2, j1] >= score[i1, j1] + score[i2, j2] - tie:
                    pairs[a], pairs[b] = (i1, j2), (i2, j1)
                    changed = True
    return pairs


def mmac(mac: np.ndarray) -> np.ndarray:
    """MMAC_i = max_j MAC_ij: best correlation of mode i of the first case (§4.4)."""
    return np.asarray(mac).max(axis=1)


def cumulative_moving_average(x) -> np.ndarray:
    """xbar_n = (1/n) sum_{k=0}^{n-1} x_{n-k}, n = 1..N (Fig. 4.19)."""
    x = np.asarray(x, dtype=float)
    return np.cumsum(x) / np.arange(1, x.size + 1)


def strain_energy_shares(result: ModalResult, meter) -> EnergyShares:
    """Per-mode strain energy of each component (thesis Figs. 4.20–4.21).

    ``meter`` has ``names`` and ``meter(x) -> (n_components,)`` global energies 1/2 x^T K_c x of a
    real vector of owned dofs (``MatrixEnergy`` from matrices, ``RegionEnergy`` from a DOLFINx model).
    For a complex mode phi = a + i b and symmetric K_c, 1/2 phi^H K_c phi = E_c(a) + E_c(b).
    """
    names = list(meter.names)
    energy = np.array([meter(np.ascontiguousarray(phi.real)) + meter(np.ascontiguousarray(phi.imag))
                       for phi in result.modes.T]).reshape(len(result), len(names))
    tot = energy.sum(axis=1, keepdims=True)
    return EnergyShares(names, energy, energy / np.where(tot > 0, tot, 1.0))


class MatrixEnergy:
    """Energy meter from assembled symmetric component stiffness matrices {name: K_c}."""

    def __init__(self, stiffness: Mapping[str, object]):
        if not stiffness:
            raise InputError("stiffness", stiffness, "at least one component matrix")
        self.names = list(stiffness)
        self._mats = [stiffness[n] for n in self.names]
        self._comm = matrix_comm(self._mats[0])

    def __call__(self, x: np.ndarray) -> np.ndarray:
        out = np.empty(len(self._mats))
        for c, K in enumerate(self._mats):
            out[c] = 0.5 * x @ mat_apply(K, x[:, None].astype(complex))[:, 0].real
        return reduce_sum(out, self._comm)


class RegionEnergy:
    """Energy meter per material region of a DOLFINx model: 1/2 int sigma(x):eps(x) over each region."""

    def __init__(self, mech):
        """``mech``: a ``multiscale.macro.mechanics.Mechanics`` (its spaces, stress and regions)."""
        self.mech = mech
        self.names, self._forms, self._work, self._sizes = [], [], [], []
        self._regions = []
        for i, body in enumerate(mech.tm.bodies):
            w = fem.Function(mech.spaces[i])
            sigma = ufl.replace(mech.stress(i), {mech.u[i]: w})
            Q = body.region_space
            q = ufl.TestFunction(Q)
            self._forms.append((fem.form(0.5 * ufl.inner(sigma, ufl.sym(ufl.grad(w))) * q * mech.dx(i),
                                         entity_maps=mech.tm.entity_maps), Q))
            self._work.append(w)
            dm = mech.spaces[i].dofmap
            self._sizes.append(dm.bs * dm.index_map.size_local)
            n_owned = body.mesh.topology.index_map(body.mesh.topology.dim).size_local
            cell_dofs = Q.dofmap.list[:n_owned, 0]
            for r in body.spec.regions:
                self.names.append(r.name)
                self._regions.append((i, cell_dofs[body.region_tags[:n_owned] == r.tag]))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        per_cell, start = [], 0
        for (form, Q), w, n in zip(self._forms, self._work, self._sizes):
            w.x.array[:n] = x[start:start + n]
            w.x.scatter_forward()
            start += n
            vec = fem.assemble_vector(form)
            vec.scatter_reverse(la.InsertMode.add)
            per_cell.append(vec.array)
        local = np.array([per_cell[i][dofs].sum() for i, dofs in self._regions])
        return self.mech.tm.comm.allreduce(local)

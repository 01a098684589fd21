"""Archard wear of the interface facets in perfect contact (effect "wear" without "roughness").

Each facet f of body 0's face (a pad, a pin) loses the depth dh_f = k_f W_f / A_f (Eq. 3.10,
dh = k_w mu p ds: W_f = mu_f p_f ds_f A_f its frictional work [J]) or, with a specific wear rate per
normal load (``per_load``), dh_f = k_f L_f / A_f (L_f = p_f ds_f A_f [N m]), over the interval since
the last update: ``MacroModel.exposure`` sums them as the heat and the frictional work are summed,
each substep's pressure over its load-weighted sliding, ds_f = |w_f| ds (|w_f| the facet's speed
per unit of body 1's: its distance from the axis of a rotation, 1 for a translation). k_f is the
rate of the facet's interface at the facet's face temperature (a table; without heat the initial
temperature). The worn depth opens the facet's initial gap, and the next contact solve
redistributes the pressure (towards p |w| uniform: the steady state of a face that wears all over,
its profile receding as a whole). A rotating body 1 whose material gives k_w loses k_w,1(T_1) W_f
per facet (per frictional work), spread round the circle of the facet's radius over its face
(``track_spread``): its track recedes.

Explicit in the pressure: an update's depth per pressure c_f = k_f mu_f ds_f [m/Pa] (k_f ds_f per
load) times the facet's contact stiffness K_f [Pa/m] must stay below 2 (a facet pressed alone: p =
K_f x its closure, dh = c_f p). ``FacetWear`` estimates K_f = 1/(1/K_n + sqrt(A_f)/E*), the penalty
in series with the bodies' stiffness over the facet (a bound of a facet's share of the assembled
stiffness), and takes an update whose S = max c_f K_f exceeds ``STABLE`` in n = ceil(S / STABLE)
increments, each with the pressure re-solved after the last. The contact is solved on the worn
gaps after an update (n solves in all), the drive's braking torque kept.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.micro.wear import WearRate

STABLE = 0.5        # the largest c_f K_f of one increment (explicit Archard: oscillation above 1, growth above 2)


def track_spread(radius, source_radius, volume, half: float) -> np.ndarray:
    """Depth [m] at ``radius`` [m] of the volumes ``volume`` [m^3] lost at ``source_radius`` spread
    around their circles: Σ_f V_f K(r − r_f) / (2 π r), K the hat of half-width ``half`` [m] and unit
    integral (the depth integrated over the track, ∫ depth 2 π r dr, is Σ V_f)."""
    r, src, v = (np.asarray(a, dtype=float) for a in (radius, source_radius, volume))
    out = np.empty(r.size)
    for i in range(0, r.size, 256):                                    # rows in blocks: memory O(256 n)
        hat = np.clip(1.0 - np.abs(r[i:i + 256, None] - src[None, :]) / half, 0.0, None) / half
        out[i:i + 256] = hat @ v / (2 * np.pi * r[i:i + 256])
    return out


@dataclass(frozen=True)
class FacetRate:
    """The wear rate of body 0 on one interface: its facets (``mask``, global), k [1/Pa] (a
    ``WearRate``: constant or against the face temperature [K]) and whether it is per normal load."""

    mask: np.ndarray
    rate: WearRate
    per_load: bool = False


class FacetWear:
    """The worn depths of a ``MacroModel``'s interface facets (see module docstring): ``depth`` of
    body 0 and ``counter_depth`` of body 1 [m] per facet (global arrays), ``volume`` [m^3] lost per
    interface and ``counter_volume`` [m^3] since the start, ``work`` [J] of the updates. ``stiffness``
    [Pa/m] per facet bounds its contact stiffness (stability); ``counter_rate`` the rotating body
    1's k_w (None: it does not wear); ``temperature`` [K] where no heat is solved."""

    def __init__(self, model, rates: Sequence[FacetRate], stiffness: np.ndarray, counter_rate: WearRate | None = None,
                 temperature: float = 293.15):
        iface, motion = model.tm.interface, model.tm.spec.motion
        if counter_rate is not None and not isinstance(motion, Rotation):
            raise InputError("counter_rate", counter_rate, "a rotating body 1: its wear spreads round a circular track")
        self.model, self.rates, self.counter_rate = model, tuple(rates), counter_rate
        self.stiffness, self.temperature = np.asarray(stiffness, dtype=float), float(temperature)
        n = iface.n_facets
        self.depth, self.counter_depth = np.zeros(n), np.zeros(n)
        self.volume, self.counter_volume, self.work, self.increments = np.zeros(len(iface.tags)), 0.0, 0.0, 1
        self.datum = iface.values(model.contact.initial_gap)
        if isinstance(motion, Rotation):
            axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis)
            arm = iface.midpoints - np.asarray(motion.centre, float)
            along = arm @ axis
            self.reach = np.linalg.norm(arm - np.outer(along, axis), axis=1)        # m per rad
            scale = model.tm.spec.length_scale                                      # faces of one axial position
            self.faces = np.unique(np.round(along / scale, 6), return_inverse=True)[1]
        else:
            self.reach, self.faces = np.ones(n), np.zeros(n, dtype=int)
        model.exposure = np.zeros((3, n))

    def update(self) -> tuple[np.ndarray, float, int]:
        """Wear over the model's ``exposure`` since the last update, then the exposure restarts and
        the contact is solved on the worn gaps (collective: the same on every rank).
        Returns the volume [m^3] body 0 lost per interface, the frictional work [J] and the
        increments taken."""
        m, iface = self.model, self.model.tm.interface
        work, load, slid = m.exposure
        m.exposure = np.zeros_like(m.exposure)
        if not slid.any():
            return np.zeros(len(iface.tags)), 0.0, 0
        T0, T1 = (m.thermal.facet_temperature(0), m.thermal.facet_temperature(1)) if m.thermal is not None else \
            (np.full(iface.n_facets, self.temperature),) * 2
        k, per_load = np.zeros(iface.n_facets), np.zeros(iface.n_facets, dtype=bool)
        for r in self.rates:
            k[r.mask], per_load[r.mask] = np.broadcast_to(r.rate(T0[r.mask]), (int(r.mask.sum()),)), r.per_load
        mu = iface.values(m.contact.friction)
        k1 = np.broadcast_to(self.counter_rate(T1), k.shape) if self.counter_rate is not None else np.zeros(k.shape)
        per_pressure = k * np.where(per_load, 1.0, mu) * slid * self.reach      # m/Pa per facet
        n = max(1, int(np.ceil((per_pressure * self.stiffness).max() / STABLE)))
        for i in range(n):
            if n == 1:                         # the exposure's own pressures: volume = k x work exactly
                self._wear(k * np.where(per_load, load, work) / iface.areas, k1 * work)
            else:                              # each increment at the pressure re-solved after the last
                p = m.contact.facet_pressure()
                self._wear(per_pressure * p / n, k1 * mu * p * slid * self.reach * iface.areas / n)
            self._solve()
        if not m.released:
            m.keep_torque(m.drive.factor(m.time))          # the worn faces moved the friction moment
        done = float(work.sum())
        self.work += done
        self.increments = max(self.increments, n)
        gained = np.bincount(iface.tag_index, self.depth * iface.areas, minlength=len(iface.tags)) - self.volume
        self.volume += gained
        return gained, done, n

    def _solve(self) -> None:
        """The contact solved again on the worn gaps (at the speed of the last solve: a stop keeps the
        friction that ended it), so that the state recorded and written is the worn one; released,
        the next loaded step solves it (``MacroModel.stale``)."""
        m = self.model
        if m.released:
            m.stale = True
            return
        now = float(m.contact.speed.value)
        m.contact.speed.value = m.solved_speed
        try:
            m.last_solve = m.mechanics.solve()
        finally:
            m.contact.speed.value = now

    def _wear(self, worn: np.ndarray, lost: np.ndarray) -> None:
        """Deepen body 0's facets by ``worn`` [m] and body 1's track by the volumes ``lost`` [m^3] per
        facet, spread round each face's circles; the facets' gaps follow."""
        iface = self.model.tm.interface
        self.depth += worn
        if lost.any():
            half = np.sqrt(2.0 * np.median(iface.areas))                       # the side of a typical facet
            for face in np.unique(self.faces):
                on = self.faces == face
                self.counter_depth[on] += track_spread(self.reach[on], self.reach[on], lost[on], half)
            self.counter_volume += float(lost.sum())
        iface.set_field(self.model.contact.initial_gap, self.datum + self.depth + self.counter_depth)

    def row(self) -> dict:
        """History columns: ``wear_volume`` [m^3] (and per interface with several), ``wear_max_depth``
        [m], ``frictional_work`` [J] and ``wear_rate_mean`` [1/Pa] (volume / work) since the start,
        ``wear_substeps`` (the most increments an update took); with a wearing body 1
        ``counter_wear_volume`` [m^3] and ``counter_wear_max_depth`` [m]."""
        tags = list(self.model.tm.interface.tags)
        row = {"wear_volume": float(self.volume.sum()), "wear_max_depth": float(self.depth.max(initial=0.0)),
               "frictional_work": self.work, "wear_substeps": self.increments,
               "wear_rate_mean": float(self.volume.sum()) / self.work if self.work > 0 else np.nan}
        if len(tags) > 1:
            row.update({f"wear_volume_{name}": float(v) for name, v in zip(tags, self.volume)})
        if self.counter_rate is not None:
            row.update(counter_wear_volume=self.counter_volume,
                       counter_wear_max_depth=float(self.counter_depth.max(initial=0.0)))
        return row

    def state(self) -> tuple[dict, dict]:
        """(attributes, arrays) a checkpoint keeps (``restore`` reads them back)."""
        return ({"wear": [self.work, self.counter_volume, self.increments]},
                {"wear_depth": self.depth, "counter_depth": self.counter_depth, "wear_volume": self.volume,
                 "exposure": self.model.exposure})

    def restore(self, attrs: dict, arrays: dict) -> None:
        """Back to a ``state``; the facets' gaps follow."""
        self.work, self.counter_volume, increments = (float(v) for v in attrs["wear"])
        self.increments = int(increments)
        self.depth, self.counter_depth = arrays["wear_depth"].copy(), arrays["counter_depth"].copy()
        self.volume, self.model.exposure = arrays["wear_volume"].copy(), arrays["exposure"].copy()
        self.model.tm.interface.set_field(self.model.contact.initial_gap, self.datum + self.depth + self.counter_depth)

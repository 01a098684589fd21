"""Archard wear of the interface facets in perfect contact (effect "wear" without "roughness").

Each facet f of body 0's face (a pad, a pin) loses the depth dh_f = k_f W_f / A_f (Eq. 3.10,
dh = k_w mu p ds: W_f = mu_f p_f ds_f A_f its frictional work [J]) or, with a specific wear rate per
normal load (``per_load``), dh_f = k_f L_f / A_f (L_f = p_f ds_f A_f [N m]), over the interval since
the last update: an ``Exposure`` (the model's) sums them as the heat and the frictional work are summed,
each substep's pressure over its load-weighted sliding, ds_f = |w_f| ds (|w_f| the facet's speed
per unit of body 1's: its distance from the axis of a rotation, 1 for a translation), each
substep's at its own rate k_f, the rate of the facet's interface at the facet's face temperature (a
table; ``Exposure``); without heat at the initial temperature. The worn depth opens the facet's initial gap and the contact is solved
on the worn gaps: the pressure redistributes (towards p |w| uniform: the steady state of a face
that wears all over, its profile receding as a whole). A rotating body 1 whose material gives k_w
loses k_w,1(T_1) W_f per facet (per frictional work), spread round the circle of the facet's radius
over its face (``track_spread``; a face in a plane normal to the axis): its track recedes, from the
exposure.

Stability. The depth per pressure of an update, c_f = k_f mu_f ds_f [m/Pa] (k_f ds_f per load; ds
the sliding of the pressure solved now: the exposure's load-weighted sliding times its loads over
the load now; mu_f the sliding's, the exposure's work over its load, W_f / L_f: with a fade table
the mu at the update, read after a stop's heating or a dwell's cooling, wore 10-45 % off k W, a
review), against the facets' contact stiffness: a depth constant over a facet is a pattern
the displacement (linear over each element) cannot follow facet by facet, so only the penalty K_n
resists it (a review measured the facet Jacobian: its largest eigenvalue times c within 1.2 % of
c K_n, 3.4 to 24 times an elastic estimate, and the explicit update failed where c K_n exceeded 2).
An update with max c_f K_n <= ``STABLE`` wears explicitly from the exposure (its volume k W, the
heat's work, to round-off) and solves once. A larger one is linearly implicit (backward Euler; the
micro wear takes the same way, ``micro.post_analysis``): the contact is solved with each facet's
penalty K_n / (1 + K_n c_f), so that dh_f = c_f p_f at the pressures p found; the facets wear by
it, the contact is solved with K_n, and ``CORRECTIONS`` solves bring the facets' mean pressures
back to p (dh_f += (p_now - p_f) / K_n: a depth constant over a facet against a pressure that is
not amplifies the within-facet variation by 1 + K_n c; without them the worn-in pin's recorded
pressure followed 1/r within 3.9 %, with them 0.4 %). Its volume is k W within 0.2-0.7 %; its
transient converges like dt^0.5 (a review: 1.4 times closer per halving, pre-asymptotic). Released,
an update that would be implicit is solved at the load the contact was released from (its last
solve's), and the model is released again from that worn state (an explicit one there made the
re-engaging contact Newton fail, as did the released state's displacement on the worn gaps;
waiting for the next loaded step put the wear, the work and a ``wear.limit`` off by the dwell: a
user trial's run stopped a stop late), unless it is the run's
last: nothing re-engages, and it wears from the exposure (k W). An update whose solve fails is
undone (the model's state and the wear's as before it) before the error goes on. The counter-face's
track wears from the exposure (k_1 W) while its depth per pressure at a facet, c_1 = k_1 mu ds times
``coverage`` (the depth a unit depth over every facet spreads to round the circles: the share of its
circle the facets cover, 3-4 % under the test pin), keeps c_1 K_n <= ``TRACK_STABLE``; beyond it the
update is implicit with c_f + c_1 and the track loses k_1 mu ds p A at the pressures found (a disc
k_w 1e5 times the pin's failed its contact Newton explicitly, c_1 K_n about 8). The track is smoothed
round its circles, so its explicit update keeps to its refined answer farther than a facet's: at
c_1 K_n = 0.8 the test pin's last peak pressure 2.285 MPa against 2.2836 at 8 times the steps, where
the implicit update gave 1.996. A translating body 1's track is uniform (it moves no pressure):
no coverage, explicit (a review: its coverage grew as 1/h with the facets). Open (a review): an
update made implicit by the track alone takes body 0 implicit too, and both bodies' volumes
follow the pressures found: 3.6 % short of k W on the demo brake at a disc k_w 1e4 times the
pads' in 2 steps, 1.25 % in 8; keeping body 0 explicit then (its volumes rescaled to the
exposure's) made the peak pressure grow, as the local penalty does not match the spread track.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.macro.thickness import WearLimit
from multiscale.micro.wear import WearRate

STABLE = 0.5        # the largest c_f K_n of an explicit update (explicit Archard: oscillation above 1, growth above 2)
CORRECTIONS = 4     # solves that bring an implicit update's facet pressures back to the ones it found
TRACK_STABLE = 1.0  # the largest c_1 K_n of the counter-face's explicit track (beyond it: oscillation; module docstring)


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


class Exposure:
    """What the facets' wear sums between updates (global arrays per facet): the frictional work
    ``work`` W = mu p |w| ds dA [J] and ``load`` L = p |w| ds dA [N m] of each loaded substep
    (``MacroModel.macro_step`` adds them), the volumes at each substep's own rates, ``volume`` = Σ
    k_0 W (Σ k_0 L where the rate is per load, ``per_load``) and ``counter_volume`` = Σ k_1 W [m^3],
    k_i at body i's face temperatures (``rates``: (T_0, T_1) or None -> (k_0, k_1) [1/Pa]) as the
    mean of the substep's start's and end's rates (its heat step's), and ``sliding``, body 1's
    load-weighted sliding [rad or m] times the load each substep's pressure was solved at [N or Pa].
    (A table read at the interval's work-weighted mean temperature wore 6-25 % off where it bends:
    a review.)"""

    def __init__(self, n: int, rates, per_load: np.ndarray):
        self.rates, self.per_load = rates, per_load
        self.sums, self.sliding, self._last = np.zeros((4, n)), 0.0, (np.zeros(n), np.zeros(n))

    work = property(lambda self: self.sums[0])
    load = property(lambda self: self.sums[1])
    volume = property(lambda self: self.sums[2])
    counter_volume = property(lambda self: self.sums[3])

    def add(self, work: np.ndarray, load: np.ndarray, sliding: float, temperatures) -> None:
        """A substep's ``work`` [J], ``load`` [N m] and ``sliding`` [rad N or m Pa], rated at the faces'
        ``temperatures`` at its start (with heat; its ``end`` adds the other half) or throughout (None)."""
        self.sums[:2] += work, load
        self.sliding += sliding
        self._last = work, load
        self._rate(temperatures, 1.0 if temperatures is None else 0.5)

    def end(self, temperatures) -> None:
        """The last substep's rate at its end's face ``temperatures`` (T_0, T_1) [K]."""
        self._rate(temperatures, 0.5)

    def _rate(self, temperatures, share: float) -> None:
        (k0, k1), (work, load) = self.rates(temperatures), self._last
        self.sums[2:] += share * k0 * np.where(self.per_load, load, work), share * k1 * work

    def mean_rates(self, temperatures) -> tuple[np.ndarray, np.ndarray]:
        """Body 0's and body 1's rates [1/Pa] per facet over the interval, their volumes over the work
        (body 0's over the load where per load), at the faces' ``temperatures`` now where it had none."""
        weight, (k0, k1) = np.where(self.per_load, self.load, self.work), self.rates(temperatures)
        return (np.divide(self.volume, weight, out=k0, where=weight > 0),
                np.divide(self.counter_volume, self.work, out=k1, where=self.work > 0))

    def clear(self) -> None:
        self.sums[:], self.sliding = 0.0, 0.0


@dataclass(frozen=True)
class FacetRate:
    """The wear rate of a body on one interface: its facets (``mask``, global), k [1/Pa] (a
    ``WearRate``: constant or against the face temperature [K]) and whether it is per normal load
    (body 0's only: body 1 wears per frictional work)."""

    mask: np.ndarray
    rate: WearRate
    per_load: bool = False


class FacetWear:
    """The worn depths of a ``MacroModel``'s interface facets (see module docstring): ``depth`` of
    body 0 and ``counter_depth`` of body 1 [m] per facet (global arrays), ``volume`` [m^3] lost per
    interface and ``counter_volume`` [m^3] since the start, ``work`` [J] of the updates, ``implicit``
    the updates taken linearly implicit. ``counter_rates``: body 1's k_w on the facets it gives
    (``FacetRate``; none: it does not wear); ``temperature`` [K] where no heat is solved; ``limit`` [m]
    the material to keep behind a facet (``WearLimit``)."""

    def __init__(self, model, rates: Sequence[FacetRate], counter_rates: Sequence[FacetRate] = (),
                 temperature: float = 293.15, limit: float = 0.0):
        iface, motion = model.tm.interface, model.tm.spec.motion
        self.model, self.rates, self.counter_rates = model, tuple(rates), tuple(counter_rates)
        self.temperature = float(temperature)
        n = iface.n_facets
        self.depth, self.counter_depth = np.zeros(n), np.zeros(n)
        self.volume, self.counter_volume, self.work, self.implicit = np.zeros(len(iface.tags)), 0.0, 0.0, 0
        self.datum = iface.values(model.contact.initial_gap)
        self.reach, self.faces = model.facet_reach, np.zeros(n, dtype=int)
        if isinstance(motion, Rotation):
            along = (iface.midpoints - np.asarray(motion.centre, float)) @ np.asarray(motion.axis, float)
            scale = model.tm.spec.length_scale * np.linalg.norm(motion.axis)       # faces of one axial position
            self.faces = np.unique(np.round(along / scale, 6), return_inverse=True)[1]
        for r in self.counter_rates:
            flat = not isinstance(motion, Rotation) or len(np.unique(self.faces[r.mask])) == 1
            if not flat:
                raise InputError("counter-face wear", r.rate, "a rotating body 1 whose worn faces lie in planes "
                                 "normal to its axis (its wear spreads round a circular track on them)")
        per_load = np.zeros(n, dtype=bool)
        for r in self.rates:
            per_load[r.mask] = r.per_load
        model.exposure = Exposure(n, self.rate_at, per_load)
        self.limit = WearLimit(model.tm, limit)   # the worn depths against the thickness behind the facets
        self.coverage = np.zeros(n)       # [-] (module docstring; a translating body 1's track is uniform: none)
        if self.counter_rates and isinstance(motion, Rotation):
            self.coverage = self._spread(iface.areas)

    def update(self, last: bool = False) -> tuple[np.ndarray, float]:
        """Wear over the model's ``exposure`` since the last update, then the exposure restarts and
        the contact is solved on the worn gaps (collective: the same on every rank). Released, an
        update that would be implicit is solved at the load of the last solve, then the model is
        released again from that worn state, unless it is the run's ``last`` (module
        docstring). Returns the volume [m^3] body 0 lost per interface and the frictional work [J]."""
        m, iface = self.model, self.model.tm.interface
        e, solved = m.exposure, float(m.mechanics.load.value)
        slid = e.sliding / solved if solved else 0.0     # the sliding of the pressure solved now
        none = np.zeros(len(iface.tags)), 0.0
        if not e.sliding:
            return none
        K = iface.values(m.contact.stiffness)     # mu: the sliding's, W / L (with fade, mu now was 45 % off: a review)
        mu = np.divide(e.work, e.load, out=iface.values(m.contact.friction), where=e.load > 0)
        k0, k1 = e.mean_rates(m.face_temperatures())
        per_pressure = k0 * np.where(e.per_load, 1.0, mu) * slid * self.reach          # m/Pa: body 0's depth
        counter = k1 * mu * slid * self.reach                                          # m/Pa: body 1's volume / area
        track = (counter * self.coverage * K).max() > TRACK_STABLE                     # its track implicit too
        explicit = (per_pressure * K).max() <= STABLE and not track
        before, (attrs, arrays) = m.snapshot(), self.state()
        before_wear = attrs, {name: a.copy() for name, a in arrays.items()}
        implicit = not explicit and not (m.released and last)
        held = m.released and implicit            # re-engaging on an explicit wear of this size failed (a review)
        try:
            if held:                              # at the load it was released from
                m.contact.engaged.value = 1.0
            self._wear_and_solve(implicit, e.volume / iface.areas, e.counter_volume.copy(), per_pressure,
                                 counter if track else None)
        except BaseException:                     # a failed solve: the update undone, for a caller going on
            m.restore(before)
            self.restore(*before_wear)
            raise
        if held:                                  # released again; the next loaded step solves from the worn state
            m.contact.engaged.value, m.stale = 0.0, True
        self.implicit += implicit
        done = float(e.work.sum())
        self.work += done
        e.clear()
        gained = np.bincount(iface.tag_index, self.depth * iface.areas, minlength=len(iface.tags)) - self.volume
        self.volume += gained
        return gained, done

    def _wear_and_solve(self, implicit: bool, worn: np.ndarray, lost: np.ndarray, per_pressure: np.ndarray,
                        counter: np.ndarray | None) -> None:
        """Wear body 0 by the depths ``worn`` [m] and body 1 by the volumes ``lost`` [m^3] per facet, or
        (``implicit``) body 0 by ``per_pressure`` [m/Pa] times the pressures of a solve with the penalty
        K_n / (1 + K_n c), c = ``per_pressure`` (+ ``counter`` ``coverage`` with its track implicit:
        then body 1 by ``counter`` [m/Pa, volume per area] times them), and the ``CORRECTIONS``; the
        contact solved on the worn gaps."""
        m, iface = self.model, self.model.tm.interface
        K = iface.values(m.contact.stiffness)
        if implicit:                              # backward Euler: dh = c p at the pressure found
            track = counter * self.coverage if counter is not None else 0.0
            iface.set_field(m.contact.stiffness, K / (1.0 + K * (per_pressure + track)))
            try:
                self._solve()
                found = m.contact.facet_pressure()
            finally:
                iface.set_field(m.contact.stiffness, K)
            worn = per_pressure * found
            lost = counter * found * iface.areas if counter is not None else lost
        self._wear(worn, lost)
        self._solve()
        for _ in range(CORRECTIONS if implicit else 0):   # the facets' mean pressures back to the ones found
            self._wear(np.divide(m.contact.facet_pressure() - found, K, out=np.zeros(K.shape), where=K > 0),
                       np.zeros(K.shape))
            self._solve()

    def _solve(self) -> None:
        """The contact solved on the worn gaps at the speed of the last solve (a stop keeps the
        friction that ended it), the drive's braking torque kept, so that the state recorded and
        written is the worn one; released, the next loaded step solves (``MacroModel.stale``)."""
        m = self.model
        if m.released:
            m.stale = True
            return
        now = float(m.contact.speed.value)
        m.contact.speed.value = m.solved_speed
        try:
            m.last_solve = m.mechanics.solve()
            m.keep_torque(m.drive.factor(m.time))           # the worn faces moved the friction moment
        finally:
            m.contact.speed.value = now

    def _wear(self, worn: np.ndarray, lost: np.ndarray) -> None:
        """Deepen body 0's facets by ``worn`` [m] and body 1's track by the volumes ``lost`` [m^3] per
        facet, spread round each face's circles; the facets' gaps follow."""
        self.depth += worn
        if lost.any():
            self.counter_depth += self._spread(lost)
            self.counter_volume += float(lost.sum())
        self._set_gap()

    def _spread(self, volumes: np.ndarray) -> np.ndarray:
        """The depth [m] per facet of body 1's ``volumes`` [m^3] per facet spread round each face's
        circles (``track_spread``, over a typical facet's side)."""
        areas, out = self.model.tm.interface.areas, np.zeros(len(volumes))
        half = np.sqrt(2.0 * np.median(areas))
        for face in np.unique(self.faces):
            on = self.faces == face
            out[on] = track_spread(self.reach[on], self.reach[on], volumes[on], half)
        return out

    def _set_gap(self) -> None:
        """The facets' initial gap: the datum opened by both bodies' worn depths."""
        self.model.tm.interface.set_field(self.model.contact.initial_gap, self.datum + self.depth + self.counter_depth)

    def row(self, updated: bool) -> dict:
        """History columns: ``wear_volume`` [m^3] (and per interface with several), ``wear_max_depth``
        [m], ``frictional_work`` [J] and ``wear_rate_mean`` [1/Pa] (volume / work) since the start,
        ``wear_substeps`` (1 in a row with an update, ``updated``, else 0: the rough loop's increments),
        ``wear_implicit_updates`` (so far), ``wear_remaining_min`` [m] (``WearLimit``); with a wearing
        body 1 ``counter_wear_volume`` [m^3] and ``counter_wear_max_depth`` [m]."""
        tags = list(self.model.tm.interface.tags)
        row = {"wear_volume": float(self.volume.sum()), "wear_max_depth": float(self.depth.max(initial=0.0)),
               "frictional_work": self.work, "wear_substeps": int(updated), "wear_implicit_updates": self.implicit,
               "wear_rate_mean": float(self.volume.sum()) / self.work if self.work > 0 else np.nan,
               **self.limit.row(self.depth)}
        if len(tags) > 1:
            row.update({f"wear_volume_{name}": float(v) for name, v in zip(tags, self.volume)})
        if self.counter_rates:
            row.update(counter_wear_volume=self.counter_volume,
                       counter_wear_max_depth=float(self.counter_depth.max(initial=0.0)))
        return row

    def rate_at(self, temperatures) -> tuple[np.ndarray, np.ndarray]:
        """(k_0, k_1) per facet [1/Pa]: body 0's rate (per frictional work, or per load where its rate
        is) and body 1's k_w (0 where it does not wear) at the faces' ``temperatures`` (T_0, T_1) [K]
        (None: ``temperature``)."""
        n = self.model.tm.interface.n_facets
        T = np.full((2, n), self.temperature) if temperatures is None else temperatures
        k = np.zeros((2, n))
        for side, rates in enumerate((self.rates, self.counter_rates)):
            for r in rates:
                k[side, r.mask] = np.broadcast_to(r.rate(T[side][r.mask]), (int(r.mask.sum()),))
        return k[0], k[1]

    def worn_through(self) -> str | None:
        """What body 0 wore through (``WearLimit.through``), or None (collective)."""
        return self.limit.through(self.depth)

    def state(self) -> tuple[dict, dict]:
        """(attributes, arrays) a checkpoint keeps (``restore`` reads them back)."""
        return ({"wear": [self.work, self.counter_volume, self.implicit, self.model.exposure.sliding]},
                {"wear_depth": self.depth, "counter_depth": self.counter_depth, "wear_volume": self.volume,
                 "exposure": self.model.exposure.sums})

    def restore(self, attrs: dict, arrays: dict) -> None:
        """Back to a ``state``; the facets' gaps follow."""
        self.work, self.counter_volume, implicit, self.model.exposure.sliding = (float(v) for v in attrs["wear"])
        self.implicit = int(implicit)
        self.depth, self.counter_depth = arrays["wear_depth"].copy(), arrays["counter_depth"].copy()
        self.volume, self.model.exposure.sums[:] = arrays["wear_volume"].copy(), arrays["exposure"]
        self._set_gap()

"""The [wear] table: Archard's wear of the rough body's zones, by a rate per frictional work (k_w,
Eq. 3.10, the thesis') or per normal load (a tribometer's specific wear rate), constant or against
the temperature, and the default k_w(T) of thesis Fig. 7.9."""
from __future__ import annotations

from dataclasses import dataclass

from multiscale.schema import Choice, Curve, Integer, OneOf, Quantity, key
from multiscale.scene_values import TEMPERATURE

# Default k_w(T) [(K, 1/Pa)]: the shape of thesis Fig. 7.9 (sintered pad material, [Mann 2017]):
# slowly rising up to 200 degC, steeply above. The figure's numbers are not in the text; the level
# is set so that the ch. 7 run (demos/pin_on_disc_thesis.toml, zones at 20-60 degC) wears the
# volume of §7.3.2 (3.8e7 um^3 in 30 s of 200 N at 1.9 m/s with mu = 0.4: V / (mu F s) = 8.4e-15
# 1/Pa on average). Calibrated on that one volume of a pin below 100 degC: below 100 degC it is
# nearly flat (the worn volume then grows linearly with the sliding), above it is the figure's
# shape only. ``multiscale check`` says so. (Until 2026-11-29 the level was 0.74 of this: 6e-15 at
# 20 degC, and the ch. 7 run wore 2.8e7 um^3; found by an adversarial test.)
FIG_7_9_CALIBRATION = ("shape of thesis Fig. 7.9 (its numbers are not in the text); level set so that "
                       "k_w mu F s gives the thesis' ch. 7 worn volume (3.8e7 um^3 in 30 s at 200 N, "
                       "1.9 m/s, mu 0.4: 8.4e-15 1/Pa on average over the ch. 7 zones); give your material's k_w")
FIG_7_9_WEAR_RATE = ((293.15, 8.2e-15), (373.15, 1.09e-14), (473.15, 2.04e-14), (573.15, 8.2e-14), (673.15, 2.7e-13))

_PER_WORK = Quantity("wear_rate", ge=0, plausible=(0.0, 1e-9))              # per frictional work (Eq. 3.10)
_PER_LOAD = Quantity("specific_wear_rate", ge=0, plausible=(0.0, 1e-9))     # per normal load and distance
_RULE = "another key of the rule, else the rough material's k_w, else thesis Fig. 7.9"


@dataclass(frozen=True)
class Wear:
    """Archard wear dh = k_w mu p ds (Eq. 3.10), k_w constant or a table k_w(T) (``FIG_7_9_WEAR_RATE``:
    calibrated as ``FIG_7_9_CALIBRATION`` says), or dh = k p ds by a specific wear rate k = V/(F s) per
    normal load (``specific_rate``, or a table k(T): a tribometer's, the same whatever mu, also where
    it fades), at the rough surface's local temperature, cell by cell in each micro patch (its face's
    macro temperature plus the flash rise; without heating the face's macro temperature), or with
    ``temperature = "macro"`` at each face's macro temperature (a dynamometer's k(T) and mu(T) were
    measured against one temperature: a fade table reads the mean of the two faces'). Every ``update_every`` macro steps (and at the last
    step, and a step ending at a stop) the zones wear over the sliding since, weighted by the load factor
    (none while released), in at least ``substeps`` (and 2) implicit increments, raised while their error
    estimate exceeds ``micro.wear.WEAR_TOL``; a counter-face whose material gives ``k_w`` wears too.
    Without effect "roughness" the interface facets wear (``macro.facet_wear``: at their face
    temperatures, their gaps opened; an update linearly implicit where an explicit one would not be
    stable). The run ends after the step that leaves less than ``limit`` [m] of a worn part behind a
    facet (``macro.thickness``: a car pad's wear limit, some 2-3 mm of friction material; 0: worn
    through)."""

    k_w: float | None = key(Quantity("wear_rate", gt=0, plausible=(1e-20, 1e-9)), absent=_RULE)
    k_w_table: tuple | None = key(Curve(TEMPERATURE, _PER_WORK, "temperature", "k_w"), absent=_RULE)
    specific_rate: float | None = key(Quantity("specific_wear_rate", gt=0, plausible=(1e-20, 1e-9)), absent=_RULE)
    specific_rate_table: tuple | None = key(Curve(TEMPERATURE, _PER_LOAD, "temperature", "k"), absent=_RULE)
    temperature: str = key(Choice(("surface", "macro")), default="surface")   # what a k_w(T) or k(T) reads
    update_every: int = key(Integer(ge=1), default=1)                         # macro steps per update
    substeps: int = key(Integer(ge=1), default=1)                             # wear increments per update
    # material kept behind a worn face: the run ends below it (plausibly a pad's few mm: a bare 2 is 2 m, a trial)
    limit: float = key(Quantity("length", ge=0, plausible=(0.0, 0.05)), default=0.0)

    rules = (OneOf(("k_w", "k_w_table", "specific_rate", "specific_rate_table")),)

    def problems(self, path, ctx):
        if "roughness" not in ctx.effects and self.substeps != 1:      # (perfect contact: macro.facet_wear)
            ctx.warnings.append(f"{path}.substeps is ignored in perfect contact: the facets' wear takes the "
                                "update explicit, or linearly implicit where that would not be stable")
        return []

    @property
    def given(self) -> str | None:
        """The key that gives the rate (None: none, the default k_w(T) table)."""
        return next((k for k in ("k_w", "k_w_table", "specific_rate", "specific_rate_table")
                     if getattr(self, k) is not None), None)

    @property
    def per_load(self) -> bool:
        """True if the rate is a specific wear rate per normal load: dh = k p ds, mu out of it."""
        return self.given in ("specific_rate", "specific_rate_table")

    @property
    def rate(self):
        """k_w, or k if ``per_load`` [1/Pa]: the constant, else the table ((temperatures [K]), (rates [1/Pa]))."""
        value = self.k_w if self.k_w is not None else self.specific_rate
        return value if value is not None else \
            tuple(zip(*(self.k_w_table or self.specific_rate_table or FIG_7_9_WEAR_RATE)))

    def read(self, rough: bool = True) -> str:
        """The largest temperature a k_w(T) reads, in words (a run's warnings): the rough surface's
        micro one, or the worn body's macro one (``temperature = "macro"``, or in perfect contact)."""
        return "the rough surface's largest micro temperature" if rough and self.temperature == "surface" else \
            "the worn body's largest macro temperature"

    def held_ends(self, T0: float | None = None, hottest: float | None = None, rough: bool = True) -> list[str]:
        """The k_w(T) (or k(T)) table held at an end: below its first point at the initial temperature
        ``T0`` (check), above its last at ``hottest`` [K] (the largest temperature it read, ``read``,
        after a run; ``rough``: the zones wear, else the facets in perfect contact); [] with a constant
        rate (a run at 1 K or 3000 K wore at the end values without a word)."""
        if self.given in ("k_w", "specific_rate"):
            return []
        temperatures, rates = self.rate
        table = f"wear.{self.given}" if self.given else "wear.k_w_table (absent: thesis Fig. 7.9)"
        name = "k" if self.per_load else "k_w"
        out = []
        for T, where, end, rate, side, beyond in (
                (T0, "the initial temperature", temperatures[0], rates[0], "below its first",
                 T0 is not None and T0 < temperatures[0]),
                (hottest, self.read(rough), temperatures[-1], rates[-1],
                 "above its last", hottest is not None and hottest > temperatures[-1])):
            if beyond:
                out.append(f"{table}: {where}, {T - 273.15:.4g} degC, is {side} point {end - 273.15:.4g} degC: the "
                           f"{'zones' if rough else 'facets'} wear with {name} held at {rate:.3g} 1/Pa there")
        return out

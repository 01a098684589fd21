"""A macro model: mechanics, an optional heat problem, the drive, and the sequential step of thesis
Fig. 7.4.

``MacroModel.macro_step`` advances one macro step Δt in ``substeps`` times {heat step over δt with
the current contact state; contact solve with the new temperatures (thermal expansion) or the new
load}. The drive gives the load and the speed of the sliding body against time: while the load
factor is 0 the contact is released (no solve, no frictional heat, no interface conductance) and
the bodies only exchange heat with their surroundings. The sliding direction does not depend on the
speed's magnitude, so a changing speed needs no contact solve (only its heat changes). ``start``
makes the first (ramped) contact solve; ``record`` gives one history row. The model is built from
plain objects (``multiscale.workflows.model.build_model`` makes one from a scene).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from multiscale.macro.mechanics import Mechanics, SolveResult
from multiscale.macro.mesh import TwoBodyMesh
from multiscale.macro.thermal import Thermal


@dataclass(frozen=True)
class Drive:
    """What drives the sliding contact: the normal load and the sliding speed of body 1.

    ``load``: N (mechanics ``load_kind="force"``) or Pa (pressure or fluid pressure), reached in
    ``ramp_steps`` increments by the first solve, times ``factor(t)`` (0: released); ``speed(t)``:
    rad/s (rotation) or m/s (translation) at time t [s].
    """

    load: float
    speed: Callable[[float], float]
    ramp_steps: int = 1
    factor: Callable[[float], float] = lambda t: 1.0


@dataclass
class MacroModel:
    """Mechanics, heat problem (None without heat) and drive of one macro run."""

    tm: TwoBodyMesh
    mechanics: Mechanics
    thermal: Thermal | None
    drive: Drive
    time: float = 0.0                                  # s
    heat_total: np.ndarray = field(default_factory=lambda: np.zeros(2))   # J, frictional heat in
    last_solve: SolveResult | None = None

    @property
    def contact(self):
        return self.mechanics.contact

    @property
    def problems(self) -> tuple[str, ...]:
        return ("mechanics",) + (("heat",) if self.thermal is not None else ())

    def speed(self, t: float) -> float:
        """Sliding speed of body 1 at time t: rad/s (rotation) or m/s (translation)."""
        return self.drive.speed(t)

    @property
    def released(self) -> bool:
        """True while the load factor is 0 (no contact)."""
        return self.contact.engaged.value == 0.0

    def start(self) -> SolveResult:
        """First contact solve from rest with the drive's load ramp (at the initial load factor;
        a start in a released phase solves at the first engaged load, then releases)."""
        self.contact.speed.value = self.speed(0.0)
        self.last_solve = self.mechanics.ramp(self.drive.load * (self.drive.factor(0.0) or 1.0), self.drive.ramp_steps)
        self.contact.engaged.value = float(self.drive.factor(0.0) > 0)
        return self.last_solve

    def macro_step(self, dt: float, substeps: int = 1) -> np.ndarray:
        """Advance by one macro step dt [s] in ``substeps`` (Fig. 7.4); returns the heat [J] put
        into each body during the step."""
        heat = np.zeros(2)
        delta = dt / substeps
        for _ in range(substeps):
            if self.thermal is not None:
                self.contact.speed.value = self.speed(self.time)
                heat += self.thermal.step(delta).heat_in
            self.time += delta
            self.contact.speed.value = self.speed(self.time)
            factor = self.drive.factor(self.time)
            self.contact.engaged.value = float(factor > 0)
            load = self.drive.load * factor
            if factor > 0 and (self.mechanics.temperatures is not None or load != self.mechanics.load.value):
                self.last_solve = self.mechanics.solve(load)
        self.heat_total += heat
        return heat

    def record(self, heat_step=(0.0, 0.0)) -> dict:
        """One history row at the current state (units: see ``multiscale.io.UNITS``)."""
        on = not self.released
        row = {"time": self.time, "interface_force": self.last_solve.normal_force * on,
               "friction_force": float(np.linalg.norm(self.contact.friction_force())) * on,
               "max_pressure": self.last_solve.max_pressure * on,
               "newton_iterations": self.last_solve.iterations}
        masks = self.tm.interface.masks()
        if len(masks) > 1:                        # per interface (a brake's pads, a disc's pucks)
            p, friction = self.contact.facet_pressure() * on, self.contact.facet_friction() * on
            for name, m in masks.items():
                row[f"interface_force_{name}"] = float(p[m] @ self.tm.interface.areas[m])
                row[f"friction_force_{name}"] = float(np.linalg.norm(friction[m].sum(axis=0)))
                row[f"max_pressure_{name}"] = float(p[m].max(initial=0.0))
        if self.thermal is not None:
            stored, hottest = self.thermal.stored_heat(), self.thermal.max_temperature()
            for i, body in enumerate(self.tm.bodies):
                row[f"max_temperature_{body.name}"] = hottest[i]
                row[f"heat_step_{body.name}"] = heat_step[i]
                row[f"heat_total_{body.name}"] = self.heat_total[i]
                row[f"stored_heat_{body.name}"] = stored[i]
        return row

"""A macro model: mechanics, an optional heat problem, the drive, and the sequential step of thesis
Fig. 7.4.

``MacroModel.macro_step`` advances one macro step Δt in ``substeps`` times {heat step over δt with
the current contact state; contact solve with the new temperatures (thermal expansion) or the new
speed}. ``start`` makes the first (ramped) contact solve; ``record`` gives one history row. The
model is built from plain objects (``multiscale.workflows.model.build_model`` makes one from a
scene).
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
    ``ramp_steps`` increments by the first solve; ``speed(t)``: rad/s (rotation) or m/s
    (translation) at time t [s]; ``steady``: True when the speed never changes (no re-solve for it).
    """

    load: float
    speed: Callable[[float], float]
    ramp_steps: int = 1
    steady: bool = True


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

    def start(self) -> SolveResult:
        """First contact solve from rest with the drive's load ramp."""
        self.contact.speed.value = self.speed(0.0)
        self.last_solve = self.mechanics.ramp(self.drive.load, self.drive.ramp_steps)
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
            speed_changed = not self.drive.steady and self.speed(self.time) != self.speed(self.time - delta)
            if self.mechanics.temperatures is not None or speed_changed:
                self.contact.speed.value = self.speed(self.time)
                self.last_solve = self.mechanics.solve()
        self.heat_total += heat
        return heat

    def record(self, heat_step=(0.0, 0.0)) -> dict:
        """One history row at the current state (units: see ``multiscale.io.UNITS``)."""
        row = {"time": self.time, "interface_force": self.last_solve.normal_force,
               "friction_force": float(np.linalg.norm(self.contact.friction_force())),
               "max_pressure": self.last_solve.max_pressure,
               "newton_iterations": self.last_solve.iterations}
        if self.thermal is not None:
            stored, hottest = self.thermal.stored_heat(), self.thermal.max_temperature()
            for i, body in enumerate(self.tm.bodies):
                row[f"max_temperature_{body.name}"] = hottest[i]
                row[f"heat_step_{body.name}"] = heat_step[i]
                row[f"heat_total_{body.name}"] = self.heat_total[i]
                row[f"stored_heat_{body.name}"] = stored[i]
        return row

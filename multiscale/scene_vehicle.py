"""[loading.vehicle] of a scene (``multiscale.scene_sections.Loading``): one braking event of a
vehicle, a stop or a drag, and the braking force and wheel speed that follow from it."""
from __future__ import annotations

import math
from dataclasses import dataclass

from multiscale.schema import OneOf, Quantity, key

GRAVITY = 9.80665                  # m/s^2, standard gravity


@dataclass(frozen=True)
class Vehicle:
    """[loading.vehicle]: the brake of a vehicle: a stop from ``speed`` at ``deceleration`` (or a
    drag at constant ``speed`` down a ``slope``), the rotating body turning with the wheel
    (omega = v / wheel_radius). With ``mass`` (the vehicle mass braked by this brake) the brake
    load follows from the braking force at the tyre (m a for a stop, m g sin(atan(slope)) for a
    drag): the friction power is then mu F v = that force times the vehicle speed."""

    speed: float | None = key(Quantity("speed", gt=0, plausible=(0.1, 150.0)), required=True)  # m/s, initial
    wheel_radius: float | None = key(Quantity("length", gt=0, plausible=(0.05, 2.0)), required=True)  # m
    deceleration: float | None = key(Quantity("acceleration", gt=0, plausible=(0.01, 15.0)),   # m/s^2: a stop
                                     absent="slope: a drag; neither: a constant speed")
    slope: float | None = key(Quantity("dimensionless", gt=0, plausible=(0.0, 0.5)),   # grade (rise/run): a drag
                              absent="deceleration: a stop; neither: a constant speed")
    mass: float | None = key(Quantity("mass", gt=0, plausible=(1.0, 1e7)),
                             absent="the load: normal_force, pressure or braking_torque")

    rules = (OneOf(("deceleration", "slope")),)

    def problems(self, path, ctx):
        if self.mass is not None and self.deceleration is None and self.slope is None:
            return [f"{path}.mass: needs {path}.deceleration (a stop) or {path}.slope (a drag) for the braking force"]
        return []

    @property
    def stop_time(self) -> float | None:
        """Duration of the stop [s] (None for a drag)."""
        return None if self.deceleration is None else self.speed / self.deceleration

    def angular_speed(self, t: float) -> float:
        """omega(t) [rad/s] of the wheel (and the rotating body)."""
        v = self.speed if self.deceleration is None else max(self.speed - self.deceleration * t, 0.0)
        return v / self.wheel_radius

    @property
    def braking_force(self) -> float | None:
        """Force at the tyre contact [N] that the brake must give (None without a mass)."""
        if self.mass is None:
            return None
        if self.deceleration is not None:
            return self.mass * self.deceleration
        return self.mass * GRAVITY * math.sin(math.atan(self.slope))

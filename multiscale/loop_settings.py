"""The time and update rules of the multiscale loop (``coupling.Multiscale``; the schemes in its docstring)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import InputError

REMOTE = ("rough", "bulk")
COUPLING = ("explicit", "fixed-point", "implicit")


@dataclass(frozen=True)
class LoopSettings:
    """Time and update rules of the loop."""

    dt: float                     # s, macro step
    substeps: int                 # thermo-mechanical sub-steps per macro step
    initial_temperature: float    # K, also the temperature of zones without a heat problem
    partition: float | np.ndarray  # share of the heat into the rough body, per zone, until the first heating (NaN: none)
    partition_law: bool = False   # micro partition per zone (ch. 6) instead of the constant
    wear: bool = False            # Archard wear of the zones
    wear_every: int = 1           # macro steps per wear update
    wear_limit: float = 0.0       # m, material kept behind a worn facet: the run ends below it (0: worn through)
    steps: int | None = None      # macro steps of the run: the last wears the rest of a wear interval
    flash_softening: bool = False  # H(T) of each zone at its last micro flash temperature (plasticity)
    forces: dict = field(default_factory=dict)   # N, per interface: the load it nominally carries
    friction: np.ndarray | None = None            # mu of every zone (its interface's; None: the post-analysis')
    remote: str = "rough"         # remote temperatures of the micro heating: "rough" or "bulk" (module docstring)
    coupling: str = "explicit"    # "explicit", "fixed-point" or "implicit" (module docstring)
    coupling_tol: float = 1e-3    # fixed point: max |G(p) - p| over the loaded zones
    coupling_iterations: int = 30  # fixed point: passes before ConvergenceError
    relaxation: float = 0.5       # fixed point: first relaxation factor

    def __post_init__(self):
        for name, allowed in (("remote", REMOTE), ("coupling", COUPLING)):
            if getattr(self, name) not in allowed:
                raise InputError(name, getattr(self, name), f"one of {', '.join(allowed)}")
        if self.coupling == "implicit" and self.remote != "bulk":
            raise InputError("coupling", self.coupling, 'the implicit coupling conducts between the bulk temperatures: '
                             'remote = "bulk"')
        if not (self.coupling_tol > 0 and self.coupling_iterations >= 1 and 0 < self.relaxation <= 1):
            raise InputError("coupling", (self.coupling_tol, self.coupling_iterations, self.relaxation),
                             "tolerance > 0, iterations >= 1, relaxation in (0, 1]")

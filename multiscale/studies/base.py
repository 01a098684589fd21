"""What a study problem is: ``Problem`` (parameters -> ``Outcome``, the scalar metrics of a run)
and ``jsonable`` (a run's identity for its record key). The registry is ``problems``."""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multiscale.schema import Context, fields_of, suggest

__all__ = ["Outcome", "Problem", "RunFailed", "jsonable"]


@dataclass
class Outcome:
    """What one run of a problem produced."""

    metrics: dict                 # name -> float (SI units, see the problem's ``metrics``)
    iterations: int = 0           # solver iterations, summed over the run's solves (-1: none to count)
    converged: bool = True        # every solve reached its tolerance
    wall_time: float | None = None   # s, the run's own time where the problem knows it better than
    #                                  the worker's clock (a scene run: without its process's start-up)
    warnings: tuple = ()          # what the run found that the study did not say before it ran (``Study.warnings``)


class RunFailed(RuntimeError):
    """A run that failed, with what it had found until then (``Outcome.warnings``: a scene run that
    diverged after its zones pressed beyond the laws' top kept only its error; a review)."""

    def __init__(self, message: str, warnings=()):
        super().__init__(message)
        self.warnings = tuple(warnings)


class Problem:
    """A named problem: ``parse`` validates raw parameters, ``run`` computes the metrics."""

    name: str
    doc: str
    metrics: dict                 # name -> description with unit
    exact_metrics: tuple = ()     # metrics the analytic reference provides
    undefined: frozenset = frozenset()   # metrics that are NaN where what they measure is absent

    def parse(self, raw: dict, path: str, ctx: Context, **options):
        """Validated parameters (problems appended to ``ctx``); ``options``: the scene problem's
        base scene and ranks."""
        raise NotImplementedError

    def key(self, params) -> dict:
        """JSON-able identity of a run's parameters (hashed to name the run's record)."""
        raise NotImplementedError

    def run(self, params, workdir: Path) -> Outcome:
        """One run of validated ``params``; files it writes go under ``workdir``."""
        raise NotImplementedError

    def knob_spec(self, name: str):
        """The schema Spec of parameter ``name`` (None: unknown kind)."""
        params = getattr(self, "params", None)
        return dict(fields_of(params)).get(name) if params is not None else None

    def metric_unit(self, name: str) -> str:
        """The unit of metric ``name`` (``unit_in`` its description), "" if unknown."""
        return unit_in(self.metrics.get(name, ""))

    def check_metric(self, name: str, scene=None, fixed=None) -> str | None:
        """None if ``name`` is a metric of this problem (of its ``scene`` file with the study's
        ``fixed`` keys, for problem "scene"), else the problem (one line)."""
        if name in self.metrics:
            return None
        return f'unknown metric of problem "{self.name}"{suggest(name, self.metrics)}; allowed: ' \
               f'{", ".join(self.metrics)}'


def unit_in(description: str) -> str:
    """The unit a metric's description ends with in brackets ("peak contact pressure [Pa]" ->
    "Pa"), "" if none."""
    unit = re.search(r"\[([^\]]+)\]\s*$", description)
    return unit.group(1) if unit else ""


def jsonable(value):
    """``value`` with tuples as lists, paths as strings and non-finite floats as strings."""
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, float) and not np.isfinite(value):
        return str(value)
    return value

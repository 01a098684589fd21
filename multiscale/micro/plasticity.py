"""Elastic-perfectly-plastic asperities through load histories (issue 18).

The contact solve with a hardness H (``ContactSolver.solve(hardness=H)``: 0 <= p <= H, the
bounded problem of Almqvist et al. 2007, Tribol. Int. 40, 574–579) gives, on the cells at H, the
interpenetration w = d − z − u >= 0 that the surface cannot carry elastically: the permanent
deformation. Carried forward, the patch's topography becomes h − w (heights point to the flat),
so that

- unloading follows the elastic law of the deformed surface (stiffer than the loading curve: the
  flattened summits carry the load on a larger area; ``stiffness.contact_stiffness(...,
  unloading=True)``), and leaves the residual deformation w;
- reloading up to the previous maximum load is that same elastic curve and meets the loading
  curve there (the deformed surface pressed to the previous maximum carries exactly the
  elastic-plastic pressure field: on the yielded cells u + z + w − d = 0 with p = H);
- loading beyond it yields again (the loading branch).

``Hardness`` is H, constant or a table H(T) (the hardness of the softer body at its temperature);
``load_path`` runs a sequence of mean pressures on a batch of patches with that bookkeeping.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multiscale.errors import InputError, check_table
from multiscale.micro.contact import ContactResult, ContactSolver


class Hardness:
    """Hardness H [Pa] of the softer body: ``Hardness(3e8)`` or ``Hardness((temperatures [K],
    values [Pa]))`` with strictly increasing temperatures (linear, held beyond the ends)."""

    def __init__(self, value):
        if np.ndim(value) == 0:
            self.value, self.table = _positive("hardness", value), None
            return
        temps, values = check_table("hardness", value, "a number [Pa] or a (temperatures [K], values [Pa]) table")
        _positive("hardness.values", values)
        self.value, self.table = None, (temps, values)

    @property
    def depends_on_temperature(self) -> bool:
        return self.table is not None

    def __call__(self, temperature=None) -> np.ndarray:
        """H [Pa] at ``temperature`` [K] (any shape; ignored when constant)."""
        if self.table is None:
            return np.asarray(self.value)
        if temperature is None:
            raise InputError("temperature", None, "a temperature-dependent hardness needs a temperature")
        return np.interp(np.asarray(temperature, dtype=float), *self.table)


def _positive(name, value):
    """``value`` (a number or an array) finite and > 0, else ``InputError`` naming it."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = np.asarray(np.nan)
    if not (np.all(np.isfinite(v)) and np.all(v > 0)):
        raise InputError(name, value, "hardness must be finite and > 0 [Pa]")
    return float(v) if v.ndim == 0 else v


@dataclass
class PathStep:
    """One load of ``load_path`` (per-patch arrays of the batch shape)."""

    load: np.ndarray             # Pa, mean pressure
    flat: np.ndarray             # m, height of the rigid flat in the heights' frame: max(h) - d
    area_fraction: np.ndarray    # real contact area / nominal area
    plastic_area_fraction: np.ndarray
    branch: np.ndarray           # "loading" (beyond the previous maximum: new yield) or "reloading"
    result: ContactResult


def load_path(solver: ContactSolver, heights, loads, hardness, *, tol: float = 1e-10) -> tuple[list, np.ndarray]:
    """Press the patches ``heights`` [m] (batch of the solver's grid) to the mean pressures
    ``loads`` [Pa] in turn (a sequence of scalars or batch arrays), with hardness H [Pa] (scalar
    or per patch), carrying the permanent deformation from load to load. Returns the steps and the
    deformed heights h − Σ w. A load at or below the largest one so far is on the elastic
    (un/re)loading branch of the deformed surface; above it, on the loading branch."""
    h = np.array(heights, dtype=float)
    peak = np.zeros(h.shape[:-2])
    steps = []
    for load in loads:
        r = solver.solve(h, load=load, hardness=hardness, tol=tol)
        flat = h.max(axis=(-2, -1)) - r.approach
        branch = np.where(np.asarray(load) > peak, "loading", "reloading")
        peak = np.maximum(peak, load)
        h -= r.plastic
        steps.append(PathStep(np.broadcast_to(load, peak.shape), flat, r.area_fraction,
                              r.plastic_area_fraction, branch, r))
    return steps, h

"""The thermal conditions of the heat problem's surfaces (``macro.thermal``): convection h(speed),
grey-body radiation and fixed temperatures on named surfaces (``ThermalBoundary``), one of them on
one body (``AppliedBoundary``), and the exterior facets a surface name stands for (``surface_rows``).
Every outer surface without a condition is insulated."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from dolfinx import fem
from dolfinx import mesh as dmesh

from multiscale.arrays import unique_rows
from multiscale.errors import InputError, check_positive
from multiscale.macro.mesh import TwoBodyMesh


@dataclass(frozen=True)
class ThermalBoundary:
    """A thermal condition on named surfaces (``TwoBodyMesh.surface`` names: a face, or
    "free:<region or body>"), on every body that holds some of their exterior facets.

    ``convection``: h [W/(m^2 K)], a constant or a callable h(speed) of the rotating body's speed
    [rad/s]; ``emissivity``: eps in (0, 1], radiation eps sigma (T^4 − T_a^4); ``ambient``: T_a [K]
    of both (default: the initial temperature); ``temperature``: a fixed temperature [K] (not
    combined with the others). Fluxes are positive out of the body."""

    surfaces: tuple
    convection: float | Callable[[float], float] | None = None
    emissivity: float | None = None
    ambient: float | None = None
    temperature: float | None = None

    def __post_init__(self):
        if self.temperature is not None and (self.convection is not None or self.emissivity is not None):
            raise InputError("temperature", self.temperature, "a fixed temperature excludes convection and radiation")
        if self.temperature is None and self.convection is None and self.emissivity is None:
            raise InputError("surfaces", self.surfaces, "give convection, emissivity or temperature")

    def h(self, speed: float) -> float:
        """Convection coefficient [W/(m^2 K)] at the speed [rad/s] (0 without convection)."""
        if self.convection is None:
            return 0.0
        value = self.convection(speed) if callable(self.convection) else self.convection
        return check_positive("convection", value, allow_zero=True)


@dataclass
class AppliedBoundary:
    """A ``ThermalBoundary`` on one body: its measure id and, for a fixed temperature, its BC."""

    index: int                     # position in Thermal.boundaries
    body: int
    condition: ThermalBoundary
    ambient: fem.Constant          # K (a form constant: a literal would compile new forms for each value)
    facets: np.ndarray             # facets of the body's submesh (this rank)
    h: fem.Constant | None = None
    bc: fem.DirichletBC | None = None


KINDS = ("temperature", "convection", "emissivity")   # a condition's kinds, each with its own measure id


def kinds(condition: ThermalBoundary) -> tuple[str, ...]:
    """The kinds of condition it gives (``KINDS``)."""
    return tuple(k for k in KINDS if getattr(condition, k) is not None)


def measure_id(k: int, kind: str) -> int:
    """The boundary measure's id of kind ``kind`` of condition ``k`` (its own facets per kind)."""
    return len(KINDS) * k + KINDS.index(kind) + 1


def settle(found: dict, boundaries, comm) -> dict:
    """Rows (cell, local facet) of each condition's kinds on each body, (k, body, kind) -> rows,
    from ``found``: (k, body) -> [(reached through "free:", rows), ...] of ``boundaries[k]``. On a
    facet that one condition names as a face, a condition that reaches it only through a "free:"
    surface does not apply its kinds that the first gives (the face's own convection replaces the
    free surface's there: before, both applied, h twice and the second's ambient defaulted). Two
    conditions of one kind on one facet otherwise are an InputError (collective): the last of two
    fixed temperatures won, two convections added up (found by a user trial)."""
    def key(rows):
        return rows[:, 0].astype(np.int64) * 64 + rows[:, 1]          # a (cell, local facet) row as one number

    empty = np.empty((0, 2), np.int32)
    whole = {ki: unique_rows(np.concatenate([r for _, r in parts] + [empty])).values for ki, parts in found.items()}
    named = {ki: key(np.concatenate([r for free, r in parts if not free] + [empty])) for ki, parts in found.items()}
    out = {}
    for (k, i), rows in whole.items():
        for kind in kinds(boundaries[k]):
            theirs = [named[j, b] for j, b in found if b == i and j != k and kind in kinds(boundaries[j])]
            taken = np.concatenate(theirs + [np.empty(0, np.int64)])
            out[k, i, kind] = rows[~(np.isin(key(rows), taken) & ~np.isin(key(rows), named[k, i]))]
    for (k, i, kind), rows in out.items():
        for (j, b, other), more in out.items():
            if j > k and b == i and other == kind:
                n = comm.allreduce(np.isin(key(rows), key(more)).sum())
                if n:
                    raise InputError(f"boundary[{k + 1}] and boundary[{j + 1}]", kind,
                                     f"both give it on {n} facets: give each facet one (a face named in one "
                                     'entry replaces what a "free:" surface of another gives there)')
    return out


def surface_rows(tm: TwoBodyMesh, name: str) -> np.ndarray:
    """(cell, local facet) rows (n, 2) on the parent mesh of the exterior facets of a named surface
    owned by this rank."""
    if name.startswith("free:"):
        (_, rows), = tm.surface(name).subdomain_data()
        return np.asarray(rows, dtype=np.int32).reshape(-1, 2)
    facets = np.intersect1d(tm.facet_tags.find(tm.face(name)), dmesh.exterior_facet_indices(tm.parent.topology))
    rows = fem.compute_integration_domains(fem.IntegralType.exterior_facet, tm.parent.topology,
                                           facets.astype(np.int32))
    return np.asarray(rows, dtype=np.int32).reshape(-1, 2)


__all__ = ["AppliedBoundary", "KINDS", "ThermalBoundary", "kinds", "measure_id", "settle", "surface_rows"]

"""Material properties in the macro forms: constants per region, or functions of the temperature.

A property of a material (``multiscale.scene.Material``: E, nu, rho, kappa, c, chi, alpha) is a
constant or a table ((T_1, y_1), ..., (T_n, y_n)) against the temperature T [K], interpolated
linearly and held constant beyond its ends. In the forms of a body:

- if every region of the body has a constant value (or no temperature field is given), the
  property is a DG0 field, one value per region: exactly the forms of the constant-material model
  (a table is then taken at the reference temperature, e.g. the density of the squeal mass matrix
  or the stiffness of a model without thermal expansion);
- otherwise it is the UFL expression sum_r 1_r y_r(T) of the body's temperature field, 1_r the
  indicator (DG0) of region r, with for a table

      y(T) = y_1 + sum_k s_k [clamp(T, T_k, T_{k+1}) − T_k],   s_k = (y_{k+1} − y_k)/(T_{k+1} − T_k),

  which is the linear interpolation, constant beyond the ends, with its exact derivative in
  Newton's tangent.

Heat capacity and enthalpy. The volumetric heat capacity rho c(T) [J/(m^3 K)] is rho(T) c(T) (or
kappa(T)/chi(T) when the material gives the diffusivity) at the union of the breakpoints of its
factors, linear in between (``heat_capacity``). The enthalpy per unit volume from the initial
temperature T_0,

      e(T) = ∫_{T_0}^{T} rho c(s) ds = y_1 (T − T_0) + sum_k s_k [phi_k(T) − phi_k(T_0)],
      phi_k(T) = (clamp(T, T_k, T_{k+1}) − T_k)^2 / 2 + (T_{k+1} − T_k) max(T − T_{k+1}, 0),

is piecewise quadratic and C^1 (``BodyProperty.integral``). The heat equation written with
de/dt conserves energy exactly in time: the heat stored over a backward-Euler step is
∫ (e(T^{n+1}) − e(T^n)) dx, whatever the temperature dependence.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import ufl

from multiscale.errors import InputError
from multiscale.macro.mesh import Body, TwoBodyMesh


def interpolate(table, T: float) -> float:
    """Linear interpolation of ((T_k, y_k), ...) at T, constant beyond the ends (float)."""
    T = float(T)
    return float(table[0][1]) + sum(s * (min(max(T, a), b) - a) for a, b, s in _segments(table))


def _segments(table):
    """(T_k, T_{k+1}, slope) of each interval of a table."""
    return [(float(a), float(b), (float(yb) - float(ya)) / (float(b) - float(a)))
            for (a, ya), (b, yb) in zip(table, table[1:])]


def table_expression(table, T):
    """UFL: the table's linear interpolation at the temperature expression T (see module docstring)."""
    out = ufl.as_ufl(float(table[0][1]))
    for a, b, s in _segments(table):
        out = out + s * (ufl.min_value(ufl.max_value(T, a), b) - a)
    return out


def _phi(T, a: float, b: float, floats: bool):
    if floats:
        c = min(max(T, a), b)
        return (c - a) ** 2 / 2 + (b - a) * max(T - b, 0.0)
    c = ufl.min_value(ufl.max_value(T, a), b)
    return (c - a) ** 2 / 2 + (b - a) * ufl.max_value(T - b, 0.0)


def table_integral(table, T, T0):
    """UFL: ∫_{T0}^{T} y(s) ds of the table's interpolation y (piecewise quadratic in T); T0 [K] a
    number or a ``fem.Constant`` (whose value is taken now in the table's segments)."""
    out = float(table[0][1]) * (T - T0)
    t0 = float(getattr(T0, "value", T0))
    for a, b, s in _segments(table):
        out = out + s * (_phi(T, a, b, False) - _phi(t0, a, b, True))
    return out


def heat_capacity(material) -> float | tuple | None:
    """Volumetric heat capacity rho c [J/(m^3 K)] of a material: rho c (or kappa/chi), a constant,
    or a table at the union of the breakpoints of its factors (see module docstring); None if
    the material gives neither rho and c nor kappa and chi."""
    if getattr(material, "c", None) is not None and getattr(material, "rho", None) is not None:
        factors, combine = ("rho", "c"), (lambda x, y: x * y)
    elif getattr(material, "chi", None) is not None and getattr(material, "kappa", None) is not None:
        factors, combine = ("kappa", "chi"), (lambda x, y: x / y)
    else:
        return None
    values = [getattr(material, f) for f in factors]
    if not any(isinstance(v, tuple) for v in values):
        return combine(*values)
    points = sorted({float(T) for v in values if isinstance(v, tuple) for T, _ in v})
    at = [[interpolate(v, T) if isinstance(v, tuple) else v for T in points] for v in values]
    return tuple((T, combine(x, y)) for T, x, y in zip(points, *at))


@dataclass
class BodyProperty:
    """One material property on one body: ``values`` maps each region tag to a constant or a
    temperature table."""

    body: Body
    name: str
    values: dict

    @property
    def constant(self) -> bool:
        return not any(isinstance(v, tuple) for v in self.values.values())

    def field(self, temperature: float | None = None):
        """DG0 field, tables taken at ``temperature`` [K]."""
        at = {}
        for tag, v in self.values.items():
            if isinstance(v, tuple):
                if temperature is None:
                    raise InputError(f"materials.{self.name}", v, "a temperature table needs a temperature here")
                v = interpolate(v, temperature)
            at[tag] = float(v)
        return self.body.cell_field(f"{self.name}_{self.body.name}", at)

    def _by_region(self, of_table: Callable, of_constant: Callable):
        """sum_r 1_r f_r: tables through ``of_table(table)``, constants ``of_constant(field)`` with
        one DG0 field holding the constants (0 in the tabulated regions)."""
        tables = {tag: v for tag, v in self.values.items() if isinstance(v, tuple)}
        if len(self.values) == 1:
            return of_table(next(iter(tables.values())))
        rest = {tag: (0.0 if tag in tables else float(v)) for tag, v in self.values.items()}
        out = of_constant(self.body.cell_field(f"{self.name}_{self.body.name}", rest)) \
            if len(tables) < len(self.values) else 0
        for tag, table in tables.items():
            indicator = self.body.cell_field(f"{self.name}_region_{tag}",
                                             {t: float(t == tag) for t in self.values})
            out = out + indicator * of_table(table)
        return out

    def expression(self, T, reference: float | None = None):
        """The property at the temperature field T: a DG0 field if constant (or T is None: tables
        at ``reference``), else the UFL expression of T."""
        if self.constant or T is None:
            return self.field(reference)
        return self._by_region(lambda table: table_expression(table, T), lambda f: f)

    def integral(self, T, T0):
        """UFL: ∫_{T0}^{T} y(s) ds, the enthalpy e(T) for the heat capacity (module docstring)."""
        return self._by_region(lambda table: table_integral(table, T, T0), lambda f: f * (T - T0))


def property_values(tm: TwoBodyMesh, materials: Mapping[str, object], name: str, of=None) -> dict:
    """{material name: constant or table} of the materials the geometry uses; ``of(material)``
    gives the value (default the attribute ``name``); a missing material or value raises
    InputError naming the scene field."""
    out = {}
    for m in tm.spec.materials:
        if m not in materials:
            raise InputError(f"materials.{m}", None, "this material is used by the geometry and is missing")
        value = of(materials[m]) if of is not None else getattr(materials[m], name, None)
        if value is None:
            raise InputError(f"materials.{m}.{name}", None, "required by this model")
        out[m] = value if isinstance(value, tuple) else float(value)
    return out


def body_properties(tm: TwoBodyMesh, materials: Mapping[str, object], name: str, of=None) -> list[BodyProperty]:
    """The property ``name`` on each body (see ``property_values`` for ``of``)."""
    values = property_values(tm, materials, name, of)
    return [BodyProperty(b, name, {r.tag: values[r.material] for r in b.spec.regions}) for b in tm.bodies]


def body_fields(tm: TwoBodyMesh, materials: Mapping[str, object], name: str,
                temperature: float | None = None, of=None) -> list:
    """Per-body DG0 fields (constant per region) of a property, tables taken at ``temperature`` [K]."""
    return [p.field(temperature) for p in body_properties(tm, materials, name, of)]


def body_expressions(tm: TwoBodyMesh, materials: Mapping[str, object], name: str,
                     temperatures: Sequence | None, reference: float) -> list:
    """Per body: the property as a DG0 field, or as a UFL expression of the body's temperature
    (``temperatures[i]``) where a region has a table; without temperatures tables are taken at
    ``reference`` [K]."""
    props = body_properties(tm, materials, name)
    return [p.expression(None if temperatures is None else temperatures[i], reference)
            for i, p in enumerate(props)]

"""Unit strings -> SI numbers, used at the border (scene and study files).

``to_si("200 rpm", "angular_speed") == 20.944`` rad/s. A value is a number (taken as SI) or a
string "<number> <unit>": units multiply by juxtaposition, space or ``*``, divide with ``/``
(everything up to the next ``/`` or ``)`` is the denominator: ``W/m K`` = ``W/(m K)``), and take
integer powers with ``^``, ``**`` or superscripts (``kg/m^3``, ``m²/s``, ``1/K``). SI prefixes
G M k c m u µ n p apply to m g s N Pa bar W J Hz rad; ``gn`` is the standard gravity
(9.80665 m/s²), ``t`` the tonne, ``in`` the inch. The angle is its own dimension (so "rpm"
and "Hz" are not confused): ``rad``, ``deg``, ``rev``; ``rpm`` = rev/min. ``degC`` alone is an
absolute temperature (+273.15 K); inside a compound unit (``1/degC``) it is a kelvin, and a
compound unit of temperature with it (``(degC)``, ``degC^1``) is refused. ``%`` is
0.01. Temperatures must carry their unit (a bare 20 would be 20 K).
"""
from __future__ import annotations

import difflib
import functools
import math
import re
from dataclasses import dataclass
from fractions import Fraction

__all__ = ["KINDS", "VALUE", "Kind", "UnitError", "parse_unit", "plausible_in", "to_si", "unit_advice"]

# Dimension exponents over the base units (m, kg, s, K, rad).
_BASE = ("m", "kg", "s", "K", "rad")
L, M, T, TH, A = ((1, 0, 0, 0, 0), (0, 1, 0, 0, 0), (0, 0, 1, 0, 0), (0, 0, 0, 1, 0), (0, 0, 0, 0, 1))
ONE = (0, 0, 0, 0, 0)


def _dim(*pairs) -> tuple[int, ...]:
    """Dimension from (base, power) pairs, e.g. _dim((L, 1), (T, -1)) for a speed."""
    out = [0] * 5
    for base, power in pairs:
        for i, b in enumerate(base):
            out[i] += b * power
    return tuple(out)


class UnitError(ValueError):
    """A unit string that cannot be read, or a unit of the wrong dimension (message says which)."""


@dataclass(frozen=True)
class Kind:
    """A physical quantity kind: its dimension, SI unit and examples for error messages."""

    name: str                 # what the user reads ("pressure or modulus")
    dim: tuple[int, ...]      # exponents of (m, kg, s, K, rad)
    si: str                   # SI unit the value is stored in
    examples: str             # accepted spellings, for messages
    needs_unit: bool = False  # bare numbers refused (temperatures: 20 would silently be 20 K)
    unit_advised: bool = False  # bare numbers warned of (angular speeds: 300 is rad/s where rpm is meant)
    advice: str = ""          # said with the units a bare number would be plausible in


KINDS: dict[str, Kind] = {
    "dimensionless": Kind("dimensionless number", ONE, "", "a plain number, or a percentage like \"14 %\""),
    "length": Kind("length", L, "m", "m, mm, um"),
    "area": Kind("area", _dim((L, 2)), "m^2", "m^2, mm^2"),
    "angle": Kind("angle", A, "rad", "rad, deg"),
    "time": Kind("time", T, "s", "s, ms, min, h"),
    "frequency": Kind("frequency", _dim((T, -1)), "Hz", "Hz, kHz"),
    "rate": Kind("rate", _dim((T, -1)), "1/s", "1/s"),       # e.g. Rayleigh's alpha (not a frequency: no 2 pi)
    "speed": Kind("speed", _dim((L, 1), (T, -1)), "m/s", "m/s, mm/s"),
    "acceleration": Kind("acceleration", _dim((L, 1), (T, -2)), "m/s^2", "m/s^2, gn"),
    "mass": Kind("mass", M, "kg", "kg, t"),
    "angular_speed": Kind("angular speed", _dim((A, 1), (T, -1)), "rad/s", "rpm, rad/s", unit_advised=True),
    "force": Kind("force", _dim((M, 1), (L, 1), (T, -2)), "N", "N, kN"),
    "torque": Kind("torque", _dim((M, 1), (L, 2), (T, -2)), "N m", "N m, kN m"),
    "pressure": Kind("pressure or modulus", _dim((M, 1), (L, -1), (T, -2)), "Pa", "Pa, kPa, MPa, GPa, bar"),
    "stiffness": Kind("stiffness per area", _dim((M, 1), (L, -2), (T, -2)), "Pa/m", "Pa/m, N/mm^3"),
    "temperature": Kind("temperature", TH, "K", "K, degC", needs_unit=True),
    "expansion": Kind("thermal expansion coefficient", _dim((TH, -1)), "1/K", "1/K"),
    "density": Kind("density", _dim((M, 1), (L, -3)), "kg/m^3", "kg/m^3, g/cm^3"),
    "conductivity": Kind("thermal conductivity", _dim((M, 1), (L, 1), (T, -3), (TH, -1)), "W/(m K)",
                         "W/(m K)"),
    "specific_heat": Kind("specific heat capacity", _dim((L, 2), (T, -2), (TH, -1)), "J/(kg K)",
                          "J/(kg K)"),
    "diffusivity": Kind("thermal diffusivity", _dim((L, 2), (T, -1)), "m^2/s", "m^2/s, mm^2/s"),
    "conductance": Kind("thermal conductance per area", _dim((M, 1), (T, -3), (TH, -1)), "W/(m^2 K)",
                        "W/(m^2 K)"),
    "resistance": Kind("thermal contact resistance per area", _dim((M, -1), (T, 3), (TH, 1)), "m^2 K/W",
                       "m^2 K/W"),
    "wear_rate": Kind("wear rate per frictional work (dh = k_w mu p ds: a specific wear rate K per normal load "
                      "is k_w = K/mu)", _dim((M, -1), (L, 1), (T, 2)), "1/Pa", "1/Pa, 1/MPa, m^2/N, mm^3/(N m)",
                      advice="per frictional work: a specific wear rate k = V/(F s) per normal load, as tribometers "
                             "give it in mm^3/(N m), is k_w = k/mu, or wear.specific_rate itself"),
    "specific_wear_rate": Kind("specific wear rate per normal load and sliding distance (k = V/(F s): dh = k p ds)",
                               _dim((M, -1), (L, 1), (T, 2)), "1/Pa", "mm^3/(N m), m^3/(N m), 1/Pa"),
}

_FORCE, _PRESSURE = KINDS["force"].dim, KINDS["pressure"].dim
_ENERGY, _POWER = _dim((M, 1), (L, 2), (T, -2)), _dim((M, 1), (L, 2), (T, -3))
_OTHER_NAMES = {_ENERGY: "energy", _POWER: "power", M: "mass", _dim((M, 1), (T, -3)): "heat flux"}
# symbol: (exact factor to SI, dimension, takes SI prefixes); factors are Fractions so that
# "10 um" is exactly the float 1e-05 (the decimal number times the factor, rounded once).
_F = Fraction
_LBF = _F("4.4482216152605")         # N, the pound-force (0.45359237 kg x 9.80665 m/s^2)
_UNITS: dict[str, tuple[Fraction, tuple[int, ...], bool]] = {
    "m": (_F(1), L, True), "g": (_F(1, 1000), M, True), "s": (_F(1), T, True), "K": (_F(1), TH, False),
    "N": (_F(1), _FORCE, True), "Pa": (_F(1), _PRESSURE, True), "bar": (_F(10**5), _PRESSURE, True),
    "J": (_F(1), _ENERGY, True), "W": (_F(1), _POWER, True),
    "Hz": (_F(1), _dim((T, -1)), True), "rad": (_F(1), A, True),
    "min": (_F(60), T, False), "h": (_F(3600), T, False),
    "deg": (_F(math.pi / 180), A, False), "°": (_F(math.pi / 180), A, False),
    "rev": (_F(2 * math.pi), A, False), "rpm": (_F(2 * math.pi) / 60, _dim((A, 1), (T, -1)), False),
    "degC": (_F(1), TH, False), "°C": (_F(1), TH, False), "%": (_F(1, 100), ONE, False),
    "gn": (_F("9.80665"), _dim((L, 1), (T, -2)), False), "t": (_F(1000), M, False),
    "in": (_F("0.0254"), L, False), "ft": (_F("0.3048"), L, False), "lb": (_F("0.45359237"), M, False),
    "lbf": (_LBF, _FORCE, False), "psi": (_LBF / _F("0.0254") ** 2, _PRESSURE, False),      # exact (NIST SP 811)
    "ksi": (1000 * _LBF / _F("0.0254") ** 2, _PRESSURE, False), "mph": (_F("0.44704"), _dim((L, 1), (T, -1)), False),
}
_ABSOLUTE = {"degC": _F("273.15"), "°C": _F("273.15")}   # offsets of a whole-unit absolute temperature
_SPELLED = {"kmh": "km/h", "kph": "km/h", "kmph": "km/h", "G": "gn"}   # other spellings
_TYPED = {"°C": "degC"}          # a suggestion as a keyboard types it ("20 C": "degC", not "°C")
_PREFIXES = {"G": _F(10**9), "M": _F(10**6), "k": _F(1000), "c": _F(1, 100), "m": _F(1, 1000),
             "u": _F(1, 10**6), "µ": _F(1, 10**6), "μ": _F(1, 10**6), "n": _F(1, 10**9),
             "p": _F(1, 10**12)}
_FAHRENHEIT, _KELVIN, _CALORIE = ("Fahrenheit is not read: give the temperature in degC or K",
                                   'the kelvin is written "K"', "the calorie is not read: 1 cal = 4.184 J")
_NOT_READ = {"degF": _FAHRENHEIT, "°F": _FAHRENHEIT, "degK": _KELVIN, "°K": _KELVIN,    # advice, not a look-alike
             "cal": _CALORIE, "kcal": _CALORIE, "ppm": "ppm is not read: write 1e-6 (or %)"}
_SUPERSCRIPT = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-")
_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
VALUE = re.compile(rf"^\s*({_NUMBER})\s*(.*?)\s*$")       # "<number> <unit>": groups number, unit
_TOKEN = re.compile(r"\s*(?:(?P<num>\d+\.?\d*(?:[eE][+-]?\d+)?)|(?P<name>°C|[A-Za-zµμ°%]+)"
                    r"|(?P<sup>[⁰¹²³⁴⁵⁶⁷⁸⁹⁻]+)|(?P<op>\*\*|[/*·^()]|-?\d+))")


def _lookup(name: str) -> tuple[Fraction, tuple[int, ...]]:
    if name in _UNITS:
        factor, dim, _ = _UNITS[name]
        return factor, dim
    if len(name) > 1 and name[0] in _PREFIXES:
        base = _UNITS.get(name[1:])
        if base is not None and base[2]:
            return _PREFIXES[name[0]] * base[0], base[1]
    if name in _NOT_READ:
        raise UnitError(f'unknown unit "{name}": {_NOT_READ[name]}')
    spelled = _SPELLED.get(name, _SPELLED.get(name.lower()))
    if spelled:                          # (by spelling alone "kmh" was "mph" and "G" "Gs": a user trial)
        raise UnitError(f'unknown unit "{name}" (did you mean "{spelled}"?)')
    known = list(_UNITS) + [p + u for u, (_, _, pre) in _UNITS.items() if pre for p in "GMkmu"]
    split = next((f"{name[:i]} {name[i:]}" for i in range(1, len(name)) if {name[:i], name[i:]} <= set(known)), None)
    near = [split] if split else difflib.get_close_matches(name, known, n=1, cutoff=0.5)   # "Nm": "N m", not "m"
    hint = f' (did you mean "{_TYPED.get(near[0], near[0])}"?)' if near else ""
    raise UnitError(f'unknown unit "{name}"{hint}')


class _Parser:
    """Recursive descent over tokens: expr := product ('/' product)*; product := power+;
    power := atom [('^' | '**') int | superscript]; atom := NAME | NUMBER | '(' expr ')'."""

    def __init__(self, text: str):
        self.tokens, pos = [], 0
        text = text.strip()
        while pos < len(text):
            match = _TOKEN.match(text, pos)
            if not match or match.end() == pos:
                raise UnitError(f'cannot read unit "{text}" at "{text[pos:].strip()}"')
            kind = match.lastgroup
            self.tokens.append((kind, match.group(kind)))
            pos = match.end()
        self.i = 0

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else (None, None)

    def take(self):
        token = self.peek()
        self.i += 1
        return token

    def expr(self) -> tuple[Fraction, tuple[int, ...]]:
        factor, dim = self.product()
        while self.peek() == ("op", "/"):
            self.take()
            f2, d2 = self.product()
            factor, dim = factor / f2, tuple(a - b for a, b in zip(dim, d2))
        return factor, dim

    def product(self):
        factor, dim = self.power()
        while self.peek()[0] in ("name", "num") or self.peek()[1] in ("(", "*", "·"):
            if self.peek()[1] in ("*", "·"):
                self.take()
            f2, d2 = self.power()
            factor, dim = factor * f2, tuple(a + b for a, b in zip(dim, d2))
        return factor, dim

    def power(self):
        factor, dim = self.atom()
        kind, tok = self.peek()
        exponent = None
        if kind == "op" and tok in ("^", "**"):
            self.take()
            kind, tok = self.take()
            if tok == "(":
                kind, tok = self.take()
                if self.take() != ("op", ")"):
                    raise UnitError("expected ')' after the exponent")
            exponent = tok
        elif kind == "sup":
            self.take()
            exponent = tok.translate(_SUPERSCRIPT)
        if exponent is None:
            return factor, dim
        try:
            n = int(exponent)
        except (TypeError, ValueError):
            raise UnitError(f'exponent must be an integer, got "{exponent}"') from None
        return factor**n, tuple(d * n for d in dim)

    def atom(self):
        kind, tok = self.take()
        if kind == "name":
            return _lookup(tok)
        if kind == "num" or (kind == "op" and tok.isdigit()):
            if self.i != 1 or _F(tok) != 1:      # only the 1 of "1/K": "0.4 5" is a typo, not 2.0
                before = self.tokens[self.i - 2] if self.i >= 2 else ("", "")
                power = f' (a power is written with "^": "{before[1]}^{tok}")' if before[0] == "name" else ""
                raise UnitError(f'a number ("{tok}") inside a unit: only "1/<unit>" may start with one{power}')
            return _F(tok), ONE
        if tok == "(":
            inner = self.expr()
            if self.take() != ("op", ")"):
                raise UnitError("unbalanced parentheses")
            return inner
        raise UnitError("unexpected end of unit" if tok is None else f'unexpected "{tok}"')


@functools.lru_cache(maxsize=256)
def parse_unit(text: str) -> tuple[Fraction, Fraction, tuple[int, ...]]:
    """Unit string -> (factor, offset, dimension): SI value = number * factor + offset (exact)."""
    text = text.strip()
    if not text:
        return _F(1), _F(0), ONE
    if text in _ABSOLUTE:
        return _F(1), _ABSOLUTE[text], TH
    parser = _Parser(text)
    factor, dim = parser.expr()
    if parser.i != len(parser.tokens):
        raise UnitError(f'cannot read unit "{text}" at "{parser.peek()[1]}"')
    if dim == TH and any(tok in _ABSOLUTE for _, tok in parser.tokens):   # "(degC)" would be a kelvin
        raise UnitError(f'write a temperature in degrees Celsius as "<number> degC" (the unit "{text}" '
                        "would read degC as a kelvin, without the 273.15)")
    return factor, _F(0), dim


def _name(dim: tuple[int, ...]) -> str | None:
    """The name of a dimension: a kind's, or another quantity's (energy, power, ...); None if none."""
    return next((kind.name for kind in KINDS.values() if kind.dim == dim), _OTHER_NAMES.get(dim))


def describe(dim: tuple[int, ...]) -> str:
    """A dimension in words: the kind's name if one matches, else base units (kg m^-1 s^-2)."""
    if _name(dim) is not None:
        return _name(dim)
    parts = [b if p == 1 else f"{b}^{p}" for b, p in zip(_BASE, dim) if p]
    return " ".join(parts) or "dimensionless"


def unit_advice(raw, kind: Kind) -> list[str]:
    """What to say of a bare number ``raw`` of a kind whose bare numbers are warned of
    (``Kind.unit_advised``: 300 is rad/s where rpm was meant, silently before: a user trial); else []."""
    if not (kind.unit_advised and isinstance(raw, (int, float)) and not isinstance(raw, bool) and raw):
        return []
    return [f"a number without a unit is taken in {kind.si}, {raw:g} {kind.si} = {raw * 30 / math.pi:.4g} rpm; "
            f'write "{raw:g} rpm" if that is meant, "{raw:g} {kind.si}" to say so']


def to_si(value, kind: str) -> float:
    """A TOML value (number or "<number> <unit>") as a float in the SI unit of ``kind``.

    Raises UnitError with a one-line reason (what was expected, e.g. "use Pa, MPa, GPa, bar").
    """
    spec = KINDS[kind]
    expect = f"expected {_a(spec.name)} ({spec.examples})"
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise UnitError(f"{expect}, got a {type(value).__name__}")
    if isinstance(value, float) and not math.isfinite(value):
        raise UnitError("must be a finite number")
    if isinstance(value, (int, float)):
        if spec.needs_unit:
            raise UnitError(f'{_a(spec.name)} needs its unit, e.g. "{value} degC" or "{value} K"')
        number, (factor, offset, dim) = _F(value), (_F(1), _F(0), spec.dim)
    else:
        match = VALUE.match(value)
        if not match:
            raise UnitError(f'{expect}: write a number then a unit, like "{_example(spec)}"')
        number = _F(match.group(1))
        if not match.group(2) and spec.needs_unit:
            raise UnitError(f'{_a(spec.name)} needs its unit, e.g. "{match.group(1)} degC"')
        try:
            factor, offset, dim = parse_unit(match.group(2))
        except UnitError as exc:          # a look-alike of this kind's units first: "mpa" is MPa here, not mPa
            whole = re.fullmatch(r'unknown unit "(.*?)"(?: \(did you mean ".*"\?\))?', str(exc))
            near = _kind_unit(match.group(2), spec) if whole and whole.group(1) == match.group(2) else None
            if near is None:
                raise
            raise UnitError(f'unknown unit "{match.group(2)}" (did you mean "{near}"?)') from None
        if dim != spec.dim and not match.group(2):
            raise UnitError(f'{expect}: a quoted number needs its unit, like "{match.group(1)} {spec.si}" (a '
                            f'number without quotes is taken in {spec.si})')
        if dim != spec.dim:
            gravity = ' (standard gravity is "gn")' if match.group(2) == "g" and spec.name == "acceleration" else ""
            turns = (f': a turning speed is "{match.group(1)} rpm" (revolutions a minute) or "{match.group(1)} rad/s" '
                     f'("{match.group(2)}" does not say revolutions or radians)' if dim == _dim((T, -1))
                     and spec.dim == _dim((A, 1), (T, -1)) else "")
            raise UnitError(f"{expect}; the unit \"{match.group(2)}\" is {_mismatch(dim, spec)}{gravity}{turns}")
    try:
        return float(number * factor + offset)
    except OverflowError:
        raise UnitError("must be a finite number") from None


def _mismatch(dim: tuple[int, ...], spec: Kind) -> str:
    """What a unit of dimension ``dim`` is, against ``spec``'s: a kind's name, or this one's times or
    per a kind ("mm^3/N" for a wear rate per frictional work: "that times a length"), or SI base units."""
    if _name(dim) is not None:
        return _a(_name(dim))
    for sign, words in ((1, "that times"), (-1, "that per")):
        off = _name(tuple(sign * (d - e) for d, e in zip(dim, spec.dim)))
        if off is not None:
            return f"{words} {_a(off)} ({describe(dim)} in SI base units)"
    return f"{describe(dim)} in SI base units"


def plausible_in(raw, spec: Kind, low: float, high: float) -> str:
    """For a bare number ``raw`` (no unit, read in SI) outside [low, high]: the units among ``spec``'s
    examples in which it would be inside, as a clause (' (as "2e-05 mm^3/(N m)" it would be
    plausible)': k_w = 2e-5 meant in mm^3/(N m), user trial M; with the kind's ``advice``: a pad
    developer took that unit for K's, a trial); "" for none or a written unit."""
    number, written = VALUE.match(raw).groups() if isinstance(raw, str) else (f"{raw:g}", "")
    fits = []
    for unit in ([] if written else [u.strip() for u in spec.examples.split(",")]):
        try:
            factor, offset, dim = parse_unit(unit)
        except UnitError:
            continue
        if dim == spec.dim and factor != 1 and low <= float(_F(number) * factor + offset) <= high:
            fits.append(f'"{number} {unit}"')
    advice = f"; {spec.advice}" if spec.advice else ""
    return f" (as {' or '.join(fits)} it would be plausible{advice})" if fits else ""


def _kind_unit(text: str, spec: Kind) -> str | None:
    """The unit of ``spec``'s dimension that ``text`` likely meant: one written alike but for case
    (its examples first: "mpa" is MPa, "kn" kN), else the closest (difflib); None if none is close."""
    named = [u.strip() for u in spec.examples.split(",")] + \
        [p + u for u, (_, dim, pre) in _UNITS.items() if dim == spec.dim for p in ("", *("GMkmu" if pre else ""))]
    spelled = _SPELLED.get(text, _SPELLED.get(text.lower()))
    if spelled and parse_unit(spelled)[2] == spec.dim:     # ("200 G" for a pressure is GPa, not gn: a review)
        return spelled
    same = [u for u in named if u.lower() == text.lower()]
    near = same[0] if same else next(iter(difflib.get_close_matches(text, named, n=1, cutoff=0.5)), None)
    return _TYPED.get(near, near)


def _a(words: str) -> str:
    return ("an " if words[0] in "aeiou" else "a ") + words


def _example(spec: Kind) -> str:
    return "1 " + spec.examples.split(",")[0].split(" or ")[0].strip('"') if spec.si else "0.5"

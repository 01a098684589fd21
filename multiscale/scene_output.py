"""The [output] table of a scene (``multiscale.scene``): the results folder, the fields of the
ParaView files and when they are written, the figures, and the temperature probes (thermocouples:
history columns ``probe_temperature_<name>``, ``multiscale.macro.probes``)."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from multiscale.outputs import name_problem
from multiscale.scene_geometry import POINT
from multiscale.schema import Choice, FilePath, Flag, FrozenMap, Integer, ListOf, Named, Text, key

# output field -> effects it needs
OUTPUT_FIELDS: dict[str, tuple[str, ...]] = {
    "displacement": (), "von_mises": (), "contact_pressure": ("contact",),
    "temperature": ("thermal",), "heat_flux": ("thermal", "friction"), "friction_coefficient": ("friction",),
    "contact_stiffness": ("roughness",), "partition": ("heat_partition",), "wear_depth": ("wear",),
    "flash_temperature": ("roughness", "heat_partition"), "counter_wear_depth": ("wear",), "interface": (),
}


@dataclass(frozen=True)
class Probe:
    """A thermocouple: the temperature [K] at ``point`` (the geometry's frame) in ``body``, the history
    column ``probe_temperature_<name>`` (with effect "thermal"). The rotating body's heat is solved in
    a fixed frame: there a probe stays at its place in space (a rubbing thermocouple, a pyrometer's
    spot) unless it ``turns`` with the body (a thermocouple embedded in the disc): the mean round its
    circle about the axis (``multiscale.macro.probes``). ``body`` may name a part of a body (a pad,
    not its backplate). The run says each probe's body, part and distance from the interface, and
    at its end each probe that a worn face reached (the bodies keep their shapes: it read on)."""

    point: tuple | None = key(POINT, required=True)        # m, [x, y, z]
    body: str | None = key(Text(), absent="the body holding the point (on the interface: give it); or a part")
    turns: bool = key(Flag(), default=False)                # embedded in the rotating body, turning with it


@dataclass(frozen=True)
class Output:
    """Where and what to write. ``folder``: the results folder (a relative path from the scene
    file's folder; a run refuses a folder holding results unless --overwrite or --resume).
    ``fields``: the fields of the ParaView files (XDMF), written at t = 0, every ``every`` macro
    steps and at the end. ``figures``: the PNG figures (false: their data files only).
    ``repeatable``: the macro Newton renews its factors by count instead of measured time, so that
    serial runs repeat bit for bit (regression checks). ``probes``: named thermocouples (``Probe``)."""

    folder: Path | None = key(FilePath(folder=True), absent="results/<name> next to the scene file")
    every: int = key(Integer(ge=1), default=1)            # write fields every n macro steps
    fields: tuple = key(ListOf(Choice(OUTPUT_FIELDS), unique=True), absent="every field the effects produce")
    figures: bool = key(Flag(), default=True)           # the PNG figures (false: their tables and fields only)
    repeatable: bool = key(Flag(), default=False)       # Newton factors renewed by count, not time: repeat bit for bit
    probes: FrozenMap = key(Named(Probe), default=FrozenMap())


def output_problems(output: Output, bodies: tuple | None, parts: dict, rotating: bool,
                    effects) -> tuple[list[str], list[str]]:
    """(problems, warnings) of ``output`` against the geometry's ``bodies`` (stationary, moving;
    None: unknown) and ``parts`` (their regions: part name -> body name), whether the moving one
    ``rotating``, and the active ``effects``."""
    problems = [f'output.fields: "{f}" needs effect "{missing[0]}" (not in effects)' for f in output.fields or ()
                if (missing := [e for e in OUTPUT_FIELDS[f] if e not in effects])]
    if output.probes and ("thermal" not in effects or "stability" in effects):
        return problems, ['output.probes is ignored: ' + ('effect "thermal" is not in effects' if "thermal" not in
                                                          effects else "the squeal analysis writes no history")]
    for name, p in output.probes.items():
        where = f"output.probes.{name}"
        if problem := name_problem(name):
            problems.append(f"{where}: the name {problem}")
        if p is None or bodies is None:
            continue
        owner = {**parts, **{b: b for b in bodies}}
        if p.body is not None and p.body not in owner:
            problems.append(f'{where}.body = "{p.body}": not a body or a part; allowed: {", ".join(owner)}')
        elif p.turns and not rotating:
            problems.append(f"{where}.turns: the geometry has no rotating body to turn with")
        elif p.turns and owner.get(p.body, bodies[1]) != bodies[1]:
            problems.append(f'{where}.turns: only a probe of the rotating body "{bodies[1]}" turns')
    return problems, []

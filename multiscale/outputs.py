"""What a run writes, known before it runs (no DOLFINx): the analysis of a scene, every file of its
results folder with what it holds, the fields of each field file and the output times.

``multiscale check`` prints this plan and the workflows write exactly it (a test runs every kind
of analysis and compares the folder with the plan). ``FIELDS`` says what each output field is
called in the field files and its unit; ``step_time`` keeps output times free of the drift of
summed steps; ``paraview_script`` is the pvpython script written beside the results. Imports
nothing heavy (``multiscale check`` uses it; so does ``multiscale.macro``).
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from multiscale.geometry import Rotation
from multiscale.scene_cycle import braking_phases, cycle_keys

CHECKPOINT = "checkpoint.h5"      # a run's last macro step (``multiscale run --resume``, ``checkpointed``)
APPLICATIONS = "applications.csv"     # a duty cycle's braking applications (``per_application``)
# files of a run named without a body: a body of that name would write its fields over them
OWN_FILES = {"interface": "interface.xdmf", "history": "history.h5", "zones": "zones.h5",
             "checkpoint": CHECKPOINT, "map": "map.h5"}
MODE_UNIT = "1/kg^0.5"     # mode shapes normalised to unit modal mass, phi^H M phi = 1 with M in kg
MODE_ARRAYS = tuple(f"mode shape {part} part [{MODE_UNIT}]" for part in ("real", "imaginary"))   # in modes_<body>.bp
NAME = re.compile(r"[A-Za-z0-9_-]+")    # a body, interface or material name: file and column names, scene keys

# output field (scene key output.fields) -> (array name in the field files, unit)
FIELDS = {"displacement": ("displacement", "m"), "temperature": ("temperature", "K"),
          "von_mises": ("von Mises stress", "Pa"), "contact_pressure": ("contact pressure", "Pa"),
          "heat_flux": ("frictional heat flux", "W/m^2"), "contact_stiffness": ("contact stiffness", "Pa/m"),
          "partition": ("heat partition into body 0", "-"), "wear_depth": ("wear depth", "m"),
          "flash_temperature": ("flash temperature", "K"), "counter_wear_depth": ("wear depth of body 1", "m"),
          "friction_coefficient": ("friction coefficient", "-"), "interface": ("interface number", "-")}


def folder_problem(folder) -> str | None:
    """Why a run could not create or write into the output folder ``folder`` (its nearest existing
    ancestor is a file, or not writable: permissions, a read-only file system, /proc), or None. What
    ``multiscale check`` says without writing anything; the run itself tries (``workflows.output``)."""
    folder = Path(folder)
    existing = next(p for p in (folder, *folder.parents) if p.exists())
    if not existing.is_dir():
        return f"cannot be created: {existing} is a file, not a folder"
    what = "written into" if existing == folder else "created"
    if not os.access(existing, os.W_OK | os.X_OK):
        return f"cannot be {what}: {existing} is not writable (permissions or a read-only file system)"
    if os.statvfs(existing).f_blocks == 0:          # root may "write" there, but no file can be made
        return f"cannot be {what}: {existing} is on a file system without storage (such as /proc or /sys)"
    return None


def name_problem(name: str, body: bool = False) -> str | None:
    """Why ``name`` cannot name a body (``body``: its fields go to ``<name>.xdmf`` and ``<name>.h5``),
    an interface or a material, which also name files (``wear_map_<interface>.png``) and history
    columns (``max_temperature_<body>_in_<material>``: a "/" makes an HDF5 group of it) and is a part of
    dotted scene keys (``interfaces.<name>.friction``: a "." would split it); None if it can."""
    if not NAME.fullmatch(name):
        return "must be letters, digits, _ - only (it names files, history columns and scene keys)"
    if body and name in OWN_FILES:
        return f"is taken: the run writes {OWN_FILES[name]} of its own (name the body otherwise)"
    return None


PART_ARRAY = "part number [-]"   # a body of several parts (a file's fixed bodies): its cells' part, 1, 2, ...


def array_name(field: str) -> str:
    """Name of an output field's array in the files, with its unit: "temperature [K]"."""
    label, unit = FIELDS[field]
    return f"{label} [{unit}]"


def step_time(t: float, dt: float) -> float:
    """t + dt [s] as the multiple n dt it is (to 1e-9 dt), rounded to 12 significant digits:
    output times stay exact decimals and do not drift (12.0, not 11.999999999999998 after 30 steps
    of 0.4 s; 10.0, not 9.99999999999, after 7 steps of 10/7 s)."""
    n = round((t + dt) / dt)
    return float(f"{n * dt if abs(n * dt - (t + dt)) <= 1e-9 * dt else t + dt:.12g}")


BODY_FIELDS = ("displacement", "temperature", "von_mises")
# output fields each analysis writes (when the scene asks for them)
WRITES = {"transient": ("displacement", "temperature", "von_mises", "contact_pressure", "heat_flux", "partition",
                        "friction_coefficient", "interface", "wear_depth", "counter_wear_depth"),
          "multiscale": tuple(FIELDS),
          "squeal": ("displacement", "von_mises", "contact_pressure", "friction_coefficient", "interface")}
PROVENANCE = {"scene.toml": "the scene file as given",
              "scene_resolved.toml": "the scene with every default filled in, SI units",
              "provenance.json": "versions, command line, ranks, start and end time, wall time per stage"}
# (named paraview.py, it imported itself for the ParaView package: Python puts a script's folder first on its path)
SCRIPT = {"open_in_paraview.py": "pvpython script that opens the fields (pvpython open_in_paraview.py, or ParaView's "
                                  "Python shell)"}


def analysis(scene) -> str:
    """Which analysis a scene runs: "squeal" (effect stability), "multiscale" (effect roughness)
    or "transient"."""
    return "squeal" if scene.has("stability") else "multiscale" if scene.has("roughness") else "transient"


def checkpointed(scene) -> bool:
    """Whether a run of ``scene`` writes ``CHECKPOINT`` (``multiscale run --resume``): the multiscale
    loop, and a transient run with macro steps (effect thermal or wear); not the squeal analysis."""
    return analysis(scene) == "multiscale" or marching(scene)


def marching(scene) -> bool:
    """Whether a run of ``scene`` takes macro steps (``time.steps``): with effect thermal or wear; not
    the squeal analysis (else: the one contact solve)."""
    return analysis(scene) != "squeal" and (scene.has("thermal") or scene.has("wear"))


def per_application(scene) -> bool:
    """Whether a run of ``scene`` writes ``APPLICATIONS`` (``multiscale.applications``): one with
    macro steps and friction whose [loading] is a duty cycle (``scene_cycle.cycle_keys``) with a
    braking phase before ``time.end``."""
    ld = scene.loading
    return (marching(scene) and scene.has("friction") and ld is not None and bool(cycle_keys(ld))
            and bool(braking_phases(ld, scene.geometry.motion, scene.time.end)))


def field_step(n: int, every: int, steps: int) -> bool:
    """Whether macro step ``n`` of ``steps`` writes its fields: every ``every`` steps (0 too) and the last."""
    return n % every == 0 or n == steps


def output_times(scene) -> tuple[float, ...]:
    """Times [s] at which the fields are written: 0, then every ``output.every`` macro step and the
    last (squeal: the preload, 0)."""
    t = scene.time
    steps = t.steps if marching(scene) else 0
    times, now = [0.0], 0.0
    for n in range(1, steps + 1):
        now = step_time(now, t.dt)
        if field_step(n, scene.output.every, steps):
            times.append(now)
    return tuple(times)


@dataclass(frozen=True)
class Plan:
    """What ``multiscale run`` writes into ``folder`` (see module docstring)."""

    analysis: str
    folder: object                  # Path
    bodies: tuple[str, ...]
    body_fields: tuple[str, ...]    # output fields in every <body>.xdmf
    interface_fields: tuple[str, ...]
    times: tuple[float, ...]        # s, of the field files
    files: dict                     # file name -> what it holds
    ignored: tuple[str, ...]        # requested fields this analysis does not write

    @property
    def field_files(self) -> dict:
        """{<name>.xdmf: output fields} of the field files."""
        out = {f"{b}.xdmf": self.body_fields for b in self.bodies} if self.body_fields else {}
        if self.interface_fields:
            out["interface.xdmf"] = self.interface_fields
        return out


def plan(scene) -> Plan:
    """The results of a run of ``scene`` (see module docstring)."""
    kind = analysis(scene)
    fields = [f for f in scene.output.fields if f in WRITES[kind]]
    body = tuple(f for f in fields if f in BODY_FIELDS)
    iface = tuple(f for f in fields if f not in BODY_FIELDS)
    times = output_times(scene)
    when = "the preload" if kind == "squeal" else f"{len(times)} output time(s)"
    files = {}
    numbers = ", ".join(f"{k} {n}" for k, n in enumerate(scene.geometry.spec.interfaces, 1))
    parts = {b.name: ", ".join(f"{k} {r.name}" for k, r in enumerate(b.regions, 1))
             for b in scene.geometry.spec.bodies if len(b.regions) > 1}
    for name, held in [(b, body) for b in scene.bodies] + [("interface", iface)]:
        if held:
            files[f"{name}.xdmf"] = f"fields of {name} at {when}: {', '.join(array_name(f) for f in held)}" + (
                f" ({numbers})" if name == "interface" and "interface" in held else "") + (
                f"; {PART_ARRAY} ({parts[name]})" if name in parts else "")
            files[f"{name}.h5"] = f"data of {name}.xdmf"
    if kind == "squeal":
        rotating = isinstance(scene.geometry.spec.motion, Rotation)
        files["modes.csv"] = ("frequency, growth rate, damping ratio (-sigma/|lambda|), unstable and potentially "
                              "unstable flags, flutter partner, relative residual in the full model and each component's "
                              "strain-energy share of every mode" + (f"; the nodal diameters and out-of-plane share of "
                                                                     f"{scene.bodies[1]}'s motion" if rotating else ""))
        files.update({f"modes_{b}.bp": f"mode shapes of {b} (VTX): real and imaginary parts, time = mode number"
                      for b in scene.bodies})
        files["pressure.png"] = "contact pressure on each interface at the preload"
        files["re_im.png"] = "complex eigenvalues: growth rate against frequency"
        files["energy.png"] = "strain-energy share of each component per mode"
        if scene.stability.prestress:
            files["prestress.csv"] = "frequency of every mode with and without the prestress stiffness"
        if scene.stability.sweep is not None:
            files.update({"map.csv": "every mode at every point of the sweep (frequency, growth rate, track)",
                          **({"onsets.csv": "the bracketed parameter at which each track turns unstable"}
                             if scene.stability.sweep.onsets else {}),
                          "map.h5": "the stability map's arrays", "map.png": "growth rate against frequency of "
                          "every mode, coloured by the swept value",
                          "map_tracks.png": "frequency and growth rate of each tracked mode against the swept value"})
    else:
        probes = ", ".join(scene.output.probes) if scene.has("thermal") else ""
        files["history.h5"] = ("scalar history per step (forces, pressures, temperatures, heat), unit per dataset"
                               + (f"; the probes' temperatures ({probes})" if probes else ""))
        files["history.png"] = "the history against time"
    if per_application(scene):
        rotating, bodies = scene.geometry.motion == "rotation", scene.bodies
        files[APPLICATIONS] = ", ".join(
            ["one row per braking application of the cycle (the last one partial if the run stopped inside it): "
             "start and end time, speeds at both, duration, frictional energy, mean friction coefficient"]
            + ["mean and peak braking torque"] * rotating
            + [f"peak temperature of {bodies[0]} and {bodies[1]}"] * scene.has("thermal")
            + ["worn volume"] * scene.has("wear")
            + ["per interface its energy, mean friction coefficient and what else the history has of it"]
            * (len(scene.geometry.spec.interfaces) > 1)) + " (SI, units in the header)"
    if checkpointed(scene):
        files[CHECKPOINT] = "the last macro step's state (multiscale run --resume)"
    if kind == "multiscale":
        files["multiscale.png"] = "both scales of the loop against time: pressures, temperatures, partition, wear"
        files["zones.h5"] = "final state of every zone: centre, wear depth and volume, partition, conductance"
        if scene.has("wear"):
            rough = scene.rough_interfaces
            files.update({("wear_map.png" if len(rough) == 1 else f"wear_map_{n}.png"):
                          f"wear depth over the interface{'' if n == 'interface' else ' ' + n}: per zone and the "
                          "micro field" for n in rough})
    if not scene.output.figures:
        files = {name: what for name, what in files.items() if not name.endswith(".png")}
    files.update(PROVENANCE)
    if body or iface or kind == "squeal":       # something to open: fields or mode shapes
        files.update(SCRIPT)
    return Plan(kind, scene.output.folder, tuple(scene.bodies), body, iface, times, files,
                tuple(f for f in scene.output.fields if f not in WRITES[kind]))


def summary(p: Plan) -> list[str]:
    """Lines of ``multiscale check``: the analysis, every file and the output times."""
    times = ", ".join(f"{t:g}" for t in p.times[:6]) + (f", ... {p.times[-1]:g}" if len(p.times) > 6 else "")
    lines = [f"  analysis  {p.analysis}", f"  writes    into {p.folder}:"]
    width = max([22] + [len(name) + 2 for name in p.files])
    lines += [f"    {name:<{width}}{what}" for name, what in p.files.items()]
    if p.analysis != "squeal":
        lines.append(f"  fields at t = {times} s")
    if p.ignored:
        lines.append(f"  note      output.fields {', '.join(p.ignored)}: not written by the {p.analysis} analysis")
    return lines


def script_name(file: str) -> str:
    """The Python variable of ``file`` in ``paraview_script``: ``src_`` and the file's stem with
    every other character than letters, digits and _ as _ (a body called "view", "os" or "in"
    must not replace the script's own names, nor be a keyword)."""
    return "src_" + re.sub(r"\W", "_", file.rsplit(".", 1)[0])


def paraview_script(p: Plan) -> str:
    """A pvpython script that opens the results of ``p`` beside it: the bodies coloured by
    temperature (else displacement or von Mises stress), at the last output time with colour
    ranges over every time and every body coloured by the array (ParaView keeps one colour map
    per array name, and each display's rescale over time replaces its range: the pin's 330 K
    would have shown the top colour of the disc's 293-299 K); the interface by contact pressure
    in a view of its own (it lies on the bodies' faces, where it would be hidden); for the squeal
    analysis the mode shapes, warped, the preloaded bodies open but hidden."""
    files, squeal = p.field_files, p.analysis == "squeal"
    interface = OWN_FILES["interface"]
    lines = ['"""Open these results in ParaView: pvpython open_in_paraview.py (a window), or paste into',
             "View > Python Shell. Each .xdmf holds one mesh with every field as a named array",
             "(unit in the name); the time slider steps through the output times. In the arrays'",
             f"names body 0 is {p.bodies[0]} and body 1 is {p.bodies[1]}.",
             '"""', "import os", "from paraview.simple import *  # noqa: F401,F403", "",
             "# the folder of this script (the results folder where it was written, if run without a file)",
             f"here = os.path.dirname(os.path.abspath(__file__)) if '__file__' in globals() else {str(p.folder)!r}",
             "view = GetActiveViewOrCreate('RenderView')",
             "coloured = []   # (display, array): the colour ranges are set once every file is shown", ""]
    if interface in files:
        lines += ["# the interface lies on the bodies' faces: it gets a view of its own, right of theirs",
                  "layout = GetLayout(view)", "layout.SplitHorizontal(0, 0.5)",
                  "face_view = CreateView('RenderView')", "layout.AssignView(2, face_view)", ""]
    for name, fields in files.items():
        var = script_name(name)
        shown = next((f for f in ("temperature", "contact_pressure", "von_mises", "displacement") if f in fields),
                     fields[0])
        centre = "CELLS" if shown not in ("temperature", "displacement") else "POINTS"
        where = "face_view" if name == interface else "view"
        lines += [f"{var} = Xdmf3ReaderS(registrationName={name!r}, FileName=[os.path.join(here, {name!r})])"]
        if squeal and name != interface:
            lines += [f"# {name}: the preloaded state, open but hidden behind the mode shapes (its eye)", ""]
            continue
        lines += [f"{var}_view = Show({var}, {where})",
                  f"ColorBy({var}_view, ({centre!r}, {array_name(shown)!r}))",
                  f"{var}_view.SetScalarBarVisibility({where}, True)",
                  f"coloured.append(({var}_view, {array_name(shown)!r}))", ""]
    lines += ["# one colour map per array name, over every output time of every file coloured by it",
              "# (each display's rescale replaces the map's range: the last file's alone would be kept)",
              "ranges = {}",
              "for display, array in coloured:",
              "    display.RescaleTransferFunctionToDataRangeOverTime()",
              "    points = list(GetColorTransferFunction(array).RGBPoints)   # x, r, g, b of each control point",
              "    lo, hi = ranges.get(array, (points[0], points[-4]))",
              "    ranges[array] = (min(lo, points[0]), max(hi, points[-4]))",
              "for array, (lo, hi) in ranges.items():",
              "    colours = GetColorTransferFunction(array)",
              "    colours.AutomaticRescaleRangeMode = 'Never'   # kept when the time changes",
              "    colours.RescaleTransferFunction(lo, hi)",
              "    GetOpacityTransferFunction(array).RescaleTransferFunction(lo, hi)", ""]
    if squeal:
        lines += ["# mode shapes (VTX, ADIOS2 reader): time = mode number, see modes.csv for the frequencies"]
        for b in p.bodies:
            var = script_name(f"modes_{b}.bp")
            lines += [f"{var} = ADIOS2VTXReader(registrationName='modes_{b}.bp', "
                      f"FileName=os.path.join(here, 'modes_{b}.bp'))",
                      f"{var}_warp = WarpByVector(Input={var}, Vectors=['POINTS', {MODE_ARRAYS[0]!r}], "
                      "ScaleFactor=0.01)",
                      f"{var}_view = Show({var}_warp, view)",
                      f"ColorBy({var}_view, ('POINTS', {MODE_ARRAYS[0]!r}, 'Magnitude'))", ""]
    else:
        lines += ["animation = GetAnimationScene()   # at the last output time (t = 0: the uniform start)",
                  "animation.UpdateAnimationUsingDataTimeSteps()", "animation.GoToLast()", ""]
    lines += ["view.ResetCamera()"] + (["face_view.ResetCamera()"] if interface in files else []) + \
        ["Render()", "if __name__ == '__main__':", "    Interact()", ""]
    return "\n".join(lines)

"""The workflow layer: a scene in, a typed result out. The only macro-side code that reads scenes.

``model`` (the scene-to-model factory), ``rough`` (the one rough-interface builder), ``output`` (the
output-folder check, ``RunResult``) and one workflow per analysis: ``transient`` (thermo-mechanics
with perfect contact), ``multiscale`` (the multiscale loop, effect ``roughness``) and ``squeal``
(complex eigenvalues, effect ``stability``). ``run`` dispatches a scene to its workflow, prints one
line per stage on rank 0 (``multiscale.io.Reporter``) and completes the results folder with its
provenance (``multiscale.provenance``), a pvpython script (``multiscale.outputs``) and, for a duty
cycle, its braking applications (``multiscale.applications``).
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from multiscale import checkpoint, io, outputs, provenance
from multiscale.applications import summary
from multiscale.errors import InputError, Interrupted, SceneError, interrupted
from multiscale.micro.laws import RESOLUTION
from multiscale.micro.wear import SUBSTEP_TOL
from multiscale.scene import loads
from multiscale.scene_friction import bare_interfaces, curve_left, fade_tables
from multiscale.scene_sections import Material
from multiscale.scene_values import HOTTEST
from multiscale.workflows import multiscale, squeal, transient
from multiscale.workflows.model import interface_materials
from multiscale.workflows.output import RunResult, write_applications
from multiscale.workflows.strain import overloaded, unloaded


def workflow(scene) -> str:
    """Which analysis a scene runs: "squeal" (effect stability), "multiscale" (effect roughness)
    or "transient" (``multiscale.outputs.analysis``)."""
    return outputs.analysis(scene)


def run(scene, *, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD,
        verbose: bool = True, warn: bool = True) -> RunResult:
    """Run a scene (``multiscale run``) with its workflow; runs with macro steps resume
    (``outputs.checkpointed``).

    Besides the analysis' results, the folder receives ``scene.toml``, ``scene_resolved.toml``,
    ``provenance.json`` (also after a failure, once the run has written into the folder), ``open_in_paraview.py``
    and, for a duty cycle (``outputs.per_application``), ``applications.csv`` (also after a Ctrl-C: the
    applications of the history written), its table in the summary.
    ``verbose``: stage lines and the summary on rank 0; ``warn``: the warnings on stderr (rank 0, the
    scene's first; ``result.warnings`` and provenance.json hold them all, whatever ``warn``)."""
    if not all(hasattr(scene, a) for a in ("has", "effects", "output")):
        raise InputError("scene", scene, "a validated scene: multiscale.scene.load(path) or loads(text)")
    try:                    # read again: a script's dataclasses.replace skipped every check (a negative
        loads(provenance.resolved_toml(scene), name=scene.name)    # friction ran to "finished": a user trial)
    except SceneError as exc:
        raise SceneError([f"{line} (the scene as changed after it was read: change it by overrides, "
                          "multiscale.scene.load(path, overrides))" for line in exc.problems]) from None
    kind = workflow(scene)
    if resume and not outputs.checkpointed(scene):
        why = ("the squeal analysis has no checkpoints to resume from" if kind == "squeal" else
               'this scene has no checkpoints to resume from (one contact solve: runs with macro steps, effect '
               '"thermal" or "roughness", write them)')
        raise InputError("--resume", None, why + ": run it again with --overwrite (in Python: overwrite=True, "
                                           "not resume)")   # (no fix said: a user trial; nor the API's)
    ended = resume and checkpoint.peek(Path(scene.output.folder) / outputs.CHECKPOINT, comm).get("finished")
    # the parts of the run before this one (rank 0 writes the record): resumed, they stay in it
    earlier = provenance.parts_of(Path(scene.output.folder)) if resume and comm.rank == 0 else []
    started, start = provenance.now(), time.perf_counter()
    with io.Reporter(comm, quiet=not verbose, warn=warn) as reporter:
        for line in scene.warnings:
            reporter.warn(line)
        try:
            if kind == "squeal":
                result = squeal.run(scene, overwrite=overwrite, comm=comm, verbose=verbose)
            else:
                module = multiscale if kind == "multiscale" else transient
                result = module.run(scene, overwrite=overwrite, resume=resume, comm=comm, verbose=verbose)
        except BaseException as exc:
            stopped = interrupted(exc)
            during = reporter.said[len(scene.warnings):]     # said as the run went (rank 0's: the record's)
            notes = list(getattr(exc, "__notes__", ()))     # the run's warnings until it failed (model.heat_warnings_as_notes)
            for line in notes:
                reporter.warn(line)
            if reporter.folder is not None and comm.rank == 0:
                try:                    # before the record, which lists the files there are
                    if isinstance(exc, Interrupted):          # stopped after a step: its results are written
                        _write_script(reporter.folder, scene)
                    elif stopped:                             # a step abandoned: the plots of what was written
                        _abandoned(reporter.folder, scene)
                    if stopped and outputs.per_application(scene):     # the applications it completed
                        written = _written_history(reporter.folder)
                        if written is not None:
                            write_applications(scene, written, reporter.folder)
                except BaseException as lost:                 # not at the record's cost (a further Ctrl-C too)
                    reporter.warn(f"the figures, {outputs.APPLICATIONS} or the ParaView script of this run were not "
                                  f"written ({type(lost).__name__}: {lost})")
                try:
                    provenance.write(reporter.folder, scene, ranks=comm.size, started=started,
                                     stages=reporter.times, wall_time=time.perf_counter() - start, analysis=kind,
                                     status=f"interrupted {stopped}".strip() if stopped else
                                     f"failed: {type(exc).__name__}: {exc}", earlier=earlier,
                                     warnings=[*scene.warnings, *during,
                                               *(exc.warnings if isinstance(exc, Interrupted) else ()),
                                               *notes, *run_warnings(scene, _written_history(reporter.folder))])
                except OSError as lost:                       # (a full disk): the error that stopped the run counts
                    reporter.warn(f"the record of this run was not written ({lost})")
            if stopped and stopped is not exc:
                raise stopped from None                       # not PETSc's error 101 around it
            raise
    result.files += [f.with_suffix(".h5") for f in result.files if f.suffix == ".xdmf"]   # their data
    if ended:                 # --resume of a finished run: nothing to do, its provenance stays as it was
        result.files += [result.folder / name for name in [*outputs.PROVENANCE, *outputs.SCRIPT, outputs.APPLICATIONS]
                         if (result.folder / name).is_file()]
        return result
    if outputs.per_application(scene):
        _applications(scene, result, comm, verbose)
    # said as the run went (the memory estimate, the first contact solve's load: rank 0's), then what the
    # results leave out (also when quiet); all in the record and the result (the first were lost: a review)
    during = comm.bcast(reporter.said[len(scene.warnings):], root=0)
    beyond = run_warnings(scene, getattr(result, "history", None)) + list(getattr(result, "warnings", ()))
    for line in beyond:
        reporter.warn(line)
    beyond = during + beyond

    def write():
        files = provenance.write(result.folder, scene, ranks=comm.size, started=started, stages=reporter.times,
                                 wall_time=time.perf_counter() - start, analysis=kind,
                                 status=("resumed and " if resume else "") + (result.ended or "finished"),
                                 earlier=earlier,
                                 warnings=[*scene.warnings, *beyond])
        return files + _write_script(result.folder, scene)
    result.files += comm.bcast(io.on_root(comm, write, f"the provenance into {result.folder}"), root=0)
    result.warnings = (*scene.warnings, *beyond)
    return result


def _applications(scene, result, comm, verbose: bool) -> None:
    """``applications.csv`` of a finished run (rank 0 writes it: ``workflows.output.write_applications``),
    in ``result.files``, and its table in the run's summary (``verbose``)."""
    apps = io.on_root(comm, lambda: write_applications(scene, result.history, result.folder),
                      f"{outputs.APPLICATIONS} into {result.folder}")
    if comm.bcast(bool(apps), root=0):
        result.files.append(result.folder / outputs.APPLICATIONS)
    if verbose and apps:                   # (rank 0's)
        print("\n".join(summary(apps, scene.geometry.motion)))


def _write_script(folder: Path, scene) -> list[Path]:
    """``open_in_paraview.py`` beside the results (rank 0), if they hold fields or mode shapes to open."""
    p, path = outputs.plan(scene), Path(folder) / "open_in_paraview.py"
    if path.name not in p.files:
        return []
    path.write_text(outputs.paraview_script(p))
    return [path]


def _abandoned(folder: Path, scene) -> None:
    """After a Ctrl-C that abandoned a step (the third, ``io.StepStop``) or came outside the steps
    of a run with a history (rank 0): with ``output.figures``, history.png (and a multiscale run's
    multiscale.png) drawn from history.h5 as written (the loop writes each step's row whole), and
    open_in_paraview.py once a field file is written. The zone results of a multiscale run (zones.h5, wear
    maps) need the state of its last step: they stay as they were."""
    kind, h5 = workflow(scene), Path(folder) / "history.h5"
    if kind == "squeal":
        return
    if h5.is_file() and scene.output.figures:
        from multiscale.plots.history import history_figure, multiscale_figure  # local: matplotlib only when a figure is drawn
        history = io.History.read(h5)
        title = f"{scene.name} (stopped at t = {history['time'][-1]:g} s)" if len(history) else scene.name
        history_figure(history, h5.with_name("history.png"), title=title)
        if kind == "multiscale":
            multiscale_figure(history, h5.with_name("multiscale.png"), title)
    if any((Path(folder) / name).is_file() for name in outputs.plan(scene).field_files):
        _write_script(folder, scene)


def _written_history(folder: Path):
    """The history a stopped run wrote into ``folder`` (its steps so far), or None: none, or one that
    cannot be read (the record of the stop is written all the same)."""
    try:
        return io.History.read(folder / outputs.OWN_FILES["history"])
    except Exception:      # h5py's and ours alike: a half-written file must not cost the record
        return None


def run_warnings(scene, history) -> list[str]:
    """What a run's history shows it extrapolated: material tables its temperatures left (held
    constant beyond their ends, ``Material.beyond``: the largest and the smallest temperature over
    the history of the bodies made of each material, for the tables the initial temperature,
    checked when the scene is read, was in; a body cooled below a table's first point was not
    said), zone pressures above the top of their laws (extrapolated linearly) and
    temperatures below every imposed one (``UNDERSHOOT``)."""
    if history is None:
        return []
    laws = _law_reach(history)
    T0, hottest, coldest = scene.time.initial_temperature, {}, {}
    for body in scene.geometry.spec.bodies:
        for name in (r.material for r in body.regions):       # the material's own column if the body has several
            for end, extreme, found in (("max", np.max, hottest), ("min", np.min, coldest)):
                column = next((c for c in (f"{end}_temperature_{body.name}_in_{name}",
                                           f"{end}_temperature_{body.name}") if c in history.columns), None)
                if column is not None:
                    T = float(extreme(history[column]))
                    if name not in found or (T > found[name][0]) == (end == "max"):
                        found[name] = (T, body.name)
    out = []
    # k_w is read at the micro temperatures (``_wear_table_ends``), the strain's without expansion at T0
    unread = ("k_w",) + (() if scene.has("expansion") else Material.STRAIN)
    for name in hottest:
        material = scene.materials[name]

        def side(key, T, table_of=material):        # -1 below the table's first point, 1 above its last, 0 in it
            table = getattr(table_of, key)
            return (T > table[-1][0]) - (T < table[0][0])
        for T, body in dict.fromkeys((hottest[name], coldest.get(name, hottest[name]))):   # the hottest, the coldest
            why = ": an undershoot, below every imposed temperature" if T < _floor(scene) else ""   # (a trial
            out += [f"materials.{name}.{phrase} (in body {body!r}{why})"          # read it apart from the undershoot)
                    for key, phrase in material.beyond(T).items()   # a table T0 left at its other end too (a trial)
                    if key not in unread and side(key, T) != side(key, T0)]
    return (out + laws + _undershoots(scene, history) + _coarse_wear(history) + _wear_table_ends(scene, history)
            + _too_hot(scene, history) + _fade_table_ends(scene, history) + _curve_ends(scene, history)
            + _unloaded(scene, history)
            + _faces_apart(scene, history)
            + (overloaded(scene, float(np.max(history["max_pressure"])), hottest)
               if "max_pressure" in history.columns else []))


def _wear_table_ends(scene, history) -> list[str]:
    """``Wear.held_ends`` at the largest temperature the wear read (the rough surface's micro one,
    ``micro_max_temperature``, or with ``wear.temperature = "macro"`` and in perfect contact the worn
    body's; the initial temperature is the scene's warning), or the worn material's k_w table left
    there (``Material.beyond``; it was not said)."""
    if not scene.has("wear"):
        return []
    rough = scene.has("roughness")
    column = "micro_max_temperature" if rough and scene.wear.temperature == "surface" else \
        f"max_temperature_{scene.bodies[0]}"
    if column not in history.columns:
        return []
    read = np.asarray(history[column], dtype=float)
    hottest = float(np.max(read, initial=-np.inf, where=np.isfinite(read)))
    if scene.rough_material_wears:
        name = scene.rough_material
        phrase = scene.materials[name].beyond(hottest).get("k_w")
        return [f"materials.{name}.{phrase} ({scene.wear.read(rough)})"] if phrase else []
    return scene.wear.held_ends(hottest=hottest, rough=rough)


def _law_reach(history) -> list[str]:
    """Zone pressures beyond the top of their laws (extrapolated linearly there): micro.p_max, or
    for a zone whose law stopped below it its halved top (raising p_max cannot help it; the demo's
    worn zone at its last step); and zones loaded beyond their law's floor (``resolved_gap``)."""
    reach, halved, floored = (float(np.max(history[c])) if c in history.columns else 0.0
                              for c in ("law_reach", "law_reach_halved", "near_perfect_zones"))
    out = []
    if reach > 1:
        out.append(f"the zone pressures reached {reach:.3g} times micro.p_max, the top of their laws: beyond it a "
                   "law is extrapolated linearly, with the contact stiffness at the top; raise micro.p_max")
    if halved > 1:
        out.append(f"zones whose laws failed at micro.p_max (their top halved: no convergence, or a pressure that "
                   f"stopped growing) were loaded to {halved:.3g} times that top: their laws are extrapolated "
                   "linearly there, with the contact stiffness at the top")
    if floored > 0:
        zones = "1 zone was" if floored == 1 else f"{floored:.0f} zones were"     # (it said "up to 1 zones")
        out.append(f"up to {zones} loaded where the roughness adds less compliance than the zone laws resolve "
                   f"({RESOLUTION:.1%} of a zone's own, micro.laws.resolved_gap): their laws' gaps fall at that "
                   "floor, so their contact stiffness is a lower bound (the interface nearly rigid beside the zone's "
                   "own compliance), their real contact area, conductance and heat partition those of the micro "
                   "solves (a smooth or worn-flat face; the column near_perfect_zones of the history says when)")
    return out


UNDERSHOOT = 0.1      # a body's undershoot warned about: this share of its temperature rise up to then [-]
NEGLIGIBLE = 0.01     # ... if it is also above this share of the whole run's rise (and 1 mK) [-]
APART = 0.2           # an interface's faces' mean temperatures this share of their rise apart (and 10 K) are warned of


def _coarse_wear(history) -> list[str]:
    """A wear update whose worn depth its increments leave more than ``micro.wear.SUBSTEP_TOL`` off
    by the step-doubling estimate (``wear_substep_error``, ``PostAnalysis.wear``): the loop raises
    an update's increments to meet ``WEAR_TOL`` up to an explicit scheme's stable count, so this
    is an update that count did not bring there. (Before the implicit increments: 4 explicit
    substeps left the test pin-on-disc's real area 31 % below the converged one.)"""
    if "wear_substep_error" not in history.columns:
        return []
    error = np.asarray(history["wear_substep_error"], dtype=float)
    if not error.size or error.max() <= SUBSTEP_TOL:
        return []
    row = int(np.argmax(error))
    taken = int(history["wear_substeps"][row])
    return [f"the {taken} wear increments of an update (at t = {history['time'][row]:g} s) left its worn depth an "
            f"estimated {100 * error.max():.3g} % off (against half the increments); for {100 * SUBSTEP_TOL:g} % "
            f"set wear.substeps to about {int(np.ceil(taken * error.max() / SUBSTEP_TOL))} (first order: fewer may do)"]


def _unloaded(scene, history) -> list[str]:
    """``strain.unloaded`` of the interfaces' largest normal forces in ``history``."""
    return unloaded({n: float(np.max(np.abs(history[f"interface_force_{n}"]))) for n in scene.geometry.spec.interfaces
                     if f"interface_force_{n}" in history.columns})


def _fade_table_ends(scene, history) -> list[str]:
    """Fade tables (``friction_temperature``) left by the run: the hottest face of the interfaces a
    table serves (``face_max_temperature_<name>_on_<body>``; with one interface, the bodies' largest
    temperature, the interface's at most) above its last point, where mu was held (below its
    first at the initial temperature: the scene's warning, ``scene_friction.fade_coverage``)."""
    if not (scene.has("friction") and scene.has("thermal")):
        return []
    names, out = scene.geometry.spec.interfaces, []
    for where, table in fade_tables(scene.loading, scene.interfaces, names).items():
        served = [where.split(".")[1]] if where.startswith("interfaces.") else bare_interfaces(scene.interfaces, names)
        faces = [k for k in history.columns if any(k.startswith(f"face_max_temperature_{n}_on_") for n in served)]
        columns = faces or [c for c in (f"max_temperature_{b.name}" for b in scene.geometry.spec.bodies)
                            if c in history.columns]
        hottest = max((float(np.max(history[c])) for c in columns), default=-np.inf)
        if hottest > table[-1][0]:
            what = f"the hottest face of {', '.join(served)}" if faces else "the bodies"
            out.append(f"{where}: {what} reached {hottest - 273.15:.4g} degC, above its last point, "
                       f"{table[-1][0] - 273.15:.4g} degC: where the interface (the mean of its two faces) was that "
                       f"hot, mu was held at {table[-1][1]:g}")
    return out


def _curve_ends(scene, history) -> list[str]:
    """[loading]'s ``friction_curve`` left by the slip speeds of the facets in contact that read it
    (``max_slip_speed``, ``min_slip_speed``; ``scene_friction.curve_left``), where mu was held at its
    end row (it was not said)."""
    curve = scene.loading.friction_curve
    if curve is None or "max_slip_speed" not in history.columns:
        return []
    extremes = []
    for column, pick in (("max_slip_speed", np.nanargmax), ("min_slip_speed", np.nanargmin)):
        V = np.asarray(history[column], float)
        if not np.isfinite(V).any():
            return []                                  # never sliding in contact
        row = int(pick(V))
        extremes.append((float(V[row]), f" at t = {history['time'][row]:g} s"))
    return curve_left(curve, *extremes)


def _too_hot(scene, history) -> list[str]:
    """Bodies hotter than any plausible temperature (``scene_values.HOTTEST``): the load, the
    partition or the materials are wrong for the case (a car pad reached 23 000 K without a word)."""
    out = []
    for body in scene.geometry.spec.bodies:
        column = f"max_temperature_{body.name}"
        if column in history.columns and float(np.max(history[column])) > HOTTEST:
            row = int(np.argmax(history[column]))
            out.append(f"body {body.name!r} reached {float(history[column][row]):.4g} K at t = {history['time'][row]:g} s, "
                       f"above any plausible temperature ({HOTTEST:g} K: molten iron): check the load, the heat "
                       "partition and the materials (the model has no melting or wear of hot material, and fade only "
                       "with a friction_temperature table)")
    return out


def _floor(scene) -> float:
    """The lowest temperature the scene imposes [K]: the initial one, ambients, fixed ones."""
    return min([scene.time.initial_temperature] + [t for b in scene.boundary for t in (b.ambient, b.temperature)
                                                   if t is not None])


def _undershoots(scene, history) -> list[str]:
    """Bodies whose temperature fell below every temperature the scene imposes (the initial one,
    ambients, fixed ones; frictional heat only adds) by more than ``UNDERSHOOT`` of their rise up
    to then and ``NEGLIGIBLE`` of the run's: the discretisation's undershoot (docs/architecture.md, Known problems). Against the
    rise of the whole run, a 5.6 K undershoot at t = 16 s of a 240 s railway drag (12 % of the 45 K
    rise by then, 2.4 % of the run's 236 K) went unsaid, and only a material table's lower end
    named it (a user trial)."""
    floor, out = _floor(scene), []
    for body in scene.geometry.spec.bodies:
        cold, hot = f"min_temperature_{body.name}", f"max_temperature_{body.name}"
        if cold not in history.columns:
            continue
        below = floor - np.asarray(history[cold], float)
        risen = np.maximum.accumulate(np.asarray(history[hot], float)) - floor     # K, the rise up to each row
        told = (below > UNDERSHOOT * risen) & (below > max(1e-3, NEGLIGIBLE * risen[-1]))
        if told.any():
            row, deepest = int(np.argmax(np.where(told, below, -np.inf))), int(np.argmax(below))   # the deepest told
            later = (f" (its lowest: {floor - below[deepest]:.2f} K at t = {history['time'][deepest]:g} s, after a "
                     f"rise of {risen[deepest]:.3g} K)" if below[deepest] > below[row] else "")   # (the lowest was
            out.append(f"the temperature of body {body.name!r} fell to {floor - below[row]:.2f} K at t = "   # unsaid: a trial)
                       f"{history['time'][row]:g} s, {below[row]:.3g} K below the lowest imposed temperature "
                       f"({floor:.2f} K) while it had risen by {risen[row]:.3g} K{later}: an undershoot of the "
                       "discretisation (a heated layer thinner than the elements; with a rotating body, its Eulerian "
                       "transport): temperatures near the rubbing surface are uncertain by at least as much; refine "
                       "the mesh across the thickness (docs/architecture.md, Known problems)")
    return out


__all__ = ["RunResult", "run", "run_warnings", "workflow"]


def _faces_apart(scene, history) -> list[str]:
    """Interfaces whose two faces' mean temperatures (``face_mean_temperature_<name>_on_<body>``)
    drifted apart by more than ``APART`` of the faces' rise and 10 K, without effect "conductance" and
    with a partition that heats both sides:
    nothing conducts across the interface, each face heats by its share of the frictional heat
    (docs/architecture.md, Known problems; a user trial read a pad face 110 K under the disc's for a
    result)."""
    if scene.has("conductance") or scene.has("roughness") or scene.interface.partition in (0.0, 1.0):
        return []          # (all the heat into one side: chosen; rough zones exchange heat by their laws: a review)
    T0, out = scene.time.initial_temperature, []
    body0, body1 = (b.name for b in scene.geometry.spec.bodies)
    for name in scene.geometry.spec.interfaces:
        columns = [f"face_mean_temperature_{name}_on_{b}" for b in (body0, body1)]
        if not all(c in history.columns for c in columns):
            continue
        a, b = (np.asarray(history[c], float) for c in columns)
        gap, rise = np.abs(a - b), np.maximum(a, b) - T0
        row = int(np.nanargmax(np.where(np.isfinite(gap), gap, -np.inf)))
        if gap[row] > max(10.0, APART * rise[row]):
            out.append(f"interface {name}: its two faces' mean temperatures drifted {gap[row]:.0f} K apart ({body0} "
                       f"{a[row] - 273.15:.0f} degC, {body1} {b[row] - 273.15:.0f} degC at t = {history['time'][row]:g} "
                       's): without effect "conductance" nothing conducts across the interface and each face heats '
                       "by its share of the frictional heat only (the partition, a mean over the face); where the "
                       'faces in contact should meet, add effect "conductance" (interface.conductance); a '
                       "face whose interface elements are thicker than the heat's depth reads low too (a warning "
                       "on its material says so before the run: refine the interface mesh first)")
    return out

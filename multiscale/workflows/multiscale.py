"""The multiscale loop of a scene with effect ``roughness`` (thesis ch. 7): build, run, checkpoint,
resume, write.

The scene gives the macro model (``workflows.model``), the rough interface (``workflows.rough``:
[roughness], [micro], [layers]) and the micro post-analysis: micro heating with effects
``thermal`` + ``heat_partition`` (``micro.heating`` steady or transient in ``micro.heating_steps``;
the micro partition law with ``micro.partition_law``, its remote temperatures and coupling
``micro.remote_temperatures``, ``micro.coupling``), the zone conductance with ``conductance``,
Archard wear with ``wear`` (the rough body's k_w or k_w(T): its material's ``k_w``, else [wear]'s,
else the default table; the counter-face wears when its material gives ``k_w``;
``wear.update_every``, ``wear.substeps``). ``multiscale.coupling.Multiscale`` runs the loop.

Every step writes a checkpoint (``checkpoint.h5``: macro fields, zone topographies, per-zone state,
history), so that ``multiscale run --resume`` continues a killed run and ends with the same history
as an uninterrupted one (to solver tolerance); then the fields of output steps (a run stopped by
Ctrl-C writes those of its last step too, dropped when it is resumed, so that the resumed series
has the times of an uninterrupted one). Results:
``history.h5`` and ``history.png`` (macro), ``multiscale.png`` (both scales: Figs. 7.12, 7.14–7.18),
``wear_map.png`` (Fig. 7.13), ``zones.h5`` (final per-zone state) and XDMF fields (the interface adds
per-facet stiffness, partition, wear depth, flash temperature and the counter-face's wear depth).
"""
from __future__ import annotations

import dataclasses
import time as _time
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import h5py
import numpy as np
from mpi4py import MPI

from multiscale import checkpoint, io, outputs
from multiscale.coupling import Multiscale
from multiscale.errors import InputError, Interrupted
from multiscale.geometry import Rotation
from multiscale.loop_settings import LoopSettings
from multiscale.macro.kept_cells import closed_on_error
from multiscale.micro.heat_kernels import ThermalMaterial
from multiscale.micro.laws import Conductance
from multiscale.micro.post_analysis import Heating, PostAnalyses, PostAnalysis, grid_of
from multiscale.workflows.model import build_mesh, build_model, friction_coefficient, heat_warnings_as_notes, \
    interface_forces, interface_materials, run_notes, say_clamp, say_load, say_model_size, worn_probes
from multiscale.workflows.output import fingerprint, totals
from multiscale.workflows.rough import (build_rough_interface, check_rough_scene, contact_kernel, interface_hardness,
                                        thermal_kernels)
from multiscale.workflows import stepping
from multiscale.workflows.strain import refuse_floating, say_at_once
from multiscale.workflows.transient import TransientResult, write_history


@dataclass
class MultiscaleResult(TransientResult):
    """``TransientResult`` plus the multiscale plots and the final per-zone state."""

    multiscale_plot: Path | None   #: multiscale.png (None with output.figures = false)
    wear_maps: list             #: one per interface (none without wear or figures)
    zones_file: Path
    steps_done: int


def post_analysis(scene, zone) -> PostAnalysis:
    """The micro post-analysis of the scene's zones (``zone``: one of them, for the grid)."""
    rough, counter = interface_materials(scene, scene.rough_interfaces[0])
    m = scene.micro
    heating = None
    if scene.has("thermal") and scene.has("heat_partition"):
        heating = Heating(ThermalMaterial(counter.kappa, counter.diffusivity),
                          ThermalMaterial(rough.kappa, rough.diffusivity),
                          transient_steps=m.heating_steps if m.heating == "transient" else 0,
                          bounded=m.remote(scene.effects) == "rough",
                          conduction=m.coupling_scheme(scene.effects) == "implicit")
    wear = scene.has("wear")
    rate = (rough.wear_rate if scene.rough_material_wears else scene.wear.rate) if wear else None
    counter_rate = counter.wear_rate if wear and counter.k_w is not None else None
    if counter_rate is not None and not isinstance(scene.geometry.spec.motion, Rotation):
        raise InputError("materials.k_w", counter.k_w, "the counter-face wears along a circular track: it must "
                         "rotate (give k_w to a rotating counter-face only)")
    s = zone.surface
    return PostAnalysis(contact_kernel(scene)[0], s.shape, s.dx, s.dy, mu=friction_coefficient(scene, scene.rough_interfaces[0]),
                        heating=heating,
                        conductance=Conductance(*thermal_kernels(scene)) if scene.has("conductance") else None,
                        wear_rate=rate, counter_rate=counter_rate, substeps=scene.wear.substeps if wear else 1,
                        per_load=wear and scene.wear.per_load and not scene.rough_material_wears,
                        wear_at_macro=wear and scene.wear.temperature == "macro",
                        tol=m.tol, hardness=interface_hardness(scene) if scene.has("plasticity") else None)


def build(scene, comm=MPI.COMM_WORLD, progress: bool = False) -> Multiscale:
    """The loop of a scene with effect ``roughness`` (collective)."""
    if not scene.has("roughness"):
        raise InputError("effects", sorted(scene.effects), 'the multiscale loop needs effect "roughness"')
    check_rough_scene(scene)              # before meshing
    with io.stage("meshing"):
        tm = build_mesh(scene, comm)
    with io.stage("model set-up"), heat_warnings_as_notes():
        rough = build_rough_interface(scene, tm, progress=progress)
        exchange = (scene.has("heat_partition") and scene.micro.partition_law
                    and scene.micro.coupling_scheme(scene.effects) == "implicit")
        model = build_model(scene, comm, law=rough.law, tm=tm, conductance=scene.has("conductance") or exchange)
    say_model_size(tm, model.mechanics, model.thermal, points=sum(z.surface.heights.size for z in rough.zones))
    say_load(scene, tm)
    t, wear = scene.time, scene.has("wear")
    mu = np.concatenate([np.full(g.n_zones, friction_coefficient(scene, n)) for n, g in zip(rough.names, rough.grids)])
    shares = np.concatenate([np.full(g.n_zones, model.partitions[n]) for n, g in zip(rough.names, rough.grids)]) \
        if scene.has("heat_partition") else np.nan      # each zone its interface's (before: the first's)
    settings = LoopSettings(dt=t.dt, substeps=t.substeps, initial_temperature=t.initial_temperature, partition=shares,
                            partition_law=scene.micro.partition_law, wear=wear,
                            wear_every=scene.wear.update_every if wear else 1, steps=t.steps,
                            wear_limit=scene.wear.limit if wear else 0.0,
                            flash_softening=scene.micro.flash_softening,
                            forces=interface_forces(scene, tm), friction=mu,
                            remote=scene.micro.remote(scene.effects), coupling=scene.micro.coupling_scheme(scene.effects),
                            coupling_tol=scene.micro.coupling_tol, coupling_iterations=scene.micro.coupling_iterations)
    grids = {grid_of(z): z for z in rough.zones}          # interfaces whose zones differ in cell size
    post = PostAnalyses({grid: post_analysis(scene, z) for grid, z in grids.items()})
    return Multiscale(model, rough, post, settings, fingerprint(scene))


def run(scene, *, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True,
        stop_after: int | None = None) -> MultiscaleResult:
    """Run a scene with effect ``roughness`` (see module docstring).

    ``resume`` continues from ``checkpoint.h5`` in the output folder; ``stop_after`` ends the run
    after that macro step's checkpoint (as if it had been killed then; for tests).
    """
    start = _time.perf_counter()
    io.abort_on_exception(comm)
    out, ckpt, stored = stepping.open_run(scene, overwrite, resume, comm)
    folder = out.path
    if stored.get("finished"):
        history, fields, png = stepping.ended(folder, scene.name, int(stored["step"]), comm, verbose)
        plot, maps = folder / "multiscale.png", sorted(folder.glob("wear_map*.png"))
        plot = plot if plot.is_file() else None
        files = fields + [f for f in (folder / "history.h5", png, plot, folder / "zones.h5", ckpt) if f] + maps
        return MultiscaleResult(folder, files, 0.0, history, folder / "history.h5", png, fields, plot, maps,
                                folder / "zones.h5", int(stored["step"]))
    ms = build(scene, comm, progress=verbose and comm.rank == 0)
    with closed_on_error(ms.model, comm):        # a script going on after a failed run gets its communicators
        steps = scene.time.steps if (ms.model.thermal is not None or scene.has("wear")) else 0
        every = scene.output.every
        if resume:
            with io.stage("restoring the checkpoint"):
                done, history = dataclasses.astuple(ms.restore(ckpt))
        else:
            with io.stage("zone laws and first solve"), heat_warnings_as_notes(ms.model):
                first = ms.start()
            done, history = 0, io.History()
            history.append(**ms.record(first))
            if steps:
                say_at_once(scene, history, comm)
            out.claim()                      # --overwrite: the earlier results go now, not before a failed start
            write_history(history, folder, scene.name, comm, plot=False)   # a run failing in step 1 keeps t = 0
            refuse_floating(scene, ms.model.tm, history)
            say_clamp(scene, history)
        ms.rough.pool.progress = False
        plan = outputs.plan(scene)
        writer = stepping.field_output(ms.model, folder, plan.body_fields + plan.interface_fields, done=done,
                                       steps=steps, every=every, resume=resume, extra=ms.facet_fields(),
                                       worn=resume and ms.worn_through() is not None)
        if not resume:                       # after the refusal: a refused run leaves nothing to resume (a review)
            ms.save(ckpt, 0, history)
        last = steps if stop_after is None else min(steps, stop_after)
        # a Ctrl-C while the end is written lets it finish
        with io.StepStop(comm, done) as stop, heat_warnings_as_notes(ms.model):
            done, stopping, through = stepping.march(ms, stop, history, writer,
                                            lambda: write_history(history, folder, scene.name, comm, plot=False),
                                            ckpt, done=done, last=last, steps=steps, every=every)
            with io.stage("writing history and plots"), stop.writing(done, last=not stopping):
                title = scene.name + stepping.stopped_after(done, steps, stopping, through)
                h5, png = write_history(history, folder, scene.name, comm, plot=scene.output.figures, title=title)
                plot, maps, zones = write_zone_results(ms, folder, history, title, comm, scene.output.figures)
        if done == steps:
            checkpoint.mark(ckpt, comm, finished=True)      # --resume: nothing left to do
        result = MultiscaleResult(folder, writer.files + [f for f in (h5, png, plot, zones, ckpt) if f] + maps,
                                  _time.perf_counter() - start, history, h5, png, writer.files, plot, maps, zones,
                                  done, warnings=run_notes(ms.model) + through_layers(ms, *_wear_keys(scene)) +
                                  worn_probes(ms.model, (ms.facet_wear_depth(), ms.counter_depth)) +
                                  ((stepping.worn_note(through, done, steps),) if through else ()),
                                  ended=stepping.ended_by(through, done, steps))
        ms.model.close()          # on every rank in the same order (MUMPS' destruction communicates)
    if stopping:                 # decided by every rank together
        raise Interrupted(f"after step {done} of {steps}", result.warnings)
    if verbose and comm.rank == 0:
        print(f"{scene.name}: {io.counted(len(history), 'record')} ({done}/{steps} steps) in "
              f"{result.wall_time:.1f} s on {io.counted(comm.size, 'rank')}")
        print(f"  ParaView: {', '.join(str(f) for f in result.field_files)}")
        plots = [str(p) for p in [png, plot] + maps if p]
        print(f"  history:  {h5}" + (f"  plots: {', '.join(plots)}" if plots else ""))
        if headline := totals(history):
            print(f"  totals:   {headline}")
    return result


def through_layers(ms: Multiscale, rate: str = "wear.k_w", layers: float = 0.0) -> tuple:
    """Rough interfaces whose deepest wear exceeds the ``layers`` [m] on them (their total thickness):
    the coating is worn through, which the micro kernel does not follow (a materials trial's wear
    rate took a 2 um coating 15.6 um). The body itself worn through ends the run (``Multiscale.
    worn_through``: an adversarial trial's wear rate took a 15 mm pin 73 mm deep). ``rate``: the key
    of the wear rate, for the message."""
    rough = ms.rough
    depth = rough.wear_depth().max(axis=(-2, -1), initial=0.0)
    out = []
    for name in rough.names:
        deepest = float(depth[rough.zone_of(name)].max(initial=0.0))
        if deepest > layers > 0:
            out.append(f"the wear on interface {name!r} reached {deepest * 1e6:.3g} um deep, through its layers "
                       f"({layers * 1e6:.3g} um): the micro contact keeps them (its kernel is the layered one), so "
                       f"the worn zones' laws are those of a coating that is gone; check the wear rate ({rate})")
    return tuple(out)


def _wear_keys(scene) -> tuple[str, float]:
    """(the key of the rough body's wear rate, the total thickness of its layers [m] or 0)."""
    given = scene.wear.given if scene.wear is not None else None            # (no [wear]: no wear)
    rate = f"materials.{scene.rough_material}.k_w" if scene.rough_material_wears else f"wear.{given or 'k_w'}"
    return rate, sum(x.thickness for x in scene.layers.layer) if scene.has("layers") else 0.0


def write_zone_results(ms: Multiscale, folder: Path, history: io.History, name: str, comm,
                       figures: bool = True) -> tuple:
    """zones.h5 and, with ``figures``, multiscale.png and the wear maps (with wear: ``wear_map.png``,
    or ``wear_map_<interface>.png`` for several interfaces): rank 0 writes multiscale.png and
    zones.h5, the wear maps are spread over the ranks (every rank holds the wear depths); a failure
    is an OutputError on every rank. Returns (multiscale.png or None, the wear maps, zones.h5)."""
    rough = ms.rough
    plot, zones = folder / "multiscale.png" if figures else None, folder / "zones.h5"
    names = list(rough.names)
    maps = [] if not (ms.settings.wear and figures) else [folder / "wear_map.png"] if len(names) == 1 else \
        [folder / f"wear_map_{n}.png" for n in names]
    depth = rough.wear_depth()

    def write():
        if plot:
            from multiscale.plots.history import multiscale_figure  # local: matplotlib only when a figure is drawn
            multiscale_figure(history, plot, name)
        with h5py.File(zones, "w") as h5:
            h5.create_dataset("centre", data=np.array([z.centre for z in rough.zones])).attrs["unit"] = "m"   # (u, v)
            h5.create_dataset("position", data=rough.zone_frames()[0]).attrs["unit"] = "m"   # the centre in space
            h5.create_dataset("mean_wear_depth", data=depth.mean(axis=(-2, -1))).attrs["unit"] = "m"
            h5.create_dataset("max_wear_depth", data=depth.max(axis=(-2, -1))).attrs["unit"] = "m"
            h5.create_dataset("wear_volume", data=rough.zone_wear_volume(depth)).attrs["unit"] = "m^3"
            h5.create_dataset("facet_area", data=rough.covered_area).attrs["unit"] = "m^2"
            h5.create_dataset("partition", data=ms.partition).attrs["unit"] = "-"     # share into body 0
            h5.create_dataset("flash_temperature", data=ms.flash).attrs["unit"] = "K"
            h5.create_dataset("counter_wear_depth", data=ms.counter_depth).attrs["unit"] = "m"   # per facet
            h5.create_dataset("facet_centre", data=ms.tm.interface.midpoints).attrs["unit"] = "m"  # of those facets
            h5.create_dataset("conductance", data=ms.conductance).attrs["unit"] = "W/(m^2 K)"
            h5.attrs["counts"] = np.array([g.counts for g in rough.grids])     # (interfaces, 2)
    offsets = np.cumsum([0] + [g.n_zones for g in rough.grids])
    faces = [rough.planes[k].uv(ms.tm.interface.triangles(n)) for k, n in enumerate(names)] if maps else []

    def draw(*args):
        from multiscale.plots.history import wear_map  # local: matplotlib only when a figure is drawn
        return wear_map(*args)
    jobs = [write] + [partial(draw, grid, depth[offsets[k]:offsets[k + 1]], path, f"{name}: {interface}", face)
                      for k, (grid, path, interface, face) in enumerate(zip(rough.grids, maps, names, faces))]
    io.on_ranks(comm, jobs, f"the zone results in {folder}")        # the wear maps spread over the ranks
    return plot, maps, zones

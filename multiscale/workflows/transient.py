"""Transient thermo-mechanics with perfect contact (thesis §7.3.1, Fig. 7.4): the workflow of a scene
without ``roughness`` or ``stability``.

Builds the model (``workflows.model``), ramps the load, marches ``time.steps`` macro steps of
``time.substeps`` sub-steps (only with effect ``thermal`` or ``wear``: the facets' Archard wear,
``macro.facet_wear``; otherwise the one contact solve), and
writes ``history.h5``, ``history.png`` and the field files (``multiscale.outputs.plan``) into
``output.folder``; with steps, a checkpoint after each (``workflows.stepping``: ``--resume``).
"""
from __future__ import annotations

import dataclasses
import time as _time
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

from multiscale import checkpoint, io, outputs
from multiscale.errors import Interrupted
from multiscale.macro.facet_wear import FacetWear
from multiscale.macro.kept_cells import closed_on_error
from multiscale.macro.model import MacroModel
from multiscale.workflows import stepping
from multiscale.workflows.model import build_mesh, build_model, facet_wear, heat_warnings_as_notes, run_notes, \
    say_clamp, say_load, say_model_size, worn_probes
from multiscale.workflows.output import RunResult, fingerprint, totals
from multiscale.workflows.strain import refuse_floating, say_at_once


@dataclass
class TransientResult(RunResult):
    """``RunResult`` of a macro run with a history."""

    history: io.History
    history_file: Path          #: history.h5
    plot_file: Path | None      #: history.png (None with output.figures = false)
    field_files: list           #: XDMF files


def write_history(history: io.History, folder: Path, name: str, comm, plot: bool = True,
                  title: str | None = None) -> tuple[Path, Path | None]:
    """``history.h5`` and (with ``plot``) ``history.png`` titled ``title`` (default ``name``), else None
    (rank 0 writes; a failure is an OutputError on every rank)."""
    h5, png = folder / "history.h5", folder / "history.png" if plot else None

    def write():
        history.write(h5, {"scene": name, "ranks": comm.size})
        if plot:
            from multiscale.plots.history import history_figure  # local: matplotlib only when a figure is drawn
            history_figure(history, png, title=title or name)
    io.on_root(comm, write, f"the history {h5}")
    return h5, png


class Marching:
    """A perfect-contact model as ``stepping.march`` drives it: its macro steps (with ``wear``, the
    facets' Archard wear every ``wear.update_every`` steps and at the last), history rows and
    checkpoints (the model's state, ``MacroModel.checkpoint_state``, and the wear's)."""

    def __init__(self, scene, model: MacroModel, wear: FacetWear | None = None):
        self.scene, self.model, self.wear, self.fingerprint = scene, model, wear, fingerprint(scene)
        self.updated = False                  # the last step updated the wear

    def step(self, n: int):
        heat = self.model.macro_step(self.scene.time.dt, self.scene.time.substeps)
        last = n == self.scene.time.steps
        self.updated = self.wear is not None and (n % self.scene.wear.update_every == 0 or last) \
            and bool(self.model.exposure.sliding)      # (a dwell's rows: no update)
        if self.updated:
            self.wear.update(last)
        return heat

    def record(self, heat) -> dict:
        return {**self.model.record(heat), **(self.wear.row(self.updated) if self.wear is not None else {})}

    def worn_through(self) -> str | None:
        return self.wear.worn_through() if self.wear is not None else None

    def save(self, path: Path, step: int, history: io.History) -> None:
        """Checkpoint after macro step ``step`` (collective; ``checkpoint.save_step``)."""
        attrs, arrays = self.model.checkpoint_state()
        if self.wear is not None:
            more, worn = self.wear.state()
            attrs, arrays = {**attrs, **more}, {**arrays, **worn}
        checkpoint.save_step(path, self.model.tm.comm, step, history, self.fingerprint, attrs, arrays, self.model)

    def restore(self, path: Path) -> checkpoint.Restored:
        """State of the checkpoint ``path`` (collective)."""
        attrs, arrays = checkpoint.load(path, self.model.tm.comm, self.model.functions, self.fingerprint)
        self.model.restore_checkpoint(attrs, arrays)
        if self.wear is not None:
            self.wear.restore(attrs, arrays)
        return checkpoint.restored(attrs, arrays)


def wear_fields(wear: FacetWear) -> dict:
    """The interface fields of the facets' wear: ``wear_depth`` of body 0 and ``counter_wear_depth`` of
    body 1 [m] (0 where it does not wear)."""
    return {"wear_depth": lambda: wear.depth.copy(), "counter_wear_depth": lambda: wear.counter_depth.copy()}


def run(scene, *, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True,
        stop_after: int | None = None) -> TransientResult:
    """Run a perfect-contact scene (see module docstring). ``resume`` continues from
    ``checkpoint.h5`` in the output folder (``workflows.stepping``); ``stop_after`` ends the run
    after that macro step's checkpoint (as if it had been killed then; for tests)."""
    start = _time.perf_counter()
    io.abort_on_exception(comm)
    out, ckpt, stored = stepping.open_run(scene, overwrite, resume, comm)
    folder = out.path
    if stored.get("finished"):
        history, fields, png = stepping.ended(folder, scene.name, int(stored["step"]), comm, verbose)
        return TransientResult(folder, fields + [f for f in (folder / "history.h5", png, ckpt) if f], 0.0, history,
                               folder / "history.h5", png, fields)
    with io.stage("meshing"):
        tm = build_mesh(scene, comm)
    with io.stage("model set-up"), heat_warnings_as_notes():
        model = build_model(scene, comm, tm=tm)
    say_model_size(tm, model.mechanics, model.thermal)
    say_load(scene, tm)
    wear = facet_wear(scene, model) if scene.has("wear") else None
    marching = Marching(scene, model, wear)
    with closed_on_error(model, comm):           # a script going on after a failed run gets its communicators
        steps = scene.time.steps if outputs.marching(scene) else 0
        if resume:
            with io.stage("restoring the checkpoint"):
                done, history = dataclasses.astuple(marching.restore(ckpt))
        else:
            with io.stage("first contact solve"), heat_warnings_as_notes(model):
                model.start()
            out.claim()                          # --overwrite: the earlier results go now, not before a failed start
            done, history = 0, io.History()
            history.append(**marching.record((0.0, 0.0)))
        plan = outputs.plan(scene)
        writer = stepping.field_output(model, folder, plan.body_fields + plan.interface_fields, done=done,
                                       steps=steps, every=scene.output.every, resume=resume,
                                       extra=wear_fields(wear) if wear is not None else None,
                                       worn=resume and marching.worn_through() is not None)
        if not resume:                       # (the first solve's fields are written: also those of a run refused next)
            write_history(history, folder, scene.name, comm, plot=False)   # a run failing in its first step keeps t = 0
            refuse_floating(scene, tm, history)
            say_clamp(scene, history)
            if steps:                        # after the refusal: a refused run leaves nothing to resume (a review)
                marching.save(ckpt, 0, history)
                say_at_once(scene, history, comm)
        last = steps if stop_after is None else min(steps, stop_after)
        with io.StepStop(comm, done) as stop, heat_warnings_as_notes(model):   # a Ctrl-C while the end is written lets it finish
            done, stopping, through = stepping.march(marching, stop, history, writer,
                                            lambda: write_history(history, folder, scene.name, comm, plot=False),
                                            ckpt, done=done, last=last, steps=steps, every=scene.output.every)
            with io.stage("writing history and plots"), stop.writing(done, last=not stopping):
                h5, png = write_history(history, folder, scene.name, comm, plot=scene.output.figures,
                                        title=scene.name + stepping.stopped_after(done, steps, stopping, through))
        if steps and done == steps:
            checkpoint.mark(ckpt, comm, finished=True)      # --resume: nothing left to do
        model.close()                    # on every rank in the same order (MUMPS' destruction communicates)
    notes = run_notes(model) + (worn_probes(model, (wear.depth, wear.counter_depth)) if wear is not None else ())
    if stopping:                     # decided by every rank together
        raise Interrupted(f"after step {done} of {steps}", notes)
    kept = [ckpt] if steps else []
    result = TransientResult(folder, writer.files + [f for f in (h5, png) if f] + kept, _time.perf_counter() - start,
                             history, h5, png, writer.files,
                             warnings=notes + ((stepping.worn_note(through, done, steps),) if through else ()),
                             ended=stepping.ended_by(through, done, steps))
    if verbose and comm.rank == 0:
        print(f"{scene.name}: {io.counted(len(history), 'record')} in {result.wall_time:.1f} s on "
              f"{io.counted(comm.size, 'rank')}")
        print(f"  ParaView: {', '.join(str(f) for f in writer.files)}")
        print(f"  history:  {h5}" + (f"  plot: {png}" if png else ""))
        if headline := totals(history):
            print(f"  totals:   {headline}")
    return result

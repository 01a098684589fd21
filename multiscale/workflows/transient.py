"""Transient thermo-mechanics with perfect contact (thesis §7.3.1, Fig. 7.4): the workflow of a scene
without ``roughness`` or ``stability``.

Builds the model (``workflows.model``), ramps the load, marches ``time.steps`` macro steps of
``time.substeps`` sub-steps (only with effect ``thermal``; otherwise the one contact solve), and
writes ``history.h5``, ``history.png`` and the field files (``multiscale.outputs.plan``) into
``output.folder``.
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass
from pathlib import Path

from mpi4py import MPI

from multiscale import io, outputs
from multiscale.errors import Interrupted
from multiscale.macro.kept_cells import closed_on_error
from multiscale.macro.output import FieldOutput
from multiscale.workflows.model import build_mesh, build_model, heat_warnings_as_notes, run_notes, say_clamp, \
    say_load, say_model_size
from multiscale.workflows.output import RunResult, prepare_folder, totals
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


def stopped_after(done: int, steps: int) -> str:
    """The figures' title note of a run stopped by Ctrl-C (theirs said nothing of it: a user trial)."""
    return f" (stopped after step {done} of {steps})"


def run(scene, *, overwrite: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True) -> TransientResult:
    """Run a perfect-contact scene (see module docstring)."""
    start = _time.perf_counter()
    io.abort_on_exception(comm)
    out = prepare_folder(scene, overwrite, False, comm)
    folder = out.path
    with io.stage("meshing"):
        tm = build_mesh(scene, comm)
    with io.stage("model set-up"), heat_warnings_as_notes():
        model = build_model(scene, comm, tm=tm)
    say_model_size(tm, model.mechanics, model.thermal)
    say_load(scene, tm)
    with closed_on_error(model, comm):           # a script going on after a failed run gets its communicators
        with io.stage("first contact solve"), heat_warnings_as_notes(model):
            model.start()
        out.claim()                          # --overwrite: the earlier results go now, not before a failed start
        plan = outputs.plan(scene)
        writer = FieldOutput(model, folder, plan.body_fields + plan.interface_fields)
        history = io.History()
        history.append(**model.record())
        writer.write()
        write_history(history, folder, scene.name, comm, plot=False)   # a run failing in its first step keeps t = 0
        refuse_floating(scene, tm, history)
        say_clamp(scene, history)
        steps = scene.time.steps if model.thermal is not None else 0
        if steps:
            say_at_once(scene, history, comm)
        done, stopping = 0, False
        with io.StepStop(comm) as stop, heat_warnings_as_notes(model):   # a Ctrl-C while the end is written lets it finish
            with io.stage("macro steps"):
                for n in io.bar(range(1, steps + 1), "macro steps"):
                    heat = model.macro_step(scene.time.dt, scene.time.substeps)
                    with stop.writing(n):            # the step's fields and history, whole
                        history.append(**model.record(heat))
                        done, stopping = n, n < steps and stop.requested()   # (the last: it finishes)
                        if n % scene.output.every == 0 or n == steps or stopping:
                            writer.write()
                        if n < steps:                # a killed run keeps the history of its steps
                            write_history(history, folder, scene.name, comm, plot=False)
                    if stopping:
                        break
            with io.stage("writing history and plots"), stop.writing(done, last=not stopping):
                h5, png = write_history(history, folder, scene.name, comm, plot=scene.output.figures,
                                        title=scene.name + stopped_after(done, steps) * stopping)
        model.close()                    # on every rank in the same order (MUMPS' destruction communicates)
    if stopping:                     # decided by every rank together
        raise Interrupted(f"after step {done} of {steps}", run_notes(model))
    result = TransientResult(folder, writer.files + [f for f in (h5, png) if f], _time.perf_counter() - start, history,
                             h5, png, writer.files, warnings=run_notes(model))
    if verbose and comm.rank == 0:
        print(f"{scene.name}: {io.counted(len(history), 'record')} in {result.wall_time:.1f} s on "
              f"{io.counted(comm.size, 'rank')}")
        print(f"  ParaView: {', '.join(str(f) for f in writer.files)}")
        print(f"  history:  {h5}" + (f"  plot: {png}" if png else ""))
        if headline := totals(history):
            print(f"  totals:   {headline}")
    return result

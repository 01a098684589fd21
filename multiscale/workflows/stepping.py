"""The macro steps of a time-marching run (``workflows.transient``, ``workflows.multiscale``) and
their checkpoints, so that ``multiscale run --resume`` continues a stopped or killed run.

Every step writes, as one whole that a Ctrl-C waits for (``io.StepStop.writing``): its history row,
at output times its fields, its checkpoint (``checkpoint.h5``: the step, the history, the model's
fields and state; the run's own ``save``), the history file (readable if the run is killed next)
and, at a stop between output times, its fields: a checkpoint's step has its fields written if they
are due. A resumed run starts from the checkpoint's
step: the field files keep their times up to it (``FieldOutput(resume_at=...)``: those of a step
whose checkpoint was not written are dropped, and the fields of a stop between output times too),
so that a run stopped and resumed, any number of times, writes what the straight run writes.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multiscale import checkpoint, io
from multiscale.errors import InputError
from multiscale.macro.output import FieldOutput
from multiscale.outputs import CHECKPOINT, field_step
from multiscale.workflows.output import OutputFolder, fingerprint, prepare_folder


def open_run(scene, overwrite: bool, resume: bool, comm) -> tuple[OutputFolder, Path, dict]:
    """The output folder of a time-marching run (``workflows.output.prepare_folder``), its checkpoint's
    path, and (``resume``) the checkpoint's attributes, {} otherwise: ``--resume`` into a folder
    without a checkpoint is refused before the folder is touched, and that of a finished run is
    checked against the scene (``finished`` in the attributes: nothing left to do); collective."""
    folder = Path(scene.output.folder)
    if resume and comm.bcast(folder.is_dir() and not (folder / CHECKPOINT).is_file() if comm.rank == 0 else None,
                             root=0):
        raise InputError("--resume", str(folder), f"no {CHECKPOINT} in the output folder to resume from (no "
                         "macro step of a run ended there): run without --resume (with --overwrite if the folder "
                         "holds results; in Python: resume=False, overwrite=True)")
    out = prepare_folder(scene, overwrite, resume, comm)
    stored = checkpoint.peek(out.path / CHECKPOINT, comm) if resume else {}
    if stored.get("finished"):
        checkpoint.same_scene(stored, fingerprint(scene), out.path / CHECKPOINT)
    elif resume:
        out.claim()                          # a part of its own in the provenance, also if it is killed
    return out, out.path / CHECKPOINT, stored


def field_output(model, folder: Path, names, *, done: int, steps: int, every: int, resume: bool,
                 extra=None, worn: bool = False) -> FieldOutput:
    """The run's field files: a new run's, with the fields of its start (step ``done`` = 0, written
    before its first checkpoint); a resumed run's, kept up to its checkpoint's step ``done`` (whose
    due fields were written before it), without the fields of a stop between output times, but with
    those of a step where wear ended the run, if it still does (``worn``: ``march`` steps no further)."""
    due = field_step(done, every, steps) or worn           # the step's fields belong to the series
    keep = model.time if due else np.nextafter(model.time, -np.inf)
    writer = FieldOutput(model, folder, names, extra=extra, resume_at=keep if resume else None)
    if not resume:
        writer.write()
    return writer


def march(run, stop: io.StepStop, history: io.History, writer: FieldOutput, write_history, ckpt: Path, *,
          done: int, last: int, steps: int, every: int) -> tuple[int, bool, str | None]:
    """Macro steps ``done`` + 1 ... ``last`` of ``steps`` (module docstring): ``run`` has
    ``step(n)`` (its result goes to ``record``), ``record(stepped)`` (a history row),
    ``save(ckpt, n, history)`` (the checkpoint) and ``worn_through()`` (what wore through, or None:
    the run ends after that step, its fields written); ``write_history()`` writes the history file.
    Returns the last step done, whether a Ctrl-C stops the run there and what wore through (decided
    by every rank)."""
    stopping, through = False, run.worn_through()      # resumed where wear ended it: no step further
    if through:
        return done, stopping, through
    with io.stage("macro steps"):
        for n in io.bar(range(done + 1, last + 1), "macro steps", initial=done, total=steps):
            stepped = run.step(n)
            through = run.worn_through()
            with stop.writing(n):                     # the step's fields, checkpoint and history, whole
                history.append(**run.record(stepped))
                due = field_step(n, every, steps) or through is not None
                if due:
                    writer.write()                    # before the checkpoint: killed between, they are dropped
                run.save(ckpt, n, history)
                write_history()                       # readable if the run is killed
                done, stopping = n, n < steps and not through and stop.requested()   # (the last, or worn: it ends)
                if stopping and not due:
                    writer.write()                    # the stop's, dropped when resumed
            if stopping or through:
                break
    return done, stopping, through


def ended(folder: Path, name: str, steps: int, comm, verbose: bool) -> tuple[io.History, list, Path | None]:
    """A run that ended (``--resume`` of a finished run: nothing to do): its history, field files
    and history.png (None if not drawn), from its folder."""
    if verbose and comm.rank == 0:
        print(f"{name}: nothing to do, the run in {folder} has ended after {steps} step(s); "
              "use --overwrite to run it again (in Python: overwrite=True)")
    png = folder / "history.png"
    return io.History.read(folder / "history.h5"), sorted(folder.glob("*.xdmf")), png if png.is_file() else None


def stopped_after(done: int, steps: int, stopping: bool, through: str | None = None) -> str:
    """The figures' title note of a run stopped by Ctrl-C (theirs said nothing of it: a user trial) or
    ended by a part worn ``through`` or to its wear limit (``march``); "" otherwise."""
    return f" (stopped after step {done} of {steps})" if stopping else \
        f" (ended by wear at step {done} of {steps})" if through else ""


def ended_by(through: str | None, done: int, steps: int) -> str:
    """A run's provenance status when a part wore ``through`` (or to its limit), else ""."""
    return f"ended by wear after step {done} of {steps}" if through else ""


def worn_note(through: str, done: int, steps: int) -> str:
    """The warning of a run that ended at step ``done`` of ``steps`` because a part wore ``through`` (or
    to its wear limit)."""
    return f"{through}; the run ended after step {done} of {steps}, its results written"

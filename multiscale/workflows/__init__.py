"""The workflow layer: a scene in, a typed result out. The only macro-side code that reads scenes.

``model`` (the scene-to-model factory), ``rough`` (the one rough-interface builder), ``output`` (the
output-folder check, ``RunResult``) and one workflow per analysis: ``transient`` (thermo-mechanics
with perfect contact), ``multiscale`` (the multiscale loop, effect ``roughness``) and ``squeal``
(complex eigenvalues, effect ``stability``). ``run`` dispatches a scene to its workflow.
"""
from __future__ import annotations

from mpi4py import MPI

from multiscale.errors import InputError
from multiscale.workflows import multiscale, squeal, transient
from multiscale.workflows.output import RunResult


def workflow(scene) -> str:
    """Which analysis a scene runs: "squeal" (effect stability), "multiscale" (effect roughness)
    or "transient"."""
    return "squeal" if scene.has("stability") else "multiscale" if scene.has("roughness") else "transient"


def run(scene, *, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD,
        verbose: bool = True) -> RunResult:
    """Run a scene (``multiscale run``) with its workflow; only the multiscale loop resumes."""
    kind = workflow(scene)
    if kind == "multiscale":
        return multiscale.run(scene, overwrite=overwrite, resume=resume, comm=comm, verbose=verbose)
    if resume:
        why = ("the squeal analysis has no checkpoints to resume from" if kind == "squeal" else
               'this scene has no checkpoints to resume from (only the multiscale loop, effect "roughness", '
               "writes checkpoints)")
        raise InputError("--resume", True, why)
    module = squeal if kind == "squeal" else transient
    return module.run(scene, overwrite=overwrite, comm=comm, verbose=verbose)


__all__ = ["RunResult", "run", "workflow"]

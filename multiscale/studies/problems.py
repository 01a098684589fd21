"""The registry of study problems (``problem = "..."`` of a study file): the micro problems, then
``scene``; ``problems_text`` is what ``multiscale study --problems`` prints."""
from __future__ import annotations

from multiscale.errors import InputError
from multiscale.schema import reference, suggest
from multiscale.studies.base import Problem
from multiscale.studies.micro_problems import MICRO_PROBLEMS
from multiscale.studies.scene_problem import SceneProblem

__all__ = ["PROBLEMS", "problem", "problems_text"]

PROBLEMS: dict[str, Problem] = {**MICRO_PROBLEMS, "scene": SceneProblem()}


def problem(name: str) -> Problem:
    """The registered problem ``name`` (InputError with did-you-mean otherwise)."""
    if name not in PROBLEMS:
        raise InputError("problem", name, f"unknown{suggest(name, PROBLEMS)}; known: {', '.join(PROBLEMS)}")
    return PROBLEMS[name]


def problems_text() -> str:
    """The registered problems: parameters (``multiscale.schema.reference``) and metrics."""
    lines = []
    for name, entry in PROBLEMS.items():
        lines += ["", f"problem = \"{name}\": {entry.doc}"]
        if getattr(entry, "params", None) is not None:
            lines += ["  parameters ([fixed] and [sweep] keys):"] + ["  " + line for line in reference(entry.params)]
        else:
            lines.append("  parameters: dotted keys of the base scene (scene = \"file.toml\"), e.g. geometry.mesh_size")
        if entry.metrics:                     # (a scene's are its history columns: said in its line)
            lines += ["  metrics:"] + [f"    {m:<22} {doc}" for m, doc in entry.metrics.items()]
        if getattr(entry, "exact", None):
            lines.append(f"  analytic reference of: {', '.join(entry.exact_metrics)}")
    return "\n".join(lines[1:])


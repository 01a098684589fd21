"""The ``scene`` problem: any macro scene with overrides (dotted scene paths -> raw values), run
in a subprocess (``python -m multiscale.studies.scene_run``, under ``mpiexec -n ranks`` when
ranks > 1); metrics from its HDF5 history, or for a squeal scene from its table of modes."""
from __future__ import annotations

import hashlib
import importlib.util
import json
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multiscale.checkpoint import file_digest
from multiscale.errors import MultiscaleError, SceneError
from multiscale.io import History, unit_of
from multiscale.scene import Scene, load
from multiscale.scene_keys import key_parts
from multiscale.schema import Integer, Named, Section, Tables, fields_of, suggest
from multiscale.studies.base import Outcome, Problem, RunFailed, jsonable, unit_in

__all__ = ["SQUEAL_METRICS", "SceneProblem", "SceneRun", "failure_line", "history_metrics", "scene_key_spec",
           "squeal_metrics"]

def _over_finite(f):
    """``f`` over the finite values of a history column, NaN if none: NaN marks a row without the
    quantity (the coupling residual at t = 0, a partition with no contact), and it made every run
    of a study that asked for its maximum a failed one (a user trial)."""
    def reduce(v):
        kept = v[np.isfinite(v)]
        return float(f(kept)) if kept.size else np.nan
    return reduce


_REDUCERS = {"last": lambda v: v[-1], "first": lambda v: v[0], "max": _over_finite(np.max),
             "min": _over_finite(np.min), "mean": _over_finite(np.mean), "rise": lambda v: v[-1] - v[0]}

_EXCEPTION = re.compile(r"^[A-Za-z_][\w.]*(Error|Exception|Interrupt)\b")


NO_DOLFINX = ("problem = \"scene\" runs each point with multiscale run, which needs DOLFINx: install it with "
              "pip install -e '.[fem]'")


def failure_line(output: str) -> str:
    """What a failed run says of its failure: the last line naming an exception (``ConvergenceError:
    ...``; the launcher's abort lines of the other ranks come after it), else the last line; the
    exception named without its module, a bad input (``InputError``, ``SceneError``) by its message
    alone, as ``multiscale run`` says it (a user trial read "multiscale.errors.InputError: ...")."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    named = [line for line in lines if _EXCEPTION.match(line)]
    last = (named or lines or ["no output"])[-1]
    kind, colon, message = last.partition(": ")
    if not named or not colon:
        return last
    kind = kind.rpartition(".")[2]
    return message if kind in ("InputError", "SceneError", "InputErrors") else f"{kind}: {message}"


SQUEAL_METRICS = {
    "modes": "number of complex modes found in the band [-]",
    "unstable_modes": "modes flagged unstable in modes.csv: damping ratio below -stability.threshold [-]",
    "max_growth": "largest real part sigma of the eigenvalues [1/s]",
    "max_growth_frequency": "frequency of the mode with the largest positive real part, the lowest of a tie; "
                            "NaN (n/a) if no mode grows [Hz]",
    "lowest_unstable_frequency": "frequency of the lowest unstable mode, NaN (n/a) if none [Hz]",
    "min_damping_ratio": "smallest damping ratio (negative: unstable) [-]",
}


def squeal_metrics(modes_csv) -> dict:
    """``SQUEAL_METRICS`` of a squeal run's mode table (``ModalResult.write_csv``)."""
    table = np.genfromtxt(modes_csv, delimiter=",", names=True, ndmin=1)
    f, sigma, unstable = table["frequency_Hz"], table["sigma_1_per_s"], table["unstable"] > 0
    k = int(np.argmax(sigma))      # (0 Hz and a stable mode's frequency when none grew: a user trial)
    return {"modes": float(f.size), "unstable_modes": float(unstable.sum()), "max_growth": float(sigma[k]),
            "max_growth_frequency": float(f[k]) if sigma[k] > 0 else np.nan,
            "lowest_unstable_frequency": float(f[unstable].min()) if unstable.any() else np.nan,
            "min_damping_ratio": float(table["damping_ratio"].min())}


def scene_key_spec(dotted: str):
    """The Spec of the dotted scene key ``dotted`` ("wear.k_w"; a named table's name is any:
    "materials.pin.E"; an entry of an array of tables by its number: "boundary[2].emissivity");
    None if the scene schema has no such key (a builder's parameters are the builder's)."""
    parts, cls = key_parts(dotted), Scene
    while True:
        spec = dict(fields_of(cls)).get(parts.pop(0))
        if spec is None or not parts:
            return spec
        if isinstance(spec.parser, Named) or (isinstance(spec.parser, Tables) and parts[0].isdigit()):
            parts.pop(0)         # (a swept boundary[2].emissivity had no unit: a user trial)
        elif isinstance(spec.parser, Tables):
            return None
        if not parts or not isinstance(spec.parser, Section):
            return None
        cls = spec.parser.cls


def _squeal(scene, fixed=None) -> bool | None:
    """Whether a scene file, with a study's ``fixed`` keys, runs the squeal analysis (None if it
    cannot be read without the swept keys: said elsewhere)."""
    try:
        return load(scene, fixed or None).has("stability")
    except MultiscaleError:
        return None


@dataclass(frozen=True)
class SceneRun:
    """A macro scene with overrides (dotted scene paths -> raw values) and MPI ranks per run;
    ``files``: the other files it reads (geometry, measured surfaces), whose bytes name the run;
    ``warnings``: the scene's own (the study's, said before it runs)."""

    scene: Path
    overrides: dict = field(default_factory=dict)
    ranks: int = 1
    files: tuple = ()
    warnings: tuple = ()


class SceneProblem(Problem):
    """Any macro scene (``multiscale run``) with overrides; metrics are history columns reduced
    over time (scalar columns: per-zone ones are skipped): ``column`` (last value) or ``column:last|first|max|min|mean|rise`` (rise = last −
    first: a temperature rise, whose relative error means more than that of a temperature in K;
    max, min and mean over the rows that have a value, ``_over_finite``).
    A squeal scene (effect ``stability``) has no history; its metrics come from ``modes.csv``
    (``squeal_metrics``). A run's wall time is its own (provenance.json ``total_wall_time_s``), not
    its process's, which starts Python and DOLFINx first."""

    name = "scene"
    doc = ("a macro scene run by the macro runner with overrides; metrics: HDF5 history columns, "
           "column[:last|first|max|min|mean|rise]; squeal scenes: " + ", ".join(SQUEAL_METRICS))
    metrics = {}
    undefined = frozenset({"max_growth_frequency", "lowest_unstable_frequency"})

    def parse(self, raw, path, ctx, scene=None, ranks=1):
        if importlib.util.find_spec("dolfinx") is None:
            ctx.problems.append(NO_DOLFINX)       # (each run failed on petsc4py after starting: a user trial)
        try:
            loaded = load(scene, overrides=raw)
        except SceneError as exc:
            ctx.problems.extend(f"{path}: {line}" if path else line for line in exc.problems)
            return None
        ctx.warnings.extend(loaded.warnings)
        own = Path(scene).resolve()
        return SceneRun(Path(scene), dict(raw), ranks, tuple(sorted(p for p in loaded.inputs if p != own)),
                        tuple(loaded.warnings))

    def key(self, params: SceneRun) -> dict:
        """The scene's path and bytes, the overrides, the bytes of the files it reads (a CAD file
        or measured surface rewritten under its name makes new runs; its old records were reused)
        and the ranks above one (a study at 2 ranks reused the times of 1)."""
        text = params.scene.read_bytes()
        files = {str(p): file_digest(p) for p in params.files if p.is_file()}
        return {"scene": str(params.scene), "scene_sha256": hashlib.sha256(text).hexdigest(),
                "overrides": jsonable(params.overrides), **({"files": files} if files else {}),
                **({"ranks": params.ranks} if params.ranks > 1 else {})}

    def knob_spec(self, name: str):
        """The Spec of a whole-number scene key (``time.steps``: a range's values rounded; 3.0000000000000004
        was refused, a user trial); None for the others, which the scene reads."""
        spec = scene_key_spec(name)
        return spec if spec is not None and isinstance(spec.parser, Integer) else None

    def metric_unit(self, name: str) -> str:
        """A squeal metric's unit (``SQUEAL_METRICS``), else its history column's (``io.unit_of``)."""
        if name in SQUEAL_METRICS:
            return unit_in(SQUEAL_METRICS[name])
        return unit_of(name.partition(":")[0])

    def check_metric(self, name, scene=None, fixed=None):
        squeal = _squeal(scene, fixed) if scene is not None else None
        if squeal:                                         # its metrics are known before it runs (with [fixed]:
            #                                                a base scene that [fixed] makes a squeal one was not)
            return None if name in SQUEAL_METRICS else \
                f'unknown metric of a squeal scene{suggest(name, SQUEAL_METRICS)}; allowed: {", ".join(SQUEAL_METRICS)}'
        column, _, reducer = name.partition(":")
        if squeal is False and name in SQUEAL_METRICS:    # (found after every run had failed for it: a user trial)
            return ('a squeal metric (of modes.csv), and this scene runs no squeal analysis (effect "stability"): '
                    "its metrics are history columns, optionally with :" + "|:".join(_REDUCERS))
        if not column or (reducer and reducer not in _REDUCERS):
            return (f"a history column, optionally with :{'|:'.join(_REDUCERS)} "
                    f"(e.g. max_temperature_pin:max)")
        return None

    def run(self, params: SceneRun, workdir: Path) -> Outcome:
        """Run the scene in a subprocess (``mpiexec -n ranks`` when ranks > 1) into workdir/output."""
        out = Path(workdir) / "output"
        Path(workdir).mkdir(parents=True, exist_ok=True)
        task = json.dumps({"scene": str(params.scene), "overrides": {**params.overrides, "output.folder": str(out)}})
        command = [sys.executable, "-m", "multiscale.studies.scene_run", task]
        if params.ranks > 1:
            mpiexec = Path(sys.executable).with_name("mpiexec")
            command = [str(mpiexec) if mpiexec.exists() else "mpiexec", "-n", str(params.ranks)] + command
        shutil.rmtree(out, ignore_errors=True)   # a run killed or failed before (the study stopped by Ctrl-C, or
        #   --rerun-failed) left files there that its output checks refused to overwrite: it never ran again (a
        #   user trial); the study runs it anew, into a folder of its own
        done = subprocess.run(command, capture_output=True, text=True)
        (Path(workdir) / "scene_run.log").write_text(done.stdout + done.stderr)
        try:
            record = json.loads((out / "provenance.json").read_text())
        except (OSError, ValueError):                         # a run that failed before writing it
            record = {}
        found = tuple(w for w in record.get("warnings", ()) if w not in params.warnings)   # (only in its log before:
        #                                           zone pressures beyond micro.p_max unseen in the study; a user trial)
        if done.returncode != 0:
            raise RunFailed(f"scene run failed (exit {done.returncode}): {failure_line(done.stderr or done.stdout)}",
                            found)
        own = record.get("total_wall_time_s")     # (the process's start-up, 10 of 18 s, made a coarser grid
        #                                           slower than the reference and the cheapest setting the reference)
        if (out / "modes.csv").exists():
            return Outcome(squeal_metrics(out / "modes.csv"), -1, True, own, found)   # (no count: n/a, not 0)
        history = History.read(out / "history.h5")
        iterations = int(history["newton_iterations"].sum()) if "newton_iterations" in history.columns else 0
        return Outcome(history_metrics(history), iterations, True, own, found)


def history_metrics(history: History) -> dict:
    """The metrics of a run's history (``SceneProblem``): each scalar column's last value and its
    reductions over time, ``column:last|first|max|min|mean|rise`` (per-zone columns are skipped)."""
    metrics = {}
    for column in history.columns:
        values = history[column]
        if values.ndim == 1:
            metrics[column] = float(values[-1])
            metrics.update({f"{column}:{r}": float(f(values)) for r, f in _REDUCERS.items()})
    return metrics

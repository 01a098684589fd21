"""One study run in this fresh process: ``python -m multiscale.studies.worker TASK_JSON [LIFELINE]``,
spawned by ``running.execute``. Parses the run's parameters, runs it ``repeat`` times and writes its
record; a failure is recorded, never raised. The problem modules (and the numba-compiled micro
modules they import) are loaded with this module, before the run's clock and memory baseline; the
compiled code itself numba loads from its cache (or compiles) at a function's first call, inside
the first timing: 1.1-1.4 s measured against a 0.015 s Hertz solve on 64^2. A run whose first
timing spent more than ``JIT_SHARE`` of it there is timed once more (``jit_time`` in the record).
``LIFELINE``: a file descriptor the driver passed on (``running._lifeline``); when the driver is
gone, ``watch_driver`` ends this worker and its process group."""
from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import resource
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

import numpy as np
from numba.core import event

import multiscale
from multiscale.errors import SceneError
from multiscale.provenance import code
from multiscale.schema import Context
from multiscale.studies.base import RunFailed
from multiscale.studies.formatting import now
from multiscale.studies.problems import problem as get_problem
from multiscale.studies.records import FAILED, JIT_SHARE, metric_problem, read_json, write_json

__all__ = ["run_task", "watch_driver"]


def _peak_mb() -> float:
    """Peak resident memory [MB] of this process and of its finished children (ru_maxrss)."""
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(own, kids) / 1024.0


def _cpu() -> float:
    """CPU time [s], user + system, of this process and of its finished children."""
    total = 0.0
    for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN):
        u = resource.getrusage(who)
        total += u.ru_utime + u.ru_stime
    return total


def watch_driver(lifeline: int) -> None:
    """End this worker's process group as soon as the study's driver is gone: ``lifeline`` is the
    read end of a pipe whose write end only the driver holds and never writes to
    (``running._lifeline``), closed by the kernel at the driver's end, a SIGKILL included (which the
    driver cannot catch to kill its workers, as it does on SIGTERM and SIGHUP). The group is the
    one this process leads (``running._spawn`` starts it in a session of its own): the worker and
    what it started there, a scene run's ``python`` or ``mpiexec``, whose hydra proxy then ends the
    ranks (it puts them in sessions of their own; they go when ``mpiexec`` does). Outside a group
    of its own (started by hand) the worker ends alone.

    On Linux the kernel itself sends the SIGKILL when the pipe's writer closes: the pipe reopened
    through /proc (an open file description of this worker's own, so that every worker on the
    shared pipe is its owner) with ``O_ASYNC``, owner the group (``F_SETOWN``) and signal SIGKILL
    (``F_SETSIG``). No thread waits, so a call that holds the GIL (numba compiling a kernel, for
    seconds under load, likely why a test failed once at load 4.5) cannot delay the end. Elsewhere a
    daemon thread reads the pipe to its end-of-file and kills the group. Not the parent's death
    signal (Linux ``prctl(PR_SET_PDEATHSIG)``): it reaches this process only, not its children, and
    fires when the forking thread ends rather than the driver; not polling ``os.getppid()``: a
    period of delay."""
    owner = -os.getpid() if os.getpgrp() == os.getpid() else os.getpid()

    def end():
        if owner < 0:
            os.killpg(-owner, signal.SIGKILL)
        os.kill(os.getpid(), signal.SIGKILL)

    if hasattr(fcntl, "F_SETSIG"):
        fd = os.open(f"/proc/self/fd/{lifeline}", os.O_RDONLY | os.O_NONBLOCK)
        fcntl.fcntl(fd, fcntl.F_SETOWN, owner)
        fcntl.fcntl(fd, fcntl.F_SETSIG, signal.SIGKILL)
        fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) | os.O_ASYNC)
        try:
            gone = os.read(fd, 64) == b""     # the driver ended before the kernel watched for it
        except BlockingIOError:
            gone = False
        if gone:
            end()
        return

    def watch():
        try:
            while os.read(lifeline, 64):      # the driver writes nothing: b"" is its end
                pass
        except OSError:
            pass
        end()
    threading.Thread(target=watch, name="watch_driver", daemon=True).start()


def run_task(task: dict) -> int:
    """One run in this (fresh) process: parse, run ``repeat`` times, write the record."""
    record = {"key": task["key"], "problem": task["problem"], "label": task["label"], "status": FAILED,
              "metrics": {}, "started": now(), "repeat": task["repeat"], "python": platform.python_version(),
              "multiscale": multiscale.__version__, "code": code(), "cpus": os.cpu_count(), "rank": task["rank"],
              "asked": list(task["metrics"])}       # (``records.metric_problem``: a metric missing, asked, is no age)
    try:
        problem = get_problem(task["problem"])
        ctx = Context(directory=Path(task["directory"]))
        extra = {"scene": task["scene"], "ranks": task["ranks"]} if "scene" in task else {}
        params = problem.parse(task["raw"], "", ctx, **extra)
        if ctx.problems:
            raise SceneError(ctx.problems)
        record["params"] = problem.key(params)
        workdir = Path(task["workdir"])
        record["base_memory_mb"] = _peak_mb()
        jit = [0.0]                                  # s in numba's compiler (cache loads included)
        with event.install_timer("numba:compiler_lock", lambda dt: jit.__setitem__(0, jit[0] + dt)):
            timings = [_timed(problem, params, workdir)]
        runs = task["repeat"] + (jit[0] > JIT_SHARE * timings[0][0])     # the first one again
        timings += [_timed(problem, params, workdir) for _ in range(runs - 1)]
        times, cpus, outcome = [t[0] for t in timings], [t[1] for t in timings], timings[-1][2]
        best = int(np.argmin(times))
        record.update(wall_time=times[best], wall_times=times, cpu_time=cpus[best], jit_time=jit[0],
                      peak_memory_mb=_peak_mb(), iterations=int(outcome.iterations),
                      converged=bool(outcome.converged), warnings=list(outcome.warnings))
        record["metrics"] = {k: float(v) for k, v in outcome.metrics.items()}
        if task["exact"]:
            record["reference"] = _exact(problem, params, Path(task["references"]))
        why = metric_problem(record["metrics"], task["metrics"], problem.undefined, task["metrics"])
        record.update(ran=True, status=FAILED if why else "ok", error=why or "")
    except Exception as exc:       # recorded, never raised: the study goes on
        text = str(exc).strip().splitlines()
        named = "" if isinstance(exc, RunFailed) else f"{type(exc).__name__}: "     # (it names its own cause)
        record.update(status=FAILED, error=f"{named}{text[0] if text else ''}".strip(),
                      traceback=traceback.format_exc(), warnings=list(getattr(exc, "warnings", ())))
    record["finished"] = now()
    record.setdefault("peak_memory_mb", _peak_mb())
    write_json(Path(task["record"]), record)
    return 0


def _timed(problem, params, workdir) -> tuple:
    """(wall time [s], CPU time [s], outcome) of one run; the wall time is the outcome's own where
    it gives one (``Outcome.wall_time``)."""
    t0, c0 = time.perf_counter(), _cpu()
    outcome = problem.run(params, workdir)
    wall = time.perf_counter() - t0
    return outcome.wall_time if outcome.wall_time is not None else wall, _cpu() - c0, outcome


def _exact(problem, params, folder: Path) -> dict:
    """The problem's analytic reference, cached on disk by the parameters it depends on."""
    ident = json.dumps(problem.exact_key(params), sort_keys=True)
    path = folder / f"{problem.name}-{hashlib.sha256(ident.encode()).hexdigest()[:16]}.json"
    if path.is_file():
        return read_json(path)["values"]
    values = {k: float(v) for k, v in problem.exact(params).items()}
    folder.mkdir(parents=True, exist_ok=True)
    write_json(path, {"params": json.loads(ident), "values": values})
    return values


if __name__ == "__main__":
    if len(sys.argv) > 2:
        watch_driver(int(sys.argv[2]))
    sys.exit(run_task(json.loads(sys.argv[1])))

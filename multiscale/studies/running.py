"""Running a study: each run without a record in a fresh worker process (``python -m
multiscale.studies.worker``), ``[run] processes`` at a time, with timeouts; under ``mpiexec`` the
runs are shared out over the ranks. A crash or timeout becomes a failed record; a study ended by
SIGTERM or SIGHUP (a batch limit, ``timeout``, a closed terminal) kills its workers first. A
driver killed by SIGKILL (``kill -9``, the OOM killer, a scheduler's hard limit) can do nothing:
its workers notice it gone themselves, through a pipe only the driver writes to (``_lifeline``,
``worker.watch_driver``), and end with their process groups."""
from __future__ import annotations

import fcntl
import json
import os
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass

from tqdm import tqdm

from multiscale.errors import MultiscaleError
from multiscale.io import on_root
from multiscale.studies.expand import Study, StudyRun
from multiscale.studies.formatting import now, warning_kind
from multiscale.studies.records import FAILED, json_default, read_json, read_records, record_path, write_json

__all__ = ["ExecStats", "execute", "world"]


@dataclass
class ExecStats:
    """What ``execute`` did, over all ranks (under mpiexec rank 0 counted only its own runs)."""

    total: int            # runs in the study
    done: int             # already recorded, skipped
    started: int          # run now
    failed: int           # of those, failed
    wall_time: float      # s


def _child_env() -> dict:
    """The worker's environment: an MPI singleton (no launcher variables), one thread."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PMI_", "PMIX_", "HYDRA_", "OMPI_", "MPI_LOCAL", "MPIR_"))}
    env.setdefault("OMP_NUM_THREADS", "1")
    env.setdefault("MPLBACKEND", "Agg")
    return env


def world():
    """MPI.COMM_WORLD when launched by mpiexec with several ranks, else None (no MPI init)."""
    if not any(k in os.environ for k in ("PMI_SIZE", "PMI_RANK", "OMPI_COMM_WORLD_SIZE", "PMIX_RANK")):
        return None
    try:
        from mpi4py import MPI       # local: importing it initialises MPI, wanted only under mpiexec
    except ImportError:
        return None
    return MPI.COMM_WORLD if MPI.COMM_WORLD.size > 1 else None


def execute(study: Study, *, rerun_failed: bool = False, progress: bool = True, comm=None) -> ExecStats:
    """Run the study's runs that have no record (and failed ones with ``rerun_failed``), each in a
    fresh worker process, ``options.processes`` at a time; with ``comm``, runs are shared out
    round-robin over its ranks (collective)."""
    start = time.perf_counter()
    rank, size = (comm.rank, comm.size) if comm is not None else (0, 1)
    lock = _claim(study, comm)
    bar, failed, running, termination, lifeline, warned, said = None, 0, {}, None, None, False, set()
    try:                                     # the lock is released whatever happens from here
        records = read_records(study)
        todo = [r for r in study.runs if not _done(records.get(r.key), rerun_failed, study.options.timeout)]
        mine = todo[rank::size]
        if progress and rank == 0 and mine:      # under MPI the bar follows rank 0's share (it said 2/2 of 3)
            share = f" (rank 0's of {len(todo)})" if size > 1 else ""
            bar = tqdm(total=len(mine), desc=study.name + share, unit="run", disable=None)   # none into a file
            #                                          (its carriage returns filled a batch job's log: an MPI trial)
        queue = list(mine)
        termination = Termination()
        lifeline = _lifeline()
        while queue or running:
            while queue and len(running) < study.options.processes:
                run = queue.pop(0)
                with termination.deferred():
                    running[_spawn(study, run, rank, lifeline[0])] = (run, time.monotonic())
            time.sleep(0.05)
            for proc, (run, t0) in list(running.items()):
                timeout = study.options.timeout
                if proc.poll() is None and not (timeout and time.monotonic() - t0 > timeout):
                    continue
                if proc.poll() is None:
                    _kill(proc)
                    _failed_record(study, run, f"timed out after {timeout:g} s (run.timeout)", timed_out=timeout)
                elif proc.returncode != 0 or not record_path(study, run).is_file():
                    _failed_record(study, run, _crash_message(study, run, proc.returncode))
                del running[proc]
                record = read_json(record_path(study, run))
                failed += record.get("status") == FAILED
                if record.get("ran") and "did you mean" in record.get("error", "") and not warned:
                    warned = True        # a misspelt metric: said at the first run, not after the last
                    tqdm.write(f"warning: {study.name}: {record['error'].split('; available:')[0]}; every run "
                               "will lack it: stop (Ctrl-C), correct the study's metrics and start again (finished "
                               "runs are kept)", file=sys.stderr)
                for line in record.get("warnings", ()) if rank == 0 else ():   # (the others: in the report)
                    if warning_kind(line) not in said:    # each kind once, with the first run that found it
                        said.add(warning_kind(line))
                        tqdm.write(f"warning: {study.name}: run {run.text}: {line}", file=sys.stderr)
                log = study.folder / "runs" / f"{run.key}.log"
                if log.is_file() and not log.stat().st_size:
                    log.unlink()
                if bar is not None:
                    bar.update()
    finally:
        for proc in running:
            _kill(proc)
        for fd in lifeline or ():
            os.close(fd)
        if termination is not None:
            termination.restore()
        if lock is not None:
            lock.close()                     # releases the folder
        if bar is not None:
            bar.close()
    if comm is not None:
        failed = comm.allreduce(failed)
    return ExecStats(len(study.runs), len(study.runs) - len(todo), len(todo), failed, time.perf_counter() - start)


def _claim(study: Study, comm):
    """Create the study's ``runs/`` folder and hold its lock (rank 0; collective): a second study on
    the same folder at the same time is refused (it ran every run again beside the first, each
    deleting the other's records as it started them, with doubled wall times). Returns the open
    lock file (None on the other ranks); a folder that cannot be made is an OutputError on every
    rank (under mpiexec the other ranks waited for rank 0 for ever)."""
    held = []

    def claim():
        (study.folder / "runs").mkdir(parents=True, exist_ok=True)
        lock = open(study.folder / "runs" / ".lock", "a+")
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock.seek(0)
            owner = lock.read().strip()
            lock.close()
            return (f"{study.folder} is in use by another multiscale study (process {owner or '?'}): let it end, "
                    "then run this one (its finished runs are not run again), or give this one another [run] folder")
        lock.truncate(0)
        lock.write(str(os.getpid()))
        lock.flush()
        held.append(lock)
        return None
    busy = claim() if comm is None else comm.bcast(on_root(comm, claim, f"the study folder {study.folder}"), root=0)
    if busy:
        raise MultiscaleError(busy)
    return held[0] if held else None


class Termination:
    """SIGTERM and SIGHUP as a ``SystemExit(128 + signal)`` (so ``execute`` kills its workers, each
    in a session of its own, before the driver ends: they ran on, orphaned), held back while a
    worker is started and registered (``deferred``: a signal between the worker's exec and its
    registration left it running after the driver, until its watchdog noticed). A signal ignored
    when the study started stays ignored: ``nohup multiscale study`` outlives its terminal, workers
    and all. Off the main thread nothing is installed."""

    def __init__(self):
        self.holding, self.pending, self.previous = False, None, {}
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.signal(s, self._stop) for s in (signal.SIGTERM, signal.SIGHUP)
                             if signal.getsignal(s) is not signal.SIG_IGN}

    def _stop(self, signum, frame):
        if self.holding:
            self.pending = signum
        else:
            raise SystemExit(128 + signum)

    @contextmanager
    def deferred(self):
        """The block runs to its end; a signal that came meanwhile then ends the driver."""
        self.holding = True
        try:
            yield
        finally:
            self.holding = False
        if self.pending is not None:
            raise SystemExit(128 + self.pending)

    def restore(self) -> None:
        for signum, handler in self.previous.items():
            signal.signal(signum, handler)


def _lifeline() -> tuple[int, int]:
    """A pipe (read end, write end) whose read end every worker gets (``_spawn``) and whose write
    end only this process holds and never writes to: the kernel closes it when the driver ends,
    however it ends, and each worker's process group is then killed (``worker.watch_driver``: by
    the kernel on Linux, by a thread reading the end-of-file elsewhere). SIGKILL cannot be caught, so the driver cannot kill
    its workers then (they ran on, orphaned, each in a session of its own). Why a pipe: its
    end-of-file comes at once and cannot be missed, even when the driver died before the worker
    started watching; polling ``os.getppid()`` would wait a period and need the driver's pid;
    Linux's ``prctl(PR_SET_PDEATHSIG)`` signals the worker alone (not the ``mpiexec`` of a scene
    run in its group) and fires when the thread that forked it ends, not the process. Both ends
    are created non-inheritable (PEP 446): no other child of the driver holds the write end open
    (a ``fork`` without ``exec`` in the driver would, and delay the end-of-file until it ends)."""
    return os.pipe()


def _done(record, rerun_failed: bool, timeout: float | None) -> bool:
    """A run is done if it has a record, unless that failed and failed runs are retried, or it timed
    out under a shorter ``run.timeout`` than the study's ``timeout`` [s] now (None: none), raised to
    let it finish (it stayed failed). A record that completed is judged by the study's metrics when
    read (``records.read_records``)."""
    if record is None or record.get("status") != FAILED:
        return record is not None
    limit = record.get("timed_out")
    return not (rerun_failed or limit is not None and (timeout is None or timeout > limit))


def _spawn(study: Study, run: StudyRun, rank: int, lifeline: int) -> subprocess.Popen:
    """The run's worker, in a session (and process group) of its own, ``lifeline`` (the read end of
    ``_lifeline``) passed on to it."""
    workdir = study.folder / "runs" / run.key
    task = {"problem": study.problem, "raw": run.raw, "label": run.label, "key": run.key,
            "metrics": list(study.metrics), "repeat": study.options.repeat,
            "exact": study.reference is not None and study.reference.kind == "analytic",
            "record": str(record_path(study, run)), "workdir": str(workdir),
            "references": str(study.folder / "references"), "directory": str(study.source.parent), "rank": rank}
    if study.problem == "scene":
        task.update(scene=str(study.scene), ranks=study.options.ranks)
    record_path(study, run).unlink(missing_ok=True)          # a failed run being retried
    log = open(study.folder / "runs" / f"{run.key}.log", "w")
    try:
        return subprocess.Popen([sys.executable, "-m", "multiscale.studies.worker",
                                 json.dumps(task, default=json_default), str(lifeline)], pass_fds=(lifeline,),
                                stdout=log, stderr=subprocess.STDOUT, env=_child_env(), start_new_session=True)
    finally:
        log.close()


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.wait()


def _crash_message(study, run, code) -> str:
    log = study.folder / "runs" / f"{run.key}.log"
    lines = [line for line in (log.read_text(errors="replace").splitlines() if log.is_file() else []) if line.strip()]
    if code is not None and code < 0:
        name = signal.Signals(-code).name if -code in {s.value for s in signal.Signals} else str(-code)
        why = f"worker killed by {name}" + (" (out of memory?)" if -code == signal.SIGKILL else "")
    else:
        why = f"worker exited with code {code} without a record"
    return why + (f": {lines[-1].strip()}" if lines else "")


def _failed_record(study, run, message, **extra) -> None:
    write_json(record_path(study, run), {"key": run.key, "problem": study.problem, "label": run.label,
                                         "status": FAILED, "error": message, "metrics": {}, "finished": now(), **extra})

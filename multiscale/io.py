"""Scalar histories on disk, MPI-safe entry points, stage messages and progress bars (no DOLFINx).

``History`` collects one row of scalars per recorded step (units in ``UNITS``) and writes them as
datasets of ``history.h5`` (only rank 0 writes; its figure is ``multiscale.plots.history``).
Fields for ParaView are written by ``multiscale.macro.output``. ``Reporter`` prints one line per
stage of a run on rank 0 (``stage``, ``bar``) and keeps the wall time of every stage.
"""
from __future__ import annotations

import difflib
import os
import re
import signal
import sys
import threading
import time as _time
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
from mpi4py import MPI
from tqdm import tqdm

from multiscale.errors import MultiscaleError, OutputError
from multiscale.signals import TERMINATING

UNITS = {"time": "s", "force": "N", "pressure": "Pa", "temperature": "K", "heat": "J", "iterations": "-",
         "volume": "m^3", "depth": "m", "rms": "m", "work": "J", "area": "m^2", "moment": "N m", "wear_rate": "1/Pa",
         "coefficient": "-", "speed": "m/s", "angular_speed": "rad/s", "remaining": "m"}


def unit_of(name: str) -> str:
    """Unit of a history column from its name: the quantity word that comes first in it (e.g.
    max_temperature_pin -> K; max_temperature_pressure_plate -> K: a body's or interface's name
    follows the quantity, and a unit word in it does not count)."""
    found = [(name.find(word), unit) for word, unit in UNITS.items() if word in name]
    return min(found)[1] if found else "-"


def solver_statistic(name: str) -> bool:
    """Whether a history column describes the solver's path, not the state: wall times
    (``time_*``) and Newton iteration counts, which follow the factorisations a run kept (timed
    decisions, ``macro.mechanics``). Repeated or resumed runs agree on every other column to the
    solver tolerances (docs/architecture.md, "Repeatability")."""
    return name.startswith("time_") or name == "newton_iterations"


class History:
    """Time series: ``append(time=..., interface_force=..., ...)``, same keys every row; a value is a
    scalar, or a 1-D array of fixed length (a per-zone quantity: its column is (rows, length)).
    A column's unit is ``unit_of(name)``, as the file's ``unit`` attributes give it."""

    def __init__(self):
        self.columns: dict[str, list[float]] = {}

    def append(self, **row: float) -> None:
        """Add one row (every column of the first row, no other; KeyError otherwise)."""
        if self.columns and set(row) != set(self.columns):
            raise KeyError(f"history row keys {sorted(row)} differ from {sorted(self.columns)}")
        for key, value in row.items():
            self.columns.setdefault(key, []).append(float(value) if np.ndim(value) == 0
                                                    else np.array(value, dtype=float))

    def __getitem__(self, key: str) -> np.ndarray:
        if key not in self.columns:      # (an int key gave "KeyError: 0": a user trial)
            close = difflib.get_close_matches(str(key), list(self.columns), n=3)
            raise KeyError(f"no history column {key!r}" + (f"; did you mean {', '.join(map(repr, close))}?"
                                                           if close else f"; {len(self.columns)} columns, e.g. "
                                                           f"{', '.join(list(self.columns)[:3])}"))
        return np.asarray(self.columns[key])

    def __contains__(self, key) -> bool:
        """Whether ``key`` names a column (as a pandas DataFrame: ``in`` and iteration go over the
        columns, ``len`` counts the rows)."""
        return key in self.columns

    def __iter__(self):
        return iter(self.columns)

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()), []))

    def write(self, path: Path, attrs: dict | None = None) -> Path:
        """Write every column as a dataset (attribute ``unit``) of an HDF5 file, replacing ``path``
        at once (written beside it first: a run killed while writing leaves the previous file)."""
        with replacing(path) as part, h5py.File(part, "w") as f:
            for key, values in self.columns.items():
                f.create_dataset(key, data=np.asarray(values)).attrs["unit"] = unit_of(key)
            for key, value in (attrs or {}).items():
                f.attrs[key] = value
        return Path(path)

    @classmethod
    def read(cls, path: Path) -> "History":
        """The history written by ``write`` to ``path``."""
        h = cls()
        with h5py.File(path, "r") as f:
            h.columns = {key: list(f[key][...]) for key in f.keys()}
        return h


@contextmanager
def replacing(path: Path):
    """``with replacing(path) as part:`` write the new ``path`` into ``part`` (``<name>.part``
    beside it), which then replaces ``path`` at once: a run killed while writing leaves the
    previous file and the part (``--overwrite`` clears it, ``provenance.results_of``); a write or
    a replacement that fails deletes the part and leaves the previous file."""
    path = Path(path)
    part = path.with_name(path.name + ".part")
    try:
        yield part
        os.replace(part, path)
    except BaseException:
        part.unlink(missing_ok=True)
        raise


def on_root(comm, write, what: str):
    """Run ``write()`` on rank 0 only (a file every rank needs written once) and make its failure
    collective: an ``OSError`` there (disk full, read-only folder) raises ``OutputError`` naming
    ``what`` on every rank, instead of leaving the others waiting (``on_ranks`` with one job).
    Returns ``write()``'s value on rank 0, None elsewhere."""
    value = []
    on_ranks(comm, [lambda: value.append(write())], what)
    return value[0] if value else None


def reason(exc: OSError) -> str:
    """An ``OSError``'s reason in a line: the system's, also out of HDF5's long text (h5py: "Can't close
    file (file write failed: time = ..., errno = 28, error message = 'No space left on device', ...)",
    which a full disk printed over two lines: an MPI review)."""
    text = exc.strerror or str(exc)
    found = re.search(r"error message = '([^']*)'", text)
    return found.group(1) if found else " ".join(text.split())


def on_ranks(comm, jobs, what: str) -> None:
    """Run the callables ``jobs`` spread over the ranks (job k on rank k mod size: files any rank
    can write alone, e.g. figures from data every rank holds) and make a failure collective: an
    ``OSError`` on any rank raises ``OutputError`` naming ``what`` on every rank."""
    failure = None
    for job in jobs[comm.rank::comm.size]:
        try:
            job()
        except OSError as exc:
            failure = f"cannot write {what}: {reason(exc)}"
            break
    failures = [f for f in comm.allgather(failure) if f]
    if failures:
        raise OutputError(failures[0])


def collective(comm, call):
    """``call()`` on every rank of ``comm`` (e.g. a rank's share of the zones); a ``MultiscaleError`` met
    by any rank is raised on every rank (the rank that met it raises its own, the others a
    ``MultiscaleError`` with its message), so that no rank waits for another in the next exchange."""
    try:
        value, failure = call(), None
    except MultiscaleError as exc:
        value, failure = None, exc
    failed = [(rank, message) for rank, message in enumerate(comm.allgather(None if failure is None else str(failure)))
              if message is not None]
    if failure is not None:
        raise failure
    if failed:
        rank, message = failed[0]
        raise MultiscaleError(f"on rank {rank}: {message}")
    return value


def counted(n: int, noun: str) -> str:
    """"1 record", "2 records": ``n`` and the noun, plural unless n is 1."""
    return f"{n} {noun}{'s' * (n != 1)}"


class Outliving:
    """A text stream (stdout, stderr) that outlives its reader: the first write or flush into a
    closed pipe (BrokenPipeError) sends it, and its file descriptor, to /dev/null, and the run
    goes on to write its results. A run piped into ``head`` or ``less`` was aborted by PETSc's
    SIGPIPE handler, its files half written; ended alone, rank 0 would leave the others waiting.
    A closed descriptor (``run >&-``: Python's stream is None) is /dev/null from the start (the
    stage lines ended such a run at once)."""

    def __init__(self, stream):
        self.stream = stream if stream is not None else open(os.devnull, "w")

    def write(self, text: str) -> int:
        try:
            return self.stream.write(text)
        except BrokenPipeError:
            self._silence()
            return len(text)

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            self._silence()

    def _silence(self) -> None:
        void = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(void, self.stream.fileno())     # its unflushed buffer, and C's writes, go there too
        except (OSError, ValueError):               # (a stream without a descriptor)
            pass
        finally:
            os.close(void)
        self.stream = open(os.devnull, "w")

    def __getattr__(self, name):
        return getattr(self.stream, name)


class StepStop:
    """Ctrl-C in a loop of steps (a context manager). The first SIGINT asks the loop to stop after
    its current step, when ``requested()`` (every rank together: one stops, all stop, at the same
    step) is True. The second is held: the step ends and its results are written. A third abandons
    the step in progress (``KeyboardInterrupt`` naming the last step whose results are written),
    unless it comes inside ``writing()``, which no Ctrl-C interrupts: a step's results are written
    whole or not at all (after the last step, ``writing(last=True)``: the run finishes). ``done``:
    the steps whose results are already written (a resumed run's).
    Under ``mpiexec`` the second Ctrl-C is the launcher's: it kills every rank (MPICH's hydra).
    SIGTERM and SIGHUP (a batch scheduler's time limit, ``timeout``, a closed terminal; unless
    ignored, as under ``nohup``) count as Ctrl-Cs: the first stops the run after its step (they
    killed it, its provenance left "running"). Without the main thread, nothing is installed."""

    SIGNALS = (signal.SIGINT, *TERMINATING)
    FIRST = "\n{}: stopping after this step, with its results written ({})\n"
    AGAIN = {1: "Ctrl-C again is mpiexec's: it kills the job at once",
             0: "{} twice more abandons the step"}
    HELD = ("\n{0}: still finishing the step and writing its results; {0} again abandons the step "
            "(the results written stay as they are)\n")
    WRITING = "\n{}: held until the results being written are complete\n"
    LAST = "\n{}: the steps are done; held until their results are written (the run finishes)\n"
    taken = 0        # signals every StepStop of this process took (``CtrlCWatch`` counts them)

    def __init__(self, comm, done: int = 0):
        self.comm, self.done, self.previous = comm, done, None
        self.count, self.saving, self.last = 0, False, False

    @property
    def asked(self) -> bool:
        """Whether this rank was sent Ctrl-C."""
        return self.count > 0

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.signal(s, self._handle) for s in self.SIGNALS
                             if s == signal.SIGINT or signal.getsignal(s) is not signal.SIG_IGN}
        return self

    def __exit__(self, *exc):
        for s, handler in (self.previous or {}).items():
            signal.signal(s, handler)
        return False

    def _handle(self, signum, frame):
        self.count += 1
        StepStop.taken += 1
        if self.count > 2 and not self.saving:
            raise KeyboardInterrupt(f"during step {self.done + 1}, abandoned: the results of step {self.done} "
                                    "are the last written")
        if self.comm.rank == 0:          # os.write, not print: the handler may run inside a write to stderr
            name = "Ctrl-C" if signum == signal.SIGINT else signal.Signals(signum).name
            again = self.AGAIN[self.comm.size > 1 and signum == signal.SIGINT].format(name)
            os.write(2, (self.LAST.format(name) if self.last else    # (it said "stopping after this step")
                         self.FIRST.format(name, again) if self.count == 1 else    # (a SIGTERM was called
                         self.HELD.format(name) if self.count == 2 else self.WRITING.format(name)).encode())  # Ctrl-C)

    @contextmanager
    def writing(self, step: int, last: bool = False):
        """The block writing the results of ``step``: Ctrl-C does not interrupt it; once it ends,
        they are the last written (``done``). ``last``: the run's final writing, after its steps."""
        self.saving, self.last = True, last
        try:
            yield
        finally:
            self.saving = False
        self.done = step

    def requested(self) -> bool:
        """Whether any rank was asked to stop (collective)."""
        return bool(self.comm.allreduce(self.asked, op=MPI.LOR))


@contextmanager
def holding_ctrl_c(what: str):
    """A block that one Ctrl-C (SIGINT) does not interrupt: it is said on stderr (``what``: what is
    being written) and the block goes on; another one abandons it (``KeyboardInterrupt``). Without
    the main thread, nothing is installed."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    count = [0]

    def hold(signum, frame):
        count[0] += 1
        if count[0] > 1:
            raise KeyboardInterrupt(f"abandoned while writing {what}")
        os.write(2, f"\nCtrl-C: still writing {what}; Ctrl-C again abandons it\n".encode())
    previous = signal.signal(signal.SIGINT, hold)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def ended_together(comm, timeout: float = 10.0) -> bool:
    """Called by a rank that met an error: True if every rank of ``comm`` reaches this call within
    ``timeout`` [s] (the error was collective: each can end cleanly), False if not (another rank is
    waiting in a collective operation that will never complete: the caller must abort the job)."""
    if comm.size == 1:
        return True
    request, start = comm.Ibarrier(), _time.monotonic()
    while not request.Test():
        if _time.monotonic() - start > timeout:
            return False
        _time.sleep(0.01)
    return True


def abort(comm, code: int, grace: float = 1.0, quiet: bool = False) -> None:
    """End every rank of the job from this one, ``grace`` [s] after flushing its output: mpiexec
    (MPICH's hydra) forwards a rank's stdout/stderr asynchronously and an immediate abort can kill
    the forwarder first, losing the rank's last message (1 in 6 and 1 in 20 runs of
    tests/test_faults.py on a loaded 2-core machine). ``quiet``: without MPICH's own line
    ("Abort(code) on node 0 ... application called MPI_Abort"), this rank's stderr closed before."""
    sys.stdout.flush()
    sys.stderr.flush()
    if comm.size == 1:          # no other rank: MPI_Abort from the watcher thread while the main thread was
        os._exit(code)          # inside gmsh ended in a segmentation fault (6 of 9 Ctrl-Cs, a user trial)
    _time.sleep(grace)
    if quiet:
        os.dup2(os.open(os.devnull, os.O_WRONLY), 2)
    comm.Abort(code)


def _terminated(signum, frame):
    """SIGTERM or SIGHUP outside a loop of steps (``CtrlCWatch``): a Ctrl-C that names it."""
    raise KeyboardInterrupt(f"by {signal.Signals(signum).name}")


class CtrlCWatch:
    """Ctrl-C outside a loop of steps, whatever each rank is doing (a context manager; the cli's).
    Python meets a SIGINT only between bytecodes of the main thread: a rank inside a long C call
    (gmsh meshing, a factorisation) or waiting in a collective operation for a rank that already
    left meets it late or never, while the ranks that left wait for it. This thread wakes at the
    signal itself (``signal.set_wakeup_fd``); if the main thread has not met the interrupt
    (``end``) within ``WAIT`` [s] (plus ``STAGGER`` [s] per rank: rank 0 first, the others only if
    it cannot), it prints ``line()`` and ends every rank with ``code`` (``abort``, quiet). SIGTERM
    and SIGHUP (a scheduler's time limit, a closed terminal) are Ctrl-Cs too, ``KeyboardInterrupt``
    "by SIGTERM" (before, outside the steps they ended the process without a word, its provenance
    left "running"); ignored ones (``nohup``) stay ignored. Signals the watch's handlers do not
    take (``StepStop``'s, an ignored SIGINT) are left alone: those a
    ``StepStop`` took are counted (``StepStop.taken``), since the watcher may read a signal's byte
    after the ``StepStop`` that took it put the default handler back (it then aborted a run while
    its end was written: provenance.json left "running", no open_in_paraview.py; 1 in 6 quick Ctrl-Cs)."""

    WAIT, STAGGER = 1.0, 2.5

    def __init__(self, comm, line, code: int):
        self.comm, self.line, self.code = comm, line, code
        self.taken, self.pipe, self.previous, self.watcher = threading.Event(), None, None, None
        self.lock, self.ending, self.ended = threading.Lock(), False, {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self.ended = {s: signal.signal(s, _terminated) for s in TERMINATING
                          if signal.getsignal(s) is not signal.SIG_IGN}
            self.pipe = os.pipe()
            os.set_blocking(self.pipe[1], False)
            self.previous = signal.set_wakeup_fd(self.pipe[1], warn_on_full_buffer=False)
            self.watcher = threading.Thread(target=self._watch, args=(self.pipe[0],), daemon=True)
            self.watcher.start()
        return self

    def __exit__(self, *exc):
        if self.pipe is not None:
            for s, handler in self.ended.items():
                signal.signal(s, handler)
            signal.set_wakeup_fd(self.previous)
            self.taken.set()
            os.close(self.pipe[1])            # the watcher reads the end of the pipe and stops
        return False

    def end(self, line: str) -> None:
        """The main thread met the interrupt: rank 0 prints ``line`` once every rank has met it;
        if one has not within ``WAIT`` (+ ``STAGGER`` per rank: it is inside a C call or a
        collective operation the interrupt cannot reach), rank 0, or the next rank if rank 0 is
        that one, prints it and ends every rank. If the watcher is already ending the job, it
        waits for it."""
        with self.lock:
            self.taken.set()
        if self.ending:
            self.watcher.join()               # its abort ends this process
        if ended_together(self.comm, self.WAIT + self.STAGGER * self.comm.rank):
            if self.comm.rank == 0:
                print(line, file=sys.stderr, flush=True)
            return
        print(line, file=sys.stderr, flush=True)
        abort(self.comm, self.code, quiet=True)

    def _watch(self, fd: int) -> None:
        seen, ours = 0, StepStop.taken          # signals read here; those StepStops took before
        handlers = {signal.SIGINT: signal.default_int_handler, **{s: _terminated for s in self.ended}}
        try:
            while (data := os.read(fd, 64)) and not self.taken.is_set():
                seen += sum(data.count(s) for s in handlers)
                if any(s in data and signal.getsignal(s) is h for s, h in handlers.items()):
                    end = _time.monotonic() + self.WAIT + self.STAGGER * self.comm.rank
                    while not self.taken.wait(0.01) and StepStop.taken - ours < seen and _time.monotonic() < end:
                        pass
                    with self.lock:
                        self.ending = not self.taken.is_set() and StepStop.taken - ours < seen
                    if self.ending:
                        print(self.line(), file=sys.stderr, flush=True)
                        abort(self.comm, self.code, quiet=True)
        finally:
            os.close(fd)


def abort_on_exception(comm=None) -> None:
    """Make an uncaught exception on one MPI rank abort every rank (instead of a hang)."""
    comm = comm or MPI.COMM_WORLD
    if comm.size == 1 or getattr(sys.excepthook, "_multiscale_abort", False):
        return
    previous = sys.excepthook

    def hook(kind, value, tb):
        previous(kind, value, tb)
        abort(comm, 1)

    hook._multiscale_abort = True
    sys.excepthook = hook


def progress(iterable, comm, **kwargs):
    """tqdm progress bar on rank 0, the plain iterable elsewhere."""
    if comm.rank != 0:
        return iterable
    return tqdm(iterable, **kwargs)


# ------------------------------------------------------------------ stages and progress
_ACTIVE: list["Reporter"] = []


class Reporter:
    """Stage messages of a run: one line per stage on rank 0 (under a terminal the line shows the
    running stage, its progress bar, then its wall time), nothing with ``quiet``. ``times`` holds
    the wall time [s] of every stage (summed over repeats), for the provenance of the results.
    Used as a context manager, it is the one that ``stage`` and ``bar`` report to. Its ``warn`` lines
    go to stderr on rank 0, with ``quiet`` too, unless ``warn`` is false, and into ``said`` (every
    rank's own) whatever ``warn``."""

    def __init__(self, comm=None, quiet: bool = False, stream=None, warn: bool = True):
        self.comm = comm or MPI.COMM_WORLD
        self.stream = stream or sys.stdout
        self.show = not quiet and self.comm.rank == 0
        self.warns = warn and self.comm.rank == 0
        self.said: list[str] = []  # the warn lines, in order
        self.tty = self.show and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.times: dict[str, float] = {}
        self.depth = 0            # nested stages are timed, not printed
        self.folder = None        # the results folder, once prepared
        self.barred = False       # a bar is showing: inner bars stay silent

    def __enter__(self):
        _ACTIVE.append(self)
        return self

    def __exit__(self, *exc):
        _ACTIVE.remove(self)
        return False

    def say(self, text: str) -> None:
        """A message line on rank 0 (not with ``quiet``)."""
        if self.show:
            print(text, file=self.stream, flush=True)

    def warn(self, line: str, keep: bool = True) -> None:
        """"warning: ``line``" on stderr (rank 0; not with ``warn`` false), kept in ``said`` while this
        reporter is active unless ``keep`` is false (a line that the end of the run says again; the
        silent reporter of no run keeps nothing)."""
        if keep and self in _ACTIVE:
            self.said.append(line)
        if self.warns:
            print(f"warning: {line}", file=sys.stderr, flush=True)

    @contextmanager
    def stage(self, name: str):
        top = self.depth == 0
        if top and self.tty:
            self.stream.write(f"{name} ...")
            self.stream.flush()
        self.depth += 1
        start, ended = _time.perf_counter(), "stopped after "    # (an error or Ctrl-C inside: not as if done)
        try:
            yield self
            ended = ""
        finally:
            seconds = _time.perf_counter() - start
            self.depth -= 1
            self.times[name] = self.times.get(name, 0.0) + seconds
            if top and self.show:
                clear = "\r\033[K" if self.tty else ""
                self.stream.write(f"{clear}{name}: {ended}{seconds:.1f} s\n")
                self.stream.flush()

    def bar(self, iterable, name: str, total: int | None = None, initial: int = 0, unit: str = "step"):
        """``iterable`` with a progress bar under a terminal, otherwise a line per tenth on rank 0
        counting ``unit``s with the time so far and the time left at the mean rate so far, after the
        first unit once there are more ("  zone laws: 3/25 batches, 1.2 s, ~9 s left"; a first
        macro step 4.5 times the later ones put 4 min 18 s left where 155 s were, a long-run trial)."""
        if not self.show or self.barred:
            yield from iterable
            return
        total = total if total is not None else (len(iterable) if hasattr(iterable, "__len__") else None)
        self.barred = True
        try:
            if self.tty:
                with tqdm(iterable, desc=name, total=total, initial=initial, unit=unit, leave=False,
                          file=self.stream, dynamic_ncols=True) as items:
                    yield from items
                return
            start, done, every = _time.perf_counter(), initial, max(1, (total or 10) // 10)
            units = unit + ("es" if unit.endswith(("s", "x", "ch", "sh")) else "s")
            first = None                      # s, the end of the first unit
            for item in iterable:
                yield item
                done += 1
                first = _time.perf_counter() - start if first is None else first
                if done % every == 0 or done == total:
                    elapsed = _time.perf_counter() - start
                    rate = (elapsed - first) / (done - initial - 1) if done - initial > 1 else elapsed
                    left = f", ~{duration(rate * (total - done))} left" if total and initial < done < total else ""
                    self.stream.write(f"  {name}: {done}/{total if total else '?'} {units}, {elapsed:.1f} s{left}\n")
                    self.stream.flush()
        finally:
            self.barred = False


def duration(seconds: float) -> str:
    """A time for people: "0.4 s", "35 s", "4 min 10 s", "2 h 05 min"."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    s = int(round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


_SILENT = Reporter(MPI.COMM_SELF, quiet=True)      # (its warnings are printed)


def reporter() -> Reporter:
    """The active ``Reporter`` (innermost ``with Reporter(...)``), else a silent one."""
    return _ACTIVE[-1] if _ACTIVE else _SILENT


def stage(name: str):
    """``with stage("meshing"): ...``: a stage of the active reporter (timed; one line on rank 0)."""
    return reporter().stage(name)


def bar(iterable, name: str, **kwargs):
    """``iterable`` with the active reporter's progress bar (see ``Reporter.bar``)."""
    return reporter().bar(iterable, name, **kwargs)

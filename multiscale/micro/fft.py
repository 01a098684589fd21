"""Real 2-D FFTs over the last two axes, with plans built once and reused.

pyfftw (FFTW) is used when importable, scipy.fft otherwise. The thread count is global:
``set_threads(n)`` or the environment variable ``MULTISCALE_THREADS`` (default 1, which is
what you want under MPI with one rank per core); a plan may also be given its own count.

Every transform is counted (``fft_counts``, ``reset_fft_counts``): benchmarks report the cost of
an iteration in FFT pairs measured, not guessed. Plans are double precision unless made with
``single=True`` (float32/complex64 buffers, counted apart): 0.42-0.79x the time of a double pair
at 512²-2048² on this machine (no gain at 256² and below), for work whose rounding does not
reach the result, such as applying a preconditioner. Zero-padded fields (isolated patches) may
skip the transforms of their zero rows (``RealFFT2``'s ``rows``).

Plans are measured (FFTW_MEASURE: 1.15-1.63x faster transforms than FFTW_ESTIMATE's on this
machine, benchmarks/README) and their wisdom is kept in a file (``wisdom_file``) that every
process reads: a shape is measured once per machine, under a file lock, and every later process,
MPI rank and run uses the same plan, hence rounds alike (measured anew in each process, two runs
could differ by 1e-7 when a solve near its tolerance took one iteration more).
"""
from __future__ import annotations

import os
import threading
import warnings
import weakref
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import scipy.fft

from multiscale.errors import check_count

try:  # pragma: no cover - POSIX only: without it, plans are measured in every process
    import fcntl
except ImportError:  # pragma: no cover
    fcntl = None
try:  # pragma: no cover - depends on the installation
    import pyfftw

except ImportError:  # pragma: no cover
    pyfftw = None


def _environment_threads() -> int:
    """Threads from ``MULTISCALE_THREADS``: a whole number >= 1, else 1 with a warning (it was a
    raw ValueError at import for "abc", and 0 or -3 were 1 unsaid: a user trial)."""
    text = os.environ.get("MULTISCALE_THREADS", "1")
    if text.strip().isdecimal() and int(text) >= 1:
        return int(text)
    warnings.warn(f"MULTISCALE_THREADS = {text!r} is not a whole number of threads >= 1: FFTs take 1 thread",
                  stacklevel=2)
    return 1


_threads = _environment_threads()
_plans: weakref.WeakSet = weakref.WeakSet()   # every RealFFT2 alive: they count their transforms
_retired: dict = {}                            # (grid, single) -> [forward, inverse] of the plans collected since
_planning = threading.Lock()                   # FFTW's planner is not thread-safe


def set_threads(n: int) -> None:
    """Threads used by FFT plans created from now on."""
    global _threads
    _threads = check_count("n", n)


def get_threads() -> int:
    return _threads


def fft_counts(single: bool = False) -> dict[tuple[int, int], tuple[int, int]]:
    """Transforms of one precision done since the last reset: {(ny, nx): (forward, inverse)},
    one per 2-D grid (a batch of B patches counts B)."""
    totals = {g: list(v) for (g, one), v in _retired.items() if one == single}
    for plan in list(_plans):
        if plan.single == single:
            t = totals.setdefault(plan.shape[-2:], [0, 0])
            t[0] += plan.counts[0] * plan.batch
            t[1] += plan.counts[1] * plan.batch
    return {g: (f, i) for g, (f, i) in sorted(totals.items()) if f or i}


def reset_fft_counts() -> None:
    _retired.clear()
    for plan in list(_plans):
        plan.counts[:] = [0, 0]


def fft_pairs(grid: tuple[int, int], single: bool = False) -> float:
    """Transforms of one precision since the last reset in pairs (one forward + one inverse) of
    an rfft2 on ``grid``, each transform weighted by its number of cells (a zero-padded 2N x 2N
    pair counts 4)."""
    cells = grid[0] * grid[1]
    return sum((f + i) / 2 * (g[0] * g[1]) / cells for g, (f, i) in fft_counts(single).items())


def wisdom_file() -> Path | None:
    """Where FFTW wisdom is kept: ``$MULTISCALE_FFTW_WISDOM`` (empty: nowhere, plans are measured
    in every process), else ``$XDG_CACHE_HOME`` or ``~/.cache``, ``multiscale/fftw-wisdom``."""
    value = os.environ.get("MULTISCALE_FFTW_WISDOM")
    if value is not None:
        return Path(value).expanduser() if value else None
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "multiscale" / "fftw-wisdom"


@contextmanager
def _locked_wisdom():
    """Hold the wisdom file's lock with its wisdom imported; yield the file, or None when it cannot
    be used (no such place, unwritable, no fcntl): then the plans are measured in this process."""
    path, lock = wisdom_file(), None
    if path is not None and fcntl is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            lock = open(path.with_name(path.name + ".lock"), "a")
        except OSError:
            pass
    if lock is None:
        yield None
        return
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            pyfftw.import_wisdom(_wisdom_parts(path.read_bytes()))
        except OSError:
            pass
        yield path


def _wisdom_parts(data: bytes) -> tuple[bytes, bytes, bytes]:
    """The double, single and long double wisdom in a wisdom file's bytes (NUL-separated, as
    written by ``_measured``; FFTW's wisdom is text; a file of double wisdom only is read too)."""
    parts = data.split(b"\0")[:3]
    return tuple(parts + [b""] * (3 - len(parts)))


def _measured(transforms, threads):
    """FFTW plans of ``transforms`` ((input, output, axes, direction) each) from wisdom, measured
    (and stored) if there is none."""
    def make(flags):
        return [pyfftw.FFTW(a, b, axes=axes, direction=f"FFTW_{d}", flags=flags, threads=threads)
                for a, b, axes, d in transforms]

    def known():
        try:
            return make(("FFTW_MEASURE", "FFTW_WISDOM_ONLY"))
        except RuntimeError:
            return None

    with _planning:
        plans = known()
        if plans is not None:
            return plans
        with _locked_wisdom() as path:                   # new here: another process's, or measure it
            plans = known()
            if plans is not None:
                return plans
            plans = make(("FFTW_MEASURE",))
            if path is not None:
                try:
                    part = path.with_name(f"{path.name}.{os.getpid()}")
                    part.write_bytes(b"\0".join(pyfftw.export_wisdom()))
                    os.replace(part, path)
                except OSError:
                    pass
            return plans


def _retire(key, batch, counts) -> None:
    t = _retired.setdefault(key, [0, 0])
    t[0] += counts[0] * batch
    t[1] += counts[1] * batch


class RealFFT2:
    """Real 2-D FFT pair over the last two axes of arrays of one fixed shape ``(..., ny, nx)``.

    Three aligned buffers: real ``input``, complex ``spectrum`` (rfft2 of input, overwritten by
    ``inverse``) and real ``output``; the methods return views of them that the next call
    overwrites. Plans are built once with ``threads`` (default: ``get_threads()``), measured or
    from the shared wisdom (module docstring); ``single``: float32/complex64 buffers and plans.

    ``rows`` (zero-padded fields, e.g. a patch of ny < Fy rows): ``forward`` reads only the first
    ``rows`` rows of ``input`` (the others count as zero) and ``inverse`` writes only those of
    ``output`` (the others keep what they held: zero from the start). The pair is then split into
    passes over rows and columns and skips the row transforms of the zero rows: 0.69-0.83x the
    time of the full pair for ``rows`` = Fy / 2 (benchmarks/README), and the same result to
    round-off (the scipy fallback transforms the whole grid).
    """

    def __init__(self, shape: tuple[int, ...], threads: int | None = None, single: bool = False,
                 rows: int | None = None):
        self.shape = tuple(int(s) for s in shape)
        self.spectral_shape = self.shape[:-1] + (self.shape[-1] // 2 + 1,)
        self.size = self.shape[-1] * self.shape[-2]
        self.threads = _threads if threads is None else max(1, int(threads))
        self.batch = int(np.prod(self.shape[:-2], dtype=int))
        self.single = bool(single)
        self.rows = None if rows is None or rows >= self.shape[-2] else check_count("rows", rows)
        self.counts = [0, 0]                   # forward, inverse transforms since ``reset_fft_counts``
        _plans.add(self)
        weakref.finalize(self, _retire, (self.shape[-2:], self.single), self.batch, self.counts)
        real, complex_ = (np.float32, np.complex64) if self.single else (np.float64, np.complex128)
        if pyfftw is not None:
            self.input = pyfftw.empty_aligned(self.shape, dtype=real)
            self.spectrum = pyfftw.empty_aligned(self.spectral_shape, dtype=complex_)
            self.output = pyfftw.empty_aligned(self.shape, dtype=real)
            if self.rows is None:
                self._fwd, self._inv = _measured([(self.input, self.spectrum, (-2, -1), "FORWARD"),
                                                  (self.spectrum, self.output, (-2, -1), "BACKWARD")], self.threads)
            else:
                self._fwd, self._inv = self._split()
        else:  # pragma: no cover
            self.input, self.output = np.empty(self.shape, dtype=real), np.empty(self.shape, dtype=real)
            self.spectrum = np.empty(self.spectral_shape, dtype=complex_)
            self._fwd = self._inv = None
        self.input[...] = 0.0   # planning scribbles on the buffers
        self.output[...] = 0.0  # (with ``rows``, the other rows of the output are never written)

    def _split(self):
        """The pair in passes (``rows``): forward the r2c of the first rows, zero spectra for the
        others, the c2c of the columns in place; back the columns' c2c in place, the rows' c2r."""
        n, S = self.rows, self.spectrum
        row_pass, column_pass, column_back, row_back = _measured(
            [(self.input[..., :n, :], S[..., :n, :], (-1,), "FORWARD"), (S, S, (-2,), "FORWARD"),
             (S, S, (-2,), "BACKWARD"), (S[..., :n, :], self.output[..., :n, :], (-1,), "BACKWARD")], self.threads)

        def forward():
            row_pass()
            S[..., n:, :] = 0.0
            column_pass()

        def inverse(normalise_idft=True):
            column_back(normalise_idft=normalise_idft)
            row_back(normalise_idft=normalise_idft)
        return forward, inverse

    def forward(self, x: np.ndarray | None = None) -> np.ndarray:
        """``spectrum = rfft2(input)`` (after copying ``x`` into ``input`` if given)."""
        if x is not None:
            self.input[...] = x
        self.counts[0] += 1
        if self._fwd is not None:
            self._fwd()
        else:  # pragma: no cover
            self.spectrum[...] = scipy.fft.rfft2(self.input, workers=self.threads)
        return self.spectrum

    def inverse(self, X: np.ndarray | None = None, normalise: bool = True) -> np.ndarray:
        """``output = irfft2(spectrum)`` (after copying ``X`` into ``spectrum`` if given).

        ``normalise=False`` skips the 1/(ny nx) factor (fold it into a multiplier instead)."""
        if X is not None:
            self.spectrum[...] = X
        self.counts[1] += 1
        if self._inv is not None:
            self._inv(normalise_idft=normalise)
        else:  # pragma: no cover
            self.output[...] = scipy.fft.irfft2(self.spectrum, s=self.shape[-2:], workers=self.threads)
            if not normalise:
                self.output *= self.size
        return self.output

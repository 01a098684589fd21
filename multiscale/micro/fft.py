"""Real 2-D FFTs over the last two axes, with plans built once and reused.

pyfftw (FFTW) is used when importable, scipy.fft otherwise. The thread count is global:
``set_threads(n)`` or the environment variable ``MULTISCALE_THREADS`` (default 1, which is
what you want under MPI with one rank per core).
"""
from __future__ import annotations

import os

import numpy as np

try:  # pragma: no cover - depends on the installation
    import pyfftw

    pyfftw.interfaces.cache.enable()
except ImportError:  # pragma: no cover
    pyfftw = None

_threads = max(1, int(os.environ.get("MULTISCALE_THREADS", "1")))


def set_threads(n: int) -> None:
    """Threads used by FFT plans created from now on."""
    global _threads
    _threads = max(1, int(n))


def get_threads() -> int:
    return _threads


class RealFFT2:
    """Forward and inverse real FFT of arrays of one fixed shape ``(..., ny, nx)``.

    ``forward(x)`` and ``inverse(X)`` return views of internal buffers that the next call of the
    same method overwrites; copy what must outlive it.
    """

    def __init__(self, shape: tuple[int, ...]):
        self.shape = tuple(int(s) for s in shape)
        self.spectral_shape = self.shape[:-1] + (self.shape[-1] // 2 + 1,)
        self.threads = _threads
        if pyfftw is not None:
            rin = pyfftw.empty_aligned(self.shape, dtype="float64")
            cout = pyfftw.empty_aligned(self.spectral_shape, dtype="complex128")
            cin = pyfftw.empty_aligned(self.spectral_shape, dtype="complex128")
            rout = pyfftw.empty_aligned(self.shape, dtype="float64")
            flags = ("FFTW_MEASURE",)
            self._fwd = pyfftw.FFTW(rin, cout, axes=(-2, -1), direction="FFTW_FORWARD",
                                    flags=flags, threads=self.threads)
            self._inv = pyfftw.FFTW(cin, rout, axes=(-2, -1), direction="FFTW_BACKWARD",
                                    flags=flags, threads=self.threads)
            rin[...] = 0.0
        else:  # pragma: no cover
            self._fwd = self._inv = None
            self._rin = np.zeros(self.shape)

    @property
    def input(self) -> np.ndarray:
        """Real input buffer of ``forward`` (write into it, then call ``forward()``)."""
        return self._fwd.input_array if self._fwd is not None else self._rin

    def forward(self, x: np.ndarray | None = None) -> np.ndarray:
        """rfft2 of ``x`` (or of the current input buffer when ``x`` is None)."""
        if x is not None:
            self.input[...] = x
        if self._fwd is not None:
            return self._fwd()
        import scipy.fft  # pragma: no cover
        return scipy.fft.rfft2(self._rin, workers=self.threads)  # pragma: no cover

    def inverse(self, X: np.ndarray) -> np.ndarray:
        """irfft2 of ``X`` (normalised so that inverse(forward(x)) == x)."""
        if self._inv is not None:
            self._inv.input_array[...] = X
            return self._inv(normalise_idft=True)
        import scipy.fft  # pragma: no cover
        return scipy.fft.irfft2(X, s=self.shape[-2:], workers=self.threads)  # pragma: no cover

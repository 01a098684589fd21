"""FFTW_ESTIMATE against FFTW_MEASURE plans, and single against double precision: planning time
and time per rfft2 + irfft2 pair.

``multiscale.micro.fft`` measures its plans (FFTW_MEASURE) once per machine and shares the wisdom
through a file; this script shows what that buys over FFTW_ESTIMATE, and what a float32 pair (the
contact solver's two pairs from 512², ``bccg_solver.SINGLE_FROM``) costs against a double one. Medians of 5 repeats per
size, the two flags side by side, one thread. Last, on zero-padded fields (isolated patches): the
full pair against the passes over rows and columns that skip the zero rows (``RealFFT2``'s ``rows``). FFTW's wisdom is forgotten before every planning: an
estimated plan made after a measured one of the same shape reuses the measured plan (the first
version of this script planned MEASURE first and found the two equally fast).

    python benchmarks/bench_fft_plans.py
"""
import argparse
import os
import time

import numpy as np
import pyfftw

from multiscale.micro import fft

SHAPES = [(16, 16), (100, 16, 16), (64, 64), (128, 128), (4, 128, 128), (100, 128, 128), (256, 256), (512, 512),
          (1024, 1024), (2048, 2048)]
PADDED = [(4, 256, 256), (512, 512), (1024, 1024), (2048, 2048)]   # isolated 128² (a chunk of 4) ... 1024²


def pair_time(shape, flag, single=False):
    """(planning time, median time of one forward + inverse transform) [s] for ``shape``."""
    real, cplx = ("float32", "complex64") if single else ("float64", "complex128")
    a = pyfftw.empty_aligned(shape, real)
    s = pyfftw.empty_aligned(shape[:-1] + (shape[-1] // 2 + 1,), cplx)
    o = pyfftw.empty_aligned(shape, real)
    pyfftw.forget_wisdom()
    t0 = time.perf_counter()
    fwd = pyfftw.FFTW(a, s, axes=(-2, -1), flags=(flag,))
    inv = pyfftw.FFTW(s, o, axes=(-2, -1), direction="FFTW_BACKWARD", flags=(flag,))
    planning = time.perf_counter() - t0
    a[:] = np.random.default_rng(0).random(shape)
    n = max(3, int(2e7 / np.prod(shape)))
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            fwd()
            inv()
        times.append((time.perf_counter() - t0) / n)
    return planning, float(np.median(times))


def padded_times(shape, rows, single, repeats=7):
    """Median times [s] of one pair of our ``RealFFT2`` on a zero-padded field (``rows`` of data):
    the full 2-D pair and the passes that skip the zero rows, interleaved."""
    plans = {"full": fft.RealFFT2(shape, single=single), "rows": fft.RealFFT2(shape, single=single, rows=rows)}
    for plan in plans.values():
        plan.input[..., :rows, :] = np.random.default_rng(0).random(shape[:-2] + (rows, shape[-1]))
    n = max(3, int(2e7 / np.prod(shape)))
    times = {k: [] for k in plans}
    for _ in range(repeats):
        for k, plan in plans.items():
            t0 = time.perf_counter()
            for _ in range(n):
                plan.forward()
                plan.inverse(normalise=False)
            times[k].append((time.perf_counter() - t0) / n)
    return {k: float(np.median(t)) for k, t in times.items()}


def main():
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}")
    print("| shape | plan MEASURE [s] | plan ESTIMATE [s] | pair MEASURE [ms] | pair ESTIMATE [ms] | ESTIMATE / MEASURE "
          "| pair single, MEASURE [ms] | single / double |")
    print("|---|---|---|---|---|---|---|---|")
    for shape in SHAPES:
        pm, m = pair_time(shape, "FFTW_MEASURE")
        pe, e = pair_time(shape, "FFTW_ESTIMATE")
        _, f = pair_time(shape, "FFTW_MEASURE", single=True)
        print(f"| {shape} | {pm:.3f} | {pe:.4f} | {m * 1e3:.3f} | {e * 1e3:.3f} | {e / m:.2f} | {f * 1e3:.3f} "
              f"| {f / m:.2f} |")
    print("\nzero-padded fields (half the rows data; our RealFFT2, plans from the wisdom file): the full pair "
          "against the passes skipping the zero rows (``rows``)")
    print("| shape | precision | full [ms] | rows skipped [ms] | ratio |")
    print("|---|---|---|---|---|")
    for shape in PADDED:
        for single in (False, True):
            t = padded_times(shape, shape[-2] // 2, single)
            print(f"| {shape} | {'single' if single else 'double'} | {t['full'] * 1e3:.3f} | {t['rows'] * 1e3:.3f} "
                  f"| {t['rows'] / t['full']:.2f} |", flush=True)


if __name__ == "__main__":
    main()

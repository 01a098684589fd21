"""What the benchmark scripts share: the median wall time of repeated calls."""
import statistics
import time


def timed(fn, repeats):
    """Median wall time [s] of ``repeats`` calls of ``fn`` and its last result."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out

"""What the benchmark scripts share: the median wall time of repeated calls, and two setups timed side by side."""
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


def alternated(runs, repeats):
    """Side by side: the calls of ``runs`` (name -> fn, two of them) in turn, ``repeats`` rounds.
    Returns the median time [s] of each, the last result of each, and the median per-round ratio
    of the second's time to the first's."""
    times, out = {name: [] for name in runs}, {}
    for _ in range(repeats):
        for name, fn in runs.items():
            t0 = time.perf_counter()
            out[name] = fn()
            times[name].append(time.perf_counter() - t0)
    first, second = times.values()
    ratio = statistics.median([b / a for a, b in zip(first, second)])
    return {name: statistics.median(t) for name, t in times.items()}, out, ratio

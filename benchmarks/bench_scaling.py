"""Where a multiscale step's time goes per rank, and a model of it on more ranks (issue 23).

Runs the first ``--steps`` macro steps of a rough scene (default: the thesis ch. 7 configuration,
``demos/pin_on_disc_thesis.toml``) and measures, on every rank:

- zone laws: the pool's solve time on each rank (``MicroPool.stats.compute_seconds``) and the wall
  time of the call (the rest is exchange and waiting for the slowest rank);
- post-analysis: each rank's time in its share of the loaded zones' local solves, and the wall
  time of ``analyse`` (the rest is the allgather and waiting);
- macro: the wall time of the macro solves (Newton with MUMPS, heat step), collective.

It prints one table (medians over the steps after the first) and writes the history to
``results/bench_scaling_<P>.h5``; ``--compare FILE`` prints the largest relative difference of
every history column to another run's (the oversubscribed correctness check).

    mpiexec -n 1 python benchmarks/bench_scaling.py --steps 4
    mpiexec -n 2 python benchmarks/bench_scaling.py --steps 4
    mpiexec -n 4 python benchmarks/bench_scaling.py --steps 4 --compare results/bench_scaling_2.h5
"""
import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from multiscale import io  # noqa: E402
from multiscale.scene import load  # noqa: E402
from multiscale.workflows.multiscale import build  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


class Timed:
    """Wraps a callable and adds its wall time on this rank to ``seconds``."""

    def __init__(self, call):
        self.call, self.seconds = call, 0.0

    def __call__(self, *args, **kwargs):
        t0 = time.perf_counter()
        try:
            return self.call(*args, **kwargs)
        finally:
            self.seconds += time.perf_counter() - t0


class PoolBusy:
    """Wraps ``MicroPool.laws`` and adds every call's solve time of each rank to ``seconds``."""

    def __init__(self, pool):
        self.pool, self.call = pool, pool.laws
        self.seconds = np.zeros(pool.comm.size)

    def __call__(self, *args, **kwargs):
        try:
            return self.call(*args, **kwargs)
        finally:
            if self.pool.stats is not None:
                self.seconds += self.pool.stats.compute_seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=str(ROOT / "demos" / "pin_on_disc_thesis.toml"))
    ap.add_argument("--steps", type=int, default=4, help="macro steps (after the first laws and solve)")
    ap.add_argument("--compare", help="history .h5 of another run: largest relative difference per column")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    scene = load(args.scene, overrides={"time.steps": args.steps,
                                        "time.end": load(args.scene).time.dt * args.steps})
    with io.Reporter(comm, quiet=True):
        ms = build(scene, comm)
        post = ms.post.run = Timed(ms.post.run)
        pool = ms.rough.pool.laws = PoolBusy(ms.rough.pool)
        rows, history = [], io.History()
        for n in range(args.steps + 1):
            post.seconds, pool.seconds = 0.0, np.zeros(comm.size)
            t0 = time.perf_counter()
            result = ms.start() if n == 0 else ms.step(n)
            wall = time.perf_counter() - t0
            history.append(**ms.record(result))
            rows.append(dict(wall=wall, macro=result.time_macro, micro=result.time_micro, laws=result.time_laws,
                             laws_busy=pool.seconds.copy(), post_busy=np.array(comm.allgather(post.seconds)),
                             zones=result.micro.loaded))
    if comm.rank:
        return
    out = ROOT / "results" / f"bench_scaling_{comm.size}.h5"
    out.parent.mkdir(exist_ok=True)
    history.write(out)
    later = rows[1:] or rows
    med = lambda key: float(np.median([r[key] for r in later]))  # noqa: E731
    busy = lambda key, f: float(np.median([f(r[key]) for r in later]))  # noqa: E731
    print(f"\n{scene.name}: {comm.size} rank(s), {args.steps} steps, load average {os.getloadavg()[0]:.2f}")
    print("| ranks | first laws + solve [s] | step wall [s] | macro [s] | laws wall [s] | laws busy max / sum [s] "
          "| post wall [s] | post busy max / sum [s] | loaded zones |")
    print("|---|---|---|---|---|---|---|---|---|")
    print(f"| {comm.size} | {rows[0]['wall']:.1f} | {med('wall'):.2f} | {med('macro'):.2f} | {med('laws'):.2f} | "
          f"{busy('laws_busy', np.max):.2f} / {busy('laws_busy', np.sum):.2f} | {med('micro'):.2f} | "
          f"{busy('post_busy', np.max):.2f} / {busy('post_busy', np.sum):.2f} | {later[-1]['zones']} |")
    first = rows[0]
    print(f"first laws: busy per rank {np.round(first['laws_busy'], 2).tolist()} s")
    if args.compare:
        other = io.History.read(Path(args.compare))
        worst = {k: float(np.nanmax(np.abs(history[k] - other[k])) / max(np.nanmax(np.abs(other[k])), 1e-300))
                 for k in other.columns if not io.solver_statistic(k) and np.isfinite(other[k]).any()}
        top = sorted(worst.items(), key=lambda kv: -kv[1])[:5]
        print("largest differences to", args.compare, "(of each column's largest value):",
              ", ".join(f"{k} {v:.1e}" for k, v in top))


if __name__ == "__main__":
    main()

"""Wall time of the perfect-contact pin-on-disc demo (issue 8 target: < 5 min on 2 cores).

Runs ``mpiexec -n N multiscale run demos/pin_on_disc.toml --overwrite`` as `make demo` does,
once with an empty DOLFINx JIT cache (cold: every form compiled) and ``--repeats`` times with
the cache warm. Prints wall time, CPU time of the child processes (all ranks summed) and the load
average of the machine during the run (other jobs share the cores).

    python benchmarks/bench_pin_on_disc.py [--ranks 2] [--repeats 3]
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def once(ranks: int, env: dict, scene: str = "demos/pin_on_disc.toml") -> tuple[float, float, float]:
    """(wall s, CPU s of the children, 1-min load average at the end) of one demo run."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([str(BIN / "mpiexec"), "-n", str(ranks), str(BIN / "multiscale"), "run",
                    scene, "--overwrite"], cwd=ROOT, env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, os.getloadavg()[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--scene", default="demos/pin_on_disc.toml",
                    help="scene to time (default: make demo's; demos/pin_on_disc_perfect.toml: perfect contact)")
    args = ap.parse_args()
    env = dict(os.environ, UCX_TLS="self,sm,tcp", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory() as cache:
        cold = once(args.ranks, dict(env, XDG_CACHE_HOME=cache), args.scene)
        warm = [once(args.ranks, dict(env, XDG_CACHE_HOME=cache), args.scene) for _ in range(args.repeats)]
    walls = [w[0] for w in warm]
    print("| ranks | cold JIT wall [s] | cold CPU [s] | warm wall median [s] | warm walls [s] | "
          "warm CPU median [s] | load avg |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {args.ranks} | {cold[0]:.1f} | {cold[1]:.1f} | {statistics.median(walls):.1f} | "
          f"{', '.join(f'{w:.1f}' for w in walls)} | {statistics.median(w[1] for w in warm):.1f} | "
          f"{', '.join(f'{x[2]:.1f}' for x in [cold] + warm)} |")


if __name__ == "__main__":
    main()

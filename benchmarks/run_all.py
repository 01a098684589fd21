"""Run every benchmark of this folder one after the other (``make bench``).

Default: the quick configurations (a few minutes in all) that check each script still runs and
show the orders of magnitude. ``--full``: the configurations whose tables are recorded in
benchmarks/README.md (about an hour on 2 cores; the thesis pin-on-disc run is separate:
``python benchmarks/bench_multiscale.py``). ``--only contact,laws`` picks scripts by name.
Each script prints its own table; this driver reports the wall time of each and fails if any did.
"""
import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# name -> (ranks, quick arguments, full arguments)
RUNS = {
    "contact": (1, ["--quick"], []),
    "asperity": (1, ["--quick"], []),
    "conduction": (1, ["--quick"], []),
    "heating": (1, ["--quick"], []),
    "laws": (2, ["--zones", "4", "--repeats", "1"], []),
    "pin_on_disc": (1, ["--repeats", "1"], []),     # launches mpiexec -n 2 itself
    "squeal": (2, ["--mesh-size", "0.02", "--degree", "1", "--modes", "20"], []),
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--full", action="store_true", help="the recorded configurations (about an hour)")
    ap.add_argument("--only", default="", help=f"comma-separated subset of: {', '.join(RUNS)}")
    args = ap.parse_args()
    names = [n for n in args.only.split(",") if n] or list(RUNS)
    unknown = sorted(set(names) - set(RUNS))
    if unknown:
        ap.error(f"unknown benchmark(s) {', '.join(unknown)}; choose from {', '.join(RUNS)}")
    env = dict(os.environ, OMP_NUM_THREADS="1", MULTISCALE_THREADS="1")
    failed, walls = [], {}
    for name in names:
        ranks, quick, full = RUNS[name]
        mpi = [str(Path(sys.executable).parent / "mpiexec"), "-n", str(ranks)] if ranks > 1 else []
        cmd = mpi + [sys.executable, str(HERE / f"bench_{name}.py"), *(full if args.full else quick)]
        print(f"\n=== {name}: {' '.join(cmd)}", flush=True)
        t0 = time.perf_counter()
        if subprocess.run(cmd, env=env, cwd=HERE.parent).returncode:
            failed.append(name)
        walls[name] = time.perf_counter() - t0
    print("\nbenchmark        wall [s]")
    for name, wall in walls.items():
        print(f"{name:<16} {wall:8.1f}{'   FAILED' if name in failed else ''}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

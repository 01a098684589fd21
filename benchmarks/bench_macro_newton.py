"""The macro Newton solve with kept LU factors against a fresh factorisation per iteration (issue 23).

Runs the perfect-contact pin-on-disc on the thesis ch. 7 mesh (``demos/pin_on_disc_thesis.toml``
without roughness and wear, penalty 1e13 Pa/m, the constant 14 % partition; 1 mm interface elements,
60.7k tetrahedra), or with ``--rough`` the rough thesis configuration itself, for ``--steps`` macro
steps, alternately with ``Mechanics()`` (the default: inexact Newton, GMRES on the current tangent
preconditioned by LU factors kept across iterations and steps until the GMRES iterations they cost
take longer than a factorisation) and ``refresh=0`` (a fresh factorisation every iteration),
``--repeats`` times each; prints the median wall times, their ratio, the largest difference of the
histories and the load average.

    mpiexec -n 2 python benchmarks/bench_macro_newton.py --steps 10 --repeats 2
"""
import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from multiscale.macro.mechanics import Mechanics  # noqa: E402
from multiscale.scene import load  # noqa: E402
from multiscale.workflows import run  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "demos" / "pin_on_disc_thesis.toml"


def timed(scene, refresh: int):
    Mechanics.__init__.__kwdefaults__["refresh"] = refresh      # every Mechanics the workflow builds
    MPI.COMM_WORLD.barrier()
    t0 = time.perf_counter()
    result = run(scene, overwrite=True, verbose=False)
    return time.perf_counter() - t0, result.history


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=10, help="macro steps (0.6 s each)")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--rough", action="store_true", help="the rough thesis configuration (zone laws, wear)")
    args = ap.parse_args()
    overrides = {"name": "bench_macro_newton", "time.steps": args.steps, "time.end": 0.6 * args.steps,
                 "output.every": 1000, "output.folder": str(ROOT / "results" / "bench_macro_newton")}
    if not args.rough:
        overrides.update({"effects": ["contact", "friction", "thermal", "heat_partition", "expansion"],
                          "interface.penalty": "1e13 Pa/m"})
    scene = load(SCENE, overrides=overrides)
    walls, histories = {None: [], 0: []}, {}
    timed(scene, None)                                    # JIT cache warm
    for _ in range(args.repeats):
        for refresh in (None, 0):
            wall, histories[refresh] = timed(scene, refresh)
            walls[refresh].append(wall)
    if MPI.COMM_WORLD.rank == 0:
        kept, fresh = (float(np.median(walls[k])) for k in (None, 0))
        diff = max(float(np.max(np.abs(np.asarray(histories[None][k]) - histories[0][k])
                                / np.maximum(np.abs(histories[0][k]), 1e-300)))
                   for k in ("max_pressure", "interface_force", "max_temperature_pin"))
        print(f"{args.steps} steps on {MPI.COMM_WORLD.size} rank(s): kept LU (timed refresh) {kept:.1f} s "
              f"{[round(w, 1) for w in walls[None]]}, fresh LU {fresh:.1f} s {[round(w, 1) for w in walls[0]]}, "
              f"ratio {kept / fresh:.2f}; largest relative history difference {diff:.1e}; "
              f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()

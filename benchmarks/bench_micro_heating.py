"""Cost of the transient micro heating in the multiscale loop (issue 19) against the steady one.

Runs the coarse pin-on-disc of `make demo` (demos/pin_on_disc.toml, 25 macro steps) in this
process's MPI world with ``micro.heating`` steady (§6.5) and transient in N_t sub-steps per macro
step (§6.3, thesis Table 7.1: N_t = 10), alternating the settings ``--repeats`` times, and prints
per setting the median wall time of the run, the median over the runs of the median per-step
post-analysis time (``time_micro``), the peak micro temperature and the mean partition, and the
1-min load average after each run (other jobs share the cores).

    mpiexec -n 2 python benchmarks/bench_micro_heating.py [--repeats 2] [--steps 10]
"""
import h5py  # noqa: F401  (before DOLFINx)
import argparse
import os
import statistics
import tempfile
import time

import numpy as np
from mpi4py import MPI

from multiscale.scene import load
from multiscale.workflows.multiscale import run


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--steps", type=int, nargs="+", default=[10], help="N_t of the transient runs")
    ap.add_argument("--scene", default="demos/pin_on_disc.toml")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    settings = [("steady", {"micro.heating": "steady"})] + [
        (f"transient N_t = {n}", {"micro.heating": "transient", "micro.heating_steps": n}) for n in args.steps]
    rows = {name: [] for name, _ in settings}
    folder = comm.bcast(tempfile.mkdtemp() if comm.rank == 0 else None)
    for _ in range(args.repeats):
        for name, overrides in settings:
            scene = load(args.scene, overrides={**overrides, "output.folder": folder, "output.every": 1000})
            comm.Barrier()
            start = time.perf_counter()
            h = run(scene, overwrite=True, verbose=False, comm=comm).history
            wall = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
            rows[name].append((wall, float(np.median(h["time_micro"][1:])), float(np.max(h["micro_max_temperature"])),
                               float(np.mean(h["partition_mean"])), os.getloadavg()[0]))
    if comm.rank == 0:
        print("| micro heating | wall median [s] | walls [s] | post-analysis per step, median [s] | "
              "micro max T [degC] | mean partition | load avg |")
        print("|---|---|---|---|---|---|---|")
        for name, r in rows.items():
            print(f"| {name} | {statistics.median(x[0] for x in r):.1f} | {', '.join(f'{x[0]:.1f}' for x in r)} | "
                  f"{statistics.median(x[1] for x in r):.3f} | {r[0][2] - 273.15:.1f} | {r[0][3]:.4f} | "
                  f"{', '.join(f'{x[4]:.1f}' for x in r)} |")


if __name__ == "__main__":
    main()

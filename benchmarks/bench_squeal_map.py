"""Stability-map benchmark: a 20-point friction sweep with MAC mode tracking on the demo brake (issue 20).

Target: under 10 minutes on the 2-core machine. Runs ``demos/brake_squeal.toml`` (P2, every mode
up to 16 kHz, at most 100) with ``[stability.sweep] friction = [first, last], points = N`` and
prints the wall time of the nominal analysis and of the map, the map's size and the peak memory of
every rank (``--repeats`` runs, median).

    mpiexec -n 2 .venv/bin/python benchmarks/bench_squeal_map.py
    .venv/bin/python benchmarks/bench_squeal_map.py --mesh-size "20 mm" --points 5 --degree 1   # quick look
"""
from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from multiscale import scene as scenes
from multiscale.workflows import squeal

DEMO = Path(__file__).resolve().parents[1] / "demos" / "brake_squeal.toml"


def run_once(args, comm, folder):
    overrides = {"geometry.mesh_size": args.mesh_size, "stability.modes": args.modes,
                 "stability.sweep.friction": [args.first, args.last], "stability.sweep.points": args.points,
                 "output.folder": str(folder)}
    scene = scenes.load(DEMO, overrides)
    t0 = time.perf_counter()
    run = squeal.run(scene, comm=comm, verbose=False, overwrite=True, degree=args.degree)
    total = time.perf_counter() - t0
    return total, run


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh-size", default="12 mm")
    ap.add_argument("--degree", type=int, default=2)
    ap.add_argument("--modes", type=int, default=100)
    ap.add_argument("--points", type=int, default=20)
    ap.add_argument("--first", type=float, default=0.05)
    ap.add_argument("--last", type=float, default=0.8)
    ap.add_argument("--repeats", type=int, default=1)
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    folder = Path(comm.bcast(tempfile.mkdtemp(prefix="bench_map_") if comm.rank == 0 else None))
    totals = []
    for _ in range(args.repeats):
        total, run = run_once(args, comm, folder)
        totals.append(total)
    peak = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20, root=0)   # GiB
    if comm.rank == 0:
        smap, case = run.map, run.case
        print(f"demo brake, mesh {args.mesh_size}, P{args.degree}, {case.modes.n_dofs} dofs, {comm.size} rank(s); "
              f"load average {Path('/proc/loadavg').read_text().split()[0]}")
        print(f"nominal case: {len(case.modes)} modes up to {case.modes.frequency.max():.0f} Hz; "
              f"map: {smap.values.size} points, {smap.n_tracks} tracks, basis {smap.basis_size}, "
              f"{len(smap.onsets)} onsets, max residual {np.nanmax(smap.residual):.1e}")
        print(f"map alone {smap.time:.1f} s; end to end (median of {args.repeats}) {statistics.median(totals):.1f} s; "
              f"peak memory per rank [GiB]: {', '.join(f'{p:.2f}' for p in peak)}")


if __name__ == "__main__":
    main()

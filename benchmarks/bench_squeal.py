"""Brake squeal benchmark: preload + complex modes of the disc-brake assembly (thesis ch. 4).

Target (issue 10): preload plus 100 complex modes of a brake mesh with >= 200 000 dofs in under
10 minutes on the 2-core machine. Prints one table (wall time per stage, peak memory summed over
ranks) for ``--repeats`` runs (median).

    mpiexec -n 2 .venv/bin/python benchmarks/bench_squeal.py                 # the target case
    .venv/bin/python benchmarks/bench_squeal.py --mesh-size 0.02 --modes 30  # quick look
"""
from __future__ import annotations

import argparse
import resource
import statistics
import time
from types import SimpleNamespace as NS

from mpi4py import MPI

from multiscale.geometry import builder
from multiscale.macro import mesh as two_body
from multiscale.macro.eigen import solve_modes
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.preload import linearise, preload

# Thesis §4.3.1 materials: cast-iron disc, composite pads, steel parts (values: ours, typical).
STEEL = NS(E=210e9, nu=0.3, rho=7850.0)
MATERIALS = {"disc": NS(E=125e9, nu=0.25, rho=7200.0), "pad": NS(E=5e9, nu=0.25, rho=2500.0),
             "backplate": STEEL, "piston": STEEL, "caliper": STEEL}


def run_once(args, comm):
    t = {}
    t0 = time.perf_counter()
    tm = two_body.build(builder("disc_brake"), {"mesh_size": args.mesh_size}, comm)
    t["mesh"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    mech = Mechanics(tm, MATERIALS, stiffness=args.penalty, friction=args.friction, speed=5.0,
                     load_kind="fluid", degree=args.degree, prefix="bench_squeal_")
    ndofs = sum(V.dofmap.index_map.size_global * 3 for V in mech.spaces)
    t["setup"] = time.perf_counter() - t0
    pre = preload(mech, args.pressure, args.ramp)
    t["preload"] = pre.time
    t0 = time.perf_counter()
    K, M = linearise(mech, MATERIALS)
    t["linearise"] = time.perf_counter() - t0
    modes = solve_modes(K, M, f_max=args.f_max, n_modes=args.modes)
    t["modes"] = modes.time
    t["total"] = sum(t.values())
    return t, ndofs, pre, modes


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh-size", type=float, default=0.008, help="m, disc/caliper element size")
    ap.add_argument("--degree", type=int, default=2, help="Lagrange degree of the displacements")
    ap.add_argument("--modes", type=int, default=100)
    ap.add_argument("--f-max", type=float, default=50e3, help="Hz, upper band edge (cap on modes)")
    ap.add_argument("--friction", type=float, default=0.4)
    ap.add_argument("--pressure", type=float, default=1e6, help="Pa (10 bar)")
    ap.add_argument("--penalty", type=float, default=1e13, help="Pa/m, perfect-contact stiffness")
    ap.add_argument("--ramp", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=1)
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    runs = [run_once(args, comm) for _ in range(args.repeats)]
    peak_mib = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) / 1024
    if comm.rank:
        return
    t = {k: statistics.median(r[0][k] for r in runs) for k in runs[0][0]}
    _, ndofs, pre, modes = runs[-1]
    print(f"brake squeal benchmark: {ndofs} dofs (P{args.degree}, mesh {args.mesh_size * 1e3:g} mm), "
          f"{comm.size} rank(s), median of {args.repeats}")
    print("| stage | wall time [s] |\n|---|---|")
    for k, v in t.items():
        print(f"| {k} | {v:.1f} |")
    print(f"| peak memory (sum over ranks) | {peak_mib:.0f} MiB |")
    print(f"Newton iterations {pre.iterations}; pad forces "
          f"{', '.join(f'{k} {v:.1f} N' for k, v in pre.normal_force.items())}; "
          f"{len(modes)} modes up to {modes.frequency.max():.0f} Hz, {len(modes.unstable().nonzero()[0])} "
          f"unstable; max residual {modes.errors.max():.1e}; SLEPc solves {modes.solves}")


if __name__ == "__main__":
    main()

"""Brake squeal benchmark: preload + complex modes of the disc-brake assembly (thesis ch. 4).

Targets: preload plus 100 complex modes of a brake mesh with >= 200 000 dofs (issue 10), then
>= 500 000 dofs within the machine's memory (issue 20), in under 10 minutes on the 2-core machine.
Prints one table (wall time per stage, peak memory per rank) for ``--repeats`` runs (median).
``--method gnhep`` (default): Newton preconditioned by the LU of the tangent, the full GNHEP by
shift-and-invert with LU; ``--method subspace``: Newton preconditioned by the LDL^T of the
frictionless tangent, the projection on its real modes plus static corrections
(``macro.damped``, docs/squeal.md), each step about half the factorisation memory.

    mpiexec -n 2 .venv/bin/python benchmarks/bench_squeal.py                 # the issue-10 case
    mpiexec -n 2 .venv/bin/python benchmarks/bench_squeal.py --mesh-size 0.0063 --method subspace
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
from multiscale.macro.damped import LinearSystem, solve_system
from multiscale.macro.eigen import solve_modes
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.preload import linearise, preload

# Thesis §4.3.1 materials: cast-iron disc, composite pads, steel parts (values: ours, typical).
STEEL = NS(E=210e9, nu=0.3, rho=7850.0)
MATERIALS = {"disc": NS(E=125e9, nu=0.25, rho=7200.0), "pad": NS(E=5e9, nu=0.25, rho=2500.0),
             "backplate": STEEL, "piston": STEEL, "caliper": STEEL}


def peak_gib(comm) -> list:
    """ru_maxrss of every rank [GiB] (on rank 0; None elsewhere)."""
    return comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2)


def run_once(args, comm):
    t = {}
    t0 = time.perf_counter()
    tm = two_body.build(builder("disc_brake"), {"mesh_size": args.mesh_size}, comm)
    t["mesh"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    mech = Mechanics(tm, MATERIALS, stiffness=args.penalty, friction=args.friction, speed=5.0,
                     load_kind="fluid", degree=args.degree, prefix="bench_squeal_",
                     preconditioner="cholesky" if args.method == "subspace" else "lu", refresh=args.refresh)
    ndofs = sum(V.dofmap.index_map.size_global * 3 for V in mech.spaces)
    t["setup"] = time.perf_counter() - t0
    pre = preload(mech, args.pressure, args.ramp)
    t["preload"] = pre.time
    if comm.rank == 0:
        print(f"# {ndofs} dofs, preload {pre.time:.1f} s", flush=True)      # progress of a long run
    linear, factorisations = mech.problem.solver.getLinearSolveIterations(), mech.factorisations
    memory = {"preload": peak_gib(comm)}
    if args.preload_only:
        if comm.rank == 0:
            print(f"# preload: last load step {pre.iterations} Newton iterations, {linear} GMRES iterations, "
                  f"{factorisations} factorisations, "
                  f"peak memory {', '.join(f'{g:.2f}' for g in memory['preload'])} GiB", flush=True)
        return None
    t0 = time.perf_counter()
    if args.method == "subspace":
        mech.release()
    K, M = linearise(mech, MATERIALS)
    t["linearise"] = time.perf_counter() - t0
    if args.method == "subspace":
        system = LinearSystem(K, M, K0=mech.frictionless_tangent())
        modes = solve_system(system, f_max=args.f_max, n_modes=args.modes, method="subspace", basis=args.basis)
    else:
        modes = solve_modes(K, M, f_max=args.f_max, n_modes=args.modes)
    t["modes"] = modes.time
    memory["modes"] = peak_gib(comm)
    t["total"] = sum(t.values())
    return t, ndofs, pre, modes, (linear, factorisations), memory


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
    ap.add_argument("--method", choices=("gnhep", "subspace"), default="gnhep")
    ap.add_argument("--basis", type=float, default=1.5, help="subspace: real modes up to basis x the band")
    ap.add_argument("--refresh", type=int, help="Newton: GMRES iterations that trigger a new factorisation "
                    "(Mechanics; default: its own)")
    ap.add_argument("--preload-only", action="store_true", help="stop after the preload")
    args = ap.parse_args(argv)
    comm = MPI.COMM_WORLD
    runs = [run_once(args, comm) for _ in range(args.repeats)]
    if comm.rank or args.preload_only:
        return
    t = {k: statistics.median(r[0][k] for r in runs) for k in runs[0][0]}
    _, ndofs, pre, modes, (linear, factorisations), memory = runs[-1]
    print(f"brake squeal benchmark ({args.method}): {ndofs} dofs (P{args.degree}, mesh {args.mesh_size * 1e3:g} mm), "
          f"{comm.size} rank(s), median of {args.repeats}")
    print("| stage | wall time [s] |\n|---|---|")
    for k, v in t.items():
        print(f"| {k} | {v:.1f} |")
    for k, v in memory.items():
        print(f"| peak memory per rank after {k} | {', '.join(f'{g:.2f}' for g in v)} GiB |")
    print(f"Newton iterations {pre.iterations} (GMRES iterations {linear}, {factorisations} factorisations); pad forces "
          f"{', '.join(f'{k} {v:.1f} N' for k, v in pre.normal_force.items())}; "
          f"{len(modes)} modes up to {modes.frequency.max():.0f} Hz, {len(modes.unstable().nonzero()[0])} "
          f"unstable; max residual {modes.errors.max():.1e}, median {statistics.median(modes.errors):.1e}; "
          + (f"real modes: {modes.iterations} block Lanczos blocks" if args.method == "subspace"
             else f"SLEPc solves {modes.solves}"))


if __name__ == "__main__":
    main()

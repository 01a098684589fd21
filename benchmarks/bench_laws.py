"""Zone laws of the thesis ch. 7 interface through the MPI pool (issue 7).

The 20 mm x 20 mm pin face of §7.3.1 (RMS 10.35 um, cut-offs 1 and 50 wavelengths, 'fractal
dimension 0.6' read as Hurst 0.6), 1000 x 1000 cells of 20 um, cut into 400 zones of 1 mm x 1 mm
(50 x 50 cells each); pad 5 GPa/0.3 against steel 220 GPa/0.3; a 20-point p-g law per zone up to
p_max = 10 MPa (20x the nominal 0.5 MPa), Love-corrected (average), tol 1e-8. Each repeat starts
from an empty cache; then a call with nothing changed and one with one worn zone.

Run on one and on two ranks (each run prints its table and, once both exist, the speed-up):
    python benchmarks/bench_laws.py
    mpiexec -n 2 python benchmarks/bench_laws.py
Targets: under 60 s on 2 ranks; 1 -> 2 rank speed-up >= 1.7. 'CPU/rank' is the process time of
the busiest rank: what the wall time would be on otherwise idle cores ('load avg' says how idle
they were).
"""
import argparse
import json
import os
import statistics as stats
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.laws import LawSpec  # noqa: E402
from multiscale.micro.surface import fractal_surface  # noqa: E402
from multiscale.micro.zones import cut_zones  # noqa: E402
from multiscale.pool import MicroPool  # noqa: E402

RESULTS = Path("results") / "bench_laws.json"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--zones", type=int, default=20, help="zones per side (20: the 400-zone interface)")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    n = 50 * args.zones
    surface = fractal_surface(n, 1e-3 * args.zones, 0.6, 1, 50 * args.zones / 20, 10.35e-6, seed=7)
    _, zones = cut_zones(surface, (args.zones, args.zones))
    spec = LawSpec(HalfSpace.from_materials(5e9, 0.3, 220e9, 0.3), p_max=10e6, n_points=20)
    mine = zones[comm.rank::comm.size]        # e.g. the zones of this rank's interface facets

    walls, cpus, balance, laws = [], [], [], None
    for _ in range(args.repeats):
        pool = MicroPool(spec, progress=comm.rank == 0)
        comm.barrier()
        t0, c0 = time.perf_counter(), time.process_time()
        laws = pool.laws(mine, gather="all")
        cpus.append(comm.allreduce(time.process_time() - c0, op=MPI.MAX))
        comm.barrier()
        walls.append(time.perf_counter() - t0)
        balance.append(max(pool.stats.compute_seconds) / max(np.mean(pool.stats.compute_seconds), 1e-12))
    t0 = time.perf_counter()
    pool.laws(mine, gather="all")
    cached = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    worn = list(mine)
    if comm.rank == 0:
        worn[0] = worn[0].with_heights(worn[0].surface.heights - 1e-7 * (worn[0].surface.heights > 0))
    comm.barrier()
    t0 = time.perf_counter()
    pool.laws(worn, gather="all")
    one = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)

    if comm.rank:
        return
    iters = np.array([nd.iterations.sum() for nd in laws.nodes])
    row = dict(ranks=comm.size, zones=len(zones), wall=stats.median(walls), walls=walls, cpu=stats.median(cpus),
               load=os.getloadavg()[0],
               imbalance=stats.median(balance), cached=cached, one_worn=one,
               iterations_per_node=float(iters.mean() / spec.n_points),
               area_fraction_at_pmax=float(np.median([nd.area_fraction[-1] for nd in laws.nodes])),
               date=time.strftime("%Y-%m-%d"))
    print(f"\n{'ranks':>5} {'zones':>5} {'laws [s] (median)':>18} {'repeats':>24} {'CPU/rank [s]':>12} "
          f"{'max/mean rank':>13} {'cached [s]':>10} {'1 worn [s]':>10} {'iters/node':>10} {'A/A0 @ p_max':>12} "
          f"{'load avg':>8}")
    print(f"{row['ranks']:>5} {row['zones']:>5} {row['wall']:>18.1f} {str([round(w, 1) for w in walls]):>24} "
          f"{row['cpu']:>12.1f} {row['imbalance']:>13.3f} {cached:>10.3f} {one:>10.2f} "
          f"{row['iterations_per_node']:>10.1f} {row['area_fraction_at_pmax']:>12.3f} {row['load']:>8.1f}")
    RESULTS.parent.mkdir(exist_ok=True)
    table = json.loads(RESULTS.read_text()) if RESULTS.exists() else {}
    table[f"{len(zones)}:{comm.size}"] = row
    RESULTS.write_text(json.dumps(table, indent=1))
    one_rank, two_ranks = table.get(f"{len(zones)}:1"), table.get(f"{len(zones)}:2")
    if one_rank and two_ranks:
        print(f"speed-up 1 -> 2 ranks: {one_rank['wall'] / two_ranks['wall']:.2f}x "
              f"(target >= 1.7); 2 ranks: {two_ranks['wall']:.1f} s (target < 60 s)  [{RESULTS}]")


if __name__ == "__main__":
    main()

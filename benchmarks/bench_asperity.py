"""Asperity models (issue 3): time per load step at ~100 / 1 000 / 5 000 interacting contacts.

Surfaces: the thesis Table 1.1 Set 1 spectrum (H 0.95, cut-offs 2–10 wavelengths per mm, 128
points per mm, RMS 5 um), E 4 GPa / nu 0.15 on a rigid flat, on square patches of L mm with L
chosen for ~7 contacts per mm² (area fraction ~1.5 %); for N = 100 and 1 000 the approach is
found (untimed bisection) so that the interacting elliptic model has N contacts; for 5 000 (a
27 mm patch, ~20 000 summits, ~4 candidates per contact) it is fixed at 34 um, one repeat,
elliptic models only (each solve takes minutes: the far field of ~20 000 candidates is
recomputed by rows, see benchmarks/README.md). Timed per model and route (medians of repeats):
"cold" = a fresh model solving one approach (neighbour search, far-field matrix, minimisation);
"warm" = one step of a load curve (from 0.95 delta to delta, warm-started, structure reused).
The FFT-BEM (``ContactSolver``, isolated patch, tol 1e-8) on the smallest case gives the
accuracy–time reference. Run: python benchmarks/bench_asperity.py [--quick]
"""
import argparse
import os
import statistics as stats

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

from multiscale.micro.asperity import AsperityModel  # noqa: E402
from multiscale.micro.asperity_laws import hertz_law  # noqa: E402
from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import find_asperities, fractal_surface  # noqa: E402

from timing import timed  # noqa: E402

SOLID = HalfSpace.from_materials(4e9, 0.15)
RUNS = [("elliptic", "energy", "l-bfgs-b"), ("elliptic", "kinematic", "trf"),
        ("circular", "energy", "l-bfgs-b"), ("circular", "kinematic", "trf")]


def patch(n_contacts, seed=1):
    L = max(2.0, round(np.sqrt(n_contacts / 7.0)))
    n = int(128 * L)
    s = fractal_surface(n, L * 1e-3, 0.95, 2 * L, 10 * L, 5e-6, seed=seed)
    return s, find_asperities(s)


def approach_for(surface, table, n_contacts):
    """Approach at which the interacting elliptic model has ~n_contacts contacts (bisection)."""
    m = AsperityModel(table, hertz_law(table, SOLID, "elliptic"), surface=surface)
    lo, hi = 0.0, float(table.height.max() - surface.heights.mean())
    for _ in range(14):
        mid = 0.5 * (lo + hi)
        if m.solve(mid, raster=False).n_contacts < n_contacts:
            lo = mid
        else:
            hi = mid
    return hi


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one repeat, 100 and 1000 contacts only")
    ap.add_argument("--sizes", default="100,1000,5000", help="numbers of contacts, comma separated")
    args = ap.parse_args()
    reps = 1 if args.quick else 3
    sizes = (100, 1000) if args.quick else tuple(int(v) for v in args.sizes.split(","))
    print(f"{'N':>5} {'patch':>7} {'summits':>7} {'model':>9} {'route':>9} {'method':>8} {'cand':>5} "
          f"{'contacts':>8} {'A/A0':>7} {'F [N]':>9} {'evals':>5} {'cold [s]':>8} {'warm [s]':>8}")
    for N in sizes:
        s, table = patch(N)
        big = N > 2000
        delta = 34e-6 if big else approach_for(s, table, N)
        nrep = 1 if big else reps
        cand = int(np.sum(table.height > table.height.max() - delta))
        L = s.size[0] * 1e3
        forces = {}
        for shape, route, method in RUNS:
            if big and shape == "circular":
                continue

            def cold():
                m = AsperityModel(table, hertz_law(table, SOLID, shape), surface=s)
                return m.solve(delta, route=route, method=method, raster=False)
            t_cold, r = timed(cold, nrep)
            m = AsperityModel(table, hertz_law(table, SOLID, shape), surface=s)
            t_warm = float("nan") if big else stats.median(
                m.curve([0.95 * delta, delta], route=route, method=method).results[-1].wall_time
                for _ in range(nrep))
            forces[shape, route] = r.force
            print(f"{N:>5} {L:>5.0f}mm {len(table):>7} {shape:>9} {route:>9} {method:>8} {cand:>5} "
                  f"{r.n_contacts:>8} {r.area_fraction:>7.4f} {r.force:>9.4g} {r.evaluations:>5} "
                  f"{t_cold:>8.3f} {t_warm:>8.3f}", flush=True)
        for shape in ("elliptic", "circular"):
            free = AsperityModel(table, hertz_law(table, SOLID, shape), surface=s, interaction=False)
            t_free, r = timed(lambda: free.solve(delta, raster=False), nrep)
            print(f"{N:>5} {L:>5.0f}mm {len(table):>7} {shape:>9} {'no inter.':>9} {'direct':>8} {cand:>5} "
                  f"{r.n_contacts:>8} {r.area_fraction:>7.4f} {r.force:>9.4g} {0:>5} {t_free:>8.3f} {'':>8}")
        if N == sizes[0]:
            solver = ContactSolver(SOLID, s.shape, s.dx, periodic=False)
            t_bem, b = timed(lambda: solver.solve(s.heights, approach=delta, tol=1e-8), 1)
            F = float(b.mean_pressure) * (L * 1e-3) ** 2
            print(f"{N:>5} {L:>5.0f}mm {'':>7} {'FFT-BEM':>9} {'':>9} {'PK CG':>8} {'':>5} {'':>8} "
                  f"{float(b.area_fraction):>7.4f} {F:>9.4g} {int(b.iterations):>5} {t_bem:>8.3f}   "
                  f"(elliptic/BEM force {forces['elliptic', 'energy'] / F:.3f}, "
                  f"circular/BEM {forces['circular', 'energy'] / F:.3f})")


if __name__ == "__main__":
    main()

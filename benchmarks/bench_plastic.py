"""Elastic-perfectly-plastic contact (issue 18): our bounded BCCG against ContactMechanics'
hardness-limited constrained CG (Polonsky-Keer with the Almqvist et al. 2007 cut-off) on the same
periodic self-affine surfaces, at three hardness levels: pressure fields (relative L2), plastic
area fractions and wall times side by side; then the plastic solve against the elastic one on
the same 512² surface. Needs the bench extra (``pip install -e '.[bench]'``).

    python benchmarks/bench_plastic.py [--quick]
"""
from __future__ import annotations

import argparse
import os
import statistics as stats
import time

import numpy as np

from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import fractal_surface, statistics

TOL = 1e-10
E = HalfSpace.from_materials(1.0, 0.0)     # E* = 1, as ContactMechanics' PeriodicFFTElasticHalfSpace(young=1)
LEVELS = (0.5, 0.2, 0.05)                 # hardness / the largest elastic pressure of the surface


def case(n, seed=1):
    s = fractal_surface(n, 1.0, 0.8, 4, min(64, n // 4), 1e-2, seed=seed)
    load = 0.01 * E.E_star * float(statistics(s).rms_slope)
    return s, load


def cm_solve(h, dx, load, H):
    """ContactMechanics' constrained_conjugate_gradients with the hardness cut-off, tolerances
    tight enough for a 1e-12 answer (forces per pixel, compressive negative)."""
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization.ConstrainedConjugateGradients import constrained_conjugate_gradients
    n = h.shape[0]
    a = dx * dx
    sub = PeriodicFFTElasticHalfSpace((n, n), E.E_star, physical_sizes=(n * dx, n * dx))
    res = constrained_conjugate_gradients(sub, h, hardness=H * a, external_force=load * n * n * a,
                                          pentol=1e-12 * float(np.ptp(h)), forcetol=1e-12 * load * a,
                                          maxiter=200000)
    if not res.success:
        raise RuntimeError(f"ContactMechanics did not converge: {res.message}")
    return np.abs(np.asarray(res.jac)) / a


def side_by_side(peer, ours, repeats):
    """Median peer time, median our time, median per-repeat ratio, our last result, peer's."""
    t_peer, t_ours, ratio = [], [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out_peer = peer()
        t1 = time.perf_counter()
        out = ours()
        t2 = time.perf_counter()
        t_peer.append(t1 - t0)
        t_ours.append(t2 - t1)
        ratio.append(t_ours[-1] / t_peer[-1])
    return stats.median(t_peer), stats.median(t_ours), stats.median(ratio), out, out_peer


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one repeat, 128² peer comparison")
    args = ap.parse_args()
    reps = 1 if args.quick else 3
    print(f"load average {os.getloadavg()[0]:.2f}; tolerance {TOL:g}")
    n = 128 if args.quick else 256
    s, load = case(n)
    solver = ContactSolver(E, s.shape, s.dx)
    elastic = solver.solve(s.heights, load=load, tol=TOL)
    print(f"\n{n}x{n} periodic, load {load:.3e} E*, elastic max pressure {elastic.pressure.max():.3e}")
    print(f"{'H/p_max':>8} {'CM [s]':>8} {'ours [s]':>9} {'ratio':>6} {'iters':>6} {'A/A0':>7} "
          f"{'Apl/A0 ours':>11} {'Apl/A0 CM':>10} {'rel L2(p)':>10}")
    for level in LEVELS:
        H = level * float(elastic.pressure.max())
        t_cm, t_us, ratio, r, p_cm = side_by_side(lambda: cm_solve(s.heights, s.dx, load, H),
                                                  lambda: solver.solve(s.heights, load=load, tol=TOL, hardness=H),
                                                  reps)
        err = np.linalg.norm(r.pressure - p_cm) / np.linalg.norm(p_cm)
        print(f"{level:8.2f} {t_cm:8.3f} {t_us:9.3f} {ratio:6.2f} {int(r.iterations):6d} {float(r.area_fraction):7.4f} "
              f"{float(r.plastic_area_fraction):11.5f} {np.mean(p_cm >= H * (1 - 1e-9)):10.5f} {err:10.2e}")
    n = 512
    s, load = case(n, seed=2)
    solver = ContactSolver(E, s.shape, s.dx)
    elastic = solver.solve(s.heights, load=load, tol=TOL)
    pmax = float(elastic.pressure.max())
    print(f"\n{n}x{n} periodic: plastic against elastic solve (same solver object, plans built)")
    print(f"{'H/p_max':>8} {'elastic [s]':>11} {'plastic [s]':>11} {'ratio':>6} {'it el':>6} {'it pl':>6} "
          f"{'Apl/A0':>8}")
    for level in LEVELS:
        t_el, t_pl, ratio, r, e = side_by_side(lambda: solver.solve(s.heights, load=load, tol=TOL),
                                               lambda: solver.solve(s.heights, load=load, tol=TOL,
                                                                    hardness=level * pmax), max(reps, 3))
        print(f"{level:8.2f} {t_el:11.3f} {t_pl:11.3f} {ratio:6.2f} {int(e.iterations):6d} {int(r.iterations):6d} "
              f"{float(r.plastic_area_fraction):8.5f}")


if __name__ == "__main__":
    main()

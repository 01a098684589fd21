"""FFT-BEM contact speed and agreement against tamaas (issue 2).

Same surfaces, same material, periodic kernel, pressure control, p/E* ~ 0.01 * rms slope,
same relative tolerance (1e-8), one thread each (OMP_NUM_THREADS=1, MULTISCALE_THREADS=1).
Each repeat times tamaas then ours back to back (the VM's speed drifts between minutes); reports
median times, the median of the per-repeat ratios, iterations, contact area and the relative L2
difference of the pressure fields. Run: python benchmarks/bench_contact.py [--quick]
"""
import argparse
import os
import statistics as stats
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import fractal_surface, statistics  # noqa: E402

TOL = 1e-8
E = HalfSpace.from_materials(1.0, 0.0)   # E* = 1: tamaas' model.E = 1, nu = 0


def case(n, batch=(), seed=1):
    s = fractal_surface(n, 1.0, 0.8, 4, min(64, n // 4), 1e-2, seed=seed, batch=batch)
    load = 0.01 * E.E_star * np.asarray(statistics(s).rms_slope)
    return s, load


def tamaas_solve(h, load):
    import tamaas as tm
    n = h.shape[-1]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = 1.0, 0.0
    solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(h), TOL)
    solver.solve(float(load))
    return np.array(model.traction).reshape(n, n)


def timed(fn, repeats):
    """Median wall time of ``repeats`` calls of ``fn`` and its last result."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return stats.median(times), out


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
    ap.add_argument("--quick", action="store_true", help="fewer repeats, smaller batch")
    args = ap.parse_args()
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    reps = 1 if args.quick else 5
    print(f"{'case':>16} {'tamaas [s]':>11} {'ours [s]':>9} {'ratio':>6} {'iters':>6} {'A/A0':>8} {'rel L2(p)':>10}")
    for n in (256, 512, 1024):
        s, load = case(n)
        solver = ContactSolver(E, s.shape, s.dx)
        solver.solve(s.heights, load=load, tol=TOL)           # plans built outside the timing
        t_tm, t_us, ratio, r, p_tm = side_by_side(lambda: tamaas_solve(s.heights, load),
                                                  lambda: solver.solve(s.heights, load=load, tol=TOL), reps)
        err = np.linalg.norm(r.pressure - p_tm) / np.linalg.norm(p_tm)
        print(f"{f'{n}x{n}':>16} {t_tm:11.3f} {t_us:9.3f} {ratio:6.2f} {int(r.iterations):6d} "
              f"{float(r.area_fraction):8.4f} {err:10.2e}")
    nb = 100 if args.quick else 400
    s, load = case(64, batch=(nb,), seed=2)
    solver = ContactSolver(E, s.shape, s.dx)
    solver.solve(s.heights, load=load, tol=TOL)
    t_tm, t_us, ratio, r, p_tm = side_by_side(
        lambda: np.stack([tamaas_solve(h, l) for h, l in zip(s.heights, load)]),
        lambda: solver.solve(s.heights, load=load, tol=TOL), reps)
    err = np.max(np.linalg.norm(r.pressure - p_tm, axis=(1, 2)) / np.linalg.norm(p_tm, axis=(1, 2)))
    print(f"{f'{nb}x(64x64)':>16} {t_tm:11.3f} {t_us:9.3f} {ratio:6.2f} {int(r.iterations.max()):6d} "
          f"{float(r.area_fraction.mean()):8.4f} {err:10.2e}")


if __name__ == "__main__":
    main()

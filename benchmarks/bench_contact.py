"""FFT-BEM normal contact: the targets of issue 23 side by side with tamaas (issues 2, 23).

Solvers: ours with the preconditioned constrained CG (``method="bccg"``, the default), ours with
Polonsky–Keer (``method="pk"``) and tamaas 2.9 ``PolonskyKeerRey`` (``basic_2d``), one thread
each (OMP_NUM_THREADS=1, MULTISCALE_THREADS=1 unless said), the same relative tolerance 1e-8.
Each repeat runs tamaas, then bccg, then pk back to back (the VM's speed drifts between
minutes); times are medians over repeats, ratios medians of the per-repeat ratios.

Surfaces the issue prescribes: self-affine, Hurst 0.8, cut-offs 4 and N/4 wavelengths over the
patch, RMS slope 1, E* = 1, mean pressure 0.01 (A/A0 ~ 2 %), N = 256 ... 2048; then at N = 512
an anisotropic one (cut-offs 4 x 16 and N/4 x N/16), H = 0.3, 30 % contact, and an isolated patch
(zero-padded; tamaas has none: pk is the reference there); batches of 100 patches of 128².
The scaling surfaces refine the grid and add roughness (cut-off N/4) at once; the refinement part
separates the two: one surface refined onto finer grids, then finer roughness on one grid. The
levels part sets the two-level preconditioner of large grids against the one-level one, the
padding part isolated patches of sides 257, 511, 1030 on FFT grids padded to 5-smooth lengths
against exactly 2N, the rows part isolated patches whose FFT pairs skip the padding rows against
full 2-D pairs, the floor part the least an iteration of bccg's form can cost (``floor``).

Columns: iterations (tamaas counted from its log in an untimed run); "pairs/it": FFT pairs per
iteration counted by the FFT wrapper (``multiscale.micro.fft.fft_pairs``: every transform of the
solve, the nested coarse solves included, weighted by its cells, in pairs of the FFT grid: N² for
a periodic patch, (2N)² zero-padded for an isolated one; "single": of which in single precision,
bccg's two pairs from 512²); "t/it [pairs]": time per iteration over the time of one
(double) rfft2 + irfft2 pair of that grid (measured here); "to ref": relative
L2 distance of the pressure to a tol = 1e-12 reference (bccg; pk at 1e-12 agrees with it to
~1e-11); "vs pk": relative L2 between bccg and pk at tol 1e-8 (the discrete answer). Batches:
"cores" the one call's CPU time over its wall time (2 if each thread had a core throughout),
"steal" the CPU seconds per second of the call the hypervisor gave to other guests (/proc/stat).

Run: python benchmarks/bench_contact.py [--quick] [--sizes 256,512] [--skip-tamaas-above N]
"""
import argparse
import contextlib
import os
import platform
import re
import statistics as stats
import subprocess
import sys
import tempfile
import time
from functools import partial
from unittest import mock

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MULTISCALE_THREADS", "1")
import numpy as np  # noqa: E402
from numba import njit  # noqa: E402

from multiscale.micro import bccg_solver, bccg_steps, fft, kernels  # noqa: E402
from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import Surface, fractal_surface, refine, statistics  # noqa: E402

from timing import alternated  # noqa: E402

TOL = 1e-8
E = HalfSpace(1.0)                    # E* = 1: tamaas' model.E = 1, nu = 0
LOAD = 0.01                           # mean pressure / E*


def surface(n, hurst=0.8, k_min=4, k_max=None, seed=1, batch=()):
    s = fractal_surface(n, 1.0, hurst, k_min, k_max or n // 4, 1.0, seed=seed, batch=batch)
    slope = np.asarray(statistics(s).rms_slope)
    return s.heights / (slope[..., None, None] if batch else slope), s.dx


def tamaas_solve(h, load, tol=TOL, log=False):
    import tamaas as tm
    n = h.shape[-1]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = 1.0, 0.0
    solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(h), tol)
    solver.max_iter = 100000
    if log:
        solver.dump_freq = 1
    solver.solve(float(load))
    return np.array(model.traction).reshape(n, n)


def tamaas_iterations(h, load):
    """Iterations of tamaas' solve, read from its log: an untimed run in a subprocess (tamaas
    prints through C++ streams) that logs every iteration."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "h.npy")
        np.save(path, h)
        code = ("import sys, numpy as np, tamaas as tm\n"
                f"sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r})\n"
                "from bench_contact import tamaas_solve\n"
                "tm.set_log_level(tm.LogLevel.info)\n"
                f"tamaas_solve(np.load({path!r}), {float(load)!r}, log=True)\n")
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        out = done.stdout + done.stderr                   # tamaas logs to stderr
    numbers = [int(m.group(1)) for m in re.finditer(r"^\s*(\d+)\s+\S+\s+\S+\s*$", out, re.M)]
    return max(numbers) if numbers else -1


def pair_time(shape, repeats=30):
    """Median time of one rfft2 + irfft2 pair of ``shape`` (our wrapper, FFTW_MEASURE plans)."""
    plan = fft.RealFFT2(shape)
    plan.input[...] = np.random.default_rng(0).random(shape)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        plan.forward()
        plan.inverse(normalise=False)
        times.append(time.perf_counter() - t0)
    return stats.median(times)


def rel(a, b):
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def ours(solver, h, load, method):
    fft.reset_fft_counts()
    t0 = time.perf_counter()
    r = solver.solve(h, load=load, tol=TOL, method=method)
    grid = solver.operator.fft_shape
    return time.perf_counter() - t0, r, (fft.fft_pairs(grid), fft.fft_pairs(grid, single=True))


def machine():
    model = "?"
    with contextlib.suppress(OSError):
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{platform.node()}, {os.cpu_count()} cores, {model}"


def compare(name, h, dx, load, reps, with_tamaas=True, periodic=True):
    """One row per solver: time, ratio to tamaas, iterations, pairs/it (all, single), t/it in pairs,
    to ref, vs pk."""
    solver = ContactSolver(E, h.shape, dx, periodic=periodic)
    solver.solve(h, load=load, tol=1e-4)                  # plans and compiled loops outside the timing
    solver.solve(h, load=load, tol=1e-4, method="pk")
    ref = solver.solve(h, load=load, tol=1e-12, max_iter=100000).pressure
    times = {"tamaas": [], "bccg": [], "pk": []}
    out = {}
    for _ in range(reps):
        if with_tamaas:
            t0 = time.perf_counter()
            out["tamaas"] = tamaas_solve(h, load)
            times["tamaas"].append(time.perf_counter() - t0)
        for m in ("bccg", "pk"):
            t, r, pairs = ours(solver, h, load, m)
            times[m].append(t)
            out[m] = (r, pairs)
    tp = pair_time(solver.operator.fft_shape)
    rows = []
    for m in ("tamaas", "bccg", "pk"):
        if not times[m]:
            continue
        t = stats.median(times[m])
        ratio = stats.median([a / b for a, b in zip(times[m], times["tamaas"])]) if times["tamaas"] else float("nan")
        if m == "tamaas":
            its = tamaas_iterations(h, load)
            p, pairs, single, area = out[m], float("nan"), float("nan"), float(np.mean(out[m] > 0))
        else:
            r, (double, single) = out[m]
            its, p, area = int(r.iterations), r.pressure, float(r.area_fraction)
            pairs, single = (double + single) / its, single / its
        per_it = t / its / tp if its > 0 else float("nan")
        vs_pk = rel(p, out["pk"][0].pressure) if m != "pk" else 0.0
        rows.append((name, m, t, ratio, its, pairs, single, per_it, rel(p, ref), vs_pk, area))
    return rows


def print_rows(rows):
    print(f"{'case':>24} {'solver':>7} {'time [s]':>9} {'/tamaas':>8} {'its':>5} {'pairs/it':>8} {'single':>6} "
          f"{'t/it [pairs]':>12} {'to ref':>9} {'vs pk':>9} {'A/A0':>7}")
    for name, m, t, ratio, its, pairs, single, per_it, to_ref, vs_pk, area in rows:
        print(f"{name:>24} {m:>7} {t:9.3f} {ratio:8.3f} {its:5d} {pairs:8.2f} {single:6.2f} {per_it:12.2f} "
              f"{to_ref:9.1e} {vs_pk:9.1e} {area:7.4f}", flush=True)


def stopping_rule(n, tols=(1e-6, 1e-8, 1e-10)):
    """Distance to the 1e-12 reference at the same nominal tolerance: ours (both) and tamaas."""
    h, dx = surface(n, seed=7)
    solver = ContactSolver(E, h.shape, dx)
    ref = solver.solve(h, load=LOAD, tol=1e-12).pressure
    print(f"\nstopping rule, N = {n}: relative L2 distance of the pressure to the tol 1e-12 reference")
    print(f"{'tol':>8} {'bccg':>9} {'pk':>9} {'tamaas':>9}")
    for tol in tols:
        b = rel(solver.solve(h, load=LOAD, tol=tol).pressure, ref)
        k = rel(solver.solve(h, load=LOAD, tol=tol, method="pk").pressure, ref)
        t = rel(tamaas_solve(h, LOAD, tol), ref)
        print(f"{tol:8.0e} {b:9.2e} {k:9.2e} {t:9.2e}", flush=True)


def refinement(sizes, k_max=64):
    """Iterations (tol 1e-8) of bccg and pk as the grid is refined under one surface (cut-offs 4 and
    ``k_max``, drawn at the smallest size, ``surface.refine``), then at the largest size as the surface's
    upper cut-off grows to N/4 (the scaling rows' surfaces refine the grid and add roughness at once)."""
    def its(h):
        solver = ContactSolver(E, h.shape, 1.0 / h.shape[0])
        b, k = (solver.solve(h, load=LOAD, tol=TOL, method=m, max_iter=100000) for m in ("bccg", "pk"))
        return f"{int(b.iterations):5d} {int(k.iterations):5d} {float(b.area_fraction):7.4f}"

    print(f"\niterations under refinement: one surface with cut-offs 4 and {k_max}, refined")
    print(f"{'N':>5} {'bccg':>5} {'pk':>5} {'A/A0':>7}")
    h0, dx0 = surface(sizes[0], k_max=k_max)
    for n in sizes:
        print(f"{n:5d} {its(refine(Surface(h0, dx0, dx0), n).heights)}", flush=True)
    n = sizes[-1]
    print(f"\niterations at N = {n} as the upper cut-off grows (a new surface each)")
    print(f"{'k_max':>5} {'bccg':>5} {'pk':>5} {'A/A0':>7}")
    k = k_max
    while k <= n // 4:
        print(f"{k:5d} {its(surface(n, k_max=k)[0])}", flush=True)
        k *= 2


def levels(sizes, reps):
    """The two-level preconditioner (``bccg_coarse``, the default from ``bccg_solver.COARSE_FROM``
    cells) against the one-level one, side by side: two solvers on each surface, one built with
    the coarse correction switched off, their solves alternated; two realisations per N, and an
    isolated patch of the smallest N."""
    cases = [(n, seed, True) for n in sizes for seed in (1, 2)] + [(sizes[0], 1, False)]
    print("\ntwo-level against one-level preconditioner (bccg, tol 1e-8): medians; ratio = median of two / one")
    print(f"{'case':>24} {'one [s]':>8} {'its':>4} {'two [s]':>8} {'its':>4} {'ratio':>6} {'rel diff':>9}")
    for n, seed, periodic in cases:
        h, dx = surface(n, seed=seed)
        solvers = {}
        for name, threshold in (("one", 1 << 62), ("two", bccg_solver.COARSE_FROM)):
            with mock.patch.object(bccg_solver, "COARSE_FROM", threshold):   # read when a solver makes its buffers
                solvers[name] = ContactSolver(E, h.shape, dx, periodic=periodic)
                solvers[name].solve(h, load=LOAD, tol=1e-4)
        t, out, ratio = alternated({k: partial(s.solve, h, load=LOAD, tol=TOL) for k, s in solvers.items()},
                                   reps.get(n, 2))
        case = f"{n}² seed {seed}" + ("" if periodic else " isolated")
        print(f"{case:>24} {t['one']:8.3f} {int(out['one'].iterations):4d} {t['two']:8.3f} "
              f"{int(out['two'].iterations):4d} {ratio:6.3f} {rel(out['two'].pressure, out['one'].pressure):9.1e}",
              flush=True)


def batch(n_patches, n, reps, threads):
    """One call with the batch against a loop over its patches, the same solver, both methods; with
    several threads also against the loop on one thread (a 128² patch gains nothing from FFT threads)."""
    h, dx = surface(n, seed=2, batch=(n_patches,))
    print(f"\nbatch of {n_patches} patches of {n}², MULTISCALE_THREADS={threads}")
    print(f"{'method':>7} {'one call [s]':>12} {'loop [s]':>9} {'speed-up':>8} {'loop 1 thr [s]':>14} "
          f"{'speed-up':>8} {'its (max)':>9} {'max rel diff':>12} {'cores':>5} {'steal':>6}")
    for m in ("bccg", "pk"):
        solver = ContactSolver(E, (n, n), dx, method=m)
        times = {"batch": [], "loop": [], "loop1": []}
        cores, steal = [], []        # the one call's CPU time over its wall time; the VM's steal over it

        def timed(name, count, solve):
            fft.set_threads(count)
            s0, c0, t0 = steal_seconds(), time.process_time(), time.perf_counter()
            r = solve()
            wall = time.perf_counter() - t0
            times[name].append(wall)
            if name == "batch":
                cores.append((time.process_time() - c0) / wall)
                steal.append((steal_seconds() - s0) / wall)
            fft.set_threads(1)
            return r

        for _ in range(reps + 1):                        # the first round plans and compiles
            rb = timed("batch", threads, lambda: solver.solve(h, load=LOAD))
            rl = timed("loop", threads, lambda: [solver.solve(h[k], load=LOAD) for k in range(n_patches)])
            if threads > 1:
                timed("loop1", 1, lambda: [solver.solve(h[k], load=LOAD) for k in range(n_patches)])
        t = {k: v[1:] for k, v in times.items()}
        ratio = stats.median([a / b for a, b in zip(t["loop"], t["batch"])])
        loop1, ratio1 = "–", "–"
        if threads > 1:
            loop1 = f"{stats.median(t['loop1']):.3f}"
            ratio1 = f"{stats.median([a / b for a, b in zip(t['loop1'], t['batch'])]):.2f}"
        diff = max(rel(rb.pressure[k], rl[k].pressure) for k in range(n_patches))
        print(f"{m:>7} {stats.median(t['batch']):12.3f} {stats.median(t['loop']):9.3f} {ratio:8.2f} {loop1:>14} "
              f"{ratio1:>8} {int(rb.iterations.max()):9d} {diff:12.1e} {stats.median(cores[1:]):5.2f} "
              f"{stats.median(steal[1:]):6.2f}", flush=True)


def steal_seconds() -> float:
    """CPU time [s] the hypervisor gave to others while this VM's cores wanted it, summed over the
    cores (/proc/stat's ``steal``; 0 where there is none)."""
    with contextlib.suppress(OSError, IndexError, ValueError), open("/proc/stat") as fh:
        return int(fh.readline().split()[8]) / os.sysconf("SC_CLK_TCK")
    return 0.0


def padding(sizes, reps):
    """Isolated patches whose 2N has large prime factors: the FFT grid padded to 5-smooth lengths
    (``kernels.padded_size``, the default) against exactly 2N, side by side: two solvers per
    surface, the second built with the padding switched off, their solves alternated."""
    print("\nisolated patches, FFT grid 2N against padded to 5-smooth (bccg, tol 1e-8): medians; ratio = median of "
          "padded / 2N")
    print(f"{'N':>5} {'2N grid':>11} {'[s]':>7} {'its':>4} {'padded grid':>11} {'[s]':>7} {'its':>4} {'ratio':>6} "
          f"{'rel diff':>9}")
    for n in sizes:
        h, dx = surface(n)
        solvers = {}
        for name, pad in (("2N", int), ("padded", kernels.padded_size)):
            with mock.patch.object(kernels, "padded_size", pad):   # read when an operator is built (nested start's too)
                solvers[name] = ContactSolver(E, h.shape, dx, periodic=False)
                solvers[name].solve(h, load=LOAD, tol=1e-4)
        t, out, ratio = alternated({k: partial(s.solve, h, load=LOAD, tol=TOL) for k, s in solvers.items()}, reps)
        shape = {k: "x".join(map(str, s.operator.fft_shape)) for k, s in solvers.items()}
        print(f"{n:5d} {shape['2N']:>11} {t['2N']:7.3f} {int(out['2N'].iterations):4d} {shape['padded']:>11} "
              f"{t['padded']:7.3f} {int(out['padded'].iterations):4d} {ratio:6.3f} "
              f"{rel(out['padded'].pressure, out['2N'].pressure):9.1e}", flush=True)


def skipped_rows(sizes, reps):
    """Isolated patches: the FFT pairs of the zero-padded grid skipping the zero rows (``RealFFT2``'s
    ``rows``, the default) against the full 2-D pairs, side by side: two solvers per surface, the
    second built with the rows' passes switched off, their solves alternated; a batch of 100 x 128²
    too (chunks of 4 patches on 256² grids)."""
    print("\nisolated patches, FFT pairs skipping the padding rows against full pairs (bccg, tol 1e-8): medians; "
          "ratio = median of skipped / full")
    print(f"{'case':>12} {'full [s]':>9} {'its':>4} {'skipped [s]':>11} {'its':>4} {'ratio':>6} {'rel diff':>9}")

    def whole(*args, rows=None, **kwargs):                   # the full pairs: ``rows`` dropped
        return fft.RealFFT2(*args, **kwargs)

    cases = [(f"{n}²", surface(n)) for n in sizes] + [("100 x 128²", surface(128, seed=2, batch=(100,)))]
    for case, (h, dx) in cases:
        solvers = {}
        for name, plan in (("full", whole), ("skipped", fft.RealFFT2)):
            with mock.patch.object(kernels, "RealFFT2", plan):   # read when a workspace is built
                solvers[name] = ContactSolver(E, h.shape[-2:], dx, periodic=False)
                solvers[name].solve(h, load=LOAD, tol=1e-4)
        t, out, ratio = alternated({k: partial(s.solve, h, load=LOAD, tol=TOL) for k, s in solvers.items()}, reps)
        its = {k: int(np.max(r.iterations)) for k, r in out.items()}
        print(f"{case:>12} {t['full']:9.3f} {its['full']:4d} {t['skipped']:11.3f} {its['skipped']:4d} {ratio:6.3f} "
              f"{rel(out['skipped'].pressure, out['full'].pressure):9.1e}", flush=True)


@njit(cache=True, fastmath=True, nogil=True)
def floor_pass(u, Y, z, p, label, factor, d):
    """The full-grid pass no iteration avoids, fused: u += factor Y (the step's response) and the
    gap test of every cell (the free set: contact, or a negative gap). Returns the free cells."""
    n = 0
    for k in range(u.size):
        v = u[k] + factor * Y[k]
        u[k] = v
        free = p[k] > 0.0 or v + z[k] - d < 0.0
        label[k] = 0 if free else -1
        n += free
    return n


def floor(sizes, reps):
    """The least an iteration of bccg's form costs, in pairs of its grid: its two single-precision
    FFT pairs (the preconditioner's with its product, the step's L t with Parseval,
    ``bccg_steps.step_length``, and its product) and one fused full-grid pass (``floor_pass``), at
    the solved state of the scaling surface. Everything else an iteration does (the free set's
    lists, the ring passes, the coarse correction, the CG vectors, the clipped increments) comes on
    top. The floor and a double pair alternated, medians; "bccg t/it": a whole solve (the nested
    start included) per iteration, alternated with the pair."""
    print("\nfloor of an iteration: two float32 pairs + one fused full-grid pass, against a double pair")
    print(f"{'N':>6} {'pair [ms]':>9} {'float32 pair [ms]':>17} {'pass [ms]':>9} {'floor [ms]':>10} "
          f"{'floor [pairs]':>13} {'its':>4} {'bccg t/it [pairs]':>17}")
    for n in sizes:
        h, dx = surface(n)
        solver = ContactSolver(E, (n, n), dx)
        r = solver.solve(h, load=LOAD)
        op = solver.operator
        u, p = r.displacement.ravel().copy(), r.pressure.ravel()
        z, d = (h.max() - h).ravel(), float(r.approach)
        label = np.empty(n * n, dtype=np.int8)
        pre, step = op.workspace((1,), 1, True), op.workspace((1,), 1, True)
        mmul, lmul = op.inverse_multiplier.astype(np.float32), op.multiplier
        pre.load_buffer[...] = np.random.default_rng(0).random(pre.load_buffer.shape)
        step.load_buffer[...] = pre.load_buffer
        rt, active, tau = np.ones(1), np.ones(1, dtype=bool), np.zeros(1)
        unit = fft.RealFFT2((n, n))
        unit.input[...] = pre.load_buffer[0]
        Y = step.response_buffer.reshape(-1)

        def double_pair():
            unit.forward()
            unit.inverse(normalise=False)

        def single_pair():
            pre.fft.forward()
            pre.fft.inverse(normalise=False)

        def one_pass():
            floor_pass(u, Y, z, p, label, 0.0, d)

        def least():
            pre.apply(mmul)
            S = step.fft.forward()
            bccg_steps.step_length(S, lmul, n, rt, active, tau)
            kernels.multiply(S, lmul)
            step.fft.inverse(normalise=False)
            floor_pass(u, Y, z, p, label, 0.0, d)

        for f in (double_pair, single_pair, one_pass, least):
            f()                                      # compiled and planned before timing
        t, _, ratio = alternated({"pair": double_pair, "floor": least}, reps)
        t1, _, _ = alternated({"single": single_pair, "pass": one_pass}, reps)
        _, _, solve = alternated({"pair": double_pair, "solve": partial(solver.solve, h, load=LOAD)}, 3)
        its = int(r.iterations)
        print(f"{n:>6} {1e3 * t['pair']:9.2f} {1e3 * t1['single']:17.2f} {1e3 * t1['pass']:9.2f} "
              f"{1e3 * t['floor']:10.2f} {ratio:13.2f} {its:4d} {solve / its:17.2f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="N = 256, 512, one repeat, smaller batches")
    ap.add_argument("--sizes", default="", help="grid sizes of the scaling rows (default 256,512,1024,2048)")
    ap.add_argument("--skip-tamaas-above", type=int, default=1 << 30, help="no tamaas above this N")
    ap.add_argument("--only", default="scaling,surfaces,refinement,levels,padding,rows,stopping,batch,floor",
                    help="parts to run")
    args = ap.parse_args()
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    parts = set(args.only.split(","))
    sizes = [int(s) for s in args.sizes.split(",") if s] or ([256, 512] if args.quick else [256, 512, 1024, 2048])
    load0 = os.getloadavg()
    print(f"{time.strftime('%Y-%m-%d %H:%M %Z')}; {machine()}; load average {load0[0]:.2f} {load0[1]:.2f}")
    print(f"command: {' '.join(sys.argv)}; tamaas {tm.__version__}; numpy {np.__version__}")
    if "scaling" in parts:
        rows = []
        for n in sizes:
            reps = 1 if args.quick else {256: 5, 512: 5, 1024: 3}.get(n, 2)
            h, dx = surface(n)
            rows += compare(f"{n}² slope 1", h, dx, LOAD, reps, n <= args.skip_tamaas_above)
        print_rows(rows)
    if "surfaces" in parts:
        n, reps = 512, (1 if args.quick else 3)
        rows = []
        h, dx = surface(n, k_min=(4, 16), k_max=(n // 4, n // 16))
        rows += compare(f"{n}² anisotropic 4x", h, dx, LOAD, reps)
        h, dx = surface(n, hurst=0.3)
        rows += compare(f"{n}² H = 0.3", h, dx, LOAD, reps)
        h, dx = surface(n)
        rows += compare(f"{n}² 30 % contact", h, dx, 0.2, reps)
        h, dx = surface(n)
        rows += compare(f"{n}² isolated", h, dx, LOAD, reps, with_tamaas=False, periodic=False)
        print()
        print_rows(rows)
    if "refinement" in parts:
        refinement(sizes)
    if "levels" in parts:
        big = [n for n in sizes if n * n >= bccg_solver.COARSE_FROM] or [1024]
        levels(big, {1024: 5, 2048: 3})
    if "padding" in parts:
        padding([257] if args.quick else [257, 511, 1030], 1 if args.quick else 3)
    if "rows" in parts:
        skipped_rows([256] if args.quick else [256, 512, 1024], 1 if args.quick else 5)
    if "stopping" in parts:
        stopping_rule(256 if args.quick else 512)
    if "batch" in parts:
        for threads in (1, 2):
            batch(100, 128, 1 if args.quick else 9, threads)
    if "floor" in parts:
        floor([n for n in sizes if n >= 512] or [512], 3 if args.quick else 15)
    load1 = os.getloadavg()
    print(f"\nload average at the end {load1[0]:.2f} {load1[1]:.2f}")


if __name__ == "__main__":
    main()

"""Micro demo: a fractal surface (thesis Table 1.1, Set 1) pressed on a rigid flat by FFT-BEM.

Run: python demos/micro_contact.py [--n 256] [--out results/micro_contact]
Writes a PNG (pressure map + real area vs load) and prints where it went.
"""
import argparse
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import fractal_surface, statistics  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=256, help="grid points per side")
    ap.add_argument("--out", default="results/micro_contact", help="output folder")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    surface = fractal_surface(args.n, 1e-3, 0.95, 2, min(64, args.n // 4), 6e-6, seed=1)
    stats = statistics(surface)
    kernel = HalfSpace.from_materials(4e9, 0.15)            # sintered pad material vs rigid disc
    solver = ContactSolver(kernel, surface.shape, surface.dx)
    loads = np.geomspace(0.1e6, 10e6, 8)                    # mean pressure [Pa]
    t0 = time.perf_counter()
    results = [solver.solve(surface.heights, load=p) for p in loads]
    wall = time.perf_counter() - t0
    area = np.array([r.area_fraction for r in results])
    print(f"surface {args.n}x{args.n}, Rq = {stats.rms_height * 1e6:.2f} um, slope {stats.rms_slope:.3f}; "
          f"{len(loads)} loads in {wall:.2f} s ({sum(int(r.iterations) for r in results)} iterations)")
    for p, r in zip(loads, results):
        print(f"  p = {p / 1e6:6.2f} MPa  A/A0 = {r.area_fraction * 100:6.2f} %  "
              f"approach = {r.approach * 1e6:6.2f} um  mean gap = {r.mean_gap * 1e6:6.2f} um")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    L = surface.size[0] * 1e3
    im = ax1.imshow(results[-1].pressure / 1e6, extent=(0, L, 0, L), origin="lower", cmap="inferno")
    ax1.set(title=f"contact pressure at {loads[-1] / 1e6:.0f} MPa mean", xlabel="x [mm]", ylabel="y [mm]")
    fig.colorbar(im, ax=ax1, label="p [MPa]")
    ax2.loglog(loads / 1e6, area * 100, "o-", label="FFT-BEM")
    kappa = area / (loads / (kernel.E_star * stats.rms_slope))
    ax2.set(xlabel="mean pressure [MPa]", ylabel="real contact area A/A0 [%]",
            title=f"area vs load (kappa = {kappa[0]:.2f} … {kappa[-1]:.2f})")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend()
    fig.tight_layout()
    png = out / "micro_contact.png"
    fig.savefig(png, dpi=120)
    print(f"wrote {png.resolve()}")


if __name__ == "__main__":
    main()

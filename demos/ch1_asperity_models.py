"""Thesis ch. 1 (Figs. 1.7 and 1.9): the four asperity models and the FFT-BEM on a Set-1 and a
Set-2 surface (Table 1.1: H 0.95, 1 mm patch, cut-offs 2–10, resp. 7 x 12 wavelengths;
E 4 GPa, nu 0.15, rigid flat).

Curves: mean pressure vs approach (i) and vs separation g_n (Eq. 1.9) (ii), real area vs mean
pressure (iii), kappa vs area fraction (iv), and the wall time of each model's whole curve, so the
accuracy–time trade-off is visible. The FFT-BEM is the isolated-patch solver (zero-padded), the same
half-space setting as the asperity sums; its separation is also (max h − mean h) − delta.

Run: python demos/ch1_asperity_models.py [--size 1] [--seed 1] [--out results/ch1_asperity_models]
(``--size`` in mm keeps the Table 1.1 spectrum per mm: 1 is the thesis patch, ~25 summits.)
"""
import argparse
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from multiscale.micro.asperity import AsperityModel  # noqa: E402
from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import fractal_surface, statistics  # noqa: E402

SOLID = HalfSpace.from_materials(4e9, 0.15)
MODELS = [("(1) elliptic, interaction", "elliptic", True, "C0", "-"),
          ("(2) circular, interaction", "circular", True, "C1", "-"),
          ("(3) elliptic, no interaction", "elliptic", False, "C0", "--"),
          ("(4) circular, no interaction", "circular", False, "C1", "--")]


def run_set(name, k_max, size_mm, seed, n_steps=14):
    km = tuple(np.array(k_max, dtype=float) * size_mm) if np.ndim(k_max) else k_max * size_mm
    surface = fractal_surface(int(128 * size_mm), size_mm * 1e-3, 0.95, 2 * size_mm, km, 5e-6, seed=seed)
    st = statistics(surface)
    top = surface.heights.max() - surface.heights.mean()
    deltas = np.linspace(0.05, 0.9, n_steps) * top
    curves = {}
    for label, shape, inter, *_ in MODELS:
        model = AsperityModel.from_surface(surface, SOLID, shape, interaction=inter)
        t0 = time.perf_counter()
        c = model.curve(deltas)
        curves[label] = (c, time.perf_counter() - t0)
    solver = ContactSolver(SOLID, surface.shape, surface.dx, periodic=False)
    t0 = time.perf_counter()
    bem = solver.solve(np.broadcast_to(surface.heights, (len(deltas),) + surface.shape), approach=deltas)
    t_bem = time.perf_counter() - t0
    A0 = np.prod(surface.size)
    table = model.table
    print(f"{name}: {size_mm:g} mm patch, {len(table)} summits, mean eccentricity "
          f"{table.eccentricity.mean():.2f}, rms slope {st.rms_slope:.3f}, Nayak {st.nayak:.2f}")
    for label, (c, t) in curves.items():
        print(f"  {label:30s} {t:7.3f} s   F(top) = {c.force[-1]:8.3f} N   "
              f"A/A0(top) = {c.area_fraction[-1]:.4f}")
    F_bem = bem.mean_pressure * A0
    print(f"  {'FFT-BEM (isolated patch)':30s} {t_bem:7.3f} s   F(top) = {F_bem[-1]:8.3f} N   "
          f"A/A0(top) = {bem.area_fraction[-1]:.4f}")
    return dict(surface=surface, stats=st, deltas=deltas, curves=curves, bem=bem, t_bem=t_bem,
                gap=top - deltas)


def plot(sets, path):
    fig, axes = plt.subplots(len(sets), 5, figsize=(22, 4.4 * len(sets)), squeeze=False)
    for row, (name, d) in zip(axes, sets.items()):
        slope = float(d["stats"].rms_slope)
        bem = d["bem"]
        for label, (c, t), (_, _, _, colour, ls) in zip(d["curves"], d["curves"].values(), MODELS):
            row[0].plot(c.approach * 1e6, c.mean_pressure / 1e6, ls, color=colour, label=label)
            row[1].semilogy(c.mean_gap * 1e6, np.maximum(c.mean_pressure, 1e-3) / 1e6, ls, color=colour)
            row[2].plot(c.mean_pressure / 1e6, c.area_fraction * 100, ls, color=colour)
            row[3].plot(c.area_fraction * 100, c.kappa, ls, color=colour)
        kappa_bem = np.where(bem.mean_pressure > 0, bem.area_fraction * SOLID.E_star * slope /
                             np.where(bem.mean_pressure > 0, bem.mean_pressure, 1), np.nan)
        row[0].plot(d["deltas"] * 1e6, bem.mean_pressure / 1e6, "k.-", label="FFT-BEM")
        row[1].semilogy(d["gap"] * 1e6, np.maximum(bem.mean_pressure, 1e-3) / 1e6, "k.-")
        row[2].plot(bem.mean_pressure / 1e6, bem.area_fraction * 100, "k.-")
        row[3].plot(bem.area_fraction * 100, kappa_bem, "k.-")
        labels = [m[0].split(")")[0] + ")" for m in MODELS] + ["BEM"]
        times = [t for _, t in d["curves"].values()] + [d["t_bem"]]
        row[4].bar(labels, times, color=["C0", "C1", "C0", "C1", "k"], alpha=0.8)
        row[4].set_yscale("log")
        row[0].set(title=f"{name} (i)", xlabel="approach delta [um]", ylabel="mean pressure [MPa]")
        row[1].set(title="(ii)", xlabel="separation g_n [um]", ylabel="mean pressure [MPa]")
        row[2].set(title="(iii)", xlabel="mean pressure [MPa]", ylabel="A/A0 [%]")
        row[3].set(title="(iv) kappa = (A/A0) E* |grad h| / p", xlabel="A/A0 [%]", ylabel="kappa",
                   ylim=(0, 5))
        row[3].axvspan(1.5, 5, color="0.9")
        row[4].set(title=f"wall time of the {len(d['deltas'])}-step curve", ylabel="s")
        row[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", type=float, default=1.0, help="patch size [mm] (Table 1.1 spectrum per mm)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="results/ch1_asperity_models", help="output folder")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    sets = {"Set 1": run_set("Set 1", 10, args.size, args.seed),
            "Set 2": run_set("Set 2", (7, 12), args.size, args.seed)}
    path = out / "ch1_asperity_models.png"
    plot(sets, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()

"""Thesis ch. 2: contact of a two-layered solid (E1 = 4 GPa on E2, nu = 0.15, H = 1 mm on a rigid base).

1. One paraboloidal asperity (§2.3.2): force vs approach of the full Fredholm solution (Eq. 2.9),
   the chi/zeta approximation (§2.4.1) and Hertz on the top layer, for Figs. 2.4 (E2/E1), 2.5 (h)
   and 2.6 (R), with FFT-BEM points on the layered kernel; chi(a), zeta(a) of Figs. 2.7–2.8; the
   approximation's force error of Fig. 2.9.
2. A rough 1 mm x 1 mm surface on h = 100 um of E1 over E2/E1 = 1, 2, 5, 10 (§2.5): the layered
   multi-asperity model with (I) and without (N) interaction against the FFT-BEM on the layered
   kernel (in place of the thesis' FEM): p_n/E1* vs separation g_n (Figs. 2.13, 2.15) and A/A0 vs
   p_n/E1* (Figs. 2.14, 2.16).

Run: python demos/ch2_layered_contact.py [--n 128] [--out results/ch2_layered_contact]
"""
import argparse
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from multiscale.micro.asperity import AsperityModel  # noqa: E402
from multiscale.micro.contact import ContactSolver, solve_contact  # noqa: E402
from multiscale.micro.layered import LayeredElastic  # noqa: E402
from multiscale.micro.layered_asperity import LayeredAsperity, layered_law  # noqa: E402
from multiscale.micro.surface import find_asperities, fractal_surface  # noqa: E402

E1, NU, H = 4e9, 0.15, 1e-3
E1_STAR = E1 / (1 - NU**2)


def two_layers(h, E2):
    return LayeredElastic([h, H - h], [E1, E2], [NU, NU])


def save(fig, png, t0, title):
    """Title with the wall time since ``t0``, write the PNG, say where; returns the wall time."""
    wall = time.perf_counter() - t0
    fig.suptitle(f"{title} — {wall:.1f} s")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    print(f"wrote {png.resolve()}")
    return wall


def bem_force(kernel, R, delta, a_guess, n=64):
    """Isolated paraboloid by FFT-BEM on the layered kernel (patch of 5 contact radii)."""
    L = 5 * a_guess
    dx = L / n
    x = (np.arange(n) - n / 2 + 0.5) * dx
    heights = -(x[:, None] ** 2 + x[None, :] ** 2) / (2 * R)
    res = solve_contact(heights, dx, kernel, periodic=False, approach=delta + heights.max(), tol=1e-9)
    return float(res.mean_pressure) * L * L


def single_asperity(out):
    t0 = time.perf_counter()
    d = np.linspace(0, 20e-6, 41)
    a_max = 120e-6
    fig, ax = plt.subplots(2, 3, figsize=(17, 9.5))
    cases = [("Fig. 2.4: h = 100 um, R = 100 um",
              [(100e-6, E2, 100e-6, f"E2/E1 = {E2 / E1:g}") for E2 in (4e9, 8e9, 20e9, 40e9)]),
             ("Fig. 2.5: E2 = 10 GPa, R = 100 um",
              [(h, 10e9, 100e-6, f"h = {h * 1e6:g} um") for h in (50e-6, 100e-6, 200e-6, 500e-6)]),
             ("Fig. 2.6: E2 = 10 GPa, h = 100 um",
              [(100e-6, 10e9, R, f"R = {R * 1e6:g} um") for R in (50e-6, 100e-6, 200e-6)])]
    worst = {}
    for col, (title, runs) in enumerate(cases):
        for i, (h, E2, R, label) in enumerate(runs):
            asp = LayeredAsperity(two_layers(h, E2), a_max)
            c = asp.force_curve(d, R)
            colour = f"C{i}"
            ax[0, col].plot(d * 1e6, c.force * 1e3, "-", color=colour, label=label)
            ax[0, col].plot(d * 1e6, c.approx_force * 1e3, "--", color=colour)
            if i == len(runs) - 1:
                ax[0, col].plot(d * 1e6, c.hertz_force * 1e3, ":", color="k", label=f"Hertz on E1, {label}")
            err = np.abs(c.approx_error[1:])
            worst[f"{title[:8]} {label}"] = err.max()
            ax[1, 2].plot(d[1:] * 1e6, 100 * c.approx_error[1:], color=colour, ls=["-", "--", ":"][col],
                          label=f"{title[:8]} {label}")
            if col == 0 and i == len(runs) - 1:                   # FFT-BEM points, E2/E1 = 10
                for k in (10, 20, 30, 40):
                    F = bem_force(asp.kernel, R, d[k], c.radius[k])
                    ax[0, col].plot(d[k] * 1e6, F * 1e3, "ks", mfc="none",
                                    label="FFT-BEM (layered kernel)" if k == 10 else None)
        ax[0, col].set(title=title, xlabel="approach delta [um]", ylabel="force P [mN]")
        ax[0, col].legend(fontsize=8, title="solid: full, dashed: chi/zeta, dotted: Hertz", title_fontsize=7)
    a = np.linspace(0, 100e-6, 101)
    for col, (runs, title) in enumerate([([(100e-6, E2, f"E2/E1 = {E2 / E1:g}") for E2 in (4e9, 8e9, 20e9, 40e9)],
                                          "Fig. 2.7: chi, zeta for h = 100 um"),
                                         ([(h, 10e9, f"h = {h * 1e6:g} um") for h in (50e-6, 100e-6, 200e-6, 500e-6)],
                                          "Fig. 2.8: chi, zeta for E2 = 10 GPa")]):
        for i, (h, E2, label) in enumerate(runs):
            chi, zeta = LayeredAsperity(two_layers(h, E2), 100e-6).approximate(a)
            ax[1, col].plot(a * 1e6, chi, "-", color=f"C{i}", label=f"chi, {label}")
            ax[1, col].plot(a * 1e6, zeta, "--", color=f"C{i}", label=f"zeta, {label}")
        ax[1, col].set(title=title, xlabel="contact radius a [um]", ylabel="chi (solid), zeta (dashed)")
        ax[1, col].legend(fontsize=7, ncol=2)
    ax[1, 2].set(title="Fig. 2.9: chi/zeta force error vs full solution", xlabel="approach delta [um]",
                 ylabel="P_approx / P_full - 1 [%]")
    ax[1, 2].legend(fontsize=6, ncol=2)
    wall = save(fig, out / "ch2_single_asperity.png", t0,
                "Asperity on a two-layered solid (E1 = 4 GPa, nu = 0.15, H = 1 mm, rigid base)")
    print(f"single asperity: {len(worst)} curves in {wall:.1f} s; max |chi/zeta force error| per curve:")
    for k, v in worst.items():
        print(f"  {k:40s} {100 * v:6.2f} %")


def rough_surface(out, n):
    t_all = time.perf_counter()
    surface = fractal_surface(n, 1e-3, 0.8, 2, 16, 5e-6, seed=4)
    table = find_asperities(surface)
    top = surface.heights.max() - surface.heights.mean()
    deltas = np.linspace(0.05, 0.6, 10) * top
    A0 = np.prod(surface.size)
    dk = deltas[-1] - (table.height.max() - table.height)
    a_max = 1.5 * np.sqrt(np.max(table.radius * np.maximum(dk, 0)))
    print(f"rough surface: {n} x {n}, 1 mm, Rq = 5 um, {len(table)} summits, a_max {a_max * 1e6:.0f} um")
    results = {}
    for E2 in (4e9, 8e9, 20e9, 40e9):
        kernel = two_layers(100e-6, E2)
        t0 = time.perf_counter()
        law = layered_law(table, kernel, a_max, np.hypot(*surface.size))
        t_law = time.perf_counter() - t0
        curves, times = {}, {}
        for name, inter in (("I", True), ("N", False)):
            t0 = time.perf_counter()
            curves[name] = AsperityModel(table, law, interaction=inter, surface=surface).curve(deltas)
            times[name] = time.perf_counter() - t0
        t0 = time.perf_counter()
        solver = ContactSolver(kernel, surface.shape, surface.dx, periodic=False)
        bem = solver.solve(np.broadcast_to(surface.heights, (len(deltas),) + surface.shape), approach=deltas)
        times["BEM"] = time.perf_counter() - t0
        results[E2] = (curves, bem)
        F = {k: c.force[-1] for k, c in curves.items()}
        print(f"  E2/E1 = {E2 / E1:4.1f}: law {t_law:5.2f} s, model I {times['I']:5.2f} s, N {times['N']:5.2f} s, "
              f"FFT-BEM {times['BEM']:6.2f} s | at the deepest approach F_I/F_BEM = "
              f"{F['I'] / (bem.mean_pressure[-1] * A0):.3f}, F_N/F_BEM = {F['N'] / (bem.mean_pressure[-1] * A0):.3f}")
    fig, ax = plt.subplots(2, 2, figsize=(12, 9.5))
    gap = top - deltas
    for i, (E2, (curves, bem)) in enumerate(results.items()):
        colour, label = f"C{i}", f"E2/E1 = {E2 / E1:g}"
        I, N = curves["I"], curves["N"]
        ax[0, 0].semilogy(I.mean_gap * 1e6, I.mean_pressure / E1_STAR, "-", color=colour, label=f"model I, {label}")
        ax[0, 0].semilogy(gap * 1e6, bem.mean_pressure / E1_STAR, "o", color=colour, mfc="none")
        ax[0, 1].plot(I.mean_pressure / E1_STAR * 1e3, I.area_fraction * 100, "-", color=colour, label=label)
        ax[0, 1].plot(bem.mean_pressure / E1_STAR * 1e3, bem.area_fraction * 100, "o", color=colour, mfc="none")
        ax[1, 0].semilogy(I.mean_gap * 1e6, I.mean_pressure / E1_STAR, "-", color=colour, label=f"I, {label}")
        ax[1, 0].semilogy(N.mean_gap * 1e6, N.mean_pressure / E1_STAR, "--", color=colour, label=f"N, {label}")
        ax[1, 1].plot(I.mean_pressure / E1_STAR * 1e3, I.area_fraction * 100, "-", color=colour, label=f"I, {label}")
        ax[1, 1].plot(N.mean_pressure / E1_STAR * 1e3, N.area_fraction * 100, "--", color=colour, label=f"N, {label}")
    pg = dict(xlabel="separation g_n [um]", ylabel="p_n / E1*")
    ap = dict(xlabel="p_n / E1* [1e-3]", ylabel="A / A0 [%]")
    ax[0, 0].set(title="Fig. 2.13: model I (lines) vs FFT-BEM (circles)", **pg)
    ax[0, 1].set(title="Fig. 2.14: real area, model I vs FFT-BEM", **ap)
    ax[1, 0].set(title="Fig. 2.15: with (I) and without (N) interaction", **pg)
    ax[1, 1].set(title="Fig. 2.16: real area, I vs N", **ap)
    for a in ax.ravel():
        a.legend(fontsize=7)
        a.grid(True, which="both", alpha=0.3)
    wall = save(fig, out / "ch2_rough_two_layer.png", t_all,
                f"Rough surface on h = 100 um of 4 GPa over E2 (H = 1 mm, rigid base), {len(table)} summits")
    print(f"rough surface: {wall:.1f} s in all")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=128, help="grid points per side of the rough surface")
    ap.add_argument("--out", default="results/ch2_layered_contact", help="output folder")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    single_asperity(out)
    rough_surface(out, args.n)


if __name__ == "__main__":
    main()

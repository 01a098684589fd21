"""Chapter 5 demo: thermal contact conductance of a rough two-layered solid (thesis §5.5).

Two 1 mm cubes (Fig. 5.10): solid 1 is two-layered (top layer h, conductivity kappa1, modulus E1;
second layer kappa2 = 10 W/(m K), E2 = 4 GPa, down to 1 mm, base at theta_l1 = 0), solid 2 is
homogeneous (kappa 50, E 220 GPa, nu 0.33, top at theta_l2 = 1). Fractal surface of the thesis
(1 mm patch, H 0.8, cut-offs 2 and 10, RMS 6 um) on a 150 x 150 grid. K_t(p) for the layer cases
of Tables 5.3, 5.5 and 5.7, the Tables 5.4/5.6/5.8 numbers at 3 MPa beside the thesis values, a
local-resistance sweep (Fig. 5.25) and the surface temperatures of both bodies (Figs. 5.14–5.15).

Run: python demos/ch5_conduction.py [--n 150] [--out results/ch5_conduction]
"""
import argparse
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from multiscale.micro.conduction import ConductionSolver, SeriesKernel, conductance_law  # noqa: E402
from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.layered import LayeredElastic, LayeredThermal  # noqa: E402
from multiscale.micro.surface import fractal_surface  # noqa: E402

L, NU1 = 1e-3, 0.15          # cube height [m]; Poisson ratio of solid 1 (Table 3.1; ch. 5 gives none)
SOLID_2 = (LayeredElastic((L,), (220e9,), (0.33,)), LayeredThermal((L,), (50.0,)))
# (E1 [Pa], kappa1 [W/(m K)], h [m] or None for homogeneous) and the thesis' K_t [W/(m² K)] and T_s at 3 MPa
TABLES = {
    "Table 5.3/5.4 (kappa1 varies)": [((4e9, 10.0, None), 3.75e3, 0.83), ((4e9, 5.0, 5e-4), 2.24e3, 0.88),
                                      ((4e9, 2.5, 5e-4), 1.24e3, 0.93)],
    "Table 5.5/5.6 (kappa1/kappa2 = E1/E2)": [((4e9, 10.0, None), 3.75e3, 0.83), ((2e9, 5.0, 5e-4), 3.20e3, 0.88),
                                              ((1e9, 2.5, 5e-4), 2.46e3, 0.93)],
    "Table 5.7/5.8 (h varies)": [((1e9, 2.5, 1e-4), 3.27e3, 0.87), ((1e9, 2.5, 2e-4), 3.10e3, 0.89),
                                 ((1e9, 2.5, 5e-4), 2.46e3, 0.93)],
}


def solid_1(E1, kappa1, h):
    """Solid 1 of the thesis: one 1 mm layer (homogeneous) or two layers, on a rigid isothermal base."""
    if h is None:
        return LayeredElastic((L,), (E1,), (NU1,)), LayeredThermal((L,), (kappa1,))
    return (LayeredElastic((h, L - h), (E1, 4e9), (NU1, NU1)), LayeredThermal((h, L - h), (kappa1, 10.0)))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=150, help="grid points per side (thesis: 150)")
    ap.add_argument("--out", default="results/ch5_conduction", help="output folder")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    surface = fractal_surface(args.n, L, 0.8, 2, 10, 6e-6, seed=1)
    pressures = np.linspace(0.5e6, 5e6, 10)
    i3 = int(np.argmin(abs(pressures - 3e6)))
    laws, walls = {}, {}
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    for ax, (title, cases) in zip(axes.flat, TABLES.items()):
        print(f"\n{title}, p = {pressures[i3] / 1e6:.0f} MPa   (thesis values in brackets)")
        print(f"{'E1 [GPa]':>9} {'k1':>5} {'h [um]':>7} {'K_t [1e3]':>15} {'T_s':>13} {'K_p [1e3]':>10} "
              f"{'K_t/K_p':>7} {'A/A0 %':>7} {'time [s]':>8}")
        for (E1, k1, h), K_thesis, Ts_thesis in cases:
            key = (E1, k1, h)
            if key not in laws:
                elastic, thermal = solid_1(E1, k1, h)
                t1 = time.perf_counter()
                laws[key] = conductance_law(surface, SeriesKernel(elastic, SOLID_2[0]), (thermal, SOLID_2[1]),
                                            pressures)
                walls[key] = time.perf_counter() - t1
            law = laws[key]
            print(f"{E1 / 1e9:9.0f} {k1:5.1f} {h * 1e6 if h else 0:7.0f} {law.conductance[i3] / 1e3:7.2f} "
                  f"[{K_thesis / 1e3:4.2f}] {law.contact_temperature[i3]:6.2f} [{Ts_thesis:4.2f}] "
                  f"{law.perfect_conductance / 1e3:10.2f} {law.conductance[i3] / law.perfect_conductance:7.2f} "
                  f"{law.area_fraction[i3] * 100:7.2f} {walls[key]:8.2f}")
            label = "homogeneous" if h is None else f"E1 {E1 / 1e9:.0f} GPa, k1 {k1}, h {h * 1e6:.0f} um"
            ax.plot(pressures / 1e6, law.conductance / 1e3, "o-", label=label)
        ax.set(xlabel="mean pressure [MPa]", ylabel="K_t [10³ W/(m² K)]", title=title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)

    # Fig. 5.25: local thermal resistance on the illustrative case (Table 5.2: homogeneous, kappa 10)
    elastic, thermal = solid_1(4e9, 10.0, None)
    mech = ContactSolver(SeriesKernel(elastic, SOLID_2[0]), surface.shape, surface.dx)
    heat = ConductionSolver(thermal, SOLID_2[1], surface.shape, surface.dx)
    ax = axes[1, 1]
    print("\nFig. 5.25, illustrative case: K_t at 3 MPa vs local resistance R")
    for R in (0.0, 1e-7, 3e-7, 1e-6):
        law = conductance_law(surface, mech, heat, pressures, resistance=R)
        ax.plot(pressures / 1e6, law.conductance / 1e3, "o-", label=f"R = {R:.0e} m² K/W")
        print(f"  R = {R:.0e}: K_t = {law.conductance[i3]:.0f}, K_i = {law.interface_conductance[i3]:.0f} W/(m² K)")
    ax.set(xlabel="mean pressure [MPa]", ylabel="K_t [10³ W/(m² K)]", title="Fig. 5.25: local resistance")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    png = out / "conductance_vs_pressure.png"
    fig.savefig(png, dpi=110)
    plt.close(fig)

    # Figs. 5.14–5.15: surface temperatures of both bodies at 3 MPa
    contact = mech.solve(surface.heights, load=pressures[i3]).contact
    res = heat.solve(contact)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    ext = (0, L * 1e3, 0, L * 1e3)
    for ax, field, title in ((axes[0], res.temperature_2, "solid 2 (hot, kappa 50)"),
                             (axes[1], res.temperature_1, "solid 1 (kappa 10)")):
        im = ax.imshow(field, extent=ext, origin="lower", cmap="coolwarm")
        fig.colorbar(im, ax=ax, label="surface temperature [°C]")
        ax.set(title=f"{title}, T_s = {res.contact_temperature_1:.2f}", xlabel="x [mm]", ylabel="y [mm]")
    fig.tight_layout()
    png2 = out / "surface_temperatures.png"
    fig.savefig(png2, dpi=110)
    plt.close(fig)
    print(f"\nsurface temperatures at 3 MPa: solid 2 {res.temperature_2.min():.2f}–{res.temperature_2.max():.2f}, "
          f"solid 1 {res.temperature_1.min():.2f}–{res.temperature_1.max():.2f} °C "
          f"(thesis: 0.83–0.90 and 0.53–0.83)")
    print(f"wrote {png.resolve()}\nwrote {png2.resolve()}")
    print(f"wall time {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()

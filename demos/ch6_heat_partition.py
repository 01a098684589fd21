"""Chapter 6 demo: heat partition and flash temperatures of a rough pin on a rotating disc.

Thesis case (Tables 6.2–6.3): a 1 mm x 1 mm rough patch of the fixed solid S2 (pad-like, kappa = 5)
at (70.7, 70.7) mm from the axis of the rotating solid S1 (steel-like, kappa = 50), pressed by
delta = 10 um, mu = 0.4. Studies (each a PNG under --out):
  contact        pressure map of the patch
  velocity       p_1(t), p_2(t), T_max(t) for omega = 1, 10, 50, 100 rad/s over 4.5 ms (Figs 6.24)
  temperatures   surface temperatures of S1 and S2 at 4.5 ms, omega = 100 rad/s (Figs 6.28–6.29)
  area           steady p_1 and T_max versus real contact area (pressure sweep; Figs 6.26–6.27)
  profile        braking omega 10 -> 5, 1, 0 rad/s over 100 ms, then constant (Figs 6.30–6.33)
  interface      heat-generation profile, R and C of a 10-component layer (Figs 6.43–6.48)
  remote         steady p_1 with remote temperatures (Table 6.6, Figs 6.49–6.50)

The thesis grid is 150 x 150 (--n 150); the default --n 75 (13.3 um cells) runs in about a minute.
Run: python demos/ch6_heat_partition.py [--n 75] [--out results/ch6_heat_partition]
"""
import argparse
import time
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.heat_kernels import Rotation, SpeedProfile, ThermalMaterial  # noqa: E402
from multiscale.micro.heating import InterfaceLayer, SteadyHeating, TransientHeating, partition_law  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import Surface, fractal_surface  # noqa: E402

DISC = ThermalMaterial(50.0, 1e-5)          # S1, Table 6.3
PIN = ThermalMaterial(5.0, 3.5e-6)          # S2
ELASTIC = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)
CENTRE = (70.7e-3, 70.7e-3)                 # Table 6.2: R = 100 mm
MU = 0.4


def rotation(omega):
    return Rotation(CENTRE, SpeedProfile.constant(omega))


def save(fig, out, name):
    fig.tight_layout()
    path = out / f"{name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path.resolve()}")


def study_contact(surface, contact, out):
    fig, ax = plt.subplots(figsize=(5.2, 4.4))
    im = ax.imshow(contact.pressure / 1e6, origin="lower", extent=(0, 1, 0, 1), cmap="inferno")
    ax.set(title=f"contact pressure, delta = 10 um, A/A0 = {contact.area_fraction * 100:.2f} %",
           xlabel="x [mm]", ylabel="y [mm]")
    fig.colorbar(im, ax=ax, label="p [MPa]")
    save(fig, out, "contact")


def study_velocity(surface, contact, out):
    dt, steps = 50e-6, 90
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    hot = None
    for omega in (1.0, 10.0, 50.0, 100.0):
        sol = TransientHeating(surface.shape, surface.dx, DISC, PIN, rotation(omega), dt, steps)
        r = sol.run(contact.pressure, MU, field_times=[steps * dt], progress=True)
        t = r.times * 1e3
        a1.plot(t, r.partition_1, label=f"p1, omega = {omega:g}")
        a1.plot(t, r.partition_2, "--", label=f"p2, omega = {omega:g}")
        a2.plot(t, r.max_temperature_1, label=f"S1, omega = {omega:g}")
        a2.plot(t, r.max_temperature_2, "--", label=f"S2, omega = {omega:g}")
        print(f"  omega = {omega:5.0f} rad/s: p1(4.5 ms) = {r.partition_1[-1]:.4f}, "
              f"T_max = {r.max_temperature_1[-1]:.1f} K, {r.iterations.sum()} CG iterations")
        hot = r
    a1.set(xlabel="t [ms]", ylabel="heat partition", title="Fig. 6.24: p1(t), p2(t)")
    a2.set(xlabel="t [ms]", ylabel="max surface temperature rise [K]", title="T_max(t)", yscale="log")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend(fontsize=7, ncol=2)
    save(fig, out, "velocity")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, T, name in zip(axes, (hot.temperature_1[0], hot.temperature_2[0]), ("S1 (mobile)", "S2 (static)")):
        im = ax.imshow(T, origin="lower", extent=(0, 1, 0, 1), cmap="inferno")
        ax.set(title=f"{name} at 4.5 ms, omega = 100 rad/s", xlabel="x [mm]", ylabel="y [mm]")
        fig.colorbar(im, ax=ax, label="T [K]")
    save(fig, out, "temperatures")


def study_area(surface, out):
    loads = np.geomspace(0.5e6, 30e6, 8)
    speeds = CENTRE[0] * np.sqrt(2) * np.array([1.0, 10.0, 50.0, 100.0])
    law = partition_law(surface, DISC, PIN, speeds, loads, mu=MU, elastic=ELASTIC)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for v, p1, t1, t2 in zip(law.speed, law.partition_1, law.max_temperature_1, law.max_temperature_2):
        a1.plot(law.area_fraction * 100, p1, "o-", label=f"V = {v:.1f} m/s")
        a2.plot(law.area_fraction * 100, np.maximum(t1, t2), "o-", label=f"V = {v:.1f} m/s")
    a1.set(xlabel="real contact area [%]", ylabel="steady p1", title="Fig. 6.26: p1 versus contact area")
    a2.set(xlabel="real contact area [%]", ylabel="steady T_max [K]", title="Fig. 6.27", yscale="log")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    save(fig, out, "area")
    return law


def study_profile(surface, contact, out):
    dt, steps = 2e-3, 100
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    for omega1, style in ((5.0, "-"), (1.0, "--"), (0.0, ":")):
        motion = Rotation(CENTRE, SpeedProfile.ramp(10.0, omega1, 0.1))
        r = TransientHeating(surface.shape, surface.dx, DISC, PIN, motion, dt, steps).run(
            contact.pressure, MU, progress=True)
        t = r.times * 1e3
        axes[0, 0].plot(t, r.heat, style, label=f"omega1 = {omega1:g}")
        axes[0, 1].plot(t, r.heat_1, style, color="C0", label=f"Phi1, omega1 = {omega1:g}")
        axes[0, 1].plot(t, r.heat_2, style, color="C3", label=f"Phi2, omega1 = {omega1:g}")
        axes[1, 0].plot(t, r.partition_1, style, label=f"omega1 = {omega1:g}")
        axes[1, 1].plot(t, np.maximum(r.max_temperature_1, r.max_temperature_2), style, label=f"omega1 = {omega1:g}")
        after = r.times > 0.1
        print(f"  omega1 = {omega1:g}: after the ramp (t > 100 ms) Phi1 in [{r.heat_1[after].min():.3g}, "
              f"{r.heat_1[after].max():.3g}] W, Phi2 in [{r.heat_2[after].min():.3g}, {r.heat_2[after].max():.3g}] W")
    titles = ("Fig. 6.30: heat generated Phi [W]", "Fig. 6.31: Phi1, Phi2 [W]",
              "Fig. 6.32: p1 (undefined once Phi = 0)", "Fig. 6.33: T_max [K]")
    for ax, title in zip(axes.flat, titles):
        ax.set(xlabel="t [ms]", title=title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    save(fig, out, "profile")


def study_interface(surface, contact, out):
    dt, steps = 25e-6, 80
    sol = TransientHeating(surface.shape, surface.dx, DISC, PIN, rotation(100.0), dt, steps)
    cases = {
        # plane: all heat generated next to the sliding S1 (the thesis' reading of Fig. 6.42a; a mid-plane
        # source is equivalent to uniform generation when all components are equal)
        "profile": [(g, InterfaceLayer(1e-8, 1e4, n=10, generation=g, plane=0.0))
                    for g in ("plane", "uniform", "linear")],
        "resistance": [(f"R = {R:g}", InterfaceLayer(R, 1e4, n=10, generation="uniform")) for R in (1e-10, 1e-9, 1e-8)],
        "capacitance": [(f"C = {C:g}", InterfaceLayer(1e-8, C, n=10, generation="uniform")) for C in (1e3, 1e4, 1e5)],
    }
    fig, axes = plt.subplots(2, 3, figsize=(14, 7.5))
    for col, (study, layers) in enumerate(cases.items()):
        for i, (label, layer) in enumerate(layers):
            r = sol.run(contact.pressure, MU, interface=layer)
            t = r.times * 1e3
            axes[0, col].plot(t, r.partition_1, color=f"C{i}", label=f"p1, {label}")
            axes[0, col].plot(t, r.partition_2, "--", color=f"C{i}", label=f"p2, {label}")
            axes[1, col].plot(t, r.max_temperature_1, color=f"C{i}", label=f"S1, {label}")
            axes[1, col].plot(t, r.max_temperature_2, "--", color=f"C{i}", label=f"S2, {label}")
        axes[0, col].set(title=f"{study}: heat partition", xlabel="t [ms]")
        axes[1, col].set(title=f"{study}: T_max [K]", xlabel="t [ms]")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    save(fig, out, "interface")


def study_remote(surface, out):
    loads = np.geomspace(0.5e6, 30e6, 6)
    cases = {"C1": (1, 0), "C4": (100, 0), "C5": (0, 1), "C8": (0, 100)}
    solver = ContactSolver(ELASTIC, surface.shape, surface.dx, periodic=surface.periodic)
    contact = solver.solve(np.broadcast_to(surface.heights, loads.shape + surface.shape), load=loads)
    area = contact.area_fraction * 100
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, omega in zip(axes, (10.0, 100.0)):
        steady = SteadyHeating(surface.shape, surface.dx, DISC, PIN, omega * np.hypot(*CENTRE))
        ax.plot(area, steady.solve(contact.pressure, MU).partition_1, "k-", label="no remote temperatures")
        for name, temps in cases.items():
            ax.plot(area, steady.solve(contact.pressure, MU, remote_temperatures=temps).partition_1, "o-",
                    label=f"{name}: theta1 = {temps[0]}, theta2 = {temps[1]}")
        ax.set(xlabel="real contact area [%]", ylabel="steady p1", title=f"omega = {omega:g} rad/s (Figs 6.49-6.50)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    save(fig, out, "remote")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=75, choices=(30, 50, 75, 150),
                    help="grid cells per side (thesis: 150; coarser grids subsample the same surface)")
    ap.add_argument("--out", default="results/ch6_heat_partition", help="output folder")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    fine = fractal_surface(150, 1e-3, 0.8, 2, 10, 6.49e-6, seed=3)         # the thesis grid
    step = 150 // args.n
    surface = Surface(fine.heights[::step, ::step], fine.dx * step, fine.dy * step, periodic=False)
    contact = ContactSolver(ELASTIC, surface.shape, surface.dx, periodic=False).solve(surface.heights, approach=10e-6)
    print(f"grid {args.n} x {args.n} ({surface.dx * 1e6:.2f} um cells), rms 6.49 um (k = 2…10), delta = 10 um: "
          f"A/A0 = {contact.area_fraction * 100:.2f} % (thesis: 1.48 %), mean pressure "
          f"{contact.mean_pressure / 1e6:.2f} MPa")
    study_contact(surface, contact, out)
    print("velocity study (4.5 ms, dt = 50 us):")
    study_velocity(surface, contact, out)
    print("contact-area study (steady partition law):")
    law = study_area(surface, out)
    print("  p1 at 3 MPa: " + ", ".join(f"{v:.1f} m/s: {law(3e6, v):.4f}" for v in law.speed))
    print("velocity-profile study (200 ms, dt = 2 ms):")
    study_profile(surface, contact, out)
    print("interface-layer study (2 ms, dt = 25 us, omega = 100 rad/s):")
    study_interface(surface, contact, out)
    print("remote-temperature study (steady):")
    study_remote(surface, out)
    print(f"done in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()

# # Wear of a rough surface under sliding (thesis ch. 3, §3.5.1, Figs. 3.3–3.10)
#
# A rough pad-like solid S1 slides on a flat, much stiffer S2 under a constant mean pressure and
# wears by Archard's law: at each contact point the wear depth grows as
#
#     dh = k_w μ p dS                                   (thesis Eq. 3.10)
#
# for a sliding increment dS. The sliding distance S is cut into N wear steps; each step wears the
# surface with the pressure of the last contact solve, then solves the contact on the worn surface
# again (FFT-BEM, §3.3). The thesis example: a fractal surface (1 mm patch, H = 0.8, cut-offs 2 and
# 10, RMS 6 µm), E = 4 GPa, ν = 0.15 against a rigid flat, p = 1 MPa, μ = 0.4, S = 10 mm,
# k_w = 1e-12 /Pa. We follow the real contact area (Fig. 3.3), the largest wear depth (Fig. 3.4) and
# the worn volume (Fig. 3.9) for several N, the pressure–gap law of the worn surface (Fig. 3.10),
# and the surfaces before and after (Figs. 3.5–3.6). Where we differ from the thesis: k_w = 1e-10
# by default, not its 1e-12, which wears 4 nm on average over the 10 mm and cannot take the area
# from 1 % to its 13 % (the mass balance below; at 1e-12, N = 200 and 300 give the same curves,
# 0.61 % -> 0.99 %, and Fig. 3.3's message, that too few steps under-estimate the area, is not
# seen: a user trial); S2 is rigid here, E = 220 GPa, ν = 0.33 in Table 3.1 (E* 1.7 % apart).
#
#     .venv/bin/python demos/ch3_wear.py                  # N = 200, 300 and 400 at k_w = 1e-10
#     .venv/bin/python demos/ch3_wear.py --kw 1e-12       # the thesis' k_w: 4 nm of mean wear

import argparse
import time
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import fractal_surface
from multiscale.micro.wear import simulate_wear

from demo_output import add_out

matplotlib.use("Agg")  # PNG files only, no display

# The loading of thesis §3.5.1: mean pressure [Pa], friction coefficient, sliding distance [m] and
# wear rate [1/Pa].
P, MU, S, KW = 1e6, 0.4, 10e-3, 1e-12

parser = argparse.ArgumentParser(description="Wear of a rough surface under sliding (thesis §3.5)")
parser.add_argument("--n", type=int, default=128,
                    help="grid points per side (another n draws another surface of the spectrum)")
parser.add_argument("--steps", type=int, default=400, help="wear steps (besides 200 and 300)")
parser.add_argument("--kw", type=float, default=100 * KW, help="wear rate k_w [1/Pa] (thesis: 1e-12; see the header)")
add_out(parser, __file__)
args = parser.parse_args()
out = Path(args.out)
t0 = time.perf_counter()

# ## The surface and the solid
# The fractal surface of §3.5 on a periodic 1 mm patch; S1 (E = 4 GPa, ν = 0.15) on a rigid flat.
surface = fractal_surface(args.n, 1e-3, 0.8, 2, 10, 6e-6, seed=1)
solver = ContactSolver(HalfSpace.from_materials(4e9, 0.15), surface.shape, surface.dx)
area = surface.size[0] * surface.size[1]

# ## Wear for several numbers of steps
# The thesis compares N = 200 to 600 and finds N >= 300 converged (Figs. 3.3–3.4); we run 200, 300
# and `--steps`. On the last run the pressure–gap law of the worn surface is sampled at eight mean
# pressures after 0, 1/4, 1/2 and all of the steps (Fig. 3.10).
#
# Mass balance: summing Eq. 3.10 over the patch, the worn volume is k_w μ p A0 S whatever the pressure
# field, so the mean wear depth is k_w μ p S = 4 nm for the thesis values, while wearing the peaks
# flat down to 13 % real area (thesis §3.5.1) would take about 0.4 µm on a 6 µm RMS surface:
# k_w = 1e-10 (the default) shows that regime.
law_steps = (0, args.steps // 4, args.steps // 2, args.steps)
law_loads = np.linspace(0.25e6, 2e6, 8)
runs = {}
for N in sorted({200, 300, args.steps}):
    runs[N] = simulate_wear(surface, solver, load=P, mu=MU, distance=S, steps=N, k_w=args.kw, progress=True,
                            law_steps=law_steps if N == args.steps else (), law_loads=law_loads)
    h = runs[N].history
    print(f"N = {N:4d}: A/A0 {h.area_fraction[0] * 100:.2f} % -> {h.area_fraction[-1] * 100:.2f} %, "
          f"max p {h.max_pressure[0] / 1e6:.0f} -> {h.max_pressure[-1] / 1e6:.0f} MPa, "
          f"max depth {h.max_depth[-1] * 1e6:.3f} µm, volume {h.volume[-1]:.3e} m³ "
          f"(k_w mu P S = {args.kw * MU * P * area * S:.3e}), RMS {h.rms_height[0] * 1e6:.2f} -> "
          f"{h.rms_height[-1] * 1e6:.2f} µm, {runs[N].wall_time:.1f} s, "
          f"median {np.median(h.iterations[1:]):.0f} iterations/step")
main_run = runs[args.steps]

# ## Figure: the wear history
# Real area (Fig. 3.3) and largest wear depth (Fig. 3.4) for each N; worn volume per unit area
# against Archard's k_w μ p S (Fig. 3.9) and the pressure–gap laws (Fig. 3.10) of the last run.
out.mkdir(parents=True, exist_ok=True)
fig, axes = plt.subplots(2, 2, figsize=(11, 8))
for N, run in runs.items():
    s_mm = run.history.sliding * 1e3
    axes[0, 0].plot(s_mm, run.history.area_fraction * 100, label=f"N = {N}")
    axes[0, 1].plot(s_mm, run.history.max_depth * 1e6, label=f"N = {N}")
axes[0, 0].set(xlabel="sliding distance [mm]", ylabel="real contact area A/A0 [%]", title="real contact area against sliding distance")
axes[0, 1].set(xlabel="sliding distance [mm]", ylabel="max wear depth [µm]", title="max wear depth against sliding distance")
h = main_run.history
axes[1, 0].plot(h.sliding * 1e3, h.volume / area * 1e9, label="wear volume")
axes[1, 0].plot(h.sliding * 1e3, args.kw * MU * P * h.sliding * 1e9, "k--", label="k_w μ p S")
axes[1, 0].set(xlabel="sliding distance [mm]", ylabel="wear volume per area [nm]", title="wear volume against sliding distance")
for law in main_run.laws:
    axes[1, 1].plot(law.mean_gap * 1e6, law.pressure / 1e6, "o-", label=f"S = {law.sliding * 1e3:.1f} mm")
axes[1, 1].set(xlabel="mean gap g_n [µm]", ylabel="mean pressure p_n [MPa]", title="pressure-gap law of the worn surface")
for ax in axes.flat:
    ax.grid(True, alpha=0.3)
    ax.legend()
fig.tight_layout()
png = out / "wear_history.png"
fig.savefig(png, dpi=110)
plt.close(fig)

# ## Figure: the surface before and after
# Initial heights (Fig. 3.5), the accumulated wear depth (Fig. 3.6) and the contact pressure on the
# initial and on the worn surface.
initial = solver.solve(surface.heights, load=P)
fig, axes = plt.subplots(2, 2, figsize=(10, 8.5))
L = surface.size[0] * 1e3
ext = (0, L, 0, L)
im = axes[0, 0].imshow(surface.heights * 1e6, extent=ext, origin="lower", cmap="terrain")
fig.colorbar(im, ax=axes[0, 0], label="height [µm]")
axes[0, 0].set(title="initial surface heights")
im = axes[0, 1].imshow(main_run.depth * 1e6, extent=ext, origin="lower", cmap="viridis")
fig.colorbar(im, ax=axes[0, 1], label="wear depth [µm]")
axes[0, 1].set(title=f"wear depth after S = {S * 1e3:.0f} mm")
for ax, title, pressure in ((axes[1, 0], "initial", initial.pressure),
                            (axes[1, 1], f"after S = {S * 1e3:.0f} mm", main_run.pressure)):
    im = ax.imshow(pressure / 1e6, extent=ext, origin="lower", cmap="inferno")
    fig.colorbar(im, ax=ax, label="p [MPa]")
    ax.set(title=f"contact pressure, {title}")
for ax in axes.flat:
    ax.set(xlabel="x [mm]", ylabel="y [mm]")
fig.tight_layout()
png2 = out / "wear_surfaces.png"
fig.savefig(png2, dpi=110)
plt.close(fig)
print(f"wrote {png.resolve()}\nwrote {png2.resolve()}")
print(f"wall time {time.perf_counter() - t0:.1f} s")

# ## The numbers to check
# The worn volume against Archard's law summed over the patch and the steps, W = k_w μ p A0 S
# (thesis §3.4, Eq. 3.10): the ratio is 1 to round-off for every N. The initial real area: the thesis
# starts from about 1 % (§3.5.1, Fig. 3.3); here 0.61 %. At k_w = 1e-10 (2026-12-06): 10.2 % after
# 10 mm with N = 200, 15.5 % with N = 300 and 400 (Fig. 3.3: N = 200 under-estimates, N >= 300
# converged, 13 %); at the thesis' 1e-12 not reachable (see the mass balance above).
archard = args.kw * MU * P * area * S
print(f"worn volume / (k_w mu p A0 S) = {h.volume[-1] / archard:.6f} after N = {args.steps} steps "
      f"(Archard, thesis Eq. 3.10: 1); initial A/A0 = {h.area_fraction[0] * 100:.2f} % (thesis: about 1 %)")

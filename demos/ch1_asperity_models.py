# # Four asperity models against the FFT-BEM (thesis ch. 1, Figs. 1.7 and 1.9)
#
# A rough surface is a set of asperities; each summit is a paraboloid with the curvatures of the
# surface there, pressed as a Hertz contact (thesis §1.2.1, Eq. 1.1). The four models of §1.2.2 differ
# in two hypotheses: the contact of a summit is elliptic or circular, and the summits interact
# through the elastic half-space (the displacement one contact causes under the others, Eq. 1.23)
# or not (Greenwood–Williamson, Bush et al.):
#
# 1. elliptic, with interaction;   2. circular, with interaction;
# 3. elliptic, no interaction;     4. circular, no interaction.
#
# We press a Set-1 and a Set-2 surface of Table 1.1 (H = 0.95, 1 mm patch, cut-offs 2–10, resp. 7 x 12
# wavelengths; E = 4 GPa, ν = 0.15 on a rigid flat) with each model and, for reference, with the
# FFT-BEM on the whole height field (the isolated-patch solver, zero-padded: the same half-space
# setting as the asperity sums). The figure has the curves of Figs. 1.7 and 1.9: mean pressure against
# approach (i) and against the separation g_n of Eq. 1.9 (ii), real area against mean pressure (iii),
# κ against the area fraction (iv), plus the wall time of each model's whole curve, so that the
# accuracy–time trade-off is visible.
#
# Where we differ from the thesis (a user trial, 2026-12-06, default run): our Set-2 surface is
# anisotropic in curvature (1.46 x along one axis) but its summits are no more eccentric than Set 1's
# (mean eccentricity 0.79 against 0.80), so its elliptic and circular curves lie on top of each other,
# where Fig. 1.9 finds the elliptic hypothesis "remarkable" for Set 2; the FFT-BEM reference gives
# kappa 3.06 / 2.97 (Sets 1 / 2) at 1.5-5 % area where the thesis has about 2.2 (Bush et al. 2.51: the
# 128² grid resolves the small contact spots coarsely, which raises kappa); the Nayak parameters are
# 3.72 / 3.64 against the thesis' 2.6 / 3.
#
#     .venv/bin/python demos/ch1_asperity_models.py                     # the thesis' 1 mm patch
#     .venv/bin/python demos/ch1_asperity_models.py --size 2 --seed 3   # 2 mm, same spectrum per mm
#
# (`--size` in mm keeps the Table 1.1 spectrum per mm: 1 is the thesis patch, about 25 summits.)

import argparse
import time
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from multiscale.micro.asperity import AsperityModel
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import fractal_surface, statistics

from demo_output import add_out

matplotlib.use("Agg")  # PNG files only, no display

parser = argparse.ArgumentParser(description="The four asperity models of thesis ch. 1 against the FFT-BEM")
parser.add_argument("--size", type=float, default=1.0, help="patch size [mm] (Table 1.1 spectrum per mm)")
parser.add_argument("--seed", type=int, default=1)
add_out(parser, __file__)
args = parser.parse_args()
out = Path(args.out)

# ## The surfaces (thesis §1.3.1, Table 1.1)
# Upper cut-off k_max in wavelengths per mm: the same in both directions for Set 1; for Set 2,
# 7 along x and 12 along y, which makes the summits strongly eccentric. Lower cut-off 2 per mm,
# Hurst exponent 0.95, RMS height 5 µm, 128 grid points per mm.
TABLE_1_1 = {"Set 1": 10, "Set 2": (7, 12)}
surfaces = {name: fractal_surface(int(128 * args.size), args.size * 1e-3, 0.95, 2 * args.size,
                                  np.multiply(k_max, args.size), 5e-6, seed=args.seed)
            for name, k_max in TABLE_1_1.items()}

# ## The solid and the four models (thesis §1.2.2)
# The pad material (E = 4 GPa, ν = 0.15) against a rigid flat. Each model is built on the summits
# of the surface: local maxima over their eight neighbours, with the principal curvatures of the
# finite-difference Hessian there (§1.3.1). Colour: contact shape; line style: interaction.
SOLID = HalfSpace.from_materials(4e9, 0.15)
MODELS = [("(1) elliptic, interaction", "elliptic", True, "C0", "-"),
          ("(2) circular, interaction", "circular", True, "C1", "-"),
          ("(3) elliptic, no interaction", "elliptic", False, "C0", "--"),
          ("(4) circular, no interaction", "circular", False, "C1", "--")]

# ## Press each surface with every model, then with the FFT-BEM
# The rigid flat comes down by 14 approaches δ from 5 % to 90 % of the highest summit's height
# above the mean plane; the separation (ii) is then (max h − mean h) − δ for the FFT-BEM. κ is the
# coefficient of A/A0 = κ p_n / (E* sqrt(<|∇h|²>)) (§1.3.2).
sets = {}
for name, surface in surfaces.items():
    st = statistics(surface)
    top = surface.heights.max() - surface.heights.mean()
    deltas = np.linspace(0.05, 0.9, 14) * top
    curves = {}
    for label, shape, inter, *_ in MODELS:
        model = AsperityModel.from_surface(surface, SOLID, shape, interaction=inter)
        curves[label] = model.curve(deltas)
    solver = ContactSolver(SOLID, surface.shape, surface.dx, periodic=False)
    t0 = time.perf_counter()
    bem = solver.solve(np.broadcast_to(surface.heights, (len(deltas),) + surface.shape), approach=deltas)
    t_bem = time.perf_counter() - t0
    touching = bem.mean_pressure > 0
    kappa_bem = np.where(touching, bem.area_fraction * SOLID.E_star * float(st.rms_slope) /
                         np.where(touching, bem.mean_pressure, 1), np.nan)
    sets[name] = dict(stats=st, deltas=deltas, curves=curves, bem=bem, t_bem=t_bem, kappa_bem=kappa_bem,
                      gap=top - deltas)

    table = model.table
    print(f"{name}: {args.size:g} mm patch, {len(table)} summits, mean eccentricity "
          f"{table.eccentricity.mean():.2f}, rms slope {st.rms_slope:.3f}, Nayak {st.nayak:.2f}")
    for label, c in curves.items():
        print(f"  {label:30s} {c.wall_time:7.3f} s   F(top) = {c.force[-1]:8.3f} N   "
              f"A/A0(top) = {c.area_fraction[-1]:.4f}")
    print(f"  {'FFT-BEM (isolated patch)':30s} {t_bem:7.3f} s   F(top) = {bem.force[-1]:8.3f} N   "
          f"A/A0(top) = {bem.area_fraction[-1]:.4f}")

# ## Figure: one row per set, the four panels of Figs. 1.7 / 1.9 and the wall times
# The grey band of (iv) is the range 1.5–5 % of area fraction where the thesis reads κ.
out.mkdir(parents=True, exist_ok=True)
fig, axes = plt.subplots(len(sets), 5, figsize=(22, 4.4 * len(sets)), squeeze=False)
for row, (name, d) in zip(axes, sets.items()):
    bem = d["bem"]
    for (label, c), (_, _, _, colour, ls) in zip(d["curves"].items(), MODELS):
        row[0].plot(c.approach * 1e6, c.mean_pressure / 1e6, ls, color=colour, label=label)
        row[1].semilogy(c.mean_gap * 1e6, np.maximum(c.mean_pressure, 1e-3) / 1e6, ls, color=colour)
        row[2].plot(c.mean_pressure / 1e6, c.area_fraction * 100, ls, color=colour)
        row[3].plot(c.area_fraction * 100, c.kappa, ls, color=colour)
    row[0].plot(d["deltas"] * 1e6, bem.mean_pressure / 1e6, "k.-", label="FFT-BEM")
    row[1].semilogy(d["gap"] * 1e6, np.maximum(bem.mean_pressure, 1e-3) / 1e6, "k.-")
    row[2].plot(bem.mean_pressure / 1e6, bem.area_fraction * 100, "k.-")
    row[3].plot(bem.area_fraction * 100, d["kappa_bem"], "k.-")
    labels = [m[0].split(")")[0] + ")" for m in MODELS] + ["BEM"]
    times = [c.wall_time for c in d["curves"].values()] + [d["t_bem"]]
    row[4].bar(labels, times, color=["C0", "C1", "C0", "C1", "k"], alpha=0.8)
    row[4].set_yscale("log")
    row[0].set(title=f"{name} (i)", xlabel="approach δ [µm]", ylabel="mean pressure [MPa]")
    row[1].set(title="(ii)", xlabel="separation g_n [µm]", ylabel="mean pressure [MPa]")
    row[2].set(title="(iii)", xlabel="mean pressure [MPa]", ylabel="A/A0 [%]")
    row[3].set(title="(iv) κ = (A/A0) E* |∇h| / p", xlabel="A/A0 [%]", ylabel="κ [-]", ylim=(0, 5))
    row[3].axvspan(1.5, 5, color="0.9")
    row[4].set(title=f"wall time of the {len(d['deltas'])}-step curve", ylabel="wall time [s]")
    row[0].legend(fontsize=8)
fig.tight_layout()
path = out / "ch1_asperity_models.png"
fig.savefig(path, dpi=110)
plt.close(fig)
print(f"wrote {path}")

# ## The numbers to check
# κ averaged over the grey band (1.5 % <= A/A0 <= 5 %), model (1) and FFT-BEM. Thesis §1.3.2: for
# Set 1, κ ≈ 2.2 once A/A0 > 1.5 % (Fig. 1.7 iv; Bush et al.: 2.5); for Set 2 the elliptic models give
# 2 to 3 (Fig. 1.9 iv). The thesis' surfaces have a Nayak parameter of 2.6 (Set 1) and 3 (Set 2).
band = (1.5e-2, 5e-2)
for name, d in sets.items():
    c1, bem = d["curves"][MODELS[0][0]], d["bem"]
    in_1 = (c1.area_fraction >= band[0]) & (c1.area_fraction <= band[1])
    in_bem = (bem.area_fraction >= band[0]) & (bem.area_fraction <= band[1])
    print(f"{name}: kappa for 1.5 % <= A/A0 <= 5 %: model (1) {np.mean(c1.kappa[in_1]):.2f}, "
          f"FFT-BEM {np.mean(d['kappa_bem'][in_bem]):.2f}   (thesis: "
          f"{'about 2.2' if name == 'Set 1' else '2 to 3'}); Nayak {d['stats'].nayak:.2f} "
          f"(thesis: {'2.6' if name == 'Set 1' else '3'})")

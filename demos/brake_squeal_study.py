# # Squeal of a disc brake with rough pads (thesis §4.4, Table 4.1)
#
# Perfect pad–disc contact against the rough cases 0–5 of Table 4.1: both pads rough with the R_q
# of the case (same statistics, different realisations), the disc flat. Every case shares the mesh
# and loading of the scene `demos/brake_squeal.toml`; a rough case embeds per-zone pressure–gap laws
# (FFT-BEM on each zone's patch) in the contact form. We compare the unstable modes (Figs. 4.13–4.14),
# how the rough modes correlate with the perfect-contact ones (MAC, MMAC: Figs. 4.16–4.19), the
# contact pressure (Fig. 4.12) and the strain energy per component (Figs. 4.20–4.21).
#
#     mpiexec -n 2 .venv/bin/python demos/brake_squeal_study.py                       # all 7 cases
#     .venv/bin/python demos/brake_squeal_study.py --cases perfect 5 0 --modes 40 --mesh-size "20 mm"

import argparse
import csv
from pathlib import Path

from mpi4py import MPI

from multiscale import io
from multiscale.macro.modal import cumulative_moving_average, mac_matrix, mmac
from multiscale.plots.squeal import plot_energy, plot_mac, plot_mode_curves, plot_pressure, plot_re_im, \
    plot_unstable_bars
from multiscale.scene import load
from multiscale.workflows.model import build_mesh
from multiscale.workflows.squeal import analyse, energy_split

from demo_output import ROOT, add_out

parser = argparse.ArgumentParser(description="Squeal of a disc brake with the rough pads of thesis Table 4.1")
parser.add_argument("--cases", nargs="+", default=["perfect", "0", "1", "2", "3", "4", "5"],
                    choices=["perfect", "0", "1", "2", "3", "4", "5"], help='"perfect" and/or Table 4.1 cases')
parser.add_argument("--mesh-size", help='geometry.mesh_size, e.g. "20 mm"')
parser.add_argument("--modes", type=int, help="stability.modes")
parser.add_argument("--seed", type=int, default=0, help="seed of the pad surfaces")
add_out(parser, __file__)
args = parser.parse_args()
comm = MPI.COMM_WORLD
io.abort_on_exception(comm)
out = Path(args.out)

# ## The cases
# R_q and sigma [m] of the pad surfaces of Table 4.1 (case 0 roughest, case 5 smoothest). The thesis
# gives R_q only; our surface model: fractal, Hurst 0.8, wavelengths from a zone (about 10 mm) down to
# 1/16 of it, 12 x 5 zones of 32 x 32 cells over each pad.
TABLE_4_1 = {0: (11.8e-6, 5.5e-6), 1: (5.7e-6, 2.7e-6), 2: (4.9e-6, 2.3e-6), 3: (4.3e-6, 2.0e-6),
             4: (3.9e-6, 1.8e-6), 5: (3.5e-6, 1.6e-6)}
base = {"output.folder": str(out)}
if args.mesh_size:
    base["geometry.mesh_size"] = args.mesh_size
if args.modes:
    base["stability.modes"] = args.modes


def rough_overrides(case: int) -> dict:
    return {**base, "effects": ["contact", "friction", "stability", "roughness"], "roughness.body": "brake",
            "roughness.rms": TABLE_4_1[case][0], "roughness.hurst": 0.8, "roughness.k_min": 1,
            "roughness.k_max": 16, "roughness.patch": "zone", "roughness.seed": args.seed + 101 * case,
            "micro.zones": [12, 5], "micro.grid": [32, 32]}


scenes = {name: load(ROOT / "demos" / "brake_squeal.toml", base if name == "perfect" else rough_overrides(int(name)))
          for name in args.cases}

# ## Mesh and analyses
# One mesh for every case, so that the modes share their dof layout and can be correlated.
tm = build_mesh(scenes[args.cases[0]], comm)
cases = {}
for name in io.progress(args.cases, comm, desc="squeal cases", unit="case"):
    label = "perfect" if name == "perfect" else f"case {name}"
    cases[label] = analyse(scenes[name], tm, name=label)

# ## Correlation with the perfect contact (collective)
ref = cases.get("perfect")
macs = {} if ref is None else {name: mac_matrix(ref.modes, c.modes) for name, c in cases.items() if c is not ref}

# ## Figures and tables (rank 0)
if comm.rank == 0:
    out.mkdir(parents=True, exist_ok=True)
    masks, split = tm.interface.masks(), energy_split(tm)
    for name, case in cases.items():
        slug = name.replace(" ", "")
        case.modes.write_csv(out / f"modes_{slug}.csv", case.report.rtol, case.report.potentially_unstable,
                             partner=case.report.flutter_partner)
        plot_pressure(tm.interface.midpoints, masks, case.facet_pressure, name, out / f"fig4_12_pressure_{slug}.png")
        plot_energy(case, out / f"fig4_20_energy_{slug}.png", split)
    plot_re_im(list(cases.values()), out / "fig4_13_re_im.png")
    plot_unstable_bars(cases, out / "fig4_14_unstable.png")
    for name, fig in (("case 5", "fig4_16"), ("case 0", "fig4_17")):
        if name in macs:
            plot_mac(macs[name], f"perfect contact vs {name}", out / f"{fig}_mac_{name.replace(' ', '')}.png")
    if macs:
        best = {name: mmac(mac) for name, mac in macs.items()}
        plot_mode_curves(best, "MMAC", out / "fig4_18_mmac.png")
        plot_mode_curves({k: cumulative_moving_average(v) for k, v in best.items()}, "cumulative mean MMAC",
                         out / "fig4_19_cumulative.png")
    with open(out / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "R_q_um", "modes", "f_max_Hz", "unstable", "unstable_Hz", "potentially_unstable",
                    "max_pressure_MPa", "mean_MMAC_first20", "preload_s", "modes_s"])
        for name, c in cases.items():
            rq = "" if name == "perfect" else f"{TABLE_4_1[int(name.split()[1])][0] * 1e6:g}"
            mm = f"{mmac(macs[name])[:20].mean():.3f}" if name in macs else ""
            w.writerow([name, rq, len(c.modes), f"{c.modes.frequency.max():.0f}", c.report.unstable.size,
                        " ".join(f"{f:.0f}" for f in c.report.frequency[c.report.unstable - 1]),
                        c.report.potentially_unstable.size, f"{c.facet_pressure.max() / 1e6:.3f}", mm,
                        f"{c.preload.time:.1f}", f"{c.modes.time:.1f}"])

# ## The numbers to check
# Unstable frequencies per case (the perfect contact of the demo scene has two near 3.4 and 12.4 kHz).
if comm.rank == 0:
    for name, c in cases.items():
        print(f"{name:>8}: {len(c.modes)} modes, unstable at "
              f"{', '.join(f'{f:.0f}' for f in c.report.frequency[c.report.unstable - 1]) or '-'} Hz")
    print(f"results in {out}")

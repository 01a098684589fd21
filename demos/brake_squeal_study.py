"""Parametric squeal study of thesis §4.4: perfect pad–disc contact and the rough cases 0–5 of Table 4.1.

    mpiexec -n 2 .venv/bin/python demos/brake_squeal_study.py                  # all 7 cases
    .venv/bin/python demos/brake_squeal_study.py --cases perfect 5 0 --modes 40 --mesh-size "20 mm"

Every case shares the mesh of ``--scene`` (default demos/brake_squeal.toml) and its loading; a rough
case embeds per-zone pressure–gap laws of two pad surfaces with the R_q of Table 4.1 (both pads
rough with the same statistics, different realisations; the disc flat). Writes under ``--out``:
mode tables ``modes_<case>.csv``, ``summary.csv`` and the figures ``fig4_12_pressure_<case>.png``,
``fig4_13_re_im.png``, ``fig4_14_unstable.png``, ``fig4_16_mac_case5.png``, ``fig4_17_mac_case0.png``,
``fig4_18_mmac.png``, ``fig4_19_cumulative.png``, ``fig4_20_energy_<case>.png`` (with Fig. 4.21's
pad split).
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mpi4py import MPI  # noqa: E402

from multiscale import io  # noqa: E402
from multiscale.macro import mesh as two_body  # noqa: E402
from multiscale.macro import stability as st  # noqa: E402
from multiscale.scene import load  # noqa: E402

# Surface model of the pads (ours: the thesis gives R_q and sigma only): fractal, Hurst 0.8,
# wavelengths from a zone down to 1/16 of it, zones of about 10 mm, 32 x 32 cells per zone.
ROUGH = dict(hurst=0.8, k_min=(1.0, 1.0), k_max=(16.0, 16.0), zones=(12, 5), grid=32)


def parse(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(ROOT / "demos" / "brake_squeal.toml"))
    ap.add_argument("--cases", nargs="+", default=["perfect", "0", "1", "2", "3", "4", "5"],
                    help='"perfect" and/or Table 4.1 case numbers 0-5')
    ap.add_argument("--mesh-size", help='override geometry.mesh_size, e.g. "20 mm"')
    ap.add_argument("--modes", type=int, help="override stability.modes")
    ap.add_argument("--degree", type=int, default=st.SQUEAL_DEGREE, help="Lagrange degree")
    ap.add_argument("--seed", type=int, default=0, help="seed of the pad surfaces")
    ap.add_argument("--out", default=str(ROOT / "results" / "brake_squeal_study"))
    args = ap.parse_args(argv)
    for c in args.cases:
        if c != "perfect" and (not c.isdigit() or int(c) not in st.TABLE_4_1):
            ap.error(f"--cases: {c!r} is not 'perfect' or a Table 4.1 case (0-5)")
    return args


def run_cases(args, comm):
    overrides = {}
    if args.mesh_size:
        overrides["geometry.mesh_size"] = args.mesh_size
    if args.modes:
        overrides["stability.modes"] = args.modes
    scene = load(args.scene, overrides)
    tm = two_body.build(scene.geometry.builder, dict(scene.geometry.params), comm)
    cases = {}
    for c in io.progress(args.cases, comm, desc="squeal cases", unit="case"):
        if c == "perfect":
            cases["perfect"] = st.analyse(scene, tm, name="perfect", degree=args.degree)
        else:
            rq, _ = st.TABLE_4_1[int(c)]
            rough = st.PadRoughness(rq, seed=args.seed + 101 * int(c), **ROUGH)
            cases[f"case {c}"] = st.analyse(scene, tm, name=f"case {c}", roughness=rough, degree=args.degree)
    return scene, tm, cases


def correlations(cases: dict) -> dict:
    """MAC of every rough case against the perfect contact (collective: every rank calls it)."""
    ref = cases.get("perfect")
    return {} if ref is None else {name: st.mac_matrix(ref.modes, c.modes)
                                   for name, c in cases.items() if c is not ref}


def figures(tm, masks: dict, cases: dict, macs: dict, out: Path) -> list[Path]:
    """Figures 4.12–4.21 and the tables (rank 0; the collective parts are computed before)."""
    files = []
    for name, case in cases.items():
        slug = name.replace(" ", "")
        files.append(case.modes.write_csv(out / f"modes_{slug}.csv"))
        files.append(st.plot_pressure(tm.interface.midpoints, masks, case, out / f"fig4_12_pressure_{slug}.png"))
        files.append(st.plot_energy(case, out / f"fig4_20_energy_{slug}.png"))
    files.append(st.plot_re_im(list(cases.values()), out / "fig4_13_re_im.png"))
    files.append(plot_unstable_bars(cases, out / "fig4_14_unstable.png"))
    for name, fig in (("case 5", "fig4_16"), ("case 0", "fig4_17")):
        if name in macs:
            files.append(plot_mac(macs[name], f"perfect contact vs {name}", out / f"{fig}_mac_{name.replace(' ', '')}.png"))
    if macs:
        files += plot_mmac({name: st.mmac(mac) for name, mac in macs.items()},
                           out / "fig4_18_mmac.png", out / "fig4_19_cumulative.png")
    files.append(write_summary(cases, macs, out / "summary.csv"))
    return files


def plot_unstable_bars(cases: dict, path) -> Path:
    """Unstable (full) and potentially unstable (hatched) modes per case against mode number (Fig. 4.14)."""
    plt, (fig, ax) = st._figure(figsize=(9, 0.6 * len(cases) + 1.5))
    for row, (name, case) in enumerate(cases.items()):
        rep = case.report
        ax.bar(rep.unstable, 0.8, bottom=row - 0.4, width=0.8, color=f"C{row}")
        ax.bar(rep.potentially_unstable, 0.8, bottom=row - 0.4, width=0.8, fill=False, hatch="///",
               edgecolor=f"C{row}")
    ax.set_yticks(range(len(cases)), list(cases))
    ax.set_xlim(0.5, max(len(c.modes) for c in cases.values()) + 0.5)
    ax.set(xlabel="mode number", title="unstable (full) and potentially unstable (hatched) modes")
    return st._save(plt, fig, path)


def plot_mac(mac: np.ndarray, title: str, path) -> Path:
    """MAC matrix between two cases (Figs. 4.16–4.17)."""
    plt, (fig, ax) = st._figure(figsize=(5.5, 4.8))
    art = ax.imshow(mac, origin="lower", vmin=0, vmax=1, cmap="viridis",
                    extent=(0.5, mac.shape[1] + 0.5, 0.5, mac.shape[0] + 0.5))
    fig.colorbar(art, ax=ax, label="MAC")
    ax.set(title=title, xlabel="mode (rough case)", ylabel="mode (perfect contact)")
    return st._save(plt, fig, path)


def plot_mmac(mmacs: dict, path, cumulative_path) -> list[Path]:
    """MMAC per mode against the perfect contact (Fig. 4.18) and its cumulative average (Fig. 4.19)."""
    out = []
    for p, transform, label in ((path, lambda x: x, "MMAC"),
                                (cumulative_path, st.cumulative_moving_average, "cumulative mean MMAC")):
        plt, (fig, ax) = st._figure(figsize=(8, 4))
        for name, m in mmacs.items():
            ax.plot(np.arange(1, len(m) + 1), transform(m), "-o", ms=2.5, label=name)
        ax.set(xlabel="mode of the perfect-contact model", ylabel=label, ylim=(0, 1.02))
        ax.legend(fontsize=7)
        out.append(st._save(plt, fig, p))
    return out


def write_summary(cases: dict, macs: dict, path) -> Path:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "R_q_um", "modes", "f_max_Hz", "unstable", "unstable_Hz", "potentially_unstable",
                    "max_pressure_MPa", "mean_MMAC_first20", "law_linearisations", "preload_s", "modes_s"])
        for name, c in cases.items():
            rq = "" if name == "perfect" else f"{st.TABLE_4_1[int(name.split()[1])][0] * 1e6:g}"
            mm = f"{st.mmac(macs[name])[:20].mean():.3f}" if name in macs else ""
            w.writerow([name, rq, len(c.modes), f"{c.modes.frequency.max():.0f}", c.report.unstable.size,
                        " ".join(f"{f:.0f}" for f in c.report.frequency[c.report.unstable - 1]),
                        c.report.potentially_unstable.size, f"{c.facet_pressure.max() / 1e6:.3f}", mm,
                        getattr(c.preload, "law_iterations", ""), f"{c.preload.time:.1f}", f"{c.modes.time:.1f}"])
    return Path(path)


def main(argv=None) -> int:
    args = parse(argv)
    comm = MPI.COMM_WORLD
    io.abort_on_exception(comm)
    out = Path(args.out)
    _, tm, cases = run_cases(args, comm)
    masks, macs = st.interface_facets(tm), correlations(cases)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        files = figures(tm, masks, cases, macs, out)
        for name, c in cases.items():
            print(f"{name:>8}: {len(c.modes)} modes, unstable at "
                  f"{', '.join(f'{f:.0f}' for f in c.report.frequency[c.report.unstable - 1]) or '-'} Hz")
        print(f"{len(files)} files in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

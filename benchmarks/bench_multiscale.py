"""The thesis ch. 7 multiscale pin-on-disc end to end (issue 9), beside the thesis' results.

Runs ``demos/pin_on_disc_thesis.toml`` (Table 7.1: 400 zones of 50 x 50 cells, 50 steps over 30 s,
200 N, 200 rpm, mu 0.4) and its perfect-contact counterpart (the same scene without roughness and
wear, penalty 1e13 Pa/m, the thesis' constant 14 % partition), then prints the wall times and the
§7.3.2 quantities next to the thesis' values and stores them in results/bench_pin_on_disc.json.

    mpiexec -n 2 python benchmarks/bench_multiscale.py              # both runs (target < 1 h)
    mpiexec -n 2 python benchmarks/bench_multiscale.py --reuse      # tabulate finished runs
    mpiexec -n 2 python benchmarks/bench_multiscale.py --steps 5    # a quick partial check
    mpiexec -n 2 python benchmarks/bench_multiscale.py --hardness "176 MPa"   # + elastic-plastic pin
With ``--hardness`` a third run adds the effect ``plasticity`` with that pin hardness (issue 18)
and the table gets a column for it.
(``python benchmarks/bench_pin_on_disc.py`` times ``make demo``: the coarse multiscale demo.)
"""
import argparse
import json
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from multiscale.io import History  # noqa: E402
from multiscale.workflows import run  # noqa: E402
from multiscale.scene import load  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "demos" / "pin_on_disc_thesis.toml"
RESULTS = ROOT / "results" / "bench_multiscale.json"
THESIS = {  # §7.3.2, Figs. 7.10-7.18
    "max zone pressure first -> last [MPa]": "6 -> 2.73",
    "max pin temperature, embedded [degC]": "~50",
    "max pin temperature, perfect 14 % [degC]": "64",
    "partition into the pin: mean (min-max) [%]": "14 (10-21)",
    "max wear depth [um]": "28",
    "wear volume [um^3]": "3.8e7",
    "RMS reduction [um]": "~0.2",
    "wall time": "~6 days on 80 cores",
}


def _run(scene, reuse: bool):
    history_file = Path(scene.output.folder) / "history.h5"
    if reuse and history_file.exists():
        return History.read(history_file), None
    t0 = time.perf_counter()
    result = run(scene, overwrite=True, verbose=MPI.COMM_WORLD.rank == 0)
    return result.history, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, help="only the first N macro steps (0.6 s each)")
    ap.add_argument("--reuse", action="store_true", help="tabulate runs already in their output folders")
    ap.add_argument("--hardness", help='pin hardness of a third, elastic-plastic run, e.g. "176 MPa"')
    args = ap.parse_args()
    over = {} if args.steps is None else {"time.steps": args.steps, "time.end": 0.6 * args.steps}
    rough_scene = load(SCENE, overrides=over)
    perfect_over = dict(over, **{"effects": ["contact", "friction", "thermal", "heat_partition", "expansion"],
                                 "interface.penalty": "1e13 Pa/m", "name": "pin_on_disc_thesis_perfect",
                                 "output.folder": str(ROOT / "results" / "pin_on_disc_thesis_perfect")})
    perfect_scene = load(SCENE, overrides=perfect_over)
    runs = {"ours": _run(rough_scene, args.reuse)}
    perfect, perfect_wall = _run(perfect_scene, args.reuse)
    if args.hardness:
        plastic_over = dict(over, **{"effects": [*rough_scene.effects, "plasticity"],
                                     "materials.pin.hardness": args.hardness, "name": "pin_on_disc_thesis_plastic",
                                     "output.folder": str(ROOT / "results" / "pin_on_disc_thesis_plastic")})
        runs[f"plastic, H = {args.hardness}"] = _run(load(SCENE, overrides=plastic_over), args.reuse)
    if MPI.COMM_WORLD.rank:
        return
    columns = {name: _quantities(rough, wall, perfect, perfect_wall) for name, (rough, wall) in runs.items()}
    names = list(columns)
    print(f"\n| quantity | thesis | {' | '.join(f'{n} ({len(runs[n][0]) - 1} steps)' for n in names)} |")
    print("|---|---|" + "---|" * len(names))
    for key in dict.fromkeys(k for n in names for k in columns[n]):
        print(f"| {key} | {THESIS.get(key, '')} | {' | '.join(columns[n].get(key, '') for n in names)} |")
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps({"date": time.strftime("%Y-%m-%d"), "ranks": MPI.COMM_WORLD.size,
                                   "columns": columns, "thesis": THESIS}, indent=1))


def _quantities(rough: History, rough_wall, perfect: History, perfect_wall) -> dict:
    """The §7.3.2 quantities of a rough run (and the perfect-contact run), as table cells."""
    c = lambda T: T - 273.15  # noqa: E731
    loaded = rough["time"] > 0
    ours = {
        "max zone pressure first -> last [MPa]": f"{rough['max_zone_pressure'][0] / 1e6:.3g} -> "
                                                 f"{rough['max_zone_pressure'][-1] / 1e6:.3g}",
        "max pin temperature, embedded [degC]": f"{c(rough['max_temperature_pin'].max()):.1f}",
        "max pin temperature, perfect 14 % [degC]": f"{c(perfect['max_temperature_pin'].max()):.1f}",
        "partition into the pin: mean (min-max) [%]": f"{100 * rough['partition_mean'][loaded].mean():.1f} "
                                                      f"({100 * rough['partition_min'][loaded].min():.1f}-"
                                                      f"{100 * rough['partition_max'][loaded].max():.1f})",
        "max wear depth [um]": f"{rough['wear_max_depth'][-1] * 1e6:.3g}",
        "wear volume [um^3]": f"{rough['wear_volume'][-1] * 1e18:.3g}",
        "RMS reduction [um]": f"{(rough['rms_height'][0] - rough['rms_height'][-1]) * 1e6:.3g}",
        "wall time": (f"{rough_wall:.0f} s (perfect: {perfect_wall:.0f} s) on {MPI.COMM_WORLD.size} rank(s)"
                      if rough_wall is not None else "reused"),
    }
    extra = {"macro facet max pressure first -> last [MPa]": f"{rough['max_pressure'][0] / 1e6:.3g} -> "
                                                            f"{rough['max_pressure'][-1] / 1e6:.3g}",
             "micro max pressure first -> last [MPa]": f"{rough['micro_max_pressure'][0] / 1e6:.4g} -> "
                                                       f"{rough['micro_max_pressure'][-1] / 1e6:.4g}",
             "micro max temperature [degC]": f"{c(np.nanmax(rough['micro_max_temperature'])):.1f}",
             "zones in contact first -> last": f"{rough['zones_in_contact'][0]:.0f} -> "
                                               f"{rough['zones_in_contact'][-1]:.0f}",
             "time per step: macro / micro / laws [s]": " / ".join(
                 f"{np.median(rough[k][1:]):.1f}" for k in ("time_macro", "time_micro", "time_laws")),
             "initial laws [s]": f"{rough['time_laws'][0]:.1f}"}
    if "real_contact_area" in rough.columns:
        area = rough["real_contact_area"]
        extra["real contact area first -> last [mm^2]"] = f"{area[0] * 1e6:.3g} -> {area[-1] * 1e6:.3g}"
    if "micro_plastic_fraction" in rough.columns:
        extra["largest plastic share of a zone first -> last"] = (f"{rough['micro_plastic_fraction'][0]:.3g} -> "
                                                                  f"{rough['micro_plastic_fraction'][-1]:.3g}")
        extra["largest permanent deformation [um]"] = f"{rough['plastic_max_depth'][-1] * 1e6:.3g}"
    return ours | extra


if __name__ == "__main__":
    main()

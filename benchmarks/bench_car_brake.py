"""Car-brake stop benchmark (issue 16): the STEP brake of ``demos/car_brake_stop.toml`` meshed for at
least 100 000 displacement dofs, a stop from 100 km/h in 20 time steps with convection and
radiation. Target: under 10 minutes on 2 cores. Prints the dofs, the wall time of every stage
(reading and meshing, forms, first solve, the 20 steps split into heat and contact solves, output)
and the time per step.

    .venv/bin/python demos/cad_models.py                         # the STEP files (once)
    .venv/bin/mpiexec -n 2 .venv/bin/python benchmarks/bench_car_brake.py
    .venv/bin/python benchmarks/bench_car_brake.py --mesh-size "7 mm"   # a quick look
"""
from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

from mpi4py import MPI

from multiscale.macro.output import FieldOutput
from multiscale.scene import load
from multiscale.workflows.model import build_mesh, build_model

ROOT = Path(__file__).resolve().parents[1]
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--mesh-size", default="3.5 mm", help="geometry.mesh_size")
parser.add_argument("--interface-mesh-size", default="2.5 mm", help="geometry.interface_mesh_size")
parser.add_argument("--out", default=str(ROOT / "results" / "bench_car_brake"))
args = parser.parse_args()
comm = MPI.COMM_WORLD
if not (ROOT / "demos" / "cad" / "car_brake.step").exists():
    raise SystemExit("run .venv/bin/python demos/cad_models.py first (it writes demos/cad/car_brake.step)")

stages = {}
t0 = time.perf_counter()
scene = load(ROOT / "demos" / "car_brake_stop.toml", {
    "geometry.mesh_size": args.mesh_size, "geometry.interface_mesh_size": args.interface_mesh_size,
    "output.folder": args.out})
tm = build_mesh(scene, comm)
stages["read and mesh"] = time.perf_counter() - t0
t0 = time.perf_counter()
model = build_model(scene, comm, tm=tm)
dofs = sum(V.dofmap.index_map.size_global * V.dofmap.index_map_bs for V in model.mechanics.spaces)
temperature_dofs = sum(T.function_space.dofmap.index_map.size_global for T in model.thermal.T)
stages["forms"] = time.perf_counter() - t0
t0 = time.perf_counter()
model.start()
stages["first solve"] = time.perf_counter() - t0

heat_times = []
step_heat = model.thermal.step


def timed_heat(dt):
    """The heat step, timed."""
    start = time.perf_counter()
    out = step_heat(dt)
    heat_times.append(time.perf_counter() - start)
    return out


model.thermal.step = timed_heat
Path(args.out).mkdir(parents=True, exist_ok=True)
writer = FieldOutput(model, Path(args.out), scene.output.fields)
step_times, output = [], 0.0
for n in range(1, scene.time.steps + 1):
    t0 = time.perf_counter()
    model.macro_step(scene.time.dt, scene.time.substeps)
    step_times.append(time.perf_counter() - t0)
    if n % scene.output.every == 0:
        t0 = time.perf_counter()
        writer.write()
        output += time.perf_counter() - t0
stages["20 steps: heat solves"] = sum(heat_times)
stages["20 steps: contact solves and the rest"] = sum(step_times) - sum(heat_times)
stages["output (XDMF)"] = output
total = sum(stages.values())
hottest = model.thermal.max_temperature()[1]          # collective: every rank
if comm.rank == 0:
    load1 = os.getloadavg()[0]
    print(f"car-brake stop: {dofs} displacement dofs, {temperature_dofs} temperature dofs, {comm.size} rank(s), "
          f"mesh {args.mesh_size} / {args.interface_mesh_size}; load average {load1:.2f}")
    print("| stage | wall time [s] |\n|---|---|")
    for k, v in stages.items():
        print(f"| {k} | {v:.1f} |")
    print(f"| total | {total:.1f} |")
    print(f"per step: median {statistics.median(step_times):.2f} s, max {max(step_times):.2f} s; "
          f"max disc temperature {hottest - 273.15:.1f} degC; "
          f"heat {sum(model.heat_total) / 1e3:.1f} kJ")

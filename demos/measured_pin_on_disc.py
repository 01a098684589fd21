# # The thesis pin-on-disc with a measured pin face (issue 17)
#
# The coarse multiscale pin-on-disc of thesis ch. 7 twice, alike but for the pin face: the synthetic
# fractal face of the thesis (`demos/pin_on_disc.toml`: RMS 10.35 um, H = 0.6) and a face that is
# statistically equivalent to a real measurement (`demos/pin_on_disc_measured.toml`: the measured PSD
# of a Sensofar confocal map, 1.3 x 1 mm, drawn over the whole 20 mm face). We read and condition the
# measurement, draw its statistics and figure, run both pins and compare what the interface does.
#
#     mpiexec -n 2 .venv/bin/python demos/measured_pin_on_disc.py            # 25 steps of 1.2 s, 2 min
#     .venv/bin/python demos/measured_pin_on_disc.py --file pad.x3p --steps 4

import argparse
from pathlib import Path

import numpy as np
from mpi4py import MPI

from multiscale import io
from multiscale.micro.spectrum import power_spectrum, surface_statistics
from multiscale.micro.topography import condition, read_topography
from multiscale.plots.surface import surface_figure
from multiscale.scene import load
from multiscale.workflows.multiscale import run

from demo_output import ROOT, add_out

SHARED = ROOT.parent / "shared" / "data" / "topographies"        # the shared data beside the repository
parser = argparse.ArgumentParser(description="The thesis pin-on-disc with a measured pin face")
parser.add_argument("--file", default=str(SHARED / "plu-1.plu"), help="the measurement (any SurfaceTopography format)")
parser.add_argument("--steps", type=int, default=25, help="macro steps of 1.2 s (the coarse scenes': 25, 30 s)")
add_out(parser, __file__)
args = parser.parse_args()
comm = MPI.COMM_WORLD
io.abort_on_exception(comm)
out = Path(args.out)

# ## The measurement
# Read in its own units, its tilt removed (the form is the macro model's), its statistics and PSD.
measured = condition(read_topography(args.file))
stats = surface_statistics(measured.surface)
if comm.rank == 0:
    out.mkdir(parents=True, exist_ok=True)
    print("\n".join(measured.report))
    print("\n".join(stats.table()))
    surface_figure(measured.surface, stats, out / "measurement.png", Path(args.file).name)

# ## Both pins
# The same scene but for the face, the same number of steps of 1.2 s. The measured face is drawn
# from the measured PSD on the micro grid (8 x 8 zones of 32 x 32 cells of 78 um): it keeps the
# measured wavelengths from the measurement's period down to two cells.
common = {"time.steps": args.steps, "time.end": 1.2 * args.steps}
scenes = {"synthetic": load(ROOT / "demos" / "pin_on_disc.toml", {**common, "output.folder": str(out / "synthetic")}),
          "measured": load(ROOT / "demos" / "pin_on_disc_measured.toml",
                           {**common, "output.folder": str(out / "measured"), "roughness.file": args.file})}
results = {name: run(scene, overwrite=True, comm=comm) for name, scene in scenes.items()}

# ## The numbers to check
# The measured face keeps the measurement's power in every wavelength the micro grid holds: its RMS
# height equals the measurement's Sq in that band, summed from the measured PSD map (15.12 against
# 15.08 nm of its 18.3 nm, ratio 1.003; the synthetic face: 10.35 um). 700 times smoother, the
# measured pin carries the load on 54 of its 64 zones (the synthetic one on 20), at about 2 MPa
# instead of 8.6, with micro hot spots near 29 degC instead of 49 after 30 s; it wears about as much
# (Archard: the worn volume follows the frictional work, 3.7e7 against 3.8e7 um^3), which roughens it
# (RMS 15 -> 32 nm). Measured 2026-12-06, 2 ranks; its laws reach the floor of micro.laws.resolved_gap
# (warned): the face's stiffness is a lower bound there, its contact area the micro solves'.
if comm.rank == 0:
    m = scenes["measured"]
    face = m.geometry.resolved()["pin_size"]
    cell = face / m.micro.zones[0] / m.micro.grid[0], face / m.micro.zones[1] / m.micro.grid[1]
    sp = power_spectrum(measured.surface)
    My, Mx = sp.map.shape
    qx = np.abs(2 * np.pi * np.fft.fftfreq(Mx, sp.period[0] / Mx))[None, :]
    qy = np.abs(2 * np.pi * np.fft.fftfreq(My, sp.period[1] / My))[:, None]
    band = (qx <= np.pi / cell[0]) & (qy <= np.pi / cell[1]) & (np.hypot(qx, qy) >= 2 * np.pi / face)
    expected = np.sqrt(sp.map[band].sum() / (sp.period[0] * sp.period[1]))
    rows = [("face RMS height [nm]", "rms_height", 1e9, 0), ("zones in contact", "zones_in_contact", 1, 0),
            ("max zone pressure [MPa]", "max_zone_pressure", 1e-6, 0),
            ("max micro pressure [MPa]", "micro_max_pressure", 1e-6, 0),
            ("zones' partition into the pin, mean [%]", "partition_mean", 100, 0),
            ("max pin temperature [degC]", "max_temperature_pin", 1, -273.15),
            ("max micro temperature [degC]", "micro_max_temperature", 1, -273.15),
            ("wear volume [um^3]", "wear_volume", 1e18, 0)]
    print(f"\nafter {1.2 * args.steps:g} s {'synthetic':>14} {'measured':>14}")
    for label, key, scale, shift in rows:
        values = [results[n].history[key][-1] * scale + shift for n in ("synthetic", "measured")]
        print(f"{label:<30} {values[0]:>14.4g} {values[1]:>14.4g}")
    first = results["measured"].history["rms_height"][0]
    print(f"measured face RMS height {first * 1e9:.4g} nm; the measurement's Sq in the band the micro grid "
          f"holds {expected * 1e9:.4g} nm (ratio {first / expected:.4f})")
    print(f"results in {out}")

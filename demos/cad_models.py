# # Two CAD models for the bring-your-own-brake demos
#
# A brake engineer brings a CAD export of their brake. To show the path from such a file to a
# simulation, this script builds two models with gmsh's OpenCASCADE kernel and writes them as STEP
# files, which the scenes then read back exactly as they would read any user's file: no names, no
# mesh, only solids in millimetres.
#
#     .venv/bin/python demos/cad_models.py         # writes demos/cad/car_brake.step, railway_disc.step
#
# Then: `multiscale check demos/car_brake_stop.toml` lists what the file holds (bodies, volumes,
# interfaces with their areas and normals) before anything is meshed.

import argparse
import math
from pathlib import Path

import gmsh

parser = argparse.ArgumentParser(description="Write the two STEP models the CAD demo scenes read (car_brake.step, "
                                 "railway_disc.step)")
parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "cad"),
                    help="folder (default: %(default)s, where the demo scenes read them)")
OUT = Path(parser.parse_args().out)
OUT.mkdir(parents=True, exist_ok=True)
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
occ = gmsh.model.occ


def sector(z0: float, dz: float, r_in: float, r_out: float, angle: float) -> int:
    """An annular sector [mm] centred on +y, from z0 to z0 + dz: a pad or a backplate."""
    outer = occ.addCylinder(0, 0, z0, 0, 0, dz, r_out, angle=angle)
    inner = occ.addCylinder(0, 0, z0, 0, 0, dz, r_in, angle=angle)
    part, _ = occ.cut([(3, outer)], [(3, inner)])
    occ.rotate(part, 0, 0, 0, 0, 0, 1, math.pi / 2 - angle / 2)
    return part[0][1]


# ## A car disc brake: a solid disc and two pads on their backplates
# Solid disc: a ring of 70–140 mm radius, 24 mm thick, its faces at z = 0 and z = 24 mm (the
# mounting bore at r = 70 mm stands for the hat). Pads: 95–135 mm, 60 degrees, 11 mm thick, on
# steel backplates of 92–138 mm, 72 degrees, 6 mm thick; the inner pad (piston side) at z < 0, the
# outer pad (caliper fingers) at z > 24 mm. The parts touch but are separate solids.
gmsh.model.add("car_brake")
ring = occ.addCylinder(0, 0, 0, 0, 0, 24, 140)
bore = occ.addCylinder(0, 0, 0, 0, 0, 24, 70)
occ.cut([(3, ring)], [(3, bore)])
pad, backplate = math.radians(60), math.radians(72)
sector(-11, 11, 95, 135, pad)            # inner pad
sector(-17, 6, 92, 138, backplate)       # inner backplate
sector(24, 11, 95, 135, pad)             # outer pad
sector(35, 6, 92, 138, backplate)        # outer backplate
occ.synchronize()
gmsh.write(str(OUT / "car_brake.step"))

# ## A railway brake disc with sintered pucks
# Railway disc: a ring of 200–320 mm radius, 40 mm thick (faces z = 0 and 40 mm). One brake pad on
# the z > 40 mm side: a steel holder plate (an 80-degree sector, 215–305 mm, 12 mm thick, 10 mm
# above the disc) carrying 9 sintered pucks (cylinders of 12 mm radius, 10 mm high) in three rows,
# each standing on the disc. The pucks are the contact: 9 interfaces.
gmsh.model.add("railway_disc")
ring = occ.addCylinder(0, 0, 0, 0, 0, 40, 320)
bore = occ.addCylinder(0, 0, 0, 0, 0, 40, 200)
occ.cut([(3, ring)], [(3, bore)])
sector(50, 12, 215, 305, math.radians(80))
for radius in (230.0, 260.0, 290.0):
    for degrees in (-24.0, 0.0, 24.0):
        theta = math.pi / 2 + math.radians(degrees)
        occ.addCylinder(radius * math.cos(theta), radius * math.sin(theta), 40, 0, 0, 10, 12)
occ.synchronize()
gmsh.write(str(OUT / "railway_disc.step"))
gmsh.finalize()

# ## What was written
for name in ("car_brake.step", "railway_disc.step"):
    print(f"{OUT / name}: {(OUT / name).stat().st_size / 1e3:.0f} kB")

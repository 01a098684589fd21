"""Pin-on-disc tribometer of thesis §7.3.1 (Fig. 7.7, Tables 7.1–7.2).

Steel disc: annulus of inner radius 12.5 mm and outer radius 107.5 mm, top face z = 0, rotating
about the z axis (omega > 0: counter-clockwise seen from +z). Sintered friction pin 20 x 20 mm,
centred on the 80–100 mm track at (track_radius, 0), standing on the disc; its upper part sits in a
steel pin-housing (a sleeve) and its top is bonded, like the housing, to a thin steel plate that runs
along the sliding direction y. The plate's extremities (faces y = ±plate_length/2) carry the normal
load along −z and are held laterally (x, y), as on the bench; the disc's bore is clamped. Body 0 is
pin + housing + plate (regions with materials "pin", "disc", "disc": the holder parts are steel,
Table 7.2 "other components"; a scene's ``geometry.part_materials``
gives them others), body 1 the disc. The thesis does not give the disc, pin, housing
and plate thicknesses: the defaults below are plausible bench values.

At (track_radius, 0) the disc moves along +y, so the leading edge of the pin (where disc material
enters the contact) is its y = −pin_size/2 edge.
"""
from __future__ import annotations

import numpy as np

from multiscale.errors import InputError
from multiscale.geometry import (BodySpec, GeometrySpec, Region, Rotation, Support, add_group,
                                       entities_in_box, entities_where, named_key, require_below,
                                       resolve_parameters, thin_warning)

DEFAULTS: dict[str, float] = {
    "inner_radius": 12.5e-3,        # m, disc bore (§7.3.1)
    "outer_radius": 107.5e-3,       # m
    "disc_thickness": 10e-3,        # m
    "track_radius": 90e-3,          # m, pin centre: middle of the 80-100 mm track (Table 7.1)
    "pin_size": 20e-3,              # m, square pin 20 x 20 mm
    "pin_height": 15e-3,            # m
    "housing_size": 32e-3,          # m, outer size of the square pin-housing sleeve
    "housing_height": 10e-3,        # m, sleeve height (the pin sticks out pin_height - housing_height)
    "plate_length": 120e-3,         # m, along y (sliding direction)
    "plate_width": 40e-3,           # m, along x
    "plate_thickness": 3e-3,        # m
    "mesh_size": 12e-3,             # m, element size far from the pin
    "holder_mesh_size": 5e-3,       # m, element size in pin, housing and plate
    "interface_mesh_size": 2.5e-3,  # m, element size on the contact face
    "track_mesh_size": 0.0,         # m, element size on the disc track surface (0: mesh_size)
}
NAME = "pin_on_disc"
CELL = {"disc": 1, "pin": 2, "housing": 3, "plate": 4}
FACET = {"interface": 10, "plate_ends": 11, "disc_bore": 12}


def parameters(params=None) -> dict:
    """DEFAULTS updated by ``params`` (SI), with consistency checks."""
    p = resolve_parameters(DEFAULTS, params, NAME)
    p["track_mesh_size"] = p["track_mesh_size"] or p["mesh_size"]
    require_below(p, params, "inner_radius", "outer_radius", why=": the disc's bore and rim")
    half, rc = p["pin_size"] / 2, p["track_radius"]
    reach = (rc - half, float(np.hypot(rc + half, half)))     # m, the square's nearest edge and farthest corners
    if not p["inner_radius"] < reach[0] < reach[1] < p["outer_radius"]:
        key = named_key(params, ("pin_size", "track_radius"), "track_radius")
        raise InputError(f"geometry.{key}", p[key], f"the square pin of side pin_size = {1e3 * p['pin_size']:.4g} mm "
                         f"at track_radius = {1e3 * rc:.4g} mm reaches from r = {1e3 * reach[0]:.4g} to "
                         f"{1e3 * reach[1]:.4g} mm (its outer corners), beyond the disc's "
                         f"{1e3 * p['inner_radius']:.4g} to {1e3 * p['outer_radius']:.4g} mm (inner_radius, "
                         "outer_radius): the pin must lie on the disc")
    chain = ": pin_size < housing_size < plate_width <= plate_length (the sleeve around the pin, the plate holding it)"
    require_below(p, params, "pin_size", "housing_size", why=chain)
    require_below(p, params, "housing_size", "plate_width", why=chain)
    require_below(p, params, "plate_width", "plate_length", strict=False, why=chain)
    require_below(p, params, "housing_height", "pin_height", why=": the pin sticks out of its sleeve")
    return p


def describe(params=None) -> GeometrySpec:
    """Bodies, tags, supports and load faces (pure Python, the same on every rank)."""
    p = parameters(params)
    holder = BodySpec("pin", (Region("pin", CELL["pin"], "pin"), Region("housing", CELL["housing"], "disc"),
                              Region("plate", CELL["plate"], "disc")))
    return GeometrySpec(
        bodies=(holder, BodySpec("disc", (Region("disc", CELL["disc"], "disc"),))),
        interfaces={"interface": FACET["interface"]},
        faces={"plate_ends": FACET["plate_ends"], "disc_bore": FACET["disc_bore"]},
        supports=(Support("plate_ends", (0, 1)), Support("disc_bore", (0, 1, 2))),
        load_faces=("plate_ends",),
        load_direction=(0.0, 0.0, -1.0),
        motion=Rotation((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
        length_scale=p["outer_radius"],
        report=(f"a square pin of side pin_size = {1e3 * p['pin_size']:.4g} mm at track_radius = "
                f"{1e3 * p['track_radius']:.4g} mm on a disc of {1e3 * p['inner_radius']:.4g} to "
                f"{1e3 * p['outer_radius']:.4g} mm, {1e3 * p['disc_thickness']:.4g} mm thick",),
        warnings=tuple(thin_warning([("disc", p["disc_thickness"], p["mesh_size"]),
                                     ("pin", min(p["pin_size"], p["pin_height"]), p["holder_mesh_size"]),
                                     ("plate", p["plate_thickness"], p["holder_mesh_size"])])),
        interface_extents={"interface": (p["pin_size"], p["pin_size"])},
        interface_areas={"interface": p["pin_size"] ** 2},
        interface_sizes={"interface": p["interface_mesh_size"]},
        load_areas={"plate_ends": 2 * p["plate_width"] * p["plate_thickness"]},   # (a pressure acts there)
    )


def generate(model, params=None) -> None:
    """Build and mesh the geometry in the (initialised, empty) gmsh ``model``."""
    p = parameters(params)
    occ = model.occ
    td, hp, rc = p["disc_thickness"], p["pin_height"], p["track_radius"]
    a, hs, hh = p["pin_size"], p["housing_size"], p["housing_height"]
    lp, wp, tp = p["plate_length"], p["plate_width"], p["plate_thickness"]
    outer = occ.addCylinder(0, 0, -td, 0, 0, td, p["outer_radius"])
    bore = occ.addCylinder(0, 0, -td, 0, 0, td, p["inner_radius"])
    disc, _ = occ.cut([(3, outer)], [(3, bore)])
    pin = occ.addBox(rc - a / 2, -a / 2, 0, a, a, hp)
    housing = occ.addBox(rc - hs / 2, -hs / 2, hp - hh, hs, hs, hh)
    plate = occ.addBox(rc - wp / 2, -lp / 2, hp, wp, lp, tp)
    occ.fragment(disc + [(3, pin)], [(3, housing), (3, plate)])
    occ.synchronize()
    eps = 1e-4 * min(tp, a, td)
    pin_parts = entities_in_box(model, 3, (rc - a / 2 - eps, -a / 2 - eps, -eps), (rc + a / 2 + eps, a / 2 + eps, hp + eps))
    sleeve = entities_in_box(model, 3, (rc - hs / 2 - eps, -hs / 2 - eps, hp - hh - eps),
                             (rc + hs / 2 + eps, hs / 2 + eps, hp + eps))
    add_group(model, 3, entities_where(model, 3, lambda c: c[2] < 0), CELL["disc"], "disc")
    add_group(model, 3, pin_parts, CELL["pin"], "pin")
    add_group(model, 3, [t for t in sleeve if t not in pin_parts], CELL["housing"], "housing")
    add_group(model, 3, entities_where(model, 3, lambda c: c[2] > hp), CELL["plate"], "plate")
    iface = entities_in_box(model, 2, (rc - a / 2 - eps, -a / 2 - eps, -eps), (rc + a / 2 + eps, a / 2 + eps, eps))
    add_group(model, 2, iface, FACET["interface"], "interface")
    ends = entities_where(model, 2, lambda c: abs(abs(c[1]) - lp / 2) < eps and c[2] > hp)
    add_group(model, 2, ends, FACET["plate_ends"], "plate_ends")
    r_in = p["inner_radius"]
    bore_faces = entities_in_box(model, 2, (-r_in - eps, -r_in - eps, -td - eps), (r_in + eps, r_in + eps, eps))
    add_group(model, 2, bore_faces, FACET["disc_bore"], "disc_bore")
    _sizes(model, p, iface)
    model.mesh.generate(3)


def _sizes(model, p: dict, iface: list[int]) -> None:
    """Interface size on the contact face growing to mesh_size in the disc; holder size above."""
    model.mesh.setSize(model.getEntities(0), p["mesh_size"])
    holder_points = model.getBoundary([(3, t) for t in model.getEntitiesForPhysicalGroup(3, CELL["plate"])]
                                      + [(3, t) for t in model.getEntitiesForPhysicalGroup(3, CELL["housing"])],
                                      combined=False, recursive=True)
    model.mesh.setSize(holder_points, p["holder_mesh_size"])
    field = model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "SurfacesList", iface)
    near = field.add("Threshold")
    field.setNumber(near, "InField", dist)
    field.setNumber(near, "SizeMin", p["interface_mesh_size"])
    field.setNumber(near, "SizeMax", p["mesh_size"])
    field.setNumber(near, "DistMin", 0.25 * p["pin_size"])
    field.setNumber(near, "DistMax", 2.5 * p["pin_size"])
    pin_box = field.add("Box")
    a, rc = p["pin_size"], p["track_radius"]
    for key, value in (("VIn", p["holder_mesh_size"]), ("VOut", p["mesh_size"]),
                       ("XMin", rc - p["plate_width"] / 2), ("XMax", rc + p["plate_width"] / 2),
                       ("YMin", -p["plate_length"] / 2), ("YMax", p["plate_length"] / 2),
                       ("ZMin", 0.0), ("ZMax", p["pin_height"] + p["plate_thickness"])):
        field.setNumber(pin_box, key, value)
    ring = field.add("MathEval")          # distance-like measure from the track's middle circle
    field.setString(ring, "F", f"Abs(Sqrt(x*x+y*y) - {rc}) + 2*Abs(z)")
    track = field.add("Threshold")
    for key, value in (("InField", ring), ("SizeMin", p["track_mesh_size"]), ("SizeMax", p["mesh_size"]),
                       ("DistMin", a / 2), ("DistMax", a)):
        field.setNumber(track, key, value)
    both = field.add("Min")
    field.setNumbers(both, "FieldsList", [near, pin_box, track])
    field.setAsBackgroundMesh(both)
    model.mesh.setSize(model.getBoundary([(2, t) for t in iface], combined=False, recursive=True),
                       p["interface_mesh_size"])

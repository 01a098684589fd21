"""Disc-brake assembly for the squeal analysis of thesis ch. 4 (§4.3.1, Fig. 4.4), simplified.

Frame: disc axis z through the origin; the friction ring spans 0 <= z <= disc_thickness; the pads
are centred on the +y axis (at the pad centre, x is circumferential, y radial, z axial). The
inboard side (piston, caliper housing) is z < 0, the outboard side (caliper fingers, hat) z > t.

Parts (one conforming tetrahedral mesh, ``occ.fragment``):

* disc (body 1, the sliding "−" side): friction ring, solid or ventilated (``vanes`` > 0 radial
  vanes between two cheeks), hat (cylindrical wall and mounting flange), revolved about z;
* body 0 (the stationary "+" side), two disconnected pieces with bonded (tied) parts:
  inner piece = inner pad + inner backplate + piston; outer piece = outer pad + outer backplate +
  floating caliper (housing behind the piston, bridge over the disc rim, fingers bonded to the outer
  backplate, two guide-pin lugs). Pad–backplate, piston–backplate and finger–backplate connections are
  bonded (one mesh); the piston and the caliper housing are separated by the brake-fluid gap.

Material tables (thesis §4.3.1): ``disc`` (cast iron), ``pad`` (composite friction material),
``backplate``, ``piston`` and ``caliper`` (steels).

Interfaces (conforming, tagged per pad): ``inner_pad`` (z = 0) and ``outer_pad`` (z = t).
Loads: the hydraulic pressure acts on ``piston_back`` (pushing the piston toward the disc) and on
``caliper_bore`` (the same circle on the housing, pushing the caliper away), i.e. a traction −p n on
both faces; the clamp force on each pad is p times the meshed piston face's area, p pi piston_radius^2
less its faceting (1644 N against 1662 N at 10 bar on the demo's 12 mm mesh: the run prints it).
Supports (§4.3.1): the disc's mounting annulus ``disc_mount`` is fixed; the anchor is represented by
its kinematic connections: the backplate ear ends (``abutment_inner``/``abutment_outer``) and the
caliper's ``guide_pins`` hold x and y and leave the axial motion free (sliding abutments and pins),
and the ``piston_wall`` is guided in x and y by the bore. Each piece is then free only along z,
where the pad–disc contact holds it, so the pad forces balance the pressure's resultant.
"""
from __future__ import annotations

import math

from multiscale.errors import InputError
from multiscale.geometry import (BodySpec, GeometrySpec, Region, Rotation, Support, add_group,
                                       entities_in_box, entities_where, resolve_parameters, thin_warning)

NAME = "disc_brake"
PARAMETER_KINDS = {"vanes": "count"}
DEFAULTS: dict[str, float] = {
    "disc_outer_radius": 0.140,      # m
    "ring_inner_radius": 0.085,      # m, inner radius of the friction ring (= hat wall outer radius)
    "disc_thickness": 0.022,         # m
    "vanes": 0.0,                    # number of radial vanes (0: solid disc; the heat problem needs 0)
    "cheek_thickness": 0.007,        # m, ventilated disc only
    "vane_width": 0.008,             # m, ventilated disc only
    "hat_height": 0.040,             # m, from the outboard friction face to the flange top
    "hat_wall": 0.006,               # m
    "flange_thickness": 0.007,       # m
    "hub_radius": 0.033,             # m, centre hole of the flange
    "pad_inner_radius": 0.092,       # m
    "pad_outer_radius": 0.136,       # m
    "pad_angle": 0.96,               # rad, angular span of the friction material
    "pad_thickness": 0.011,          # m
    "backplate_thickness": 0.0055,   # m
    "backplate_angle": 1.20,         # rad, angular span of the backplate (ears = abutments)
    "backplate_margin": 0.004,       # m, radial overhang of the backplate beyond the pad
    "piston_radius": 0.023,          # m
    "piston_length": 0.030,          # m
    "piston_offset": 0.002,          # m, piston centre below the pad's mean radius
    "fluid_gap": 0.002,              # m, between piston back and caliper bore bottom
    "caliper_thickness": 0.020,      # m, housing and finger thickness along z
    "caliper_width": 0.080,          # m, housing and bridge width along x
    "bridge_thickness": 0.015,       # m, radial thickness of the bridge over the disc rim
    "rim_clearance": 0.008,          # m, between disc rim and bridge
    "lug_length": 0.015,             # m, guide-pin lugs on both sides of the housing
    "mesh_size": 0.012,              # m, element size in the disc and caliper
    "pad_mesh_size": 0.0,            # m, element size in pads, backplates, piston (0: mesh_size / 2)
}
CELL = {"disc": 1, "inner_pad": 2, "outer_pad": 3, "inner_backplate": 4, "outer_backplate": 5,
        "piston": 6, "caliper": 7}
FACET = {"inner_pad": 10, "outer_pad": 11, "disc_mount": 12, "piston_back": 13, "caliper_bore": 14,
         "abutment_inner": 15, "abutment_outer": 16, "guide_pins": 17, "piston_wall": 18}
MATERIALS = {"disc": "disc", "inner_pad": "pad", "outer_pad": "pad", "inner_backplate": "backplate",
             "outer_backplate": "backplate", "piston": "piston", "caliper": "caliper"}   # region -> table
COMPONENTS = tuple(CELL)            # strain-energy components (thesis Fig. 4.20)


def parameters(params=None) -> dict:
    """DEFAULTS updated by ``params`` (SI); checks that the parts fit together."""
    p = resolve_parameters(DEFAULTS, params, NAME)
    p["pad_mesh_size"] = p["pad_mesh_size"] or p["mesh_size"] / 2
    if p["vanes"] != int(p["vanes"]):
        raise InputError("geometry.vanes", p["vanes"], "a whole number of vanes (0: solid disc)")
    p["vanes"] = int(p["vanes"])
    checks = [
        ("ring_inner_radius", p["ring_inner_radius"] - p["hat_wall"] > p["hub_radius"],
         "ring_inner_radius - hat_wall must exceed hub_radius"),
        ("pad_inner_radius", p["pad_inner_radius"] - p["backplate_margin"] > p["ring_inner_radius"],
         "the backplate must lie on the friction ring (pad_inner_radius - backplate_margin > ring_inner_radius)"),
        ("pad_outer_radius", p["pad_outer_radius"] <= p["disc_outer_radius"]
         and p["pad_outer_radius"] > p["pad_inner_radius"],
         "pad_inner_radius < pad_outer_radius <= disc_outer_radius"),
        ("pad_angle", p["pad_angle"] < p["backplate_angle"],     # (55 for 55 deg blamed backplate_angle: a trial)
         f"must be below backplate_angle ({p['backplate_angle']:.4g} rad); a bare number is in radians: \"40 deg\""),
        ("backplate_angle", p["backplate_angle"] < math.pi, "pad_angle < backplate_angle < pi (rad: \"70 deg\")"),
        ("piston_radius", _piston_fits(p), "the piston must lie inside the backplate"),
        ("cheek_thickness", p["vanes"] == 0 or 2 * p["cheek_thickness"] < p["disc_thickness"],
         "two cheeks must be thinner than the disc"),
        ("hat_height", p["hat_height"] > p["flange_thickness"], "must exceed flange_thickness"),
    ]
    for name, ok, allowed in checks:
        if not ok:
            raise InputError(f"geometry.{name}", p[name], allowed)
    return p


def _piston_fits(p) -> bool:
    yc = _piston_centre(p)
    r_in = p["pad_inner_radius"] - p["backplate_margin"]
    r_out = p["pad_outer_radius"] + p["backplate_margin"]
    rp = p["piston_radius"]
    half = p["backplate_angle"] / 2
    return (yc - rp > r_in and yc + rp < r_out
            and math.atan2(rp, yc - rp) < half)


def _piston_centre(p) -> float:
    return 0.5 * (p["pad_inner_radius"] + p["pad_outer_radius"]) - p["piston_offset"]


def clamp_force(pressure: float, params=None) -> float:
    """Axial force on each pad [N] from the hydraulic ``pressure`` [Pa]: p pi r_piston^2."""
    return pressure * math.pi * parameters(params)["piston_radius"] ** 2


def describe(params=None) -> GeometrySpec:
    """Bodies, tags, supports and load faces (pure Python, the same on every rank)."""
    p = parameters(params)
    stationary = tuple(Region(n, CELL[n], MATERIALS[n]) for n in COMPONENTS if n != "disc")
    return GeometrySpec(
        bodies=(BodySpec("brake", stationary), BodySpec("disc", (Region("disc", CELL["disc"], MATERIALS["disc"]),))),
        interfaces={"inner_pad": FACET["inner_pad"], "outer_pad": FACET["outer_pad"]},
        faces={k: v for k, v in FACET.items() if k not in ("inner_pad", "outer_pad")},
        supports=(Support("disc_mount", (0, 1, 2)), Support("abutment_inner", (0, 1)),
                  Support("abutment_outer", (0, 1)), Support("guide_pins", (0, 1)),
                  Support("piston_wall", (0, 1))),
        load_faces=("piston_back", "caliper_bore"),
        load_direction=(0.0, 0.0, 1.0),           # piston face; the bore face is loaded opposite (−p n)
        motion=Rotation((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),
        length_scale=p["disc_outer_radius"],
        fluid_load=True,                          # the hydraulic pressure on piston and caliper bore
        interface_regions={"inner_pad": "inner_pad", "outer_pad": "outer_pad"},
        interface_extents=dict.fromkeys(("inner_pad", "outer_pad"), _pad_extent(p)),
        interface_areas=dict.fromkeys(("inner_pad", "outer_pad"),            # the annular sector
                                      p["pad_angle"] / 2 * (p["pad_outer_radius"] ** 2 - p["pad_inner_radius"] ** 2)),
        crossed=_vane_share(p),
        interface_sizes=dict.fromkeys(("inner_pad", "outer_pad"), p["pad_mesh_size"]),
        load_areas=dict.fromkeys(("piston_back", "caliper_bore"), math.pi * p["piston_radius"] ** 2),
        report=(f"piston and bore discs of radius {p['piston_radius'] * 1e3:.4g} mm: a pressure's force is given "
                "for pi r^2; their meshed polygons carry a little less (1.14 % with a 20 mm mesh), which the run says",),
        warnings=tuple(thin_warning([("disc", p["cheek_thickness"] if p["vanes"] else p["disc_thickness"],
                                      p["mesh_size"]), ("pads", p["pad_thickness"], p["pad_mesh_size"]),
                                     ("backplates", p["backplate_thickness"], p["pad_mesh_size"])])),
    )


def _vane_share(p) -> float:
    """The share of the disc's surface that its rotation crosses, weighted by the speed (as the
    run's check of its mesh, ``macro.mesh.crossing``): the vanes' sides, int r dA = n h (R² − ri²),
    over them and the ring's four faces (cheeks outside and inside), 4 x 2 pi (R³ − ri³) / 3; the
    hat left out: an estimate. 0 for a solid disc."""
    R, ri = p["disc_outer_radius"], p["ring_inner_radius"]
    sides = p["vanes"] * (p["disc_thickness"] - 2 * p["cheek_thickness"]) * (R * R - ri * ri)
    return sides / (sides + 8 * math.pi * (R ** 3 - ri ** 3) / 3)


def _pad_extent(p) -> tuple[float, float]:
    """Size (x, y) [m] of a pad's friction face, an annular sector centred on +y: its outer arc's
    chord across, from its inner corners to the outer radius along y."""
    half = p["pad_angle"] / 2
    return 2 * p["pad_outer_radius"] * math.sin(half), p["pad_outer_radius"] - p["pad_inner_radius"] * math.cos(half)


def _z_levels(p) -> dict:
    t, tp, tb = p["disc_thickness"], p["pad_thickness"], p["backplate_thickness"]
    z = {"pad_in": -tp, "bp_in": -tp - tb, "pad_out": t + tp, "bp_out": t + tp + tb}
    z["piston_back"] = z["bp_in"] - p["piston_length"]
    z["bore"] = z["piston_back"] - p["fluid_gap"]
    z["housing_back"] = z["bore"] - p["caliper_thickness"]
    z["finger_back"] = z["bp_out"] + p["caliper_thickness"]
    z["hat_top"] = t + p["hat_height"]
    return z


def _sector(occ, z0, dz, r_in, r_out, angle):
    """Annular sector r_in..r_out, centred on +y, z0..z0+dz."""
    outer = occ.addCylinder(0, 0, z0, 0, 0, dz, r_out, angle=angle)
    inner = occ.addCylinder(0, 0, z0, 0, 0, dz, r_in, angle=angle)
    vol, _ = occ.cut([(3, outer)], [(3, inner)])
    occ.rotate(vol, 0, 0, 0, 0, 0, 1, math.pi / 2 - angle / 2)
    return vol[0][1]


def _disc(occ, p, z, hat=True):
    """Friction ring (+ hat) as a revolved r–z profile; vent channels cut for a ventilated disc."""
    t, R, ri = p["disc_thickness"], p["disc_outer_radius"], p["ring_inner_radius"]
    rh = ri - p["hat_wall"]
    zt, zf = z["hat_top"], z["hat_top"] - p["flange_thickness"]
    profile = ([(R, 0), (R, t), (ri, t), (ri, zt), (p["hub_radius"], zt), (p["hub_radius"], zf),
                (rh, zf), (rh, 0)] if hat else [(R, 0), (R, t), (ri, t), (ri, 0)])
    pts = [occ.addPoint(r, 0, zz) for r, zz in profile]
    lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
    face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
    disc = occ.revolve([(2, face)], 0, 0, 0, 0, 0, 1, 2 * math.pi)
    disc = [d for d in disc if d[0] == 3]
    if p["vanes"] > 0:
        tc = p["cheek_thickness"]
        channel = occ.addCylinder(0, 0, tc, 0, 0, t - 2 * tc, R + 1e-3)
        core = occ.addCylinder(0, 0, tc, 0, 0, t - 2 * tc, ri)
        channel, _ = occ.cut([(3, channel)], [(3, core)])
        w = p["vane_width"]
        vanes = []
        for k in range(p["vanes"]):
            b = occ.addBox(ri - 1e-3, -w / 2, tc - 1e-3, R - ri + 2e-3, w, t - 2 * tc + 2e-3)
            occ.rotate([(3, b)], 0, 0, 0, 0, 0, 1, 2 * math.pi * (k + 0.5) / p["vanes"])
            vanes.append((3, b))
        channel, _ = occ.cut(channel, vanes)
        disc, _ = occ.cut(disc, channel)
    return disc[0][1]


def _caliper(occ, p, z, yc):
    """Housing behind the piston, bridge over the rim, fingers, guide-pin lugs (one fused volume)."""
    w = p["caliper_width"]
    y_bridge = p["disc_outer_radius"] + p["rim_clearance"]
    y_top = y_bridge + p["bridge_thickness"]
    y_low = yc - p["piston_radius"] - 0.01
    tcal = p["caliper_thickness"]
    housing = occ.addBox(-w / 2, y_low, z["housing_back"], w, y_top - y_low, tcal)
    bridge = occ.addBox(-w / 2, y_bridge, z["housing_back"], w, y_top - y_bridge,
                        z["finger_back"] - z["housing_back"])
    fingers = occ.addBox(-w / 2 * 0.8, yc - 0.5 * p["piston_radius"], z["bp_out"], 0.8 * w,
                         y_top - yc + 0.5 * p["piston_radius"], tcal)
    lug = p["lug_length"]
    lugs = [occ.addBox(s, yc - 0.01, z["housing_back"], lug, 0.02, tcal) for s in (w / 2, -w / 2 - lug)]
    vol, _ = occ.fuse([(3, housing)], [(3, v) for v in (bridge, fingers, *lugs)])
    return vol[0][1]


def generate(model, params=None) -> None:
    """Build and mesh the assembly in the (initialised, empty) gmsh ``model``."""
    p = parameters(params)
    occ = model.occ
    z = _z_levels(p)
    yc = _piston_centre(p)
    r_bi, r_bo = p["pad_inner_radius"] - p["backplate_margin"], p["pad_outer_radius"] + p["backplate_margin"]
    tp, tb, t = p["pad_thickness"], p["backplate_thickness"], p["disc_thickness"]
    parts = {
        "disc": _disc(occ, p, z),
        "inner_pad": _sector(occ, -tp, tp, p["pad_inner_radius"], p["pad_outer_radius"], p["pad_angle"]),
        "outer_pad": _sector(occ, t, tp, p["pad_inner_radius"], p["pad_outer_radius"], p["pad_angle"]),
        "inner_backplate": _sector(occ, z["bp_in"], tb, r_bi, r_bo, p["backplate_angle"]),
        "outer_backplate": _sector(occ, z["pad_out"], tb, r_bi, r_bo, p["backplate_angle"]),
        "piston": occ.addCylinder(0, yc, z["piston_back"], 0, 0, p["piston_length"], p["piston_radius"]),
        "caliper": _caliper(occ, p, z, yc),
    }
    # A thin cylinder behind the bore face imprints the pressurised circle on the housing.
    boss = occ.addCylinder(0, yc, z["bore"] - p["caliper_thickness"] / 2, 0, 0,
                           p["caliper_thickness"] / 2, p["piston_radius"])
    names = list(parts)
    _, out_map = occ.fragment([(3, parts[n]) for n in names], [(3, boss)])
    occ.synchronize()
    owner: dict[int, str] = {}
    for name, out in zip(names + ["caliper"], out_map):
        for dim, tag in out:
            owner.setdefault(tag, name)
    for name in names:
        add_group(model, 3, [tag for tag, n in owner.items() if n == name], CELL[name], name)
    _tag_faces(model, p, z, yc)
    _mesh(model, p, owner)


def _tag_faces(model, p, z, yc):
    eps = 1e-5
    R, rp = p["disc_outer_radius"], p["piston_radius"]
    half_pad, half_bp = p["pad_angle"] / 2, p["backplate_angle"] / 2
    x_pad = p["pad_outer_radius"] * math.sin(half_pad) + eps
    y_pad = p["pad_inner_radius"] * math.cos(half_pad) - eps
    box = lambda x, y0, y1, z0, z1: ((-x, y0, z0 - eps), (x, y1, z1 + eps))  # noqa: E731
    t = p["disc_thickness"]
    groups = {
        "inner_pad": entities_in_box(model, 2, *box(x_pad, y_pad, R, 0.0, 0.0)),
        "outer_pad": entities_in_box(model, 2, *box(x_pad, y_pad, R, t, t)),
        "piston_back": entities_in_box(model, 2, *box(rp + eps, yc - rp - eps, yc + rp + eps,
                                                      z["piston_back"], z["piston_back"])),
        "caliper_bore": entities_in_box(model, 2, *box(rp + eps, yc - rp - eps, yc + rp + eps,
                                                       z["bore"], z["bore"])),
    }
    zf = z["hat_top"] - p["flange_thickness"]
    rh = p["ring_inner_radius"] - p["hat_wall"]
    groups["disc_mount"] = entities_in_box(model, 2, (-rh - eps, -rh - eps, zf - eps), (rh + eps, rh + eps, zf + eps))

    def ear(z0, z1):
        def pred(c):
            ang = math.atan2(c[1], c[0])
            return (z0 - eps < c[2] < z1 + eps and
                    min(abs(ang - math.pi / 2 - half_bp), abs(ang - math.pi / 2 + half_bp)) < 1e-6)
        return entities_where(model, 2, pred)

    groups["abutment_inner"] = ear(z["bp_in"], z["pad_in"])
    groups["abutment_outer"] = ear(z["pad_out"], z["bp_out"])
    x_lug = p["caliper_width"] / 2 + p["lug_length"]
    groups["guide_pins"] = entities_where(model, 2, lambda c: abs(abs(c[0]) - x_lug) < eps
                                          and abs(c[1] - yc) < 0.0101)
    zp = z["piston_back"] + p["piston_length"] / 2
    groups["piston_wall"] = entities_where(model, 2, lambda c: abs(c[0]) < eps and abs(c[1] - yc) < eps
                                           and abs(c[2] - zp) < eps)
    for name, tags in groups.items():
        add_group(model, 2, tags, FACET[name], name)


def _mesh(model, p, owner):
    gmsh_size(model, p["mesh_size"])
    fine = [(3, tag) for tag, name in owner.items() if name not in ("disc", "caliper")]
    model.mesh.setSize(model.getBoundary(fine, combined=False, recursive=True), p["pad_mesh_size"])
    model.mesh.generate(3)


def generate_disc(model, params=None, hat: bool = True) -> int:
    """Only the disc (ring, with or without hat), meshed, one physical volume ``disc``."""
    p = parameters(params)
    vol = _disc(model.occ, p, _z_levels(p), hat)
    model.occ.synchronize()
    add_group(model, 3, [vol], CELL["disc"], "disc")
    gmsh_size(model, p["mesh_size"])
    model.mesh.generate(3)
    return vol


def gmsh_size(model, size: float) -> None:
    """Uniform target element size [m] (curvature-refined on circles)."""
    import gmsh   # only when meshing: scenes read this builder's parameters without gmsh

    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 24)
    model.mesh.setSize(model.getEntities(0), size)

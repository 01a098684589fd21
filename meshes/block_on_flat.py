"""Elastic block pressed on a flat: the thesis ch. 1 verification geometry (§1.4–1.5).

Block [0, length] x [0, width] x [0, height] on a flat [0, flat_length] x [0, flat_width] x
[-flat_thickness, 0] (by default the same footprint), meshed conformingly with tetrahedra. The
planes x = 0 and y = 0 are symmetry planes (quarter model): x-, resp. y-displacements are held there
in both bodies; the flat's bottom is held in z; the normal load acts on the block's top face
along -z. With equal footprints the exact solution is a uniform stress, so the contact pressure is
uniform: the first check of the penalty interface.
"""
from __future__ import annotations

from multiscale.geometry import (BodySpec, GeometrySpec, Region, Support, Translation, add_group,
                                       entities_in_box, entities_where, require_below, resolve_parameters,
                                       thin_warning)

DEFAULTS: dict[str, float] = {
    "length": 10e-3,              # m, block size along x
    "width": 10e-3,               # m, block size along y
    "height": 5e-3,               # m, block size along z
    "flat_length": 0.0,           # m, flat size along x (0: same as the block)
    "flat_width": 0.0,            # m, flat size along y (0: same as the block)
    "flat_thickness": 5e-3,       # m
    "mesh_size": 2.5e-3,          # m, element size in the bodies
    "interface_mesh_size": 0.0,   # m, element size on the interface (0: mesh_size)
}
NAME = "block_on_flat"
CELL = {"block": 1, "flat": 2}
FACET = {"interface": 10, "block_top": 11, "flat_bottom": 12, "symmetry_x": 13, "symmetry_y": 14}


def parameters(params=None) -> dict:
    """DEFAULTS updated by ``params`` (SI), zero sizes replaced by their fallbacks."""
    p = resolve_parameters(DEFAULTS, params, NAME)
    p["flat_length"] = p["flat_length"] or p["length"]
    p["flat_width"] = p["flat_width"] or p["width"]
    p["interface_mesh_size"] = p["interface_mesh_size"] or p["mesh_size"]
    for flat, block in (("flat_length", "length"), ("flat_width", "width")):
        require_below(p, params, block, flat, strict=False, why=": the flat is at least as large as the block",
                      dependent=flat)
    return p


def describe(params=None) -> GeometrySpec:
    """Bodies, tags, supports and load faces (pure Python, the same on every rank)."""
    p = parameters(params)
    return GeometrySpec(
        bodies=(BodySpec("block", (Region("block", CELL["block"], "block"),)),
                BodySpec("flat", (Region("flat", CELL["flat"], "flat"),))),
        interfaces={"interface": FACET["interface"]},
        faces={k: v for k, v in FACET.items() if k != "interface"},
        supports=(Support("symmetry_x", (0,)), Support("symmetry_y", (1,)), Support("flat_bottom", (2,))),
        load_faces=("block_top",),
        load_direction=(0.0, 0.0, -1.0),
        motion=Translation((1.0, 0.0, 0.0)),
        length_scale=max(p["length"], p["width"], p["height"]),
        symmetry={"symmetry_x": (1.0, 0.0, 0.0), "symmetry_y": (0.0, 1.0, 0.0)},
        interface_extents={"interface": (p["length"], p["width"])},      # the block's footprint
        interface_areas={"interface": p["length"] * p["width"]},
        load_areas={"block_top": p["length"] * p["width"]},
        interface_sizes={"interface": p["interface_mesh_size"]},
        report=(f"a quarter model of a {2e3 * p['length']:.4g} x {2e3 * p['width']:.4g} mm block (symmetry planes "
                "x = 0, y = 0): its load, forces, areas, heats and worn volumes are the quarter's, a quarter of "
                "the whole block's",),
        warnings=tuple(thin_warning([("block", min(p["length"], p["width"], p["height"]), p["mesh_size"]),
                                     ("flat", p["flat_thickness"], p["mesh_size"])])),
    )


def generate(model, params=None) -> None:
    """Build and mesh the geometry in the (initialised, empty) gmsh ``model``."""
    p = parameters(params)
    occ = model.occ
    lx, ly, h = p["length"], p["width"], p["height"]
    fx, fy, hf = p["flat_length"], p["flat_width"], p["flat_thickness"]
    block = occ.addBox(0, 0, 0, lx, ly, h)
    flat = occ.addBox(0, 0, -hf, fx, fy, hf)
    occ.fragment([(3, block)], [(3, flat)])
    occ.synchronize()
    eps = 1e-4 * min(lx, ly, h, hf)
    add_group(model, 3, entities_where(model, 3, lambda c: c[2] > 0), CELL["block"], "block")
    add_group(model, 3, entities_where(model, 3, lambda c: c[2] < 0), CELL["flat"], "flat")
    on = lambda i, v: (lambda c: abs(c[i] - v) < eps)  # noqa: E731
    iface = entities_in_box(model, 2, (-eps, -eps, -eps), (lx + eps, ly + eps, eps))
    add_group(model, 2, iface, FACET["interface"], "interface")
    add_group(model, 2, entities_where(model, 2, on(2, h)), FACET["block_top"], "block_top")
    add_group(model, 2, entities_where(model, 2, on(2, -hf)), FACET["flat_bottom"], "flat_bottom")
    add_group(model, 2, entities_where(model, 2, on(0, 0.0)), FACET["symmetry_x"], "symmetry_x")
    add_group(model, 2, entities_where(model, 2, on(1, 0.0)), FACET["symmetry_y"], "symmetry_y")
    # Interface size on the contact plane, body size elsewhere.
    model.mesh.setSize(model.getEntities(0), p["mesh_size"])
    model.mesh.setSize(model.getBoundary([(2, t) for t in iface], combined=False, recursive=True),
                       p["interface_mesh_size"])
    model.mesh.generate(3)

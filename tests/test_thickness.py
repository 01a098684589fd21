"""The material behind each interface facet (``multiscale.macro.thickness``): the boundary of a set of
tetrahedra, rays cut with it, the thickness of a meshed block, and the message of a part worn
through."""
import numpy as np
import pytest

from multiscale.macro.thickness import nearest_facing, part_boundaries, ray_exit


def sloped_box(n: int = 4):
    """The unit cube in n^3 cubes of 6 tetrahedra each (Kuhn), its top lifted to z = 1 + x / 2
    (z -> z (1 + x / 2): every face of the top stays in that plane): (tets (6 n^3, 4, 3), the
    z-index of each tetrahedron's cube)."""
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets, layer = [], []
    for i, j, k in np.ndindex(n, n, n):
        for path in paths:
            corner, tet = np.array([i, j, k], float), [np.array([i, j, k], float)]
            for axis in path:
                corner = corner.copy()
                corner[axis] += 1
                tet.append(corner)
            tets.append(np.array(tet) / n)
            layer.append(k)
    tets = np.array(tets)
    tets[..., 2] *= 1 + tets[..., 0] / 2
    return tets, np.array(layer)


def test_rays_leave_a_sloped_box_through_its_top_and_a_part_through_the_face_it_shares():
    """From the midpoints of the bottom's triangles straight up: the top lies at 1 + x / 2 (to
    round-off); the lower half of the cells (a part bonded to the upper) ends at its shared face,
    (1 + x / 2) / 2. The boundary's normals point into the cells: +z on the bottom. A ray leaves
    through a face that looks back at it (a side wall met at 53 degrees), not one it grazes (at 73
    degrees: no exit); one through an edge two triangles share meets them."""
    tets, layer = sloped_box()
    tri, normal = part_boundaries(tets)
    assert len(tri) == 6 * 2 * 16                                     # two triangles a square, 16 squares a side
    bottom = np.all(tri[:, :, 2] == 0, axis=1)
    assert bottom.sum() == 32
    np.testing.assert_allclose(normal[bottom], np.tile([0.0, 0.0, 1.0], (32, 1)), atol=1e-15)
    start = tri[bottom].mean(axis=1)
    top = 1 + start[:, 0] / 2
    np.testing.assert_allclose(ray_exit(start, normal[bottom], tri, normal, 1e-12), top, rtol=1e-13)
    low_tri, low_normal = part_boundaries(tets[layer < 2])
    assert len(low_tri) == 2 * 32 + 4 * 2 * 8                         # bottom, shared face, four sides of 2 x 4 squares
    np.testing.assert_allclose(ray_exit(start, normal[bottom], low_tri, low_normal, 1e-12), top / 2, rtol=1e-13)
    sideways = ray_exit(np.array([[0.5, 0.5, 0.25]]), np.array([[-1.0, 0.0, 0.0]]), low_tri, low_normal, 1e-12)
    assert sideways == pytest.approx([0.5], rel=1e-13)
    assert ray_exit(start[:1], -normal[bottom][:1], tri, normal, 1e-12) == [np.inf]     # out of the box: nothing
    steep, grazing = np.array([[0.8, 0.0, 0.6]]), np.array([[0.3, 0.0, 0.954]]) / np.hypot(0.3, 0.954)
    assert ray_exit(np.array([[0.9, 0.5, 0.01]]), steep, tri, normal, 1e-12) == pytest.approx([0.125], rel=1e-12)
    assert ray_exit(np.array([[0.9, 0.5, 0.01]]), grazing, tri, normal, 1e-12) == [np.inf]   # a side wall grazed
    inside = np.array([[0.5, 0.5, 0.0], [0.9, 0.5, 0.01]])          # the nearest face looking back: the top plane's
    np.testing.assert_allclose(nearest_facing(inside, np.tile([0.0, 0.0, 1.0], (2, 1)), tri, normal),
                               [1.25 / np.sqrt(1.25), (1.45 - 0.01) / np.sqrt(1.25)], rtol=1e-12)
    through_edge = np.array([[0.125, 0.125, 0.0]])                   # on an edge two of the top's triangles share
    assert ray_exit(through_edge, np.array([[0.0, 0.0, 1.0]]), tri, normal, 1e-12) == pytest.approx([1.0625])


dolfinx = pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")


def test_the_block_keeps_five_millimetres_behind_every_facet_until_worn_through():
    """The block on the flat (10 x 10 x 5 mm, 2.5 mm cells): 5 mm behind each interface facet; worn
    4 mm it keeps 1 mm, worn 6 mm at one facet it is through there (named, with the place); with a
    wear limit of 1.5 mm, 3.6 mm worn reaches it, 3.4 mm does not; a limit of 5 mm is refused."""
    from multiscale.geometry import builder
    from multiscale.macro import mesh
    from multiscale.errors import InputError
    from multiscale.macro.thickness import WearLimit
    tm = mesh.build(builder("block_on_flat"), {"mesh_size": 2.5e-3})
    limit = WearLimit(tm)
    n = tm.interface.n_facets
    np.testing.assert_allclose(limit.thickness.value, 5e-3, rtol=1e-12)
    assert set(limit.thickness.part) == {0} and limit.thickness.names == (tm.bodies[0].spec.regions[0].name,)
    depth = np.full(n, 4e-3)
    assert limit.row(depth)["wear_remaining_min"] == pytest.approx(1e-3, rel=1e-10) and limit.through(depth) is None
    depth[7] = 6e-3
    where = ", ".join(f"{1e3 * x:.4g}" for x in tm.interface.midpoints[7])
    name = limit.thickness.names[0]
    assert limit.through(depth).startswith(f"{name} worn through: 6 mm worn of its 5 mm at ({where}) mm, 1 of its "
                                           "facets through (the model keeps")
    keep = WearLimit(tm, 1.5e-3)                                     # a wear limit: 1.5 mm to keep
    assert keep.through(np.full(n, 3.4e-3)) is None
    depth[:] = 3.4e-3
    depth[:3] = 3.6e-3
    assert keep.through(depth).startswith(f"{name} at its wear limit: 3.6 mm worn of its 5 mm at (")
    assert keep.through(depth).endswith("1.4 mm left (wear.limit 1.5 mm), 3 of its facets at it")
    depth[0] = 5.5e-3                                                # beyond the limit and through
    assert keep.through(depth).startswith(f"{name} worn through: 5.5 mm worn of its 5 mm at (")
    assert ", 1 of its facets through, wear.limit 1.5 mm (the model keeps" in keep.through(depth)
    with pytest.raises(InputError, match=rf'wear.limit = "5 mm": must be less than the thinnest part behind an interface '
                                         rf"facet \({name}, 5 mm\)"):
        WearLimit(tm, 5e-3)


def test_each_pad_of_a_brake_keeps_its_friction_material_behind_it():
    """The demo brake (tests' coarse mesh of demos/brake_squeal.toml): each pad's 11 mm of friction
    material to its backplate (a part of its own) behind every facet; with two interfaces the
    history has each one's least material left, and the worn pad names itself."""
    from pathlib import Path
    from multiscale.macro.thickness import WearLimit
    from multiscale.scene import load
    from multiscale.workflows.model import build_mesh
    tm = build_mesh(load(Path(__file__).parents[1] / "demos" / "brake_squeal.toml"))
    limit = WearLimit(tm)
    assert limit.thickness.names == ("inner_pad", "outer_pad")
    np.testing.assert_allclose(limit.thickness.value, 11e-3, rtol=1e-12)
    masks = tm.interface.masks()
    depth = np.where(masks["outer_pad"], 2e-3, 1e-3)
    depth[np.flatnonzero(masks["outer_pad"])[0]] = 12e-3
    row = limit.row(depth)
    assert row["wear_remaining_min_inner_pad"] == pytest.approx(10e-3, rel=1e-12)
    assert row["wear_remaining_min_outer_pad"] == row["wear_remaining_min"] == pytest.approx(-1e-3, rel=1e-9)
    assert limit.through(depth).startswith("outer_pad worn through: 12 mm worn of its 11 mm at (")
    depth[np.flatnonzero(masks["inner_pad"])[:2]] = 11.5e-3
    assert ", 1 of its facets through; inner_pad too (the model keeps" in limit.through(depth)


def test_a_shoe_on_a_rim_is_as_thick_as_its_back_says(tmp_path):
    """A 20 mm block cut by a wheel's rim (r = 50 mm; its back at y = 60 mm): behind every facet of
    its curved face from 10 mm (the crown) to 11.3 mm (along the facet's normal, 10.8 mm where it
    reaches the back's edge), or where the ray leaves through a side wall it grazes (from |x| = 8.3
    mm, 17 % of the facets: their material does not end there) the distance to the nearest point of
    the back, 0.06 m - y (within the chord's sag, 20 um). A review found 2.3 mm behind the edge facets, 0.5 mm on a finer mesh, and a
    run ended "worn through"."""
    from multiscale.macro.thickness import facet_thickness
    from multiscale.scene import loads
    from multiscale.workflows.model import build_mesh
    from test_geometry_files import rim_scene
    scene = loads(rim_scene(tmp_path, '["contact", "friction"]', 'interface_mesh_size = "1 mm"') + f"""
rotation_speed = "100 rpm"
friction = 0.4
[geometry.surfaces.bore]
body = "wheel"
contains = [0, 0.01, 0]
[interface]
penalty = "1e13 Pa/m"
[[boundary]]
surfaces = ["back"]
fix = ["x", "z"]
[[boundary]]
surfaces = ["bore"]
fix = ["x", "y", "z"]
[output]
folder = "{tmp_path / 'out'}"
""")
    tm = build_mesh(scene)
    thick = facet_thickness(tm)
    assert (thick.part == 0).all() and thick.value.min() > 9.99e-3 and thick.value.max() < 11.3e-3
    x = np.abs(tm.interface.midpoints[:, 0])
    edge = x > 8.5e-3                               # out by a side along the normal: the nearest back point
    np.testing.assert_allclose(thick.value[edge], 0.06 - np.sqrt(0.05 ** 2 - x[edge] ** 2), rtol=0, atol=2e-5)

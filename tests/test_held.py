"""Rigid motions nothing holds (multiscale/held.py), found by adversarial tests of check_held."""

import pytest

pytest.importorskip("dolfinx_solver", reason="DOLFINx wheel not installed")

from test_geometry_files import TWO_PADS, TWO_PADS_GEO  # noqa: E402

from multiscale.errors import InputError  # noqa: E402
from multiscale.scene import loads  # noqa: E402
from multiscale.workflows.model import build_mesh  # noqa: E402

PAD_A = '[geometry.bodies.pad_a]\ncontains = ["0 mm", "80 mm", "14 mm"]'


def test_a_part_joined_to_another_only_along_an_edge_turns_about_it(tmp_path):
    """pad_c, a second box of pad_a's body on the disc, touches pad_a only along their vertical
    edge at x = 10, y = 70 mm, its own sides unheld. The edge's nodes are shared (one body), so
    the check took pad_a and pad_c for one rigid part, held, and passed; but a shared edge is a
    hinge: pad_c turns about it in the plane of the contact, which holds only its normal. With the
    check bypassed, 4 runs of this scene (OMP_NUM_THREADS=1) each hit 30 Newton iterations and
    ended 'converged' with interface forces 1000.15, 999.98, 1001.33 and 1000.06 N for the 1000 N
    load (without pad_c: 3 iterations, 1000.0 N). Now parts are cells joined through faces, and a
    node two parts share holds only their relative translation there."""
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO + "\nBox(6) = {10, 50, 10, 20, 20, 8};")
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out"))
    assert PAD_A in text
    hinge = text.replace(PAD_A, '[geometry.bodies.pad_a]\ncontains = [["0 mm", "80 mm", "14 mm"], '
                                '["20 mm", "60 mm", "14 mm"]]')
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'pad_a' around "
                                         r"\[20\.0, 60\.0, 14\.0\] mm: rotation about z; it shares only an edge or a "
                                         r"vertex with the part\(s\) of 'pad_a' around \[0\.0, 80\.0, 14\.0\] mm: "
                                         r"a joint holds no turn about it\)"):
        build_mesh(loads(hinge, tmp_path))
    # held at its own sides too, it passes
    sides = hinge.replace('["10 mm", "-80 mm", "14 mm"]]', '["10 mm", "-80 mm", "14 mm"], ["30 mm", "60 mm", "14 mm"]]')
    assert sides != hinge
    assert build_mesh(loads(sides, tmp_path)).interface is not None


TETRA = """
Point(101) = {10, 70, 18}; Point(102) = {30, 50, 10}; Point(103) = {30, 70, 10}; Point(104) = {12, 50, 10};
Line(201) = {101, 102}; Line(202) = {101, 103}; Line(203) = {101, 104};
Line(204) = {102, 103}; Line(205) = {103, 104}; Line(206) = {104, 102};
Curve Loop(301) = {201, 204, -202}; Plane Surface(301) = {301};
Curve Loop(302) = {202, 205, -203}; Plane Surface(302) = {302};
Curve Loop(303) = {203, 206, -201}; Plane Surface(303) = {303};
Curve Loop(304) = {204, 205, 206}; Plane Surface(304) = {304};
Surface Loop(401) = {301, 302, 303, 304}; Volume(6) = {401};
"""


def test_a_part_joined_to_another_at_one_vertex_turns_about_it(tmp_path):
    """A tetrahedron of pad_a's body on the disc whose apex is pad_a's corner (10, 70, 18) mm: one
    shared node, a ball joint; the contact holds its tilts, nothing its turn about the vertical
    through the apex. The check passed it (one part); with the check bypassed, 4 runs took 14, 9,
    9 and 11 Newton iterations, pad_a's peak pressure differing in the 8th digit."""
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO + TETRA)
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out")).replace(
        PAD_A, '[geometry.bodies.pad_a]\ncontains = [["0 mm", "80 mm", "14 mm"], ["24 mm", "62 mm", "11 mm"]]')
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'pad_a' around "
                                         r"\[20\.0, 60\.0, 14\.0\] mm: rotation about z; it shares only an edge or a "
                                         r"vertex with the part\(s\) of 'pad_a' around"):
        build_mesh(loads(text, tmp_path))


# a shaft (r = 10 mm) turning in a bush (r = 20 mm, 20 mm long) whose outer face is held; a force
# pushes the shaft's top along x; the shaft's end is held along z alone
SHAFT_GEO = """SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 30, 10};
Cylinder(2) = {0, 0, 5, 0, 0, 20, 20};
BooleanDifference(3) = { Volume{2}; Delete; }{ Volume{1}; };
"""
SHAFT = """name = "shaft"
effects = ["contact", "friction"]
[geometry]
file = "shaft.geo"
unit = "mm"
mesh_size = "5 mm"
interface_mesh_size = "2 mm"
rotating = "shaft"
[geometry.bodies.bush]
contains = ["15 mm", "0 mm", "15 mm"]
material = "steel"
[geometry.bodies.shaft]
contains = ["0 mm", "0 mm", "15 mm"]
material = "steel"
[geometry.surfaces.outer]
body = "bush"
contains = ["20 mm", "0 mm", "15 mm"]
[geometry.surfaces.end]
body = "shaft"
contains = ["0 mm", "0 mm", "0 mm"]
[geometry.surfaces.top]
body = "shaft"
contains = ["0 mm", "0 mm", "30 mm"]
[materials.steel]
E = "210 GPa"
nu = 0.3
[interface]
penalty = "1e13 Pa/m"
[loading]
faces = ["top"]
direction = [1, 0, 0]
normal_force = "100 N"
rotation_speed = "300 rpm"
friction = 0.4
[[boundary]]
surfaces = ["outer"]
fix = ["x", "y", "z"]
[[boundary]]
surfaces = ["end"]
fix = ["z"]
[time]
end = "1 s"
steps = 1
[output]
folder = "{folder}"
"""


def test_a_turning_body_held_about_its_axis_only_by_the_facets_of_its_interface_is_refused(tmp_path):
    """The shaft's turn about its axis is its sliding along the cylindrical interface: only the
    facets of the meshed cylinder hold it (3e-4 of the largest holding, far above the threshold),
    and the check passed. Friction turns it against them: 2 runs failed the first solve alike
    (SNES -6, 16 iterations, the residual stuck near 7.8 from the 5th on); without friction it
    converged in 7 iterations, and so it does with friction once the top is held along y (which
    holds the turn). With friction the interfaces no longer hold body 1's motion along them."""
    (tmp_path / "shaft.geo").write_text(SHAFT_GEO)
    text = SHAFT.replace("{folder}", str(tmp_path / "out"))
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'shaft' around "
                                         r"\[0\.0, 0\.0, 15\.0\] mm: rotation about z; the facets of its curved "
                                         r"interfaces alone held its sliding along them\)"):
        build_mesh(loads(text, tmp_path))
    assert build_mesh(loads(text.replace('effects = ["contact", "friction"]', 'effects = ["contact"]'), tmp_path))
    assert build_mesh(loads(text + '[[boundary]]\nsurfaces = ["top"]\nfix = ["y"]\n', tmp_path))


def test_a_stationary_part_held_about_the_axis_only_by_the_facets_of_its_interface_is_refused(tmp_path):
    """The same with the shaft held at its end in x, y and z and the bush, loaded along x on its
    outer face, held along z at its bottom: friction turns the bush about the axis, which only the
    facets hold. With the check bypassed, 2 runs failed the first solve, differently (SNES -6 after
    13 iterations, SNES -5 after 30, the residual stuck near 4.77); without friction 2 runs
    converged in 7 iterations with the same answer (134.3112 N through the interface)."""
    (tmp_path / "shaft.geo").write_text(SHAFT_GEO)
    text = (SHAFT.replace("{folder}", str(tmp_path / "out"))
            .replace('surfaces = ["outer"]\nfix = ["x", "y", "z"]', 'surfaces = ["bottom"]\nfix = ["z"]')
            .replace('surfaces = ["end"]\nfix = ["z"]', 'surfaces = ["end"]\nfix = ["x", "y", "z"]')
            .replace('faces = ["top"]', 'faces = ["outer"]')
            .replace('[geometry.surfaces.top]', '[geometry.surfaces.bottom]\nbody = "bush"\n'
                     'contains = ["15 mm", "0 mm", "5 mm"]\n[geometry.surfaces.top]'))
    assert text.count("bottom") == 2
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'bush' around "
                                         r"\[0\.0, 0\.0, 15\.0\] mm: rotation about z; the facets of its curved "
                                         r"interfaces alone held its sliding along them\)"):
        build_mesh(loads(text, tmp_path))
    assert build_mesh(loads(text.replace('effects = ["contact", "friction"]', 'effects = ["contact"]'), tmp_path))


def test_a_part_that_touches_nothing_is_refused_after_meshing(tmp_path):
    """A steel box beside the pads, in pad_b's body, touching nothing and held by no support: it
    could move freely (a squeal run reported its rigid motions as three unstable 0 Hz modes, and
    every other mode's residual rose to 1e-2: an adversarial test). Meshing refuses it, naming the
    region and a point."""
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO + "\nBox(6) = {150, -10, 0, 20, 20, 10};")
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out")).replace(
        '[geometry.bodies.pad_b]\ncontains = ["0 mm", "-80 mm", "14 mm"]',
        '[geometry.bodies.pad_b]\ncontains = [["0 mm", "-80 mm", "14 mm"], ["160 mm", "0 mm", "5 mm"]]')
    with pytest.raises(InputError, match=r"1 part\(s\) touch no interface and no support \(one of region 'pad_b' "
                                         r"around \[160\.0, 0\.0, 5\.0\] mm\): they could move freely"):
        build_mesh(loads(text, tmp_path))


def test_pads_free_to_slide_sideways_are_refused_before_solving(tmp_path):
    """Without the pads' side supports nothing holds them sideways: the contact holds them along
    its normal only. The stiffness is singular, and the first solve failed on one machine and ran
    on another (CI), with whatever sideways position MUMPS gave the pads. Meshing refuses it,
    naming a pad and its free motions; so it does a pad held along x only, a disc whose bore is
    held along z only (the pads' side supports reach its nodes at their edge, not its cells), and
    the pads and disc that can move along z together; with the supports the same mesh passes."""
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO)
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out"))
    free = text.replace('[[boundary]]\nsurfaces = ["sides"]\nfix = ["x", "y"]\n', "")
    assert free != text
    with pytest.raises(InputError, match=r"2 part\(s\) could move as rigid bodies \(one of region 'pad_(a|b)' "
                                         r"around \[0\.0, -?80\.0, 14\.0\] mm: translation along x, translation "
                                         r"along y, rotation about z; also region\(s\) 'pad_(a|b)' around "
                                         r"\[0\.0, -?80\.0, 14\.0\] mm\)"):     # both named (one was: a user trial)
        build_mesh(loads(free, tmp_path))
    sides = ('[geometry.surfaces.sides]\ncontains = [["-10 mm", "80 mm", "14 mm"], ["10 mm", "80 mm", "14 mm"], '
             '["-10 mm", "-80 mm", "14 mm"], ["10 mm", "-80 mm", "14 mm"]]\n')
    assert sides in text
    x_only = text.replace(sides, sides.replace(', ["-10 mm", "-80 mm", "14 mm"], ["10 mm", "-80 mm", "14 mm"]', '')
                          + '[geometry.surfaces.b_sides]\ncontains = [["-10 mm", "-80 mm", "14 mm"], '
                            '["10 mm", "-80 mm", "14 mm"]]\n') + '[[boundary]]\nsurfaces = ["b_sides"]\nfix = ["x"]\n'
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'pad_b' around "
                                         r"\[0\.0, -80\.0, 14\.0\] mm: translation along y\)"):
        build_mesh(loads(x_only, tmp_path))     # pad_b's sides fixed along x only
    bore = 'surfaces = ["bore"]\nfix = ["x", "y", "z"]'
    with pytest.raises(InputError, match=r"1 part\(s\) could move as rigid bodies \(one of region 'disc' around "
                                         r"\[0\.0, 0\.0, 5\.0\] mm: translation along x, translation along y, "
                                         r"rotation about z\)"):   # a support at the edge of the pads' sides
        build_mesh(loads(text.replace(bore, 'surfaces = ["bore"]\nfix = ["z"]'), tmp_path))   # holds no disc
    with pytest.raises(InputError, match=r"3 part\(s\) could move as rigid bodies \(one of region '\w+' around .*: "
                                         r"translation along z, together with region\(s\) '\w+', '\w+'\)"):
        build_mesh(loads(text.replace(bore, 'surfaces = ["bore"]\nfix = ["x", "y"]'), tmp_path))  # all along z
    held = build_mesh(loads(text, tmp_path))
    assert held.interface is not None


def test_check_cells_refuses_what_meshing_would(tmp_path, capsys):
    """`check --cells` meshes (its trials): the pads without side supports are refused there as the run
    refuses them at meshing, naming the pads' free motions (a user trial's scene was OK by check and
    refused by run); the supported pads pass."""
    from multiscale.cli import main
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO)
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out"))
    (tmp_path / "free.toml").write_text(text.replace('[[boundary]]\nsurfaces = ["sides"]\nfix = ["x", "y"]\n', ""))
    (tmp_path / "held.toml").write_text(text)
    assert main(["check", str(tmp_path / "free.toml"), "--cells"]) == 2
    err = capsys.readouterr().err
    assert "error: geometry = 'pad_" in err and "could move as rigid bodies" in err and "1 problem" in err
    assert main(["check", str(tmp_path / "held.toml"), "--cells"]) == 0
    assert "held.toml: OK" in capsys.readouterr().out


def test_a_load_face_held_along_its_normals_under_a_fluid_load_is_refused_at_meshing(tmp_path, capsys):
    """A fluid pressure on the pads' backs and sides, the sides fixed in x and y: the sides' load
    pushes along their normals (x), which the support takes whole. The scene refused a support on a
    load face only if it fixed every component (a pressure's normals are not in the scene); a trial's
    abutments so held passed check, and the run warned afterwards that a pad carried no force.
    Meshing refuses it, and so does `check --cells`; loaded on the backs alone it passes."""
    from multiscale.cli import main
    (tmp_path / "twopads.geo").write_text(TWO_PADS_GEO)
    text = TWO_PADS.replace("{folder}", str(tmp_path / "out")).replace('normal_force = "1000 N"', 'pressure = "1 MPa"')
    both = text.replace('faces = ["backs"]', 'faces = ["backs", "sides"]')
    assert both != text
    refusal = (r"loading.faces = 'sides': a load face whose supports fix \['x', 'y'\], every component the load "
               r"pushes along its normals: they would take the load and the contact none")
    with pytest.raises(InputError, match=refusal):
        build_mesh(loads(both, tmp_path))
    (tmp_path / "both.toml").write_text(both)
    assert main(["check", str(tmp_path / "both.toml"), "--cells"]) == 2
    assert "error: loading.faces = 'sides': a load face whose supports fix" in capsys.readouterr().err
    assert build_mesh(loads(text, tmp_path)).interface is not None

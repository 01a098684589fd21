"""Rigid motions nothing holds (multiscale/macro/held.py), found by adversarial tests of check_held."""

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
                                         r"\[20\.0, 60\.0, 14\.0\] mm: rotation about z"):
        build_mesh(loads(hinge, tmp_path))
    # held at its own sides too, it passes
    sides = hinge.replace('["10 mm", "-80 mm", "14 mm"]]', '["10 mm", "-80 mm", "14 mm"], ["30 mm", "60 mm", "14 mm"]]')
    assert sides != hinge
    assert build_mesh(loads(sides, tmp_path)).interface is not None

"""Mode pairing by MAC (``multiscale modes``) on synthetic shapes: MAC against its definition, blind
to a mode's complex scale (a run's phase and sign are its solver's), pairs found through a
reordering, a frequency of 0 without a shift, another mesh refused, a reverse run mirrored."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.mode_pairs import ModeSet, mac, mirrored, pair, report

RNG = np.random.default_rng(3)
POINTS = RNG.random((40, 3))
SHAPES = RNG.standard_normal((120, 4)) + 1j * RNG.standard_normal((120, 4))


def modes(order, scale=1.0, points=POINTS, frequency=(0.0, 1000.0, 2000.0, 3000.0)):
    f = np.asarray(frequency)[list(order)]
    return ModeSet("run", np.arange(1, 5), f, np.zeros(4), points, SHAPES[:, list(order)] * scale)


def test_mac_is_its_definition_and_blind_to_a_modes_complex_scale():
    a, b = SHAPES[:, 0], SHAPES[:, 1]
    expected = abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real)
    assert mac(SHAPES, SHAPES * (-2 + 3j))[0, 1] == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(np.diag(mac(SHAPES, SHAPES * (0.5 - 1j))), 1.0, rtol=1e-12)


def test_modes_are_paired_through_a_reordering_and_a_zero_frequency_has_no_shift():
    p = pair(modes((0, 1, 2, 3)), modes((2, 0, 3, 1), scale=1j))
    assert list(p.best) == [1, 3, 0, 2] and np.allclose(p.mac[np.arange(4), p.best], 1.0)
    assert np.isnan(p.shift[0]) and np.allclose(p.shift[1:], 0.0)
    assert "nan" in report(p)[2] and len(report(p)) == 6


def test_another_mesh_is_refused():
    with pytest.raises(InputError, match="MAC compares runs of one mesh"):
        pair(modes(range(4)), modes(range(4), points=POINTS + 1e-3))


def test_a_folder_without_modes_is_said_for_what_it_is(tmp_path):
    """`multiscale modes A B` with B a folder that does not exist said only what a results folder
    holds (a user trial); now: no such folder, not a folder, or which file it lacks."""
    from multiscale.mode_pairs import read_modes
    (tmp_path / "file").write_text("")
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "modes.csv").write_text("")
    for name, said in (("nowhere", "no such folder"), ("file", "not a folder"), ("run", "it holds no modes_<part>.bp")):
        with pytest.raises(InputError, match=f"modes_<part>.bp\\); {said}"):
            read_modes(tmp_path / name)


def mirror_image(shapes, points, twin):
    """Shapes (3 n, m) of the mirror image in x of the field ``shapes`` on ``points``: the value at node
    i is the reflected value at node ``twin[i]``, the reflection of node i."""
    field = shapes.reshape(len(points), 3, -1)[twin].copy()
    field[:, 0] *= -1
    return field.reshape(3 * len(points), -1)


def test_a_reverse_run_is_paired_with_the_forward_one_mirrored():
    """A brake symmetric about a plane, turned the other way, is the mirror image of the forward
    one: its modes are the forward modes mirrored. Here a part whose nodes are symmetric about
    x = 0.5 (the middle of its extent) and a second part on the very same points (a pad's face on
    the disc's): B's modes are A's mirrored, reordered and rescaled. Mirrored, B's nodes fall on
    A's (distance 0) and every pair is found with MAC 1; unmirrored, the pairs are lost; the parts
    are not mixed although their nodes coincide."""
    half = RNG.random((20, 3)) * [0.5, 1.0, 1.0] + [0.5, 0.0, 0.0]
    part = np.concatenate([half, half * [-1, 1, 1] + [1, 0, 0]])
    points = np.concatenate([part, part])
    twin = np.concatenate([np.arange(20, 40), np.arange(20), np.arange(60, 80), np.arange(40, 60)])
    shapes = RNG.standard_normal((240, 4)) + 1j * RNG.standard_normal((240, 4))
    a = ModeSet("forward", np.arange(1, 5), np.array([1e3, 2e3, 3e3, 4e3]), np.zeros(4), points, shapes, (40, 40))
    order = [3, 1, 0, 2]
    b = ModeSet("reverse", np.arange(1, 5), a.frequency[order], np.zeros(4), points,
                mirror_image(shapes, points, twin)[:, order] * (0.3 - 2j), (40, 40))
    p = pair(a, mirrored(b, "x"), transfer=True)
    assert list(p.best) == [2, 1, 3, 0] and p.distance.max() == 0.0
    np.testing.assert_allclose(p.mac[np.arange(4), p.best], 1.0, rtol=1e-12)
    assert "mirrored in x" in report(p)[0] and "distance: median 0 mm" in report(p)[1]
    assert pair(a, b).mac.max() < 0.5                         # as they are: no pair
    with pytest.raises(InputError, match="the normal of the plane of symmetry"):
        mirrored(b, "w")


def test_a_mirrored_run_on_a_mesh_not_symmetric_node_for_node_is_taken_at_the_nearest_nodes():
    """A mesh symmetric in shape but not node for node (gmsh's): B's nodes are A's jittered by up to
    1 % of the extent, its modes the mirror images of smooth fields (wavelengths of the extent).
    Taken at A's nodes from the nearest node, the pairs keep MAC >= 0.99; B's nodes as they are
    refuse the comparison (another mesh)."""
    grid = np.stack(np.meshgrid(*[np.linspace(0, 1, 9)] * 3, indexing="ij"), -1).reshape(-1, 3)
    moved = grid + RNG.uniform(-0.01, 0.01, grid.shape)

    def smooth(p, k):                                          # mode k: a field of wavelength 2 / k
        wave = np.exp(1j * np.pi * k * (p @ [1.0, 0.7, 0.4]))[:, None]
        return (wave * [1.0, 0.5j, -0.3] * (1 + p[:, :1])).ravel()
    a = ModeSet("forward", np.arange(1, 4), np.array([1e3, 2e3, 3e3]), np.zeros(3), grid,
                np.stack([smooth(grid, k) for k in (1, 2, 3)], 1), (len(grid),))
    image = moved * [-1, 1, 1] + [1, 0, 0]                     # B's field at its node i: A's at the image of i
    field = np.stack([smooth(image, k) for k in (1, 2, 3)], 1).reshape(len(grid), 3, 3)
    field[:, 0] *= -1
    b = ModeSet("reverse", np.arange(1, 4), a.frequency, np.zeros(3), moved, field.reshape(-1, 3), (len(grid),))
    p = pair(a, mirrored(b, "x"), transfer=True)
    assert list(p.best) == [0, 1, 2] and p.mac[np.arange(3), p.best].min() >= 0.99
    assert 0 < p.distance.max() <= 0.01 * 3 ** 0.5 + 0.02
    with pytest.raises(InputError, match="mirrored in x"):
        pair(a, mirrored(b, "x"))

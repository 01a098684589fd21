"""Nodal diameters of a disc's mode shapes (``macro.nodal_diameters``) on manufactured shapes:
standing and travelling waves, in-plane and out-of-plane, a nodal circle, a tilted axis off the
origin (two ranks: tests/mpi/test_squeal_mpi.py)."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.macro.nodal_diameters import nodal_diameters

AXIS, CENTRE = np.array([1.0, 2.0, 0.5]) / np.sqrt(5.25), np.array([0.3, -0.1, 0.2])


def annulus(n=6000, seed=0):
    """Nodes spread evenly over an annulus of radii 80-150 mm and 20 mm thickness about AXIS, and
    the cylindrical unit vectors there: axial, radial, tangential; the angle; the radius."""
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform(0.08**2, 0.15**2, n))
    theta = rng.uniform(0, 2 * np.pi, n)
    a = np.cross(AXIS, [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    b = np.cross(AXIS, a)
    er = np.outer(np.cos(theta), a) + np.outer(np.sin(theta), b)
    points = CENTRE + r[:, None] * er + np.outer(rng.uniform(-0.01, 0.01, n), AXIS)
    return points, np.broadcast_to(AXIS, er.shape), er, np.cross(AXIS, er), theta, r


def test_manufactured_shapes_are_named_by_their_nodal_diameters():
    points, ez, er, et, theta, r = annulus()
    shapes = [np.cos(3 * theta + 0.4)[:, None] * (r - 0.115)[:, None] * ez,   # 3 ND, one nodal circle
              np.cos(5 * theta)[:, None] * er,                         # 5 ND in-plane (radial)
              np.exp(4j * theta)[:, None] * ez,                        # 4 ND travelling
              et,                                                      # 0 ND in-plane (torsion)
              np.cos(2 * theta)[:, None] * ez + 0.1 * np.sin(7 * theta)[:, None] * er]   # 2 ND + 1 % of 7 ND
    motion = np.stack(shapes, axis=2)
    d = nodal_diameters(points, motion, 3 * AXIS, CENTRE + 2 * AXIS)   # any length, any point of the axis
    assert list(d.nodal_diameters) == [3, 5, 4, 0, 2]
    assert list(d.axial_nodal_diameters)[::2] == [3, 4, 2]        # (the in-plane ones have no axial motion)
    inplane = np.cos(5 * theta)[:, None] * er + 0.2 * np.cos(3 * theta)[:, None] * ez   # radial 5 ND, axial 3 ND
    both = nodal_diameters(points, inplane[:, :, None], AXIS, CENTRE)
    assert (both.nodal_diameters[0], both.axial_nodal_diameters[0]) == (5, 3) and both.out_of_plane[0] < 0.1
    bending, radial = np.sum(np.cos(2 * theta) ** 2), 0.01 * np.sum(np.sin(7 * theta) ** 2)
    np.testing.assert_allclose(d.out_of_plane, [1, 0, 1, 0, bending / (bending + radial)], atol=1e-12)
    assert np.all(d.share > 0.95)                                      # measured 0.988-1 (even spread: Parseval)


def test_bad_shapes_are_named():
    points, *_ = annulus(10)
    with pytest.raises(InputError, match=r"motion.shape"):
        nodal_diameters(points, np.zeros((10, 2, 1)), AXIS, CENTRE)
    with pytest.raises(InputError, match="axis"):
        nodal_diameters(points, np.zeros((10, 3, 1)), (0, 0, 0), CENTRE)

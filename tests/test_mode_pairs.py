"""Mode pairing by MAC (``multiscale modes``) on synthetic shapes: MAC against its definition, blind
to a mode's complex scale (a run's phase and sign are its solver's), pairs found through a
reordering, a frequency of 0 without a shift, another mesh refused."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.mode_pairs import ModeSet, mac, pair, report

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

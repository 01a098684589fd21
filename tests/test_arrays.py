"""multiscale.arrays against numpy's own unique(axis=0)."""
import numpy as np
import pytest

from multiscale.arrays import unique_rows


@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.float64])
def test_unique_rows_are_numpys(dtype):
    rng = np.random.default_rng(7)
    a = rng.integers(-3, 4, size=(500, 3)).astype(dtype)          # many repeats, negatives
    a = np.vstack([a, a[::7]])
    got = unique_rows(a)
    values, first, inverse, counts = np.unique(a, axis=0, return_index=True, return_inverse=True,
                                               return_counts=True)
    assert got.values.dtype == a.dtype
    np.testing.assert_array_equal(got.values, values)
    np.testing.assert_array_equal(got.first, first)
    np.testing.assert_array_equal(got.inverse, inverse.ravel())
    np.testing.assert_array_equal(got.counts, counts)
    np.testing.assert_array_equal(got.values[got.inverse], a)


def test_unique_rows_of_signed_zeros_empty_and_flat_input():
    assert unique_rows(np.array([[0.0, 1.0], [-0.0, 1.0], [0.0, -1.0]])).counts.tolist() == [1, 2]
    empty = unique_rows(np.empty((0, 2), np.int32))
    assert empty.values.shape == (0, 2) and empty.inverse.size == empty.counts.size == 0
    with pytest.raises(ValueError, match="2-D"):
        unique_rows(np.arange(4))

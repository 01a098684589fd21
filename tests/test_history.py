"""``io.History``: rows in, columns out, and written to HDF5 and read back unchanged."""
import numpy as np
import pytest

from multiscale.io import History


def test_a_history_is_read_as_its_columns_and_names_a_missing_one(tmp_path):
    """``in`` and iteration go over the column names, ``len`` counts the rows (as a pandas
    DataFrame; ``"time" in history`` raised KeyError: 0, a user trial), and an unknown column is
    refused naming the close ones; a file round trip keeps every value and per-zone column."""
    h = History()
    for t in (0.0, 0.5, 1.0):
        h.append(time=t, max_temperature_disc=293.15 + 10 * t, zone_pressure=np.full(3, t))
    assert len(h) == 3 and list(h) == ["time", "max_temperature_disc", "zone_pressure"]
    assert "time" in h and "temperature" not in h and 0 not in h
    with pytest.raises(KeyError, match=r"no history column 'max_temperature'; did you mean 'max_temperature_disc'\?"):
        h["max_temperature"]
    with pytest.raises(KeyError, match=r"no history column 0; 3 columns, e\.g\. time, max_temperature_disc"):
        h[0]
    with pytest.raises(KeyError, match="differ from"):
        h.append(time=1.5)
    back = History.read(h.write(tmp_path / "history.h5"))
    assert sorted(back) == sorted(h) and back["zone_pressure"].shape == (3, 3)
    for name in h:
        np.testing.assert_array_equal(back[name], h[name])

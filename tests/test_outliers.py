"""Outliers of measured topographies (docs/architecture.md §7, formerly "no outlier removal"):
found by ``micro.outliers.find_outliers`` (a point deviating from its 9 x 9 neighbourhood's median
by more than k Sq of the other heights), warned of by ``condition`` and ``multiscale check``,
removed with ``despike`` (CLI ``--despike K``, scene ``roughness.despike``) and filled like the
instrument's undefined points."""
import os
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.ndimage
from scipy.stats import norm

from multiscale.cli import main
from multiscale.errors import InputError
from multiscale.micro.outliers import DESPIKE, find_outliers
from multiscale.micro.spectrum import surface_statistics
from multiscale.micro.topography import Measurement, TopographyWarning, condition, read_topography
from multiscale.scene import loads

ROOT = Path(__file__).resolve().parents[1]
SHARED = next((p for p in (Path(os.environ.get("MULTISCALE_TOPOGRAPHIES", "/nonexistent")),
                           ROOT.parent / "shared/data/topographies") if p.is_dir()), None)
# planted: isolated spikes and pits, a 2 x 2 pit, one at a corner, one beside an undefined point
PLANTED = {(40, 50): 25.0, (100, 200): -30.0, (150, 20): 18.0, (0, 0): -20.0, (61, 81): 40.0,
           **{(r, c): -22.0 for r in (200, 201) for c in (300, 301)}}
HOLE = (61, 80)


def gaussian(seed, shape=(240, 320), correlation=3.0):
    """A Gaussian surface [m], Sq 1e-7 (white noise smoothed over ``correlation`` pixels)."""
    h = np.random.default_rng(seed).normal(size=shape)
    h = scipy.ndimage.gaussian_filter(h, correlation, mode="wrap") if correlation else h
    return 1e-7 * h / h.std()


def spiky(seed):
    """``gaussian`` with ``PLANTED`` (in its Sq) and one undefined point beside a spike."""
    h = gaussian(seed)
    for (r, c), size in PLANTED.items():
        h[r, c] += size * 1e-7
    h[HOLE] = np.nan
    return h


def measurement(h, path=Path("spiky.npy")):
    return Measurement(h, 1e-6, 1e-6, path, 0, "matrix", None, ())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_planted_outliers_are_found_exactly_and_none_on_the_clean_surface(seed):
    assert find_outliers(gaussian(seed)).count == 0
    found = find_outliers(spiky(seed))
    assert set(zip(found.rows.tolist(), found.cols.tolist())) == set(PLANTED)
    assert found.largest / found.sq == pytest.approx(40.0, abs=3.0)        # the +40 Sq spike, its neighbours' ±3
    assert found.sq == pytest.approx(1e-7, rel=0.02)                        # Sq without them
    assert found.dominated and found.shares[1] > 0.9


@pytest.mark.parametrize("seed", [0, 1])
def test_the_share_of_sdq2_the_outliers_carry_is_that_of_the_whole_map(seed):
    """The warning said only that Ssk and Sku were the outliers'; on sur-2.sur they carry 93 % of Sdq²
    too, and a surface drawn from the spectrum (cover = "equivalent") had a third of the contact
    area (a user trial). The share is checked against Sdq² of the whole map, with the outliers
    set to their neighbourhood's median, by numpy differences (pixels 1 x 2 um, a hole beside one)."""
    h = spiky(seed)
    found = find_outliers(h)
    clean = h.copy()
    clean[found.rows, found.cols] -= found.deviations

    def sdq2(z):
        return np.nansum((np.diff(z, axis=1) / 1e-6) ** 2) + np.nansum((np.diff(z, axis=0) / 2e-6) ** 2)
    expected = 1 - sdq2(clean) / sdq2(h)
    assert found.gradient_share(h, 1e-6, 2e-6) == pytest.approx(expected, rel=1e-9)
    assert 0.1 < expected < 0.95
    assert "of Sdq² is theirs: the slopes, the spectrum's short wavelengths" in found.note(
        "x.npy", "--despike 7", expected)
    assert find_outliers(gaussian(seed)).gradient_share(gaussian(seed), 1e-6, 1e-6) == 0.0


def test_the_false_positive_rate_on_uncorrelated_gaussian_heights_is_about_2_phi_minus_k():
    """The worst case (module docstring): 3 seeds of 512² uncorrelated heights, 786 432 points:
    none at the default k = 7 (expected 2e-6); at k = 4, 2Φ(−4) N = 50 expected: within 30 to 80."""
    counts = {k: sum(find_outliers(gaussian(seed, (512, 512), 0)).count if k == DESPIKE else
                     find_outliers(gaussian(seed, (512, 512), 0), k).count for seed in range(3)) for k in (DESPIKE, 4)}
    assert counts[DESPIKE] == 0 and 2 * norm.sf(DESPIKE) * 786432 < 1e-5
    assert 30 <= counts[4] <= 80, (counts, 2 * norm.sf(4) * 786432)


def test_condition_warns_and_keeps_them_unless_despike_removes_them():
    m = measurement(spiky(0))
    with pytest.warns(TopographyWarning, match=r"outliers in 'spiky.npy': 9 points deviating from the median of "
                                               r"their 9 x 9 neighbourhood by more than 7 Sq "
                                               r"\(Sq 99.9 nm without them\), up to \+39.6 Sq"):
        kept = condition(m)
    line = next(line for line in kept.report if line.startswith("warning: outliers"))
    assert "Ssk and Sku are theirs, not the surface's; " in line and "; kept (despike = 7 removes them" in line
    assert kept.notes == (line.removeprefix("warning: "),)
    assert kept.surface.heights.max() > 30e-7 and "filled 1 undefined points (0.00%)" in kept.report[-1]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        removed = condition(m, despike=7)
    assert removed.notes == () and not any(line.startswith("warning") for line in removed.report)
    assert "removed 9 outliers (despike = 7), points deviating" in removed.report[-2]
    assert "filled 10 undefined points" in removed.report[-1]
    clean = surface_statistics(condition(measurement(gaussian(0))).surface)
    stats = surface_statistics(removed.surface)
    assert abs(stats.Ssk - clean.Ssk) < 0.05 and abs(stats.Sku - clean.Sku) < 0.1
    assert abs(surface_statistics(kept.surface).Sku - clean.Sku) > 5       # what the warning is about
    with pytest.raises(InputError, match="despike = 0"):
        condition(m, despike=0)
    with pytest.raises(InputError, match="10 of spiky.npy's 76800 points are undefined or outliers"):
        condition(m, despike=7, max_undefined=1e-4)


def test_before_a_waviness_filter_outliers_are_judged_against_the_roughness():
    """``spiky`` (Sq 100 nm, pits and spikes of 18-40 Sq) on a waviness of 2 um amplitude and 200 um
    wavelength: against the Sq of the heights (1.3 um) no point is an outlier, and the roughness
    left by λc = 50 um kept them all (Sku 28 where the clean one has 3; sur-2.sur at λc = 0.5 mm
    kept Sku 57: a user trial). With the cut-off they are judged against the roughness' Sq and
    found, as on the flat map, and said to be so."""
    x = np.arange(320) * 1e-6
    wavy = spiky(0) + 2e-6 * np.sin(2 * np.pi * x / 200e-6)[None, :]
    assert find_outliers(wavy).count == 0
    with pytest.warns(TopographyWarning, match=r"outliers in 'spiky.npy': 9 points .* by more than 7 Sq \(Sq 12\d "
                                               r"nm of the roughness at λc = 0.05 mm without them\)"):
        condition(measurement(wavy), cutoff=50e-6)
    removed = condition(measurement(wavy), despike=7, cutoff=50e-6)
    assert "removed 9 outliers (despike = 7)" in removed.report[-3]
    clean = surface_statistics(condition(measurement(gaussian(0) + wavy - spiky(0)), cutoff=50e-6).surface)
    assert abs(surface_statistics(removed.surface).Sku - clean.Sku) < 0.2       # the map without them


@pytest.mark.skipif(SHARED is None, reason="../shared/data/topographies not here")
def test_sur2s_pits_are_found_and_without_them_its_ssk_and_sku_are_a_surfaces():
    """sur-2.sur: Ssk −15.6, Sku 787 from 100 points up to 1.2 um deep (Sq 17 nm); without them
    −0.47 and 2.50 (a Gaussian surface's: 0 and 3)."""
    m = read_topography(SHARED / "sur-2.sur")
    with pytest.warns(TopographyWarning, match=r"outliers in 'sur-2.sur': 100 points .* up to -89.4 Sq \(-1236 nm\)"):
        kept = condition(m)
    assert "Ssk and Sku are theirs" in kept.notes[0]
    before, after = surface_statistics(kept.surface), surface_statistics(condition(m, despike=DESPIKE).surface)
    assert before.Ssk < -15 and before.Sku > 700
    assert abs(after.Ssk) < 1.0 and 2.0 < after.Sku < 4.0


def test_surface_command_warns_and_removes_with_despike(tmp_path, capsys):
    path = tmp_path / "spiky.npy"
    np.save(path, spiky(1))
    assert main(["surface", str(path), "--pixel-size", "1 um"]) == 0
    out = capsys.readouterr().out
    assert "warning: outliers in 'spiky.npy': 9 points" in out and "kept (--despike 7 removes them" in out
    assert main(["surface", str(path), "--pixel-size", "1 um", "--despike", "7"]) == 0
    out = capsys.readouterr().out
    assert "warning" not in out and "removed 9 outliers (--despike 7)" in out and "filled 10 undefined" in out
    assert main(["surface", str(path), "--pixel-size", "1 um", "--despike", "-1"]) == 2
    assert "--despike = -1" in capsys.readouterr().err


SCENE = (ROOT / "demos" / "block_on_flat.toml").read_text().replace(
    'effects = ["contact"]', 'effects = ["contact", "roughness"]').replace('penalty = "1e13 Pa/m"', "") + """
[roughness]
body = "block"
file = "spiky.npy"
pixel_size = "1 um"
cover = "tile"
{despike}
[micro]
zones = [2, 2]
grid = [16, 16]
"""


def test_scene_warns_when_read_and_the_run_removes_with_roughness_despike(tmp_path):
    from multiscale.workflows import rough
    np.save(tmp_path / "spiky.npy", spiky(2))
    warned = loads(SCENE.format(despike=""), tmp_path)
    said = [w for w in warned.warnings if "of the measured RMS gradient" not in w      # (the 1 um pixels on 312 um
            and not w.startswith('roughness.cover = "tile"')]          # cells, the tiles: not the subject here)
    assert len(said) == 1 and said[0].startswith("outliers in 'spiky.npy': 9 points")
    assert "kept (roughness.despike = 7 removes them" in said[0]
    lines = []
    rough.make_zones(warned.roughness, warned.micro, (0.0, 0.0), (2e-4, 2e-4), seed=0, log=lines.append)
    assert not any("outliers" in line for line in lines)        # said once, as the scene's warning
    despiked = loads(SCENE.format(despike="despike = 7"), tmp_path)
    assert not [w for w in despiked.warnings if "of the measured RMS gradient" not in w
                and not w.startswith('roughness.cover = "tile"')]
    assert despiked.roughness.despike == 7
    rough.make_zones(despiked.roughness, despiked.micro, (0.0, 0.0), (2e-4, 2e-4), seed=0, log=lines.append)
    assert any(line.startswith("roughness: removed 9 outliers (roughness.despike = 7)") for line in lines)
    with pytest.raises(Exception, match="roughness.despike"):
        loads(SCENE.format(despike="despike = 0"), tmp_path)

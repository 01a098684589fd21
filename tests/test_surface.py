"""Rough surfaces: PSD band, determinism, statistics, import, asperity detection (thesis §1.3.1)."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro.reading import read_topography
from multiscale.micro.surface import Surface, find_asperities, fractal_surface, refine, statistics
from multiscale.micro.topography import remove_form


def test_same_seed_same_surface_and_rms():
    a = fractal_surface(64, 1e-3, 0.95, 2, 10, 2e-6, seed=11)
    b = fractal_surface(64, 1e-3, 0.95, 2, 10, 2e-6, seed=11)
    c = fractal_surface(64, 1e-3, 0.95, 2, 10, 2e-6, seed=12)
    np.testing.assert_array_equal(a.heights, b.heights)
    assert not np.allclose(a.heights, c.heights)
    assert np.sqrt(np.mean(a.heights**2)) == pytest.approx(2e-6, rel=1e-12)
    assert abs(a.heights.mean()) < 1e-20


def test_anisotropic_surface_has_requested_cutoffs():
    s = fractal_surface((128, 96), (1e-3, 0.75e-3), 0.95, 2, (7, 12), 1e-6, seed=3)
    assert s.heights.shape == (96, 128)
    P = np.abs(np.fft.rfft2(s.heights)) ** 2
    kx = np.fft.rfftfreq(128, 1 / 128)[None, :]
    ky = np.fft.fftfreq(96, 1 / 96)[:, None]
    on = P > 1e-20 * P.max()
    inside = ((kx / 7) ** 2 + (ky / 12) ** 2 <= 1 + 1e-12) & ((kx / 2) ** 2 + (ky / 2) ** 2 >= 1 - 1e-12)
    assert np.all(inside[on]) and np.all(on[inside])                  # exactly the requested band
    assert kx[0, np.nonzero(on.any(axis=0))[0].max()] == 7
    assert np.abs(ky[np.nonzero(on.any(axis=1))[0], 0]).max() == 12


def test_power_law_slope_of_psd():
    H = 0.8
    s = fractal_surface(256, 1e-3, H, 4, 100, 1e-6, seed=5, batch=(8,))
    P = (np.abs(np.fft.rfft2(s.heights)) ** 2).mean(axis=0)
    k = np.hypot(np.fft.fftfreq(256, 1 / 256)[:, None], np.fft.rfftfreq(256, 1 / 256)[None, :])
    band = (k > 6) & (k < 90)
    slope = np.polyfit(np.log(k[band]), np.log(P[band]), 1)[0]
    assert slope == pytest.approx(-2 * (H + 1), abs=0.05)


def test_every_wavevector_of_one_length_has_the_same_power():
    """Isotropic: the power |h(q)|^2 depends on |q| only, on the kx = 0 and ky = 0 lines too, in
    every patch (the phases are random, the amplitudes exact). The kx = 0 line had half the power
    (irfft2 keeps the real part of a non-Hermitian column: an adversarial test); the mean slopes
    along x and y then differed by 5 % at the tutorial's settings."""
    s = fractal_surface(64, 1e-3, 0.8, 1, 32, 1e-6, seed=1, batch=(3,))
    P = np.abs(np.fft.fft2(s.heights)) ** 2
    for a, b in (((0, 5), (3, 4)), ((5, 0), (3, 4)), ((0, 5), (0, -5)), ((0, 3), (3, 0)), ((0, 32), (32, 0))):
        np.testing.assert_allclose(P[:, a[0], a[1]], P[:, b[0], b[1]], rtol=1e-9)
    hx, hy = np.gradient(fractal_surface(256, 1e-3, 0.8, 2, 64, 1e-6, seed=0, batch=(50,)).heights, axis=(-1, -2))
    assert np.mean(hx ** 2) / np.mean(hy ** 2) == pytest.approx(1.0, abs=0.02)       # was 1.05


def test_statistics_of_a_sinusoid():
    n, L, A = 64, 1e-3, 1e-6
    x = (np.arange(n) + 0.5) * L / n
    q = 2 * np.pi * 3 / L
    h = A * np.cos(q * x)[None, :] * np.ones((n, 1))
    st = statistics(Surface(h, L / n, L / n))
    assert st.m0 == pytest.approx(A**2 / 2, rel=1e-12)
    assert st.rms_slope == pytest.approx(A * q / np.sqrt(2), rel=1e-12)
    assert st.m2 == pytest.approx(A**2 * q**2 / 4, rel=1e-12)      # average of x (A²q²/2) and y (0)
    assert st.m4 == pytest.approx(A**2 * q**4 / 4, rel=1e-12)
    assert st.nayak == pytest.approx(2.0, rel=1e-12)
    assert np.ndim(st.nayak) == 0 and "array" not in repr(st)     # one surface: scalars (nayak was a 0-d array)
    fd = statistics(Surface(h, L / n, L / n, periodic=False))        # finite differences
    assert fd.rms_slope == pytest.approx(st.rms_slope, rel=2e-2)


@pytest.mark.parametrize("theta", [0.0, 0.4, 1.3, 2.8])
def test_asperity_radii_and_direction_of_elliptic_paraboloid(theta):
    n, dx, R1, R2 = 33, 1e-6, 3e-3, 1e-3
    x = (np.arange(n) - 16) * dx
    X, Y = np.meshgrid(x, x)
    xr, yr = X * np.cos(theta) + Y * np.sin(theta), -X * np.sin(theta) + Y * np.cos(theta)
    h = -xr**2 / (2 * R1) - yr**2 / (2 * R2)
    t = find_asperities(Surface(h, dx, dx, periodic=False))
    assert len(t) == 1 and t.row[0] == 16 and t.col[0] == 16
    assert t.R1[0] == pytest.approx(R1, rel=1e-9) and t.R2[0] == pytest.approx(R2, rel=1e-9)
    assert t.angle[0] == pytest.approx(theta % np.pi, abs=1e-9)
    assert t.eccentricity[0] == pytest.approx(np.sqrt(1 - (R2 / R1) ** (4 / 3)), rel=1e-12)


def test_summits_are_strict_8_neighbour_maxima():
    s = fractal_surface(64, 1e-3, 0.9, 2, 20, 1e-6, seed=2)
    t = find_asperities(s)
    h = s.heights
    for r, c in zip(t.row, t.col):
        window = np.roll(np.roll(h, 1 - r, 0), 1 - c, 1)[:3, :3]
        assert (window < h[r, c]).sum() == 8
    brute = sum(1 for r in range(64) for c in range(64)
                if (np.roll(np.roll(h, 1 - r, 0), 1 - c, 1)[:3, :3] < h[r, c]).sum() == 8)
    assert len(t) <= brute and len(t) >= 0.9 * brute         # only non-definite Hessians dropped
    assert np.all(t.R1 >= t.R2) and np.all(t.R2 > 0)


def test_import_npy_txt_csv(tmp_path):
    """Plain height matrices (``read_topography`` with a pixel size) read exactly; the plane removed
    (``topography.remove_form``) leaves heights orthogonal to 1, x and y."""
    rng = np.random.default_rng(0)
    h = rng.normal(size=(16, 18))
    np.save(tmp_path / "s.npy", h)
    np.savetxt(tmp_path / "s.txt", h)
    np.savetxt(tmp_path / "s.csv", h, delimiter=",")
    for name in ("s.npy", "s.txt", "s.csv"):
        m = read_topography(tmp_path / name, pixel_size=2e-6, height_unit=1e-6)
        np.testing.assert_allclose(m.heights, h * 1e-6, rtol=1e-12)
        assert m.dx == m.dy == 2e-6
    tilted = h + 3.0 * np.arange(18)[None, :] - 2.0 * np.arange(16)[:, None]
    flat = remove_form(tilted, "plane")
    Y, X = np.mgrid[:16, :18]
    A = np.column_stack([np.ones(h.size), X.ravel(), Y.ravel()])
    assert np.abs(A.T @ flat.ravel()).max() < 1e-9          # plane removed


def test_bad_surface_input(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_topography(tmp_path / "missing.npy", pixel_size=1e-6)
    (tmp_path / "bad.csv").write_text("1,2,x\n3,4,5\n")
    with pytest.raises(InputError, match="could not read a height matrix"):
        read_topography(tmp_path / "bad.csv", pixel_size=1e-6)
    # an empty file, a row, complex or boolean values: one clear error (before: a ZeroDivisionError
    # later, a read row, the imaginary part dropped with numpy's ComplexWarning)
    (tmp_path / "empty.txt").write_text("# no data\n")
    np.save(tmp_path / "row.npy", np.ones((1, 9)))
    np.save(tmp_path / "small.npy", np.ones((3, 9)))    # said 2 x 2 here, 4 x 4 in Surface
    np.save(tmp_path / "complex.npy", np.ones((8, 8)) * (1 + 1j))
    np.save(tmp_path / "mask.npy", np.ones((8, 8), bool))
    (tmp_path / "empty.npy").write_bytes(b"")          # numpy's EOFError came through as a traceback
    for name, why in [("empty.txt", r"the height matrix has 1 x 0 points: a height map of at least 4 x 4"),
                      ("empty.npy", r"the file is empty \(0 bytes\)"),
                      ("row.npy", r"has 9 x 1 points: a height map of at least 4 x 4 points is needed"),
                      ("small.npy", r"has 9 x 3 points: a height map of at least 4 x 4 points is needed"),
                      ("complex.npy", "real numbers, not complex128"), ("mask.npy", "real numbers, not bool")]:
        with pytest.raises(InputError, match=why):
            read_topography(tmp_path / name, pixel_size=1e-6)
    with pytest.raises(InputError, match="dx"):
        Surface(np.zeros((8, 8)), -1.0, 1.0)
    with pytest.raises(InputError, match="hurst"):
        fractal_surface(64, 1e-3, 1.5, 2, 10, 1e-6)
    with pytest.raises(InputError, match="k_max"):
        fractal_surface(64, 1e-3, 0.8, 2, 40, 1e-6)
    with pytest.raises(InputError, match="rms"):
        fractal_surface(64, 1e-3, 0.8, 2, 10, 0.0)
    with pytest.warns(UserWarning, match=r"^rms = 6 m: taller than the patch is wide \(0.001 m\); rms is in m"):  # (a
        fractal_surface(64, 1e-3, 0.8, 2, 10, 6.0)                                 # 6 for 6 um: a user trial)
    # a grid beyond the memory: refused at once (200 000²: a raw MemoryError for 149 GiB, a user trial)
    with pytest.raises(InputError, match=r"^n = 200000: 200000 x 200000 points take about 1.08e\+03 GiB to "
                       r"generate, more than the .* GiB this process may use"):
        fractal_surface(200000, 1e-3, 0.8, 2, 10, 1e-6)


def sines(nx, ny, size=(1.0, 0.75)):
    """A band-limited field with content at the Nyquist wavenumbers of a 16 x 12 grid, sampled at
    the cell centres of an nx x ny grid."""
    x = (np.arange(nx) + 0.5) * size[0] / nx
    y = (np.arange(ny) + 0.5) * size[1] / ny
    X, Y = np.meshgrid(2 * np.pi * x / size[0], 2 * np.pi * y / size[1])
    return 0.3 + np.sin(8 * X) + np.sin(6 * Y) + np.sin(8 * X) * np.sin(6 * Y) + np.cos(3 * X + 5 * Y)


@pytest.mark.parametrize("n", [(40, 30), (16, 30), (40, 12), (33, 17), (16, 12)])
def test_refine_is_the_trigonometric_interpolant(n):
    """A sum of sines up to the Nyquist wavenumbers of a 16 x 12 grid, refined to n (odd, even, one
    direction, none): the same sines at the new cell centres, to round-off."""
    coarse = Surface(sines(16, 12), 1.0 / 16, 0.75 / 12)
    fine = refine(coarse, n)
    assert fine.dx == pytest.approx(1.0 / n[0], rel=1e-14) and fine.dy == pytest.approx(0.75 / n[1], rel=1e-14)
    assert np.abs(fine.heights - sines(*n)).max() < 1e-12


def test_refine_keeps_the_samples_and_batches():
    """Refined 3x, every third new cell centre is an old one: the samples are kept (a batch of two
    anisotropic patches)."""
    s = fractal_surface((64, 48), (1.0, 0.75), 0.8, 2, 24, 1.0, seed=3, batch=(2,))
    fine = refine(s, (192, 144))
    assert fine.heights.shape == (2, 144, 192)
    assert np.abs(fine.heights[..., 1::3, 1::3] - s.heights).max() < 1e-12


def test_refine_rejects_measured_and_coarser_grids():
    s = fractal_surface(32, 1.0, 0.8, 2, 8, 1.0)
    with pytest.raises(InputError, match="resample"):
        refine(Surface(s.heights, s.dx, s.dy, periodic=False), 64)
    with pytest.raises(InputError, match="at least"):
        refine(s, (64, 16))

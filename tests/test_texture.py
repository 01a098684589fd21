"""Spatial parameters (ISO 25178-2 §4.2): the areal autocorrelation against direct sums, and Sal,
Str and the lay against surfaces whose autocorrelation is known in closed form."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro import texture as texture_module
from multiscale.micro.spectrum import surface_statistics
from multiscale.micro.surface import Surface
from multiscale.micro.texture import autocorrelation, texture


def gaussian_correlated(n: int, lengths: tuple[float, float], angle: float = 0.0, seed: int = 0,
                        pixel: tuple[float, float] = (1.0, 1.0)) -> np.ndarray:
    """Heights [y, x] of a periodic n x n patch whose circular f_ACF is exp(-(u/l_u)^2 - (v/l_v)^2)
    in pixels of ``pixel`` = (dx, dy), (u, v) the lag's components along and across the direction
    ``angle`` [rad] from x: C(q) = exp(-(q_u l_u)^2/4 - (q_v l_v)^2/4) with |H(q)|^2 = C(q) exactly
    (unit amplitudes, random phases of a real field)."""
    qx, qy = np.meshgrid(2 * np.pi * np.fft.fftfreq(n, pixel[0]), 2 * np.pi * np.fft.fftfreq(n, pixel[1]))
    qu, qv = qx * np.cos(angle) + qy * np.sin(angle), -qx * np.sin(angle) + qy * np.cos(angle)
    spectrum = np.exp(-(qu * lengths[0]) ** 2 / 4 - (qv * lengths[1]) ** 2 / 4)
    noise = np.fft.fft2(np.random.default_rng(seed).normal(size=(n, n)))
    return np.fft.ifft2(np.sqrt(spectrum) * noise / np.abs(noise)).real


def test_the_autocorrelation_is_the_direct_sum_over_pairs():
    """Every lag of a 9 x 12 measured patch and of a periodic one, against the sums over its pairs
    (to the single-precision transforms' round-off)."""
    z = np.random.default_rng(3).normal(size=(9, 12))
    zc = z - z.mean()
    ny, nx = z.shape
    acf = autocorrelation(Surface(z, 1e-6, 2e-6, periodic=False))
    periodic = autocorrelation(Surface(z, 1e-6, 2e-6, periodic=True))
    assert acf.shape == periodic.shape == (9, 13)              # lags to half the patch
    for ty in range(-(ny // 2), ny // 2 + 1):
        for tx in range(-(nx // 2), nx // 2 + 1):
            a = zc[max(0, -ty):ny - max(0, ty), max(0, -tx):nx - max(0, tx)]
            b = zc[max(0, ty):ny - max(0, -ty), max(0, tx):nx - max(0, -tx)]
            assert acf[ny // 2 + ty, nx // 2 + tx] == pytest.approx(np.mean(a * b) / np.mean(zc * zc), abs=1e-6)
            circular = np.mean(zc * np.roll(zc, (-ty, -tx), axis=(0, 1))) / np.mean(zc * zc)
            assert periodic[ny // 2 + ty, nx // 2 + tx] == pytest.approx(circular, abs=1e-6)


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, -60.0])
def test_sal_str_and_the_lay_of_an_elliptic_autocorrelation(angle):
    """f_ACF = exp(-(u/20)^2 - (v/5)^2) pixels: it falls to 0.2 at l sqrt(ln 5) along each axis, so
    Sal = 5 sqrt(ln 5) pixels, Str = 1/4 and the lay is the long axis (to the 0.5 deg rays)."""
    pixel = 2e-6
    h = gaussian_correlated(512, (20 * pixel, 5 * pixel), np.radians(angle), pixel=(pixel, pixel))
    t = texture(Surface(h, pixel, pixel))
    assert t.Sal == pytest.approx(5 * np.sqrt(np.log(5)) * pixel, rel=3e-3)
    assert t.Str == pytest.approx(0.25, rel=3e-3) and t.bounded and t.threshold == 0.2
    assert abs((t.lay - angle + 90) % 180 - 90) <= 0.5
    measured = texture(Surface(h, pixel, pixel, periodic=False))         # the overlap estimate, from fewer pairs
    assert measured.Sal == pytest.approx(t.Sal, rel=0.02) and measured.Str == pytest.approx(t.Str, rel=0.03)


def test_unequal_pixels_and_an_isotropic_surface():
    """Lengths are physical: a lay along y measured with pixels twice as long along y (the x3p
    sample's are 0.13 x 0.31 um); an isotropic f_ACF has Str 1."""
    dx, dy = 1e-6, 2e-6
    h = gaussian_correlated(512, (30e-6, 10e-6), np.pi / 2, pixel=(dx, dy))
    t = texture(Surface(h, dx, dy))
    assert t.Sal == pytest.approx(10e-6 * np.sqrt(np.log(5)), rel=5e-3) and t.Str == pytest.approx(1 / 3, rel=5e-3)
    assert abs(abs(t.lay) - 90) <= 0.5
    iso = texture(Surface(gaussian_correlated(256, (8e-6, 8e-6), pixel=(1e-6, 1e-6)), 1e-6, 1e-6))
    assert iso.Str == pytest.approx(1.0, rel=5e-3) and iso.Sal == pytest.approx(8e-6 * np.sqrt(np.log(5)), rel=5e-3)


def test_a_lay_longer_than_the_measurement_bounds_str():
    """Grooves along y (heights of x alone): f_ACF is 1 along y, so the longest decay is beyond
    half the patch and Str is only bounded: Sal over the longest reach of a ray that does not decay
    (Ly / 2 along y, 0.3 % more at 85.5 deg); a flat patch has no autocorrelation."""
    n, pixel = 512, 1e-6
    grooves = gaussian_correlated(n, (4 * pixel, 1e3 * pixel), pixel=(pixel, pixel))   # only q_y = 0 modes
    assert np.ptp(grooves, axis=0).max() < 1e-6 * np.ptp(grooves)
    t = texture(Surface(grooves, pixel, pixel))
    assert not t.bounded and t.lay == 90.0 and t.Str == pytest.approx(t.Sal / (n / 2 * pixel), rel=5e-3)
    # across the grooves: the mean's removal takes the q = 0 mode's 1/72 of the power (a 1.5 % shorter Sal)
    assert t.Sal == pytest.approx(4 * pixel * np.sqrt(np.log(5)), rel=0.02)
    with pytest.raises(InputError, match="flat"):
        texture(Surface(np.ones((8, 8)), pixel, pixel))
    with pytest.raises(InputError, match="threshold"):
        texture(Surface(grooves, pixel, pixel), threshold=1.5)


def test_a_large_map_is_read_at_a_stride(monkeypatch):
    """Beyond MAX_POINTS every stride-th point: the same f_ACF at the lags kept, so Sal and Str of
    a patch correlated over many pixels within 1 %; in the statistics ``multiscale surface`` prints."""
    pixel = 1e-6
    h = gaussian_correlated(512, (40 * pixel, 10 * pixel), pixel=(pixel, pixel))
    full = texture(Surface(h, pixel, pixel))
    monkeypatch.setattr(texture_module, "MAX_POINTS", 256 * 256)
    strided = texture(Surface(h, pixel, pixel))
    assert strided.stride == 2 and full.stride == 1
    assert strided.Sal == pytest.approx(full.Sal, rel=0.01) and strided.Str == pytest.approx(full.Str, rel=0.01)
    lines = "\n".join(surface_statistics(Surface(h, pixel, pixel)).table())
    assert "Str  texture aspect ratio" in lines and "lay  longest correlation     0.0 deg" in lines

"""Kernels and their FFT operator: every argument checked (issue 21), two mutants the suite used
to miss (kx built with dy; E* of two bodies with nu1 for both), the preconditioner spectrum of
the contact solver, and the transform counter and the shared measured plans of the FFT wrapper
(issue 23)."""
import os
import subprocess
import sys

import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro import fft
from multiscale.micro.kernels import HalfSpace, InfluenceOperator, ThermalHalfSpace

E = HalfSpace.from_materials(4e9, 0.15)


@pytest.mark.parametrize("value", ["1e9", None, [1e9], np.nan, -np.inf, 0.0, True])
def test_half_space_modulus_is_a_positive_number(value):
    with pytest.raises(InputError) as info:
        HalfSpace(value)
    assert info.value.name == "E_star"


def test_half_space_keeps_a_float():
    assert type(HalfSpace(np.float32(2e9)).E_star) is float and HalfSpace(3).E_star == 3.0
    with pytest.raises(InputError) as info:
        ThermalHalfSpace("10")
    assert info.value.name == "kappa"


@pytest.mark.parametrize("kwargs, name", [
    (dict(E2=np.nan), "E2"), (dict(E2=-np.inf), "E2"), (dict(E2=0.0), "E2"), (dict(E2="2e11"), "E2"),
    (dict(E=np.inf), "E"), (dict(nu=0.6), "nu"), (dict(nu=-1.0), "nu"), (dict(nu=np.nan), "nu"),
    (dict(nu="0.3"), "nu"), (dict(nu2=0.7), "nu2"), (dict(nu2=np.nan), "nu2"),
])
def test_from_materials_checks_every_argument(kwargs, name):
    args = dict(E=4e9, nu=0.3, E2=2e11, nu2=0.3)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        HalfSpace.from_materials(**args)
    assert info.value.name == name


def test_composite_modulus_of_two_bodies_with_different_poisson_ratios():
    """1/E* = (1 - nu1²)/E1 + (1 - nu2²)/E2: each body with its own ratio (a counter-face taken
    with nu1 used to survive); +inf is a rigid counter-face, nu = 0.5 incompressible."""
    E1, nu1, E2, nu2 = 4e9, 0.15, 2.2e11, 0.45
    expected = 1 / ((1 - nu1**2) / E1 + (1 - nu2**2) / E2)
    assert HalfSpace.from_materials(E1, nu1, E2, nu2).E_star == pytest.approx(expected, rel=1e-14)
    assert HalfSpace.from_materials(E2, nu2, E1, nu1).E_star == pytest.approx(expected, rel=1e-14)
    assert HalfSpace.from_materials(E1, 0.5).E_star == pytest.approx(E1 / 0.75, rel=1e-14)
    assert HalfSpace.from_materials(E1, nu1, np.inf, nu2).E_star == pytest.approx(E1 / (1 - nu1**2), rel=1e-14)


@pytest.mark.parametrize("periodic", (True, False))
def test_rectangular_pixels_use_dx_along_x_and_dy_along_y(periodic):
    """A pressure wave along x (columns, pixel dx) or along y (rows, pixel dy) on a patch with
    dx != dy: the periodic response is 2/(E* k) times it with k = 2 pi / L along that axis (a
    kernel whose kx was built with dy used to survive); the isolated patch's response to a
    uniform pressure is symmetric under swapping the axes together with dx and dy."""
    ny, nx, dx, dy = 16, 24, 1e-6, 3e-6
    if periodic:
        for axis, (n, d) in enumerate(((ny, dy), (nx, dx))):
            k = 2 * np.pi / (n * d)
            wave = np.cos(2 * np.pi * 3 * np.arange(n) / n)
            p = np.tile(wave[:, None], (1, nx)) if axis == 0 else np.tile(wave, (ny, 1))
            u = InfluenceOperator(E, (ny, nx), dx, dy, periodic=True)(p)
            np.testing.assert_allclose(u, 2 / (E.E_star * 3 * k) * p, rtol=0, atol=1e-12 * np.abs(u).max())
    else:
        u = InfluenceOperator(E, (ny, nx), dx, dy, periodic=False)(np.ones((ny, nx)))
        v = InfluenceOperator(E, (nx, ny), dy, dx, periodic=False)(np.ones((nx, ny)))
        np.testing.assert_allclose(u, v.T, rtol=1e-12)
        swapped = InfluenceOperator(E, (ny, nx), dy, dx, periodic=False)(np.ones((ny, nx)))
        assert np.max(np.abs(u - swapped)) > 0.05 * np.max(u)


@pytest.mark.parametrize("shape", [(4.5, 8), (8.0001, 8), ("8", 8), (8,), 8, (3, 8), (8, 8, 8), None, (True, 8)])
def test_grid_shape_is_two_whole_numbers(shape):
    """Float grid sizes used to be truncated (4.5 -> 4)."""
    with pytest.raises(InputError) as info:
        InfluenceOperator(E, shape, 1e-6)
    assert info.value.name == "shape"
    assert InfluenceOperator(E, (8.0, np.int64(8)), 1e-6).shape == (8, 8)


@pytest.mark.parametrize("kwargs, name", [
    (dict(kernel="steel"), "kernel"), (dict(kernel=HalfSpace), "kernel"), (dict(kernel=None), "kernel"),
    (dict(dx=-1e-6), "dx"), (dict(dx="1e-6"), "dx"), (dict(dx=np.nan), "dx"), (dict(dy=0.0), "dy"),
    (dict(periodic="yes"), "periodic"), (dict(periodic=None), "periodic"),
])
def test_influence_operator_checks_every_argument(kwargs, name):
    args = dict(kernel=E, shape=(8, 8), dx=1e-6)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        InfluenceOperator(**args)
    assert info.value.name == name


def test_preconditioner_spectrum_inverts_the_operator():
    """M = L⁻¹ on the FFT grid (the contact solver's preconditioner): exact on a periodic patch
    for mean-free loads (L has no q = 0 response on a half-space), and the inverse of the
    zero-padded circulant of an isolated patch."""
    rng = np.random.default_rng(2)
    for periodic in (True, False):
        op = InfluenceOperator(E, (12, 10), 1e-6, 2e-6, periodic=periodic)
        plan = fft.RealFFT2(op.fft_shape)                  # the whole FFT grid (no rows skipped)
        x = rng.normal(size=op.fft_shape)
        x -= x.mean()
        response = plan.inverse(plan.forward(x) * op.multiplier, normalise=False).copy()
        back = plan.inverse(plan.forward(response) * op.inverse_multiplier, normalise=False)
        np.testing.assert_allclose(back, x, rtol=0, atol=1e-10 * np.abs(x).max())
        assert np.all(op.inverse_spectrum >= 0)


def test_fft_counter_counts_transforms_per_grid():
    fft.reset_fft_counts()
    plan = fft.RealFFT2((3, 8, 8))
    plan.forward()
    plan.inverse()
    plan.forward()
    assert fft.fft_counts()[(8, 8)] == (6, 3)
    assert fft.fft_pairs((8, 8)) == 4.5
    assert fft.fft_pairs((4, 4)) == 18.0                # a transform of 8² counts 4 of 4²
    del plan
    assert fft.fft_counts()[(8, 8)] == (6, 3)           # plans collected keep their counts
    fft.reset_fft_counts()
    assert fft.fft_counts() == {}


def test_single_precision_plan_transforms_to_float32_rounding_and_is_counted_apart():
    """RealFFT2(single=True): float32 buffers, rfft2/irfft2 within 1e-5 of numpy's (double) relative
    to the largest magnitude (float32 rounding, 6e-8, times the log of the size), counted under
    ``single=True`` only."""
    fft.reset_fft_counts()
    x = np.random.default_rng(4).normal(size=(2, 32, 24))
    plan = fft.RealFFT2(x.shape, single=True)
    assert plan.input.dtype == np.float32 and plan.spectrum.dtype == np.complex64
    spectrum = plan.forward(x)
    exact = np.fft.rfft2(x)
    assert np.abs(spectrum - exact).max() <= 1e-5 * np.abs(exact).max()
    assert np.abs(spectrum - exact).max() > 0              # it is not double precision
    back = plan.inverse()
    assert np.abs(back - x).max() <= 1e-5 * np.abs(x).max()
    assert fft.fft_counts(single=True) == {(32, 24): (2, 2)} and fft.fft_counts() == {}
    assert fft.fft_pairs((32, 24), single=True) == 2.0


@pytest.mark.parametrize("shape, rows, single", [((20, 16), 10, False), ((3, 40, 30), 17, False),
                                                 ((2, 64, 48), 32, True)])
def test_plan_with_rows_transforms_the_padded_field_alike(shape, rows, single):
    """RealFFT2(rows=n) (the passes over rows and columns that skip the zero rows) gives the full
    pair's spectrum and the first n rows of its inverse (within 1e-14, float32 1e-6, of the largest
    value), ignores what the other rows of ``input`` hold and leaves those of ``output`` alone."""
    rng = np.random.default_rng(5)
    full, part = fft.RealFFT2(shape, single=single), fft.RealFFT2(shape, single=single, rows=rows)
    x = np.zeros(shape)
    x[..., :rows, :] = rng.normal(size=shape[:-2] + (rows, shape[-1]))
    exact = full.forward(x).copy()
    part.input[...] = 7.0                                  # not read
    part.input[..., :rows, :] = x[..., :rows, :]
    spectrum = part.forward()
    tol = 1e-6 if single else 1e-14
    assert np.abs(spectrum - exact).max() <= tol * np.abs(exact).max()
    m = rng.random(exact.shape[-2:])
    expected = full.inverse(exact * m).copy()
    part.output[...] = 5.0
    back = part.inverse(spectrum * m)
    assert np.abs(back[..., :rows, :] - expected[..., :rows, :]).max() <= tol * np.abs(expected).max()
    assert np.all(back[..., rows:, :] == 5.0)              # not written
    assert part.rows == rows and fft.RealFFT2(shape, rows=shape[-2]).rows is None


PLAN = """
import numpy as np
from multiscale.micro import fft
x = np.random.default_rng(1).random((3, 24, 40))
X = fft.RealFFT2(x.shape).forward(x)
assert np.abs(X - np.fft.rfft2(x)).max() < 1e-12
print(X.tobytes().hex())
print(fft.RealFFT2(x.shape, single=True).forward(x).tobytes().hex())
padded = fft.RealFFT2(x.shape, rows=12)                 # the passes of a zero-padded field
padded.input[...] = x
print(padded.inverse(padded.forward()).tobytes().hex())     # its other rows: zero, never written
"""


def plan_in_a_process(wisdom):
    env = {**os.environ, "MULTISCALE_FFTW_WISDOM": str(wisdom)}
    done = subprocess.run([sys.executable, "-c", PLAN], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_fft_plans_are_measured_once_and_shared_by_later_processes(tmp_path):
    """The first process measures a shape's plans, double and single precision, and the passes of
    a zero-padded field (``rows``), and stores the wisdom; a later process plans from it (measures
    nothing, so it rewrites nothing) and rounds bit for bit alike."""
    wisdom = tmp_path / "cache" / "fftw-wisdom"
    first = plan_in_a_process(wisdom)
    assert wisdom.read_bytes().startswith(b"(fftw-3") and b"fftwf_wisdom" in wisdom.read_bytes()
    stored = wisdom.stat().st_ino
    assert plan_in_a_process(wisdom) == first
    assert wisdom.stat().st_ino == stored                # nothing new measured, nothing rewritten


def test_fft_plans_without_a_usable_wisdom_file_are_measured_in_the_process(tmp_path):
    (tmp_path / "file").write_text("")                  # a file where the folder should be
    plan_in_a_process(tmp_path / "file" / "fftw-wisdom")
    plan_in_a_process("")                               # no wisdom file wanted

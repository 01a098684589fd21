"""Faults of the contact solver (issue 21): a solver poisoned by an overflowing solve, a
stopping criterion that depended on the units, unchecked arguments."""
import numpy as np
import pytest

from multiscale.errors import InputError
from multiscale.micro.contact import ContactNonFiniteError, ContactSolver, solve_contact
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.surface import fractal_surface

E = HalfSpace.from_materials(4e9, 0.15)
METHODS = ("bccg", "pk")


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("periodic", (True, False))
def test_an_overflowing_solve_raises_and_does_not_poison_the_solver(method, periodic):
    """Heights ~1e306 m overflow float64: a named error (never NaN marked converged), and the
    next valid solve on the same object gives the answer of a fresh solver."""
    s = fractal_surface(32, 1e-3, 0.8, 2, 8, 1e-6, seed=1)
    solver = ContactSolver(E, s.shape, s.dx, periodic=periodic, method=method)
    before = solver.solve(s.heights, load=1e6)
    huge = s.heights / s.heights.std() * 1e306
    with pytest.raises(ContactNonFiniteError):
        solver.solve(huge, load=1e6)
    with pytest.raises(ContactNonFiniteError):            # also when a partial result is accepted
        solver.solve(huge, load=1e6, partial=True)
    after = solver.solve(s.heights, load=1e6)
    fresh = ContactSolver(E, s.shape, s.dx, periodic=periodic, method=method).solve(s.heights, load=1e6)
    assert after.converged and np.all(np.isfinite(after.pressure))
    np.testing.assert_allclose(after.pressure, fresh.pressure, rtol=0, atol=1e-12 * fresh.pressure.max())
    np.testing.assert_allclose(after.pressure, before.pressure, rtol=0, atol=1e-12 * fresh.pressure.max())


def test_an_underflowing_load_is_named_as_such():
    """A load of 1e-300 Pa on a 4 GPa solid underflows: the error said "overflowed" (a stress test)."""
    s = fractal_surface(32, 1e-3, 0.8, 2, 8, 1e-6, seed=1)
    with pytest.raises(ContactNonFiniteError, match="overflow or underflow"):
        ContactSolver(E, s.shape, s.dx).solve(s.heights, load=1e-300)


def circular_punch(n, size, radius_cells):
    """Isolated patch with a flat circular plateau (the punch) and the rest far below it."""
    dx = size / n
    x = (np.arange(n) - n / 2 + 0.5) * dx
    r = np.hypot(*np.meshgrid(x, x))
    inside = r < radius_cells * dx
    return inside, r, dx


@pytest.mark.parametrize("method", METHODS)
def test_flat_circular_punch_against_boussinesq_at_any_size(method):
    """A rigid flat circular punch of radius a (the plateau of radius a of an isolated patch):
    P = 2 a E* delta, p(r) = P / (2 pi a sqrt(a² - r²)) (Boussinesq). Same dimensionless answer
    (p / p_mean, delta / L) for a 1 mm and a 1 m patch; discretisation error ~ dx / a."""
    n, cells, pbar = 128, 32, 1e4
    answers = []
    for size in (1e-3, 1.0):
        inside, r, dx = circular_punch(n, size, cells)
        a = np.sqrt(inside.sum() / np.pi) * dx               # radius of the staircase disc's area
        P = pbar * size**2
        delta = P / (2 * a * E.E_star)
        h = np.where(inside, 0.0, -10 * delta)              # far below the reach of the deformation
        res = ContactSolver(E, h.shape, dx, periodic=False, method=method).solve(h, load=pbar, tol=1e-10)
        assert res.converged and np.array_equal(res.contact, inside)
        u = res.displacement[inside]
        assert np.ptp(u) < 1e-8 * u.mean()                    # uniform displacement under the punch
        assert res.approach == pytest.approx(delta, rel=0.006)
        c = n // 2
        centre = res.pressure[c - 1:c + 1, c - 1:c + 1].mean()
        assert centre == pytest.approx(P / (2 * np.pi * a**2), rel=0.012)
        ring = inside & (np.abs(r - a / 2) < dx / 2)        # p(a/2) = 2 / sqrt(3) p(0)
        assert res.pressure[ring].mean() == pytest.approx(P / (2 * np.pi * a * np.sqrt(a**2 - (a / 2)**2)), rel=0.015)
        answers.append((res.pressure / pbar, res.approach / size))
    np.testing.assert_allclose(answers[0][0], answers[1][0], rtol=0, atol=1e-7 * answers[0][0].max())
    assert answers[0][1] == pytest.approx(answers[1][1], rel=1e-8)


@pytest.mark.parametrize("method", METHODS)
def test_flat_and_nearly_flat_square_patch_give_the_same_dimensionless_answer(method):
    """The whole isolated patch is the punch (full contact, uniform displacement). It used to stop
    after 6 iterations 1.6 % non-uniform at 1 mm (criterion scaled by the RMS height, 1 m when
    zero) and never converge with heights of RMS 1e-13 m. Now a flat patch gives the same
    p / p_mean and delta / L at 1 mm and at 1 m, and with heights of RMS 1e-13 m scaled by 1e-6;
    heights of RMS 1e-13 m at 1 mm and 1e-10 m at 1 m (the same dimensionless problem) agree."""
    n, pbar = 48, 2e6
    noise = np.random.default_rng(5).normal(size=(n, n))
    noise /= noise.std()
    cases = [(1e-3, 0.0), (1.0, 0.0), (1e-3, 1e-19), (1e-3, 1e-13), (1.0, 1e-10)]
    answers = []
    for size, rms in cases:
        h = rms * noise
        res = ContactSolver(E, (n, n), size / n, periodic=False, method=method).solve(h, load=pbar)
        assert res.converged and res.area_fraction == 1.0
        u = res.displacement
        assert np.ptp(u - h) < 1e-8 * u.mean()                # zero gap: u = delta - (max h - h)
        answers.append((res.pressure / pbar, res.approach / size))
    (p0, d0), (p1, d1), (p2, d2), (p3, d3), (p4, d4) = answers
    for p, d in ((p1, d1), (p2, d2)):                         # flat: 1 mm, 1 m, heights of 1e-19 m
        np.testing.assert_allclose(p, p0, rtol=0, atol=1e-7 * p0.max())
        assert d == pytest.approx(d0, rel=1e-7)
    np.testing.assert_allclose(p4, p3, rtol=0, atol=1e-7 * p3.max())   # 1e-13 m at 1 mm = 1e-10 m at 1 m
    assert d4 == pytest.approx(d3, rel=1e-7)
    np.testing.assert_allclose(p3, p0, rtol=0, atol=1e-4 * p0.max())   # pixel noise: p ~ E*/dx * 1e-13 m
    # corner and edge pressures of a square punch: singular, the largest; the centre the smallest
    assert p0[0, 0] > (1 - 1e-9) * p0.max() and p0[n // 2, n // 2] < p0[n // 2, 0] < p0[0, 0]


@pytest.mark.parametrize("kwargs, name", [
    (dict(kernel="steel"), "kernel"), (dict(kernel=HalfSpace), "kernel"), (dict(kernel=None), "kernel"),
    (dict(dx=-1e-6), "dx"), (dict(dx="1e-6"), "dx"), (dict(dx=np.nan), "dx"), (dict(dy=0.0), "dy"),
    (dict(periodic="yes"), "periodic"), (dict(periodic=None), "periodic"), (dict(method="cg"), "method"),
])
def test_solver_construction_checks_every_argument(kwargs, name):
    args = dict(kernel=E, shape=(8, 8), dx=1e-6)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        ContactSolver(**args)
    assert info.value.name == name


@pytest.mark.parametrize("kwargs, name", [
    (dict(max_iter=np.nan), "max_iter"), (dict(max_iter=10.5), "max_iter"), (dict(max_iter=0), "max_iter"),
    (dict(max_iter=True), "max_iter"), (dict(max_iter="50"), "max_iter"), (dict(max_iter=np.inf), "max_iter"),
    (dict(tol="1e-8"), "tol"), (dict(tol=1.0), "tol"), (dict(tol=np.nan), "tol"),
    (dict(load="1e6"), "load"), (dict(load=np.ones(2) * 1e6), "load"), (dict(load=[1e6, "a", 2]), "load"),
    (dict(load=None, approach=np.ones(4) * 1e-7), "approach"), (dict(load=1e6, method="pk2"), "method"),
    (dict(initial_pressure=np.ones((3, 8, 9))), "initial_pressure"), (dict(initial_pressure="1"), "initial_pressure"),
    (dict(initial_pressure=-np.ones((8, 8))), "initial_pressure"), (dict(partial="no"), "partial"),
])
def test_solve_checks_every_argument(kwargs, name):
    h = fractal_surface(8, 1e-4, 0.8, 1, 4, 1e-7, seed=3, batch=(3,)).heights
    args = dict(load=1e6)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        ContactSolver(E, (8, 8), 1.25e-5).solve(h, **args)
    assert info.value.name == name


@pytest.mark.parametrize("heights, name", [
    ("rough", "heights"), ([[1, 2], [3]], "heights"), (np.zeros(8), "heights.shape"),
    (np.zeros((8, 9)), "heights.shape"), (np.full((8, 8), np.inf), "heights"),
    (np.array([[1e308, -1e308] * 4] * 8), "heights"),
    (np.zeros((8, 8)) + 1e-6j, "heights"), (np.eye(8, dtype=bool), "heights"),   # (were read as real / 0-1 m)
])
def test_bad_heights_are_named(heights, name):
    with pytest.raises(InputError) as info:
        ContactSolver(E, (8, 8), 1e-6).solve(heights, load=1e6)
    assert info.value.name == name
    if name == "heights":
        with pytest.raises(InputError) as info:
            solve_contact(heights, 1e-6, E, load=1e6)
        assert info.value.name == "heights"


@pytest.mark.parametrize("kwargs, name", [
    (dict(n=64.5), "n"), (dict(n="64"), "n"), (dict(n=(64, 32.5)), "n"), (dict(seed=1.5), "seed"),
    (dict(seed="a"), "seed"), (dict(seed=-1), "seed"), (dict(seed=True), "seed"), (dict(seed=None), "seed"),
    (dict(batch=(2.5,)), "batch"), (dict(batch="3"), "batch"), (dict(batch=(0,)), "batch"),
])
def test_the_surfaces_fed_to_the_solver_check_sizes_and_seeds(kwargs, name):
    """Float grid sizes were truncated, wrong seeds and batches raised numpy's errors."""
    args = dict(n=16, size=1e-3, hurst=0.8, k_min=2, k_max=4, rms=1e-6)
    args.update(kwargs)
    with pytest.raises(InputError) as info:
        fractal_surface(**args)
    assert info.value.name == name
    assert fractal_surface(16, 1e-3, 0.8, 2, 4, 1e-6, seed=np.int64(3), batch=3).heights.shape == (3, 16, 16)
    assert fractal_surface(16, 1e-3, 0.8, 2, 4, 1e-6, seed=np.random.SeedSequence([3, 1])).heights.shape == (16, 16)


def test_an_initial_pressure_of_another_grid_names_the_heights_shape():
    """It said "must broadcast to the batch's shape (64, 64), one value per patch" of a (32, 32)
    start for one 64² patch, whose batch shape is () (a user trial)."""
    h = fractal_surface(16, 1e-4, 0.8, 1, 4, 1e-7, seed=3).heights
    with pytest.raises(InputError, match=r"must broadcast to the heights' shape \(16, 16\), one value per cell$"):
        ContactSolver(E, (16, 16), 1e-4 / 16).solve(h, load=1e6, initial_pressure=np.ones((8, 8)))


def test_a_solve_beyond_the_memory_is_refused_at_once(monkeypatch):
    """``contact.BUILD_BYTES`` and its companions give at most the traced peak of a build and a solve (so a refusal is a
    solve that could not fit), and a grid or batch beyond the process' memory is refused before
    anything is built (an isolated 4096² solver built for 14 s before a raw MemoryError under a
    3 GB limit: a user trial)."""
    import tracemalloc

    from multiscale import memory
    from multiscale.micro import contact
    for periodic, batch in ((True, ()), (False, ()), (True, (8,))):
        s = fractal_surface(256, 1e-3, 0.8, 2, 64, 1e-6, seed=1, batch=batch)
        tracemalloc.start()
        try:
            ContactSolver(E, s.shape, s.dx, s.dy, periodic).solve(s.heights, load=1e6)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        patches = batch[0] if batch else 1
        per_cell = contact.BUILD_BYTES[periodic] + contact.SCRATCH_BYTES + contact.RESULT_BYTES * patches
        assert 256**2 * per_cell < peak < 2.5 * 256**2 * per_cell, (periodic, batch, peak)
    for shape in (64, None, "64x64"):          # checked before the estimate (a raw TypeError: an adversarial test)
        with pytest.raises(InputError, match="^shape.*must be a pair"):
            ContactSolver(E, shape, 1e-7)
    monkeypatch.setattr(memory, "memory_limit", lambda: 2.0**31)
    with pytest.raises(InputError, match=r"^shape = \(4096, 4096\): an isolated 4096 x 4096 patch takes at least "
                                         r"5.38 GiB to solve, more than the 2 GiB this process may use"):
        ContactSolver(E, (4096, 4096), 1e-7, periodic=False)
    monkeypatch.setattr(memory, "memory_limit", lambda: 2.0**30)
    solver = ContactSolver(E, (1024, 1024), 1e-7)          # a batch beyond it
    with pytest.raises(InputError, match=r"^heights.shape = \(20, 1024, 1024\): a periodic 1024 x 1024 patch x 20 "
                                         r"patches takes at least 1.11 GiB to solve, more than the 1 GiB"):
        solver.solve(np.broadcast_to(0.0, (20, 1024, 1024)), load=1e6)


def test_heights_in_another_unit_than_the_pixels_are_warned_about():
    """Heights in um given as metres beside pixels in metres were solved as given (A/A0 0.00024
    against 0.0012 in metres: an API trial): a warning by the median slope of the first patch
    (``contact.STEEP``); a rough surface and a flat punch, whose rim is steep, say nothing."""
    import warnings
    s = fractal_surface(64, 1e-3, 0.8, 2, 16, 1e-6, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        solve_contact(s, kernel=E, load=1e6)
        x, y = np.meshgrid(np.arange(64) - 31.5, np.arange(64) - 31.5)
        solve_contact(np.where(np.hypot(x, y) < 20, 0.0, -1e-3), 1e-6, E, load=1e6)   # 1 mm cliff on 1 um pixels
    with pytest.warns(UserWarning, match=r"^heights: a median slope of [0-9.e+]+, beyond any rough surface's .*: "
                                         r"are the heights and dx in m\?"):
        solve_contact(s.heights * 1e6, s.dx, E, load=1e6)

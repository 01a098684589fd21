"""Masked Krylov solves of the micro heat systems (``multiscale.micro.masked_krylov``): BiCGSTAB
against a dense direct solve of the same masked system and against the thesis' CGLS (Eqs.
6.19-6.21), and the CGLS fallback for patches BiCGSTAB leaves unconverged."""
import numpy as np

from multiscale.micro import masked_krylov
from multiscale.micro.contact import ContactSolver
from multiscale.micro.heat_kernels import ThermalMaterial, Translation, pulse_tables
from multiscale.micro.kernels import HalfSpace, padded_size
from multiscale.micro.surface import fractal_surface

DISC = ThermalMaterial(50.0, 1e-5)       # thesis Table 6.3, solid S1 (moving)
PIN = ThermalMaterial(5.0, 3.5e-6)       # solid S2 (fixed)
ELASTIC = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)
TOL = 1e-8


def steady_system(n=32, batch=4):
    """A batch of steady sliding-contact systems (Eq. 6.23, V = 2 m/s: non-symmetric) on rough
    contacts, built here from the pulse tables with numpy's FFT: operator, adjoint, right-hand side,
    contact mask, residual scale, convolution count."""
    s = fractal_surface(n, 1e-3, 0.8, 2, 8, 6.49e-6, seed=11, batch=(batch,))
    p = ContactSolver(ELASTIC, s.shape, s.dx, periodic=False).solve(s.heights, load=np.full(batch, 8e6)).pressure
    half = (padded_size(n), padded_size(n))
    tables = [pulse_tables(half, s.dx, s.dx, DISC, np.inf, 1, Translation.steady(2.0)).coeffs[0],
              pulse_tables(half, s.dx, s.dx, PIN, np.inf, 1).coeffs[0]]
    full = tables[0].shape
    S1, S2 = (np.fft.rfft2(k) for k in tables)
    count = [0]

    def conv(S, x):                   # linear convolution with a wrap-around table, cropped to the patch
        count[0] += 1
        return np.fft.irfft2(np.fft.rfft2(x, s=full) * S, s=full)[..., :n, :n]
    b = conv(S2, 0.4 * p * 2.0) + 5.0                       # remote temperatures 0 and 5 K
    mask = p > 0
    scale = np.sqrt(np.sum(mask * b**2, axis=(-2, -1), keepdims=True))
    count[0] = 0
    return (lambda x: conv(S1 + S2, x)), (lambda x: conv(np.conj(S1 + S2), x)), b, mask, scale, count


def dense(apply, b, mask):
    """The masked system of each patch assembled column by column and solved directly (LAPACK)."""
    out = np.zeros_like(b)
    for k in range(b.shape[0]):
        cells = np.flatnonzero(mask[k])
        unit = np.zeros((len(cells),) + b.shape)
        unit.reshape(len(cells), b.shape[0], -1)[np.arange(len(cells)), k, cells] = 1.0
        columns = np.stack([apply(e)[k].reshape(-1)[cells] for e in unit], axis=1)
        out[k].reshape(-1)[cells] = np.linalg.solve(columns, b[k].reshape(-1)[cells])
    return out


def test_bicgstab_gives_the_direct_solution_with_fewer_convolutions_than_cgls():
    """On four rough contacts (2-4 % of 32 x 32 cells), BiCGSTAB at tol 1e-8 gives the direct
    solution of the masked system to 1e-6 of its largest flux (the residual tolerance times the
    system's condition number, ~1e2 here), as the thesis' CGLS does; both residuals, the true one
    recomputed here, are at most tol; BiCGSTAB needs at most half of CGLS' convolutions (measured
    0.3-0.4x)."""
    apply, apply_t, b, mask, scale, count = steady_system()
    x, its, res, hist = masked_krylov.masked_solve(apply, apply_t, b, mask, scale, TOL, 500)
    fast, count[0] = count[0], 0
    ref, its_ref, res_ref, _ = masked_krylov.cgls(apply, apply_t, b, mask, scale, TOL, 500)
    slow = count[0]
    exact = dense(apply, b, mask)
    true = np.sqrt(np.sum(np.where(mask, b - apply(x), 0.0) ** 2, axis=(-2, -1))) / scale[..., 0, 0]
    assert np.all(res <= TOL) and np.all(res_ref <= TOL) and np.all(true <= TOL)
    assert np.all(x[~mask] == 0)
    for solution in (x, ref):
        assert np.abs(solution - exact).max() <= 1e-6 * np.abs(exact).max()
    assert fast <= 0.5 * slow and len(hist) == its.max() + 1


def test_patches_bicgstab_leaves_unconverged_are_finished_by_cgls(monkeypatch):
    """Patches left above tol by BiCGSTAB (a breakdown, or its iterations spent; here one iteration
    allowed) are solved again by CGLS alone: the answer of CGLS on the whole batch, the iterations
    of both counted, the histories joined."""
    apply, apply_t, b, mask, scale, _ = steady_system()
    bicgstab = masked_krylov.bicgstab
    monkeypatch.setattr(masked_krylov, "bicgstab", lambda apply, b, mask, scale, tol, max_iter, x0=None:
                        bicgstab(apply, b, mask, scale, tol, 1, x0))
    x, its, res, hist = masked_krylov.masked_solve(apply, apply_t, b, mask, scale, TOL, 500)
    ref, its_ref, res_ref, hist_ref = masked_krylov.cgls(apply, apply_t, b, mask, scale, TOL, 500)
    assert np.all(res <= TOL) and np.array_equal(its, its_ref + 1)
    np.testing.assert_allclose(x, ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    assert len(hist) == 2 + len(hist_ref)


def test_a_singular_operator_is_left_unconverged_not_wrong():
    """A zero operator breaks BiCGSTAB down at once and CGLS cannot move: the patches come back
    with their residual above tol (the callers raise HeatingConvergenceError), x finite."""
    _, _, b, mask, scale, _ = steady_system(batch=2)
    x, its, res, hist = masked_krylov.masked_solve(lambda x: 0.0 * x, lambda x: 0.0 * x, b, mask, scale, TOL, 50)
    assert np.all(res > TOL) and np.all(np.isfinite(x)) and np.all(np.isfinite(hist))


def test_contacts_of_one_or_two_cells_are_solved_by_bicgstab_alone():
    """One contact cell: the first half step is exact (h = 0, so omega = 0), which used to count as
    a breakdown and send the patch to CGLS; two cells: solved within a few steps. BiCGSTAB alone
    meets tol and gives the direct solution (ch. 7 run: 28 of rank 0's 1818 solves fell back so)."""
    apply, _, b, mask, scale, _ = steady_system()
    for cells in (1, 2):
        few = np.zeros_like(mask)
        for k in range(mask.shape[0]):
            few[k].reshape(-1)[np.flatnonzero(mask[k])[:cells]] = True
        x, its, res, _ = masked_krylov.bicgstab(apply, b, few, scale, TOL, 50)
        exact = dense(apply, b, few)
        assert np.all(res <= TOL) and np.all(its <= 2 * cells), (cells, its, res)
        assert np.abs(x - exact).max() <= 1e-6 * np.abs(exact).max()

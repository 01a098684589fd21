"""The two-level (balancing) preconditioner of the contact solver (issue 23, ``bccg_coarse``): its
near coefficients are those of the approximate stiffness it defines, the preconditioner is
symmetric positive definite and balances exactly (P Ã Z = Z), the solver keeps the discrete answer
with it, and it takes the growth out of the iterations on large grids."""
import numpy as np
import pytest
import scipy.linalg

from multiscale.micro import bccg_coarse, bccg_solver
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import HalfSpace, InfluenceOperator
from multiscale.micro.surface import fractal_surface, statistics

E = HalfSpace(1.0)


def slope_one(n, seed=1):
    """Self-affine surface (cut-offs 4 and n/4 wavelengths), RMS slope 1 (the issue-23 family)."""
    s = fractal_surface(n, 1.0, 0.8, 4, n // 4, 1.0, seed=seed)
    return s.heights / statistics(s).rms_slope, s.dx


def rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


def approximate_stiffness(grid, fi, fj, kernel):
    """Ã over the cells (fi, fj) by its definition, pair by pair: the exact coefficient when their
    sub-blocks are neighbours, that of the sub-block centres when their coarse cells are, that of
    the coarse cell centres otherwise (wrapped when periodic)."""
    Fy, Fx = kernel.shape

    def offset(a, b, n):                       # b - a, wrapped to the nearest image when periodic
        d = b[None, :] - a[:, None]
        return (d + n // 2) % n - n // 2 if grid.periodic else d

    sub_y, sub_x = fi // grid.S, fj // grid.S
    agg_y, agg_x = grid.row_of[fi], grid.col_of[fj]
    near_sub = (np.abs(offset(sub_y, sub_y, grid.sy)) <= 1) & (np.abs(offset(sub_x, sub_x, grid.sx)) <= 1)
    near_agg = (np.abs(offset(agg_y, agg_y, grid.cy)) <= 1) & (np.abs(offset(agg_x, agg_x, grid.cx)) <= 1)
    exact = kernel[(fi[:, None] - fi[None, :]) % Fy, (fj[:, None] - fj[None, :]) % Fx]
    sub = kernel[(grid.S * offset(sub_y, sub_y, grid.sy)) % Fy, (grid.S * offset(sub_x, sub_x, grid.sx)) % Fx]
    cell = agg_y * grid.cx + agg_x
    return np.where(near_sub, exact, np.where(near_agg, sub, grid.far[cell[:, None], cell[None, :]])), cell


def random_free_set(shape, fraction, seed):
    rng = np.random.default_rng(seed)
    fi, fj = np.nonzero(rng.random(shape) < fraction)
    return fi.astype(np.int32), fj.astype(np.int32)


@pytest.mark.parametrize("periodic", (True, False))
def test_near_coefficients_are_those_of_the_approximate_stiffness(periodic):
    """C[m, s] = Σ of Ã over the cells of F in coarse slot s around cell m (relative 1e-12), on a
    136 x 130 grid (a partial sub-block at the edge; coarse cells wrapped when periodic) with a
    random F of 6 % of its cells."""
    shape = (136, 130)
    operator = InfluenceOperator(E, shape, 1e-6, periodic=periodic)
    grid = bccg_coarse.CoarseGrid(operator)
    fi, fj = random_free_set(shape, 0.06, 1)
    C = grid.near_coefficients(fi, fj, fi.size)
    kernel = np.fft.irfft2(operator.spectrum, s=operator.fft_shape)
    A, cell = approximate_stiffness(grid, fi, fj, kernel)
    reference = np.zeros_like(C)
    for s in range(9):
        slot = grid.slots[cell, s]
        reference[:, s] = np.where(cell[None, :] == slot[:, None], A, 0.0).sum(axis=1)
    assert np.abs(C - reference).max() <= 1e-12 * np.abs(reference).max()
    assert np.count_nonzero(reference[:, [0, 2, 6, 8]]) > 0       # the corner slots were exercised


@pytest.mark.parametrize("periodic", (True, False))
def test_the_two_level_preconditioner_is_symmetric_positive_definite_and_balances(periodic):
    """With P1 = I: P = Z Ẽ⁻¹ Zᵀ + Qᵀ Q as ``balance`` and ``complete`` apply it, column by column
    on a random F, is symmetric (1e-12) and positive definite, and maps Ã Z onto Z (1e-9): K and
    Ẽ are Ã Z and Zᵀ Ã Z of the one Ã."""
    shape = (136, 130)
    operator = InfluenceOperator(E, shape, 1e-6, periodic=periodic)
    grid = bccg_coarse.CoarseGrid(operator)
    fi, fj = random_free_set(shape, 0.03, 2)
    n, nx = fi.size, shape[1]
    c = bccg_coarse.CoarseCorrection(grid)
    c.prepare(fi, fj, n)
    assert c.active and c.builds == 1
    flat = fi.astype(int) * nx + fj

    def apply(v):
        r = np.zeros(shape[0] * nx)
        r[flat] = v
        X = r.copy()
        c.balance(fi, fj, n, r, X, nx)
        s = np.zeros_like(r)
        s[flat] = X[flat]
        c.complete(fi, fj, n, s, False)
        return s[flat]

    P = np.column_stack([apply(e) for e in np.eye(n)])
    assert np.abs(P - P.T).max() <= 1e-12 * np.abs(P).max()
    assert np.linalg.eigvalsh(0.5 * (P + P.T)).min() > 0.0
    A, _ = approximate_stiffness(grid, fi, fj, np.fft.irfft2(operator.spectrum, s=operator.fft_shape))
    Z = (c.agg[:, None] == np.arange(c.counts.size)[None, :]).astype(float)
    AZ = A @ Z
    PAZ = np.column_stack([apply(col) for col in AZ.T])
    assert np.abs(PAZ - Z).max() <= 1e-9


def two_level(monkeypatch, builds=None):
    """The two-level preconditioner on every grid that fits; ``builds`` (a list) collects the
    cells of F of each build."""
    monkeypatch.setattr(bccg_solver, "COARSE_FROM", 0)
    if builds is not None:
        build = bccg_coarse.CoarseCorrection.build

        def counted(self, fi, fj, n):
            builds.append(n)
            build(self, fi, fj, n)

        monkeypatch.setattr(bccg_coarse.CoarseCorrection, "build", counted)


@pytest.mark.parametrize("periodic", (True, False))
def test_the_two_level_solver_gives_the_discrete_answer(periodic, monkeypatch):
    """256², load and displacement control: the same pressure as Polonsky–Keer (relative L2 < 1e-9
    at tol 1e-11) and the same contact set; with a pressure bound (which Polonsky–Keer has not), as
    the one-level solver; the coarse operator built."""
    h, dx = slope_one(256, seed=3)
    pk = ContactSolver(E, h.shape, dx, periodic=periodic, method="pk")
    ref = [pk.solve(h, load=0.01, tol=1e-11)]
    ref.append(pk.solve(h, approach=ref[0].approach * 0.9, tol=1e-11))
    H = 0.6 * ref[0].pressure.max()
    ref.append(ContactSolver(E, h.shape, dx, periodic=periodic).solve(h, load=0.01, tol=1e-11, hardness=H))
    builds = []
    two_level(monkeypatch, builds)
    solver = ContactSolver(E, h.shape, dx, periodic=periodic)
    out = [solver.solve(h, load=0.01, tol=1e-11), solver.solve(h, approach=ref[0].approach * 0.9, tol=1e-11),
           solver.solve(h, load=0.01, tol=1e-11, hardness=H)]
    assert len(builds) >= 3 and max(builds) < 0.1 * h.size
    for a, b in zip(out, ref):
        assert rel(a.pressure, b.pressure) < 1e-9
        assert np.array_equal(a.contact, b.contact)


def test_a_coarse_operator_that_is_not_positive_definite_leaves_the_one_level_preconditioner(monkeypatch):
    """When Ẽ's Cholesky factorisation fails, the patch goes on with P1 (same answer, converged)."""
    h, dx = slope_one(256, seed=4)
    one = ContactSolver(E, h.shape, dx).solve(h, load=0.01, tol=1e-10)
    builds = []
    two_level(monkeypatch, builds)

    def fail(*args, **kwargs):
        raise np.linalg.LinAlgError("not positive definite")

    monkeypatch.setattr(scipy.linalg, "cho_factor", fail)
    r = ContactSolver(E, h.shape, dx).solve(h, load=0.01, tol=1e-10)
    assert builds and r.converged and r.iterations == one.iterations
    assert rel(r.pressure, one.pressure) < 1e-12


def test_two_levels_take_the_growth_out_of_the_iterations(monkeypatch):
    """The benchmark family at 1024²: the one-level preconditioner needs 18 iterations (13 at
    256²), the two-level one at most 15, within 1.2x the 256² count (measured 14), and ends
    within the tolerance of a tight solution."""
    h, dx = slope_one(1024)
    monkeypatch.setattr(bccg_solver, "COARSE_FROM", 10 ** 12)
    one = ContactSolver(E, h.shape, dx).solve(h, load=0.01)
    small = ContactSolver(E, (256, 256), dx * 4).solve(slope_one(256)[0], load=0.01)
    two_level(monkeypatch)
    solver = ContactSolver(E, h.shape, dx)
    r = solver.solve(h, load=0.01)
    tight = solver.solve(h, load=0.01, tol=1e-12)
    assert one.iterations >= 17
    assert r.iterations <= min(15, 1.2 * small.iterations)
    assert rel(r.pressure, tight.pressure) < 1e-8

"""FFT-BEM frictionless normal contact of a rough elastic solid and a rigid flat (thesis §3.3).

The complementary energy U = ½ pᵀ L p − pᵀ δ (Eqs. 3.4, 3.9) is minimised over p ≥ 0 with
``L`` applied by FFT (``InfluenceOperator``). Load control fixes the mean pressure, displacement
control the rigid approach. Two methods give the same discrete answer:

- ``"bccg"`` (default): the preconditioned constrained CG of Vollebregt (2014, J. Comput. Phys.
  257, 333–351) with an FFT-based preconditioner (``bccg_solver``) and a nested start: iteration
  counts that do not grow with the grid (one surface refined from 256² to 2048²: 13, 13, 11,
  13, Polonsky–Keer 48 to 162) nor with the roughness resolved (13, 14, 14, 14 at N = 256 … 2048 on
  self-affine surfaces with cut-off N/4, Polonsky–Keer 48 … 225; from 1024² with a two-level
  coarse correction, ``bccg_coarse``), 2–2.5 FFT pairs each;
- ``"pk"``: the constrained CG of Polonsky & Keer (1999) (``pk_solver``): iterations growing like
  the square root of the grid size, ~2 FFT pairs each. Slower from 128² up, as fast below.

Both stop on the same unit-free criterion (see ``ContactSolver.solve``). With a ``hardness`` H
(``"bccg"`` only) the surface is elastic-perfectly plastic: 0 <= p <= H, the cells at H flow
plastically and their interpenetration is the permanent deformation (the bounded problem of
Almqvist et al. 2007, Tribol. Int. 40, 574–579; Weber et al. 2018, Nat. Commun. 9, 888;
ContactMechanics' hardness cut-off and tamaas' saturated solvers solve the same discrete
problem). Batches of patches (leading axes) are solved in one call, each patch iterating on its
own until it converges (then it is frozen), so batched and looped answers agree. A batch is split
into one contiguous part per thread of ``multiscale.micro.fft`` (each with single-threaded FFTs
and its own nested start), and a part into chunks of at most ``CHUNK_CELLS`` cells that keep the
working set in the CPU cache.

Conventions: heights ``h`` [m] point towards the rigid flat. The flat first touches the highest
point; the approach ``delta`` [m] moves it into the solid. Gap
``g = (max h − h) − delta + u ≥ 0`` with the elastic displacement ``u = L p`` positive into the
solid; pressure [Pa] positive in compression.
"""
from __future__ import annotations

import queue
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from multiscale.errors import ConvergenceError, InputError, check_count, check_flag, check_positive, non_finite
from multiscale.micro import bccg_solver, pk_solver
from multiscale.memory import beyond_limit
from multiscale.micro.fft import get_threads
from multiscale.micro.kernels import InfluenceOperator, Kernel, check_kernel, grid_shape
from multiscale.micro.surface import Surface

METHODS = ("bccg", "pk")
CHUNK_CELLS = {"bccg": 65536, "pk": 32768}   # cells per chunk of a batch (the working set stays in L2)
COARSE_MIN = 32      # smallest side of the grids of the nested start of "bccg"
COARSE_TOL = 1e-1    # tolerance of the coarse solves of the nested start
BALANCE = 1e-9      # a load-controlled patch whose mean pressure is further off its load is not converged
SNAP = 1e-12         # a start within this relative distance below the hardness is at the hardness
AT_HARDNESS = 10     # a cell within AT_HARDNESS x tol below H is at H (plastic): a cell's error reaches a
#                      few tol (2.7 tol where a fractal patch is reloaded to its maximum load)
# The local start of displacement control, max(delta - z, 0) / L_00, ignores the neighbours'
# displacement and over-estimates the pressure (35x on a 509 x 16 patch). On a periodic grid a
# uniform excess is invisible to the iteration (a uniform pressure moves nothing, L(q = 0) = 0, and
# the preconditioner is 0 there too): "bccg" stopped in full contact with a uniform gap, marked
# converged, and "pk" overflowed (elongated patches, 11 of 42 cases). A start below the answer is
# safe (cells with negative gaps join), so there it is scaled down by this factor:
PERIODIC_LOCAL_START = 1e-3


@dataclass
class ContactResult:
    """Solution of a (batch of) contact problem(s); per-patch arrays have the batch shape (...).

    - ``pressure`` [Pa] (..., ny, nx), >= 0; ``contact`` (bool, p > 0) and ``gap`` [m] (>= 0, zero
      on the contact) on the same grid; ``displacement`` [m], elastic normal displacement, positive
      into the solid;
    - ``area_fraction`` [-], real contact area / nominal area, and ``area`` [m²] = area_fraction x
      the nominal area ny nx dx dy; ``mean_pressure`` [Pa], total force / nominal area, and
      ``force`` [N] = mean_pressure x the nominal area;
    - ``approach`` [m], rigid approach of the flat from first touch of the highest point. It holds
      the mean elastic displacement, so it depends on the patch: of an isolated patch, the
      indentation of the whole loaded patch (143.5 of the 290 nm of tutorial micro_patch's measured
      case), of a periodic one, that about a displacement of mean zero;
    - ``mean_gap`` [m], mean separation between the flat and the deformed surface: it depends much
      less on the patch than the approach (periodic against isolated 128²: 6 %);
    - ``plastic_area_fraction`` [-], cells at p = H (plastic flow) / all cells (0 without a
      hardness); ``plastic`` [m], permanent deformation d - z - u at p = H, >= 0 into the solid
      (None without a hardness);
    - ``iterations``, ``residual`` (see ``ContactSolver.solve``) and ``converged`` (bool) per
      patch; ``history``, the max residual over the patches per iteration.

    Its normal contact stiffness dp̄/dδ: ``micro.stiffness.contact_stiffness``."""

    pressure: np.ndarray
    displacement: np.ndarray
    gap: np.ndarray
    contact: np.ndarray
    area_fraction: np.ndarray
    mean_pressure: np.ndarray
    force: np.ndarray
    area: np.ndarray
    approach: np.ndarray
    mean_gap: np.ndarray
    plastic_area_fraction: np.ndarray
    plastic: np.ndarray | None
    iterations: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    history: list = field(default_factory=list, repr=False)
    grid: tuple | None = field(default=None, repr=False)   # (dx, dy, periodic) of the solver that solved it


class ContactConvergenceError(ConvergenceError):
    """The contact solver reached ``max_iter`` before ``tol``."""


class ContactNonFiniteError(ContactConvergenceError):
    """The iteration produced non-finite numbers (the problem's scales overflow float64); the
    solver's buffers are cleared, so the next solve starts clean."""


# the least memory of a solver [bytes per cell of the grid]: its build (kernel spectrum, plans;
# periodic, isolated), each thread's scratch and each patch's result (tracemalloc peaks of build +
# solve, one thread: periodic 200-210 a cell from 512² to 2048², isolated 490-560 from 256² to 2048²;
# 8 x 256² periodic 615, 16 x 128² 2510 periodic and 2990 isolated)
BUILD_BYTES = {True: 33, False: 194}
SCRATCH_BYTES, RESULT_BYTES = 100, 50


STEEP = 100.0     # a median |grad h| above this is no rough surface: heights or pixels in another unit


def _steepness(z: np.ndarray, dx: float, dy: float) -> float:
    """The median |dz/dx| and |dz/dy| of the batch's first patch by forward differences along about 8
    of its rows and 8 of its columns (a median: a punch's rim or a few spikes do not count; a sample:
    every cell took 2.5 ms at 256², a tenth of a solve; a unit slip is the whole batch's)."""
    first = z.reshape(-1, *z.shape[-2:])[0]
    ny, nx = first.shape
    with np.errstate(over="ignore", invalid="ignore"):          # (an overflowing height range: inf, not said)
        along_x = np.diff(first[::max(ny // 8, 1), :], axis=-1) / dx
        along_y = np.diff(first[:, ::max(nx // 8, 1)], axis=-2) / dy
        return float(np.median(np.abs(np.concatenate([along_x.ravel(), along_y.ravel()]))))


def _fits(name: str, shape, grid, periodic: bool, patches: int) -> None:
    """InputError naming ``name`` (given as ``shape``) if a solver on the grid ``grid`` (ny, nx;
    periodic or not) solving ``patches`` patches at once needs more memory than this process may use
    (``BUILD_BYTES``; an isolated 4096² solver built for 14 s before a raw MemoryError under 3 GB: a
    user trial)."""
    ny, nx = grid
    per_cell = BUILD_BYTES[bool(periodic)] + SCRATCH_BYTES * min(patches, get_threads()) + RESULT_BYTES * patches
    need = float(ny * nx * per_cell)
    if have := beyond_limit(need):
        raise InputError(name, tuple(shape), f"{'a periodic' if periodic else 'an isolated'} {ny} x {nx} patch"
                         f"{f' x {patches} patches' * (patches > 1)} takes at least {need / 2**30:.3g} GiB to solve, more "
                         f"than the {have / 2**30:.3g} GiB this process may use: a coarser grid or fewer patches at once")


class ContactSolver:
    """Reusable FFT-BEM contact solver on one grid (plans and kernel spectrum built once).

    Parameters: kernel (e.g. ``HalfSpace``), grid ``shape`` (ny, nx), pixel ``dx`` (and ``dy``) [m],
    ``periodic`` (repeating patch) or not (isolated patch, zero-padded DC-FFT on a grid padded to
    5-smooth lengths: fast at any size), ``method`` ("bccg" or "pk", see the module). A periodic
    patch's FFT grid is the patch: sides with large prime factors are slow (a 1022² FFT pair takes
    4x a 1024² one); choose 5-smooth sides (2^a 3^b 5^c). A solver keeps its FFT buffers between
    calls: use one solver per thread (it runs the chunks of a batch on ``get_threads()`` threads
    itself).
    """

    def __init__(self, kernel: Kernel, shape, dx: float, dy: float | None = None, periodic: bool = True,
                 method: str = "bccg"):
        _fits("shape", shape, grid_shape("shape", shape), periodic is not False and periodic is not np.False_, 1)
        self.operator = InfluenceOperator(check_kernel("kernel", kernel, thermal=False), shape, dx, dy, periodic)
        self.kernel, self.shape, self.periodic = kernel, self.operator.shape, self.operator.periodic
        self.method = _method(method)
        self._scratch: dict[tuple, queue.SimpleQueue] = {}   # (method, chunk, threads) -> free buffers
        self._coarse: ContactSolver | None = None             # the half-resolution solver of the nested start
        self._pool: ThreadPoolExecutor | None = None
        self._pool_threads = 0

    @property
    def grid(self) -> tuple:
        """(dx, dy, periodic): what a ``ContactResult`` of this solver records of its grid."""
        return self.operator.dx, self.operator.dy, self.periodic

    def _heights_of(self, surface: Surface) -> np.ndarray:
        """The heights of ``surface`` (m), refused unless it lies on this solver's grid: its shape,
        pixel sizes and periodicity (a measured, non-periodic surface on a periodic solver would be
        solved as a repeating patch)."""
        op = self.operator
        for name, own, theirs in (("shape", self.shape, surface.shape), ("dx", op.dx, surface.dx),
                                  ("dy", op.dy, surface.dy), ("periodic", self.periodic, surface.periodic)):
            if own != theirs:
                raise InputError(f"surface.{name}", theirs, f"the solver's is {own}: make the solver from the "
                                 "surface (ContactSolver(kernel, s.shape, s.dx, s.dy, s.periodic)) or use solve_contact")
        return surface.heights

    def solve(self, heights, *, load=None, approach=None, tol: float = 1e-8, max_iter: int = 5000,
              initial_pressure=None, partial: bool = False, method: str | None = None,
              hardness=None) -> ContactResult:
        """Solve under load control (``load`` = mean pressure [Pa], >= 0: at 0 the patch is
        untouched) or displacement control (``approach`` = delta [m]); scalars or arrays of the
        batch shape. ``heights`` [m]: an array
        (..., ny, nx) or a ``Surface`` on the solver's grid (checked: shape, dx, dy, periodic). ``hardness`` H [Pa]
        (scalar or per patch, > 0; inf or None: elastic) bounds the pressure (p <= H, load < H):
        the result's ``plastic`` field is then the permanent deformation d - z - u on the cells at
        H (``plastic_area_fraction``: p >= H (1 - AT_HARDNESS tol)); H = inf computes bit for bit what
        None computes.

        Stopping criterion (both methods): eps = ||s||₂ / ||p||₂ <= ``tol`` per patch, where s is
        the preconditioned residual over the free set (contact cells, and cells with a negative
        gap), i.e. the pressure correction predicted by the FFT preconditioner M ≈ L⁻¹ from the
        gap residual: an estimate of the relative L2 error of the pressure, free of units
        (``result.residual``). Under load control the pressure balances the load exactly.
        Raises ``ContactConvergenceError`` after ``max_iter`` iterations unless ``partial`` is True,
        ``ContactNonFiniteError`` if the numbers overflow (never a non-finite result).
        """
        method = self.method if method is None else _method(method)
        h = real_heights(self._heights_of(heights) if isinstance(heights, Surface) else heights)
        if h.ndim < 2 or h.shape[-2:] != self.shape:
            raise InputError("heights.shape", h.shape, f"last two axes must be {self.shape}")
        if h.size == 0:
            raise InputError("heights.shape", h.shape, "the batch holds no patch")
        if not np.all(np.isfinite(h)):
            raise InputError("heights", f"array of shape {h.shape}", f"{non_finite(h)}: all heights must be finite")
        tol = check_positive("tol", tol)
        if tol >= 1:
            raise InputError("tol", tol, "relative tolerance must lie in (0, 1)")
        max_iter = check_count("max_iter", max_iter)
        check_flag("partial", partial)
        if (load is None) == (approach is None):
            raise InputError("load/approach", (load, approach), "give exactly one of them")
        batch = h.shape[:-2]
        _fits("heights.shape", h.shape, self.shape, self.periodic, int(np.prod(batch)))
        with np.errstate(over="ignore", invalid="ignore"):
            z = h.max(axis=(-2, -1), keepdims=True) - h        # depth below the highest point, >= 0
        if not np.all(np.isfinite(z)):
            raise InputError("heights", "array", "the height range overflows float64")
        if np.isfinite(steep := _steepness(z, self.operator.dx, self.operator.dy)) and steep > STEEP:   # (um as m:
            warnings.warn(f"heights: a median slope of {steep:.3g}, beyond any rough surface's (about 0.01 to 2): "
                          "are the heights and dx in m?", UserWarning, stacklevel=2)   # solved as given, a trial)
        if load is not None:
            target = _batch_values("load", load, batch)
            if not np.all(np.isfinite(target)) or np.any(target < 0):
                raise InputError("load", load, "mean pressure must be finite and >= 0")
            delta = None
        else:
            target = None
            delta = _batch_values("approach", approach, batch)
            if not np.all(np.isfinite(delta)) or np.any(delta < 0):
                raise InputError("approach", approach, "rigid approach must be finite and >= 0")
        upper = None
        if hardness is not None:
            upper = _batch_values("hardness", hardness, batch)
            if np.any(np.isnan(upper)) or np.any(upper <= 0):
                raise InputError("hardness", hardness, "must be > 0 (inf: no bound)")
            if np.all(upper == np.inf):
                upper = None
            elif method != "bccg":
                raise InputError("hardness", hardness, f"method {method!r} has no pressure bound: use 'bccg'")
            elif target is not None and np.any(target >= upper):
                raise InputError("load", load, "mean pressure must be below the hardness (a fully plastic "
                                 "patch carries at most H)")
        # an elastic periodic patch in full contact has no finite load, unless its kernel has a finite,
        # positive static compliance F(0) (a layer on a rigid base: the load is then (delta - mean z) / F(0);
        # an incompressible one has F(0) = 0: it ran its 5000 iterations to an unexplained failure, a user trial)
        static = getattr(self.kernel, "static_compliance", np.inf)
        if delta is not None and self.periodic and not (np.isfinite(static) and static > 0):
            unbounded = np.ones(batch, dtype=bool) if upper is None else np.broadcast_to(upper, batch) == np.inf
            if np.any(unbounded & (delta >= z.mean(axis=(-2, -1)))):
                raise InputError("approach", approach, "a periodic elastic patch under displacement control "
                                 "needs approach < max(h) - mean(h) (full contact has no finite load"
                                 + ("" if static else ": an incompressible layer on a rigid base, F(0) = 0")
                                 + "; with a hardness it has)")
        p0 = None
        if initial_pressure is not None:
            p0 = _batch_values("initial_pressure", initial_pressure, h.shape, cells=True)
            if np.any(p0 < 0) or not np.all(np.isfinite(p0)):
                raise InputError("initial_pressure", "array", "must be finite and >= 0")
        if target is not None and np.any(target == 0):   # unloaded: touching at the highest point (a sweep from 0)
            return self._unloaded(h, z, target, dict(tol=tol, max_iter=max_iter, initial_pressure=initial_pressure,
                                                     partial=partial, method=method, hardness=hardness))
        return self._run_chunks(method, z, target, delta, tol, max_iter, p0, partial, upper=upper)

    def _unloaded(self, h: np.ndarray, z: np.ndarray, load: np.ndarray, options: dict) -> ContactResult:
        """``solve`` under the loads ``load`` of which some are 0: those patches untouched (no
        contact, pressure or displacement; the gap the depth ``z`` below the highest point, approach
        0), the others solved as asked (with their hardness and initial pressure)."""
        zero = load == 0
        flat = np.zeros(h.shape)
        result = ContactResult(flat, flat.copy(), z.copy(), flat != 0, *(np.zeros(load.shape) for _ in range(5)),
                               z.mean(axis=(-2, -1)).reshape(load.shape),
                               np.zeros(load.shape), flat.copy(), np.zeros(load.shape, dtype=int),
                               np.zeros(load.shape), np.ones(load.shape, dtype=bool), grid=self.grid)
        if zero.all():
            return result
        p0, upper = options.pop("initial_pressure"), options.pop("hardness")
        p0 = None if p0 is None else _batch_values("initial_pressure", p0, h.shape, cells=True)[~zero]
        upper = None if upper is None else _batch_values("hardness", upper, load.shape)[~zero]
        loaded = self.solve(h[~zero], load=load[~zero], initial_pressure=p0, hardness=upper, **options)
        for k, a in vars(loaded).items():
            if isinstance(a, np.ndarray):
                getattr(result, k)[~zero] = a
        result.history = loaded.history
        return result

    def _run_chunks(self, method, z, target, delta, tol, max_iter, p0, partial, fields=True, upper=None,
                    threads=None):
        """Run the iterations on ``threads`` (default ``get_threads()``) contiguous parts of the
        batch, one per thread when the batch fills several chunks, else one part with ``threads``
        FFT threads. A part makes its start (one nested coarse solve for all its patches: the
        coarse grids' per-iteration overhead is paid once) and runs its chunks of near-equal sizes,
        small enough for the CPU cache (the full-grid passes are memory bound: 400 patches of 64²
        in one block run ~2x slower than in chunks of 8); each chunk fills its part of the result
        (``fields``: the gap and the means, not needed by a nested start; ``upper``: the hardness
        per patch or None). Threads on parts rather than on chunks, and no FFT threads inside a
        part: 100 patches of 128² on 2 threads ran 1.6–1.8x faster than on one thread before,
        2.1x now (benchmarks/README)."""
        batch, grid = z.shape[:-2], z.shape[-2:]
        B = int(np.prod(batch, dtype=int))
        size = max(1, CHUNK_CELLS[method] // (grid[0] * grid[1]))
        z = np.ascontiguousarray(np.reshape(z, (B,) + grid))
        target, delta, upper = (None if a is None else _writable(np.ascontiguousarray(np.reshape(a, B), dtype=float))
                                for a in (target, delta, upper))
        p0 = None if p0 is None else np.reshape(p0, (B,) + grid)
        threads = get_threads() if threads is None else threads
        workers = max(1, min(threads, B // size))   # one contiguous part of the batch per thread
        inner = 1 if workers > 1 else threads       # FFT threads of a part and of its nested start
        bounds = np.linspace(0, B, workers + 1).round().astype(int)
        parts = []
        for a, b in zip(bounds[:-1], bounds[1:]):   # a part's chunks: as few as fit, near-equal sizes
            edges = np.linspace(a, b, -(-(b - a) // size) + 1).round().astype(int)
            parts.append((slice(a, b), [slice(x, y) for x, y in zip(edges[:-1], edges[1:])]))
        p, u = np.empty_like(z), np.empty_like(z)
        out = {k: np.zeros(B, dtype=t) for k, t in (("d", float), ("iterations", int), ("residual", float),
                                                    ("converged", bool), ("area_fraction", float),
                                                    ("mean_pressure", float), ("mean_gap", float))}
        gap = np.empty_like(p) if fields else None
        plastic = np.zeros_like(p) if fields and upper is not None else None
        out["plastic_area_fraction"] = np.zeros(B)
        histories = []

        def part(w):
            whole, chunks = parts[w]
            tc, dc, uc = (None if a is None else a[whole] for a in (target, delta, upper))
            p[whole] = self._initial_pressure(method, z[whole], tc, dc, None if p0 is None else p0[whole], max_iter,
                                              uc, inner)
            for c in chunks:
                histories.append(one(c))

        def one(c):
            key = (method, c.stop - c.start, inner)
            free = self._scratch.setdefault(key, queue.SimpleQueue())
            try:
                work = free.get_nowait()
            except queue.Empty:
                work = self._new_scratch(method, *key[1:])
            history: list = []
            tc, dc, uc = (None if a is None else a[c] for a in (target, delta, upper))
            args = (z[c], p[c], u[c], tc, dc, tol, max_iter, history)
            try:
                with np.errstate(all="ignore"):
                    if method == "bccg":
                        solved = bccg_solver.run(self.operator, work, *args, uc)
                    else:
                        solved = pk_solver.run(self.operator, work[0], work[1], *args)
                    finite = np.all(np.isfinite(solved["d"])) and np.all(np.isfinite(u[c])) and np.all(np.isfinite(p[c]))
            except FloatingPointError:
                finite = False
            if not finite:
                for w in (work if isinstance(work, tuple) else (work,)):
                    w.clear()
                free.put(work)
                raise ContactNonFiniteError("the contact iteration left float64's range (non-finite pressure or "
                                            "displacement: its scales overflow or underflow): rescale the problem "
                                            "(heights, load, modulus)")
            free.put(work)
            for name, values in solved.items():
                out[name][c] = values
            out["mean_pressure"][c] = p[c].mean(axis=(1, 2))
            if tc is not None:                               # load control: balanced, whatever the residual says
                out["converged"][c] &= np.abs(out["mean_pressure"][c] - tc) <= BALANCE * tc
            if fields:
                np.add(u[c], z[c], out=gap[c])
                gap[c] -= solved["d"][:, None, None]
                if plastic is not None:                      # the interpenetration at p = H (reloaded
                    flow = p[c] >= uc[:, None, None] * (1.0 - AT_HARDNESS * tol)    # cells reach it from below)
                    np.copyto(plastic[c], -gap[c], where=flow)
                    np.maximum(plastic[c], 0.0, out=plastic[c])
                    out["plastic_area_fraction"][c] = flow.mean(axis=(1, 2))
                np.maximum(gap[c], 0.0, out=gap[c])
                gap[c][p[c] > 0] = 0.0
                out["area_fraction"][c] = np.mean(p[c] > 0, axis=(1, 2))
                out["mean_gap"][c] = gap[c].mean(axis=(1, 2))
            return history

        if workers > 1:
            if self._pool is None or self._pool_threads != workers:
                self._pool, self._pool_threads = ThreadPoolExecutor(workers), workers
            list(self._pool.map(part, range(workers)))
        else:
            part(0)
        length = max(len(h) for h in histories)
        history = [max(h[k] for h in histories if k < len(h)) for k in range(length)]
        cells, nominal = batch + grid, self.shape[0] * self.shape[1] * self.operator.dx * self.operator.dy
        result = ContactResult(
            pressure=p.reshape(cells), displacement=u.reshape(cells),
            gap=gap.reshape(cells) if fields else None, contact=(p > 0).reshape(cells) if fields else None,
            plastic=(np.zeros(cells) if plastic is None else plastic.reshape(cells)) if fields else None,
            approach=out.pop("d").reshape(batch), history=history, force=out["mean_pressure"].reshape(batch) * nominal,
            area=out["area_fraction"].reshape(batch) * nominal, grid=self.grid,
            **{k: v.reshape(batch) for k, v in out.items()})
        if not np.all(result.converged) and not partial:
            raise ContactConvergenceError(
                f"contact solver did not converge in {max_iter} iterations "
                f"(residual {result.residual.max():.3e} > tol {tol:.1e} on "
                f"{int(np.sum(~result.converged))} patch(es))", result.history, result)
        return result

    def _new_scratch(self, method, chunk, threads):
        if method == "bccg":
            return bccg_solver.Scratch(self.operator, chunk, threads, coarse=True)
        return self.operator.workspace((chunk,), threads), bccg_solver.Scratch(self.operator, chunk, threads,
                                                                                steps=False)

    def _initial_pressure(self, method, z, target, delta, p0, max_iter, upper, threads):
        """A feasible start: the warm start (a patch's zero warm start counts as none); else for
        "bccg" the nested start (the solution on the grid of half the resolution,
        ``coarse_start``) when the grid allows it; else uniform (load control) or the local
        solution max(delta - z, 0) / L_00 (displacement control; times ``PERIODIC_LOCAL_START`` on
        a periodic grid). Balanced under load control; within the bounds ``upper``
        (``bounded_start``)."""
        B, N = z.shape[0], z.shape[1] * z.shape[2]
        if p0 is not None and not np.all(np.any(p0 > 0, axis=(-2, -1))):   # a zero warm start: none
            cold = ~np.any(p0 > 0, axis=(-2, -1))
            p = np.array(p0, dtype=float)
            p[cold] = self._initial_pressure(method, z[cold], None if target is None else target[cold],
                                             None if delta is None else delta[cold], None, max_iter,
                                             None if upper is None else upper[cold], threads)
            p0 = p
        p = None if p0 is None else np.array(p0, dtype=float)
        if p is None and method == "bccg":
            p = self.coarse_start(z, target, delta, max_iter, upper, threads)
        if p is None and target is not None:
            p = np.repeat(target, N).reshape(z.shape)
        elif p is None:
            p = np.maximum(delta[:, None, None] - z, 0.0) / self.operator.self_influence
            if self.periodic:
                p *= PERIODIC_LOCAL_START
        if target is not None:
            p = pk_solver.rescale(p.reshape(B, N), target, z.reshape(B, N)).reshape(z.shape)
        if upper is not None:
            p = bounded_start(p.reshape(B, N), upper, None if target is None else target * N).reshape(z.shape)
        return np.ascontiguousarray(p)

    def coarse_start(self, z, target, delta, max_iter, upper=None, threads=None):
        """Nested iteration (as in full multigrid; for contact: the cascade multi-resolution start
        of Bemporad & Paggi 2015, Int. J. Solids Struct. 69–70, 94–105): solve the patches with
        2 x 2 cells merged (heights averaged, same kernel, recursively down to ``COARSE_MIN``
        cells) to ``COARSE_TOL`` and prolong the pressure piecewise constant. It gives the fine
        iteration a nearly right contact set: on the self-affine benchmark surfaces a third fewer
        fine iterations for a quarter of the work. None where the grid is odd or small."""
        (ny, nx), B = self.shape, z.shape[0]
        if ny % 2 or nx % 2 or min(ny, nx) < 2 * COARSE_MIN:
            return None
        if self._coarse is None:
            op = self.operator
            self._coarse = ContactSolver(self.kernel, (ny // 2, nx // 2), 2 * op.dx, 2 * op.dy, self.periodic)
        zc = z[:, 0::2] + z[:, 1::2]                     # the 2 x 2 means: pairs of rows, then of columns
        zc = zc[:, :, 0::2] + zc[:, :, 1::2]             # (a strided mean(axis=(2, 4)) took 14x longer)
        zc *= 0.25
        low = zc.min(axis=(1, 2))                        # the coarse top lies this far below the fine one
        zc -= low[:, None, None]
        if target is None:
            delta = delta - low
            if np.any(delta <= 0) or (self.periodic and np.any(delta >= zc.mean(axis=(1, 2)))):
                return None
        r = self._coarse._run_chunks("bccg", zc, target, delta, COARSE_TOL, max_iter, None, True, fields=False,
                                     upper=upper, threads=threads)
        p = np.empty(z.shape)                            # piecewise constant (a broadcast copy: np.repeat holds the GIL)
        p.reshape(B, ny // 2, 2, nx // 2, 2)[...] = r.pressure[:, :, None, :, None]
        return p


def bounded_start(p, upper, total=None):
    """p (B, N) >= 0 made feasible for the bounds ``upper`` (B,): min(c p, H) per patch, with c
    (>= 0) such that Σ min(c p, H) = ``total`` (B,) under load control (exact on the sorted
    values: the k largest cells saturate, c v_k <= H <= c v_(k-1)), else c = 1. Values within
    ``SNAP`` of H are set to H: a warm start from a bounded solution (its cells at H rescaled by
    1 ± 1e-16) keeps its saturated set (the first iteration's projection restores the balance).
    A start whose loaded cells all at H carry less than ``total`` (a warm start from a harder or
    less loaded solve) has no such c: it is replaced by the uniform total / N (< H, ``solve``'s
    check); before, its cells all at H carried part of the load (11-95 % in a user trial), which
    the solver took for converged (no free cell left: residual 0). Where round-off alone leaves no
    k exact (ties at H of a prolonged coarse start), the first k's scale is kept: its free cells
    restore the balance."""
    p = np.maximum(np.asarray(p, dtype=float), 0.0)
    H = upper[:, None]
    if total is None:
        return np.minimum(p, H)
    bounded = np.isfinite(upper)
    if not bounded.all():                                          # elastic patches keep p
        p[bounded] = bounded_start(p[bounded], upper[bounded], total[bounded])
        return p
    short = np.count_nonzero(p, axis=1) * upper < total           # all its loaded cells at H carry less
    v = -np.sort(-p, axis=1)                                       # descending
    k = np.arange(p.shape[1] + 1)
    tail = np.concatenate([np.cumsum(v[:, ::-1], axis=1)[:, ::-1], np.zeros((p.shape[0], 1))], axis=1)
    nxt = np.concatenate([v, np.zeros((p.shape[0], 1))], axis=1)   # the largest cell not saturated
    prev = np.concatenate([np.full((p.shape[0], 1), np.inf), v], axis=1)  # the smallest saturated one
    with np.errstate(divide="ignore", invalid="ignore"):
        c = (total[:, None] - k * H) / tail                        # scale if the k largest saturate
        ok = (c >= 0) & (c * nxt <= H) & (c * prev >= H) & (tail > 0)
    first = np.argmax(ok, axis=1)
    scale = c[np.arange(p.shape[0]), first]
    p = np.minimum(p * scale[:, None], H)
    p[p >= H * (1 - SNAP)] = np.broadcast_to(H, p.shape)[p >= H * (1 - SNAP)]   # ties at H stay saturated
    p[short] = (total[short] / p.shape[1])[:, None]
    return p


def real_heights(heights) -> np.ndarray:
    """``heights`` as a float array; InputError for what is not real numbers (strings, ragged
    lists, complex or bool arrays: numpy would drop an imaginary part or read True as 1 m)."""
    try:
        given = np.asarray(heights)
        h = np.asarray(given, dtype=float) if given.dtype.kind not in "cb" else None
    except (TypeError, ValueError):
        hint = (" (a measurement as read? give its conditioned surface, topography.condition(m).surface)"
                if hasattr(heights, "heights") else "")            # (it said no more: a user trial)
        raise InputError("heights", heights, f"must be an array of numbers{hint}") from None
    if h is None:
        raise InputError("heights", "array", "must be real numbers [m] (not complex or bool)")
    return h


def _method(method) -> str:
    if not isinstance(method, str) or method not in METHODS:
        raise InputError("method", method, f"choose one of {', '.join(METHODS)}")
    return method


def _writable(a: np.ndarray) -> np.ndarray:
    """``a``, or a copy of it if it is read-only (``_batch_values`` gives read-only views): the
    compiled kernels take these per-patch values, and numba compiles every kernel once more for a
    read-only argument (the same machine code: 16 extra compilations, ~1-2 s each, on a fresh
    cache; the copy holds B numbers)."""
    return a if a.flags.writeable else a.copy()


def _batch_values(name: str, value, shape, cells: bool = False) -> np.ndarray:
    """``value`` as a float array broadcast to ``shape`` (the batch's, or with ``cells`` the
    heights'), else ``InputError`` naming it."""
    a = np.asarray(value)
    if a.dtype.kind not in "iuf":
        raise InputError(name, value, "must be a number or an array of numbers")
    try:
        return np.broadcast_to(a.astype(float), shape)
    except ValueError:
        if cells:                # (it said "the batch's shape (64, 64), one value per patch": a user trial)
            raise InputError(name, f"array of shape {a.shape}", f"must broadcast to the heights' shape {shape}, one "
                             "value per cell") from None
        sweep = " (a sweep on one patch: its heights broadcast to the values' shape, " \
                "np.broadcast_to(h, (n, ny, nx)))" if not shape else ""
        raise InputError(name, f"array of shape {a.shape}", f"must broadcast to the batch's shape {shape}, one "
                         f"value per patch{sweep}") from None


def solve_contact(heights, dx: float | None = None, kernel: Kernel | None = None, *, dy: float | None = None,
                  periodic: bool | None = None, **options) -> ContactResult:
    """One-call form of ``ContactSolver(kernel, heights.shape[-2:], dx, dy, periodic).solve(...)``:
    ``heights`` [m] an array (..., ny, nx) with ``dx`` (``periodic`` True unless given), or a
    ``Surface``, whose pixel sizes and periodicity are taken (``solve_contact(s, kernel=k, load=p)``)."""
    if isinstance(dx, Kernel):           # solve_contact(s, k, ...): it said the kernel was missing (a trial)
        raise InputError("dx", dx, "a Kernel given as the pixel size: name it, solve_contact(heights, kernel=k, ...)")
    if kernel is None:
        raise InputError("kernel", None, "a Kernel (e.g. HalfSpace.from_materials(E, nu)) is required")
    if isinstance(heights, Surface):
        given = {"dx": dx, "dy": dy, "periodic": periodic}
        if any(v is not None for v in given.values()):
            raise InputError(", ".join(k for k, v in given.items() if v is not None), None,
                             "a Surface gives its own pixel sizes and periodicity: leave them out")
        return ContactSolver(kernel, heights.shape, heights.dx, heights.dy, heights.periodic).solve(heights, **options)
    h = real_heights(heights)
    if h.ndim < 2:
        raise InputError("heights", h.shape, "must be at least 2-D (..., ny, nx)")
    if dx is None:
        raise InputError("dx", None, "the pixel size [m] is required with an array of heights")
    return ContactSolver(kernel, h.shape[-2:], dx, dy, True if periodic is None else periodic).solve(h, **options)

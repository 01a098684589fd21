"""Archard wear of a rough surface under sliding, with a temperature-dependent rate (thesis §3.4–3.5, §7.2.2).

Only the rough body wears (the counter-face is the rigid flat of ``contact.py``); the worn material
leaves the contact (no third body). At a surface point the wear depth over a sliding distance dS
is ``dh = k_w mu p dS`` (Eq. 3.10), with the wear-rate coefficient k_w [1/Pa] constant, tabulated
against temperature (thesis Fig. 7.9 style) or any callable of temperature.

``wear_step`` applies one increment for a given pressure field (the seam the macro loop calls);
``simulate_wear`` splits a sliding distance into N steps under load control: after each step the
topography is lowered by the wear depth and the contact is re-solved at the prescribed mean
pressure, warm-started from the previous pressure with one reused ``ContactSolver`` (§3.5.1).

Conventions: heights [m] point to the counter-face, so wear lowers them; wear depths are >= 0;
pressure [Pa] positive in compression; sliding distance [m].
"""
from __future__ import annotations

import itertools
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from multiscale.errors import InputError, check_count, check_field, check_flag, check_instance, check_positive, \
    check_table, non_finite
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import Kernel
from multiscale.micro.surface import Surface, check_surface


STEP_RMS = 0.5   # a simulate_wear step wearing deeper than this many RMS heights is warned about [-]
SUBSTEP_TOL = 0.05   # a wear update whose worn depth its increments leave this far off is warned about [-]
WEAR_TOL = 0.005     # the coupled loop raises a wear update's increments while their estimated error is above [-]
UNIFORM = 1e-12      # a step's depths equal to this share of the deepest: uniform wear (full contact of a flat)
ROUND_OFF_FLAT = 1e-12  # a surface whose RMS height is at most this share of its largest height, or of its
#                        side, is flat [-] (a flat levelled to heights of round-off about 0: a review)


STABLE = 1.0          # an explicit wear step's k_w mu ds over the least compliance of the grid, at most [-]


def stable_substeps(operator, wear_per_pressure) -> int:
    """Fewest explicit Archard increments (Eq. 3.10) of a sliding that keep each stable.

    An increment lowers the heights by dh = c p with c = k_w mu ds [m/Pa] (``wear_per_pressure``,
    the whole sliding's, any shape: its largest counts) and the pressure of the heights before it:
    forward Euler on dh/ds = -k_w mu K h, K = L_C^-1 the stiffness of the contact set C. Its modes
    are damped only for c lambda_max(K) < 2, and lambda_max(K) <= 1 / lambda_min(L) =
    1 / ``operator.least_compliance`` (interlacing), the grid's stiffest wavelength: hence
    ceil(c / (STABLE least_compliance)) increments. Beyond, the scheme amplifies grid-scale relief
    and the worn topography is noise (a railway trial at c = 770 least compliances: the RMS height
    3 -> 123 um; a 64^2 fractal patch worn 40 least compliances deep: real area 0.54-0.60 from
    c <= 2, 0.36-0.40 at 4, 0.18-0.19 at 10)."""
    c = float(np.max(wear_per_pressure, initial=0.0))
    return max(1, int(np.ceil(c / (STABLE * operator.least_compliance))))


class WearWarning(UserWarning):
    """Wear steps too coarse for the relief they wear (``simulate_wear``)."""


class WearRate:
    """Archard wear-rate coefficient k_w [1/Pa] (Eq. 3.10), optionally a function of temperature.

    ``WearRate(1e-12)``: constant. ``WearRate((temperatures, rates))``: table, temperatures strictly
    increasing, linear interpolation, held at the end values outside the table (§7.2.2, Fig. 7.9).
    ``WearRate(callable)``: ``callable(temperature_array) -> k_w array``. Temperatures are in the
    unit of the table or callable (K inside the package; convert °C tables at the border).
    """

    def __init__(self, k_w):
        if isinstance(k_w, WearRate):
            self.value, self.table, self.function = k_w.value, k_w.table, k_w.function
            return
        self.value = self.table = self.function = None
        if callable(k_w):
            self.function = k_w
        elif np.ndim(k_w) == 0:
            self.value = check_positive("k_w", k_w, allow_zero=True)
        else:
            temps, rates = check_table("k_w", k_w, "a number, a (temperatures, rates) table or a callable")
            if not np.all(np.isfinite(rates)) or np.any(rates < 0):
                raise InputError("k_w.rates", rates, "wear rates must be finite and >= 0 [1/Pa]")
            self.table = (temps, rates)

    @property
    def depends_on_temperature(self) -> bool:
        return self.value is None

    def __repr__(self) -> str:
        if self.value is not None:
            return f"WearRate({self.value:g} 1/Pa)"
        if self.table is not None:
            temps, rates = self.table
            return f"WearRate(table of {len(temps)} points, {temps[0]:g}-{temps[-1]:g}: {rates.min():g}-{rates.max():g} 1/Pa)"
        return f"WearRate({getattr(self.function, '__name__', self.function)!s})"

    def __call__(self, temperature=None) -> np.ndarray:
        """k_w [1/Pa] at ``temperature`` (any shape; ignored when constant)."""
        if self.value is not None:
            return np.asarray(self.value)
        if temperature is None:
            raise InputError("temperature", None, "a temperature-dependent wear rate needs a temperature")
        T = np.asarray(temperature, dtype=float)
        if not np.all(np.isfinite(T)):
            raise InputError("temperature", f"array of shape {T.shape}", f"{non_finite(T)}: temperatures must be finite")
        if self.table is not None:
            return np.interp(T, *self.table)
        k = np.asarray(self.function(T), dtype=float)
        if not np.all(np.isfinite(k)) or np.any(k < 0):
            raise InputError("k_w", self.function, "callable returned a wear rate that is negative or not finite")
        return k


@dataclass
class WearIncrement:
    """One Archard wear increment (Eq. 3.10) of a patch or a batch of patches."""

    surface: Surface     # worn topography (heights lowered by depth)
    depth: np.ndarray    # m, wear depth of this increment, >= 0, (..., ny, nx)
    volume: np.ndarray   # m³, worn volume per patch (batch shape)


def wear_step(surface: Surface, pressure, k_w, mu: float, distance: float,
              temperature=None) -> WearIncrement:
    """Wear ``surface`` by ``dh = k_w(T) mu p dS`` over the sliding ``distance`` dS [m] (Eq. 3.10).

    pressure [Pa] is the contact pressure field (..., ny, nx), >= 0; k_w a ``WearRate`` or anything
    it accepts; mu the friction coefficient; temperature: a scalar, one value per patch (batch
    shape) or a field (..., ny, nx), in the unit of the k_w table (needed only when k_w depends on it).
    """
    check_surface(surface)
    rate = WearRate(k_w)
    h = surface.heights
    mu = check_positive("mu", mu, allow_zero=True)
    distance = check_positive("distance", distance, allow_zero=True)
    p = check_field("pressure", pressure, nonnegative=True)
    try:
        p = np.broadcast_to(p, h.shape)
    except ValueError:
        raise InputError("pressure.shape", p.shape, f"must broadcast to the heights {h.shape}") from None
    T = _per_point("temperature", temperature, h.shape) if rate.depends_on_temperature else None
    depth = rate(T) * (mu * distance) * p
    worn = Surface(h - depth, surface.dx, surface.dy, surface.periodic)
    return WearIncrement(worn, depth, depth.sum(axis=(-2, -1)) * surface.dx * surface.dy)


@dataclass
class PressureGapLaw:
    """Mean pressure vs mean gap of a (worn) patch at one wear step (thesis Fig. 3.10)."""

    step: int                   # wear step (0 = initial surface)
    sliding: float              # m, sliding distance at that step
    pressure: np.ndarray        # Pa, prescribed mean pressures (n,)
    mean_gap: np.ndarray        # m, mean separation flat – deformed surface, (n, *batch)
    approach: np.ndarray        # m, rigid approach from first touch, (n, *batch)
    area_fraction: np.ndarray   # -, (n, *batch)


@dataclass
class WearHistory:
    """Per-step history; arrays are (N + 1, *batch), row 0 the initial state (§3.5, Figs. 3.3–3.9)."""

    sliding: np.ndarray         # m, (N + 1,)
    area_fraction: np.ndarray   # -, real contact area / nominal area
    max_pressure: np.ndarray    # Pa
    max_depth: np.ndarray       # m, largest accumulated wear depth
    mean_depth: np.ndarray      # m, accumulated wear depth averaged over the nominal patch
    volume: np.ndarray          # m³, accumulated worn volume
    rms_height: np.ndarray      # m, RMS height of the worn surface (about its mean)
    mean_gap: np.ndarray        # m, mean separation flat – deformed surface at the load
    iterations: np.ndarray      # contact-solver iterations of the solve at that step


@dataclass
class WearResult:
    """Outcome of ``simulate_wear``."""

    surface: Surface            #: worn topography
    depth: np.ndarray           #: m, accumulated wear depth field (..., ny, nx), >= 0
    pressure: np.ndarray        #: Pa, contact pressure on the worn surface at the load
    history: WearHistory
    laws: list = field(default_factory=list)   #: PressureGapLaw at the requested steps
    wall_time: float = 0.0      #: s


def simulate_wear(surface: Surface, contact: Kernel | ContactSolver, *, load, mu: float, distance: float,
                  steps: int, k_w, temperature=None, law_steps=(), law_loads=None,
                  initial_pressure=None, tol: float = 1e-8, max_iter: int = 5000,
                  progress: bool = False) -> WearResult:
    """Wear a rough patch (or batch) sliding ``distance`` [m] in ``steps`` equal increments (§3.4–3.5).

    contact: the solid's ``Kernel`` (homogeneous or layered; a ``ContactSolver`` is built) or a
    ``ContactSolver`` on the surface grid to reuse (its FFT plans). load: prescribed mean pressure
    [Pa], scalar or per patch (batch shape), >= 0 (a patch at 0 is out of contact and does not wear).
    k_w: ``WearRate`` or what it accepts; temperature as in ``wear_step``, constant over the run.
    Step j wears the surface with the pressure of the solve before it, then re-solves at the load
    warm-started from that pressure, so the total worn volume is exactly k_w mu P S for constant
    k_w. law_steps: steps (0…N) at which the p_n–g_n law is sampled at the mean pressures
    ``law_loads`` [Pa]. initial_pressure: warm start of the first solve (e.g. a previous call's
    ``pressure``).

    The step is explicit: a step that wears a patch deeper than a fraction of the RMS height it
    starts from lowers the loaded asperities past their neighbours, and the result depends on the
    step count (an opd patch slid 10 m: RMS 136 nm in 1 step, 9.6 nm in 16, 4.6 nm in 64 and 256;
    a fractal patch run in to 19.5 % contact: 12.3 % with 16 steps, whose largest step wore 0.63
    RMS heights, 19.48 % with 32, 0.31). A step that changes the relief (its deepest less its
    shallowest wear) by more than ``STEP_RMS`` RMS heights is warned about (``WearWarning``),
    asking for steps of a quarter RMS height; a step that wears every point alike (a periodic flat
    in full contact) changes nothing the step count could.
    """
    t0 = time.perf_counter()
    check_surface(surface)
    check_instance("contact", contact, (Kernel, ContactSolver), "an elastic Kernel or a ContactSolver")
    check_flag("progress", progress)
    solver = contact if isinstance(contact, ContactSolver) else ContactSolver(
        contact, surface.shape, surface.dx, surface.dy, surface.periodic)
    if tuple(solver.shape) != tuple(surface.shape) or solver.periodic != surface.periodic:
        raise InputError("contact", solver, f"solver grid must match the surface ({surface.shape}, "
                         f"periodic={surface.periodic})")
    distance = check_positive("distance", distance, allow_zero=True)
    mu = check_positive("mu", mu, allow_zero=True)
    steps = check_count("steps", steps)
    rate = WearRate(k_w)
    h0 = surface.heights
    batch = h0.shape[:-2]
    loads = check_field("load", load, nonnegative=True)
    try:
        loads = np.broadcast_to(loads, batch)
    except ValueError:
        raise InputError("load.shape", loads.shape, f"a scalar or the batch shape {batch}") from None
    T = _per_point("temperature", temperature, h0.shape) if rate.depends_on_temperature else None
    law_steps = sorted({check_count("law_steps", s, minimum=0)
                        for s in np.atleast_1d(check_field("law_steps", law_steps))})
    if law_steps and (law_steps[0] < 0 or law_steps[-1] > steps):
        raise InputError("law_steps", law_steps, f"steps must lie in 0…{steps}")
    if law_steps:
        law_loads = np.sort(np.atleast_1d(check_field("law_loads", law_loads)))
        if law_loads.ndim != 1 or np.any(law_loads <= 0):
            raise InputError("law_loads", law_loads, "a 1-D array of mean pressures > 0 [Pa]")

    dS = distance / steps
    cols = ("area_fraction", "max_pressure", "max_depth", "mean_depth", "volume", "rms_height",
            "mean_gap", "iterations")
    rows = {c: np.zeros((steps + 1,) + batch) for c in cols}
    laws = []
    current = surface
    options = dict(tol=tol, max_iter=max_iter)
    p = _solve_at_load(solver, current.heights, loads, initial_pressure, rows, 0, options)
    steps_iter = range(1, steps + 1)
    if progress:
        steps_iter = tqdm(steps_iter, desc="wear steps", unit="step")
    overshoot, from_flat = 0.0, False        # largest step relief over the RMS height it started from, and whether
    #                                          that surface was flat to round-off (a flat punch)
    for j in itertools.chain([0], steps_iter):       # (a list drew the bar before the steps: 150 000 step/s)
        if j > 0:
            rms = np.std(current.heights, axis=(-2, -1))
            increment = wear_step(current, p, rate, mu, dS, T)
            worn, least = increment.depth.max(axis=(-2, -1)), increment.depth.min(axis=(-2, -1))
            relief = np.where(worn - least > UNIFORM * worn, worn - least, 0.0)    # uniform wear: exact
            ratio = relief / np.maximum(rms, np.finfo(float).tiny)
            if ratio.max() > overshoot:
                k = np.unravel_index(np.argmax(ratio), ratio.shape)
                overshoot = float(ratio[k])
                from_flat = bool(rms[k] <= ROUND_OFF_FLAT * max(np.abs(current.heights[k]).max(), *surface.size))
            current = increment.surface
            p = _solve_at_load(solver, current.heights, loads, p, rows, j, options)
        depth = h0 - current.heights
        rows["max_depth"][j] = depth.max(axis=(-2, -1))
        rows["mean_depth"][j] = depth.mean(axis=(-2, -1))
        rows["volume"][j] = depth.sum(axis=(-2, -1)) * surface.dx * surface.dy
        hc = current.heights - current.heights.mean(axis=(-2, -1), keepdims=True)
        rows["rms_height"][j] = np.sqrt(np.mean(hc**2, axis=(-2, -1)))
        if j in law_steps:
            laws.append(_pressure_gap_law(solver, current.heights, law_loads, j, j * dS, options))
    history = WearHistory(sliding=np.arange(steps + 1) * dS, **rows)
    if overshoot > STEP_RMS and from_flat:
        warnings.warn(f"simulate_wear: a step wore a relief into a surface flat to round-off (e.g. a flat punch's "
                      f"edges), so the result depends on the step count (steps = {steps}): use more until the "
                      "result stops changing", WearWarning, stacklevel=2)
    elif overshoot > STEP_RMS:                 # (an absurd k_w was said to wear into a flat surface: a user trial)
        deep = float((h0 - current.heights).max())
        warnings.warn(f"simulate_wear: a step changed the relief by up to {overshoot:.3g} times the RMS height it "
                      f"started from (more than {STEP_RMS:g}), so the result depends on the step count (steps = "
                      f"{steps}): use more, at least {int(min(np.ceil(steps * overshoot / (STEP_RMS / 2)), 1e15))}, "
                      f"until the result stops changing; the deepest wear is {deep:.3g} m (are the wear rate and "
                      "the sliding distance right?)", WearWarning, stacklevel=2)
    return WearResult(current, h0 - current.heights, p, history, laws, time.perf_counter() - t0)


def _solve_at_load(solver, heights, loads, p0, rows, j, options) -> np.ndarray:
    """Contact pressure at the mean pressures ``loads`` (batch shape; patches at 0 stay unloaded),
    warm-started from ``p0`` where it carries load. Fills row ``j`` of the contact columns."""
    pressure = np.zeros(heights.shape)
    z = heights.max(axis=(-2, -1), keepdims=True) - heights
    rows["mean_gap"][j] = z.mean(axis=(-2, -1))        # unloaded: the flat just touches the top
    for name in ("area_fraction", "max_pressure", "iterations"):
        rows[name][j] = 0.0
    on = loads > 0
    if not on.any():
        return pressure
    sel = (Ellipsis,) if on.all() else np.nonzero(on)
    warm = None
    if p0 is not None:
        warm = np.array(np.broadcast_to(np.asarray(p0, dtype=float), heights.shape)[sel])
        cold = warm.sum(axis=(-2, -1)) <= 0
        warm[cold] = 1.0                                  # no usable warm start: uniform
    r = solver.solve(heights[sel], load=loads[sel], initial_pressure=warm, **options)
    pressure[sel] = r.pressure
    for name, value in (("area_fraction", r.area_fraction), ("max_pressure", r.pressure.max(axis=(-2, -1))),
                        ("mean_gap", r.mean_gap), ("iterations", r.iterations)):
        rows[name][(j,) + sel] = value
    return pressure


def _pressure_gap_law(solver, heights, loads, step, sliding, options) -> PressureGapLaw:
    """p_n–g_n law of the current topography: solve at each mean pressure, warm-started (Fig. 3.10)."""
    gaps, approaches, areas = [], [], []
    p = None
    for i, load in enumerate(loads):
        warm = None if p is None else p * (load / loads[i - 1])
        r = solver.solve(heights, load=load, initial_pressure=warm, **options)
        p = r.pressure
        gaps.append(r.mean_gap)
        approaches.append(r.approach)
        areas.append(r.area_fraction)
    return PressureGapLaw(step, sliding, loads.copy(), np.array(gaps), np.array(approaches), np.array(areas))


def _per_point(name: str, value, shape) -> np.ndarray:
    """A scalar, per-patch (batch shape) or per-point (full shape) value broadcast to ``shape``."""
    if value is None:
        raise InputError(name, None, "is required here")
    v = check_field(name, value)
    batch = shape[:-2]
    if v.ndim == len(shape):
        target = v
    elif v.shape == batch or v.ndim == 0:
        target = v[..., None, None]
    else:
        raise InputError(f"{name}.shape", v.shape, f"a scalar, the batch shape {batch} or the grid {shape}")
    try:
        return np.broadcast_to(target, shape)
    except ValueError:
        raise InputError(f"{name}.shape", v.shape, f"must broadcast to {shape}") from None

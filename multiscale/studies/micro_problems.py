"""The micro problems of parametric studies: parameters -> scalar metrics, with ``multiscale.micro``.

A problem declares its parameters as a frozen dataclass of ``multiscale.schema`` keys (unit kind,
range, default: study files are validated like scenes, with did-you-mean), the scalar metrics it
returns (name -> description [unit]) and, where one exists, an exact or independent reference
(``exact``): the study's ``reference.kind = "analytic"``. ``run(params, workdir)`` returns an
``Outcome``. Only ``multiscale.micro`` is used (a worker never loads DOLFINx); its modules are
imported here, with the worker, so a run's wall time and memory baseline never include loading
them.

Surfaces: the random fractal patch is drawn on a fixed generator grid (``source_n``) and resampled
to the study's grid ``n`` by Fourier interpolation, which is exact for a band-limited surface
(k_max < n/2): every grid size samples the SAME continuous surface, so a grid study measures the
discretisation alone. Physics lives in ``multiscale.micro``; this module only sets problems up.
"""
from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from multiscale.checkpoint import file_digest
from multiscale.micro.asperity import AsperityModel, AsperityWarning
from multiscale.micro.conduction import ConductionSolver, SeriesKernel
from multiscale.micro.contact import ContactSolver
from multiscale.micro.heat_kernels import Rotation, SpeedProfile, ThermalMaterial
from multiscale.micro.heating import SteadyHeating, TransientHeating
from multiscale.micro.kernels import HalfSpace
from multiscale.micro.laws import LawSpec, compute_laws
from multiscale.micro.layered import LayeredElastic, LayeredThermal
from multiscale.micro.outliers import DESPIKE
from multiscale.micro.stiffness import contact_stiffness
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.topography import DETREND, condition, read_topography
from multiscale.micro.wear import simulate_wear
from multiscale.micro.zones import cut_zones
from multiscale.references.hertz import sphere_on_flat
from multiscale.references.love import love_rectangle, love_rectangle_mean
from multiscale.scene_sections import MODULUS
from multiscale.scene_values import ROUGHNESS
from multiscale.schema import Choice, FilePath, Flag, Integer, Pair, Quantity, key, read
from multiscale.studies.base import Outcome, Problem, jsonable

__all__ = ["MICRO_PROBLEMS", "MicroProblem", "SurfaceParams", "rough_surface"]

_LENGTH = Quantity("length", gt=0)
_POISSON = Quantity("dimensionless", gt=-1, lt=0.5)
_POSITIVE = Quantity("dimensionless", gt=0)


class MicroProblem(Problem):
    """A micro problem: ``params`` dataclass, ``function(params) -> Outcome``, optional
    ``exact(params) -> dict`` depending only on ``exact_params`` (None: all parameters)."""

    def __init__(self, name, params, metrics, function, exact=None, exact_metrics=(), exact_params=None):
        self.name, self.params, self.metrics, self.function = name, params, dict(metrics), function
        self.doc = (function.__doc__ or "").strip().split("\n\n")[0].replace("\n", " ")
        self.exact, self.exact_metrics, self.exact_params = exact, tuple(exact_metrics), exact_params

    def parse(self, raw, path, ctx, **options):
        return read(self.params, raw, path, ctx)

    def key(self, params) -> dict:
        """The parameters, and the bytes of the files they name (a measured surface rewritten under
        its name makes new runs, as a scene's files do); a parameter added since records were made
        (the params' ``ADDED``) is left out while absent, so those records stay this run's."""
        values = {k: v for k, v in asdict(params).items() if not (v is None and k in getattr(params, "ADDED", ()))}
        files = {k: file_digest(v) for k, v in values.items() if isinstance(v, Path)}
        return {**jsonable(values), **({"files": files} if files else {})}

    def exact_key(self, params) -> dict:
        values = self.key(params)
        return values if self.exact_params is None else {k: values[k] for k in self.exact_params}

    def run(self, params, workdir):
        return self.function(params)


MICRO_PROBLEMS: dict[str, Problem] = {}     # name -> problem, in registration order


def _register(params, metrics, exact=None, exact_metrics=(), exact_params=None):
    """Decorator: register ``function(params) -> Outcome`` as the problem named after it."""
    def wrap(function):
        name = function.__name__.lstrip("_")
        MICRO_PROBLEMS[name] = MicroProblem(name, params, metrics, function, exact, exact_metrics, exact_params)
        return function
    return wrap


# ----------------------------------------------------------------------------- shared parameters
@dataclass(frozen=True)
class SurfaceParams:
    """A fractal rough patch (Eqs. 1.24–1.25): grid ``n`` per side; cut-offs in wavelengths per
    patch (a pair for anisotropy); drawn on ``source_n`` and resampled exactly to ``n``."""

    n: int = key(Integer(ge=8), default=128)
    size: float = key(_LENGTH, default=1e-3)                                   # m, patch side
    hurst: float = key(Quantity("dimensionless", gt=0, le=1), default=0.8)
    k_min: tuple = key(Pair(_POSITIVE), default=(2.0, 2.0))
    k_max: tuple = key(Pair(_POSITIVE), default=(10.0, 10.0))
    rms: float = key(ROUGHNESS, default=6e-6)                                    # m
    seed: int = key(Integer(ge=0), default=1)
    source_n: int = key(Integer(ge=8), default=64)

    def problems(self, path, ctx):
        out, where = [], f"{path}." if path else ""
        if any(hi <= lo for lo, hi in zip(self.k_min, self.k_max)):
            out.append(f"{where}k_max = {list(self.k_max)}: must exceed k_min = {list(self.k_min)}")
        for name in ("n", "source_n"):
            if max(self.k_max) >= getattr(self, name) / 2:
                out.append(f"{where}{name} = {getattr(self, name)}: must exceed 2 k_max = {2 * max(self.k_max):g} "
                           "(the surface must be resolved)")
        return out


def rough_surface(p: SurfaceParams, periodic: bool = True):
    """The patch of ``p`` on an n x n grid: drawn on ``source_n`` (seeded), Fourier-resampled."""
    h = fractal_surface(p.source_n, p.size, p.hurst, p.k_min, p.k_max, p.rms, seed=p.seed).heights
    if p.n != p.source_n:
        h = _fourier_resample(h, p.n)
    return Surface(h, p.size / p.n, p.size / p.n, periodic=periodic)


def _fourier_resample(h: np.ndarray, n: int) -> np.ndarray:
    """Samples on an n x n grid of the trigonometric polynomial through the periodic samples ``h``
    (exact when its spectrum has no content at or beyond either grid's Nyquist index)."""
    m = h.shape[0]
    H = np.fft.rfft2(h)
    out = np.zeros((n, n // 2 + 1), dtype=complex)
    k = min(m, n) // 2                                   # wavenumbers |k| < k copied
    out[:k, :k], out[n - k + 1:, :k] = H[:k, :k], H[m - k + 1:, :k]
    return np.ascontiguousarray(np.fft.irfft2(out, s=(n, n)) * (n * n) / (m * m))


# ----------------------------------------------------------------------------- hertz
@dataclass(frozen=True)
class HertzParams:
    """Rigid sphere on an elastic half-space, FFT-BEM on an isolated window of ``window`` contact
    radii per side (thesis §1.2.1; Johnson 1985 §4.2)."""

    grid: int = key(Integer(ge=8), default=64)                                 # cells per side
    window: float = key(Quantity("dimensionless", gt=2), default=4.0)          # window side / a
    radius: float = key(_LENGTH, default=10e-3)                                # m, sphere radius R
    load: float = key(Quantity("force", gt=0), default=10.0)                   # N
    E: float = key(MODULUS, default=210e9)                                    # Pa
    nu: float = key(_POISSON, default=0.3)
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)
    max_iter: int = key(Integer(ge=1), default=5000)


def _hertz_closed_form(p: HertzParams) -> dict:
    """The exact values of ``references.hertz.sphere_on_flat``."""
    h = sphere_on_flat(p.load, p.radius, HalfSpace.from_materials(p.E, p.nu).E_star)
    return {"contact_radius": h.contact_radius, "max_pressure": h.max_pressure, "approach": h.approach}


@_register(HertzParams, {"contact_radius": "radius of the contact area sqrt(A/pi) [m]",
                         "max_pressure": "peak contact pressure [Pa]",
                         "approach": "rigid approach from first touch [m]"},
           exact=_hertz_closed_form, exact_metrics=("contact_radius", "max_pressure", "approach"))
def _hertz(p: HertzParams) -> Outcome:
    """FFT-BEM Hertz contact (sphere on a half-space under a force) against the closed form."""
    kernel = HalfSpace.from_materials(p.E, p.nu)
    side = p.window * _hertz_closed_form(p)["contact_radius"]
    dx = side / p.grid
    x = (np.arange(p.grid) + 0.5) * dx - side / 2
    heights = -(x[None, :] ** 2 + x[:, None] ** 2) / (2 * p.radius)
    r = ContactSolver(kernel, heights.shape, dx, periodic=False).solve(
        heights, load=p.load / side**2, tol=p.tol, max_iter=p.max_iter)
    area = float(r.contact.sum()) * dx * dx
    return Outcome({"contact_radius": np.sqrt(area / np.pi), "max_pressure": float(r.pressure.max()),
                    "approach": float(r.approach)}, int(r.iterations), bool(r.converged))


# ----------------------------------------------------------------------------- rough contact
_MODELS = {"fft-bem": None, "circular": ("circular", False), "elliptic": ("elliptic", False),
           "circular-interacting": ("circular", True), "elliptic-interacting": ("elliptic", True)}


@dataclass(frozen=True)
class RoughContactParams(SurfaceParams):
    """A rough patch of an elastic half-space pressed by a rigid flat at ``approach`` (from the
    first touch of the highest point) with one micro model: FFT-BEM or one of the four asperity
    models of ch. 1 (circular/elliptic Hertz summits, with or without interaction)."""

    hurst: float = key(Quantity("dimensionless", gt=0, le=1), default=0.95)   # Table 1.1, set 1
    rms: float = key(ROUGHNESS, default=4e-6)
    E: float = key(MODULUS, default=4e9)                                     # §1.3: E = 4 GPa
    nu: float = key(_POISSON, default=0.15)
    approach: float = key(ROUGHNESS, default=5e-6)                              # m
    model: str = key(Choice(_MODELS), default="fft-bem")
    route: str = key(Choice(("energy", "kinematic")), default="energy")       # interacting models
    periodic: bool = key(Flag(), default=False)                                # FFT-BEM kernel
    tol: float | None = key(Quantity("dimensionless", gt=0, lt=1))            # default: the solver's
    hardness: float | None = key(Quantity("pressure", gt=0))                  # Pa, elastic-plastic FFT-BEM

    def problems(self, path, ctx):
        out = super().problems(path, ctx)
        if self.hardness is not None and self.model != "fft-bem":
            out.append(f'{path + "." if path else ""}hardness: only with model = "fft-bem" (the asperity models '
                       "are elastic)")
        return out


@_register(RoughContactParams, {"mean_pressure": "force / nominal area [Pa]",
                                "area_fraction": "real contact area / nominal area [-]"})
def _rough_contact(p: RoughContactParams) -> Outcome:
    """Rough contact at one rigid approach: FFT-BEM (optionally with a hardness) or an asperity model (§1.2.2)."""
    kernel = HalfSpace.from_materials(p.E, p.nu)
    surface = rough_surface(p, periodic=p.periodic)
    if p.model == "fft-bem":
        r = ContactSolver(kernel, surface.shape, surface.dx, periodic=p.periodic).solve(
            surface.heights, approach=p.approach, hardness=p.hardness, **({"tol": p.tol} if p.tol else {}))
        return Outcome({"mean_pressure": float(r.mean_pressure), "area_fraction": float(r.area_fraction)},
                       int(r.iterations), bool(r.converged))
    shape, interaction = _MODELS[p.model]
    model = AsperityModel.from_surface(surface, kernel, shape, interaction=interaction)
    # the same flat position: the asperity approach counts from the highest summit
    delta = p.approach - (float(surface.heights.max()) - model.z_max)
    with warnings.catch_warnings():               # said by the outcome, per run (``AsperityResult.notes``)
        warnings.simplefilter("ignore", AsperityWarning)
        r = model.solve(max(delta, 0.0), route=p.route, raster=False, **({"tol": p.tol} if p.tol else {}))
    return Outcome({"mean_pressure": r.mean_pressure, "area_fraction": r.area_fraction},
                   int(r.iterations), bool(r.converged), warnings=r.notes)


# ----------------------------------------------------------------------------- measured contact
@dataclass(frozen=True)
class MeasuredContactParams:
    """A measured topography (an instrument file, read and conditioned as ``multiscale surface``
    does: ``detrend`` form removed, optionally filtered at ``cutoff``, undefined points filled; the
    isolated patch it is, with its own pixel sizes; outliers warned of, or removed at ``despike``)
    on an elastic half-space, pressed by a rigid flat to the mean pressure ``load`` (FFT-BEM:
    ``ContactSolver`` of the conditioned ``Surface``; its stiffness by ``contact_stiffness``)."""

    file: Path = key(FilePath(base="the study file"), required=True)
    detrend: str = key(Choice(tuple(DETREND)), default="plane")
    cutoff: float | None = key(Quantity("length", gt=0, plausible=(1e-7, 0.1)))   # m, Gaussian λc
    despike: float | None = key(Quantity("dimensionless", gt=0), absent=f"outliers warned of (k = {DESPIKE:g}), kept")
    E: float = key(MODULUS, default=4e9)
    nu: float = key(_POISSON, default=0.15)
    load: float = key(Quantity("pressure", gt=0, plausible=(1e3, 5e9)), default=5e6)   # Pa, mean pressure
    tol: float | None = key(Quantity("dimensionless", gt=0, lt=1))            # default: the solver's

    ADDED = ("despike",)     # parameters added since records were made (``MicroProblem.key``)


@_register(MeasuredContactParams, {"approach": "rigid approach from the first touch [m]",
                                   "area_fraction": "real contact area / nominal area [-]",
                                   "stiffness": "normal contact stiffness d(mean pressure)/d(approach) of the "
                                                "isolated patch, its own spreading included [Pa/m]",
                                   "interface_stiffness": "the roughness' own normal stiffness, the patch's spreading "
                                                          "taken out (what an interface law adds) [Pa/m]"})
def _measured_contact(p: MeasuredContactParams) -> Outcome:
    """Contact of a measured topography at one mean pressure (FFT-BEM on its isolated patch)."""
    measured = read_topography(p.file)
    conditioned = condition(measured, p.detrend, p.cutoff, despike=p.despike)   # (the warning offered "despike",
    #                                                                              which the study refused: a trial)
    s = conditioned.surface
    solver = ContactSolver(HalfSpace.from_materials(p.E, p.nu), s.shape, s.dx, s.dy, s.periodic)
    r = solver.solve(s, load=p.load, **({"tol": p.tol} if p.tol else {}))
    k = contact_stiffness(solver, r)
    return Outcome({"approach": float(r.approach), "area_fraction": float(r.area_fraction),
                    "stiffness": float(k.stiffness), "interface_stiffness": float(k.interface)},
                   int(r.iterations), bool(r.converged), warnings=measured.notes + conditioned.notes)


# ----------------------------------------------------------------------------- wear steps
@dataclass(frozen=True)
class WearParams(SurfaceParams):
    """Archard wear of a rough patch sliding ``distance`` in ``steps`` equal increments at a
    constant mean pressure (thesis §3.5.1, Table 3.1)."""

    E: float = key(MODULUS, default=4e9)                                     # solid S1 (worn)
    nu: float = key(_POISSON, default=0.15)
    E2: float = key(MODULUS, default=220e9)                                  # solid S2
    nu2: float = key(_POISSON, default=0.33)
    pressure: float = key(Quantity("pressure", gt=0), default=1e6)            # Pa
    mu: float = key(Quantity("dimensionless", ge=0), default=0.4)
    distance: float = key(_LENGTH, default=10e-3)                             # m
    k_w: float = key(Quantity("wear_rate", gt=0), default=1e-12)              # 1/Pa
    steps: int = key(Integer(ge=1), default=400)
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)


@_register(WearParams, {"area_fraction": "final real contact area / nominal area [-]",
                        "max_depth": "final largest wear depth [m]",
                        "max_pressure": "final peak contact pressure [Pa]",
                        "mean_gap": "final mean gap at the load [m]",
                        "rms_height": "final RMS height [m]",
                        "volume": "worn volume [m^3]"})
def _wear_steps(p: WearParams) -> Outcome:
    """Wear of a rough patch in N steps (thesis §3.5.1: N = 200…600): final state."""
    r = simulate_wear(rough_surface(p), HalfSpace.from_materials(p.E, p.nu, p.E2, p.nu2), load=p.pressure,
                      mu=p.mu, distance=p.distance, steps=p.steps, k_w=p.k_w, tol=p.tol)
    h = r.history
    return Outcome({name: float(getattr(h, name)[-1]) for name in
                    ("area_fraction", "max_depth", "max_pressure", "mean_gap", "rms_height", "volume")},
                   int(h.iterations.sum()))


# ----------------------------------------------------------------------------- conductance
@dataclass(frozen=True)
class ConductanceParams(SurfaceParams):
    """Two 1 mm cubes (thesis §5.5, Fig. 5.10): solid 1 two-layered (top layer ``h`` of E1,
    kappa1 on a second layer E2, kappa2; h = 0: homogeneous E1, kappa1) on a rigid isothermal
    base, solid 2 homogeneous (Table 5.1); steady conduction at mean pressure ``pressure``."""

    thickness: float = key(_LENGTH, default=1e-3)                             # m, cube height
    E1: float = key(MODULUS, default=4e9)
    kappa1: float = key(Quantity("conductivity", gt=0), default=10.0)
    h: float = key(Quantity("length", ge=0), default=0.0)                     # m, top layer
    E2: float = key(MODULUS, default=4e9)
    kappa2: float = key(Quantity("conductivity", gt=0), default=10.0)
    nu1: float = key(_POISSON, default=0.15)
    E_s: float = key(MODULUS, default=220e9)                                 # solid 2 (Table 5.1)
    nu_s: float = key(_POISSON, default=0.33)
    kappa_s: float = key(Quantity("conductivity", gt=0), default=50.0)
    pressure: float = key(Quantity("pressure", gt=0), default=3e6)            # Pa
    resistance: float = key(Quantity("resistance", ge=0), default=0.0)        # m^2 K/W, local R
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)

    def problems(self, path, ctx):
        out = super().problems(path, ctx)
        if self.h >= self.thickness:
            out.append(f"{path + '.' if path else ''}h = {self.h:g} m: the top layer must be thinner than "
                       f"thickness = {self.thickness:g} m")
        return out


@_register(ConductanceParams, {"conductance": "total thermal contact conductance K_t [W/(m^2 K)]",
                               "interface_conductance": "K_i = 1/(1/K_t - 1/K_p) [W/(m^2 K)]",
                               "contact_temperature": "T_s, mean temperature of solid 1 on the contact [K]",
                               "area_fraction": "real contact area / nominal area [-]"})
def _conductance(p: ConductanceParams) -> Outcome:
    """Thermal contact conductance of a rough (layered) contact at one pressure (thesis §5.5)."""
    L = p.thickness
    if p.h > 0:
        el1 = LayeredElastic((p.h, L - p.h), (p.E1, p.E2), (p.nu1, p.nu1))
        th1 = LayeredThermal((p.h, L - p.h), (p.kappa1, p.kappa2))
    else:
        el1, th1 = LayeredElastic((L,), (p.E1,), (p.nu1,)), LayeredThermal((L,), (p.kappa1,))
    el2, th2 = LayeredElastic((L,), (p.E_s,), (p.nu_s,)), LayeredThermal((L,), (p.kappa_s,))
    surface = rough_surface(p)
    mech = ContactSolver(SeriesKernel(el1, el2), surface.shape, surface.dx).solve(
        surface.heights, load=p.pressure, tol=p.tol)
    heat = ConductionSolver(th1, th2, surface.shape, surface.dx).solve(mech.contact, resistance=p.resistance)
    return Outcome({"conductance": float(heat.conductance), "interface_conductance": float(heat.interface_conductance),
                    "contact_temperature": float(heat.contact_temperature_1),
                    "area_fraction": float(mech.area_fraction)},
                   int(mech.iterations) + int(heat.iterations), bool(mech.converged and heat.converged))


# ----------------------------------------------------------------------------- heat partition
@dataclass(frozen=True)
class HeatPartitionParams(SurfaceParams):
    """A 1 mm rough patch of the fixed solid S2 on the rotating disc S1 (thesis §6.4.1, Tables
    6.2–6.3), pressed by ``approach`` (or the mean ``pressure``); transient over ``duration``
    with time step ``dt`` and angular speed ``omega`` ramping linearly to ``omega_end`` over
    ``ramp_time`` (Eq. 6.6; default constant), or the steady state (§6.5) at ``omega``."""

    hurst: float = key(Quantity("dimensionless", gt=0, le=1), default=0.59)   # §6.4.1
    rms: float = key(ROUGHNESS, default=6.49e-6)
    n: int = key(Integer(ge=8), default=75)
    E: float = key(MODULUS, default=4e9)                                     # S2 (Table 6.3)
    nu: float = key(_POISSON, default=0.15)
    E1: float = key(MODULUS, default=220e9)                                  # S1
    nu1: float = key(_POISSON, default=0.33)
    kappa1: float = key(Quantity("conductivity", gt=0), default=50.0)
    chi1: float = key(Quantity("diffusivity", gt=0), default=1e-5)
    kappa2: float = key(Quantity("conductivity", gt=0), default=5.0)
    chi2: float = key(Quantity("diffusivity", gt=0), default=3.5e-6)
    radius: float = key(_LENGTH, default=0.1)                                 # m, patch centre from the axis
    approach: float = key(ROUGHNESS, default=10e-6)                             # m
    pressure: float | None = key(Quantity("pressure", gt=0))                  # Pa: load control instead
    mu: float = key(Quantity("dimensionless", gt=0), default=0.4)
    omega: float = key(Quantity("angular_speed", gt=0), default=100.0)        # rad/s
    omega_end: float | None = key(Quantity("angular_speed", ge=0))            # rad/s, end of the ramp
    ramp_time: float = key(Quantity("time", gt=0), default=0.1)               # s
    model: str = key(Choice(("transient", "steady")), default="transient")
    duration: float = key(Quantity("time", gt=0), default=4.5e-3)             # s
    dt: float = key(Quantity("time", gt=0), default=50e-6)                    # s, flux time step
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)

    def problems(self, path, ctx):
        out = super().problems(path, ctx)
        steps = self.duration / self.dt
        if self.model == "transient" and abs(steps - round(steps)) > 1e-6 * steps:
            out.append(f"{path + '.' if path else ''}dt = {self.dt:g} s: must divide duration = {self.duration:g} s")
        return out


@_register(HeatPartitionParams, {"partition_1": "share of the frictional heat into the disc S1 at the end [-]",
                                 "partition_1_mean": "time average of partition_1 over the run [-]",
                                 "max_temperature": "largest surface temperature rise at the end [K]",
                                 "area_fraction": "real contact area / nominal area [-]",
                                 "mean_pressure": "mean contact pressure [Pa]"})
def _heat_partition(p: HeatPartitionParams) -> Outcome:
    """Heat partition and flash temperature of a rough pin on a rotating disc (thesis §6.4)."""
    surface = rough_surface(p, periodic=False)
    control = {"load": p.pressure} if p.pressure else {"approach": p.approach}
    contact = ContactSolver(HalfSpace.from_materials(p.E, p.nu, p.E1, p.nu1), surface.shape, surface.dx,
                            periodic=False).solve(surface.heights, tol=p.tol, **control)
    disc, pin = ThermalMaterial(p.kappa1, p.chi1), ThermalMaterial(p.kappa2, p.chi2)
    common = {"area_fraction": float(contact.area_fraction), "mean_pressure": float(contact.mean_pressure)}
    if p.model == "steady":
        r = SteadyHeating(surface.shape, surface.dx, disc, pin, p.omega * p.radius).solve(
            contact.pressure, p.mu, tol=p.tol)
        return Outcome({"partition_1": float(r.partition_1), "partition_1_mean": float(r.partition_1),
                        "max_temperature": float(max(r.max_temperature_1, r.max_temperature_2)), **common},
                       int(contact.iterations) + int(r.iterations), bool(contact.converged and r.converged))
    profile = SpeedProfile.constant(p.omega) if p.omega_end is None else \
        SpeedProfile.ramp(p.omega, p.omega_end, p.ramp_time)
    centre = (p.radius / np.sqrt(2), p.radius / np.sqrt(2))          # Table 6.2: (70.7, 70.7) mm
    steps = int(round(p.duration / p.dt))
    r = TransientHeating(surface.shape, surface.dx, disc, pin, Rotation(centre, profile), p.dt, steps).run(
        contact.pressure, p.mu, tol=p.tol)
    p1 = r.partition_1[np.isfinite(r.partition_1)]
    return Outcome({"partition_1": float(r.partition_1[-1]), "partition_1_mean": float(p1.mean()),
                    "max_temperature": float(max(r.max_temperature_1[-1], r.max_temperature_2[-1])), **common},
                   int(contact.iterations) + int(r.iterations.sum()), bool(contact.converged and r.converged.all()))


# ----------------------------------------------------------------------------- zone laws
@dataclass(frozen=True)
class ZoneLawParams(SurfaceParams):
    """A rough surface cut into ``zones`` = (nx, ny) zones, each with its own p_n(g_n) law (thesis
    §1.4.2), embedded in a flat macro interface on an elastic half-space pressed by a rigid flat
    at ``approach``; reference: FFT-BEM of the whole surface on ``reference_n`` (default n)."""

    hurst: float = key(Quantity("dimensionless", gt=0, le=1), default=0.95)   # §1.5, set 1
    rms: float = key(ROUGHNESS, default=4e-6)
    n: int = key(Integer(ge=8), default=150)
    E: float = key(MODULUS, default=4e9)
    nu: float = key(_POISSON, default=0.15)
    zones: tuple = key(Pair(Integer(ge=1), names="[nx, ny]"), default=(5, 5))
    approach: float = key(ROUGHNESS, default=6e-6)                              # m, from the first touch
    p_max: float = key(Quantity("pressure", gt=0), default=50e6)              # Pa, top law node
    law_points: int = key(Integer(ge=4), default=20)
    love: str = key(Choice(("average", "centre")), default="average")
    reference_n: int | None = key(Integer(ge=8), absent="n")
    tol: float = key(Quantity("dimensionless", gt=0, lt=1), default=1e-8)

    def __post_init__(self):
        """An absent ``reference_n`` is ``n``, in the run's record key and in its reference's cache key
        (the reference of a sweep over n was cached without n: every n was judged against one)."""
        if self.reference_n is None:
            object.__setattr__(self, "reference_n", self.n)

    def problems(self, path, ctx):
        out = super().problems(path, ctx)
        where = f"{path}." if path else ""
        if any(self.n % z or self.n // z < 4 for z in self.zones):
            out.append(f"{where}zones = {list(self.zones)}: must divide n = {self.n} into zones of >= 4 x 4 cells")
        if self.reference_n != self.n and self.reference_n <= 2 * max(self.k_max):
            out.append(f"{where}reference_n = {self.reference_n}: must exceed 2 k_max")
        return out


def _zone_reference(p: ZoneLawParams) -> dict:
    """FFT-BEM of the whole (isolated) surface at the same approach on ``reference_n``."""
    surface = rough_surface(replace(p, n=p.reference_n), periodic=False)
    r = ContactSolver(HalfSpace.from_materials(p.E, p.nu), surface.shape, surface.dx, periodic=False).solve(
        surface.heights, approach=p.approach, tol=p.tol)
    return {"mean_pressure": float(r.mean_pressure), "area_fraction": float(r.area_fraction)}


def _zone_coupling(zones, grid, love: str) -> np.ndarray:
    """C_ij [m per Pa·π E*]: Love displacement of zone i (its mean, or at its centre) under a unit
    uniform pressure on zone j (Eq. 1.30), the flat macro half-space between the zones."""
    a, b = grid.size[0] / 2, grid.size[1] / 2
    c = np.array([z.centre for z in zones])
    if love == "centre":
        C = love_rectangle(c[:, None, 0] - c[None, :, 0], c[:, None, 1] - c[None, :, 1], a, b)
    else:          # Galerkin: mean over zone i by 8 x 8 Gauss points (smooth off the diagonal)
        x, w = np.polynomial.legendre.leggauss(8)
        X, Y = (a * x)[None, :], (b * x)[:, None]
        W = (w[None, :] * w[:, None]).ravel() / 4
        px, py = (X + 0 * Y).ravel(), (Y + 0 * X).ravel()
        dx = c[:, None, 0, None] + px - c[None, :, 0, None]
        dy = c[:, None, 1, None] + py - c[None, :, 1, None]
        C = love_rectangle(dx, dy, a, b) @ W
    np.fill_diagonal(C, love_rectangle_mean(a, b) if love == "average" else love_rectangle(0.0, 0.0, a, b))
    return C


def _flat_interface(laws, ids, C, flat, tol=1e-12, max_iter=100):
    """Zone pressures p with p_i = law_i(flat + sum_j C_ij p_j) (Eq. 1.31 on every zone with the
    macro half-space's Love coupling), by Newton with backtracking on the residual norm."""
    p = np.zeros(len(ids))
    for it in range(1, max_iter + 1):
        v = laws.pressure(flat + C @ p, ids)
        F = p - v.pressure
        norm = np.linalg.norm(F)
        if norm <= tol * max(float(v.pressure.max()), 1.0):
            return p, it, True
        step = np.linalg.solve(np.eye(len(ids)) + v.stiffness[:, None] * C, -F)
        lam = 1.0
        while lam > 1e-6:
            trial = np.maximum(p + lam * step, 0.0)
            if np.linalg.norm(trial - laws.pressure(flat + C @ trial, ids).pressure) < norm:
                break
            lam /= 2
        p = trial
    return p, max_iter, False


@_register(ZoneLawParams, {"mean_pressure": "mean pressure of the flat zoned interface [Pa]",
                           "area_fraction": "real contact area / nominal area from the zone laws [-]"},
           exact=_zone_reference, exact_metrics=("mean_pressure", "area_fraction"),
           exact_params=("size", "hurst", "k_min", "k_max", "rms", "seed", "source_n", "E", "nu", "approach",
                         "reference_n", "tol"))
def _zone_laws(p: ZoneLawParams) -> Outcome:
    """Zone laws on a flat macro interface vs the micro solve of the whole surface (thesis Fig. 1.14)."""
    kernel = HalfSpace.from_materials(p.E, p.nu)
    surface = rough_surface(p, periodic=False)
    grid, zones = cut_zones(surface, p.zones)
    love = "centre" if p.love == "centre" else "average"
    laws = compute_laws(zones, LawSpec(kernel, p_max=p.p_max, n_points=p.law_points, love=love, tol=p.tol))
    ids = np.array([z.id for z in zones])
    C = _zone_coupling(zones, grid, p.love) / (np.pi * kernel.E_star)
    pressure, its, ok = _flat_interface(laws, ids, C, float(surface.heights.max()) - p.approach)
    area = laws.area_fraction(pressure, ids)
    micro = int(sum(nd.iterations.sum() for nd in laws.nodes))
    return Outcome({"mean_pressure": float(pressure.mean()), "area_fraction": float(area.mean())}, micro + its, ok)

"""Frictional heating of a rough sliding contact: heat partition and flash temperatures (thesis ch. 6).

Body 1 moves (``Motion``: a rotating disc or a translation), body 2 is fixed; the grid is a
window of body 2's surface. The frictional heat phi = mu p_n V (W/m², contact cells only) splits
into phi_1 + phi_2 so that the surface temperatures match on the contact (perfect contact, §6.3.6)
or differ by the temperature jump of an interface layer (§6.3.3).

Transient (§6.3, ``TransientHeating``): fluxes are constant over each time step dt (§6.3.2); at step N
the increment psi = phi_1(t_N) − phi_1(t_{N−1}) on the contact solves A^N psi = Phi^N − Lambda^N
(Eqs. 6.9–6.18) with A^N = (T_1 + T_2)(one step) + interface diagonal (Eq. 6.16) applied by FFT
convolution (Eq. 6.22), restricted to the contacting cells (Eq. 6.21): by BiCGSTAB on the
non-symmetric system, and by the thesis' conjugate gradients on the least-squares objective
(Eqs. 6.19–6.20) for the patches where BiCGSTAB breaks down or stalls (``masked_krylov``).
Energy is conserved exactly: phi_2 = phi − phi_1. The history terms are summed in Fourier space
as Σ_k S_k · (flux of step N−k) with the pulse tables S_k of ``heat_kernels`` (the thesis' step
increments, summed by parts); matching at the end of each step makes the scheme first order in dt.
Steady (§6.5, ``SteadyHeating``): the same with steady kernels and remote temperatures (Eqs. 6.23–6.25);
the transient problem takes remote temperatures too (an extension: the thesis gives them to the
steady problem only). ``partition_law`` gives the steady p_1(p_mean, V) that the macro model needs.

Temperatures are rises [K] above the initial temperature, or remote temperature + rise when remote
temperatures are given. Sign: phi_i > 0 flows into body i. Heat rates Phi [W] are over the patch
window; with remote temperatures Phi_1 includes the conduction between them, so that a share
Phi_i/Phi may leave [0, 1].
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from multiscale.errors import (ConvergenceError, InputError, check_count, check_field, check_flag, check_instance,
                               check_positive, check_real)
from multiscale.memory import beyond_limit
from multiscale.micro.contact import ContactResult, ContactSolver
from multiscale.micro.fft import RealFFT2
from multiscale.micro.heat_kernels import Motion, Rotation, ThermalMaterial, Translation, pulse_tables
from multiscale.micro.kernels import Kernel, check_kernel, grid_shape, padded_size
from multiscale.micro.masked_krylov import masked_solve
from multiscale.micro.surface import Surface

FAR_AXIS = 0.2   # a rotating patch's half-diagonal at most this times its centre's radius (speeds within ±20 %)


class HeatingConvergenceError(ConvergenceError):
    """The solve of a thermal contact step reached ``max_iter`` before ``tol``."""


@dataclass(frozen=True)
class InterfaceLayer:
    """Thin interface layer of n components in series (§6.3.3, Fig. 6.19).

    Component m (1 … n, from body 1 to body 2) is a resistance ``resistance[m]`` [K m²/W] in
    parallel with a capacitance ``capacitance[m]`` [J/(m² K)] (step response R (1 − e^{−t/RC})).
    The heat is generated at the n + 1 nodes (node 0 on body 1, node n on body 2) with the
    ``generation`` profile of Fig. 6.42: "plane" (all at node round(plane · n)), "uniform", "linear"
    (weights n+1 … 1, largest next to the sliding body 1), or explicit weights (n + 1 values).
    Scalars apply to every component. R = 0 everywhere is the perfect contact of §6.3.6.
    """

    resistance: float | tuple = 0.0
    capacitance: float | tuple = 0.0
    n: int = 1
    generation: str | tuple = "plane"
    plane: float = 0.5

    def __post_init__(self):
        n = check_count("n", self.n)
        object.__setattr__(self, "n", n)
        for name in ("resistance", "capacitance"):
            v = check_field(name, getattr(self, name), nonnegative=True)
            if v.size not in (1, n) or v.ndim > 1:
                raise InputError(name, getattr(self, name), f"{n} finite values >= 0 (or one)")
            object.__setattr__(self, name, tuple(np.broadcast_to(v, (n,)).tolist()))
        if not 0.0 <= check_real("plane", self.plane) <= 1.0:
            raise InputError("plane", self.plane, "position of the heating plane in [0, 1]")
        self.weights  # validates the profile

    @property
    def weights(self) -> np.ndarray:
        """Fraction of the heat generated at each node 0 … n (sums to 1)."""
        n = int(self.n)
        if isinstance(self.generation, str):
            if self.generation == "plane":
                w = np.zeros(n + 1)
                w[int(round(self.plane * n))] = 1.0
            elif self.generation == "uniform":
                w = np.ones(n + 1)
            elif self.generation == "linear":
                w = np.arange(n + 1, 0, -1, dtype=float)
            else:
                raise InputError("generation", self.generation, "'plane', 'uniform', 'linear' or n+1 weights")
        else:
            w = check_field("generation", self.generation)
            if w.shape != (n + 1,) or np.any(w < 0) or not np.all(np.isfinite(w)) or w.sum() <= 0:
                raise InputError("generation", self.generation, f"{n + 1} finite weights >= 0, not all 0")
        return w / w.sum()

    def terms(self, dt: float):
        """(R, e, c) per component: resistance, exp(−dt/RC) (0 when C = 0), and the fraction c_m of
        the heat generated between body 1 and component m (flux through m: phi_1 − c_m phi)."""
        R, C = np.asarray(self.resistance), np.asarray(self.capacitance)
        tau = R * C
        with np.errstate(divide="ignore", over="ignore"):
            e = np.where(tau > 0, np.exp(-dt / np.where(tau > 0, tau, 1.0)), 0.0)
        return R, e, np.cumsum(self.weights)[:-1]


class _Layer:
    """Jump theta_2 − theta_1 = diagonal · phi_1 + offset at the end of a step across an interface
    layer (§6.3.3): Σ_m Σ_k (1 − exp(−(t_{N+1} − t_k)/(R^m C^m))) R^m Δ(phi_1 − c_m phi)_k, the
    memory of each component carried by one exponential sum (no history is stored).
    dt = inf gives the steady jump Σ_m R^m (phi_1 − c_m phi)."""

    def __init__(self, interface: InterfaceLayer | None, dt: float, shape):
        if interface is not None:
            check_instance("interface", interface, InterfaceLayer, "an InterfaceLayer or None")
        self.R, self.e, self.c = (interface or InterfaceLayer()).terms(dt)
        self.diagonal = float(np.sum(self.R * (1 - self.e)))
        self.active = bool(np.any(self.R > 0))                   # R = 0: perfect contact (§6.3.6)
        size = (self.R.size,) + tuple(shape) if self.active else (self.R.size,)
        self._sum = np.zeros(size)                               # Σ_k e^{−(t_{N+1}−t_k)/RC} Δvarphi_k
        self._last = np.zeros(size)                              # varphi_{N−1} = phi_1 − c_m phi

    def offset(self, phi):
        if not self.active:
            return 0.0
        memory = np.tensordot(self.R * self.e, self._last - self._sum, axes=1)
        return memory - float(np.sum(self.R * (1 - self.e) * self.c)) * phi

    def advance(self, phi_1, phi):
        if not self.active:
            return
        varphi = phi_1 - self.c.reshape((-1,) + (1,) * phi.ndim) * phi
        self._sum = self.e.reshape(self._sum.shape[:1] + (1,) * phi.ndim) * (self._sum + varphi - self._last)
        self._last = varphi


@dataclass
class HeatingResult:
    """Transient frictional heating (§6.3). Per-step arrays: (n_steps, *batch)."""

    times: np.ndarray              #: s, end t_{N+1} of each step (the matching instant)
    heat: np.ndarray               #: W, Phi: frictional heat rate during each step (mu F_n V)
    heat_1: np.ndarray             #: W, Phi_1 into body 1 (moving)
    heat_2: np.ndarray             #: W, Phi_2 into body 2 (fixed)
    partition_1: np.ndarray        #: p_1 = Phi_1/Phi; NaN where Phi = 0 (no heat: undefined)
    partition_2: np.ndarray        #: p_2 = Phi_2/Phi = 1 − p_1
    max_temperature_1: np.ndarray  #: K, max surface temperature rise of body 1 on the window (+ theta_1^0)
    max_temperature_2: np.ndarray  #: K, same for body 2
    field_times: np.ndarray        #: s, step ends at which fields were stored
    temperature_1: np.ndarray      #: K, (n_fields, *batch, ny, nx) surface temperature rise of body 1 (+ theta_1^0)
    temperature_2: np.ndarray      #: K, same for body 2
    flux_1: np.ndarray             #: W/m², (n_fields, *batch, ny, nx) phi_1 (phi_2 = flux − flux_1)
    flux: np.ndarray               #: W/m², (n_fields, *batch, ny, nx) generated phi
    iterations: np.ndarray         #: conjugate-gradient iterations per step
    residual: np.ndarray           #: relative temperature mismatch on the contact per step
    converged: np.ndarray          #: bool per step


@dataclass
class SteadyHeatingResult:
    """Steady sliding with remote temperatures (§6.5). Per-patch arrays have the batch shape."""

    heat: np.ndarray               #: W, Phi = mu F_n V
    heat_1: np.ndarray             #: W, into body 1 (includes conduction from the remote temperatures)
    heat_2: np.ndarray             #: W, into body 2
    partition_1: np.ndarray        #: Phi_1/Phi (NaN where Phi = 0)
    partition_2: np.ndarray
    max_temperature_1: np.ndarray  #: K, including the remote temperature theta_1^0
    max_temperature_2: np.ndarray  #: K
    temperature_1: np.ndarray      #: K, (*batch, ny, nx), Eq. 6.24
    temperature_2: np.ndarray      #: K
    flux_1: np.ndarray             #: W/m², (*batch, ny, nx)
    flux: np.ndarray               #: W/m², generated
    iterations: np.ndarray
    residual: np.ndarray
    converged: np.ndarray
    history: list = field(default_factory=list, repr=False)


class _Padded:
    """Real FFTs of (..., ny, nx) fields zero-padded to (2 my, 2 mx), ``half`` = (my, mx) the next
    5-smooth sizes (``kernels.padded_size``): products of spectra with the wrap-around influence
    tables of ``half`` are exact linear convolutions. Plans are reused per batch shape."""

    def __init__(self, shape):
        self.shape = shape
        self.half = (padded_size(shape[0]), padded_size(shape[1]))
        self._plans: dict[tuple, RealFFT2] = {}

    def _plan(self, batch):
        plan = self._plans.get(batch)
        if plan is None:
            my, mx = self.half
            plan = self._plans[batch] = RealFFT2(batch + (2 * my, 2 * mx), rows=self.shape[0])
        return plan

    def spectrum(self, x):
        ny, nx = self.shape
        plan = self._plan(x.shape[:-2])
        plan.input[..., :ny, :nx] = x
        return plan.forward().copy()

    def field(self, spec):
        ny, nx = self.shape
        return self._plan(spec.shape[:-2]).inverse(spec)[..., :ny, :nx].copy()

    def convolve(self, kernel_spec, x):
        ny, nx = self.shape
        plan = self._plan(x.shape[:-2])
        plan.input[..., :ny, :nx] = x
        spec = plan.forward()
        spec *= kernel_spec
        return plan.inverse(spec)[..., :ny, :nx].copy()


def _extrapolate(last, before):
    """Initial increment psi_N = r psi_{N−1} with r = <psi_{N−1}, psi_{N−2}>/|psi_{N−2}|² per patch
    (the increments of a heating transient decay nearly geometrically)."""
    axes = (-2, -1)
    bb = np.sum(before * before, axis=axes, keepdims=True)
    ratio = np.sum(last * before, axis=axes, keepdims=True) / np.where(bb > 0, bb, 1.0)
    return np.where(bb > 0, ratio, 0.0) * last


def _check_grid(shape, dx, dy):
    ny, nx = grid_shape("shape", shape, minimum=1)
    dx = check_positive("dx", dx)
    return (ny, nx), dx, check_positive("dy", dy if dy is not None else dx)


def _check_pressure(pressure, shape):
    p = check_field("pressure", pressure, min_ndim=2, nonnegative=True)
    if p.shape[-2:] != shape:
        raise InputError("pressure.shape", p.shape, f"last two axes must be {shape}")
    return p


def _check_bodies(body1, body2):
    for name, body in (("body1", body1), ("body2", body2)):
        check_instance(name, body, ThermalMaterial, "a ThermalMaterial(kappa, diffusivity)")


def _check_iteration(tol, max_iter, partial):
    """The CG options of both heating solvers."""
    check_positive("tol", tol)
    check_flag("partial", partial)
    return check_count("max_iter", max_iter)


def _remote_temperatures(value) -> tuple[float, float]:
    """(theta_1^0, theta_2^0) [K] of both heating solvers: two finite numbers, else InputError."""
    th = check_field("remote_temperatures", value)
    if th.shape != (2,):
        raise InputError("remote_temperatures", value, "two finite temperatures [K]")
    return float(th[0]), float(th[1])


def _partition(part, total):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total != 0, part / np.where(total != 0, total, 1.0), np.nan)


class TransientHeating:
    """Transient thermal contact (§6.3) on one grid and time step; kernels tabulated once.

    shape (ny, nx) and pixel dx (dy) [m] of the patch window; body1 (moving with ``motion``) and
    body2 (fixed) materials; time step dt [s]; n_steps: the longest run. For a constant speed the
    kernel tables are Toeplitz in time and built here; for a varying speed (e.g. Eq. 6.6) body 1's
    tables depend on the absolute time and are rebuilt each step (A^N changes with N).
    ``run`` can be called many times (pressures, friction, interface layers) with the same tables.
    The tables hold every age up to n_steps (``memory``), and step N sums over the N before it: a run's
    time grows like n_steps² (64², one thread: 200 steps 1.2 s, 400 steps 3.9 s, 2000 steps 69 s).
    """

    def __init__(self, shape, dx: float, body1: ThermalMaterial, body2: ThermalMaterial, motion: Motion,
                 dt: float, n_steps: int, dy: float | None = None):
        self.shape, self.dx, self.dy = _check_grid(shape, dx, dy)
        self.dt = check_positive("dt", dt)
        self.n_steps = check_count("n_steps", n_steps)
        need = self.memory(self.shape, self.n_steps)
        if have := beyond_limit(need):     # (200 000 steps on 64² was a raw MemoryError, or tens of GB asked: a trial)
            raise InputError("n_steps", n_steps, f"the pulse tables of {n_steps} steps on a {self.shape[0]} x "
                             f"{self.shape[1]} grid take about {need / 2**30:.3g} GiB, more than the "
                             f"{have / 2**30:.3g} GiB this process may use (the machine's, or its container's or "
                             "job's limit): fewer steps (a longer dt) or a coarser grid")
        _check_bodies(body1, body2)
        check_instance("motion", motion, Motion, "a Motion (Rotation or Translation)")
        reach = 0.5 * float(np.hypot(self.shape[0] * self.dy, self.shape[1] * self.dx))   # m, centre to corner
        if isinstance(motion, Rotation) and reach > FAR_AXIS * motion.radius:   # (on the axis: no heat, NaN
            raise InputError("motion.centre", motion.centre, f"{motion.radius:.3g} m from the axis, within "    # partitions:
                             f"{1 / FAR_AXIS:g} x the patch's half-diagonal {reach:.3g} m: the patch moves with its "  # a user
                             "centre's speed (far-axis approximation), whose error is of order that ratio")  # trial)
        self.body1, self.body2, self.motion = body1, body2, motion
        self._pad = _Padded(self.shape)
        self._tables2 = self._spectra(pulse_tables(self._pad.half, self.dx, self.dy, body2, self.dt, self.n_steps))
        self.toeplitz = motion.profile.is_constant
        self._tables1 = self._spectra(pulse_tables(self._pad.half, self.dx, self.dy, body1, self.dt, self.n_steps,
                                                   motion)) if self.toeplitz else None

    @staticmethod
    def memory(shape, n_steps: int) -> float:
        """Peak memory [bytes] of the tables for ``n_steps`` on a grid of ``shape`` (ny, nx): both
        bodies' spectra and their build, 4 x 16 bytes per age and point of the spectrum of the padded
        grid, 2 my (mx + 1) for the 5-smooth sizes (my, mx) >= (ny, nx) (traced: 106 MB for 200 steps
        on 64², 212 MB for 400). ``run`` adds 32 bytes per step and point for each pressure field
        (its flux histories: half as much again for one field)."""
        my, mx = (padded_size(int(n)) for n in shape)
        return 64.0 * n_steps * 2 * my * (mx + 1)

    @staticmethod
    def _spectra(tables):
        return tables.ages, np.fft.rfft2(tables.coeffs)

    def _body1_tables(self, N):
        if self.toeplitz:
            return self._tables1
        return self._spectra(pulse_tables(self._pad.half, self.dx, self.dy, self.body1, self.dt, N + 1,
                                          self.motion, t=(N + 1) * self.dt))

    @staticmethod
    def _history(tables, F, N, nb):
        """Σ_{age k >= 1} S_k · F[N − k]: temperature spectra at t_{N+1} of the fluxes of past steps."""
        ages, S = tables
        i0, i1 = np.searchsorted(ages, [1, N + 1])
        if i1 <= i0:
            return np.zeros(F.shape[1:], dtype=complex)
        ag, S = ages[i0:i1], S[i0:i1].reshape((i1 - i0,) + (1,) * nb + S.shape[-2:])
        if ag[-1] - ag[0] == ag.size - 1:
            Fk = F[N - ag[-1]: N - ag[0] + 1][::-1]
        else:
            Fk = F[N - ag]
        return np.einsum("k...,k...->...", S, Fk)

    def run(self, pressure, mu: float, *, interface: InterfaceLayer | None = None, n_steps: int | None = None,
            field_times=(), tol: float = 1e-8, max_iter: int = 2000, partial: bool = False,
            progress: bool = False, remote_temperatures=(0.0, 0.0)) -> HeatingResult:
        """Heat the contact of ``pressure`` [Pa] ((..., ny, nx), p > 0 on the contact, e.g.
        ``ContactResult.pressure``) with friction coefficient ``mu`` for ``n_steps`` steps.

        ``field_times`` [s]: store the surface temperature and flux fields at the step ends nearest
        to these times. Raises ``HeatingConvergenceError`` if a step does not reach ``tol`` in
        ``max_iter`` iterations, unless ``partial`` (then the step is flagged not converged).
        ``remote_temperatures`` = (theta_1^0, theta_2^0) [K]: both bodies start uniform at their
        own temperature, held far inside each body; the matching of every step gets theta_2^0 −
        theta_1^0 on its right-hand side as Eq. 6.23 does in the steady problem (the thesis
        gives remote temperatures to the steady problem only, §6.5; this extends them to §6.3),
        and the temperatures returned are theta^0 + rise. Default (0, 0): rises, as in §6.3.
        """
        p = _check_pressure(pressure, self.shape)
        mu = check_positive("mu", mu)
        th1, th2 = _remote_temperatures(remote_temperatures)
        n_steps = self.n_steps if n_steps is None else check_count("n_steps", n_steps)
        if not n_steps <= self.n_steps:
            raise InputError("n_steps", n_steps, f"between 1 and the tabulated {self.n_steps}")
        max_iter = _check_iteration(tol, max_iter, partial)
        check_flag("progress", progress)
        field_times = check_field("field_times", field_times, nonnegative=True)
        batch, nb = p.shape[:-2], p.ndim - 2
        mask = p > 0
        area = self.dx * self.dy
        edges = self.dt * np.arange(n_steps + 1)
        speed = self.motion.mean_speed(edges[:-1], edges[1:])               # m/s over each step
        keep = np.unique(np.clip(np.rint(field_times / self.dt).astype(int) - 1,
                                 0, n_steps - 1))
        layer = _Layer(interface, self.dt, p.shape)
        spec_shape = (n_steps,) + batch + (2 * self._pad.half[0], self._pad.half[1] + 1)
        F1, F2 = np.zeros(spec_shape, complex), np.zeros(spec_shape, complex)
        out = {k: np.zeros((n_steps,) + batch) for k in ("heat", "heat_1", "max_1", "max_2", "res")}
        its = np.zeros((n_steps,) + batch, dtype=int)
        fields = {k: np.zeros((keep.size,) + p.shape) for k in ("T1", "T2", "f", "phi")}
        f_prev = psi_prev = psi_prev2 = np.zeros(p.shape)
        A2 = self._tables2[1][0]
        for N in tqdm(range(n_steps), disable=not progress, desc="heating", unit="step"):
            tables1 = self._body1_tables(N)
            A1 = tables1[1][0]                          # age 0 (the current step) is never empty
            A = A1 + A2
            phi = mu * p * speed[N]
            phi_hat = self._pad.spectrum(phi)
            H1, H2 = self._history(tables1, F1, N, nb), self._history(self._tables2, F2, N, nb)
            free1 = self._pad.field(H1)
            free2 = self._pad.field(H2 + A2 * phi_hat)
            # Phi^N - Lambda^N (Eqs. 6.17-6.18): body-2 temperature of all the heat minus the
            # temperatures of phi_1 frozen at its last value, with the layer's jump
            rhs = free2 - free1 - layer.diagonal * f_prev - layer.offset(phi) + (th2 - th1)
            if N:
                rhs -= self._pad.field(A * F1[N - 1])
            scale = np.sqrt(np.sum(mask * (free1**2 + free2**2 + (th2 - th1) ** 2), axis=(-2, -1), keepdims=True))
            scale = np.where(scale > 0, scale, np.inf)
            psi, it, res, hist = masked_solve(lambda x: self._pad.convolve(A, x) + layer.diagonal * x,
                                              lambda x: self._pad.convolve(np.conj(A), x) + layer.diagonal * x,
                                              rhs, mask, scale, tol, max_iter, _extrapolate(psi_prev, psi_prev2))
            psi_prev2, psi_prev = psi_prev, psi
            f = f_prev + psi
            F1[N] = self._pad.spectrum(f)
            F2[N] = phi_hat - F1[N]
            T1 = self._pad.field(H1 + A1 * F1[N]) + th1
            T2 = self._pad.field(H2 + A2 * F2[N]) + th2
            layer.advance(f, phi)
            out["heat"][N] = np.sum(phi, axis=(-2, -1)) * area
            out["heat_1"][N] = np.sum(f, axis=(-2, -1)) * area
            out["max_1"][N], out["max_2"][N] = T1.max(axis=(-2, -1)), T2.max(axis=(-2, -1))
            out["res"][N], its[N] = res, it
            if N in keep:
                i = int(np.searchsorted(keep, N))
                fields["T1"][i], fields["T2"][i], fields["f"][i], fields["phi"][i] = T1, T2, f, phi
            f_prev = f
            if np.any(res > tol) and not partial:
                raise HeatingConvergenceError(
                    f"thermal contact step {N} did not converge in {max_iter} iterations "
                    f"(residual {res.max():.3e} > tol {tol:.1e})", hist,
                    self._result(out, its, fields, keep, edges, N + 1, tol))
        return self._result(out, its, fields, keep, edges, n_steps, tol)

    @staticmethod
    def _result(out, its, fields, keep, edges, n, tol):
        heat, heat_1 = out["heat"][:n], out["heat_1"][:n]
        heat_2 = heat - heat_1
        sel = keep < n
        return HeatingResult(
            times=edges[1:n + 1], heat=heat, heat_1=heat_1, heat_2=heat_2,
            partition_1=_partition(heat_1, heat), partition_2=_partition(heat_2, heat),
            max_temperature_1=out["max_1"][:n], max_temperature_2=out["max_2"][:n],
            field_times=edges[keep[sel] + 1], temperature_1=fields["T1"][sel], temperature_2=fields["T2"][sel],
            flux_1=fields["f"][sel], flux=fields["phi"][sel], iterations=its[:n], residual=out["res"][:n],
            converged=out["res"][:n] <= tol)


class SteadyHeating:
    """Steady sliding contact with remote temperatures (§6.5), tables built once per (grid, speed).

    Body 1 slides at constant ``speed`` [m/s] along ``angle`` [rad from +x] (a ``Rotation`` is
    replaced by the translation of its patch centre: far axis); body 2 is fixed. At ``speed`` 0
    no frictional heat enters: ``solve`` gives the conduction between the remote temperatures
    through the contact (``heat_1`` = −``heat_2``, Holm's constriction), and the partitions, Φ_1/Φ
    with Φ = 0, are NaN: undefined (``partition_law`` refuses a speed of 0).
    """

    def __init__(self, shape, dx: float, body1: ThermalMaterial, body2: ThermalMaterial, speed: float,
                 dy: float | None = None, angle: float = 0.0):
        self.shape, self.dx, self.dy = _check_grid(shape, dx, dy)
        self.speed = check_positive("speed", speed, allow_zero=True)
        _check_bodies(body1, body2)
        if not np.isfinite(check_real("angle", angle)):
            raise InputError("angle", angle, "must be finite [rad]")
        self.body1, self.body2 = body1, body2
        self._pad = _Padded(self.shape)
        motion = Translation.steady(self.speed, angle)
        k1 = pulse_tables(self._pad.half, self.dx, self.dy, body1, np.inf, 1, motion).coeffs[0]
        k2 = pulse_tables(self._pad.half, self.dx, self.dy, body2, np.inf, 1).coeffs[0]
        self._S1, self._S2 = np.fft.rfft2(k1), np.fft.rfft2(k2)

    def solve(self, pressure, mu: float, *, interface: InterfaceLayer | None = None,
              remote_temperatures=(0.0, 0.0), tol: float = 1e-8, max_iter: int = 2000,
              partial: bool = False) -> SteadyHeatingResult:
        """Steady partition of phi = mu p V on the contact of ``pressure`` [Pa] (..., ny, nx).

        (F1 + F2 + Σ R^m) phi_1 = F2 phi + Σ R^m c_m phi + theta_2^0 − theta_1^0 on the contact
        (Eq. 6.23 with the steady interface jump), by ``masked_krylov.masked_solve`` (BiCGSTAB,
        the least-squares CG of Eq. 6.25 where it fails).
        ``remote_temperatures`` = (theta_1^0, theta_2^0) [K], temperatures far inside each body.
        """
        p = _check_pressure(pressure, self.shape)
        mu = check_positive("mu", mu)
        th1, th2 = _remote_temperatures(remote_temperatures)
        max_iter = _check_iteration(tol, max_iter, partial)
        layer = _Layer(interface, np.inf, p.shape)
        mask = p > 0
        phi = mu * p * self.speed
        phi_hat = self._pad.spectrum(phi)
        free2 = self._pad.field(self._S2 * phi_hat)
        rhs = free2 - layer.offset(phi) + (th2 - th1)
        A = self._S1 + self._S2
        scale = np.sqrt(np.sum(mask * (free2**2 + (th2 - th1) ** 2), axis=(-2, -1), keepdims=True))
        scale = np.where(scale > 0, scale, np.inf)
        f, it, res, hist = masked_solve(lambda x: self._pad.convolve(A, x) + layer.diagonal * x,
                                        lambda x: self._pad.convolve(np.conj(A), x) + layer.diagonal * x,
                                        rhs, mask, scale, tol, max_iter)
        f_hat = self._pad.spectrum(f)
        T1 = self._pad.field(self._S1 * f_hat) + th1
        T2 = self._pad.field(self._S2 * (phi_hat - f_hat)) + th2
        area = self.dx * self.dy
        heat, heat_1 = phi.sum(axis=(-2, -1)) * area, f.sum(axis=(-2, -1)) * area
        result = SteadyHeatingResult(
            heat=heat, heat_1=heat_1, heat_2=heat - heat_1, partition_1=_partition(heat_1, heat),
            partition_2=_partition(heat - heat_1, heat), max_temperature_1=T1.max(axis=(-2, -1)),
            max_temperature_2=T2.max(axis=(-2, -1)), temperature_1=T1, temperature_2=T2, flux_1=f, flux=phi,
            iterations=it, residual=res, converged=res <= tol, history=hist)
        if np.any(res > tol) and not partial:
            raise HeatingConvergenceError(f"steady thermal contact did not converge in {max_iter} iterations "
                                          f"(residual {res.max():.3e} > tol {tol:.1e})", hist, result)
        return result


@dataclass
class PartitionLaw:
    """Steady heat partition of a rough patch over a pressure sweep (and speeds): the law p_1(p, V)
    the macro model applies per interface facet. Arrays are (n_speeds, n_pressures)."""

    mean_pressure: np.ndarray      # Pa, (n_p,), ascending
    speed: np.ndarray              # m/s, (n_v,), ascending
    partition_1: np.ndarray        # steady p_1 = Phi_1/Phi into the moving body 1
    area_fraction: np.ndarray      # (n_p,), real contact area / nominal area
    max_temperature_1: np.ndarray  # K, steady flash temperature rise of body 1 (with this mu)
    max_temperature_2: np.ndarray  # K, same for body 2
    mu: float                      # friction coefficient used for the temperatures

    def __call__(self, pressure, speed=None) -> np.ndarray:
        """p_1 at mean pressure(s) [Pa] (and speed(s) [m/s], needed when several were sampled):
        linear in log p and in V, clamped to the sampled ranges; InputError for a NaN or inf."""
        logp = np.log(np.clip(check_field("pressure", pressure), self.mean_pressure[0], self.mean_pressure[-1]))
        rows = np.array([np.interp(logp, np.log(self.mean_pressure), row) for row in self.partition_1])
        if self.speed.size == 1:
            return rows[0]
        if speed is None:
            raise InputError("speed", speed, f"the law was sampled at {self.speed.size} speeds: give one")
        v = np.clip(np.broadcast_to(check_field("speed", speed), logp.shape), self.speed[0], self.speed[-1])
        i = np.clip(np.searchsorted(self.speed, v, side="right") - 1, 0, self.speed.size - 2)
        w = (v - self.speed[i]) / (self.speed[i + 1] - self.speed[i])
        lo = np.take_along_axis(rows, i[None], 0)[0]
        hi = np.take_along_axis(rows, (i + 1)[None], 0)[0]
        return (1 - w) * lo + w * hi


def partition_law(source, body1: ThermalMaterial, body2: ThermalMaterial, speed, pressures=None, *,
                  mu: float, elastic: Kernel | None = None, dx: float | None = None, dy: float | None = None,
                  angle: float = 0.0, interface: InterfaceLayer | None = None, tol: float = 1e-8) -> PartitionLaw:
    """Steady partition law p_1(p_mean, V) of one patch (§6.4.2, Fig. 6.26; steady solver of §6.5).

    source: a ``Surface`` (then ``elastic`` kernel and ``pressures`` [Pa] are needed: the patch is
    pressed by ``ContactSolver`` at each mean pressure, batched) or a batched ``ContactResult``
    (pressure fields (n_p, ny, nx); give ``dx``). speed: sliding speed(s) V [m/s] > 0 of body 1
    along ``angle``; body 2 is fixed. The thermal problem is an isolated patch (heat-source kernels).
    """
    if isinstance(source, Surface):
        if elastic is None or pressures is None:
            raise InputError("elastic/pressures", (elastic, pressures),
                             "a Surface needs an elastic kernel and mean pressures")
        check_kernel("elastic", elastic, thermal=False)
        if source.heights.ndim != 2:
            raise InputError("source", source.heights.shape, "one patch (a 2-D height map)")
        loads = np.sort(np.atleast_1d(check_field("pressures", pressures)))
        if loads.ndim != 1 or not loads.size or np.any(loads <= 0):    # (empty: "heights.shape ... no patch")
            raise InputError("pressures", pressures, "one or more mean pressures > 0 [Pa] (a 1-D array)")
        h = np.broadcast_to(source.heights, loads.shape + source.shape)
        contact = ContactSolver(elastic, source.shape, source.dx, source.dy, source.periodic).solve(
            h, load=loads, tol=tol)
        dx, dy = source.dx, source.dy
    elif isinstance(source, ContactResult):
        if dx is None:
            raise InputError("dx", dx, "a ContactResult needs the pixel size dx [m]")
        if pressures is not None:
            raise InputError("pressures", pressures, "taken from the ContactResult: leave it None")
        contact = source
    else:
        raise InputError("source", type(source).__name__, "a Surface or a ContactResult")
    p = np.asarray(contact.pressure, dtype=float).reshape((-1,) + contact.pressure.shape[-2:])
    order = np.argsort(np.asarray(contact.mean_pressure).reshape(-1))
    p = p[order]
    mean = np.asarray(contact.mean_pressure, dtype=float).reshape(-1)[order]
    if np.any(mean <= 0) or np.any(np.diff(mean) <= 0):
        raise InputError("pressures", mean, "distinct mean pressures > 0")
    speeds = np.sort(np.atleast_1d(check_field("speed", speed)))
    if speeds.ndim != 1 or not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise InputError("speed", speed, "sliding speeds must be finite and > 0 (no heat at rest)")
    rows = [SteadyHeating(p.shape[-2:], dx, body1, body2, v, dy, angle).solve(p, mu, interface=interface, tol=tol)
            for v in speeds]
    return PartitionLaw(
        mean_pressure=mean, speed=speeds, partition_1=np.array([r.partition_1 for r in rows]),
        area_fraction=np.mean(p > 0, axis=(-2, -1)), max_temperature_1=np.array([r.max_temperature_1 for r in rows]),
        max_temperature_2=np.array([r.max_temperature_2 for r in rows]), mu=float(mu))

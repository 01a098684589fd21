"""Steady thermal conduction through a rough contact: thermal contact conductance (thesis §5.2–5.4).

Two solids touch on the real contact area found by the mechanics solve. The surface temperature of
solid i is ``theta_i = T_i * phi_i + theta_li`` (Eqs. 5.1–5.3 for one solid, §5.4.2 for two) with ``phi_1 + phi_2 = 0``; on the
contact, ``theta_2 − theta_1 = R phi_1`` (local resistance R [m² K/W], f = R phi). Hence Eq. 5.8,

    (T_1 + T_2) * phi_1 + R phi_1 = theta_l2 − theta_l1   on the contact,   phi_1 = 0 elsewhere (Eq. 5.12),

solved as the minimum of F = ½ phiᵀ(T + R)phi − phiᵀ Δθ (Eq. 5.11) on the contact points by
conjugate gradients with FFT convolutions (Eqs. 5.10–5.11; the operator is symmetric positive
definite there). K_t = mean(phi_1) / Δθ (Eq. 5.9), K_p = 1 / (F_1(0) + F_2(0)) and
K_i = 1 / (1/K_t − 1/K_p). On an isolated patch K_p is the conductance of a uniform flux over the
whole patch (mean temperature difference per flux: the bodies' spreading from the patch, and their
bulk), as ``micro.laws.Conductance`` takes a zone's: 1/(F_1(0) + F_2(0)) there would leave the
patch's own spreading resistance in K_i (K_i = K_t on half-spaces, bounded by the patch size
instead of the roughness; on layers 1/K_t − 1/K_p < 0, an "infinite" K_i at 1 % contact: a user
trial).

Thermal kernels (``Kernel``: surface temperature [K] per surface flux [W/m²]): the q = 0 value
F(0) [m² K/W] is the bulk resistance of a body of finite thickness with a fixed temperature at its
base (layered kernels). A semi-infinite body has F(0) infinite (the kernel returns 0): its
temperature ``theta_l`` is then the mean surface temperature of the periodic patch (the far field
extrapolated to the surface), K_p is infinite and K_t = K_i is the constriction conductance.

Signs: phi_1 [W/m²] is the heat flux entering solid 1 (from 2 to 1 when theta_l2 > theta_l1).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from multiscale.errors import (ConvergenceError, InputError, check_count, check_field, check_flag, check_instance,
                               check_mask, check_positive, check_real)
from multiscale.micro.contact import ContactSolver
from multiscale.micro.kernels import InfluenceOperator, Kernel, check_kernel
from multiscale.micro.masked_krylov import masked_cg
from multiscale.micro.surface import Surface, check_surface


class SeriesKernel(Kernel):
    """Two solids' kernels in series: responses add (Eq. 5.8's T_1 + T_2; or two elastic bodies).

    At q = 0 an infinite compliance (a kernel value 0 there) stays infinite (0).
    """

    def __init__(self, first: Kernel, second: Kernel):
        check_instance("first", first, Kernel, "a Kernel")
        self.first, self.second = first, check_kernel("second", second, first.thermal)   # of one kind: they add

    @property
    def thermal(self) -> bool:
        """Of the two kernels' kind (the same)."""
        return self.first.thermal

    def compliance(self, q):
        q = np.asarray(q, dtype=float)
        f1, f2 = self.first.compliance(q), self.second.compliance(q)
        return np.where((q == 0) & ((f1 == 0) | (f2 == 0)), 0.0, f1 + f2)

    def influence(self, ny, nx, dy, dx):
        return self.first.influence(ny, nx, dy, dx) + self.second.influence(ny, nx, dy, dx)

    def key(self) -> tuple:
        return ("SeriesKernel", self.first.key(), self.second.key())


class ConductionConvergenceError(ConvergenceError):
    """The conduction CG reached ``max_iter`` before ``tol``."""


@dataclass
class ConductionResult:
    """Steady thermal contact of a (batch of) patch(es); per-patch arrays have the batch shape."""

    flux: np.ndarray                   #: W/m², phi_1 into solid 1, zero off the contact, (..., ny, nx)
    temperature_1: np.ndarray          #: K, surface temperature of solid 1, (..., ny, nx)
    temperature_2: np.ndarray          #: K, surface temperature of solid 2, (..., ny, nx)
    contact: np.ndarray                #: bool, contacting points, (..., ny, nx)
    conductance: np.ndarray            #: W/(m² K), K_t total (Eq. 5.9)
    interface_conductance: np.ndarray  #: W/(m² K), K_i = 1/(1/K_t − 1/K_p); inf for a perfect interface
    perfect_conductance: float         #: W/(m² K), K_p: full contact under a uniform flux (``ConductionSolver``)
    contact_temperature_1: np.ndarray  #: K, T_s: mean of temperature_1 over the contact
    contact_temperature_2: np.ndarray  #: K, mean of temperature_2 over the contact (= T_s when R = 0)
    iterations: np.ndarray             #: CG iterations per patch
    residual: np.ndarray               #: |(T + R)phi − Δθ| on the contact / |Δθ| (2-norms), per patch
    converged: np.ndarray              #: bool per patch


class ConductionSolver:
    """Reusable steady thermal-contact solver on one grid (FFT plans built once; §5.4.3).

    kernel_1, kernel_2: thermal ``Kernel`` of solid 1 and solid 2 (``ThermalHalfSpace`` or
    layered); grid ``shape`` (ny, nx), pixel ``dx`` (``dy``) [m]; ``periodic`` patch or isolated
    (zero-padded DC-FFT, temperatures then relative to the far field at infinity).
    """

    def __init__(self, kernel_1: Kernel, kernel_2: Kernel, shape, dx: float, dy: float | None = None,
                 periodic: bool = True):
        for name, kernel in (("kernel_1", kernel_1), ("kernel_2", kernel_2)):
            check_kernel(name, kernel, thermal=True)
        self.kernels = (kernel_1, kernel_2)
        self.series = InfluenceOperator(SeriesKernel(kernel_1, kernel_2), shape, dx, dy, periodic)
        self.body_1 = InfluenceOperator(kernel_1, shape, dx, dy, periodic)
        self.shape, self.periodic = self.series.shape, bool(periodic)
        f0 = [float(np.asarray(k.compliance(np.zeros(1)))[0]) for k in self.kernels]
        if min(f0) < 0 or not all(np.isfinite(f0)):
            raise InputError("kernel", self.kernels, "q = 0 value must be finite and >= 0")
        self.bulk = (f0[0], f0[1]) if min(f0) > 0 else None    # m² K/W each, None: semi-infinite

    def uniform_resistance(self, masks) -> np.ndarray:
        """R_u [m² K/W] of each mask (..., ny, nx): the mean over it of the temperature difference of
        the two surfaces under a uniform unit flux on it (the series kernels' response)."""
        masks = check_mask("masks", masks).astype(float)
        return np.sum(self.series(masks) * masks, axis=(-2, -1)) / masks.sum(axis=(-2, -1))

    @cached_property
    def perfect_conductance(self) -> float:
        """K_p [W/(m² K)], the conductance of a perfect (full) contact under a uniform flux: periodic
        1/(F_1(0) + F_2(0)) (inf if a body is semi-infinite), isolated 1/R_u of the whole patch
        (``uniform_resistance``; e.g. 1/(0.4732 c (1/kappa_1 + 1/kappa_2)) for a square of side c
        on half-spaces, Yovanovich)."""
        if self.periodic:
            return np.inf if self.bulk is None else 1.0 / sum(self.bulk)
        return 1.0 / float(self.uniform_resistance(np.ones(self.shape)))

    def solve(self, contact, *, resistance=0.0, theta_1: float = 0.0, theta_2: float = 1.0,
              tol: float = 1e-10, max_iter: int | None = None, initial_flux=None,
              partial: bool = False) -> ConductionResult:
        """Solve Eq. 5.8 on the contact mask ``contact`` (bool, (..., ny, nx)).

        resistance: local resistance R [m² K/W] >= 0, scalar or field broadcastable to the grid;
        theta_1, theta_2: base (or far-field) temperatures theta_l1, theta_l2 [K], must differ;
        tol: relative 2-norm residual; max_iter (default 20 sqrt(contact points) + 100);
        initial_flux: warm start (W/m², restricted to the contact). Raises
        ``ConductionConvergenceError`` if not converged, unless ``partial``.
        """
        mask = check_mask("contact", contact)
        if mask.shape[-2:] != self.shape:
            raise InputError("contact.shape", mask.shape, f"last two axes must be {self.shape}")
        R = check_field("resistance", resistance, nonnegative=True)
        try:
            R = np.broadcast_to(R, mask.shape)
        except ValueError:
            raise InputError("resistance.shape", R.shape, f"must broadcast to {mask.shape}") from None
        if not np.isfinite(check_real("theta_1", theta_1)):
            raise InputError("theta_1", theta_1, "must be finite [K]")
        dtheta = check_real("theta_2", theta_2) - float(theta_1)
        if not np.isfinite(dtheta) or dtheta == 0:
            raise InputError("theta_2", theta_2, f"must be finite and differ from theta_1 = {theta_1}")
        check_positive("tol", tol)
        check_flag("partial", partial)
        if initial_flux is not None:
            initial_flux = check_field("initial_flux", initial_flux)
        axes = (-2, -1)
        full = mask.all(axis=axes)
        if self.periodic and self.bulk is None and np.any(full & np.all(R == 0, axis=axes)):
            raise InputError("contact", "full contact", "full contact of semi-infinite bodies without "
                             "a local resistance has an infinite conductance")
        n_contact = mask.sum(axis=axes)
        if max_iter is None:
            max_iter = int(20 * np.sqrt(max(int(n_contact.max()), 1))) + 100
        max_iter = check_count("max_iter", max_iter)
        if initial_flux is None:    # uniform flux of the 1-D (bulk + self-influence) estimate
            initial_flux = dtheta / (self.series.self_influence + (sum(self.bulk) if self.bulk else 0.0) + R)
        else:
            try:
                initial_flux = np.broadcast_to(initial_flux, mask.shape)
            except ValueError:
                raise InputError("initial_flux.shape", initial_flux.shape, f"must broadcast to {mask.shape}") from None
        phi, its, res, ok = masked_cg(self.series, dtheta, mask, tol, max_iter, initial_flux, diagonal=R)
        if not np.all(np.isfinite(phi)):
            raise ConductionConvergenceError("conduction CG produced non-finite fluxes", [], None)
        T1phi = self.body_1(phi)
        Tphi = self.series(phi)
        temp_1 = theta_1 + T1phi
        temp_2 = theta_2 - (Tphi - T1phi)
        K_t = phi.mean(axis=axes) / dtheta
        K_p = self.perfect_conductance          # (isolated: 1/K_t <= 1/K_p in full contact, Thomson: K_i inf)
        with np.errstate(divide="ignore"):
            excess = 1.0 / K_t - 1.0 / K_p                    # interface resistance [m² K/W]
            K_i = np.where(excess > 1e-12 / np.maximum(K_t, 1e-300), 1.0 / excess, np.inf)
        K_i = np.where(K_t > 0, K_i, 0.0)
        nc = np.maximum(n_contact, 1)
        result = ConductionResult(
            flux=phi, temperature_1=temp_1, temperature_2=temp_2, contact=mask, conductance=K_t,
            interface_conductance=K_i, perfect_conductance=K_p,
            contact_temperature_1=np.where(n_contact > 0, np.sum(temp_1 * mask, axis=axes) / nc, theta_1),
            contact_temperature_2=np.where(n_contact > 0, np.sum(temp_2 * mask, axis=axes) / nc, theta_2),
            iterations=its, residual=res, converged=ok)
        if not np.all(ok) and not partial:
            raise ConductionConvergenceError(
                f"conduction CG did not converge in {max_iter} iterations (residual {res.max():.3e} > "
                f"tol {tol:.1e} on {int(np.sum(~ok))} patch(es))", [float(res.max())], result)
        return result


@dataclass
class ConductanceLaw:
    """Thermal contact conductance vs mean contact pressure of a patch (or batch) (Figs. 5.13, 5.18)."""

    pressure: np.ndarray               # Pa, mean contact pressures (n,), increasing
    area_fraction: np.ndarray          # -, real area / nominal area, (n, *batch)
    conductance: np.ndarray            # W/(m² K), K_t, (n, *batch)
    interface_conductance: np.ndarray  # W/(m² K), K_i, (n, *batch)
    perfect_conductance: float         # W/(m² K), K_p (pressure independent)
    contact_temperature: np.ndarray    # K, T_s of solid 1, (n, *batch)
    mechanics_time: float              # s, contact solves
    conduction_time: float             # s, thermal solves


def conductance_law(surface: Surface, elastic: Kernel | ContactSolver, thermal, pressures, *,
                    resistance=0.0, theta_1: float = 0.0, theta_2: float = 1.0, tol: float = 1e-8,
                    thermal_tol: float = 1e-10) -> ConductanceLaw:
    """K_t(p) law of a rough patch (or batch of patches) over mean pressures ``pressures`` [Pa] (§5.5).

    elastic: the mechanical ``Kernel`` of the contact (or a ``ContactSolver`` to reuse); thermal:
    ``(kernel_1, kernel_2)`` or a ``ConductionSolver``. Each pressure: FFT-BEM contact solve (area),
    then Eq. 5.8 on that area; both warm-started from the previous pressure.
    """
    check_surface(surface)
    check_instance("elastic", elastic, (Kernel, ContactSolver), "an elastic Kernel or a ContactSolver")
    check_positive("thermal_tol", thermal_tol)
    p = check_field("pressures", pressures)
    if p.ndim != 1 or p.size == 0 or np.any(p <= 0):
        raise InputError("pressures", pressures, "a 1-D array of mean pressures > 0 [Pa]")
    p = np.sort(p)
    mech = elastic if isinstance(elastic, ContactSolver) else ContactSolver(
        elastic, surface.shape, surface.dx, surface.dy, surface.periodic)
    if isinstance(thermal, ConductionSolver):
        heat = thermal
    else:
        try:
            k1, k2 = thermal
        except (TypeError, ValueError):
            raise InputError("thermal", thermal, "(kernel_1, kernel_2) or a ConductionSolver") from None
        heat = ConductionSolver(k1, k2, surface.shape, surface.dx, surface.dy, surface.periodic)
    for name, s in (("elastic", mech), ("thermal", heat)):
        if tuple(s.shape) != tuple(surface.shape) or s.periodic != surface.periodic:
            raise InputError(name, s, f"solver grid must match the surface ({surface.shape}, "
                             f"periodic={surface.periodic})")
    rows = {k: [] for k in ("area", "K_t", "K_i", "T_s")}
    t_mech = t_heat = 0.0
    pressure = flux = None
    for i, load in enumerate(p):
        t0 = time.perf_counter()
        warm = None if pressure is None else pressure * (load / p[i - 1])
        mres = mech.solve(surface.heights, load=load, tol=tol, initial_pressure=warm)
        t1 = time.perf_counter()
        hres = heat.solve(mres.contact, resistance=resistance, theta_1=theta_1, theta_2=theta_2,
                          tol=thermal_tol, initial_flux=flux)
        t_mech += t1 - t0
        t_heat += time.perf_counter() - t1
        pressure, flux = mres.pressure, hres.flux
        rows["area"].append(mres.area_fraction)
        rows["K_t"].append(hres.conductance)
        rows["K_i"].append(hres.interface_conductance)
        rows["T_s"].append(hres.contact_temperature_1)
    return ConductanceLaw(p, np.array(rows["area"]), np.array(rows["K_t"]), np.array(rows["K_i"]),
                          heat.perfect_conductance, np.array(rows["T_s"]), t_mech, t_heat)

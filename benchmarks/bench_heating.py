"""Transient frictional heating speed and accuracy versus time step (issue 6, thesis §6.4).

Thesis case: 1 mm x 1 mm fractal patch on a 150 x 150 grid, delta = 10 um, mu = 0.4, disc at
R = 100 mm, 4.5 ms transient. Reports (medians over repeats, one thread): kernel tabulation time,
run time, CG iterations per step and time per step for omega = 1 and 100 rad/s with dt = 50 us;
then p_1 and T_max at 4.5 ms versus dt (accuracy for the cost); and, as an independent check of
the FFT + least-squares CG step, a dense direct solve (LAPACK) of the first step's restricted
system A^0 psi = b on the contacting cells; last, isolated windows of 127² and 257² on FFT grids
padded to 5-smooth lengths against exactly 2N.
Run: python benchmarks/bench_heating.py [--quick] [--repeats 3]
"""
import argparse
import os
import time
from functools import partial
from unittest import mock

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402

from multiscale.micro import heating  # noqa: E402
from multiscale.micro.contact import ContactSolver  # noqa: E402
from multiscale.micro.heat_kernels import Rotation, SpeedProfile, ThermalMaterial, pulse_tables  # noqa: E402
from multiscale.micro.heating import TransientHeating  # noqa: E402
from multiscale.micro.kernels import HalfSpace  # noqa: E402
from multiscale.micro.surface import fractal_surface  # noqa: E402

from timing import alternated, timed  # noqa: E402

DISC, PIN = ThermalMaterial(50.0, 1e-5), ThermalMaterial(5.0, 3.5e-6)
ELASTIC = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)
T_END, MU = 4.5e-3, 0.4


def rotation(omega):
    return Rotation((70.7e-3, 70.7e-3), SpeedProfile.constant(omega))


def patch(n):
    s = fractal_surface(150, 1e-3, 0.8, 2, 10, 6.49e-6, seed=3)
    step = 150 // n
    h, dx = s.heights[::step, ::step], s.dx * step
    c = ContactSolver(ELASTIC, h.shape, dx, periodic=False).solve(h, approach=10e-6)
    return h.shape, dx, c


def dense_first_step(shape, dx, pressure, omega, dt):
    """ψ of step 0 from the dense restricted matrix of Eq. 6.16 (no FFT), and its solve time."""
    ny, nx = shape
    k = (pulse_tables(shape, dx, dx, DISC, dt, 1, rotation(omega)).coeffs[0]
         + pulse_tables(shape, dx, dx, PIN, dt, 1).coeffs[0])
    iy, ix = np.nonzero(pressure > 0)
    A = k[(iy[:, None] - iy[None, :]) % (2 * ny), (ix[:, None] - ix[None, :]) % (2 * nx)]
    phi = MU * pressure * rotation(omega).radius * omega
    b = (pulse_tables(shape, dx, dx, PIN, dt, 1).coeffs[0])
    b_full = np.fft.irfft2(np.fft.rfft2(b) * np.fft.rfft2(phi, s=(2 * ny, 2 * nx)), s=(2 * ny, 2 * nx))[:ny, :nx]
    t0 = time.perf_counter()
    psi = np.linalg.solve(A, b_full[iy, ix])
    return psi, (iy, ix), time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="50 x 50 grid, one repeat")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    n = 50 if args.quick else 150
    repeats = 1 if args.quick else args.repeats
    shape, dx, contact = patch(n)
    print(f"grid {n} x {n}, A/A0 = {contact.area_fraction * 100:.2f} % ({int(contact.contact.sum())} cells), "
          f"mean pressure {contact.mean_pressure / 1e6:.2f} MPa; median of {repeats}")
    dt = 50e-6
    steps = int(round(T_END / dt))
    print(f"\n4.5 ms transient, dt = {dt * 1e6:g} us ({steps} steps), target < 60 s")
    print(f"{'omega':>6} {'tables [s]':>10} {'run [s]':>8} {'total [s]':>9} {'CG its':>7} {'its/step':>8} "
          f"{'ms/step':>8} {'p1(4.5ms)':>9} {'Tmax [K]':>9}")
    for omega in (1.0, 100.0):
        t_tab, sol = timed(lambda: TransientHeating(shape, dx, DISC, PIN, rotation(omega), dt, steps), repeats)
        t_run, r = timed(lambda: sol.run(contact.pressure, MU), repeats)
        its = int(r.iterations.sum())
        t_max = max(r.max_temperature_1[-1], r.max_temperature_2[-1])
        print(f"{omega:6g} {t_tab:10.2f} {t_run:8.2f} {t_tab + t_run:9.2f} {its:7d} {its / steps:8.1f} "
              f"{t_run / steps * 1e3:8.1f} {r.partition_1[-1]:9.5f} {t_max:9.2f}")
    print("\naccuracy versus time step (omega = 100 rad/s, one run each)")
    print(f"{'dt [us]':>8} {'steps':>6} {'time [s]':>8} {'p1(4.5ms)':>10} {'Tmax [K]':>9}")
    for dt in (150e-6, 100e-6, 50e-6, 25e-6):
        steps = int(round(T_END / dt))
        t0 = time.perf_counter()
        r = TransientHeating(shape, dx, DISC, PIN, rotation(100.0), dt, steps).run(contact.pressure, MU)
        print(f"{dt * 1e6:8g} {steps:6d} {time.perf_counter() - t0:8.2f} {r.partition_1[-1]:10.6f} "
              f"{r.max_temperature_1[-1]:9.3f}")
    dt = 50e-6
    psi, (iy, ix), t_dense = dense_first_step(shape, dx, contact.pressure, 100.0, dt)
    sol = TransientHeating(shape, dx, DISC, PIN, rotation(100.0), dt, 1)
    t0 = time.perf_counter()
    r = sol.run(contact.pressure, MU, field_times=[dt], tol=1e-10)
    t_fft = time.perf_counter() - t0
    err = np.linalg.norm(r.flux_1[0][iy, ix] - psi) / np.linalg.norm(psi)
    print(f"\nfirst step, omega = 100: FFT + CG {t_fft * 1e3:.1f} ms ({int(r.iterations[0])} its) vs dense "
          f"LAPACK solve {t_dense * 1e3:.1f} ms on {psi.size} contact cells; relative difference {err:.2e}")
    padding([127] if args.quick else [127, 257], repeats)


def padding(sizes, repeats):
    """Isolated windows whose 2N has large prime factors: the FFT grid padded to 5-smooth lengths
    (``kernels.padded_size``, the default) against exactly 2N, side by side (two solvers, the
    second built with the padding switched off, runs alternated): 10 steps of 100 us, omega = 50."""
    print("\ntransient heating of isolated windows, FFT grid 2N against padded to 5-smooth: medians; ratio = "
          "median of padded / 2N")
    print(f"{'N':>5} {'2N [s]':>8} {'padded [s]':>10} {'ratio':>6} {'max diff p1':>11}")
    for n in sizes:
        s = fractal_surface(n, 1e-3, 0.8, 2, n // 4, 6.49e-6, seed=3)
        c = ContactSolver(ELASTIC, s.shape, s.dx, periodic=False).solve(s.heights, approach=10e-6)
        solvers = {}
        for name, pad in (("2N", int), ("padded", heating.padded_size)):
            with mock.patch.object(heating, "padded_size", pad):   # read when a solver builds its tables and plans
                solvers[name] = TransientHeating(s.shape, s.dx, DISC, PIN, rotation(50.0), 1e-4, 10)
                solvers[name].run(c.pressure, MU)
        t, out, ratio = alternated({k: partial(sol.run, c.pressure, MU) for k, sol in solvers.items()}, repeats)
        diff = np.max(np.abs(out["padded"].partition_1 - out["2N"].partition_1))
        print(f"{n:5d} {t['2N']:8.3f} {t['padded']:10.3f} {ratio:6.3f} {diff:11.1e}", flush=True)


if __name__ == "__main__":
    main()

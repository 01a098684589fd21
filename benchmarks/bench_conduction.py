"""K_t(p) sweep of one thesis ch. 5 case: wall time against the 30 s target (issue 5), peers side by side.

Case: thesis §5.5 surface (1 mm patch, H = 0.8, cut-offs 2 and 10, RMS 6 um), solid 1 (E 4 GPa,
nu 0.15, kappa 10) against solid 2 (E 220 GPa, nu 0.33, kappa 50); 10 mean pressures 0.5–5 MPa.
Thermal kernels: two half-spaces (K_t is then the constriction conductance); then, on the thesis
grid, the layered Table 5.3 case 3 (1 mm cubes, solid 1: 500 um of kappa 2.5 over kappa 10, solid
2: kappa 50; isothermal bases), ours only (no peer has layered kernels).
Ours: ``conductance_law`` (FFT-BEM contact + CG on Eq. 5.8, both warm-started along the sweep).
Peers: tamaas' PolonskyKeerRey for the contact solves (same loads, same tolerance 1e-8) and
scipy.sparse.linalg.cg on the same FFT operator for the thermal solves (same tolerance).
Medians of repeats, one thread. Run: python benchmarks/bench_conduction.py [--quick]
"""
import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
import numpy as np  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

from multiscale.micro.conduction import ConductionSolver, SeriesKernel, conductance_law  # noqa: E402
from multiscale.micro.kernels import HalfSpace, ThermalHalfSpace  # noqa: E402
from multiscale.micro.layered import LayeredElastic, LayeredThermal  # noqa: E402
from multiscale.micro.surface import fractal_surface  # noqa: E402

from timing import timed  # noqa: E402

PRESSURES = np.linspace(0.5e6, 5e6, 10)
ELASTIC = HalfSpace.from_materials(4e9, 0.15, 220e9, 0.33)
THERMAL = (ThermalHalfSpace(10.0), ThermalHalfSpace(50.0))
TOL, THERMAL_TOL = 1e-8, 1e-10
LAYERED_ELASTIC = SeriesKernel(LayeredElastic((5e-4, 5e-4), (4e9, 4e9), (0.15, 0.15)),
                               LayeredElastic((1e-3,), (220e9,), (0.33,)))
LAYERED_THERMAL = (LayeredThermal((5e-4, 5e-4), (2.5, 10.0)), LayeredThermal((1e-3,), (50.0,)))


def tamaas_sweep(surface):
    import tamaas as tm
    ny, nx = surface.shape
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, list(surface.size[::-1]), [ny, nx])
    model.E, model.nu = ELASTIC.E_star, 0.0
    solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(surface.heights), TOL)
    masks = []
    for p in PRESSURES:
        solver.solve(float(p))
        masks.append(np.array(model.traction).reshape(ny, nx) > 0)
    return masks


def scipy_sweep(solver, masks):
    """Same restricted operator and right-hand side, scipy's CG (no warm start)."""
    K = []
    for mask in masks:
        idx = np.flatnonzero(mask)
        work = np.zeros(mask.shape)

        def matvec(x):
            work.ravel()[idx] = x
            out = solver.series(work).ravel()[idx]
            work.ravel()[idx] = 0.0
            return out

        op = spla.LinearOperator((idx.size, idx.size), matvec=matvec)
        phi, info = spla.cg(op, np.ones(idx.size), rtol=THERMAL_TOL, atol=0.0, maxiter=10000)
        assert info == 0
        K.append(phi.sum() / mask.size)
    return np.array(K)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one repeat, thesis grid only")
    args = ap.parse_args()
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    reps = 1 if args.quick else 3
    grids = (150,) if args.quick else (150, 300, 512)
    print(f"K_t(p) sweep, {PRESSURES.size} pressures {PRESSURES[0] / 1e6:.1f}–{PRESSURES[-1] / 1e6:.1f} MPa, "
          f"medians of {reps}")
    print(f"{'grid':>8} {'sweep [s]':>10} {'mech [s]':>9} {'therm [s]':>10} {'tamaas mech [s]':>16} "
          f"{'scipy cg [s]':>13} {'A/A0 @3MPa':>11} {'K_t @3MPa':>10} {'max dK/K':>9}")
    for n in grids:
        surface = fractal_surface(n, 1e-3, 0.8, 2, 10, 6e-6, seed=1)
        conductance_law(surface, ELASTIC, THERMAL, PRESSURES[:2])          # FFTW plans outside the timing
        t_us, law = timed(lambda: conductance_law(surface, ELASTIC, THERMAL, PRESSURES, tol=TOL,
                                                  thermal_tol=THERMAL_TOL), reps)
        t_tm, masks = timed(lambda: tamaas_sweep(surface), reps)
        heat = ConductionSolver(*THERMAL, surface.shape, surface.dx)
        t_sp, K_sp = timed(lambda: scipy_sweep(heat, masks), reps)
        ours_on_masks = np.array([heat.solve(m, tol=THERMAL_TOL).conductance for m in masks])
        i3 = int(np.argmin(abs(PRESSURES - 3e6)))
        print(f"{f'{n}x{n}':>8} {t_us:10.2f} {law.mechanics_time:9.2f} {law.conduction_time:10.2f} {t_tm:16.2f} "
              f"{t_sp:13.2f} {law.area_fraction[i3]:11.4f} {law.conductance[i3]:10.1f} "
              f"{np.max(abs(ours_on_masks / K_sp - 1)):9.1e}")
    surface = fractal_surface(150, 1e-3, 0.8, 2, 10, 6e-6, seed=1)
    conductance_law(surface, LAYERED_ELASTIC, LAYERED_THERMAL, PRESSURES[:2])
    t_us, law = timed(lambda: conductance_law(surface, LAYERED_ELASTIC, LAYERED_THERMAL, PRESSURES, tol=TOL,
                                              thermal_tol=THERMAL_TOL), reps)
    i3 = int(np.argmin(abs(PRESSURES - 3e6)))
    print(f"layered Table 5.3 case 3, 150x150: sweep {t_us:.2f} s (mech {law.mechanics_time:.2f}, thermal "
          f"{law.conduction_time:.2f}); at 3 MPa A/A0 {law.area_fraction[i3]:.4f}, K_t {law.conductance[i3]:.0f}, "
          f"K_p {law.perfect_conductance:.0f}, K_t/K_p {law.conductance[i3] / law.perfect_conductance:.2f} "
          f"(thesis 1240, 3700, 0.33)")


if __name__ == "__main__":
    main()

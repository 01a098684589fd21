"""The squeal analysis of a scene with effect ``stability`` (thesis ch. 4, §4.3–4.4).

Two steps (§4.3.1): the preload, a quasi-static steady sliding state (``macro.preload``), then the
complex modes of the system linearised there (``macro.eigen.solve_modes``), with the unstable and
potentially unstable modes and the strain-energy shares per material region (``macro.modal``).
Quadratic tetrahedra (``SQUEAL_DEGREE``): linear ones are far too stiff in bending.

With effect ``roughness`` the pads are rough (§4.2, §4.3.2, Table 4.1): the rough-interface builder
of the multiscale loop (``workflows.rough``, same scene rules) gives every interface its zone laws,
embedded exactly in the contact form, and the rigid datum gap where Newton starts; the Newton
matrix at the preload then holds the laws' consistent tangent.

Beyond the thesis (issue 20, ``squeal_options``): damping (``stability.damping``,
``rayleigh_alpha``/``rayleigh_beta`` over the whole system; per-material loss factors and Rayleigh
coefficients), a friction coefficient falling with the slip speed (``loading.friction_curve`` or
``loading.stribeck``: mu(V) per facet at the preload, its slope as damping), the gyroscopic and
centrifugal terms of the rotating body (``stability.gyroscopic``) and the prestress stiffness
(``stability.prestress``, with the shift of every frequency it causes). A damped system that the
undamped modes do not map exactly is solved as a quadratic eigenproblem (viscous damping) or by
projection on the undamped modes (loss factors; ``macro.damped``). ``[stability.sweep]`` adds a
stability map (``workflows.squeal_map``).

``run`` writes into ``output.folder``: ``modes.csv``, mode shapes (``modes_<body>.bp``, VTX), the
preloaded state's fields (``<body>.xdmf``, ``interface.xdmf``), ``pressure.png`` (Fig. 4.12),
``re_im.png`` (Fig. 4.13) and ``energy.png`` (Figs. 4.20–4.21), the figures unless
``output.figures = false``; ``multiscale.outputs.plan``.
With prestress also ``prestress.csv``; with a sweep the map's files (``workflows.squeal_map.write``).
"""
from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np
import ufl
from dolfinx import fem, la
from mpi4py import MPI

from multiscale import io, outputs
from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.macro.damped import SPURIOUS, PrestressEffect, prestress_effect, solve_system
from multiscale.macro.eigen import Damping, ModalResult
from multiscale.macro.friction import ConstantFriction, set_friction
from multiscale.macro.kept_cells import closed_on_error
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.modal import CLOSE, EnergyShares, RegionEnergy, StabilityReport, stability_report, \
    strain_energy_shares
from multiscale.macro.nodal_diameters import DiscShapes, nodal_diameters
from multiscale.macro.output import write_modes, write_state
from multiscale.macro.preload import Preload, linearise_system, preload
from multiscale.macro.stability_map import StabilityMap
from multiscale.scene_friction import bare_interfaces, curve_left
from multiscale.scene_stability import structurally_damped
from multiscale.workflows import squeal_map
from multiscale.workflows.model import build_mechanics, build_mesh, drive, friction_coefficient, global_dofs, \
    interface_forces, say_load, say_model_size, speed_law
from multiscale.workflows.output import RunResult, prepare_folder
from multiscale.workflows.rough import build_rough_interface
from multiscale.workflows.strain import idle_holder, overloaded, unloaded

SQUEAL_DEGREE = 2     # quadratic tetrahedra: linear ones are far too stiff in bending (tests)
MAP_RESIDUAL = 1e-3   # a stability map's modes with larger relative residuals are warned to be approximate
WEAK = 1e-4           # unstable modes at damping ratios above -WEAK are warned marginal in an undamped structure
SOLVERS = {"gnhep": "the generalized eigenproblem K phi = theta M phi (exact)",   # ModalResult.method, said
           "pep": "the full quadratic eigenproblem (SLEPc PEP, exact)",
           "projection": "projection on the undamped modes and static responses (approximate: the residual column)"}
MODE_RESIDUAL = 3e-2  # the analysis' modes with larger relative residuals are warned to be approximate
DISC_SHARE = 0.25     # a mode is named by the disc's nodal diameters where the disc holds this share of its energy


@dataclass(frozen=True)
class SquealOptions:
    """What the linearised system holds beyond the tangent K and the mass M (issue 20)."""

    damping: Damping | None = None         # proportional: alpha M + beta K, eta K of the whole system
    material_damping: bool = True          # the materials' loss factors and Rayleigh coefficients
    friction_laws: dict | None = None      # interface -> mu(v) law (None: the friction field as set)
    friction_damping: bool = True          # the slope of the laws as damping
    prestress: bool = False
    gyroscopic: bool = False
    method: str = "auto"                   # macro.damped.solve_system
    basis: float = 1.5


@dataclass
class SquealCase:
    """One case of a squeal study: preload, complex modes and their post-processing (§4.4)."""

    name: str
    preload: Preload
    modes: ModalResult
    report: StabilityReport
    energy: EnergyShares | None
    facet_pressure: np.ndarray      # Pa, per interface facet (global order of tm.interface)
    mech: Mechanics | None = field(default=None, repr=False)   # the model (spaces of the modes; closed by ``run``)
    prestress: PrestressEffect | None = None    # the frequencies without the prestress stiffness
    terms: tuple = ()                           # parts of the linearised system beyond K and M
    slip_speed: np.ndarray | None = None        # m/s, per facet: what the mu(v) laws read (with laws)
    disc: DiscShapes | None = None              # nodal diameters of the rotating body's motion (a rotation)


def squeal_case(mech: Mechanics, materials: Mapping[str, object], name: str = "case", *, load: float = 1e6,
                steps: int = 1, band=(0.0, 16e3), n_modes: int | None = None,
                target: float | None = None, energy: bool = True, rtol: float = 1e-6, close_tol: float = CLOSE,
                options: SquealOptions | None = None, torque: float | None = None, on_preload=None) -> SquealCase:
    """Preload ``mech`` from rest to ``load`` [Pa or N] in ``steps`` (with ``torque`` [N m] a first
    guess, scaled to that friction moment: ``preload``), linearise and extract the complex modes in
    ``band`` [Hz] (§4.3.1, two steps); ``options`` (``SquealOptions``) the damping and the rest. ``on_preload(mech)`` is called
    between the preload and the eigen solve (``run`` writes the preloaded state then)."""
    opt = options or SquealOptions()
    _, slope, slip = set_friction(mech, opt.friction_laws) if opt.friction_laws else (None, None, None)
    with io.stage("preload"):
        pre = preload(mech, load, steps, torque=torque)
    if on_preload is not None:
        on_preload(mech)
    floating = idle_holder(mech.tm.sole_holds, {n: abs(f) for n, f in pre.normal_force.items()})
    if floating is not None:       # before the eigen solve finds their rigid motions, or not
        raise floating
    with io.stage("eigen solve"):
        lin = linearise_system(mech, materials, damping=opt.damping,
                               slope=slope if opt.friction_damping else None, prestress=opt.prestress,
                               gyroscopic=opt.gyroscopic, material=opt.material_damping)
        if opt.method == "subspace":       # the memory-lean path: no Newton factors next to the modes'
            mech.release()
            lin.system.K0 = mech.frictionless_tangent()
        modes = solve_system(lin.system, f_min=band[0], f_max=band[1], n_modes=n_modes, target=target,
                             method=opt.method, basis=opt.basis)
        effect = prestress_effect(modes, lin.system, lin.K_sigma) if lin.K_sigma is not None else None
        for A in (lin.system.M, lin.system.C, lin.system.H, lin.K_sigma):
            if A is not None:
                A.destroy()
    with io.stage("strain energy per component"):
        shares = strain_energy_shares(modes, RegionEnergy(mech)) if energy else None
    return SquealCase(name, pre, modes, stability_report(modes, rtol, close_tol), shares,
                      mech.contact.facet_pressure(), mech, effect, lin.terms, slip, disc_shapes(mech, modes))


def mode_name(case: SquealCase, j: int) -> str:
    """Mode ``j`` (1-based) by its frequency and, on a rotating body that holds at least ``DISC_SHARE``
    of the mode's strain energy and whose motion one angular harmonic holds at least half of, its
    nodal diameters, e.g. "4321 Hz: 5 ND out-of-plane" (the disc's motion mostly along its axis) or
    "in-plane"."""
    name = f"{case.modes.frequency[j - 1]:.0f} Hz"
    if case.disc is None:
        return name
    if case.disc.share[j - 1] < 0.5:     # no one harmonic (or the disc does not move): no name (a review)
        return name
    if case.energy is not None:          # a pad's mode, the disc holding 8.8 % of its strain energy, was
        disc = [r.name for r in case.mech.tm.bodies[1].spec.regions]             # named by it (an NVH trial)
        if sum(case.energy.share[j - 1, case.energy.names.index(r)] for r in disc) < DISC_SHARE:
            return name
    plane = "out-of-plane" if case.disc.out_of_plane[j - 1] >= 0.5 else "in-plane"
    return f"{name}: {case.disc.nodal_diameters[j - 1]} ND {plane}"


def disc_shapes(mech: Mechanics, modes: ModalResult) -> DiscShapes | None:
    """``macro.nodal_diameters`` of the modes on the moving body (body 1) about its rotation axis;
    None if it translates."""
    motion = mech.tm.spec.motion
    if not isinstance(motion, Rotation):
        return None
    before, own = (f.x.index_map.size_local * 3 for f in mech.u)
    V = mech.spaces[1]
    return nodal_diameters(V.tabulate_dof_coordinates()[:own // 3], modes.modes[before:before + own].reshape(
        own // 3, 3, -1), motion.axis, motion.centre, mech.tm.comm, node_volumes(V))


def node_volumes(V) -> np.ndarray:
    """Each owned node's share of its body's volume [m^3]: every cell's volume split equally among
    its nodes (positive, where a quadratic element's lumped mass is negative at its vertices)."""
    msh, imap = V.mesh, V.dofmap.index_map
    cells = msh.topology.index_map(msh.topology.dim).size_local
    Q = fem.functionspace(msh, ("DG", 0))
    volume = fem.assemble_vector(fem.form(ufl.TestFunction(Q) * ufl.dx)).array[Q.dofmap.list[:cells, 0]]
    nodes = V.dofmap.list[:cells]
    share = la.vector(imap, 1)
    np.add.at(share.array, nodes.ravel(), np.repeat(volume / nodes.shape[1], nodes.shape[1]))
    share.scatter_reverse(la.InsertMode.add)
    return share.array[:imap.size_local].copy()


def friction_laws(scene, tm) -> dict | None:
    """mu(v) law of every interface when [loading] gives a ``friction_curve`` or ``stribeck``
    (an interface's own ``friction`` stays constant, its own fade table its mu at the initial
    temperature); None with a constant friction."""
    law = speed_law(scene.loading)
    if not scene.has("friction") or law is None:
        return None
    bare = bare_interfaces(scene.interfaces, tm.interface.tags)
    return {n: law if n in bare else ConstantFriction(friction_coefficient(scene, n)) for n in tm.interface.tags}


def squeal_options(scene, tm) -> SquealOptions:
    """The ``SquealOptions`` of a scene's [stability], [materials] and [loading]."""
    st = scene.stability
    proportional = (st.rayleigh_alpha, st.rayleigh_beta, st.damping)
    return SquealOptions(Damping(*proportional) if any(proportional) else None, True, friction_laws(scene, tm),
                         st.friction_damping, st.prestress, st.gyroscopic, st.method, st.basis)


def build_squeal_mechanics(scene, tm, *, degree: int = SQUEAL_DEGREE, prefix: str = "squeal_") -> Mechanics:
    """The mechanics of a scene's squeal analysis on ``tm`` (rough laws with effect roughness;
    the datum gap as Newton's start)."""
    rough = build_rough_interface(scene, tm) if scene.has("roughness") else None
    if rough is not None:
        with io.stage("zone laws"):
            rough.update_laws()
    with io.stage("model set-up"):       # function spaces, forms compiled (cached after the first run)
        mech = build_mechanics(scene, tm, law=rough.law if rough else None, degree=degree, prefix=prefix)
    if rough is not None:            # Newton starts at rest from the rigid datum gap
        tm.interface.set_field(mech.contact.initial_gap, rough.datum_gap(interface_forces(scene, tm)))
    return mech


def analyse(scene, tm, *, name: str | None = None, energy: bool = True, degree: int = SQUEAL_DEGREE,
            on_preload=None) -> SquealCase:
    """The squeal case of a scene on the mesh ``tm``: perfect penalty contact, or the rough zone
    laws of [roughness]/[micro] with effect ``roughness`` (see module docstring); ``on_preload`` as
    in ``squeal_case``."""
    st = scene.stability
    name = name or scene.name
    prefix = "squeal_" + "".join(ch if ch.isalnum() else "_" for ch in name) + "_"
    mech = build_squeal_mechanics(scene, tm, degree=degree, prefix=prefix)
    dofs = global_dofs(mech.u)
    if st.modes is not None and st.modes > dofs:     # (said after the preload, with a memory warning: a trial)
        mech.close()
        raise InputError("stability.modes", st.modes, f"must not exceed the number of dofs ({dofs})")
    say_model_size(tm, mech, kind="squeal", modes=st.modes, sweep=st.sweep.preload_mode if st.sweep else None)
    say_load(scene, tm)
    try:
        with closed_on_error(mech, tm.comm):
            d = drive(scene, tm)
            return squeal_case(mech, dict(scene.materials), name, load=d.load, torque=d.torque,
                               steps=scene.loading.ramp_steps, band=tuple(st.band), n_modes=st.modes,
                               target=st.target, energy=energy, rtol=st.threshold, options=squeal_options(scene, tm),
                               on_preload=on_preload, close_tol=CLOSE if frictional(scene) else 0.0)
    except InputError as exc:        # the eigen solvers' arguments by their scene keys
        band = [f"{f:g} Hz" for f in st.band]          # (shown as "(100.0, 500.0)": an NVH user trial)
        keys = {"f_min": ("stability.band", band), "f_max": ("stability.band", band),
                "n_modes": ("stability.modes", st.modes)}
        if exc.name not in keys:
            raise
        raise InputError(*keys[exc.name], exc.allowed) from None


def frictional(scene) -> bool:
    """Whether friction couples the modes: some interface with mu > 0 (or mu(v)). Without, two close
    modes are not "potentially unstable" (an axisymmetric disc's doublets at mu = 0 were all
    flagged: 16 of 20 modes, a user trial)."""
    ld = scene.loading
    return scene.has("friction") and (ld.friction_curve is not None or ld.stribeck is not None or any(
        friction_coefficient(scene, n) > 0 for n in scene.geometry.spec.interfaces))


def write_prestress_csv(effect: PrestressEffect, path) -> Path:
    """Frequency of every mode with and without the prestress stiffness, and the shift."""
    path = Path(path)
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["mode", "frequency_Hz", "frequency_without_prestress_Hz", "shift_Hz", "sigma_1_per_s",
                    "sigma_without_prestress_1_per_s", "mac", "residual_without"])
        for j in range(effect.frequency.size):
            w.writerow([j + 1, f"{effect.frequency[j]:.6f}", f"{effect.frequency_without[j]:.6f}",
                        f"{effect.shift[j]:.6f}", f"{effect.growth[j]:.6e}", f"{effect.growth_without[j]:.6e}",
                        f"{effect.mac[j]:.4f}", f"{effect.residual[j]:.2e}"])
    return path


def energy_split(tm) -> tuple[str, str] | None:
    """The two body-0 regions along two interfaces (e.g. inner and outer pad), for Fig. 4.21."""
    regions = {r.tag: r.name for r in tm.spec.bodies[0].regions}
    along = [tags[0] for tags in tm.interface.plus_regions.values() if len(tags) == 1]
    return tuple(regions[t] for t in along) if len(along) == 2 and along[0] != along[1] else None


@dataclass
class SquealResult(RunResult):
    """``RunResult`` of the squeal analysis, with its case."""

    case: SquealCase
    map: StabilityMap | None = None  #: with [stability.sweep]


def approximate_modes(scene, case: SquealCase) -> list[str]:
    """A warning naming the modes whose relative residual of the full problem exceeds
    ``MODE_RESIDUAL`` (a projected solve's modes: approximate; an exact solver's: not converged)."""
    st, modes = scene.stability, case.modes
    bad = np.flatnonzero(modes.errors > MODE_RESIDUAL)
    if not bad.size:
        return []
    named = ", ".join(f"{j + 1} ({modes.frequency[j]:.0f} Hz, {modes.errors[j]:.1e})" for j in bad[:6])
    more = f" and {bad.size - 6} more" if bad.size > 6 else ""
    which = f"modes {named}{more} have relative residuals above {MODE_RESIDUAL:g}: their frequencies and growth " \
        "rates are" if bad.size > 1 else f"mode {named} has a relative residual above {MODE_RESIDUAL:g}: its " \
        "frequency and growth rate are"
    if modes.method != "projection":             # an exact solver's: no basis to widen (a user trial was told to)
        return [f"{which} not converged, though solved by {SOLVERS[modes.method]}: a nearly singular system, e.g. "
                "a part that only an unpressed contact holds"]
    lossy = "material loss factors" in case.terms
    if st.method == "subspace" and lossy:        # its basis has no static responses to H (docs/squeal.md)
        hint = '; stability.method = "projection" adds the static responses to the loss factors\' forces'
    else:
        exact = not (st.damping or lossy or st.band[0] > 0 or st.target)   # the PEP reaches a band from 0 Hz only
        hint = '; stability.method = "quadratic" solves viscous damping exactly' if exact else ""
    return [f"{which} approximate (projected on the modes up to stability.basis x f_max; a larger "
            f"stability.basis, now {st.basis:g}, widens the basis{hint})"]


def _left_out(scene, case: SquealCase, smap: StabilityMap | None) -> list[str]:
    """Warnings: a band cut short by stability.modes, modes or a map whose modes are approximate, a
    contact pressure beyond small strains (at the preload, or at a map point's own preload), an
    interface that the preload left without force, a friction_curve its slip speeds left, unstable
    modes that any damping would stabilise (``WEAK``) in an undamped structure; the mesh's
    (``TwoBodyMesh.notes``)."""
    st, out = scene.stability, [*case.mech.tm.notes, *approximate_modes(scene, case)]
    f = case.modes.frequency
    top = float(f.max(initial=0.0))
    lo, hi = st.band
    floor, ceiling = lo, top               # PEP: found by frequency from the band's low edge
    t = lo if st.target is None else st.target
    if case.modes.method == "gnhep" and len(f):    # the modes nearest theta_t = (2 pi target)^2: searched
        r = float(np.abs(f ** 2 - t ** 2).max())   # within the farthest found |theta - theta_t|
        floor, ceiling = np.sqrt(max(t ** 2 - r, 0.0)), np.sqrt(t ** 2 + r)
    elif case.modes.method == "projection" and len(f):   # the modes nearest the target in frequency
        r = float(np.abs(f - t).max())
        floor, ceiling = max(t - r, 0.0), t + r
    still = case.report.divergent
    if still.size:                          # (listed as flutter: a user trial at mu = 2)
        out.append(f"{io.counted(still.size, 'unstable mode')} at 0 Hz ("
                   + ", ".join(f"mode {j}: sigma = {case.modes.growth[j - 1]:+.4g} 1/s" for j in still[:4])
                   + "): a static divergence, not flutter: the sliding state the modes are linearised about is "
                   "itself unstable (friction too high for the structure?), so its modes say little")
    spurious = [x for x in case.modes.spurious if floor <= x <= ceiling]   # (outside, they displaced no mode)
    if spurious:
        out.append(f"{len(spurious)} value(s) of the projected problem among the modes found "
                   f"({', '.join(f'{x:.0f}' for x in spurious[:6])} Hz) had relative residuals above {SPURIOUS:g} in "
                   f"the full model: not modes of it, left out (a larger stability.basis, now {st.basis:g}, widens "
                   "the basis)")
    below, above = floor > 1.01 * lo + 1.0, ceiling < 0.99 * hi
    if st.modes is not None and len(case.modes) >= st.modes and below:
        out.append(f"stability.modes = {st.modes}: the modes found span {f.min():.0f} to {top:.0f} Hz around "
                   f"stability.target = {st.target:.0f} Hz; the band below {floor:.0f} Hz, from {lo:.0f} Hz"
                   + (f", and above {ceiling:.0f} Hz, up to {hi:.0f} Hz," if above else ",")
                   + " was not searched (raise stability.modes or move stability.target)")
    elif st.modes is not None and len(case.modes) >= st.modes and above:
        out.append(f"stability.modes = {st.modes}: the modes found reach {top:.0f} Hz; the band above, up to "
                   f"{hi:.0f} Hz, was not searched (raise stability.modes)")
    if smap is not None and smap.onsets and st.sweep.preload_mode == "once":
        out.append(f"the stability map's onsets are for the preloaded state of the nominal analysis "
                   f"(stability.sweep.preload = \"once\"): its points change the {smap.parameter}'s coupling, not "
                   "the contact state and deformation that preload holds, so they are not the onsets of full "
                   "analyses at those values, and an instability of a full analysis can be missing altogether "
                   "(demo brake: friction onset 0.109 against 0.062); stability.sweep.preload = \"each\" preloads "
                   "every point")
    elif smap is not None and smap.onsets and not st.sweep.refine_steps:
        out.append("the stability map's onsets are bisected between its points on systems blended from the two "
                   "neighbouring points' (stability.sweep.refine = 0), not narrowed by full analyses: the bracket "
                   "in onsets.csv is the blend's, and such onsets were up to 9 % low against direct runs in trials "
                   "(demo brake 4.3 kHz pair: 0.543 against 0.585-0.593); stability.sweep.refine = 3 (the default) "
                   "brackets each between full analyses")
    worst = float(np.nanmax(smap.residual)) if smap is not None and np.isfinite(smap.residual).any() else 0.0
    if worst > MAP_RESIDUAL:
        out.append(f"the stability map's modes have relative residuals up to {worst:.1e}: its frequencies and growth "
                   "rates are approximate, and a mode outside its basis is missed (stability.sweep.preload = \"each\" "
                   "solves every point in full)")
    if case.slip_speed is not None and (curve := scene.loading.friction_curve) is not None:   # (a curve the
        iface = case.mech.tm.interface                                   # preload missed was unsaid: a user trial)
        masks = iface.masks()
        read = np.logical_or.reduce([masks[n] for n in bare_interfaces(scene.interfaces, masks)] or [np.zeros(
            iface.n_facets, bool)]) & (case.facet_pressure > 0)
        V = case.slip_speed[read]
        out += curve_left(curve, (float(V.max()), ""), (float(V.min()), ""), " at the preload") if V.size else []
    # (gyroscopic terms at 48 rpm flagged 10 of 24 modes, most at damping ratios of -1e-5: an NVH trial)
    weak = case.report.unstable[case.modes.damping_ratio[case.report.unstable - 1] > -WEAK]
    if weak.size and not structurally_damped(scene, scene.geometry.materials):
        n = case.report.unstable.size
        which = ("the unstable mode grows" if n == 1 else f"all {n} unstable modes grow" if weak.size == n else
                 f"{weak.size} of the {n} unstable modes grow{'s' * (weak.size == 1)}")      # (grammar: a review)
        them = "it" if weak.size == 1 else "them"
        out.append(f"{which} at damping ratios above -{WEAK:g} ({', '.join(f'{f[j - 1]:.0f} Hz' for j in weak[:6])}), "
                   f"which a loss factor of {2 * WEAK:g} would damp, and nothing damps this structure: give the damping "
                   f"the brake has (stability.damping, rayleigh_alpha/beta, the materials' loss_factor) to weigh {them}, "
                   f"or stability.threshold = {WEAK:g} to leave {them} out")
    peak = max(float(case.facet_pressure.max(initial=0.0)), smap.max_pressure if smap is not None else 0.0)
    return out + overloaded(scene, peak) + unloaded({n: abs(f) for n, f in case.preload.normal_force.items()})


def run(scene, *, overwrite: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True,
        degree: int = SQUEAL_DEGREE) -> SquealResult:
    """``multiscale run`` of a scene with effect "stability" (see module docstring)."""
    t0 = time.perf_counter()
    if not scene.has("stability"):
        raise InputError("effects", sorted(scene.effects), 'the squeal analysis needs effect "stability"')
    io.abort_on_exception(comm)
    out = prepare_folder(scene, overwrite, False, comm)
    folder = out.path
    with io.stage("meshing"):
        tm = build_mesh(scene, comm)
    plan, masks, files = outputs.plan(scene), tm.interface.masks(), []

    def preloaded(mech):         # the first results: written before the eigen solve, which may fail or be stopped
        out.claim()              # --overwrite: the earlier results go now, not before a failed preload
        with io.stage("writing the preload"):
            files.extend(write_state(folder, mech, plan.body_fields + plan.interface_fields))
            pressure = mech.contact.facet_pressure()

            def figure():
                from multiscale.plots.squeal import plot_pressure  # local: matplotlib only when a figure is drawn
                mid = tm.interface.midpoints
                return [plot_pressure(mid, masks, pressure, scene.name, folder / "pressure.png",
                                      (tm.bodies[1].name, tm.spec.motion.velocity(mid)))]
            files.extend(io.on_root(comm, figure if scene.output.figures else list, f"the figures in {folder}") or [])
    replacing = bool(out.replace)     # --overwrite of earlier results: they stay until the modes are found (an
    case = analyse(scene, tm, degree=degree, on_preload=None if replacing else preloaded)   # empty band deleted
    with closed_on_error(case.mech, comm):       # them after the preload: a user trial)
        if replacing:
            preloaded(case.mech)
        with io.stage("writing results"):
            rep = case.report
            files += io.on_root(comm, lambda: [case.modes.write_csv(folder / "modes.csv", rep.rtol,
                                                                   rep.potentially_unstable, case.energy,
                                                                   rep.flutter_partner, case.disc,
                                                                   tm.bodies[1].name)],
                                f"{folder / 'modes.csv'}") or []
            files += write_modes(folder, case.modes, case.mech.u, [b.name for b in tm.bodies])
            split = energy_split(tm)

            def figures():
                out = []
                if scene.output.figures:
                    from multiscale.plots.squeal import plot_energy, plot_re_im  # local: matplotlib only when a figure is drawn
                    out += [plot_re_im([case], folder / "re_im.png"), plot_energy(case, folder / "energy.png", split)]
                if case.prestress is not None:
                    out.append(write_prestress_csv(case.prestress, folder / "prestress.csv"))
                return out
            files += io.on_root(comm, figures, f"the figures in {folder}") or []
        smap = None
        if scene.stability.sweep is not None:
            with io.stage("stability map"):
                smap = squeal_map.stability_map(scene, tm, case.mech, squeal_options(scene, tm),
                                                case.preload.pressure,         # (scaled to a braking torque)
                                                lambda changed: build_squeal_mechanics(changed, tm, degree=degree,
                                                                                       prefix="squeal_map_"))
                files += squeal_map.write(smap, folder, comm, scene.output.figures, scene.stability.sweep.onsets)
        case.mech.close()                # on every rank in the same order (MUMPS' destruction communicates)
    result = SquealResult(folder, files, time.perf_counter() - t0, case, smap,
                          warnings=tuple(_left_out(scene, case, smap)))   # what the results leave out or approximate
    if verbose and comm.rank == 0:
        rep = case.report
        print(f"{scene.name}: {io.counted(len(case.modes), 'mode')} up to {case.modes.frequency.max():.0f} Hz, "
              f"{rep.unstable.size} unstable"
              + (f" ({', '.join(mode_name(case, j) for j in rep.unstable)})" if rep.unstable.size else "")
              + f", {rep.potentially_unstable.size} potentially unstable; {result.wall_time:.1f} s on "
              f"{io.counted(comm.size, 'rank')}")
        moment = case.preload.friction_moment       # (in no file, and not said: a user trial)
        print("  preload: " + ", ".join(f"{abs(f):.6g} N on {n}" for n, f in case.preload.normal_force.items())
              + " (normal contact force)" + (f"; braking torque {moment:.6g} N m" if moment else ""))
        touching = case.slip_speed[case.facet_pressure > 0] if case.slip_speed is not None else np.zeros(0)
        if touching.size:            # a mu(v) law: the mu it gave (only in interface.xdmf before: a user trial)
            print("  friction: mu " + ", ".join(f"{mu:.3g} on {n}" for n, mu in case.preload.friction.items())
                  + f" (facet means) at slip speeds of {touching.min():.3g} to {touching.max():.3g} m/s")
        print(f"  modes by {SOLVERS[case.modes.method]}")
        if case.prestress is not None:
            shift = case.prestress.shift
            print(f"  prestress shifts the frequencies by {np.nanmin(shift):+.2f} to {np.nanmax(shift):+.2f} Hz")
        if smap is not None:
            print(smap.summary())
        print(f"  results: {folder}")
    return result

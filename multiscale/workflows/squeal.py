"""The squeal analysis of a scene with effect ``stability`` (thesis ch. 4, §4.3–4.4).

Two steps (§4.3.1): the preload, a quasi-static steady sliding state (``macro.preload``), then the
complex modes of the system linearised there (``macro.eigen.solve_modes``), with the unstable and
potentially unstable modes and the strain-energy shares per material region (``macro.modal``).
Quadratic tetrahedra (``SQUEAL_DEGREE``): linear ones are far too stiff in bending.

With effect ``roughness`` the pads are rough (§4.2, §4.3.2, Table 4.1): the rough-interface builder
of the multiscale loop (``workflows.rough``, same scene rules) gives every interface its zone laws,
embedded exactly in the contact form, and the rigid datum gap where Newton starts; the Newton
matrix at the preload then holds the laws' consistent tangent.

``run`` writes into ``output.folder``: ``modes.csv``, mode shapes (``modes_<body>.bp``, VTX), the
preloaded state's fields (``<body>.xdmf``, ``interface.xdmf``), ``pressure.png`` (Fig. 4.12),
``re_im.png`` (Fig. 4.13) and ``energy.png`` (Figs. 4.20–4.21); ``multiscale.outputs.plan``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
from mpi4py import MPI

from multiscale import io, outputs
from multiscale.errors import InputError
from multiscale.macro.eigen import Damping, ModalResult, solve_modes
from multiscale.macro.mechanics import Mechanics
from multiscale.macro.modal import EnergyShares, RegionEnergy, StabilityReport, stability_report, \
    strain_energy_shares
from multiscale.macro.output import write_modes, write_state
from multiscale.macro.preload import Preload, linearise, preload
from multiscale.plots.squeal import plot_energy, plot_pressure, plot_re_im
from multiscale.workflows.model import build_mechanics, build_mesh, drive, interface_forces
from multiscale.workflows.output import RunResult, prepare_folder
from multiscale.workflows.rough import build_rough_interface

SQUEAL_DEGREE = 2     # quadratic tetrahedra: linear ones are far too stiff in bending (tests)


@dataclass
class SquealCase:
    """One case of a squeal study: preload, complex modes and their post-processing (§4.4)."""

    name: str
    preload: Preload
    modes: ModalResult
    report: StabilityReport
    energy: EnergyShares | None
    facet_pressure: np.ndarray      # Pa, per interface facet (global order of tm.interface)
    mech: Mechanics | None = field(default=None, repr=False)   # the model (spaces of the modes)


def squeal_case(mech: Mechanics, materials: Mapping[str, object], name: str = "case", *, load: float = 1e6,
                steps: int = 1, band=(0.0, 16e3), n_modes: int | None = None,
                target: float | None = None, damping: Damping | None = None, energy: bool = True,
                rtol: float = 1e-6, close_tol: float = 1e-3) -> SquealCase:
    """Preload ``mech`` from rest to ``load`` [Pa or N] in ``steps``, linearise and extract the
    complex modes in ``band`` [Hz] (§4.3.1, two steps)."""
    with io.stage("preload"):
        pre = preload(mech, load, steps)
    with io.stage("eigen solve"):
        K, M = linearise(mech, materials)
        modes = solve_modes(K, M, f_min=band[0], f_max=band[1], n_modes=n_modes, target=target, damping=damping)
        M.destroy()
    with io.stage("strain energy per component"):
        shares = strain_energy_shares(modes, RegionEnergy(mech)) if energy else None
    return SquealCase(name, pre, modes, stability_report(modes, rtol, close_tol), shares,
                      mech.contact.facet_pressure(), mech)


def analyse(scene, tm, *, name: str | None = None, energy: bool = True, degree: int = SQUEAL_DEGREE) -> SquealCase:
    """The squeal case of a scene on the mesh ``tm``: perfect penalty contact, or the rough zone
    laws of [roughness]/[micro] with effect ``roughness`` (see module docstring)."""
    st = scene.stability
    name = name or scene.name
    prefix = "squeal_" + "".join(ch if ch.isalnum() else "_" for ch in name) + "_"
    rough = build_rough_interface(scene, tm) if scene.has("roughness") else None
    if rough is not None:
        with io.stage("zone laws"):
            rough.update_laws()
    with io.stage("model set-up"):       # function spaces, forms compiled (cached after the first run)
        mech = build_mechanics(scene, tm, law=rough.law if rough else None, degree=degree, prefix=prefix)
    if rough is not None:            # Newton starts at rest from the rigid datum gap
        tm.interface.set_field(mech.contact.initial_gap, rough.datum_gap(interface_forces(scene, tm)))
    return squeal_case(mech, dict(scene.materials), name, load=drive(scene, tm).load, steps=scene.loading.ramp_steps,
                       band=tuple(st.band), n_modes=st.modes, target=st.target,
                       damping=Damping(eta=st.damping) if st.damping else None, energy=energy)


def energy_split(tm) -> tuple[str, str] | None:
    """The two body-0 regions along two interfaces (e.g. inner and outer pad), for Fig. 4.21."""
    regions = {r.tag: r.name for r in tm.spec.bodies[0].regions}
    along = [tags[0] for tags in tm.interface.plus_regions.values() if len(tags) == 1]
    return tuple(regions[t] for t in along) if len(along) == 2 and along[0] != along[1] else None


@dataclass
class SquealResult(RunResult):
    """``RunResult`` of the squeal analysis, with its case."""

    case: SquealCase


def run(scene, *, overwrite: bool = False, comm=MPI.COMM_WORLD, verbose: bool = True,
        degree: int = SQUEAL_DEGREE) -> SquealResult:
    """``multiscale run`` of a scene with effect "stability" (see module docstring)."""
    t0 = time.perf_counter()
    if not scene.has("stability"):
        raise InputError("effects", sorted(scene.effects), 'the squeal analysis needs effect "stability"')
    io.abort_on_exception(comm)
    folder = prepare_folder(scene, overwrite, False, comm)
    with io.stage("meshing"):
        tm = build_mesh(scene, comm)
    case = analyse(scene, tm, degree=degree)
    with io.stage("writing results"):
        plan = outputs.plan(scene)
        files = io.on_root(comm, lambda: [case.modes.write_csv(folder / "modes.csv")], f"{folder / 'modes.csv'}") or []
        files += write_state(folder, case.mech, plan.body_fields + plan.interface_fields)
        files += write_modes(folder, case.modes, case.mech.u, [b.name for b in tm.bodies])
        split = energy_split(tm)
        masks = tm.interface.masks()
        files += io.on_root(comm, lambda: [
            plot_pressure(tm.interface.midpoints, masks, case.facet_pressure, case.name, folder / "pressure.png"),
            plot_re_im([case], folder / "re_im.png"), plot_energy(case, folder / "energy.png", split)],
            f"the figures in {folder}") or []
    result = SquealResult(folder, files, time.perf_counter() - t0, case)
    if verbose and comm.rank == 0:
        rep = case.report
        print(f"{scene.name}: {len(case.modes)} modes up to {case.modes.frequency.max():.0f} Hz, "
              f"{rep.unstable.size} unstable ({', '.join(f'{f:.0f} Hz' for f in rep.frequency[rep.unstable - 1])}), "
              f"{rep.potentially_unstable.size} potentially unstable; {result.wall_time:.1f} s on {comm.size} rank(s)")
        print(f"  results: {folder}")
    return result

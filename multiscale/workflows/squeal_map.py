"""Stability map of a scene's squeal analysis ([stability.sweep], issue 20).

The swept parameter: ``friction`` (mu of every interface, a constant), ``pressure`` (the brake
pressure, ``loading.pressure``), ``speed`` (of the rotating body: the slip speed of a mu(v) law,
the gyroscopic terms) or ``rms`` (R_q of the rough surfaces: the zone laws are rebuilt). Every
point is linearised with the options of the nominal analysis, and

- ``preload = "once"`` (default for friction and speed): the sliding state of the nominal
  analysis is kept and only the operators change (as a friction change in a commercial
  complex-eigenvalue step). The linearised system is then smooth (affine for friction) in the
  parameter, and all points are projected on one basis: the undamped modes of (K, M) at the first
  and the last value, up to ``stability.basis`` x the band's top (``macro.damped.Subspace``);
  onsets are bisected on the reduced systems. Fast: one factorisation per end point.
- ``preload = "each"`` (default, and the only choice, for pressure and roughness): every point is
  preloaded again from the previous state. The contact status of the penalty facets changes with
  the state, which one modal basis does not follow (frequency errors of ~0.5 % measured between
  the end points of a friction sweep), so every point is solved on its own (``solve_system``) and
  an onset is bisected on the two neighbouring points projected on the union of their modes.

Every mode carries the relative residual of the full problem at its point. The modes are tracked
by ``macro.stability_map.MapBuilder``.

``write`` puts ``map.csv`` (the mode-pairing table), ``onsets.csv``, ``map.h5``, ``map.png``
(growth rate against frequency, coloured by the swept value) and ``map_tracks.png`` (frequency and
growth rate of every track against the parameter, onsets marked) into the output folder.
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Callable

from mpi4py import MPI

from multiscale import io
from multiscale.macro.damped import Subspace, basis_modes, project, solve_projected, solve_system
from multiscale.macro.eigen import matrix_comm, reduce_sum
from multiscale.macro.friction import set_friction
from multiscale.macro.kept_cells import closed_on_error
from multiscale.macro.preload import linearise_system, preload
from multiscale.macro.stability_map import MapBuilder, StabilityMap
from multiscale.schema import FrozenMap
from multiscale.scene_stability import SWEEP_PARAMETERS

UNITS = SWEEP_PARAMETERS          # swept parameter -> unit


class MapModel:
    """The model at one value of the swept parameter (see module docstring)."""

    def __init__(self, scene, tm, mech, options, load: float, rebuild: Callable):
        self.scene, self.tm, self.mech, self.options, self.load = scene, tm, mech, options, load
        self.nominal = mech
        self.rebuild = rebuild
        self.sweep = scene.stability.sweep
        self.materials = dict(scene.materials)
        self.max_pressure = 0.0        # Pa, the largest facet pressure of the points' own preloads

    def close(self, mech=None) -> None:
        """Close ``mech`` (default: the current one; collective) if it is one this map rebuilt."""
        mech = self.mech if mech is None else mech
        if mech is not self.nominal:
            mech.close()

    def linearise(self, value: float):
        """Set the parameter to ``value``, preload if asked, and linearise: a ``Linearised``."""
        name, opt = self.sweep.parameter, self.options
        if name == "rms":               # the nominal analysis' model is its caller's, the others ours
            mech, self.mech = self.mech, self.rebuild(with_rms(self.scene, value))
            self.close(mech)
        mech = self.mech
        if name == "friction":
            self.tm.interface.set_field(mech.contact.friction, value)
        elif name == "speed":
            mech.contact.speed.value = value
        slope = None
        if opt.friction_laws and name != "friction":
            slope = set_friction(mech, opt.friction_laws)[1]
        if self.sweep.preload_mode == "each":
            preload(mech, value if name == "pressure" else self.load, 1, reset=name == "rms")
            self.max_pressure = max(self.max_pressure, float(mech.contact.facet_pressure().max(initial=0.0)))
        return linearise_system(mech, self.materials, damping=opt.damping,
                                slope=slope if opt.friction_damping else None, prestress=opt.prestress,
                                gyroscopic=opt.gyroscopic, material=opt.material_damping)


def with_rms(scene, rms: float):
    """The scene with the R_q of every generated rough surface set to ``rms`` [m]."""
    def set_rms(r):
        return dataclasses.replace(r, rms=rms) if r is not None and r.rms is not None else r
    own = {n: (dataclasses.replace(s, roughness=set_rms(s.roughness)) if s is not None else s)
           for n, s in scene.interfaces.items()}
    return dataclasses.replace(scene, roughness=set_rms(scene.roughness), interfaces=FrozenMap(own))


def _free(lin):
    for A in (lin.system.M, lin.system.C, lin.system.H, lin.K_sigma):
        if A is not None:
            A.destroy()


def stability_map(scene, tm, mech, options, load: float, rebuild: Callable) -> StabilityMap:
    """The stability map of ``scene``'s [stability.sweep] with the mechanics ``mech`` of its
    nominal analysis (``options``: its ``SquealOptions``; ``load``: its load; ``rebuild(scene)``
    a new mechanics for a changed roughness)."""
    t0 = time.perf_counter()
    st, sw = scene.stability, scene.stability.sweep
    model = MapModel(scene, tm, mech, options, load, rebuild)
    builder = MapBuilder(sw.parameter, UNITS[sw.parameter], st.band, mac_min=sw.mac, rtol=st.threshold)
    with closed_on_error(model, tm.comm):        # a rebuilt model of a failed point (one rank)
        size = (_common_basis if sw.preload_mode == "once" else _per_point)(model, builder, st, options)
    model.close()
    return builder.finish(basis_size=size, time=time.perf_counter() - t0, max_pressure=model.max_pressure)


def _common_basis(model: MapModel, builder: MapBuilder, st, options) -> int:
    """All points projected on the undamped modes of the first and last points (fixed preload)."""
    band, values, sw = tuple(st.band), list(st.sweep.values), st.sweep
    bases, responses = [], []
    for value in (values[0], values[-1]):
        lin = model.linearise(value)
        _, modes, static = basis_modes(lin.system, band=band, n_modes=st.modes, target=st.target,
                                       basis=options.basis, left=lin.system.general)   # left: the damping's shifts
        bases, responses = bases + modes, responses + static
        if value == values[0]:
            _free(lin)
    sub = Subspace(bases, lin.system.M, matrix_comm(lin.system.K), responses=responses)
    del bases, responses
    results, reduced = [None] * len(values), [None] * len(values)
    for k in [len(values) - 1] + list(range(len(values) - 1)):
        if k != len(values) - 1:
            lin = model.linearise(values[k])
        results[k], reduced[k] = solve_projected(lin.system, sub, band=band, n_modes=st.modes, target=st.target,
                                                 expand=False)
        _free(lin)
    for k, (value, result) in enumerate(zip(values, results)):
        for track, j in builder.add(value, result):
            if sw.onsets:
                builder.onset(track, j, reduced[k - 1], reduced[k], result.modes[:, j], result.gram)
        for track, i, _ in builder.calmed if sw.onsets else ():
            builder.end(track, i, reduced[k - 1], reduced[k], results[k - 1].modes[:, i], result.gram)
    return sub.size


def _per_point(model: MapModel, builder: MapBuilder, st, options) -> int:
    """Every point preloaded and solved on its own; an onset (or a track's return to stability) is
    bisected on the two neighbouring points projected on the union of their modes."""
    band, sw = tuple(st.band), st.sweep
    prev = None
    for value in sw.values:
        lin = model.linearise(value)
        result = solve_system(lin.system, f_min=band[0], f_max=band[1], n_modes=st.modes, target=st.target,
                              method=options.method, basis=options.basis)
        turned = builder.add(value, result)
        if (turned or builder.calmed) and sw.onsets and prev is not None:
            sub = Subspace([prev[1].modes, result.modes], lin.system.M, result.comm)
            lo, hi = project(prev[0], sub)[0], project(lin.system, sub)[0]
            MV = sub.apply(lin.system.M)
            for track, j in turned:
                builder.onset(track, j, lo, hi, reduce_sum(MV.T @ result.modes[:, j], sub.comm), sub.gram)
            for track, i, _ in builder.calmed:
                builder.end(track, i, lo, hi, reduce_sum(MV.T @ prev[1].modes[:, i], sub.comm), sub.gram)
        if prev is not None:
            prev[0].K.destroy()
            _free(prev[2])
        kept = dataclasses.replace(lin.system, K=lin.system.K.copy())    # the next preload overwrites K
        prev = (kept, result, lin)
    prev[0].K.destroy()
    _free(prev[2])
    return 0


def write(smap: StabilityMap, folder, comm=MPI.COMM_WORLD, figures: bool = True, onsets: bool = True) -> list[Path]:
    """The map's tables (``onsets.csv`` only with ``onsets``: without, its header alone read as "no
    track turns unstable"; a user trial) and, with ``figures``, its figures (rank 0 writes, the
    list is empty elsewhere; a failed write is an OutputError on every rank)."""
    folder = Path(folder)

    def files():
        out = [smap.write_csv(folder / "map.csv"), *([smap.write_onsets_csv(folder / "onsets.csv")] if onsets else []),
               smap.write_h5(folder / "map.h5")]
        if figures:
            from multiscale.plots.squeal import plot_map, plot_tracks  # local: matplotlib only when a figure is drawn
            out += [plot_map(smap, folder / "map.png"), plot_tracks(smap, folder / "map_tracks.png")]
        return out
    return io.on_root(comm, files, f"the stability map in {folder}") or []

"""Stability map of a scene's squeal analysis ([stability.sweep], issue 20).

The swept parameter: ``friction`` (mu of every interface, a constant), ``pressure`` (the brake
pressure, ``loading.pressure``), ``speed`` (of the rotating body: the slip speed of a mu(v) law,
the gyroscopic terms) or ``rms`` (R_q of the rough surfaces: the zone laws are rebuilt). Every
point is linearised with the options of the nominal analysis, and

- ``preload = "once"`` (default for speed): the sliding state of the nominal
  analysis is kept and only the operators change (as a friction change in a commercial
  complex-eigenvalue step). The linearised system is then smooth (affine for friction) in the
  parameter, and all points are projected on one basis: the undamped modes of (K, M) at the first
  and the last value, up to ``stability.basis`` x the band's top (``macro.damped.Subspace``);
  onsets are bisected on the reduced systems. Fast: one factorisation per end point; approximate
  (docs/squeal.md: a friction map of the demo brake missed its strongest instability).
- ``preload = "each"`` (default for friction, the only choice for pressure and roughness): every
  point is
  preloaded again from the previous state. The contact status of the penalty facets changes with
  the state, which one modal basis does not follow (frequency errors of ~0.5 % measured between
  the end points of a friction sweep), so every point is solved on its own (``solve_system``) and
  an onset is bisected on the two neighbouring points projected on the union of their modes. That
  blend is not the system between them (onsets 8-9 % low against direct runs in user trials), so
  each onset's bracket is then narrowed by up to ``stability.sweep.refine`` full analyses
  (``_refiner``): the bracket in onsets.csv is then of full analyses, the onset the blend's
  bisection inside it.

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
from multiscale.macro.stability_map import MapBuilder, StabilityMap, best_match, bisect_onset
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

    def state(self) -> list:
        """The preloaded state: each body's displacements [m] (copies)."""
        return [u.x.array.copy() for u in self.mech.u]

    def restore(self, state: list) -> None:
        """Back to ``state`` (a roughness sweep rebuilds and preloads every point from rest: nothing to restore)."""
        if self.sweep.parameter != "rms":
            self.mech.set_displacements(state)

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
    builder.track(values, results, reduced, onsets=sw.onsets)
    return sub.size


@dataclasses.dataclass
class MapPoint:
    """A point of an "each" map solved in full: its value, linearised system (with its own copy of K:
    the next preload overwrites the Newton matrix) and modes."""

    value: float
    system: object           # macro.damped.LinearSystem
    result: object           # macro.eigen.ModalResult
    lin: object              # macro.preload.Linearised, owner of the other operators

    def free(self) -> None:
        self.system.K.destroy()
        _free(self.lin)


def _point(model: MapModel, value: float, st, options) -> MapPoint:
    """Preload, linearise and solve the full system at ``value``."""
    lin = model.linearise(value)
    result = solve_system(lin.system, f_min=st.band[0], f_max=st.band[1], n_modes=st.modes, target=st.target,
                          method=options.method, basis=options.basis)
    return MapPoint(float(value), dataclasses.replace(lin.system, K=lin.system.K.copy()), result, lin)


def _union(a: MapPoint, b: MapPoint):
    """The two points' systems projected on the union of their modes: (reduced a, reduced b, the
    reduced coordinates of a's modes, of b's, the Gram matrix of the basis)."""
    sub = Subspace([a.result.modes, b.result.modes], b.system.M, b.result.comm)
    MV = sub.apply(b.system.M)
    Qa, Qb = (reduce_sum(MV.T @ r.modes, sub.comm) for r in (a.result, b.result))
    return project(a.system, sub)[0], project(b.system, sub)[0], Qa, Qb, sub.gram


KEEP = 0.2     # a refining analysis lies in the middle 60 % of its bracket: each cuts it to 0.8 or less


def _refiner(model: MapModel, builder: MapBuilder, st, options, stable: MapPoint, unstable: MapPoint, j: int):
    """``MapBuilder.onset``'s ``refine`` for mode j of ``unstable``, stable at ``stable``:
    ``stability.sweep.refine`` full analyses, each at the blend's estimate (kept inside the middle
    60 % of the bracket; at its middle after two analyses that replaced the same end, as the blend
    then errs to one side) and replacing the bracket's end on its side (the mode that continues
    mode j, by MAC less the eigenvalue jump, stable or not), then bisected again on the new
    bracket's blend; returns the last bisection with the full analyses' bracket, and their number."""
    def refine(found):
        s, u, jj, made = stable, unstable, j, []      # made: the analyses in the bracket (freed here)
        moved = []                                     # the end each analysis replaced: "s" or "u"
        try:
            for _ in range(st.sweep.refine_steps):
                t = min(max((found[0] - s.value) / (u.value - s.value), KEEP), 1.0 - KEEP)
                if moved[-2:] in (["s", "s"], ["u", "u"]):
                    t = 0.5              # the blend erred to one side twice: halve the bracket (Brent's guard)
                mid = _point(model, s.value + t * (u.value - s.value), st, options)
                made.append(mid)
                k = best_match(mid.result.eigenvalues, mid.result.modes, u.result.modes[:, jj],
                               u.result.eigenvalues[jj], comm=mid.result.comm)
                if mid.result.unstable(builder.rtol)[k]:
                    u, jj = mid, k
                    moved.append("u")
                else:
                    s = mid
                    moved.append("s")
                for p in [p for p in made if p is not s and p is not u]:
                    p.free()
                    made.remove(p)
                lo, hi, _, Q, gram = _union(s, u)
                found = bisect_onset(lo, hi, s.value, u.value, Q[:, jj], u.result.eigenvalues[jj], gram,
                                     builder.band, rtol=builder.rtol, xtol=builder.xtol)
        finally:
            for p in made:
                p.free()
        return (found[0], found[1], (s.value, u.value), found[3]), st.sweep.refine_steps
    return refine if st.sweep.refine_steps else None


def _per_point(model: MapModel, builder: MapBuilder, st, options) -> int:
    """Every point preloaded and solved on its own; an onset (or a track's return to stability) is
    bisected on the two neighbouring points projected on the union of their modes, and narrowed by
    full analyses (``_refiner``); the model is then put back in the point's preloaded state."""
    sw = st.sweep
    prev = None
    for value in io.bar(sw.values, "map points", unit="point"):      # each a full analysis, its onsets' too
        point = _point(model, value, st, options)
        turned = builder.add(value, point.result)
        if (turned or builder.calmed) and sw.onsets and prev is not None:
            if sw.refine_steps:          # (outside the bar's time left: 6.9 s were said, 41.9 s followed, a user trial)
                io.reporter().say(f"  {len(turned) + len(builder.calmed)} onset(s) between {prev.value:g} and "
                                  f"{value:g}: narrowed by up to {sw.refine_steps} full analyses each")
            state = model.state()
            lo, hi, Q_prev, Q, gram = _union(prev, point)
            for track, j in turned:
                builder.onset(track, j, lo, hi, Q[:, j], gram, _refiner(model, builder, st, options, prev, point, j))
            for track, i, _ in builder.calmed:
                builder.end(track, i, lo, hi, Q_prev[:, i], gram, _refiner(model, builder, st, options, point, prev, i))
            model.restore(state)
        if prev is not None:
            prev.free()
        prev = point
    prev.free()
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

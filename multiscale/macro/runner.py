"""Run a scene: build only the problems its effects ask for, march the staggered loop, write results.

``build_model(scene)`` makes a ``MacroModel`` (mesh, mechanics, and a heat problem only with
effect ``thermal``). ``MacroModel.macro_step`` is the sequential thermo-mechanical loop of thesis
Fig. 7.4 over one macro step Δt: ``substeps`` times {heat step over δt with the current contact
state; contact solve with the new temperatures (effect ``expansion``)}. ``run(scene)`` ramps the
load, marches ``time.steps`` macro steps, and writes ``history.h5``, ``history.png`` and the XDMF
files into ``output.folder``.
"""
from __future__ import annotations

from multiscale.macro import _dolfinx  # noqa: F401,I001  (before DOLFINx)
import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from multiscale import io
from multiscale.errors import InputError
from multiscale.macro import mesh as _mesh
from multiscale.macro.geometry import Rotation
from multiscale.macro.mechanics import Mechanics, SolveResult
from multiscale.macro.thermal import Thermal, temperature_functions


@dataclass
class MacroModel:
    """What a scene built: ``problems`` names the assembled problems ("mechanics", "heat")."""

    scene: object
    tm: _mesh.TwoBodyMesh
    mechanics: Mechanics
    thermal: Thermal | None
    time: float = 0.0                                  # s
    heat_total: np.ndarray = field(default_factory=lambda: np.zeros(2))   # J, frictional heat in
    last_solve: SolveResult | None = None

    @property
    def contact(self):
        return self.mechanics.contact

    @property
    def problems(self) -> tuple[str, ...]:
        return ("mechanics",) + (("heat",) if self.thermal is not None else ())

    def speed(self, t: float) -> float:
        """Sliding speed of body 1 at time t: rad/s (rotation) or m/s (translation)."""
        ld = self.scene.loading
        if isinstance(self.tm.spec.motion, Rotation):
            return ld.angular_speed(t)
        return ld.sliding_speed or 0.0

    def load(self) -> float:
        ld = self.scene.loading
        return ld.normal_force if ld.normal_force is not None else ld.pressure

    def start(self) -> SolveResult:
        """First contact solve from rest with the scene's load ramp."""
        self.contact.speed.value = self.speed(0.0)
        self.last_solve = self.mechanics.ramp(self.load(), self.scene.loading.ramp_steps)
        return self.last_solve

    def macro_step(self, dt: float, substeps: int = 1) -> np.ndarray:
        """Advance by one macro step dt [s] in ``substeps`` (Fig. 7.4); returns the heat [J] put
        into each body during the step."""
        heat = np.zeros(2)
        delta = dt / substeps
        for _ in range(substeps):
            if self.thermal is not None:
                self.contact.speed.value = self.speed(self.time)
                heat += self.thermal.step(delta).heat_in
            self.time += delta
            if self.mechanics.temperatures is not None or self._speed_changes(delta):
                self.contact.speed.value = self.speed(self.time)
                self.last_solve = self.mechanics.solve()
        self.heat_total += heat
        return heat

    def _speed_changes(self, delta: float) -> bool:
        return self.scene.loading.speed_profile is not None and \
            self.speed(self.time) != self.speed(self.time - delta)

    def record(self, heat_step=(0.0, 0.0)) -> dict:
        """One history row at the current state (units: see ``multiscale.io.UNITS``)."""
        row = {"time": self.time, "interface_force": self.last_solve.normal_force,
               "friction_force": float(np.linalg.norm(self.contact.friction_force())),
               "max_pressure": self.last_solve.max_pressure,
               "newton_iterations": self.last_solve.iterations}
        if self.thermal is not None:
            stored, hottest = self.thermal.stored_heat(), self.thermal.max_temperature()
            for i, body in enumerate(self.tm.bodies):
                row[f"max_temperature_{body.name}"] = hottest[i]
                row[f"heat_step_{body.name}"] = heat_step[i]
                row[f"heat_total_{body.name}"] = self.heat_total[i]
                row[f"stored_heat_{body.name}"] = stored[i]
        return row


def build_model(scene, comm=MPI.COMM_WORLD, law=None, tm=None) -> MacroModel:
    """Mesh and the problems the scene's effects ask for (no heat problem without ``thermal``).

    ``law`` optionally replaces the perfect-contact penalty law (see ``interface.PressureLaw``);
    ``tm``: an already built mesh of the scene (e.g. the one the law's per-facet fields live on).
    """
    if not scene.has("contact"):
        raise InputError("effects", sorted(scene.effects), 'the macro model needs effect "contact"')
    tm = tm or _mesh.build(scene.geometry.builder, dict(scene.geometry.params), comm)
    materials = dict(scene.materials)
    thermal = scene.has("thermal")
    T = temperature_functions(tm) if thermal else None
    if T is not None:
        for f in T:
            f.x.array[:] = scene.time.initial_temperature
    ld = scene.loading
    mech = Mechanics(tm, materials, stiffness=scene.interface.penalty or 0.0,
                     friction=ld.friction if scene.has("friction") else 0.0, law=law,
                     temperatures=T if scene.has("expansion") else None,
                     reference_temperature=scene.time.initial_temperature,
                     load_kind="force" if ld.normal_force is not None else "pressure")
    heat = None
    if thermal:
        dt = scene.time.dt / scene.time.substeps
        heat = Thermal(mech.contact, materials, initial_temperature=scene.time.initial_temperature, dt=dt,
                       frictional_heat=scene.has("heat_partition"), conductance=scene.has("conductance"),
                       temperatures=T)
        if scene.has("heat_partition"):
            tm.interface.set_field(mech.contact.partition, scene.partition)
        if scene.has("conductance") and scene.interface.conductance is not None:   # else per facet later
            tm.interface.set_field(mech.contact.conductance, scene.interface.conductance)
    return MacroModel(scene, tm, mech, heat)


@dataclass
class RunResult:
    """Where a run's results are."""

    folder: Path
    history: io.History
    history_file: Path
    plot_file: Path
    field_files: list
    wall_time: float                 # s


def prepare_folder(scene, overwrite: bool, resume: bool, comm) -> Path:
    """The scene's output folder, created; refuses to overwrite results without ``overwrite``
    (or ``resume``, which continues them). Rank 0 decides for every rank."""
    folder = Path(scene.output.folder)
    existing = comm.bcast(sorted(p.name for p in folder.iterdir()) if comm.rank == 0 and folder.is_dir() else [],
                          root=0)
    if existing and not (overwrite or resume):
        raise InputError("output.folder", str(folder),
                         f"already holds results ({', '.join(existing[:3])}...); pass --overwrite to replace them")
    if comm.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    return folder


def run(scene, overwrite: bool = False, resume: bool = False, comm=MPI.COMM_WORLD,
        verbose: bool = True) -> RunResult:
    """Run a scene (``multiscale run``): see module docstring. Scenes with effect ``roughness``
    run the multiscale loop (``multiscale.coupling.run``, checkpointed, resumable); scenes with
    effect ``stability`` the squeal analysis (``multiscale.macro.stability.run_scene``)."""
    if scene.has("stability"):
        if resume:
            raise InputError("--resume", True, "the squeal analysis has no checkpoints to resume from")
        from multiscale.macro.stability import run_scene
        return run_scene(scene, comm=comm, overwrite=overwrite, verbose=verbose)
    if scene.has("roughness"):
        from multiscale.coupling import run as run_multiscale
        return run_multiscale(scene, overwrite=overwrite, resume=resume, comm=comm, verbose=verbose)
    start = _time.perf_counter()
    io.abort_on_exception(comm)
    if resume:
        raise InputError("--resume", True, "this scene has no checkpoints to resume from "
                         "(only the multiscale loop, effect \"roughness\", writes checkpoints)")
    folder = prepare_folder(scene, overwrite, False, comm)
    model = build_model(scene, comm)
    model.start()
    writer = _FieldOutput(model, folder, scene.output.fields)
    history = io.History()
    history.append(**model.record())
    writer.write()
    steps = scene.time.steps if model.thermal is not None else 0
    for n in io.progress(range(1, steps + 1), comm, desc=f"{scene.name}", unit="step"):
        heat = model.macro_step(scene.time.dt, scene.time.substeps)
        history.append(**model.record(heat))
        if n % scene.output.every == 0 or n == steps:
            writer.write()
    writer.close()
    h5, png = folder / "history.h5", folder / "history.png"
    if comm.rank == 0:
        history.write(h5, {"scene": scene.name, "ranks": comm.size})
        history.plot(png, title=f"{scene.name}")
    comm.barrier()
    result = RunResult(folder, history, h5, png, writer.files, _time.perf_counter() - start)
    if verbose and comm.rank == 0:
        print(f"{scene.name}: {len(history)} records in {result.wall_time:.1f} s on {comm.size} rank(s)")
        print(f"  ParaView: {', '.join(str(f) for f in writer.files)}")
        print(f"  history:  {h5}  plot: {png}")
    return result


class _FieldOutput:
    """The scene's output fields, refreshed and written at each output time.

    ``extra``: {interface field name: callable returning its global per-facet array}, written when
    the name is among ``fields``; ``append``: continue existing XDMF files (a resumed run)."""

    def __init__(self, model: MacroModel, folder: Path, fields, extra=None, append: bool = False):
        self.model = model
        tm, mech, th = model.tm, model.mechanics, model.thermal
        fields = set(fields)
        body = [[], []]
        self.von_mises = []
        for i, b in enumerate(tm.bodies):
            if "displacement" in fields:
                body[i].append(mech.u[i])
            if "temperature" in fields and th is not None:
                body[i].append(th.T[i])
            if "von_mises" in fields:
                V = b.region_space
                f = fem.Function(V, name=f"von_mises_{b.name}")
                self.von_mises.append((f, fem.Expression(mech.von_mises(i), V.element.interpolation_points)))
                body[i].append(f)
        iface = []
        self.pressure = tm.interface.field("contact_pressure") if "contact_pressure" in fields else None
        self.flux = tm.interface.field("heat_flux") if "heat_flux" in fields and th is not None else None
        self.extra = [(tm.interface.field(name), make) for name, make in (extra or {}).items() if name in fields]
        iface = [f for f in (self.pressure, self.flux) if f is not None] + [f for f, _ in self.extra]
        self.writer = io.FieldWriter(folder, tm, body, iface, append=append)
        self.files = self.writer.files

    def write(self) -> None:
        m = self.model
        for f, expr in self.von_mises:
            f.interpolate(expr)
        if self.pressure is not None:
            m.tm.interface.set_field(self.pressure, m.contact.facet_pressure())
        if self.flux is not None:
            m.tm.interface.set_field(self.flux, m.contact.facet_heat_flux())
        for f, make in self.extra:
            m.tm.interface.set_field(f, make())
        self.writer.write(m.time)

    def close(self) -> None:
        self.writer.close()

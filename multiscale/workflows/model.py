"""The scene-to-model factory: the only code that reads a scene's sections for the macro side.

From a validated scene (``multiscale.scene``) it builds the mesh (the registered builder or the
user's file), the mechanics (materials per body, the interface law, the friction of every
interface, the supports and the load), the heat problem (only with effect ``thermal``) and the
drive (load, ramp, load factor and speed against time), as plain objects for ``multiscale.macro``.
The rules that more than one analysis follows live here once:

- supports: the builder's, plus every [[boundary]] ``fix``; load faces and direction: [loading]
  ``faces``/``direction``, else the builder's;
- friction coefficient of an interface: its [interfaces.<name>] ``friction`` or ``friction_temperature``,
  else [loading]'s; a fade table at the initial temperature (and, with heat, at each facet's temperature
  as the run goes: ``friction_law``), a mu(v) law at each facet's slip speed as the run goes, with effect
  ``friction``; else 0;
- load: a fluid pressure -p n for builders that declare ``fluid_load`` and for geometry files (a
  normal force spread as the uniform pressure F / A, A the load faces' areas projected normal to
  each face's resultant, or of each of a face's flat parts facing opposite ways, ``load_face_areas``;
  with ``loading.direction`` a traction along it), else the scene's normal force [N] or pressure [Pa] on the load faces; with
  ``loading.braking_torque`` or ``loading.vehicle.mass`` the load whose friction moment about the axis is the braking
  torque (that torque, or the braking force x wheel radius): first guessed with every interface carrying the same clamp
  force N, sum_k mu_k N r_k = torque (r_k the interface's mean radius), then scaled by the model
  after its first solve to the friction moment of the real pressure distribution;
- interface forces: every interface carries its area's share of the resultant of the load on the
  load faces (``interface_forces``; what the rigid datum gap and the law range start from);
- materials at an interface: the first region of each body at the initial temperature
  (``interface_materials``).
"""
from __future__ import annotations

import itertools
import warnings
from contextlib import contextmanager

import numpy as np
from mpi4py import MPI

from multiscale.errors import InputError
from multiscale.geometry import Rotation
from multiscale.io import reporter
from multiscale.macro import mesh as two_body
from multiscale.macro.facet_wear import FacetRate, FacetWear
from multiscale.macro.friction import FacetFriction, StribeckFriction, TableFriction
from multiscale.macro.interface import PenaltyLaw, SumLaw
from multiscale.macro.kept_cells import SolverOptionWarning
from multiscale.macro.load_faces import load_face_areas, load_face_forces
from multiscale.macro.mechanics import REPEATABLE_REFRESH, Mechanics
from multiscale.macro.model import Drive, MacroModel
from multiscale.macro.probes import Probes, ProbeSpec
from multiscale.macro.thermal import HeatStepWarning, Thermal, ThermalBoundary, temperature_functions
from multiscale.memory import SPREAD, memory_available, micro_memory, remedy, run_memory
from multiscale.micro.wear import WearRate
from multiscale.scene_friction import bare_interfaces, initial_friction, speed_law_guess
from multiscale.scene_geometry import scene_spec
from multiscale.workflows.strain import last_forces


def friction_coefficient(scene, interface: str) -> float:
    """mu [-] of an interface (``Scene.interface_settings``: its constant, else its fade table at the
    initial temperature, else [loading]'s mu(v) law's mean mu (speed_law_guess), a first guess until the law
    sets each facet's) with effect "friction", else 0."""
    if not scene.has("friction"):
        return 0.0
    mu = initial_friction(scene.interface_settings(interface), scene.time.initial_temperature)
    return speed_law_guess(scene.loading) if mu is None else mu


def speed_law(loading):
    """[loading]'s mu(v) law (``friction_curve`` or ``stribeck``; ``macro.friction``), or None."""
    if loading.friction_curve is not None:
        return TableFriction(loading.friction_curve)
    st = loading.stribeck
    return None if st is None else StribeckFriction(st.static, st.kinetic, st.speed, st.exponent)


def facet_friction(scene, tm) -> np.ndarray:
    """mu [-] of every interface facet of ``tm`` (n_facets,): its interface's ``friction_coefficient``."""
    return np.array([friction_coefficient(scene, name) for name in tm.interface.tags])[tm.interface.tag_index]


def friction_law(scene, tm) -> FacetFriction | None:
    """mu per interface facet as the run goes (``FacetFriction``), with effect "friction" and a fade table
    on any interface (its own or [loading]'s ``friction_temperature``, with heat) or [loading]'s mu(v) law
    on any (those without a friction of their own); else None (mu constant on each interface)."""
    if not scene.has("friction"):
        return None
    tags, tag = tm.interface.tags, tm.interface.tag_index
    tables = [scene.interface_settings(name).friction_temperature for name in tags] if scene.has("thermal") else []
    fades = tuple((tag == i, *(np.array(column, dtype=float) for column in zip(*t)))
                  for i, t in enumerate(tables) if t)
    law = speed_law(scene.loading)
    bare = bare_interfaces(scene.interfaces, tags) if law is not None else []
    speeds = tuple((tag == i, law) for i, name in enumerate(tags) if name in bare)
    return FacetFriction(facet_friction(scene, tm), fades, speeds) if fades or speeds else None


def load_kind(scene) -> str:
    """How the load acts: "fluid" (-p n: builders with ``fluid_load``, files), "force" or "pressure"."""
    if scene_spec(scene).fluid_load:        # a builder's fluid load takes no normal_force: refused when read
        return "fluid"
    return "force" if scene.loading.pressure is None else "pressure"


def interface_radii(scene, tm) -> dict:
    """Mean distance [m] of every interface from the rotation axis (area-weighted)."""
    motion, iface = tm.spec.motion, tm.interface
    axis = np.asarray(motion.axis, float) / np.linalg.norm(motion.axis)
    r = iface.midpoints - np.asarray(motion.centre, float)
    r = np.linalg.norm(r - np.outer(r @ axis, axis), axis=1)
    return {n: float(r[m] @ iface.areas[m] / iface.areas[m].sum()) for n, m in iface.masks().items()}


def partitions(scene, tm) -> dict:
    """Share of frictional heat into body 0 [-] at every interface (``Scene.partition_at``): the
    effusivity partition weighted by the interface's area A_0 and, for a rotating body 1, by its
    share of the track it sweeps (``macro.mesh.swept_area``; the ch. 7 pin, 4 cm^2 sweeping
    116 cm^2, takes 2.6 %, not the 43.5 % of equal areas). Interfaces on one track
    (``shared_tracks``: a pad's pucks, two pads on one face of a disc) heat it together: each
    takes the track's area times its share of their faces' area, the equal mean temperatures of
    the rule with each one's heat in proportion to its area (N equal pads: 1/N of the track each,
    where each alone would take all of it). A translating body 1 keeps equal areas (collective)."""
    iface, motion = tm.interface, tm.spec.motion
    masks = iface.masks()
    if scene.interface.partition != "effusivity" or scene.geometry.motion != "rotation":
        return {name: scene.partition_at(name) for name in masks}
    face = {name: float(iface.areas[m].sum()) for name, m in masks.items()}
    bands = {name: iface.box(name, motion.axis, motion.centre) for name in masks}
    out = {}
    for name, together in shared_tracks(bands).items():
        lo, hi = np.min([bands[n][0] for n in together], axis=0), np.max([bands[n][1] for n in together], axis=0)
        track = two_body.swept_area(lo, hi) * face[name] / sum(face[n] for n in together)
        out[name] = scene.partition_at(name, (face[name], max(track, face[name])))
    return out


def shared_tracks(bands: dict, rtol: float = 1e-6) -> dict:
    """{name: the names of the interfaces on its track, itself included, in the order of
    ``bands``}: ``bands`` {name: (lo, hi)} are the (radius, axial position) corners [m] of the
    band each interface sweeps (``Interface.box``). Two bands share a track where they overlap in
    both, within ``rtol`` of the largest radius, by more than that in one (a disc face's bands
    are segments at one axial position, a drum's at one radius); joined transitively."""
    tol = rtol * max(float(hi[0]) for _, hi in bands.values())
    track = {name: {name} for name in bands}
    for a, b in itertools.combinations(bands, 2):
        overlap = np.minimum(bands[a][1], bands[b][1]) - np.maximum(bands[a][0], bands[b][0])
        if overlap.min() >= -tol and overlap.max() > tol:
            joined = track[a] | track[b]
            track.update(dict.fromkeys(joined, joined))
    return {name: [n for n in bands if n in track[name]] for name in bands}


def drive(scene, tm) -> Drive:
    """Load [N or Pa] (``load_kind``), ramp, load factor and speed of body 1 (rad/s for a
    rotation, m/s for a translation) against time."""
    ld, kind = scene.loading, load_kind(scene)
    force, torque = ld.normal_force, ld.torque
    if torque is not None:
        radius = interface_radii(scene, tm)
        moment = sum(friction_coefficient(scene, n) * radius[n] for n in tm.interface.tags)
        if moment <= 0:
            raise InputError("loading", None, f"braking at {torque:.6g} N m needs friction (effect \"friction\" "
                             "and mu > 0 at the initial temperature: [loading]'s or the interfaces' own)")
        force = len(radius) * torque / moment          # a first guess: the model scales it to the torque
    if force is not None and kind != "force":          # a force as a uniform pressure on the load faces
        area = sum(load_face_areas(tm, kind).values())  # with that resultant (a fluid's: projected areas)
        if not area > 0:
            raise InputError("loading.faces", list(tm.spec.load_faces), "a pressure on them has no resultant "
                             "(their normals cancel), so no normal force can act there: load faces that push "
                             "the parts towards the contact")
        load = force / area
    else:
        load = force if force is not None else ld.pressure
    if scene.geometry.motion == "rotation":
        return Drive(load, ld.angular_speed, ld.ramp_steps, ld.factor, ld.mean_factor, ld.steady_speed, torque,
                     ld.mean_angular_speed, ld.mean_sliding_factor)
    speed = ld.sliding_speed or 0.0
    return Drive(load, lambda t: speed, ld.ramp_steps, ld.factor, ld.mean_factor)


def interface_materials(scene, interface: str | None = None) -> tuple:
    """Materials on both sides of an interface (default: the first) at the initial temperature:
    (body 0's region along it, body 1)."""
    T0 = scene.time.initial_temperature
    return tuple(scene.materials[m].at(T0) for m in scene.geometry.spec.interface_materials(interface))


def build_mesh(scene, comm=MPI.COMM_WORLD) -> two_body.TwoBodyMesh:
    """The scene's mesh (gmsh on rank 0, distributed), with the scene's supports and loads. With
    friction, body 1 must slide along every interface: one its motion crosses (a wrong
    ``geometry.axis`` or ``centre``) is refused (collective; a squeal run with a wrong axis had
    reported 0 unstable modes instead of 1: an adversarial test)."""
    g = scene.geometry
    params = g.params if g.builder == "file" else dict(g.params)
    tm = two_body.build(g.module(), params, comm, spec=scene_spec(scene), max_cells=g.max_cells,
                        sliding=scene.has("friction"), pressed=scene.loading.pressure is not None)
    motion = tm.spec.motion
    for name in tm.interface.tags if scene.has("friction") else ():
        c = tm.interface.crossing(name, motion)
        if c.share > 0:
            where = f"({100 * c.share:.3g} % of its area, e.g. at {np.round(c.where * 1e3, 1).tolist()} mm)"
            if isinstance(motion, Rotation):
                raise InputError("geometry.axis", list(motion.axis), f"the rotation through {list(motion.centre)} m "
                                 f"crosses interface {name!r} instead of sliding along it {where}: check the "
                                 "rotating body's axis and centre")
            raise InputError("geometry", g.builder, f"the translation along {list(motion.direction)} crosses "
                             f"interface {name!r} instead of sliding along it {where}")
    return tm


def say_load(scene, tm) -> None:
    """Say what a pressure load (``loading.pressure``) gives, a console line: its resultant [N] on each
    load face of the mesh (a pin-on-disc's plate ends, a brake's piston: not the contact's nominal
    pressure; said nowhere before, a user trial). Collective."""
    if scene.loading.pressure is None:
        return
    forces = load_face_forces(tm, scene.loading.pressure, load_kind(scene))
    reporter().say(f"  load: {scene.loading.pressure / 1e6:g} MPa on "
                   + ", ".join(f"{face}: {force:.4g} N" for face, force in forces.items()))


def say_clamp(scene, history) -> None:
    """Say the clamp force that a braking torque (``loading.torque``: a vehicle's, or given) asked of
    the first contact solve, a console line: the normal force on each interface (``history``'s last
    record) and the torque; the run finds it (T = mu F r), check cannot (said nowhere: a user trial)."""
    if scene.loading.torque is None:
        return
    each = last_forces(scene, history) or {"the interface": abs(float(history["interface_force"][-1]))}
    forces = ", ".join(f"{f:.4g} N on {n}" for n, f in each.items()) if max(each.values()) > 0 else "none (released)"
    reporter().say(f"  clamp: {forces} at the start, for the braking torque {scene.loading.torque:.4g} N m")


def global_dofs(functions) -> int:
    """The dofs of ``functions`` (DOLFINx Functions) over every rank (collective-free: the index maps
    know their global sizes)."""
    return sum(f.function_space.dofmap.index_map.size_global * f.function_space.dofmap.index_map_bs
               for f in functions)


def say_model_size(tm, mechanics, thermal=None, kind: str = "transient", modes: int = 0, points: int = 0,
                   sweep: str | None = None) -> None:
    """Say the size of a model, a console line: its cells, displacement dofs and (with heat)
    temperature dofs; and warn (stderr, at once) when a run of ``kind`` ("transient" or "squeal")
    of that size (a squeal run asking for ``modes`` modes) is estimated to need, ``SPREAD`` times, more
    memory than the machines of its ranks have free (``memory.run_memory``, with ``thermal``'s
    temperature dofs; a squeal run of ~1M dofs was checked OK and would take ~40 GB: a user
    trial), with a multiscale loop's zones of ``points`` grid points in all (``memory.micro_memory``)
    or a stability map of preload ``sweep``.
    Collective: global counts."""
    def spaced(n: int) -> str:
        return f"{n:,}".replace(",", " ")
    n, n_T = global_dofs(mechanics.u), global_dofs(thermal.T) if thermal is not None else 0
    heat = f", {spaced(n_T)} temperature dofs" if thermal is not None else ""
    reporter().say(f"  model: {spaced(tm.parent.topology.index_map(tm.parent.topology.dim).size_global)} cells, "
                   f"{spaced(n)} displacement dofs{heat}")
    comm = tm.comm
    hosts = comm.allgather(MPI.Get_processor_name())
    free = comm.allgather(memory_available() if hosts.index(hosts[comm.rank]) == comm.rank else 0.0)
    linear = thermal is not None and not thermal.nonlinear
    need, have = run_memory(n, kind, comm.size, modes, n_T, linear, sweep), (None if None in free else sum(free))
    need += micro_memory(points, comm.size) if points else 0.0
    if comm.rank == 0 and have is not None and SPREAD * need > have:
        machines = "this machine" if len(set(hosts)) == 1 else f"the {len(set(hosts))} machines of its ranks"
        zones = f" and {spaced(points)} zone grid points" if points else ""
        reporter().warn(f"a {kind} run of {spaced(n)} displacement dofs{zones} takes about {need / 1e9:.3g} GB at its "
                        f"peak (an estimate from measured runs, docs/performance.rst; up to {SPREAD:g} times that), "
                        f"near or above the {have / 1e9:.3g} GB {machines} has free: it may be killed without a word "
                        f"by the out-of-memory killer; {remedy(kind == 'squeal')}")


def build_mechanics(scene, tm, *, law=None, temperatures=None, degree: int = 1,
                    prefix: str = "mech_") -> Mechanics:
    """Quasi-static sliding mechanics of the scene on ``tm``: perfect-contact penalty, or ``law``
    on the rough interfaces (``scene.rough_interfaces``) and the penalty on the others; thermal
    expansion with ``temperatures``; Lagrange ``degree``; every interface's friction. With
    ``[stability] method = "subspace"`` the Newton solves are preconditioned by the LDL^T of the
    frictionless tangent (``Mechanics`` ``preconditioner="cholesky"``), half the memory of the LU."""
    penalty = scene.interface.penalty or 0.0
    masks = tm.interface.masks()
    if law is not None and len(scene.rough_interfaces) < len(masks):     # some interfaces in perfect contact
        perfect = np.zeros(tm.interface.n_facets)
        for name, m in masks.items():
            if name not in scene.rough_interfaces:
                perfect[m] = penalty
        law = SumLaw(law, PenaltyLaw(tm.interface.field("perfect_stiffness", perfect)))
    mu = facet_friction(scene, tm)
    d = drive(scene, tm)
    lean = scene.stability is not None and scene.stability.method == "subspace"
    return Mechanics(tm, dict(scene.materials), stiffness=penalty, friction=mu, speed=d.speed(0.0), law=law,
                     temperatures=temperatures, reference_temperature=scene.time.initial_temperature,
                     load_kind=load_kind(scene), degree=degree, prefix=prefix,
                     preconditioner="cholesky" if lean else "lu",
                     refresh=REPEATABLE_REFRESH if scene.output is not None and scene.output.repeatable else None)


def thermal_conditions(scene) -> tuple[ThermalBoundary, ...]:
    """The thermal conditions of [[boundary]] for the heat problem (none without effect "thermal"):
    convection h [W/(m^2 K)], constant or against the rotating body's speed [rad/s]; radiation with
    an emissivity; both towards ``ambient`` (default ``time.initial_temperature``); or a fixed
    temperature. Surfaces without one are insulated; ``fix`` is a mechanical support."""
    if not scene.has("thermal"):
        return ()
    T0 = scene.time.initial_temperature
    return tuple(ThermalBoundary(tuple(b.surfaces), convection=b.h if b.convection is not None else None,
                                 emissivity=b.emissivity, ambient=b.ambient if b.ambient is not None else T0,
                                 temperature=b.temperature)
                 for b in scene.boundary
                 if any(v is not None for v in (b.convection, b.emissivity, b.temperature)))


def build_model(scene, comm=MPI.COMM_WORLD, *, law=None, tm=None, conductance: bool | None = None) -> MacroModel:
    """Mesh and the problems the scene's effects ask for (no heat problem without ``thermal``).

    ``law`` optionally replaces the perfect-contact penalty law on the rough interfaces
    (``macro.interface.PressureLaw``); ``tm``: an already built mesh of the scene (e.g. the one
    the law's per-facet fields live on); ``conductance``: the heat problem's interface conductance
    term (default: with effect "conductance"; the multiscale loop's implicit coupling sets it).
    """
    if not scene.has("contact"):
        raise InputError("effects", sorted(scene.effects), 'the macro model needs effect "contact"')
    tm = tm or build_mesh(scene, comm)
    t = scene.time
    T = temperature_functions(tm) if scene.has("thermal") else None
    if T is not None:
        for f in T:
            f.x.array[:] = t.initial_temperature
    found = probes(scene, tm, T) if T is not None and scene.output.probes else None   # (refused: nothing to free)
    mech = build_mechanics(scene, tm, law=law, temperatures=T if scene.has("expansion") else None)
    heat, shares = None, {}
    if T is not None:
        heat = Thermal(mech.contact, dict(scene.materials), initial_temperature=t.initial_temperature,
                       dt=t.dt / t.substeps, frictional_heat=scene.has("heat_partition"),
                       conductance=scene.has("conductance") if conductance is None else conductance, temperatures=T,
                       boundaries=thermal_conditions(scene))
        if scene.has("heat_partition"):
            share, shares = np.zeros(tm.interface.n_facets), partitions(scene, tm)
            for name, m in tm.interface.masks().items():
                share[m] = shares[name]
            tm.interface.set_field(mech.contact.partition, share)
            if scene.interface.partition == "effusivity":    # (check gives it at equal areas: the share the run
                reporter().say(f"heat partition into {scene.bodies[0]} (effusivity, by area): " + ", ".join(   # used
                    f"{n} {v:.4g}" for n, v in shares.items()))                      # was said nowhere: a user trial)
        if scene.has("conductance") and scene.interface.conductance is not None:   # else per facet later
            tm.interface.set_field(mech.contact.conductance, scene.interface.conductance)
    return MacroModel(tm, mech, heat, drive(scene, tm), partitions=shares, friction_law=friction_law(scene, tm),
                      probes=found)


def facet_wear(scene, model: MacroModel) -> FacetWear:
    """The Archard wear of the interface facets in perfect contact (effect "wear" without
    "roughness"): body 0 on each interface by its material's k_w, else by [wear]'s rate (k_w, k per
    normal load, their tables, the default table: refused where another interface's material gives
    its own, a pad of no rate of its own worn by the thesis' sintered table unsaid: a review); body 1
    on each interface whose material gives k_w, along its track."""
    spec, rates, counter, own = scene.geometry.spec, [], [], []
    for name, mask in model.tm.interface.masks().items():
        worn, other = (scene.materials[m] for m in spec.interface_materials(name))
        own.append(worn.k_w is not None)
        rates.append(FacetRate(mask, WearRate(worn.wear_rate)) if worn.k_w is not None else
                     FacetRate(mask, WearRate(scene.wear.rate), scene.wear.per_load))
        if other.k_w is not None:
            counter.append(FacetRate(mask, WearRate(other.wear_rate)))
    if any(own) and not all(own) and scene.wear.given is None:
        bare = [n for n, given in zip(model.tm.interface.tags, own) if not given]
        raise InputError("wear", None, f"a rate for interface(s) {', '.join(bare)}, whose worn material gives no "
                         "k_w while another interface's does: give wear.k_w (or wear.specific_rate, a table) or that "
                         "material's k_w (else the thesis' default k_w(T) table would wear it)")
    return FacetWear(model, rates, counter, temperature=scene.time.initial_temperature, limit=scene.wear.limit)


def probes(scene, tm, temperatures) -> Probes:
    """The scene's thermocouples (``output.probes``) on the temperature functions; says where each
    one reads (its body and part, its distance from the interface, how far outside the meshed
    surface; in the rotating body whether it turns with it or stays in place). A probe's ``body``
    may name a part of a body (a pad against its backplate)."""
    motion, specs = tm.spec.motion, []
    parts = {r.name: i for i, b in enumerate(scene.geometry.spec.bodies) for r in b.regions}
    for name, p in scene.output.probes.items():
        body = scene.bodies.index(p.body) if p.body in scene.bodies else parts.get(p.body)
        part = p.body if p.body is not None and p.body not in scene.bodies else None
        specs.append(ProbeSpec(name, p.point, body, p.turns, part))
    rotating = isinstance(motion, Rotation)
    found = Probes(tm, temperatures, specs, motion if rotating else None)
    for where, spec in zip(found.located, specs):
        body, turning = tm.bodies[where.body], where.body == 1 and rotating
        said = [f"probe {where.name}: in {body.name}" + (f", part {where.part}" if len(body.spec.regions) > 1 else "")]
        if turning:
            said.append("turning with it: its circle's mean" if spec.turns else "fixed in space: a rubbing "
                        "thermocouple or pyrometer; output.probes.<name>.turns for one embedded in it")
        said.append(f"{where.depth * 1e3:.3g} mm from " + ("the interfaces' track" if turning else "the interface"))
        if where.outside > 0:
            said.append(f"{where.outside * 1e6:.3g} um outside the meshed surface, read in the closest cell")
        reporter().say(", ".join(said))
    return found


def worn_probes(model: MacroModel, depths) -> tuple:
    """The model's probes that a worn face reached (``Probes.worn``: ``depths`` [m] per body, global
    arrays per facet); none without probes."""
    return tuple(model.probes.worn(depths)) if model.probes is not None else ()


def run_notes(model: MacroModel) -> tuple:
    """What a run of the model adds to its warnings: the model's notes (``MacroModel.notes``) and
    the heat's (``Thermal.notes``)."""
    return (*model.notes, *(model.thermal.notes if model.thermal is not None else ()))


@contextmanager
def heat_warnings_as_notes(model: MacroModel | None = None):
    """The heat's ``HeatStepWarning`` and ``SolverOptionWarning`` (the model's build) kept quiet in
    the block: the run's report says them, once, with the other warnings and in the provenance
    (``run_notes``). With ``model``, an error that ends the block carries the run's notes so far as
    its own (PEP 678, ``add_note``): a failed run's report and record say them too (before, a run
    that failed lost them, the failing step's with the rest)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HeatStepWarning)
        warnings.simplefilter("ignore", SolverOptionWarning)
        try:
            yield
        except BaseException as exc:
            for note in run_notes(model) if model is not None else ():
                if note not in getattr(exc, "__notes__", ()):
                    exc.add_note(note)
            raise


def interface_forces(scene, tm) -> dict:
    """Normal force [N] every interface nominally carries: its area's share of the total load on
    the load faces (a pin carries the whole load; two pads of equal area half of it each)."""
    d = drive(scene, tm)
    total = sum(load_face_forces(tm, d.load, load_kind(scene)).values())
    areas = {n: tm.interface.areas[m].sum() for n, m in tm.interface.masks().items()}
    return {n: total * a / sum(areas.values()) for n, a in areas.items()}

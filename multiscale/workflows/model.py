"""The scene-to-model factory: the only code that reads a scene's sections for the macro side.

From a validated scene (``multiscale.scene``) it builds the mesh (the registered builder), the
mechanics (materials per body, the interface law, the friction rule, the load), the heat problem
(only with effect ``thermal``) and the drive (load, ramp, speed program), as plain objects for
``multiscale.macro``. The rules that more than one analysis follows live here once:

- friction coefficient: ``loading.friction`` with effect ``friction``, else 0;
- load: a fluid pressure for builders that declare ``fluid_load`` (the disc brake), else the
  scene's normal force [N] or pressure [Pa] on the builder's load faces;
- interface forces: every interface carries its area's share of the resultant of the load on the
  load faces (``interface_forces``; what the rigid datum gap and the law range start from);
- materials at an interface: the first region of each body (``interface_materials``).
"""
from __future__ import annotations

import numpy as np
from mpi4py import MPI

from multiscale.errors import InputError
from multiscale.macro import mesh as two_body
from multiscale.macro.mechanics import Mechanics, load_face_forces
from multiscale.macro.model import Drive, MacroModel
from multiscale.macro.thermal import Thermal, temperature_functions


def friction_coefficient(scene) -> float:
    """mu [-] of the sliding contact: ``loading.friction`` with effect "friction", else 0."""
    return scene.loading.friction if scene.has("friction") else 0.0


def load_kind(scene) -> str:
    """How the load acts: "fluid" (builders with ``fluid_load``), "force" or "pressure"."""
    ld = scene.loading
    if scene.geometry.spec.fluid_load:
        if ld.pressure is None:
            raise InputError("loading.pressure", None, f'builder "{scene.geometry.builder}" is loaded by a '
                             "fluid pressure on its load faces (give loading.pressure)")
        return "fluid"
    return "force" if ld.normal_force is not None else "pressure"


def drive(scene) -> Drive:
    """Load [N or Pa], ramp and speed program of body 1 (rad/s for a rotation, m/s for a translation)."""
    ld = scene.loading
    load = ld.normal_force if ld.normal_force is not None else ld.pressure
    if scene.geometry.motion == "rotation":
        return Drive(load, ld.angular_speed, ld.ramp_steps, steady=ld.speed_profile is None)
    speed = ld.sliding_speed or 0.0
    return Drive(load, lambda t: speed, ld.ramp_steps)


def interface_materials(scene) -> tuple:
    """Materials at the interface: (body 0, body 1), each body's first region."""
    return tuple(scene.materials[b.regions[0].material] for b in scene.geometry.spec.bodies)


def build_mesh(scene, comm=MPI.COMM_WORLD) -> two_body.TwoBodyMesh:
    """The scene's mesh (gmsh builder on rank 0, distributed)."""
    return two_body.build(scene.geometry.module(), dict(scene.geometry.params), comm)


def build_mechanics(scene, tm, *, law=None, temperatures=None, degree: int = 1,
                    prefix: str = "mech_") -> Mechanics:
    """Quasi-static sliding mechanics of the scene on ``tm`` (perfect-contact penalty unless ``law``;
    thermal expansion with ``temperatures``; Lagrange ``degree``)."""
    return Mechanics(tm, dict(scene.materials), stiffness=scene.interface.penalty or 0.0,
                     friction=friction_coefficient(scene), speed=drive(scene).speed(0.0), law=law,
                     temperatures=temperatures, reference_temperature=scene.time.initial_temperature,
                     load_kind=load_kind(scene), degree=degree, prefix=prefix)


def build_model(scene, comm=MPI.COMM_WORLD, *, law=None, tm=None) -> MacroModel:
    """Mesh and the problems the scene's effects ask for (no heat problem without ``thermal``).

    ``law`` optionally replaces the perfect-contact penalty law (``macro.interface.PressureLaw``);
    ``tm``: an already built mesh of the scene (e.g. the one the law's per-facet fields live on).
    """
    if not scene.has("contact"):
        raise InputError("effects", sorted(scene.effects), 'the macro model needs effect "contact"')
    tm = tm or build_mesh(scene, comm)
    t = scene.time
    T = temperature_functions(tm) if scene.has("thermal") else None
    if T is not None:
        for f in T:
            f.x.array[:] = t.initial_temperature
    mech = build_mechanics(scene, tm, law=law, temperatures=T if scene.has("expansion") else None)
    heat = None
    if T is not None:
        heat = Thermal(mech.contact, dict(scene.materials), initial_temperature=t.initial_temperature,
                       dt=t.dt / t.substeps, frictional_heat=scene.has("heat_partition"),
                       conductance=scene.has("conductance"), temperatures=T)
        if scene.has("heat_partition"):
            tm.interface.set_field(mech.contact.partition, scene.partition)
        if scene.has("conductance") and scene.interface.conductance is not None:   # else per facet later
            tm.interface.set_field(mech.contact.conductance, scene.interface.conductance)
    return MacroModel(tm, mech, heat, drive(scene))


def interface_forces(scene, tm) -> np.ndarray:
    """Normal force [N] each interface (order of ``tm.interface.tags``) nominally carries: its
    area's share of the load on the load faces (a pin carries the whole load; each pad of a brake
    the clamp force of its piston)."""
    total = sum(load_face_forces(tm, drive(scene).load, load_kind(scene)).values())
    areas = np.array([tm.interface.areas[m].sum() for m in tm.interface.masks().values()])
    return total * areas / areas.sum()

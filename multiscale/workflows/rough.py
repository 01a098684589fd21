"""The one rough-interface builder: a scene's [roughness], [micro] and [layers] -> zones -> patches
-> laws through the pool -> facet laws (``multiscale.rough.RoughInterface``), with the same rules for
the multiscale loop and the squeal analysis:

- the rough body is the stationary body 0 (zones do not move); the counter-face is flat;
- the rough interfaces are ``scene.rough_interfaces`` (all, unless [interfaces.<name>] says
  ``rough = false``: those keep the perfect-contact penalty), each planar and covered by
  ``micro.zones`` = (nx, ny) zones over the bounding box of its facets in its plane, each zone a
  patch of ``micro.grid`` = (nx, ny) cells (default ``DEFAULT_GRID``): one measured surface per
  interface (``roughness.file``: read, conditioned and made to cover the face by
  ``multiscale.micro.topography``, each step printed by rank 0; without ``micro.grid`` a
  measurement used as it is keeps its own pixel size) or one generated fractal surface per
  interface cut into zones (``patch = "face"``; cut-offs in wavelengths per face), or one
  generated patch per zone (``patch = "zone"``; per zone); the k-th interface of the geometry
  draws with seed ``seed + 7919 k`` (fractal and statistically equivalent surfaces);
  [interfaces.<name>.roughness] and [interfaces.<name>.micro] change these per interface (the
  grid per zone and the law settings must be the same on every interface: one law table, one
  post-analysis grid);
- laws by FFT-BEM (``micro.model = "fft-bem"``; the asperity models are refused), ``micro.law_points``
  nodes up to ``micro.p_max`` (default ``P_MAX_FACTOR`` x the nominal interface pressure), contact
  tolerance ``micro.tol``; the micro solid is layered with effect ``layers``;
- with effect ``plasticity`` the micro solves are elastic-perfectly plastic with the hardness of
  the softer body of the interface (``interface_hardness``): the laws at H(T0), the top node at
  most ``P_MAX_PLASTIC`` x H (no zone carries more than H).
"""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from multiscale import io
from multiscale.errors import InputError
from multiscale.micro.conduction import SeriesKernel
from multiscale.micro.kernels import HalfSpace, ThermalHalfSpace
from multiscale.micro.layered import LayeredElastic, LayeredThermal
from multiscale.micro.laws import LawSpec
from multiscale.micro.plasticity import Hardness
from multiscale.micro.surface import Surface, fractal_surface
from multiscale.micro.filters import check_cutoff
from multiscale.micro.topography import TopographyWarning, condition, cover, read_topography, zone_cells
from multiscale.micro.zones import ZoneGrid, cut_zones, generate_zones
from multiscale.pool import MicroPool
from multiscale.rough import RoughInterface, check_zone_size, interface_plane
from multiscale.scene_cycle import largest_load_factor
from multiscale.scene_rough import micro_key, rough_rules
from multiscale.scene_sections import DEFAULT_GRID, P_MAX_FACTOR, P_MAX_PLASTIC
from multiscale.workflows.model import interface_forces, interface_materials

SEED_STRIDE = 7919         # interface k draws its surfaces with seed + SEED_STRIDE k


def check_rough_scene(scene) -> None:
    """The rules every rough analysis shares (``scene_rough.rough_rules``, the first broken raised;
    the rough body, and the layers' body, is the stationary one: checked when the scene is read)."""
    broken = rough_rules(scene)
    if broken:
        raise broken[0]


def make_zones(r, m, lo, hi, seed: int, log=None, prefix: str = "roughness.",
               warned: bool = False) -> tuple[ZoneGrid, list]:
    """The zone grid over the box [lo, hi] (u, v) [m] of one interface and each zone's initial
    patch (``r``: its [roughness], ``m``: its [micro]; see module docstring; ids from 0; errors
    name ``prefix`` + the key, as the scene's check does: ``Scene.roughness_key``).
    ``log(line)`` receives the steps that made a measured surface (the warnings among them too,
    instead of Python warnings on every rank; ``warned``: the scene's check said the measured face's
    resolution warnings already, ``topography.cover``)."""
    counts = tuple(int(c) for c in m.zones)
    size = np.asarray(hi, float) - np.asarray(lo, float)
    if r.file is not None:
        return cut_zones(measured_face(r, m, counts, size, seed, log, prefix, warned), counts, origin=tuple(lo))
    cells_per_zone = m.grid or DEFAULT_GRID
    if r.patch == "face":
        cells = (counts[0] * cells_per_zone[0], counts[1] * cells_per_zone[1])
        s = fractal_surface(cells, tuple(size), r.hurst, r.k_min, r.k_max, r.rms, seed=seed)
        return cut_zones(Surface(s.heights, s.dx, s.dy, periodic=False), counts, origin=tuple(lo))
    grid = ZoneGrid(tuple(lo), counts, tuple(size / np.array(counts)))
    return grid, generate_zones(grid, tuple(cells_per_zone), r.hurst, r.k_min, r.k_max, r.rms, seed=seed)


def measured_face(r, m, counts, size, seed: int, log=None, prefix: str = "roughness.", warned: bool = False) -> Surface:
    """The face of ``size`` [m] from ``roughness.file``: read, conditioned (``roughness.detrend``,
    ``cutoff``, ``max_undefined``, ``despike``) and covering the face (``roughness.cover``), on counts x
    ``topography.zone_cells`` cells (``micro.grid``; without it 50 x 50 per zone for an equivalent
    surface, else the measurement's pixel size rounded to whole cells per zone)."""
    with warnings.catch_warnings():      # the warnings are lines of the report: printed once, not per rank
        warnings.simplefilter("ignore", TopographyWarning)
        measured = read_topography(r.file, r.channel, pixel_size=r.pixel_size, height_unit=r.height_unit,
                                   prefix=prefix)      # the scene's read, kept (read_topography)
        cells = zone_cells(m.grid, r.cover, size, counts, (measured.dx, measured.dy), DEFAULT_GRID, r.file.name)
        if r.cutoff is not None:                # as the scene's check, for a face whose extent it did not know
            check_cutoff(f"{prefix}cutoff", r.cutoff, *(size / np.multiply(counts, cells)), measured=measured.size)
        done = condition(measured, r.detrend, r.cutoff, r.max_undefined, prefix=prefix, despike=r.despike)
        surface, lines = cover(done.surface, (counts[0] * cells[0], counts[1] * cells[1]), tuple(size), r.cover,
                               seed, prefix=prefix, warn=not warned)
    known = {f"warning: {note}" for note in (*measured.notes, *done.notes)}   # the scene's warnings already
    for line in (*done.report, *lines) if log is not None else ():
        if line not in known:
            log(f"roughness: {line}")
    return surface


def contact_kernel(scene):
    """Elastic micro kernel of the rough body against the counter-face (layered with ``layers``)
    and the composite modulus E* of the macro bodies for Love's correction (Eq. 1.31)."""
    rough, counter = interface_materials(scene, scene.rough_interfaces[0])
    E_star = HalfSpace.from_materials(rough.E, rough.nu, counter.E, counter.nu).E_star
    if not scene.has("layers"):
        return HalfSpace(E_star), E_star
    L = scene.layers
    substrate = rough.E if L.base == "half-space" else np.inf
    layered = LayeredElastic(tuple(x.thickness for x in L.layer), tuple(x.E for x in L.layer),
                             tuple(x.nu for x in L.layer), substrate, rough.nu)
    return SeriesKernel(layered, HalfSpace.from_materials(counter.E, counter.nu)), E_star


def thermal_kernels(scene):
    """Steady thermal kernels (rough body, counter-face) for the zone conductance (layered with
    ``layers``: each layer's kappa on the rough body, or on an isothermal base)."""
    rough, counter = interface_materials(scene, scene.rough_interfaces[0])
    first = ThermalHalfSpace(rough.kappa)
    if scene.has("layers"):
        L = scene.layers
        if any(x.kappa is None for x in L.layer):
            raise InputError("layers.layer.kappa", None, 'every layer needs kappa with effect "conductance"')
        first = LayeredThermal(tuple(x.thickness for x in L.layer), tuple(x.kappa for x in L.layer),
                               rough.kappa if L.base == "half-space" else np.inf)
    return first, ThermalHalfSpace(counter.kappa)


def interface_hardness(scene) -> Hardness:
    """The hardness of the softer body of the rough interfaces (one material pair, see
    ``check_rough_scene``): of the side(s) with materials.<name>.hardness, the one with the lower
    value at the initial temperature (constant or its H(T) table, in K)."""
    soft = scene.softer_hardness
    if soft is None:
        raise InputError("hardness", None, 'effect "plasticity" needs materials.<name>.hardness on the rough interface')
    return Hardness(_table(scene.materials[soft].hardness))


def _table(value):
    """A scene property (a number, or rows ((K, value), ...)) as ``Hardness`` takes it."""
    return value if not isinstance(value, tuple) else tuple(zip(*value))


def build_rough_interface(scene, tm, *, progress: bool = False) -> RoughInterface:
    """Zones of every rough interface of ``tm``, the law spec and the pool (collective; laws not
    yet computed: ``RoughInterface.update_laws``)."""
    check_rough_scene(scene)
    names, planes, grids, zones = list(scene.rough_interfaces), [], [], []

    def say(line: str) -> None:     # a step as a stage line (not with --quiet: it was said), a warning always
        if "warning: " in line:
            io.reporter().warn(line.replace("warning: ", "", 1))
        else:
            io.reporter().say(line)
    log = say if tm.comm.rank == 0 else None
    for name in names:
        settings = scene.interface_settings(name)
        k = list(tm.interface.tags).index(name)
        plane, lo, hi = interface_plane(tm, name)
        grid, patches = make_zones(settings.roughness, settings.micro, lo, hi, settings.roughness.seed + SEED_STRIDE * k,
                                   log=log, prefix=f"{scene.roughness_key(name)}.",
                                   warned=name in scene.geometry.spec.interface_extents)   # by the scene's check
        check_zone_size(grid, tm.interface.areas[tm.interface.masks()[name]], name, f"{micro_key(scene, name)}.zones")
        offset = len(zones)
        planes.append(plane)
        grids.append(grid)
        zones += [replace(z, id=offset + z.id) for z in patches]
    m = scene.micro
    kernel, E_star = contact_kernel(scene)
    nominal = sum(interface_forces(scene, tm).values()) / tm.interface.areas.sum()
    p_max, hardness = m.p_max or P_MAX_FACTOR * nominal, None
    why = "micro.p_max" if m.p_max is not None else f"{P_MAX_FACTOR:g} x the nominal pressure {nominal:.4g} Pa"
    if scene.has("plasticity"):
        hardness = float(interface_hardness(scene)(scene.time.initial_temperature))
        peak = nominal * largest_load_factor(scene.loading, scene.time.end or 0.0)
        if peak >= hardness:   # as the scene's check over the interfaces' boxes for a normal force; a
            raise InputError(  # pressure only now (the laws took minutes to fail: a user trial)
                f"materials.{scene.softer_hardness}.hardness", None,
                f"{hardness:.3g} Pa at the initial temperature, at most the interfaces' nominal pressure (the load "
                f"over their area, at the load profile's largest in the run: {peak:.3g} Pa), so a zone would carry "
                "the hardness or more (fully plastic), which the micro model refuses; raise the hardness or lower the "
                "load")
        if P_MAX_PLASTIC * hardness < p_max:
            p_max, why = P_MAX_PLASTIC * hardness, f"{P_MAX_PLASTIC:g} x the hardness"
    spec = LawSpec(kernel, p_max, n_points=m.law_points, tol=m.tol, E_star=E_star, hardness=hardness)
    io.reporter().say(f"laws: {m.law_points} nodes up to p_max = {p_max:.4g} Pa ({why})")
    return RoughInterface(tm, names, planes, grids, zones, spec, MicroPool(spec, tm.comm, progress=progress))

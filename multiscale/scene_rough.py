"""The rules of a scene's rough interfaces that ``multiscale check`` applies before meshing (the
scene's cross-checks call them once the sections read; the run applies ``rough_rules`` again,
``workflows.rough.check_rough_scene``): one micro solid and one set of micro settings over the
rough interfaces, a generated surface within its grid's Nyquist index, a measured one covering its
face with a grid that resolves it, zones no smaller than the facets, and the perfect-contact keys
where an interface keeps perfect contact, with a penalty within the bodies' stiffness."""
from __future__ import annotations

import warnings

from multiscale.errors import InputError
from multiscale.micro.spectrum import power_spectrum
from multiscale.micro.filters import check_cutoff
from multiscale.micro.topography import (TopographyWarning, beyond_measurement, check_resolved, coarse_grid, condition,
                                         copy_notes, covers, read_topography, zone_cells)
from multiscale.micro.zones import THINNEST, ZoneGrid
from multiscale.scene_cycle import largest_load_factor
from multiscale.scene_sections import DEFAULT_GRID, P_MAX_FACTOR, P_MAX_PLASTIC
from multiscale.scene_values import LOAD_PRESSURE

FACET_AREA = 0.4   # median area of gmsh's interface triangles over h^2, h the size aimed at (0.37-0.43 on the demos)
SHARED_MICRO = ("grid", "law_points", "model", "p_max", "tol", "partition_law", "heating", "heating_steps",
                "remote_temperatures", "coupling", "coupling_tol", "coupling_iterations")


GENERATED = ("rms", "hurst", "k_min", "k_max", "patch")         # [roughness] keys of a generated surface
MEASURED = ("file", "channel", "pixel_size", "height_unit", "detrend", "cutoff", "max_undefined", "despike", "cover")
FILE_OWN = MEASURED[:4]                                          # ... and those that describe one file


def roughness_over(base: dict, own: dict) -> dict:
    """An interface's raw [interfaces.<name>.roughness] table ``own`` over the scene's [roughness]
    ``base``, key by key, but a surface of its own replaces the other's: with ``rms``, base's
    measured file and its keys are not taken; with ``file``, base's generated surface and the keys
    of base's file (channel, pixel_size, height_unit). Before, a pad measured beside one generated
    was refused ("give only one of rms, file"), and an x3p file given over a .npy took the .npy's
    pixel size and height unit (Sq 7.7e-14 m for 77 nm; a user trial)."""
    drop = MEASURED if "rms" in own else GENERATED + FILE_OWN if "file" in own else ()
    return {**{k: v for k, v in base.items() if k not in drop}, **own}


def own_surface_tables(root: dict) -> list[dict]:
    """The raw [interfaces.<name>.roughness] tables of a scene file ``root`` (those that are tables)."""
    tables = root.get("interfaces") if isinstance(root.get("interfaces"), dict) else {}
    return [t["roughness"] for t in tables.values() if isinstance(t, dict) and isinstance(t.get("roughness"), dict)]


def rough_rules(scene) -> list[InputError]:
    """What every rough analysis needs (each an InputError naming the key): FFT-BEM laws, a rough
    interface, a surface for each (its own or [roughness]'s), the same materials on both sides of
    every rough interface (one micro solid: a pad of another material was refused by the run only,
    after check said OK; a user trial) and the same micro settings but the zones (``SHARED_MICRO``)."""
    if not scene.has("roughness") or scene.micro is None:
        return []
    if scene.micro.model != "fft-bem":
        return [InputError("micro.model", scene.micro.model, 'the zone laws are computed by FFT-BEM: "fft-bem"')]
    if not scene.rough_interfaces:
        return [InputError("interfaces", "rough = false", 'effect "roughness" needs at least one rough interface')]
    bare = [n for n in scene.rough_interfaces if scene.interface_settings(n).roughness is None]
    if bare:                                    # ([roughness] left out: ``scene.RoughnessSection``)
        return [InputError("roughness", None, 'missing; effect "roughness" needs a surface for ' + ", ".join(
            f"interfaces.{n}" for n in bare) + ": give [roughness], or rms or file in [interfaces.<name>.roughness]")]
    out = []
    pairs = {scene.geometry.spec.interface_materials(n) for n in scene.rough_interfaces}
    if len(pairs) > 1:
        out.append(InputError("interfaces", sorted(scene.rough_interfaces), "the rough interfaces must have the same "
                              f"materials on both sides (one micro solid); found {sorted(pairs)}"))
    for name in scene.rough_interfaces:
        s = scene.interface_settings(name)
        out += [InputError(f"interfaces.{name}.micro.{key}", getattr(s.micro, key), f"must be the same on every "
                           f"interface (micro.{key} = {getattr(scene.micro, key)}); only zones may differ")
                for key in SHARED_MICRO if getattr(s.micro, key) != getattr(scene.micro, key)]
        size = scene.geometry.spec.interface_extents.get(name)     # (0.8 for 0.8 um ran to a rigid-body
        if s.roughness.rms is not None and size is not None and s.roughness.rms > max(size):   # error: a trial)
            out.append(InputError(f"{scene.roughness_key(name)}.rms", s.roughness.rms, f"an RMS height [m] below "
                                  f"the interface's width ({max(size):g} m): 0.8 um is 8e-7 or \"0.8 um\""))
    return out


PERFECT_CONTACT = {"penalty": "contact", "conductance": "conductance"}   # [interface] key: the effect it serves


def perfect_contact(scene, warnings_out: list) -> list[str]:
    """The perfect-contact keys of [interface] (``PERFECT_CONTACT``) with effect "roughness": the
    zones' laws replace them on the rough interfaces only, so the interfaces kept in perfect contact
    (``rough = false``) need them (without, such an interface had K_n = 0, no contact, or h_c = 0,
    said nowhere; found in review), and with every interface rough they are ignored (warned, into
    ``warnings_out``). A key whose effect is off is the schema's (``warn_unused``). With effect
    "wear", such interfaces wear neither body (warned: a user trial's disc lost only the rough pad's
    track, at half the rate the frictional work of both pads suggested)."""
    if not scene.has("roughness") or not scene.rough_interfaces:
        return []
    perfect = [n for n in scene.geometry.spec.interfaces if n not in scene.rough_interfaces]
    out = []
    for key, effect in PERFECT_CONTACT.items():
        given = getattr(scene.interface, key, None) is not None
        if not scene.has(effect):
            continue
        if perfect and not given:
            out.append(f'interface.{key}: missing; effect "{effect}" needs it on the interfaces in perfect contact: '
                       + ", ".join(f"interfaces.{n}.rough = false" for n in perfect))
        elif given and not perfect:
            warnings_out.append(f'interface.{key} is ignored: every interface is rough (effect "roughness") '
                                "and the zones' laws replace it")
    if scene.has("wear") and perfect:
        warnings_out.append(f'effect "wear" wears the rough zones and their tracks only: {", ".join(perfect)} (rough = '
                            "false) wear neither body, though the run's frictional_work counts their work")
    return out


STIFF_PENALTY = 1e4   # a penalty above this many times E*/h is warned about (ill-conditioned tangent)


def contact_modulus(sides) -> float:
    """E* [Pa] of two materials (constants: ``Material.at``): 1/E* = (1 - nu_0^2)/E_0 + (1 - nu_1^2)/E_1
    (Johnson 1985, Eq. 4.22)."""
    return 1.0 / sum((1.0 - m.nu ** 2) / m.E for m in sides)


def penalty_range(scene, spec, effects) -> list[str]:
    """A perfect-contact penalty K_n [Pa/m] below E*/h on an interface of ``spec`` (the
    ``GeometrySpec``) in perfect contact, E* the contact modulus of its two materials at the initial
    temperature, 1/E* = (1 - nu_0^2)/E_0 + (1 - nu_1^2)/E_1 (Johnson 1985, Eq. 4.22), and h its
    element size [m] (``GeometrySpec.interface_sizes``: the disc brake's pads at pad_mesh_size; a
    user trial): the penetration p/K_n then exceeds the elastic deflection
    p h/E* over an element, and the displacements and pressure peaks follow the penalty
    (block on flat, 4 GPa, h 2.5 mm: the top moves 2.27 um with 1e12 Pa/m, 1.27 um converged; a
    steel punch on a 21 MPa flat peaks at 3.6 MPa with 1e11 Pa/m, 5.2 MPa converged). Or above
    ``STIFF_PENALTY`` E*/h: the tangent's conditioning grows with K_n h/E*, and the contact Newton's
    linear solves failed (the coarse demo brake at 1e17 Pa/m, 4.9e5 E*/h by its mesh_size, twice
    its pads'; 1e16 ran; the pin on disc at 1e19 Pa/m, 4.7e6 E*/h; 1e17 ran), inside the plausible
    range of K_n."""
    K = scene.interface.penalty if scene.interface is not None else None
    if "contact" not in effects or K is None or scene.materials is None or scene.time is None:
        return []
    out = []
    for name in spec.interfaces:
        h = spec.interface_sizes.get(name)
        try:
            if name in scene.rough_interfaces or h is None:
                continue
            modulus = contact_modulus([scene.materials[m].at(scene.time.initial_temperature)
                                       for m in spec.interface_materials(name)])
        except (AttributeError, KeyError, StopIteration, TypeError):   # a partial scene: reported elsewhere
            continue
        if K < modulus / h:
            out.append(f"interface.penalty = {K:g} Pa/m is softer than the bodies at interface {name}: E*/h = "
                       f"{modulus / h:.3g} Pa/m (contact modulus E* = {modulus:.3g} Pa, element size h = {h:g} m), "
                       "so the penetration p/K_n exceeds their elastic deflection and the displacements and "
                       "pressure peaks follow the penalty; perfect contact needs K_n well above E*/h")
        elif K > STIFF_PENALTY * modulus / h:
            out.append(f"interface.penalty = {K:g} Pa/m is {K * h / modulus:.2g} times E*/h = {modulus / h:.3g} Pa/m "
                       f"at interface {name} (contact modulus E* = {modulus:.3g} Pa, element size h = {h:g} m): the "
                       "contact makes the stiffness matrix ill-conditioned and the Newton's linear solves may fail "
                       f"(they did from about 1e5 E*/h); at {STIFF_PENALTY:.0e} E*/h the penetration is already "
                       f"{1 / STIFF_PENALTY:.0e} of the elastic deflection")
    return out


def scene_surface_used(scene) -> bool:
    """Whether some rough interface takes [roughness]'s surface (its rms or file), not one of its own."""
    r = scene.roughness
    return r is not None and any((s.rms, s.file) == (r.rms, r.file) for s in
                                 (scene.interface_settings(n).roughness for n in scene.rough_interfaces))


def own_tables(scene, warnings_out: list) -> list[str]:
    """[interfaces.<name>.roughness] and [interfaces.<name>.micro]: a rough body other than the
    stationary one refused, as in [roughness] (it passed check), and tables no interface reads
    warned about (into ``warnings_out``): without effect "roughness", or on an interface kept in
    perfect contact (rough = false), and [roughness]'s surface where every rough interface gives its
    own. Before, all were silent (a user trial: its file's notes read as the run's)."""
    out, stationary = [], scene.geometry.bodies[0]
    r = scene.roughness
    if scene.rough_interfaces and r is not None and not scene_surface_used(scene):
        given = f"roughness.rms = {r.rms * 1e6:g} um" if r.rms is not None else f"roughness.file ({r.file.name})"
        warnings_out.append(f"{given} is not used: every rough interface gives a surface of its own"
                            + ("; the notes on its file concern no interface" if r.file is not None else ""))
    for name, own in (scene.interfaces or {}).items():
        body = own.roughness.body if own is not None and own.roughness is not None else None
        if body not in (None, stationary):
            out.append(f'interfaces.{name}.roughness.body = "{body}": the rough body must be the stationary one, '
                       f'"{stationary}" (zones do not move)')
        why = ('effect "roughness" is not in effects' if not scene.has("roughness") else
               f"interface {name} keeps perfect contact (rough = false)" if own is not None and not own.rough else "")
        warnings_out += [f"interfaces.{name}.{s} is ignored: {why}" for s in ("roughness", "micro")
                         if why and getattr(own, s, None) is not None]
    return out


def micro_constants(scene) -> list[str]:
    """Warnings of what the micro scale takes as constants: the rough interface's materials at the
    initial temperature (``workflows.model.interface_materials``: E, nu for the zone laws; kappa,
    chi, rho, c for the heat partition and flash temperatures; their tables act on the macro model
    only; H(T) and k_w(T) are taken at the micro temperatures, H(T) the softer body's at the initial
    temperature, at the rough body's), and the rough body without its layers for the heat partition
    and flash temperatures (``Heating``; only the conductance sees a layer's kappa), and at the
    softer body's hardness with layers too. Before, all
    were silent (a materials engineer's trial: a pin's kappa falling 10x over its 14 K rise left the
    partition to 5 digits)."""
    if not scene.has("roughness") or not scene.rough_interfaces or scene.materials is None:
        return []
    used = ("E", "nu") + (("kappa", "chi", "rho", "c") if scene.has("thermal") else ())
    sides = [n for n in dict.fromkeys(scene.geometry.spec.interface_materials(scene.rough_interfaces[0]))
             if n in scene.materials]
    out = []
    for name in sides:
        tables = [p for p in used if scene.materials[name].tabulated(p)]
        if tables:
            out.append(f"materials.{name}: the micro scale (zone laws, heat partition, flash temperatures) takes "
                       f"{', '.join(tables)} at the initial temperature ({scene.time.initial_temperature - 273.15:.4g} "
                       "degC), constant; the tables act on the macro model only")
    given = [n for n in sides if scene.materials[n].hardness is not None]
    if scene.has("plasticity") and given and any(scene.materials[n].tabulated("hardness") for n in given):
        soft = scene.softer_hardness
        other = [n for n in given if n != soft]
        out.append(f"materials.{soft}.hardness: the micro solves take the hardness of the body softer at the initial "
                   f"temperature, {soft}'s, at the rough body's temperatures"
                   + (f"; materials.{other[0]}.hardness is not used, even where {other[0]} is the softer"
                      if other else ""))     # (a materials engineer's trial: it was silent)
    if scene.has("layers") and scene.has("heat_partition"):
        out.append("layers: the heat partition and flash temperatures take the rough body without its layers "
                   "(its own kappa and chi); a layer's kappa acts on the conductance only")
    if scene.has("layers") and scene.has("plasticity") and scene.softer_hardness is not None:
        out.append(f"layers: the micro contact yields at materials.{scene.softer_hardness}.hardness, layers or not (a "
                   "layer has no hardness of its own: a hard coating is capped at its substrate's; a user trial)")
    return out


def nominal_pressure(scene) -> tuple[float, float] | None:
    """(The interfaces' nominal pressure [Pa] at the load profile's largest factor, that factor):
    ``loading.normal_force`` times the factor over the faces' areas where the geometry knows them all
    (``contact_area``), else over their extents' boxes, which cover them: a lower bound (a rotated
    pad's box was 1.8 times its area: a trial); None without a normal force or a box. The run
    divides by the meshed areas."""
    force = getattr(scene.loading, "normal_force", None) if scene.loading is not None else None
    spec = scene.geometry.spec if scene.geometry is not None else None
    boxes = [spec.interface_extents.get(n) for n in spec.interfaces] if spec is not None else [None]
    area = contact_area(scene)
    if not force or (None in boxes and area is None):
        return None
    factor = largest_load_factor(scene.loading, scene.time.end or 0.0)
    return factor * force / (area or sum(a * b for a, b in boxes)), factor


def pressure_range(scene) -> list[str]:
    """A warning where ``loading.normal_force`` puts the interfaces' ``nominal_pressure`` outside
    the plausible range of a pressure on a load face (``scene_values.LOAD_PRESSURE``): a force in
    the wrong unit, or a face of the wrong size (50 kN on a 6 mm pin: 1389 MPa, said by check as a
    number and warned of only when given as a pressure; a tribologist's trial)."""
    try:
        nominal = nominal_pressure(scene)
    except (AttributeError, TypeError):          # a partial scene (a refused vehicle speed): reported elsewhere
        return []
    lo, hi = LOAD_PRESSURE.plausible
    if nominal is None or nominal[0] == 0 or lo <= nominal[0] <= hi:   # (0: released throughout, warned of)
        return []
    at = f" at the load profile's largest factor {nominal[1]:.3g}" if nominal[1] != 1 else ""
    return [f"loading.normal_force = {scene.loading.normal_force:g} N is a nominal contact pressure of "
            f"{'at least ' if contact_area(scene) is None else ''}{nominal[0]:.4g} Pa on the interfaces{at}, "
            f"outside {lo:g} to {hi:g} Pa: is the force in N and the geometry in m?"]


def contact_area(scene) -> float | None:
    """The interfaces' area [m^2] before meshing, where the geometry knows every face's
    (``GeometrySpec.interface_areas``); None otherwise."""
    spec = scene.geometry.spec if scene.geometry is not None else None
    areas = [spec.interface_areas.get(n) for n in spec.interfaces] if spec is not None else [None]
    return None if None in areas else float(sum(areas))


def _over_them(scene, factor: float, nominal: float) -> str:
    """How ``nominal_pressure`` was found, at load factor ``factor``, and its value, for the messages."""
    return "loading.normal_force over them" + (f" at the load profile's largest factor {factor:.3g}"
                                               if factor != 1 else "") + \
        (f": {nominal:.3g} Pa" if contact_area(scene) else f": at least {nominal:.3g} Pa")


def default_p_max(scene) -> float | None:
    """The laws' top without ``micro.p_max`` [Pa]: ``P_MAX_FACTOR`` x the nominal pressure at load
    factor 1 (``nominal_pressure``); None where that is not known."""
    bound = nominal_pressure(scene)
    return P_MAX_FACTOR * bound[0] / bound[1] if bound is not None else None


def plastic_everywhere(scene) -> list[str]:
    """A hardness at the initial temperature at most the interfaces' ``nominal_pressure``, so that
    some zone carries H or more, which the run refuses after its set-up (check said OK: a materials
    engineer's trial; for a profile's peak, minutes later: a user trial)."""
    soft, bound = scene.softer_hardness, nominal_pressure(scene)
    if soft is None or bound is None:
        return []
    (nominal, factor), H = bound, scene.materials[soft].value("hardness", scene.time.initial_temperature)
    return [f"materials.{soft}.hardness = {H:.3g} Pa at the initial temperature: at most the interfaces' nominal "
            f"pressure ({_over_them(scene, factor, nominal)}), so a zone would carry the "
            "hardness or more (fully plastic), which the micro model refuses; raise the hardness or lower the load"] \
        if H <= nominal else []


def law_top_warnings(scene) -> list[str]:
    """A warning of zone laws whose top is at most the interfaces' ``nominal_pressure``: the zones
    then press on average beyond it, where a law is extrapolated linearly (the run warned of it only
    at its end; a user trial). The top is the run's (``workflows.rough``): ``micro.p_max`` (one for
    every rough interface), else ``P_MAX_FACTOR`` x the nominal pressure at load factor 1, and with
    plasticity at most ``P_MAX_PLASTIC`` x the softer body's hardness."""
    bound = nominal_pressure(scene) if scene.has("roughness") and scene.rough_interfaces else None
    micro = scene.interface_settings(scene.rough_interfaces[0]).micro if bound is not None else None
    if micro is None:
        return []
    (nominal, factor), soft = bound, scene.softer_hardness if scene.has("plasticity") else None
    tops = {"micro.p_max": (micro.p_max, "raise micro.p_max")} if micro.p_max is not None else \
        {f"{P_MAX_FACTOR:g} x the nominal pressure at load factor 1 (no micro.p_max)":
         (default_p_max(scene), "give micro.p_max")}
    if soft is not None:
        H = scene.materials[soft].value("hardness", scene.time.initial_temperature)
        tops[f"{P_MAX_PLASTIC:g} x materials.{soft}.hardness"] = (P_MAX_PLASTIC * H, "the zones are near fully "
                                                                  "plastic: raise the hardness or lower the load")
    what, (top, fix) = min(tops.items(), key=lambda item: item[1][0])
    if top > nominal:
        return []
    return [f"the zone laws' top, {what} = {top:.3g} Pa, is at most the interfaces' nominal pressure "
            f"({_over_them(scene, factor, nominal)}): the zones will press beyond it on "
            f"average, where a law is extrapolated linearly with the contact stiffness at its top; {fix}"]


def micro_key(scene, name: str) -> str:
    """Where interface ``name``'s micro settings are given: "interfaces.<name>.micro" or "micro"."""
    own = scene.interfaces.get(name) if scene.interfaces else None
    return f"interfaces.{name}.micro" if own is not None and own.micro is not None else "micro"


def zone_sizes(scene) -> list[str]:
    """Warnings of zones smaller than the facets an interface will likely have, ``FACET_AREA`` h^2
    for the element size h its mesh aims at (``GeometrySpec.interface_sizes``), on faces whose
    extent the geometry knows: after meshing, the run refuses zones smaller than the facets' median
    area (``rough.check_zone_size``; check said nothing before)."""
    out = []
    spec = scene.geometry.spec
    for name in scene.rough_interfaces:
        s, size, h = scene.interface_settings(name), spec.interface_extents.get(name), spec.interface_sizes.get(name)
        if size is None or h is None or s.micro is None or s.micro.zones is None:
            continue
        grid = ZoneGrid((0.0, 0.0), s.micro.zones, (size[0] / s.micro.zones[0], size[1] / s.micro.zones[1]))
        zone, facet = grid.size[0] * grid.size[1], FACET_AREA * h ** 2
        if zone < facet:
            fit = grid.counts_for(facet)
            out.append(f"{micro_key(scene, name)}.zones = {list(s.micro.zones)}: zones of {zone * 1e6:.3g} mm^2 on "
                       f"interface {name} are likely smaller than its facets (about {facet * 1e6:.3g} mm^2 for "
                       f"elements of {h * 1e3:.3g} mm), which the run refuses after meshing (a facet loads only the "
                       f"zone holding its midpoint); use at most {fit[0]} x {fit[1]} zones or a finer interface mesh")
    return out


def thin_layer(scene) -> list[str]:
    """A top layer thinner than ``zones.THINNEST`` of a micro cell (the run refuses its kernel
    after meshing; check said OK: a materials engineer's trial), for faces whose extent the
    geometry knows and whose grid the scene gives (or the default of a generated surface)."""
    if not scene.has("layers") or scene.layers is None:
        return []
    top = scene.layers.layer[0].thickness
    out = []
    for name in scene.rough_interfaces:
        s, size = scene.interface_settings(name), scene.geometry.spec.interface_extents.get(name)
        if size is None or s.micro is None or s.micro.zones is None or (s.roughness.file and not s.micro.grid):
            continue
        cell = min(L / (z * c) for L, z, c in zip(size, s.micro.zones, s.micro.grid or DEFAULT_GRID))
        if top < THINNEST * cell:
            out.append(f"layers.layer[1].thickness = {top:.3g} m: thinner than {THINNEST:g} of the micro cells of "
                       f"interface {name} ({cell:.3g} m): its kernel would take hours and gigabytes; drop the layer "
                       "(its effect is below the grid's resolution) or refine micro.grid")
    return sorted(set(out))


def nyquist(scene) -> list[str]:
    """A generated surface's k_max within the Nyquist index of the cells it is drawn on (the zone's
    micro grid, or zones x grid for patch = "face")."""
    out = []
    for name in scene.rough_interfaces:
        s = scene.interface_settings(name)
        r, m = s.roughness, s.micro
        if r is None or r.rms is None or m is None or m.zones is None:
            continue
        cells = [g * (z if r.patch == "face" else 1) for g, z in zip(m.grid or DEFAULT_GRID, m.zones)]
        if any(k > c // 2 for k, c in zip(r.k_max, cells)):
            out.append(f"{scene.roughness_key(name)}.k_max = {list(r.k_max)}: must not exceed the Nyquist index "
                       f"{[c // 2 for c in cells]} of the {'face' if r.patch == 'face' else 'zone'}'s micro grid "
                       f"of {cells} cells")
    return sorted(set(out))


def measured_cover(scene, warnings_out: list) -> list[str]:
    """A face's cells per zone taken from a measurement's pixels stay within
    ``topography.MAX_CELLS`` (``topography.zone_cells``, the run's rule), a measurement used as it
    is (``cover = "measured"``) covers its face, one drawn from (``"equivalent"``) holds a
    wavelength the face's micro grid resolves: the run's refusals (``topography.covers``,
    ``topography.check_resolved``) before meshing, for the faces whose extent the geometry knows then
    (``GeometrySpec.interface_extents``; the others are refused after meshing), and a filter
    ``cutoff`` spans 2 of its pixels and 2 micro cells (``filters.check_cutoff``); a grid too
    coarse for the measured gradient is warned about (``topography.coarse_grid``, into
    ``warnings_out``)."""
    out = []
    for name in scene.rough_interfaces:
        s, size = scene.interface_settings(name), scene.geometry.spec.interface_extents.get(name)
        r = s.roughness
        if r is None or r.file is None:
            continue
        prefix = f"{scene.roughness_key(name)}."
        try:
            with warnings.catch_warnings():        # the file's notes are the scene's warnings already
                warnings.simplefilter("ignore", TopographyWarning)
                measured = read_topography(r.file, r.channel, pixel_size=r.pixel_size, height_unit=r.height_unit,
                                           prefix=prefix)
            if r.cutoff is not None:
                check_cutoff(f"{prefix}cutoff", r.cutoff, measured.dx, measured.dy, r.file.name)
                if r.cutoff > min(measured.size):       # (8 mm on a 1.3 mm map passed without a word)
                    warnings_out.append(f"{prefix}cutoff = {r.cutoff * 1e6:.4g} um is longer than the measurement "
                                        f"({measured.size[0] * 1e6:.4g} x {measured.size[1] * 1e6:.4g} um): the "
                                        "filter takes out little more than its form")
            if size is None:
                continue
            if r.cover == "measured":     # before the cells: said with a missing micro.grid too (it was hidden)
                try:
                    covers(measured.size, size, r.cover, prefix=prefix)
                except InputError as exc:
                    out.append(str(exc))
            cells = zone_cells(s.micro.grid, r.cover, size, s.micro.zones, (measured.dx, measured.dy), DEFAULT_GRID,
                               r.file.name)
            cell = [L / (z * c) for L, z, c in zip(size, s.micro.zones, cells)]
            if r.cutoff is not None:
                try:
                    check_cutoff(f"{prefix}cutoff", r.cutoff, *cell, measured=measured.size)
                except InputError as exc:
                    out.append(str(exc))
            if r.cover == "equivalent":
                check_resolved(measured.size, [z * c for z, c in zip(s.micro.zones, cells)], size, prefix=prefix)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", TopographyWarning)
                done = condition(measured, r.detrend, r.cutoff, r.max_undefined, prefix=prefix, despike=r.despike)
            spectrum = power_spectrum(done.surface)       # one PSD for both checks
            beyond = beyond_measurement(done.surface, cell, prefix, spectrum) if r.cover == "equivalent" else None
            copies = copy_notes(done.surface.size, (done.surface.dx, done.surface.dy), size, cell, r.cover, prefix)
            warnings_out += [w for w in [coarse_grid(done.surface, cell, prefix, spectrum), beyond, *copies]
                             if w and w not in warnings_out]
        except InputError as exc:
            out.append(str(exc))
    return sorted(set(out))

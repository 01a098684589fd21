"""What ``multiscale check`` prints: the scene format (``--keys``) and a scene's summary."""
from __future__ import annotations

import json
import math
import textwrap

from multiscale.geometry import CellEstimate, estimate_cells
from multiscale.held import check_held
from multiscale.memory import DOFS_PER_CELL, HEAT_DOFS, MAP_MEMORY, MICRO_MEMORY, RUN_MEMORY, micro_memory, run_memory
from multiscale.outputs import CHECKPOINT, checkpointed
from multiscale.provenance import entries, results_of, unrecorded_results
from multiscale.scene import EFFECTS, FIG_7_9_CALIBRATION, OUTPUT_FIELDS, Scene
from multiscale.scene_friction import FRICTION, bare_interfaces
from multiscale.scene_geometry import GeometrySection, scene_spec
from multiscale.scene_rough import contact_area, default_p_max, nominal_pressure, scene_surface_used
from multiscale.scene_sections import DEFAULT_GRID, P_MAX_FACTOR, P_MAX_PLASTIC
from multiscale.errors import InputError
from multiscale.schema import Named, Section, fields_of, suggest
from multiscale.schema import reference as schema_reference


def reference() -> list[str]:
    """The scene format: effects, then every section and key (``multiscale check --keys``)."""
    effects = [f"  {name:<15} {e.doc}" + (f"  (needs {', '.join(e.requires)})" if e.requires else "")
               for name, e in EFFECTS.items()]
    fields = [f"  {name:<18} needs {', '.join(needs) or 'nothing'}" for name, needs in OUTPUT_FIELDS.items()]
    return (["Scene file (TOML). Values: SI numbers or unit strings (\"4 GPa\", \"200 rpm\", \"20 degC\").",
             "What a table's keys do: multiscale check --keys TABLE (e.g. loading, materials, roughness).",
             "", "effects:"] + effects + ["", "output.fields:"] + fields + ["", "top level:"]
            + schema_reference(Scene))



def tables(cls=Scene, path: str = "") -> dict:
    """{dotted path of every table of the scene format ("loading.vehicle"): (its parser, that path,
    the path its keys are shown under: "materials.<name>")}."""
    out = {}
    for name, spec in fields_of(cls):
        if isinstance(spec.parser, Section):
            where = f"{path}.{name}" if path else name
            shown = where + (".<name>" if isinstance(spec.parser, Named) else "")
            out[where] = (spec.parser, where, shown)
            out.update(tables(getattr(spec.parser, "key_schema", spec.parser.cls), shown))
    return out


def table_reference(name: str) -> list[str]:
    """One table of the scene format with what its keys do (``multiscale check --keys loading``):
    its text (the dataclass' docstring, the scene reference page's), then its keys as ``reference``
    lists them. ``name``: a dotted table path, brackets allowed ("[loading]"); InputError otherwise."""
    known = tables()
    key = name.strip().strip("[]").replace(".<name>", "").lower()
    if key not in known:
        parent, _, leaf = key.rpartition(".")
        if parent in known and leaf in dict(fields_of(known[parent][0].cls)):      # (a key: a trial was offered
            raise InputError("--keys", name, f"a key of [{known[parent][2]}]: multiscale check --keys {parent}")  # a table)
        raise InputError("--keys", name, "not a table of the scene format" + suggest(key, known)
                         + f"; the tables: {', '.join(known)}")
    parser, where, shown = known[key]
    doc = " ".join(((GeometrySection if isinstance(parser, GeometrySection) else parser.cls).__doc__ or "").split())
    doc = doc.replace("``", "").removeprefix(f"[{shown}]: ")
    text = textwrap.fill(doc, 100, initial_indent="  ", subsequent_indent="  ")
    keys = parser.reference(where) if hasattr(parser, "reference") else schema_reference(parser.cls, shown)
    return [f"[{shown}]", text, ""] + keys


def _toml(value) -> str:
    """A value as a TOML file would have it (numbers short: 2e+13)."""
    return f"{value:g}" if isinstance(value, float) else json.dumps(value)


def _axis(axis) -> str:
    """An axis as given: "[0, 0, -1]"."""
    return "[" + ", ".join(f"{float(a) + 0.0:g}" for a in axis) + "]"


def summary(scene: Scene) -> list[str]:
    """A few lines: bodies, effects, loading, time, output — what a run would compute."""
    g, ld, t, o = scene.geometry, scene.loading, scene.time, scene.output
    params = g.resolved()
    bodies = " | ".join(f"{b.name} ({', '.join(f'{r.name}: {r.material}' for r in b.regions)})"
                        for b in g.spec.bodies)
    sizes = ", ".join(f"{k} {params[k] * 1e3:g} mm" for k in params if k.endswith("mesh_size"))
    source = f"file {g.params.file.name}" if g.builder == "file" else g.builder
    lines = [f"scene {scene.name}" + (f" ({scene.source})" if scene.source else ""),
             *([f"  set       {', '.join(f'{k} = {_toml(v)}' for k, v in scene.overrides)}"] if scene.overrides else []),
             f"  geometry  {source}, {g.motion} of {g.bodies[1]}" + (f" about {_axis(g.spec.motion.axis)}"
                                                                  if g.motion == "rotation" else "")
             + (f"; {sizes}" if sizes else ""),
             *(f"            {line}" for line in g.spec.report),
             f"  bodies    {bodies}",
             *(f"  material  {name}: {_material(m)}" for name, m in scene.materials.items()),
             f"  effects   {', '.join(e for e in EFFECTS if e in scene.effects)}"]
    for effect in EFFECTS:
        if scene.has(effect):
            lines.append(f"    {effect:<15}{_effect_line(scene, effect)}")
    v = ld.vehicle
    load_text = (f"{ld.normal_force:g} N" if ld.normal_force is not None else
                 f"{ld.pressure / 1e6:g} MPa" if ld.pressure is not None else
                 f"braking torque {ld.braking_torque:g} N m" if ld.braking_torque is not None else
                 f"braking {v.mass:g} kg" if v is not None and v.mass is not None else "none")
    motion = (f"{ld.rotation_speed * 30 / math.pi:g} rpm" if ld.rotation_speed is not None else
              f"speed profile of {len(ld.speed_profile)} points (up to {max(w for _, w in ld.speed_profile) * 30 / math.pi:.4g} "
              "rpm)" if ld.speed_profile is not None else
              (f"a stop from {v.speed * 3.6:g} km/h in {v.stop_time:.3g} s" if v.deceleration else
               f"a drag at {v.speed * 3.6:g} km/h") + f" (wheel radius {v.wheel_radius * 1e3:g} mm)"
              if v is not None else f"{ld.sliding_speed:g} m/s" if ld.sliding_speed is not None else "no sliding")
    where = _load_faces(scene)
    profile = f", load profile of {len(ld.load_profile)} points" if ld.load_profile else ""
    lines.append(f"  loading   {load_text}{where}, {motion}{profile}, {ld.ramp_steps} ramp step(s)")
    if (bound := nominal_pressure(scene)) is not None:      # (an engineer's first number: said nowhere, a trial)
        at = f" at the load profile's largest factor {bound[1]:.3g}" if bound[1] != 1 else ""
        area = contact_area(scene)
        over = f"the force over the interfaces' {area * 1e6:.6g} mm^2" if area else \
            "at least: the force over the boxes around the interfaces"      # (said as the pressure: a trial)
        lines.append(f"            nominal contact pressure {bound[0] / 1e6:.4g} MPa{at} ({over}; the run divides "
                     "by their meshed areas)")
    if v is not None and ld.torque is not None and ld.braking_torque is None:   # (said nowhere before: a user trial)
        force = "m a" if v.deceleration else f"m g sin(atan {v.slope:g})"
        lines.append(f"            braking torque {ld.torque:.4g} N m at the {g.bodies[1]}: braking force {force} = "
                     f"{v.braking_force:.4g} N x wheel radius; the clamp force that gives it (mu F r on each "
                     "interface) is found and said by the run")
    end = scene.time.end if scene.has("thermal") or scene.has("wear") else None
    if ld.torque is not None and end and g.motion == "rotation":     # the heat the run must account for
        work = ld.torque * ld.mean_sliding_factor(0.0, end) * end      # torque x load factor x angle, to time.end
        heat = "the frictional heat of the run" if scene.has("heat_partition") else \
            'no heat enters the bodies without effect "heat_partition"'   # (it said both; a user trial)
        lines.append(f"            braking work to time.end: {work / 1e3:.6g} kJ ({heat})")
    for name in g.spec.interfaces:
        if name in scene.interfaces or len(g.spec.interfaces) > 1:
            s = scene.interface_settings(name)
            kind = "rough" if name in (scene.rough_interfaces if scene.has("roughness") else ()) else "perfect contact"
            mu = "" if not scene.has("friction") else f", mu = {s.friction:g}" if s.friction is not None else \
                f", mu(T) {_fade(s.friction_temperature)}" if s.friction_temperature is not None else ""
            own, extra = scene.interfaces.get(name), []
            if kind == "rough" and own is not None:        # its own surface and zones (before: said nowhere)
                extra += [f"its own surface: {_surface(s.roughness)}"] if own.roughness is not None else []
                extra += [f"its own {s.micro.zones[0]} x {s.micro.zones[1]} zones"] if own.micro is not None else []
            lines.append(f"  interface {name}: {kind}{mu}" + (f" ({'; '.join(extra)})" if extra else ""))
    for b in scene.boundary:
        what = [f"fix {''.join(b.fix)}" if b.fix else "",
                "convection h(speed)" if isinstance(b.convection, tuple) else
                f"convection h = {b.convection:g} W/(m^2 K)" if b.convection is not None else "",
                f"radiation eps = {b.emissivity:g}" if b.emissivity is not None else "",
                f"T = {b.temperature - 273.15:g} degC" if b.temperature is not None else ""]
        lines.append(f"  boundary  {', '.join(b.surfaces)}: {'; '.join(w for w in what if w)}")
    if t.end is not None:
        lines.append(f"  time      {t.end:g} s in {t.steps} step(s) of {t.dt:g} s x {t.substeps} substep(s); "
                     f"T0 = {t.initial_temperature - 273.15:g} degC")
    lines.append(f"  output    {o.folder} every {o.every} step(s): {', '.join(o.fields)}")
    names = scene.earlier_results()
    if names:
        earlier = len(set(names) & set(results_of(o.folder)))
        own = unrecorded_results(scene, names)
        lines.append(f"  note      the output folder already holds {entries(len(names))}: run needs --overwrite "
                     f"(deletes the {earlier} the run before wrote)"
                     + (" or --resume" if checkpointed(scene) and CHECKPOINT in names else "")
                     + (f"; it refuses to write over {', '.join(own)}, not written by a run" if own else ""))
    lines += [f"  warning   {w}" for w in scene.warnings]
    return lines


MATERIAL_UNITS = {"E": (1e9, "GPa"), "nu": (1, ""), "rho": (1, "kg/m^3"), "kappa": (1, "W/(m K)"),
                  "c": (1, "J/(kg K)"), "chi": (1, "m^2/s"), "alpha": (1, "1/K"), "k_w": (1, "1/Pa"),
                  "hardness": (1e9, "GPa"), "loss_factor": (1, ""), "damping_alpha": (1, "1/s"),
                  "damping_beta": (1, "s")}


def _load_faces(scene: Scene) -> str:
    """Where the load acts, for the loading line: the faces given, or the builder's; a pressure's
    force on each where the builder knows their areas (a pin-on-disc's 0.375 MPa acts on the
    holder plate's ends, 90 N, not on the pin's 400 mm^2: said nowhere before, a user trial)."""
    ld, spec = scene.loading, scene.geometry.spec
    faces = ld.faces or spec.load_faces
    if ld.normal_force is not None and ld.faces and len(ld.faces) > 1:   # (read as each pad's clamp force)
        return f" in all on {', '.join(ld.faces)}, shared by their areas"
    if ld.pressure is None or not all(f in spec.load_areas for f in faces):
        return f" on {', '.join(faces)}" if faces else ""
    return " on " + ", ".join(f"{f} ({spec.load_areas[f] * 1e6:.4g} mm^2): {ld.pressure * spec.load_areas[f]:.4g} N"
                              for f in faces)


def _material(m) -> str:
    """A material's given properties in words: "E 110 GPa, nu 0.26, kappa(T) 3 rows ..."."""
    given = [(k, getattr(m, k)) for k in MATERIAL_UNITS if getattr(m, k) is not None]
    return ", ".join(f"{k}(T) {len(v)} rows" if isinstance(v, tuple) else
                     f"{k} {v / MATERIAL_UNITS[k][0]:.4g}" + (f" {MATERIAL_UNITS[k][1]}" if MATERIAL_UNITS[k][1] else "")
                     for k, v in given)


def _fade(table) -> str:
    """A fade table in words: "0.42 at 100 degC, 0.3 at 400 degC"."""
    return ", ".join(f"{mu:g} at {T - 273.15:g} degC" for T, mu in table)


def _own_friction(scene: Scene, name: str) -> str:
    """" (its own on a, b)": the interfaces whose friction is not [loading]'s ``name`` key's (a mu(v)
    law's: those with a friction of their own)."""
    names = scene.geometry.spec.interfaces
    own = [n for n in names if n not in bare_interfaces(scene.interfaces, names)] if name in FRICTION[2:] else \
        [n for n in names if getattr(scene.interface_settings(n), name) != getattr(scene.loading, name)]
    return f" (its own on {', '.join(own)})" if own else ""


def _effect_line(scene: Scene, effect: str) -> str:
    i, ld = scene.interface, scene.loading
    if effect == "contact":
        return _rough_or_perfect(scene, "rough per-zone laws", "penalty K_n = {:g} Pa/m", i.penalty)
    if effect == "friction":
        if ld.friction_curve is not None:
            return "mu(slip speed) from friction_curve: " + ", ".join(f"{mu:g} at {v:g} m/s"
                                                                      for v, mu in ld.friction_curve) \
                + _own_friction(scene, "friction_curve")
        if ld.friction_temperature is not None:
            return "Coulomb, mu(interface temperature) from friction_temperature: " + _fade(ld.friction_temperature) \
                + _own_friction(scene, "friction_temperature")
        if ld.stribeck is not None:
            st = ld.stribeck
            return (f"Stribeck mu(v) = {st.kinetic:g} + ({st.static:g} - {st.kinetic:g}) exp(-(v / {st.speed:g} m/s)"
                    f"^{st.exponent:g})" + _own_friction(scene, "stribeck"))
        if ld.friction is None:
            return "Coulomb, mu per interface"
        return f"Coulomb, mu = {ld.friction:g}" + _own_friction(scene, "friction")
    if effect == "thermal":
        return f"transient conduction in {', '.join(scene.bodies)}"
    if effect == "stability" and scene.stability is not None:   # (the band and count said nowhere: a user trial)
        st = scene.stability
        target = f"{st.target:g} Hz" if st.target is not None else "its lower edge"
        sw, line = st.sweep, (f"complex eigenvalues at the sliding state: {st.modes} mode(s) in {st.band[0]:g} to "
                              f"{st.band[1]:g} Hz, nearest {target} first")
        if sw is None or sw.parameter is None:
            return line
        each = sw.preload_mode == "each"        # what the map costs (said nowhere: 214 s for a 20 s analysis, a trial)
        cost = (f"each point preloaded and solved: {len(sw.values) + 1} analyses"
                + (f" and up to {sw.refine_steps} more per onset found" if sw.onsets and sw.refine_steps else "")
                if each else "its points projected on the undamped modes of the first and last: 2 eigen solves more")
        return f"{line}; then a stability map over {sw.parameter}, {len(sw.values)} points: {cost}"
    if effect == "heat_partition" and scene.has("roughness") and scene.micro.partition_law:
        m = scene.micro
        heating = f"transient, N_t = {m.heating_steps}" if m.heating == "transient" else "steady"
        return (f"micro partition per zone ({heating} heating, remote temperatures: {m.remote(scene.effects)}, "
                f"{m.coupling_scheme(scene.effects)} coupling; "
                + ("the effusivity share weighted by the areas" if i.partition == "effusivity" else
                   f"{scene.partition:.3g}") + " before the first)")
    if effect == "heat_partition":
        if i.partition != "effusivity":
            return f"share {scene.partition:.3g} of mu p |v| into the {scene.bodies[0]}"
        names = scene.geometry.spec.interfaces
        shares = {n: f"{scene.partition_at(n):.3g}" for n in names}      # at equal areas
        share = ", ".join(f"{v} at {n}" for n, v in shares.items()) if len(set(shares.values())) > 1 else \
            f"{scene.partition:.3g}"           # the effusivity ratio per pair of materials
        if scene.geometry.motion != "rotation":
            return f"share {share} (effusivity) of mu p |v| into the {scene.bodies[0]}"
        return (f"effusivity share of mu p |v| into the {scene.bodies[0]}: {share} at equal areas, weighted at "
                f"meshing by the {scene.bodies[0]}'s face against the track it sweeps on the {scene.bodies[1]} "
                "(interfaces on one track share it by their areas)")
    if effect == "conductance":
        return _rough_or_perfect(scene, "h_c(p) per zone (micro)", "h_c = {:g} W/(m^2 K)", i.conductance)
    if effect == "roughness":
        r, m = scene.interface_settings(scene.rough_interfaces[0]).roughness, scene.micro
        surface = _surface(scene.roughness) if scene_surface_used(scene) else "each interface its own surface"
        measured_pixels = r.file is not None and r.cover != "equivalent"
        cells = f"{m.grid[0]} x {m.grid[1]} cells" if m.grid else \
            "the measurement's pixel size" if measured_pixels else "50 x 50 cells"
        least = default_p_max(scene) if m.p_max is None else None     # (its number unsaid before: a user trial)
        about = "" if contact_area(scene) else "at least "              # (over the faces' boxes: a lower bound)
        top = f"{m.p_max:g} Pa" if m.p_max is not None else f"{P_MAX_FACTOR:g} x the nominal pressure" + (
            f" ({about}{least:.3g} Pa)" if least is not None else "")
        if scene.has("plasticity"):
            top += f", at most {P_MAX_PLASTIC:g} x the hardness"     # (check said 3e7 Pa, the run used 9e6)
        top += "" if m.p_max is not None and not scene.has("plasticity") else " (the run prints it)"
        return (f"{r.body or scene.bodies[0]}: {surface}; {m.zones[0]} x {m.zones[1]} zones of {cells}, "
                f"{m.law_points}-point laws up to p_max {top}")
    if effect == "wear":
        w = scene.wear
        counter = scene.materials[scene.geometry.spec.interface_materials(
            scene.rough_interfaces[0] if scene.rough_interfaces else None)[1]]
        named = {"k_w": "k_w = {:g} 1/Pa", "k_w_table": "k_w(T) table", "specific_rate": "k = {:g} 1/Pa ({:.4g} "
                 "mm^3/(N m))", "specific_rate_table": "k(T) table"}        # (a tribologist's unit too: a trial)
        constant = w.given in ("k_w", "specific_rate")           # (a table's format took rate * 1e9: check failed)
        rate = "k_w of its material" if scene.rough_material_wears else named[w.given].format(
            *((w.rate, w.rate * 1e9) if constant else ())) if w.given else f"k_w(T) default table: {FIG_7_9_CALIBRATION}"
        both = f"; the {scene.bodies[1]} wears too (k_w of its material)" if counter.k_w is not None else ""
        law = "k p ds" if w.per_load and not scene.rough_material_wears else "k_w mu p ds"
        if not constant or scene.rough_material_wears:                         # a table (or the material's)
            law += (", a table's T each face's macro temperature" if w.temperature == "macro" or not
                    scene.has("roughness") else ", a table's T the rough surface's local one, macro + flash") + \
                " (wear.temperature),"
        increments = f"in {w.substeps} increment(s)" if scene.has("roughness") else \
            "per interface facet (perfect contact: its gap opens), linearly implicit where it would not be stable"
        end = f"{w.limit * 1e3:.4g} mm are left behind a facet" if w.limit else "a worn part is worn through"
        return (f"Archard dh = {law} every {w.update_every} step(s) {increments}{both}; "
                f"{rate} (k_w per frictional work, k per normal load: a specific wear rate k is k_w = k/mu); "
                f"the run ends once {end} (wear.limit)")

    return EFFECTS[effect].doc


def cells_line(scene: Scene) -> tuple[str, CellEstimate]:
    """The mesh's estimated cell count against its limit (``check --cells``; runs gmsh trials),
    and the estimate; an InputError if the trial mesh leaves a part free (``held.check_held``)."""
    g = scene.geometry
    params = g.params if g.builder == "file" else dict(g.params)
    bodies = [[r.tag for r in b.regions] for b in g.spec.bodies]
    spec, sliding = scene_spec(scene), scene.has("friction")

    def held(model):            # the run's check at meshing (an InputError naming a part nothing holds)
        check_held(model, spec, sliding)
    e = estimate_cells(g.module(), params, length_scale=g.spec.length_scale, bodies=bodies, inspect=held)
    if not e.exact and e.cells > g.max_cells:          # the run's verdict: it refines near the limit
        e = estimate_cells(g.module(), params, enough=g.max_cells, length_scale=g.spec.length_scale, bodies=bodies)
    how = "exact" if e.exact else f"from a trial mesh {e.factor:.3g}x coarser with {e.trial} cells"
    verdict = "refused by run" if e.cells > g.max_cells else "within"
    return (f"  mesh      {'' if e.exact else 'about '}{e.cells:,} cells ({how}); {verdict} geometry.max_cells = "
            f"{g.max_cells:,}", e)


def modes_problem(scene: Scene, mesh: CellEstimate) -> str | None:
    """What the squeal run would refuse of ``stability.modes`` on the estimated ``mesh``: more modes
    than its displacement dofs (quadratic: three a vertex and an edge; the run said it after meshing
    and the preload, and check had estimated 440 GB for them: a user trial); None if nothing."""
    modes = scene.stability.modes if scene.has("stability") else None
    dofs = 3 * (mesh.nodes + mesh.edges)
    if modes is None or not mesh.nodes or modes <= dofs:
        return None
    return (f"stability.modes = {modes}: more than the model's {'' if mesh.exact else 'about '}{dofs:,} displacement "
            "dofs on this mesh: the run refuses it; ask fewer (a cap: the band's modes are found up to it)")


def linear_heat(scene: Scene) -> bool:
    """Whether a run's heat problem is linear, as ``macro.thermal`` decides it: no radiation, the
    bodies' rho, c, kappa and chi constants, not tables (its LU factors are then double precision)."""
    names = {r.material for b in scene.geometry.spec.bodies for r in b.regions}
    return not any(b.emissivity is not None for b in scene.boundary) and not any(
        isinstance(getattr(scene.materials[n], k), tuple) for n in names if n in scene.materials
        for k in ("rho", "c", "kappa", "chi"))


def memory_line(scene: Scene, mesh: CellEstimate) -> tuple[str, float]:
    """The estimated peak memory of a serial run of the scene's estimated ``mesh`` (``memory.run_memory``
    of its displacement dofs: quadratic for a squeal run, three a vertex and an edge, linear
    otherwise, three a vertex; ``DOFS_PER_CELL`` a cell where its vertices were not counted; with
    heat ``HEAT_DOFS`` temperature dofs a displacement dof, their problem ``linear_heat`` or not; a
    multiscale run adds its zones' ``memory.micro_memory``: it was left out, 0.41 GB said for
    0.55-1.75 GB measured, a user trial), and that memory [bytes]."""
    kind = "squeal" if scene.has("stability") else "transient"
    dofs = 3 * (mesh.nodes + mesh.edges * (kind == "squeal")) if mesh.nodes else DOFS_PER_CELL[kind] * mesh.cells
    heat = HEAT_DOFS * dofs if kind == "transient" and scene.has("thermal") else 0.0
    sweep = scene.stability.sweep.preload_mode if kind == "squeal" and scene.stability.sweep else None
    linear = linear_heat(scene)
    need = run_memory(dofs, kind, modes=scene.stability.modes if kind == "squeal" else 0, heat_dofs=heat,
                      linear_heat=linear, sweep=sweep)
    each = RUN_MEMORY[kind][0] * MAP_MEMORY.get(sweep, 1.0)
    counted = f"{dofs:,.0f} displacement dofs" + (f", {heat:,.0f} temperature dofs" + (
        " (a linear heat problem: double-precision factors)" if linear else "") if heat else "")
    micro = ""
    if scene.rough_interfaces and kind == "transient":
        kind, own = "multiscale", [scene.interface_settings(n) for n in scene.rough_interfaces]
        if any(s.roughness.file and not s.micro.grid for s in own):   # (of each interface: the shared ones were)
            micro = "; its zones not counted: their grid is the measured file's pixels, give micro.grid"
        else:
            points = sum(math.prod(s.micro.zones) * math.prod(s.micro.grid or DEFAULT_GRID) for s in own)
            need, each = need + micro_memory(points), each + MICRO_MEMORY[0]
            micro = f"; its zones {points:,} grid points"
    kind += " map" * bool(sweep)
    return (f"  memory    about {need / 1e9:.2g} GB at the peak of a {kind} run on one rank, each more adding about "
            f"{each / 1e9:.2g} GB (about {counted}{micro}; an estimate from measured runs, "
            "docs/performance.rst)", need)


def _rough_or_perfect(scene: Scene, rough: str, perfect: str, value: float) -> str:
    """An interface effect's line: ``rough`` without perfect-contact interfaces, ``perfect`` (a
    format of the [interface] ``value``) without rough ones, else each with its interfaces."""
    laws = scene.rough_interfaces
    kept = [n for n in scene.geometry.spec.interfaces if n not in laws]
    if not laws or not kept:
        return rough if laws else perfect.format(value)
    return f"{rough} on {', '.join(laws)}; {perfect.format(value)} on {', '.join(kept)}"


def _surface(r) -> str:
    """A rough surface in words: generated (RMS, H; with patch "zone" its wavelengths per zone, which
    micro.zones changes: a trial's real area 0.0081 against 0.0057 m^2 at 2 x 2 and 4 x 4 zones) or
    measured (file, cover)."""
    per_zone = f", wavelengths from 1/{list(r.k_min)} to 1/{list(r.k_max)} of a zone (patch = \"zone\": micro.zones " \
        "changes the surface)" if r.rms is not None and r.patch == "zone" else ""
    return f"RMS {r.rms * 1e6:g} um, H {r.hurst:g}{per_zone}" if r.rms is not None else \
        f"file {r.file.name} ({r.cover}" + (f", seed {r.seed})" if r.cover == "equivalent" else ")")

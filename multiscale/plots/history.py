"""Figures of a run's history (``history.h5``): the macro quantities, both scales of the multiscale
loop (thesis ch. 7) and the wear map.

``history_figure``: interface force, max contact pressure, max temperatures and the heat of each body
(into it, stored in it, lost by it) against time; with several interfaces each one's frictional heat
and the hottest facet of each face, with a body of several parts each part's stored heat (two rows
of panels then). ``multiscale_figure``: max contact pressure macro (facets,
zones) vs micro (Fig. 7.14; log scale, linear with a note if no row has contact), max temperature
macro vs micro (Fig. 7.15), heat partition min/mean/max (Fig. 7.12), wear volume (Fig. 7.16), max
wear depth (Fig. 7.17), RMS of the worn surface (Fig. 7.18), the real contact area (each rough
interface's too) and the largest plastic share of a zone — the panels whose columns the history
has. ``wear_map``: the mean wear depth of every zone over the interface (Fig. 7.13) beside the
micro wear depth field of the whole face (blank off the face; the zones' edges, isolated patches'
edges, wear the most: docs/results.rst).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

LEGEND_ROWS = 6                 # entries in a legend column before it takes another
BODY_STYLES = ("-", "--", ":", "-.")


def column_label(key: str) -> str:
    """Legend of a per-body or per-interface column: max_temperature_outer_pad -> "outer pad",
    max_temperature_pin_in_disc -> "pin, disc material" (the pin's cells of material disc),
    max_temperature_fixed_part_inner_pad -> "inner pad" (a part of body fixed),
    face_max_temperature_inner_pad_on_disc -> "inner pad on disc" (the disc's face of interface
    inner_pad), friction_coefficient_inner_pad -> "inner pad" (friction_coefficient: "all interfaces",
    as in multiscale.png: "all" clashed with an interface of that name)."""
    if key == "friction_coefficient":
        return "all interfaces"
    if key.startswith("probe_temperature_"):          # a probe's own name, whole
        return key.removeprefix("probe_temperature_").replace("_", " ")
    face = key.startswith("face_max_temperature_")
    if key in ("wear_max_depth", "counter_wear_max_depth"):
        return "body 1's track" if key.startswith("counter") else "body 0"
    for prefix in ("max_temperature_", "heat_total_", "heat_conducted_total_", "stored_heat_", "heat_lost_total_",
                   "frictional_heat_total_", "face_max_temperature_", "friction_coefficient_", "wear_volume_",
                   "wear_remaining_min_"):
        key = key.removeprefix(prefix)
    key = key.partition("_part_")[2] or key
    words = lambda name: name.replace("_", " ")
    if face:                      # (split at "_in_" first: "padA_in_on_fixed" was "padA, on fixed material", a trial)
        interface, _, body = key.rpartition("_on_")
        return f"{words(interface)} on {words(body)}"
    body, within, material = key.rpartition("_in_")
    return f"{words(body)}, {words(material)} material" if within else words(key)


def temperature_columns(columns) -> list[str]:
    """The max-temperature columns to draw: per body, or for a body of several parts per part
    (max_temperature_fixed_part_inner_pad, ...; a brake's pads), else per material for a body of
    several materials (max_temperature_pin_in_pin, ..._pin_in_disc). A body's whole-body column is
    the highest of those and would hide under one of them; its materials' under its parts'."""
    hot = [k for k in columns if k.startswith("max_temperature")]
    parted = {k.partition("_part_")[0] for k in hot if "_part_" in k}
    return [k for k in hot if k not in parted and k.partition("_in_")[0] not in parted
            and not any(j.startswith(k + "_in_") for j in hot)]


# the heat of a body by what it is (heat_total_<body> etc.): its word in the legend, in this order
HEAT_KINDS = {"heat_total_": "into", "heat_conducted_total_": "conducted in", "stored_heat_": "stored",
              "heat_lost_total_": "lost"}


def curve_pairs(keys) -> list | None:
    """(colour, line style) names of a panel's columns drawn by two properties, or None: faces
    (face_max_temperature_<interface>_on_<body>: a colour per interface, a style per body) or the
    heat of bodies (heat_total_, heat_conducted_total_, stored_heat_, heat_lost_total_ <body>: a colour
    per body, a style per kind, if there are several kinds)."""
    if all(k.startswith("face_max_temperature_") for k in keys):
        return [(pad, f"on {body}") for pad, _, body in (column_label(k).rpartition(" on ") for k in keys)]
    kinds = [next((word for prefix, word in HEAT_KINDS.items() if k.startswith(prefix)), None) for k in keys]
    if all(kinds) and len(set(kinds)) > 1:
        return [(column_label(k), kind) for k, kind in zip(keys, kinds)]
    return None


def colours(names) -> dict:
    """A distinct colour per name, in order: tab10, tab20 beyond 10 names (tab10 repeats its
    colours), turbo beyond 20."""
    names = list(names)
    cmap = colormaps["tab10" if len(names) <= 10 else "tab20" if len(names) <= 20 else "turbo"]
    return {n: cmap(k if len(names) <= 20 else k / (len(names) - 1)) for k, n in enumerate(names)}


def body_colours(columns) -> dict:
    """One colour per body and part name of a history, for every panel of ``history_figure`` and
    ``multiscale_figure``: in the order of the max-temperature panel's curves, then the other
    bodies and parts, then the interfaces (each panel numbered its own before: the pin was green,
    orange and orange in three panels of one figure, and a pad orange in one panel and red in the
    next; user trials)."""
    names = [column_label(k) for k in temperature_columns(columns)]
    names += [column_label(k) for k in columns if k.startswith("heat_total_")
              or k.startswith("stored_heat_") and "_part_" in k]
    # the interfaces (a pad's own colour where it is named as its part), all of them together black
    names += [column_label(k).rpartition(" on ")[0] or column_label(k) for k in columns
              if k.startswith(("friction_coefficient_", "frictional_heat_total_", "face_max_temperature_"))]
    return colours(dict.fromkeys(names)) | {"all interfaces": (0.0, 0.0, 0.0, 1.0)}


def curve_styles(keys, palette: dict | None = None) -> tuple[list[dict], list]:
    """The colour and line style of each column of a panel, and its legend's entries (a Line2D
    each): a colour per column, or for ``curve_pairs`` a colour and a line style by its two names,
    each named once (9 pads on 2 bodies: 11 entries, and no two curves alike). The colours are
    ``palette``'s where it names every curve (``body_colours``), else the panel's own."""
    pairs = curve_pairs(keys) if len(keys) > 1 else None
    names = list(dict.fromkeys(n for n, _ in pairs)) if pairs else [column_label(k) for k in keys]
    kinds = list(dict.fromkeys(k for _, k in pairs)) if pairs else []
    colour = palette if palette and all(n in palette for n in names) else colours(names)
    style = {b: BODY_STYLES[k % len(BODY_STYLES)] for k, b in enumerate(kinds)}
    if not pairs:
        return [{"color": colour[n], "ls": "-"} for n in names], []
    entries = [Line2D([], [], color=colour[n], label=n) for n in names]
    entries += [Line2D([], [], color="0.4", ls=style[b], label=b) for b in kinds]
    return [{"color": colour[n], "ls": style[b]} for n, b in pairs], entries


def history_figure(history, path: Path, title: str = "") -> Path:
    """PNG of the history: force, max pressure, the speed, max temperatures, heat per body (and the friction
    coefficient with fade or mu(v), the slip speeds with mu(v), the braking torque of a rotating body, the probes'
    temperatures, per interface, max face temperatures, stored heat per part, the worn volume and depth) vs time."""
    t = history["time"]
    bodies = [k.removeprefix("heat_total_") for k in history.columns if k.startswith("heat_total_")]
    heat = [prefix + b for b in bodies for prefix in HEAT_KINDS if prefix + b in history.columns]
    groups = [("interface force [N]", ["interface_force"], 1.0, 0.0),
              ("max contact pressure [MPa]", ["max_pressure"], 1e-6, 0.0),
              ("friction coefficient [-]", [k for k in history.columns if k.startswith("friction_coefficient")],
               1.0, 0.0),                                                          # with fade (and per interface)
              ("rotation speed [rpm]", ["angular_speed"], 30 / np.pi, 0.0),     # the cycle (drawn nowhere: a trial)
              ("sliding speed [m/s]", ["sliding_speed"], 1.0, 0.0),
              ("slip speed in contact [m/s]", ["max_slip_speed", "min_slip_speed"], 1.0, 0.0),      # with mu(v)
              ("braking torque [N m]", ["friction_moment"], 1.0, 0.0),    # a rotating body's (wanted: a trial)
              ("max temperature [°C]", temperature_columns(history.columns), 1.0, -273.15),
              ("probe temperature [°C]", [k for k in history.columns if k.startswith("probe_temperature_")],
               1.0, -273.15),                                                     # thermocouples (output.probes)
              ("heat of each body [J]", heat, 1.0, 0.0),
              ("frictional heat per interface [J]",
               [k for k in history.columns if k.startswith("frictional_heat_total_")], 1.0, 0.0),
              ("max face temperature [°C]", [k for k in history.columns if k.startswith("face_max_temperature_")],
               1.0, -273.15),
              ("heat stored in each part [J]",
               [k for k in history.columns if k.startswith("stored_heat_") and "_part_" in k], 1.0, 0.0),
              ("wear volume [mm³]", [k for k in history.columns if k.startswith("wear_volume_")]
               or [k for k in ("wear_volume",) if k in history.columns], 1e9, 0.0),             # (its interfaces')
              ("max wear depth [µm]", [k for k in ("wear_max_depth", "counter_wear_max_depth") if k in history.columns],
               1e6, 0.0),
              ("least material left\nbehind a facet [mm]", [k for k in history.columns
                                                              if k.startswith("wear_remaining_min_")]
               or [k for k in ("wear_remaining_min",) if k in history.columns], 1e3, 0.0)]    # (its interfaces')
    groups = [g for g in groups if g[1] and all(k in history.columns for k in g[1])]
    rows = 1 if len(groups) <= 4 else 2
    cols = -(-len(groups) // rows)
    fig = Figure(figsize=(4.2 * cols, 3.4 * rows))
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[len(groups):]:
        ax.set_visible(False)
    palette = body_colours(history.columns)
    for ax, (label, keys, scale, shift) in zip(axes, groups):
        styles, entries = curve_styles(keys, palette)
        named = len(keys) > 1 or keys[0].startswith("probe_temperature_")     # (a probe's name: said only there)
        for k, (key, style) in enumerate(zip(keys, styles)):    # each curve thinner than the one before:
            wide = (len(keys) - 1 - k) / max(len(keys) - 1, 1)   # one on another (equal pads) stays seen
            ax.plot(t, history[key] * scale + shift, marker="o", ms=3 + 3 * wide, lw=1.2 + 2.4 * wide,
                    label=column_label(key) if named else None, **style)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        values = np.concatenate([history[k] * scale + shift for k in keys])
        if np.ptp(values) <= 1e-6 * np.abs(values).max(initial=0.0):     # constant to round-off
            centre = values.mean()
            ax.set_ylim(centre - 0.05 * abs(centre) - 1e-30, centre + 0.05 * abs(centre) + 1e-30)
        if named:
            handles = entries or ax.get_lines()
            ax.legend(handles=handles, fontsize="medium" if len(handles) <= LEGEND_ROWS else "x-small",
                      ncol=-(-len(handles) // LEGEND_ROWS))
    for ax in axes[1:len(groups)]:       # one time axis (a panel's NaN rows, at rest, shortened its own)
        ax.set_xlim(axes[0].get_xlim())
    fig.suptitle(f"{title}: interface force, contact pressure, temperatures and heat against time" if title else
                 "interface force, contact pressure, temperatures and heat against time")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def nice_range(values) -> tuple[float, float]:
    """The largest 1, 2 or 5 x 10^k at or below the smallest of the positive ``values`` and the
    smallest at or above their largest: the limits of a log axis that carry a tick."""
    def step(v, up):
        k = np.floor(np.log10(v))
        choices = np.array([1.0, 2.0, 5.0, 10.0]) * 10.0**k
        return float(choices[choices >= v * (1 - 1e-12)][0] if up else choices[choices <= v * (1 + 1e-12)][-1])
    lo, hi = step(float(np.min(values)), False), step(float(np.max(values)), True)
    return (lo, hi) if hi > lo else (step(lo * 0.999, False), step(hi * 1.001, True))    # one value on a tick


def multiscale_figure(history, path: Path, title: str = "") -> Path:
    """PNG of the multiscale history columns at both scales (see module docstring)."""
    cols = history.columns
    hot = temperature_columns(cols)
    areas = [k for k in cols if k.startswith("real_contact_area_")]          # one per rough interface
    area = 1e6 if np.nanmax(np.abs(cols.get("real_contact_area", [0.0])), initial=0.0) > 1e-8 else 1e12  # mm² or µm²
    after, before = (" (after wear)", " (before wear)") if "wear_volume" in cols else ("", "")   # a row's two states (a
    panels = [("max contact pressure [MPa]", [("max_pressure", "macro facet" + after),       # zone above every facet
                                               ("max_zone_pressure", "macro zone mean" + before),   # puzzled a user
                                               ("micro_max_pressure", "micro local" + before)],     # trial: results.rst
               1e-6, 0),                                                                           # "When in the step")
              ("max temperature [°C]", [(k, "macro " + column_label(k)) for k in hot]
               + [("micro_max_temperature", "micro: zone mean + local rise")], 1.0, -273.15),   # (below a macro
                                                                                   # facet's max puzzled a user trial)
              ("zones' heat partition\ninto the rough body [%]",   # the coefficients of Fig. 7.12, not
               [("partition_max", "max"), ("partition_mean", "mean over zones"),    # weighted by the heat
                ("partition_min", "min")], 100.0, 0),
              ("wear volume [mm³]", [("wear_volume", None)], 1e9, 0),     # a tribologist's unit, however small
              ("max wear depth [µm]", [("wear_max_depth", "micro: a patch's deepest cell")], 1e6, 0),   # (read as
                                                                  # the pad's deepest facet: a user trial)
              ("RMS roughness of the worn zones [µm]", [("rms_height", None)], 1e6, 0),
              ("real contact area [mm²]" if area == 1e6 else "real contact area [µm²]",
               [("real_contact_area", "all interfaces" if len(areas) > 1 else None)]
               + [(k, k.removeprefix("real_contact_area_")) for k in areas], area, 0),
              ("largest plastic share\nof a zone's cells [%]", [("micro_plastic_fraction", None)], 100.0, 0)]
    panels = [(label, [(k, n) for k, n in keys if k in cols], s, o) for label, keys, s, o in panels]
    panels = [p for p in panels if p[1]]
    ncol = min(3, len(panels))
    nrow = -(-len(panels) // ncol)
    fig = Figure(figsize=(4.3 * ncol, 3.3 * nrow))
    axes = fig.subplots(nrow, ncol, squeeze=False)
    t, palette = history["time"], body_colours(cols)
    for ax, (label, keys, scale, shift) in zip(axes.ravel(), panels):
        for key, name in keys:     # the macro temperatures in history.png's colours, the micro one black
            colour = {"color": palette[column_label(key)] if key in hot else "black"} \
                if label.startswith("max temperature") else {}
            y = np.asarray(history[key], dtype=float) * scale + shift
            if label.startswith("max contact pressure"):    # released rows (0): a gap, not a drop off the log axis
                y = np.where(y > 0, y, np.nan)
            ax.plot(t, y, "o-", ms=3, label=name, **colour)
        if label.startswith("max contact pressure"):
            values = np.concatenate([np.asarray(history[k], dtype=float) for k, _ in keys])
            if (values > 0).any():     # log of the positive values (0 released or between zones)
                ax.set_yscale("log")   # ticks at 1, 2, 5 x 10^k in plain numbers, the limits on such ticks
                ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
                ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.yaxis.set_minor_formatter(NullFormatter())
                ax.set_ylim(*nice_range(values[values > 0] * scale))
            else:                      # a history of released rows only: nothing to log-scale
                ax.text(0.5, 0.5, "no contact in this history", transform=ax.transAxes, ha="center", va="center")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if ax.get_yscale() == "linear":
            ax.ticklabel_format(axis="y", useOffset=False)
        if any(name for _, name in keys):     # above the panel, in two columns: inside, it hid the curves
            ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.02, 1.0, 0.1), mode="expand", ncol=2,
                      borderaxespad=0.0)
    for ax in axes.ravel()[len(panels):]:
        ax.axis("off")
    fig.suptitle((f"{title}:" + ("\n" if ncol == 1 else " ") if title else "") +      # (one panel: cut off at
                 "both scales of the multiscale loop against time")                     # both ends; a user trial)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def cells_on_face(grid, cells, triangles) -> np.ndarray:
    """(ny my, nx mx) booleans: whether the centre of each micro cell of ``grid`` (``cells`` = (my, mx)
    per zone; rows along v) lies on one of ``triangles`` (n, 3, 2) [m], a planar face's facets in the
    grid's plane (edges included to 1e-9 of a cell)."""
    (nx, ny), (my, mx) = grid.counts, cells
    on = np.zeros((ny * my, nx * mx), dtype=bool)
    t = (np.asarray(triangles, dtype=float) - grid.origin) / (grid.size[0] / mx, grid.size[1] / my) - 0.5
    lo = np.maximum(np.ceil(t.min(axis=1) - 1e-9), 0).astype(int)
    hi = np.minimum(np.floor(t.max(axis=1) + 1e-9), (nx * mx - 1, ny * my - 1)).astype(int)
    for (a, b, c), (i0, j0), (i1, j1) in zip(t, lo, hi):
        det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        if i1 < i0 or j1 < j0 or det == 0:
            continue
        i, j = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        l1 = ((b[1] - c[1]) * (i - c[0]) + (c[0] - b[0]) * (j - c[1])) / det     # barycentric coordinates
        l2 = ((c[1] - a[1]) * (i - c[0]) + (a[0] - c[0]) * (j - c[1])) / det
        inside = (l1 >= -1e-9) & (l2 >= -1e-9) & (l1 + l2 <= 1 + 1e-9)
        on[j[inside], i[inside]] = True
    return on


def wear_map(grid, depth: np.ndarray, path: Path, title: str = "", face=None) -> Path:
    """PNG of the zone-mean wear depth (zone grid) and of the micro wear depth field [µm]. With
    ``face`` (the interface's facets (n, 3, 2) in the grid's plane [m]), the cells whose centre lies
    off the face, and the zones holding none on it, are left blank (a round face's corners)."""
    nx, ny = grid.counts
    _, my, mx = depth.shape
    x0, y0 = grid.origin
    extent = [1e3 * x0, 1e3 * (x0 + nx * grid.size[0]), 1e3 * y0, 1e3 * (y0 + ny * grid.size[1])]
    zone_mean = depth.mean(axis=(-2, -1)).reshape(ny, nx)
    field = depth.reshape(ny, nx, my, mx).transpose(0, 2, 1, 3).reshape(ny * my, nx * mx)
    if face is not None:
        on = cells_on_face(grid, (my, mx), face)
        field = np.where(on, field, np.nan)
        zone_mean = np.where(on.reshape(ny, my, nx, mx).any(axis=(1, 3)), zone_mean, np.nan)
    fig = Figure(figsize=(10, 4.2))
    axes = fig.subplots(1, 2)
    for ax, data, label in ((axes[0], zone_mean, "mean wear depth per zone [µm]"),
                            (axes[1], field, "micro wear depth [µm]")):
        im = ax.imshow(1e6 * data, origin="lower", extent=extent, cmap="inferno", interpolation="nearest")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        fig.colorbar(im, ax=ax, label=label, shrink=0.85)
    axes[1].set_title("each zone an isolated patch: its edges carry and wear the most", fontsize=8)
    fig.suptitle(f"wear depth over the interface ({title})" if title else "wear depth over the interface")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path

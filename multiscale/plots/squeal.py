"""Figures of the squeal analysis (thesis §4.4): contact pressure at the preload (Fig. 4.12),
complex eigenvalues (Fig. 4.13), unstable modes per case (Fig. 4.14), MAC matrices (Figs. 4.16–4.17),
per-mode curves such as the MMAC and its cumulative mean (Figs. 4.18–4.19), strain-energy shares per component (Figs. 4.20–4.21).

Every function takes results already gathered (the collective parts are computed before), so that
rank 0 alone can draw.
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

SPLIT_FLOOR = 0.01     # energy.png: a split drawn hatched where its two components hold less of the mode's


def _save(fig: Figure, path, tight: bool = True) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def plot_pressure(midpoints: np.ndarray, masks: Mapping[str, np.ndarray], facet_pressure: np.ndarray,
                  name: str, path, moving: tuple[str, np.ndarray] | None = None) -> Path:
    """Contact pressure [MPa] on each interface at the preloaded state (Fig. 4.12).

    ``midpoints`` and ``facet_pressure`` are global per interface facet; ``masks`` select each
    interface's facets. ``moving``: the moving body's name and its velocity per facet (any scale):
    an arrow across each interface shows where it slides, the leading edge where it enters (not
    shown before: an NVH user trial)."""
    fig = Figure(figsize=(4.2 * len(masks) + 1.2, 3.8), layout="constrained")   # (tight_layout and then the
    axes = fig.subplots(1, len(masks), squeeze=False)[0]                          # colorbar: labels overlapped)
    mid, p = midpoints, facet_pressure / 1e6
    levels = np.linspace(0.0, max(float(p.max(initial=0.0)), 1e-12), 21)    # one scale for every interface
    for ax, (iface, mask) in zip(axes, masks.items()):
        art = ax.tricontourf(mid[mask, 0] * 1e3, mid[mask, 1] * 1e3, p[mask], levels=levels, cmap="viridis")
        ax.set(title=iface, xlabel="x [mm]", ylabel="y [mm]", aspect="equal")
        d = moving[1][mask].mean(axis=0)[:2] if moving is not None and mask.any() else np.zeros(2)
        if np.linalg.norm(d) > 0:
            x = mid[mask, :2] * 1e3
            c, half = x.mean(axis=0), 0.3 * float(np.ptp(x, axis=0).max()) * d / np.linalg.norm(d)
            ax.annotate("", xy=c + half, xytext=c - half, arrowprops={"arrowstyle": "->", "color": "w", "lw": 1.5})
            ax.text(*(c - half), f"{moving[0]} slides", color="w", fontsize=7, ha="center", va="top")
    fig.suptitle(f"{name}: contact pressure at the preload")
    fig.colorbar(art, ax=list(axes), label="contact pressure [MPa]", shrink=0.9, ticks=MaxNLocator(6))
    return _save(fig, path, tight=False)


LABELLED = 8     # unstable modes labelled with their frequency per case in re_im.png (the fastest growing)


def plot_re_im(cases: Sequence, path) -> Path:
    """Real part against imaginary part of the eigenvalues, one marker set per case (Fig. 4.13),
    the unstable modes circled in red and labelled with their frequencies (the first ``LABELLED``
    by growth; they were unlabelled: an NVH user trial); ``cases`` have ``name``, ``modes``
    (``ModalResult``) and ``report`` (``StabilityReport``)."""
    fig = Figure(figsize=(8, 4.5))
    ax = fig.subplots()
    for c in cases:
        art, = ax.plot(c.modes.frequency, c.modes.growth, "o", ms=3, label=c.name)
        bad = np.asarray(c.report.unstable, dtype=int) - 1                   # mode numbers from 1
        ax.plot(c.modes.frequency[bad], c.modes.growth[bad], "o", ms=8, mfc="none", mec="r", mew=1.2,
                label=f"{c.name}: unstable" if len(cases) > 1 else "unstable")
        for j in bad[np.argsort(-c.modes.growth[bad])][:LABELLED]:
            ax.annotate(f"{c.modes.frequency[j]:.0f} Hz", (c.modes.frequency[j], c.modes.growth[j]), fontsize=7,
                        xytext=(5, 5), textcoords="offset points", color="r")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="imaginary part: frequency [Hz]", ylabel="real part sigma [1/s]",
           title="complex eigenvalues (sigma > 0: unstable)")
    if len(cases) > 1 or any(len(c.report.unstable) for c in cases):
        ax.legend(fontsize=7)
    return _save(fig, path)


def plot_energy(case, path, split: tuple[str, str] | None = None) -> Path:
    """Strain-energy share of each component per mode (Fig. 4.20) and, with ``split`` = (a, b), a
    second panel: the share of component a in the energy of a and b (Fig. 4.21: inner vs outer
    pad); unstable modes marked. ``case`` has ``name``, ``modes``, ``energy`` (``EnergyShares``) and
    ``report``."""
    sh = case.energy
    fig = Figure(figsize=(9, 6 if split is not None else 3.5))
    axes = list(fig.subplots(2, 1, sharex=True)) if split is not None else [fig.subplots()]
    a = axes[0]
    n = np.arange(1, len(case.modes) + 1)
    bottom = np.zeros(len(n))
    for j, name in enumerate(sh.names):
        a.bar(n, sh.share[:, j], bottom=bottom, label=name, width=0.9)
        bottom += sh.share[:, j]
    a.set(ylabel="strain-energy share [-]", ylim=(0.0, 1.3), yticks=np.linspace(0.0, 1.0, 6),
          title=f"{case.name}: share of the strain energy of each mode per component")
    a.legend(fontsize=7, ncol=min(len(sh.names), 6), loc="upper center")      # above the bars (shares sum to 1)
    if split is not None:
        b = axes[1]
        ratio, held = sh.split(*split), sh.share[:, sh.names.index(split[0])] + sh.share[:, sh.names.index(split[1])]
        faint = held < SPLIT_FLOOR                        # the pads hold next to none of the mode's energy
        b.bar(n[~faint], ratio[~faint], width=0.9, label=f"{split[0]} / ({split[0]} + {split[1]})")
        if faint.any():
            b.bar(n[faint], ratio[faint], width=0.9, color="none", edgecolor="0.6", hatch="//",
                  label=f"the two hold < {SPLIT_FLOOR:.0%} of the mode's energy")
        b.axhline(0.5, color="k", lw=0.5)
        b.set(ylim=(0.0, 1.3), yticks=np.linspace(0.0, 1.0, 6), ylabel="energy share [-]")
        b.legend(fontsize=7, loc="upper center")
    for j in case.report.unstable:
        axes[-1].axvline(j, color="r", lw=0.8, ls=":", zorder=3)     # over the bars
    axes[-1].set(xlabel="mode number (red: unstable)")
    axes[-1].xaxis.set_major_locator(MaxNLocator(integer=True))
    return _save(fig, path)


def plot_unstable_bars(cases: Mapping, path) -> Path:
    """Unstable (full) and potentially unstable (hatched) modes per case against mode number (Fig. 4.14)."""
    fig = Figure(figsize=(9, 0.6 * len(cases) + 1.5))
    ax = fig.subplots()
    for row, (name, case) in enumerate(cases.items()):
        rep = case.report
        ax.bar(rep.unstable, 0.8, bottom=row - 0.4, width=0.8, color=f"C{row}")
        ax.bar(rep.potentially_unstable, 0.8, bottom=row - 0.4, width=0.8, fill=False, hatch="///",
               edgecolor=f"C{row}")
    ax.set_yticks(range(len(cases)), list(cases))
    ax.set_xlim(0.5, max(len(c.modes) for c in cases.values()) + 0.5)
    ax.set(xlabel="mode number", title="unstable (full) and potentially unstable (hatched) modes")
    return _save(fig, path)


def plot_mac(mac: np.ndarray, title: str, path, labels: tuple[str, str] = ("mode (rough case)",
                                                                            "mode (perfect contact)")) -> Path:
    """MAC matrix between two cases (Figs. 4.16–4.17), ``labels`` of its columns' and rows' modes."""
    fig = Figure(figsize=(5.5, 4.8))
    ax = fig.subplots()
    art = ax.imshow(mac, origin="lower", vmin=0, vmax=1, cmap="viridis",
                    extent=(0.5, mac.shape[1] + 0.5, 0.5, mac.shape[0] + 0.5))
    fig.colorbar(art, ax=ax, label="MAC")
    ax.set(title=title, xlabel=labels[0], ylabel=labels[1])
    return _save(fig, path)


def plot_mode_curves(curves: Mapping[str, np.ndarray], ylabel: str, path) -> Path:
    """One value per mode of the perfect-contact model for each case, e.g. the MMAC (Fig. 4.18) or
    its cumulative mean (Fig. 4.19)."""
    fig = Figure(figsize=(8, 4))
    ax = fig.subplots()
    for name, m in curves.items():
        ax.plot(np.arange(1, len(m) + 1), m, "-o", ms=2.5, label=name)
    ax.set(xlabel="mode of the perfect-contact model", ylabel=ylabel, ylim=(0, 1.02))
    ax.legend(fontsize=7)
    return _save(fig, path)


def plot_map(smap, path) -> Path:
    """Stability map: growth rate against frequency of every mode at every point of a sweep,
    coloured by the swept value; unstable modes above the line (``smap``: a
    ``macro.stability_map.StabilityMap``)."""
    fig = Figure(figsize=(8, 4.8))
    ax = fig.subplots()
    values = np.broadcast_to(smap.values[:, None], smap.frequency.shape)
    ok = ~np.isnan(smap.frequency)
    art = ax.scatter(smap.frequency[ok], smap.growth[ok], c=values[ok], s=8, cmap="viridis")
    fig.colorbar(art, ax=ax, label=f"{smap.parameter} [{smap.unit}]")
    ax.axhline(0.0, color="k", lw=0.5)
    for o in (o for o in smap.onsets if np.isfinite(o.value)):      # not those below the sweep
        ax.plot(o.frequency, 0.0, "rx", ms=7)
    ax.set(xlabel="frequency [Hz]", ylabel="growth rate sigma [1/s]",
           title=f"stability map over {smap.parameter} (x: onsets)")
    return _save(fig, path)


def plot_tracks(smap, path) -> Path:
    """Frequency and growth rate of every tracked mode against the swept value; unstable
    tracks coloured, the others grey; onsets marked."""
    fig = Figure(figsize=(8, 7))
    a, b = fig.subplots(2, 1, sharex=True)
    bad = smap.unstable().any(axis=0)
    for t in range(smap.n_tracks):       # a marker at each point: a track of one point is seen too
        style = dict(lw=1.2, marker=".", ms=5) if bad[t] else dict(color="0.75", lw=0.6, marker=".", ms=2)
        line = a.plot(smap.values, smap.frequency[:, t], label=f"track {t + 1}" if bad[t] else None, **style)[0]
        b.plot(smap.values, smap.growth[:, t], **dict(style, color=line.get_color()))
    for o in smap.onsets:
        a.plot(o.value, o.frequency, "kx", ms=6)
        b.plot(o.value, 0.0, "kx", ms=6)
    b.axhline(0.0, color="k", lw=0.5)
    a.set(ylabel="frequency [Hz]", title="tracked modes (coloured: unstable somewhere; x: onsets)")
    b.set(xlabel=f"{smap.parameter} [{smap.unit}]", ylabel="growth rate sigma [1/s]")
    if bad.any() and bad.sum() <= 12:
        a.legend(fontsize=7, ncol=2)
    return _save(fig, path)

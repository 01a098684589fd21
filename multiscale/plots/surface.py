"""Figure of a measured or generated surface (``multiscale surface``): the height map beside its
radially averaged PSD with the self-affine fit and its cut-offs (``multiscale.micro.spectrum``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

SHOWN = 1000      # height-map points per side drawn at most (a strided view; the figure has ~500 pixels a side)
SPAN = (0.1, 99.9)   # percentiles of the whole map's heights that the colours span (beyond: the bar's arrows)


def colour_range(heights: np.ndarray) -> tuple[float, float]:
    """The heights [m] the colours span: the ``SPAN`` percentiles of the whole map (single outlier
    points set the range of the whole map's extremes: a 1.2 um spike hid a 14 nm texture), its
    extremes if they coincide."""
    lo, hi = np.percentile(heights, SPAN)
    return (float(lo), float(hi)) if hi > lo else (float(heights.min()), float(heights.max()))


def surface_figure(surface, stats, path: Path, title: str = "", waviness=None) -> Path:
    """PNG: height map [µm] (its texture aspect ratio and lay in the title; and the waviness taken
    out, if given), then C(q) [m⁴] against q [rad/m] (complete bins as points, partial ones hollow)
    with the power-law fit between its cut-offs."""
    maps = [("roughness" if waviness is not None else "heights", surface)] + (
        [("waviness", waviness)] if waviness is not None else [])
    fig = Figure(figsize=(4.6 * (len(maps) + 1), 5.0))
    axes = fig.subplots(1, len(maps) + 1, squeeze=False)[0]
    for ax, (label, s) in zip(axes, maps):
        Lx, Ly = s.size
        step = -(-max(s.shape) // SHOWN)            # every step-th point along both axes
        lo, hi = colour_range(s.heights)
        image = ax.imshow(s.heights[::step, ::step] * 1e6, origin="lower", extent=(0, Lx * 1e3, 0, Ly * 1e3),
                          cmap="viridis", interpolation="nearest", vmin=lo * 1e6, vmax=hi * 1e6)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        t = stats.texture if s is surface else None
        ax.set_title(label if t is None else f"{label}: Str {'< ' * (not t.bounded)}{t.Str:.2g},\nlay {t.lay:.0f}° from x")
        #          (on two lines: one reached into the next panel, a user trial)
        below, above = s.heights.min() < lo, s.heights.max() > hi
        fig.colorbar(image, ax=ax, shrink=0.85, extend={(0, 0): "neither", (1, 0): "min", (0, 1): "max",
                                                        (1, 1): "both"}[below, above],
                     label="height [µm]" + (f" ({SPAN[0]:g}–{SPAN[1]:g} % of points)" if below or above else ""))
    ax = axes[-1]
    sp = stats.spectrum
    ax.loglog(sp.q[sp.complete], sp.C[sp.complete], "o", ms=3, label="PSD (radial average)")
    if (~sp.complete).any():
        ax.loglog(sp.q[~sp.complete], sp.C[~sp.complete], "o", ms=3, mfc="none", color="C0", label="partial bins")
    fit = stats.power_law
    if fit is not None:
        q = np.geomspace(sp.q[0], sp.q[-1], 200)
        inside = q <= fit.q_s
        ax.loglog(q[inside], fit(q[inside]), "-", color="C1", label=f"fit: H = {fit.hurst:.2f}")
        for value, resolved, name, colour in ((fit.q_r, fit.resolved[0], "q_r", "C2"),
                                              (fit.q_s, fit.resolved[1], "q_s", "C3")):   # (alike before: a trial)
            ax.axvline(value, color=colour, ls="--" if resolved else ":", lw=1,
                       label=f"{name} = {value:.3g} rad/m (λ = {2e6 * np.pi / value:.3g} µm)"   # µm, as the report
                       + ("" if resolved else " (end of data)"))
    ax.set_xlabel("wavevector q = 2π/λ [rad/m]")
    ax.set_ylabel("PSD C(q) [m⁴]")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16))   # below: it hid the short wavelengths
    ax.set_title(f"Sq = {stats.Sq * 1e6:.3g} µm, Sdq = {stats.Sdq:.3g}")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path

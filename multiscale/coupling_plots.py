"""Figures of a multiscale run (thesis ch. 7): the history at both scales and the wear map.

``history_figure``: max contact pressure macro (facets, zones) vs micro (Fig. 7.14; log scale), max temperature macro vs micro
(Fig. 7.15), heat partition min/mean/max (Fig. 7.12), wear volume (Fig. 7.16), max wear depth
(Fig. 7.17) and RMS of the worn surface (Fig. 7.18) — the panels whose columns the history has.
``wear_map``: the mean wear depth of every zone over the interface (Fig. 7.13) beside the micro
wear depth field of the whole face.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def history_figure(history, path: Path, title: str = "") -> Path:
    """PNG of the multiscale history columns (see module docstring)."""
    plt = _pyplot()
    cols = history.columns
    hot = [k for k in cols if k.startswith("max_temperature")]
    panels = [("max contact pressure [MPa]", [("max_pressure", "macro facet"), ("max_zone_pressure", "macro zone"),
                                               ("micro_max_pressure", "micro")], 1e-6, 0),
              ("max temperature [°C]", [(k, "macro " + k.split("_")[-1]) for k in hot]
               + [("micro_max_temperature", "micro")], 1.0, -273.15),
              ("heat into the rough body [%]", [("partition_max", "max"), ("partition_mean", "mean"),
                                                ("partition_min", "min")], 100.0, 0),
              ("wear volume [µm³]", [("wear_volume", None)], 1e18, 0),
              ("max wear depth [µm]", [("wear_max_depth", None)], 1e6, 0),
              ("RMS of the worn surface [µm]", [("rms_height", None)], 1e6, 0)]
    panels = [(label, [(k, n) for k, n in keys if k in cols], s, o) for label, keys, s, o in panels]
    panels = [p for p in panels if p[1]]
    ncol = min(3, len(panels))
    nrow = -(-len(panels) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.3 * ncol, 3.3 * nrow), squeeze=False)
    t = history["time"]
    for ax, (label, keys, scale, shift) in zip(axes.ravel(), panels):
        for key, name in keys:
            ax.plot(t, history[key] * scale + shift, "o-", ms=3, label=name)
        if label.startswith("max contact pressure"):
            ax.set_yscale("log")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        if ax.get_yscale() == "linear":
            ax.ticklabel_format(axis="y", useOffset=False)
        if any(name for _, name in keys):
            ax.legend(fontsize=8)
    for ax in axes.ravel()[len(panels):]:
        ax.axis("off")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def wear_map(grid, depth: np.ndarray, path: Path, title: str = "") -> Path:
    """PNG of the zone-mean wear depth (zone grid) and of the micro wear depth field [µm]."""
    plt = _pyplot()
    nx, ny = grid.counts
    _, my, mx = depth.shape
    x0, y0 = grid.origin
    extent = [1e3 * x0, 1e3 * (x0 + nx * grid.size[0]), 1e3 * y0, 1e3 * (y0 + ny * grid.size[1])]
    zone_mean = depth.mean(axis=(-2, -1)).reshape(ny, nx)
    field = depth.reshape(ny, nx, my, mx).transpose(0, 2, 1, 3).reshape(ny * my, nx * mx)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, data, label in ((axes[0], zone_mean, "mean wear depth per zone [µm]"),
                            (axes[1], field, "micro wear depth [µm]")):
        im = ax.imshow(1e6 * data, origin="lower", extent=extent, cmap="inferno", interpolation="nearest")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        fig.colorbar(im, ax=ax, label=label, shrink=0.85)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path

"""Figures of a parametric study (``multiscale.studies``), written as PNGs beside its report:
each metric's relative error against wall time (Pareto front), and error (or metric value) and
wall time against each swept knob."""
from __future__ import annotations

import json
import math
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FuncFormatter, MaxNLocator, NullFormatter, NullLocator

from multiscale.studies.expand import Study, StudyRun
from multiscale.studies.formatting import metric_heading, percent
from multiscale.studies.problems import PROBLEMS
from multiscale.studies.results import Row, case_key, crossings, knob_unit, measured_value, pareto, sample_std

__all__ = ["plot"]

matplotlib.use("Agg")          # PNG files only, no display


COLUMNS = 3        # panels per row of a figure against one axis


def plot(study: Study, rows: list[Row], folder: Path) -> list[Path]:
    """PNGs: error vs wall time per metric (Pareto front; with many runs only the front is
    labelled), and per knob: error (or metric) and wall time vs the knob; the study's earlier PNGs
    are removed first, so none is left beside a report that no longer draws it."""
    ok = [r for r in rows if r.ok]
    for stale in [_pareto_path(study, folder)] + [_axis_path(study, axis, folder) for axis in study.axes]:
        stale.unlink(missing_ok=True)    # (a report of failed runs sat beside the plots of the study before; a user trial)
    if not ok or not study.report.plots:
        return []
    out = []
    if study.judged:
        out.append(_plot_pareto(study, ok, folder))
    found = crossings(study, rows)
    for axis in study.axes:
        if axis[0] not in study.averaged:
            out.append(_plot_axis(study, ok, axis, folder, found))
    return [p for p in out if p is not None]


def _numeric(values) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _short(run: StudyRun, skip=()) -> str:
    return ", ".join(v for k, v in run.shown.items() if k not in skip)


def _plot_pareto(study, ok, folder):
    """Relative error vs wall time, one panel per metric, the Pareto front of each case of
    [report] cases in its colour (a case is a problem of its own: one front across them put a
    setting 17 % off at one load on the front for its 7 % at another; None if no error is positive)."""
    n = len(study.judged)
    fig, axes = plt.subplots(1, n, figsize=(5.2 * n, 4.3), squeeze=False)
    cases = list(dict.fromkeys(case_key(study, r) for r in ok))
    drawn = False
    for ax, m in zip(axes[0], study.judged):
        t = [r.record["wall_time"] for r in ok]
        e = [r.errors.get(m, math.nan) for r in ok]
        members = [[i for i, r in enumerate(ok) if case_key(study, r) == case and math.isfinite(e[i]) and e[i] > 0]
                   for case in cases]
        fronts = [[idx[j] for j in pareto([t[i] for i in idx], [e[i] for i in idx])] for idx in members]
        labelled = set(range(len(ok))) if len(ok) <= 16 else {i for front in fronts for i in front}
        named = False                  # the fronts' legend entry: once per panel
        for c, (case, idx, front) in enumerate(zip(cases, members, fronts)):
            ax.scatter([t[i] for i in idx], [e[i] for i in idx], color=f"C{c}", s=28, zorder=3,
                       label=", ".join(f"{k} = {v}" for k, v in zip(study.cases, case)) or None)
            for i in (i for i in idx if i in labelled):
                ax.annotate(_short(ok[i].run, study.cases), (t[i], e[i]), fontsize=6,
                            xytext=(3, 3), textcoords="offset points")
            if front:                   # its points ringed: a front of one point drew nothing under its entry (a trial)
                ax.step([t[i] for i in front], [e[i] for i in front], where="post", color=f"C{c}", lw=2, alpha=0.6,
                        marker="o", ms=9, mfc="none", zorder=2,
                        label=None if named else "Pareto front" + (" of each case" if len(cases) > 1 else ""))
                drawn = named = True
        refs = sorted(r.record["wall_time"] for r in ok if r.is_reference)
        if refs:                 # (the band was unexplained: a user trial)
            ax.axvspan(refs[0], refs[-1], color="green", alpha=0.15, lw=0,
                       label="reference runs' wall times" if len(refs) > 1 else None)
            ax.axvline(refs[len(refs) // 2], color="green", ls=":",
                       label="reference run" if len(refs) == 1 else "their median")
        if any(fronts):
            ax.set(xscale="log", yscale="log")
        for tol in study.report.errors:
            ax.axhline(tol, color="gray", ls="--", lw=0.8)
            ax.annotate(percent(tol), (1, tol), xycoords=("axes fraction", "data"), fontsize=7, ha="right",
                        va="bottom", color="gray")
        if any(fronts):                # (the tolerances' lines widen the view: ticks after them)
            for axis in (ax.xaxis, ax.yaxis):
                _plain_log(axis)
        ax.set(xlabel="wall time [s]", ylabel=f"relative error of {m}", title=f"error of {m} against cost")
        ax.grid(True, which="both", alpha=0.25)
        if ax.get_legend_handles_labels()[0]:       # (else matplotlib warned "No artists with labels")
            ax.legend(fontsize=7)
    if not drawn:
        plt.close(fig)
        return None
    fig.suptitle(f"{study.name}: relative error against wall time (lower left is better)")
    fig.tight_layout()
    path = _pareto_path(study, folder)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _spans_decades(ax) -> bool:
    """Whether the lines of ``ax`` are positive and span more than a factor 5: a log axis for them."""
    y = np.concatenate([np.asarray(line.get_ydata(), float) for line in ax.get_lines()] or [np.zeros(0)])
    y = y[np.isfinite(y)]
    return y.size > 1 and y.min() > 0 and y.max() / y.min() > 5


def _pareto_path(study, folder: Path) -> Path:
    return folder / f"{study.name}_error_vs_time.png"


def _axis_path(study, axis, folder: Path) -> Path:
    return folder / f"{study.name}_{axis[0].replace('.', '_')}.png"


def _plain_log(axis) -> None:
    """Plain numbers on a log axis, "0.4" and not "4 x 10^-1" (those overlapped on short decades),
    at least two of them: every decade on an axis spanning over two, and 2 and 5 times it over one,
    and 3 times it too over a factor 4; on a shorter one (4.1 ... 4.8 s, where no such number falls:
    the axis was bare, a user trial) about four evenly spaced values, with the digits their step
    needs (1000.5 ... 1002 s read "1e+03" each with 3; a review). Call it once the view is final."""
    lo, hi = axis.get_view_interval()
    if hi <= 4 * lo:
        axis.set_major_locator(MaxNLocator(4))
        axis.set_minor_locator(NullLocator())

        def even(x, _):            # the fewest digits that write every tick exactly
            ticks = axis.get_majorticklocs()
            step = float(np.min(np.diff(ticks))) if len(ticks) > 1 else abs(x)
            digits = next((d for d in range(1, 16) if all(abs(float(f"{t:.{d}g}") - t) < 1e-6 * step for t in ticks)),
                          16)
            return f"{x:.{digits}g}"
        axis.set_major_formatter(FuncFormatter(even))
        return
    shown = (1,) if hi > 100 * lo else (1, 2, 5) if hi > 10 * lo else (1, 2, 3, 5)

    def label(x, _):
        mantissa = x / 10 ** math.floor(math.log10(x) + 1e-9)
        return f"{x:g}" if any(abs(mantissa - m) < 1e-6 for m in shown) else ""
    axis.set_major_formatter(FuncFormatter(label))
    axis.set_minor_formatter(FuncFormatter(label))


def _axis_label(study, axis, raw) -> str:
    """The knobs of an axis, with the SI unit of a micro parameter or scene key (``knob_unit``) whose
    values ``raw`` (as the study gave them) are bare numbers ("E [Pa]"; "E / nu" of a zipped axis
    read as a ratio: "E, nu")."""
    unit = knob_unit(study, axis[0])
    bare = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in raw)
    return ", ".join(axis) + (f" [{unit}]" if unit and bare else "")


def _plot_axis(study, ok, axis, folder, found):
    """Errors (or metric values) and wall time against one axis (a knob, or zipped knobs plotted
    against the first), one line per setting of the other knobs (mean ± std over averaged ones);
    against measured values (a reference file) the metric itself, the measured value and where the
    sweep meets it (``found``: ``results.crossings``)."""
    def point(r):
        return json.dumps([r.run.label[k] for k in axis])
    values = list(dict.fromkeys(point(r) for r in ok))
    raw = [json.loads(v)[0] for v in values]
    numeric = _numeric(raw) and len(set(raw)) == len(raw)    # else categorical, one tick per setting
    xs = {v: (x if numeric else i) for i, (v, x) in enumerate(zip(values, raw))}
    ticks = {point(r): ", ".join(r.run.shown[k] for k in axis) for r in ok}
    shown_at = {json.loads(point(r))[0]: r.run.shown[axis[0]] for r in ok} if numeric else {}   # "100 rpm", not 10.47
    log_x = numeric and min(raw) > 0 and max(raw) / min(raw) > 5
    averaged = set(study.averaged)
    others = [k for k in study.knobs if k not in axis and k not in averaged]
    lines = {}
    for r in ok:
        lines.setdefault(tuple(r.run.shown[k] for k in others), []).append(r)
    measured = study.reference is not None and study.reference.kind == "file"
    panels = [("error" if m in study.judged and not measured else "value", m) for m in study.metrics] + [("time", None)]
    columns = min(COLUMNS, len(panels))        # (all in one row: 4400 px wide for 9 metrics, a trial)
    fig, axes = plt.subplots(-(-len(panels) // columns), columns, figsize=(4.4 * columns,
                                                                         3.9 * -(-len(panels) // columns)),
                             squeeze=False)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    for ax, (kind, m) in zip(axes.ravel(), panels):
        for c, (other, group) in enumerate(lines.items()):
            pts = {}
            for r in group:
                y = (r.errors.get(m, math.nan) or math.nan if kind == "error" else     # 0: the reference
                     r.record["metrics"][m] if kind == "value" else r.record["wall_time"])
                pts.setdefault(xs[point(r)], []).append(y)
            x = sorted(pts)
            mean = np.array([np.mean(pts[v]) for v in x])
            label = ", ".join(f"{k} = {v}" for k, v in zip(others, other)) if others else None
            if averaged and kind != "error":
                std = np.array([sample_std(pts[v]) for v in x])
                ax.errorbar(x, mean, yerr=std, marker="o", ms=4, color=f"C{c % 10}", capsize=3, label=label)
            else:
                ax.plot(x, mean, "o-", ms=4, color=f"C{c % 10}", label=label)
        curves = ax.get_lines() + ax.containers      # the swept lines (errorbar: a container)
        if kind == "error":
            if any(np.isfinite(np.asarray(line.get_ydata(), float)).any() for line in ax.get_lines()):
                ax.set_yscale("log")
            else:            # a metric the knob does not change: no error to draw on a log axis (it raised);
                zeros = sum(r.errors.get(m) == 0 for r in ok)   # or no reference value (its run not run: a trial)
                ax.text(0.5, 0.5, "error 0 in every run:\nequal to the reference" if zeros == len(ok) else
                        "no error: the reference\nhas no value of it" if not zeros else
                        "error 0 where the reference\nhas a value, none elsewhere", transform=ax.transAxes,
                        ha="center", va="center")
            for tol in study.report.errors:
                ax.axhline(tol, color="gray", ls="--", lw=0.8)
            at = sorted({xs[point(r)] for r in ok if r.is_reference})   # its error 0 has no place on a log axis
            for k, x in enumerate(at):       # (it was missing from the plot: a user trial)
                ax.axvline(x, color="green", ls=":", lw=1, label=None if k else "the reference (error 0)")
        if kind == "value" and not any(np.isfinite(np.asarray(line.get_ydata(), float)).any()
                                       for line in ax.get_lines()):
            ax.text(0.5, 0.5, "n/a in every run:\nwhat it measures is absent", transform=ax.transAxes, ha="center", va="center")
        if kind == "value" and m in study.judged:        # calibration: the measured value, and where it is met
            ref = measured_value(ok, m)
            ax.axhline(ref, color="green", ls="--", lw=1, label="measured")
            met = [c.value for c in found if c.knob == axis[0] and c.metric == m and c.value is not None]
            ax.plot(met, [ref] * len(met), "*", color="green", ms=11, label="where the sweep meets it" if met else None)
        if kind == "time" or (kind == "value" and log_x and _spans_decades(ax)):   # a power law straight (a linear
            ax.set_yscale("log")                                                   # law looked exponential: a trial)
        value = metric_heading(m, PROBLEMS[study.problem].metric_unit(m)) if kind == "value" else ""
        ax.set(xlabel=_axis_label(study, axis, [r.run.raw[axis[0]] for r in ok]),
               ylabel={"error": f"relative error of {m}", "value": value, "time": "wall time [s]"}[kind],
               title={"error": f"error of {m}", "value": m, "time": "wall time of a run"}[kind])
        if log_x:             # ticks at the swept values, no minor labels (they overlap on short decades)
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(NullFormatter())
        if numeric:
            ticks_at = sorted(set(raw))
            at = np.log(ticks_at) if log_x else np.asarray(ticks_at, float)
            labels, row = [shown_at[v] for v in ticks_at], 0
            for k in range(1, len(at)):    # a value close to the last one's label (8.9e-15 by 1e-14) a line lower
                row = 1 - row if at[k] - at[k - 1] < 0.12 * (at[-1] - at[0]) else 0
                labels[k] = "\n" * row + labels[k]
            ax.set_xticks(ticks_at, labels, rotation=30 if len(ticks_at) > 5 else 0)
        else:
            ax.set_xticks(range(len(values)), [ticks[v] for v in values], rotation=30, ha="right", fontsize=7)
        if ax.get_yscale() == "log":
            _plain_log(ax.yaxis)
        ax.grid(True, which="both", alpha=0.25)
        shown = [(h, t) for h, t in zip(*ax.get_legend_handles_labels()) if len(lines) <= 8 or h not in curves]
        if shown:            # the reference and measured marks always; the lines' labels up to 8 of them
            ax.legend(*zip(*shown), fontsize=6)
    fig.suptitle(f"{study.name}: {' and '.join(study.metrics)} and wall time against {', '.join(axis)}"
                 + (f" (mean ± sample std over {', '.join(averaged)})" if averaged else ""))
    fig.tight_layout()
    path = _axis_path(study, axis, folder)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path

"""Time axes of the figures: seconds from the log's start, each run (a recording a long gap splits from the others)
its own panel.

A log's stamps are often those of a clock that started long before (Unix epoch seconds, 1.46e9 s): drawn as they
are, the axis reads ``1.4600350e9`` with its tick labels on top of each other, and two runs 29 minutes apart are two
slivers of one axis. :func:`~wbfriction.logs.runs.log_runs` finds the runs, :func:`time_panels` gives each run its
own axes (widths in proportion to its duration, shared torque axis), time from the run's start; the first starts at
the log's start, and each later one says in its title when it starts.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, SubFigure

from wbfriction.logs.runs import Run, log_runs

MAX_PANELS = 4
"""Most runs drawn as panels of their own; a log with more is drawn on one axis of recorded time, the gaps cut
out (:func:`time_panels`)."""


def time_from_start(time: np.ndarray, runs: list[Run] | None = None) -> np.ndarray:
    """Each sample's time from the start of its run [s] (N,) (:func:`log_runs` of ``time`` unless given): the time a
    figure draws."""
    t = np.asarray(time, dtype=float)
    out = np.empty_like(t)
    for run in log_runs(t) if runs is None else runs:
        out[run.rows] = t[run.rows] - t[run.rows.start]
    return out


def _minutes(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.1f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def run_title(k: int, run: Run) -> str:
    """What a run's panel says: ``run 2, from 29.3 min`` (from the log's start)."""
    return f"run {k + 1}, from {_minutes(run.start)}"


PlotRun = Callable[[Axes, slice, np.ndarray], Any]
"""Draws one run on its axes: ``(ax, rows, t)``, ``t`` the rows' time from the run's start [s]."""


def time_panels(fig: Figure | SubFigure, spec: Any, time: np.ndarray, plot: PlotRun,
                xlabel: str = "time [s]") -> list[Axes]:
    """Axes over time in the place ``spec`` (a ``SubplotSpec``) of ``fig``, a panel per run of ``time`` (N,) [s]
    (:func:`log_runs`), each from its run's start (a shared y axis; the panels' widths in proportion to the runs'
    durations, none under a sixth of the widest), and ``plot`` called on each. One run: one axes, time from the
    log's start. More than :data:`MAX_PANELS` runs: one axes of recorded time, each run after the one before
    (dotted lines at the gaps cut out). ``xlabel`` goes under each panel (``time from its start [s]`` where there
is room). Returns the axes, the first run's first,
each labelled ``time...`` (:meth:`~matplotlib.artist.Artist.get_label`: a test finds the axes over time)."""
    t = np.asarray(time, dtype=float)
    runs = log_runs(t)
    if len(runs) <= 1 or len(runs) > MAX_PANELS:
        ax = fig.add_subplot(spec)
        drawn = np.empty_like(t)
        offset = 0.0
        for run in runs:
            drawn[run.rows] = t[run.rows] - t[run.rows.start] + offset
            if offset > 0:
                ax.axvline(offset, color="0.4", lw=0.8, ls=":")
            offset = float(drawn[run.rows.stop - 1]) + float(np.median(np.diff(t))) if t.size > 1 else 0.0
        ax.set_label("time")
        plot(ax, slice(0, t.size), drawn)
        ax.set_xlabel(xlabel if len(runs) <= 1 else f"recorded {xlabel} ({len(runs)} runs; dotted: gaps cut out)")
        return [ax]
    durations = np.array([t[r.rows.stop - 1] - t[r.rows.start] for r in runs])
    ratios = np.maximum(durations, durations.max() / 6) + 1e-9
    grid = spec.subgridspec(1, len(runs), width_ratios=ratios, wspace=0.06)
    axes: list[Axes] = []
    for k, run in enumerate(runs):
        ax = fig.add_subplot(grid[0, k], sharey=axes[0] if axes else None, label=f"time, run {k + 1}")
        plot(ax, run.rows, t[run.rows] - t[run.rows.start])
        ax.set_xlim(0, max(float(durations[k]), 1e-6))
        ax.set_title(run_title(k, run), fontsize="small", loc="left")
        if k:
            ax.tick_params(labelleft=False)
        wide = ratios[k] >= 0.3 * ratios.sum()  # room for the longer label
        ax.set_xlabel(xlabel.replace("time", "time from its start") if wide else xlabel)
        axes.append(ax)
    return axes


def widest_run(mask: np.ndarray, x: np.ndarray) -> slice:
    """The stretch of consecutive True values of ``mask`` over which ``x`` spans the widest
    range (empty slice if none): for Fig. 7.4, the swing phase where the joint moves most."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    if edges.size == 0:
        return slice(0, 0)
    runs = [slice(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]
    return max(runs, key=lambda r: float(np.nanmax(x[r]) - np.nanmin(x[r])) if np.isfinite(x[r]).any() else -1.0)

"""What ``wbfriction predict`` writes: the prediction table (:mod:`~wbfriction.pipeline.prediction_table`) and its
figure, per joint the measured and the predicted torque over time and the friction estimated and predicted against
the velocity, in the report's style (:data:`~wbfriction.report.figures.READABLE` fonts,
:data:`~wbfriction.report.figures.REPORT_WIDTH` inches wide).

The figure is drawn from the table alone, so it shows what the file holds. Its time axes are the report's
(:func:`~wbfriction.report.timeaxis.time_panels`): seconds from the log's start, a log joining runs recorded apart
(:func:`~wbfriction.logs.runs.log_runs`) drawn one panel per run, each from its own start: the runs are not
squeezed into slivers of one axis.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
from matplotlib import rc_context
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from wbfriction.exceptions import InputError
from wbfriction.fit.predict import TorquePrediction
from wbfriction.logs.tables import write_atomic
from wbfriction.pipeline.predict_step import predict_table
from wbfriction.pipeline.prediction_table import read_prediction_summary
from wbfriction.report.figures import READABLE, REPORT_WIDTH, joint_label, png_bytes
from wbfriction.report.timeaxis import time_panels

MAX_POINTS = 20000
"""Samples drawn per joint against the velocity at most (every k-th valid sample beyond): the same cloud, a figure
drawn in seconds."""
ROW_HEIGHT = 2.3
"""Height of a joint's row [in]."""
MEASURED, PREDICTED = "0.25", "C1"


def _column(table: pa.Table, name: str) -> np.ndarray:
    return table.column(name).to_numpy(zero_copy_only=False).astype(float)


def _row_title(joint: str, entry: dict) -> str:
    """A joint's row title: its name, its model (family and terms), status and RMS of measured less predicted."""
    model = entry.get("model") or "model"
    terms = entry.get("terms") or []
    status = entry.get("status") or ""
    rms = entry.get("rms")
    return (f"{joint}: {model}{' + ' + ', '.join(terms) if terms else ''}{f' ({status})' if status else ''}"
            + (f"; RMS of measured - predicted {rms:.3g} N·m" if rms is not None else ""))


def _time_plot(table: pa.Table, joint: str):
    """Draws measured torque (all samples) and predicted (the valid ones) of a run over its time
    (:data:`~wbfriction.report.timeaxis.PlotRun`)."""
    torque = f"tau.{joint}" in table.column_names
    measured = _column(table, f"tau.{joint}" if torque else f"tau_f.{joint}")
    predicted = _column(table, f"tau_pred.{joint}" if torque else f"tau_f_pred.{joint}")
    valid = table.column(f"valid.{joint}").to_numpy(zero_copy_only=False).astype(bool)
    predicted = np.where(valid, predicted, np.nan)

    def plot(ax: Axes, rows: slice, t: np.ndarray) -> None:
        ax.plot(t, measured[rows], color=MEASURED, lw=0.8)
        ax.plot(t, predicted[rows], color=PREDICTED, lw=0.8)
    return plot


def _velocity_panel(ax: Axes, table: pa.Table, joint: str) -> None:
    """The friction estimated and predicted against the velocity, on the valid samples."""
    valid = table.column(f"valid.{joint}").to_numpy(zero_copy_only=False).astype(bool)
    rows = np.flatnonzero(valid)
    rows = rows[::max(1, int(np.ceil(rows.size / MAX_POINTS)))]
    qd = _column(table, f"qd.{joint}")[rows]
    ax.plot(qd, _column(table, f"tau_f.{joint}")[rows], ".", ms=1.5, color=MEASURED)
    ax.plot(qd, _column(table, f"tau_f_pred.{joint}")[rows], ".", ms=1.5, color=PREDICTED)
    ax.axhline(0, color="k", lw=0.3)
    ax.set_ylabel("tau_f [N·m]")
    if not rows.size:
        ax.text(0.5, 0.5, "no valid sample", ha="center", va="center", transform=ax.transAxes)


def prediction_figure(table: pa.Table, title: str = "") -> Figure:
    """Per joint of a prediction table (one row each): the measured and the predicted torque over the time from the
    log's start [s] (one panel per run), and the friction estimated and predicted [N·m] against the velocity
    [rad/s]; each row titled with the joint's name, model, status and RMS of measured less predicted torque over the
    valid samples (the metadata's); one legend. Grey: measured (torque) and estimated (friction); orange: predicted.

    Raises:
        InputError: a table that is not a prediction table.
    """
    info = read_prediction_summary(table)
    joints = list(info.joints)
    t = _column(table, "time")
    with rc_context(READABLE):
        fig = Figure(figsize=(REPORT_WIDTH, ROW_HEIGHT * max(len(joints), 1) + 0.9), layout="constrained")
        grid = fig.add_gridspec(max(len(joints), 1), 2, width_ratios=[2.6, 1.0])
        velocity_axes = []
        for k, joint in enumerate(joints):
            time_axes = time_panels(fig, grid[k, 0], t, _time_plot(table, joint))
            velocity_axes.append(fig.add_subplot(grid[k, 1]))
            _velocity_panel(velocity_axes[-1], table, joint)
            time_axes[0].set_ylabel("tau [N·m]" if f"tau.{joint}" in table.column_names else "tau_f [N·m]")
            run = time_axes[0].get_title(loc="left")  # a log of several runs: the first's title
            title = _row_title(joint_label(joint, joints, joint), info.summary.get(joint, {}))
            time_axes[0].set_title(title + (f"\n{run}" if run else ""), loc="left")
        for ax in velocity_axes:
            ax.set_xlabel("qd [rad/s]")
        fig.suptitle(title or "Measured and predicted torque")
        fig.legend(handles=[Line2D([], [], color=MEASURED, lw=1.5, label="measured torque; estimated friction"),
                            Line2D([], [], color=PREDICTED, lw=1.5, label="predicted by the model")],
                   loc="outside lower center", ncol=2)
    return fig


def write_prediction(friction: str | Path, params: str | Path, table: str | Path | None = None,
                     figure: str | Path | None = None, workers: int = 1) -> TorquePrediction:
    """Predict the torques of the friction table ``friction`` with the parameters ``params``
    (:func:`~wbfriction.pipeline.predict_step.predict_table`) and write the prediction table to ``table`` and its
    figure (:func:`prediction_figure`, PNG) to ``figure``, each whole or not at all (None: not written).

    Raises:
        InputError: what :func:`~wbfriction.pipeline.predict_step.predict_table` raises; a ``figure`` not named
            ``.png`` (before any work).
        OutputError: the system refused a write.
    """
    if figure is not None and Path(figure).suffix.lower() != ".png":
        raise InputError(f"--figure {figure}: the figure is a PNG file: name it .png")
    pred, samples = predict_table(friction, params, workers, table)
    if figure is not None:
        fig = prediction_figure(samples, f"Torques of {Path(friction).name} predicted by {Path(params).name}")
        data = png_bytes(fig)
        write_atomic(figure, lambda tmp: Path(tmp).write_bytes(data))
    return pred

"""Friction over velocity as the report and the studies draw it: each joint's valid estimates, its fit as it predicts
them (:data:`FIT_DRAWN`, :func:`drawn_fit`) and its target, joint by joint (:func:`friction_overview_figure`,
:func:`friction_curves_figure`), and one joint at a glance (:func:`joint_figure`: the cloud, ``tau_f`` over time by
support phase, Fig. 7.4 and Fig. 7.1). Friction in the project's sign convention, as in :mod:`.figures`.
"""

from __future__ import annotations

from collections.abc import Mapping
from collections.abc import Set as AbstractSet
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import rc_context
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from wbfriction.fit.predict import predicted_friction
from wbfriction.fit.result import FitResult
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import ModelParams
from wbfriction.report.figures import READABLE, REPORT_WIDTH, joint_label, save_png, short_joint
from wbfriction.report.timeaxis import log_runs, time_from_start, time_panels, widest_run


def friction_curves_figure(est: FrictionEstimate, fits: list[FitResult], path: str | Path,
                           columns: int = 6) -> None:
    """Small multiples: per joint the valid estimates over velocity, the fitted model and the
    target (when known), shared axes (:func:`friction_overview_figure`)."""
    fig = friction_overview_figure(est, [f.joint for f in fits], {f.joint: f for f in fits},
                                   {f.joint: f.target for f in fits if f.target is not None}, columns=columns,
                                   title="Friction over velocity: valid estimates, each joint's fit as it "
                                         "predicts them, target")
    save_png(fig, path)


def model_label(fit: FitResult) -> str:
    """A fit's model as its legend names it: the family, and the terms beyond velocity it kept (``stribeck +
    ripple``)."""
    terms = fit.kept_terms
    return fit.model + ("" if terms is None else " + " + " + ".join(terms.kept))


FIT_DRAWN = ("the fit as it predicts the samples: its curve over velocity; where it kept terms beyond velocity or "
             "the estimate went through a filter, its prediction at each valid sample (dots)")
"""How :func:`_cloud` draws a fit (the figures' captions say so)."""


def drawn_fit(est: FrictionEstimate, i: int, fit: FitResult | None) -> tuple[str, np.ndarray, np.ndarray] | None:
    """The fit of joint ``i`` as :func:`_cloud` draws it: ``(kind, qd, tau_f)``, ``kind`` ``"curve"`` (a velocity
    model with no filter: its curve over the valid samples' velocities, 400 points, ``qd`` [rad/s] increasing) or
    ``"samples"`` (its prediction at each valid sample where it has one,
    :func:`~wbfriction.fit.predict.predicted_friction`: the terms beyond velocity at the angles, loads and
    temperatures the log met them, the offset included); ``tau_f`` [N·m] in the sign convention. None: no fit, no
    parameters or no valid sample."""
    m = est.valid[:, i]
    if fit is None or fit.params is None or not m.any():
        return None
    terms = fit.kept_terms
    if terms is None and est.smoother is None:
        v = np.linspace(est.qd[m, i].min(), est.qd[m, i].max(), 400)
        return "curve", v, np.asarray(fit.params.torque(v), dtype=float)
    model = predicted_friction(est, i, fit.params if terms is None else terms, m)
    drawn = m & np.isfinite(model)
    return "samples", est.qd[drawn, i], model[drawn]


def fit_legend(fit: FitResult, width: int = 30) -> str:
    """A fit's legend entry, its model (:func:`model_label`), broken before a ``+`` past ``width`` characters so that
    it fits a small panel: ``fit: coulomb-viscous\n+ load + ripple``."""
    lines = [f"fit: {fit.model}"]
    for term in (fit.kept_terms.kept if fit.kept_terms is not None else ()):
        if len(lines[-1]) + len(term) + 3 > width:
            lines.append(f"+ {term}")
        else:
            lines[-1] += f" + {term}"
    return "\n".join(lines)


def _cloud(ax, est: FrictionEstimate, i: int, fit: FitResult | None, target: ModelParams | None) -> None:
    """The valid estimates of joint ``i`` over its velocity, under the target (wide, grey) and under the fitted
    model as it predicts those samples (:data:`FIT_DRAWN`, :func:`drawn_fit`): a model of the velocity alone is a
    curve over the velocity, dashed, so that it hides no sample; with terms beyond velocity (a ripple, a load, a
    temperature, which the velocity curve alone leaves out: issue 63) or through the estimate's filter, it is no
    function of the velocity, and its prediction at each valid sample is drawn, a dot per sample (an average over
    velocity would draw a hysteresis loop's two branches as one line between them, where no sample is). The legend
    names its family and terms (:func:`fit_legend`)."""
    m = est.valid[:, i]
    ax.plot(est.qd[m, i], est.tau_f[m, i], ".", ms=1.5, color="C0", alpha=0.35, zorder=2, rasterized=True)
    if m.any() and target is not None:
        v = np.linspace(est.qd[m, i].min(), est.qd[m, i].max(), 400)
        ax.plot(v, target.torque(v), color="k", lw=3, alpha=0.25, zorder=1, label="target")
    drawn = drawn_fit(est, i, fit)
    if drawn is not None and fit is not None:
        kind, qd, tau = drawn
        if kind == "curve":
            ax.plot(qd, tau, color="C1", lw=1.6, ls="--", zorder=3, label=fit_legend(fit))
        else:
            ax.plot(qd, tau, ".", ms=1.0, color="C1", zorder=3, rasterized=True, label=fit_legend(fit))
    ax.axhline(0, color="k", lw=0.4, zorder=0)
    ax.axvline(0, color="k", lw=0.4, zorder=0)


def friction_overview_figure(est: FrictionEstimate, joints: list[str], fits: dict[str, FitResult],
                             targets: Mapping[str, ModelParams], flagged: AbstractSet[str] = frozenset(),
                             columns: int = 4, title: str = "Friction over velocity, valid samples, and each "
                                                            "joint's fit as it predicts them (each joint on its own "
                                                            "axes; red: generates power)",
                             labels: dict[str, str] | None = None) -> Figure:
    """Small multiples, each joint on its own axes (a knee's newton-metres do not squash an ankle's): per
    joint the valid estimates over velocity, the fitted model and the target; titles of joints flagged by
    the energy check in red. ``labels``: joint -> title (default: the name without ``_joint``)."""
    n = max(len(joints), 1)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    with rc_context(READABLE):
        fig = Figure(figsize=(REPORT_WIDTH * columns / 4, 2.6 * rows + 0.9), layout="constrained")
        axes = fig.subplots(rows, columns, squeeze=False).ravel()
        for ax, joint in zip(axes, joints):
            _cloud(ax, est, est.joints.index(joint), fits.get(joint), targets.get(joint))
            label = joint_label((labels or {}).get(joint) or short_joint(joint), est.joints, joint)
            ax.set_title(label, color="C3" if joint in flagged else "k")
        for ax in axes[len(joints):]:
            ax.set_visible(False)
        for ax in axes[:len(joints)]:  # each joint's own model in its own legend
            fitted = [(h, n) for h, n in zip(*ax.get_legend_handles_labels()) if n.startswith("fit: ")]
            if fitted:
                ax.legend(*zip(*fitted), loc="best", frameon=False, markerscale=6)
        handles, names = axes[0].get_legend_handles_labels()
        shared = [(h, n) for h, n in zip(handles, names) if not n.startswith("fit: ")]
        if shared:  # under the panels, where it hides no sample
            fig.legend(*zip(*shared), loc="outside lower right", ncols=len(shared))
        fig.supxlabel("qd [rad/s]")
        fig.supylabel("tau_f [N·m]")
        fig.suptitle(title)
    return fig


def _cloud_panel(ax: Axes, est: FrictionEstimate, i: int, fit: FitResult | None,
                 target: ModelParams | None) -> None:
    """Panel (a) of :func:`joint_figure`: the friction cloud with the fitted model and the target."""
    _cloud(ax, est, i, fit, target)
    ax.set_xlabel("qd [rad/s]")
    ax.set_ylabel("tau_f [N·m]")
    ax.set_title("(a) friction over velocity, valid samples")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper right")


PHASE_COLORS = {"single": "#1f5fa8", "double": "#2ca02c", "flight": "#d62728"}
"""Each support phase's colour in panel (b) of :func:`joint_figure`, drawn opaque: dark blue, green, red (the
valid samples over them in orange)."""


def _phase_panel(fig: Figure, spec: Any, est: FrictionEstimate, i: int) -> list[Axes]:
    """Panel (b) of :func:`joint_figure` in the place ``spec``: ``tau_f`` over time coloured by support phase
    (:data:`PHASE_COLORS`; one colour, "samples", for a log of one phase, a fixed-base arm's), the valid samples in
    orange over them; time from the log's start, a panel per run (:func:`~wbfriction.report.timeaxis.time_panels`).
    The y axis spans the valid samples (a double-support estimate, never valid, may leave it: said in the title)."""
    valid_tau = est.tau_f[est.valid[:, i], i]
    lim = 1.5 * float(np.max(np.abs(valid_tau))) + 1e-6 if valid_tau.size else None
    phases = [p for p in PHASE_COLORS if (est.phase == p).any()]
    clipped = [False]

    def plot(ax: Axes, rows: slice, t: np.ndarray) -> None:
        tau, phase, valid = est.tau_f[rows, i], est.phase[rows], est.valid[rows, i]
        for name in phases:
            y = np.where(phase == name, tau, np.nan)
            ax.plot(t, y, lw=0.7, color=PHASE_COLORS[name], label=name if len(phases) > 1 else "samples")
            clipped[0] |= lim is not None and bool(np.nanmax(np.abs(y), initial=0.0) > lim)
        ax.plot(t, np.where(valid, tau, np.nan), lw=0.9, color="C1", label="valid")

    axes = time_panels(fig, spec, est.time, plot)
    axes[0].set_ylabel("tau_f [N·m]")
    title = "(b) tau_f over time by support phase" + (" (axis: valid samples; others clipped)" if clipped[0] else "")
    if len(axes) > 1:
        box = axes[0].get_position(), axes[-1].get_position()  # above the runs' titles
        fig.text(0.5 * (box[0].x0 + box[1].x1), box[0].y1 + 0.035, title, ha="center", va="bottom",
                 fontsize=READABLE["axes.titlesize"])
    else:
        axes[0].set_title(title)
    if lim is not None:
        axes[0].set_ylim(-lim, lim)
    axes[-1].legend(ncol=2, loc="upper right")
    return axes


def _delta_panel(ax: Axes, est: FrictionEstimate, i: int) -> None:
    """Panel (c) of :func:`joint_figure` (Fig. 7.4): both schemes' ``Delta qdd`` and ``qd`` over one valid stretch,
    time from its run's start (:func:`~wbfriction.report.timeaxis.time_from_start`)."""
    run = widest_run(est.valid[:, i], est.qd[:, i])
    if est.delta_qdd is not None and run.stop > run.start:
        runs = log_runs(est.time)
        t = time_from_start(est.time, runs)[run]
        ax.set_label("time")
        diff = est.metadata.get("estimate_options", {}).get("diff", "estimate")
        ax.plot(t, est.delta_qdd[run, i], color="C0", lw=1, label=f"Δqdd ({diff})")
        if est.companion_delta_qdd is not None:
            ax.plot(t, est.companion_delta_qdd[run, i], color="C2", lw=0.8, alpha=0.8,
                    label=f"Δqdd ({est.companion_diff or 'companion'})")
        ax.axhline(0, color="k", lw=0.4)
        ax.set_ylabel("Δqdd [rad/s²]")
        ax_v = ax.twinx()
        ax_v.plot(t, est.qd[run, i], color="C3", lw=1, label="qd")
        ax_v.set_ylabel("qd [rad/s]", color="C3")
        for a in (ax, ax_v):  # both zero lines at mid-height: the crossings line up by eye
            top = float(np.nanmax(np.abs(a.get_ylim())))
            a.set_ylim(-top, top)
        ax.legend(loc="upper left")
        which = next((k for k, r in enumerate(runs) if r.rows.start <= run.start < r.rows.stop), 0)
        ax.set_xlabel("time [s]" if len(runs) == 1 else f"time from run {which + 1}'s start [s]")
    else:
        ax.text(0.5, 0.5, "no acceleration difference in the table", ha="center", va="center",
                transform=ax.transAxes)
    ax.set_title("(c) Fig. 7.4: Δqdd and qd, one valid stretch")


def _spectrum_panel(ax: Axes, spectrum: tuple[np.ndarray, np.ndarray, float] | None, max_freq: float) -> None:
    """Panel (d) of :func:`joint_figure` (Fig. 7.1): the spectrum of ``qdd_est`` and its cutoff, hidden without
    one. The axis reaches the cutoff when it lies beyond ``max_freq`` (up to the spectrum's last frequency)."""
    if spectrum is not None:
        freq, amp, cutoff = spectrum
        top = min(max(max_freq, 1.15 * cutoff), float(freq[-1]))
        keep = (freq > 0) & (freq <= top)
        ax.semilogy(freq[keep], amp[keep], lw=0.7, color="C0")
        ax.axvline(cutoff, color="C1", ls="--", lw=1.2, label=f"cutoff {cutoff:.1f} Hz")
        ax.set_xlim(0, top)
        ax.set_title("(d) Fig. 7.1: spectrum of qdd_est")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("amplitude [rad/s²]")
        ax.legend(loc="upper right")
    else:
        ax.set_visible(False)


def joint_figure(est: FrictionEstimate, joint: str, fit: FitResult | None, target: ModelParams | None,
                 spectrum: tuple[np.ndarray, np.ndarray, float] | None = None, max_freq: float = 50.0) -> Figure:
    """One joint at a glance, four panels in two rows, :data:`REPORT_WIDTH` inches wide with fonts of
    :data:`READABLE` size:

    (a) the friction cloud with the fitted model and the target;
    (b) ``tau_f`` over time coloured by support phase (valid samples dark);
    (c) Fig. 7.4: ``Delta qdd`` through the estimate's scheme and through the companion scheme,
        with ``qd`` (right axis), over the valid stretch where the joint moves most: with an exact
        model they cross zero together with opposite signs;
    (d) Fig. 7.1: the amplitude spectrum of ``qdd_est = qdd - Delta qdd`` and its suggested cutoff
        (``spectrum = (freq, amplitude, cutoff)``), when computed.
    """
    i = est.joints.index(joint)
    with rc_context(READABLE):
        # a fixed layout: constrained layout would cost most of the time of a report's many figures
        fig = Figure(figsize=(REPORT_WIDTH, 6.4))
        grid = fig.add_gridspec(2, 2, width_ratios=[1, 1.3], wspace=0.3, hspace=0.5, left=0.075, right=0.985,
                                bottom=0.09, top=0.93)
        _cloud_panel(fig.add_subplot(grid[0, 0]), est, i, fit, target)
        _phase_panel(fig, grid[0, 1], est, i)
        _delta_panel(fig.add_subplot(grid[1, 0]), est, i)
        _spectrum_panel(fig.add_subplot(grid[1, 1]), spectrum, max_freq)
    return fig

"""Figures of the simulation study (thesis Fig. 6.1-6.3) and friction curves, as PNG files.

Uses matplotlib's object API (``matplotlib.figure.Figure``), so no display or global
backend is needed. Friction is plotted in the project's sign convention: ``tau_f``, the
torque friction exerts on the joint [N·m] (negative of the model f of eq. 3.5).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from .estimate import FrictionEstimate
from .friction import FrictionParams
from .identify import FitResult
from .log import write_atomic

_DOUBLE_SUPPORT_COLOR = "#dddddd"


def _save(fig: Figure, path: str | Path) -> None:
    write_atomic(path, lambda tmp: fig.savefig(tmp, format="png", dpi=110))


def _shade_double_support(ax, est: FrictionEstimate) -> None:
    ds = est.contact.all(axis=1)
    edges = np.flatnonzero(np.diff(np.r_[0, ds.astype(np.int8), 0]))
    for s, e in zip(edges[::2], edges[1::2]):
        ax.axvspan(est.time[s], est.time[e - 1], color=_DOUBLE_SUPPORT_COLOR, lw=0)


def support_phases_figure(est: FrictionEstimate, joints: list[str], path: str | Path,
                          title: str = "Fig. 6.1: estimated friction, single and double support") -> None:
    """Estimated (all samples, single and double support) vs true friction over time, one
    panel per joint; double support shaded grey."""
    fig = Figure(figsize=(11, 1.6 * len(joints) + 0.8), layout="constrained")
    axes = fig.subplots(len(joints), 1, sharex=True, squeeze=False)[:, 0]
    for ax, joint in zip(axes, joints):
        i = est.joints.index(joint)
        _shade_double_support(ax, est)
        if est.tau_f_true is not None:
            ax.plot(est.time, est.tau_f_true[:, i], color="k", lw=2.5, alpha=0.35, label="target")
        ax.plot(est.time, est.tau_f[:, i], color="C0", lw=0.8, label="estimate")
        ax.set_ylabel(joint.replace("_joint", ""), fontsize=8)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s] (grey: double support)")
    fig.suptitle(title)
    _save(fig, path)


def derivative_schemes_figure(estimates: dict[str, FrictionEstimate], joint: str, foot: int,
                              path_time: str | Path, path_velocity: str | Path) -> None:
    """Fig. 6.2 (over time) and Fig. 6.3 (over the joint velocity) of one joint for several
    differentiation schemes, in its valid single-support samples, split by whether the
    joint's leg (the one ending at contact ``foot``) swings or stands."""
    fig_t = Figure(figsize=(11, 4), layout="constrained")
    ax_t = fig_t.subplots()
    fig_v = Figure(figsize=(11, 3.6), layout="constrained")
    axes_v = fig_v.subplots(1, len(estimates), sharex=True, sharey=True, squeeze=False)[0]
    first = next(iter(estimates.values()))
    i = first.joints.index(joint)
    _shade_double_support(ax_t, first)
    if first.tau_f_true is not None:
        ax_t.plot(first.time, first.tau_f_true[:, i], color="k", lw=2.5, alpha=0.35, label="target")
    for c, (label, est) in enumerate(estimates.items()):
        tau = np.where(est.unique, est.tau_f[:, i], np.nan)
        ax_t.plot(est.time, tau, lw=0.8, color=f"C{c}", label=label)
        ax = axes_v[c]
        swing = est.valid[:, i] & ~est.contact[:, foot]
        stance = est.valid[:, i] & est.contact[:, foot]
        ax.plot(est.qd[stance, i], est.tau_f[stance, i], ".", ms=1.5, color="C3", label="leg in stance")
        ax.plot(est.qd[swing, i], est.tau_f[swing, i], ".", ms=1.5, color="C0", label="leg in swing")
        if est.tau_f_true is not None:
            order = np.argsort(est.qd[est.unique, i])
            ax.plot(est.qd[est.unique, i][order], est.tau_f_true[est.unique, i][order], color="k", lw=1,
                    label="target")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel("qd [rad/s]")
    axes_v[0].set_ylabel("tau_f [N·m]")
    axes_v[0].legend(fontsize=7, markerscale=4)
    lim = np.nanpercentile(np.abs(first.tau_f_true[:, i]), 100) * 3 if first.tau_f_true is not None else None
    if lim:
        ax_t.set_ylim(-lim, lim)
        axes_v[0].set_ylim(-lim, lim)
    ax_t.set_xlabel("time [s] (grey: double support; single support only)")
    ax_t.set_ylabel(f"tau_f {joint} [N·m]")
    ax_t.legend(fontsize=8, loc="upper right")
    fig_t.suptitle(f"Fig. 6.2: differentiation schemes over time, {joint}")
    fig_v.suptitle(f"Fig. 6.3: differentiation schemes over velocity, {joint}")
    _save(fig_t, path_time)
    _save(fig_v, path_velocity)


def friction_curves_figure(est: FrictionEstimate, fits: list[FitResult], path: str | Path,
                           columns: int = 6) -> None:
    """Small multiples: per joint the valid estimates over velocity, the fitted model and the
    target (when known), shared velocity axis."""
    n = len(fits)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(2.6 * columns, 2.3 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, squeeze=False).ravel()
    for ax, fit in zip(axes, fits):
        i = est.joints.index(fit.joint)
        m = est.valid[:, i]
        ax.plot(est.qd[m, i], est.tau_f[m, i], ".", ms=1, color="C0", alpha=0.3)
        if m.any():
            v = np.linspace(est.qd[m, i].min(), est.qd[m, i].max(), 400)
            if fit.target is not None:
                ax.plot(v, fit.target.torque(v), color="k", lw=2.5, alpha=0.35, label="target")
            if fit.params is not None:
                ax.plot(v, fit.params.torque(v), color="C1", lw=1, label="fit")
        ax.set_title(fit.joint.replace("_joint", ""), fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7)
    fig.supxlabel("qd [rad/s]")
    fig.supylabel("tau_f [N·m]")
    fig.suptitle("Friction over velocity: valid estimates, fitted model (3.5), target")
    _save(fig, path)


def filter_curves_figure(curves: dict[str, dict], joint: str, target, position_std: float | None,
                         path: str | Path) -> None:
    """Fig. 7.2 kind: one joint's valid estimates over velocity for several filters (one
    panel each, shared axes), with the target and the model fitted through the filter."""
    n = max(len(curves), 1)
    columns = min(n, 4)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.2 * columns, 2.7 * rows + 0.7), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, sharey=True, squeeze=False).ravel()
    for ax, (label, c) in zip(axes, curves.items()):
        ax.plot(c["qd"], c["tau_f"], ".", ms=1, color="C0", alpha=0.3)
        if len(c["qd"]):
            v = np.linspace(np.min(c["qd"]), np.max(c["qd"]), 400)
            ax.plot(v, target.torque(v), color="k", lw=2.5, alpha=0.35, label="target")
            if c["fit"] is not None:
                ax.plot(v, FrictionParams.from_dict(c["fit"]).torque(v), color="C1", lw=1, label="fit")
        ax.set_title(label, fontsize=9)
        ax.tick_params(labelsize=7)
    for ax in axes[len(curves):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=7)
    lim = 3 * float(np.max(np.abs(target.torque(np.linspace(-1, 1, 50)))))
    axes[0].set_ylim(-lim, lim)
    fig.supxlabel("qd [rad/s]")
    fig.supylabel("tau_f [N·m]")
    noise = "exact log" if position_std is None else f"position noise {position_std:g} rad"
    fig.suptitle(f"Fig. 7.2: {joint} over velocity through each filter ({noise})")
    _save(fig, path)


def spectrum_figure(spec, path: str | Path, max_freq: float = 50.0, columns: int = 4) -> None:
    """Fig. 7.1 kind: amplitude spectrum of the estimated acceleration per joint (log scale,
    shared axes), the suggested cutoff of each joint dashed, the overall one solid."""
    n = len(spec.joints)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.0 * columns, 2.2 * rows + 0.7), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, sharey=True, squeeze=False).ravel()
    keep = (spec.freq > 0) & (spec.freq <= max_freq)
    for i, (ax, joint) in enumerate(zip(axes, spec.joints)):
        ax.semilogy(spec.freq[keep], spec.amplitude[keep, i], lw=0.7, color="C0")
        ax.axvline(spec.cutoff[i], color="C1", ls="--", lw=1)
        ax.axvline(spec.suggestion, color="C3", lw=1)
        ax.set_title(f"{joint.replace('_joint', '')}: {spec.cutoff[i]:.1f} Hz", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.supxlabel("frequency [Hz]")
    fig.supylabel("amplitude of qdd_est [rad/s²]")
    fig.suptitle(f"Fig. 7.1: spectrum of the estimated acceleration; suggested cutoff {spec.suggestion:.1f} Hz "
                 f"(dashed: each joint's; the median of them)")
    _save(fig, path)


def velocity_panels_figure(panels: list[tuple[str, FrictionEstimate, np.ndarray]], joint: str,
                           target: FrictionParams | None, path: str | Path, title: str) -> None:
    """Friction of one joint over its velocity, one panel per (label, estimate, samples mask),
    on shared axes, with the target curve (Fig. 6.4, 6.5)."""
    fig = Figure(figsize=(5.0 * len(panels), 3.8), layout="constrained")
    axes = fig.subplots(1, len(panels), sharex=True, sharey=True, squeeze=False)[0]
    for ax, (label, est, mask) in zip(axes, panels):
        i = est.joints.index(joint)
        ax.plot(est.qd[mask, i], est.tau_f[mask, i], ".", ms=1.5, alpha=0.4, color="C0", label="estimate")
        if target is not None:
            v = np.linspace(np.nanmin(est.qd[mask, i]), np.nanmax(est.qd[mask, i]), 400)
            ax.plot(v, target.torque(v), color="k", lw=2, alpha=0.6, label="target")
        ax.set_title(f"{label} ({int(mask.sum())} samples)", fontsize=9)
        ax.set_xlabel(f"{joint.replace('_joint', '')} velocity [rad/s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("tau_f [N·m]")
    axes[0].legend(loc="upper right", fontsize=8, markerscale=6)
    fig.suptitle(title)
    _save(fig, path)

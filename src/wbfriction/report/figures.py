"""Figures of the simulation study (thesis Fig. 6.1-6.3) and friction curves, as PNG files.

Uses matplotlib's object API (``matplotlib.figure.Figure``), so no display or global
backend is needed. Friction is plotted in the project's sign convention: ``tau_f``, the
torque friction exerts on the joint [N·m] (negative of the model f of eq. 3.5).
"""

from __future__ import annotations

import io
import re
import warnings
from collections.abc import Mapping, Sequence
from collections.abc import Set as AbstractSet
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import rc_context, rcParams
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from wbfriction.fit.predict import predicted_friction
from wbfriction.fit.result import FitResult
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import FrictionParams, ModelParams
from wbfriction.logs.tables import write_atomic
from wbfriction.report.timeaxis import log_runs, time_from_start, time_panels, widest_run

_DOUBLE_SUPPORT_COLOR = "#dddddd"
REPORT_DPI = 100
"""Pixels per inch of the report's figures: they are at most :data:`REPORT_WIDTH` inches wide, so a page 1400 px
wide shows them at their own size and a font of :data:`READABLE` points is at least 11 px."""
REPORT_WIDTH = 12.0
"""Width of the report's figures [in] (1200 px at :data:`REPORT_DPI`)."""
READABLE: dict[Any, Any] = {"font.size": 10.0, "axes.titlesize": 10.5, "axes.labelsize": 10.0, "xtick.labelsize": 9.0,
                            "ytick.labelsize": 9.0, "legend.fontsize": 8.5, "figure.titlesize": 11.0,
                            "axes.formatter.useoffset": False}
"""Font sizes [pt] of the report's figures: the smallest, 8.5 pt, is 11.8 px at :data:`REPORT_DPI`."""


# ----------------------------------------------------------------- names no font draws (issue 53)
BY_INDEX = "joint #{}"
"""How a joint whose name no installed font draws is drawn: by its index in the figure's estimate (from 0)."""
BY_INDEX_NOTE = ("joint #i: joint i (from 0; on a trends page, by name) of the log, whose name no installed font draws "
                 "(e.g. Noto Sans CJK would)")
"""What a figure that draws a joint by its index says, once."""
_GLYPH_WARNING = r"Glyph \d+ .*missing from font"
"""Matplotlib's warning for a character its font has no glyph for (its figure shows a box)."""


@lru_cache(maxsize=1)
def _default_charmap() -> frozenset[int]:
    """The characters the default font (matplotlib's ``sans-serif``) draws."""
    from matplotlib import font_manager
    from matplotlib.ft2font import FT2Font

    return frozenset(FT2Font(font_manager.findfont(font_manager.FontProperties())).get_charmap())


@lru_cache(maxsize=1)
def _installed_charmaps() -> tuple[tuple[str, frozenset[int]], ...]:
    """(family, characters) of every other font matplotlib finds installed, in its list's order."""
    from matplotlib import font_manager
    from matplotlib.ft2font import FT2Font

    out = []
    for entry in font_manager.fontManager.ttflist:
        try:
            out.append((entry.name, frozenset(FT2Font(entry.fname).get_charmap())))
        except (OSError, RuntimeError, ValueError):
            continue
    return tuple(out)


@lru_cache(maxsize=256)
def font_for(text: str) -> str | None:
    """``""`` when the default font draws every character of ``text``; else the family of an installed font that
    draws those it does not (drawn in it, the default font first); None: no installed font does."""
    missing = {ord(c) for c in text if not c.isspace()} - _default_charmap()
    if not missing:
        return ""
    return next((name for name, charmap in _installed_charmaps() if missing <= charmap), None)


def joint_label(label: str, joints: Sequence[str], joint: str) -> str:
    """``label`` (a joint's name as a figure shows it) where a font draws it, else :data:`BY_INDEX` with the
    joint's index in ``joints`` (the figure says what it is, :func:`_drawable`)."""
    return label if font_for(label) is not None else BY_INDEX.format(list(joints).index(joint))


def _drawable(fig: Figure) -> None:
    """Every text of ``fig`` in a font that draws it (an installed font beside the default where the default has
    no glyph for a character); one line added to the title where a joint is drawn by its index."""
    from matplotlib.text import Text

    by_index = False
    for text in fig.findobj(Text):
        content = text.get_text()
        font = font_for(content) if content else ""
        if font:
            text.set_fontfamily([*rcParams["font.family"], font])
        by_index = by_index or re.search(r"\bjoint #\d+\b", content) is not None
    title = fig.get_suptitle()
    if by_index and BY_INDEX_NOTE not in title:  # once, however often the figure is saved
        fig.suptitle(f"{title}\n{BY_INDEX_NOTE}" if title else BY_INDEX_NOTE)


def _savefig(fig: Figure, target: Any, **kwargs: Any) -> None:
    """``fig.savefig`` with every text drawable (:func:`_drawable`); a character no installed font has (a title
    given) is drawn as a box, without matplotlib's warning on standard error."""
    _drawable(fig)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", _GLYPH_WARNING, UserWarning)
        fig.savefig(target, **kwargs)


def _save(fig: Figure, path: str | Path) -> None:
    write_atomic(path, lambda tmp: _savefig(fig, tmp, format="png", dpi=110))


def png_bytes(fig: Figure, dpi: int = REPORT_DPI) -> bytes:
    """The figure as PNG bytes (no timestamp in the file: the same figure gives the same bytes)."""
    buf = io.BytesIO()
    _savefig(fig, buf, format="png", dpi=dpi, metadata={"Software": None})
    return buf.getvalue()


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
        ax.set_ylabel(joint_label(_short(joint), est.joints, joint), fontsize=8)
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
    target (when known), shared axes (:func:`friction_overview_figure`)."""
    fig = friction_overview_figure(est, [f.joint for f in fits], {f.joint: f for f in fits},
                                   {f.joint: f.target for f in fits if f.target is not None}, columns=columns,
                                   title="Friction over velocity: valid estimates, each joint's fit as it "
                                         "predicts them, target")
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


def spectrum_figure(spec, path: str | Path, max_freq: float | None = None, columns: int = 4) -> None:
    """Fig. 7.1 kind: amplitude spectrum of the estimated acceleration per joint (log scale,
    shared axes), the suggested cutoff of each joint dashed, the overall one solid (none when the content is
    broadband: :attr:`~wbfriction.signals.spectrum.AccelerationSpectrum.cutoff_found`), up to ``max_freq``
    [Hz] (default: :attr:`~wbfriction.signals.spectrum.AccelerationSpectrum.shown_band`, which every cutoff
    drawn is inside)."""
    max_freq = spec.shown_band if max_freq is None else max_freq
    n = len(spec.joints)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.0 * columns, 2.2 * rows + 0.7), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, sharey=True, squeeze=False).ravel()
    keep = (spec.freq > 0) & (spec.freq <= max_freq)
    for i, (ax, joint) in enumerate(zip(axes, spec.joints)):
        ax.semilogy(spec.freq[keep], spec.amplitude[keep, i], lw=0.7, color="C0")
        ax.axvline(spec.cutoff[i], color="C1", ls="--", lw=1)
        if spec.cutoff_found:
            ax.axvline(spec.suggestion, color="C3", lw=1)
        ax.set_title(f"{joint_label(_short(joint), spec.joints, joint)}: {spec.cutoff[i]:.1f} Hz", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.supxlabel("frequency [Hz]")
    fig.supylabel("amplitude of qdd_est [rad/s²]")
    overall = (f"suggested cutoff {spec.suggestion:.1f} Hz (the median of them)" if spec.cutoff_found else
               f"no cutoff: the content is broadband (median {spec.suggestion:.0f} Hz of {spec.nyquist:.0f})")
    fig.suptitle(f"Fig. 7.1: spectrum of the estimated acceleration\ndashed: where each joint's content ends; "
                 f"{overall}")
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
        ax.set_xlabel(f"{joint_label(_short(joint), est.joints, joint)} velocity [rad/s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("tau_f [N·m]")
    axes[0].legend(loc="upper right", fontsize=8, markerscale=6)
    fig.suptitle(title)
    _save(fig, path)



def _short(joint: str) -> str:
    return joint.replace("_joint", "")


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
            label = joint_label((labels or {}).get(joint) or _short(joint), est.joints, joint)
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


def sensitivity_figure(sens, joints: list[str], columns: int = 4) -> Figure:
    """Fig. 7.5 / 7.6 kind: per joint the valid estimates over velocity for every inertia factor
    (lines through consecutive samples, so that the branches of rising and falling velocity
    show), small multiples with a shared velocity axis."""
    from matplotlib import colormaps

    n = max(len(joints), 1)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.3 * columns, 2.6 * rows + 0.8), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, squeeze=False).ravel()
    others = sorted(f for f in sens.factors if f != 1.0)
    span = max([abs(f - 1.0) for f in others] + [1e-9])
    cmap = colormaps["coolwarm"]
    for ax, joint in zip(axes, joints):
        for f, est in sorted(zip(sens.factors, sens.estimates), key=lambda x: x[0]):
            i = est.joints.index(joint)
            m = est.valid[:, i]
            color = "k" if f == 1.0 else cmap(0.5 + 0.5 * (f - 1.0) / span)
            ax.plot(np.where(m, est.qd[:, i], np.nan), np.where(m, est.tau_f[:, i], np.nan), lw=0.6,
                    color=color, alpha=0.9 if f == 1.0 else 0.7, label=f"x {f:g}")
        ax.set_title(joint_label(_short(joint), joints, joint), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.axhline(0, color="k", lw=0.3)
    for ax in axes[len(joints):]:
        ax.set_visible(False)
    axes[0].legend(fontsize=6, loc="upper left")
    fig.supxlabel("qd [rad/s]")
    fig.supylabel("tau_f [N·m]")
    fig.suptitle(f"Friction estimate with every body's inertia scaled ({sens.part}; black: the model as given)",
                 fontsize=10)
    return fig


def save_png(fig: Figure, path: str | Path) -> None:
    """Write a figure as a PNG file, whole or not at all."""
    _save(fig, path)


def rollout_figure(results: Sequence[Any], path: str | Path, columns: int = 3) -> None:
    """The tracking error of replays of one log (:class:`~wbfriction.replay.rollout.RolloutResult`, the same joints and
    stretch): per joint, the simulated less the logged angle [mrad] against the log's time from the stretch's start
    [s], one line per replay, its RMS in the legend; a replay restarted from the log every ``horizon`` seconds starts
    each window at zero error (dotted lines mark the restarts)."""
    first = results[0]
    n = len(first.joints)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    fig = Figure(figsize=(3.4 * columns, 2.0 * rows + 0.9), layout="constrained")
    axes = fig.subplots(rows, columns, sharex=True, squeeze=False).ravel()
    t = first.time - first.time[0]
    for i, (ax, joint) in enumerate(zip(axes, first.joints)):
        for k, result in enumerate(results):
            ax.plot(t, 1e3 * result.error[:, i], lw=0.7, color=f"C{k}",
                    label=f"{result.label} {1e3 * result.rms[i]:.2f}")
        if first.horizon is not None:
            for start in np.arange(first.horizon, t[-1], first.horizon):
                ax.axvline(start, color="0.8", lw=0.5, ls=":")
        ax.axhline(0.0, color="0.5", lw=0.5)
        ax.set_title(_short(joint), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, loc="upper right", title="RMS [mrad]", title_fontsize=6)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.supxlabel("time from the stretch's start [s]")
    fig.supylabel("simulated - logged angle [mrad]")
    window = "one shot" if first.horizon is None else f"restarted from the log every {first.horizon:g} s"
    fig.suptitle(f"Replay of the log's set-points, {window}")
    _save(fig, path)

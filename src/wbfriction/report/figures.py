"""Figures of the simulation study (thesis Fig. 6.1-6.3), as PNG files, and what every figure of the report shares:
its size and fonts, a name no font draws, the PNG it is saved as (friction over velocity:
:mod:`~wbfriction.report.friction_figures`).

Uses matplotlib's object API (``matplotlib.figure.Figure``), so no display or global
backend is needed. Friction is plotted in the project's sign convention: ``tau_f``, the
torque friction exerts on the joint [N·m] (negative of the model f of eq. 3.5).
"""

from __future__ import annotations

import io
import re
import warnings
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import rcParams
from matplotlib.figure import Figure

from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import FrictionParams
from wbfriction.logs.tables import write_atomic

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
        ax.set_ylabel(joint_label(short_joint(joint), est.joints, joint), fontsize=8)
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
        ax.set_title(f"{joint_label(short_joint(joint), spec.joints, joint)}: {spec.cutoff[i]:.1f} Hz", fontsize=8)
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
        ax.set_xlabel(f"{joint_label(short_joint(joint), est.joints, joint)} velocity [rad/s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("tau_f [N·m]")
    axes[0].legend(loc="upper right", fontsize=8, markerscale=6)
    fig.suptitle(title)
    _save(fig, path)



def short_joint(joint: str) -> str:
    """A joint's name as a figure's panel title names it: without ``_joint``."""
    return joint.replace("_joint", "")


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
        ax.set_title(joint_label(short_joint(joint), joints, joint), fontsize=8)
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
        ax.set_title(short_joint(joint), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, loc="upper right", title="RMS [mrad]", title_fontsize=6)
    for ax in axes[n:]:
        ax.set_visible(False)
    fig.supxlabel("time from the stretch's start [s]")
    fig.supylabel("simulated - logged angle [mrad]")
    window = "one shot" if first.horizon is None else f"restarted from the log every {first.horizon:g} s"
    fig.suptitle(f"Replay of the log's set-points, {window}")
    _save(fig, path)

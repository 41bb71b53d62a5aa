"""A fleet's friction trends as one self-contained HTML page (issue 25): ``wbfriction trends RESULTS -o x.html``.

Per robot: the drifts found first (a table), then a small multiple per joint (flagged joints first, each on its
own axes): each followed quantity over time relative to its baseline, value ± standard error, a drift's onset
marked; then every tested quantity as a table, the figures' numbers. Figures are PNG
embedded in the page (no script, no network); the same trends give the same bytes.
"""

from __future__ import annotations

import base64
import html
from datetime import datetime
from pathlib import Path

import numpy as np
from matplotlib import rc_context
from matplotlib.artist import Artist
from matplotlib.figure import Figure

from wbfriction.fleet.change_point import ChangePoint
from wbfriction.fleet.trends import FleetTrends, JointTrend
from wbfriction.logs.tables import write_atomic
from wbfriction.report.figures import READABLE, REPORT_WIDTH, joint_label, png_bytes
from wbfriction.report.html import PAGE_CSS
from wbfriction.report.numbers import p_value_text

SHOWN = ("F_c", "F_v", "f_at_0.3")
"""The quantities each joint's panel shows (every tested quantity is in the table)."""
COLORS = {"F_c": "C0", "F_v": "C1", "f_at_0.3": "C2"}
UNREADABLE = 0.5
"""A series whose median standard error exceeds this share of its baseline is left out of its panel (its numbers
stay in the table): a parameter near zero, such as the viscous friction of a joint that barely moves."""


def _relative(j: JointTrend, q: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A series' used points: times (as datetimes), values and standard errors over its baseline (the fitted one
    when tested, else the median of its first third)."""
    s = j.series[q]
    idx = np.flatnonzero(s.used)
    cp = j.tests.get(q)
    base = cp.baseline if cp is not None else float(np.median(s.value[idx][: max(1, idx.size // 3)]))
    base = base if base != 0 else 1.0
    return np.array([s.time[i] for i in idx], dtype=object), s.value[idx] / base, s.se[idx] / abs(base)


def joints_figure(joints: list[JointTrend], title: str, columns: int = 4) -> Figure:
    """Small multiples, one joint per axes: :data:`SHOWN` over time relative to their baselines, ± one
    standard error (a series of :data:`UNREADABLE` precision left out); a flagged joint's title in red and its
    drift's onset a dashed line."""
    n = max(len(joints), 1)
    columns = min(columns, n)
    rows = int(np.ceil(n / columns))
    with rc_context(READABLE):
        fig = Figure(figsize=(REPORT_WIDTH * columns / 4, 2.4 * rows + 1.0), layout="constrained")
        axes = fig.subplots(rows, columns, squeeze=False, sharex=True).ravel()
        names = sorted({j.joint for j in joints})  # a joint no font draws is drawn by its index among them
        for ax, j in zip(axes, joints):
            for q in SHOWN:
                if q in j.series and j.series[q].used.any():
                    t, y, e = _relative(j, q)
                    if np.median(e) > UNREADABLE:  # a value near zero: its ratio would flatten the others
                        continue
                    ax.errorbar(t, y, yerr=e, fmt="o-", ms=3, lw=0.8, color=COLORS[q], label=q, capsize=0)
            if not ax.lines:
                ax.text(0.5, 0.5, "no quantity precise\nenough to draw:\nsee the table", ha="center", va="center",
                        transform=ax.transAxes, color="#5f6b76")
                ax.set_yticks([])
            for cp in j.drifts[:1]:
                ax.axvline(cp.onset_time, color="C3", ls="--", lw=1.0)
            ax.axhline(1.0, color="#888888", lw=0.6)
            drift = f"  drift: {j.drifts[0].quantity}" if j.flagged else ""
            ax.set_title(joint_label(j.joint.removesuffix("_joint"), names, j.joint) + drift,
                         color="C3" if j.flagged else "k")
            ax.tick_params(axis="x", labelrotation=30)
        for ax in axes[len(joints):]:
            ax.set_visible(False)
        legend: dict[str, Artist] = {}
        for ax in axes:  # every quantity shown somewhere, once
            for handle, name in zip(*ax.get_legend_handles_labels()):
                legend.setdefault(name, handle)
        if legend:
            names = [q for q in SHOWN if q in legend]
            fig.legend([legend[q] for q in names], names, loc="outside lower right", ncols=len(names))
        fig.supylabel("value / baseline")
        fig.suptitle(title)
    return fig


def _img(fig: Figure, alt: str) -> str:
    data = base64.b64encode(png_bytes(fig)).decode()
    return f'<img class="fig" alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _date(t: datetime | None) -> str:
    return "" if t is None else t.strftime("%Y-%m-%d %H:%M")


def _num(x: float, digits: int = 4) -> str:
    return "–" if not np.isfinite(x) else f"{x:.{digits}g}"


def _relative_change(cp: ChangePoint) -> str:
    """A relative change in percent; "–" where the baseline is not told from zero (undefined)."""
    return "–" if not np.isfinite(cp.relative) else f"{100 * cp.relative:+.1f} %"


def _at(cp: ChangePoint) -> str:
    """The temperature a change is measured at, and the slope found ("as logged" without temperatures)."""
    if cp.reference_temperature is None:
        return "as logged"
    return (f"{cp.reference_temperature:.3g} °C ({_num(cp.temperature_slope, 2)} ± {_num(cp.temperature_slope_se, 1)}"
            " per °C)")


def _drifts_table(joints: list[JointTrend]) -> str:
    head = ("joint", "quantity", "shape", "onset", "change at the last log", "relative", "p-value", "at")
    rows = "".join(
        f'<tr class="flag"><td>{html.escape(j.joint)}</td><td>{html.escape(cp.quantity)}</td><td>{cp.shape}</td>'
        f"<td>{_date(cp.onset_time)}</td><td>{_num(cp.change)} ± {_num(cp.change_se, 2)}</td>"
        f"<td>{_relative_change(cp)}</td><td>{html.escape(p_value_text(cp.p_value))}</td><td>{_at(cp)}</td></tr>"
        for j in joints for cp in j.drifts)
    return ('<div class="scroll"><table><tr>' + "".join(f"<th>{h}</th>" for h in head) + f"</tr>{rows}</table></div>")


def _tests_table(joints: list[JointTrend]) -> str:
    head = ("joint", "quantity", "points", "last value", "baseline", "shape", "best onset", "change ± se", "relative",
            "p-value", "drift")
    rows = []
    for j in joints:
        for q, cp in j.tests.items():
            s = j.series[q]
            flag = cp in j.drifts
            cls = ' class="flag"' if flag else ""
            rows.append(f"<tr{cls}><td>{html.escape(j.joint)}</td>"
                        f"<td>{html.escape(q)}</td><td>{int(s.used.sum())}</td>"
                        f"<td>{_num(float(s.value[s.used][-1]))}</td><td>{_num(cp.baseline)}</td>"
                        f"<td>{cp.shape}</td><td>{_date(cp.onset_time)}</td>"
                        f"<td>{_num(cp.change)} ± {_num(cp.change_se, 2)}</td>"
                        f"<td>{_relative_change(cp)}</td><td>{html.escape(p_value_text(cp.p_value))}</td>"
                        f"<td>{'yes' if flag else ''}</td></tr>")
    return ('<details><summary>Every tested quantity</summary><div class="scroll"><table><tr>'
            + "".join(f"<th>{h}</th>" for h in head) + "</tr>" + "".join(rows) + "</table></div></details>")


def render_trends(trends: FleetTrends, title: str = "Friction trends") -> str:
    """The page (module docstring)."""
    robots = sorted({j.robot_id for j in trends.joints})
    o = trends.options
    flagged = trends.flagged
    summary = (f'<div class="box {"warn" if flagged or not trends.tested else "ok"}">'
               f"{html.escape(trends.summary())}: " + (", ".join(f"{html.escape(j.robot_id)} {html.escape(j.joint)} "
                                               f"({html.escape(j.drifts[0].quantity)} from "
                                               f"{_date(j.onset_time)})" for j in flagged) or "none") + "</div>")
    sections = []
    for robot_id in robots:
        mine = [j for j in trends.joints if j.robot_id == robot_id]
        shown = [j for j in mine if j.tests]
        still = [j.joint for j in mine if not j.tests]
        mine_flagged = [j for j in shown if j.flagged]
        part = [f'<h2 id="{html.escape(robot_id)}">{html.escape(robot_id)}</h2>']
        part.append(_drifts_table(mine_flagged) if mine_flagged else '<p class="sub">No drift found.</p>')
        if shown:
            part.append(_img(joints_figure(shown, f"{robot_id}: friction over time, relative to its baseline "
                                                  "(± one standard error; dashed: a drift's onset)"),
                             f"{robot_id}'s joints over time"))
        if still:
            part.append(f'<p class="sub">Too few usable logs to follow: {html.escape(", ".join(still))}</p>')
        part.append(_tests_table(shown))
        sections.append("\n".join(part))
    method = (f"A drift is a change of shape {' or '.join(o.shapes)} (hinge: a constant, then a linear change "
              f"from an onset; step: a jump at the onset; the better fit chosen) that fits a quantity's series "
              f"better than a constant, weighted by the fits' standard errors, with a p-value below {o.alpha:g} per "
              f"joint (Bonferroni over its quantities; Monte Carlo, {o.draws()} noise series) and a change of at "
              f"least {100 * o.min_change:.0f} % at the last log. "
              + ("Where a series' logs record the joint's temperature (temperature.<joint>) and it spreads, the "
                 "values' linear dependence on it is fitted with the change, and the change is stated at one "
                 "reference temperature (the drifts' last column): friction measured warm compares with friction "
                 "measured cold. The figures show the values as measured. " if o.temperature else "")
              + "Sign convention: F_c, F_v and f_at_v are "
              "positive for friction opposing the motion (f_at_v = (f(v) − f(−v)) / 2 [N·m], v in rad/s).")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{html.escape(title)}</title><style>{PAGE_CSS}</style></head>
<body>
<h1>{html.escape(title)}</h1>
<p class="sub">{len(robots)} robots, {len(trends.joints)} robot joints. {html.escape(method)}</p>
{summary}
{"".join(sections)}
</body></html>
"""


def write_trends_html(trends: FleetTrends, path: str | Path, title: str = "Friction trends") -> None:
    """Write :func:`render_trends`' page, whole or not at all."""
    text = render_trends(trends, title)
    write_atomic(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))

"""What ``demo`` prints of the thesis's simulation study (:mod:`wbfriction.studies.simulation`,
:mod:`wbfriction.studies.realistic`): Tables 6.1/6.2's layout, the fits that are not ``ok`` and why, the worst
errors, the welded feet's pulls; as :class:`~wbfriction.report.printed.Printed` items."""

from __future__ import annotations

from rich.markup import escape
from rich.table import Table
from rich.text import Text

from wbfriction.report.printed import Printed


def thesis_percent(x: float) -> str:
    """A thesis error [%] to the digits that mean something: 972, not 971.75."""
    return f"{x:.0f}" if x >= 100 else f"{x:.2f}"


def thesis_caption(rows, cols: list[int], params: tuple[str, ...]) -> str:
    """What the table's thesis rows are, and why some of Table 6.1's errors are over 100 % (the straight walk
    barely moved those joints in swing: its fit traded Coulomb for viscous friction; Table 6.2's walk, sideways
    too, has them small)."""
    text = "T6.1 / T6.2: the thesis's errors for the same joint (TORO, straight / straight and sideways) [%]"
    over = [(row, params[k], c) for row in rows if row.thesis_6_1 is not None
            for k, c in enumerate(cols) if row.thesis_6_1[c] > 100]
    if not over:
        return text
    named = ", ".join(f"#{row.number} {name} {thesis_percent(row.thesis_6_1[c])}" for row, name, c in over)
    after = max((row.thesis_6_2[c] for row, _, c in over if row.thesis_6_2 is not None), default=None)
    return (f"{text}; T6.1 over 100 % ({named}): the thesis's straight walk barely moved these joints in swing "
            "and its fit traded Coulomb for viscous friction"
            + ("" if after is None else f"; with sideways steps (T6.2) the same errors are at most {after:.0f} %"))


def study_table(rows, title: str, params: tuple[str, ...] | None = None) -> Table:
    """Tables 6.1/6.2 layout: per leg joint (thesis numbering) the fit's status, target, estimate, error,
    thesis errors (a joint that did not move: no estimate, no error); ``params``: the parameters shown (default:
    every one of model 3.5), their units in the headers."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.report.terminal import header

    params = PARAM_NAMES if params is None else params
    cols = [PARAM_NAMES.index(n) for n in params]
    table = Table(title=title, box=None, pad_edge=False, caption_justify="left",
                  caption="err: error to the target [%]; " + thesis_caption(rows, cols, params))
    table.add_column("#", justify="right")
    table.add_column("joint")
    table.add_column("status")
    for name in params:  # the unit below the name: the columns stay as narrow as their numbers
        table.add_column(Text(header(name).replace(" [", "\n[")), justify="right")
    for row in rows:
        fit = row.fit
        err = fit.error_percent() or {}
        status = fit.verdict().status
        shown = fit.params is not None and status != "not excited"  # a joint that did not move: no value to show
        table.add_row(str(row.number), row.joint, status,
                      *[f"{getattr(fit.params, n):.4f}" if shown else "—" for n in params],
                      style=None if status == "ok" else "dim")
        table.add_row("", f"  {row.group} target", "", *[f"{getattr(fit.target, n):.4g}" for n in params],
                      style="dim")
        table.add_row("", "  err [%]", "", *[f"{err.get(n, float('nan')):.2f}" if shown else "—" for n in params],
                      style="bold")
        for label, ref in (("  T6.1 [%]", row.thesis_6_1), ("  T6.2 [%]", row.thesis_6_2)):
            if ref is not None:
                table.add_row("", label, "", *[thesis_percent(ref[c]) for c in cols], style="dim")
    return table


def not_ok_printed(rows) -> list[Printed]:
    """Which rows of a study table are not ``ok`` fits and why: their errors measure the walk's excitation (or the
    fit's trouble), not the estimate."""
    from wbfriction.studies.common import not_ok

    printed = []
    for row in not_ok(rows):
        verdict = row.fit.verdict()
        if verdict.status == "at bound":
            printed.append(Printed(escape(f"not an ok fit: {row.joint} ({row.group}), {verdict}; a value at a bound "
                                          "is the bound's, not the data's (the others may hold).")))
            continue
        why = ("this walk hardly moved it: no estimate below (a short walk hardly turns the hip yaws: try more "
               "--steps)" if verdict.status == "not excited"
               else "its errors below measure the walk, not the estimate: its parameters are not determined by "
                    "these samples")
        printed.append(Printed(escape(f"not an ok fit: {row.joint} ({row.group}), {verdict}; {why}.")))
    return printed


def worst_printed(rows, worst: dict[str, float], params: tuple[str, ...]) -> list[Printed]:
    """The worst error of each parameter over the leg joints whose fit is ``ok`` (the others said above); none
    without one."""
    ok = sum(row.fit.verdict().ok for row in rows)
    return [Printed(f"worst error over the {ok} leg joints with an ok fit [%]: "
                    + ", ".join(f"{n} {worst[n]:.2f}" for n in params))] if ok else []


def pulls_note(pulls: int, in_double: int) -> str:
    """The demo's count of samples where a welded foot pulled, and what it means."""
    if not pulls:
        return "no welded foot pulled on the ground (the walk is one a real sole could make)"
    return (f"samples where a welded foot pulled on the ground: {pulls}, {in_double} of them in double support. "
            "The ideal simulator welds a standing sole (a bilateral contact): just after a touch-down the weld "
            "stops the landing foot and shares the load with the other by pulling, where a real sole would "
            "bounce or roll. Double-support samples are never valid for the estimate, so its numbers are not "
            "touched" + ("." if in_double == pulls else "; the others are single-support samples: there the "
                         "walk asks more of the ground than it can give."))

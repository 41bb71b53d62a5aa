"""What ``excite`` prints of a design (:mod:`wbfriction.excite`): the predicted errors per joint, the swing joints'
bands and bounds, the log's fits beside the next recording's prediction; as :class:`~wbfriction.report.printed.
Printed` items."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rich.table import Table
from rich.text import Text

from wbfriction.report.printed import Printed

if TYPE_CHECKING:
    from wbfriction.excite.pd_design import PdDesign


def design_shares(doc: dict) -> dict[str, dict[str, float]]:
    """Each joint's parameters' predicted shares of their limits, from a design's document."""
    return {j: {n: p["share"] for n, p in params.items() if p.get("share") is not None}
            for j, params in doc["predicted"].items()}


def pd_design_printed(design: PdDesign, doc: dict) -> list[Printed]:
    """A hung robot's design: each joint's predicted standard error over its ``ok`` limit (status), then the
    ramps, the delay and the worst parameter."""
    names = list(next(iter(doc["predicted"].values())))
    table = Table(title="Predicted standard error / limit of ok (status)", box=None)
    table.add_column("joint")
    for name in names:
        table.add_column(name, justify="right")

    def cell(p: dict) -> str:
        share = "inf" if p["share"] is None else f"{p['share']:.2f}"  # a value of 0: no relative limit
        return share + ("" if p["status"] == "ok" else f" ({p['status']})")

    for joint, params in doc["predicted"].items():
        table.add_row(joint, *(cell(params[n]) for n in names))
    joint, name, share = design.worst()
    chosen = design.chosen
    return [Printed(table), *(Printed(line) for line in (
        f"ramps over {chosen.amplitude:g} of each half range, reversing every {chosen.reversal[0]:g}-"
        f"{chosen.reversal[1]:g} s; least margin to a limit {design.margins.least():.0%}",
        f"delay {1e3 * doc['delay']['value']:.2f} ± {1e3 * doc['delay']['se']:.2g} ms, "
        f"{doc['delay']['share']:.2f} of its limit",
        f"worst: {joint} {name}, {share:.2f} of its limit (below 1: predicted ok)"))]


def arm_design_printed(doc: dict, least_margin: float, weak: float) -> list[Printed]:
    """An arm's design: each joint's predicted F_c and F_v errors over ``weak`` x value, the family the fit is
    predicted to choose and its worst status; then the least margin to a limit (``least_margin``, a share) and the
    worst parameter."""
    shares = design_shares(doc)
    table = Table(title=f"Predicted standard error / {weak:g} x value (family the fit is predicted to choose)",
                  box=None)
    for col in ("joint", "family", "F_c", "F_v", "status"):
        table.add_column(col, justify="left" if col in ("joint", "family", "status") else "right")
    for joint, params in doc["predicted"].items():
        cells = [f"{shares[joint][n]:.3f}" if n in shares[joint] else "-" for n in ("F_c", "F_v")]
        worst = next((p["status"] for p in params.values() if p["status"] != "ok"), "ok")
        table.add_row(joint, doc["models"].get(joint, "-"), *cells, worst)
    w = doc["worst"]
    return [Printed(table), Printed(f"least margin to a limit {least_margin:.0%}; worst: {w['joint']} "
                                    f"{w['parameter']}, {w['share']:.3f} of its limit (below 1: predicted ok)")]


def swing_printed(doc: dict, where: str) -> Printed:
    """The swing joints' table of a standing design's document: band, reach, peak speed, bounds' shares."""
    table = Table(title=f"{where}: band and Cramér-Rao bound / weak limit", box=None)
    for col in ("joint", "band [rad]", "reached [rad]", "peak [rad/s]", "F_c", "F_v"):  # Text: "[rad]" is no tag
        table.add_column(Text(col), justify="left" if col == "joint" else "right")
    for joint, s in doc["swing"].items():
        table.add_row(joint, f"{s['band'][0]:.2f} to {s['band'][1]:.2f}",
                      f"{s['reached'][0]:.2f} to {s['reached'][1]:.2f}", f"{s['peak_velocity']:.2f}",
                      *(f"{s['share'][n]:.3f}" if n in s["share"] else "-" for n in ("F_c", "F_v")))
    return Printed(table)


def next_printed(following, after: Path) -> list[Printed]:
    """The joints ``after`` (the parameters file of the log recorded) left undetermined: the log's fit against the
    next design's prediction (printed whole: a few rows, none of their numbers cut), and the joints held."""
    from wbfriction.actuator.identification import UNITS
    from wbfriction.excite.next import COMPARED

    design = following.design
    units = ", ".join(f"{name} [{UNITS[name]}]" for name in COMPARED)
    table = Table(title=f"The joints {after.name} left undetermined: the log's fit against the design's prediction "
                        f"({units})", box=None)
    table.add_column("joint")
    table.add_column("log's status")
    for name in COMPARED:  # the units in the title: the table fits 100 columns
        table.add_column(f"{name} log", justify="right")
        table.add_column(f"{name} next", justify="right")
    for joint, logged in following.logged.items():
        predicted = design.prediction.joints.get(joint, {})
        cells = []
        for name in COMPARED:
            value, se = logged.values.get(name, (float("nan"), float("nan")))
            p = predicted.get(name)  # an arm's fit predicted to fail has none
            cells += [f"{value:.3f} ± {se:.2g}", "-" if p is None else f"{p.value:.3f} ± {p.se:.2g}"]
        table.add_row(joint, logged.status, *cells)
    held = [j for j in design.joints if j not in design.moving]
    return [Printed(table, whole=True),
            Printed(f"held at their posture (their fits ok): {', '.join(held) if held else 'none'}; prior friction "
                    f"from the fit on {len(following.prior_from_fit)} joints, the simulator's default on the others")]

"""``wbfriction excite``: the motion to record, designed so that its identification determines every parameter."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Literal, Optional

import typer
from rich.table import Table
from rich.text import Text

from wbfriction.cli.common import (
    ConfigOpt,
    MjcfOpt,
    RobotOpt,
    UrdfOpt,
    app,
    console,
    out,
    print_whole,
    refuse_unread,
    robot_of,
    stages,
)
from wbfriction.cli.helpformat import ROBOT
from wbfriction.exceptions import InputError

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: the design is imported when the command runs.
from wbfriction.excite.options import ARM_PERIOD, ARM_RATE, PD_EXCITE, PdExciteOptions
from wbfriction.pipeline.paths import check_paths

HUNG_ONLY = ("amplitude", "velocity")
"""The options only a hung PD-driven robot's design reads: refused for an arm."""
ARM_ONLY = ("period",)
"""The options only an arm's design reads: refused for a hung PD-driven robot."""
FIXED_ONLY = (*HUNG_ONLY, "torque_share", "after")
"""The options only a fixed base's designs read: refused for a floating base."""
BIPED_ONLY = ("stance",)
"""The options only a biped's design reads: refused for a quadruped."""
QUADRUPED_ONLY = ("swing",)
"""The options only a quadruped's design reads: refused for a biped."""
FLOATING_ONLY = (*BIPED_ONLY, *QUADRUPED_ONLY)
"""The options only a floating base's designs read: refused for a fixed base."""
BIPED_DURATION, BIPED_PERIOD = 8.0, 4.0
"""A biped's default time on one foot and its swing joints' Fourier period [s]
(:class:`~wbfriction.excite.one_foot.OneFootOptions`' own); a quadruped's on three feet are the same
(:class:`~wbfriction.excite.tripod.TripodOptions`' own)."""
QUADRUPED_RATE = 500.0
"""A quadruped's default set-points rate [Hz]: its simulators' control rate (:class:`~wbfriction.excite.tripod.
TripodOptions`' own)."""
Stance = Literal["left", "right"]

if TYPE_CHECKING:
    from wbfriction.excite.pd_design import PdDesign


@app.command(rich_help_panel=ROBOT,
             short_help="Design a motion to record whose identification determines every parameter")
def excite(ctx: typer.Context,
           output: list[Path] = typer.Option(..., "-o", "--output",
                                             help="Set-points to write, as many as given (.parquet, .csv): time "
                                                  "[s], q_des.<joint> [rad] in the encoders' coordinates, "
                                                  "qd_des.<joint> [rad/s], at the drivers' rate; then 'wbfriction "
                                                  "simulate --play FILE' or the robot plays it."),
           prediction: Optional[Path] = typer.Option(None, "--json",
                                                     help="Also write the predicted standard error of every "
                                                          "parameter, the limits' margins and the search (JSON)."),
           figure: Optional[Path] = typer.Option(None, "--figure", help="Also write a PNG of the set-points within "
                                                                        "the limits and of the predicted errors."),
           duration: Optional[float] = typer.Option(None, help=f"The recording [s] (default {PD_EXCITE.duration:g} "
                                                               f"hung or an arm; a biped or a quadruped: the time "
                                                               f"on one or three feet, default "
                                                               f"{BIPED_DURATION:g})."),
           rate: Optional[float] = typer.Option(None, help=f"The drivers' rate [Hz]: the set-points' samples "
                                                           f"(default {PD_EXCITE.rate:g} hung, {ARM_RATE:g} an "
                                                           f"arm or a biped, {QUADRUPED_RATE:g} a quadruped)."),
           amplitude: list[float] = typer.Option(list(PD_EXCITE.amplitudes),
                                                 help="Hung: shares of each joint's half range the search tries "
                                                      "(repeat the option for each)."),
           torque_share: float = typer.Option(PD_EXCITE.torque_share,
                                              help="A fixed base: share of each joint's torque limit the motion "
                                                   "may ask."),
           velocity: bool = typer.Option(PD_EXCITE.velocity, help="Hung: send qd_des = the set-points' slope "
                                                                  "(default: zeros, as most drivers are sent)."),
           seed: int = typer.Option(PD_EXCITE.seed, help="Seed of the ramps' levels and times (hung), of the "
                                                         "design's starts (an arm, a swing leg's joints)."),
           period: Optional[float] = typer.Option(None, help=f"An arm or a swing leg: the Fourier series' period [s] "
                                                             f"(default {ARM_PERIOD:g} an arm, {BIPED_PERIOD:g} a "
                                                             "biped or a quadruped); the recording holds a whole "
                                                             "number of them."),
           stance: Optional[Stance] = typer.Option(None, help="A biped (a floating base on two soles): the foot it "
                                                              "stands on, left (default) or right, while the other "
                                                              "leg's joints follow their designed series."),
           swing: Optional[str] = typer.Option(None, help="A quadruped (a floating base on four point feet, --robot "
                                                          "go2_walking): the leg lifted, by its name (FL, FR, RL, RR; "
                                                          "default FR) or its foot frame's, while it stands on the "
                                                          "other three."),
           after: Optional[Path] = typer.Option(None, "--after",
                                                help="What to record next, after a log whose parameters JSON "
                                                     "'fit' wrote: only the joints whose fit is not ok move (the "
                                                     "others are held: hung, at their posture; an arm, at the "
                                                     "middle of their range), with their fitted friction as the "
                                                     "prior where it can be one; the log's values and errors are "
                                                     "printed beside the predicted ones (and in --json)."),
           robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
           mjcf: Optional[Path] = MjcfOpt) -> None:
    """Design the motion to record so that its identification determines every parameter: on a hung PD-driven
    robot (its base fixed), set-points whose 'identify --actuator pd' is predicted to report every joint's armature,
    F_v, F_c and encoder offset and the drivers' delay furthest inside their 'ok' limits; on a fixed-base arm, a
    Fourier excitation whose 'estimate' and 'fit' determine each joint's friction; on a biped (--robot talos), one
    leg's Fourier excitation while it stands on the other foot (--stance), every sample in single support; on a
    quadruped (--robot go2_walking), one leg's while it stands on the other three point feet (--swing). Within
    the URDF's position, velocity and torque limits; predicted by simulating the motion under the robot's model and
    identifying it (a biped or a quadruped: each swing joint's Cramér-Rao bound)."""
    check_paths({"--urdf": urdf, "--config": config, "--mjcf": mjcf, "--after": after},
                {**{f"-o #{k + 1}": p for k, p in enumerate(output)}, "--json": prediction, "--figure": figure})
    r = robot_of(robot, urdf, config, mjcf)
    if r.floating_base:
        refuse_unread(ctx, f"robot '{r.name}' has a floating base", FIXED_ONLY, "fixed base's")
        _excite_floating(ctx, r, (output, prediction, figure), stance, swing, (duration, rate, period, seed))
        return
    refuse_unread(ctx, f"robot '{r.name}' has a fixed base", FLOATING_ONLY, "floating base's")
    duration = PD_EXCITE.duration if duration is None else duration
    if r.pd is None:
        refuse_unread(ctx, f"robot '{r.name}' is a fixed-base arm", HUNG_ONLY, "hung PD-driven robot's")
        _excite_arm(r, output, prediction, figure, duration, rate or ARM_RATE, period or ARM_PERIOD,
                    torque_share, seed, after)
        return
    refuse_unread(ctx, f"robot '{r.name}' is a hung PD-driven robot", ARM_ONLY, "arm's")
    options = PdExciteOptions(duration=duration, rate=rate or PD_EXCITE.rate, amplitudes=tuple(amplitude),
                              torque_share=torque_share, velocity=velocity, seed=seed)
    _excite_pd(r, output, prediction, figure, options, after)


def _excite_floating(ctx: typer.Context, r, paths: tuple[list[Path], Path | None, Path | None],
                     stance: str | None, swing: str | None,
                     design: tuple[float | None, float | None, float | None, int]) -> None:
    """A floating base's design, by the kind of robot: a biped (two soles) stands on one foot, a quadruped (four
    point feet) on three; ``paths``: the tables, the JSON and the figure to write; ``design``: the duration, rate,
    period given (None: the kind's default) and the seed.

    Raises:
        InputError: a floating base of another kind; an option of the other kind.
    """
    from wbfriction.excite.design import ExciteOptions
    from wbfriction.excite.one_foot import OneFootOptions
    from wbfriction.excite.tripod import TripodOptions

    feet = len(r.contact_frames)
    quadruped = bool(r.partial_contacts) and feet == 4
    if quadruped:
        refuse_unread(ctx, f"robot '{r.name}' is a quadruped on {r.stands_on}", BIPED_ONLY, "biped's")
    elif r.partial_contacts or feet != 2:
        raise InputError(f"robot '{r.name}' has a floating base on {feet} {r.stands_on}: excite designs a biped's "
                         "one-foot stance or a quadruped's on three point feet")
    else:
        refuse_unread(ctx, f"robot '{r.name}' is a biped", QUADRUPED_ONLY, "quadruped's")
    duration, rate, period, seed = design
    kind = TripodOptions() if quadruped else OneFootOptions()
    excite = ExciteOptions(duration=BIPED_DURATION if duration is None else duration,
                           rate=rate or (QUADRUPED_RATE if quadruped else ARM_RATE), period=period or BIPED_PERIOD,
                           harmonics=kind.design.harmonics, range_share=1.0, seed=seed)
    if quadruped:
        _excite_quadruped(r, *paths, TripodOptions(swing=swing or "FR", design=excite))
    else:
        _excite_biped(r, *paths, OneFootOptions(stance=stance or "left", design=excite))


def _candidates(total: int, what: str):
    """The design's stages (:func:`~wbfriction.cli.common.stages`), its first counting ``total`` ``what``s, and the
    callable told of each done."""
    status = stages()
    return status, status.steps("design", total, f"{what}s")


def _excite_pd(r, output: list[Path], prediction: Path | None, figure: Path | None, options: PdExciteOptions,
               after: Path | None) -> None:
    from wbfriction.excite.document import next_document, pd_document, pd_setpoints
    from wbfriction.excite.pd_design import design_pd
    from wbfriction.logs.tables import write_json, write_table

    fits = _read_after(r, after)
    status, advance = _candidates(len(options.amplitudes) + len(options.reversals) - 1, "candidate")
    with status:
        if fits is None:
            design = design_pd(r, options, progress=advance)
        else:
            from wbfriction.excite.next import record_next

            following = record_next(r, fits, str(after), options, progress=advance)
            design = following.design
    table = pd_setpoints(design)
    for path in output:
        write_table(table, path)
    doc = pd_document(design)
    if fits is not None and after is not None:
        doc["after"] = next_document(following, str(after))
    if prediction is not None:
        write_json(prediction, doc)
    if figure is not None:
        _figure(design, doc, r, figure)
    _print(design, doc)
    if fits is not None and after is not None:
        _print_next(following, after)
    _wrote(output, prediction, figure)


def _read_after(r, after: Path | None):
    """The fits of the parameters file ``--after`` names, for robot ``r`` (None without it)."""
    if after is None:
        return None
    from wbfriction.fit.params_file import read_robot_params

    return read_robot_params(after, r.name, r.actuated, r.urdf)


def _excite_arm(r, output: list[Path], prediction: Path | None, figure: Path | None, duration: float, rate: float,
                period: float, torque_share: float, seed: int, after: Path | None) -> None:
    from wbfriction.excite.arm_design import design_arm
    from wbfriction.excite.design import ExciteOptions
    from wbfriction.excite.document import arm_document, arm_setpoints, next_document
    from wbfriction.excite.next import record_next_arm, undetermined
    from wbfriction.fit.status import WEAK
    from wbfriction.logs.tables import write_json, write_table
    from wbfriction.report.excite import excite_figure

    options = ExciteOptions(duration=duration, rate=rate, period=period, torque_share=torque_share, seed=seed)
    fits = _read_after(r, after)
    following = None
    status, advance = _candidates(r.n_act if fits is None else len(undetermined(r, fits, str(after))), "joint")
    with status:
        if fits is None:
            design = design_arm(r, options, progress=advance)
        else:
            following = record_next_arm(r, fits, str(after), options, progress=advance)
            design = following.design
        status("predicting what estimate and fit will report (two simulated recordings)")
    table = arm_setpoints(design, r.offset_vector)
    for path in output:
        write_table(table, path)
    doc = arm_document(design)
    if following is not None:
        doc["after"] = next_document(following, str(after))
    if prediction is not None:
        write_json(prediction, doc)
    shares = _shares(doc)
    if figure is not None:
        lower, upper = r.angle_limits
        excite_figure(figure, design.design.joints, design.time, design.q_des + r.offset_vector,
                      lower + r.offset_vector, upper + r.offset_vector, shares,
                      f"{r.name}: Fourier excitation; predicted worst {doc['worst']['share']:.2f} of the weak limit")
    table_out = Table(title=f"Predicted standard error / {WEAK:g} x value (family the fit is predicted to choose)",
                      box=None)
    for col in ("joint", "family", "F_c", "F_v", "status"):
        table_out.add_column(col, justify="left" if col in ("joint", "family", "status") else "right")
    for joint, params in doc["predicted"].items():
        cells = [f"{shares[joint][n]:.3f}" if n in shares[joint] else "-" for n in ("F_c", "F_v")]
        worst = next((p["status"] for p in params.values() if p["status"] != "ok"), "ok")
        table_out.add_row(joint, doc["models"].get(joint, "-"), *cells, worst)
    out.print(table_out)
    w = doc["worst"]
    out.print(f"least margin to a limit {design.design.margins.least():.0%}; worst: {w['joint']} {w['parameter']}, "
              f"{w['share']:.3f} of its limit (below 1: predicted ok)", highlight=False)
    if following is not None and after is not None:
        _print_next(following, after)
    _wrote(output, prediction, figure)


def _excite_biped(r, output: list[Path], prediction: Path | None, figure: Path | None, options) -> None:
    from wbfriction.excite.document import one_foot_document, one_foot_setpoints
    from wbfriction.excite.one_foot import one_foot_reference, swing_bounds

    with stages() as stage:
        stage(f"designing the swing leg's series, then the stance on the {options.stance} foot (its IK "
              "at every sample)")
        excitation = one_foot_reference(r, options)
    doc = one_foot_document(r, excitation, options, swing_bounds(r, excitation, options))
    _write_standing(r, (output, prediction, figure), excitation, one_foot_setpoints(r, excitation, options), doc,
                    f"{r.name} on its {options.stance} foot: the swing leg within its posture band; Cramér-Rao "
                    "bound / weak limit")
    _print_swing(doc, f"The swing leg on the {doc['stance']} foot")
    out.print(f"ZMP {doc['zmp_margin'] * 1e3:.1f} mm inside the {doc['stance']} sole's edges (at least "
              f"{doc['limits']['zmp_margin'] * 1e3:.0f}); the swing sole {doc['clearance'] * 1e3:.1f} mm above the "
              f"ground (at least {doc['limits']['clearance'] * 1e3:.0f})", highlight=False)
    _wrote(output, prediction, figure)


def _excite_quadruped(r, output: list[Path], prediction: Path | None, figure: Path | None, options) -> None:
    from wbfriction.excite.document import tripod_document, tripod_setpoints
    from wbfriction.excite.tripod import swing_bounds, tripod_reference

    with stages() as stage:
        stage("designing the swing leg's series, then the stance on the three other feet (its IK at "
              "every sample)")
        excitation = tripod_reference(r, options)
    doc = tripod_document(r, excitation, options, swing_bounds(r, excitation, options))
    leg = doc["swing_foot"].split("_")[0]
    _write_standing(r, (output, prediction, figure), excitation, tripod_setpoints(r, excitation, options), doc,
                    f"{r.name} on three feet, its {leg} leg swung within its posture band; Cramér-Rao bound / weak "
                    "limit")
    _print_swing(doc, f"The {leg} leg swung, on {', '.join(f.split('_')[0] for f in doc['stance_feet'])}")
    mm = {n: f"{doc[n] * 1e3:.1f} mm (at least {doc['limits'][n] * 1e3:.0f})"
          for n in ("com_margin", "zmp_margin", "clearance", "spacing")}
    out.print(f"centre of mass {mm['com_margin']} and ZMP {mm['zmp_margin']} inside the stance triangle's edges; the "
              f"swing foot {mm['clearance']} above the ground, {mm['spacing']} from the other legs", highlight=False)
    _wrote(output, prediction, figure)


def _write_standing(r, paths: tuple[list[Path], Path | None, Path | None], excitation, table, doc: dict,
                    title: str) -> None:
    """Write a standing design's set-points ``table`` to every path, its ``doc`` as JSON, and its figure (the swing
    joints' set-points within their bands, the shares of their bounds, ``title``), where asked."""
    import numpy as np

    from wbfriction.logs.tables import write_json, write_table
    from wbfriction.report.excite import excite_figure

    output, prediction, figure = paths
    for path in output:
        write_table(table, path)
    if prediction is not None:
        write_json(prediction, doc)
    if figure is not None:
        joints = excitation.joints
        offset = r.offset_vector[[r.actuated.index(j) for j in joints]]
        q_des = np.column_stack([table.column(f"q_des.{j}").to_numpy() for j in joints])
        excite_figure(figure, joints, table.column("time").to_numpy(), q_des, excitation.lower + offset,
                      excitation.upper + offset, {j: s["share"] for j, s in doc["swing"].items()}, title)


def _print_swing(doc: dict, where: str) -> None:
    """The swing joints' table of a standing design's document: band, reach, peak speed, bounds' shares."""
    table = Table(title=f"{where}: band and Cramér-Rao bound / weak limit", box=None)
    for col in ("joint", "band [rad]", "reached [rad]", "peak [rad/s]", "F_c", "F_v"):  # Text: "[rad]" is no tag
        table.add_column(Text(col), justify="left" if col == "joint" else "right")
    for joint, s in doc["swing"].items():
        table.add_row(joint, f"{s['band'][0]:.2f} to {s['band'][1]:.2f}",
                      f"{s['reached'][0]:.2f} to {s['reached'][1]:.2f}", f"{s['peak_velocity']:.2f}",
                      *(f"{s['share'][n]:.3f}" if n in s["share"] else "-" for n in ("F_c", "F_v")))
    out.print(table)


def _wrote(*paths) -> None:
    for path in paths:
        for written in (path if isinstance(path, list) else [path]):
            if written is not None:
                console.print(f"wrote {written}")


def _shares(doc: dict) -> dict[str, dict[str, float]]:
    """Each joint's parameters' predicted shares of their limits, from a design's document."""
    return {j: {n: p["share"] for n, p in params.items() if p.get("share") is not None}
            for j, params in doc["predicted"].items()}


def _figure(design: PdDesign, doc: dict, robot, path: Path) -> None:
    from wbfriction.report.excite import excite_figure

    lower, upper = robot.angle_limits
    shares = _shares(doc)
    excite_figure(path, design.joints, design.time, design.q_des, lower + robot.offset_vector,
                  upper + robot.offset_vector, shares,
                  f"{design.robot}: ramps over {design.chosen.amplitude:g} of each half range, reversing every "
                  f"{design.chosen.reversal[0]:g}-{design.chosen.reversal[1]:g} s; predicted worst "
                  f"{design.worst()[2]:.2f} of its limit")


def _print(design: PdDesign, doc: dict) -> None:
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
    out.print(table)
    joint, name, share = design.worst()
    chosen = design.chosen
    for line in (f"ramps over {chosen.amplitude:g} of each half range, reversing every {chosen.reversal[0]:g}-"
                 f"{chosen.reversal[1]:g} s; least margin to a limit {design.margins.least():.0%}",
                 f"delay {1e3 * doc['delay']['value']:.2f} ± {1e3 * doc['delay']['se']:.2g} ms, "
                 f"{doc['delay']['share']:.2f} of its limit",
                 f"worst: {joint} {name}, {share:.2f} of its limit (below 1: predicted ok)"):
        out.print(line, highlight=False)


def _print_next(following, after: Path) -> None:
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
    print_whole(table)  # a few rows, none of their numbers cut
    held = [j for j in design.joints if j not in design.moving]
    out.print(f"held at their posture (their fits ok): {', '.join(held) if held else 'none'}; prior friction from "
              f"the fit on {len(following.prior_from_fit)} joints, the simulator's default on the others",
              highlight=False)

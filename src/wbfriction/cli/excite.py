"""``wbfriction excite``: the motion to record, designed so that its identification determines every parameter."""

from __future__ import annotations

from pathlib import Path
from typing import Literal, Optional

import typer

from wbfriction.cli.common import (
    ConfigOpt,
    MjcfOpt,
    RobotOpt,
    UrdfOpt,
    app,
    console,
    given_options,
    print_items,
    robot_of,
    stages,
)
from wbfriction.cli.helpformat import ROBOT
from wbfriction.cli.outputs import suffixes, written_as
from wbfriction.cli.rigs import RigOptionOpt, rig_options
from wbfriction.exceptions import InputError

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: the design is imported when the command runs.
from wbfriction.excite.options import ARM_PERIOD, ARM_RATE, PD_EXCITE, check_design_size
from wbfriction.pipeline.paths import check_paths
from wbfriction.rigs import DesignOutput, RigProgress, rig_for
from wbfriction.rigs.quadruped import STANDING_RATE
from wbfriction.rigs.standing import STANDING_DURATION, STANDING_PERIOD

SHARED = ("output", "prediction", "figure", "robot", "urdf", "config", "mjcf", "rig_option")
"""The options every rig's design reads: what is written, the robot."""
Stance = Literal["left", "right"]


@app.command(rich_help_panel=ROBOT,
             short_help="Design a motion to record whose identification determines every parameter")
def excite(ctx: typer.Context,
           output: list[Path] = typer.Option(..., "-o", "--output", callback=written_as("table"),
                                             help=f"Set-points to write, as many as given ({suffixes('table')}): "
                                                  "time [s], q_des.<joint> [rad] in the encoders' coordinates, "
                                                  "qd_des.<joint> [rad/s], at the drivers' rate; then 'wbfriction "
                                                  "simulate --play FILE' or the robot plays it."),
           prediction: Optional[Path] = typer.Option(None, "--json", callback=written_as("json"),
                                                     help="Also write the predicted standard error of every "
                                                          "parameter, the limits' margins and the search (JSON)."),
           figure: Optional[Path] = typer.Option(None, "--figure", callback=written_as("png"),
                                                 help="Also write a PNG of the set-points within the limits and of "
                                                      "the predicted errors."),
           duration: Optional[float] = typer.Option(None, help=f"The recording [s] (default {PD_EXCITE.duration:g} "
                                                               f"hung or an arm; a biped or a quadruped: the time "
                                                               f"on one or three feet, default "
                                                               f"{STANDING_DURATION:g})."),
           rate: Optional[float] = typer.Option(None, help=f"The drivers' rate [Hz]: the set-points' samples "
                                                           f"(default {PD_EXCITE.rate:g} hung, {ARM_RATE:g} an "
                                                           f"arm or a biped, {STANDING_RATE:g} a quadruped)."),
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
                                                             f"(default {ARM_PERIOD:g} an arm, {STANDING_PERIOD:g} a "
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
           mjcf: Optional[Path] = MjcfOpt, rig_option: list[str] = RigOptionOpt) -> None:
    """Design the motion to record so that its identification determines every parameter: on a hung PD-driven
    robot (its base fixed), set-points whose 'identify --actuator pd' is predicted to report every joint's armature,
    F_v, F_c and encoder offset and the drivers' delay furthest inside their 'ok' limits; on a fixed-base arm, a
    Fourier excitation whose 'estimate' and 'fit' determine each joint's friction; on a biped (--robot talos), one
    leg's Fourier excitation while it stands on the other foot (--stance), every sample in single support; on a
    quadruped (--robot go2_walking), one leg's while it stands on the other three point feet (--swing). Within
    the URDF's position, velocity and torque limits; predicted by simulating the motion under the robot's model and
    identifying it (a biped or a quadruped: each swing joint's Cramér-Rao bound)."""
    values = {name: value for name, value in locals().items() if name != "ctx"}
    check_paths({"--urdf": urdf, "--config": config, "--mjcf": mjcf, "--after": after},
                {**{f"-o #{k + 1}": p for k, p in enumerate(output)}, "--json": prediction, "--figure": figure})
    r = robot_of(robot, urdf, config, mjcf)
    rig = rig_for(r)
    if rig.design_options is None:
        raise InputError(f"{rig.what(r)}: excite designs no motion for it")
    (options,) = rig_options(ctx, values, (rig.design_options,), rig.what(r), SHARED, rig_option)
    length, samples = getattr(options, "duration", None), getattr(options, "rate", None)  # a rig's own may have none
    if length is not None and samples is not None:
        check_design_size(r.name, r.n_act, length, samples,
                          "--rate" if "rate" in given_options(ctx) and duration is None else "--duration")
    with stages() as status:
        design = rig.design(r, options, RigProgress(status, status.steps))
    write_design(design, output, prediction, figure, rig.what(r))


def write_design(design: DesignOutput, output: list[Path], prediction: Path | None, figure: Path | None,
                 what: str) -> None:
    """Write a rig's design (the set-points to every ``-o``, the prediction to ``--json``, the figure to
    ``--figure``), print what it prints and name what was written; ``what``: the robot on its rig.

    Raises:
        InputError: ``--figure`` for a design that draws none (before anything is written).
    """
    draw = design.figure
    if figure is not None and draw is None:
        raise InputError(f"--figure: {what}: its design draws no figure")
    from wbfriction.logs.tables import write_json, write_table

    for path in output:
        write_table(design.table, path)
    if prediction is not None:
        write_json(prediction, design.document)
    if figure is not None and draw is not None:
        draw(figure)
    print_items(design.printed)
    for written in (*output, prediction, figure):
        if written is not None:
            console.print(f"wrote {written}")

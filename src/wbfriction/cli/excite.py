"""``wbfriction excite``: the motion to record, designed so that its identification determines every parameter."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional

import typer
from rich.table import Table

from wbfriction.cli.common import ConfigOpt, MjcfOpt, RobotOpt, UrdfOpt, app, console, out, robot_of
from wbfriction.exceptions import InputError

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: the design is imported when the command runs.
from wbfriction.excite.options import PD_EXCITE, PdExciteOptions
from wbfriction.pipeline.paths import check_paths

if TYPE_CHECKING:
    from wbfriction.excite.pd_design import PdDesign


@app.command()
def excite(output: list[Path] = typer.Option(..., "-o", "--output",
                                             help="Set-points to write, as many as given (.parquet, .csv): time "
                                                  "[s], q_des.<joint> [rad] in the encoders' coordinates, "
                                                  "qd_des.<joint> [rad/s], at the drivers' rate; then 'wbfriction "
                                                  "simulate --play FILE' or the robot plays it."),
           prediction: Optional[Path] = typer.Option(None, "--json",
                                                     help="Also write the predicted standard error of every "
                                                          "parameter, the limits' margins and the search (JSON)."),
           figure: Optional[Path] = typer.Option(None, "--figure", help="Also write a PNG of the set-points within "
                                                                        "the limits and of the predicted errors."),
           duration: float = typer.Option(PD_EXCITE.duration, help="The recording [s]."),
           rate: float = typer.Option(PD_EXCITE.rate, help="The drivers' rate [Hz]: the set-points' samples."),
           amplitude: list[float] = typer.Option(list(PD_EXCITE.amplitudes),
                                                 help="Shares of each joint's half range the search tries (repeat "
                                                      "the option for each)."),
           torque_share: float = typer.Option(PD_EXCITE.torque_share,
                                              help="Share of each driver's torque limit the motion may ask."),
           velocity: bool = typer.Option(PD_EXCITE.velocity, help="Send qd_des = the set-points' slope (default: "
                                                                  "zeros, as most drivers are sent)."),
           seed: int = typer.Option(PD_EXCITE.seed, help="Seed of the ramps' levels and times."),
           after: Optional[Path] = typer.Option(None, "--after",
                                                help="What to record next: the parameters JSON 'fit' wrote from a log "
                                                     "of this robot. Only the joints whose fit is not ok move (the "
                                                     "others are held), with their fitted friction as the prior; "
                                                     "the log's errors are printed beside the predicted ones."),
           robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
           mjcf: Optional[Path] = MjcfOpt) -> None:
    """Design the motion to record on a hung PD-driven robot (its base fixed): set-points whose identification
    ('identify --actuator pd') is predicted to report every joint's armature, F_v, F_c and encoder offset, and the
    drivers' delay, furthest inside their 'ok' limits, within the URDF's position and velocity limits and the
    drivers' torque. Predicted by simulating the motion under the robot's own model and identifying it."""
    from wbfriction.excite.document import pd_document, pd_setpoints
    from wbfriction.excite.pd_design import design_pd
    from wbfriction.logs.tables import write_json, write_table

    check_paths({"--urdf": urdf, "--config": config, "--mjcf": mjcf, "--after": after},
                {**{f"-o #{k + 1}": p for k, p in enumerate(output)}, "--json": prediction, "--figure": figure})
    options = PdExciteOptions(duration=duration, rate=rate, amplitudes=tuple(amplitude), torque_share=torque_share,
                              velocity=velocity, seed=seed)
    r = robot_of(robot, urdf, config, mjcf)
    if r.floating_base or r.pd is None:
        raise InputError(f"robot '{r.name}': excite designs a hung PD-driven robot's motion (a fixed base and a "
                         "[pd] table)")
    fits = None
    if after is not None:
        from wbfriction.fit.params_file import read_robot_params

        fits = read_robot_params(after, r.name, r.actuated, r.urdf)
    total = len(options.amplitudes) + len(options.reversals) - 1
    done = [0]
    with console.status(f"designing: candidate 1 of {total}") as status:
        def advance(n: int) -> None:
            done[0] += n
            status.update(f"designing: candidate {min(done[0] + 1, total)} of {total}")
        if fits is None:
            design = design_pd(r, options, progress=advance)
        else:
            from wbfriction.excite.next import record_next

            following = record_next(r, fits, str(after), options, progress=advance)
            design = following.design
    table = pd_setpoints(design)
    for path in output:
        write_table(table, path)
    if prediction is not None:
        write_json(prediction, pd_document(design))
    if figure is not None:
        _figure(design, r, figure)
    _print(design)
    if fits is not None and after is not None:
        _print_next(following, after)
    for written in (*output, prediction, figure):
        if written is not None:
            console.print(f"wrote {written}")


def _figure(design: PdDesign, robot, path: Path) -> None:
    from wbfriction.excite.pd_design import SHARE_LIMITS
    from wbfriction.fit.status import WEAK
    from wbfriction.report.excite import excite_figure

    lower, upper = robot.angle_limits
    shares = {j: {n: p.se / SHARE_LIMITS.get(n, WEAK * abs(p.value)) for n, p in params.items()}
              for j, params in design.prediction.joints.items()}
    excite_figure(path, design.joints, design.time, design.q_des, lower + robot.offset_vector,
                  upper + robot.offset_vector, shares,
                  f"{design.robot}: ramps over {design.chosen.amplitude:g} of each half range, reversing every "
                  f"{design.chosen.reversal[0]:g}-{design.chosen.reversal[1]:g} s; predicted worst "
                  f"{design.worst()[2]:.2f} of its limit")


def _print(design: PdDesign) -> None:
    from wbfriction.excite.document import pd_document

    doc = pd_document(design)
    names = list(next(iter(doc["predicted"].values())))
    table = Table(title="Predicted standard error / limit of ok (status)", box=None)
    table.add_column("joint")
    for name in names:
        table.add_column(name, justify="right")
    for joint, params in doc["predicted"].items():
        table.add_row(joint, *(f"{params[n]['share']:.2f}" + ("" if params[n]["status"] == "ok"
                                                               else f" ({params[n]['status']})") for n in names))
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
    from wbfriction.excite.next import COMPARED

    design = following.design
    table = Table(title=f"The joints {after.name} left undetermined: the log's fit against the design's prediction",
                  box=None)
    table.add_column("joint")
    table.add_column("log's status")
    for name in COMPARED:
        unit = "N·m·s/rad" if name == "F_v" else "N·m"
        table.add_column(f"{name} log [{unit}]", justify="right")
        table.add_column(f"{name} next [{unit}]", justify="right")
    for joint, logged in following.logged.items():
        predicted = design.prediction.joints[joint]
        cells = []
        for name in COMPARED:
            value, se = logged.values.get(name, (float("nan"), float("nan")))
            p = predicted[name]
            cells += [f"{value:.3f} ± {se:.2g}", f"{p.value:.3f} ± {p.se:.2g}"]
        table.add_row(joint, logged.status, *cells)
    out.print(table)
    held = [j for j in design.joints if j not in design.moving]
    out.print(f"held at their posture (their fits ok): {', '.join(held) if held else 'none'}; prior friction from "
              f"the fit on {len(following.prior_from_fit)} joints, the simulator's default on the others",
              highlight=False)

"""``wbfriction refine``: an exported MJCF's parameters refined on its own tracking error of a training log."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from rich.markup import escape
from rich.table import Table

from wbfriction.cli.common import ConfigOpt, LogArg, MjcfOpt, RobotOpt, UrdfOpt, app, console, out, robot_of, stages
from wbfriction.cli.helpformat import ROBOT
from wbfriction.cli.outputs import suffixes, written_as
from wbfriction.cli.rollout import replay_options
from wbfriction.pipeline.paths import check_paths


@app.command(rich_help_panel=ROBOT)
def refine(log: Path = LogArg,
           model: Path = typer.Argument(..., metavar="MODEL",
                                        help="MuJoCo MJCF written by 'wbfriction export' for the robot (--config), "
                                             "its PD-driven joints' actuators named as the joints."),
           output: Path = typer.Option(..., "-o", "--output", callback=written_as("mjcf"),
                                       help=f"The refined MJCF to write ({suffixes('mjcf')})."),
           held_out: Optional[Path] = typer.Option(None, "--held-out",
                                                   help="A log not refined on: MODEL and the refined file replayed "
                                                        "on it, their tracking errors side by side."),
           table: Optional[Path] = typer.Option(None, "--table", callback=written_as("text-table"),
                                                help=f"Table to write ({suffixes('text-table')}): per joint and "
                                                     "parameter, the file's value, the refined one, its standard "
                                                     "error and status."),
           window: float = typer.Option(1.0, "--window",
                                        help="Restart each replay from the log's state every so many seconds [s]."),
           start: Optional[float] = typer.Option(None, "--from", help="Refine on the log from this time [s] "
                                                                      "(default: its start)."),
           stop: Optional[float] = typer.Option(None, "--to", help="Refine on the log up to this time [s] "
                                                                   "(default: its end)."),
           timestep: Optional[float] = typer.Option(None, "--timestep",
                                                    help="Physics step to refine at [s], written into the "
                                                         "refined file (default: the file's)."),
           robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
           mjcf: Optional[Path] = MjcfOpt) -> None:
    """Refine an exported MuJoCo model on the log it should reproduce: each PD-driven joint's armature,
    frictionloss (F_c), damping (F_v) and constant torque (tau_os), and the set-points' delay, moved to minimise
    the replayed angles' error (as 'wbfriction rollout' replays it), each with its standard error and status; the
    refined file written to -o, MODEL untouched (a hung robot, its base fixed)."""
    from wbfriction.replay.refine import refine_mjcf, write_refined

    check_paths({"LOG": log, "MODEL": model, "--held-out": held_out, "--config": config, "--urdf": urdf,
                 "--mjcf": mjcf}, {"-o": output, "--table": table})
    replay, times = replay_options(window, timestep, start, stop)
    the_robot = robot_of(robot, urdf, config, mjcf)
    held = None if held_out is None else _held_out_checked(model, the_robot, held_out, replay)
    with stages() as stage:
        stage(f"refining {model.name} on {log.name} (a minute or so: MuJoCo replays the log some "
              "hundred times)")
        result = refine_mjcf(model, the_robot, log, replay, times=times)
        write_refined(model, result, the_robot, output, timestep=timestep)
        if table is not None:
            from wbfriction.logs.tables import write_table

            write_table(result.table(), table)
    out.print(_values(result))
    out.print(f"delay {1e3 * result.delay_start:.2f} -> {1e3 * result.delay:.2f} ms "
              f"(± {1e3 * result.delay_se:.2g}, {result.delay_status}); training RMS "
              f"{1e3 * result.rms_start.mean():.2f} -> {1e3 * result.rms.mean():.2f} mrad; {result.replays} replays in "
              f"{result.seconds:.0f} s" + ("" if result.converged else " (stopped at its budget of replays)"))
    if held_out is not None and held is not None:  # both or neither
        out.print(_held_out(model, output, the_robot, held_out, held, replay))
    for path in (output, table):
        if path is not None:
            console.print(f"wrote {path}")


def _values(result) -> Table:
    """Each joint's refined values ± their standard errors, a status beside a value that is not ok."""
    from wbfriction.replay.refine import PARAMETERS, UNITS

    table = Table(title="refined values ± standard error (--table: the file's beside them)", box=None)
    table.add_column("joint")
    for name in PARAMETERS:
        table.add_column(escape(f"{name} [{UNITS[name]}]"), justify="right")
    for j, joint in enumerate(result.joints):
        cells = []
        for k in range(len(PARAMETERS)):
            status = result.status[k][j]
            cells.append(f"{result.value[k, j]:.4g} ± {result.stderr[k, j]:.1g}"
                         + ("" if status == "ok" else f" ({status})"))
        table.add_row(joint, *cells)
    return table


def _held_out_checked(model: Path, robot, held_out: Path, replay):
    """The held-out log read, its replay on ``model`` checked feasible (:mod:`wbfriction.replay.feasibility`) before
    the refinement's minute rather than after it."""
    from wbfriction.replay.mjcf import checked_replay
    from wbfriction.replay.rollout import read_log_setpoints

    data = read_log_setpoints(robot, held_out)
    checked_replay(model, robot, data, replay)
    return data


def _held_out(model: Path, refined: Path, robot, held_out: Path, data, replay) -> Table:
    """The file and the refined file replayed on the held-out log (``data``, its reading): their RMS per joint
    [mrad]."""
    from wbfriction.replay.mjcf import replay_mjcf

    before, after = replay_mjcf(model, robot, data, replay), replay_mjcf(refined, robot, data, replay)
    table = Table(title=f"held out ({held_out.name}): RMS of simulated - logged angle \\[mrad], windows of "
                        f"{replay.horizon:g} s", box=None)
    for col in ("joint", model.name, refined.name):
        table.add_column(col, justify="left" if col == "joint" else "right")
    for joint, a, b in zip(robot.actuated, before.rms, after.rms):
        table.add_row(joint, f"{1e3 * a:.2f}", f"{1e3 * b:.2f}")
    table.add_row("mean", f"{1e3 * before.rms.mean():.2f}", f"{1e3 * after.rms.mean():.2f}")
    return table

"""``wbfriction rollout``: an exported MJCF replayed under a log's set-points, its tracking error per joint."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Optional

import typer
from rich.table import Table

from wbfriction.cli.common import ConfigOpt, LogArg, MjcfOpt, RobotOpt, UrdfOpt, app, console, out, robot_of, stages
from wbfriction.cli.helpformat import ROBOT
from wbfriction.cli.outputs import suffixes, written_as
from wbfriction.exceptions import OptionError
from wbfriction.pipeline.paths import check_paths

if TYPE_CHECKING:
    from wbfriction.replay.mjcf import Replay


@app.command(rich_help_panel=ROBOT)
def rollout(log: Path = LogArg,
            model: Path = typer.Argument(..., metavar="MODEL",
                                         help="MuJoCo MJCF written by 'wbfriction export' for the robot (--config): "
                                              "its PD-driven joints' actuators, named as the joints, are replayed."),
            window: float = typer.Option(1.0, "--window",
                                         help="Restart from the log's state every so many seconds [s]; the "
                                              "whole stretch in one shot is scored too."),
            start: Optional[float] = typer.Option(None, "--from", help="Replay from this time of the log [s] "
                                                                       "(default: its start)."),
            stop: Optional[float] = typer.Option(None, "--to", help="Replay up to this time of the log [s] "
                                                                    "(default: its end)."),
            torque_delay: Optional[int] = typer.Option(None, "--torque-delay", min=0,
                                                       help="Replay PACE's actuator instead of the file's: the PD "
                                                            "law computed once a log period and its whole torque "
                                                            "applied so many periods later (a model identified so)."),
            timestep: Optional[float] = typer.Option(None, "--timestep",
                                                     help="Physics step [s] (default: the file's)."),
            label: str = typer.Option("model", "--label", help="What the figure calls the replay."),
            output: Optional[Path] = typer.Option(None, "-o", "--output", callback=written_as("text-table"),
                                                  help=f"Table to write ({suffixes('text-table')}): per joint, the "
                                                       "RMS tracking error [rad] in windows and in one shot."),
            figure: Optional[Path] = typer.Option(None, "--figure", callback=written_as("png"),
                                                  help="PNG of each joint's tracking error."),
            robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
            mjcf: Optional[Path] = MjcfOpt) -> None:
    """Replay the log's set-points on an exported MuJoCo model, as MuJoCo runs it (the file's timestep, gains,
    offsets, torque limits and set-point delay), restarted from the log's state every --window seconds and in one
    shot: how far the simulated encoder angles go from the logged ones, per joint (a hung robot, its base fixed)."""
    from wbfriction.replay.mjcf import replay_check
    from wbfriction.report.figures import rollout_figure

    check_paths({"LOG": log, "MODEL": model, "--config": config, "--urdf": urdf, "--mjcf": mjcf},
                {"-o": output, "--figure": figure})
    replay, times = replay_options(window, timestep, start, stop, label=label, torque_delay=torque_delay)
    with stages() as stage:
        stage(f"replaying {log.name} on {model.name}")
        check = replay_check(model, robot_of(robot, urdf, config, mjcf), log, replay, times=times, output=output)
        if figure is not None:
            rollout_figure([check.windows], figure)
    w = check.windows
    table = Table(title="RMS of simulated - logged angle \\[mrad]", box=None, caption_justify="left",
                  caption=f"{model.name} replayed on rows {w.rows[0]} to {w.rows[1]} of {log.name}; windows: "
                          f"restarted from the log every {window:g} s; whole: one shot" + runs_note(w.runs))
    for col in ("joint", f"windows ({window:g} s)", "whole"):
        table.add_column(col, justify="left" if col == "joint" else "right")
    for joint, a, b in zip(w.joints, check.windows.rms, check.whole.rms):
        table.add_row(joint, f"{1e3 * a:.2f}", f"{1e3 * b:.2f}")
    table.add_row("mean", f"{1e3 * check.windows.rms.mean():.2f}", f"{1e3 * check.whole.rms.mean():.2f}")
    out.print(table)
    for path in (output, figure):
        if path is not None:
            console.print(f"wrote {path}")


def runs_note(runs: tuple[tuple[int, int], ...]) -> str:
    """What a table's caption says of a stretch replayed in several runs (the log's gaps: each run replayed on its
    own, :mod:`wbfriction.replay.feasibility`); nothing for one."""
    if len(runs) < 2:
        return ""
    starts = ", ".join(str(a) for a, _ in runs[1:4]) + (", ..." if len(runs) > 4 else "")
    return (f"; the log's gaps cut it into {len(runs)} evenly sampled runs, each replayed on its own (restarted at "
            f"rows {starts})")


def replay_options(window: float, timestep: float | None, start: float | None, stop: float | None,
                   **replay) -> tuple[Replay, tuple[float, float] | None]:
    """The replay (:class:`~wbfriction.replay.mjcf.Replay`, its other fields ``replay``) and the stretch ``[--from,
    --to)`` (None: the whole log) of the options ``--window``, ``--timestep``, ``--from``, ``--to``.

    Raises:
        OptionError: a window or timestep that is not a time > 0.
    """
    from wbfriction.replay.mjcf import Replay

    if not (math.isfinite(window) and window > 0):
        raise OptionError("--window", window, "a time > 0 [s]")
    if timestep is not None and not (math.isfinite(timestep) and timestep > 0):
        raise OptionError("--timestep", timestep, "a physics step > 0 [s]")
    times = None if start is None and stop is None else (-math.inf if start is None else start,
                                                          math.inf if stop is None else stop)
    return Replay(horizon=window, timestep=timestep, **replay), times

"""``wbfriction demo`` and the ``study-*`` commands: the thesis's studies and this project's."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Optional, cast

import typer
from rich.markup import escape
from rich.table import Table

from wbfriction.exceptions import InputError
from wbfriction.friction.options import RouteOption

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import Diff, FilterOptions
from wbfriction.sim.engines.registry import ENGINES
from wbfriction.sim.options import SensorNoise

if TYPE_CHECKING:
    pass

from wbfriction.cli.common import (
    GAIT,
    FitWorkersOpt,
    RobotOpt,
    RouteOpt,
    app,
    console,
    out,
    print_items,
    robot_of,
    stages,
)
from wbfriction.cli.helpformat import STUDIES
from wbfriction.cli.rigs import RigOptionOpt, check_engine, rig_options


@app.command(rich_help_panel=STUDIES)
def demo(ctx: typer.Context,
         output_dir: Path = typer.Option(Path("wbfriction-demo"), "-o", "--output-dir", help="Where to write."),
         robot: str = RobotOpt,
         steps: int = typer.Option(GAIT.steps, help="A biped: steps per direction of the combined walk (--simulator "
                                                    "mujoco: of the forward walks of Fig. 6.4-6.5 too, at most 5)."),
         simulator: Optional[str] = typer.Option(None, metavar=f"[{'|'.join(ENGINES.loaded())}]",
                                                 help="The engine: ideal (a biped: Tables 6.1/6.2, Fig. 6.1-6.3) or "
                                                      "mujoco (the realistic simulator's study, Fig. 6.4-6.5); "
                                                      "default: the first the rig runs on."),
         rig_option: list[str] = RigOptionOpt) -> None:
    """What the robot's rig shows in a few minutes, against the truth its simulation injected: a biped (talos,
    the default), the thesis's simulation study (walk, estimate, fit; Tables 6.1/6.2 and Fig. 6.1-6.3; --simulator
    mujoco: the realistic simulator's tables and Fig. 6.4-6.5); a quadruped on point feet (go2_walking), what its
    gait gives each joint (--rig-option gait=walk); an arm (panda), its friction fitted; a hung PD-driven robot
    (go2), its actuators identified."""
    from wbfriction.rigs import RigProgress, rig_for

    values = {name: value for name, value in locals().items() if name != "ctx"}
    check_engine(simulator)
    check_paths({}, {}, {"-o": output_dir})
    start = time.perf_counter()
    r = robot_of(robot, None, None)
    rig = rig_for(r)
    if rig.demo_options is None:
        raise InputError(f"{rig.what(r)}: demo shows nothing of it")
    engine = rig.engine(r, simulator)
    (options,) = rig_options(ctx, values, (rig.demo_options,), rig.what(r), ("output_dir", "robot", "rig_option"),
                             rig_option, engine=engine is not None)
    with stages() as status:
        shown = rig.demo(r, options, engine, output_dir, RigProgress(status, status.steps))
    print_items(shown.printed)
    for f in shown.files:
        console.print(f"wrote {f}")
    console.print(f"demo finished in {time.perf_counter() - start:.1f} s")


def _percent(x: float) -> str:
    import numpy as np

    return f"{x:.1f}" if x < 1e4 else ("inf" if not np.isfinite(x) else ">1e4")


@app.command("study-sensors", rich_help_panel=STUDIES)
def study_sensors(output_dir: Path = typer.Option(Path("wbfriction-sensors"), "-o", "--output-dir",
                                                  help="Where to write."),
                  robot: str = RobotOpt,
                  steps: int = typer.Option(3, min=1, help="Steps per direction of the combined walk."),
                  diff: Diff = typer.Option("central", help="Differentiation: central, savgol, butterworth or true."),
                  window: int = typer.Option(151, help="savgol: window length L (odd) [samples]."),
                  noise: bool = typer.Option(False, "--noise", help="The studies' sensor noise in the loop (1e-4 "
                                                                    "rad, 19-bit encoders, 0.05 N·m torques)."),
                  substeps: Optional[int] = typer.Option(None, min=1,
                                                         help="MuJoCo physics steps per 1 ms control period "
                                                              "(default 16: friction lags half a step)."),
                  route: RouteOption = RouteOpt) -> None:
    """What the ankle force-torque sensors and the base pose change, on MuJoCo's soft contacts."""
    from wbfriction.studies.realistic import NOISE
    from wbfriction.studies.sensors import SUBSTEPS, run_sensors_study, sensors_markdown

    check_paths({}, {}, {"-o": output_dir})
    r = robot_of(robot, None, None)
    if not r.ft_sensors:
        raise InputError(f"--robot {robot}: the robot has no force-torque sensors ([force_torque.<name>] in its TOML)")
    with stages() as status:
        result = run_sensors_study(r, output_dir, steps=steps, diff=diff,
                                   filtering=FilterOptions(window=window), noise=NOISE if noise else SensorNoise(),
                                   substeps=substeps or SUBSTEPS, progress=status,
                                   route=route)
    out.print(escape(sensors_markdown(result)), highlight=False, soft_wrap=True)
    for f in result.files:
        console.print(f"wrote {f}")


@app.command("study-noise", rich_help_panel=STUDIES)
def study_noise(output_dir: Path = typer.Option(Path("wbfriction-noise"), "-o", "--output-dir", help="Where to write."),
                robots: str = typer.Option("panda,talos", help="Comma-separated built-in robots: an arm (panda) "
                                                               "and a humanoid (talos, on MuJoCo)."),
                families: str = typer.Option("coulomb-viscous,stribeck,thesis,frictionloss",
                                             help="Comma-separated frictions: coulomb-viscous, stribeck, thesis "
                                                  "(3.5), frictionloss (MuJoCo's, the humanoid)."),
                noises: str = typer.Option("1e-4,3e-4", help="Comma-separated position noises [rad]; the first "
                                                             "gets every seed."),
                seeds: int = typer.Option(10, min=1, help="Noise seeds at the first noise level."),
                duration: float = typer.Option(20.0, min=1.0, help="The arm's excitation [s]."),
                steps: int = typer.Option(10, min=1, help="The humanoid's combined walk: steps per direction."),
                workers: int = FitWorkersOpt) -> None:
    """Every model family on noisy logs, estimated and fitted with the default options: errors
    against the injected friction, the model chosen, and each parameter's RMS error over the seeds against its
    Cramér-Rao bound."""
    from wbfriction.studies.noise import FAMILIES, Family, noise_markdown, run_noise_study

    check_paths({}, {}, {"-o": output_dir})
    chosen = [f.strip() for f in families.split(",") if f.strip()]
    unknown = [f for f in chosen if f not in FAMILIES]
    if unknown:
        raise InputError(f"--families: unknown friction '{unknown[0]}': choose from {', '.join(FAMILIES)}")
    try:
        levels = [float(x) for x in noises.split(",") if x.strip()]
    except ValueError:
        raise InputError(f"--noises must be comma-separated numbers [rad], got '{noises}'") from None
    if not levels or any(not x > 0 for x in levels):
        raise InputError(f"--noises must be positive numbers [rad], got '{noises}'")
    loaded = [robot_of(name.strip(), None, None) for name in robots.split(",") if name.strip()]
    with stages() as status:
        rows = run_noise_study(loaded, output_dir, families=cast("list[Family]", chosen), noises=levels, seeds=seeds,
                               duration=duration, steps=steps, workers=workers,
                               progress=status)
    out.print(escape(noise_markdown(rows)), highlight=False, soft_wrap=True)
    console.print(f"wrote {output_dir / 'noise.md'}, {output_dir / 'noise.json'}")


@app.command("study-fleet", rich_help_panel=STUDIES)
def study_fleet(output_dir: Path = typer.Option(Path("wbfriction-fleet"), "-o", "--output-dir", help="Where to write."),
                robots: int = typer.Option(4, min=1, help="Robots of the fleet."),
                logs: int = typer.Option(25, min=12, help="Logs per robot (one a day)."),
                workers: int = typer.Option(2, min=1, help="Worker processes of the local Dask cluster.")) -> None:
    """A simulated TALOS fleet whose friction drifts on two joints: batch, trends, and the joints
    flagged against the truth."""
    import dataclasses

    from wbfriction.studies.drifting_fleet import FleetPlan, run_fleet_study

    check_paths({}, {}, {"-o": output_dir})
    plan = dataclasses.replace(FleetPlan(), robots=robots, logs=logs)
    if robots < 3:
        plan = dataclasses.replace(plan, drifts=tuple(d for d in plan.drifts if d.robot_id in plan.robot_ids))
    with stages() as status:
        study = run_fleet_study(robot_of("talos", None, None), output_dir, plan, workers,
                                progress=status)
    s = study.score
    for robot_id, joint, quantity, onset in study.flagged:
        console.print(f"flagged: {robot_id} {joint} ({quantity}, onset at log {onset})", highlight=False)
    console.print(f"drifts found {len(s.found)} of {len(plan.drifts)} (onset errors in logs: "
                  f"{', '.join(str(e) for e in s.found.values()) or '-'}), missed {len(s.missed)}, false alarms "
                  f"{len(s.false_alarms)} of {s.series} robot-joint series; simulate "
                  f"{study.seconds['simulate']:.0f} s, batch {study.seconds['batch']:.0f} s, trends "
                  f"{study.seconds['trends']:.1f} s")
    for f in study.files:
        console.print(f"wrote {f}")


def noise_levels(text: str) -> tuple[float | None, ...]:
    """``study-filters --levels``: comma-separated position noises [rad], ``exact`` for a log without a sensor model
    (None), in the order given. Raises InputError: not such a list, a negative noise or one given twice."""
    try:
        levels = tuple(None if x.strip() == "exact" else float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise InputError(f"--levels must be comma-separated noises [rad] or 'exact', got '{text}'") from None
    if not levels or any(x is not None and not x >= 0 for x in levels) or len(set(levels)) < len(levels):
        raise InputError(f"--levels must be distinct noises of at least 0 rad or 'exact', got '{text}'")
    return levels


@app.command("study-filters", rich_help_panel=STUDIES)
def study_filters(output_dir: Path = typer.Option(Path("wbfriction-filters"), "-o", "--output-dir",
                                                  help="Where to write."),
                  robot: str = RobotOpt,
                  steps: int = typer.Option(GAIT.steps, help="Steps per direction of the combined walk."),
                  seed: int = typer.Option(0, help="Noise seed (the i-th level takes seed + i)."),
                  levels: str = typer.Option("exact,0,1e-5,1e-4,1e-3", "--levels",
                                             help="Comma-separated position noises [rad] (0: the encoder's and the "
                                                  "torque's noise alone; exact: no sensor model); the figure at "
                                                  "1e-4, else the last."),
                  workers: Optional[int] = typer.Option(None, help="Processes (default: up to 2).")) -> None:
    """Score the differentiation schemes on noisy logs (thesis 7.2, Fig. 7.2)."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.studies.filters import run_filter_study

    check_paths({}, {}, {"-o": output_dir})
    chosen = noise_levels(levels)
    start = time.perf_counter()
    r = robot_of(robot, None, None)
    with stages() as status:
        result = run_filter_study(r, output_dir, steps=steps, levels=chosen, seed=seed, workers=workers,
                                  curve_level=1e-4 if 1e-4 in chosen else chosen[-1], progress=status)
    table = Table(title="Friction of the 12 leg joints through each scheme: combined walk, sensor noise",
                  caption="rms: estimate - tau_f_true on the valid samples [N·m]; parameters: worst error over "
                          "the leg joints [%]; se F_v: the largest standard error of F_v the fit reports [% of "
                          "its value]; *: best scheme of its noise level (lowest worst F_v, F_c, tau_os); "
                          "inf: a joint left with too few samples",
                  box=None)
    for col in ("position noise", "scheme", "N", "rms", *PARAM_NAMES, "se F_v"):
        table.add_column(col, justify="left" if col in ("position noise", "scheme") else "right")
    for level in chosen:
        best = result.best(level)
        for row in (x for x in result.rows if x.position_std == level):
            noise = "exact log" if level is None else f"{level:g} rad"
            mark = " *" if row is best else ""
            table.add_row(noise, row.scheme + mark, str(row.n_samples), f"{row.rms_error:.4g}",
                          *[_percent(row.worst[n]) for n in PARAM_NAMES], _percent(row.worst_se_F_v),
                          style="bold" if mark else None)
    out.print(table)
    for f in result.files:
        console.print(f"wrote {f}")
    console.print(f"study finished in {time.perf_counter() - start:.1f} s")




@app.command("study-quadruped", rich_help_panel=STUDIES)
def study_quadruped(output_dir: Path = typer.Option(Path("wbfriction-quadruped"), "-o", "--output-dir",
                                                    help="Where to write."),
                    robot: str = typer.Option("go2_walking", help="A built-in quadruped on point feet."),
                    simulator: Optional[str] = typer.Option(None, metavar=f"[{'|'.join(ENGINES.loaded())}]",
                                                            help="The engine: ideal (point feet welded while down) "
                                                                 "or mujoco (soft contacts, sphere feet); default: "
                                                                 "the first."),
                    gait: str = typer.Option("trot", help="trot, walk (three feet down), step (a trot in place) "
                                                          "or stand."),
                    drive: str = typer.Option("torque", help="torque (joint torque sensors) or pd (the drivers' "
                                                             "PD law on the logged set-points)."),
                    foot_forces: str = typer.Option("none", help="The feet's forces logged: none, normal or 3d."),
                    noise: bool = typer.Option(False, "--noise", help="A real robot's sensors (19-bit encoders, "
                                                                      "0.05 N·m torques; on MuJoCo the IMU and "
                                                                      "foot forces too): estimated as a user's log "
                                                                      "(route and differentiation chosen)."),
                    duration: float = typer.Option(8.0, min=1.0, help="Simulated time [s]."),
                    seed: int = typer.Option(0, help="The gait's and the noise's seed.")) -> None:
    """What each gait gives a walking quadruped: per joint, the share of samples where its friction is
    determined, by feet on the ground, and its fit against the injected friction."""
    from wbfriction.report.terminal import determination_table
    from wbfriction.rigs import rig_for
    from wbfriction.rigs.quadruped import QuadrupedRig
    from wbfriction.studies.quadruped import QuadrupedCase, case_robot, fits_markdown, run_quadruped, write_study

    check_paths({}, {}, {"-o": output_dir})
    given = robot_of(robot, None, None)
    rig = rig_for(given)
    if not isinstance(rig, QuadrupedRig):
        raise InputError(f"--robot {robot}: not a robot on point feet (contact_model = \"point\" in its TOML)")
    engine = rig.engine(given, simulator)
    assert engine is not None  # a quadruped runs in an engine
    case = QuadrupedCase(simulator=engine.name, gait=gait, drive=drive, foot_forces=foot_forces,  # type: ignore[arg-type]
                         noise=noise, duration=duration, seed=seed)
    r = case_robot(given, case)
    with stages() as status:
        study = run_quadruped(r, case, progress=status)
    console.print(determination_table(study.shares))
    out.print(escape(fits_markdown(study)), highlight=False, soft_wrap=True)
    for f in write_study(r, study, output_dir):
        console.print(f"wrote {f}")

"""``wbfriction demo`` and the ``study-*`` commands: the thesis's studies and this project's."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Optional, cast

import typer
from rich.markup import escape
from rich.table import Table
from rich.text import Text

from wbfriction.exceptions import InputError
from wbfriction.friction.options import RouteOption

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import Diff, FilterOptions
from wbfriction.sim.options import SensorNoise, Simulator

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot

from wbfriction.cli.common import (
    GAIT,
    FitWorkersOpt,
    RobotOpt,
    RouteOpt,
    app,
    console,
    out,
    robot_of,
    stages,
)
from wbfriction.cli.helpformat import STUDIES


def _thesis_percent(x: float) -> str:
    """A thesis error [%] to the digits that mean something: 972, not 971.75."""
    return f"{x:.0f}" if x >= 100 else f"{x:.2f}"


def _thesis_caption(rows, cols: list[int], params: tuple[str, ...]) -> str:
    """What the table's thesis rows are, and why some of Table 6.1's errors are over 100 % (the straight walk
    barely moved those joints in swing: its fit traded Coulomb for viscous friction; Table 6.2's walk, sideways
    too, has them small)."""
    text = "T6.1 / T6.2: the thesis's errors for the same joint (TORO, straight / straight and sideways) [%]"
    over = [(row, params[k], c) for row in rows if row.thesis_6_1 is not None
            for k, c in enumerate(cols) if row.thesis_6_1[c] > 100]
    if not over:
        return text
    named = ", ".join(f"#{row.number} {name} {_thesis_percent(row.thesis_6_1[c])}" for row, name, c in over)
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
                  caption="err: error to the target [%]; " + _thesis_caption(rows, cols, params))
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
                table.add_row("", label, "", *[_thesis_percent(ref[c]) for c in cols], style="dim")
    return table


def _print_not_ok(rows) -> None:
    """Say which rows of a study table are not ``ok`` fits and why: their errors measure the walk's excitation
    (or the fit's trouble), not the estimate."""
    from wbfriction.studies.common import not_ok

    for row in not_ok(rows):
        verdict = row.fit.verdict()
        if verdict.status == "at bound":
            out.print(escape(f"not an ok fit: {row.joint} ({row.group}), {verdict}; a value at a bound is the "
                             "bound's, not the data's (the others may hold)."), highlight=False)
            continue
        why = ("this walk hardly moved it: no estimate below (a short walk hardly turns the hip yaws: try more "
               "--steps)" if verdict.status == "not excited"
               else "its errors below measure the walk, not the estimate: its parameters are not determined by "
                    "these samples")
        out.print(escape(f"not an ok fit: {row.joint} ({row.group}), {verdict}; {why}."), highlight=False)


def _print_worst(rows, worst: dict[str, float], params: tuple[str, ...]) -> None:
    """The worst error of each parameter over the leg joints whose fit is ``ok`` (the others said above)."""
    ok = sum(row.fit.verdict().ok for row in rows)
    if ok:
        out.print(f"worst error over the {ok} leg joints with an ok fit [%]: "
                  + ", ".join(f"{n} {worst[n]:.2f}" for n in params))


def _pulls_note(pulls: int, in_double: int) -> str:
    """The demo's count of samples where a welded foot pulled, and what it means."""
    if not pulls:
        return "no welded foot pulled on the ground (the walk is one a real sole could make)"
    return (f"samples where a welded foot pulled on the ground: {pulls}, {in_double} of them in double support. "
            "The ideal simulator welds a standing sole (a bilateral contact): just after a touch-down the weld "
            "stops the landing foot and shares the load with the other by pulling, where a real sole would "
            "bounce or roll. Double-support samples are never valid for the estimate, so its numbers are not "
            "touched" + ("." if in_double == pulls else "; the others are single-support samples: there the "
                         "walk asks more of the ground than it can give."))


def _demo_mujoco(output_dir: Path, r: Robot, steps: int) -> list[Path]:
    from wbfriction.studies.realistic import KNEE_STEPS, run_realistic_study, worst_scored

    with stages() as status:  # a short combined walk, short forward walks too (the full size's are 5 steps)
        result = run_realistic_study(r, output_dir, steps=steps, knee_steps=min(steps, KNEE_STEPS), progress=status)
    for k, case in enumerate(result.cases):
        if k:
            out.print()
        _print_not_ok(case.rows)
        out.print(study_table(case.rows, f"MuJoCo, combined walk, swing phase: {case.label}", case.scored))
        ok = [row for row in case.rows if row.fit.verdict().ok]
        _print_worst(case.rows, worst_scored(case, ok), case.scored)
        if case.thesis_rows is not None:  # the thesis's comparison: the same log, rigid contacts, no wrenches
            thesis = worst_scored(case, [row for row in case.thesis_rows if row.fit.verdict().ok])
            out.print("  the thesis's route on the same log (rigid stance contact, no wrenches) [%]: "
                      + ", ".join(f"{n} {thesis[n]:.2f}" for n in case.scored))
    out.print("right knee alone, RMS error [N·m] (central differences): " + "; ".join(
        f"{k} {v:.4f}" for k, v in result.knee_rms.items()))
    return result.files


@app.command(rich_help_panel=STUDIES)
def demo(output_dir: Path = typer.Option(Path("wbfriction-demo"), "-o", "--output-dir", help="Where to write."),
         robot: str = RobotOpt,
         steps: int = typer.Option(GAIT.steps, help="Steps per direction of the combined walk (--simulator mujoco: "
                                                    "of the forward walks of Fig. 6.4-6.5 too, at most 5)."),
         simulator: Simulator = typer.Option("ideal", help="ideal: Tables 6.1/6.2, Fig. 6.1-6.3; mujoco: the realistic "
                                                     "simulator's study, Fig. 6.4-6.5.")) -> None:
    """The thesis's simulation study: walk, estimate, fit; Tables 6.1/6.2 and Fig. 6.1-6.3 (--simulator mujoco:
    the realistic simulator's tables and Fig. 6.4-6.5)."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.studies.common import worst_errors
    from wbfriction.studies.simulation import run_study

    check_paths({}, {}, {"-o": output_dir})
    start = time.perf_counter()
    r = robot_of(robot, None, None)
    if simulator == "mujoco":
        for f in _demo_mujoco(output_dir, r, steps):
            console.print(f"wrote {f}")
        console.print(f"demo finished in {time.perf_counter() - start:.1f} s")
        return
    with stages() as status:
        result = run_study(r, output_dir, steps=steps, progress=status, steps_done=status.steps)
    _print_not_ok(result.rows)  # before the table: its error figures of those joints measure the walk
    out.print(study_table(result.rows, "Identified friction (3.5) of the leg joints, combined walk, "
                                        "central differences"))
    _print_worst(result.rows, worst_errors([row for row in result.rows if row.fit.verdict().ok]), PARAM_NAMES)
    out.print(f"true accelerations: max |tau_f - tau_f_true| in single support = {result.truth_max_error:.2e} N·m")
    out.print("right knee, RMS error [N·m] with the leg in swing / in stance: " + "; ".join(
        f"{k} {a:.4f} / {b:.4f}" for k, (a, b) in result.knee_rms.items()))
    out.print(_pulls_note(result.pulls, result.pulls_double_support))
    worst_joint = max(result.generating_share, key=lambda j: result.generating_share[j])
    out.print(f"friction generating power (eq. 7.9), leg joints in swing: at most "
              f"{100 * result.generating_share[worst_joint]:.2f} % of the samples ({worst_joint})")
    for f in result.files:
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
                    simulator: str = typer.Option("ideal", help="ideal (point feet welded while down) or mujoco "
                                                                "(soft contacts, sphere feet)."),
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
    from wbfriction.studies.quadruped import QuadrupedCase, case_robot, fits_markdown, run_quadruped, write_study

    check_paths({}, {}, {"-o": output_dir})
    case = QuadrupedCase(simulator=simulator, gait=gait, drive=drive, foot_forces=foot_forces,  # type: ignore[arg-type]
                         noise=noise, duration=duration, seed=seed)
    r = case_robot(robot_of(robot, None, None), case)
    if not r.partial_contacts:
        raise InputError(f"--robot {robot}: not a robot on point feet (contact_model = \"point\" in its TOML)")
    with stages() as status:
        study = run_quadruped(r, case, progress=status)
    console.print(determination_table(study.shares))
    out.print(escape(fits_markdown(study)), highlight=False, soft_wrap=True)
    for f in write_study(r, study, output_dir):
        console.print(f"wrote {f}")

"""``wbfriction identify``: the inertia model and the friction identified together (thesis 2.4, ch. 8)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Literal, Optional

import typer
from rich.markup import escape

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.actuator.options import ActuatorOptions
from wbfriction.exceptions import InputError
from wbfriction.friction.options import BaseMotion, EstimateOptions, RouteOption
from wbfriction.inertia.options import ArmatureMode, InertialOptions
from wbfriction.logs.options import TimeUnit
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import DiffOption, Mask

if TYPE_CHECKING:
    from wbfriction.inertia.document import Identification
    from wbfriction.pipeline.identify_step import IdentifiedFile

from wbfriction.cli.common import (
    ESTIMATE,
    INERTIAL,
    BaseMotionOpt,
    ConfigOpt,
    FitWorkersOpt,
    LogArg,
    MjcfOpt,
    NoiseTargetOpt,
    RobotOpt,
    RouteOpt,
    TimeUnitOpt,
    UrdfOpt,
    WideOpt,
    app,
    config_text,
    console,
    out,
    print_whole,
    refuse_options,
    robot_of,
    stages,
    warn,
    warn_energy,
)
from wbfriction.cli.helpformat import ROBOT
from wbfriction.cli.outputs import suffixes, written_as

Actuator = Literal["none", "pd"]
ACTUATOR = ActuatorOptions()
OutputOpt = typer.Option(None, "-o", "--output", callback=written_as("urdf"),
                         help=f"Corrected URDF to write ({suffixes('urdf')}: the given one's structure, identified "
                              "inertias); not with --actuator pd.")
JsonOpt = typer.Option(None, "--json", callback=written_as("json"),
                       help=f"Also write every figure as JSON ({suffixes('json')}; for 'wbfriction report "
                            "--identification').")
StribeckOpt = typer.Option("auto", help="v_s of the Stribeck term [rad/s]: auto (from the acceleration route, refined "
                                        "each pass), a number, or none.")
StrideOpt = typer.Option(INERTIAL.stride, min=1, help="Every stride-th single-support sample is used.")
PriorOpt = typer.Option(INERTIAL.prior, min=0.0, help="Weight of the prior toward the given model, in units of the "
                                                      "residual variance; default: chosen by validation from 1e4 down "
                                                      "to 1.")
ArmatureOpt = typer.Option(INERTIAL.armature, help="Rotor inertia: known (the TOML's [armature]), identify (one per "
                                                   "joint, with the friction; for motor-current torques) or none "
                                                   "(link-side torque sensors).")
LinkMarginOpt = typer.Option(INERTIAL.link_margin, help="Share of each given body's pseudo-inertia an identified body "
                                                        "keeps (mass and second moments), in [0, 1); 0: any physical "
                                                        "body.")
PriorToleranceOpt = typer.Option(INERTIAL.prior_tolerance, help="With the prior's weight chosen by validation: the "
                                                                "strongest weight within this share of the best "
                                                                "score.")
TanhSlopeOpt = typer.Option(INERTIAL.tanh_slope, min=1e-12, help="a of the Coulomb term tanh(a qd) [s/rad].")
ConfigOutputOpt = typer.Option(None, "--config-output", callback=written_as("toml"),
                               help="Also write the robot's configuration (TOML) for the "
                                                             "identified model: its urdf the corrected URDF, its "
                                                             "[armature] the identified one (--armature identify), "
                                                             "the rest as given; then 'wbfriction estimate LOG "
                                                             "--config THIS'.")
HoldoutOpt = typer.Option(INERTIAL.holdout, help="Share of the log, at its end, kept out to compare torque predictions "
                                                 "(between 0 and 1; below 0.5 with --actuator pd).")
ActuatorOpt = typer.Option("none", help="pd: a hung PD-driven robot's actuators instead (armature, friction, encoder "
                                        "offsets, the drivers' delay), from its set-points q_des.<joint>; the URDF "
                                        "is kept.")
MaxDelayOpt = typer.Option(ACTUATOR.max_delay, help="--actuator pd: longest delay searched [s].")
DelayOpt = typer.Option(None, help="--actuator pd: a known delay [s] instead.")
WindowOpt = typer.Option(ACTUATOR.window, help="--actuator pd: window of the momentum balance [s].")
OffsetBoundOpt = typer.Option(ACTUATOR.offset_bound, help="--actuator pd: largest encoder offset [rad]; 0: the "
                                                          "TOML's kept.")
DelayedOpt = typer.Option(ACTUATOR.delayed, help="--actuator pd: what the drivers' delay holds back: auto, setpoints "
                                                 "(Isaac Lab's DelayedPDActuator) or torque (PACE's actuator).")
VelocityOpt = typer.Option(ACTUATOR.velocity, help="--actuator pd: the dynamics' velocity: auto, positions "
                                                   "(differentiated once) or logged (the drivers' qd).")

SHARED = ("log", "robot", "urdf", "config", "mjcf", "actuator")
"""The options both modes of ``identify`` read that name what is identified: the log, the robot, the mode."""
BOTH = ("json_output", "config_output", "time_unit", "wide", "holdout")
MODES: dict[Actuator, tuple[str, tuple[str, ...]]] = {
    "none": ("identify without --actuator pd identifies the inertia model and the friction (the URDF written)",
             ("output", "stribeck_velocity", "passes", "stride", "prior", "armature", "link_margin",
              "prior_tolerance", "noise_target", "tanh_slope", "diff", "mask", "route", "base_motion", "workers",
              *BOTH)),
    "pd": ("--actuator pd identifies a hung PD-driven robot's actuators (the URDF kept)",
           ("max_delay", "delay", "window", "offset_bound", "velocity", "delayed", *BOTH)),
}
"""Each ``--actuator``: what it does, as a refusal says it, and the options (:func:`identify`'s parameters) it reads
beyond :data:`SHARED`: the inertia model's identification's (:func:`~wbfriction.pipeline.identify_step.identify_file`)
or the PD-driven actuators' (:func:`~wbfriction.cli.actuator.identify_pd`); any other given on the command line is
refused before the work (:func:`~wbfriction.cli.common.refuse_options`)."""


@app.command(rich_help_panel=ROBOT,
             short_help="Identify inertias and friction together (--actuator pd: a PD robot's drives)")
def identify(ctx: typer.Context, log: Path = LogArg, output: Optional[Path] = OutputOpt, robot: str = RobotOpt,
             urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt, mjcf: Optional[Path] = MjcfOpt,
             json_output: Optional[Path] = JsonOpt, stribeck_velocity: str = StribeckOpt,
             passes: int = typer.Option(2, min=1, help="Identifications with --stribeck-velocity auto."),
             holdout: float = HoldoutOpt, stride: int = StrideOpt, prior: Optional[float] = PriorOpt,
             armature: ArmatureMode = ArmatureOpt, link_margin: float = LinkMarginOpt,
             prior_tolerance: float = PriorToleranceOpt, noise_target: float = NoiseTargetOpt,
             tanh_slope: float = TanhSlopeOpt,
             diff: DiffOption = typer.Option("auto", help="Differentiation scheme (see 'estimate')."),
             mask: Mask = typer.Option(ESTIMATE.mask, help="swing or single (see 'estimate')."),
             route: RouteOption = RouteOpt, base_motion: BaseMotion = BaseMotionOpt,
             workers: int = FitWorkersOpt, time_unit: Optional[TimeUnit] = TimeUnitOpt,
             config_output: Optional[Path] = ConfigOutputOpt, wide: bool = WideOpt,
             actuator: Actuator = ActuatorOpt, max_delay: float = MaxDelayOpt, delay: Optional[float] = DelayOpt,
             window: float = WindowOpt, offset_bound: float = OffsetBoundOpt, velocity: str = VelocityOpt,
             delayed: str = DelayedOpt) -> None:
    """Identify the inertia model and the friction together from the joint torques of single support (thesis
    2.4, ch. 8), write the corrected URDF: then 'wbfriction estimate LOG --urdf IDENTIFIED.urdf'. With --actuator
    pd: a hung PD-driven robot's actuators (armature, friction, encoder offsets, delay) instead; the options of the
    other kind are refused."""
    refuse_options(ctx, *MODES[actuator], SHARED)
    if actuator == "pd":
        from wbfriction.cli.actuator import identify_pd

        identify_pd(log, robot, urdf, config, mjcf, json_output, config_output, time_unit, wide, ActuatorOptions(
            window, max_delay, delay, offset_bound, velocity=velocity, delayed=delayed, holdout=holdout))
        return
    if output is None:
        raise InputError("identify: -o/--output (the corrected URDF) is required")
    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output, "--json": json_output,
                                                                                "--config-output": config_output})
    stribeck = stribeck_option(stribeck_velocity)
    if not 0.0 < holdout < 1.0:
        raise InputError(f"--holdout must be between 0 and 1, got {holdout}")
    from wbfriction.pipeline.identify_step import identify_file, rotor_inertia_notes

    r = robot_of(robot, urdf, config, mjcf)
    r.require_urdf("identify (it writes the corrected URDF)")
    opts = InertialOptions(tanh_slope=tanh_slope, stride=stride, holdout=holdout, prior=prior,
                           armature=armature, link_margin=link_margin, prior_tolerance=prior_tolerance)
    warn(rotor_inertia_notes(r, log, opts))  # torques from currents, no rotor inertia: said before the work
    with stages() as status:
        estimate_options = EstimateOptions(diff=diff, mask=mask, route=route, noise_target=noise_target,
                                           base_motion=base_motion)
        done = identify_file(r, log, output, json_output, estimate_options=estimate_options,
                             options=opts, stribeck=stribeck, passes=passes, progress=status, steps=status.steps,
                             workers=workers,
                             time_unit=time_unit)
    print_identification(done, wide)
    if json_output is not None:
        console.print(f"wrote {json_output}")
    warn_energy(done.loop.final.route.energy)
    console.print(f"wrote {output}")
    if config_output is not None:
        write_config(robot, config, output, config_output, done)


def write_config(robot: str, config: Optional[Path], urdf: Path, config_output: Path, done: IdentifiedFile) -> None:
    """``--config-output``: the robot's TOML for the identified model."""
    from wbfriction.pipeline.identify_step import write_identified_config

    text, folder = config_text(robot, config)
    write_identified_config(text, folder, urdf, config_output, done.armature)
    console.print(f"wrote {config_output}")


def stribeck_option(text: str) -> float | Literal["auto"] | None:
    """``--stribeck-velocity``: ``auto``, ``none`` (any case, spaces around) or a number [rad/s].

    Raises:
        InputError: anything else, naming the option.
    """
    vs_text = text.strip().lower()
    try:
        return None if vs_text == "none" else "auto" if vs_text == "auto" else float(vs_text)
    except ValueError:
        raise InputError(f"--stribeck-velocity must be auto, none or a number, got '{text}'") from None


def print_passes(result: Identification) -> None:
    """One line per pass of the identification (its v_s, samples, base parameters, condition, prior and how it
    went), its gate's verdict and the parameters its log did not excite."""
    for p in result.passes:
        vs = "none" if p.stribeck_velocity is None else f"{p.stribeck_velocity:.4g} rad/s"
        condition = "not finite" if p.condition is None else f"{p.condition:.3g}"
        out.print(escape(f"v_s {vs}: {p.samples} samples, {p.base_parameters} base parameters of "
                         f"{p.parameters}, condition {condition}, prior {p.prior:g}; {p.message}"), highlight=False)
        if p.verdict:
            out.print(escape(p.verdict), highlight=False)
        if p.not_excited:
            names = [u.parameter for u in p.not_excited]
            out.print(escape(f"not excited by this log, kept at the given model: {len(names)} parameters ("
                             + ", ".join(names[:4]) + (", ..." if len(names) > 4 else "") + ")"), highlight=False)


def print_identification(done: IdentifiedFile, wide: bool) -> None:
    """What ``identify`` found: its passes (:func:`print_passes`), the tables of the bodies and joints and their
    notes (``wide``: whole, not fitted to the terminal), the identified armature as TOML, and the joints whose
    body went whole to the child link."""
    from wbfriction.report.terminal import identification_tables

    print_passes(done.identification)
    tables, notes = identification_tables(done.identification, wide)
    for table in tables:
        print_whole(table) if wide else out.print(table)
    for note in notes:
        out.print(escape(note), highlight=False)
    toml = done.armature_toml()
    if toml is not None:
        out.print(escape("identified armature [kg·m^2], for the robot's TOML:\n" + toml), highlight=False)
    if done.moved:
        console.print(f"[yellow]note:[/] the whole identified body went to the child link of {', '.join(done.moved)} "
                      "(lighter than the links merged with it)")

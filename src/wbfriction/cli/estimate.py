"""``wbfriction estimate``, ``convert``, ``sensitivity`` and ``spectrum``: what is read from a log."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional

import typer
from rich.markup import escape
from rich.table import Table

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.exceptions import OptionError
from wbfriction.friction.options import BaseMotion, EstimateOptions, Method, MomentumOptions, RouteOption
from wbfriction.inertia.options import InertiaPart
from wbfriction.logs.formats.catalog import mapped_formats, table_formats
from wbfriction.logs.options import ReadOptions, RepeatsPolicy, TimeBase, TimeUnit
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import AlignmentOption, DiffOption, FilterOptions, Mask, SavgolWeights, Velocity

if TYPE_CHECKING:
    from wbfriction.model.loading import RobotSpec
    from wbfriction.model.robot import Robot

from wbfriction.cli.common import (
    ESTIMATE,
    FILTER,
    BaseMotionOpt,
    ConfigOpt,
    LimitMarginOpt,
    LogArg,
    MapOpt,
    MaxGapOpt,
    MjcfOpt,
    MomentumWindowOpt,
    NoiseTargetOpt,
    RateOpt,
    RepeatsOpt,
    RobotOpt,
    RouteOpt,
    TimeBaseOpt,
    TimeUnitOpt,
    UrdfOpt,
    VelocityWindowOpt,
    app,
    console,
    joint_list,
    out,
    progress_bar,
    refuse_unread,
    robot_of,
    stages,
    warn,
)
from wbfriction.cli.helpformat import FRICTION, LOGS, STUDIES
from wbfriction.cli.outputs import suffixes, written_as


def _run_estimate(r: Robot, spec: RobotSpec, log: Path, output: Path, opts: EstimateOptions,
                  bag_map: Optional[Path] = None, read: ReadOptions = ReadOptions(), workers: int = 2,
                  chunk_rows: int = 10_000, companion: bool = False) -> None:
    """Estimate a log file in chunks on ``workers`` processes (which load the robot from
    ``spec``), read as ``read`` says; a ROS 2 bag is first streamed into a temporary Parquet log beside the
    output."""
    from wbfriction.logs.torque import torque_kind
    from wbfriction.pipeline.chunks import Chunking
    from wbfriction.pipeline.estimate_step import estimate_source

    with stages() as status:
        result = estimate_source(spec, log, output, opts, bag_map=bag_map, robot=r, stage=status,
                                 progress=lambda total: status.steps("estimate", total, "samples"),
                                 chunking=Chunking(rows=chunk_rows, workers=workers), companion=companion, read=read)
    for line in result.prepared:  # a raw walking log made the project's log (wbfriction.pipeline.raw_log): wrapped
        console.print(escape(line), highlight=False, soft_wrap=False)
    console.print(escape(result.clock), highlight=False, soft_wrap=True)
    warn(result.warnings)
    if result.differentiation:
        console.print(f"differentiation: {escape(result.differentiation)}", highlight=False, soft_wrap=True)
    if result.route:
        console.print(f"route: {escape(result.route)}", highlight=False, soft_wrap=True)
    torque = result.metadata.get("torque_source", {})
    kind = torque_kind(torque["source"]) if "source" in torque else None  # what the source is, asked of it
    if (kind is not None and kind.printed) or "setpoints" in torque:
        held = "the whole torque" if torque.get("delayed") == "torque" else "the set-points"
        delay = f", {held} {1e3 * torque['delay']:.3g} ms late ({torque['gains']})" if "delay" in torque else ""
        if torque.get("delayed_known") is False:
            delay += "; the log it was identified on does not tell what the delay holds back: F_v known to kp delay"
        unused = "; the set-points q_des.<joint> not used" if "setpoints" in torque else ""
        console.print(escape(f"torque: {torque['what']}{delay}{unused}"), highlight=False, soft_wrap=True)
        if kind is not None and kind.pd_law and bag_map is None:
            from wbfriction.pipeline.actuator_step import pd_law_warnings

            warn(pd_law_warnings(r, log, read.time_unit))
    if opts.velocity == "logged":
        velocity = result.metadata.get("velocity", {})  # measured on the first chunk
        console.print(f"velocity: {escape(velocity.get('reason', 'logged'))} (not compensated)", highlight=False)
    routes = result.metadata.get("base_motion")
    if routes and r.floating_base:  # decided on the first chunk; a fixed base has none
        console.print(f"base motion: {routes['base']}" + ("; wrenches: every joint in every phase"
                                                          if routes["wrenches"] else ""), highlight=False)
        if r.partial_contacts:
            _print_determination(output, r)
        else:
            _print_cross_check(output)
    console.print(f"wrote {output}: {result.rows} samples")


def _print_determination(friction: Path, robot: Robot) -> None:
    """The share of samples that determine each joint's friction, by contact pattern (a robot on point feet)."""
    from wbfriction.friction.io import read_friction_file
    from wbfriction.friction.point_contacts import determined_shares
    from wbfriction.report.terminal import determination_table

    shares = determined_shares(read_friction_file(friction))
    if shares is not None:
        console.print(determination_table(shares))


def _print_cross_check(friction: Path) -> None:
    """The joints whose measured and rigid-contact routes disagree: one line per likely cause, the worst first,
    each joint with its disagreement's RMS against its friction's."""
    from wbfriction.friction.cross_check import LARGE, cross_check_file
    from wbfriction.report.terminal import NAMES_SHOWN

    checks = cross_check_file(friction)
    large = sorted((c for c in checks if c.cause), key=lambda c: -c.rms)
    if checks:
        console.print(f"routes cross-checked on {max(c.samples for c in checks)} single-support samples: "
                      f"{len(large)} of {len(checks)} joints disagree by more than {100 * LARGE:g} % of their "
                      "friction's RMS", highlight=False)
    for cause in dict.fromkeys(c.cause for c in large):
        joints = [f"{c.joint} {c.rms:.2g}/{c.rms / c.share:.2g} N·m" for c in large if c.cause == cause]
        more = f" and {len(joints) - NAMES_SHOWN} more" if len(joints) > NAMES_SHOWN else ""
        console.print(f"  likely {escape(cause)}: {', '.join(joints[:NAMES_SHOWN])}{more} (RMS against friction)",
                      highlight=False, soft_wrap=True)


@app.command(rich_help_panel=FRICTION)
def estimate(ctx: typer.Context, log: Path = typer.Argument(..., metavar="LOG",
                                        help=f"Log in the wbfriction format: {table_formats()}; through --map: "
                                             f"{mapped_formats()}."),
             output: Path = typer.Option(..., "-o", "--output",
                                         help=f"Friction table to write: {suffixes('streamed-table')}.",
                                         callback=written_as("streamed-table")),
             robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
             mjcf: Optional[Path] = MjcfOpt,
             bag_map: Optional[Path] = MapOpt, max_gap: float = MaxGapOpt, limit_margin: float = LimitMarginOpt,
             workers: int = typer.Option(2, min=1, help="Processes estimating chunks of a long log (started when "
                                                       "each gets at least 4 chunks)."),
             chunk_rows: int = typer.Option(10_000, min=200, help="Rows per chunk (cut at the next contact "
                                                                   "change)."),
             diff: DiffOption = typer.Option("auto", help="Differentiation: auto (scheme and window chosen from the "
                                                   "positions' noise, printed), central (6.2), backward (6.3), "
                                                   "savgol (Savitzky-Golay, 7.1.1), butterworth (7.1.2) or true."),
             window: int = typer.Option(FILTER.window, help="savgol: window length L (odd, at least 3) [samples]."),
             poly_order: int = typer.Option(FILTER.poly_order,
                                            help="savgol: polynomial order k (at least 2, below L)."),
             weights: SavgolWeights = typer.Option(FILTER.weights, help="savgol: uniform or gaussian weights."),
             cutoff: float = typer.Option(FILTER.cutoff, help="butterworth: cutoff [Hz] (see 'wbfriction spectrum')."),
             butter_order: int = typer.Option(FILTER.butter_order, min=1, help="butterworth: filter order."),
             delay_compensation: bool = typer.Option(ESTIMATE.compensate_delay,
                                                     help="Shift derivatives by their delay (6.1.2)."),
             torque_alignment: AlignmentOption = typer.Option(ESTIMATE.torque_alignment,
                                                  help="zoh: mean of tau[k-1], tau[k]; sample: tau[k]."),
             mask: Mask = typer.Option(ESTIMATE.mask, help="swing: leg joints only while their leg swings; single."),
             lift_off: float = typer.Option(ESTIMATE.lift_off_skip, min=0.0, help="Seconds dropped after a lift-off."),
             touch_down: float = typer.Option(ESTIMATE.touch_down_skip, min=0.0, help="Seconds dropped before a "
                                                                                "touch-down."),
             ds_weight: float = typer.Option(ESTIMATE.ds_weight, min=1e-12,
                                             help="W of the double-support problem (6.1)."),
             ds_regularization: float = typer.Option(ESTIMATE.ds_regularization, min=0.0,
                                                     help="Lambda of the double-support problem (6.1)."),
             cond: bool = typer.Option(ESTIMATE.condition_number, "--cond",
                                       help="Report cond(M_mod^-1) per sample (slower)."),
             method: Method = typer.Option(ESTIMATE.method, help="Single-support route: rnea (fast) or kkt "
                                                        "(5.10-5.13)."),
             time_base: TimeBase = TimeBaseOpt, time_unit: Optional[TimeUnit] = TimeUnitOpt,
             repeats: RepeatsPolicy = RepeatsOpt, rate: Optional[float] = RateOpt,
             velocity: Velocity = typer.Option(ESTIMATE.velocity,
                                               help="Joint velocities: differentiated (by --diff) or "
                                                    "logged (the log's qd.<joint> columns; their lag "
                                                    "is measured and printed)."),
             companion: bool = typer.Option(False, "--companion",
                                            help="Also write delta_qdd_companion.<joint>: the acceleration "
                                                 "difference through the other kind of scheme, for the report's "
                                                 "Fig. 7.4 (one more pass)."),
             base_motion: BaseMotion = BaseMotionOpt,
             wrenches: bool = typer.Option(ESTIMATE.wrenches, help="Use the force-torque sensors' wrench.<sensor>.* "
                                                             "columns where logged: every joint's friction in "
                                                             "every phase."),
             route: RouteOption = RouteOpt, velocity_window: Optional[int] = VelocityWindowOpt,
             momentum_window: Optional[int] = MomentumWindowOpt, noise_target: float = NoiseTargetOpt) -> None:
    """Estimate the friction torque of every torque-controlled joint at every sample."""
    from wbfriction.model.loading import RobotSpec

    check_paths({"LOG": log, "--map": bag_map, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    opts = EstimateOptions(diff=diff, compensate_delay=delay_compensation,
                           torque_alignment=torque_alignment, mask=mask,
                           lift_off_skip=lift_off, touch_down_skip=touch_down, ds_weight=ds_weight,
                           ds_regularization=ds_regularization, condition_number=cond, method=method,
                           velocity=velocity, base_motion=base_motion,
                           wrenches=wrenches, route=route, noise_target=noise_target,
                           momentum=MomentumOptions(velocity_window, momentum_window),
                           filtering=FilterOptions(window=window, poly_order=poly_order,
                                                   weights=weights,
                                                   cutoff=cutoff, butter_order=butter_order))
    _refuse_acceleration_outputs(opts, companion)
    spec = RobotSpec.given(robot, urdf, config, mjcf)
    r = spec.load()
    if not r.floating_base:
        refuse_unread(ctx, f"robot '{r.name}' has a fixed base", CONTACT_OPTIONS, "contact or base")
    read = ReadOptions(max_gap=max_gap, limit_margin=limit_margin, time_base=time_base, time_unit=time_unit,
                       repeats=repeats, rate=rate)
    _run_estimate(r, spec, log, output, opts, bag_map, read, workers, chunk_rows, companion)


CONTACT_OPTIONS = ("mask", "lift_off", "touch_down", "ds_weight", "ds_regularization", "base_motion", "wrenches")
"""The options of ``estimate`` (its parameters) that read the contacts or the floating base: a fixed-base robot's
estimate reads none of them, and refuses them given (:func:`~wbfriction.cli.common.refuse_unread`)."""


def _refuse_acceleration_outputs(opts: EstimateOptions, companion: bool) -> None:
    """The acceleration route's outputs, not the momentum route's: asked for with it, refused (with --route auto, the
    route's line says which was taken).

    Raises:
        OptionError: ``--cond`` or ``--companion`` with ``--route momentum``.
    """
    if opts.condition_number and opts.route == "momentum":
        raise OptionError("--cond", True, "left out with --route momentum (cond(M_mod^-1) is the acceleration "
                          "route's: the momentum route inverts no M_mod)")
    if companion and opts.route == "momentum":
        raise OptionError("--companion", True, "left out with --route momentum (the companion is the acceleration "
                          "route's other differentiation)")


@app.command(rich_help_panel=LOGS)
def convert(bag: Path = typer.Argument(..., metavar="BAG", help=f"Log to convert, through --map: {mapped_formats()}; "
                                                                f"or a table log: {table_formats()}."),
            bag_map: Optional[Path] = typer.Option(None, "--map", help="Topic map TOML of a bag: [joint_states], "
                                                                        "[[contacts]], [base]; of a table log: "
                                                                        "[joint_states] rename, [[contacts]] "
                                                                        "column, threshold."),
            output: Path = typer.Option(..., "-o", "--output",
                                        help=f"Log to write: {suffixes('streamed-table')}.",
                                        callback=written_as("streamed-table")),
            robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
            mjcf: Optional[Path] = MjcfOpt,
            max_gap: float = MaxGapOpt, limit_margin: float = LimitMarginOpt) -> None:
    """Convert a ROS 2 bag (or another log file) into a wbfriction log: joint states, contacts
    (zero-order hold) and base pose (linear + slerp) aligned on the joint-state stamps,
    streamed, and checked against the robot before it is renamed into place."""
    from wbfriction.pipeline.convert import convert_log

    check_paths({"BAG": bag, "--map": bag_map, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    r = robot_of(robot, urdf, config, mjcf)
    with stages() as stage:
        stage(f"reading {bag}")
        rows = convert_log(r, bag, output, bag_map, read=ReadOptions(max_gap=max_gap, limit_margin=limit_margin))
    console.print(f"wrote {output} ({rows} samples)")


@app.command(rich_help_panel=STUDIES)
def sensitivity(log: Path = LogArg,
                output: Path = typer.Option(Path("sensitivity.png"), "-o", "--output", callback=written_as("png"),
                                            help=f"Figure to write ({suffixes('png')})."),
                robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
                mjcf: Optional[Path] = MjcfOpt,
                factors: str = typer.Option("0.9,0.95,1.05,1.1", help="Comma-separated inertia scaling factors."),
                part: InertiaPart = typer.Option("all", help="all (the whole 6x6 inertia), mass or rotational (its "
                                                             "mass or principal-moment eigenvalues only)."),
                joints: Optional[str] = typer.Option(None, help="Comma-separated joints to plot (default: the "
                                                                "legs' joints)."),
                diff: DiffOption = typer.Option("auto", help="Differentiation scheme (see 'estimate')."),
                mask: Mask = typer.Option(ESTIMATE.mask, help="swing or single (see 'estimate')."),
                route: RouteOption = RouteOpt,
                time_unit: Optional[TimeUnit] = TimeUnitOpt) -> None:
    """Re-run the estimate with every body's inertia scaled (thesis 7.2, Fig. 7.5/7.6): how the
    friction curves shift (mass) and split into branches (rotational inertia)."""
    from wbfriction.inertia.sensitivity import inertia_sensitivity, parse_factors
    from wbfriction.logs.source import read_log
    from wbfriction.report.figures import save_png, sensitivity_figure

    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    values = parse_factors(factors)
    r = robot_of(robot, urdf, config, mjcf)
    data = read_log(log, r, read=ReadOptions(time_unit=time_unit))
    warn(data.warnings)
    opts = EstimateOptions(diff=diff, mask=mask,
                           route=route)
    with stages() as status:
        sens = inertia_sensitivity(r, data, values, part, opts, progress=status)
    names = joint_list(r, joints)
    with stages() as stage:
        stage("fitting the offsets of the model as given")
        tau_os = sens.reference_offsets(names)
    table = Table(title=f"Change of the friction estimate with {part} inertia scaled, against the model as given",
                  caption="shift: mean change over the valid samples; split: mean change on rising minus falling "
                          "velocity; gen: share of valid samples generating power (eq. 7.9), the offset tau_os "
                          "identified with the model as given removed", box=None)
    table.add_column("joint")
    table.add_column("x1 gen [%]", justify="right")
    for f in sens.factors[1:]:
        table.add_column(f"x{f:g} shift [N·m]", justify="right")
        table.add_column("split", justify="right")
        table.add_column("gen [%]", justify="right")
    for j in names:
        base = sens.reference_share(j, tau_os[j])
        cells = [c for js in sens.joint(j, tau_os[j]) for c in (f"{js.shift:+.3f}", f"{js.split:+.3f}",
                                                                 f"{100 * js.generating_share:.1f}")]
        table.add_row(j, f"{100 * base:.1f}", *cells)
    out.print(table)
    save_png(sensitivity_figure(sens, names), output)
    console.print(f"wrote {output}")


@app.command(rich_help_panel=STUDIES)
def spectrum(log: Path = LogArg,
             output: Path = typer.Option(Path("spectrum.png"), "-o", "--output", callback=written_as("png"),
                                         help=f"Figure to write ({suffixes('png')})."),
             robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
             mjcf: Optional[Path] = MjcfOpt,
             joints: Optional[str] = typer.Option(None, help="Comma-separated joints (default: the legs' joints, "
                                                             "else every torque-controlled one)."),
             tail: float = typer.Option(0.01, min=0.0, max=1.0, help="Share of the power (above the noise floor) "
                                                                     "left above the suggested cutoff."),
             time_unit: Optional[TimeUnit] = TimeUnitOpt) -> None:
    """The estimated acceleration's spectrum and the Butterworth cutoff it suggests (thesis Fig. 7.1)."""
    from wbfriction.logs.source import read_log
    from wbfriction.report.figures import spectrum_figure
    from wbfriction.signals.spectrum import acceleration_spectrum

    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    r = robot_of(robot, urdf, config, mjcf)
    data = read_log(log, r, read=ReadOptions(time_unit=time_unit))
    warn(data.warnings)
    names = joint_list(r, joints)
    with progress_bar(len(data), "dynamics") as advance:
        spec = acceleration_spectrum(r, data, names, tail=tail, progress=advance)
    table = Table(title=f"Estimated acceleration (5.10), {spec.span[0]:.2f}-{spec.span[1]:.2f} s", box=None)
    table.add_column("joint")
    table.add_column("content ends at [Hz]", justify="right")
    for j, c in zip(spec.joints, spec.cutoff):
        table.add_row(j, f"{c:.1f}")
    out.print(table)
    if spec.cutoff_found:
        out.print(f"suggested cutoff: {spec.suggestion:.1f} Hz  (wbfriction estimate --diff butterworth "
                  f"--cutoff {spec.suggestion:.0f})")
    else:
        out.print(f"no cutoff to suggest: the content reaches {spec.suggestion:.0f} Hz of the {spec.nyquist:.0f} Hz "
                  "band (broadband: noise, or a vibration the controller makes of it); a low-pass filter would not "
                  "separate it: 'wbfriction estimate' chooses the route and its smoothing from the noise (--diff "
                  "auto, --route auto)")
    spectrum_figure(spec, output)
    console.print(f"wrote {output}")



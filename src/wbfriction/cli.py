"""Command-line interface: a thin layer over the library.

Commands: ``simulate`` (a walk with known friction), ``estimate`` (friction per sample),
``fit`` (model 3.5 per joint), ``identify`` (inertia model and friction together,
corrected URDF), ``report`` (one HTML file), ``sensitivity`` (inertia-model
errors), ``spectrum``, ``demo`` and ``study-filters`` (the thesis's studies).
Bad input prints one line naming the file, column, row or option at fault and exits
with status 2.
"""

from __future__ import annotations

import sys
import time
from contextlib import ExitStack, contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Optional, cast

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.exceptions import InputError, WbfrictionError
from wbfriction.friction.options import (
    DEFAULT_THRESHOLD,
    DEFAULT_TOLERANCE,
    BaseMotion,
    EstimateOptions,
    FitOptions,
    Method,
    ModelChoice,
    MomentumOptions,
    RouteOption,
)
from wbfriction.inertia.options import ArmatureMode, InertialOptions, InertiaPart
from wbfriction.logs.options import LIMIT_MARGIN, MAX_GAP, TimeBase, TimeUnit
from wbfriction.model.robots import BUILTIN_ROBOTS
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import AlignmentOption, Diff, DiffOption, FilterOptions, Mask, SavgolWeights, Velocity
from wbfriction.sim.options import FrictionMode, IdealOptions, Integrator, MujocoOptions, SensorNoise, Simulator
from wbfriction.version import __version__
from wbfriction.walking.options import Gait, GaitOptions

if TYPE_CHECKING:
    from wbfriction.friction.fit import FitResult
    from wbfriction.model.robot import Robot
    from wbfriction.pipeline.estimate import RobotSpec
    from wbfriction.sim.arm import ArmOptions

# rich_markup_mode=None: click's plain help, so that units in brackets ([m], [rad/s], [friction.<group>]) are
# printed as written (Rich markup would take them for tags and delete them)
app = typer.Typer(add_completion=False, rich_markup_mode=None)
console = Console(stderr=True, soft_wrap=True)  # a message is one line, wrapped by the terminal, not cut into lines
out = Console()  # as wide as the terminal (COLUMNS); tables fit it (--wide: every column)

WideOpt = typer.Option(False, "--wide", help="Every column in one table, as wide as it takes (default: tables that "
                                            "fit the terminal).")
VerboseOpt = typer.Option(False, "--verbose", help="Each joint's own line for the notes shared by several.")
RobotOpt = typer.Option("talos", "--robot", help=f"Built-in robot: {', '.join(BUILTIN_ROBOTS)}.")
LOG_FORMATS = "Parquet (.parquet), CSV (.csv) or HDF5 (.h5, .hdf5)"
"""The log file formats every command reads (a ROS 2 bag too, where a command takes --map)."""
LogArg = typer.Argument(..., metavar="LOG", help=f"Log in the wbfriction format: {LOG_FORMATS}.")
FrictionArg = typer.Argument(..., metavar="FRICTION", help="Friction table written by 'wbfriction estimate'.")
EnergyThresholdOpt = typer.Option(DEFAULT_THRESHOLD, min=0.0, max=1.0,
                                  help="Share of power-generating samples (eq. 7.9) above which a joint is flagged.")
EnergyToleranceOpt = typer.Option(DEFAULT_TOLERANCE, min=0.0,
                                  help="Smallest friction torque that counts as generating power [N·m] (the torque "
                                       "sensor's resolution).")
UrdfOpt = typer.Option(None, "--urdf", help="URDF of another robot (with --config), or another URDF of the "
                                             "built-in --robot (e.g. identified inertias).")
ConfigOpt = typer.Option(None, "--config", help="Robot TOML: urdf or mjcf (else give --urdf or --mjcf), "
                                                  "contact_frames, position_controlled, groups.")
MjcfOpt = typer.Option(None, "--mjcf", help="MuJoCo MJCF of the robot instead of its URDF (with --config, or the "
                                             "built-in --robot's configuration); not with --urdf.")
FitWorkersOpt = typer.Option(2, min=1, help="Processes fitting joints side by side.")
RouteOpt = typer.Option("auto", "--route", help="How the friction is reached: momentum (positions "
                                                "differentiated once, generalized momentum), acceleration (twice, "
                                                "the thesis's) or auto (chosen from the positions' noise, printed); "
                                                "the other route is estimated too, as a check.")
VelocityWindowOpt = typer.Option(None, "--velocity-window", help="momentum: the velocity's Savitzky-Golay window "
                                                                 "(odd, at least 7) [samples]; default: chosen from "
                                                                 "the noise.")
MomentumWindowOpt = typer.Option(None, "--momentum-window", help="momentum: the window the friction is averaged "
                                                                 "over (odd, at least 3) [samples]; default: chosen "
                                                                 "from the noise.")
TimeUnitOpt = typer.Option(None, help="Unit of a numeric time column: s, ms, us or ns (needed for integer stamps; "
                                      "float stamps are seconds unless said otherwise; timestamps carry theirs).")
MapOpt = typer.Option(None, "--map", help="Topic map TOML of a ROS 2 bag log (see 'wbfriction convert'); with a "
                                           "table log: its [joint_states] rename and [[contacts]] column, threshold.")


MaxGapOpt = typer.Option(MAX_GAP, min=1.5, help="Time steps of at least this many local median steps split the log "
                                        "into segments, estimated apart.")
TimeBaseOpt = typer.Option("auto", help="Time base the positions are differentiated on: auto (decided from the "
                                         "data and printed), recorded (the stamps as they are: a clock that "
                                         "skips samples) or regularised (a uniform clock fitted to "
                                         "receive-time stamps).")
LimitMarginOpt = typer.Option(LIMIT_MARGIN, min=0.0,
                              help="Positions beyond the URDF limits by more than this [rad] are refused (wrong "
                                   "units).")


@contextmanager
def _progress(total: int, label: str):
    with Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=console, transient=True, disable=total < 2000) as bar:
        task = bar.add_task(label, total=total)
        yield lambda n: bar.advance(task, n)


def _robot(robot: str, urdf: Optional[Path], config: Optional[Path], mjcf: Optional[Path] = None) -> Robot:
    from wbfriction.model.loading import load_robot

    return load_robot(robot, urdf=urdf, config=config, mjcf=mjcf)


def _print_whole(renderable) -> None:
    """Print ``renderable`` as wide as it takes, nothing cut or wrapped (``--wide``; the terminal wraps its
    lines): a console of that width on the same output (``Console.print`` stays within its console's)."""
    from rich.measure import Measurement

    width = max(out.width, Measurement.get(out, out.options.update(width=10_000), renderable).maximum)
    Console(width=width, file=out.file, force_terminal=out.is_terminal, no_color=out.no_color).print(renderable)


def _print_fits(results: list[FitResult], wide: bool = False, verbose: bool = False) -> None:
    """The fitted friction's tables and notes (:mod:`~wbfriction.report.terminal`), as wide as the terminal."""
    from wbfriction.report.terminal import fit_notes, fit_tables

    for table in fit_tables(results, wide):
        _print_whole(table) if wide else out.print(table)
    for line in fit_notes(results, verbose):
        out.print(escape(line), highlight=False)


def _warn(warnings) -> None:
    """Print warnings, one line each."""
    for w in warnings:
        console.print(f"[yellow]warning:[/] {escape(w)}", highlight=False, soft_wrap=True)


def _warn_energy(energy) -> None:
    """Print the energy-consistency warnings (eq. 7.9) of the flagged joints."""
    for e in energy:
        if e.flagged:
            console.print(f"[yellow]warning:[/] {escape(e.warning())}", highlight=False, soft_wrap=True)


def _joint_list(r: Robot, joints: Optional[str]) -> list[str]:
    """``--joints`` as a list (checked), or by default the legs' torque-controlled joints, else all of them."""
    if joints is None:
        legs = [j for f in r.contact_frames for j in r.limb(f) if j in r.torque_controlled]
        return legs or list(r.torque_controlled)
    names = [j.strip() for j in joints.split(",") if j.strip()]
    unknown = [j for j in names if j not in r.torque_controlled]
    if unknown or not names:
        bad = unknown[0] if unknown else joints
        raise InputError(f"--joints: '{bad}' is not a torque-controlled joint of {r.name}")
    return names


_E = EstimateOptions()  # one source of defaults: the library's
_F = FilterOptions()
_G = GaitOptions()
_I = IdealOptions()
_M = MujocoOptions()
_N = InertialOptions()
_FIT = FitOptions()
MinSamplesOpt = typer.Option(_FIT.min_samples, min=1, help="Joints with fewer valid samples are not fitted.")
ModelOpt = typer.Option(_FIT.model, "--model", help="Friction model per joint: auto (the simplest whose held-out RMS "
                                                    "is within --selection-tolerance of the best), coulomb-viscous "
                                                    "(3.1 + 3.2), stribeck (3.3 + 3.2) or thesis (3.5); each with "
                                                    "an offset tau_os.")


def _run_simulate(r: Robot, output: Path, gait: GaitOptions, options: IdealOptions | MujocoOptions,
                  friction: Optional[Path]) -> None:
    from wbfriction.friction.targets import load_friction_toml
    from wbfriction.logs.log import write_log
    from wbfriction.sim.ideal import simulate_ideal
    from wbfriction.sim.mujoco_sim import simulate_mujoco
    from wbfriction.walking.reference import walking_reference

    params = None if friction is None else load_friction_toml(friction, r.groups, r.torque_controlled)
    with console.status(f"planning {gait.steps} steps ({gait.gait})"):
        ref = walking_reference(r, gait)
    with _progress(len(ref), "simulate") as advance:
        if isinstance(options, MujocoOptions):
            result = simulate_mujoco(r, ref, params, options, progress=advance)
        else:
            result = simulate_ideal(r, ref, params, options, progress=advance)
    write_log(result.log, r, output)
    console.print(f"wrote {output} ({len(result.log)} samples, {result.log.time[-1]:.1f} s)")
    for p in result.pulls():
        console.print(f"[yellow]warning:[/] {p.frame} pulled on the ground from {p.start:.3f} s to {p.end:.3f} s "
                      f"({p.samples} samples, down to {p.min_force:.1f} N)", highlight=False)


def _run_simulate_arm(r: Robot, output: Path, options: ArmOptions, friction: Optional[Path]) -> None:
    from wbfriction.friction.targets import load_friction_toml
    from wbfriction.logs.tables import write_table
    from wbfriction.sim.arm import default_arm_friction, simulate_arm

    params = (load_friction_toml(friction, r.groups, r.torque_controlled) if friction is not None
              else default_arm_friction(r))
    with _progress(int(options.duration * options.rate), "simulate") as advance:
        result = simulate_arm(r, params, options=options, progress=advance)
    write_table(result.table, output)
    console.print(f"wrote {output} ({result.table.num_rows} samples, {options.duration:g} s, motor currents)")


def _run_estimate(r: Robot, spec: RobotSpec, log: Path, output: Path, opts: EstimateOptions,
                  bag_map: Optional[Path] = None, max_gap: float = MAX_GAP, limit_margin: float = LIMIT_MARGIN,
                  workers: int = 2, chunk_rows: int = 10_000, time_base: TimeBase = "auto",
                  time_unit: TimeUnit | None = None, companion: bool = False) -> None:
    """Estimate a log file in chunks on ``workers`` processes (which load the robot from
    ``spec``); a ROS 2 bag is first streamed into a temporary Parquet log beside the output."""
    from wbfriction.logs.source import open_log
    from wbfriction.logs.tables import TableFile
    from wbfriction.pipeline.chunks import Chunking
    from wbfriction.pipeline.estimate import estimate_file, table_log
    from wbfriction.pipeline.provenance import log_provenance

    chunking = Chunking(rows=chunk_rows, workers=workers)
    source = open_log(log, bag_map, r)
    provenance = {"provenance": log_provenance(log, r)}
    with ExitStack() as stack:
        with console.status(f"reading {log}") if source.is_bag else nullcontext():
            table = stack.enter_context(table_log(source, output))
        with _progress(TableFile(table).row_count(), "estimate") as advance:
            result = estimate_file(spec, table, output, opts, chunking=chunking, companion=companion,
                                   max_gap=max_gap, limit_margin=limit_margin, extra_metadata=provenance,
                                   progress=advance, robot=r, source=str(log), time_base=time_base,
                                   time_unit=time_unit)
    console.print(escape(result.clock), highlight=False, soft_wrap=True)
    _warn(result.warnings)
    if result.differentiation:
        console.print(f"differentiation: {escape(result.differentiation)}", highlight=False, soft_wrap=True)
    if result.route:
        console.print(f"route: {escape(result.route)}", highlight=False, soft_wrap=True)
    if opts.velocity == "logged":
        velocity = result.metadata.get("velocity", {})  # measured on the first chunk
        console.print(f"velocity: {escape(velocity.get('reason', 'logged'))} (not compensated)", highlight=False)
    routes = result.metadata.get("base_motion")
    if routes and r.floating_base:  # decided on the first chunk; a fixed base has none
        console.print(f"base motion: {routes['base']}" + ("; wrenches: every joint in every phase"
                                                          if routes["wrenches"] else ""), highlight=False)
        _print_cross_check(output)
    console.print(f"wrote {output}: {result.rows} samples")


def _print_cross_check(friction: Path) -> None:
    """The joints whose measured and rigid-contact routes disagree, with the likely cause."""
    from wbfriction.friction.cross_check import LARGE, cross_check_file

    checks = cross_check_file(friction)
    large = [c for c in checks if c.cause]
    if checks:
        console.print(f"routes cross-checked on {max(c.samples for c in checks)} single-support samples: "
                      f"{len(large)} of {len(checks)} joints disagree by more than {100 * LARGE:g} % of their "
                      "friction's RMS", highlight=False)
    for c in sorted(large, key=lambda c: -c.rms):
        console.print(f"  {c.joint}: {c.rms:.2g} N·m RMS against {c.rms / c.share:.2g} of friction; likely "
                      f"{escape(c.cause)}", highlight=False, soft_wrap=True)


def _run_fit(friction: Path, output: Path, options: FitOptions, threshold: float, tolerance: float,
             workers: int, wide: bool = False, verbose: bool = False) -> None:
    from wbfriction.pipeline.fit import fit_file

    fitted = fit_file(friction, output, options, threshold=threshold, tolerance=tolerance, workers=workers)
    _print_fits(fitted.fits, wide, verbose)
    _warn_energy(fitted.energy)
    console.print(f"wrote {output}")


@app.command()
def simulate(output: Path = typer.Option(..., "-o", "--output", help="Log to write: .parquet, .csv or .h5."),
             robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
             mjcf: Optional[Path] = MjcfOpt,
             gait: Gait = typer.Option(_G.gait, help="forward, sideways, turning, both (forward + sideways) or "
                                                    "combined (all three)."),
             steps: int = typer.Option(_G.steps, help="Number of steps (per direction for both/combined)."),
             step_length: float = typer.Option(_G.step_length, help="Forward distance between footprints [m]."),
             step_width: float = typer.Option(_G.step_width, help="Sideways step [m]."),
             turn_angle: float = typer.Option(_G.turn_angle, help="Heading change per turning step [rad]."),
             lift_height: float = typer.Option(_G.lift_height, help="Swing-foot apex [m]."),
             friction: Optional[Path] = typer.Option(None, help="TOML with [friction.<group or joint>] tables (a "
                                                               "model key: coulomb-viscous, stribeck or (3.5)); "
                                                               "default: thesis Table 6.1 on the legs."),
             simulator: Simulator = typer.Option("ideal", help="ideal (rigid contacts, thesis 6.1) or mujoco (soft "
                                                         "contacts, measured contact flags, sensors, thesis 6.2)."),
             substeps: Optional[int] = typer.Option(None, help=f"Physics steps per 1 ms control period (default: "
                                                              f"{_I.substeps} ideal, {_M.substeps} mujoco)."),
             integrator: Integrator = typer.Option(_I.integrator, help="ideal: semi-implicit or explicit Euler."),
             mujoco_friction: FrictionMode = typer.Option(_M.friction, help="mujoco: model (eq. 3.5 as a joint torque) "
                                                                   "or mujoco (MuJoCo's frictionloss = F_c, damping "
                                                                   "= F_v)."),
             sensors: Optional[Path] = typer.Option(None, help="mujoco: TOML with a [sensors] table (position_std, "
                                                               "encoder_bits, torque_std, seed, delay); the options "
                                                               "below override it."),
             position_noise: Optional[float] = typer.Option(None, help="mujoco and arms: joint-position noise std "
                                                                       "[rad]."),
             encoder_bits: Optional[int] = typer.Option(None, help="mujoco and arms: encoder resolution [bits per "
                                                                   "turn]."),
             torque_noise: Optional[float] = typer.Option(None, help="mujoco and arms: torque-sensor noise std "
                                                                     "[N·m]."),
             noise_seed: Optional[int] = typer.Option(None, help="mujoco and arms: seed of the sensor noise."),
             delay: Optional[float] = typer.Option(None, help="mujoco: measurement-to-command delay [ms], whole "
                                                              "control periods."),
             log_base: bool = typer.Option(_I.log_base, help="Write the base pose to the log."),
             force_torque: bool = typer.Option(_I.force_torque, help="ideal: write what the robot's force-torque "
                                                                     "sensors and IMU measure (wrench.<sensor>.*, "
                                                                     "imu.* columns; mujoco always does)."),
             sole_timeconst: Optional[float] = typer.Option(None, help="mujoco: the soles' contact time constant "
                                                                       "(s; default MuJoCo's 0.02, larger is "
                                                                       "softer: a compliant sole)."),
             friction_timeconst: Optional[float] = typer.Option(None, help="mujoco: the friction-loss constraint's "
                                                                           "time constant (s; default two physics "
                                                                           "steps: a joint that sticks; MuJoCo's "
                                                                           "0.02 leads the velocity by 10 ms)."),
             torque_drift: float = typer.Option(_M.torque_drift, min=0.0, help="mujoco: drift rate of each torque "
                                                                               "sensor's offset (N·m/s)."),
             ft_offset: tuple[float, float] = typer.Option(_M.ft_offset, help="mujoco: standard deviations of the "
                                                                               "force-torque sensors' constant "
                                                                               "offsets: force (N), torque (N·m)."),
             duration: float = typer.Option(10.0, help="Fixed-base robot (an arm): seconds of excitation "
                                                       "trajectory.")) -> None:
    """Simulate a walk with known friction: ideal (rigid contacts) or MuJoCo (realistic); a
    fixed-base robot (--robot panda) tracks an excitation trajectory, logging motor currents."""
    from wbfriction.sim.arm import ArmOptions
    from wbfriction.sim.sensors import load_sensors_toml

    check_paths({"--urdf": urdf, "--mjcf": mjcf, "--config": config, "--friction": friction, "--sensors": sensors},
                {"-o": output})
    r = _robot(robot, urdf, config, mjcf)
    if not r.floating_base:
        arm = ArmOptions(duration=duration, encoder_bits=19 if encoder_bits is None else encoder_bits,
                         position_std=position_noise or 0.0, torque_std=torque_noise or 0.0, seed=noise_seed or 0)
        _run_simulate_arm(r, output, arm, friction)
        return
    gait_opts = GaitOptions(gait=gait, steps=steps, step_length=step_length, step_width=step_width,
                            turn_angle=turn_angle, lift_height=lift_height)
    options: IdealOptions | MujocoOptions
    if simulator == "ideal":
        options = IdealOptions(substeps=substeps or _I.substeps, integrator=integrator,
                               log_base=log_base, force_torque=force_torque, imu=force_torque)
    else:
        table = load_sensors_toml(sensors) if sensors is not None else {}
        given = {"position_std": position_noise, "encoder_bits": encoder_bits, "torque_std": torque_noise,
                 "seed": noise_seed, "delay": None if delay is None else delay * 1e-3}
        table.update({k: v for k, v in given.items() if v is not None})
        lag = float(table.pop("delay", 0.0))
        options = MujocoOptions(substeps=substeps or _M.substeps, friction=mujoco_friction,
                                sensors=SensorNoise(**table), delay=lag, log_base=log_base,
                                sole_timeconst=sole_timeconst, friction_timeconst=friction_timeconst,
                                torque_drift=torque_drift, ft_offset=ft_offset)
    _run_simulate(r, output, gait_opts, options, friction)


@app.command()
def estimate(log: Path = typer.Argument(..., metavar="LOG",
                                        help=f"Log in the wbfriction format: {LOG_FORMATS}; or a ROS 2 bag (--map)."),
             output: Path = typer.Option(..., "-o", "--output", help="Friction table to write: .parquet, .csv or "
                                                                     ".h5."),
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
             window: int = typer.Option(_F.window, help="savgol: window length L (odd, at least 3) [samples]."),
             poly_order: int = typer.Option(_F.poly_order, help="savgol: polynomial order k (at least 2, below L)."),
             weights: SavgolWeights = typer.Option(_F.weights, help="savgol: uniform or gaussian weights."),
             cutoff: float = typer.Option(_F.cutoff, help="butterworth: cutoff [Hz] (see 'wbfriction spectrum')."),
             butter_order: int = typer.Option(_F.butter_order, min=1, help="butterworth: filter order."),
             delay_compensation: bool = typer.Option(_E.compensate_delay,
                                                     help="Shift derivatives by their delay (6.1.2)."),
             torque_alignment: AlignmentOption = typer.Option(_E.torque_alignment,
                                                  help="zoh: mean of tau[k-1], tau[k]; sample: tau[k]."),
             mask: Mask = typer.Option(_E.mask, help="swing: leg joints only while their leg swings; single."),
             lift_off: float = typer.Option(_E.lift_off_skip, min=0.0, help="Seconds dropped after a lift-off."),
             touch_down: float = typer.Option(_E.touch_down_skip, min=0.0, help="Seconds dropped before a "
                                                                                "touch-down."),
             ds_weight: float = typer.Option(_E.ds_weight, min=1e-12, help="W of the double-support problem (6.1)."),
             ds_regularization: float = typer.Option(_E.ds_regularization, min=0.0,
                                                     help="Lambda of the double-support problem (6.1)."),
             cond: bool = typer.Option(_E.condition_number, "--cond",
                                       help="Report cond(M_mod^-1) per sample (slower)."),
             method: Method = typer.Option(_E.method, help="Single-support route: rnea (fast) or kkt "
                                                        "(5.10-5.13)."),
             time_base: TimeBase = TimeBaseOpt, time_unit: Optional[TimeUnit] = TimeUnitOpt,
             velocity: Velocity = typer.Option(_E.velocity, help="Joint velocities: differentiated (by --diff) or "
                                                            "logged (the log's qd.<joint> columns; their lag "
                                                            "is measured and printed)."),
             companion: bool = typer.Option(False, "--companion",
                                            help="Also write delta_qdd_companion.<joint>: the acceleration "
                                                 "difference through the other kind of scheme, for the report's "
                                                 "Fig. 7.4 (one more pass)."),
             base_motion: BaseMotion = typer.Option(_E.base_motion, help="Base motion: contact (rigid stance foot, "
                                                                  "thesis 5.4), logged (the base.* pose "
                                                                  "differentiated like the joints), imu (the "
                                                                  "imu.* gyro and accelerometer, the base.q* "
                                                                  "orientation) or auto (imu, else logged with "
                                                                  "wrenches, else contact; printed)."),
             wrenches: bool = typer.Option(_E.wrenches, help="Use the force-torque sensors' wrench.<sensor>.* "
                                                             "columns where logged: every joint's friction in "
                                                             "every phase."),
             route: RouteOption = RouteOpt, velocity_window: Optional[int] = VelocityWindowOpt,
             momentum_window: Optional[int] = MomentumWindowOpt) -> None:
    """Estimate the friction torque of every torque-controlled joint at every sample."""
    from wbfriction.pipeline.estimate import RobotSpec

    check_paths({"LOG": log, "--map": bag_map, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    opts = EstimateOptions(diff=diff, compensate_delay=delay_compensation,
                           torque_alignment=torque_alignment, mask=mask,
                           lift_off_skip=lift_off, touch_down_skip=touch_down, ds_weight=ds_weight,
                           ds_regularization=ds_regularization, condition_number=cond, method=method,
                           velocity=velocity, base_motion=base_motion,
                           wrenches=wrenches, route=route,
                           momentum=MomentumOptions(velocity_window, momentum_window),
                           filtering=FilterOptions(window=window, poly_order=poly_order,
                                                   weights=weights,
                                                   cutoff=cutoff, butter_order=butter_order))
    spec = RobotSpec(None if config else robot, None if urdf is None else str(urdf),
                     None if config is None else str(config), None if mjcf is None else str(mjcf))
    _run_estimate(_robot(robot, urdf, config, mjcf), spec, log, output, opts, bag_map, max_gap, limit_margin, workers,
                  chunk_rows, time_base, time_unit, companion)


@app.command()
def convert(bag: Path = typer.Argument(..., metavar="BAG", help="ROS 2 bag (folder with metadata.yaml; MCAP or "
                                                                "sqlite3), or a Parquet, CSV or HDF5 log."),
            bag_map: Optional[Path] = typer.Option(None, "--map", help="Topic map TOML of a bag: [joint_states], "
                                                                        "[[contacts]], [base]; of a table log: "
                                                                        "[joint_states] rename, [[contacts]] "
                                                                        "column, threshold."),
            output: Path = typer.Option(..., "-o", "--output", help="Log to write: .parquet or .csv."),
            robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
            mjcf: Optional[Path] = MjcfOpt,
            max_gap: float = MaxGapOpt, limit_margin: float = LimitMarginOpt) -> None:
    """Convert a ROS 2 bag (or another log file) into a wbfriction log: joint states, contacts
    (zero-order hold) and base pose (linear + slerp) aligned on the joint-state stamps,
    streamed, and checked against the robot before it is renamed into place."""
    from wbfriction.pipeline.convert import convert_log

    check_paths({"BAG": bag, "--map": bag_map, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    r = _robot(robot, urdf, config, mjcf)
    with console.status(f"reading {bag}"):
        rows = convert_log(r, bag, output, bag_map, max_gap=max_gap, limit_margin=limit_margin)
    console.print(f"wrote {output} ({rows} samples)")


@app.command()
def fit(friction: Path = FrictionArg,
        output: Path = typer.Option(..., "-o", "--output", help="Parameters to write (JSON)."),
        min_samples: int = MinSamplesOpt,
        energy_threshold: float = EnergyThresholdOpt, energy_tolerance: float = EnergyToleranceOpt,
        workers: int = FitWorkersOpt, model: ModelChoice = ModelOpt,
        selection_tolerance: float = typer.Option(_FIT.selection_tolerance, min=0.0,
                                                  help="With --model auto: relative excess of held-out RMS within "
                                                       "which the simpler model is chosen."),
        wide: bool = WideOpt, verbose: bool = VerboseOpt) -> None:
    """Identify a friction model of every joint, with standard errors and the parameters left
    at a bound; warn about joints whose friction generates power (eq. 7.9)."""
    check_paths({"FRICTION": friction}, {"-o": output})
    _run_fit(friction, output, FitOptions(model=model, selection_tolerance=selection_tolerance,
                                          min_samples=min_samples), energy_threshold, energy_tolerance, workers,
             wide, verbose)


@app.command()
def export(params: Path = typer.Argument(..., metavar="PARAMS", help="Parameters written by 'wbfriction fit'."),
           outputs: list[Path] = typer.Option(..., "-o", "--output",
                                              help="File to write, format by name: .urdf (<dynamics damping "
                                                   "friction>), .xml (MuJoCo MJCF: damping, frictionloss, "
                                                   "armature) or .yaml (Isaac Lab actuators); repeat -o for "
                                                   "several."),
           include: str = typer.Option("", "--include",
                                       help="Fit statuses exported besides ok, comma-separated: weak (large "
                                            "standard errors), at-bound (a parameter at a bound of the fit), "
                                            "routes-disagree (the two routes' fits differ: one is biased). "
                                            "Fits not excited or failed are never exported."),
           robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
           mjcf: Optional[Path] = MjcfOpt) -> None:
    """Write the fitted friction where simulators read it: the fits whose status is ok (and --include),
    each with its status in a comment; the other joints keep what the model file has. F_v -> damping,
    F_c -> Coulomb friction (MuJoCo frictionloss); the Stribeck bump, the tanh and tau_os have no
    simulator field and are dropped. Inertias are the URDF's: give --urdf IDENTIFIED.urdf to export
    identified ones."""
    from wbfriction.pipeline.export import export_files

    check_paths({"PARAMS": params, "--urdf": urdf, "--mjcf": mjcf, "--config": config},
                {f"-o {o}": o for o in outputs})
    result = export_files(_robot(robot, urdf, config, mjcf), params, outputs,
                          include=[c.strip() for c in include.split(",") if c.strip()])
    counts = result.selection.exported_statuses
    console.print(f"exported the friction of {sum(counts.values())} joints ("
                  + ", ".join(f"{n} {status}" for status, n in counts.items()) + ")", highlight=False)
    for status, joints in result.selection.left_out.items():
        console.print(f"not exported, {status}: {', '.join(joints)}", highlight=False, soft_wrap=True)
    for path, fmt in result.outputs:
        console.print(f"wrote {path} ({fmt})")


@app.command()
def predict(friction: Path = typer.Argument(..., metavar="FRICTION",
                                            help="Friction table of a held-out log ('wbfriction estimate' with the URDF"
                                                 " under test)."),
            params: Path = typer.Option(..., "--params", help="Parameters fitted on other logs estimated with "
                                                              "the same URDF ('wbfriction fit').")) -> None:
    """How well a model predicts torques it was not fitted on: per joint, the RMS of measured minus
    predicted torque, tau - (M qdd + h + f(qd)), with the friction model and without it."""
    import numpy as np

    from wbfriction.pipeline.predict import predict_file

    check_paths({"FRICTION": friction, "--params": params}, {})
    pred = predict_file(friction, params)
    table = Table(title=f"Torque prediction on {friction.name}: RMS of measured - predicted [N·m]", box=None)
    for col in ("joint", "samples", "rigid body only", "with friction", "fit"):
        table.add_column(col, justify="right" if col in ("samples", "rigid body only", "with friction") else "left")
    statuses = pred.status or ("",) * len(pred.joints)
    for j, n, rigid, full, status in zip(pred.joints, pred.samples, pred.rms_rigid_body, pred.rms, statuses):
        table.add_row(j, str(n), f"{rigid:.4g}", "—" if not np.isfinite(full) else f"{full:.4g}", status,
                      style=None if status in ("ok", "") else "dim")
    rigid, full = pred.overall(pred.rms_rigid_body), pred.overall(pred.rms)
    table.add_row("all joints", str(int(pred.samples.sum())), f"{rigid:.4g}",
                  "—" if not np.isfinite(full) else f"{full:.4g}", "", style="bold", end_section=True)
    out.print(table)
    if any(status not in ("ok", "") for status in statuses):
        console.print("a prediction by a fit that is not ok is no better than that fit: see 'fit' for the reason")


@app.command()
def report(friction: Path = FrictionArg,
           output: Path = typer.Option(Path("report.html"), "-o", "--output", help="HTML file to write."),
           params: Optional[Path] = typer.Option(None, help="Parameters written by 'wbfriction fit' (default: "
                                                            "fitted here)."),
           identification: Optional[Path] = typer.Option(None, help="JSON written by 'wbfriction identify --json': "
                                                                    "adds the held-out torque RMS, both routes' "
                                                                    "friction and the body changes."),
           energy_threshold: float = EnergyThresholdOpt, energy_tolerance: float = EnergyToleranceOpt,
           workers: int = typer.Option(2, min=1, help="Processes fitting the joints (without --params) and "
                                                     "rendering their figures (the same report for any "
                                                     "number).")) -> None:
    """One self-contained HTML report: friction clouds and fits, parameters, energy consistency,
    per-joint time series, Fig. 7.4, spectra, provenance."""
    from wbfriction.report.build import make_report
    from wbfriction.report.html import write_report

    check_paths({"FRICTION": friction, "--params": params, "--identification": identification}, {"-o": output})

    with console.status("building the report"):
        rep = make_report(friction, params, energy_threshold, energy_tolerance, identification, workers)
        write_report(rep, output, workers)
    _warn_energy(rep.energy.values())
    console.print(f"wrote {output} ({len(rep.est.joints)} joints, {len(rep.flagged)} flagged)")


@app.command()
def sensitivity(log: Path = LogArg,
                output: Path = typer.Option(Path("sensitivity.png"), "-o", "--output", help="Figure to write (PNG)."),
                robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
                mjcf: Optional[Path] = MjcfOpt,
                factors: str = typer.Option("0.9,0.95,1.05,1.1", help="Comma-separated inertia scaling factors."),
                part: InertiaPart = typer.Option("all", help="all (the whole 6x6 inertia), mass or rotational (its "
                                                             "mass or principal-moment eigenvalues only)."),
                joints: Optional[str] = typer.Option(None, help="Comma-separated joints to plot (default: the "
                                                                "legs' joints)."),
                diff: DiffOption = typer.Option("auto", help="Differentiation scheme (see 'estimate')."),
                mask: Mask = typer.Option(_E.mask, help="swing or single (see 'estimate')."),
                route: RouteOption = RouteOpt,
                time_unit: Optional[TimeUnit] = TimeUnitOpt) -> None:
    """Re-run the estimate with every body's inertia scaled (thesis 7.2, Fig. 7.5/7.6): how the
    friction curves shift (mass) and split into branches (rotational inertia)."""
    from wbfriction.inertia.sensitivity import inertia_sensitivity, parse_factors
    from wbfriction.logs.source import read_log
    from wbfriction.report.figures import save_png, sensitivity_figure

    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output})
    values = parse_factors(factors)
    r = _robot(robot, urdf, config, mjcf)
    data = read_log(log, r, time_unit=time_unit)
    _warn(data.warnings)
    opts = EstimateOptions(diff=diff, mask=mask,
                           route=route)
    with console.status("") as status:
        sens = inertia_sensitivity(r, data, values, part, opts, progress=status.update)
    names = _joint_list(r, joints)
    with console.status("fitting the offsets of the model as given"):
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


@app.command()
def identify(log: Path = LogArg,
             output: Path = typer.Option(..., "-o", "--output", help="Corrected URDF to write (the given one's "
                                                                    "structure, identified inertias)."),
             robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
             mjcf: Optional[Path] = MjcfOpt,
             json_output: Optional[Path] = typer.Option(None, "--json", help="Also write every figure as "
                                                                             "JSON (for 'wbfriction report "
                                                                             "--identification')."),
             stribeck_velocity: str = typer.Option("auto", help="v_s of the Stribeck term [rad/s]: auto (from the "
                                                                "acceleration route, refined each pass), a number, "
                                                                "or none."),
             passes: int = typer.Option(2, min=1, help="Identifications with --stribeck-velocity auto."),
             holdout: float = typer.Option(_N.holdout, help="Share of the log, at its end, kept out to compare "
                                                            "torque predictions (between 0 and 1)."),
             stride: int = typer.Option(_N.stride, min=1, help="Every stride-th single-support sample is used."),
             prior: Optional[float] = typer.Option(_N.prior, min=0.0, help="Weight of the prior toward the given "
                                                                          "model, in units of the residual variance; "
                                                                          "default: chosen by validation from 1e4 "
                                                                          "down to 1."),
             armature: ArmatureMode = typer.Option(_N.armature, help="Rotor inertia: known (the TOML's [armature]), "
                                                            "identify (one per joint, with the friction; for "
                                                            "motor-current torques) or none (link-side "
                                                            "torque sensors)."),
             tanh_slope: float = typer.Option(_N.tanh_slope, min=1e-12,
                                              help="a of the Coulomb term tanh(a qd) [s/rad]."),
             diff: DiffOption = typer.Option("auto", help="Differentiation scheme (see 'estimate')."),
             mask: Mask = typer.Option(_E.mask, help="swing or single (see 'estimate')."),
             route: RouteOption = RouteOpt,
             workers: int = FitWorkersOpt, time_unit: Optional[TimeUnit] = TimeUnitOpt,
             wide: bool = WideOpt) -> None:
    """Identify the inertia model and the friction together from the joint torques of single
    support (thesis 2.4, ch. 8), write the corrected URDF, and estimate the friction again
    with it: then 'wbfriction estimate LOG --urdf IDENTIFIED.urdf'."""
    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config}, {"-o": output, "--json": json_output})
    vs_text = stribeck_velocity.strip().lower()
    try:
        stribeck: float | Literal["auto"] | None = (None if vs_text == "none" else "auto" if vs_text == "auto"
                                                    else float(vs_text))
    except ValueError:
        raise InputError(f"--stribeck-velocity must be auto, none or a number, got '{stribeck_velocity}'") from None
    if not 0.0 < holdout < 1.0:
        raise InputError(f"--holdout must be between 0 and 1, got {holdout}")
    from wbfriction.pipeline.identify import identify_file
    from wbfriction.report.terminal import identification_tables

    r = _robot(robot, urdf, config, mjcf)
    r.require_urdf("identify (it writes the corrected URDF)")
    opts = InertialOptions(tanh_slope=tanh_slope, stride=stride, holdout=holdout, prior=prior,
                           armature=armature)
    with console.status("") as status:
        estimate_options = EstimateOptions(diff=diff, mask=mask,
                                           route=route)
        done = identify_file(r, log, output, json_output, estimate_options=estimate_options,
                             options=opts, stribeck=stribeck, passes=passes, progress=status.update, workers=workers,
                             time_unit=time_unit)
    doc, moved = done.document, done.moved
    for p in doc["passes"]:
        vs = "none" if p["stribeck_velocity"] is None else f"{p['stribeck_velocity']:.4g} rad/s"
        out.print(escape(f"v_s {vs}: {p['samples']} samples, {p['base_parameters']} base parameters of "
                         f"{p['parameters']}, condition {p['condition']:.3g}, prior {p['prior']:g}; {p['message']}"),
                  highlight=False)
        if p.get("verdict"):
            out.print(escape(p["verdict"]), highlight=False)
        unexcited = p.get("not_excited") or []
        if unexcited:
            names = [str(u.get("parameter", u)) if isinstance(u, dict) else str(u) for u in unexcited]
            out.print(escape(f"not excited by this log, kept at the given model: {len(names)} parameters ("
                             + ", ".join(names[:4]) + (", ..." if len(names) > 4 else "") + ")"), highlight=False)
    tables, notes = identification_tables(doc, wide)
    for table in tables:
        _print_whole(table) if wide else out.print(table)
    for note in notes:
        out.print(escape(note), highlight=False)
    toml = done.armature_toml()
    if toml is not None:
        out.print(escape("identified armature [kg·m^2], for the robot's TOML:\n" + toml), highlight=False)
    if moved:
        console.print(f"[yellow]note:[/] the whole identified body went to the child link of {', '.join(moved)} "
                      "(lighter than the links merged with it)")
    if json_output is not None:
        console.print(f"wrote {json_output}")
    _warn_energy(done.loop.final.route.energy)
    console.print(f"wrote {output}")


def _study_table(rows, title: str, params: tuple[str, ...] | None = None) -> Table:
    """Tables 6.1/6.2 layout: per leg joint (thesis numbering) the fit's status, target, estimate, error,
    thesis errors; ``params``: the parameters shown (default: every one of model 3.5)."""
    from wbfriction.friction.models import PARAM_NAMES

    params = PARAM_NAMES if params is None else params
    table = Table(title=title, box=None,
                  caption="err: error to the target [%]; T6.1 / T6.2: the thesis's errors for the same joint "
                          "(TORO, straight / straight and sideways)")
    table.add_column("#", justify="right")
    table.add_column("joint")
    table.add_column("status")
    for name in params:
        table.add_column(name, justify="right")
    cols = [PARAM_NAMES.index(n) for n in params]
    for row in rows:
        fit = row.fit
        err = fit.error_percent() or {}
        status = fit.verdict().status
        table.add_row(str(row.number), f"{row.joint} ({row.group})", status,
                      *[f"{getattr(fit.params, n):.4f}" if fit.params else "—" for n in params],
                      style=None if status == "ok" else "dim")
        table.add_row("", "  target", "", *[f"{getattr(fit.target, n):.4g}" for n in params], style="dim")
        table.add_row("", "  err [%]", "", *[f"{err.get(n, float('nan')):.2f}" for n in params], style="bold")
        for label, ref in (("  T6.1 [%]", row.thesis_6_1), ("  T6.2 [%]", row.thesis_6_2)):
            if ref is not None:
                table.add_row("", label, "", *[f"{ref[c]:.2f}" for c in cols], style="dim")
    return table


def _print_not_ok(rows) -> None:
    """Say which rows of a study table are not ``ok`` fits and why: their errors measure the walk's excitation
    (or the fit's trouble), not the estimate."""
    from wbfriction.studies.common import not_ok

    for row in not_ok(rows):
        verdict = row.fit.verdict()
        why = ("this walk hardly moved it (a short walk hardly turns the hip yaws: try more --steps)"
               if verdict.status == "not excited" else "its parameters are not determined by these samples")
        out.print(escape(f"not an ok fit: {row.joint} ({row.group}), {verdict}; its errors below measure the "
                         f"walk, not the estimate: {why}."), highlight=False)


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
    from wbfriction.studies.realistic import run_realistic_study, worst_scored

    with console.status("") as status:
        result = run_realistic_study(r, output_dir, steps=steps, progress=lambda label: status.update(label))
    for case in result.cases:
        _print_not_ok(case.rows)
        out.print(_study_table(case.rows, f"MuJoCo, combined walk, swing phase: {case.label}", case.scored))
        worst = worst_scored(case)
        out.print("worst error over the leg joints [%]: " + ", ".join(f"{n} {v:.2f}" for n, v in worst.items()))
    out.print("right knee alone, RMS error [N·m] (central differences): " + "; ".join(
        f"{k} {v:.4f}" for k, v in result.knee_rms.items()))
    return result.files


@app.command()
def demo(output_dir: Path = typer.Option(Path("wbfriction-demo"), "-o", "--output-dir", help="Where to write."),
         robot: str = RobotOpt,
         steps: int = typer.Option(_G.steps, help="Steps per direction of the combined walk."),
         simulator: Simulator = typer.Option("ideal", help="ideal: Tables 6.1/6.2, Fig. 6.1-6.3; mujoco: the realistic "
                                                     "simulator's study, Fig. 6.4-6.5.")) -> None:
    """The thesis's simulation study: walk, estimate, fit; Tables 6.1/6.2 and Fig. 6.1-6.5."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.studies.common import worst_errors
    from wbfriction.studies.simulation import run_study

    start = time.perf_counter()
    r = _robot(robot, None, None)
    if simulator == "mujoco":
        for f in _demo_mujoco(output_dir, r, steps):
            console.print(f"wrote {f}")
        console.print(f"demo finished in {time.perf_counter() - start:.1f} s")
        return
    with console.status("") as status:
        result = run_study(r, output_dir, steps=steps, progress=lambda label: status.update(label))
    _print_not_ok(result.rows)  # before the table: its error figures of those joints measure the walk
    out.print(_study_table(result.rows, "Identified friction (3.5) of the leg joints, combined walk, "
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


@app.command()
def spectrum(log: Path = LogArg,
             output: Path = typer.Option(Path("spectrum.png"), "-o", "--output", help="Figure to write (PNG)."),
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
    r = _robot(robot, urdf, config, mjcf)
    data = read_log(log, r, time_unit=time_unit)
    _warn(data.warnings)
    names = _joint_list(r, joints)
    with _progress(len(data), "dynamics") as advance:
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


def _percent(x: float) -> str:
    import numpy as np

    return f"{x:.1f}" if x < 1e4 else ("inf" if not np.isfinite(x) else ">1e4")


@app.command("study-sensors")
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
    """What the ankle force-torque sensors and the base pose change, on MuJoCo's soft contacts (issue 23)."""
    from wbfriction.studies.realistic import NOISE
    from wbfriction.studies.sensors import SUBSTEPS, run_sensors_study, sensors_markdown

    r = _robot(robot, None, None)
    if not r.ft_sensors:
        raise InputError(f"--robot {robot}: the robot has no force-torque sensors ([force_torque.<name>] in its TOML)")
    with console.status("") as status:
        result = run_sensors_study(r, output_dir, steps=steps, diff=diff,
                                   filtering=FilterOptions(window=window), noise=NOISE if noise else SensorNoise(),
                                   substeps=substeps or SUBSTEPS, progress=lambda label: status.update(label),
                                   route=route)
    out.print(escape(sensors_markdown(result)), highlight=False, soft_wrap=True)
    for f in result.files:
        console.print(f"wrote {f}")


@app.command("study-noise")
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
    """Every model family on noisy logs, estimated and fitted with the default options (issue 38): errors
    against the injected friction, the model chosen, and each parameter's RMS error over the seeds against its
    Cramér-Rao bound."""
    from wbfriction.studies.noise import FAMILIES, Family, noise_markdown, run_noise_study

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
    loaded = [_robot(name.strip(), None, None) for name in robots.split(",") if name.strip()]
    with console.status("") as status:
        rows = run_noise_study(loaded, output_dir, families=cast("list[Family]", chosen), noises=levels, seeds=seeds,
                               duration=duration, steps=steps, workers=workers,
                               progress=lambda label: status.update(label))
    out.print(escape(noise_markdown(rows)), highlight=False, soft_wrap=True)
    console.print(f"wrote {output_dir / 'noise.md'}, {output_dir / 'noise.json'}")


@app.command("study-fleet")
def study_fleet(output_dir: Path = typer.Option(Path("wbfriction-fleet"), "-o", "--output-dir", help="Where to write."),
                robots: int = typer.Option(4, min=1, help="Robots of the fleet."),
                logs: int = typer.Option(25, min=12, help="Logs per robot (one a day)."),
                workers: int = typer.Option(2, min=1, help="Worker processes of the local Dask cluster.")) -> None:
    """A simulated TALOS fleet whose friction drifts on two joints (issue 25): batch, trends, and the joints
    flagged against the truth."""
    import dataclasses

    from wbfriction.studies.fleet import FleetPlan, run_fleet_study

    plan = dataclasses.replace(FleetPlan(), robots=robots, logs=logs)
    if robots < 3:
        plan = dataclasses.replace(plan, drifts=tuple(d for d in plan.drifts if d.robot_id in plan.robot_ids))
    with console.status("") as status:
        study = run_fleet_study(_robot("talos", None, None), output_dir, plan, workers,
                                progress=lambda label: status.update(label))
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


@app.command("study-filters")
def study_filters(output_dir: Path = typer.Option(Path("wbfriction-filters"), "-o", "--output-dir",
                                                  help="Where to write."),
                  robot: str = RobotOpt,
                  steps: int = typer.Option(_G.steps, help="Steps per direction of the combined walk."),
                  seed: int = typer.Option(0, help="Noise seed."),
                  workers: Optional[int] = typer.Option(None, help="Processes (default: up to 2).")) -> None:
    """Score the differentiation schemes on noisy logs (thesis 7.2, Fig. 7.2)."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.studies.filters import LEVELS, run_filter_study

    start = time.perf_counter()
    r = _robot(robot, None, None)
    with console.status("") as status:
        result = run_filter_study(r, output_dir, steps=steps, seed=seed, workers=workers,
                                  progress=lambda label: status.update(label))
    table = Table(title="Friction of the 12 leg joints through each scheme: combined walk, sensor noise",
                  caption="rms: estimate - tau_f_true on the valid samples [N·m]; parameters: worst error over "
                          "the leg joints [%]; se F_v: the largest standard error of F_v the fit reports [% of "
                          "its value]; *: best scheme of its noise level (lowest worst F_v, F_c, tau_os); "
                          "inf: a joint left with too few samples",
                  box=None)
    for col in ("position noise", "scheme", "N", "rms", *PARAM_NAMES, "se F_v"):
        table.add_column(col, justify="left" if col in ("position noise", "scheme") else "right")
    for level in LEVELS:
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


@app.command()
def batch(source: Path = typer.Argument(..., metavar="MANIFEST",
                                        help="Manifest (CSV or Parquet; columns log, robot_id, start_time [ISO 8601 "
                                             "with zone], robot or urdf/config, optional diff and model), or a "
                                             "folder of <robot_id>/<log> files (with --robot or --urdf/--config)."),
          output: Path = typer.Option(..., "-o", "--output", help="Results folder: a Parquet dataset, a folder per "
                                                                  "robot; logs whose results are there are "
                                                                  "skipped, results of a log listed with anything "
                                                                  "changed are replaced. Failures go beside it "
                                                                  "(RESULTS-failed)."),
          robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
          workers: Optional[int] = typer.Option(None, min=1, help="Worker processes of the local Dask cluster "
                                                                  "[default: 2]."),
          scheduler: Optional[str] = typer.Option(None, help="Address of a running Dask scheduler "
                                                             "(tcp://host:8786) instead of a local cluster; its "
                                                             "workers must see the logs and the results."),
          serial: bool = typer.Option(False, "--serial", help="One log after the other in this process, without "
                                                              "Dask (the reference the cluster's results equal)."),
          tables: Optional[Path] = typer.Option(None, "--tables",
                                                help="Also keep each log's friction table in this folder "
                                                     "(TABLES/<robot_id>/<key>.parquet)."),
          diff: DiffOption = typer.Option(_E.diff, help="Differentiation, as 'wbfriction estimate --diff' (a "
                                                        "manifest's diff column overrides it per log)."),
          model: ModelChoice = typer.Option(_FIT.model, help="Friction model, as 'wbfriction fit --model' (a "
                                                             "manifest's model column overrides it per log)."),
          min_samples: int = MinSamplesOpt) -> None:
    """Estimate, fit and check every log of a fleet on Dask, into one results dataset (exit status 1 when a log
    failed: it is listed, the others are done)."""
    from wbfriction.fleet.batch import check_outputs, quiet_dask_logs, run_batch
    from wbfriction.fleet.manifest import read_manifest, scan_folder
    from wbfriction.fleet.options import BatchOptions
    from wbfriction.fleet.results import failures_folder
    from wbfriction.pipeline.estimate import RobotSpec

    check_paths({"MANIFEST": source}, {})
    check_outputs(output, tables)
    quiet_dask_logs()  # its faults are said here, one line each
    start = time.perf_counter()
    if source.is_dir():
        scan = scan_folder(source, RobotSpec(None if config else robot, None if urdf is None else str(urdf),
                                             None if config is None else str(config)),
                           exclude=[p for p in (output, failures_folder(output), tables) if p is not None])
        for skipped in scan.skipped:
            console.print(f"[yellow]skipped:[/] {escape(str(skipped))}", highlight=False, soft_wrap=True)
        entries = scan.entries
    else:
        entries = read_manifest(source)
    options = BatchOptions(estimate=EstimateOptions(diff=diff), fit=FitOptions(model=model, min_samples=min_samples))
    with Progress(TextColumn("batch"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(), console=console,
                  transient=True, disable=not console.is_terminal) as bar:
        task = bar.add_task("batch", total=len(entries))
        summary = run_batch(entries, output, options, engine="serial" if serial else "dask", workers=workers,
                            scheduler=scheduler, tables=tables, progress=lambda outcome: bar.advance(task, 1))
    for a, b in summary.copies:
        console.print(f"[yellow]note:[/] {escape(b.where)} has the same bytes as {escape(a.where)}: two results",
                      highlight=False, soft_wrap=True)
    for note in (*summary.stale, *summary.foreign):
        console.print(f"[yellow]note:[/] {escape(str(note))}", highlight=False, soft_wrap=True)
    for _, error in summary.failed:
        console.print(f"[bold red]failed:[/] {escape(error)}", highlight=False, soft_wrap=True)
    why = "".join(f"; {n} {reason}" for reason, n in sorted(summary.reasons.items()) if reason != "new")
    kept = f", {summary.kept} of logs not listed kept" if summary.kept else ""
    console.print(f"{summary.processed} logs processed ({len(summary.failed)} failed{why}), {summary.skipped} already "
                  f"done{kept}; results in {output} ({time.perf_counter() - start:.1f} s)", highlight=False,
                  soft_wrap=True)
    if summary.failed:
        console.print(f"failures recorded in {failures_folder(output)}", highlight=False, soft_wrap=True)
        raise typer.Exit(1)


@app.command()
def trends(results: Path = typer.Argument(..., metavar="RESULTS", help="Results folder written by 'wbfriction "
                                                                       "batch'."),
           output: Path = typer.Option(..., "-o", "--output", help="HTML page to write (.html)."),
           table: Optional[Path] = typer.Option(None, "--table", help="Also write the trends as a table "
                                                                      "(.parquet or .csv)."),
           alpha: float = typer.Option(1e-3, min=1e-6, max=0.5, help="False-alarm probability per joint."),
           replicates: Optional[int] = typer.Option(None, min=1, help="Noise series of the p-values' Monte Carlo "
                                                                      "[default: 20000, more for a small --alpha]."),
           min_change: float = typer.Option(0.10, min=0.0, help="Smallest change flagged, relative to the "
                                                                "baseline (0.1: 10 %)."),
           title: str = typer.Option("Friction trends", help="The page's title.")) -> None:
    """Friction over time per robot and joint, and the joints whose friction drifted (a hinge change detector
    weighted by the fits' standard errors), as one HTML page."""
    import math

    from wbfriction.fleet.results import read_results
    from wbfriction.fleet.trends import UNITS, TrendOptions, fleet_trends
    from wbfriction.logs.tables import write_table
    from wbfriction.report.trends import write_trends_html

    if output.suffix.lower() not in (".html", ".htm"):
        raise InputError(f"-o {output}: the trends page is written as .html")
    if table is not None and table.suffix.lower() not in (".parquet", ".pq", ".csv"):
        raise InputError(f"--table {table}: written as .parquet or .csv")
    check_paths({"RESULTS": results}, {"-o": output, **({"--table": table} if table is not None else {})})
    options = TrendOptions(alpha=alpha, min_change=min_change, replicates=replicates)
    dataset = read_results(results)
    for left in dataset.left_out:
        console.print(f"[yellow]left out:[/] {escape(str(left))}", highlight=False, soft_wrap=True)
    found = fleet_trends(dataset.table, options)
    write_trends_html(found, output, title)
    if table is not None:
        write_table(found.to_table(), table)
    for j in found.flagged:
        cp = j.drifts[0]
        size = (f"{100 * cp.relative:+.1f} %" if not math.isnan(cp.relative)
                else f"{cp.change:+.3g} {UNITS[cp.quantity]} from a baseline not told from zero")
        console.print(f"drift: {j.robot_id} {j.joint}: {cp.quantity} {size} from {cp.onset_time:%Y-%m-%d} "
                      f"(p {cp.p_value:.2g})", highlight=False)
    console.print(f"{found.summary()}; wrote {output}" + (f" and {table}" if table is not None else ""),
                  highlight=False)


@app.command()
def dataset(name: Literal["kuka-lwr4"] = typer.Argument(..., metavar="NAME",
                                                       help="The dataset: kuka-lwr4 (FloBaRoID's KUKA LWR4+: three "
                                                            "runs of 25 s, link-side joint torque sensors, about "
                                                            "6 MB)."),
            output_dir: Path = typer.Option(..., "-o", "--output-dir",
                                            help="Folder to write into (made if missing): runs12.parquet (runs 1 "
                                                 "and 2), run3.parquet (run 3, held out), the robot's URDF and "
                                                 "its configuration kuka_lwr4.toml.")) -> None:
    """Fetch a real robot's logs and write them as wbfriction logs with the robot beside them: downloaded once
    into the user's cache, each file checked against its SHA-256, or taken from $WBFRICTION_DATA/<dataset>/ (a
    local copy, for offline machines, checked the same way). Prints the commands to run next."""
    import shlex

    from wbfriction.datasets import write_kuka_lwr4_logs

    with console.status("fetching the KUKA LWR4+ dataset"):
        logs = write_kuka_lwr4_logs(output_dir)
    console.print(f"wrote {logs.runs12} ({logs.rows[0]} samples: runs 1 and 2), {logs.run3} ({logs.rows[1]} "
                  f"samples: run 3) and the robot, {logs.config}", highlight=False, markup=False)
    robot = f"--config {shlex.quote(str(logs.config))}"
    runs12, run3 = shlex.quote(str(logs.runs12)), shlex.quote(str(logs.run3))
    for line in ("next:", f"  wbfriction estimate {runs12} {robot} -o runs12_friction.parquet",
                 "  wbfriction fit runs12_friction.parquet -o runs12_params.json",
                 f"  wbfriction estimate {run3} {robot} -o run3_friction.parquet",
                 "  wbfriction predict run3_friction.parquet --params runs12_params.json",
                 f"  wbfriction identify {runs12} {robot} -o kuka_identified.urdf"):
        out.print(line, highlight=False, markup=False, soft_wrap=True)


def _version(value: bool) -> None:
    if value:
        out.print(f"wbfriction {__version__}", highlight=False)
        raise typer.Exit()


@app.callback(invoke_without_command=True)
def overview(ctx: typer.Context,
             version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")) -> None:
    """Whole-body joint friction estimation for torque-controlled legged robots: estimate the friction torque of
    every joint from a log, fit a friction model, check it, export it. Run 'wbfriction demo' to see it on a
    simulated walk, 'wbfriction COMMAND --help' for a command."""
    if ctx.invoked_subcommand is None:  # 'wbfriction' alone: the overview, successfully
        out.print(ctx.get_help(), highlight=False, markup=False)
        raise typer.Exit()


def main() -> None:
    """Entry point: run the app, turning wbfriction errors into one line and their exit status (2 for
    the input, 1 for the environment: an output the system refused to write, a cluster gone;
    :attr:`~wbfriction.exceptions.WbfrictionError.exit_status`). Interruptions (Ctrl-C, SIGTERM)
    are :mod:`wbfriction.entry`'s, which calls this."""
    try:
        status = app(standalone_mode=False)
    except WbfrictionError as exc:
        console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
        sys.exit(exc.exit_status)
    except typer.Exit as exc:  # pragma: no cover - typer control flow
        sys.exit(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):  # pragma: no cover
        sys.exit(130)
    except Exception as exc:  # usage errors: click's (typer vendors its own copy in newer releases)
        message, code = getattr(exc, "format_message", None), getattr(exc, "exit_code", None)
        if callable(message) and isinstance(code, int):  # one line, as every other error
            console.print(f"[bold red]error:[/] {escape(str(message()))}", highlight=False, soft_wrap=True)
            sys.exit(code)
        raise
    if isinstance(status, int) and status:
        sys.exit(status)

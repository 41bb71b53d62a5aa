"""``wbfriction simulate``: a robot with known friction, as a log (a walk, ideal or on MuJoCo; a quadruped's gait; an
arm's excitation; a hung PD-driven robot's set-points). What runs is the robot's rig (:func:`~wbfriction.rigs.
rig_for`) in the engine ``--simulator`` names where the rig runs in one (:mod:`wbfriction.sim.engines`): this module
parses, asks the rig, hands it its typed options (refusing those it does not read), shows the progress, writes and
prints."""

from __future__ import annotations

from pathlib import Path
from typing import Literal, Optional

import typer

from wbfriction.cli.common import (
    GAIT,
    IDEAL,
    MUJOCO,
    ConfigOpt,
    MjcfOpt,
    RobotOpt,
    UrdfOpt,
    app,
    console,
    robot_of,
    stages,
)
from wbfriction.cli.helpformat import LOGS
from wbfriction.cli.outputs import suffixes, written_as
from wbfriction.cli.rigs import RigOptionOpt, check_engine, rig_options

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.pipeline.paths import check_paths
from wbfriction.rigs import RigProgress, rig_for
from wbfriction.sim.engines.registry import ENGINES
from wbfriction.sim.options import FrictionMode, Integrator
from wbfriction.sim.pd_options import HungOptions, SetpointKind, SetpointOptions

HUNG = HungOptions()
SETPOINTS = SetpointOptions()
GaitChoice = Literal["forward", "sideways", "turning", "both", "combined", "stand", "step", "trot", "walk"]
"""``--gait``: a walk's (:data:`~wbfriction.walking.options.Gait`) or, for a robot on point feet, a quadruped's
(:data:`~wbfriction.walking.quadruped.Gait`)."""
FootForces = Literal["none", "normal", "3d"]
"""``--foot-forces``: the feet's force columns a walking quadruped's log carries."""
Actuator = Literal["torque", "pd"]
"""How a robot's joints are driven (``--actuator``): motors whose torque is logged, or PD motor drivers."""
SensorNoiseChoice = Literal["none", "unitree"]
"""A robot on point feet's every sensor's noise (``--sensor-noise``): the options' alone, or a Unitree-like robot's."""
LoggerChoice = Literal["full", "raw"]
"""What log a robot on point feet writes (``--logger``): the project's full log, or a robot logger's raw one."""
AnglesChoice = Literal["angles", "cos-sin"]
ContactsChoice = Literal["soft", "firm"]
"""How a raw log holds the joint angles (``--angles``)."""
DriverNoiseChoice = Literal["real", "none"]
"""The PD drivers' sensor noise (``--driver-noise``): a real driver's (:data:`~wbfriction.sim.pd_options.REAL_DRIVER`)
or none."""


OutputOpt = typer.Option(..., "-o", "--output", help=f"Log to write: {suffixes('table')}.",
                         callback=written_as("table"))
FrictionOpt = typer.Option(None, help="TOML with [friction.<group or joint>] tables (a model key: coulomb-viscous, "
                                      "stribeck or (3.5)), each with an optional terms table (F_L, dF_v, ripple, "
                                      "F_cT, F_vT, reference_temperature), and a [temperature] warm-up (start, end "
                                      "[°C]) logged as temperature.<joint>; default: thesis Table 6.1 on the legs, "
                                      "Coulomb-viscous on every joint of a PD-driven robot.")
GaitOpt = typer.Option(None, help="A walk: forward (default), sideways, turning, both (forward + sideways) or "
                                  "combined (all three); a robot on point feet: stand, step (a trot in place), trot "
                                  "(default) or walk (a crawl).")
StepsOpt = typer.Option(GAIT.steps, help="A walk: number of steps (per direction for both/combined).")
StepLengthOpt = typer.Option(GAIT.step_length, help="A walk: forward distance between footprints [m].")
StepWidthOpt = typer.Option(GAIT.step_width, help="A walk: sideways step [m].")
TurnAngleOpt = typer.Option(GAIT.turn_angle, help="A walk: heading change per turning step [rad].")
LiftHeightOpt = typer.Option(GAIT.lift_height, help="A walk: swing-foot apex [m].")
# the engines registered as the command line loads (no entry point read: an installed package's engine is named)
SimulatorOpt = typer.Option(None, metavar=f"[{'|'.join(ENGINES.loaded())}]",
                            help="A walk or a robot on point feet: the engine it runs in, "
                                 + "; ".join(e.what for e in ENGINES.registered()) + " (default: the first); or one "
                                 "a program registered (wbfriction.sim.engines.register_engine) or an installed "
                                 "package advertises (entry-point group wbfriction.engines).")
SubstepsOpt = typer.Option(None, help=f"Physics steps per control period (default: {IDEAL.substeps} ideal, "
                                      f"{MUJOCO.substeps} mujoco (1 ms periods), {HUNG.substeps} PD-driven (at "
                                      f"{HUNG.rate:g} Hz: 1 ms steps), 4 for a robot on point feet (2 ms periods: "
                                      "0.5 ms steps), 8 playing its three-feet stance (0.25 ms: the Go2's swing "
                                      "calf's F_v within 2 %; at 0.5 ms 4.5 % off)).")
IntegratorOpt = typer.Option(IDEAL.integrator, help="A walk, ideal: semi-implicit or explicit Euler.")
MujocoFrictionOpt = typer.Option(MUJOCO.friction, help="mujoco and PD-driven: model (any friction model as a joint "
                                                       "torque) or mujoco (MuJoCo's frictionloss = F_c, damping = "
                                                       "F_v).")
SensorsOpt = typer.Option(None, help="mujoco and a robot on point feet: TOML with a [sensors] table (position_std, "
                                     "encoder_bits, torque_std, seed; mujoco: delay); the options below override it.")
PositionNoiseOpt = typer.Option(None, help="mujoco, a robot on point feet, arms and PD-driven: joint-position noise "
                                           "std [rad].")
EncoderBitsOpt = typer.Option(None, help="mujoco, a robot on point feet, arms and PD-driven: encoder resolution [bits "
                                         "per turn].")
TorqueNoiseOpt = typer.Option(None, help="mujoco, a robot on point feet and arms: torque-sensor noise std [N·m].")
NoiseSeedOpt = typer.Option(None, help="mujoco, a robot on point feet, arms and PD-driven: seed of the sensor noise.")
DelayOpt = typer.Option(None, help="mujoco: measurement-to-command delay [ms], whole control periods; PD-driven: "
                                   "the drivers' set-point delay [ms], any (default the robot's [pd] delay).")
LogBaseOpt = typer.Option(IDEAL.log_base, help="A walk: write the base pose to the log.")
ForceTorqueOpt = typer.Option(IDEAL.force_torque, help="A walk, ideal: write what the robot's force-torque sensors "
                                                       "and IMU measure (wrench.<sensor>.*, imu.* columns; mujoco "
                                                       "always does).")
SoleOpt = typer.Option(None, help="mujoco: the soles' contact time constant (s; default MuJoCo's 0.02, larger is "
                                  "softer: a compliant sole).")
FrictionTimeOpt = typer.Option(None, help="mujoco and PD-driven: the friction-loss constraint's time constant (s; "
                                          "default two physics steps: a joint that sticks; MuJoCo's 0.02 leads the "
                                          "velocity by 10 ms).")
TorqueDriftOpt = typer.Option(MUJOCO.torque_drift, min=0.0, help="mujoco: drift rate of each torque sensor's offset "
                                                                 "(N·m/s).")
FtOffsetOpt = typer.Option(MUJOCO.ft_offset, help="mujoco: standard deviations of the force-torque sensors' constant "
                                                  "offsets: force (N), torque (N·m).")
DurationOpt = typer.Option(None, help="Fixed-base robot: seconds of excitation trajectory (an arm, default 10) or of "
                                      f"set-points (PD-driven, default {HUNG.duration:g}); a robot on point feet: "
                                      "seconds of gait (default 8).")
SeedOpt = typer.Option(0, help="Fixed-base robot: seed of the excitation trajectory's Fourier coefficients or of the "
                               "set-points (another seed, another motion); a robot on point feet: of the gait's swings "
                               "and sway.")
ActuatorOpt = typer.Option(None, "--actuator", "--drive",
                           help="torque (motors whose torque is logged) or pd (motor drivers closing a PD loop: "
                                "a fixed-base robot hung, its drivers tracking ramps and chirps, "
                                "wbfriction.sim.hung; a walking quadruped's drivers sent its set-points); default pd "
                                "for a fixed-base robot with a [pd] table, torque otherwise.")
SpeedOpt = typer.Option(None, help="A robot on point feet: forward speed [m/s] (default 0.2 trot, 0.1 walk).")
FootForcesOpt = typer.Option("none", help="A robot on point feet: the feet's force columns logged: none, normal "
                                          "(force.<foot>, as Unitree's foot sensors) or 3d (force.<foot>.x|y|z).")
SensorNoiseOpt = typer.Option("none", help="A robot on point feet, mujoco: none (the options above alone) or unitree "
                                           "(a Unitree-like robot's every sensor: 15-bit encoders, drives' velocity "
                                           "0.02 rad/s, torque 0.05 N·m, gyro 0.005 rad/s, accelerometer 0.05 m/s², "
                                           "foot forces 2 N; a raw log's IMU orientation 0.001 rad), seeded by "
                                           "--noise-seed.")
LoggerOpt = typer.Option("full", help="A robot on point feet: full (every column the simulator knows) or raw (the "
                                      "log a robot's logger writes: no time, contacts, foot forces or base pose; "
                                      "motor currents, the IMU's roll, pitch, yaw and rate; rows repeating the "
                                      "drives' sample; the truth beside it: wbfriction.sim.logger).")
LoggerPeriodOpt = typer.Option(None, help="--logger raw: the logger's period [ms] (default 1.22; the drives update "
                                          "every 2 ms).")
ImuPeriodOpt = typer.Option(None, help="--logger raw: the IMU's update period [ms] (default 5).")
AnglesOpt = typer.Option(None, help="--logger raw: the joint angles as angles (q.<joint>, default) or cos-sin "
                                    "(q_cos.<joint>, q_sin.<joint>).")
KtErrorOpt = typer.Option(None, help="--logger raw: the bound of each joint's torque-constant error, a share (default "
                                     "0.03: the true constant within ±3 % of the TOML's [torque_constants]).")
FootCountsOpt = typer.Option(None, "--foot-counts/--no-foot-counts",
                             help="--logger raw: log raw foot-force counts (foot_count.<foot>: an offset and a scale "
                                  "per foot).")
ContactsOpt = typer.Option("soft", help="A robot on point feet, mujoco: its feet on the ground: soft (MuJoCo's "
                                        "default contacts: a stance foot creeps about 1.5 cm/s) or firm (elliptic "
                                        "friction cones, impratio 10, a 5 ms time constant: feet that hold, as "
                                        "rubber on concrete).")
SetpointsOpt = typer.Option(SETPOINTS.kind, help="PD-driven: ramps (triangle ramps reversing every "
                                                 f"{SETPOINTS.reversal[0]:g}-{SETPOINTS.reversal[1]:g} s), chirps "
                                                 f"({SETPOINTS.chirp[0]:g}-{SETPOINTS.chirp[1]:g} Hz) or both "
                                                 "(ramps, then chirps).")
DriverNoiseOpt = typer.Option("real", help="PD-driven: real (a real driver's noise, measured on a Unitree Aliengo: "
                                           "encoder steps 1.2e-5 rad hip and thigh, 3.8e-5 calf; white noise of "
                                           "0.08 rad/s on the driver's velocity) or none (exact readings); "
                                           "--encoder-bits, --position-noise and --velocity-noise override it.")
VelocityNoiseOpt = typer.Option(None, help="PD-driven: white noise std of the driver's velocity [rad/s].")
PlayOpt = typer.Option(None, "--play", help="PD-driven, arms, a biped and a robot on point feet (ideal, mujoco): "
                                            "the set-points to play (a table 'wbfriction excite' writes: time, "
                                            "q_des.<joint>, qd_des.<joint>; an arm's also its Fourier series, a "
                                            "biped's its stance foot and swing leg's series, a quadruped's its swing "
                                            "foot, base height and swing leg's series, from which its stance is "
                                            "rebuilt) instead of ramps and chirps, a random excitation, a walk or a "
                                            "gait; its duration and rate are the table's.")
SHARED = ("output", "robot", "urdf", "config", "mjcf", "actuator", "rig_option")
"""The options every simulator of ``simulate`` reads that name what is simulated: the log, the robot, how it is
driven."""


@app.command(rich_help_panel=LOGS,
             short_help="Simulate a log with known friction: a walk, an arm's motion, a hung PD robot")
def simulate(ctx: typer.Context, output: Path = OutputOpt, robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt,
             config: Optional[Path] = ConfigOpt, mjcf: Optional[Path] = MjcfOpt,
             gait: Optional[GaitChoice] = GaitOpt, steps: int = StepsOpt, step_length: float = StepLengthOpt,
             step_width: float = StepWidthOpt, turn_angle: float = TurnAngleOpt, lift_height: float = LiftHeightOpt,
             friction: Optional[Path] = FrictionOpt, simulator: Optional[str] = SimulatorOpt,
             substeps: Optional[int] = SubstepsOpt, integrator: Integrator = IntegratorOpt,
             mujoco_friction: FrictionMode = MujocoFrictionOpt, sensors: Optional[Path] = SensorsOpt,
             position_noise: Optional[float] = PositionNoiseOpt, encoder_bits: Optional[int] = EncoderBitsOpt,
             torque_noise: Optional[float] = TorqueNoiseOpt, noise_seed: Optional[int] = NoiseSeedOpt,
             delay: Optional[float] = DelayOpt, log_base: bool = LogBaseOpt, force_torque: bool = ForceTorqueOpt,
             sole_timeconst: Optional[float] = SoleOpt, friction_timeconst: Optional[float] = FrictionTimeOpt,
             torque_drift: float = TorqueDriftOpt, ft_offset: tuple[float, float] = FtOffsetOpt,
             duration: Optional[float] = DurationOpt, excitation_seed: int = SeedOpt,
             actuator: Optional[Actuator] = ActuatorOpt, setpoints: SetpointKind = SetpointsOpt,
             driver_noise: DriverNoiseChoice = DriverNoiseOpt,
             velocity_noise: Optional[float] = VelocityNoiseOpt, speed: Optional[float] = SpeedOpt,
             foot_forces: FootForces = FootForcesOpt, play: Optional[Path] = PlayOpt,
             sensor_noise: SensorNoiseChoice = SensorNoiseOpt, logger: LoggerChoice = LoggerOpt,
             logger_period: Optional[float] = LoggerPeriodOpt, imu_period: Optional[float] = ImuPeriodOpt,
             angles: Optional[AnglesChoice] = AnglesOpt, kt_error: Optional[float] = KtErrorOpt,
             foot_counts: Optional[bool] = FootCountsOpt, contacts: ContactsChoice = ContactsOpt,
             rig_option: list[str] = RigOptionOpt) -> None:
    """Simulate a walk with known friction: ideal (rigid contacts) or MuJoCo (realistic); a
    fixed-base robot (--robot panda) tracks an excitation trajectory, logging motor currents; a PD-driven one
    (--robot go2) hangs with its base fixed, its drivers tracking ramps and chirps; --simulator also takes an engine
    a program registered, --rig-option any option of the robot's rig by name. Options the rig does not read are
    refused."""
    values = {name: value for name, value in locals().items() if name != "ctx"}
    check_engine(simulator)
    check_paths({"--urdf": urdf, "--mjcf": mjcf, "--config": config, "--friction": friction, "--sensors": sensors,
                 "--play": play}, {"-o": output})
    r = robot_of(robot, urdf, config, mjcf)
    rig = rig_for(r, actuator)
    engine = rig.engine(r, simulator)
    mode = rig.what(r, actuator) + ("" if engine is None else f", simulated in {engine.name}")
    options, own = rig_options(ctx, values, (rig.simulation, rig.engine_options(engine)), mode, SHARED, rig_option,
                               play, engine=engine is not None)
    with stages() as status:
        result = rig.simulate(r, options, engine, own, RigProgress(status, status.steps))
    if result.log is not None:
        from wbfriction.logs.log import write_log
        write_log(result.log, r, output)
    else:
        from wbfriction.logs.tables import write_table
        write_table(result.table, output)
    console.print(f"wrote {output} ({result.summary})")
    for line in result.warnings:
        console.print(f"[yellow]warning:[/] {line}", highlight=False)

"""``wbfriction simulate``: a walk (ideal or MuJoCo) or an arm's excitation with known friction, as a log."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Optional

import typer

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.exceptions import InputError
from wbfriction.logs.formats.catalog import written_suffixes
from wbfriction.pipeline.paths import check_paths
from wbfriction.quantities import check_options
from wbfriction.sim.options import FrictionMode, IdealOptions, Integrator, MujocoOptions, SensorNoise, Simulator
from wbfriction.sim.pd_options import DriverNoise, HungOptions, SetpointKind, SetpointOptions
from wbfriction.walking.options import GaitOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.arm import ArmOptions

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
    progress_bar,
    refuse_options,
    robot_of,
)

HUNG = HungOptions()
SETPOINTS = SetpointOptions()
GaitChoice = Literal["forward", "sideways", "turning", "both", "combined", "stand", "step", "trot", "walk"]
"""``--gait``: a walk's (:data:`~wbfriction.walking.options.Gait`) or, for a robot on point feet, a quadruped's
(:data:`~wbfriction.walking.quadruped.Gait`)."""
QUADRUPED_GAITS = ("stand", "step", "trot", "walk")
FootForces = Literal["none", "normal", "3d"]
"""``--foot-forces``: the feet's force columns a walking quadruped's log carries."""
Actuator = Literal["torque", "pd"]
"""How a robot's joints are driven (``--actuator``): motors whose torque is logged, or PD motor drivers."""
DriverNoiseChoice = Literal["real", "none"]
"""The PD drivers' sensor noise (``--driver-noise``): a real driver's (:data:`~wbfriction.sim.pd_options.REAL_DRIVER`)
or none."""


def _run_simulate(r: Robot, output: Path, gait: GaitOptions, options: IdealOptions | MujocoOptions,
                  friction: Optional[Path]) -> None:
    from wbfriction.fit.targets import load_friction_spec
    from wbfriction.logs.log import write_log
    from wbfriction.sim.ideal import simulate_ideal
    from wbfriction.sim.mujoco_sim import simulate_mujoco
    from wbfriction.walking.reference import walking_reference

    spec = None if friction is None else load_friction_spec(friction, r.groups, r.torque_controlled)
    params, terms = (None, None) if spec is None else (spec.params, spec.terms)
    if spec is not None and spec.temperature is not None:
        options = dataclasses.replace(options, temperature=spec.temperature)
    with console.status(f"planning {gait.steps} steps ({gait.gait})"):
        ref = walking_reference(r, gait)
    with progress_bar(len(ref), "simulate") as advance:
        if isinstance(options, MujocoOptions):
            result = simulate_mujoco(r, ref, params, options, progress=advance, terms=terms)
        else:
            result = simulate_ideal(r, ref, params, options, progress=advance, terms=terms)
    write_log(result.log, r, output)
    console.print(f"wrote {output} ({len(result.log)} samples, {result.log.time[-1]:.1f} s)")
    for p in result.pulls():
        console.print(f"[yellow]warning:[/] {p.frame} pulled on the ground from {p.start:.3f} s to {p.end:.3f} s "
                      f"({p.samples} samples, down to {p.min_force:.1f} N)", highlight=False)


def _run_simulate_arm(r: Robot, output: Path, options: ArmOptions, friction: Optional[Path]) -> None:
    from wbfriction.fit.targets import load_friction_spec
    from wbfriction.logs.tables import write_table
    from wbfriction.sim.arm import default_arm_friction, simulate_arm

    spec = None if friction is None else load_friction_spec(friction, r.groups, r.torque_controlled)
    params = default_arm_friction(r) if spec is None else spec.params
    if spec is not None and spec.temperature is not None:
        options = dataclasses.replace(options, temperature=spec.temperature)
    with progress_bar(int(options.duration * options.rate), "simulate") as advance:
        result = simulate_arm(r, params, options=options, progress=advance,
                              terms=None if spec is None else spec.terms)
    write_table(result.table, output)
    console.print(f"wrote {output} ({result.table.num_rows} samples, {options.duration:g} s, motor currents)")


def _run_simulate_hung(r: Robot, output: Path, options: HungOptions, friction: Optional[Path]) -> None:
    from wbfriction.fit.targets import load_friction_spec
    from wbfriction.logs.tables import write_table
    from wbfriction.sim.hung import simulate_hung

    spec = None if friction is None else load_friction_spec(friction, r.groups, r.actuated)
    if spec is not None and (spec.terms or spec.temperature is not None):
        raise InputError(f"{friction}: a PD-driven robot's simulation takes friction models per joint, without terms "
                         "beyond velocity or a temperature")
    with progress_bar(int(round(options.duration * options.rate)), "simulate") as advance:
        result = simulate_hung(r, options, None if spec is None else spec.params, progress=advance)
    write_table(result.table, output)
    console.print(f"wrote {output} ({result.table.num_rows} samples, {options.duration:g} s, PD set-points; "
                  f"delay {result.driver.delay * 1e3:g} ms, physics step {result.physics_step * 1e3:g} ms)")


def _run_simulate_quadruped(r: Robot, output: Path, gait: str, duration: Optional[float], speed: Optional[float],
                            seed: int, simulator: Simulator, options: dict, friction: Optional[Path]) -> None:
    """A walking quadruped (a robot on point feet): its gait planned
    (:func:`~wbfriction.walking.quadruped.quadruped_reference`), simulated in the ideal simulator
    (:func:`~wbfriction.sim.quadruped.simulate_quadruped`) or on MuJoCo
    (:func:`~wbfriction.sim.quadruped_mujoco.simulate_quadruped_mujoco`), the log written; ``options``: the
    :class:`~wbfriction.sim.quadruped.QuadrupedOptions` fields the command line gave."""
    from wbfriction.fit.targets import load_friction_spec
    from wbfriction.logs.log import write_log
    from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun, simulate_quadruped
    from wbfriction.walking.quadruped import GaitOptions as QuadrupedGait
    from wbfriction.walking.quadruped import quadruped_reference

    if gait not in QUADRUPED_GAITS:
        raise InputError(f"--gait {gait}: robot '{r.name}' stands on {r.stands_on}: its gaits are "
                         f"{', '.join(QUADRUPED_GAITS)}")
    spec = None if friction is None else load_friction_spec(friction, r.groups, r.actuated)
    if spec is not None and (spec.terms or spec.temperature is not None):
        raise InputError(f"{friction}: a walking quadruped's simulation takes friction models per joint, without "
                         "terms beyond velocity or a temperature")
    gait_options = QuadrupedGait(gait=gait, duration=8.0 if duration is None else duration, speed=speed,  # type: ignore[arg-type]
                                 seed=seed)
    opts = QuadrupedOptions(friction=None if spec is None else spec.params, **options)
    with console.status(f"planning {gait_options.duration:g} s ({gait})"):
        ref = quadruped_reference(r, gait_options)
    with progress_bar(len(ref), "simulate") as advance:
        if simulator == "mujoco":
            from wbfriction.sim.quadruped_mujoco import simulate_quadruped_mujoco
            run: QuadrupedRun = simulate_quadruped_mujoco(r, ref, opts, progress=advance)
        else:
            run = simulate_quadruped(r, ref, opts, progress=advance)
    write_log(run.log, r, output)
    drive = "PD set-points" if opts.drive == "pd" else "joint torques"
    console.print(f"wrote {output} ({len(run.log)} samples, {gait_options.duration:g} s, {gait}, {drive})")
    normal = run.force[..., 2][run.log.contact]
    if normal.size and normal.min() < 0:
        console.print(f"[yellow]warning:[/] a foot pulled on the ground at {int((normal < 0).sum())} samples (down to "
                      f"{normal.min():.1f} N)", highlight=False)


OutputOpt = typer.Option(..., "-o", "--output", help=f"Log to write: {written_suffixes()}.")
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
SimulatorOpt = typer.Option("ideal", help="A walk or a robot on point feet: ideal (rigid contacts, thesis 6.1) or "
                                          "mujoco (soft contacts, measured contact flags, sensors, thesis 6.2).")
SubstepsOpt = typer.Option(None, help=f"Physics steps per control period (default: {IDEAL.substeps} ideal, "
                                      f"{MUJOCO.substeps} mujoco (1 ms periods), {HUNG.substeps} PD-driven (at "
                                      f"{HUNG.rate:g} Hz: 1 ms steps), 4 for a robot on point feet (2 ms periods: "
                                      "0.5 ms steps)).")
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
SetpointsOpt = typer.Option(SETPOINTS.kind, help="PD-driven: ramps (triangle ramps reversing every "
                                                 f"{SETPOINTS.reversal[0]:g}-{SETPOINTS.reversal[1]:g} s), chirps "
                                                 f"({SETPOINTS.chirp[0]:g}-{SETPOINTS.chirp[1]:g} Hz) or both "
                                                 "(ramps, then chirps).")
DriverNoiseOpt = typer.Option("real", help="PD-driven: real (a real driver's noise, measured on a Unitree Aliengo: "
                                           "encoder steps 1.2e-5 rad hip and thigh, 3.8e-5 calf; white noise of "
                                           "0.08 rad/s on the driver's velocity) or none (exact readings); "
                                           "--encoder-bits, --position-noise and --velocity-noise override it.")
VelocityNoiseOpt = typer.Option(None, help="PD-driven: white noise std of the driver's velocity [rad/s].")

SimulateMode = Literal["quadruped", "hung", "arm", "ideal walk", "mujoco walk"]
"""The ways ``simulate`` runs, chosen by the robot (:func:`simulate_mode`)."""
SHARED = ("output", "robot", "urdf", "config", "mjcf", "actuator")
"""The options every mode of ``simulate`` reads that name what is simulated: the log, the robot, how it is driven."""
SENSOR_NOISE = ("position_noise", "encoder_bits", "torque_noise", "noise_seed")
WALK = ("gait", "steps", "step_length", "step_width", "turn_angle", "lift_height", "friction", "simulator", "substeps",
        "log_base")
MODES: dict[SimulateMode, tuple[str, ...]] = {
    "quadruped": ("gait", "friction", "simulator", "substeps", "sensors", *SENSOR_NOISE, "duration", "excitation_seed",
                  "speed", "foot_forces"),
    "hung": ("friction", "substeps", "mujoco_friction", "position_noise", "encoder_bits", "noise_seed", "delay",
             "friction_timeconst", "duration", "excitation_seed", "setpoints", "driver_noise", "velocity_noise"),
    "arm": ("friction", *SENSOR_NOISE, "duration", "excitation_seed"),
    "ideal walk": (*WALK, "integrator", "force_torque"),
    "mujoco walk": (*WALK, "mujoco_friction", "sensors", *SENSOR_NOISE, "delay", "sole_timeconst",
                    "friction_timeconst", "torque_drift", "ft_offset"),
}
"""The options (:func:`simulate`'s parameters) each mode reads beyond :data:`SHARED`, what its branch passes on:
any other given on the command line is refused before the work (:func:`~wbfriction.cli.common.refuse_options`)."""


def simulate_mode(r: Robot, actuator: Optional[Actuator], simulator: Simulator) -> tuple[SimulateMode, str]:
    """How ``simulate`` runs robot ``r``, and what that is as a refusal says it: a robot on point feet walks as a
    quadruped; one driven by PD drivers (``--actuator pd``; by default one with a ``[pd]`` table) hangs, its base
    fixed; a fixed base otherwise is an arm tracking an excitation; the rest walks in the ``simulator``."""
    who = f"robot '{r.name}'"
    if r.partial_contacts:
        return "quadruped", f"{who} stands on {r.stands_on} (a walking quadruped)"
    if actuator == "pd" or (actuator is None and r.pd is not None):
        return "hung", f"{who} is a hung PD-driven robot (fixed base, {'--actuator pd' if actuator else '[pd]'})"
    if not r.floating_base:
        return "arm", f"{who} is a fixed-base arm (torque-driven, an excitation trajectory)"
    if simulator == "ideal":
        return "ideal walk", f"{who} walks in the ideal simulator"
    return "mujoco walk", f"{who} walks on MuJoCo (--simulator mujoco)"


@app.command()
def simulate(ctx: typer.Context, output: Path = OutputOpt, robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt,
             config: Optional[Path] = ConfigOpt, mjcf: Optional[Path] = MjcfOpt,
             gait: Optional[GaitChoice] = GaitOpt, steps: int = StepsOpt, step_length: float = StepLengthOpt,
             step_width: float = StepWidthOpt, turn_angle: float = TurnAngleOpt, lift_height: float = LiftHeightOpt,
             friction: Optional[Path] = FrictionOpt, simulator: Simulator = SimulatorOpt,
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
             foot_forces: FootForces = FootForcesOpt) -> None:
    """Simulate a walk with known friction: ideal (rigid contacts) or MuJoCo (realistic); a
    fixed-base robot (--robot panda) tracks an excitation trajectory, logging motor currents; a PD-driven one
    (--robot go2) hangs with its base fixed, its drivers tracking ramps and chirps. Options of another kind of robot
    are refused."""
    check_paths({"--urdf": urdf, "--mjcf": mjcf, "--config": config, "--friction": friction, "--sensors": sensors},
                {"-o": output})
    r = robot_of(robot, urdf, config, mjcf)
    mode, what = simulate_mode(r, actuator, simulator)
    refuse_options(ctx, what, MODES[mode], SHARED)
    check_options({"--duration": ("duration", duration), "--excitation-seed": ("seed", excitation_seed),
                   "--noise-seed": ("seed", noise_seed), "--encoder-bits": ("encoder_bits", encoder_bits),
                   "--delay": ("delay_ms", delay), "--substeps": ("substeps", substeps),
                   "--position-noise": ("position_std", position_noise), "--torque-noise": ("torque_std", torque_noise),
                   "--velocity-noise": ("velocity_std", velocity_noise)})
    if mode == "quadruped":
        noise, lag = sensor_noise(sensors, position_noise, encoder_bits, torque_noise, noise_seed, None)
        if lag:
            raise InputError(f"{sensors}: delay: a walking quadruped's simulation has no measurement delay (its "
                             "drivers' is the robot's [pd] delay)")
        physics = {} if substeps is None else {"physics_dt": 0.002 / substeps}
        return _run_simulate_quadruped(r, output, gait or "trot", duration, speed, excitation_seed, simulator,
                                       {"drive": actuator or "torque", "noise": noise, "foot_forces": foot_forces,
                                        **physics}, friction)
    if mode == "hung":
        drivers = driver_noise_of(driver_noise, encoder_bits, position_noise, velocity_noise, noise_seed)
        return _run_simulate_hung(r, output, hung_options(duration, substeps, setpoints, excitation_seed, drivers,
                                                          delay, mujoco_friction, friction_timeconst), friction)
    if mode == "arm":
        return _run_simulate_arm(r, output, arm_options(duration or 10.0, excitation_seed, position_noise,
                                                        encoder_bits, torque_noise, noise_seed), friction)
    if gait in QUADRUPED_GAITS:
        raise InputError(f"--gait {gait}: a quadruped's gait; robot '{r.name}' walks forward, sideways, turning, "
                         "both or combined")
    gait_opts = GaitOptions(gait=gait or GAIT.gait,  # type: ignore[arg-type]  # a walk's: checked above
                            steps=steps, step_length=step_length, step_width=step_width, turn_angle=turn_angle,
                            lift_height=lift_height)
    if mode == "ideal walk":
        options: IdealOptions | MujocoOptions = IdealOptions(substeps=substeps or IDEAL.substeps, integrator=integrator,
                                                             log_base=log_base, force_torque=force_torque,
                                                             imu=force_torque)
    else:
        noise, lag = sensor_noise(sensors, position_noise, encoder_bits, torque_noise, noise_seed, delay)
        options = MujocoOptions(substeps=substeps or MUJOCO.substeps, friction=mujoco_friction, sensors=noise,
                                delay=lag, log_base=log_base, sole_timeconst=sole_timeconst,
                                friction_timeconst=friction_timeconst, torque_drift=torque_drift, ft_offset=ft_offset)
    _run_simulate(r, output, gait_opts, options, friction)


def arm_options(duration: float, excitation_seed: int, position_noise: Optional[float], encoder_bits: Optional[int],
                torque_noise: Optional[float], noise_seed: Optional[int]) -> ArmOptions:
    """The options of a fixed-base robot's simulation from the command line's: ``duration`` [s] of the
    excitation trajectory of seed ``excitation_seed``; sensor noise: joint-position std [rad], encoder bits (19
    if not given), torque-sensor std [N·m] (none if not given) and their seed (0 if not given)."""
    from wbfriction.sim.arm import ArmOptions, ExcitationOptions

    return ArmOptions(duration=duration, encoder_bits=19 if encoder_bits is None else encoder_bits,
                      position_std=position_noise or 0.0, torque_std=torque_noise or 0.0, seed=noise_seed or 0,
                      excitation=ExcitationOptions(seed=excitation_seed))


def sensor_noise(sensors: Optional[Path], position_noise: Optional[float], encoder_bits: Optional[int],
                 torque_noise: Optional[float], noise_seed: Optional[int],
                 delay: Optional[float]) -> tuple[SensorNoise, float]:
    """MuJoCo's sensor noise and measurement-to-command delay [s]: the ``sensors`` TOML's ``[sensors]`` table
    (none: the defaults), each option given overriding it (``delay`` in ms)."""
    from wbfriction.sim.sensors import load_sensors_toml

    table = load_sensors_toml(sensors) if sensors is not None else {}
    given = {"position_std": position_noise, "encoder_bits": encoder_bits, "torque_std": torque_noise,
             "seed": noise_seed, "delay": None if delay is None else delay * 1e-3}
    table.update({k: v for k, v in given.items() if v is not None})
    lag = float(table.pop("delay", 0.0))
    return SensorNoise(**table), lag


def driver_noise_of(choice: str, encoder_bits: Optional[int], position_noise: Optional[float],
                    velocity_noise: Optional[float], noise_seed: Optional[int]) -> DriverNoise:
    """The PD drivers' noise: ``choice``'s levels (``real``: :data:`~wbfriction.sim.pd_options.REAL_DRIVER`;
    ``none``: exact), each option given overriding its level (``encoder_bits`` per turn on every joint)."""
    import math

    from wbfriction.sim.pd_options import REAL_DRIVER

    noise = REAL_DRIVER if choice == "real" else DriverNoise()
    resolution = None if encoder_bits is None else 2.0 * math.pi / 2.0**encoder_bits
    given: dict[str, object] = {"encoder_resolution": resolution, "position_std": position_noise,
                                "velocity_std": velocity_noise, "seed": noise_seed}
    return dataclasses.replace(noise, **{k: v for k, v in given.items() if v is not None})  # type: ignore[arg-type]


def hung_options(duration: Optional[float], substeps: Optional[int], kind: SetpointKind, seed: int,
                 noise: DriverNoise, delay: Optional[float], friction: FrictionMode,
                 friction_timeconst: Optional[float]) -> HungOptions:
    """The options of a PD-driven robot's simulation from the command line's (``delay`` in ms)."""
    return HungOptions(duration=HUNG.duration if duration is None else duration,
                       substeps=HUNG.substeps if substeps is None else substeps,
                       setpoints=SetpointOptions(kind=kind, seed=seed), noise=noise,
                       delay=None if delay is None else delay * 1e-3, friction=friction,
                       friction_timeconst=friction_timeconst)

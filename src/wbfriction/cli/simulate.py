"""``wbfriction simulate``: a walk (ideal or MuJoCo) or an arm's excitation with known friction, as a log."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Optional

import typer

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.pipeline.paths import check_paths
from wbfriction.sim.options import FrictionMode, IdealOptions, Integrator, MujocoOptions, SensorNoise, Simulator
from wbfriction.walking.options import Gait, GaitOptions

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
    robot_of,
)


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


@app.command()
def simulate(output: Path = typer.Option(..., "-o", "--output", help="Log to write: .parquet, .csv or .h5."),
             robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
             mjcf: Optional[Path] = MjcfOpt,
             gait: Gait = typer.Option(GAIT.gait, help="forward, sideways, turning, both (forward + sideways) or "
                                                    "combined (all three)."),
             steps: int = typer.Option(GAIT.steps, help="Number of steps (per direction for both/combined)."),
             step_length: float = typer.Option(GAIT.step_length, help="Forward distance between footprints [m]."),
             step_width: float = typer.Option(GAIT.step_width, help="Sideways step [m]."),
             turn_angle: float = typer.Option(GAIT.turn_angle, help="Heading change per turning step [rad]."),
             lift_height: float = typer.Option(GAIT.lift_height, help="Swing-foot apex [m]."),
             friction: Optional[Path] = typer.Option(None, help="TOML with [friction.<group or joint>] tables (a "
                                                               "model key: coulomb-viscous, stribeck or (3.5)), "
                                                               "each with an optional terms table (F_L, dF_v, "
                                                               "ripple, F_cT, F_vT, reference_temperature), and "
                                                               "a [temperature] warm-up (start, end [°C]) logged "
                                                               "as temperature.<joint>; default: thesis Table "
                                                               "6.1 on the legs."),
             simulator: Simulator = typer.Option("ideal", help="ideal (rigid contacts, thesis 6.1) or mujoco (soft "
                                                         "contacts, measured contact flags, sensors, thesis 6.2)."),
             substeps: Optional[int] = typer.Option(None, help=f"Physics steps per 1 ms control period (default: "
                                                              f"{IDEAL.substeps} ideal, {MUJOCO.substeps} mujoco)."),
             integrator: Integrator = typer.Option(IDEAL.integrator, help="ideal: semi-implicit or explicit Euler."),
             mujoco_friction: FrictionMode = typer.Option(MUJOCO.friction,
                                                          help="mujoco: model (eq. 3.5 as a joint torque) "
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
             log_base: bool = typer.Option(IDEAL.log_base, help="Write the base pose to the log."),
             force_torque: bool = typer.Option(IDEAL.force_torque, help="ideal: write what the robot's force-torque "
                                                                     "sensors and IMU measure (wrench.<sensor>.*, "
                                                                     "imu.* columns; mujoco always does)."),
             sole_timeconst: Optional[float] = typer.Option(None, help="mujoco: the soles' contact time constant "
                                                                       "(s; default MuJoCo's 0.02, larger is "
                                                                       "softer: a compliant sole)."),
             friction_timeconst: Optional[float] = typer.Option(None, help="mujoco: the friction-loss constraint's "
                                                                           "time constant (s; default two physics "
                                                                           "steps: a joint that sticks; MuJoCo's "
                                                                           "0.02 leads the velocity by 10 ms)."),
             torque_drift: float = typer.Option(MUJOCO.torque_drift, min=0.0, help="mujoco: drift rate of each torque "
                                                                               "sensor's offset (N·m/s)."),
             ft_offset: tuple[float, float] = typer.Option(MUJOCO.ft_offset, help="mujoco: standard deviations of the "
                                                                               "force-torque sensors' constant "
                                                                               "offsets: force (N), torque (N·m)."),
             duration: float = typer.Option(10.0, help="Fixed-base robot (an arm): seconds of excitation "
                                                       "trajectory."),
             excitation_seed: int = typer.Option(0, help="Fixed-base robot (an arm): seed of the excitation "
                                                         "trajectory's Fourier coefficients (another seed, another "
                                                         "motion).")) -> None:
    """Simulate a walk with known friction: ideal (rigid contacts) or MuJoCo (realistic); a
    fixed-base robot (--robot panda) tracks an excitation trajectory, logging motor currents."""
    check_paths({"--urdf": urdf, "--mjcf": mjcf, "--config": config, "--friction": friction, "--sensors": sensors},
                {"-o": output})
    r = robot_of(robot, urdf, config, mjcf)
    if not r.floating_base:
        return _run_simulate_arm(r, output, arm_options(duration, excitation_seed, position_noise, encoder_bits,
                                                        torque_noise, noise_seed), friction)
    gait_opts = GaitOptions(gait=gait, steps=steps, step_length=step_length, step_width=step_width,
                            turn_angle=turn_angle, lift_height=lift_height)
    if simulator == "ideal":
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

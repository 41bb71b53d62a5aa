"""A fixed-base robot with known friction, as ``simulate`` runs it: an arm tracking an excitation trajectory, its
motor currents logged (:func:`~wbfriction.sim.arm.simulate_arm`), or a hung PD-driven robot, its drivers tracking
ramps and chirps (:func:`~wbfriction.sim.hung.simulate_hung`)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

from wbfriction.exceptions import InputError
from wbfriction.sim.options import FrictionMode
from wbfriction.sim.pd_options import DriverNoise, HungOptions, SetpointKind, SetpointOptions
from wbfriction.sim.simulators.base import SimulationOutput, SimulationProgress, SimulatorKind
from wbfriction.sim.simulators.walks import SENSOR_NOISE

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.arm import ArmOptions

HUNG = HungOptions()
SETPOINTS = SetpointOptions()


def arm_options(duration: float, excitation_seed: int, position_noise: Optional[float], encoder_bits: Optional[int],
                torque_noise: Optional[float], noise_seed: Optional[int]) -> ArmOptions:
    """The options of a fixed-base robot's simulation from the command line's: ``duration`` [s] of the
    excitation trajectory of seed ``excitation_seed``; sensor noise: joint-position std [rad], encoder bits (19
    if not given), torque-sensor std [N·m] (none if not given) and their seed (0 if not given)."""
    from wbfriction.sim.arm import ArmOptions, ExcitationOptions

    return ArmOptions(duration=duration, encoder_bits=19 if encoder_bits is None else encoder_bits,
                      position_std=position_noise or 0.0, torque_std=torque_noise or 0.0, seed=noise_seed or 0,
                      excitation=ExcitationOptions(seed=excitation_seed))


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
    """The options of a PD-driven robot's simulation from the command line's (``duration`` [s], ``delay`` in ms,
    ``friction_timeconst`` [s]; None: the defaults)."""
    return HungOptions(duration=HUNG.duration if duration is None else duration,
                       substeps=HUNG.substeps if substeps is None else substeps,
                       setpoints=SetpointOptions(kind=kind, seed=seed), noise=noise,
                       delay=None if delay is None else delay * 1e-3, friction=friction,
                       friction_timeconst=friction_timeconst)


def played(robot: Robot, path: Path, options: HungOptions) -> tuple[HungOptions, tuple[Any, Any]]:
    """``options`` and the reference (:func:`~wbfriction.sim.hung.simulate_hung`) that play the set-points table
    at ``path`` (:mod:`wbfriction.logs.setpoint_table`, what ``excite`` writes): its duration and rate, the velocity
    set-points sent where it holds any.

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises.
    """
    import numpy as np

    from wbfriction.logs.setpoint_table import read_setpoint_table

    table = read_setpoint_table(path, robot)
    velocity = bool(np.any(table.qd_des != 0.0))
    options = dataclasses.replace(options, duration=table.duration, rate=table.rate,
                                  setpoints=dataclasses.replace(options.setpoints, velocity=velocity))
    return options, (table.q_des - robot.offset_vector, table.qd_des)


def played_arm(robot: Robot, path: Path, options: ArmOptions) -> tuple[ArmOptions, Any]:
    """``options`` and the trajectory (:class:`~wbfriction.walking.fourier.FourierTrajectory`) that play the set-points
    table at ``path`` on a fixed-base arm: its duration and rate, the Fourier series its metadata holds (what
    ``excite`` writes for an arm: the accelerations the arm's feed-forward takes are exact).

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without the
            series.
    """
    import numpy as np

    from wbfriction.logs.setpoint_table import read_setpoint_table
    from wbfriction.walking.fourier import FourierTrajectory

    table = read_setpoint_table(path, robot)
    if table.fourier is None:
        raise InputError(f"{path}: no Fourier series: an arm plays what 'wbfriction excite' writes for an arm")
    f = table.fourier
    trajectory = FourierTrajectory(np.asarray(f["center"], dtype=float), np.asarray(f["a"], dtype=float),
                                   np.asarray(f["b"], dtype=float), float(f["omega"]))
    return dataclasses.replace(options, duration=table.duration, rate=table.rate), trajectory


class ArmKind(SimulatorKind):
    """A fixed-base arm (torque-driven) tracking an excitation trajectory, its motor currents logged; default
    friction :func:`~wbfriction.sim.arm.default_arm_friction`."""

    name, precedence, chosen = "arm", 30, False
    options = ("friction", *SENSOR_NOISE, "duration", "excitation_seed", "play")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is a fixed-base arm (torque-driven, an excitation trajectory)"

    def claims(self, robot: Robot, actuator: str | None, simulator: str) -> bool:
        return not robot.floating_base

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.sim.arm import default_arm_friction, simulate_arm

        options = arm_options(values.get("duration") or 10.0, values.get("excitation_seed", 0),
                              values.get("position_noise"), values.get("encoder_bits"), values.get("torque_noise"),
                              values.get("noise_seed"))
        spec = None if friction is None else load_friction_spec(friction, robot.groups, robot.torque_controlled)
        params = default_arm_friction(robot) if spec is None else spec.params
        if spec is not None and spec.temperature is not None:
            options = dataclasses.replace(options, temperature=spec.temperature)
        trajectory = None
        if values.get("play") is not None:
            options, trajectory = played_arm(robot, values["play"], options)
        with progress.steps(int(options.duration * options.rate)) as advance:
            result = simulate_arm(robot, params, options=options, progress=advance,
                                  terms=None if spec is None else spec.terms, trajectory=trajectory)
        return SimulationOutput(table=result.table, summary=f"{result.table.num_rows} samples, "
                                                            f"{options.duration:g} s, motor currents")


class HungKind(SimulatorKind):
    """A PD-driven robot hung, its base fixed, its drivers tracking ramps and chirps (``--actuator pd``, by default
    a robot with a ``[pd]`` table); default friction Coulomb-viscous on every joint."""

    name, precedence, chosen = "hung", 20, False
    options = ("friction", "substeps", "mujoco_friction", "position_noise", "encoder_bits", "noise_seed", "delay",
               "friction_timeconst", "duration", "excitation_seed", "setpoints", "driver_noise", "velocity_noise",
               "play")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is a hung PD-driven robot (fixed base, {'--actuator pd' if actuator else '[pd]'})"

    def claims(self, robot: Robot, actuator: str | None, simulator: str) -> bool:
        # a robot on point feet walks, PD-driven or not (the quadruped's)
        return not robot.partial_contacts and (actuator == "pd" or (actuator is None and robot.pd is not None))

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.sim.hung import simulate_hung

        drivers = driver_noise_of(values.get("driver_noise", "real"), values.get("encoder_bits"),
                                  values.get("position_noise"), values.get("velocity_noise"), values.get("noise_seed"))
        options = hung_options(values.get("duration"), values.get("substeps"),
                               values.get("setpoints", SETPOINTS.kind), values.get("excitation_seed", 0), drivers,
                               values.get("delay"), values.get("mujoco_friction", HUNG.friction),
                               values.get("friction_timeconst"))
        spec = None if friction is None else load_friction_spec(friction, robot.groups, robot.actuated)
        if spec is not None and (spec.terms or spec.temperature is not None):
            raise InputError(f"{friction}: a PD-driven robot's simulation takes friction models per joint, without "
                             "terms beyond velocity or a temperature")
        reference = None
        if values.get("play") is not None:
            options, reference = played(robot, values["play"], options)
        with progress.steps(int(round(options.duration * options.rate))) as advance:
            result = simulate_hung(robot, options, None if spec is None else spec.params, progress=advance,
                                   reference=reference)
        return SimulationOutput(table=result.table, summary=f"{result.table.num_rows} samples, {options.duration:g} s, "
                                                            f"PD set-points; delay {result.driver.delay * 1e3:g} ms, "
                                                            f"physics step {result.physics_step * 1e3:g} ms")

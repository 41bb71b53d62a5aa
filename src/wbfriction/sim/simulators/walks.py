"""A walk with known friction (thesis 6.1, 6.2): the reference walk planned (:mod:`wbfriction.walking.reference`),
or a biped's one-foot stance played (``--play``, what ``excite --stance`` writes:
:mod:`wbfriction.walking.single_support`), simulated ideal (:func:`~wbfriction.sim.ideal.simulate_ideal`) or on MuJoCo
(:func:`~wbfriction.sim.mujoco_sim.simulate_mujoco`), as ``simulate --simulator ideal|mujoco`` runs it."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

from wbfriction.exceptions import InputError
from wbfriction.sim.options import IdealOptions, MujocoOptions, SensorNoise
from wbfriction.sim.simulators.base import SimulationOutput, SimulationProgress, SimulatorKind
from wbfriction.walking.options import GaitOptions

if TYPE_CHECKING:
    import numpy as np

    from wbfriction.logs.setpoint_table import SetpointTable
    from wbfriction.model.robot import Robot
    from wbfriction.walking.fourier import FourierTrajectory
    from wbfriction.walking.reference import WalkingReference

IDEAL = IdealOptions()
MUJOCO = MujocoOptions()
GAIT = GaitOptions()
QUADRUPED_GAITS = ("stand", "step", "trot", "walk")
"""The gaits of a robot on point feet (:data:`wbfriction.walking.quadruped.Gait`), refused for a walk."""
SENSOR_NOISE = ("position_noise", "encoder_bits", "torque_noise", "noise_seed")
"""The ``simulate`` options of the sensor noise."""
WALK = ("gait", "steps", "step_length", "step_width", "turn_angle", "lift_height", "friction", "simulator", "substeps",
        "log_base", "play")
"""The ``simulate`` options both walks read."""


def sensor_noise(sensors: Optional[Path], position_noise: Optional[float], encoder_bits: Optional[int],
                 torque_noise: Optional[float], noise_seed: Optional[int],
                 delay: Optional[float]) -> tuple[SensorNoise, float]:
    """MuJoCo's sensor noise and measurement-to-command delay [s]: the ``sensors`` TOML's ``[sensors]`` table
    (none: the defaults), each option given overriding it (``delay`` in ms).

    Raises:
        InputError: a sensors TOML that cannot be read, or with unknown keys.
    """
    from wbfriction.sim.sensors import load_sensors_toml

    table = load_sensors_toml(sensors) if sensors is not None else {}
    given = {"position_std": position_noise, "encoder_bits": encoder_bits, "torque_std": torque_noise,
             "seed": noise_seed, "delay": None if delay is None else delay * 1e-3}
    table.update({k: v for k, v in given.items() if v is not None})
    lag = float(table.pop("delay", 0.0))
    return SensorNoise(**table), lag


def walk_gait(robot: Robot, values: Mapping[str, Any]) -> GaitOptions:
    """The walk the ``simulate`` options give (``gait``, ``steps``, ``step_length`` [m], ``step_width`` [m],
    ``turn_angle`` [rad], ``lift_height`` [m]).

    Raises:
        InputError: a quadruped's gait (``trot``).
    """
    gait = values.get("gait")
    if gait in QUADRUPED_GAITS:
        raise InputError(f"--gait {gait}: a quadruped's gait; robot '{robot.name}' walks forward, sideways, turning, "
                         "both or combined")
    return GaitOptions(gait=gait or GAIT.gait, steps=values.get("steps", GAIT.steps),
                       step_length=values.get("step_length", GAIT.step_length),
                       step_width=values.get("step_width", GAIT.step_width),
                       turn_angle=values.get("turn_angle", GAIT.turn_angle),
                       lift_height=values.get("lift_height", GAIT.lift_height))


def played_series(table: SetpointTable) -> FourierTrajectory:
    """The swing leg's series a set-points table holds (its ``fourier`` metadata; the caller checked it has one)."""
    import numpy as np

    from wbfriction.walking.fourier import FourierTrajectory

    f = table.fourier or {}
    return FourierTrajectory(np.asarray(f["center"], dtype=float), np.asarray(f["a"], dtype=float),
                             np.asarray(f["b"], dtype=float), float(f["omega"]))


def check_played(robot: Robot, table: SetpointTable, angles: np.ndarray, what: str) -> None:
    """Refuse a table whose ``q_des`` are more than 1e-6 rad from the rebuilt reference's ``angles`` (N, n_act)
    [rad] (the model's; ``what`` names the reference: ``stance``).

    Raises:
        InputError: one joint's ``q_des`` that far (the table edited, or another robot's model).
    """
    import numpy as np

    off = np.abs(angles + robot.offset_vector - table.q_des).max(axis=0)
    if off.max() > 1e-6:
        raise InputError(f"{table.source}: q_des.{robot.actuated[int(off.argmax())]} is {off.max():.2g} "
                         f"rad from the {what} its series make: not as 'wbfriction excite' wrote it")


def played_stance(robot: Robot, path: Path) -> WalkingReference:
    """The reference of a biped's one-foot stance that the set-points table at ``path`` holds (what ``excite
    --stance`` writes): rebuilt from its stance foot, its swing leg's series and its times
    (:func:`~wbfriction.walking.single_support.single_support_reference`), checked against its ``q_des``
    (:func:`check_played`).

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without a
            stance or series; its ``q_des`` more than 1e-6 rad from the rebuilt reference (edited, or another
            robot's model).
    """
    from wbfriction.logs.setpoint_table import read_setpoint_table
    from wbfriction.walking.single_support import SIDES, single_support_reference

    table = read_setpoint_table(path, robot)
    if table.stance is None or table.fourier is None:
        raise InputError(f"{path}: no stance foot or swing series: a biped plays what 'excite --stance' writes")
    ref = single_support_reference(robot, SIDES.index(table.stance), table.fourier_joints, played_series(table),
                                   table.time)
    check_played(robot, table, robot.angles(ref.q), "stance")
    return ref


def walk_reference(robot: Robot, values: Mapping[str, Any], progress: SimulationProgress) -> WalkingReference:
    """The reference to simulate: the ``--play`` table's one-foot stance (:func:`played_stance`), else the walk the
    options give (:func:`walk_gait`) planned.

    Raises:
        InputError: what those raise; a walk the robot cannot make.
    """
    from wbfriction.walking.reference import walking_reference

    if values.get("play") is not None:
        with progress.stage(f"rebuilding the stance of {Path(values['play']).name} (its IK at every sample)"):
            return played_stance(robot, values["play"])
    gait = walk_gait(robot, values)
    with progress.stage(f"planning {gait.steps} steps ({gait.gait})"):
        return walking_reference(robot, gait)


def run_walk(robot: Robot, ref: WalkingReference, options: IdealOptions | MujocoOptions, friction: Path | None,
             progress: SimulationProgress) -> SimulationOutput:
    """The reference ``ref`` (:func:`walk_reference`) simulated with ``options`` (MuJoCo's or the ideal
    simulator's), the friction of the ``friction`` TOML (None: thesis Table 6.1 on the legs); a foot that pulled on
    the ground is a warning.

    Raises:
        InputError: a friction file that cannot be read.
    """
    from wbfriction.fit.targets import load_friction_spec
    from wbfriction.sim.ideal import simulate_ideal

    spec = None if friction is None else load_friction_spec(friction, robot.groups, robot.torque_controlled)
    params, terms = (None, None) if spec is None else (spec.params, spec.terms)
    if spec is not None and spec.temperature is not None:
        options = dataclasses.replace(options, temperature=spec.temperature)
    with progress.steps(len(ref)) as advance:
        if isinstance(options, MujocoOptions):
            from wbfriction.sim.mujoco_sim import simulate_mujoco
            result = simulate_mujoco(robot, ref, params, options, progress=advance, terms=terms)
        else:
            result = simulate_ideal(robot, ref, params, options, progress=advance, terms=terms)
    pulls = tuple(f"{p.frame} pulled on the ground from {p.start:.3f} s to {p.end:.3f} s ({p.samples} samples, down "
                  f"to {p.min_force:.1f} N)" for p in result.pulls())
    return SimulationOutput(log=result.log, summary=f"{len(result.log)} samples, {result.log.time[-1]:.1f} s",
                            warnings=pulls)


class IdealWalk(SimulatorKind):
    """A walk in the ideal simulator (rigid contacts, thesis 6.1): ``--simulator ideal``, the default."""

    name, precedence = "ideal", 40
    options = (*WALK, "integrator", "force_torque")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' walks in the ideal simulator"

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        ref = walk_reference(robot, values, progress)
        substeps, force_torque = values.get("substeps"), values.get("force_torque", IDEAL.force_torque)
        options = IdealOptions(substeps=substeps or IDEAL.substeps,
                               integrator=values.get("integrator", IDEAL.integrator),
                               log_base=values.get("log_base", IDEAL.log_base), force_torque=force_torque,
                               imu=force_torque)
        return run_walk(robot, ref, options, friction, progress)


class MujocoWalk(SimulatorKind):
    """A walk on MuJoCo (soft contacts, measured contact flags, sensors, thesis 6.2): ``--simulator mujoco``."""

    name, precedence = "mujoco", 50
    options = (*WALK, "mujoco_friction", "sensors", *SENSOR_NOISE, "delay", "sole_timeconst", "friction_timeconst",
               "torque_drift", "ft_offset")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' walks on MuJoCo (--simulator mujoco)"

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        noise, lag = sensor_noise(values.get("sensors"), values.get("position_noise"), values.get("encoder_bits"),
                                  values.get("torque_noise"), values.get("noise_seed"), values.get("delay"))
        options = MujocoOptions(substeps=values.get("substeps") or MUJOCO.substeps,
                                friction=values.get("mujoco_friction", MUJOCO.friction), sensors=noise, delay=lag,
                                log_base=values.get("log_base", MUJOCO.log_base),
                                sole_timeconst=values.get("sole_timeconst"),
                                friction_timeconst=values.get("friction_timeconst"),
                                torque_drift=values.get("torque_drift", MUJOCO.torque_drift),
                                ft_offset=values.get("ft_offset", MUJOCO.ft_offset))
        return run_walk(robot, walk_reference(robot, values, progress), options, friction, progress)

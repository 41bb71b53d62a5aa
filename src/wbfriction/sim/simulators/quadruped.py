"""A walking quadruped (a robot on point feet) with known friction, as ``simulate`` runs it: its gait planned
(:func:`~wbfriction.walking.quadruped.quadruped_reference`), simulated ideal
(:func:`~wbfriction.sim.quadruped.simulate_quadruped`) or on MuJoCo
(:func:`~wbfriction.sim.quadruped_mujoco.simulate_quadruped_mujoco`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from wbfriction.exceptions import InputError
from wbfriction.sim.simulators.base import SimulationOutput, SimulationProgress, SimulatorKind
from wbfriction.sim.simulators.walks import QUADRUPED_GAITS, SENSOR_NOISE, sensor_noise

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot


def quadruped_options(robot: Robot, values: Mapping[str, Any], friction: Path | None) -> dict[str, Any]:
    """The :class:`~wbfriction.sim.quadruped.QuadrupedOptions` fields the ``simulate`` options give: ``drive``
    (``actuator``), the sensor noise (``sensors`` TOML, ``position_noise``, ...), ``foot_forces``, ``physics_dt``
    (2 ms periods over ``substeps``) and the friction of the ``friction`` TOML.

    Raises:
        InputError: a sensor delay; a friction file with terms beyond velocity or a temperature.
    """
    from wbfriction.fit.targets import load_friction_spec

    sensors = values.get("sensors")
    noise, lag = sensor_noise(sensors, values.get("position_noise"), values.get("encoder_bits"),
                              values.get("torque_noise"), values.get("noise_seed"), None)
    if lag:
        raise InputError(f"{sensors}: delay: a walking quadruped's simulation has no measurement delay (its "
                         "drivers' is the robot's [pd] delay)")
    substeps, gait = values.get("substeps"), values.get("gait") or "trot"
    if gait not in QUADRUPED_GAITS:
        raise InputError(f"--gait {gait}: robot '{robot.name}' stands on {robot.stands_on}: its gaits are "
                         f"{', '.join(QUADRUPED_GAITS)}")
    spec = None if friction is None else load_friction_spec(friction, robot.groups, robot.actuated)
    if spec is not None and (spec.terms or spec.temperature is not None):
        raise InputError(f"{friction}: a walking quadruped's simulation takes friction models per joint, without "
                         "terms beyond velocity or a temperature")
    return {"drive": values.get("actuator") or "torque", "noise": noise,
            "foot_forces": values.get("foot_forces", "none"),
            **({} if substeps is None else {"physics_dt": 0.002 / substeps}),
            "friction": None if spec is None else spec.params}


class QuadrupedKind(SimulatorKind):
    """A robot on point feet walks as a quadruped, in the simulator ``--simulator`` names (ideal or mujoco)."""

    name, precedence, chosen = "quadruped", 10, False
    options = ("gait", "friction", "simulator", "substeps", "sensors", *SENSOR_NOISE, "duration", "excitation_seed",
               "speed", "foot_forces")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' stands on {robot.stands_on} (a walking quadruped)"

    def claims(self, robot: Robot, actuator: str | None, simulator: str) -> bool:
        return bool(robot.partial_contacts) and simulator in ("ideal", "mujoco")

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun, simulate_quadruped
        from wbfriction.walking.quadruped import GaitOptions as QuadrupedGait
        from wbfriction.walking.quadruped import quadruped_reference

        fields = quadruped_options(robot, values, friction)
        gait: Any = values.get("gait") or "trot"  # one of QUADRUPED_GAITS: checked above
        duration, speed = values.get("duration"), cast(float, values.get("speed"))  # None: the gait's speed
        gait_options = QuadrupedGait(gait=gait, duration=8.0 if duration is None else duration, speed=speed,
                                     seed=values.get("excitation_seed", 0))
        opts = QuadrupedOptions(**fields)
        with progress.stage(f"planning {gait_options.duration:g} s ({gait})"):
            ref = quadruped_reference(robot, gait_options)
        with progress.steps(len(ref)) as advance:
            if values.get("simulator") == "mujoco":
                from wbfriction.sim.quadruped_mujoco import simulate_quadruped_mujoco
                run: QuadrupedRun = simulate_quadruped_mujoco(robot, ref, opts, progress=advance)
            else:
                run = simulate_quadruped(robot, ref, opts, progress=advance)
        drive = "PD set-points" if opts.drive == "pd" else "joint torques"
        normal = run.force[..., 2][run.log.contact]
        pulled = () if not normal.size or normal.min() >= 0 else \
            (f"a foot pulled on the ground at {int((normal < 0).sum())} samples (down to {normal.min():.1f} N)",)
        return SimulationOutput(log=run.log, summary=f"{len(run.log)} samples, {gait_options.duration:g} s, {gait}, "
                                                     f"{drive}", warnings=pulled)

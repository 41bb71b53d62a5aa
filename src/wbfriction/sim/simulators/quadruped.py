"""A walking quadruped (a robot on point feet) with known friction, as ``simulate`` runs it: its gait planned
(:func:`~wbfriction.walking.quadruped.quadruped_reference`), or its stance on three feet played (``--play``, what
``excite --swing`` writes: :mod:`wbfriction.walking.tripod_support`), simulated ideal
(:func:`~wbfriction.sim.quadruped.simulate_quadruped`) or on MuJoCo
(:func:`~wbfriction.sim.quadruped_mujoco.simulate_quadruped_mujoco`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from wbfriction.exceptions import InputError
from wbfriction.sim.simulators.base import SimulationOutput, SimulationProgress, SimulatorKind
from wbfriction.sim.simulators.walks import QUADRUPED_GAITS, SENSOR_NOISE, check_played, played_series, sensor_noise

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.walking.quadruped import QuadrupedReference

PLAYED_SUBSTEPS = 8
"""The physics steps per 2 ms period when a three-feet stance is played and ``--substeps`` is not given: 0.25 ms
(4 kHz). At the gaits' 0.5 ms the explicit integration of the injected Coulomb term chatters about zero velocity on
the light calf and the front right calf's F_v comes out 4.5 % low; at 0.25 ms every swing joint's F_c and F_v within
0.6 % (``tests/excite/test_tripod.py``)."""


def quadruped_options(robot: Robot, values: Mapping[str, Any], friction: Path | None) -> dict[str, Any]:
    """The :class:`~wbfriction.sim.quadruped.QuadrupedOptions` fields the ``simulate`` options give: ``drive``
    (``actuator``), the sensor noise (``sensors`` TOML, ``position_noise``, ...), ``foot_forces``, ``physics_dt``
    (2 ms periods over ``substeps``; a table played: :data:`PLAYED_SUBSTEPS` by default) and the friction of the
    ``friction`` TOML.

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
    if substeps is None and values.get("play") is not None:
        substeps = PLAYED_SUBSTEPS
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


def played_tripod(robot: Robot, path: Path) -> QuadrupedReference:
    """The reference of a quadruped's three-feet stance that the set-points table at ``path`` holds (what ``excite
    --swing`` writes): rebuilt from its swing foot, base height, swing leg's series and times
    (:func:`~wbfriction.walking.tripod_support.tripod_support_reference`), checked against its ``q_des``
    (:func:`~.walks.check_played`).

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without a
            swing foot or series; its ``q_des`` more than 1e-6 rad from the rebuilt reference.
    """
    from wbfriction.logs.setpoint_table import read_setpoint_table
    from wbfriction.walking.tripod_support import tripod_support_reference

    table = read_setpoint_table(path, robot)
    if table.swing is None or table.base_height is None or table.fourier is None:
        raise InputError(f"{path}: no swing foot or swing series: a quadruped plays what 'excite --swing' writes")
    ref = tripod_support_reference(robot, robot.contact_frames.index(table.swing), table.fourier_joints,
                                   played_series(table), table.time, table.base_height).reference
    check_played(robot, table, ref.q, "three-feet stance")
    return ref


def quadruped_motion(robot: Robot, values: Mapping[str, Any], progress: SimulationProgress
                     ) -> tuple[QuadrupedReference, str]:
    """The reference to simulate and its name: the ``--play`` table's three-feet stance (:func:`played_tripod`),
    else the gait the options give (``gait``, ``duration``, ``speed``, ``excitation_seed``) planned."""
    from wbfriction.walking.quadruped import GaitOptions as QuadrupedGait
    from wbfriction.walking.quadruped import quadruped_reference

    if values.get("play") is not None:
        with progress.stage(f"rebuilding the stance of {Path(values['play']).name} (its IK at every sample)"):
            ref = played_tripod(robot, values["play"])
        return ref, f"{robot.contact_frames[int(ref.contact[0].argmin())]} swung on three feet"
    gait: Any = values.get("gait") or "trot"  # one of QUADRUPED_GAITS: checked by quadruped_options
    duration, speed = values.get("duration"), cast(float, values.get("speed"))  # None: the gait's speed
    gait_options = QuadrupedGait(gait=gait, duration=8.0 if duration is None else duration, speed=speed,
                                 seed=values.get("excitation_seed", 0))
    with progress.stage(f"planning {gait_options.duration:g} s ({gait})"):
        return quadruped_reference(robot, gait_options), gait


class QuadrupedKind(SimulatorKind):
    """A robot on point feet walks as a quadruped, or plays a three-feet stance (``--play``), in the simulator
    ``--simulator`` names (ideal or mujoco)."""

    name, precedence, chosen = "quadruped", 10, False
    options = ("gait", "friction", "simulator", "substeps", "sensors", *SENSOR_NOISE, "duration", "excitation_seed",
               "speed", "foot_forces", "play")

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' stands on {robot.stands_on} (a walking quadruped)"

    def claims(self, robot: Robot, actuator: str | None, simulator: str) -> bool:
        return bool(robot.partial_contacts) and simulator in ("ideal", "mujoco")

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun, simulate_quadruped

        opts = QuadrupedOptions(**quadruped_options(robot, values, friction))
        ref, motion = quadruped_motion(robot, values, progress)
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
        return SimulationOutput(log=run.log, summary=f"{len(run.log)} samples, {len(ref) * ref.dt:g} s, {motion}, "
                                                     f"{drive}", warnings=pulled)

"""MuJoCo as an engine: soft contacts, measured contact flags, sensors (thesis 6.2; a walk:
:func:`~wbfriction.sim.mujoco_sim.simulate_mujoco`, a quadruped: :func:`~wbfriction.sim.quadruped_mujoco.
simulate_quadruped_mujoco`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Optional

from wbfriction.options import option
from wbfriction.sim.engines.base import Engine, WalkSettings
from wbfriction.sim.noise_options import SensorsFileOptions
from wbfriction.sim.options import FrictionMode, MujocoOptions

if TYPE_CHECKING:
    from collections.abc import Mapping

    from wbfriction.fit.terms import TermFit
    from wbfriction.friction.models import ModelParams
    from wbfriction.model.robot import Robot
    from wbfriction.progress import Progress
    from wbfriction.sim.common import SimulationResult
    from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun
    from wbfriction.walking.quadruped import QuadrupedReference
    from wbfriction.walking.reference import WalkingReference

MUJOCO = MujocoOptions()


@dataclass(frozen=True)
class MujocoWalkOptions(SensorsFileOptions):
    """What a walk on MuJoCo reads beyond the rig's: the sensor noise (:class:`~wbfriction.sim.noise_options.
    SensorsFileOptions`) and

    Attributes:
        mujoco_friction: ``model`` (any friction model as a joint torque) or ``mujoco`` (MuJoCo's frictionloss =
            F_c, damping = F_v).
        delay: measurement-to-command delay [ms], whole control periods.
        sole_timeconst: the soles' contact time constant [s]; None: MuJoCo's 0.02.
        friction_timeconst: the friction-loss constraint's time constant [s]; None: two physics steps.
        torque_drift: drift rate of each torque sensor's offset [N·m/s].
        ft_offset: standard deviations of the force-torque sensors' constant offsets: force [N], torque [N·m].
    """

    mujoco_friction: FrictionMode = option(MUJOCO.friction)
    delay: Optional[float] = option(None, quantity="delay_ms")
    sole_timeconst: Optional[float] = option(None)
    friction_timeconst: Optional[float] = option(None)
    torque_drift: float = option(MUJOCO.torque_drift)
    ft_offset: tuple[float, float] = option(MUJOCO.ft_offset)


class MujocoEngine(Engine):
    """MuJoCo's soft contacts (thesis 6.2): contact flags from the measured forces, sensors, a quadruped's feet
    spheres."""

    name, precedence, what = "mujoco", 20, "mujoco (soft contacts, measured contact flags, sensors, thesis 6.2)"
    soft_contacts = True
    walk_options = MujocoWalkOptions

    def walk(self, robot: Robot, reference: WalkingReference, friction: Mapping[str, ModelParams] | None,
             terms: Mapping[str, TermFit] | None, settings: WalkSettings, options: Any,
             progress: Progress | None) -> SimulationResult:
        from wbfriction.sim.mujoco_sim import simulate_mujoco

        noise, lag = options.noise(options.delay)
        run = MujocoOptions(substeps=settings.substeps or MUJOCO.substeps, friction=options.mujoco_friction,
                            sensors=noise, delay=lag, log_base=settings.log_base,
                            sole_timeconst=options.sole_timeconst, friction_timeconst=options.friction_timeconst,
                            torque_drift=options.torque_drift, ft_offset=options.ft_offset,
                            temperature=settings.temperature)
        return simulate_mujoco(robot, reference, friction, run, progress=progress, terms=terms)

    def quadruped(self, robot: Robot, reference: QuadrupedReference, options: QuadrupedOptions,
                  progress: Progress | None = None, sensors: Any = None) -> QuadrupedRun:
        from wbfriction.sim.quadruped_mujoco import simulate_quadruped_mujoco

        return simulate_quadruped_mujoco(robot, reference, options, sensors, progress=progress)


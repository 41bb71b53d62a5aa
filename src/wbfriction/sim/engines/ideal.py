"""The project's ideal simulator as an engine: rigid contacts, the constrained dynamics integrated exactly (thesis
6.1; a walk: :func:`~wbfriction.sim.ideal.simulate_ideal`, a quadruped: :func:`~wbfriction.sim.quadruped.
simulate_quadruped`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from wbfriction.options import option
from wbfriction.sim.engines.base import Engine, WalkSettings
from wbfriction.sim.options import IdealOptions, Integrator

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

IDEAL = IdealOptions()


@dataclass(frozen=True)
class IdealWalkOptions:
    """What a walk in the ideal simulator reads beyond the rig's.

    Attributes:
        integrator: semi-implicit or explicit Euler (:data:`~wbfriction.sim.options.Integrator`).
        force_torque: write what the robot's force-torque sensors and IMU measure (``wrench.<sensor>.*``,
            ``imu.*`` columns).
    """

    integrator: Integrator = option(IDEAL.integrator)
    force_torque: bool = option(IDEAL.force_torque)


class IdealEngine(Engine):
    """Rigid contacts (thesis 6.1): a standing sole or a point foot down is welded; the log is exact."""

    name, precedence, what = "ideal", 10, "ideal (rigid contacts, thesis 6.1)"
    walk_options = IdealWalkOptions

    def walk(self, robot: Robot, reference: WalkingReference, friction: Mapping[str, ModelParams] | None,
             terms: Mapping[str, TermFit] | None, settings: WalkSettings, options: Any,
             progress: Progress | None) -> SimulationResult:
        from wbfriction.sim.ideal import simulate_ideal

        run = IdealOptions(substeps=settings.substeps or IDEAL.substeps, integrator=options.integrator,
                           log_base=settings.log_base, force_torque=options.force_torque, imu=options.force_torque,
                           temperature=settings.temperature)
        return simulate_ideal(robot, reference, friction, run, progress=progress, terms=terms)

    def quadruped(self, robot: Robot, reference: QuadrupedReference, options: QuadrupedOptions,
                  progress: Progress | None = None, sensors: Any = None) -> QuadrupedRun:
        from wbfriction.sim.quadruped import simulate_quadruped

        return simulate_quadruped(robot, reference, options, progress=progress)

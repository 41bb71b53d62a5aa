"""A toy engine, one file: the project's ideal simulator with twice its physics steps where the run does not say
(``--simulator ideal-fine``): a biped's walk at 2 steps per control period, a quadruped's gait at 0.25 ms."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from wbfriction.sim.engines.base import WalkSettings
from wbfriction.sim.engines.ideal import IdealEngine

NAME = "ideal-fine"
WALK_SUBSTEPS, QUADRUPED_DT = 2, 0.00025
"""A walk's physics steps per 1 ms period, a quadruped's physics step [s], where the run does not say."""


class FineIdeal(IdealEngine):
    """The ideal simulator, its physics steps finer by default."""

    name, precedence, what = NAME, 15, f"{NAME} (the ideal simulator, finer physics steps)"

    def walk(self, robot, reference, friction, terms, settings: WalkSettings, options: Any, progress):
        return super().walk(robot, reference, friction, terms,
                            replace(settings, substeps=settings.substeps or WALK_SUBSTEPS), options, progress)

    def quadruped(self, robot, reference, options, progress=None, sensors=None):
        from wbfriction.sim.quadruped import QuadrupedOptions

        default = QuadrupedOptions().physics_dt
        fine = options if options.physics_dt != default else replace(options, physics_dt=QUADRUPED_DT)
        return super().quadruped(robot, reference, fine, progress, sensors)

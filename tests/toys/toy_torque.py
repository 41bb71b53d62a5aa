"""A toy torque source, one file: the drives' effort, ``effort.<joint>`` in mN·m, for every torque-controlled
joint."""

from __future__ import annotations

import numpy as np

from wbfriction.logs.pd import PdSetpoints
from wbfriction.logs.torque import TorqueColumns, TorqueKind
from wbfriction.model.robot import Robot

SCALE = 1e-3
"""N·m per logged unit (mN·m)."""


class Effort(TorqueKind):
    """``effort.<joint>`` [mN·m], tried after the drivers' estimates and before the currents."""

    name = "effort"
    what = "the drives' effort in mN·m (effort.<joint>)"
    prefix = "effort"
    precedence = 25

    def torque(self, given: TorqueColumns) -> np.ndarray:
        return SCALE * given.columns(self.prefix)

    def columns(self, tau: np.ndarray, robot: Robot, setpoints: PdSetpoints | None) -> dict[str, np.ndarray]:
        return {f"effort.{n}": tau[:, i] / SCALE for i, n in enumerate(robot.torque_controlled)}

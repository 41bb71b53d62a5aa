"""A quadruped's size against the nominal one's, and the gait, gains and friction scaled to it (issue 82).

The walking quadruped's defaults (:class:`~wbfriction.walking.quadruped.GaitOptions`' heights, period and speed, the
sway's and swings' amplitudes; :class:`~wbfriction.sim.quadruped.QuadrupedOptions`' joint gains;
:func:`~wbfriction.sim.quadruped.default_quadruped_friction`) were set for the built-in ``go2_walking`` (Unitree's
Go2: 16 kg, standing 0.34 m high). Another robot takes them by **dynamic similarity** (equal Froude numbers: the same
gait in the robot's own units), from two numbers of its model:

* its length scale ``s``: its standing height (the feet's contact frames' mean depth below the root at its reference
  configuration, plus its feet's radius, :func:`~wbfriction.walking.quadruped.foot_sphere`) over the nominal one's;
* its mass ratio ``m``: its total mass over the nominal one's.

Lengths go as ``s``, times as ``sqrt(s)`` (gravity is the same), speeds as ``sqrt(s)``, joint torques as ``m s``
(a weight times a leg's length), so a joint stiffness [N·m/rad] and a Coulomb friction [N·m] as ``m s`` and a joint
damping or viscous friction [N·m·s/rad] as ``m s sqrt(s)``. The nominal robot's own ratios are exactly 1 (the same
computation on the same model): its gait, gains and friction are unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np
import pinocchio as pin

from wbfriction.model.robot import Robot
from wbfriction.walking.quadruped import GaitOptions, foot_sphere

NOMINAL_ROBOT = "go2_walking"
"""The built-in robot the quadruped's defaults were set for (module docstring)."""


@dataclass(frozen=True)
class RobotScale:
    """A robot's size against the nominal quadruped's (module docstring).

    Attributes:
        length: ``s``, its standing height over the nominal one's.
        mass: ``m``, its total mass over the nominal one's.
    """

    length: float = 1.0
    mass: float = 1.0

    @property
    def time(self) -> float:
        """``sqrt(s)``: a period's (and a speed's) ratio."""
        return float(np.sqrt(self.length))

    @property
    def torque(self) -> float:
        """``m s``: a joint torque's (a stiffness's, a Coulomb friction's) ratio."""
        return self.mass * self.length

    @property
    def damping(self) -> float:
        """``m s sqrt(s)``: a joint damping's (a viscous friction's) ratio [N·m·s/rad]."""
        return self.torque * self.time


def standing_height(robot: Robot) -> float:
    """The robot's standing height [m]: its contact frames' mean depth below the root at its reference configuration,
    plus its feet's radius (:func:`~wbfriction.walking.quadruped.foot_sphere`)."""
    q = robot.configuration(robot.reference_angles)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    depth = np.mean([q[2] - data.oMf[f].translation[2] for f in robot.contact_frame_ids])
    return float(depth) + foot_sphere(robot)


@lru_cache(maxsize=1)
def _nominal() -> tuple[float, float]:
    """The nominal robot's standing height [m] and total mass [kg]."""
    from wbfriction.model.loading import load_robot

    nominal = load_robot(NOMINAL_ROBOT)
    return standing_height(nominal), float(pin.computeTotalMass(nominal.model))


def robot_scale(robot: Robot) -> RobotScale:
    """``robot``'s :class:`RobotScale` (module docstring): a floating-base robot with contact frames."""
    height, mass = _nominal()
    return RobotScale(standing_height(robot) / height, float(pin.computeTotalMass(robot.model)) / mass)


def scaled_gait(robot: Robot, given: dict[str, Any], seed: int = 0) -> GaitOptions:
    """The gait's options for ``robot``: those ``given`` (field name -> value; None or absent: the default), the
    defaults' lengths, period and speed scaled to the robot (module docstring).

    Raises:
        OptionError: what :class:`~wbfriction.walking.quadruped.GaitOptions` refuses.
    """
    given = {k: v for k, v in given.items() if v is not None}
    nominal = GaitOptions(seed=seed, **given)
    scale = robot_scale(robot)
    scaled: dict[str, Any] = {"base_height": nominal.base_height * scale.length,
                              "step_height": nominal.step_height * scale.length, "period": nominal.period * scale.time,
                              "speed": nominal.speed * scale.time, "scale": scale.length}
    return replace(nominal, **{k: v for k, v in scaled.items() if k not in given})

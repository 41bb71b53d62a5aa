"""What a designed motion must stay within: each joint's position range, velocity and torque limits (the URDF's),
and how far inside them a motion stays (:class:`Margins`, what ``excite`` prints and writes).

The torque a motion asks of a fixed-base robot is its inverse dynamics with the friction expected,
``M(q) qdd + h(q, qd) + f(qd)`` (``pin.rnea`` on the robot's fixed-base tree, armature included): what the drives
must give to follow it (a PD driver's law gives it through its tracking error).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class JointLimits:
    """Each designed joint's limits, in the robot's actuated order.

    Attributes:
        joints: the joints.
        lower, upper: position limits (n,) [rad].
        velocity: velocity limits (n,) [rad/s].
        torque: torque limits (n,) [N·m] (the drivers' clip where the robot has one, else the URDF's effort).
    """

    joints: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    torque: np.ndarray

    @classmethod
    def of(cls, robot: Robot) -> JointLimits:
        """The limits of every actuated joint of ``robot``: its URDF's, the torque its ``[pd]`` drivers clip at
        where it has them.

        Raises:
            InputError: a joint without finite position, velocity or torque limits (a continuous joint, a URDF
                without ``<limit velocity effort>``): the design has nothing to stay within.
        """
        lower, upper = robot.angle_limits
        iv = robot.act_v_index
        velocity = np.array(robot.model.velocityLimit[iv], dtype=float)
        torque = np.array(robot.model.effortLimit[iv], dtype=float)
        if robot.pd is not None:
            clip = dict(zip(robot.pd.joints, robot.pd.torque_limit))
            torque = np.array([min(t, clip.get(j, np.inf)) for j, t in zip(robot.actuated, torque)])
        for what, values in (("position", upper - lower), ("velocity", velocity), ("torque", torque)):
            bad = np.flatnonzero(~(np.isfinite(values) & (values > 0)))
            if bad.size:
                raise InputError(f"{robot.urdf}: joint '{robot.actuated[bad[0]]}' has no finite {what} limit: a "
                                 "designed motion needs one to stay within")
        return cls(robot.actuated, lower, upper, velocity, torque)


@dataclass(frozen=True)
class Margins:
    """How far inside its limits a motion stays, per joint (n,), as a share of each limit (1: unused, 0: at it).

    Attributes:
        position: the least distance to either position limit over half the range.
        velocity: ``1 - max |qd| / velocity limit``.
        torque: ``1 - max |tau| / torque limit`` (:func:`inverse_dynamics`).
    """

    position: np.ndarray
    velocity: np.ndarray
    torque: np.ndarray

    def least(self) -> float:
        """The smallest margin of any joint and limit."""
        return float(min(self.position.min(), self.velocity.min(), self.torque.min()))


def inverse_dynamics(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                     friction: Mapping[str, ModelParamsBase]) -> np.ndarray:
    """The torque (N, n_act) [N·m] a fixed-base robot needs to follow ``q``, ``qd``, ``qdd`` (N, n_act), its
    armature included, with the friction ``friction`` per joint (the others: none) (module docstring)."""
    from wbfriction.sim.arm import arm_model

    model = arm_model(robot)
    data = model.createData()
    tau = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])
    for i, joint in enumerate(robot.actuated):
        if joint in friction:
            tau[:, i] += friction[joint].f(qd[:, i])
    return tau


def margins(limits: JointLimits, q: np.ndarray, qd: np.ndarray, tau: np.ndarray) -> Margins:
    """The :class:`Margins` of a motion ``q``, ``qd`` and the torque it asks, ``tau`` (N, n) each."""
    half = 0.5 * (limits.upper - limits.lower)
    position = np.minimum(q.min(axis=0) - limits.lower, limits.upper - q.max(axis=0)) / half
    return Margins(position, 1.0 - np.abs(qd).max(axis=0) / limits.velocity,
                   1.0 - np.abs(tau).max(axis=0) / limits.torque)

"""The swing leg's design shared by a humanoid's one-foot stance (:mod:`.one_foot`) and a quadruped's three-feet
stance (:mod:`.tripod`): each swing joint's posture band within its URDF range (:func:`posture_band`), its
finite Fourier series designed alone on the Cramér-Rao bound of its friction (:func:`design_swing`), the noise that
design takes (:func:`swing_noise`) and the bounds its series reach (:func:`series_bounds`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.excite.design import ExciteOptions, design_joint
from wbfriction.excite.information import torque_bound
from wbfriction.excite.trajectory import FourierSpace
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.noise import NoiseModel
from wbfriction.model.robot import Robot
from wbfriction.walking.fourier import FourierTrajectory

SLACK = (1e-3, 0.99)
"""What each joint's design is given: its band less 1 mrad at each end, 99 % of its velocity cap: the design holds
its limits on a grid (:data:`~.design.GRID` points per period) and overshoots them between the points by up to about
0.2 mrad (measured), which this keeps within the band and the cap at every sample."""


class SwingOptions(Protocol):
    """The fields of :class:`~.one_foot.OneFootOptions` and :class:`~.tripod.TripodOptions` the swing's design reads."""

    @property
    def design(self) -> ExciteOptions: ...

    @property
    def velocity(self) -> float: ...

    @property
    def torque_noise(self) -> float: ...

    @property
    def position_noise(self) -> float: ...


def posture_band(robot: Robot, joints: tuple[str, ...], bands: dict[str, tuple[float, float]],
                 mirrored: tuple[str, ...], margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Each swing joint's band (n,), (n,) [rad]: ``bands`` of its group [rad] (given for a right leg), negated for
    the groups in ``mirrored`` (a left leg's mirrored groups, none for a right leg), within its URDF range less
    ``margin``.

    Raises:
        InputError: a joint whose group has no band, or whose band leaves no room within its range.
    """
    lo_urdf, hi_urdf = robot.angle_limits
    lower, upper = np.empty(len(joints)), np.empty(len(joints))
    for i, joint in enumerate(joints):
        group = robot.group_of(joint)
        if group not in bands:
            raise InputError(f"swing joint '{joint}' (group {group!r}) has no posture band: one of {sorted(bands)}")
        lo, hi = bands[group]
        if group in mirrored:
            lo, hi = -hi, -lo
        a = robot.actuated.index(joint)
        lower[i], upper[i] = max(lo, lo_urdf[a] + margin), min(hi, hi_urdf[a] - margin)
        if not upper[i] > lower[i]:
            raise InputError(f"swing joint '{joint}': its band [{lo:g}, {hi:g}] rad leaves no room within its "
                             f"range [{lo_urdf[a]:g}, {hi_urdf[a]:g}] less {margin:g} rad")
    return lower, upper


def swing_noise(robot: Robot, joints: tuple[str, ...], options: SwingOptions, posture: np.ndarray
                ) -> list[NoiseModel]:
    """Each swing joint's noise as its design takes it: the options' torque and position noise, the joint's inertia
    (the mass matrix's diagonal at the configuration ``posture`` (nq,)), the design's sample period."""
    inertia = np.diag(pin.crba(robot.model, robot.model.createData(), posture))
    return [NoiseModel(options.torque_noise, options.position_noise,
                       float(inertia[robot.act_v_index[robot.actuated.index(j)]]), 1.0 / options.design.rate)
            for j in joints]


def design_swing(robot: Robot, joints: tuple[str, ...], band: tuple[np.ndarray, np.ndarray],
                 prior: Mapping[str, ModelParamsBase], options: SwingOptions, noise: list[NoiseModel]
                 ) -> FourierTrajectory:
    """The swing joints' series (n joints): each designed alone by :func:`~.design.design_joint` within its band
    ``(lower, upper)`` (n,) each [rad] and below the velocity cap (the options' and the design's velocity share of
    its URDF limit), for its ``prior`` friction and its ``noise`` (:func:`swing_noise`), less :data:`SLACK`."""
    excite = options.design
    space = FourierSpace(1, excite.harmonics, excite.omega)
    rng = np.random.default_rng(excite.seed)
    z = []
    for i, (joint, joint_noise) in enumerate(zip(joints, noise)):
        iv = robot.act_v_index[robot.actuated.index(joint)]
        velocity = min(options.velocity, excite.velocity_share * float(robot.model.velocityLimit[iv]))
        z.append(design_joint(space, excite, float(band[0][i]) + SLACK[0], float(band[1][i]) - SLACK[0],
                              SLACK[1] * velocity, prior[joint], joint_noise, rng))
    return FourierSpace(len(joints), excite.harmonics, excite.omega).trajectory(np.concatenate(z))


def series_bounds(joints: tuple[str, ...], trajectory: FourierTrajectory, time: np.ndarray,
                 prior: Mapping[str, ModelParamsBase], noise: list[NoiseModel]) -> dict[str, dict[str, float]]:
    """Each swing joint's Cramér-Rao bound of its friction's parameters on its series ``trajectory`` sampled at
    ``time`` (N,) [s] (:func:`~.information.torque_bound`: its ``prior`` friction, its ``noise``), per joint and
    parameter name (``F_c`` [N·m], ``F_v`` [N·m·s/rad], ...)."""
    _, qd, _ = trajectory(time)
    return {j: torque_bound(prior[j], qd[:, i], noise[i]) for i, j in enumerate(joints)}

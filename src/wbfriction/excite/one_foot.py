"""A humanoid standing on one foot while its other leg is excited (issue 66): a reference the project's walking
simulators play (:class:`~wbfriction.walking.reference.WalkingReference`), single support from the first sample to
the last, so that every sample is one the estimator maps exactly to the swing leg's friction torque.

* **The swing leg**: each joint a finite Fourier series at rest at both ends (:mod:`.trajectory`), designed alone by
  :func:`~.design.design_joint` on the Cramér-Rao bound of its friction (:attr:`OneFootOptions.asked`) within a
  conservative *posture band* (:data:`SWING_BAND`, given for a right swing leg, mirrored for a left one: hip and
  ankle roll and hip yaw change sign) intersected with its URDF range less :attr:`OneFootOptions.margin`, and below
  :attr:`OneFootOptions.velocity`. The band keeps the leg flexed (hip pitch forward, knee bent, the foot lifted) and
  its hip rolled outward, away from the stance leg; :func:`one_foot_reference` checks on the solved motion that the
  swing sole's lowest corner stays :attr:`OneFootOptions.clearance` above the ground and its corners beside the
  stance sole's footprint (ModelError otherwise).
* **Every other joint but the stance leg's** is held at the robot's reference posture (arms, torso, head).
* **The floating base and the stance leg** (``6 + 6`` unknowns) come from a square inverse kinematics per sample
  (:mod:`wbfriction.walking.single_support`, which ``simulate --play`` reruns on the set-points table's series:
  Newton iterations, Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians), twelve tasks: the stance sole's placement
  (flat at its standing footprint, 6), the centre of mass over the sole's centre at the standing posture's height
  (3), the base upright (3). Velocities from ``J v = 0``, accelerations from ``J a = -Jd v`` (the targets are
  constant), so the reference keeps the stance sole still at the acceleration level. *Quasi-static*: the centre of
  mass, not the zero-moment point, is held over the sole; the ZMP of the reference's own dynamics
  (:func:`zero_moment_point`) is computed and must stay inside the sole's footprint (:func:`support_margin`,
  ModelError otherwise): the swing leg's velocity cap is what keeps it there. (TALOS, the default options: the ZMP
  within 27 mm of the sole's centre along either axis, 49 mm inside its edges; the swing sole 69 mm above the ground
  at its lowest corner, 52-64 mm beside the stance sole; measured on both feet.)

The motion starts at rest in single support (the series is at rest at ``t = 0``) with the swing foot already in the
air: both simulators accept that (the ideal one welds the stance sole at its first sample; MuJoCo starts from the
reference's first state), so no transition from double support is planned.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.swing import design_swing, posture_band, series_bounds, swing_noise
from wbfriction.fit.targets import THESIS_TARGETS, friction_by_group
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.model.footprint import sole_footprint
from wbfriction.model.robot import Robot
from wbfriction.walking.fourier import FourierTrajectory
from wbfriction.walking.reference import WalkingReference, standing_configuration
from wbfriction.walking.single_support import (  # noqa: F401 (SingleSupportIK, zero_moment_point: this module's names too)
    SIDES,
    SingleSupportIK,
    single_support_ik,
    single_support_reference,
    zero_moment_point,
)

SWING_BAND: dict[str, tuple[float, float]] = {
    "hip_yaw": (-0.05, 0.15),
    "hip_roll": (-0.5, -0.25),
    "hip_pitch": (-0.9, -0.5),
    "knee": (1.3, 1.8),
    "ankle_pitch": (-0.9, -0.4),
    "ankle_roll": (-0.2, 0.0),
}
"""The swing leg's posture band [rad] per joint group, for a *right* swing leg (TALOS's conventions: a negative hip
roll moves the right foot outward; a left swing leg's hip yaw, hip roll and
ankle roll bands are negated): the foot lifted and rolled away from the stance leg. Every posture of the band
(its 64 corners checked by :func:`band_clearance`, with the floating base and stance leg solved) keeps the swing
sole clear of the ground and beside the stance sole, whatever combination of the band the designed series reach:
on TALOS at least 43 mm above the ground and 17 mm beside (the earlier band, hip yaw -0.15..0.05, hip roll
-0.4..-0.2 and ankle roll -0.15..0.15, let corners come 44 mm across the stance sole, and whether the design's series
met them depended on the optimiser's rounding)."""
MIRRORED = ("hip_yaw", "hip_roll", "ankle_roll")
"""The groups whose band changes sign from one leg to the other."""
@dataclass(frozen=True)
class OneFootOptions:
    """What :func:`one_foot_reference` builds.

    Attributes:
        stance: ``"left"`` or ``"right"``: the foot stood on (the other leg swings).
        design: each swing joint's design (:class:`~.design.ExciteOptions`: the recording's duration and rate, the
            series' period (a whole number per recording) and harmonics, the share of each URDF velocity limit, the
            friction parameters asked, the starts and seed; its range share is not read: the band is
            :data:`SWING_BAND`'s).
        velocity: the cap on each swing joint's speed [rad/s] (also at most the design's velocity share of its URDF
            limit).
        margin: how far inside its URDF range each swing joint stays [rad].
        clearance: the least height of the swing sole's lowest corner above the ground [m].
        zmp_margin: the least distance of the reference's ZMP to the stance sole's edges [m].
        torque_noise: the design's torque noise [N·m]; position_noise: its position noise [rad].
    """

    stance: str = "left"
    design: ExciteOptions = ExciteOptions(duration=8.0, period=4.0, harmonics=5, range_share=1.0)
    velocity: float = 1.5
    margin: float = 0.05
    clearance: float = 0.02
    zmp_margin: float = 0.01
    torque_noise: float = 0.05
    position_noise: float = 1e-4

    def __post_init__(self) -> None:
        if self.stance not in ("left", "right"):
            raise InputError(f"--stance {self.stance!r}: 'left' or 'right'")
        if not (np.isfinite(self.velocity) and self.velocity > 0):
            raise InputError(f"--velocity {self.velocity!r}: a swing joint's speed cap must be > 0 rad/s")


@dataclass(frozen=True)
class OneFootExcitation:
    """A one-foot stance with the swing leg excited.

    Attributes:
        reference: the whole-body reference (N samples at ``rate``): ``contact`` has the stance foot only,
            ``feet`` the stance sole's footprint and the swing sole's pose (x, y, z [m], yaw [rad], world),
            ``com`` the centre of mass [m], ``zmp`` the ZMP of the reference's own dynamics [m].
        stance: the stance foot's index in :attr:`Robot.contact_frames`.
        joints: the swing leg's joints (the robot's actuated order); trajectory: their series.
        lower, upper: each swing joint's band [rad] (the posture band within its URDF range less the margin).
        zmp_margin: the least distance of the ZMP to the stance sole's edges [m] (negative: outside).
        clearance: the least height of the swing sole's corners above the ground [m].
    """

    reference: WalkingReference
    stance: int
    joints: tuple[str, ...]
    trajectory: FourierTrajectory
    lower: np.ndarray
    upper: np.ndarray
    zmp_margin: float
    clearance: float


def swing_band(robot: Robot, joints: tuple[str, ...], side: str, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Each swing joint's band (n,), (n,) [rad]: :data:`SWING_BAND` of its group (mirrored for a ``"left"`` leg,
    :data:`MIRRORED`) within its URDF range less ``margin`` (:func:`~.swing.posture_band`).

    Raises:
        InputError: a joint whose group has no band, or whose band leaves no room within its range.
    """
    return posture_band(robot, joints, SWING_BAND, MIRRORED if side == "left" else (), margin)


def support_margin(robot: Robot, stance: int, zmp: np.ndarray) -> float:
    """The least distance [m] of the points ``zmp`` (N, 2) (world) to the edges of the stance sole's footprint
    (:func:`~wbfriction.model.footprint.sole_footprint`), the sole flat at its standing placement; negative: a
    point outside."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, standing_configuration(robot))
    sole = data.oMf[robot.contact_frame_ids[stance]]
    centre, half = sole_footprint(robot, robot.contact_frames[stance])
    local = (zmp - sole.translation[:2]) @ sole.rotation[:2, :2]
    return float(np.min(half - np.abs(local - centre)))


def band_clearance(robot: Robot, stance: int, joints: tuple[str, ...], lower: np.ndarray,
                   upper: np.ndarray) -> tuple[float, float]:
    """The swing sole's least height [m] and least distance beside the stance sole [m] (as :func:`_swing_corners`)
    over every corner of the band ``lower``, ``upper`` (n,) [rad] of the swing ``joints`` (2^n postures, the other
    joints at the reference posture, the floating base and the stance leg from :func:`single_support_ik`, at rest)."""
    ik = single_support_ik(robot, stance)
    iq = robot.act_q_index[[robot.actuated.index(j) for j in joints]]
    rest = np.zeros(len(ik.rest))
    postures = []
    for corner in itertools.product(*zip(lower, upper)):
        q = standing_configuration(robot)
        q[iq] = corner
        postures.append(ik.solve(q, rest, rest)[0])
    return _swing_corners(robot, stance, np.array(postures), every=1)


def _swing_corners(robot: Robot, stance: int, q: np.ndarray, every: int = 10) -> tuple[float, float]:
    """The swing sole's lowest corner height [m] over the motion ``q`` (N, nq) (every ``every`` samples), and its
    corners' least lateral distance beyond the stance sole's inner edge [m] (negative: beside it no longer)."""
    model, data = robot.model, robot.model.createData()
    swing = 1 - stance
    centre, half = sole_footprint(robot, robot.contact_frames[swing])
    corners = np.array([[centre[0] + sx * half[0], centre[1] + sy * half[1], 0.0]
                        for sx in (-1, 1) for sy in (-1, 1)])
    s_centre, s_half = sole_footprint(robot, robot.contact_frames[stance])
    pin.framesForwardKinematics(model, data, q[0])
    stance_sole = data.oMf[robot.contact_frame_ids[stance]].copy()
    inward = 1.0 if stance == 0 else -1.0  # the swing foot lies to the stance sole's -y (left stance) or +y
    edge = s_centre[1] - inward * s_half[1]
    low, beside = np.inf, np.inf
    for k in range(0, len(q), every):
        pin.framesForwardKinematics(model, data, q[k])
        world = corners @ data.oMf[robot.contact_frame_ids[swing]].rotation.T + data.oMf[
            robot.contact_frame_ids[swing]].translation
        in_stance = (world - stance_sole.translation) @ stance_sole.rotation
        low = min(low, float(world[:, 2].min()))
        beside = min(beside, float(np.min(inward * (edge - in_stance[:, 1]))))
    return low, beside


def one_foot_reference(robot: Robot, options: OneFootOptions = OneFootOptions(),
                     prior: Mapping[str, ModelParamsBase] | None = None) -> OneFootExcitation:
    """Stand on one foot for :attr:`OneFootOptions.duration` while the other leg follows its designed series
    (module docstring).

    Args:
        robot: a biped: two soles (left, right, in that order), six joints per leg, its leg joints in groups of
            :data:`SWING_BAND`.
        options: :class:`OneFootOptions`.
        prior: per swing joint, the friction its design's bound is taken at; default: the thesis's targets by
            group (:data:`~wbfriction.fit.targets.THESIS_TARGETS`).

    Returns:
        A :class:`OneFootExcitation` of ``duration x rate`` samples.

    Raises:
        InputError: a robot without two soles, a swing joint without band or prior, a period that does not divide
            the duration; ModelError: the IK out of reach, the ZMP leaving the sole, the swing sole too low or
            under the stance sole, a stance joint outside its URDF range.
    """
    stance = SIDES.index(options.stance)
    joints = robot.limb(robot.contact_frames[1 - stance])
    prior = friction_by_group(robot.groups, THESIS_TARGETS) if prior is None else prior
    if missing := [j for j in joints if j not in prior]:
        raise InputError(f"no prior friction for swing joint '{missing[0]}'")
    lower, upper = swing_band(robot, joints, SIDES[1 - stance], options.margin)
    _clear(options, *band_clearance(robot, stance, joints, lower, upper), "the posture band lets the swing sole come")
    noise = swing_noise(robot, joints, options, standing_configuration(robot))
    trajectory = design_swing(robot, joints, (lower, upper), prior, options, noise)
    reference = single_support_reference(robot, stance, joints, trajectory, options.design.times())
    margin, low = _checked(robot, options, stance, reference)
    return OneFootExcitation(reference, stance, joints, trajectory, lower, upper, margin, low)


def _checked(robot: Robot, options: OneFootOptions, stance: int, reference: WalkingReference) -> tuple[float, float]:
    """The ZMP's least distance to the stance sole's edges [m] and the swing sole's least height [m] of a solved
    motion, its ZMP, clearance and stance leg's range checked (ModelError)."""
    margin = support_margin(robot, stance, reference.zmp)
    if margin < options.zmp_margin:
        raise ModelError(f"the ZMP comes within {margin * 1e3:.1f} mm of the stance sole's edge (at least "
                         f"{options.zmp_margin * 1e3:.1f} mm asked): lower --velocity")
    low, beside = _swing_corners(robot, stance, reference.q)
    _clear(options, low, beside, "the swing sole comes")
    lo, hi = robot.angle_limits
    angles = robot.angles(reference.q)
    if np.any(angles < lo) or np.any(angles > hi):
        worst = int(np.argmax(np.maximum(lo - angles, angles - hi).max(axis=0)))
        raise ModelError(f"joint '{robot.actuated[worst]}' leaves its URDF range on one foot")
    return margin, low


def _clear(options: OneFootOptions, low: float, beside: float, subject: str) -> None:
    """ModelError unless the swing sole's least height ``low`` [m] reaches the clearance asked and its least
    distance ``beside`` [m] the stance sole is not negative (``subject`` begins the message)."""
    if low < options.clearance or beside < 0.0:
        raise ModelError(f"{subject} {low * 1e3:.1f} mm above the ground and {beside * 1e3:.1f} mm beside the stance "
                         f"sole (at least {options.clearance * 1e3:.1f} and 0 mm): a narrower band")


def swing_bounds(robot: Robot, excitation: OneFootExcitation, options: OneFootOptions,
                 prior: Mapping[str, ModelParamsBase] | None = None) -> dict[str, dict[str, float]]:
    """Each swing joint's Cramér-Rao bound of its friction's parameters on the designed motion [their units]
    (:func:`~.swing.series_bounds`: its prior friction, as its design takes it, the options' noise at the
    standing posture), per joint and parameter name (``F_c`` [N·m], ``F_v`` [N·m·s/rad], ...)."""
    prior = friction_by_group(robot.groups, THESIS_TARGETS) if prior is None else prior
    noise = swing_noise(robot, excitation.joints, options, standing_configuration(robot))
    return series_bounds(excitation.joints, excitation.trajectory, excitation.reference.time, prior, noise)

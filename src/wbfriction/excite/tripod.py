"""A quadruped standing on three point feet while its fourth leg is excited (issue 66): a reference the project's
quadruped simulators play (:class:`~wbfriction.walking.quadruped.QuadrupedReference`, the ideal one and MuJoCo's),
three feet down from the first sample to the last, so that every sample is one the estimator maps to the swing
leg's friction torque (its joints' rows of the equation of motion hold no contact force).

* **The swing leg** (:attr:`TripodOptions.swing`): each of its three joints a finite Fourier series at rest at both
  ends (:mod:`.trajectory`), designed alone by :func:`~.design.design_joint` on the Cramér-Rao bound of its friction
  (:attr:`TripodOptions.design`'s ``asked``) within a conservative *posture band* (:data:`SWING_BAND`, given for a
  right leg, the hip's mirrored for a left one) intersected with its URDF range less :attr:`TripodOptions.margin`,
  and below :attr:`TripodOptions.velocity`. The band keeps the knee bent (the foot tucked up), the hip abducted
  outward and the thigh within a range that keeps the foot away from the other legs; :func:`tripod_reference`
  checks on the solved motion that the foot's sphere stays :attr:`TripodOptions.clearance` above the ground and
  the swing leg's foot and knee :attr:`TripodOptions.spacing` away from the other legs' feet and knees
  (ModelError otherwise).
* **The floating base and the three stance legs** (``6 + 9`` unknowns) come from a square inverse kinematics per
  sample (:mod:`wbfriction.walking.tripod_support`, which ``simulate --play`` reruns on the set-points table's series:
  Newton iterations, Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians), fifteen tasks: the three stance feet's
  contact frame origins at their footprints (9), the centre of mass over the *incentre* of the stance triangle (the
  point farthest from its edges) at the standing height (3), the base upright and facing forward (3). Velocities
  from ``J v = 0``, accelerations from ``J a = -Jd v`` (the targets are constant), so that the reference keeps
  the stance feet still at the acceleration level. *Quasi-static*: the centre of mass, not the zero-moment point,
  is held inside the triangle (:attr:`TripodOptions.com_margin` from its edges); the ZMP of the reference's own
  dynamics (:func:`~wbfriction.walking.single_support.zero_moment_point`, on the ground) is computed and must stay
  :attr:`TripodOptions.zmp_margin` inside the triangle (ModelError otherwise): the swing leg's velocity cap is
  what keeps it there. (The Go2 ``go2_walking``, the default options, each leg swung in turn: the centre of mass
  held 104 mm inside the triangle's edges (its inradius), the ZMP at least 100 mm; the swing foot's sphere 59-94 mm
  above the ground at its lowest, the swing leg 97-210 mm from the others.)

The feet stand where the robot's reference posture puts them (moved together along the base so that their centre
lies under the centre of mass, as :func:`~wbfriction.walking.quadruped.quadruped_reference` does), the base
:attr:`TripodOptions.height` above the ground. The motion starts at rest on three feet (the series is at rest at
``t = 0``) with the swing foot already in the air: both quadruped simulators accept that (the ideal one anchors
the feet down at the first sample; MuJoCo starts from the reference's first state), so no transition from four
feet is planned. The reference's ``options`` is a :class:`~wbfriction.walking.quadruped.GaitOptions` of the
``stand`` gait (the simulators read its sample period; the log's metadata records it).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.one_foot import zero_moment_point
from wbfriction.excite.swing import design_swing, posture_band, series_bounds, swing_noise
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.model.robot import Robot
from wbfriction.sim.quadruped import default_quadruped_friction
from wbfriction.walking.fourier import FourierTrajectory
from wbfriction.walking.quadruped import FOOT_RADIUS, QuadrupedReference
from wbfriction.walking.tripod_support import (  # noqa: F401 (TripodIK, leg_points, LWA: this module's names too)
    LWA,
    TripodIK,
    TripodMotion,
    incentre,
    leg_points,
    standing_feet,
    triangle_margin,
    tripod_support_reference,
)

SWING_BAND: dict[str, tuple[float, float]] = {
    "hip": (-0.5, -0.05),
    "thigh": (0.4, 1.4),
    "calf": (-2.6, -2.0),
}
"""The swing leg's posture band [rad] per joint group, for a *right* leg (the Go2's conventions: a negative hip
angle moves a right foot outward; a left leg's hip band is negated): the knee bent more than standing (-1.44 rad),
the hip abducted, the thigh such that a rear foot stays behind the front knee. On the Go2 with its base 0.30 m up,
the foot's sphere stays at least 52 mm above the ground over the whole box (measured on a grid of its corners and
inside)."""
MIRRORED = ("hip",)
"""The groups whose band changes sign from a right leg to a left one."""


@dataclass(frozen=True)
class TripodOptions:
    """What :func:`tripod_reference` builds.

    Attributes:
        swing: the leg lifted and excited: its foot's index in :attr:`Robot.contact_frames` or its leg's name (the
            foot frame's name before its first ``_``, e.g. ``"FR"`` for ``FR_foot``).
        design: each swing joint's design (:class:`~.design.ExciteOptions`: the recording's duration and rate, the
            series' period (a whole number per recording) and harmonics, the share of each URDF velocity limit, the
            friction parameters asked, the starts and seed; its range share is not read: the band is
            :data:`SWING_BAND`'s). Its rate is the reference's (the quadruped simulators' usual 500 Hz).
        velocity: the cap on each swing joint's speed [rad/s] (also at most the design's velocity share of its URDF
            limit).
        margin: how far inside its URDF range each swing joint stays [rad].
        height: the base's height above the ground in the standing posture [m] (the centre of mass's target height
            follows from it).
        com_margin: the least distance of the centre of mass to the stance triangle's edges [m].
        zmp_margin: the least distance of the reference's ZMP to the stance triangle's edges [m].
        clearance: the least height of the swing foot's sphere (its contact frame's origin less
            :data:`~wbfriction.walking.quadruped.FOOT_RADIUS`) above the ground [m].
        spacing: the least distance of the swing leg's foot and knee to the other legs' feet and knees [m].
        torque_noise: the design's torque noise [N·m]; position_noise: its position noise [rad].

    Raises:
        InputError: a swing that is neither a foot index nor a name, a cap or a height that is not > 0.
    """

    swing: int | str = "FR"
    design: ExciteOptions = ExciteOptions(duration=8.0, rate=500.0, period=4.0, harmonics=5, range_share=1.0)
    velocity: float = 3.0
    margin: float = 0.05
    height: float = 0.30
    com_margin: float = 0.05
    zmp_margin: float = 0.03
    clearance: float = 0.03
    spacing: float = 0.05
    torque_noise: float = 0.05
    position_noise: float = 1e-4

    def __post_init__(self) -> None:
        if isinstance(self.swing, bool) or not isinstance(self.swing, (int, str)):
            raise InputError(f"--swing {self.swing!r}: a foot's index or a leg's name (e.g. FR)")
        for name in ("velocity", "height"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"--{name} {value!r}: must be > 0")


@dataclass(frozen=True)
class TripodExcitation:
    """A three-feet stance with the fourth leg excited.

    Attributes:
        reference: the quadruped reference (N samples at the design's rate): ``contact`` has the three stance feet,
            ``feet`` their footprints and the swing foot's path (contact frame origins [m], world).
        swing: the swing foot's index in :attr:`Robot.contact_frames`; stance: the three others (increasing).
        joints: the swing leg's joints (the robot's actuated order); trajectory: their series.
        lower, upper: each swing joint's band [rad] (the posture band within its URDF range less the margin).
        triangle: the stance feet's footprints on the ground (3, 2) [m], world, in :attr:`stance` order.
        com_margin: the least distance of the centre of mass to the triangle's edges [m].
        zmp_margin: the least distance of the ZMP to the triangle's edges [m] (negative: outside).
        clearance: the least height of the swing foot's sphere above the ground [m].
        spacing: the least distance of the swing leg's foot and knee to the other legs' feet and knees [m].
    """

    reference: QuadrupedReference
    swing: int
    stance: tuple[int, ...]
    joints: tuple[str, ...]
    trajectory: FourierTrajectory
    lower: np.ndarray
    upper: np.ndarray
    triangle: np.ndarray
    com_margin: float
    zmp_margin: float
    clearance: float
    spacing: float


def swing_foot(robot: Robot, swing: int | str) -> int:
    """The index in :attr:`Robot.contact_frames` of the foot ``swing`` names (an index, a leg's name such as
    ``"FR"``, or the foot frame's name).

    Raises:
        ModelError: a robot without a floating base and four contact frames; InputError: no such foot.
    """
    frames = robot.contact_frames
    if not robot.floating_base or len(frames) != 4:
        raise ModelError(f"robot '{robot.name}': a three-feet stance needs a floating base and four feet, got "
                         f"{len(frames)}")
    names = [f.split("_")[0] for f in frames]
    if isinstance(swing, str):
        if swing in frames or swing in names:
            return frames.index(swing) if swing in frames else names.index(swing)
    elif 0 <= swing < 4:
        return int(swing)
    raise InputError(f"--swing {swing!r}: one of {', '.join(names)} (or 0-3)")


def swing_band(robot: Robot, joints: tuple[str, ...], left: bool, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Each swing joint's band (n,), (n,) [rad]: :data:`SWING_BAND` of its group (mirrored for a ``left`` leg,
    :data:`MIRRORED`) within its URDF range less ``margin`` (:func:`~.swing.posture_band`).

    Raises:
        InputError: a joint whose group has no band, or whose band leaves no room within its range.
    """
    return posture_band(robot, joints, SWING_BAND, MIRRORED if left else (), margin)


def tripod_reference(robot: Robot, options: TripodOptions = TripodOptions(),
                     prior: Mapping[str, ModelParamsBase] | None = None) -> TripodExcitation:
    """Stand on three feet for the design's duration while the fourth leg follows its designed series (module
    docstring).

    Args:
        robot: a quadruped on point feet (four contact frames, three joints per leg, its leg joints in groups of
            :data:`SWING_BAND`), e.g. the built-in ``go2_walking``.
        options: :class:`TripodOptions`.
        prior: per swing joint, the friction its design's bound is taken at; default: the quadruped simulators'
            default friction (:func:`~wbfriction.sim.quadruped.default_quadruped_friction`).

    Returns:
        A :class:`TripodExcitation` of ``duration x rate`` samples.

    Raises:
        InputError: no such swing leg, a swing joint without band or prior, a period that does not divide the
            duration; ModelError: not such a quadruped, the IK out of reach, the centre of mass or the ZMP too near
            the triangle's edges, the swing foot too low or too near another leg, a joint outside its URDF range.
    """
    swing = swing_foot(robot, options.swing)
    stance = [c for c in range(4) if c != swing]
    joints = robot.limb(robot.contact_frames[swing])
    prior = default_quadruped_friction(robot) if prior is None else prior
    if missing := [j for j in joints if j not in prior]:
        raise InputError(f"no prior friction for swing joint '{missing[0]}'")
    feet = standing_feet(robot)
    _, inradius = incentre(feet[stance, :2])
    if inradius < options.com_margin:
        raise ModelError(f"the stance triangle's incentre is {inradius * 1e3:.1f} mm from its edges (at least "
                         f"{options.com_margin * 1e3:.1f} mm asked): lower --com-margin")
    band = swing_band(robot, joints, bool(feet[swing, 1] > 0), options.margin)
    noise = swing_noise(robot, joints, options, robot.configuration(robot.reference_angles))
    trajectory = design_swing(robot, joints, band, prior, options, noise)
    motion = tripod_support_reference(robot, swing, joints, trajectory, options.design.times(), options.height)
    return _checked(robot, options, swing, (joints, trajectory, band), motion)


def swing_spacing(swing: int, feet: np.ndarray, knees: np.ndarray) -> float:
    """The least distance [m] of the swing leg's foot and knee to the other legs' feet and knees, from their
    positions (N, 4, 3) each."""
    others = [c for c in range(4) if c != swing]
    mine = np.stack([feet[:, swing], knees[:, swing]], axis=1)[:, :, None]  # (N, 2, 1, 3)
    theirs = np.concatenate([feet[:, others], knees[:, others]], axis=1)[:, None]  # (N, 1, 6, 3)
    return float(np.linalg.norm(mine - theirs, axis=-1).min())


def _checked(robot: Robot, options: TripodOptions, swing: int,
             design: tuple[tuple[str, ...], FourierTrajectory, tuple[np.ndarray, np.ndarray]],
             motion: TripodMotion) -> TripodExcitation:
    """The :class:`TripodExcitation` of a solved motion, its centre of mass, ZMP, clearance, spacing and joints'
    ranges checked."""
    Q, V, A = motion.q, motion.v, motion.a
    joints, trajectory, band = design
    stance = tuple(c for c in range(4) if c != swing)
    triangle = motion.triangle
    model, data = robot.model, robot.model.createData()
    com = np.array([pin.centerOfMass(model, data, q) for q in Q])
    com_margin = triangle_margin(com[:, :2], triangle)
    zmp_margin = triangle_margin(zero_moment_point(robot, Q, V, A), triangle)
    if zmp_margin < options.zmp_margin:
        raise ModelError(f"the ZMP comes within {zmp_margin * 1e3:.1f} mm of the stance triangle's edge (at least "
                         f"{options.zmp_margin * 1e3:.1f} mm asked): lower --velocity")
    clearance = float(motion.feet[:, swing, 2].min()) - FOOT_RADIUS
    if clearance < options.clearance:
        raise ModelError(f"the swing foot comes {clearance * 1e3:.1f} mm above the ground (at least "
                         f"{options.clearance * 1e3:.1f} mm asked): raise --height or lower --clearance")
    spacing = swing_spacing(swing, motion.feet, motion.knees)
    if spacing < options.spacing:
        raise ModelError(f"the swing leg comes {spacing * 1e3:.1f} mm from another leg (at least "
                         f"{options.spacing * 1e3:.1f} mm asked): lower --spacing")
    lo, hi = robot.angle_limits
    angles = robot.angles(Q)
    if np.any(angles < lo) or np.any(angles > hi):
        worst = int(np.argmax(np.maximum(lo - angles, angles - hi).max(axis=0)))
        raise ModelError(f"joint '{robot.actuated[worst]}' leaves its URDF range on three feet: lower --height")
    return TripodExcitation(motion.reference, swing, stance, joints, trajectory, band[0], band[1], triangle,
                            com_margin, zmp_margin, clearance, spacing)


def swing_bounds(robot: Robot, excitation: TripodExcitation, options: TripodOptions,
                 prior: Mapping[str, ModelParamsBase] | None = None) -> dict[str, dict[str, float]]:
    """Each swing joint's Cramér-Rao bound of its friction's parameters on the designed motion [their units]
    (:func:`~.swing.series_bounds`: its prior friction, as its design takes it (default the quadruped simulators'
    default), the options' noise at the reference posture), per joint and parameter name (``F_c`` [N·m], ``F_v``
    [N·m·s/rad], ...)."""
    prior = default_quadruped_friction(robot) if prior is None else prior
    noise = swing_noise(robot, excitation.joints, options, robot.configuration(robot.reference_angles))
    return series_bounds(excitation.joints, excitation.trajectory, excitation.reference.time, prior, noise)

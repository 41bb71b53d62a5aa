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
  sample (Newton iterations, Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians), fifteen tasks: the three stance feet's
  contact frame origins at their footprints (9), the centre of mass over the *incentre* of the stance triangle (the
  point farthest from its edges) at the standing height (3), the base upright and facing forward (3). Velocities
  from ``J v = 0``, accelerations from ``J a = -Jd v`` (the targets are constant), so that the reference keeps
  the stance feet still at the acceleration level. *Quasi-static*: the centre of mass, not the zero-moment point,
  is held inside the triangle (:attr:`TripodOptions.com_margin` from its edges); the ZMP of the reference's own
  dynamics (:func:`~.stance.zero_moment_point`, on the ground) is computed and must stay
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
from wbfriction.excite.design import ExciteOptions, design_joint
from wbfriction.excite.stance import SLACK, zero_moment_point
from wbfriction.excite.trajectory import FourierSpace
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.noise import NoiseModel
from wbfriction.model.robot import Robot
from wbfriction.sim.arm import FourierTrajectory
from wbfriction.sim.quadruped import default_quadruped_friction
from wbfriction.walking.quadruped import FOOT_RADIUS, GaitOptions, QuadrupedReference

LWA = pin.LOCAL_WORLD_ALIGNED

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
    """Each swing joint's band (n,), (n,) [rad]: :data:`SWING_BAND` of its group (mirrored for a ``left`` leg)
    within its URDF range less ``margin``.

    Raises:
        InputError: a joint whose group has no band, or whose band leaves no room within its range.
    """
    lo_urdf, hi_urdf = robot.angle_limits
    lower, upper = np.empty(len(joints)), np.empty(len(joints))
    for i, joint in enumerate(joints):
        group = robot.group_of(joint)
        if group not in SWING_BAND:
            raise InputError(f"swing joint '{joint}' (group {group!r}) has no posture band: one of "
                             f"{sorted(SWING_BAND)}")
        lo, hi = SWING_BAND[group]
        if left and group in MIRRORED:
            lo, hi = -hi, -lo
        a = robot.actuated.index(joint)
        lower[i], upper[i] = max(lo, lo_urdf[a] + margin), min(hi, hi_urdf[a] - margin)
        if not upper[i] > lower[i]:
            raise InputError(f"swing joint '{joint}': its band [{lo:g}, {hi:g}] rad leaves no room within its "
                             f"range [{lo_urdf[a]:g}, {hi_urdf[a]:g}] less {margin:g} rad")
    return lower, upper


def design_swing(robot: Robot, joints: tuple[str, ...], band: tuple[np.ndarray, np.ndarray],
                 prior: Mapping[str, ModelParamsBase], options: TripodOptions) -> FourierTrajectory:
    """The swing joints' series (n joints): each designed alone by :func:`~.design.design_joint` within its band
    ``(lower, upper)`` (n,) each [rad] and below the velocity cap, for its ``prior`` friction and the options'
    noise (the joint's inertia: the mass matrix's diagonal at the reference posture), less
    :data:`~.stance.SLACK`."""
    excite = options.design
    space = FourierSpace(1, excite.harmonics, excite.omega)
    q0 = robot.configuration(robot.reference_angles)
    inertia = np.diag(pin.crba(robot.model, robot.model.createData(), q0))
    rng = np.random.default_rng(excite.seed)
    z = []
    for i, joint in enumerate(joints):
        a = robot.actuated.index(joint)
        iv = robot.act_v_index[a]
        velocity = min(options.velocity, excite.velocity_share * float(robot.model.velocityLimit[iv]))
        noise = NoiseModel(options.torque_noise, options.position_noise, float(inertia[iv]), 1.0 / excite.rate)
        z.append(design_joint(space, excite, float(band[0][i]) + SLACK[0], float(band[1][i]) - SLACK[0],
                              SLACK[1] * velocity, prior[joint], noise, rng))
    return FourierSpace(len(joints), excite.harmonics, excite.omega).trajectory(np.concatenate(z))


class TripodIK:
    """The square three-feet inverse kinematics of the module docstring, for one robot and swing foot.

    Args:
        robot: a quadruped (four point feet, three joints per leg); swing: the swing foot's index.
        feet: the stance feet's footprints (3, 3) [m], world, in increasing foot order; com: the centre of mass's
            target (3,) [m], world.

    Attributes:
        cols: the velocity indices solved (15,): the base's six, then the stance legs' joints.
        rest: every other velocity index (nv - 15,), in increasing order: the joints prescribed.

    Raises:
        ModelError: a stance leg of other than three joints.
    """

    def __init__(self, robot: Robot, swing: int, feet: np.ndarray, com: np.ndarray) -> None:
        self.robot, self.model, self.data = robot, robot.model, robot.model.createData()
        stance = [c for c in range(len(robot.contact_frames)) if c != swing]
        legs = [[robot.actuated.index(j) for j in robot.limb(robot.contact_frames[c])] for c in stance]
        if any(len(leg) != 3 for leg in legs):
            raise ModelError(f"robot '{robot.name}': a stance leg of other than 3 joints (the IK needs 3 per leg)")
        self.cols = np.concatenate([np.arange(6), robot.act_v_index[np.concatenate(legs)]])
        self.rest = np.setdiff1d(np.arange(self.model.nv), self.cols)
        self.frames = [robot.contact_frame_ids[c] for c in stance]
        self.feet, self.com = np.asarray(feet, dtype=float), np.asarray(com, dtype=float)

    def _system(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The task Jacobian (15, nv) and error (15,) at ``q``: the stance feet [m], the centre of mass [m], the
        base's rotation [rad]."""
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        J = np.zeros((15, model.nv))
        for i, f in enumerate(self.frames):
            J[3 * i:3 * i + 3] = pin.getFrameJacobian(model, data, f, LWA)[:3]
        J[9:12] = pin.jacobianCenterOfMass(model, data, True)
        R = data.oMi[1].rotation
        J[12:15, 3:6] = R
        e = np.concatenate([*(p - data.oMf[f].translation for p, f in zip(self.feet, self.frames)),
                            self.com - data.com[0], pin.log3(R.T)])
        return J, e

    def solve(self, q: np.ndarray, v_rest: np.ndarray, a_rest: np.ndarray, tol: float = 1e-11,
              max_iter: int = 50) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The configuration (nq,), velocity and acceleration (nv,) whose joints outside the base and the stance
        legs are those of ``q`` (a guess of the rest), ``v_rest`` and ``a_rest`` (on :attr:`rest`).

        Raises:
            ModelError: the Newton iterations do not converge (the target out of reach).
        """
        model, data, cols = self.model, self.data, self.cols
        for _ in range(max_iter):
            J, e = self._system(q)
            if np.max(np.abs(e)) < tol:
                break
            dv = np.zeros(model.nv)
            dv[cols] = np.linalg.solve(J[:, cols], e)
            q = pin.integrate(model, q, dv)
        else:
            raise ModelError(f"three-feet stance IK did not converge (residual {np.max(np.abs(e)):.2e}): "
                             "lower --height")
        Jc_inv, Jr = np.linalg.inv(J[:, cols]), J[:, self.rest]
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v[self.rest], a[self.rest] = v_rest, a_rest
        v[cols] = -Jc_inv @ (Jr @ v_rest)
        pin.centerOfMass(model, data, q, v, np.zeros(model.nv))  # drift: zero acceleration
        pin.updateFramePlacements(model, data)
        drift = np.concatenate([*(pin.getFrameClassicalAcceleration(model, data, f, LWA).linear
                                  for f in self.frames), data.acom[0], np.zeros(3)])
        a[cols] = -Jc_inv @ (drift + Jr @ a_rest)
        return q, v, a


def triangle_margin(points: np.ndarray, triangle: np.ndarray) -> float:
    """The least signed distance [m] of the points ``points`` (N, 2) to the edges of the triangle ``triangle``
    (3, 2) (world, on the ground): positive inside, negative for a point outside."""
    points, triangle = np.atleast_2d(points), np.asarray(triangle, dtype=float)
    centre = triangle.mean(axis=0)
    worst = np.inf
    for i in range(3):
        a, b = triangle[i], triangle[(i + 1) % 3]
        normal = np.array([b[1] - a[1], a[0] - b[0]]) / np.linalg.norm(b - a)
        if normal @ (centre - a) < 0:
            normal = -normal  # inward
        worst = min(worst, float(np.min((points - a) @ normal)))
    return worst


def incentre(triangle: np.ndarray) -> tuple[np.ndarray, float]:
    """The triangle's (3, 2) incentre (2,) [m] (the point farthest from its edges) and its inradius [m]."""
    side = np.array([np.linalg.norm(triangle[(i + 1) % 3] - triangle[(i + 2) % 3]) for i in range(3)])
    centre = side @ triangle / side.sum()
    return centre, triangle_margin(centre[None], triangle)


def standing_feet(robot: Robot) -> np.ndarray:
    """The four feet's footprints (4, 3) [m], world: where the reference posture puts the contact frames about the
    base (its origin at x = y = 0), moved together along it so that their centre lies under the centre of mass, at
    :data:`~wbfriction.walking.quadruped.FOOT_RADIUS` above the ground."""
    model, data = robot.model, robot.model.createData()
    q = robot.configuration(robot.reference_angles)
    pin.framesForwardKinematics(model, data, q)
    feet = np.array([data.oMf[f].translation for f in robot.contact_frame_ids]) - q[:3]
    feet[:, 0] += pin.centerOfMass(model, data, q)[0] - q[0] - feet[:, 0].mean()
    feet[:, 2] = FOOT_RADIUS
    return feet


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
    stance = tuple(c for c in range(4) if c != swing)
    joints = robot.limb(robot.contact_frames[swing])
    prior = default_quadruped_friction(robot) if prior is None else prior
    if missing := [j for j in joints if j not in prior]:
        raise InputError(f"no prior friction for swing joint '{missing[0]}'")
    feet = standing_feet(robot)
    centre, inradius = incentre(feet[list(stance), :2])
    if inradius < options.com_margin:
        raise ModelError(f"the stance triangle's incentre is {inradius * 1e3:.1f} mm from its edges (at least "
                         f"{options.com_margin * 1e3:.1f} mm asked): lower --com-margin")
    band = swing_band(robot, joints, bool(feet[swing, 1] > 0), options.margin)
    trajectory = design_swing(robot, joints, band, prior, options)
    qs, qds, qdds = trajectory(options.design.times())
    model, data = robot.model, robot.model.createData()
    q = robot.configuration(robot.reference_angles)
    com_z = pin.centerOfMass(model, data, q)[2] - q[2] + options.height
    q[:3] = [centre[0], centre[1], options.height]
    act = np.array([robot.actuated.index(j) for j in joints])
    q[robot.act_q_index[act]] = qs[0]
    ik = TripodIK(robot, swing, feet[list(stance)], np.array([*centre, com_z]))
    motion = _solved(robot, ik, q, act, (qs, qds, qdds))
    return _checked(robot, options, swing, (joints, trajectory, band), feet, motion)


def _solved(robot: Robot, ik: TripodIK, q: np.ndarray, act: np.ndarray,
            swing: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The IK at every sample of the swing joints' motion (N, n) each (``act``: their actuated indices), from ``q``
    (the first guess)."""
    qs, qds, qdds = swing
    model = robot.model
    n = len(qs)
    Q, V, A = np.empty((n, model.nq)), np.empty((n, model.nv)), np.empty((n, model.nv))
    iq = robot.act_q_index[act]
    on_rest = np.searchsorted(ik.rest, robot.act_v_index[act])
    v_rest, a_rest = np.zeros(len(ik.rest)), np.zeros(len(ik.rest))
    for k in range(n):
        q = q.copy()
        q[iq] = qs[k]
        v_rest[on_rest], a_rest[on_rest] = qds[k], qdds[k]
        q, V[k], A[k] = ik.solve(q, v_rest, a_rest)
        Q[k] = q
    return Q, V, A


def leg_points(robot: Robot, motion: tuple[np.ndarray, np.ndarray, np.ndarray]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Along a motion ``(q, v, a)`` (N, nq), (N, nv), (N, nv): the feet's positions, velocities and accelerations
    (N, 4, 3) each (contact frame origins [m, m/s, m/s^2], world) and the knees' positions (N, 4, 3) [m] (each
    leg's last joint's origin)."""
    model, data = robot.model, robot.model.createData()
    knees = [model.getJointId(robot.limb(f)[-1]) for f in robot.contact_frames]
    out = np.empty((4, len(motion[0]), 4, 3))
    for k, (q, v, a) in enumerate(zip(*motion)):
        pin.forwardKinematics(model, data, q, v, a)
        pin.updateFramePlacements(model, data)
        for c, f in enumerate(robot.contact_frame_ids):
            out[0, k, c] = data.oMf[f].translation
            out[1, k, c] = pin.getFrameVelocity(model, data, f, LWA).linear
            out[2, k, c] = pin.getFrameClassicalAcceleration(model, data, f, LWA).linear
            out[3, k, c] = data.oMi[knees[c]].translation
    return out[0], out[1], out[2], out[3]


def swing_spacing(swing: int, feet: np.ndarray, knees: np.ndarray) -> float:
    """The least distance [m] of the swing leg's foot and knee to the other legs' feet and knees, from their
    positions (N, 4, 3) each."""
    others = [c for c in range(4) if c != swing]
    mine = np.stack([feet[:, swing], knees[:, swing]], axis=1)[:, :, None]  # (N, 2, 1, 3)
    theirs = np.concatenate([feet[:, others], knees[:, others]], axis=1)[:, None]  # (N, 1, 6, 3)
    return float(np.linalg.norm(mine - theirs, axis=-1).min())


def _checked(robot: Robot, options: TripodOptions, swing: int,
             design: tuple[tuple[str, ...], FourierTrajectory, tuple[np.ndarray, np.ndarray]], feet0: np.ndarray,
             motion: tuple[np.ndarray, np.ndarray, np.ndarray]) -> TripodExcitation:
    """The :class:`TripodExcitation` of a solved motion, its centre of mass, ZMP, clearance, spacing and joints'
    ranges checked."""
    Q, V, A = motion
    joints, trajectory, band = design
    stance = tuple(c for c in range(4) if c != swing)
    triangle = feet0[list(stance), :2]
    model, data = robot.model, robot.model.createData()
    com = np.array([pin.centerOfMass(model, data, q) for q in Q])
    com_margin = triangle_margin(com[:, :2], triangle)
    zmp_margin = triangle_margin(zero_moment_point(robot, Q, V, A), triangle)
    if zmp_margin < options.zmp_margin:
        raise ModelError(f"the ZMP comes within {zmp_margin * 1e3:.1f} mm of the stance triangle's edge (at least "
                         f"{options.zmp_margin * 1e3:.1f} mm asked): lower --velocity")
    feet, feet_v, feet_a, knees = leg_points(robot, motion)
    clearance = float(feet[:, swing, 2].min()) - FOOT_RADIUS
    if clearance < options.clearance:
        raise ModelError(f"the swing foot comes {clearance * 1e3:.1f} mm above the ground (at least "
                         f"{options.clearance * 1e3:.1f} mm asked): raise --height or lower --clearance")
    spacing = swing_spacing(swing, feet, knees)
    if spacing < options.spacing:
        raise ModelError(f"the swing leg comes {spacing * 1e3:.1f} mm from another leg (at least "
                         f"{options.spacing * 1e3:.1f} mm asked): lower --spacing")
    lo, hi = robot.angle_limits
    angles = robot.angles(Q)
    if np.any(angles < lo) or np.any(angles > hi):
        worst = int(np.argmax(np.maximum(lo - angles, angles - hi).max(axis=0)))
        raise ModelError(f"joint '{robot.actuated[worst]}' leaves its URDF range on three feet: lower --height")
    feet[:, list(stance)] = feet0[list(stance)]  # their footprints (the IK's residual below 1e-11 m)
    feet_v[:, list(stance)], feet_a[:, list(stance)] = 0.0, 0.0
    contact = np.ones((len(Q), 4), dtype=bool)
    contact[:, swing] = False
    excite = options.design
    gait = GaitOptions(gait="stand", duration=excite.duration, dt=1.0 / excite.rate, step_height=0.0, speed=0.0,
                       base_height=options.height)
    iq, iv = robot.act_q_index, robot.act_v_index
    reference = QuadrupedReference(gait, excite.times(), contact, Q[:, :7].copy(), feet, Q[:, iq], V[:, iv],
                                   A[:, iv], V[:, :6].copy(), A[:, :6].copy(), feet_v, feet_a)
    return TripodExcitation(reference, swing, stance, joints, trajectory, band[0], band[1], triangle, com_margin,
                            zmp_margin, clearance, spacing)

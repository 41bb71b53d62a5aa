"""A quadruped standing on three point feet while its fourth leg follows given Fourier series: the reference
(:class:`~wbfriction.walking.quadruped.QuadrupedReference`, three feet down from the first sample to the last) that
``wbfriction excite --swing`` designs (:mod:`wbfriction.excite.tripod`) and ``wbfriction simulate --play`` rebuilds
from the set-points table's swing foot, base height and series, sample for sample the same.

* **The swing leg** follows its series (:class:`~wbfriction.walking.fourier.FourierTrajectory`).
* **The floating base and the three stance legs** (``6 + 9`` unknowns) come from a square inverse kinematics per
  sample (:class:`TripodIK`: Newton iterations, Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians), fifteen tasks: the
  three stance feet's contact frame origins at their footprints (9), the centre of mass over the *incentre* of the
  stance triangle (the point farthest from its edges) at the standing height (3), the base upright and facing
  forward (3). Velocities from ``J v = 0``, accelerations from ``J a = -Jd v`` (the targets are constant), so that
  the reference keeps the stance feet still at the acceleration level. *Quasi-static*: the centre of mass, not the
  zero-moment point, is held inside the triangle.

The feet stand where the robot's reference posture puts them (moved together along the base so that their centre
lies under the centre of mass, as :func:`~wbfriction.walking.quadruped.quadruped_reference` does), the base
``height`` above the ground. The reference's ``options`` is a :class:`~wbfriction.walking.quadruped.GaitOptions` of
the ``stand`` gait (the simulators read its sample period; the log's metadata records it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.robot import Robot
from wbfriction.walking.fourier import FourierTrajectory
from wbfriction.walking.quadruped import FOOT_RADIUS, GaitOptions, QuadrupedReference
from wbfriction.walking.support_ik import LWA, SupportIK


class TripodIK(SupportIK):
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

    stance_name, hint = "three-feet", ": lower --height"

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

    def _feet_drift(self) -> np.ndarray:
        """The stance feet's classical linear accelerations (9,) at a zero acceleration: their tasks' ``Jd v``."""
        model, data = self.model, self.data
        pin.updateFramePlacements(model, data)
        return np.concatenate([pin.getFrameClassicalAcceleration(model, data, f, LWA).linear for f in self.frames])


@dataclass(frozen=True)
class TripodMotion:
    """A three-feet stance solved (:func:`tripod_support_reference`).

    Attributes:
        reference: the quadruped reference (N samples): ``contact`` has the three stance feet, ``feet`` their
            footprints and the swing foot's path (contact frame origins [m], world).
        q, v, a: the whole-body motion (N, nq), (N, nv), (N, nv) the IK solved.
        feet: the four feet's contact frame origins along it as solved (N, 4, 3) [m], world (the stance feet within
            the IK's tolerance, 1e-11 m, of their footprints); knees: each leg's last joint's origin (N, 4, 3) [m].
        triangle: the stance feet's footprints on the ground (3, 2) [m], world, in increasing foot order.
    """

    reference: QuadrupedReference
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    feet: np.ndarray
    knees: np.ndarray
    triangle: np.ndarray


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


def tripod_support_reference(robot: Robot, swing: int, joints: tuple[str, ...], trajectory: FourierTrajectory,
                             time: np.ndarray, height: float) -> TripodMotion:
    """Stand on the three feet other than ``swing`` (its index in :attr:`Robot.contact_frames`) at the evenly
    spaced ``time`` (N,) [s] from 0, the base ``height`` [m] above the ground, while ``joints`` (the swing leg's,
    n) follow ``trajectory`` (n joints) (module docstring).

    Returns:
        The :class:`TripodMotion`: its reference's gait options the ``stand`` gait's, ``dt`` the times' step,
        ``duration`` N of them, ``base_height`` ``height``.

    Raises:
        ModelError: not a quadruped on four point feet, a stance leg of other than three joints, the IK out of reach.
    """
    if not robot.floating_base or len(robot.contact_frames) != 4:
        raise ModelError(f"robot '{robot.name}': a three-feet stance needs a floating base and four feet, got "
                         f"{len(robot.contact_frames)}")
    time = np.asarray(time, dtype=float)
    stance = [c for c in range(4) if c != swing]
    feet0 = standing_feet(robot)
    centre, _ = incentre(feet0[stance, :2])
    qs, qds, qdds = trajectory(time)
    model, data = robot.model, robot.model.createData()
    q = robot.configuration(robot.reference_angles)
    com_z = pin.centerOfMass(model, data, q)[2] - q[2] + height
    q[:3] = [centre[0], centre[1], height]
    act = np.array([robot.actuated.index(j) for j in joints])
    q[robot.act_q_index[act]] = qs[0]
    ik = TripodIK(robot, swing, feet0[stance], np.array([*centre, com_z]))
    Q, V, A = ik.solve_motion(q, act, (qs, qds, qdds))
    solved, feet_v, feet_a, knees = leg_points(robot, (Q, V, A))
    feet = solved.copy()
    feet[:, stance] = feet0[stance]  # their footprints (the IK's residual below 1e-11 m)
    feet_v[:, stance], feet_a[:, stance] = 0.0, 0.0
    contact = np.ones((len(Q), 4), dtype=bool)
    contact[:, swing] = False
    dt = float(time[1] - time[0])
    gait = GaitOptions(gait="stand", duration=len(time) * dt, dt=dt, step_height=0.0, speed=0.0, base_height=height)
    iq, iv = robot.act_q_index, robot.act_v_index
    reference = QuadrupedReference(gait, time, contact, Q[:, :7].copy(), feet, Q[:, iq], V[:, iv], A[:, iv],
                                   V[:, :6].copy(), A[:, :6].copy(), feet_v, feet_a)
    return TripodMotion(reference, Q, V, A, solved, knees, feet0[stance, :2])

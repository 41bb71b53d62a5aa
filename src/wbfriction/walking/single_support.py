"""A humanoid standing on one foot while its other leg follows given Fourier series: the whole-body reference
(:class:`~wbfriction.walking.reference.WalkingReference`, single support from the first sample to the last) that
``wbfriction excite --stance`` designs (:mod:`wbfriction.excite.one_foot`) and ``wbfriction simulate --play``
rebuilds from the set-points table's stance foot and series, sample for sample the same.

* **The swing leg** follows its series (:class:`~wbfriction.walking.fourier.FourierTrajectory`).
* **Every other joint but the stance leg's** is held at the robot's reference posture (arms, torso, head).
* **The floating base and the stance leg** (``6 + 6`` unknowns) come from a square inverse kinematics per sample
  (:class:`SingleSupportIK`: Newton iterations, Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians), twelve tasks: the stance
  sole's placement (flat at its standing footprint, 6), the centre of mass over the sole's centre at the standing
  posture's height (3), the base upright (3). Velocities from ``J v = 0``, accelerations from ``J a = -Jd v`` (the
  targets are constant), so the reference keeps the stance sole still at the acceleration level. *Quasi-static*:
  the centre of mass, not the zero-moment point, is held over the sole; the reference's ``zmp`` is that of its
  own dynamics (:func:`zero_moment_point`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.footprint import sole_footprint
from wbfriction.model.robot import Robot
from wbfriction.walking.footsteps import FootstepPlan
from wbfriction.walking.fourier import FourierTrajectory
from wbfriction.walking.options import GaitOptions
from wbfriction.walking.reference import WalkingReference, standing_configuration
from wbfriction.walking.support_ik import LWA, SupportIK
from wbfriction.walking.swing import foot_placement

SIDES = ("left", "right")
"""The stance foot's names, in :attr:`Robot.contact_frames` order (a biped's left sole first)."""


class SingleSupportIK(SupportIK):
    """The square single-support inverse kinematics of the module docstring, for one robot and stance foot.

    Args:
        robot: a biped (two soles, six joints per leg); stance: the stance sole's index.
        sole: the stance sole's placement (flat on the ground, world frame); com: the centre-of-mass target (3,)
            [m], world frame.

    Attributes:
        cols: the velocity indices solved (12,): the base's six, then the stance leg's joints.
        rest: every other velocity index (nv - 12,), in increasing order: the joints prescribed.

    Raises:
        ModelError: a stance leg of other than six joints.
    """

    stance_name = "one-foot"

    def __init__(self, robot: Robot, stance: int, sole: pin.SE3, com: np.ndarray) -> None:
        self.robot, self.model, self.data = robot, robot.model, robot.model.createData()
        leg = [robot.actuated.index(j) for j in robot.limb(robot.contact_frames[stance])]
        if len(leg) != 6:
            raise ModelError(f"robot '{robot.name}': a stance leg of {len(leg)} joints, the IK needs 6")
        self.cols = np.concatenate([np.arange(6), robot.act_v_index[leg]])
        self.rest = np.setdiff1d(np.arange(self.model.nv), self.cols)
        self.frame = robot.contact_frame_ids[stance]
        self.sole, self.com = sole, np.asarray(com, dtype=float)
        self.base_R = pin.rpy.rpyToMatrix(0.0, 0.0, pin.rpy.matrixToRpy(sole.rotation)[2])

    def _system(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The task Jacobian (12, nv) and error (12,) at ``q``: sole (position [m], rotation [rad]), centre of
        mass [m], base rotation [rad]."""
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        J = np.zeros((12, model.nv))
        J[0:6] = pin.getFrameJacobian(model, data, self.frame, LWA)
        J[6:9] = pin.jacobianCenterOfMass(model, data, True)
        R = data.oMi[1].rotation
        J[9:12, 3:6] = R
        oMf = data.oMf[self.frame]
        e = np.concatenate([self.sole.translation - oMf.translation, pin.log3(self.sole.rotation @ oMf.rotation.T),
                            self.com - data.com[0], pin.log3(self.base_R @ R.T)])
        return J, e

    def _feet_drift(self) -> np.ndarray:
        """The stance sole's classical acceleration (6,) at a zero acceleration: its tasks' ``Jd v``."""
        return pin.getFrameClassicalAcceleration(self.model, self.data, self.frame, LWA).vector


def zero_moment_point(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The zero-moment point (N, 2) [m] on the ground (z = 0, world frame) of a motion ``q`` (N, nq), ``v``, ``a``
    (N, nv): where the contact wrench that the rate of the centroidal momentum asks
    (``pin.computeCentroidalMomentumTimeVariation``) has no horizontal moment."""
    model, data = robot.model, robot.model.createData()
    mass, g = pin.computeTotalMass(model), model.gravity.linear
    out = np.empty((len(q), 2))
    for k in range(len(q)):
        pin.computeCentroidalMomentumTimeVariation(model, data, q[k], v[k], a[k])
        force = data.dhg.linear - mass * g
        moment = data.dhg.angular + np.cross(data.com[0], force)  # about the world origin
        out[k] = -moment[1] / force[2], moment[0] / force[2]
    return out


def standing_feet(robot: Robot) -> np.ndarray:
    """Both soles' footprints at the standing posture (2, 4): x, y, z = 0 [m], yaw [rad], world frame."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, standing_configuration(robot))
    return np.array([[*data.oMf[f].translation[:2], 0.0, pin.rpy.matrixToRpy(data.oMf[f].rotation)[2]]
                     for f in robot.contact_frame_ids])


def single_support_ik(robot: Robot, stance: int) -> SingleSupportIK:
    """The :class:`SingleSupportIK` of sole ``stance`` (its index in :attr:`Robot.contact_frames`): the sole flat at its
    standing footprint, the centre of mass over the sole's centre at the standing posture's height."""
    q0 = standing_configuration(robot)
    sole = foot_placement(standing_feet(robot)[stance])
    centre, _ = sole_footprint(robot, robot.contact_frames[stance])
    height = pin.centerOfMass(robot.model, robot.model.createData(), q0)[2]
    return SingleSupportIK(robot, stance, sole, np.array([*sole.act(np.array([*centre, 0.0]))[:2], height]))


def single_support_reference(robot: Robot, stance: int, joints: tuple[str, ...], trajectory: FourierTrajectory,
                             time: np.ndarray) -> WalkingReference:
    """Stand on sole ``stance`` (its index in :attr:`Robot.contact_frames`) at the evenly spaced ``time`` (N,) [s]
    while ``joints`` (the swing leg's, n) follow ``trajectory`` (n joints) (module docstring).

    Returns:
        The reference: ``contact`` the stance foot only, ``feet`` the stance sole's standing footprint and the
        swing sole's pose (x, y, z [m], yaw [rad], world), ``com`` [m], ``zmp`` that of its own dynamics [m].

    Raises:
        ModelError: a stance leg of other than six joints, the IK out of reach.
    """
    time = np.asarray(time, dtype=float)
    qs, qds, qdds = trajectory(time)
    feet0 = standing_feet(robot)
    model, data = robot.model, robot.model.createData()
    act = np.array([robot.actuated.index(j) for j in joints])
    q = standing_configuration(robot)
    q[robot.act_q_index[act]] = qs[0]
    Q, V, A = single_support_ik(robot, stance).solve_motion(q, act, (qs, qds, qdds))
    feet = np.empty((len(Q), 2, 4))
    feet[:, stance] = feet0[stance]
    swing = robot.contact_frame_ids[1 - stance]
    coms = np.empty((len(Q), 3))
    for k in range(len(Q)):
        coms[k] = pin.centerOfMass(model, data, Q[k])
        pin.updateFramePlacement(model, data, swing)
        M = data.oMf[swing]
        feet[k, 1 - stance] = [*M.translation, np.arctan2(M.rotation[1, 0], M.rotation[0, 0])]
    contact = np.zeros((len(Q), 2), dtype=bool)
    contact[:, stance] = True
    plan = FootstepPlan(feet0[:, [0, 1, 3]], (), float(len(time) * (time[1] - time[0])), GaitOptions())
    return WalkingReference(time, Q, V, A, contact, feet, coms, zero_moment_point(robot, Q, V, A), plan)

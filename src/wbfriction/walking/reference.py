"""Walking reference: footsteps, ZMP, centre of mass, swing feet and whole-body IK.

At every control sample the whole-body inverse kinematics solves, for the floating base
and the leg joints, the square system of tasks (all in the world frame, Pinocchio's
``LOCAL_WORLD_ALIGNED`` Jacobians):

* both soles: position and orientation (flat, with the planned yaw),
* the centre of mass: the LIPM trajectory at height ``z_c``,
* the base orientation: upright, with the mean yaw of the feet,

while every other joint follows a prescribed trajectory (the reference posture; a slow
sine on the position-controlled joints). Positions are solved by Newton iterations,
velocities from ``J v = xd`` and accelerations from ``J a = xdd - Jd v``, so the
reference ``(q, v, a)`` satisfies the contact constraints to machine precision at the
acceleration level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.walking.com import lipm_com, zmp_reference
from wbfriction.walking.footsteps import FootstepPlan, plan_footsteps
from wbfriction.walking.options import GaitOptions
from wbfriction.walking.swing import feet_trajectory, foot_placement, quintic

LWA = pin.LOCAL_WORLD_ALIGNED


@dataclass
class WalkingReference:
    """A planned walk sampled at the control rate.

    Attributes:
        time: (N,) [s].
        q: configurations (N, nq) (Pinocchio layout: base x, y, z, quaternion x, y, z, w, joints).
        v: velocities (N, nv) (base twist in the base frame, joint velocities).
        a: accelerations (N, nv).
        contact: planned contact flags (N, 2) in :attr:`Robot.contact_frames` order.
        feet: planned sole poses (N, 2, 4): x, y, z [m], yaw [rad], world frame.
        com: centre-of-mass reference (N, 3) [m]; zmp: ZMP reference (N, 2) [m].
        plan: the footstep plan.
    """

    time: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    contact: np.ndarray
    feet: np.ndarray
    com: np.ndarray
    zmp: np.ndarray
    plan: FootstepPlan

    @property
    def dt(self) -> float:
        return float(self.time[1] - self.time[0])

    def __len__(self) -> int:
        return len(self.time)


def standing_configuration(robot: Robot) -> np.ndarray:
    """Reference posture with the soles' midpoint at the world origin, on the ground (z = 0).

    Raises:
        InputError: not two contact frames; ModelError: a sole tilted by more than 0.05 rad.
    """
    if len(robot.contact_frames) != 2:
        raise InputError(f"robot '{robot.name}': walking needs exactly two contact frames (feet)")
    model, data = robot.model, robot.model.createData()
    q = robot.configuration(robot.reference_angles)
    pin.framesForwardKinematics(model, data, q)
    soles = [data.oMf[f] for f in robot.contact_frame_ids]
    for s in soles:
        if s.rotation[2, 2] < np.cos(0.05):  # the IK flattens small tilts
            raise ModelError(f"robot '{robot.name}': the soles are not flat in the reference posture")
    mid = 0.5 * (soles[0].translation + soles[1].translation)
    q[:3] -= mid
    return q


def _planar(placement: pin.SE3) -> np.ndarray:
    R = placement.rotation
    return np.array([placement.translation[0], placement.translation[1], np.arctan2(R[1, 0], R[0, 0])])


def _prescribed(robot: Robot, time: np.ndarray, amplitude: float, period: float = 4.0,
                ramp: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angles, velocities, accelerations (N, n_act) of the joints the IK does not solve:
    the reference posture, plus a sine of ``amplitude`` faded in over ``ramp`` seconds on
    the position-controlled joints (clipped to their range)."""
    n = len(time)
    q = np.tile(robot.reference_angles, (n, 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    if amplitude and robot.pc_index.size:
        lo, hi = robot.angle_limits
        q0 = robot.reference_angles[robot.pc_index]
        room = np.minimum(hi[robot.pc_index] - q0, q0 - lo[robot.pc_index])
        amp = np.minimum(amplitude, 0.8 * np.maximum(room, 0.0))
        w = 2 * np.pi / period
        e, de, dde = quintic(time / ramp)
        de, dde = de / ramp, dde / ramp**2
        s, c = np.sin(w * time), np.cos(w * time)
        q[:, robot.pc_index] += np.outer(e * s, amp)
        qd[:, robot.pc_index] = np.outer(de * s + e * w * c, amp)
        qdd[:, robot.pc_index] = np.outer(dde * s + 2 * de * w * c - e * w**2 * s, amp)
    return q, qd, qdd


class _WholeBodyIK:
    """The square IK of the module docstring for one robot."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        legs = sorted({robot.actuated.index(j) for f in robot.contact_frames for j in robot.limb(f)})
        self.solved_act = np.array(legs, dtype=int)
        self.free_act = np.array([i for i in range(robot.n_act) if i not in legs], dtype=int)
        iv = robot.act_v_index
        self.sel = np.concatenate([np.arange(6), iv[self.solved_act]])
        self.rest = iv[self.free_act]
        self.iq_free = robot.act_q_index[self.free_act]
        if self.sel.size != 18:
            raise ModelError(f"robot '{robot.name}': walking IK needs 6 joints per leg, got {self.sel.size - 6}")

    def _jacobian(self, q: np.ndarray) -> np.ndarray:
        """Task Jacobian (18, nv): sole poses, centre of mass, base rotation."""
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        J = np.empty((18, model.nv))
        for i, f in enumerate(self.robot.contact_frame_ids):
            J[6 * i:6 * i + 6] = pin.getFrameJacobian(model, data, f, LWA)
        J[12:15] = pin.jacobianCenterOfMass(model, data, True)
        J[15:18] = pin.getJointJacobian(model, data, 1, LWA)[3:]
        return J

    def _error(self, targets: list[pin.SE3], com: np.ndarray, base_R: np.ndarray) -> np.ndarray:
        data = self.data
        e = np.empty(18)
        for i, f in enumerate(self.robot.contact_frame_ids):
            M = data.oMf[f]
            e[6 * i:6 * i + 3] = targets[i].translation - M.translation
            e[6 * i + 3:6 * i + 6] = pin.log3(targets[i].rotation @ M.rotation.T)
        e[12:15] = com - data.com[0]
        e[15:18] = pin.log3(base_R @ data.oMi[1].rotation.T)
        return e

    def solve(self, q_guess: np.ndarray, free: tuple[np.ndarray, np.ndarray, np.ndarray],
              feet: np.ndarray, feet_d: np.ndarray, feet_dd: np.ndarray, com: tuple,
              yaw: tuple[float, float, float], tol: float = 1e-11, max_iter: int = 20):
        """Configuration, velocity and acceleration at one sample (see module docstring)."""
        model, data = self.model, self.data
        q = q_guess.copy()
        q[self.iq_free] = free[0]
        targets = [foot_placement(feet[i]) for i in range(2)]
        base_R = foot_placement(np.array([0.0, 0.0, 0.0, yaw[0]])).rotation
        for _ in range(max_iter):
            J = self._jacobian(q)
            e = self._error(targets, com[0], base_R)
            if np.max(np.abs(e)) < tol:
                break
            dv = np.zeros(model.nv)
            dv[self.sel] = np.linalg.solve(J[:, self.sel], e)
            q = pin.integrate(model, q, dv)
        else:
            raise ModelError(f"whole-body IK did not converge (residual {np.max(np.abs(e)):.2e}): "
                             "is the step reachable?")
        Js, Jr = J[:, self.sel], J[:, self.rest]
        Js_inv = np.linalg.inv(Js)
        xd = np.concatenate([feet_d[0, :3], [0, 0, feet_d[0, 3]], feet_d[1, :3], [0, 0, feet_d[1, 3]],
                             com[1], [0, 0, yaw[1]]])
        v = np.zeros(model.nv)
        v[self.rest] = free[1]
        v[self.sel] = Js_inv @ (xd - Jr @ free[1])
        # drift Jd v: classical accelerations at zero joint acceleration
        pin.centerOfMass(model, data, q, v, np.zeros(model.nv))
        drift = np.zeros(18)
        for i, f in enumerate(self.robot.contact_frame_ids):
            drift[6 * i:6 * i + 6] = pin.getFrameClassicalAcceleration(model, data, f, LWA).vector
        drift[12:15] = data.acom[0]
        xdd = np.concatenate([feet_dd[0, :3], [0, 0, feet_dd[0, 3]], feet_dd[1, :3], [0, 0, feet_dd[1, 3]],
                              com[2], [0, 0, yaw[2]]])
        a = np.zeros(model.nv)
        a[self.rest] = free[2]
        a[self.sel] = Js_inv @ (xdd - drift - Jr @ free[2])
        return q, v, a


def walking_reference(robot: Robot, options: GaitOptions = GaitOptions(), dt: float = 1e-3,
                      progress: Progress | None = None) -> WalkingReference:
    """Plan a walk and sample its whole-body reference at the control rate.

    Args:
        robot: a biped: two contact frames (left, right soles) with six joints in each leg.
        options: :class:`~wbfriction.walking.footsteps.GaitOptions`.
        dt: control period [s].
        progress: optional callable receiving numbers of samples done.

    Raises:
        InputError: not two contact frames; ModelError: soles not flat in the reference
        posture, or a step out of reach (IK does not converge).
    """
    model = robot.model
    q0 = standing_configuration(robot)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    feet0 = np.array([_planar(data.oMf[f]) for f in robot.contact_frame_ids])
    plan = plan_footsteps(feet0, options)
    n = int(round(plan.duration / dt)) + 1
    time = np.arange(n) * dt

    com0 = pin.centerOfMass(model, data, q0)
    z_c = options.com_height if options.com_height is not None else com0[2] - options.com_lowering
    zmp = zmp_reference(plan, time)
    c, cd, cdd = lipm_com(zmp, dt, z_c)
    com = np.column_stack([c, np.full(n, z_c)])
    com_d = np.column_stack([cd, np.zeros(n)])
    com_dd = np.column_stack([cdd, np.zeros(n)])
    feet, feet_d, feet_dd = feet_trajectory(plan, time)
    yaw = feet[:, :, 3].mean(1), feet_d[:, :, 3].mean(1), feet_dd[:, :, 3].mean(1)
    free_q, free_qd, free_qdd = _prescribed(robot, time, options.pc_amplitude)

    ik = _WholeBodyIK(robot)
    Q = np.empty((n, model.nq))
    V = np.empty((n, model.nv))
    A = np.empty((n, model.nv))
    q, v, a = q0, np.zeros(model.nv), np.zeros(model.nv)
    for k in counted(n, progress):
        guess = pin.integrate(model, q, v * dt + 0.5 * a * dt**2)
        free = (free_q[k, ik.free_act], free_qd[k, ik.free_act], free_qdd[k, ik.free_act])
        q, v, a = ik.solve(guess, free, feet[k], feet_d[k], feet_dd[k], (com[k], com_d[k], com_dd[k]),
                           (yaw[0][k], yaw[1][k], yaw[2][k]))
        Q[k], V[k], A[k] = q, v, a
    return WalkingReference(time, Q, V, A, plan.contact(time), feet, com, zmp, plan)

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
from numpy.linalg import _umath_linalg

from wbfriction.exceptions import InputError, ModelError
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.walking.com import lipm_com, zmp_reference
from wbfriction.walking.footsteps import FootstepPlan, plan_footsteps
from wbfriction.walking.indexing import as_slice
from wbfriction.walking.options import GaitOptions
from wbfriction.walking.swing import feet_trajectory, quintic

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


@dataclass
class _Tasks:
    """The IK's targets at every sample (N samples), in the row order of :meth:`_WholeBodyIK._jacobian`.

    Attributes:
        sole_R: sole rotations (N, 2, 3, 3), flat with the planned yaw; sole_p: positions (N, 2, 3) [m].
        com: centre of mass (N, 3) [m]; base_R: base rotation (N, 3, 3), upright with the feet's mean yaw.
        xd: task velocities (N, 18) (feet: linear [m/s], angular [rad/s]; centre of mass; base angular);
        xdd: task accelerations (N, 18).
        free: angles (N, n_free), velocities and accelerations of the joints the IK does not solve.
    """

    sole_R: np.ndarray
    sole_p: np.ndarray
    com: np.ndarray
    base_R: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    free: tuple[np.ndarray, np.ndarray, np.ndarray]


def yaw_rotations(yaw: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about the vertical by ``yaw`` (...) [rad], as
    :func:`~wbfriction.walking.swing.foot_placement`'s."""
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.zeros(yaw.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def _task_rates(feet: np.ndarray, com: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Task velocities or accelerations (N, 18) from the feet's x, y, z, yaw rates (N, 2, 4), the
    centre of mass's (N, 3) and the base yaw's (N,): feet and base turn about the vertical only."""
    x = np.zeros((len(com), 18))
    for i in range(2):
        x[:, 6 * i:6 * i + 3] = feet[:, i, :3]
        x[:, 6 * i + 5] = feet[:, i, 3]
    x[:, 12:15] = com
    x[:, 17] = yaw
    return x


def _solve(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``A^-1 b`` for one small square system: the LAPACK routine of ``np.linalg.solve`` without
    its per-call checks (half its time at 18 x 18; a singular ``A`` gives inf or nan, which
    the IK's convergence test then reports)."""
    return _umath_linalg.solve1(A, b)


class _WholeBodyIK:
    """The square IK of the module docstring for one robot.

    Every per-sample array lives in a buffer made once (the Jacobian, the error, the Newton step, the drift)
    and the task blocks are views into them; the soles' and the base's placements, the centre of mass and its
    acceleration are read through views of ``data`` taken once (Pinocchio fills its containers in place, so
    the views follow every kinematics call; were they ever copies, the error would not fall and the Newton
    iterations would raise, not mislead). A sample then costs Pinocchio's kinematics and a few small
    products, not allocations, slicing and attribute look-ups. Small matrix products go through
    ``ndarray.dot``, which calls the same BLAS routine as ``@`` without the ``matmul`` ufunc's dispatch (the
    same bits, a fifth of the time at 3 x 3).
    """

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        legs = sorted({robot.actuated.index(j) for f in robot.contact_frames for j in robot.limb(f)})
        self.solved_act = np.array(legs, dtype=int)
        self.free_act = np.array([i for i in range(robot.n_act) if i not in legs], dtype=int)
        iv = robot.act_v_index
        if len(legs) + 6 != 18:
            raise ModelError(f"robot '{robot.name}': walking IK needs 6 joints per leg, got {len(legs)}")
        # slices where the indices are consecutive (views: cheaper in the per-sample loop)
        self.sel = as_slice(np.concatenate([np.arange(6), iv[self.solved_act]]))
        self.rest = as_slice(iv[self.free_act])
        self.iq_free = as_slice(robot.act_q_index[self.free_act])
        self.frames = robot.contact_frame_ids
        nv = self.model.nv
        self._J = np.zeros((18, nv))  # the base rows stay zero but for the base's angular columns
        self._e = np.empty(18)
        self._abs_e = np.empty(18)
        self._dv = np.zeros(nv)  # the Newton step: zero on the joints the IK does not solve
        self._drift = np.zeros(18)
        self._zero = np.zeros(nv)
        J, e, drift = self._J, self._e, self._drift
        self._J_soles = (J[0:6], J[6:12])
        self._J_com, self._J_base = J[12:15], J[15:18, 3:6]
        self._e_soles = ((e[0:3], e[3:6]), (e[6:9], e[9:12]))
        self._e_com, self._e_base = e[12:15], e[15:18]
        self._drift_soles, self._drift_com = (drift[0:6], drift[6:12]), drift[12:15]
        oMf, data = self.data.oMf, self.data
        # live views: world positions (3,) and transposed rotations (3, 3) of the soles and of the base
        self._soles = tuple((oMf[f].translation, oMf[f].rotation.T) for f in self.frames)
        self._base_R = data.oMi[1].rotation
        self._base_RT = self._base_R.T
        self._com, self._acom = data.com[0], data.acom[0]

    def _jacobian(self) -> np.ndarray:
        """Task Jacobian (18, nv) at the configuration of the last ``computeJointJacobians``: sole poses, centre
        of mass, base rotation (a buffer, overwritten by the next call); places the soles (``data.oMf``) and
        the centre of mass (``data.com[0]``). The base's angular Jacobian in ``LOCAL_WORLD_ALIGNED`` is
        ``[0 R 0]`` (the free-flyer's angular velocity is in its own frame, R its rotation): the rotation is
        copied in, the bits of ``getJointJacobian``'s rows (tests/walking/test_unchanged_route.py)."""
        model, data = self.model, self.data
        for J_f, f in zip(self._J_soles, self.frames):  # getFrameJacobian also places the frame (data.oMf[f])
            J_f[:] = pin.getFrameJacobian(model, data, f, LWA)
        self._J_com[:] = pin.jacobianCenterOfMass(model, data, True)
        self._J_base[:] = self._base_R
        return self._J

    def _error(self, tasks: _Tasks, k: int) -> np.ndarray:
        """Task error (18,) at sample ``k`` after :meth:`_jacobian` (a buffer, overwritten by the next call):
        target minus actual position [m], ``log3(R_target R^T)`` [rad] for the rotations."""
        for (e_p, e_R), (p, RT), p_ref, R_ref in zip(self._e_soles, self._soles, tasks.sole_p[k], tasks.sole_R[k]):
            np.subtract(p_ref, p, out=e_p)
            e_R[:] = pin.log3(R_ref.dot(RT))
        np.subtract(tasks.com[k], self._com, out=self._e_com)
        self._e_base[:] = pin.log3(tasks.base_R[k].dot(self._base_RT))
        return self._e

    def solve(self, q_guess: np.ndarray, tasks: _Tasks, k: int, v: np.ndarray, a: np.ndarray,
              tol: float = 1e-11, max_iter: int = 20) -> np.ndarray:
        """Configuration (nq,) at sample ``k`` (see module docstring), by Newton iterations from ``q_guess``
        (overwritten); its velocity and acceleration (nv,) written into ``v`` and ``a``."""
        model, data, sel, rest, dv = self.model, self.data, self.sel, self.rest, self._dv
        free_q, free_qd, free_qdd = tasks.free
        q = q_guess
        q[self.iq_free] = free_q[k]
        for _ in range(max_iter):
            pin.computeJointJacobians(model, data, q)
            J = self._jacobian()
            e = self._error(tasks, k)
            abs_e = np.abs(e, out=self._abs_e)
            if abs_e[abs_e.argmax()] < tol:  # max |e| (nan if any is), without ufunc.reduce's set-up
                break
            dv[sel] = _solve(J[:, sel], e)
            q = pin.integrate(model, q, dv)
        else:
            raise ModelError(f"whole-body IK did not converge (residual {np.max(np.abs(e)):.2e}): "
                             "is the step reachable?")
        Js_inv, Jr = _umath_linalg.inv(J[:, sel]), J[:, rest]
        v[rest] = free_qd[k]
        v[sel] = Js_inv.dot(tasks.xd[k] - Jr.dot(free_qd[k]))
        # drift Jd v: classical accelerations at zero joint acceleration
        pin.centerOfMass(model, data, q, v, self._zero)
        for d, f in zip(self._drift_soles, self.frames):
            d[:] = pin.getFrameClassicalAcceleration(model, data, f, LWA).vector
        self._drift_com[:] = self._acom
        a[rest] = free_qdd[k]
        a[sel] = Js_inv.dot(tasks.xdd[k] - self._drift - Jr.dot(free_qdd[k]))
        return q


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
    tasks = _Tasks(yaw_rotations(feet[:, :, 3]), feet[:, :, :3], com, yaw_rotations(yaw[0]),
                   _task_rates(feet_d, com_d, yaw[1]), _task_rates(feet_dd, com_dd, yaw[2]),
                   (free_q[:, ik.free_act], free_qd[:, ik.free_act], free_qdd[:, ik.free_act]))
    Q = np.empty((n, model.nq))
    V = np.empty((n, model.nv))
    A = np.empty((n, model.nv))
    q, v, a = q0, np.zeros(model.nv), np.zeros(model.nv)
    half_dt2 = 0.5 * dt**2  # a * (dt^2 / 2) has the bits of (a / 2) * dt^2: both halvings are exact (no subnormals)
    step = np.empty(model.nv)
    for k in counted(n, progress):  # each sample starts from the previous one's motion
        np.multiply(v, dt, out=step)
        step += a * half_dt2
        v, a = V[k], A[k]
        Q[k] = q = ik.solve(pin.integrate(model, q, step), tasks, k, v, a)
    return WalkingReference(time, Q, V, A, plan.contact(time), feet, com, zmp, plan)

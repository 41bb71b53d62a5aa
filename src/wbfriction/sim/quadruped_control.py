"""The walking quadruped's balance controller: whole-body inverse dynamics with point feet, at the log rate.

Two point feet exert no moment about the line between them: in a trot's stance the robot's rotation about that
diagonal is not actuated (its angular momentum about the line changes by gravity alone), and a feed-forward of the
reference's inverse dynamics plus joint PD lets it tip, more at each step. The controller instead chooses, at each
sample, the accelerations ``a`` (nv) and the stance feet's forces ``lambda`` (3 per foot, world axes) that the
dynamics allow and that come closest to its tasks, then the torques that produce them:

.. math::

    \\min_{a, \\lambda} \\; \\|a_{base} - a_{base}^*\\|^2 + \\sum_{swing} \\|J_c a + \\dot J_c v - \\ddot p_c^*\\|^2
    + w_q \\|a_{joints} - \\ddot q^*\\|^2 + w_\\lambda \\|D (\\lambda - \\lambda_0)\\|^2
    \\quad \\text{s.t.} \\quad M_{base} a + h_{base} = J_{s,base}^T \\lambda, \\quad J_s a + \\dot J_s v = 0

with ``tau = M_joints a + h_joints - J_{s,joints}^T lambda``, ``lambda_0`` an even share of the robot's weight on the
stance feet (vertical), ``D`` weighing the tangential components more (:class:`BalanceGains`). The tasks are PD
laws on the reference (:class:`~wbfriction.walking.quadruped.QuadrupedReference`): the base's pose (world position
and orientation, Pinocchio's free-flyer acceleration in the base frame), the swing feet's world positions (a swing
foot lands on its footprint wherever the base is), the joint angles (a light posture task). The first constraint is
the whole body's Newton-Euler equation (the base's six rows of the equation of motion), the second keeps the stance
feet still. Solved as one equality-constrained least-squares problem (its KKT system, about 50 unknowns).

With the torque it gives joint set-points for a PD on top (the drivers' or the torque drive's,
:meth:`BalanceController.leg_setpoints`): a stance leg's the reference's (the PD holds the base's posture over the
feet), a swing leg's those that put its foot on its reference from where the base is (the PD moves the foot to
its footprint, not with the base: it lands within about a millimetre of it), a landed leg's faded from the one to
the other over ``landing`` seconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.model.robot import Robot
from wbfriction.walking.quadruped import QuadrupedReference

LWA = pin.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class BalanceGains:
    """The controller's PD gains ``(Kp [1/s^2], Kd [1/s])`` per task and its weights (module docstring).

    Attributes:
        base: the base's position and orientation.
        feet: the swing feet's positions.
        joints: the joint angles (the posture task).
        joint_weight: ``w_q``, the posture task's weight against the base's and the feet's (1).
        force_weight: ``w_lambda`` [1/N^2 in the tasks' units]: among forces that do the same, those nearest an
            even share of the robot's weight on the stance feet, pushing down.
        tangential: the tangential components' scale in that distance (their weight the square).
        landing: the time a landed leg's joint set-points take to go from where its swing left them to the
            reference's [s] (:meth:`BalanceController.leg_setpoints`).
    """

    base: tuple[float, float] = (50.0, 10.0)
    feet: tuple[float, float] = (400.0, 40.0)
    joints: tuple[float, float] = (100.0, 20.0)
    feet_weight: float = 1.0
    joint_weight: float = 1e-2
    force_weight: float = 1e-4
    tangential: float = 3.0
    landing: float = 0.1


class BalanceController:
    """The controller of one run (module docstring) on ``model`` (the robot's, or a copy with another armature)."""

    def __init__(self, robot: Robot, model: pin.Model, reference: QuadrupedReference,
                 gains: BalanceGains = BalanceGains()) -> None:
        self.robot, self.model, self.ref, self.gains = robot, model, reference, gains
        self.data = model.createData()
        self.weight = float(pin.computeTotalMass(model)) * float(np.linalg.norm(model.gravity.linear))
        self.iv, self.iq = robot.act_v_index, robot.act_q_index
        self.swing_offset = np.zeros((len(robot.contact_frames), 3))
        self.stance_samples = np.zeros(len(robot.contact_frames), dtype=int)
        # each leg's velocity columns and its joints' places in the actuated order
        self.legs = [(self.iv[rows], rows) for rows in
                     (np.array([robot.actuated.index(j) for j in robot.limb(f)]) for f in robot.contact_frames)]
        # the reference base's world velocity and acceleration (linear, angular)
        R = np.array([pin.Quaternion(np.asarray(b[3:])).toRotationMatrix() for b in reference.base])
        v, a = reference.base_v, reference.base_a
        self.R_ref = R
        self.pd_ref = np.einsum("nij,nj->ni", R, v[:, :3])
        self.pdd_ref = np.einsum("nij,nj->ni", R, a[:, :3] + np.cross(v[:, 3:], v[:, :3]))
        self.w_ref = np.einsum("nij,nj->ni", R, v[:, 3:])
        self.wd_ref = np.einsum("nij,nj->ni", R, a[:, 3:])

    def base_task(self, k: int, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The base's desired free-flyer acceleration (6,) (base frame, Pinocchio's ``a[:6]``)."""
        kp, kd = self.gains.base
        R = pin.Quaternion(q[3:7]).toRotationMatrix()
        vl, wl = v[:3], v[3:6]
        lin = self.pdd_ref[k] + kp * (self.ref.base[k, :3] - q[:3]) + kd * (self.pd_ref[k] - R @ vl)
        ang = self.wd_ref[k] + kp * pin.log3(self.R_ref[k] @ R.T) + kd * (self.w_ref[k] - R @ wl)
        return np.concatenate([R.T @ lin - np.cross(wl, vl), R.T @ ang])

    def torque(self, k: int, q: np.ndarray, v: np.ndarray, active: np.ndarray) -> np.ndarray:
        """The joint torques (n_act,) [N·m] at sample ``k`` from the state ``q``, ``v``, the feet ``active`` (indices
        into the contact frames) standing (module docstring)."""
        model, data, g, ref = self.model, self.data, self.gains, self.ref
        self.q_now = q
        nv, n_lam = model.nv, 3 * len(active)
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.nle(model, data, q, v)
        pin.computeJointJacobians(model, data, q)
        pin.forwardKinematics(model, data, q, v, np.zeros(nv))
        pin.updateFramePlacements(model, data)
        J, drift, p = [], [], []
        for f in self.robot.contact_frame_ids:
            J.append(pin.getFrameJacobian(model, data, f, LWA)[:3])
            drift.append(pin.getFrameClassicalAcceleration(model, data, f, LWA).linear)
            p.append(data.oMf[f].translation.copy())
        rows: list[tuple[np.ndarray, np.ndarray, float]] = []  # (A over x = [a, lambda], b, weight)
        pad = lambda A: np.hstack([A, np.zeros((A.shape[0], n_lam))])  # noqa: E731
        rows.append((pad(np.eye(6, nv)), self.base_task(k, q, v), 1.0))
        kp, kd = g.feet
        for c in range(len(J)):
            if c not in active:
                want = ref.feet_a[k, c] + kp * (ref.feet[k, c] - p[c]) + kd * (ref.feet_v[k, c] - J[c] @ v)
                rows.append((pad(J[c]), want - drift[c], g.feet_weight))
        kp, kd = g.joints
        want = ref.qdd[k] + kp * (ref.q[k] - q[self.iq]) + kd * (ref.qd[k] - v[self.iv])
        rows.append((pad(np.eye(nv)[self.iv]), want, g.joint_weight))
        if n_lam:  # near an even share of the weight, pushing down (tangential components weigh more)
            scale = np.tile([g.tangential, g.tangential, 1.0], len(active))
            nominal = np.tile([0.0, 0.0, self.weight / len(active)], len(active))
            rows.append((np.hstack([np.zeros((n_lam, nv)), np.diag(scale)]), scale * nominal, g.force_weight))
        Js = np.vstack([J[c] for c in active]) if n_lam else np.zeros((0, nv))
        C = np.vstack([np.hstack([M[:6], -Js[:, :6].T]), np.hstack([Js, np.zeros((n_lam, n_lam))])])
        d = np.concatenate([-h[:6]] + [-drift[c] for c in active])
        H = sum(w * A.T @ A for A, _, w in rows)
        r = sum(w * A.T @ b for A, b, w in rows)
        m = len(d)
        K = np.block([[H, C.T], [C, np.zeros((m, m))]])
        x = np.linalg.solve(K, np.concatenate([r, d]))
        a, lam = x[:nv], x[nv:nv + n_lam]
        self.setpoints = self.leg_setpoints(k, v, J, p, active)
        return (M[self.iv] @ a + h[self.iv] - Js[:, self.iv].T @ lam)

    def leg_setpoints(self, k: int, v: np.ndarray, J: list[np.ndarray], p: list[np.ndarray], active: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Joint angle and velocity set-points (n_act,) each: a stance leg's, the reference's (a joint PD toward
        them holds the base's posture over the feet); a swing leg's, those that put its foot on its reference from
        the base where it is (one Newton step of the leg's IK from the present angles; the velocity that gives the
        foot its reference velocity): a joint PD toward them moves the swing foot where it should land, not with
        the base."""
        ref = self.ref
        fade = self.gains.landing / ref.dt
        q_des, qd_des = ref.q[k].copy(), ref.qd[k].copy()
        for c, (cols, rows) in enumerate(self.legs):
            if c in active:  # the last swing's offset from the reference, faded out over the landing time
                self.stance_samples[c] += 1
                q_des[rows] += self.swing_offset[c] * max(0.0, 1.0 - self.stance_samples[c] / fade)
                continue
            J_leg = J[c][:, cols]
            q_des[rows] = self.q_now[self.iq[rows]] + np.linalg.solve(J_leg, ref.feet[k, c] - p[c])
            qd_des[rows] = np.linalg.solve(J_leg, ref.feet_v[k, c] - J[c][:, :6] @ v[:6])
            self.swing_offset[c], self.stance_samples[c] = q_des[rows] - ref.q[k, rows], 0
        return q_des, qd_des

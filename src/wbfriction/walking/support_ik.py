"""The square inverse kinematics a robot standing still on some of its feet solves per sample (the base of
:class:`~wbfriction.walking.single_support.SingleSupportIK`, a humanoid on one sole, and
:class:`~wbfriction.walking.tripod_support.TripodIK`, a quadruped on three point feet): Newton iterations on the
base's and the stance legs' velocity columns (:attr:`SupportIK.cols`) until the tasks' error (the stance feet, the
centre of mass, the base's rotation) vanishes, then velocities from ``J v = 0`` and accelerations from
``J a = -Jd v`` (the targets are constant), the other joints (:attr:`SupportIK.rest`) prescribed. Pinocchio's
``LOCAL_WORLD_ALIGNED`` Jacobians.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.robot import Robot

LWA = pin.LOCAL_WORLD_ALIGNED


class SupportIK:
    """A square standing inverse kinematics: a subclass sets the attributes below and gives :meth:`_system` and
    :meth:`_feet_drift`.

    Attributes:
        robot, model, data: the robot, its Pinocchio model and the IK's own data.
        cols: the velocity indices solved (m,): the base's six, then the stance legs' joints.
        rest: every other velocity index (nv - m,), in increasing order: the joints prescribed.
        stance_name: the stance's name in the error raised (``"one-foot"``); hint: the error's advice (``""`` or
            ``": lower --height"``).
    """

    robot: Robot
    model: pin.Model
    data: pin.Data
    cols: np.ndarray
    rest: np.ndarray
    stance_name: str = ""
    hint: str = ""

    def _system(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The task Jacobian (m, nv) and error (m,) at ``q``."""
        raise NotImplementedError

    def _feet_drift(self) -> np.ndarray:
        """The stance feet's tasks' ``Jd v`` (their rows' count), from :attr:`data` after the forward kinematics
        of ``q, v`` and a zero acceleration."""
        raise NotImplementedError

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
            raise ModelError(f"{self.stance_name} stance IK did not converge (residual {np.max(np.abs(e)):.2e})"
                             f"{self.hint}")
        Jc_inv, Jr = np.linalg.inv(J[:, cols]), J[:, self.rest]
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v[self.rest], a[self.rest] = v_rest, a_rest
        v[cols] = -Jc_inv @ (Jr @ v_rest)
        pin.centerOfMass(model, data, q, v, np.zeros(model.nv))  # drift: zero acceleration
        drift = np.concatenate([self._feet_drift(), data.acom[0], np.zeros(3)])
        a[cols] = -Jc_inv @ (drift + Jr @ a_rest)
        return q, v, a

    def solve_motion(self, q: np.ndarray, act: np.ndarray, swing: tuple[np.ndarray, np.ndarray, np.ndarray]
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve` at every sample of the swing joints' motion (N, n) each (``act``: their actuated indices),
        from ``q`` (the first guess), each sample's solution the next one's guess: the configurations (N, nq),
        velocities and accelerations (N, nv)."""
        qs, qds, qdds = swing
        robot, model = self.robot, self.model
        n = len(qs)
        Q, V, A = np.empty((n, model.nq)), np.empty((n, model.nv)), np.empty((n, model.nv))
        iq = robot.act_q_index[act]
        on_rest = np.searchsorted(self.rest, robot.act_v_index[act])
        v_rest, a_rest = np.zeros(len(self.rest)), np.zeros(len(self.rest))
        for k in range(n):
            q = q.copy()
            q[iq] = qs[k]
            v_rest[on_rest], a_rest[on_rest] = qds[k], qdds[k]
            q, V[k], A[k] = self.solve(q, v_rest, a_rest)
            Q[k] = q
        return Q, V, A

"""Whole-body inverse dynamics with a measured base motion or measured contact wrenches (issue 23).

The equation of motion ``M(q) qdd + h(q, v) = S^T (tau + tau_f) + J^T lambda`` has six rows without
actuation (the base's). The rigid-contact route (:mod:`wbfriction.model.dynamics`) closes it with the
contacts' kinematics; here the robot's sensors close it instead:

* **measured wrenches** (:mod:`wbfriction.model.force_torque`): on the robot above its force-torque
  sensors, ``M_a qdd + h_a - sum_s J_s^T f_s = S^T (tau + tau_f)`` has no unknown wrench. With the
  base acceleration measured, one RNEA pass with the sensors' wrenches as external forces gives every
  joint's torque, and its six base rows, which should be zero, are a cross-check. Without it, the
  six base rows give the base acceleration: ``M_bb a_b = -r_b`` with ``r`` the RNEA torques at zero
  base acceleration and ``M_bb`` the whole robot's composite inertia at the base (``crba``). Every
  joint, every phase: stance leg, double support, flight.
* **measured base motion, no wrench**: one RNEA pass gives ``r = M qdd + h``; in single support the
  stance contact's six unknowns solve the six base rows, ``J_b^T lambda = r_b`` (``J`` the contact's
  LOCAL Jacobian, ``J_b`` its base columns), then ``tau_joint = r_joint - J_joint^T lambda`` for every
  joint, the stance leg's included; in flight ``lambda = 0``; in double support twelve unknowns
  meet six equations: not unique (NaN).

The base's linear velocity need not be measured: Newton-Euler's equations are the same in every
inertial frame (a uniform velocity added to the whole robot changes no force), so with the wrench
route a base twist whose linear part is zero gives the same joint torques, provided the acceleration
solved for goes with it. Its orientation (gravity's direction) and angular velocity are needed.

Sign convention: ``tau_f = tau_joint - tau``, the torque friction exerts on the joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.model.force_torque import above_sensors_model, external_wrenches
from wbfriction.model.momentum import momentum_and_drift
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress


@dataclass
class MeasuredDynamics:
    """Output of :func:`measured_inverse_dynamics` for N samples.

    Attributes:
        tau: the torques the motion needs at the actuated joints (N, n_act) [N·m]; NaN where not unique.
        base_acceleration: the base's spatial acceleration used, measured or solved (N, 6), base frame
            [m/s^2, rad/s^2].
        base_residual: with measured wrenches and a measured base acceleration, the six base rows
            ``M qdd + h - J^T f`` (N, 6) [N, N·m], zero for consistent data (a cross-check); else None.
        unique: (N,) the torques are determined (every sample with wrenches; single support or
            flight without).
    """

    tau: np.ndarray
    base_acceleration: np.ndarray
    base_residual: np.ndarray | None
    unique: np.ndarray


def _above_sensors(robot: Robot) -> pin.Model:
    key = ("above_sensors",)
    if key not in robot.cache:
        robot.cache[key] = above_sensors_model(robot.model, robot.ft_sensors)
    return robot.cache[key]


def measured_inverse_dynamics(robot: Robot, q: np.ndarray, v: np.ndarray, qdd: np.ndarray, *,
                              base_acceleration: np.ndarray | None = None, wrench: np.ndarray | None = None,
                              contact: np.ndarray | None = None, progress: Progress | None = None
                              ) -> MeasuredDynamics:
    """The actuated joints' torques from a measured base motion and/or measured wrenches (module docstring).

    Args:
        robot: the robot (its :attr:`~wbfriction.model.robot.Robot.ft_sensors` with ``wrench``).
        q: configurations (N, nq), the base pose included (its orientation matters, its position not).
        v: velocities (N, nv): the base twist in the base frame (its linear part may be zero with
            ``wrench`` and no ``base_acceleration``), then the joints' [rad/s].
        qdd: measured joint accelerations (N, n_act) [rad/s^2].
        base_acceleration: measured base spatial acceleration (N, 6), base frame (Pinocchio's
            free-flyer ``a[:6]``), or None: solved from the base rows (needs ``wrench``).
        wrench: measured wrenches (N, n_sensors, 6), each in its sensor frame [N, N·m], or None.
        contact: contact flags (N, n_contacts), needed without ``wrench``.
        progress: optional callable receiving numbers of samples done.

    Raises:
        ValueError: neither a base acceleration nor wrenches, or no contact flags without wrenches.
    """
    if base_acceleration is None and wrench is None:
        raise ValueError("the base rows need a measured base acceleration or measured wrenches")
    if wrench is None and contact is None:
        raise ValueError("without measured wrenches, the contact flags say which contact's wrench to solve for")
    model = _above_sensors(robot) if wrench is not None else robot.model
    data = model.createData()
    n = len(q)
    iv = robot.act_v_index
    tau = np.full((n, robot.n_act), np.nan)
    a_base = np.full((n, 6), np.nan) if base_acceleration is None else np.array(base_acceleration, dtype=float)
    residual = np.full((n, 6), np.nan) if (wrench is not None and base_acceleration is not None) else None
    unique = np.zeros(n, dtype=bool)
    a = np.zeros(model.nv)
    for k in range(n):
        a[iv] = qdd[k]
        if wrench is not None:
            fext = external_wrenches(model, robot.ft_sensors, wrench[k])
            if base_acceleration is None:
                a[:6] = 0.0
                r = pin.rnea(model, data, q[k], v[k], a, fext)
                M_b = pin.crba(model, data, q[k])[:6]  # the base rows of M
                a_base[k] = -np.linalg.solve(M_b[:, :6], r[:6])
                r = r + M_b.T @ a_base[k]
            else:
                a[:6] = a_base[k]
                r = pin.rnea(model, data, q[k], v[k], a, fext)
                assert residual is not None
                residual[k] = r[:6]
            tau[k], unique[k] = r[iv], True
        else:
            assert contact is not None  # checked above
            a[:6] = a_base[k]
            r = pin.rnea(model, data, q[k], v[k], a)
            active = np.flatnonzero(contact[k])
            if active.size == 0:
                tau[k], unique[k] = r[iv], True
            elif active.size == 1:
                J = pin.computeFrameJacobian(model, data, q[k], robot.contact_frame_ids[active[0]], pin.LOCAL)
                lam = np.linalg.solve(J[:, :6].T, r[:6])
                tau[k], unique[k] = r[iv] - J[:, iv].T @ lam, True
        if progress is not None and (k + 1) % 1024 == 0:
            progress(1024)
    if progress is not None and n % 1024:
        progress(n % 1024)
    return MeasuredDynamics(tau, a_base, residual, unique)


def measured_momentum(robot: Robot, q: np.ndarray, v: np.ndarray, wrench: np.ndarray,
                      progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The generalized momentum of the actuated joints and its rate without friction on the robot above its
    force-torque sensors, the measured wrenches acting on it (the momentum route's ``wrench`` closure,
    :mod:`wbfriction.friction.momentum`): ``p = (M v)_j``, ``b = (C^T v - g)_j`` and the sensors' ``e = (sum_s
    J_s^T f_s)_j`` (:func:`~wbfriction.model.momentum.momentum_and_drift`), so that ``dp/dt = tau + tau_f + b + e``
    with no unknown wrench, in every phase.

    Args:
        robot: the robot (its :attr:`~wbfriction.model.robot.Robot.ft_sensors`).
        q: configurations (N, nq), the base pose included; v: velocities (N, nv), the base twist in the base
            frame (its linear part too: unlike the accelerations' route, momenta are not the same in every
            inertial frame, only their balance is).
        wrench: measured wrenches (N, n_sensors, 6), each in its sensor frame [N, N·m].
        progress: optional callable receiving numbers of samples done.

    Returns:
        ``(p, b, e)``, (N, n_act) each [N·m·s], [N·m], [N·m].
    """
    model = _above_sensors(robot)
    p, b, e = momentum_and_drift(model, q, v, fext=lambda k: external_wrenches(model, robot.ft_sensors, wrench[k]),
                                 progress=progress)
    iv = robot.act_v_index
    return p[:, iv], b[:, iv], e[:, iv]

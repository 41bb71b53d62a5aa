"""Friction from what a humanoid's sensors measure (issue 23): foot force-torque sensors and the base's motion.

Two routes beside the rigid-contact one of :mod:`wbfriction.friction.estimate`, both from
:func:`~wbfriction.model.measured_dynamics.measured_inverse_dynamics`:

* ``wrench``: the force-torque sensors' wrenches close the base's six equations, so ``tau_f`` is
  unique for **every** torque-controlled joint in **every** phase (stance leg, double support, flight).
  The base's orientation and angular velocity come from the logged base pose (``base_motion =
  "logged"``) or, from the stance contacts as in the rigid-contact route (``"contact"``: a foot on the
  ground, flat, not moving); its acceleration from the base rows.
* ``base``: the base's acceleration measured (its logged pose differentiated on SO(3)), no wrench: in
  single support the stance contact's wrench follows from the base's six rows, so ``tau_f`` is unique
  for every joint (the stance leg's included); in double support it is not.

Sign convention: ``tau_f = tau_joint - tau``, the torque friction exerts on the joint.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np

from wbfriction.model.dynamics import floating_base_state
from wbfriction.model.measured_dynamics import measured_inverse_dynamics
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics

BaseMotion = Literal["auto", "contact", "logged"]
"""Where the base's motion comes from: the rigid contacts (the thesis's route), the logged base pose
differentiated like the joints, or ``auto``: logged where the log has a base pose and the sensors'
wrenches, contact otherwise (:func:`resolve_base_motion`)."""
BASE_MOTIONS: tuple[BaseMotion, ...] = get_args(BaseMotion)

Route = Literal["contact", "base", "wrench", "none"]
"""How a sample's friction was estimated: rigid contacts, measured base motion, measured wrenches, or not."""


def resolve_base_motion(choice: BaseMotion, has_base: bool, has_wrench: bool) -> Literal["contact", "logged"]:
    """The base motion ``auto`` stands for: ``logged`` with a logged base pose and wrenches (the base's
    orientation and angular velocity measured rather than assumed from a flat, still stance foot),
    ``contact`` otherwise (a log's base pose alone is often the output of a state estimator that
    assumes the same rigid contact, and differentiating it twice adds its noise)."""
    if choice != "auto":
        return choice
    return "logged" if has_base and has_wrench else "contact"


def wrench_route(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray, logged_base: bool
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Friction from the measured wrenches (module docstring) on the rows ``rows`` (N,) of ``kin``.

    Returns:
        ``(tau_f, done)``: (N, n_tc) [N·m], NaN where not estimated, and (N,) the rows estimated: those
        of ``rows`` whose wrenches (and, with ``logged_base``, base twist) are finite and, with the
        base from the contacts, that have a foot on the ground.
    """
    assert kin.wrench is not None
    n = len(kin.time)
    ok = rows & np.all(np.isfinite(kin.wrench.reshape(n, -1)), axis=1)
    if logged_base:
        assert kin.base_qd is not None and kin.base is not None
        ok &= np.all(np.isfinite(kin.base_qd), axis=1)
    else:
        ok &= kin.contact.any(axis=1)
    r = np.flatnonzero(ok)
    q, v = _base_state(robot, kin, r, logged_base)
    dyn = measured_inverse_dynamics(robot, q, v, kin.qdd[r], wrench=kin.wrench[r])
    tau_f = np.full((n, robot.tc_index.size), np.nan)
    tau_f[r] = dyn.tau[:, robot.tc_index] - kin.tau[r]
    return tau_f, ok


def base_route(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Friction from the measured base acceleration, no wrench (module docstring), on the rows ``rows``
    (N,) of ``kin`` that have at most one contact; returns ``(tau_f, done)`` as :func:`wrench_route`."""
    assert kin.base_qd is not None and kin.base_qdd is not None
    n = len(kin.time)
    ok = (rows & (kin.contact.sum(axis=1) <= 1) & np.all(np.isfinite(kin.base_qd), axis=1)
          & np.all(np.isfinite(kin.base_qdd), axis=1))
    r = np.flatnonzero(ok)
    q, v = _base_state(robot, kin, r, True)
    dyn = measured_inverse_dynamics(robot, q, v, kin.qdd[r], base_acceleration=kin.base_qdd[r],
                                    contact=kin.contact[r])
    tau_f = np.full((n, robot.tc_index.size), np.nan)
    tau_f[r] = dyn.tau[:, robot.tc_index] - kin.tau[r]
    return tau_f, ok


def _base_state(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, logged_base: bool
                ) -> tuple[np.ndarray, np.ndarray]:
    """Full ``q`` (len(r), nq) and ``v`` (len(r), nv) of the rows ``r``: the logged base pose and its
    differentiated twist, or the stance contacts' (flat, not moving: :func:`floating_base_state`)."""
    if logged_base:
        assert kin.base is not None and kin.base_qd is not None
        q = robot.configuration(kin.q[r], kin.base[r])
        v = np.zeros((r.size, robot.model.nv))
        v[:, :6], v[:, robot.act_v_index] = kin.base_qd[r], kin.qd[r]
        return q, v
    data = robot.model.createData()
    q, v = np.empty((r.size, robot.model.nq)), np.empty((r.size, robot.model.nv))
    for i, k in enumerate(r):
        q[i], v[i], _ = floating_base_state(robot, data, kin.q[k], kin.qd[k], np.flatnonzero(kin.contact[k]).tolist(),
                                            None if kin.base is None else kin.base[k])
    return q, v

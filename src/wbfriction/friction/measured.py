"""Friction from what a humanoid's sensors measure (issue 23): foot force-torque sensors and the base's motion.

Two routes beside the rigid-contact one of :mod:`wbfriction.friction.estimate`, both from
:func:`~wbfriction.model.measured_dynamics.measured_inverse_dynamics`:

* ``wrench``: the force-torque sensors' wrenches close the base's six equations, so ``tau_f`` is
  unique for **every** torque-controlled joint in **every** phase (stance leg, double support, flight).
  The base's orientation and angular velocity come from the logged base pose (``base_motion =
  "logged"``), from the IMU's gyro and the logged orientation (``"imu"``), or from the stance contacts
  as in the rigid-contact route (``"contact"``: a foot on the ground, flat, not moving); its
  acceleration from the base rows.
* ``base``: the base's acceleration measured (its logged pose differentiated on SO(3), or the IMU's
  gyro differentiated once and its accelerometer, :func:`~wbfriction.model.imu.base_motion_from_imu`),
  no wrench: in single support the stance contact's wrench follows from the base's six rows, so
  ``tau_f`` is unique for every joint (the stance leg's included); in double support it is not.

Sign convention: ``tau_f = tau_joint - tau``, the torque friction exerts on the joint.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.options import BaseMotion
from wbfriction.logs.contacts import default_thresholds, normal_forces, sensed_contacts
from wbfriction.logs.log import Log
from wbfriction.model.dynamics import floating_base_state
from wbfriction.model.imu import base_motion_from_imu
from wbfriction.model.measured_dynamics import measured_inverse_dynamics
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics

Closure = Literal["contact", "base", "wrench", "none"]
"""How a sample's friction was estimated: rigid contacts, measured base motion, measured wrenches, or not."""


def resolve_base_motion(choice: BaseMotion, has_base: bool, has_wrench: bool, has_imu: bool = False
                        ) -> Literal["contact", "logged", "imu"]:
    """The base motion ``auto`` stands for: ``imu`` with an IMU and a logged base orientation (measured
    rates, one differentiation); else ``logged`` with a logged base pose and wrenches (the base's
    orientation and angular velocity measured rather than assumed from a flat, still stance foot); else
    ``contact`` (a log's base pose alone is often the output of a state estimator that assumes the
    same rigid contact, and differentiating it twice adds its noise)."""
    if choice != "auto":
        return choice
    if has_imu and has_base:
        return "imu"
    return "logged" if has_base and has_wrench else "contact"


def log_base_motion(robot: Robot, log: Log, choice: BaseMotion, wrenches: bool
                    ) -> tuple[bool, Literal["contact", "logged", "imu"]]:
    """Whether the log's wrenches are used (``wrenches`` and the log has them) and the base motion ``choice`` stands
    for on this log (:func:`resolve_base_motion`), for either route.

    Raises:
        InputError: ``imu`` without the robot's IMU or the log's base orientation.
    """
    has_wrench = wrenches and log.wrench is not None
    has_imu = log.imu is not None and robot.imu is not None
    # point feet need the base measured (wbfriction.friction.point_contacts): a logged pose is taken without wrenches
    base_motion = resolve_base_motion(choice, log.base is not None, has_wrench or robot.partial_contacts, has_imu)
    if base_motion == "imu" and (robot.imu is None or log.base is None):
        raise InputError(f"{log.source}: --base-motion imu needs the robot's [imu] (its TOML) and the base "
                         "orientation columns base.qx ... base.qw")
    return has_wrench, base_motion


IMPACT_SKIP = 0.02
"""Seconds left out after a sole's first touch of the ground: the impact's jerk, which differentiated
accelerations smear over their stencil while the sensors read it at its instants (MuJoCo, central
differences: up to 0.9 N·m). The first touch is where the normal force, going back from the rise of the
contact flag, last rose above 1 % of the robot's weight (:func:`impacts`)."""


def impacts(robot: Robot, kin: MeasuredKinematics, skip: float = IMPACT_SKIP) -> np.ndarray:
    """(N,) the rows of each touch-down's impact: from two rows before the sole's first touch (module
    docstring of :data:`IMPACT_SKIP`) to ``skip`` seconds after it, and at least to its flag's rise; all False
    without wrenches. Anchored on the flags' rises, so that a swinging sole plate's own inertia (a 0.4 kg
    plate at 25 m/s^2 reads 10 N) is never taken for a touch.

    The first touch is looked for only while the flag was off: a flag that dropped for a few rows while its
    sole still carried more than 1 % of the weight (a lift-off's normal force chattering about the flag's
    threshold) rises again without a touch-down, and is no impact. Walking back past the drop took the whole
    stance before it for one (MuJoCo's combined walk: 2.2 s of the left foot's stance, the right leg's two
    swings in it)."""
    out = np.zeros(len(kin.time), dtype=bool)
    if kin.wrench is None or not sensed_contacts(robot):
        return out
    low = 0.1 * default_thresholds(robot)[0]  # 1 % of the weight
    normal = normal_forces(robot, kin.wrench)
    for c in range(kin.contact.shape[1]):
        on = kin.contact[:, c]
        falls = np.flatnonzero(on[:-1] & ~on[1:]) + 1
        for k in np.flatnonzero(on[1:] & ~on[:-1]) + 1:
            before = falls[falls < k]
            off = int(before[-1]) if before.size else 0  # the first row of the flag's drop
            first = k
            while first > off and normal[first - 1, c] > low:
                first -= 1
            if before.size and first == off:  # the sole never left the ground: no touch-down
                continue
            stop = max(k + 1, np.searchsorted(kin.time, kin.time[first] + skip, side="right"))
            out[max(first - 2, 0):stop] = True
    return out


def measured_base(kin: MeasuredKinematics) -> Literal["contact", "logged", "imu"]:
    """Where ``kin``'s base motion comes from: its IMU rates, its differentiated base pose, or neither."""
    return "imu" if kin.imu is not None else "logged" if kin.base_qd is not None else "contact"


def wrench_route(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Friction from the measured wrenches (module docstring) on the rows ``rows`` (N,) of ``kin``, the base's
    orientation and angular velocity from :func:`measured_base`.

    Returns:
        ``(tau_f, done)``: (N, n_tc) [N·m], NaN where not estimated, and (N,) the rows estimated: those
        of ``rows`` whose wrenches (and measured base rates) are finite and, with the base from the
        contacts, that have a foot on the ground.
    """
    assert kin.wrench is not None
    n = len(kin.time)
    ok = rows & np.all(np.isfinite(kin.wrench.reshape(n, -1)), axis=1) & finite_base(kin)
    r = np.flatnonzero(ok)
    q, v, _ = base_state(robot, kin, r)
    dyn = measured_inverse_dynamics(robot, q, v, kin.qdd[r], wrench=kin.wrench[r])
    tau_f = np.full((n, robot.tc_index.size), np.nan)
    tau_f[r] = dyn.tau[:, robot.tc_index] - kin.tau[r]
    return tau_f, ok


def base_route(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Friction from the measured base acceleration, no wrench (module docstring), on the rows ``rows``
    (N,) of ``kin`` that have at most one contact; returns ``(tau_f, done)`` as :func:`wrench_route`."""
    n = len(kin.time)
    ok = rows & (kin.contact.sum(axis=1) <= 1) & finite_base(kin)
    r = np.flatnonzero(ok)
    q, v, a_b = base_state(robot, kin, r)
    assert a_b is not None  # a measured base
    dyn = measured_inverse_dynamics(robot, q, v, kin.qdd[r], base_acceleration=a_b, contact=kin.contact[r])
    tau_f = np.full((n, robot.tc_index.size), np.nan)
    tau_f[r] = dyn.tau[:, robot.tc_index] - kin.tau[r]
    return tau_f, ok


def finite_base(kin: MeasuredKinematics) -> np.ndarray:
    """(N,) the rows whose base motion is known: measured rates finite, or a foot on the ground."""
    source = measured_base(kin)
    if source == "imu":
        assert kin.imu is not None and kin.base is not None
        return np.asarray(np.all(np.isfinite(kin.imu), axis=1))
    if source == "logged":
        assert kin.base_qd is not None and kin.base_qdd is not None
        return np.asarray(np.all(np.isfinite(kin.base_qd), axis=1) & np.all(np.isfinite(kin.base_qdd), axis=1))
    return np.asarray(kin.contact.any(axis=1))


def base_state(robot: Robot, kin: MeasuredKinematics, r: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Full ``q`` (len(r), nq), ``v`` (len(r), nv) and the base's measured acceleration (len(r), 6) of the rows
    ``r``, from :func:`measured_base`: the logged base pose and its differentiated twist, the IMU's rates
    (:func:`~wbfriction.model.imu.base_motion_from_imu`, the base's linear velocity zero), or the stance
    contacts' (flat, not moving: :func:`floating_base_state`; no acceleration)."""
    source = measured_base(kin)
    if source in ("logged", "imu"):
        assert kin.base is not None
        q = robot.configuration(kin.q[r], kin.base[r])
        v = np.zeros((r.size, robot.model.nv))
        v[:, robot.act_v_index] = kin.qd[r]
        if source == "logged":
            assert kin.base_qd is not None and kin.base_qdd is not None
            v[:, :6] = kin.base_qd[r]
            return q, v, kin.base_qdd[r]
        assert kin.imu is not None and robot.imu is not None
        imu = kin.imu[r]
        v[:, :6], a_b = base_motion_from_imu(robot.model, robot.imu, q, robot.act_v_index, kin.qd[r], kin.qdd[r],
                                             imu[:, :3], imu[:, 3:6], imu[:, 6:])
        return q, v, a_b
    data = robot.model.createData()
    q, v = np.empty((r.size, robot.model.nq)), np.empty((r.size, robot.model.nv))
    for i, k in enumerate(r):
        q[i], v[i], _ = floating_base_state(robot, data, kin.q[k], kin.qd[k], np.flatnonzero(kin.contact[k]).tolist(),
                                            None if kin.base is None else kin.base[k])
    return q, v, None

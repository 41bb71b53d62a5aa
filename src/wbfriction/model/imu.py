"""An inertial measurement unit on a link of the robot: its readings, and the base's motion from them.

The robot TOML names it (``[imu]``: ``link``, a frame of the model; ``xyz`` [m], ``rpy`` [rad], its
placement in that frame). It measures, in its own frame:

* ``gyro`` [rad/s]: the angular velocity of its link;
* ``acc`` [m/s^2]: the specific force, the classical linear acceleration of its origin less gravity,
  ``R^T (p_ddot - g)`` (a resting IMU reads ``+9.81`` up).

**Base motion from an IMU** (:func:`base_motion_from_imu`). With the joints' ``q, qd, qdd`` measured, the
IMU frame's angular velocity and its classical acceleration are linear in the base's twist and
acceleration: ``omega_imu = J_w,b omega_b + J_w,j qd`` and ``(a_lin, omega_dot)_imu = J_b a_b + d``, with
``J`` the IMU frame's LOCAL Jacobian (``J_b`` its six base columns, invertible) and ``d`` its acceleration
at ``a_b = 0``. The base's linear velocity is not measured and not needed: it is set to zero, the
acceleration solved for goes with it (Newton-Euler's equations hold in every inertial frame,
:mod:`wbfriction.model.measured_dynamics`); the base's orientation comes from the log's base pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError

IMU_AXES = ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z")
"""The six columns of an IMU, ``imu.<axis>``: angular velocity [rad/s], then specific force [m/s^2], IMU frame."""


@dataclass(frozen=True)
class Imu:
    """An IMU of the robot (module docstring).

    Attributes:
        frame: the Pinocchio frame id of the IMU frame (added to the model by :func:`add_imu_frame`).
    """

    frame: int

    @staticmethod
    def columns() -> list[str]:
        """The IMU's log columns, ``imu.gyro_x`` ... ``imu.acc_z``."""
        return [f"imu.{axis}" for axis in IMU_AXES]


def add_imu_frame(model: pin.Model, table: object, source: str) -> Imu | None:
    """The ``[imu]`` table of a robot TOML as a frame ``imu`` added to ``model`` (in place), or None.

    Raises:
        InputError: naming the file and key: an unknown link, a vector that is not three numbers, an
            unknown key.
    """
    if table is None:
        return None
    if not isinstance(table, dict):
        raise InputError(f"{source}: '[imu]' must be a table (link, xyz, rpy)")
    unknown = set(table) - {"link", "xyz", "rpy"}
    if unknown:
        raise InputError(f"{source}: [imu] has an unknown key '{sorted(unknown)[0]}'")
    link = table.get("link")
    if not isinstance(link, str) or not model.existFrame(link):
        raise InputError(f"{source}: [imu] link = {link!r} is not a frame of the model")
    xyz, rpy = (_three(table, key, source) for key in ("xyz", "rpy"))
    parent = model.frames[model.getFrameId(link)]
    placement = parent.placement * pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)
    frame = model.addFrame(pin.Frame("wbfriction_imu", parent.parentJoint, model.getFrameId(link), placement,
                                     pin.FrameType.OP_FRAME))
    return Imu(int(frame))


def _three(table: dict, key: str, source: str) -> np.ndarray:
    value = table.get(key, [0.0, 0.0, 0.0])
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        out = np.empty(0)
    if out.shape != (3,) or not np.all(np.isfinite(out)):
        raise InputError(f"{source}: [imu] {key} must be 3 numbers, got {value!r}")
    return out


def imu_readings(model: pin.Model, imu: Imu, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """What the IMU reads (N, 6): ``gyro`` then ``acc`` (module docstring), from the full motion ``q`` (N, nq),
    ``v``, ``a`` (N, nv): the simulators' truth."""
    data = model.createData()
    out = np.empty((len(q), 6))
    g = model.gravity.linear
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k], v[k], a[k])
        pin.updateFramePlacements(model, data)
        R = data.oMf[imu.frame].rotation
        out[k, :3] = pin.getFrameVelocity(model, data, imu.frame, pin.LOCAL).angular
        out[k, 3:] = pin.getFrameClassicalAcceleration(model, data, imu.frame, pin.LOCAL).linear - R.T @ g
    return out


def base_motion_from_imu(model: pin.Model, imu: Imu, q: np.ndarray, qd_index: np.ndarray, qd: np.ndarray,
                         qdd: np.ndarray, gyro: np.ndarray, gyro_d: np.ndarray, acc: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
    """The base's twist (linear part zero) and spatial acceleration (N, 6) each, base frame, from the IMU
    (module docstring).

    Args:
        model: the robot's model (with the IMU frame); q: configurations (N, nq), the base's orientation in them.
        qd_index: the velocity indices of the actuated joints (:attr:`Robot.act_v_index`).
        qd, qdd: the actuated joints' velocities and accelerations (N, n_act).
        gyro, gyro_d: the IMU's angular velocity and its time derivative (N, 3), IMU frame.
        acc: the IMU's specific force (N, 3), IMU frame [m/s^2].
    """
    data = model.createData()
    n = len(q)
    v_b, a_b = np.zeros((n, 6)), np.zeros((n, 6))
    v, a = np.zeros(model.nv), np.zeros(model.nv)
    g = model.gravity.linear
    for k in range(n):
        J = pin.computeFrameJacobian(model, data, q[k], imu.frame, pin.LOCAL)
        v[:] = 0.0
        v[qd_index] = qd[k]
        v_b[k, 3:] = np.linalg.solve(J[3:, 3:6], gyro[k] - J[3:] @ v)
        v[3:6] = v_b[k, 3:]
        a[:] = 0.0
        a[qd_index] = qdd[k]
        pin.forwardKinematics(model, data, q[k], v, a)
        pin.updateFramePlacements(model, data)
        drift = pin.getFrameClassicalAcceleration(model, data, imu.frame, pin.LOCAL)
        R = data.oMf[imu.frame].rotation
        measured = np.r_[acc[k] + R.T @ g, gyro_d[k]]
        a_b[k] = np.linalg.solve(J[:, :6], measured - drift.vector)
    return v_b, a_b

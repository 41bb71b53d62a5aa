"""Names of the log format's column groups that several modules write or read (:mod:`wbfriction.logs.log` has
the whole format)."""

from __future__ import annotations

BASE_COLUMNS = ("base.x", "base.y", "base.z", "base.qx", "base.qy", "base.qz", "base.qw")
"""The root's world pose: position [m], then unit quaternion x, y, z, w."""
BASE_TWIST_AXES = ("vx", "vy", "vz", "wx", "wy", "wz")
"""Components of a base twist (Pinocchio's free-flyer ``v[:6]``): linear [m/s], then angular [rad/s], base frame."""
IMU_COLUMNS = tuple(f"imu.{a}" for a in ("gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"))
"""An IMU's columns (:mod:`wbfriction.model.imu`): angular velocity [rad/s], specific force [m/s^2], IMU frame."""
BASE_QD_TRUE_COLUMNS = tuple(f"base_qd_true.{a}" for a in BASE_TWIST_AXES)
"""The base's true twist (simulations only)."""
BASE_QDD_TRUE_COLUMNS = tuple(f"base_qdd_true.{a}" for a in BASE_TWIST_AXES)
"""The base's true acceleration (simulations only)."""

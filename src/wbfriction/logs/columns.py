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
BASE_TRUE_COLUMNS = tuple(f"base_true.{a}" for a in ("x", "y", "z", "qx", "qy", "qz", "qw"))
"""The base's true world pose (simulations only; a raw log's, :mod:`wbfriction.sim.logger`): position [m], then unit
quaternion x, y, z, w."""
TRUTH_PREFIXES = ("tau_f_true", "qd_true", "qdd_true", "base_qd_true", "base_qdd_true", "base_true", "contact_true")
"""The prefixes of the per-item truth columns a simulation writes beside what a robot logs (``<prefix>.<item>``):
never read as measurements (``contact_true.<frame>``: the simulator's own contact state, 0 / 1)."""
TRUTH_COLUMNS = ("time_true", "sample_true", "imu_sample_true")
"""The whole-name truth columns of a raw log (:mod:`wbfriction.sim.logger`): the true time [s] of the drive sample a
row holds, that sample's index (rows repeating a sample share it) and the index of the sample the IMU's update
holds."""


def is_truth_column(name: str) -> bool:
    """Whether the column ``name`` is a simulation's truth (:data:`TRUTH_PREFIXES`, :data:`TRUTH_COLUMNS`), which no
    robot's log has and the estimator never reads as a measurement."""
    return name in TRUTH_COLUMNS or name.partition(".")[0] in TRUTH_PREFIXES

"""A log's angles checked as they are read: within the URDF's limits (an angle in degrees, a length in
millimetres, says so first) and free of wraps (a continuous joint's angle unwrapped; another's jump refused)."""

from __future__ import annotations

import numpy as np

from wbfriction.exceptions import ColumnError
from wbfriction.logs.options import LIMIT_MARGIN
from wbfriction.model.robot import Robot


def check_limits(q: np.ndarray, robot: Robot, source: str, margin: float = LIMIT_MARGIN, first_row: int = 0,
                 prefix: str = "q", joints: tuple[str, ...] | None = None) -> None:
    """Refuse angles beyond the joints' limits (:attr:`~wbfriction.model.robot.Robot.angle_limits`: the URDF's or the
    TOML's ``[angle_limits]``) by more than ``margin`` [rad] (degrees logged as
    radians, millimetres as metres); joints without finite limits are not checked.

    Args:
        q: the logged angles (N, len(joints)) [rad], the encoders' offsets included (taken off here); a continuous
            joint's on any turn (checked on the turn nearest its limits' middle: a joint the TOML's
            ``[angle_limits]`` gives limits the URDF does not).
        robot: the robot: its limits and encoder offsets.
        prefix: the columns' prefix (``q``, ``q_des``).
        joints: the columns' joints, in order (default :attr:`Robot.actuated`).

    Raises:
        InputError: naming the column, the row and the limits.
    """
    lower, upper = robot.angle_limits
    continuous = {robot.actuated[k] for k in robot.layout.q2_joint}
    for i, name in enumerate(joints or robot.actuated):
        k_act = robot.actuated.index(name)
        offset = robot.encoder_offset.get(name, 0.0)
        lo, hi = lower[k_act] + offset, upper[k_act] + offset
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
            continue
        x = q[:, i]
        if name in continuous:  # on the turn nearest the limits' middle
            middle = 0.5 * (lo + hi)
            x = middle + (x - middle + np.pi) % (2 * np.pi) - np.pi
        out = np.flatnonzero((x < lo - margin) | (x > hi + margin))
        if out.size:
            k = out[0]
            raise ColumnError(source, f"{prefix}.{name}", int(first_row + k),
                              f"column '{prefix}.{name}' is {q[k, i]:.6g} at row {first_row + k}, beyond its "
                              f"limits [{lo:.4g}, {hi:.4g}] by more than {margin:g}: wrong units (degrees for "
                              "radians)?")


def unwrap_positions(q: np.ndarray, robot: Robot, source: str, segments: list[tuple[int, int]],
                     first_row: int = 0) -> np.ndarray:
    """Positions (N, n_act) [rad] with every continuous joint (unbounded revolute) unwrapped
    within each segment (:meth:`~wbfriction.model.layout.JointLayout.unwrap`; a logger writes its angle in (-pi, pi]
    or [0, 2pi): a jump of 2 pi between two samples is a wrap, not motion; differentiated across it, it is a 1e5 N·m
    friction).

    Raises:
        ColumnError: another joint whose position jumps by more than pi between two samples of
            a segment (a wrapped angle, or a glitch), naming the column and the row.
    """
    continuous = len(robot.layout.q2_joint) > 0
    out = q.copy() if continuous else q
    for a, b in segments:
        if continuous:
            out[a:b] = robot.layout.unwrap(q[a:b])
        jump = np.abs(np.diff(out[a:b], axis=0)) > np.pi
        if jump.any():
            k, i = np.argwhere(jump)[0]
            name = robot.actuated[i]
            raise ColumnError(source, f"q.{name}", int(first_row + a + k + 1),
                              f"column 'q.{name}' jumps by {out[a + k + 1, i] - out[a + k, i]:.4g} rad at row "
                              f"{first_row + a + k + 1}: a wrapped angle of a joint the URDF does not make "
                              "continuous, or a glitch")
    return out


PAIR_NORM_TOL = 0.2
"""How far the norm of a ``q_cos``/``q_sin`` pair may be from 1: a resolver's or a float32 pair is within a few
per cent; a norm 20 % off is two columns that are not a cosine and a sine of one angle."""


def pair_joints(names: list[str] | tuple[str, ...]) -> list[str]:
    """The joints whose angle a table gives as a cosine/sine pair (a ``q_cos.<joint>`` or ``q_sin.<joint>``
    column), in their columns' order."""
    return list(dict.fromkeys(n.partition(".")[2] for n in names if n.partition(".")[0] in ("q_cos", "q_sin")))


def angles_from_pairs(cos: np.ndarray, sin: np.ndarray, joint: str, source: str, first_row: int = 0) -> np.ndarray:
    """A joint's angle (N,) [rad] from its ``q_cos.<joint>`` and ``q_sin.<joint>`` columns: ``atan2(sin, cos)``,
    unwrapped along the rows (a continuous joint keeps its turns; a bounded joint's turn is
    :func:`nearest_turn`'s).

    Raises:
        ColumnError: a pair whose norm is further than :data:`PAIR_NORM_TOL` from 1 (not a cosine and a sine),
            naming the column and the first such row.
    """
    norm = np.hypot(cos, sin)
    bad = np.flatnonzero(~(np.abs(norm - 1.0) <= PAIR_NORM_TOL))
    if bad.size:
        k = int(bad[0])
        raise ColumnError(source, f"q_cos.{joint}", first_row + k,
                          f"columns 'q_cos.{joint}' and 'q_sin.{joint}' are no cosine/sine pair at row "
                          f"{first_row + k}: norm {norm[k]:.4g}, not 1 (within {PAIR_NORM_TOL:g})")
    return np.unwrap(np.arctan2(sin, cos))


def nearest_turn(q: np.ndarray, robot: Robot, joint: str) -> np.ndarray:
    """A bounded joint's unwrapped angle (N,) [rad] moved by whole turns so that its mean lies nearest the
    middle of its limits (:attr:`Robot.angle_limits`, the encoder's offset included); a continuous joint's, or
    one without finite limits, as it is."""
    lower, upper = robot.angle_limits
    k = robot.actuated.index(joint)
    continuous = {robot.actuated[i] for i in robot.layout.q2_joint}
    offset = robot.encoder_offset.get(joint, 0.0)
    lo, hi = lower[k] + offset, upper[k] + offset
    if joint in continuous or not (np.isfinite(lo) and np.isfinite(hi)) or len(q) == 0:
        return q
    turns = np.rint((0.5 * (lo + hi) - float(np.mean(q))) / (2 * np.pi))
    return q + 2 * np.pi * turns


def rpy_quaternions(rpy: np.ndarray) -> np.ndarray:
    """Unit quaternions (N, 4) x, y, z, w of roll, pitch, yaw angles (N, 3) [rad] in Pinocchio's convention
    (``pin.rpy.rpyToMatrix``: ``R = Rz(yaw) Ry(pitch) Rx(roll)``), each on the hemisphere nearest the previous."""
    from scipy.spatial.transform import Rotation

    from wbfriction.logs.streams import hemisphere
    return hemisphere(Rotation.from_euler("ZYX", np.asarray(rpy, dtype=float)[:, ::-1]).as_quat())


def imu_orientation(rpy: np.ndarray | None, quat: np.ndarray | None, source: str, first_row: int = 0
                    ) -> np.ndarray | None:
    """The IMU frame's orientation in the world as unit quaternions (N, 4) x, y, z, w, from its logged roll, pitch,
    yaw (N, 3) [rad] (:func:`rpy_quaternions`) or quaternion (N, 4) (normalised), or None if neither is logged.

    Raises:
        ColumnError: both given (ambiguous), or a quaternion whose norm is further than :data:`PAIR_NORM_TOL`
            from 1, naming the column and the row.
    """
    if rpy is not None and quat is not None:
        raise ColumnError(source, "imu.qw", None, "the IMU's orientation is given twice, as imu.roll, imu.pitch, "
                          "imu.yaw and as imu.qx ... imu.qw: keep one")
    if rpy is not None:
        return rpy_quaternions(rpy)
    if quat is None:
        return None
    norm = np.linalg.norm(quat, axis=1)
    bad = np.flatnonzero(~(np.abs(norm - 1.0) <= PAIR_NORM_TOL))
    if bad.size:
        k = int(bad[0])
        raise ColumnError(source, "imu.qw", first_row + k, f"the IMU's quaternion is not unit at row {first_row + k} "
                          f"(norm {norm[k]:.4g})")
    return quat / norm[:, None]

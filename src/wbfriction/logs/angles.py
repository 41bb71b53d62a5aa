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

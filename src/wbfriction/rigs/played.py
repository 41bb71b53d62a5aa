"""A set-points table played (``simulate --play``, what ``excite`` writes): read for the rig that plays it, the
motion its metadata holds rebuilt and checked against its ``q_des``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from wbfriction.exceptions import InputError

if TYPE_CHECKING:
    import numpy as np

    from wbfriction.logs.setpoint_table import SetpointTable
    from wbfriction.model.robot import Robot
    from wbfriction.walking.fourier import FourierTrajectory
    from wbfriction.walking.quadruped import QuadrupedReference
    from wbfriction.walking.reference import WalkingReference


def played_series(table: SetpointTable) -> FourierTrajectory:
    """The Fourier series a set-points table holds (its ``fourier`` metadata; the caller checked it has one)."""
    import numpy as np

    from wbfriction.walking.fourier import FourierTrajectory

    f = table.fourier or {}
    return FourierTrajectory(np.asarray(f["center"], dtype=float), np.asarray(f["a"], dtype=float),
                             np.asarray(f["b"], dtype=float), float(f["omega"]))


def check_played(robot: Robot, table: SetpointTable, angles: np.ndarray, what: str) -> None:
    """Refuse a table whose ``q_des`` are more than 1e-6 rad from the rebuilt reference's ``angles`` (N, n_act)
    [rad] (the model's; ``what`` names the reference: ``stance``).

    Raises:
        InputError: one joint's ``q_des`` that far (the table edited, or another robot's model).
    """
    import numpy as np

    off = np.abs(angles + robot.offset_vector - table.q_des).max(axis=0)
    if off.max() > 1e-6:
        raise InputError(f"{table.source}: q_des.{robot.actuated[int(off.argmax())]} is {off.max():.2g} "
                         f"rad from the {what} its series make: not as 'wbfriction excite' wrote it")


def played_arm(robot: Robot, path: Path) -> tuple[SetpointTable, FourierTrajectory]:
    """The set-points table at ``path`` on a fixed-base arm and the trajectory its metadata's Fourier series makes
    (what ``excite`` writes for an arm: the accelerations the arm's feed-forward takes are exact).

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without the
            series.
    """
    from wbfriction.logs.setpoint_table import read_setpoint_table

    table = read_setpoint_table(path, robot)
    if table.fourier is None:
        raise InputError(f"{path}: no Fourier series: an arm plays what 'wbfriction excite' writes for an arm")
    return table, played_series(table)


def played_stance(robot: Robot, path: Path) -> WalkingReference:
    """The reference of a biped's one-foot stance that the set-points table at ``path`` holds (what ``excite
    --stance`` writes): rebuilt from its stance foot, its swing leg's series and its times
    (:func:`~wbfriction.walking.single_support.single_support_reference`), checked against its ``q_des``.

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without a
            stance or series; its ``q_des`` more than 1e-6 rad from the rebuilt reference (edited, or another
            robot's model).
    """
    from wbfriction.logs.setpoint_table import read_setpoint_table
    from wbfriction.walking.single_support import SIDES, single_support_reference

    table = read_setpoint_table(path, robot)
    if table.stance is None or table.fourier is None:
        raise InputError(f"{path}: no stance foot or swing series: a biped plays what 'excite --stance' writes")
    ref = single_support_reference(robot, SIDES.index(table.stance), table.fourier_joints, played_series(table),
                                   table.time)
    check_played(robot, table, robot.angles(ref.q), "stance")
    return ref


def played_tripod(robot: Robot, path: Path) -> QuadrupedReference:
    """The reference of a quadruped's three-feet stance that the set-points table at ``path`` holds (what ``excite
    --swing`` writes): rebuilt from its swing foot, base height, swing leg's series and times
    (:func:`~wbfriction.walking.tripod_support.tripod_support_reference`), checked against its ``q_des``.

    Raises:
        InputError: what :func:`~wbfriction.logs.setpoint_table.read_setpoint_table` raises; a table without a
            swing foot or series; its ``q_des`` more than 1e-6 rad from the rebuilt reference.
    """
    from wbfriction.logs.setpoint_table import read_setpoint_table
    from wbfriction.walking.tripod_support import tripod_support_reference

    table = read_setpoint_table(path, robot)
    if table.swing is None or table.base_height is None or table.fourier is None:
        raise InputError(f"{path}: no swing foot or swing series: a quadruped plays what 'excite --swing' writes")
    ref = tripod_support_reference(robot, robot.contact_frames.index(table.swing), table.fourier_joints,
                                   played_series(table), table.time, table.base_height).reference
    check_played(robot, table, ref.q, "three-feet stance")
    return ref

"""A table of set-points for a robot to play: what ``wbfriction excite`` writes and ``wbfriction simulate --play``
reads (one writer, one reader).

=====================  ==========  ==========================================================================
column                 unit        meaning
=====================  ==========  ==========================================================================
``time``               s           from the motion's start, at the drivers' (or controller's) rate
``q_des.<joint>``      rad         the joint's position set-point, in its encoder's coordinates (the model's
                                   angle plus the robot's ``[encoder_offset]``)
``qd_des.<joint>``     rad/s       the velocity set-point (zeros: the drivers are sent none)
=====================  ==========  ==========================================================================

The metadata (:mod:`wbfriction.logs.metadata`) says ``generator`` (``wbfriction.excite``), the ``robot``, and for a
motion that is a finite Fourier series (an arm's), its coefficients (``fourier``: ``center`` (n,) [rad], ``a``,
``b`` (n, L) [rad/s], ``omega`` [rad/s]; :class:`~wbfriction.walking.fourier.FourierTrajectory`), from which the
motion's accelerations are exact. A humanoid standing on one foot (``excite --stance``) also says the foot stood on
(``stance``: ``left`` or ``right``), and its series are the swing leg's only (``fourier.joints``: their names, n):
the rest of the body follows from them (:mod:`wbfriction.walking.single_support`); without ``joints`` the series are
of every actuated joint. A quadruped standing on three point feet (``excite --swing``) says the foot lifted
(``swing``: its contact frame's name; the three others stand) and the base's height above the ground
(``base_height`` [m]), its series the swing leg's (:mod:`wbfriction.walking.tripod_support`).

The reader checks the table as ``identify`` checks a log, before anything is played: a table whose ``robot`` is
another's (two robots of one class share their joints' names: a Go2's design on an Aliengo) is refused, naming both;
so is a ``q_des`` beyond its joint's limits (:func:`~wbfriction.logs.angles.check_limits`: degrees for radians).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.angles import check_limits
from wbfriction.logs.metadata import read_metadata, with_metadata
from wbfriction.logs.options import LIMIT_MARGIN
from wbfriction.logs.tables import numeric_column, numeric_columns, read_table
from wbfriction.model.robot import Robot

GENERATOR = "wbfriction.excite"


@dataclass(frozen=True)
class SetpointTable:
    """Set-points read from a table (module docstring).

    Attributes:
        source: the file.
        time: (N,) [s], from 0, evenly spaced; rate: its samples per second [Hz].
        joints: the joints (the robot's actuated order).
        q_des, qd_des: (N, n) [rad, rad/s], encoder coordinates.
        fourier: the motion's Fourier coefficients where the table holds them (module docstring), else None.
        fourier_joints: the joints the series are of (the robot's actuated order): all where the metadata names
            none, none without series.
        stance: the foot stood on (``left``, ``right``): a humanoid's one-foot stance; else None.
        swing: the foot lifted (its contact frame's name): a quadruped on three feet; else None.
        base_height: a quadruped on three feet: its base's height above the ground [m]; else None.
    """

    source: str
    time: np.ndarray
    rate: float
    joints: tuple[str, ...]
    q_des: np.ndarray
    qd_des: np.ndarray
    fourier: dict | None = None
    fourier_joints: tuple[str, ...] = ()
    stance: str | None = None
    swing: str | None = None
    base_height: float | None = None

    @property
    def duration(self) -> float:
        """The motion's length [s]: its samples over its rate."""
        return len(self.time) / self.rate


def setpoint_table(robot: str, joints: tuple[str, ...], time: np.ndarray, q_des: np.ndarray, qd_des: np.ndarray,
                   fourier: dict | None = None, fourier_joints: tuple[str, ...] | None = None,
                   stance: str | None = None, swing: str | None = None, base_height: float | None = None,
                   **meta) -> pa.Table:
    """The table (module docstring) of the set-points ``q_des``, ``qd_des`` (N, n) [rad, rad/s] of ``joints`` at
    ``time`` (N,) [s]; ``fourier``: the series' coefficients, of ``fourier_joints`` (None: of ``joints``);
    ``stance``: the foot a humanoid stands on; ``swing``, ``base_height``: the foot a quadruped lifts and its base's
    height [m]; ``meta``: more metadata (JSON-able)."""
    columns = {"time": pa.array(np.asarray(time, dtype=float))}
    for i, j in enumerate(joints):
        columns[f"q_des.{j}"] = pa.array(np.asarray(q_des[:, i], dtype=float))
    for i, j in enumerate(joints):
        columns[f"qd_des.{j}"] = pa.array(np.asarray(qd_des[:, i], dtype=float))
    doc = {"generator": GENERATOR, "robot": robot, **meta}
    if fourier is not None:
        doc["fourier"] = {k: np.asarray(v, dtype=float).tolist() for k, v in fourier.items()}
        if fourier_joints is not None:
            doc["fourier"]["joints"] = list(fourier_joints)
    if stance is not None:
        doc["stance"] = stance
    if swing is not None:
        doc["swing"], doc["base_height"] = swing, None if base_height is None else float(base_height)
    return with_metadata(pa.table(columns), doc)


def read_setpoint_table(path: str | Path, robot: Robot) -> SetpointTable:
    """The set-points of ``robot``'s actuated joints in the table at ``path`` (any format
    :func:`~wbfriction.logs.tables.read_table` reads).

    Raises:
        ColumnError: no ``time`` column, a joint's ``q_des`` column missing or not finite, a ``qd_des`` column
            for some joints only, times not evenly spaced from 0; a ``q_des`` beyond the joint's limits by more
            than :data:`~wbfriction.logs.options.LIMIT_MARGIN` (degrees for radians: what ``identify`` refuses of
            a log, :func:`~wbfriction.logs.angles.check_limits`), naming the column, the row and the robot.
        InputError: a table made for another robot (its metadata's ``robot`` is not ``robot``'s name), naming
            both; fewer than two rows; Fourier coefficients of another number of joints than they name (all
            the robot's where they name none), or of a joint the robot has not; a stance not ``left`` or
            ``right``; a swing foot not one of the robot's contact frames, or without a base height > 0.
    """
    source = str(path)
    table = read_table(path)
    meta = read_metadata(table, source)
    made = meta.get("robot")
    if made is not None and made != robot.name:  # two robots of one class share their joints' names
        raise InputError(f"{source}: set-points made for robot '{made}' (its metadata), not for robot "
                         f"'{robot.name}': play them on '{made}', or design the motion for '{robot.name}' "
                         f"(wbfriction excite --robot {robot.name})")
    for col in ("time", *(f"q_des.{j}" for j in robot.actuated)):
        if col not in table.column_names:
            raise ColumnError(source, col, None, f"missing column '{col}': robot '{robot.name}' plays time and "
                              "q_des.<joint>")
    if table.num_rows < 2:
        raise InputError(f"{source}: {table.num_rows} row(s): set-points need at least two")
    time = numeric_column(table, "time", source)
    step = np.diff(time)
    median = float(np.median(step))
    bad = np.flatnonzero(~(np.abs(step / median - 1.0) <= 1e-6)) if median > 0 else np.arange(len(step))
    rate = (len(time) - 1) / float(time[-1] - time[0]) if not bad.size else 1.0 / median
    if abs(time[0]) > 1e-9 or bad.size:
        row = 0 if abs(time[0]) > 1e-9 else int(bad[0]) + 1
        raise ColumnError(source, "time", row, f"row {row} of column 'time': set-points start at 0 and are evenly "
                          f"spaced (a rate of {rate:g} Hz)")
    q_des = numeric_columns(table, [f"q_des.{j}" for j in robot.actuated], source)
    try:  # a set-point in degrees drives the joint to its limits (a calf to -129 rad), as a log's does
        check_limits(q_des, robot, source, LIMIT_MARGIN, 0, "q_des")
    except ColumnError as exc:
        raise ColumnError(source, exc.column, exc.row, f"{exc.problem} (robot '{robot.name}')") from None
    velocity = [f"qd_des.{j}" for j in robot.actuated]
    there = [c in table.column_names for c in velocity]
    if any(there) and not all(there):
        missing = velocity[there.index(False)]
        raise ColumnError(source, missing, None, f"missing column '{missing}': qd_des.* is given for some joints "
                          "only; give it for every one, or for none")
    qd_des = numeric_columns(table, velocity, source) if all(there) else np.zeros_like(q_des)
    fourier, stance = meta.get("fourier"), meta.get("stance")
    series: tuple[str, ...] = ()
    if fourier is not None:
        named = "joints" in fourier
        series = tuple(fourier.pop("joints", robot.actuated))
        if unknown := [j for j in series if j not in robot.actuated]:
            raise InputError(f"{source}: its Fourier series names joint '{unknown[0]}', not robot '{robot.name}''s")
        if np.shape(fourier.get("center")) != (len(series),):
            of = f"it names {len(series)}" if named else f"robot '{robot.name}' has {len(series)}"
            raise InputError(f"{source}: its Fourier coefficients are of {np.size(fourier.get('center'))} joints, {of}")
    if stance not in (None, "left", "right"):
        raise InputError(f"{source}: its stance {stance!r} is not 'left' or 'right'")
    swing, height = meta.get("swing"), meta.get("base_height")
    if swing is not None and swing not in robot.contact_frames:
        raise InputError(f"{source}: its swing foot {swing!r} is not one of robot '{robot.name}''s feet "
                         f"({', '.join(robot.contact_frames)})")
    if swing is not None and not (isinstance(height, (int, float)) and height > 0):
        raise InputError(f"{source}: its swing foot {swing} without a base height > 0 (base_height: {height!r})")
    return SetpointTable(source, time, rate, robot.actuated, q_des, qd_des, fourier, series, stance, swing,
                         float(height) if swing is not None and height is not None else None)

"""Foot forces: what a quadruped's foot sensors measure (issue 56).

A point foot (:attr:`~wbfriction.model.robot.Robot.contact_kinds`) carries a force, the ground's on the foot, in
world axes [N] (z up: the ground flat and horizontal). A log gives it per contact frame as

* ``force.<frame>.x``, ``force.<frame>.y``, ``force.<frame>.z``: the whole force (research robots' 3-D sensors), or
* ``force.<frame>``: its normal component alone (world z), as Unitree's foot sensors give one number per foot.

A foot's forces are measured in every row or in none (a foot without sensor has no column). Measured components
remove unknowns from the equations of motion (:mod:`wbfriction.model.determination`); a log without
``contact.*`` columns takes its flags from the normal forces (hysteresis, :mod:`wbfriction.logs.contacts`).
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError
from wbfriction.logs.tables import numeric_column
from wbfriction.model.robot import Robot

AXES = ("x", "y", "z")
"""The components of a 3-D foot force, world axes."""


def foot_force_columns(frame: str) -> tuple[str, ...]:
    """The column names a foot's force can have: the normal ``force.<frame>``, then the three components."""
    return (f"force.{frame}",) + tuple(f"force.{frame}.{a}" for a in AXES)


def column_names(robot: Robot) -> set[str]:
    """Every foot-force column a log of ``robot`` may have (the part after ``force.``)."""
    return {c.partition(".")[2] for f in robot.contact_frames for c in foot_force_columns(f)}


def read_foot_forces(table: pa.Table, robot: Robot, source: str, first_row: int = 0) -> np.ndarray | None:
    """The feet's measured forces (N, n_contacts, 3) in world axes [N], NaN for every component not measured (a foot
    without columns; x and y of a foot that logs its normal only); None if no foot force is logged.

    Raises:
        ColumnError: a foot with some of its three components but not all, or with both its normal and its
            components (two readings of one force), naming the column.
    """
    names = set(table.column_names)
    if not any(c in names for f in robot.contact_frames for c in foot_force_columns(f)):
        return None
    out = np.full((table.num_rows, len(robot.contact_frames), 3), np.nan)
    for c, frame in enumerate(robot.contact_frames):
        normal, *axes = foot_force_columns(frame)
        given = [a for a in axes if a in names]
        if given and normal in names:
            raise ColumnError(source, normal, None, f"column '{normal}' and '{given[0]}' both give the force of "
                              f"'{frame}': log its normal force or its three components, not both")
        if given and len(given) < 3:
            missing = next(a for a in axes if a not in names)
            raise ColumnError(source, missing, None, f"the force of '{frame}' is partial: missing column "
                              f"'{missing}' (log all three components, or the normal force as '{normal}')")
        if given:
            out[:, c] = np.column_stack([numeric_column(table, a, source, first_row) for a in axes])
        elif normal in names:
            out[:, c, 2] = numeric_column(table, normal, source, first_row)
    return out


def foot_force_table(robot: Robot, foot_force: np.ndarray) -> dict[str, np.ndarray]:
    """The log columns of ``foot_force`` (N, n_contacts, 3) (:func:`read_foot_forces`'s inverse): a foot measured in
    three components as three columns, a foot whose normal alone is measured as ``force.<frame>``, none for a foot
    not measured."""
    cols: dict[str, np.ndarray] = {}
    for c, frame in enumerate(robot.contact_frames):
        normal, *axes = foot_force_columns(frame)
        measured = np.isfinite(foot_force[:, c]).all(axis=0)
        if measured.all():
            cols.update({a: foot_force[:, c, i] for i, a in enumerate(axes)})
        elif measured[2]:
            cols[normal] = foot_force[:, c, 2]
    return cols


def measured_components(foot_force: np.ndarray | None, n_contacts: int) -> np.ndarray:
    """(n_contacts, 3) which components of each foot's force are measured (finite in the log's first row; a foot's
    columns are all-or-none, :func:`read_foot_forces`); all False without foot forces."""
    if foot_force is None or not len(foot_force):
        return np.zeros((n_contacts, 3), dtype=bool)
    return np.isfinite(foot_force[0])

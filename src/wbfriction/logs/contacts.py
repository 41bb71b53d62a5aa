"""Contact flags from the feet's measured forces, for logs that carry force-torque sensors but no ``contact.*`` columns.

Each contact frame measured by a sensor of the robot (:attr:`~wbfriction.model.robot.Robot.ft_sensors`)
is in contact while the normal force on the sole, the sensor's force turned into the contact frame's
axes, ``n = (R_cs f_s)_z`` [N], is high: a threshold with hysteresis, on above ``on`` and off below
``off`` (between them the flag keeps its last value), so that a force that hovers near one value does
not make the flag chatter. The sole plate's weight and inertia below the sensor (a few newtons) are
left out of ``n``: they are small against the thresholds, which default to 10 % (on) and 5 % (off) of
the robot's weight (:func:`default_thresholds`), or are given in the robot TOML (``contact_force =
[on, off]``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pyarrow as pa

from wbfriction.exceptions import ColumnError
from wbfriction.logs.tables import numeric_column
from wbfriction.model.robot import Robot

ON_SHARE, OFF_SHARE = 0.10, 0.05
"""Default thresholds as shares of the robot's weight: on above 10 %, off below 5 %."""


def default_thresholds(robot: Robot) -> tuple[float, float]:
    """``(on, off)`` [N]: the robot TOML's ``contact_force``, else :data:`ON_SHARE` and :data:`OFF_SHARE`
    of the robot's weight ``m |g|``."""
    if robot.contact_force is not None:
        return robot.contact_force
    weight = pin.computeTotalMass(robot.model) * float(np.linalg.norm(robot.model.gravity.linear))
    return ON_SHARE * weight, OFF_SHARE * weight


def sensed_contacts(robot: Robot) -> bool:
    """Every contact frame of a floating-base robot is measured by one of its force-torque sensors."""
    measured = {s.contact for s in robot.ft_sensors}
    return robot.floating_base and all(f in measured for f in robot.contact_frames)


def normal_forces(robot: Robot, wrench: np.ndarray) -> np.ndarray:
    """The soles' normal forces (N, n_contacts) [N] from the sensors' wrenches (N, n_sensors, 6): each
    sensor's force in its contact frame's axes, z component (module docstring)."""
    model = robot.model
    out = np.zeros((wrench.shape[0], len(robot.contact_frames)))
    for s, sensor in enumerate(robot.ft_sensors):
        contact = model.frames[model.getFrameId(sensor.contact)].placement  # joint -> contact frame
        R_cs = contact.rotation.T @ sensor.placement.rotation  # sensor axes in contact axes
        out[:, robot.contact_frames.index(sensor.contact)] = wrench[:, s, :3] @ R_cs[2]
    return out


def hysteresis(x: np.ndarray, on: float, off: float) -> np.ndarray:
    """Flags (same shape as ``x``, along axis 0): True from where ``x > on`` until ``x < off``, False from
    where ``x < off`` until ``x > on``; before the first crossing, ``x > (on + off) / 2``.

    Raises:
        ValueError: ``off > on``.
    """
    if off > on:
        raise ValueError(f"the off threshold ({off:g}) must not exceed the on threshold ({on:g})")
    x = np.asarray(x, dtype=float)
    event = np.where(x > on, 1, np.where(x < off, 0, -1))  # 1 on, 0 off, -1 keep
    rows = np.arange(x.shape[0]).reshape((-1,) + (1,) * (x.ndim - 1))
    last = np.maximum.accumulate(np.where(event >= 0, rows, -1), axis=0)  # the last event's row
    initial = x[:1] > 0.5 * (on + off)
    state = np.take_along_axis(event, np.maximum(last, 0), axis=0) == 1
    return np.where(last >= 0, state, initial)


def flag_column(table: pa.Table, name: str, source: str, first_row: int = 0) -> np.ndarray:
    """The column ``name`` of 0/1 flags (numbers or booleans) as booleans (N,).

    Raises:
        ColumnError: a value other than 0 and 1, naming the column and the row.
    """
    x = numeric_column(table, name, source, first_row)
    bad = np.flatnonzero((x != 0) & (x != 1))
    if bad.size:
        raise ColumnError(source, name, int(first_row + bad[0]),
                          f"column '{name}' must hold 0 or 1, found {x[bad[0]]:g} at row {first_row + bad[0]}")
    return x.astype(bool)


def read_unsure(table: pa.Table, source: str, first_row: int) -> np.ndarray | None:
    """The ``unsure`` column (0/1) as booleans, or None: the rows whose contact flags were inferred without
    confidence (:mod:`wbfriction.pipeline.raw_log`), which no route estimates.

    Raises:
        ColumnError: a value other than 0 and 1, naming the row.
    """
    return flag_column(table, "unsure", source, first_row) if "unsure" in table.column_names else None

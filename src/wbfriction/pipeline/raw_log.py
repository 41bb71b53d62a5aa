"""A walking robot's log as its logger wrote it, made the project's log from the robot's own sensors.

A real quadruped's low-level log often holds no contact flag, no foot force and no base pose: its angles (or
their cosines and sines), its drives' velocities, torques from motor currents, and an IMU's orientation and
angular rate, on a logger's clock that repeats a sample until the drives write the next one. The point-feet route
(:mod:`wbfriction.friction.point_contacts`) needs each foot's contact state and the base's motion. This stage
makes them from what the log holds, in memory, before the log is read as any other:

1. the logger's rows: repeated samples merged, sample times re-estimated, angles from cosine/sine pairs, slower
   streams on the joints' clock (:func:`~wbfriction.logs.raw_table.condition_raw_table`);
2. the feet's contact states with their confidence, from the legs' torques and kinematics
   (:func:`~wbfriction.signals.contact_inference.infer_contacts`);
3. the base's orientation from the IMU, its velocity and acceleration from the stance legs' kinematics fused with
   the IMU (:func:`~wbfriction.signals.leg_odometry.base_from_legs`).

The result is a log in the project's format: ``contact.<frame>`` the inferred states, ``base.*`` the base's pose
(its position integrated from the fused velocity, its orientation the IMU's), and ``unsure`` (0/1), the rows whose
contact state is not confident, which no route estimates (they are counted, :class:`RawLogSummary`). The
estimate then takes the base's motion as logged (``--base-motion logged``): the pose is differentiated with the
joints' scheme, so the base's accelerations carry the same filter as the joints'.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.columns import BASE_COLUMNS
from wbfriction.logs.options import ReadOptions
from wbfriction.model.robot import Robot

if TYPE_CHECKING:
    from wbfriction.logs.raw_table import RawLogReport
    from wbfriction.signals.contact_inference import InferredContacts
    from wbfriction.signals.leg_odometry import BaseEstimate

UNSURE = "unsure"
"""The column of the rows whose contact state was inferred without confidence (0/1): not estimated."""
IMU_ORIENTATION = (("imu.roll", "imu.pitch", "imu.yaw"), ("imu.qx", "imu.qy", "imu.qz", "imu.qw"))
"""The IMU orientation's columns: roll, pitch, yaw [rad] (Pinocchio's convention), or a unit quaternion."""


@dataclass(frozen=True)
class RawLogSummary:
    """What making a raw log the project's log found (module docstring).

    Attributes:
        rows: the rows the logger wrote; samples: the distinct samples kept.
        clock: one line on the rows merged and the clock re-estimated.
        cues: the contact inference's cues; unsure: rows whose contact state is not confident (not estimated).
        swing_share: per contact frame, the share of samples its foot is off the ground.
        speed: the base's RMS speed estimated [m/s] (its filter's standard deviations are not printed: on the MuJoCo
            twin the error is 3 to 34 times them, the stance feet creeping together:
            :mod:`wbfriction.signals.leg_odometry`).
    """

    rows: int
    samples: int
    clock: str
    cues: tuple[str, ...]
    unsure: int
    swing_share: dict[str, float]
    speed: float

    def lines(self) -> list[str]:
        """What a user reads, one line each."""
        swing = ", ".join(f"{f} {s:.0%}" for f, s in self.swing_share.items())
        return [self.clock,
                f"contacts inferred from {', '.join(self.cues)}: off the ground {swing}; {self.unsure} of "
                f"{self.samples} samples not confident, left out",
                f"base velocity from the stance legs and the IMU: RMS speed {self.speed:.3f} m/s"]


def is_raw(robot: Robot, columns: set[str] | list[str]) -> bool:
    """Whether a log with these columns needs this stage: a floating base on point feet, no ``contact.*`` column,
    no foot force or sensor wrench that gives the flags, no base pose, and the IMU's orientation."""
    from wbfriction.logs.log import forces_give_contacts

    seen = set(columns)
    if not (robot.floating_base and robot.partial_contacts):
        return False
    if any(f"contact.{f}" in seen for f in robot.contact_frames) or forces_give_contacts(robot, seen):
        return False
    if any(c in seen for c in BASE_COLUMNS):
        return False
    return any(all(c in seen for c in group) for group in IMU_ORIENTATION)


def _orientation(table: pa.Table, source: str) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``(rpy (N, 3), quaternion (N, 4))``, one of them None: the IMU's logged orientation."""
    from wbfriction.logs.tables import numeric_columns

    rpy_cols, quat_cols = IMU_ORIENTATION
    names = set(table.column_names)
    if all(c in names for c in quat_cols):
        return None, numeric_columns(table, list(quat_cols), source, 0)
    return numeric_columns(table, list(rpy_cols), source, 0), None


@dataclass(frozen=True)
class PreparedLog:
    """A raw log made the project's log (:func:`prepare_raw`).

    Attributes:
        table: the log in the project's format (module docstring).
        report: what merging the logger's repeats did (:class:`~wbfriction.logs.raw_table.RawLogReport`).
        contacts: the feet's inferred contact states (:class:`~wbfriction.signals.contact_inference.InferredContacts`).
        base: the base's motion (:class:`~wbfriction.signals.leg_odometry.BaseEstimate`).
    """

    table: pa.Table
    report: RawLogReport
    contacts: InferredContacts
    base: BaseEstimate

    def summary(self, robot: Robot) -> RawLogSummary:
        """What a user is told of it."""
        speed = np.linalg.norm(self.base.twist[:, :3], axis=1)
        contact = self.contacts.contact
        return RawLogSummary(self.report.rows, len(contact), self.report.reason, self.contacts.cues,
                             int(self.contacts.unconfident_rows().sum()),
                             {f: float(np.mean(~contact[:, i])) for i, f in enumerate(robot.contact_frames)},
                             float(np.sqrt(np.mean(speed ** 2))))


def prepare_raw(table: pa.Table, robot: Robot, source: str, read: ReadOptions = ReadOptions()) -> PreparedLog:
    """The raw log ``table`` as the project's log (module docstring).

    Args:
        table: the log as the logger wrote it (:func:`is_raw`).
        robot: the robot: point feet, its ``[imu]``.
        source: the log's name, for the messages.
        read: how the log is read (its nominal rate where it has no stamps).

    Returns:
        The table with ``time``, ``q.<joint>``, ``contact.<frame>``, ``base.*`` and ``unsure`` (the rows not
        confident), every other column but the IMU's carried, and what was found on the way.

    Raises:
        InputError: a robot without ``[imu]``; what conditioning, inferring and fusing raise (too few distinct
            samples, no foot leaving the ground, no stance foot), one line naming the log.
    """
    from wbfriction.logs.raw_table import condition_raw_table
    from wbfriction.logs.tables import numeric_columns
    from wbfriction.signals.contact_inference import MIN_SAMPLES, infer_contacts
    from wbfriction.signals.leg_odometry import base_from_legs, base_rotation, imu_rotation

    if robot.imu is None:
        raise InputError(f"{source}: robot '{robot.name}' has no [imu] in its TOML: a log without contact flags and "
                         "base pose needs the IMU's placement to take the base's motion from it")
    table, report = condition_raw_table(table, robot, source, read, min_samples=MIN_SAMPLES)  # the inference's
    t = numeric_columns(table, ["time"], source, 0)[:, 0]
    q = numeric_columns(table, [f"q.{j}" for j in robot.actuated], source, 0)
    q = q - robot.offset_vector if robot.encoder_offset else q  # the model's angles (wbfriction.model.pd)
    tau = _torque(table, robot, source, t, q)
    dt = float(np.median(np.diff(t)))
    qd, qdd = _derivatives(table, robot, source, t, q, tau)
    rpy, quat = _orientation(table, source)
    r_imu = imu_rotation(robot, roll_pitch_yaw=rpy, quaternion=quat)
    gyro = numeric_columns(table, ["imu.gyro_x", "imu.gyro_y", "imu.gyro_z"], source, 0)
    acc_cols = ["imu.acc_x", "imu.acc_y", "imu.acc_z"]
    acc = numeric_columns(table, acc_cols, source, 0) if all(c in table.column_names for c in acc_cols) else None
    counts_cols = [f"foot_count.{f}" for f in robot.contact_frames]
    counts = numeric_columns(table, counts_cols, source, 0) if all(c in table.column_names for c in counts_cols) \
        else None
    contacts = infer_contacts(robot, q, qd, tau, base_rotation(robot, q, r_imu), dt, foot_counts=counts,
                              source=source)
    base = base_from_legs(robot, q, qd, qdd, r_imu, gyro, contacts.contact, contacts.confident, dt, acc=acc,
                          source=source)
    out = _with_columns(table, robot, contacts.contact, base.pose, contacts.unconfident_rows())
    return PreparedLog(out, report, contacts, base)


def _torque(table: pa.Table, robot: Robot, source: str, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(N, n_act) the joints' torques as the log's torque source gives them (:mod:`wbfriction.logs.torque`; 0 for a
    joint that is not torque-controlled)."""
    from wbfriction.logs.torque import TorqueColumns, torque_source_of

    given = TorqueColumns(table, robot, source, 0, t, q, None)
    tau_tc = torque_source_of(given).torque(given)
    tau = np.zeros_like(q)
    tau[:, [robot.actuated.index(j) for j in robot.torque_controlled]] = tau_tc
    return tau


def _derivatives(table: pa.Table, robot: Robot, source: str, t: np.ndarray, q: np.ndarray, tau: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """``(qd, qdd)`` (N, n_act): the drives' velocities where logged (``qd.<joint>``, else differentiated) and the
    angles differentiated twice, with the scheme and window the estimate's own decision takes on these angles
    (:func:`~wbfriction.friction.decision.decide_log`)."""
    from wbfriction.friction.decision import decide_log
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.logs.log import Log
    from wbfriction.logs.tables import numeric_columns
    from wbfriction.signals.kinematics import measure
    from wbfriction.signals.options import SCHEMES, Diff

    dt = float(np.median(np.diff(t)))
    options = decide_log(robot, EstimateOptions(), q, dt, segments=None, rows=len(t), source=source).options
    contact = np.zeros((len(t), len(robot.contact_frames)), dtype=bool)
    diff = cast(Diff, options.diff if options.diff in SCHEMES else "central")  # decided: no longer "auto"
    kin = measure(Log(t, q, tau[:, [robot.actuated.index(j) for j in robot.torque_controlled]], contact,
                      source=source), diff, filtering=options.filtering)
    qdd = np.nan_to_num(kin.qdd)
    qd_cols = [f"qd.{j}" for j in robot.actuated]
    if all(c in table.column_names for c in qd_cols):
        return numeric_columns(table, qd_cols, source, 0), qdd
    return np.nan_to_num(kin.qd), qdd


def _with_columns(table: pa.Table, robot: Robot, contact: np.ndarray, pose: np.ndarray, unsure: np.ndarray
                  ) -> pa.Table:
    """``table`` with the inferred ``contact.<frame>``, the base's ``base.*`` and ``unsure``, and without the IMU's
    columns (its orientation and rates are in ``base.*`` now: the estimate differentiates the pose)."""
    keep = [c for c in table.column_names if not c.startswith("imu.")]
    out = table.select(keep)
    for i, f in enumerate(robot.contact_frames):
        out = out.append_column(f"contact.{f}", pa.array(contact[:, i].astype(np.int8)))
    for k, c in enumerate(BASE_COLUMNS):
        out = out.append_column(c, pa.array(pose[:, k]))
    return out.append_column(UNSURE, pa.array(unsure.astype(np.int8)))


@contextmanager
def prepared_log(path: Path, robot: Robot, source: str, read: ReadOptions, near: Path
                 ) -> Iterator[tuple[Path, RawLogSummary | None]]:
    """The log at ``path`` as the estimate reads it: a log in the project's format as it is (summary None); a raw
    log (:func:`is_raw`) made one (:func:`prepare_raw`) into a temporary Parquet log in a temporary folder beside
    ``near`` (the output), removed on leaving. The raw log is read whole (a walking log of minutes).

    Raises:
        InputError: what :func:`prepare_raw` raises.
        OutputError: a temporary log the system refuses to write, naming ``near``.
    """
    from wbfriction.exceptions import OutputError
    from wbfriction.logs.tables import TableFile, read_table, scratch_folder, write_tables

    if not is_raw(robot, TableFile(path).schema().names):
        yield path, None
        return
    prepared = prepare_raw(read_table(path), robot, source, read)
    folder = near.parent if near.parent.exists() else None
    with scratch_folder(folder) as tmp:
        converted = Path(tmp) / "log.parquet"
        try:
            write_tables(converted, iter([prepared.table]))
        except OutputError as exc:  # the temporary file's name means nothing to the user: the output's does
            raise OutputError(str(near), exc.errno, exc.reason, near.is_file()) from exc
        yield converted, prepared.summary(robot)

"""The wbfriction log format: reading, validation, and atomic writing of tables.

A log is a Parquet file (or CSV with the same columns, or HDF5: :mod:`wbfriction.logs.hdf5`),
one row per sample:

=====================  ==========  ==================================================
column                 unit        content
=====================  ==========  ==================================================
``time``               s           strictly increasing (float s, or integer ns); uniform,
                                   skipping or jittered (:mod:`wbfriction.logs.clock`)
``q.<joint>``          rad (m)     position of every actuated joint
``tau.<joint>``        N·m (N)     measured torque of every torque-controlled joint
                                   (joint torque sensor), or else:
``current.<joint>``    A           motor current of every torque-controlled joint,
                                   times the robot's ``[torque_constants]``
``contact.<frame>``    0 / 1       contact flag of every contact frame (floating
                                   base only: a fixed base is always welded)
``qd.<joint>``         rad/s       optional velocity as the robot logged it (used
                                   with ``--velocity logged``)
``base.x`` ... ``base.qw``  m, -   optional world pose of the root (unit quaternion
                                   x, y, z, w)
``temperature.<joint>`` °C         optional motor or gear temperature of a
                                   torque-controlled joint (friction's temperature
                                   term, :mod:`wbfriction.fit.terms`)
``tau_f_true.<joint>`` N·m         optional true friction (simulations only; never
                                   used by the estimator)
``qd_true.<joint>``    rad/s       optional true velocity of every actuated joint
``qdd_true.<joint>``   rad/s²      optional true acceleration (simulations only;
                                   used only with ``diff="true"``)
=====================  ==========  ==================================================

Names are those of the model. ``tau.<joint>`` of a position-controlled joint is
allowed and ignored. Schema metadata under the key ``wbfriction`` (JSON) is carried
through, e.g. the friction parameters a simulator injected.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.angles import check_limits, imu_orientation, unwrap_positions
from wbfriction.logs.clock import JITTER, Clock, read_clock, split_at_gaps, table_stamps
from wbfriction.logs.columns import BASE_COLUMNS, BASE_QD_TRUE_COLUMNS, BASE_QDD_TRUE_COLUMNS, IMU_COLUMNS
from wbfriction.logs.contacts import (
    default_thresholds,
    flag_column,
    hysteresis,
    normal_forces,
    read_unsure,
    sensed_contacts,
)
from wbfriction.logs.foot_forces import column_names as foot_force_names
from wbfriction.logs.foot_forces import foot_force_columns, foot_force_table, read_foot_forces
from wbfriction.logs.options import MAX_GAP, ReadOptions
from wbfriction.logs.pd import PdSetpoints, read_setpoints, setpoint_columns
from wbfriction.logs.raw_table import condition_raw_table
from wbfriction.logs.streams import ANGLE_COLUMNS, QUATERNION_COLUMNS
from wbfriction.logs.tables import numeric_column, numeric_columns, read_metadata, with_metadata, write_table
from wbfriction.logs.temperature import screen_temperature
from wbfriction.logs.torque import (
    TorqueColumns,
    TorqueSource,
    check_torque_columns,
    rotor_inertia_warnings,
    torque_columns_named,
    torque_kind,
    torque_source_of,
)
from wbfriction.model.robot import Robot


@dataclass
class Log:
    """A validated log, with columns mapped to the robot's joints by name.

    Attributes:
        time: sample times (N,) [s], as recorded (absolute, e.g. Unix epoch); the time base
            derivatives are taken on is :attr:`clock`'s.
        q: joint positions (N, n_act) in :attr:`Robot.actuated` order [rad].
        tau: torques of the torque-controlled joints (N, n_tc) [N·m].
        contact: contact flags (N, n_contacts) in :attr:`Robot.contact_frames` order.
        base: root poses (N, 7) (x, y, z, qx, qy, qz, qw), or None if not logged.
        tau_f_true: true friction (N, n_tc) [N·m] with NaN columns for joints not
            logged, or None if no such column.
        metadata: the JSON metadata stored with the log.
        source: file the log came from.
        qd_true, qdd_true: true joint velocities [rad/s] and accelerations [rad/s^2]
            (N, n_act) (simulations only, for evaluation), or None.
        segments: row ranges between time gaps (:func:`check_time`); None: one segment.
        period: the sampling period of the log this one was cut from [s] (its segments, a
            chunk of a long log), so that every stretch is differentiated with the same one;
            None: the clock's nominal step, else the median step of ``time``.
        qd_logged: joint velocities as the robot logged them (``qd.<joint>`` columns)
            (N, n_act) [rad/s], or None; used with ``--velocity logged`` only.
        torque_source: where ``tau`` comes from, the name of a registered torque source
            (:mod:`wbfriction.logs.torque`): ``"sensor"`` (link-side joint torque sensors: only the friction after
            the sensor is in it), ``"driver"`` (the motor drivers' own estimates, ``tau_est.<joint>``),
            ``"current"`` (motor current x torque constant) or ``"pd"`` (the drivers' PD law on the logged
            set-points, :mod:`wbfriction.logs.pd`); the last three are the motor's torque: the whole drive's
            friction and the rotor inertia are in it.
        setpoints: a PD-driven robot's set-points and driver velocities
            (:class:`~wbfriction.logs.pd.PdSetpoints`), or None.
        wrench: measured wrenches of the robot's force-torque sensors (N, n_sensors, 6) in
            :attr:`Robot.ft_sensors <wbfriction.model.robot.Robot.ft_sensors>` order, each in its
            sensor frame [N, N·m] (columns ``wrench.<sensor>.fx`` ... ``.tz``,
            :mod:`wbfriction.model.force_torque`), or None if not logged.
        foot_force: the feet's measured forces (N, n_contacts, 3), world axes [N], NaN where not measured (columns
            ``force.<frame>.x`` ... ``.z``, or the normal ``force.<frame>``: :mod:`wbfriction.logs.foot_forces`),
            or None.
        unsure: (N,) the rows whose contact flags were inferred without confidence (column ``unsure``, 0/1, written
            by :mod:`wbfriction.pipeline.raw_log`): no route estimates them; None: every row's flags are sure.
        imu: the IMU's readings (N, 6): angular velocity [rad/s] and specific force [m/s^2] in its frame
            (columns ``imu.gyro_x`` ... ``imu.acc_z``, :mod:`wbfriction.model.imu`), or None; a gyro logged without
            an accelerometer has NaN specific-force columns.
        imu_orientation: the IMU frame's orientation in the world (N, 4), unit quaternions x, y, z, w (columns
            ``imu.qx`` ... ``imu.qw``, or ``imu.roll``, ``imu.pitch``, ``imu.yaw`` in Pinocchio's convention
            ``R = Rz(yaw) Ry(pitch) Rx(roll)``: :func:`~wbfriction.logs.angles.imu_orientation`), or None.
        foot_counts: the feet's raw force-sensor counts (N, n_contacts) in :attr:`Robot.contact_frames` order
            (columns ``foot_count.<frame>``, no unit: an offset and a scale unknown), or None.
        temperature: the torque-controlled joints' temperatures (N, n_tc) [°C] (``temperature.<joint>`` columns),
            NaN for a joint not logged, or None if no such column.
        base_qd_true, base_qdd_true: the base's true twist and its derivative (N, 6) in the base
            frame (Pinocchio's free-flyer ``v[:6]`` and ``a[:6]``, simulations only), or None.
        clock: what wrote the stamps and the time base derivatives are taken on
            (:class:`~wbfriction.logs.clock.Clock`: uniform, skipping samples, or receive-time
            jitter regularised), or None: uniform (a log built in memory).
        warnings: what reading the log found that costs accuracy without making it wrong (e.g.
            float32 columns, :func:`check_schema`), one line each.
    """

    time: np.ndarray
    q: np.ndarray
    tau: np.ndarray
    contact: np.ndarray
    base: np.ndarray | None = None
    tau_f_true: np.ndarray | None = None
    metadata: dict = field(default_factory=dict)
    source: str = "<memory>"
    qd_true: np.ndarray | None = None
    qdd_true: np.ndarray | None = None
    segments: list[tuple[int, int]] | None = None
    period: float | None = None
    qd_logged: np.ndarray | None = None
    torque_source: TorqueSource = "sensor"
    clock: Clock | None = None
    warnings: tuple[str, ...] = ()
    wrench: np.ndarray | None = None
    base_qd_true: np.ndarray | None = None
    base_qdd_true: np.ndarray | None = None
    imu: np.ndarray | None = None
    temperature: np.ndarray | None = None
    setpoints: PdSetpoints | None = None
    foot_force: np.ndarray | None = None
    imu_orientation: np.ndarray | None = None
    foot_counts: np.ndarray | None = None
    unsure: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.segments is None and self.clock is not None and len(self.clock.segments) > 1:
            self.segments = list(self.clock.segments)  # a clock's gaps split the log

    @property
    def dt(self) -> float:
        """Sampling period [s]: :attr:`period` if set, else the clock's nominal step
        (:attr:`Clock.step <wbfriction.logs.clock.Clock.step>`), else the median time step."""
        if self.period is not None:
            return self.period
        return self.clock.step if self.clock is not None else float(np.median(np.diff(self.time)))

    def parts(self) -> list[Log]:
        """The log's segments (split at its time gaps, :func:`check_time`) as logs of their own."""
        bounds = self.segments or [(0, len(self.time))]
        if len(bounds) == 1:
            return [self]
        return [self.rows(a, b) for a, b in bounds]

    def rows(self, start: int, stop: int) -> Log:
        """The rows ``[start, stop)`` as a log (arrays are views)."""
        cut = lambda x: None if x is None else x[start:stop]  # noqa: E731
        return Log(self.time[start:stop], self.q[start:stop], self.tau[start:stop], self.contact[start:stop],
                   cut(self.base), cut(self.tau_f_true), self.metadata, self.source, cut(self.qd_true),
                   cut(self.qdd_true), None, self.dt, cut(self.qd_logged), self.torque_source,
                   clock=None if self.clock is None else self.clock.rows(start, stop), warnings=self.warnings,
                   wrench=cut(self.wrench), base_qd_true=cut(self.base_qd_true),
                   base_qdd_true=cut(self.base_qdd_true), imu=cut(self.imu),
                   temperature=cut(self.temperature),
                   setpoints=None if self.setpoints is None else self.setpoints.rows(start, stop),
                   foot_force=cut(self.foot_force), imu_orientation=cut(self.imu_orientation),
                   foot_counts=cut(self.foot_counts), unsure=cut(self.unsure))

    def __len__(self) -> int:
        return len(self.time)

    def to_table(self, robot: Robot) -> pa.Table:
        """The log as an Arrow table in the log format."""
        cols: dict[str, np.ndarray] = {"time": self.time}
        offset = robot.encoder_offset  # the logged angle is the model's plus the encoder's offset
        cols.update({f"q.{n}": self.q[:, i] + offset[n] if n in offset else self.q[:, i]
                     for i, n in enumerate(robot.actuated)})
        cols.update(torque_kind(self.torque_source).columns(self.tau, robot, self.setpoints))
        if self.setpoints is not None and robot.pd is not None:  # kept whatever the torque's source
            cols.update(setpoint_columns(self.setpoints, robot.pd.joints))
        if robot.floating_base:
            cols.update({f"contact.{n}": self.contact[:, i].astype(np.int8)
                         for i, n in enumerate(robot.contact_frames)})
        for names, x in ((BASE_COLUMNS, self.base), (BASE_QD_TRUE_COLUMNS, self.base_qd_true),
                         (BASE_QDD_TRUE_COLUMNS, self.base_qdd_true), (IMU_COLUMNS, self.imu),
                         (QUATERNION_COLUMNS, self.imu_orientation),
                         ([f"foot_count.{f}" for f in robot.contact_frames], self.foot_counts)):
            if x is not None:  # an accelerometer not logged is not written
                cols.update({c: x[:, i] for i, c in enumerate(names) if not np.all(np.isnan(x[:, i]))})
        if self.foot_force is not None:
            cols.update(foot_force_table(robot, self.foot_force))
        if self.wrench is not None:
            cols.update({c: self.wrench[:, s, i] for s, sensor in enumerate(robot.ft_sensors)
                         for i, c in enumerate(sensor.columns())})
        for prefix, x in (("tau_f_true", self.tau_f_true), ("temperature", self.temperature)):
            if x is not None:
                cols.update({f"{prefix}.{n}": x[:, i] for i, n in enumerate(robot.torque_controlled)
                             if not np.all(np.isnan(x[:, i]))})
        for prefix, x in (("qd", self.qd_logged), ("qd_true", self.qd_true), ("qdd_true", self.qdd_true)):
            if x is not None:
                cols.update({f"{prefix}.{n}": x[:, i] for i, n in enumerate(robot.actuated)})
        if self.unsure is not None:
            cols["unsure"] = self.unsure.astype(np.int8)
        return with_metadata(pa.table(cols), self.metadata)


def check_time(time: np.ndarray, source: str, max_gap: float = MAX_GAP,
               rel_tol: float = JITTER, first_row: int = 0) -> list[tuple[int, int]]:
    """Check a time column and split it at its gaps (:func:`~wbfriction.logs.clock.split_at_gaps`).

    A step of at least ``max_gap`` times the local median step (less ``rel_tol``) is a gap,
    which ends a segment (a log with dropped samples or pauses is estimated segment by
    segment, never differentiated across a gap). Irregular steps are accepted: what kind of
    clock wrote them is :func:`~wbfriction.logs.clock.read_clock`'s to decide.

    Args:
        time: stamps (N,): float seconds or integer nanoseconds.

    Returns:
        The segments as half-open row ranges ``[(a, b), ...]`` covering every row.

    Raises:
        InputError: fewer than 5 rows; ColumnError: a non-finite, duplicated or decreasing
            stamp, naming column ``time`` and the first row at fault (counted from ``first_row``).
    """
    return split_at_gaps(time, source, max_gap, rel_tol, first_row)


def log_from_table(table: pa.Table, robot: Robot, source: str = "<table>", read: ReadOptions = ReadOptions(),
                   first_row: int = 0, period: float | None = None, *, clock: Clock | None = None) -> Log:
    """Validate an Arrow table against ``robot`` and map its columns by joint name.

    Args:
        read: how the log is read (:class:`~wbfriction.logs.options.ReadOptions`): the gaps that split it
            (``max_gap``, :func:`check_time`), the tolerance on the URDF joint limits (``limit_margin``,
            :func:`check_limits`), the time base (``time_base``, :data:`~wbfriction.logs.clock.TimeBase`; not used
            with ``clock``) and the unit of a numeric ``time`` column (``time_unit``,
            :func:`~wbfriction.logs.clock.table_stamps`: needed for integers; floats are seconds by default).
        first_row: row number of the table's first row in its file (a chunk of a long log),
            for the messages.
        period: the sampling period of the whole log, for a chunk of it (:attr:`Log.period`).
        clock: the whole log's clock cut to this chunk's rows
            (:meth:`Clock.rows <wbfriction.logs.clock.Clock.rows>`), so that a log estimated in
            chunks is the whole log's; None: read from this table's stamps and positions
            (:func:`~wbfriction.logs.clock.read_clock`).

    Raises:
        InputError: what :func:`check_schema` refuses, NaN, a duplicated or decreasing time
            column or one whose unit is unknown, positions far beyond the joint limits or that
            jump by more than pi between two samples (a wrapped angle), contact flags other than
            0/1, a partial base pose, or a non-unit quaternion.
    """
    raw = None
    if clock is None:  # a whole log (a chunk's table was conditioned with the whole log): as a logger wrote it
        table, raw = condition_raw_table(table, robot, source, read)
        read = replace(read, time_unit=None) if raw.restamped else read
    warnings = check_schema(table.schema, robot, source) + ((f"{source}: {raw.reason}",) if raw and raw.reason else ())
    time, clock, q = _read_motion(table, robot, source, read, first_row, clock,
                                   raw is not None and raw.drive_period is not None)
    qd_logged = _read_true_rates(table, "qd", robot, source, first_row)
    setpoints = read_setpoints(table, robot, time, q, qd_logged, source, first_row)
    if setpoints is not None and robot.pd is not None:  # a set-point in degrees drives the joint to its limits
        check_limits(setpoints.q_des, robot, source, read.limit_margin, first_row, "q_des", robot.pd.joints)
    kind = torque_source_of(given := TorqueColumns(table, robot, source, first_row, time, q, setpoints))
    tau = kind.torque(given)  # one source for every joint (wbfriction.logs.torque)
    q = q - robot.offset_vector if robot.encoder_offset else q  # the model's angles (wbfriction.model.pd)
    wrench = _read_wrench(table, robot, source, first_row)
    foot_force = read_foot_forces(table, robot, source, first_row)
    contact = _read_contact(table, robot, source, first_row, wrench, foot_force)
    base = _read_base(table, source, first_row)
    tau_f_true = _read_per_joint(table, "tau_f_true", robot, len(time), source, first_row)
    temperature = _read_per_joint(table, "temperature", robot, len(time), source, first_row)
    if temperature is not None:  # units, plausibility, glitches (wbfriction.logs.temperature)
        temperature, glitched = screen_temperature(temperature, robot.torque_controlled, source, first_row)
        warnings = warnings + glitched
    qd_true = _read_true_rates(table, "qd_true", robot, source, first_row)
    qdd_true = _read_true_rates(table, "qdd_true", robot, source, first_row)
    base_qd_true = _read_group(table, BASE_QD_TRUE_COLUMNS, source, first_row, "true base twist")
    base_qdd_true = _read_group(table, BASE_QDD_TRUE_COLUMNS, source, first_row, "true base acceleration")
    imu = _read_imu(table, source, first_row)
    orientation = imu_orientation(_read_group(table, ANGLE_COLUMNS, source, first_row, "the IMU's roll, pitch, yaw"),
                                  _read_group(table, QUATERNION_COLUMNS, source, first_row, "the IMU's quaternion"),
                                  source, first_row)
    foot_counts = _read_group(table, [f"foot_count.{f}" for f in robot.contact_frames], source, first_row,
                              "the feet's force counts")
    metadata = read_metadata(table, source)
    if kind.alignment is not None:  # e.g. the PD law's: each sample's torque its period's mean (wbfriction.model.pd)
        metadata = {"torque_alignment": kind.alignment, **metadata}
    return Log(time, q, tau, contact, base, tau_f_true, metadata, source,
               qd_true=qd_true, qdd_true=qdd_true, segments=clock.segments, period=period, qd_logged=qd_logged,
               torque_source=kind.name, clock=clock, warnings=warnings, wrench=wrench,
               base_qd_true=base_qd_true, base_qdd_true=base_qdd_true, imu=imu, temperature=temperature,
               setpoints=setpoints, foot_force=foot_force, imu_orientation=orientation, foot_counts=foot_counts,
               unsure=read_unsure(table, source, first_row))


NUMERIC_PREFIXES = ("q", "qd", "qd_true", "qdd_true", "tau_f_true", "base", "wrench", "force", "base_qd_true",
                    "base_qdd_true", "imu", "temperature", "q_cos", "q_sin", "foot_count")
"""Column prefixes whose values must be numbers, besides those of the torque sources (each source's own:
:meth:`TorqueKind.named <wbfriction.logs.torque.TorqueKind.named>`)."""


def check_schema(schema: pa.Schema, robot: Robot, source: str) -> tuple[str, ...]:
    """Check a log's columns against ``robot`` from its schema alone, before any row is read:
    names (no duplicate, none naming an unknown joint or frame, none required missing) and
    types (numbers; contact flags as numbers or booleans; ``time`` as numbers or timestamps). The torque
    columns are those every registered torque source says it reads
    (:meth:`TorqueKind.named <wbfriction.logs.torque.TorqueKind.named>`), a registered one's as a built-in one's.

    Returns:
        Warnings, one line each: float32 columns (7 significant digits: the accelerations
        differentiated from such positions are noisier; nothing is refused); torques from the motors' currents on a
        robot whose model has no rotor inertia (:func:`~wbfriction.logs.torque.rotor_inertia_warnings`).

    Raises:
        ColumnError: a duplicated column name, a missing ``time`` or required column, a column
            naming an unknown joint or contact frame, a column of a type that is not a number.
    """
    names = list(schema.names)
    seen: set[str] = set()
    for col in names:
        if col in seen:
            raise ColumnError(source, col, None, f"column '{col}' appears {names.count(col)} times")
        seen.add(col)
    if "time" not in seen:
        raise ColumnError(source, "time", None, "missing column 'time': a log without stamps is read at its "
                          "logger's nominal rate: give it with --rate HZ")
    act, tc = set(robot.actuated), set(robot.torque_controlled)
    wrenches = {c.partition(".")[2] for s in robot.ft_sensors for c in s.columns()}
    torque = torque_columns_named(robot)  # every registered source's columns, as it says them
    named: dict[str, set[str] | None] = {
        **torque, "q": act, "tau_f_true": tc, "temperature": tc, "contact": set(robot.contact_frames),
        "qd_true": act, "qdd_true": act, "qd": act, "wrench": wrenches,
        "imu": {c.partition(".")[2] for c in IMU_COLUMNS + ANGLE_COLUMNS + QUATERNION_COLUMNS},
        "force": foot_force_names(robot), "q_cos": act, "q_sin": act, "foot_count": set(robot.contact_frames)}
    for col in names:
        prefix, _, item = col.partition(".")
        known = named.get(prefix)
        if known is not None and item not in known:
            what = {"contact": "contact frame", "wrench": "force-torque sensor (or axis)", "force": "foot (or axis)",
                    "imu": "IMU axis"}.get(prefix, "joint")
            raise ColumnError(source, col, None,
                              f"column '{col}' names an unknown {what} '{item}' of robot '{robot.name}'")
    contact = [f"contact.{f}" for f in robot.contact_frames] if robot.floating_base else []
    if contact and not any(c in seen for c in contact) and forces_give_contacts(robot, seen):
        contact = []  # flags from the measured forces (wbfriction.logs.contacts)
    paired = [f"q.{n}" for n in robot.actuated if f"q_cos.{n}" in seen and f"q_sin.{n}" in seen]  # a raw log's
    for col in [f"q.{n}" for n in robot.actuated if f"q.{n}" not in paired] + contact:
        if col not in seen:
            raise ColumnError(source, col, None, f"missing column '{col}'")
    check_torque_columns(robot, seen, source)  # every joint's torque from a registered source
    single = []
    for f in schema:
        prefix = f.name.partition(".")[0]
        number = pa.types.is_integer(f.type) or pa.types.is_floating(f.type)
        if f.name == "time":
            ok = number or pa.types.is_timestamp(f.type)
        elif prefix == "contact":
            ok = number or pa.types.is_boolean(f.type)
        elif prefix in NUMERIC_PREFIXES or prefix in torque:
            ok = number
        else:
            continue  # a column the log format does not use
        if not ok:
            hint = "; contact flags are 0/1 (integers) or booleans" if prefix == "contact" else ""
            raise ColumnError(source, f.name, None, f"column '{f.name}' holds {f.type} values, not numbers{hint}")
        if pa.types.is_floating(f.type) and f.type.bit_width < 64:
            single.append(f.name)
    motor = rotor_inertia_warnings(robot, seen, source)  # torques from currents, no rotor inertia in the model
    return single_precision_warnings(schema, single, source) + motor


def single_precision_warnings(schema: pa.Schema, single: list[str], source: str) -> tuple[str, ...]:
    """One line on the ``single`` (float32 or shorter) columns of ``schema``: each kind's rounding in its unit, and
    whether the accelerations differentiated from them amplify it; none if there is none."""
    if not single:
        return ()
    shown = ", ".join(single[:3]) + (f" and {len(single) - 3} more" if len(single) > 3 else "")
    prefixes = list(dict.fromkeys(n.partition(".")[0] for n in single))
    sizes = []  # each kind of column in its own unit: the rounding at a typical value (issue 53)
    for prefix in prefixes:
        typical, unit = SINGLE_PRECISION_SCALE.get(prefix, (1.0, ""))
        step = float(np.spacing(np.float32(typical)))
        sizes.append(f"{prefix}: {step:.2g} {unit} at {typical:g} {unit}" if unit
                     else f"{prefix}: {step:.2g} at {typical:g}")
    differentiated = [p for p in prefixes if p in ("time", "q", "qd", "qd_true")]
    cost = f", whose rounding the accelerations differentiated from {', '.join(differentiated)} amplify" \
        if differentiated else ""
    return (f"{source}: {shown} are float{schema.field(single[0]).type.bit_width}: "
            f"about 7 significant digits ({'; '.join(sizes)}){cost}; log float64",)


SINGLE_PRECISION_SCALE: dict[str, tuple[float, str]] = {
    "time": (1000.0, "s"), "q": (2.0, "rad"), "qd": (2.0, "rad/s"), "qd_true": (2.0, "rad/s"),
    "qdd_true": (20.0, "rad/s²"), "tau": (100.0, "N·m"), "tau_f_true": (10.0, "N·m"), "current": (10.0, "A"),
    "temperature": (50.0, "°C"), "wrench": (500.0, "N or N·m"), "contact": (1.0, ""), "base": (1.0, "m or rad"),
    "imu": (10.0, "m/s² or rad/s"), "q_cos": (1.0, ""), "q_sin": (1.0, ""), "foot_count": (100.0, "")}
"""A typical value and the unit of each kind of column: what the float32 warning says its rounding is at."""


def _stack(table: pa.Table, columns: list[str], source: str, first_row: int) -> np.ndarray:
    """The numeric ``columns`` of ``table`` side by side (N, len(columns)), read as one array."""
    return numeric_columns(table, columns, source, first_row)


def _read_motion(table: pa.Table, robot: Robot, source: str, read: ReadOptions, first_row: int,
                 clock: Clock | None = None, drive: bool = False) -> tuple[np.ndarray, Clock, np.ndarray]:
    """Time [s] (checked, its unit too: :func:`~wbfriction.logs.clock.table_stamps`), its clock
    (``clock``, the whole log's cut to these rows, else read from the stamps and positions) and
    q [rad] (checked against the limits; continuous joints unwrapped, :func:`unwrap_positions`).
    ``drive``: the stamps are a drive clock's ticks re-estimated from repeated rows
    (:mod:`wbfriction.logs.repeats`): exact by construction, never read as receive-time jitter."""
    stamps = table_stamps(table, source, first_row, read.time_unit)
    segments = check_time(stamps, source, read.max_gap, first_row=first_row)
    raw = _stack(table, [f"q.{n}" for n in robot.actuated], source, first_row)
    check_limits(raw, robot, source, read.limit_margin, first_row)  # before the jumps: degrees say so first
    q = unwrap_positions(raw, robot, source, segments, first_row)
    if clock is None:
        clock = read_clock(stamps, source, max_gap=read.max_gap, first_row=first_row, q=q, time_base=read.time_base)
        if drive and clock.kind == "jittered" and read.time_base == "auto":
            clock = read_clock(stamps, source, max_gap=read.max_gap, first_row=first_row, q=q, time_base="recorded")
            clock = replace(clock, reason=clock.reason.replace(", as asked", ": the drives' clock re-estimated "
                                                               "from the repeated rows, exact by construction"))
    elif len(clock) != len(stamps):
        raise InputError(f"{source}: a clock of {len(clock)} rows for a table of {len(stamps)} rows")
    if clock.segments != segments:  # samples the clock skipped are not gaps: unwrapped across them too
        q = unwrap_positions(raw, robot, source, clock.segments, first_row)
    time = stamps * 1e-9 if np.issubdtype(stamps.dtype, np.integer) else stamps
    return time, clock, q


def forces_give_contacts(robot: Robot, columns: set[str] | list[str]) -> bool:
    """Whether a log with these columns and no ``contact.*`` column has its contact flags from the
    measured forces: every contact frame is sensed and every sensor's columns are there, or every foot's normal
    force is logged (:mod:`wbfriction.logs.foot_forces`)."""
    feet = all(any(c in columns for c in foot_force_columns(f)) for f in robot.contact_frames)
    return feet or sensed_contacts(robot) and all(c in columns for s in robot.ft_sensors for c in s.columns())


def contact_flags_from_forces(robot: Robot, wrench: np.ndarray | None, foot_force: np.ndarray | None = None
                              ) -> np.ndarray:
    """Contact flags (N, n_contacts) from the feet's normal forces, the sensors' wrenches' (N, n_sensors, 6) or
    the foot forces' (N, n_contacts, 3), through the robot's thresholds with hysteresis (:mod:`.contacts`)."""
    on, off = default_thresholds(robot)
    normal = normal_forces(robot, wrench) if wrench is not None else foot_force[..., 2]  # type: ignore[index]
    return hysteresis(normal, on, off)


def _read_contact(table: pa.Table, robot: Robot, source: str, first_row: int,
                  wrench: np.ndarray | None = None, foot_force: np.ndarray | None = None) -> np.ndarray:
    """The contact flags (N, n_contacts) as booleans, refusing values other than 0 and 1; on a fixed
    base, the weld: always in contact; without ``contact.*`` columns, from the measured forces."""
    if not robot.floating_base:
        return np.ones((table.num_rows, 1), dtype=bool)
    if not any(f"contact.{f}" in table.column_names for f in robot.contact_frames) and \
            forces_give_contacts(robot, table.column_names):
        return contact_flags_from_forces(robot, wrench, foot_force)
    contact_cols = [flag_column(table, f"contact.{f}", source, first_row) for f in robot.contact_frames]
    return np.column_stack(contact_cols)


def _read_group(table: pa.Table, columns: tuple[str, ...] | list[str], source: str, first_row: int,
                what: str) -> np.ndarray | None:
    """The ``columns`` side by side (N, len(columns)), or None if none of them is logged; refuses a part."""
    names = set(table.column_names)
    if not any(c in names for c in columns):
        return None
    missing = [c for c in columns if c not in names]
    if missing:
        raise ColumnError(source, missing[0], None, f"{what} is partial: missing column '{missing[0]}'")
    return _stack(table, list(columns), source, first_row)


def _read_imu(table: pa.Table, source: str, first_row: int) -> np.ndarray | None:
    """The IMU's readings (N, 6) (:data:`IMU_COLUMNS`), or None if none is logged: the gyro's three columns needed,
    the accelerometer's optional (NaN when not logged; refused if partial)."""
    gyro = _read_group(table, IMU_COLUMNS[:3], source, first_row, "the IMU's gyro")
    acc = _read_group(table, IMU_COLUMNS[3:], source, first_row, "the IMU's accelerometer")
    if gyro is None and acc is not None:
        raise ColumnError(source, IMU_COLUMNS[0], None, f"the IMU's reading is partial: missing column "
                          f"'{IMU_COLUMNS[0]}'")
    if gyro is None:
        return None
    return np.column_stack([gyro, acc if acc is not None else np.full_like(gyro, np.nan)])


def _read_wrench(table: pa.Table, robot: Robot, source: str, first_row: int) -> np.ndarray | None:
    """The force-torque sensors' wrenches (N, n_sensors, 6), or None if no sensor is logged; refuses a
    partial wrench and a log with some sensors but not all, naming the first column missing."""
    per_sensor = [_read_group(table, s.columns(), source, first_row, f"wrench of sensor '{s.name}'")
                  for s in robot.ft_sensors]
    if all(w is None for w in per_sensor):
        return None
    absent = next((s for s, w in zip(robot.ft_sensors, per_sensor) if w is None), None)
    if absent is not None:
        raise ColumnError(source, absent.columns()[0], None,
                          f"missing column '{absent.columns()[0]}': the log has other sensors' wrenches but not "
                          f"that of sensor '{absent.name}'")
    return np.stack([w for w in per_sensor if w is not None], axis=1)


def _read_base(table: pa.Table, source: str, first_row: int) -> np.ndarray | None:
    """The base poses (N, 7) with unit quaternions, or None if not logged; refuses a partial or non-unit pose."""
    base = _read_group(table, BASE_COLUMNS, source, first_row, "base pose")
    if base is None:
        return None
    norm = np.linalg.norm(base[:, 3:], axis=1)
    bad = np.flatnonzero(np.abs(norm - 1.0) > 1e-3)
    if bad.size:
        raise ColumnError(source, "base.qw", int(first_row + bad[0]),
                          f"base quaternion is not unit at row {first_row + bad[0]} (norm {norm[bad[0]]:.6g})")
    base[:, 3:] /= norm[:, None]
    return base


def _read_per_joint(table: pa.Table, prefix: str, robot: Robot, rows: int, source: str,
                    first_row: int) -> np.ndarray | None:
    """The ``<prefix>.<joint>`` columns of the torque-controlled joints (N, n_tc) (the true friction [N·m], the
    temperature [°C]), NaN for joints not logged, or None if no such column."""
    names = set(table.column_names)
    if not any(c.startswith(prefix + ".") for c in names):
        return None
    return np.column_stack([
        numeric_column(table, f"{prefix}.{n}", source, first_row) if f"{prefix}.{n}" in names
        else np.full(rows, np.nan)
        for n in robot.torque_controlled])


def _read_true_rates(table: pa.Table, prefix: str, robot: Robot, source: str, first_row: int) -> np.ndarray | None:
    """The true ``qd_true`` or ``qdd_true`` columns (N, n_act), all of them, or None if none is logged."""
    names = set(table.column_names)
    if not any(c.startswith(prefix + ".") for c in names):
        return None
    missing = [n for n in robot.actuated if f"{prefix}.{n}" not in names]
    if missing:
        raise ColumnError(source, f"{prefix}.{missing[0]}", None, f"missing column '{prefix}.{missing[0]}'")
    return _stack(table, [f"{prefix}.{n}" for n in robot.actuated], source, first_row)


def write_log(log: Log, robot: Robot, path: str | Path) -> None:
    """Write ``log`` in the log format (Parquet, or CSV by extension), atomically."""
    write_table(log.to_table(robot), path)

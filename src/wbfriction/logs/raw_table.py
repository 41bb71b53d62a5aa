"""A log as a robot's logger writes it, conditioned into the log format (:mod:`wbfriction.logs.log`).

:func:`condition_raw_table` makes, in memory, from a raw table:

* a ``time`` column where there is none: the rows are ticks of the logger at its nominal rate (``--rate``),
  stamped ``k / rate`` [s];
* ``q.<joint>`` from a cosine/sine pair ``q_cos.<joint>``, ``q_sin.<joint>``
  (:func:`~wbfriction.logs.angles.angles_from_pairs`);
* one row per distinct drive sample, at its re-estimated time, where the rows repeat the previous sample in every
  joint column (``q``, ``qd`` and every torque source's columns) because the logger runs faster than the drives
  (:mod:`wbfriction.logs.repeats`; ``--repeats keep`` keeps them);
* every slower stream (``imu.*``, ``foot_count.*``) found repeating on its own and resampled at the joints'
  sample times, each at its own re-estimated sample times (:mod:`wbfriction.logs.streams`).

Other columns are taken on each distinct sample's first row. A table that needs none of this is returned as it
is (the same object): a log in the log format reads as it always did.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.angles import angles_from_pairs, nearest_turn, pair_joints
from wbfriction.logs.clock import relative_stamps, split_at_gaps, table_stamps
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.repeats import Repeats, find_repeats
from wbfriction.logs.streams import STREAMS, resample, stream_columns
from wbfriction.logs.tables import numeric_column, numeric_columns
from wbfriction.logs.torque import torque_columns_named
from wbfriction.model.robot import Robot

MIN_SAMPLES = 5
"""The fewest distinct samples a log is read with (a clock's least: :func:`~wbfriction.logs.clock.read_clock`)."""


@dataclass(frozen=True)
class RawLogReport:
    """What :func:`condition_raw_table` found and did.

    Attributes:
        rows: rows read.
        samples: rows kept: the distinct joint samples when merged, else ``rows``.
        repeated: per stream (``joints``, ``imu``, ``foot_count``; those logged), the share of its rows that
            repeat the previous sample [0-1].
        drive_period: the drives' period re-estimated from the repeats [s], or None (not merged).
        rate: the nominal rate the rows were stamped at [Hz], or None (the log's own ``time``).
        reason: one line saying what was found and done ("" when nothing).
        restamped: the ``time`` column was written here (seconds, or nanoseconds as an Arrow timestamp when the
            log's were integers or timestamps): read it without ``--time-unit``.
        resampled: the streams resampled at the joints' sample times.
        changed: the table was changed (stamped, merged, angles from pairs, streams resampled).
    """

    rows: int
    samples: int
    repeated: dict[str, float] = field(default_factory=dict)
    drive_period: float | None = None
    rate: float | None = None
    reason: str = ""
    restamped: bool = False
    resampled: tuple[str, ...] = ()
    changed: bool = False


def _stamps(table: pa.Table, source: str, read: ReadOptions) -> tuple[np.ndarray, float, bool]:
    """The rows' times relative to the first [s], the first [s], and whether they were made from ``read.rate``."""
    if "time" in table.column_names:
        stamps = table_stamps(table, source, 0, read.time_unit)
        t, t0, _ = relative_stamps(stamps)
        return t, t0, False
    if read.rate is None:
        raise ColumnError(source, "time", None, "missing column 'time': a log without stamps is read at its "
                          "logger's nominal rate: give it with --rate HZ")
    return np.arange(table.num_rows) / float(read.rate), 0.0, True


def joint_stream(table: pa.Table, robot: Robot) -> list[str]:
    """The joint columns whose every value is the drives' (``q``, ``qd`` and every torque source's prefix), in
    the table's order: a row equal to the previous one in all of them repeats the previous sample."""
    prefixes = {"q", "qd", *torque_columns_named(robot)}
    return [n for n in table.column_names if n.partition(".")[0] in prefixes]


def repeated_columns(table: pa.Table, columns: list[str]) -> np.ndarray:
    """Rows (N,) equal to the previous one in every one of ``columns`` (NaN equal to NaN; row 0 never; no column:
    none), column by column (a log whose first column never repeats is read no further)."""
    out = np.zeros(table.num_rows, dtype=bool)
    if not columns or table.num_rows < 2:
        return out
    out[1:] = True
    for c in columns:
        x = table.column(c).to_numpy(zero_copy_only=False)
        same = x[1:] == x[:-1]
        if x.dtype.kind == "f":
            same |= np.isnan(x[1:]) & np.isnan(x[:-1])
        out[1:] &= same
        if not out.any():
            break
    return out


def _pairs_to_angles(table: pa.Table, robot: Robot, source: str) -> tuple[pa.Table, list[str]]:
    """The table with each cosine/sine pair replaced by its ``q.<joint>`` column, and those joints.

    Raises:
        ColumnError: a pair of a joint the robot does not have, a pair missing its other half, a joint given both
            as ``q.<joint>`` and as a pair, a pair that is not one (norm far from 1)."""
    joints = pair_joints(table.column_names)
    for j in joints:
        if j not in robot.actuated:
            raise ColumnError(source, f"q_cos.{j}", None, f"column 'q_cos.{j}' names an unknown joint '{j}' of "
                              f"robot '{robot.name}'")
        for half in ("q_cos", "q_sin"):
            if f"{half}.{j}" not in table.column_names:
                raise ColumnError(source, f"{half}.{j}", None, f"missing column '{half}.{j}': joint '{j}' is given "
                                  "by half a cosine/sine pair")
        if f"q.{j}" in table.column_names:
            raise ColumnError(source, f"q.{j}", None, f"joint '{j}' is given twice, as 'q.{j}' and as the pair "
                              f"'q_cos.{j}', 'q_sin.{j}': keep one")
    for j in joints:
        q = angles_from_pairs(numeric_column(table, f"q_cos.{j}", source), numeric_column(table, f"q_sin.{j}", source),
                              j, source)
        angle = pa.array(nearest_turn(q, robot, j))
        table = table.drop_columns([f"q_cos.{j}", f"q_sin.{j}"]).append_column(f"q.{j}", angle)
    return table, joints


def _time_column(t0: float, t: np.ndarray, table: pa.Table, nominal: bool) -> pa.Array:
    """The ``time`` column for times ``t0 + t`` [s]: float seconds, or an Arrow timestamp [ns] when the log's own
    were integers or timestamps (their precision kept)."""
    if nominal or pa.types.is_floating(table.schema.field("time").type):
        return pa.array(t0 + t, pa.float64())
    ns = np.int64(round(t0 * 1e9)) + np.rint(t * 1e9).astype(np.int64)
    return pa.array(ns, pa.timestamp("ns"))


def condition_raw_table(table: pa.Table, robot: Robot, source: str, read: ReadOptions = ReadOptions(),
                        min_samples: int = MIN_SAMPLES) -> tuple[pa.Table, RawLogReport]:
    """A raw log's table in the log format (module docstring), and what was found.

    Args:
        table: the raw table, one row per logger tick.
        robot: the robot whose joints the columns name.
        source: the file name, for the messages.
        read: how it is read: ``rate`` (a log without ``time``), ``repeats`` (``merge`` or ``keep``), ``time_unit``
            (of its own ``time``), ``max_gap``.
        min_samples: the fewest distinct samples the caller's route needs.

    Returns:
        ``(table, report)``: the conditioned table (``table`` itself when nothing was needed) and a
        :class:`RawLogReport`.

    Raises:
        ColumnError: a missing ``time`` without ``read.rate`` (naming ``--rate``); a duplicated, decreasing or
            non-finite stamp; a cosine/sine pair at fault (:func:`_pairs_to_angles`).
        InputError: merged rows that leave fewer than ``min_samples`` distinct samples, naming the counts.
    """
    n = table.num_rows
    t, t0, nominal = _stamps(table, source, read)
    table, pairs = _pairs_to_angles(table, robot, source)
    streams = {s: stream_columns(table.column_names, s) for s in STREAMS}
    masks = {"joints": repeated_columns(table, joint_stream(table, robot)),
             **{s: repeated_columns(table, c) for s, c in streams.items() if c}}
    if n >= 2 and any(m.any() for m in masks.values()):
        split_at_gaps(t, source, read.max_gap)  # increasing, finite stamps (their gaps are the clock's to read)
    joints = find_repeats(None, t, masks.pop("joints"))
    merge = read.repeats == "merge" and joints.merge
    found = {s: find_repeats(None, t, m) for s, m in masks.items()}
    resampled = tuple(s for s, r in found.items() if read.repeats == "merge" and (merge or r.merge))
    lines = _lines(n, joints, merge, nominal, read, pairs, found, resampled)
    report = RawLogReport(n, len(joints.first) if merge else n, {"joints": joints.share, **{s: r.share for s, r in
                          found.items()}}, joints.clock.period if merge and joints.clock else None,
                          read.rate if nominal else None, "; ".join(lines), nominal or merge, resampled,
                          bool(nominal or pairs or merge or resampled))
    if not (nominal or pairs or merge or resampled):
        return table, report
    if merge and len(joints.first) < min_samples:
        raise InputError(f"{source}: {n} rows hold only {len(joints.first)} distinct samples (the others repeat the "
                         f"previous one in every joint column); at least {min_samples} are needed")
    at = joints.times(t) if merge else t
    keep = joints.first if merge else np.arange(n)
    out = table.take(pa.array(keep)) if merge else table
    for s in resampled:
        values = numeric_columns(table, streams[s], source)
        r = found[s]
        latency = float(np.mean(t[joints.first] - at)) if merge else 0.0
        when = r.times(t) if r.merge else t[r.first] - latency
        new = resample(when, values[r.first], at, streams[s])
        for i, c in enumerate(streams[s]):
            out = out.set_column(out.schema.get_field_index(c), c, pa.array(new[:, i]))
    if "time" in out.column_names:
        if merge:
            out = out.set_column(out.schema.get_field_index("time"), "time", _time_column(t0, at, table, nominal))
    else:
        out = out.add_column(0, "time", _time_column(t0, at, table, nominal))
    return out.replace_schema_metadata(table.schema.metadata), report


def _lines(n: int, joints: Repeats, merge: bool, nominal: bool, read: ReadOptions, pairs: list[str],
           found: dict[str, Repeats], resampled: tuple[str, ...]) -> list[str]:
    """What conditioning did, one phrase each (none: nothing to do)."""
    lines = []
    if nominal:
        lines.append(f"no time stamps: {n} rows stamped at the nominal {read.rate:g} Hz")
    if pairs:
        lines.append(f"angles of {len(pairs)} joint(s) from cosine/sine pairs")
    if merge:
        lines.append(joints.describe("rows"))
    elif read.repeats == "keep" and joints.merge:
        lines.append(f"{joints.share * 100:.0f} % of rows repeat the previous sample: kept (--repeats keep)")
    for s in resampled:
        lines.append(f"{s}: {found[s].describe('its rows')}, resampled at the joints' sample times")
    return lines

"""The wbfriction log format: reading, validation, and atomic writing of tables.

A log is a Parquet file (or CSV with the same columns, or HDF5: :mod:`wbfriction.hdf5`),
one row per sample:

=====================  ==========  ==================================================
column                 unit        content
=====================  ==========  ==================================================
``time``               s           strictly increasing, uniformly sampled
``q.<joint>``          rad (m)     position of every actuated joint
``tau.<joint>``        N·m (N)     measured torque of every torque-controlled joint
``contact.<frame>``    0 / 1       contact flag of every contact frame
``base.x`` ... ``base.qw``  m, -   optional world pose of the root (unit quaternion
                                   x, y, z, w)
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

import hashlib
import json
import os
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from .exceptions import InputError
from .hdf5 import SUFFIXES as HDF5_SUFFIXES
from .hdf5 import read_hdf5, write_hdf5
from .robot import Robot

BASE_COLUMNS = ("base.x", "base.y", "base.z", "base.qx", "base.qy", "base.qz", "base.qw")
META_KEY = b"wbfriction"


@dataclass
class Log:
    """A validated log, with columns mapped to the robot's joints by name.

    Attributes:
        time: sample times (N,) [s].
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
            None: the median step of ``time``.
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

    @property
    def dt(self) -> float:
        """Sampling period [s]: :attr:`period` if set, else the median time step."""
        return self.period if self.period is not None else float(np.median(np.diff(self.time)))

    def parts(self) -> list["Log"]:
        """The log's segments (split at its time gaps, :func:`check_time`) as logs of their own."""
        bounds = self.segments or [(0, len(self.time))]
        if len(bounds) == 1:
            return [self]
        return [self.rows(a, b) for a, b in bounds]

    def rows(self, start: int, stop: int) -> "Log":
        """The rows ``[start, stop)`` as a log (arrays are views)."""
        cut = lambda x: None if x is None else x[start:stop]  # noqa: E731
        return Log(self.time[start:stop], self.q[start:stop], self.tau[start:stop], self.contact[start:stop],
                   cut(self.base), cut(self.tau_f_true), self.metadata, self.source, cut(self.qd_true),
                   cut(self.qdd_true), None, self.dt)

    def __len__(self) -> int:
        return len(self.time)

    def to_table(self, robot: Robot) -> pa.Table:
        """The log as an Arrow table in the log format."""
        cols: dict[str, np.ndarray] = {"time": self.time}
        cols.update({f"q.{n}": self.q[:, i] for i, n in enumerate(robot.actuated)})
        cols.update({f"tau.{n}": self.tau[:, i] for i, n in enumerate(robot.torque_controlled)})
        cols.update({f"contact.{n}": self.contact[:, i].astype(np.int8) for i, n in enumerate(robot.contact_frames)})
        if self.base is not None:
            cols.update({c: self.base[:, i] for i, c in enumerate(BASE_COLUMNS)})
        if self.tau_f_true is not None:
            cols.update({f"tau_f_true.{n}": self.tau_f_true[:, i] for i, n in enumerate(robot.torque_controlled)
                         if not np.all(np.isnan(self.tau_f_true[:, i]))})
        for prefix, x in (("qd_true", self.qd_true), ("qdd_true", self.qdd_true)):
            if x is not None:
                cols.update({f"{prefix}.{n}": x[:, i] for i, n in enumerate(robot.actuated)})
        return with_metadata(pa.table(cols), self.metadata)


# ------------------------------------------------------------------ metadata
def with_metadata(table: pa.Table, metadata: dict) -> pa.Table:
    """Attach ``metadata`` (JSON-serialisable) to ``table`` under the ``wbfriction`` key."""
    return table.replace_schema_metadata({META_KEY: json.dumps(metadata, sort_keys=True).encode()})


def read_metadata(table: pa.Table, source: str = "<table>") -> dict:
    """The ``wbfriction`` metadata of a table ({} if none)."""
    meta = table.schema.metadata or {}
    if META_KEY not in meta:
        return {}
    try:
        doc = json.loads(meta[META_KEY])
    except ValueError:
        raise InputError(f"{source}: the 'wbfriction' metadata is not JSON") from None
    if not isinstance(doc, dict):
        raise InputError(f"{source}: the 'wbfriction' metadata is not a JSON object")
    return doc


# ------------------------------------------------------------------- reading
TABLE_SUFFIXES = (".parquet", ".pq", ".csv", *HDF5_SUFFIXES)


def table_suffix(path: Path) -> str:
    """The file type of an existing table file (lower-case suffix).

    Raises:
        InputError: a missing file, or a type that is not Parquet, CSV or HDF5.
    """
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    suffix = path.suffix.lower()
    if suffix not in TABLE_SUFFIXES:
        raise InputError(f"{path}: unknown file type '{suffix}' (expected .parquet, .csv or .h5)")
    return suffix


def read_table(path: str | Path) -> pa.Table:
    """Read a Parquet, CSV or HDF5 file into an Arrow table.

    Raises:
        InputError: missing file, unknown extension, or unreadable content.
    """
    path = Path(path)
    suffix = table_suffix(path)
    if suffix in HDF5_SUFFIXES:
        return read_hdf5(path)
    readers = {".parquet": pq.read_table, ".pq": pq.read_table, ".csv": pacsv.read_csv}
    try:
        table = readers[suffix](path)
        _ = table.column_names  # decoded lazily: a damaged header fails here
        return table
    except (pa.ArrowException, OSError, ValueError) as exc:  # ValueError: e.g. damaged UTF-8 in the footer
        raise InputError(f"{path}: cannot be read: {(str(exc).splitlines() or [repr(exc)])[0]}") from exc


def numeric_column(table: pa.Table, name: str, source: str, first_row: int = 0, finite: bool = True) -> np.ndarray:
    """Column ``name`` as float64 (N,).

    Raises:
        InputError: a column that is not numeric, or (``finite``) holds NaN or inf, naming
            ``source``, the column and the first bad row (counted from ``first_row``).
    """
    try:
        col = table.column(name)
        values = col.to_numpy(zero_copy_only=False).astype(float)
    except (pa.ArrowException, ValueError, TypeError) as exc:
        raise InputError(f"{source}: column '{name}' is not numeric") from exc
    bad = np.flatnonzero(~np.isfinite(values)) if finite else ()
    if len(bad):
        raise InputError(f"{source}: column '{name}' has a non-finite value (NaN or inf) at row {first_row + bad[0]}")
    return values


MAX_GAP = 2.0
"""Default gap [sampling periods]: a time step at least this long splits a log into segments."""
JITTER = 0.05
"""Tolerated deviation of a time step from the median step, relative."""
LIMIT_MARGIN = 0.2
"""How far a position may pass its URDF limits before the log is refused [rad or m]."""


def check_time(time: np.ndarray, source: str, max_gap: float = MAX_GAP,
               rel_tol: float = JITTER, first_row: int = 0) -> list[tuple[int, int]]:
    """Check a time column and split it at its gaps.

    A step within ``rel_tol`` of the median step ``dt`` is regular; a step of at least
    ``max_gap`` periods (less the tolerance) is a gap, which ends a segment (a log with
    dropped samples or pauses is estimated segment by segment, never differentiated
    across a gap); anything else is irregular sampling and refused.

    Returns:
        The segments as half-open row ranges ``[(a, b), ...]`` covering every row.

    Raises:
        InputError: fewer than 5 rows, a duplicated or decreasing stamp, or an irregular
            step, naming the first row at fault (counted from ``first_row``).
    """
    if time.size < 5:
        raise InputError(f"{source}: only {time.size} rows; at least 5 samples are needed")
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        k = bad[0] + 1
        what = "duplicated" if step[bad[0]] == 0 else "decreasing"
        raise InputError(f"{source}: column 'time' has a {what} stamp at row {first_row + k} ({time[k]:.9g} s after "
                         f"{time[k - 1]:.9g} s)")
    dt = np.median(step)
    gap = step >= (max_gap - rel_tol) * dt
    bad = np.flatnonzero(~gap & (np.abs(step - dt) > rel_tol * dt))
    if bad.size:
        raise InputError(f"{source}: column 'time' is irregular at row {first_row + bad[0] + 1} "
                         f"(step {step[bad[0]]:.6g} s, median {dt:.6g} s; gaps of {max_gap:g} periods or more "
                         f"split the log)")
    cuts = np.flatnonzero(gap) + 1
    edges = [0, *cuts.tolist(), time.size]
    return list(zip(edges[:-1], edges[1:]))


def check_limits(q: np.ndarray, robot: Robot, source: str, margin: float = LIMIT_MARGIN, first_row: int = 0) -> None:
    """Refuse positions beyond the URDF limits by more than ``margin`` (degrees logged as
    radians, millimetres as metres); joints without finite limits are not checked.

    Raises:
        InputError: naming the column, the row and the limits.
    """
    lower, upper = robot.angle_limits
    for i, name in enumerate(robot.actuated):
        lo, hi = lower[i], upper[i]
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
            continue
        out = np.flatnonzero((q[:, i] < lo - margin) | (q[:, i] > hi + margin))
        if out.size:
            k = out[0]
            raise InputError(f"{source}: column 'q.{name}' is {q[k, i]:.6g} at row {first_row + k}, beyond its URDF limits "
                             f"[{lo:.4g}, {hi:.4g}] by more than {margin:g}: wrong units (degrees for radians)?")


def log_from_table(table: pa.Table, robot: Robot, source: str = "<table>", max_gap: float = MAX_GAP,
                   limit_margin: float = LIMIT_MARGIN, first_row: int = 0, period: float | None = None) -> Log:
    """Validate an Arrow table against ``robot`` and map its columns by joint name.

    Args:
        max_gap: time steps of at least this many periods split the log (:func:`check_time`).
        limit_margin: tolerance on the URDF joint limits (:func:`check_limits`).
        first_row: row number of the table's first row in its file (a chunk of a long log),
            for the messages.
        period: the sampling period of the whole log, for a chunk of it (:attr:`Log.period`).

    Raises:
        InputError: missing ``time``, a missing or unknown joint/frame column, NaN, a
            duplicated, decreasing or irregular time column, positions far beyond the
            joint limits, contact flags other than 0/1, a partial base pose, or a
            non-unit quaternion.
    """
    names = set(table.column_names)
    if "time" not in names:
        raise InputError(f"{source}: missing column 'time'")
    act, tc = set(robot.actuated), set(robot.torque_controlled)
    frames = set(robot.contact_frames)
    for col in table.column_names:
        prefix, _, item = col.partition(".")
        known = {"q": act, "tau": act, "tau_f_true": tc, "contact": frames, "qd_true": act,
                 "qdd_true": act}.get(prefix)
        if known is not None and item not in known:
            what = "contact frame" if prefix == "contact" else "joint"
            raise InputError(f"{source}: column '{col}' names an unknown {what} '{item}' of robot '{robot.name}'")
    for col in ([f"q.{n}" for n in robot.actuated] + [f"tau.{n}" for n in robot.torque_controlled]
                + [f"contact.{f}" for f in robot.contact_frames]):
        if col not in names:
            raise InputError(f"{source}: missing column '{col}'")
    time = numeric_column(table, "time", source, first_row)
    segments = check_time(time, source, max_gap, first_row=first_row)
    q = np.column_stack([numeric_column(table, f"q.{n}", source, first_row) for n in robot.actuated])
    check_limits(q, robot, source, limit_margin, first_row)
    tau = np.column_stack([numeric_column(table, f"tau.{n}", source, first_row) for n in robot.torque_controlled])
    contact_cols = []
    for f in robot.contact_frames:
        c = numeric_column(table, f"contact.{f}", source, first_row)
        bad = np.flatnonzero((c != 0) & (c != 1))
        if bad.size:
            raise InputError(f"{source}: column 'contact.{f}' must hold 0 or 1, found {c[bad[0]]:g} at row {first_row + bad[0]}")
        contact_cols.append(c.astype(bool))
    contact = np.column_stack(contact_cols)
    base = None
    present = [c for c in BASE_COLUMNS if c in names]
    if present:
        missing = [c for c in BASE_COLUMNS if c not in names]
        if missing:
            raise InputError(f"{source}: base pose is partial: missing column '{missing[0]}'")
        base = np.column_stack([numeric_column(table, c, source, first_row) for c in BASE_COLUMNS])
        norm = np.linalg.norm(base[:, 3:], axis=1)
        bad = np.flatnonzero(np.abs(norm - 1.0) > 1e-3)
        if bad.size:
            raise InputError(f"{source}: base quaternion is not unit at row {first_row + bad[0]} (norm {norm[bad[0]]:.6g})")
        base[:, 3:] /= norm[:, None]
    tau_f_true = None
    if any(c.startswith("tau_f_true.") for c in names):
        tau_f_true = np.column_stack([
            numeric_column(table, f"tau_f_true.{n}", source, first_row) if f"tau_f_true.{n}" in names else np.full(len(time), np.nan)
            for n in robot.torque_controlled])
    truth = {}
    for prefix in ("qd_true", "qdd_true"):
        if any(c.startswith(prefix + ".") for c in names):
            missing = [n for n in robot.actuated if f"{prefix}.{n}" not in names]
            if missing:
                raise InputError(f"{source}: missing column '{prefix}.{missing[0]}'")
            truth[prefix] = np.column_stack([numeric_column(table, f"{prefix}.{n}", source, first_row) for n in robot.actuated])
    return Log(time, q, tau, contact, base, tau_f_true, read_metadata(table, source), source,
               qd_true=truth.get("qd_true"), qdd_true=truth.get("qdd_true"), segments=segments, period=period)


def read_log(path: str | Path, robot: Robot, bag_map=None, max_gap: float = MAX_GAP,
             limit_margin: float = LIMIT_MARGIN) -> Log:
    """Read and validate a log: a Parquet or CSV file in the format of the module docstring,
    or a ROS 2 bag with its topic map (:mod:`wbfriction.bags`).

    Args:
        path: the file (or bag folder).
        robot: the robot whose names the columns must match.
        bag_map: a :class:`~wbfriction.bags.BagMap` (needed for a bag).
        max_gap, limit_margin: see :func:`log_from_table`.

    Raises:
        InputError: see :func:`log_from_table` and :func:`~wbfriction.bags.read_bag`;
            messages start with the file name.
    """
    from .bags import is_bag, read_bag

    if is_bag(path):
        if bag_map is None:
            raise InputError(f"{path}: a ROS 2 bag needs a topic map (--map MAP.toml)")
        table = read_bag(path, bag_map)
    else:
        table = read_table(path)
    return log_from_table(table, robot, str(path), max_gap, limit_margin)


# ------------------------------------------------------------------- writing
def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex), for provenance records; of a folder (a ROS 2 bag),
    over its files' relative names and bytes in name order."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file not found")
    digest = hashlib.sha256()
    files = [path] if not path.is_dir() else sorted(p for p in path.rglob("*") if p.is_file())
    for f in files:
        if f != path:
            digest.update(str(f.relative_to(path)).encode() + b"\0")
        with open(f, "rb") as handle:  # in blocks: a log of an hour is gigabytes
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()


def write_atomic(path: str | Path, write) -> None:
    """Write a file whole or not at all.

    ``write(tmp_path)`` writes to a temporary file in the destination directory, which
    is then renamed onto ``path`` (atomic on POSIX). On any error the temporary file is
    removed and ``path`` is left untouched.
    """
    path = Path(path)
    if path.parent and not path.parent.exists():
        raise InputError(f"{path}: output directory {path.parent} does not exist")
    # the temporary name ends like the destination: ``write`` may read it back by its type
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=path.parent or ".")
    os.close(fd)
    try:
        write(Path(tmp))
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_table(table: pa.Table, path: str | Path) -> None:
    """Write an Arrow table as Parquet (CSV if ``path`` ends in .csv, HDF5 in .h5 or .hdf5), atomically."""
    path = Path(path)
    if path.suffix.lower() == ".csv":
        write_atomic(path, lambda tmp: pacsv.write_csv(table, tmp))
    elif path.suffix.lower() in HDF5_SUFFIXES:
        write_atomic(path, lambda tmp: write_hdf5(table, tmp))
    else:
        write_atomic(path, lambda tmp: pq.write_table(table, tmp))


def write_tables(path: str | Path, tables: Iterable[pa.Table], check=None) -> int:
    """Stream tables with the same columns into one Parquet or CSV file, whole or not at
    all: the first table gives the schema and its metadata (later ones are cast to it);
    ``check(tmp_path)``, if given, runs on the complete temporary file before the rename and
    may raise to keep the previous output. Returns the rows written.

    Raises:
        InputError: an output that is neither .parquet nor .csv, or no table at all; what
            the tables' source or ``check`` raises.
    """
    path = Path(path)
    if path.suffix.lower() not in (".parquet", ".pq", ".csv"):
        raise InputError(f"{path}: tables are streamed as .parquet or .csv")
    rows = 0

    def write(tmp: Path) -> None:
        nonlocal rows
        writer = None
        try:
            for table in tables:
                if writer is None:
                    schema = table.schema
                    writer = (pacsv.CSVWriter(tmp, schema) if path.suffix.lower() == ".csv"
                              else pq.ParquetWriter(tmp, schema))
                writer.write_table(table.cast(schema) if table.schema != schema else table)
                rows += table.num_rows
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise InputError(f"{path}: nothing to write")
        if check is not None:
            check(tmp)

    write_atomic(path, write)
    return rows


def write_log(log: Log, robot: Robot, path: str | Path) -> None:
    """Write ``log`` in the log format (Parquet, or CSV by extension), atomically."""
    write_table(log.to_table(robot), path)

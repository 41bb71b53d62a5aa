"""The logs a batch processes (issue 25): a manifest table, or a folder scanned.

A manifest is a CSV or Parquet table, one row per log:

=============  ========================================================================================
column         meaning
=============  ========================================================================================
``log``        the log's path (Parquet, CSV or HDF5), relative to the manifest's folder or absolute
``robot_id``   the robot that wrote it (letters, digits, ``.``, ``_``, ``-``): the results' partition
``start_time`` when the log started: ISO 8601 with a time zone (``2026-03-01T08:00:00+00:00``), or a
               Parquet timestamp
``robot``      a built-in robot (``talos``, ...), or empty with ``urdf`` and/or ``config`` (paths, relative
               to the manifest) for any other robot (:func:`~wbfriction.model.loading.load_robot`)
``diff``       optional: the differentiation of this log (``auto``, ``central``, ``savgol``, ...)
``model``      optional: the friction model fitted (``auto``, ``thesis``, ``stribeck``, ``coulomb-viscous``)
=============  ========================================================================================

A folder is scanned as ``FOLDER/<robot_id>/**/<log>`` (``.parquet``, ``.csv``, ``.h5``), every log with the
robot given on the command line, its start time from its ``time`` column when that holds dates (a Parquet
timestamp); a log whose time stamps are relative needs a manifest row.

Everything is checked here, before any log is processed: a fault is one :class:`~wbfriction.exceptions.InputError`
naming the manifest, its row and column.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import get_args

import pyarrow as pa
import pyarrow.compute as pc

from wbfriction.exceptions import InputError
from wbfriction.friction.fit import MODEL_CHOICES
from wbfriction.logs.tables import TableFile, table_format
from wbfriction.pipeline.estimate import RobotSpec
from wbfriction.signals.kinematics import Diff

REQUIRED = ("log", "robot_id", "start_time")
"""The columns every manifest has."""
OPTIONAL = ("robot", "urdf", "config", "diff", "model")
"""The columns a manifest may have (others are refused: a misspelt option would be silently ignored)."""
LOG_SUFFIXES = (".parquet", ".pq", ".csv", ".h5", ".hdf5")
"""The files a scanned folder's logs are."""
DIFF_CHOICES: tuple[str, ...] = ("auto", *get_args(Diff))
"""The values of a manifest's ``diff`` column."""
ROBOT_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")
"""What a robot id may be: it names a folder of the results."""


@dataclass(frozen=True)
class LogEntry:
    """One log of a batch.

    Attributes:
        log: the log's path (absolute).
        robot_id: the robot that wrote it.
        start_time: when it started (UTC, aware).
        robot: how to load its robot model.
        options: per-log options (``diff``, ``model``) that override the batch's.
        row: the manifest's row it came from (0-based), or None for a scanned log.
    """

    log: Path
    robot_id: str
    start_time: datetime
    robot: RobotSpec
    options: dict[str, str] = field(default_factory=dict)
    row: int | None = None


def read_manifest(path: str | Path) -> list[LogEntry]:
    """The logs a manifest lists (module docstring), checked: columns, robot ids, start times, option values,
    the logs' existence and format, and no log listed twice.

    Raises:
        InputError: the first fault, naming the manifest, the row (0-based, as the file's data rows) and column.
    """
    path = Path(path)
    table = TableFile(path).read()
    names = table.column_names
    missing = [c for c in REQUIRED if c not in names]
    if missing:
        raise InputError(f"{path}: the manifest has no column {', '.join(repr(c) for c in missing)} "
                         f"(it needs {', '.join(REQUIRED)})")
    unknown = [c for c in names if c not in REQUIRED + OPTIONAL]
    if unknown:
        raise InputError(f"{path}: unknown manifest column {unknown[0]!r} (known: {', '.join(REQUIRED + OPTIONAL)})")
    if table.num_rows == 0:
        raise InputError(f"{path}: the manifest lists no log")
    starts = _start_times(table.column("start_time"), path)
    columns = {c: table.column(c).to_pylist() for c in names if c != "start_time"}
    entries: list[LogEntry] = []
    seen: dict[Path, int] = {}
    for row in range(table.num_rows):
        cell = {c: ("" if columns[c][row] is None else str(columns[c][row]).strip()) for c in columns}
        entry = _entry(path, row, cell, starts[row])
        if entry.log in seen:
            raise InputError(f"{path}: row {row}, column 'log': {entry.log} is listed twice (first in row "
                             f"{seen[entry.log]})")
        seen[entry.log] = row
        entries.append(entry)
    return entries


def scan_folder(folder: str | Path, robot: RobotSpec) -> list[LogEntry]:
    """The logs of ``FOLDER/<robot_id>/**`` (module docstring), each with ``robot``, in path order.

    Raises:
        InputError: an empty folder, a robot id that cannot name a folder, a log without dates in its ``time``.
    """
    folder = Path(folder)
    entries = []
    for sub in sorted(p for p in folder.iterdir() if p.is_dir()):
        if not ROBOT_ID.match(sub.name):
            continue  # the results' own folders, hidden folders
        for log in sorted(p for p in sub.rglob("*") if p.is_file() and p.suffix.lower() in LOG_SUFFIXES):
            entries.append(LogEntry(log.resolve(), sub.name, log_start_time(log), robot))
    if not entries:
        raise InputError(f"{folder}: no log found as {folder}/<robot_id>/<log>.parquet|.csv|.h5")
    return entries


def log_start_time(log: Path) -> datetime:
    """When a log started, from its ``time`` column if that holds dates (a timestamp column).

    Raises:
        InputError: a ``time`` column of relative seconds (the log then needs a manifest row).
    """
    time = TableFile(log).read(["time"])
    if "time" not in time.column_names or time.num_rows == 0:
        raise InputError(f"{log}: column 'time' not found")
    column = time.column("time")
    if not pa.types.is_timestamp(column.type):
        raise InputError(f"{log}: column 'time' holds no dates ({column.type}): give the log's start_time in a "
                         "manifest")
    first = pc.min(column).as_py()
    return first.replace(tzinfo=first.tzinfo or UTC).astimezone(UTC)


def _start_times(column: pa.ChunkedArray, path: Path) -> list[datetime]:
    """Every row's start time (UTC), from ISO 8601 strings with a zone or timestamps."""
    if pa.types.is_timestamp(column.type) and column.type.tz is None:  # a CSV's dates without a zone, inferred
        raise InputError(f"{path}: row 0, column 'start_time': dates without a time zone (add +00:00 for UTC)")
    out = []
    for row, value in enumerate(column.to_pylist()):
        if isinstance(value, datetime):
            t = value
        else:
            try:
                t = datetime.fromisoformat(str(value).strip())
            except ValueError:
                raise InputError(f"{path}: row {row}, column 'start_time': {value!r} is not an ISO 8601 date "
                                 "(e.g. 2026-03-01T08:00:00+00:00)") from None
            if t.tzinfo is None:
                raise InputError(f"{path}: row {row}, column 'start_time': {value!r} has no time zone "
                                 "(add +00:00 for UTC)")
        out.append(t.astimezone(UTC))
    return out


def _entry(path: Path, row: int, cell: dict[str, str], start: datetime) -> LogEntry:
    """One manifest row as a :class:`LogEntry`, checked."""
    where = f"{path}: row {row}"
    if not cell["log"]:
        raise InputError(f"{where}, column 'log': empty")
    log = (path.parent / cell["log"]).resolve()
    if not log.exists():
        raise InputError(f"{where}, column 'log': {log} not found")
    try:
        table_format(log)
    except InputError as exc:
        raise InputError(f"{where}, column 'log': {exc}") from None
    if not ROBOT_ID.match(cell["robot_id"]):
        raise InputError(f"{where}, column 'robot_id': {cell['robot_id']!r} is not a robot id (letters, digits, "
                         "'.', '_', '-'; it names a folder)")
    name, urdf, config = cell.get("robot", ""), cell.get("urdf", ""), cell.get("config", "")
    if not (name or urdf or config):
        raise InputError(f"{where}: no robot (give column 'robot', a built-in name, or 'urdf' and 'config')")
    for column, value in (("urdf", urdf), ("config", config)):
        if value and not (path.parent / value).exists():
            raise InputError(f"{where}, column '{column}': {(path.parent / value).resolve()} not found")
    robot = RobotSpec(name or None, str((path.parent / urdf).resolve()) if urdf else None,
                      str((path.parent / config).resolve()) if config else None)
    options = {c: cell[c] for c in ("diff", "model") if cell.get(c)}
    for column, choices in (("diff", DIFF_CHOICES), ("model", MODEL_CHOICES)):
        if column in options and options[column] not in choices:
            raise InputError(f"{where}, column '{column}': {options[column]!r} is not one of {', '.join(choices)}")
    return LogEntry(log, cell["robot_id"], start, robot, options, row)

"""The logs a batch processes (issue 25): a manifest table, or a folder scanned.

A manifest is a table of text columns, in a format that holds them (CSV, Parquet), one row per log:

=============  ========================================================================================
column         meaning
=============  ========================================================================================
``log``        the log's path (a file of any log format), relative to the manifest's folder or absolute
``robot_id``   the robot that wrote it, as text (letters, digits, ``.``, ``_``, ``-``): ``007`` and ``7``
               are two robots, whatever a CSV reader would infer; it names the robot's results folder
``start_time`` when the log started: ISO 8601 with a time zone (``2026-03-01T08:00:00+00:00``), or a
               Parquet timestamp; between 1970 and 2262 (the results' nanosecond timestamps)
``robot``      a built-in robot (``talos``, ...), optionally with ``urdf`` (another model of it, e.g.
               identified inertias); or empty with ``urdf`` and/or ``config`` (paths, relative to the
               manifest) for any other robot (:func:`~wbfriction.model.loading.load_robot`); not both
               ``robot`` and ``config`` (the configuration defines the robot)
``diff``       optional: the differentiation of this log (``auto``, ``central``, ``savgol``, ...)
``route``      optional: the route of this log (``auto``, ``acceleration``, ``momentum``)
``model``      optional: the friction model fitted (``auto``, ``thesis``, ``stribeck``, ``coulomb-viscous``,
               or a registered family)
=============  ========================================================================================

A folder is scanned as ``FOLDER/<robot_id>/**/<log>``, a log being any file (or folder) a registered log format
detects (:func:`~wbfriction.logs.formats.registry.find_format`: Parquet, CSV, HDF5, ``.npz`` built in, and any
format registered), every log with the robot given on the command line, its start time from its ``time`` column
when that holds dates (a timestamp column); a log whose time stamps are relative needs a manifest row. Every file
or folder the scan passes over is said (:attr:`FolderScan.skipped`), but hidden ones (a name starting with ``.``):
a folder whose name is not a robot id, a file outside any robot's folder or that no format reads, a log read only
through a map (a ROS 2 bag: a batch takes none), a table that wbfriction wrote (a friction table, a batch's
result) and the batch's own output folders.

Everything is checked here, before any log is processed: a fault is one :class:`~wbfriction.exceptions.InputError`
naming the manifest, its row and column.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc

from wbfriction.exceptions import InputError
from wbfriction.fit.options import model_choices
from wbfriction.fleet.schema import RESULT_DOCUMENT
from wbfriction.friction.options import ROUTE_OPTIONS
from wbfriction.logs.formats.catalog import table_formats
from wbfriction.logs.formats.registry import find_format
from wbfriction.logs.tables import TableFile, read_metadata, table_format
from wbfriction.pipeline.estimate_step import RobotSpec
from wbfriction.signals.options import DIFF_OPTIONS

REQUIRED = ("log", "robot_id", "start_time")
"""The columns every manifest has."""
OPTIONAL = ("robot", "urdf", "config", "diff", "route", "model")
"""The columns a manifest may have (others are refused: a misspelt option would be silently ignored)."""
ROBOT_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$")
"""What a robot id may be: it names a folder of the results (at most 128 characters: a file system's names end at
255 bytes)."""
EARLIEST = datetime(1970, 1, 1, tzinfo=UTC)
LATEST = datetime(2262, 1, 1, tzinfo=UTC)
"""The start times a log may have: the results store them as nanoseconds since 1970 in 64 bits (up to April
2262)."""


@dataclass(frozen=True)
class LogEntry:
    """One log of a batch.

    Attributes:
        log: the log's path (absolute).
        robot_id: the robot that wrote it (text, as the manifest or the folder's name gives it).
        start_time: when it started (UTC, aware).
        robot: how to load its robot model.
        options: per-log options (``diff``, ``route``, ``model``) that override the batch's.
        row: the manifest's row it came from (0-based), or None for a scanned log.
    """

    log: Path
    robot_id: str
    start_time: datetime
    robot: RobotSpec
    options: dict[str, str] = field(default_factory=dict)
    row: int | None = None

    @property
    def where(self) -> str:
        """How a message names this log: its manifest row, or its path for a scanned log."""
        return f"manifest row {self.row} ({self.log.name})" if self.row is not None else str(self.log)


@dataclass(frozen=True)
class Skipped:
    """A file or folder a scan passed over, and why (one line)."""

    path: Path
    reason: str

    def __str__(self) -> str:
        return f"{self.path}: {self.reason}"


@dataclass(frozen=True)
class FolderScan:
    """What a scanned folder holds: its logs (:class:`LogEntry`, in path order) and what was passed over."""

    entries: list[LogEntry]
    skipped: list[Skipped]


def read_manifest(path: str | Path) -> list[LogEntry]:
    """The logs a manifest lists (module docstring), checked: columns, robot ids, start times, robot columns,
    option values, the logs' existence and format, and no log listed twice.

    Raises:
        InputError: the first fault, naming the manifest, the row (0-based, as the file's data rows) and column.
    """
    path = Path(path)
    table = TableFile(path).read(text_columns=REQUIRED + OPTIONAL)
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
    columns = {c: _text_column(table.column(c), c, path) for c in names if c != "start_time"}
    entries: list[LogEntry] = []
    seen: dict[Path, int] = {}
    for row in range(table.num_rows):
        cell = {c: (columns[c][row] or "").strip() for c in columns}
        entry = _entry(path, row, cell, starts[row])
        if entry.log in seen:
            raise InputError(f"{path}: row {row}, column 'log': {entry.log} is listed twice (first in row "
                             f"{seen[entry.log]})")
        seen[entry.log] = row
        entries.append(entry)
    return entries


def scan_folder(folder: str | Path, robot: RobotSpec, exclude: Sequence[str | Path] = ()) -> FolderScan:
    """The logs of ``FOLDER/<robot_id>/**`` (module docstring), each with ``robot``, in path order, and every
    file or folder passed over, with why.

    Args:
        folder: the folder scanned.
        robot: every log's robot.
        exclude: folders that are not scanned (the batch's own outputs, when they lie in ``folder``).

    Raises:
        InputError: a folder without any log, a log without dates in its ``time`` column or one out of range.
    """
    folder = Path(folder)
    excluded = {Path(p).resolve() for p in exclude}
    entries: list[LogEntry] = []
    skipped: list[Skipped] = []
    for sub in sorted(p for p in folder.iterdir() if not p.name.startswith(".")):
        if sub.resolve() in excluded:
            skipped.append(Skipped(sub, "this batch's output, not logs"))
        elif not sub.is_dir():
            if find_format(sub) is not None:
                skipped.append(Skipped(sub, f"not in a robot's folder ({folder}/<robot_id>/<log>)"))
        elif not ROBOT_ID.match(sub.name):
            skipped.append(Skipped(sub, "not a robot id (at most 128 letters, digits, '.', '_', '-'; it names a "
                                        "results folder): rename the folder or list its logs in a manifest"))
        else:
            _scan_robot(sub, robot, excluded, entries, skipped)
    if not entries:
        raise InputError(f"{folder}: no log found as {folder}/<robot_id>/<log> ({table_formats()})"
                         + (f" ({len(skipped)} passed over, e.g. {skipped[0]})" if skipped else ""))
    return FolderScan(entries, skipped)


def _scan_robot(sub: Path, robot: RobotSpec, excluded: set[Path], entries: list[LogEntry],
                skipped: list[Skipped]) -> None:
    """The logs of one robot's folder (recursively, hidden names left out) into ``entries``; what is not a log
    into ``skipped``. A folder a format detects (a ROS 2 bag's) is one file: said once, its files not scanned."""
    passed: set[Path] = set()  # the folders a format detects: their files are the format's, not scanned
    for path in sorted(sub.rglob("*")):
        if any(p.startswith(".") for p in path.relative_to(sub).parts):
            continue  # hidden
        resolved = path.resolve()
        if resolved in excluded:
            skipped.append(Skipped(path, "this batch's output, not logs"))
            continue
        if any(resolved.is_relative_to(p) for p in excluded | passed):
            continue  # inside an output or a format's folder (said once, for it)
        fmt = find_format(path)
        if fmt is None:
            if path.is_file():
                skipped.append(Skipped(path, f"not a log: no log format reads it ({table_formats()})"))
            continue  # a folder: its files are scanned
        if path.is_dir():
            passed.add(resolved)
        why = (f"a {fmt.label}, read only through a map (--map), which a batch does not take: convert it first "
               "('wbfriction convert')") if fmt.needs_map else _written_by_wbfriction(path)
        if why:
            skipped.append(Skipped(path, why))
        else:
            entries.append(LogEntry(path.resolve(), sub.name, log_start_time(path), robot))


def _written_by_wbfriction(path: Path) -> str:
    """Why a table file is not a log when wbfriction wrote it (a friction table, a batch's result), else ''."""
    try:
        meta = read_metadata(TableFile(path).schema().empty_table(), str(path))
    except InputError:
        return ""  # unreadable: reported as the log it claims to be
    if "estimate_options" in meta:
        return "a friction table ('wbfriction estimate' wrote it), not a log"
    if meta.get("document") == RESULT_DOCUMENT:
        return "a batch's result, not a log"
    return ""


def log_start_time(log: Path) -> datetime:
    """When a log started, from its ``time`` column if that holds dates (a timestamp column): its first stamp,
    to the microsecond below (a ``datetime``'s resolution, whatever reads it).

    Raises:
        InputError: a ``time`` column of relative seconds (the log then needs a manifest row), or a date out of
            :data:`EARLIEST`-:data:`LATEST`.
    """
    time = TableFile(log).read(["time"])
    if "time" not in time.column_names or time.num_rows == 0:
        raise InputError(f"{log}: column 'time' not found")
    column = time.column("time")
    if not pa.types.is_timestamp(column.type):
        raise InputError(f"{log}: column 'time' holds no dates ({column.type}): give the log's start_time in a "
                         "manifest")
    try:
        first = pc.min(_to_microseconds(column)).as_py()
    except (ValueError, OverflowError, pa.ArrowInvalid) as exc:  # a date Python's datetime cannot hold
        raise InputError(f"{log}: column 'time': {exc}") from None
    return _in_range(first.replace(tzinfo=first.tzinfo or UTC).astimezone(UTC), f"{log}: column 'time'")


def _to_microseconds(column: pa.ChunkedArray) -> pa.ChunkedArray:
    """Timestamps to the microsecond below (a ``datetime``'s resolution: Arrow's ``as_py`` would otherwise give
    pandas' Timestamp or a datetime by what is installed, and keys made of them would differ)."""
    return pc.cast(column, pa.timestamp("us", tz=column.type.tz), safe=False)


def _in_range(t: datetime, where: str) -> datetime:
    if not EARLIEST <= t < LATEST:
        raise InputError(f"{where}: {t.isoformat()} is out of range ({EARLIEST:%Y} to {LATEST:%Y})")
    return t


def _text_column(column: pa.ChunkedArray, name: str, path: Path) -> list[str | None]:
    """A manifest column's cells as text. A Parquet manifest's integer column reads as its decimal digits; any
    other type that is not text is refused (a robot id stored as a float has lost its own spelling)."""
    if pa.types.is_string(column.type) or pa.types.is_large_string(column.type) or pa.types.is_null(column.type):
        return column.to_pylist()
    if pa.types.is_integer(column.type):
        return [None if v is None else str(v) for v in column.to_pylist()]
    raise InputError(f"{path}: column {name!r} holds {column.type} values, not text: store it as strings (an id "
                     "such as '007' read as a number is another id)")


def _start_times(column: pa.ChunkedArray, path: Path) -> list[datetime]:
    """Every row's start time (UTC), from ISO 8601 strings with a zone or timestamps."""
    if pa.types.is_timestamp(column.type) and column.type.tz is None:
        raise InputError(f"{path}: column 'start_time': timestamps without a time zone (store them as UTC)")
    out = []
    for row, value in enumerate(_to_microseconds(column).to_pylist() if pa.types.is_timestamp(column.type)
                                else _text_column(column, "start_time", path)):
        where = f"{path}: row {row}, column 'start_time'"
        if isinstance(value, datetime):
            t = value
        else:
            try:
                t = datetime.fromisoformat(str(value).strip())
            except ValueError:
                raise InputError(f"{where}: {value!r} is not an ISO 8601 date (e.g. 2026-03-01T08:00:00+00:00)"
                                 ) from None
            if t.tzinfo is None:
                raise InputError(f"{where}: {value!r} has no time zone (add +00:00 for UTC)")
        out.append(_in_range(t.astimezone(UTC), where))
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
        raise InputError(f"{where}, column 'robot_id': {cell['robot_id']!r} is not a robot id (at most 128 letters, "
                         "digits, '.', '_', '-'; it names a folder)")
    name, urdf, config = cell.get("robot", ""), cell.get("urdf", ""), cell.get("config", "")
    if not (name or urdf or config):
        raise InputError(f"{where}: no robot (give column 'robot', a built-in name, or 'urdf' and 'config')")
    if name and config:
        raise InputError(f"{where}, columns 'robot' and 'config': give a built-in robot ({name!r}) or a robot "
                         f"TOML ({config!r}), not both")
    for column, value in (("urdf", urdf), ("config", config)):
        if value and not (path.parent / value).exists():
            raise InputError(f"{where}, column '{column}': {(path.parent / value).resolve()} not found")
    robot = RobotSpec(name or None, str((path.parent / urdf).resolve()) if urdf else None,
                      str((path.parent / config).resolve()) if config else None)
    options = {c: cell[c] for c in ("diff", "route", "model") if cell.get(c)}
    for column, choices in (("diff", DIFF_OPTIONS), ("route", ROUTE_OPTIONS), ("model", model_choices())):
        if column in options and options[column] not in choices:
            raise InputError(f"{where}, column '{column}': {options[column]!r} is not one of {', '.join(choices)}")
    return LogEntry(log, cell["robot_id"], start, robot, options, row)

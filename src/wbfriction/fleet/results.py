"""The results dataset on disk (issue 25, issue 37; layout in :mod:`wbfriction.fleet.schema`): written one log at a
time, whole or not at all, each file checked when it is read back.

A log's file is written only when its result is complete (:func:`~wbfriction.logs.tables.write_atomic` writes a
temporary file and renames it), so a batch stopped at any moment leaves only whole results. Each file carries
the SHA-256 of its rows (:func:`rows_sha256`) in its ``wbfriction`` metadata; :func:`read_part` checks it, the
columns, and that the file's name and folder are its rows' key and robot id, so that a truncated, altered or
stray file is found and named (:class:`Part`), never read as a result. Failures live beside the dataset
(:func:`failures_folder`), never inside it: the folder stays a dataset any Parquet reader opens.

A robot's log is its start time (issue 53): a batch replaces the result of a log it no longer lists by that of
the listed log with its robot id and start time (:mod:`wbfriction.fleet.batch`), and :func:`read_results` says
where one start time still holds several logs' results (:meth:`ResultsDataset.notes`: written by an earlier
version, or several logs listed with one start time): each is counted, and said.
"""

from __future__ import annotations

import hashlib
import json
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from wbfriction.exceptions import InputError
from wbfriction.fleet.manifest import Skipped
from wbfriction.fleet.schema import RESULT_DOCUMENT, RESULT_SCHEMA
from wbfriction.fleet.task import LogOutcome, ResultKey
from wbfriction.logs.tables import META_KEY, make_folder, remove_file, with_metadata, write_json, write_table

SORT = [("robot_id", "ascending"), ("start_time", "ascending"), ("log", "ascending"), ("joint", "ascending")]
"""The order :func:`read_results` gives the rows in."""
FAILED = "-failed"
"""The suffix of the failures' folder, beside the results': ``RESULTS-failed``."""
EARLIER_LAYOUT = "robot_id="
"""The prefix of a robot's folder in the layout of wbfriction before issue 37 (Hive partitions, failures inside)."""


def failures_folder(results: str | Path) -> Path:
    """Where the failures of the batch writing ``results`` are recorded: the folder ``RESULTS-failed`` beside it."""
    results = Path(results).absolute()
    return results.parent / f"{results.name}{FAILED}"


def result_path(results: Path, robot_id: str, key: str) -> Path:
    """Where the rows of the log of ``key`` go."""
    return results / robot_id / f"{key}.parquet"


def failure_path(results: Path, key: str) -> Path:
    """Where the failure of the log of ``key`` is recorded."""
    return failures_folder(results) / f"{key}.json"


def table_path(tables: Path, robot_id: str, key: str) -> Path:
    """Where the friction table of the log of ``key`` goes, in the folder of tables asked for."""
    return tables / robot_id / f"{key}.parquet"


def rows_sha256(rows: pa.Table) -> str:
    """SHA-256 of a result's rows as canonical JSON (column names and values in the schema's order, floats as
    their shortest exact repr, timestamps as integer nanoseconds): the same rows give the same digest however
    the file stores them."""
    columns = {}
    for name in rows.column_names:
        column = rows.column(name)
        if pa.types.is_timestamp(column.type):
            column = column.cast(pa.int64())
        columns[name] = column.to_pylist()
    return hashlib.sha256(json.dumps(columns, allow_nan=True).encode()).hexdigest()


@dataclass(frozen=True)
class Part:
    """One file of a results folder, as read back: its rows when it is a whole result, else why not.

    Attributes:
        path: the file.
        rows: its rows (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`, at least one), or None.
        problem: why it is not a result (one line): ``""`` for a whole result.
        foreign: it is not a file of wbfriction's (no result metadata): left as it is, never removed.
    """

    path: Path
    rows: pa.Table | None = None
    problem: str = ""
    foreign: bool = False

    @property
    def key(self) -> str:
        """The key its name says it holds."""
        return self.path.stem

    def first(self, column: str) -> Any:
        """A column's value in its first row (every row of a result has the same key fields)."""
        assert self.rows is not None
        return self.rows.column(column)[0].as_py()

    @property
    def log_id(self) -> tuple[str, int]:
        """What tells a log from another: its robot id and start time (nanoseconds since 1970)."""
        assert self.rows is not None
        return self.first("robot_id"), self.rows.column("start_time").cast(pa.int64())[0].as_py()


def write_part(results: Path, rows: pa.Table) -> Path:
    """Write one log's rows (one key, one robot) with the digest of its rows; the file's path."""
    key, robot_id = rows.column("key")[0].as_py(), rows.column("robot_id")[0].as_py()
    path = result_path(results, robot_id, key)
    make_folder(path.parent)
    rows = rows.cast(RESULT_SCHEMA)
    write_table(with_metadata(rows, {"document": RESULT_DOCUMENT, "rows_sha256": rows_sha256(rows)}), path)
    return path


def read_part(path: Path) -> Part:
    """One file of a results folder, checked: readable, a result (its metadata), this version's columns, rows
    matching their digest, and its name and folder those of its rows' key and robot id."""
    try:
        table = pq.read_table(path)
    except (pa.ArrowException, OSError, ValueError) as exc:
        return Part(path, problem=f"unreadable ({(str(exc).splitlines() or [type(exc).__name__])[0]})")
    raw = (table.schema.metadata or {}).get(META_KEY)
    try:
        meta = json.loads(raw) if raw is not None else {}
    except ValueError:
        meta = {}
    if not isinstance(meta, dict) or meta.get("document") != RESULT_DOCUMENT:
        return Part(path, problem="not a result of 'wbfriction batch' (no result metadata)", foreign=True)
    rows = table.replace_schema_metadata(None)
    if not rows.schema.equals(RESULT_SCHEMA):
        return Part(path, problem="its columns are not those of this version's results")
    if rows.num_rows == 0 or rows_sha256(rows) != meta.get("rows_sha256"):
        return Part(path, problem="damaged: its rows do not match their SHA-256")
    if set(rows.column("key").to_pylist()) != {path.stem} or \
            set(rows.column("robot_id").to_pylist()) != {path.parent.name}:
        return Part(path, problem="moved: its name and folder are not its rows' key and robot id")
    return Part(path, rows)


def read_parts(results: str | Path) -> list[Part]:
    """Every Parquet file of a results folder (:func:`read_part`; hidden files left out), in path order; none
    for a folder that does not exist.

    Raises:
        InputError: a folder of the layout before issue 37 (``robot_id=<id>`` folders).
    """
    results = Path(results)
    if not results.is_dir():
        return []
    if any(p.name.startswith(EARLIER_LAYOUT) for p in results.iterdir()):
        raise InputError(f"{results}: results of an earlier wbfriction ({EARLIER_LAYOUT}<id> folders): run the "
                         "batch into a new folder")
    files = sorted(p for p in results.rglob("*.parquet")
                   if not any(s.startswith(".") for s in p.relative_to(results).parts))
    return [read_part(p) if p.parent.parent == results else
            Part(p, problem="not in a robot's folder (RESULTS/<robot_id>/<key>.parquet)", foreign=True)
            for p in files]


@dataclass(frozen=True)
class ResultsDataset:
    """A results folder read back (:func:`read_results`).

    Attributes:
        table: the rows (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`) of every whole result, one result
            per log: of a robot's logs with the same bytes (a copy) only the first (by start time, then path);
            sorted by robot, start time, log and joint.
        left_out: the files whose rows are not in ``table``, with why (damaged, not a result, a copy).
        shared_starts: per robot whose start times hold the results of several logs (other bytes, other paths),
            how many such start times and the first one's logs (each log's rows are in ``table``).
    """

    table: pa.Table
    left_out: tuple[Skipped, ...] = ()
    shared_starts: tuple[tuple[str, int, tuple[str, ...]], ...] = ()

    def notes(self) -> list[str]:
        """What the reader passed over or found doubtful, one line each: ``left out:`` a file with why (files left
        out for one reason as one line: their count and the first), ``note:`` per robot the start times that hold
        several logs (:attr:`shared_starts`)."""
        counts = Counter(s.reason for s in self.left_out)
        out, said = [], set()
        for s in self.left_out:
            if counts[s.reason] == 1:
                out.append(f"left out: {s}")
            elif s.reason not in said:
                said.add(s.reason)
                out.append(f"left out: {counts[s.reason]} files ({s.path}, ...): {s.reason}")
        for robot_id, starts, logs in self.shared_starts:
            hold = f"{starts} start times each hold" if starts > 1 else "1 start time holds"
            out.append(f"note: robot {robot_id}: {hold} the results of several logs (e.g. {', '.join(logs)}), each "
                       "counted as a point: for logs saved again elsewhere, 'wbfriction batch' on the manifest of "
                       "those to keep replaces the others' results")
        return out


def read_results(results: str | Path) -> ResultsDataset:
    """Every whole result of a results folder (:class:`ResultsDataset`): each file checked (:func:`read_part`),
    each robot's log counted once (of its copies, one), and the start times holding several logs found.

    Raises:
        InputError: a folder without any result (naming what it holds instead), or of the earlier layout.
    """
    results = Path(results)
    parts = read_parts(results)
    whole = [p for p in parts if p.rows is not None]
    left_out = [Skipped(p.path, p.problem) for p in parts if p.rows is None]
    if not whole:
        raise InputError(f"{results}: no results (a folder written by 'wbfriction batch', RESULTS/<robot_id>/"
                         f"<key>.parquet)" + (f"; {left_out[0]}" if left_out else ""))
    counted: dict[tuple[str, str], Part] = {}
    tables = []
    for part in sorted(whole, key=lambda p: (p.first("robot_id"), p.first("start_time"), p.first("log"))):
        same = (part.first("robot_id"), part.first("log_sha256"))
        if same in counted:
            left_out.append(Skipped(part.path, f"the log {part.first('log')} has the same bytes as "
                                               f"{counted[same].first('log')}: counted once"))
            continue
        counted[same] = part
        assert part.rows is not None
        tables.append(part.rows)
    table = pa.concat_tables(tables)
    return ResultsDataset(table.take(pc.sort_indices(table, sort_keys=SORT)), tuple(left_out),
                          _shared_starts(list(counted.values())))


def _shared_starts(parts: list[Part]) -> tuple[tuple[str, int, tuple[str, ...]], ...]:
    """Per robot (in order), the start times at which its counted results are of several logs: how many, and the
    first one's logs."""
    logs: dict[tuple[str, int], list[str]] = defaultdict(list)
    for part in parts:
        logs[part.log_id].append(part.first("log"))
    shared: dict[str, list[tuple[int, list[str]]]] = defaultdict(list)
    for (robot_id, start), names in sorted(logs.items()):
        if len(names) > 1:
            shared[robot_id].append((start, sorted(names)))
    return tuple((robot_id, len(starts), tuple(starts[0][1][:2]) + (("...",) if len(starts[0][1]) > 2 else ()))
                 for robot_id, starts in shared.items())


def failure_record(outcome: LogOutcome) -> dict[str, Any]:
    """What a failure's file holds: the log's key fields, its manifest row and the one-line error."""
    k: ResultKey = outcome.key
    return {"log": k.log, "robot_id": k.robot_id, "start_time": k.start_time.isoformat(),
            "manifest_row": outcome.entry.row, "key": k.key, "log_sha256": k.log_sha256,
            "robot_sha256": k.robot_sha256, "options_sha256": k.options_sha256, "error": outcome.error}


def write_outcome(results: Path, outcome: LogOutcome, replaces: tuple[Path, ...] = ()) -> None:
    """Record one log's outcome: the files of its earlier results and failures (``replaces``) removed first,
    then its rows, or its failure record (:func:`failure_record`).

    Raises:
        OutputError: a file that cannot be written or removed, naming it.
    """
    for path in replaces:
        remove_file(path)
    if outcome.rows is not None:
        write_part(results, outcome.rows)
        return
    failure = failure_path(results, outcome.key.key)
    make_folder(failure.parent)
    write_json(failure, failure_record(outcome))


def failure_files(results: str | Path) -> list[tuple[Path, dict[str, Any]]]:
    """The failure records of the batch writing ``results`` (:func:`failure_record`) with their files, in file
    order; an unreadable one is left out (the log it names is tried again anyway)."""
    out = []
    for path in sorted(failures_folder(results).glob("*.json")):
        try:
            record = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(record, dict):
            out.append((path, record))
    return out


def read_failures(results: str | Path) -> list[dict[str, Any]]:
    """The failure records of the batch writing ``results`` (:func:`failure_record`), by log."""
    return sorted((record for _, record in failure_files(results)), key=lambda d: str(d.get("log")))

"""The results dataset on disk (issue 25; layout in :mod:`wbfriction.fleet.schema`): written one log at a time,
whole or not at all, read back as one table.

A log's file is written only when its result is complete (:func:`~wbfriction.logs.tables.write_table` writes a
temporary file and renames it), so a batch stopped at any moment leaves only whole results, and the next run
skips them (:func:`done_keys`). The files do not repeat ``robot_id``: their folder's name gives it (Hive
partitioning), so that readers which add partition columns (``pyarrow.dataset`` with ``partitioning="hive"``,
pandas, Polars, DuckDB, Spark) see it once.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from wbfriction.exceptions import InputError
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.fleet.task import LogOutcome
from wbfriction.logs.tables import write_json, write_table

FILE_SCHEMA = pa.schema([f for f in RESULT_SCHEMA if f.name != "robot_id"])
"""The schema of one log's file: :data:`~wbfriction.fleet.schema.RESULT_SCHEMA` without ``robot_id``."""
PARTITION = "robot_id="
"""The prefix of a robot's folder."""
SORT = [("robot_id", "ascending"), ("start_time", "ascending"), ("log", "ascending"), ("joint", "ascending")]
"""The order :func:`read_results` gives the rows in."""


def result_path(results: Path, robot_id: str, key: str) -> Path:
    """Where the rows of the log of ``key`` go."""
    return results / f"{PARTITION}{robot_id}" / f"{key}.parquet"


def failure_path(results: Path, key: str) -> Path:
    """Where the failure of the log of ``key`` is recorded."""
    return results / "failed" / f"{key}.json"


def table_path(results: Path, robot_id: str, key: str) -> Path:
    """Where the friction table of the log of ``key`` goes, when asked for."""
    return results / "tables" / f"{PARTITION}{robot_id}" / f"{key}.parquet"


def done_keys(results: Path) -> set[str]:
    """The keys of the logs whose results are in ``results`` (none for a new folder)."""
    return {p.stem for p in results.glob(f"{PARTITION}*/*.parquet")} if results.is_dir() else set()


def write_outcome(results: Path, outcome: LogOutcome) -> None:
    """Record one log's outcome: its rows (and its failure record removed), or its failure (entry and error)."""
    key = outcome.key.key
    failure = failure_path(results, key)
    if outcome.rows is not None:
        path = result_path(results, outcome.entry.robot_id, key)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_table(outcome.rows.drop_columns(["robot_id"]).cast(FILE_SCHEMA), path)
        failure.unlink(missing_ok=True)
        return
    failure.parent.mkdir(parents=True, exist_ok=True)
    write_json(failure, {"log": str(outcome.entry.log), "robot_id": outcome.entry.robot_id,
                         "start_time": outcome.entry.start_time.isoformat(), "manifest_row": outcome.entry.row,
                         "key": key, "error": outcome.error})


def read_results(results: str | Path) -> pa.Table:
    """Every log's rows (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`), sorted by robot, start time, log and
    joint.

    Raises:
        InputError: a folder that is not a results dataset (no ``robot_id=<id>`` folder of results).
    """
    results = Path(results)
    parts = sorted(results.glob(f"{PARTITION}*")) if results.is_dir() else []
    if not parts:
        raise InputError(f"{results}: no results (a folder written by 'wbfriction batch', with robot_id=<id> "
                         "folders)")
    tables = []
    for part in parts:
        robot_id = part.name[len(PARTITION):]
        for file in sorted(part.glob("*.parquet")):
            t = pq.read_table(file, schema=FILE_SCHEMA)
            tables.append(t.add_column(0, "robot_id", pa.array([robot_id] * t.num_rows, pa.string())))
    table = pa.concat_tables(tables).cast(RESULT_SCHEMA) if tables else RESULT_SCHEMA.empty_table()
    return table.take(pc.sort_indices(table, sort_keys=SORT))


def read_failures(results: str | Path) -> list[dict[str, Any]]:
    """The failure records (log, robot_id, start_time, manifest_row, key, error) of ``results``, by log."""
    files = sorted((Path(results) / "failed").glob("*.json"))
    return sorted((json.loads(f.read_text()) for f in files), key=lambda d: d["log"])

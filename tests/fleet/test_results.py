"""The results folder (issue 37): a dataset every Parquet reader opens, failures and tables beside it, every file
checked when read back (a damaged one found, named, recomputed), each robot's log counted once."""

from __future__ import annotations

import shutil
from datetime import UTC, datetime, timedelta
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

from wbfriction.fleet.batch import plan_batch, run_batch
from wbfriction.fleet.manifest import read_manifest
from wbfriction.fleet.results import failures_folder, read_failures, read_part, read_results, rows_sha256
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.logs.tables import read_metadata


def _parts(results: Path) -> dict[str, bytes]:
    return {p.relative_to(results).as_posix(): p.read_bytes() for p in sorted(results.glob("*/*.parquet"))}


@pytest.fixture(scope="module")
def with_failure(arm_fleet, tmp_path_factory) -> Path:
    """A batch of one good log and one broken log, friction tables kept: its folder (manifest, logs, results,
    tables)."""
    folder, _ = arm_fleet
    tmp = tmp_path_factory.mktemp("failure")
    shutil.copy(folder / "a1.parquet", tmp / "a1.parquet")
    (tmp / "broken.parquet").write_bytes((folder / "a2.parquet").read_bytes()[:5000])
    (tmp / "m.csv").write_text("log,robot_id,start_time,robot\n"
                               "broken.parquet,007,2026-03-01T08:00:00Z,panda\n"
                               "a1.parquet,7,2026-03-02T08:00:00Z,panda\n")
    summary = run_batch(read_manifest(tmp / "m.csv"), tmp / "results", engine="serial", tables=tmp / "tables")
    assert summary.processed == 2 and len(summary.failed) == 1
    return tmp


def test_every_reader_opens_the_results_after_a_failure(with_failure):
    """Issue 37: pandas, pq.read_table and pyarrow.dataset failed once a log had failed (failed/*.json and the
    tables sat in the dataset's root)."""
    results = with_failure / "results"
    expected = read_results(results).table
    assert expected.num_rows == 7 and set(expected.column("robot_id").to_pylist()) == {"7"}
    tables = [pq.read_table(results), ds.dataset(results, partitioning="hive").to_table(),
              ds.dataset(results, format="parquet").to_table()]
    pandas = pytest.importorskip("pandas")
    tables.append(pa.Table.from_pandas(pandas.read_parquet(results), preserve_index=False))
    try:
        import duckdb
    except ImportError:
        pass
    else:
        read = duckdb.sql(f"select * from read_parquet('{results}/*/*.parquet')").arrow()
        tables.append(read.read_all() if hasattr(read, "read_all") else read)
    for table in tables:
        table = table.select(RESULT_SCHEMA.names).cast(RESULT_SCHEMA)
        table = pa.table([pc.fill_null(c, float("nan")) if pa.types.is_floating(c.type) else c for c in table.columns],
                         schema=RESULT_SCHEMA)  # pandas' NaN comes back as a null
        assert rows_sha256(table.sort_by("joint")) == rows_sha256(expected.sort_by("joint"))  # NaN = NaN
    (failure,) = read_failures(results)
    assert failure["robot_id"] == "007" and failure["manifest_row"] == 0
    assert list(failures_folder(results).glob("*.json")) and failures_folder(results).parent == with_failure
    (table,) = (with_failure / "tables" / "7").glob("*.parquet")
    assert "estimate_options" in read_metadata(pq.read_table(table))


def test_a_damaged_part_is_found_named_and_recomputed(with_failure, tmp_path):
    """Issue 37: a truncated part made trends raise ArrowInvalid, and batch called its log done."""
    results = tmp_path / "results"
    shutil.copytree(with_failure / "results", results)
    original = _parts(results)
    (name,) = original
    part = results / name
    part.write_bytes(original[name][:3000])  # truncated
    assert "unreadable" in read_part(part).problem
    with pytest.raises(Exception, match="no results"):
        read_results(results)
    entries = read_manifest(with_failure / "m.csv")
    plan = plan_batch(entries, results)
    (todo,) = [p for p in plan.todo if p.entry.robot_id == "7"]
    assert todo.reason.startswith("its result was unreadable") and part in todo.replaces
    run_batch(entries[1:], results, engine="serial")
    assert _parts(results) == original  # recomputed, the same bytes


def test_rows_altered_in_place_do_not_pass_as_a_result(with_failure, tmp_path):
    results = tmp_path / "results"
    shutil.copytree(with_failure / "results", results)
    (name,) = _parts(results)
    table = pq.read_table(results / name)
    f_c = pc.multiply(table.column("F_c"), 1.5)
    pq.write_table(table.set_column(table.schema.get_field_index("F_c"), "F_c", f_c), results / name)
    assert read_part(results / name).problem == "damaged: its rows do not match their SHA-256"
    moved = results / "8" / Path(name).name
    moved.parent.mkdir()
    shutil.copy(with_failure / "results" / name, moved)
    assert read_part(moved).problem.startswith("moved:")


def test_a_stray_file_is_left_as_it_is_and_left_out(with_failure, tmp_path):
    """Issue 37: a stray Parquet file in a robot's folder made trends raise TypeError."""
    results = tmp_path / "results"
    shutil.copytree(with_failure / "results", results)
    pq.write_table(pa.table({"x": [1.0]}), results / "7" / "stray.parquet")
    dataset = read_results(results)
    assert dataset.table.num_rows == 7
    (left,) = dataset.left_out
    assert left.path.name == "stray.parquet" and "not a result of 'wbfriction batch'" in left.reason
    plan = plan_batch(read_manifest(with_failure / "m.csv")[1:], results)
    assert plan.todo == [] and [f.path.name for f in plan.foreign] == ["stray.parquet"]
    run_batch(read_manifest(with_failure / "m.csv")[1:], results, engine="serial")
    assert (results / "7" / "stray.parquet").exists()  # not ours: never removed


def test_the_earlier_layout_is_refused_with_one_line(tmp_path):
    (tmp_path / "robot_id=r1").mkdir()
    with pytest.raises(Exception, match=r"results of an earlier wbfriction \(robot_id=<id> folders\)"):
        read_results(tmp_path)


def test_a_robots_log_saved_twice_counts_once(tmp_path, synthetic_results):
    """Issue 37: the same data saved again under another name gave trends a second point of the same log."""
    parts = synthetic_results(tmp_path / "results", 3)
    table = pq.read_table(parts[1]).replace_schema_metadata(None)
    again = table.set_column(table.schema.get_field_index("log"), "log", pa.array(["/logs/r1/again.parquet"] * 2))
    again = again.set_column(again.schema.get_field_index("key"), "key", pa.array(["r1-again"] * 2))
    again = again.set_column(again.schema.get_field_index("start_time"), "start_time",
                             pc.add(again.column("start_time"), pa.scalar(timedelta(hours=1))))
    from wbfriction.fleet.results import write_part

    write_part(tmp_path / "results", again)  # the same bytes (log_sha256) as log 1, an hour later
    dataset = read_results(tmp_path / "results")
    assert dataset.table.num_rows == 3 * 2 and "/logs/r1/again.parquet" not in dataset.table.column("log").to_pylist()
    (left,) = dataset.left_out
    assert left.path.name == "r1-again.parquet"
    assert left.reason == "the log /logs/r1/again.parquet has the same bytes as /logs/r1/1.parquet: counted once"


def _saved_again(part: Path, log: str, start_time=None) -> Path:
    """The rows of ``part`` as the result of another log (its path ``log``, other bytes), at ``start_time``."""
    from wbfriction.fleet.results import write_part

    table = pq.read_table(part).replace_schema_metadata(None)
    changes = {"log": log, "key": log.strip("/").replace("/", "-").removesuffix(".parquet"),
               "log_sha256": "other bytes of " + log}
    if start_time is not None:
        changes["start_time"] = start_time
    for column, value in changes.items():
        field = table.schema.field(column)
        table = table.set_column(table.schema.get_field_index(column), field, pa.array([value] * table.num_rows,
                                                                                       field.type))
    return write_part(part.parents[1], table)


def test_start_times_holding_several_logs_are_said_in_one_line(tmp_path, synthetic_results):
    """Issue 53, class 8: ten logs saved again (with a temperature column) elsewhere and batched into the same results
    by an earlier version gave trends 20 points at 10 start times of one robot, without a word. The reader says it,
    one line per robot (a batch run on the logs to keep replaces the others: tests/fleet/test_batch.py)."""
    results = tmp_path / "results"
    parts = synthetic_results(results, 10)
    for i, part in enumerate(parts):
        _saved_again(part, f"/again/r1/{i}.parquet")
    dataset = read_results(results)
    assert dataset.table.num_rows == 2 * 10 * 2 and dataset.left_out == ()
    (note,) = dataset.notes()
    assert note.startswith("note: robot r1: 10 start times each hold the results of several logs (e.g. "
                           "/again/r1/0.parquet, /logs/r1/0.parquet)")


def test_logs_listed_at_one_start_time_are_each_counted_and_said(tmp_path, synthetic_results):
    """Ten logs listed with one start time are ten points (trends says they are at one time), and said."""
    results = tmp_path / "results"
    parts = synthetic_results(results, 10)
    for i, part in enumerate(parts):
        _saved_again(part, f"/logs/r1/one-{i}.parquet", start_time=datetime(2026, 1, 1, tzinfo=UTC))
        part.unlink()
    dataset = read_results(results)
    assert dataset.table.num_rows == 10 * 2 and dataset.left_out == ()
    (note,) = dataset.notes()
    assert note.startswith("note: robot r1: 1 start time holds the results of several logs (e.g. "
                           "/logs/r1/one-0.parquet, /logs/r1/one-1.parquet, ...)")

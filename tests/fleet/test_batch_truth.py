"""What a batch decides, case by case (issue 37, mutation testing of ``fleet/batch.py``): which logs are done,
computed (and why), which files are replaced, removed, kept or left; its options refused before any work; the
tasks on a Dask cluster and their chunks on one BLAS thread. Each log's computation is a fast function of its
key (the computation's own truth is tests/fleet/test_batch.py's)."""

from __future__ import annotations

import dataclasses
import json
import re
import socket
import subprocess
import sys
from datetime import UTC, datetime, timedelta
from pathlib import Path
from types import SimpleNamespace

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from threadpoolctl import threadpool_info

from wbfriction.exceptions import InputError
from wbfriction.fit.options import FitOptions
from wbfriction.fleet.batch import DaskChunks, check_outputs, chunk_on_one_thread, connect, plan_batch, run_batch
from wbfriction.fleet.manifest import LogEntry
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.results import failures_folder, read_failures, read_results, result_path
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.fleet.task import LogOutcome
from wbfriction.pipeline.estimate_step import RobotSpec

DAY = datetime(2026, 3, 1, 8, tzinfo=UTC)
CALLS: list[dict] = []
"""What the fake task was called with, in order."""


def fake_process_log(entry, key, options, scratch, table=None, executor=None, chunk_workers=1) -> LogOutcome:
    """One joint's row, F_c the log's first byte; a ``stribeck`` fit fails; a log named ``crash*`` raises."""
    CALLS.append(dict(entry=entry, key=key, options=options, scratch=scratch, table=table, executor=executor,
                      chunk_workers=chunk_workers))
    if entry.log.name.startswith("crash"):
        raise RuntimeError("worker lost")
    if options.fit.model == "stribeck":
        return LogOutcome(entry, key, error=f"{entry.log}: cannot fit")
    row = {name: float("nan") for name in RESULT_SCHEMA.names}
    row.update(robot_id=key.robot_id, log=key.log, start_time=key.start_time, key=key.key, log_sha256=key.log_sha256,
               robot_sha256=key.robot_sha256, options_sha256=key.options_sha256, joint="j", model=options.fit.model,
               route="acceleration",
               status="ok", n_samples=1, version="test", F_c=float(Path(key.log).read_bytes()[0]))
    return LogOutcome(entry, key, pa.Table.from_pydict({k: [v] for k, v in row.items()}, schema=RESULT_SCHEMA),
                      table=table)


@pytest.fixture
def fleet(monkeypatch, tmp_path):
    """Logs ``a``, ``b``, ``c`` (one byte each) and the robot models' digests (``models[name]``), the task faked."""
    models = {"panda": "1" * 64, "other": "2" * 64}
    monkeypatch.setattr("wbfriction.fleet.batch.process_log", fake_process_log)
    monkeypatch.setattr("wbfriction.fleet.batch.worker_robot", lambda spec: SimpleNamespace(name=spec.name))
    monkeypatch.setattr("wbfriction.fleet.batch.robot_sha256", lambda spec, robot: models[spec.name])
    for i, name in enumerate("abc"):
        (tmp_path / f"{name}.log").write_bytes(bytes([i + 1]))
    CALLS.clear()
    return tmp_path, models


def entry(folder: Path, name: str, robot_id: str = "r1", day: int = 0, row: int | None = 0, **options) -> LogEntry:
    return LogEntry(folder / f"{name}.log", robot_id, DAY + timedelta(days=day), RobotSpec("panda"), options, row)


def files(results: Path) -> list[str]:
    return sorted(p.relative_to(results).as_posix() for p in results.rglob("*") if p.is_file())


def test_each_change_of_a_listed_log_is_computed_again_and_said(fleet):
    folder, models = fleet
    results = folder / "results"
    first = [entry(folder, "a", row=0), entry(folder, "b", row=1), entry(folder, "c", row=2)]
    summary = run_batch(first, results, engine="serial")
    assert (summary.processed, summary.skipped, summary.reasons) == (3, 0, {"new": 3})
    done = {p.entry.log.name: result_path(results, "r1", p.key.key) for p in plan_batch(first, results).skipped}
    assert sorted(done) == ["a.log", "b.log", "c.log"] and all(f.exists() for f in done.values())
    # a: robot id and start time corrected; b: its bytes changed; c: as it was
    (folder / "b.log").write_bytes(b"\x09")
    second = [entry(folder, "a", "r2", day=1, row=0), entry(folder, "b", row=1), entry(folder, "c", row=2)]
    plan = plan_batch(second, results)
    assert [(p.entry.log.name, p.reason, p.replaces) for p in plan.todo] == [
        ("a.log", "robot id corrected, start time corrected", (done["a.log"],)),
        ("b.log", "the log changed", (done["b.log"],))]
    assert [p.entry.log.name for p in plan.skipped] == ["c.log"] and plan.stale == () and plan.kept == 0
    summary = run_batch(second, results, engine="serial")
    assert (summary.processed, summary.skipped) == (2, 1)
    assert summary.reasons == {"robot id corrected, start time corrected": 1, "the log changed": 1}
    table = read_results(results).table
    assert sorted(zip(table.column("robot_id").to_pylist(), table.column("F_c").to_pylist())) == [
        ("r1", 3.0), ("r1", 9.0), ("r2", 1.0)]
    assert len(files(results)) == 3
    # other options, another robot model: computed again, each said
    models["panda"] = "3" * 64
    plan = plan_batch(second, results)
    assert {p.reason for p in plan.todo} == {"robot model changed"} and len(plan.todo) == 3
    plan = plan_batch(second[:1], results, BatchOptions(fit=FitOptions(model="thesis")))
    assert [p.reason for p in plan.todo] == ["robot model changed, options changed"]
    models["panda"] = "1" * 64
    plan = plan_batch(second[:1], results, BatchOptions(fit=FitOptions(model="thesis")))
    assert [p.reason for p in plan.todo] == ["options changed"]
    plan = plan_batch([dataclasses.replace(second[0], start_time=DAY + timedelta(days=1, microseconds=1))], results)
    assert [p.reason for p in plan.todo] == ["start time corrected"]


def test_a_log_moved_or_copied_is_the_same_log(fleet):
    """A listed log whose bytes an earlier result had under a path no longer listed replaces that result; a log
    that is not listed and whose bytes no listed log has is kept; two listed logs with the same bytes are two
    results (the pairs named)."""
    folder, _ = fleet
    results = folder / "results"
    # b and c at start times of their own: a robot's other log at one start time replaces it (issue 53)
    run_batch([entry(folder, "a"), entry(folder, "b", day=1, row=1)], results, engine="serial")
    (folder / "a.log").rename(folder / "moved.log")
    (folder / "copy.log").write_bytes((folder / "moved.log").read_bytes())
    (folder / "copy2.log").write_bytes((folder / "moved.log").read_bytes())
    listed = [entry(folder, "moved"), entry(folder, "copy", row=1), entry(folder, "copy2", row=2),
              entry(folder, "c", day=2, row=3)]
    plan = plan_batch(listed, results)
    reasons = {p.entry.log.name: p.reason for p in plan.todo}
    assert reasons["moved.log"] == f"the same log (same bytes) as {folder / 'a.log'}, listed at another path"
    assert reasons["copy.log"] == reasons["copy2.log"] == "new" and reasons["c.log"] == "new"
    assert [p.entry.log.name for p in plan.todo if p.replaces] == ["moved.log"]  # the first listed with its bytes
    assert plan.kept == 1  # b's result: not listed, its bytes not listed
    assert plan.copies == ((listed[0], listed[1]), (listed[0], listed[2]))
    summary = run_batch(listed, results, engine="serial")
    assert summary.kept == 1 and summary.copies == plan.copies and summary.processed == 4
    table = read_results(results).table
    assert len(files(results)) == 5  # b, c, moved, copy and copy2: the three of one day counted once when read
    assert sorted(Path(p).name for p in table.column("log").to_pylist()) == ["b.log", "c.log", "copy.log"]


def test_what_a_plan_removes_and_what_it_leaves(fleet):
    """Earlier results of a log whose result is there and damaged files no listed key names are removed before
    any work; a damaged file a listed key names is its log's, recomputed; files that are not results stay."""
    folder, _ = fleet
    results, other = folder / "results", folder / "other"
    listed = [entry(folder, "a"), entry(folder, "b", row=1)]
    run_batch(listed, results, engine="serial")
    run_batch(listed[:1], other, BatchOptions(fit=FitOptions(model="thesis")), engine="serial")
    (earlier,) = (other / "r1").glob("*.parquet")
    (results / "r1" / earlier.name).write_bytes(earlier.read_bytes())  # a's result with other options
    b_file = result_path(results, "r1", plan_batch(listed, results).skipped[1].key.key)
    b_file.write_bytes(b_file.read_bytes()[:50])  # b's result damaged
    stray_damaged = results / "r1" / f"{'f' * 64}.parquet"
    stray_damaged.write_bytes(b"not parquet")
    foreign = results / "r1" / "notes.parquet"
    pq.write_table(pa.table({"x": [1]}), foreign)
    plan = plan_batch(listed, results)
    assert [p.entry.log.name for p in plan.skipped] == ["a.log"]
    (todo,) = plan.todo
    assert todo.entry.log.name == "b.log" and todo.replaces == (b_file,) and todo.reason.startswith(
        "its result was unreadable")
    stale = {s.path: s.reason for s in plan.stale}
    assert sorted(stale) == sorted([results / "r1" / earlier.name, stray_damaged])
    assert stale[results / "r1" / earlier.name] == f"an earlier result of {listed[0].where}, whose result is there: " \
                                                  "removed"
    assert stale[stray_damaged].startswith("unreadable (") and \
        stale[stray_damaged].endswith(": removed (no listed log has its key)")
    assert [(f.path, f.reason) for f in plan.foreign] == [
        (foreign, "not a result of 'wbfriction batch' (no result metadata): left as it is")]
    summary = run_batch(listed, results, engine="serial")
    assert (summary.processed, summary.skipped, summary.reasons) == (1, 1, {todo.reason: 1})
    assert not (results / "r1" / earlier.name).exists() and not stray_damaged.exists() and foreign.exists()
    assert len(read_results(results).table) == 2


def test_a_failure_is_recorded_retried_and_replaced(fleet):
    folder, _ = fleet
    results = folder / "results"
    listed = [entry(folder, "a", model="stribeck"), entry(folder, "b", row=1)]
    summary = run_batch(listed, results, engine="serial")
    assert summary.processed == 2 and summary.failed == [(listed[0], f"{listed[0].log}: cannot fit")]
    (record,) = read_failures(results)
    assert record["manifest_row"] == 0 and record["error"] == f"{listed[0].log}: cannot fit"
    plan = plan_batch(listed, results)
    assert [(p.entry.log.name, p.reason) for p in plan.todo] == [("a.log", "failed before")]
    assert plan.todo[0].replaces == tuple(failures_folder(results).glob("*.json"))
    (failures_folder(results) / "garbage.json").write_text("{not json")
    (failures_folder(results) / "list.json").write_text("[1, 2]")
    fixed = [entry(folder, "a"), listed[1]]
    summary = run_batch(fixed, results, engine="serial")
    assert summary.reasons == {"failed before": 1} and summary.failed == []
    assert sorted(p.name for p in failures_folder(results).iterdir()) == ["garbage.json", "list.json"]
    assert read_results(results).table.num_rows == 2


def test_the_tasks_get_their_key_options_and_table(fleet):
    folder, _ = fleet
    results, tables = folder / "results", folder / "tables"
    listed = [entry(folder, "a", "r1", model="coulomb-viscous"), entry(folder, "b", "r2", row=1, diff="central")]
    seen = []
    summary = run_batch(listed, results, BatchOptions(fit=FitOptions(model="thesis")), engine="serial", tables=tables,
                        progress=seen.append)
    assert [o.entry for o in seen] == listed and summary.processed == 2
    a, b = CALLS
    assert a["options"].fit.model == "coulomb-viscous" and b["options"].fit.model == "thesis"
    assert b["options"].estimate.diff == "central" and a["options"].estimate.diff == "auto"
    for call, robot_id in ((a, "r1"), (b, "r2")):
        # the run's own scratch folder in the results, removed however the run ends (issue 53)
        assert call["scratch"].parent == results and call["scratch"].name.startswith(".wbfriction-")
        assert call["executor"] is None and not call["scratch"].exists()
        assert call["table"] == tables / robot_id / f"{call['key'].key}.parquet" and call["table"].parent.is_dir()
        assert call["key"].robot_id == robot_id and call["key"].log == str(call["entry"].log)
    run_batch(listed, results, BatchOptions(fit=FitOptions(model="thesis")), engine="serial")
    assert len(CALLS) == 2  # done: no task


def test_a_killed_batchs_temporary_files_are_removed(fleet):
    """In the results folder, its robots' folders and the failures' folder beside it (a failure record half
    written when the batch was killed stayed there, a JSON file among the records)."""
    folder, _ = fleet
    results = folder / "results"
    run_batch([entry(folder, "a", model="stribeck")], results, engine="serial")
    run_batch([entry(folder, "b")], results, engine="serial")
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    host = re.sub(r"[^A-Za-z0-9]", "", socket.gethostname())[:32]  # a temporary's name, as tables.py documents it
    name = f".x.parquet.wbfriction-{host}-{int(dead.stdout)}-0123abcd.tmp.json"
    for where in (results, results / "r1", failures_folder(results)):
        (where / name).write_bytes(b'{"log": "')
    run_batch([entry(folder, "b")], results, engine="serial")
    assert [p for p in (results, results / "r1", failures_folder(results)) if (p / name).exists()] == []


def test_a_batchs_options_are_refused_before_any_work(fleet):
    folder, _ = fleet
    results = folder / "results"
    listed = [entry(folder, "a")]
    cases = [
        (dict(engine="serial", scheduler="tcp://127.0.0.1:8786"), "--scheduler and --serial: a serial batch runs"),
        (dict(scheduler="tcp://127.0.0.1:8786", client=object()), "a scheduler's address and a client: give one"),
        (dict(engine="serial", workers=2), "--workers: the local cluster's, not used with --serial"),
        (dict(scheduler="tcp://127.0.0.1:8786", workers=2),
         "--workers: the local cluster's, not used with --scheduler"),
        (dict(client=object(), workers=2), "--workers: the local cluster's, not used with --scheduler"),
        (dict(workers=0), "--workers must be at least 1, got 0"),
    ]
    for kwargs, message in cases:
        with pytest.raises(InputError, match="^" + message.replace("(", r"\(")):
            run_batch(listed, results, **kwargs)
    assert not results.exists() and CALLS == []


def test_output_folders_that_cannot_be_are_refused(tmp_path, monkeypatch):
    (tmp_path / "file.txt").write_text("x")
    check_outputs(tmp_path / "new" / "results", tmp_path / "new" / "tables")  # folders to be made: fine
    check_outputs(tmp_path, None)
    for results, tables, message in (
            (tmp_path / "file.txt", None, f"-o {tmp_path / 'file.txt'}: not a folder"),
            (tmp_path / "file.txt" / "r", None, f"-o {tmp_path / 'file.txt' / 'r'}: under {tmp_path / 'file.txt'}, "
                                                "which is a file"),
            (tmp_path / "r", tmp_path / "file.txt", f"--tables {tmp_path / 'file.txt'}: not a folder"),
            (tmp_path / "r", tmp_path / "file.txt" / "t", f"--tables {tmp_path / 'file.txt' / 't'}: under")):
        with pytest.raises(InputError) as info:
            check_outputs(results, tables)
        assert str(info.value).startswith(message)
    # a folder that cannot be written (as root every folder can: its access is what is asked)
    asked = []

    def access(path, mode):
        asked.append((Path(path), mode))
        return not mode & 2  # W_OK: refused

    monkeypatch.setattr("wbfriction.fleet.batch.os.access", access)
    with pytest.raises(InputError, match=f"-o {tmp_path / 'a' / 'b'}: {tmp_path} cannot be written"):
        check_outputs(tmp_path / "a" / "b")
    assert asked == [(tmp_path, 3)]  # written and entered


def test_a_scheduler_that_is_not_one_is_one_line():
    with pytest.raises(InputError, match=r"^--scheduler 'foo bar': not a scheduler's address \(.*e\.g\. tcp://"):
        connect("foo bar")
    with pytest.raises(InputError, match=r"^--scheduler tcp://127\.0\.0\.1:9: no Dask scheduler answered within "
                                         r"0\.5 s$"):
        connect("tcp://127.0.0.1:9", timeout=0.5)


def test_a_chunk_runs_on_one_blas_thread():
    assert chunk_on_one_thread(lambda x: (x, {i["num_threads"] for i in threadpool_info()}), 7) == (7, {1})


def test_tasks_and_chunks_on_a_dask_cluster(fleet):
    """A task hands its log's chunks to the cluster (DaskChunks, as many at a time as the cluster has threads) when
    the log has at least 4 chunks per thread (:data:`~wbfriction.pipeline.chunks.CHUNKS_PER_WORKER`), else runs it
    in its own thread; a task that raises is its log's failure, the batch goes on."""
    from distributed import Client, LocalCluster

    from wbfriction.pipeline.chunks import CHUNKS_PER_WORKER

    folder, _ = fleet
    threads, chunk_rows = 2, 3
    enough = chunk_rows * CHUNKS_PER_WORKER * threads
    for name, rows in (("short", enough - 1), ("long", enough), ("crash", enough)):
        pq.write_table(pa.table({"t": [float(i) for i in range(rows)]}), folder / f"{name}.parquet")
    listed = [LogEntry(folder / f"{n}.parquet", "r1", DAY + timedelta(days=i), RobotSpec("panda"), {}, i)
              for i, n in enumerate(("short", "long", "crash"))]
    with LocalCluster(n_workers=1, processes=False, threads_per_worker=threads, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        summary = run_batch(listed, folder / "results", BatchOptions(chunk_rows=chunk_rows), client=client)
        future = DaskChunks(client).submit(lambda x: (x, {i["num_threads"] for i in threadpool_info()}), 3)
        assert future.result() == (3, {1})
    calls = {c["entry"].log.name: c for c in CALLS}
    assert (calls["short.parquet"]["executor"], calls["short.parquet"]["chunk_workers"]) == (None, 1)
    assert isinstance(calls["long.parquet"]["executor"], DaskChunks) and calls["long.parquet"]["chunk_workers"] == 2
    assert summary.processed == 3 and [e.log.name for e, _ in summary.failed] == ["crash.parquet"]
    (error,) = [e for _, e in summary.failed]
    assert error == f"{listed[2].log}: the cluster could not run it: RuntimeError: worker lost"
    assert read_results(folder / "results").table.num_rows == 2
    assert json.loads(next(failures_folder(folder / "results").glob("*.json")).read_text())["manifest_row"] == 2

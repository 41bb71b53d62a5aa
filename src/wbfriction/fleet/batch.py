"""Many logs, on Dask (issue 25): ``wbfriction batch MANIFEST -o RESULTS/``.

Every log is one task (:func:`~wbfriction.fleet.task.process_log`) on a ``dask.distributed`` cluster: a
:class:`~distributed.LocalCluster` of worker processes by default, or an existing cluster's scheduler
(``scheduler="tcp://host:8786"``; its workers must see the logs and the results folder at the same paths).
Scheduling, retries of tasks whose worker died and the transfer of results are Dask's; wbfriction writes
each result as it arrives (:func:`~wbfriction.fleet.results.write_outcome`), so a batch stopped at any moment
keeps what it finished, and the next run skips the logs whose key (log bytes, robot model, options) has a
result. ``engine="serial"`` runs the same tasks one after the other in this process: the reference the
distributed run equals, bit for bit (each task runs its linear algebra on one BLAS thread, whatever the engine).

A log that fails is recorded with its one line (``RESULTS/failed/<key>.json``) and the batch goes on; it is
tried again by the next run.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from threadpoolctl import threadpool_limits

from wbfriction.exceptions import InputError
from wbfriction.fleet.manifest import LogEntry
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.results import done_keys, table_path, write_outcome
from wbfriction.fleet.task import LogKey, LogOutcome, log_key, process_log, robot_sha256
from wbfriction.logs.tables import TableFile
from wbfriction.pipeline.chunks import CHUNKS_PER_WORKER
from wbfriction.pipeline.estimate import worker_robot

Engine = Literal["dask", "serial"]
"""Where the tasks run: on a Dask cluster, or one after the other in this process."""


@dataclass(frozen=True)
class PlannedLog:
    """A log to process: its entry, key and effective options."""

    entry: LogEntry
    key: LogKey
    options: BatchOptions


@dataclass(frozen=True)
class BatchPlan:
    """What a batch will do: the logs to process, and those whose results are already there."""

    todo: list[PlannedLog]
    skipped: list[PlannedLog]


@dataclass(frozen=True)
class BatchSummary:
    """What a batch did: logs processed, skipped (results already there) and failed (entry, one-line error)."""

    processed: int
    skipped: int
    failed: list[tuple[LogEntry, str]] = field(default_factory=list)
    results: Path = Path()


def plan_batch(entries: list[LogEntry], results: str | Path, options: BatchOptions = BatchOptions()) -> BatchPlan:
    """Load every robot model once (a bad one is an error now, before any work), key every log, and split the
    logs into those to process and those already done.

    Raises:
        InputError: a robot model that does not load (naming the manifest row), an unreadable log.
    """
    results = Path(results)
    robot_hashes: dict[Any, str] = {}
    done = done_keys(results)
    todo: list[PlannedLog] = []
    skipped: list[PlannedLog] = []
    for entry in entries:
        if entry.robot not in robot_hashes:
            try:
                robot_hashes[entry.robot] = robot_sha256(entry.robot, worker_robot(entry.robot))
            except InputError as exc:
                where = f"manifest row {entry.row}: " if entry.row is not None else ""
                raise InputError(f"{where}{exc}") from None
        opts = options.for_entry(entry.options)
        planned = PlannedLog(entry, log_key(entry, robot_hashes[entry.robot], opts), opts)
        (skipped if planned.key.key in done else todo).append(planned)
    return BatchPlan(todo, skipped)


def run_batch(entries: list[LogEntry], results: str | Path, options: BatchOptions = BatchOptions(), *,
              engine: Engine = "dask", workers: int = 2, scheduler: str | None = None, client: Any = None,
              tables: bool = False, progress: Callable[[LogOutcome], None] | None = None) -> BatchSummary:
    """Process every log not yet in ``results`` (module docstring) and write its rows there.

    Args:
        entries: the logs (:func:`~wbfriction.fleet.manifest.read_manifest`,
            :func:`~wbfriction.fleet.manifest.scan_folder`).
        results: the results folder (created; results already in it are kept).
        options: the batch's options (a manifest row's ``diff`` and ``model`` override them).
        engine: ``dask`` (default) or ``serial``.
        workers: worker processes of the local cluster (ignored with ``scheduler`` or ``client``).
        scheduler: address of an existing Dask scheduler, or None for a local cluster.
        client: a ``distributed.Client`` to use as it is (tests run one in-process).
        tables: also keep each log's friction table (``RESULTS/tables/``).
        progress: called with each log's outcome as it is written.

    Raises:
        InputError: what :func:`plan_batch` raises, before any log is processed; ``workers`` below 1.
    """
    if workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    results = Path(results)
    plan = plan_batch(entries, results, options)
    results.mkdir(parents=True, exist_ok=True)
    failed: list[tuple[LogEntry, str]] = []

    def record(outcome: LogOutcome) -> None:
        write_outcome(results, outcome)
        if outcome.failed:
            failed.append((outcome.entry, outcome.error))
        if progress is not None:
            progress(outcome)

    args = [(p.entry, p.key, p.options, results,
             table_path(results, p.entry.robot_id, p.key.key) if tables else None) for p in plan.todo]
    for robot_id in {p.entry.robot_id for p in plan.todo} if tables else ():
        table_path(results, robot_id, "").parent.mkdir(parents=True, exist_ok=True)
    if engine == "serial":
        for a in args:
            record(process_log(*a))
    elif args:
        _run_on_dask(args, record, workers, scheduler, client)
    return BatchSummary(len(plan.todo), len(plan.skipped), failed, results)


class DaskChunks:
    """A long log's chunks as tasks of the cluster its log's task runs on (a
    :class:`~wbfriction.pipeline.estimate.ChunkExecutor`): submitted from inside the task through
    ``distributed.worker_client``, which frees the task's thread while its chunks run."""

    def __init__(self, client: Any):
        self.client = client

    def submit(self, fn: Callable, /, *args: Any) -> Any:
        return self.client.submit(chunk_on_one_thread, fn, *args, pure=False)


def chunk_on_one_thread(fn: Callable, *args: Any) -> Any:
    """``fn(*args)`` with its linear algebra on one BLAS thread, as every task of a batch."""
    with threadpool_limits(1):
        return fn(*args)


def log_task(entry: LogEntry, key: LogKey, options: BatchOptions, scratch: Path, table: Path | None) -> LogOutcome:
    """One log's task on a Dask worker: :func:`~wbfriction.fleet.task.process_log` with its chunks handed to the
    cluster (its workers, at most, at a time) when the log is long enough to pay for it
    (:meth:`~wbfriction.pipeline.chunks.Chunking.processes`; a task that hands out chunks leaves its thread to
    them, and a short log's task keeps its thread: every worker thread then runs one log at a time)."""
    from distributed import get_client, worker_client

    workers = max(1, sum(get_client().nthreads().values()))
    if TableFile(entry.log).row_count() < options.chunk_rows * CHUNKS_PER_WORKER * workers:
        return process_log(entry, key, options, scratch, table)  # on this task's thread: nothing to hand out
    with worker_client(separate_thread=False) as client:
        return process_log(entry, key, options, scratch, table, executor=DaskChunks(client), chunk_workers=workers)


def local_cluster(workers: int) -> Any:
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes, without Dask's default
    ``MALLOC_TRIM_THRESHOLD_=65536`` for them: it turns off glibc's adaptive mmap threshold, so that every
    NumPy array above 64 KiB is mapped and unmapped afresh, and a log's task took 1.5-2x as long as in this
    process (measured: 6 Panda logs, 3.3-6.1 s per task against 2.3-3.5 s). The cluster's dashboard is on any
    free port; its workers log errors only (a worker that takes over 4 s to close is not the user's concern)."""
    import dask
    from distributed import LocalCluster

    environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
               if k != "MALLOC_TRIM_THRESHOLD_"}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                            silence_logs=logging.ERROR)


def _run_on_dask(args: list[tuple], record: Callable[[LogOutcome], None], workers: int, scheduler: str | None,
                 client: Any) -> None:
    """Submit one task per log and record each outcome as it completes; a task Dask gave up on (its workers
    died each time it ran) is recorded as the log's failure."""
    from distributed import Client, as_completed

    own = client is None
    cluster = None
    if own:
        if scheduler is not None:
            client = Client(scheduler)
        else:
            cluster = local_cluster(workers)
            client = Client(cluster)
    try:
        futures = {client.submit(log_task, *a, key=f"wbfriction-log-{a[1].key}", pure=False): a for a in args}
        for future in as_completed(futures):
            a = futures[future]
            try:
                outcome = future.result()
            except Exception as exc:  # the task, not the log: e.g. distributed.KilledWorker
                outcome = LogOutcome(a[0], a[1], error=f"{a[0].log}: the cluster could not run it: "
                                                       f"{type(exc).__name__}: {exc}")
            record(outcome)
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()

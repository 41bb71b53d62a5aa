"""Many logs, on Dask (issue 25, issue 37): ``wbfriction batch MANIFEST -o RESULTS/``.

Every log is one task (:func:`~wbfriction.fleet.task.process_log`) on a ``dask.distributed`` cluster: a
:class:`~distributed.LocalCluster` of worker processes by default, or an existing cluster's scheduler
(``scheduler="tcp://host:8786"``; its workers must see the logs and the results folder at the same paths).
Scheduling, retries of tasks whose worker died and the transfer of results are Dask's; wbfriction writes
each result as it arrives (:func:`~wbfriction.fleet.results.write_outcome`), so a batch stopped at any moment
keeps what it finished. ``engine="serial"`` runs the same tasks one after the other in this process: the
reference the distributed run equals, bit for bit (each task runs its linear algebra on one BLAS thread,
whatever the engine).

**What a run does with what is there** (:func:`plan_batch`). Each listed log has a key
(:class:`~wbfriction.fleet.task.ResultKey`: robot id, start time, path, bytes, robot model, options) and holds
one result at most:

* a whole result under its key: the log is done, skipped;
* a result of the same log under another key (a row corrected, other options, the log changed), or of a log
  no longer listed whose bytes a listed log has (the same data moved or saved again), or of a log no longer
  listed with a listed log's robot id and start time (the log saved again with other bytes, e.g. a temperature
  column added: a robot's log is its start time), or a damaged file: the log is computed again, and the earlier
  files are removed when its outcome is written (the reason is said);
* results of logs not listed, and not theirs by bytes or start time: kept as they are (counted);
* files that are not results (no result metadata): left as they are (named).

So the folder after any sequence of runs holds what one run of the last manifest into an empty folder writes,
plus the results of logs it no longer lists. Two rows whose logs have the same bytes are two results (named).

A log that fails is recorded with its one line (``RESULTS-failed/<key>.json``, beside the dataset) and the
batch goes on; it is tried again by the next run.
"""

from __future__ import annotations

import gc
import logging
import os
from collections import Counter, defaultdict
from collections.abc import Callable, Iterator
from concurrent.futures import CancelledError
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC
from pathlib import Path
from typing import Any, Literal

from threadpoolctl import threadpool_limits

from wbfriction.exceptions import ClusterError, InputError, OutputError
from wbfriction.fleet.lock import results_lock
from wbfriction.fleet.manifest import LogEntry, Skipped
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.results import Part, failure_files, failures_folder, read_parts, table_path, write_outcome
from wbfriction.fleet.task import LogOutcome, ResultKey, one_line, process_log, result_key, robot_sha256, utc_ns
from wbfriction.logs.tables import (
    TableFile,
    file_sha256,
    make_folder,
    remove_file,
    remove_stale_temporaries,
    scratch_folder,
)
from wbfriction.pipeline.chunks import CHUNKS_PER_WORKER
from wbfriction.pipeline.estimate_step import worker_robot
from wbfriction.workers import DASK_PRELOAD, started_held

Engine = Literal["dask", "serial"]
"""Where the tasks run: on a Dask cluster, or one after the other in this process."""
LOCAL_WORKERS = 2
"""Worker processes of the local cluster, by default."""
CONNECT_TIMEOUT = 10.0
"""Seconds a batch waits for the Dask scheduler it is given to answer."""


@dataclass(frozen=True)
class PlannedLog:
    """A listed log, keyed: its entry, key, effective options; for a log to compute, the files of its earlier
    results and failures it replaces and why it is computed (``new``, ``options changed``, ...)."""

    entry: LogEntry
    key: ResultKey
    options: BatchOptions
    replaces: tuple[Path, ...] = ()
    reason: str = "new"


@dataclass(frozen=True)
class BatchPlan:
    """What a batch will do (module docstring).

    Attributes:
        todo: the logs to compute.
        skipped: the logs whose whole result is there.
        stale: files removed before any work: earlier results and failures of logs already done, damaged files
            no listed log's key names (each with why).
        kept: the results of logs not listed (kept as they are).
        foreign: files in the results folder that are not results (left as they are).
        copies: pairs of listed logs with the same bytes (two results).
    """

    todo: list[PlannedLog]
    skipped: list[PlannedLog]
    stale: tuple[Skipped, ...] = ()
    kept: int = 0
    foreign: tuple[Skipped, ...] = ()
    copies: tuple[tuple[LogEntry, LogEntry], ...] = ()


@dataclass(frozen=True)
class BatchSummary:
    """What a batch did: logs processed (and why, by reason), skipped (results already there) and failed
    (entry, one-line error); the plan's notes (:class:`BatchPlan`)."""

    processed: int
    skipped: int
    failed: list[tuple[LogEntry, str]] = field(default_factory=list)
    results: Path = Path()
    reasons: dict[str, int] = field(default_factory=dict)
    stale: tuple[Skipped, ...] = ()
    kept: int = 0
    foreign: tuple[Skipped, ...] = ()
    copies: tuple[tuple[LogEntry, LogEntry], ...] = ()


def _changes(earlier: Part, key: ResultKey) -> str:
    """What differs between an earlier result of a log and its key now, in words."""
    changed = [what for what, column, now in (
        ("the log changed", "log_sha256", key.log_sha256), ("robot id corrected", "robot_id", key.robot_id),
        ("start time corrected", "start_time", key.start_time.astimezone(UTC)),
        ("robot model changed", "robot_sha256", key.robot_sha256), ("options changed", "options_sha256",
                                                                     key.options_sha256))
        if earlier.first(column) != now]
    return ", ".join(changed) or "another version's key"


def _keys(entries: list[LogEntry], options: BatchOptions) -> list[PlannedLog]:
    """Every entry keyed: its robot model loaded once per robot (a bad one is an error now), its log hashed."""
    robot_hashes: dict[Any, str] = {}
    keyed = []
    for entry in entries:
        try:
            if entry.robot not in robot_hashes:
                robot_hashes[entry.robot] = robot_sha256(entry.robot, worker_robot(entry.robot))
            log_hash = file_sha256(entry.log)
        except InputError as exc:
            raise InputError(f"{entry.where}: {exc}") from None
        opts = options.for_entry(entry.options)
        keyed.append(PlannedLog(entry, result_key(entry, log_hash, robot_hashes[entry.robot], opts), opts))
    return keyed


def plan_batch(entries: list[LogEntry], results: str | Path, options: BatchOptions = BatchOptions()) -> BatchPlan:
    """Key every log (:func:`~wbfriction.fleet.task.result_key`), read what ``results`` holds
    (:func:`~wbfriction.fleet.results.read_parts`, the failure records beside it) and decide what is done, what is
    computed and which files it replaces (module docstring). Reads only.

    Raises:
        InputError: a robot model that does not load, an unreadable log (naming the manifest row); a results
            folder of the earlier layout.
    """
    results = Path(results)
    keyed = _keys(entries, options)
    by_path = {str(p.entry.log): i for i, p in enumerate(keyed)}
    by_bytes: dict[str, list[int]] = defaultdict(list)
    for i, p in enumerate(keyed):
        by_bytes[p.key.log_sha256].append(i)
    by_key = {p.key.key: i for i, p in enumerate(keyed)}
    by_start: dict[tuple[str, int], int] = {}
    for i, p in enumerate(keyed):
        by_start.setdefault((p.key.robot_id, utc_ns(p.key.start_time)), i)

    def owner(log: str, log_sha256: str | None) -> int | None:
        """The listed log whose earlier result or failure a file is: the same path, else the same bytes."""
        if log in by_path:
            return by_path[log]
        same = by_bytes.get(log_sha256 or "")
        return same[0] if same else None

    done: set[int] = set()
    files: dict[int, list[Path]] = defaultdict(list)
    why: dict[int, str] = {}
    stale, foreign, kept = [], [], 0
    for part in read_parts(results):
        if part.foreign:
            foreign.append(Skipped(part.path, f"{part.problem}: left as it is"))
            continue
        if part.rows is None:  # damaged: its name is all that is left of its key
            named = by_key.get(part.key)
            if named is None:
                stale.append(Skipped(part.path, f"{part.problem}: removed (no listed log has its key)"))
            else:
                files[named].append(part.path)
                why[named] = f"its result was {part.problem}"
            continue
        of = owner(part.first("log"), part.first("log_sha256"))
        if of is None and part.log_id in by_start:  # the log saved again with other bytes (issue 53)
            files[by_start[part.log_id]].append(part.path)
            why.setdefault(by_start[part.log_id], "an earlier result of its robot and start time")
        elif of is None:
            kept += 1
        elif part.key == keyed[of].key.key:
            done.add(of)
        else:
            files[of].append(part.path)
            why.setdefault(of, _changes(part, keyed[of].key) if part.first("log") == str(keyed[of].entry.log)
                           else f"the same log (same bytes) as {part.first('log')}, listed at another path")
    for path, record in failure_files(results):
        of = owner(str(record.get("log", "")), record.get("log_sha256"))
        if of is not None:
            files[of].append(path)
            why.setdefault(of, "failed before")
    todo, skipped = [], []
    for i, p in enumerate(keyed):
        if i in done:
            skipped.append(p)
            stale += [Skipped(f, f"an earlier result of {p.entry.where}, whose result is there: removed")
                      for f in files[i]]
        else:
            todo.append(PlannedLog(p.entry, p.key, p.options, tuple(files[i]), why.get(i, "new")))
    copies = tuple((keyed[group[0]].entry, keyed[j].entry) for group in by_bytes.values() for j in group[1:])
    return BatchPlan(todo, skipped, tuple(stale), kept, tuple(foreign), copies)


def check_outputs(results: Path, tables: Path | None = None) -> None:
    """Refuse, before any work, a results (or tables) folder that cannot be one: a file, a path under a file, a
    folder that cannot be written.

    Raises:
        InputError: naming the option (``-o``, ``--tables``) and the path.
    """
    for label, folder in (("-o", results), ("--tables", tables)):
        if folder is None:
            continue
        existing = folder
        while not existing.exists() and existing != existing.parent:
            existing = existing.parent
        if existing == folder and not folder.is_dir():
            raise InputError(f"{label} {folder}: not a folder (the results are a folder)")
        if not existing.is_dir():
            raise InputError(f"{label} {folder}: under {existing}, which is a file, not a folder")
        if not os.access(existing, os.W_OK | os.X_OK):
            raise InputError(f"{label} {folder}: {existing} cannot be written")


def quiet_dask_logs() -> None:
    """Dask's own log records below CRITICAL left unprinted (for the command line, whose batch says every fault
    in one line: a lost scheduler's reconnection tracebacks are Dask's). Its loggers' levels are set when
    ``distributed`` is imported, so it is imported first."""
    import distributed  # noqa: F401

    for name in list(logging.root.manager.loggerDict):
        if name == "distributed" or name.startswith("distributed."):
            logging.getLogger(name).setLevel(logging.CRITICAL)


def connect(scheduler: str, timeout: float = CONNECT_TIMEOUT) -> Any:
    """A ``distributed.Client`` of the scheduler at ``scheduler``.

    Raises:
        InputError: an address that is not one, or no scheduler answering within ``timeout`` seconds.
    """
    from distributed import Client

    try:
        return Client(scheduler, timeout=timeout)
    except ValueError as exc:
        message = f"--scheduler {scheduler!r}: not a scheduler's address ({exc}; e.g. tcp://host:8786)"
    except OSError:
        message = f"--scheduler {scheduler}: no Dask scheduler answered within {timeout:g} s"
    # The half-made Client is garbage now: collected here, its __del__ closes its event loop at once. Left to a
    # later collection, it can run inside the next Client's start, which holds the lock that closing waits for:
    # the process hangs (seen in the test suite: Client.__init__ -> LoopRunner.start -> Client.__del__).
    gc.collect()
    raise InputError(message)


def run_batch(entries: list[LogEntry], results: str | Path, options: BatchOptions = BatchOptions(), *,
              engine: Engine = "dask", workers: int | None = None, scheduler: str | None = None, client: Any = None,
              tables: str | Path | None = None, progress: Callable[[LogOutcome], None] | None = None
              ) -> BatchSummary:
    """Compute every listed log whose whole result is not in ``results`` (module docstring), writing each result
    as it arrives and removing the files it replaces.

    Args:
        entries: the logs (:func:`~wbfriction.fleet.manifest.read_manifest`,
            :func:`~wbfriction.fleet.manifest.scan_folder`).
        results: the results folder (created; results already in it are kept or replaced as the module says).
        options: the batch's options (a manifest row's ``diff`` and ``model`` override them).
        engine: ``dask`` (default) or ``serial``.
        workers: worker processes of the local cluster (default :data:`LOCAL_WORKERS`; not with ``scheduler``,
            ``client`` or the serial engine).
        scheduler: address of an existing Dask scheduler, or None for a local cluster.
        client: a ``distributed.Client`` to use as it is (tests run one in-process).
        tables: a folder where each computed log's friction table is kept (``TABLES/<robot_id>/<key>.parquet``),
            or None.
        progress: called with each log's outcome as it is written.

    Raises:
        InputError: what :func:`check_outputs`, :func:`connect` and :func:`plan_batch` raise, before any log is
            processed; ``workers`` below 1, or given where no local cluster runs; ``scheduler`` with the serial
            engine or a ``client``.
        OutputError: a result that cannot be written (the batch stops; what was written is kept).
        ClusterError: the scheduler went away (likewise).
    """
    if engine == "serial" and scheduler is not None:
        raise InputError("--scheduler and --serial: a serial batch runs in this process, without a scheduler")
    if scheduler is not None and client is not None:
        raise InputError("a scheduler's address and a client: give one")
    if workers is not None and (engine == "serial" or scheduler is not None or client is not None):
        raise InputError(f"--workers: the local cluster's, not used with "
                         f"{'--serial' if engine == 'serial' else '--scheduler'}")
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be at least 1, got {workers}")
    results = Path(results).absolute()  # a worker elsewhere (a scheduler's) has another working folder
    tables = Path(tables).absolute() if tables is not None else None
    check_outputs(results, tables)
    with results_lock(results), _cluster_client(engine, scheduler, client) as connected:
        plan = plan_batch(entries, results, options)
        for folder in [results, *(p for p in results.iterdir() if p.is_dir()), failures_folder(results)]:
            remove_stale_temporaries(folder)  # those a killed batch left (a failure record half written too)
        for s in plan.stale:
            remove_file(s.path)
        failed: list[tuple[LogEntry, str]] = []
        planned = {p.key.key: p for p in plan.todo}
        if len(planned) != len(plan.todo):  # the keys name the tasks and files: one per listed log
            raise AssertionError("two logs of one batch with one key")

        def record(outcome: LogOutcome) -> None:
            write_outcome(results, outcome, planned[outcome.key.key].replaces)
            if outcome.failed:
                failed.append((outcome.entry, outcome.error))
            if progress is not None:
                progress(outcome)

        # the tasks' scratch folders go in this run's, removed with it however the run ends (a signal kills the
        # workers, whose own folders would stay): where no result is looked for (a hidden folder)
        with scratch_folder(results) as scratch, _tables_cleaned(tables):
            args = [(p.entry, p.key, p.options, scratch,
                     table_path(tables, p.entry.robot_id, p.key.key) if tables is not None else None)
                    for p in plan.todo]
            for a in args:
                if a[4] is not None:
                    make_folder(a[4].parent)
            if engine == "serial":
                for a in args:
                    record(process_log(*a))
            elif args:
                _run_on_dask(args, record, workers or LOCAL_WORKERS, connected)
    return BatchSummary(len(plan.todo), len(plan.skipped), failed, results, dict(Counter(p.reason for p in plan.todo)),
                        plan.stale, plan.kept, plan.foreign, plan.copies)


@contextmanager
def _tables_cleaned(tables: Path | None) -> Iterator[None]:
    """On leaving, the partial friction tables of the workers that ended with the run (killed on a signal) removed
    from each robot's folder of ``tables`` (those of processes of this machine that no longer exist)."""
    try:
        yield
    finally:
        if tables is not None and tables.is_dir():
            for folder in [tables, *(p for p in tables.iterdir() if p.is_dir())]:
                remove_stale_temporaries(folder)


@contextmanager
def _cluster_client(engine: Engine, scheduler: str | None, client: Any) -> Iterator[Any]:
    """The client given, or one connected now to ``scheduler`` (before any other work: a wrong address is said
    within seconds) and closed after; None for the serial engine or a local cluster (started when there is work)."""
    if engine == "serial" or client is not None or scheduler is None:
        yield client
        return
    own = connect(scheduler)
    try:
        yield own
    finally:
        own.close()


class DaskChunks:
    """A long log's chunks as tasks of the cluster its log's task runs on (a
    :class:`~wbfriction.pipeline.estimate_step.ChunkExecutor`): submitted from inside the task through
    ``distributed.worker_client``, which frees the task's thread while its chunks run."""

    def __init__(self, client: Any):
        self.client = client

    def submit(self, fn: Callable, /, *args: Any) -> Any:
        return self.client.submit(chunk_on_one_thread, fn, *args, pure=False)


def chunk_on_one_thread(fn: Callable, *args: Any) -> Any:
    """``fn(*args)`` with its linear algebra on one BLAS thread, as every task of a batch."""
    with threadpool_limits(1):
        return fn(*args)


def log_task(entry: LogEntry, key: ResultKey, options: BatchOptions, scratch: Path, table: Path | None) -> LogOutcome:
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
    free port; its workers log critical errors only (a task's error is said by the batch, in one line; a worker
    that takes over 4 s to close is not the user's concern)
    and leave the signals that end a command to this process (:func:`~wbfriction.workers.dask_setup`; a
    signal while it starts closes it, :func:`~wbfriction.workers.started_held`)."""
    import dask
    from distributed import LocalCluster

    environ = {k: v for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
               if k != "MALLOC_TRIM_THRESHOLD_"}
    preload = [*dask.config.get("distributed.worker.preload", []), DASK_PRELOAD]
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ, "distributed.worker.preload": preload}):
        return started_held(lambda: LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                                 dashboard_address=":0", silence_logs=logging.CRITICAL),
                            lambda cluster: cluster.close())


def _run_on_dask(args: list[tuple], record: Callable[[LogOutcome], None], workers: int, client: Any) -> None:
    """Submit one task per log and record each outcome as it completes; a task Dask gave up on (its workers
    died each time it ran) is recorded as the log's failure. Without ``client``, on a local cluster of
    ``workers`` processes started here.

    Raises:
        ClusterError: the scheduler went away (the tasks left are cancelled): what was recorded is kept.
        OutputError: a result that cannot be written.
    """
    from distributed import Client, as_completed

    cluster = None
    own = client is None
    try:
        if own:
            cluster = local_cluster(workers)
            client = started_held(lambda: Client(cluster), lambda c: c.close())
        from wbfriction.fleet.dask_plugin import HeapForArrays
        client.register_plugin(HeapForArrays())  # a cluster not started here: its workers' malloc as a process's
        futures = {client.submit(log_task, *a, key=f"wbfriction-log-{a[1].key}", pure=False): a for a in args}
        done = 0
        for future in as_completed(futures):
            a = futures[future]
            try:
                outcome = future.result()
            except OutputError:
                raise  # the results cannot be written (a task's friction table): the batch stops
            except Exception as exc:  # the task, not the log: e.g. distributed.KilledWorker
                if client.status not in ("running", "connecting") or isinstance(exc, CancelledError):
                    raise ClusterError(f"the Dask scheduler {client.scheduler.address} went away: {done} of "
                                       f"{len(args)} logs done, the others not processed (run the batch again)"
                                       ) from None
                outcome = LogOutcome(a[0], a[1], error=one_line(f"{a[0].log}: the cluster could not run it: "
                                                                f"{type(exc).__name__}: {exc}"))
            record(outcome)
            done += 1
    finally:
        if own and client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

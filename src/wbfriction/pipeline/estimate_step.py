"""Files in, files out: a log file estimated chunk by chunk on several processes, streamed to disk.

A log of an hour at 1 kHz (3.6 million rows for TALOS: about 2 GB of joint signals) is
never held whole: its rows are cut into chunks (:mod:`wbfriction.pipeline.chunks`), each
chunk is read with a few rows of context on either side, validated
(:func:`~wbfriction.logs.log.log_from_table`, rows numbered as in the file), estimated
(:func:`~wbfriction.friction.estimate.estimate_log`), and its own rows are appended to the
output, which is renamed into place once complete. A ROS 2 bag is first streamed into a
temporary Parquet log beside the output (:func:`table_log`); :func:`estimate_source` takes either, and records
the log's provenance.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager, nullcontext
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from wbfriction.exceptions import InputError, OutputError
from wbfriction.friction.decision import decide_log
from wbfriction.friction.estimate import estimate_resolved, no_single_support
from wbfriction.friction.io import friction_table
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.clock import Clock, longest_segment
from wbfriction.logs.formats.registry import format_to_stream
from wbfriction.logs.log import log_from_table
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.source import LogSource, open_log
from wbfriction.logs.tables import TableFile, read_metadata, scratch_folder, with_metadata, write_tables
from wbfriction.model.dynamics import check_contact_patterns
from wbfriction.model.loading import RobotSpec
from wbfriction.model.robot import Robot
from wbfriction.pipeline.chunks import (
    CONTEXT,
    Chunk,
    Chunking,
    chunk_rows,
    plan_chunks,
    plan_columns,
    release_freed_memory,
)
from wbfriction.pipeline.provenance import log_provenance
from wbfriction.pipeline.raw_log import prepared_log
from wbfriction.progress import Progress, StageProgress
from wbfriction.signals.content import contact_changes
from wbfriction.signals.phase_window import log_swings
from wbfriction.workers import process_pool


def check_file(robot: Robot, path: str | Path, source: str | None = None, chunking: Chunking = Chunking(),
               read: ReadOptions = ReadOptions()) -> int:
    """Validate a log file against ``robot`` chunk by chunk, as :func:`estimate_file` does
    before estimating (:func:`~wbfriction.logs.log.log_from_table`, as ``read`` says the log is read), in bounded
    memory. Returns its rows.

    Raises:
        InputError: the first fault, naming ``source`` (default ``path``), column and row.
    """
    file = TableFile(path)
    source = source or str(file.path)
    plan = plan_columns(file, robot, source, read)
    clock = plan.clock
    reader = file.row_reader(max(1024, min(chunking.rows, 65_536)))
    for c in plan_chunks(plan.contact, chunking):
        log_from_table(chunk_rows(reader, robot, plan, c), robot, source, read, first_row=c.read_start,
                       period=clock.step, clock=clock.rows(c.read_start, c.read_stop))
    return len(plan.contact)


# worker state: the robots a process has loaded, by how they are loaded
_ROBOTS: dict[RobotSpec, Robot] = {}


def worker_robot(spec: RobotSpec) -> Robot:
    """The robot of ``spec``, loaded once per process (a worker estimates many chunks, or many logs, of one
    robot)."""
    if spec not in _ROBOTS:
        _ROBOTS[spec] = spec.load()
    return _ROBOTS[spec]


def _estimate_chunk(robot: Robot, table: pa.Table, chunk: Chunk, clock: Clock, source: str, options: EstimateOptions,
                    companion: bool, read: ReadOptions) -> pa.Table:
    """The friction table of a chunk's own rows; ``clock``: the whole log's, cut to the rows read."""
    log = log_from_table(table, robot, source, read, first_row=chunk.read_start, period=clock.step, clock=clock)
    est = estimate_resolved(robot, log, options, companion=companion, require_single_support=False)
    return friction_table(est).slice(chunk.start - chunk.read_start, chunk.stop - chunk.start)


def estimate_chunk_task(spec: RobotSpec, args: tuple) -> pa.Table:
    """One chunk's friction table, as a worker computes it: ``args`` as :func:`estimate_file` sends them (the
    chunk's rows, the chunk, its clock and the settings); the robot loaded once per process."""
    return _estimate_chunk(worker_robot(spec), *args)


class ChunkExecutor(Protocol):
    """Where chunks go when not in this process: anything with ``submit(fn, *args)`` returning a future whose
    ``result()`` is ``fn(*args)`` (a :class:`concurrent.futures.Executor`, a Dask client's adapter)."""

    def submit(self, fn: Callable, /, *args: Any) -> Any: ...


def _chunk_tables(spec: RobotSpec, robot: Robot, rows: Callable[[Chunk], pa.Table], chunks: list[Chunk], clock: Clock,
                  workers: int, settings: tuple, executor: ChunkExecutor | None = None) -> Iterator[pa.Table]:
    """Each chunk's friction table in order, estimated in this process or, ``workers`` at a time, on
    ``executor`` (default: a pool of ``workers`` processes), each given its rows of the whole log's ``clock``."""
    args = lambda c: (rows(c), c, clock.rows(c.read_start, c.read_stop),  # noqa: E731
                      *settings)
    if workers <= 1 or len(chunks) == 1:
        for c in chunks:
            yield _estimate_chunk(robot, *args(c))
        return
    with (nullcontext(executor) if executor is not None
          else process_pool(workers, "spawn", worker_robot, (spec,))) as pool:
        pending: deque = deque()
        for c in chunks:
            table, *rest = args(c)
            # a slice of the reader's batches pickles with the whole batches behind it: send a copy of its rows
            pending.append(pool.submit(estimate_chunk_task, spec, (table.take(np.arange(table.num_rows)), *rest)))
            if len(pending) > workers:  # bounded read-ahead: bounded memory
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()


def _with_provenance(tables: Iterator[pa.Table], chunks: list[Chunk], robot: Robot, source: str,
                     extra_metadata: dict | None, progress: Progress | None, first_meta: dict,
                     valid: dict[str, int]) -> Iterator[pa.Table]:
    """``tables`` with provenance in the first one's metadata (kept in ``first_meta``), counted to
    ``progress``, their valid samples per joint counted into ``valid``; a log without a
    single-support sample, or without a valid sample, is an error raised after the last table,
    before the output is renamed into place (nothing is written)."""
    single = False
    for k, table in enumerate(tables):
        single = single or bool(pc.any(table.column("unique")).as_py())
        for j in robot.torque_controlled:
            valid[j] = valid.get(j, 0) + int(pc.sum(table.column(f"valid.{j}")).as_py() or 0)
        if k == 0:
            meta = read_metadata(table, source)
            meta.update(extra_metadata or {})
            first_meta.update(meta)
            table = with_metadata(table, meta)
        yield table
        release_freed_memory()  # the chunk just written, its rows read and sent
        if progress is not None:
            progress(chunks[k].stop - chunks[k].start)
    if not single:
        raise no_single_support(robot, source)
    if not any(valid.values()):
        why = ("the --mask, --lift-off and --touch-down leave none" if robot.floating_base else
               "derivatives defined nowhere: the stretches between time gaps are shorter than the differentiation's "
               "window")
        raise InputError(f"{source}: no valid sample for any joint ({why})")


def no_valid_warnings(source: str, valid: dict[str, int]) -> tuple[str, ...]:
    """One warning per joint left without a valid sample (not fitted: nothing to fit it on)."""
    empty = [j for j, n in valid.items() if n == 0]
    if not empty:
        return ()
    shown = ", ".join(empty[:4]) + (f" and {len(empty) - 4} more" if len(empty) > 4 else "")
    return (f"{source}: no valid sample for {shown} (never in a phase the --mask keeps)",)


def force_sampling_warnings(metadata: dict) -> tuple[str, ...]:
    """The momentum route's line on the foot forces' sampling (:mod:`wbfriction.friction.force_sampling`), from the
    estimate's metadata or its route check's, if it names another reading."""
    found = [m.get("foot_force_sampling", {}).get("warning", "") for m in (metadata, metadata.get("route_check", {}))]
    return tuple(w for w in found if w)


@dataclass
class ChunkedResult:
    """What :func:`estimate_file` did: rows, chunks, and their contact-change cuts; ``clock``: the
    one line saying what the stamps are and which time base was used (:attr:`Clock.reason
    <wbfriction.logs.clock.Clock.reason>`); ``differentiation``: the line saying which scheme ``diff="auto"``
    chose and why (:class:`~wbfriction.signals.choice.DiffChoice`), or ""; ``route``: the line saying which route
    ``route="auto"`` took and its windows (:class:`~wbfriction.friction.route.RouteDecision`), or ""."""

    rows: int
    chunks: int
    forced_cuts: int
    metadata: dict
    clock: str = ""
    differentiation: str = ""
    warnings: tuple[str, ...] = ()
    route: str = ""
    prepared: tuple[str, ...] = ()


def estimate_file(spec: RobotSpec, path: str | Path, output: str | Path, options: EstimateOptions = EstimateOptions(),
                  *, chunking: Chunking = Chunking(), companion: bool = False, read: ReadOptions = ReadOptions(),
                  extra_metadata: dict | None = None,
                  progress: Progress | None = None, robot: Robot | None = None,
                  source: str | None = None, executor: ChunkExecutor | None = None) -> ChunkedResult:
    """Estimate a log file chunk by chunk into ``output`` (Parquet or CSV: a format that streams), whole or not at
    all.

    Args:
        spec: the robot, as worker processes load it.
        path: the log, a table file in any registered format (:mod:`wbfriction.logs.formats`), read chunk by chunk.
        output: the friction table to write (:func:`~wbfriction.friction.io.friction_table`).
        options, companion: as :func:`~wbfriction.friction.estimate.estimate_log` (the companion
            scheme, one more differentiation and inverse-dynamics pass, only on request).
        chunking: chunk length, overlap at forced cuts, processes.
        read: how the log is read (:class:`~wbfriction.logs.options.ReadOptions`: its gaps, the margin on the
            joint limits, the time base, decided once for the whole log, :func:`~wbfriction.logs.clock.read_clock`,
            and the unit of its stamps).
        extra_metadata: merged into the table's metadata (provenance).
        progress: optional callable receiving numbers of rows done.
        robot: ``spec`` already loaded in this process, if the caller has it.
        source: the name messages give the log (default ``path``; a bag converted to a
            temporary file is named as the bag).
        executor: where the chunks go instead of a pool of ``chunking.workers`` processes (e.g. a Dask cluster,
            :mod:`wbfriction.fleet.batch`), ``chunking.workers`` at a time, when the log has enough chunks
            (:meth:`~wbfriction.pipeline.chunks.Chunking.processes`). The table is the same.

    Raises:
        InputError: what reading, validating and estimating raise, naming the file and row (contacts the robot's
            contact models make redundant, :func:`~wbfriction.model.dynamics.check_contact_patterns`, before any chunk);
            an output in no format that streams (:func:`~wbfriction.logs.formats.format_to_stream`); a log that
            leaves no valid sample (:func:`no_valid_sample`). Nothing is written then.
    """
    path, output = Path(path), Path(output)
    format_to_stream(output, "friction tables are written")
    source = source or str(path)
    robot = robot if robot is not None else spec.load()
    file = TableFile(path)
    plan = plan_columns(file, robot, source, read)
    contact, clock, first = plan.contact, plan.clock, plan.first_positions
    check_contact_patterns(robot, contact, source)  # before any chunk: the KKT route's matrix singular
    changes = None
    if first is not None:  # the noise is measured on one segment: a gap between two recordings is no noise
        a, b = longest_segment(clock.segments, len(first))
        first, changes = first[a:b], contact_changes(contact[a:b])
    # the noise measured on the first rows, the route's windows bounded by them: all a file's plan reads (the whole
    # log's rows in memory, estimate_log: wbfriction.friction.decision)
    swings = log_swings(contact, robot.contact_frames, clock.step, clock.segments,
                        (options.lift_off_skip, options.touch_down_skip)) if robot.floating_base else None
    feet = any(c.startswith("force.") for c in file.schema().names)  # the feet's forces: stances estimated too
    decision = decide_log(robot, options, first, clock.step, segments=clock.segments, rows=len(clock), source=source,
                          changes=changes, swings=swings, swings_only=not robot.ft_sensors and not feet)
    options = decision.options
    extra_metadata = {**(extra_metadata or {}), **decision.metadata()}
    n = len(contact)
    chunks = plan_chunks(contact, chunking)
    del contact
    release_freed_memory()  # the whole log's columns the plan read
    reader = file.row_reader(max(1024, min(chunking.rows, 65_536)))
    first_meta: dict = {}
    valid: dict[str, int] = {}
    settings = (source, options, companion, read)
    rows = partial(chunk_rows, reader, robot, plan)
    write_tables(output, _with_provenance(_chunk_tables(spec, robot, rows, chunks, clock,
                                                        chunking.processes(len(chunks)),
                                                        settings, executor),
                                          chunks, robot, source, extra_metadata, progress, first_meta, valid))
    return ChunkedResult(n, len(chunks), sum(1 for c in chunks if c.start - c.read_start > CONTEXT), first_meta,
                         clock.reason, "" if decision.differentiation is None else decision.differentiation.reason,
                         plan.warnings + decision.warnings + no_valid_warnings(source, valid)
                         + force_sampling_warnings(first_meta),
                         "" if decision.route is None else decision.route.reason)


def estimate_source(spec: RobotSpec, log: str | Path, output: str | Path,
                    options: EstimateOptions = EstimateOptions(), *, bag_map: str | Path | None = None,
                    robot: Robot | None = None, stage: StageProgress | None = None,
                    progress: Callable[[int], Progress | None] | None = None, **file_options: Any) -> ChunkedResult:
    """Estimate a log as a user names it (a table file, a ROS 2 bag or a table read through ``bag_map``,
    :func:`~wbfriction.logs.source.open_log`) into ``output``, its provenance recorded in the table's metadata
    (:func:`~wbfriction.pipeline.provenance.log_provenance`): a bag is first streamed into a temporary Parquet log
    beside the output (:func:`table_log`, removed after), then :func:`estimate_file` runs on it.

    Args:
        spec, output, options: as :func:`estimate_file`; ``robot``: ``spec`` loaded in this process, if the
            caller has it.
        log: the log file or bag folder; ``bag_map``: its topic or column map (TOML).
        stage: told ``reading <log>`` while a bag (or a table read through a map) is converted.
        progress: called once with the log's row count, returns the per-row progress of :func:`estimate_file`.
        file_options: the rest of :func:`estimate_file`'s keywords (chunking, companion, read, ...).

    Raises:
        InputError, OutputError: what opening the log, converting it and :func:`estimate_file` raise.
    """
    robot = robot if robot is not None else spec.load()
    source = open_log(log, bag_map, robot)
    output = Path(output)
    with ExitStack() as stack:
        if source.is_mapped and stage is not None:
            stage(f"reading {log}")
        table = stack.enter_context(table_log(source, output))
        table, raw = stack.enter_context(prepared_log(table, robot, str(log), file_options.get("read", ReadOptions()),
                                                      output))
        advance = None if progress is None else progress(TableFile(table).row_count())
        result = estimate_file(spec, table, output, options, robot=robot, source=str(log), progress=advance,
                               extra_metadata={"provenance": log_provenance(log, robot)}, **file_options)
        return result if raw is None else replace(result, prepared=tuple(raw.lines()))


@contextmanager
def table_log(log: LogSource, near: Path) -> Iterator[Path]:
    """The log as a table file for :func:`estimate_file`: a table file as it is; a ROS 2 bag, or a
    table file read through a map (:mod:`wbfriction.logs.table_map`), streamed into a temporary
    Parquet log in a temporary folder beside ``near`` (the output), removed on leaving.

    Raises:
        InputError: what reading the bag (or mapped table) raises.
        OutputError: a temporary log the system refuses to write (a full disk: it is as large as the log),
            naming ``near``, the output that could not be written for it.
    """
    if not log.is_mapped:
        yield log.path
        return
    folder = near.parent if near.parent.exists() else None
    with scratch_folder(folder) as tmp:
        converted = Path(tmp) / "log.parquet"
        try:
            write_tables(converted, log.blocks())
        except OutputError as exc:  # the temporary file's name means nothing to the user: the output's does
            raise OutputError(str(near), exc.errno, exc.reason, near.is_file()) from exc
        yield converted

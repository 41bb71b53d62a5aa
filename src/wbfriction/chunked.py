"""Long logs in bounded memory: the estimate in chunks, on several cores, streamed to disk.

A log of an hour at 1 kHz (3.6 million rows for TALOS: about 2 GB of joint signals) is
never held whole. Its rows are cut into chunks; each chunk is read with a few rows of
context on either side, validated (:func:`~wbfriction.log.log_from_table`, rows numbered
as in the file), estimated (:func:`~wbfriction.estimate.estimate_log`), and its own rows
are appended to the output, which is renamed into place once complete.

**Cuts at contact changes make chunk borders change nothing.** Every stage stops at a
change of the contact flags anyway: no differentiation stencil or filter window spans
one (:func:`~wbfriction.kinematics.straddling`), and the support phases and their
lift-off / touch-down margins (:func:`~wbfriction.phases.segment`) are bounded by them.
So a chunk cut at a contact change, read with :data:`CONTEXT` rows of context (the
previous phase's last rows, the next phase's first), gives exactly the rows of the
whole-log estimate (tests: to 1e-9 N·m; the only difference is the rounding of the
sampling period, the median of the chunk's own time steps). A stretch with no contact
change for twice the chunk length is cut where it must, with ``overlap`` rows of context:
exact for the finite-window schemes when ``overlap`` exceeds the window, within the
Butterworth filter's decay otherwise.
"""

from __future__ import annotations

import multiprocessing
from collections import deque
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from .estimate import EstimateOptions, no_single_support, estimate_log
from .exceptions import InputError
from .hdf5 import SUFFIXES as HDF5_SUFFIXES, read_hdf5
from .log import (LIMIT_MARGIN, MAX_GAP, log_from_table, read_metadata, read_table, table_suffix, with_metadata,
                  write_tables)
from .robot import Robot, load_robot

CONTEXT = 3
"""Rows of context either side of a cut at a contact change (central and backward
differences, the torque alignment and the phase margins need at most two)."""


@dataclass(frozen=True)
class Chunking:
    """How a long log is cut.

    Attributes:
        rows: target rows per chunk (the cut is at the first contact change after it).
        overlap: rows of context at a forced cut (no contact change within ``2 rows``).
        workers: processes estimating chunks (1: in this process).
    """

    rows: int = 10_000
    overlap: int = 2_000
    workers: int = 2


@dataclass(frozen=True)
class RobotSpec:
    """How a worker process loads the robot (:func:`~wbfriction.robot.load_robot`)."""

    name: str | None = "talos"
    urdf: str | None = None
    config: str | None = None

    def load(self) -> Robot:
        return load_robot(self.name, urdf=self.urdf, config=self.config)


@dataclass(frozen=True)
class Chunk:
    """Rows ``[start, stop)`` of the log, read as ``[read_start, read_stop)``."""

    start: int
    stop: int
    read_start: int
    read_stop: int


def plan_chunks(contact: np.ndarray, chunking: Chunking = Chunking()) -> list[Chunk]:
    """Cut ``N`` rows with contact flags ``contact`` (N, n_contacts) into chunks (module docstring)."""
    n = len(contact)
    changes = np.flatnonzero(np.any(contact[1:] != contact[:-1], axis=1)) + 1
    cuts, forced = [0], [False]
    while n - cuts[-1] > chunking.rows:
        target = cuts[-1] + chunking.rows
        k = np.searchsorted(changes, target)
        if k < len(changes) and changes[k] - cuts[-1] <= 2 * chunking.rows and changes[k] < n:
            cuts.append(int(changes[k]))
            forced.append(False)
        else:
            cuts.append(target)
            forced.append(True)
    cuts.append(n)
    forced.append(False)
    context = [chunking.overlap if f else CONTEXT for f in forced]
    return [Chunk(a, b, max(0, a - context[i]), min(n, b + context[i + 1]))
            for i, (a, b) in enumerate(zip(cuts[:-1], cuts[1:]))]


class _RowReader:
    """Row ranges of a Parquet or CSV file, read forwards with a rolling buffer (the memory
    it holds is one chunk and its context); of an HDF5 file, read by slicing its datasets."""

    def __init__(self, path: Path, batch_rows: int):
        self.path = path
        suffix = table_suffix(path)
        self._hdf5 = suffix in HDF5_SUFFIXES
        if self._hdf5:
            self.metadata = read_hdf5(path, columns=[], stop=0).schema.metadata
            return
        try:
            if suffix in (".parquet", ".pq"):
                # without pre-buffering: pyarrow would otherwise keep whole column chunks read ahead
                self._file = pq.ParquetFile(path, pre_buffer=False)
                self.metadata = self._file.schema_arrow.metadata
                self._batches = self._file.iter_batches(batch_size=batch_rows, use_threads=False)
            else:
                self._file = pacsv.open_csv(path, read_options=pacsv.ReadOptions(block_size=1 << 24))
                self.metadata = None
                self._batches = iter(self._file)
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise InputError(f"{path}: cannot be read: {(str(exc).splitlines() or [repr(exc)])[0]}") from exc
        self._buffer: list[pa.RecordBatch] = []
        self._start = 0  # file row of the buffer's first row
        self._stop = 0

    def rows(self, start: int, stop: int) -> pa.Table:
        """Rows ``[start, stop)`` (``start`` never below an earlier call's), with the file's metadata."""
        if self._hdf5:
            return read_hdf5(self.path, start=start, stop=stop)
        while self._stop < stop:
            try:
                batch = next(self._batches)
            except StopIteration:
                break
            except (pa.ArrowException, OSError, ValueError) as exc:
                raise InputError(f"{self.path}: cannot be read at row {self._stop}: "
                                 f"{(str(exc).splitlines() or [repr(exc)])[0]}") from exc
            self._buffer.append(batch)
            self._stop += batch.num_rows
        while self._buffer and self._start + self._buffer[0].num_rows <= start:  # drop what is behind
            self._start += self._buffer.pop(0).num_rows
        table = pa.Table.from_batches(self._buffer) if self._buffer else pa.table({})
        table = table.slice(start - self._start, stop - start)
        return table.replace_schema_metadata(self.metadata) if self.metadata else table


def _plan_columns(path: Path, robot: Robot, source: str) -> tuple[np.ndarray, float]:
    """The contact columns (N, n_contacts), to plan the chunks, and the sampling period of
    the whole log (the median time step) [s], read alone."""
    columns = ["time"] + [f"contact.{f}" for f in robot.contact_frames]
    suffix = path.suffix.lower()
    try:
        if suffix in (".parquet", ".pq"):
            table = pq.read_table(path, columns=[c for c in columns if c in pq.ParquetFile(path).schema_arrow.names])
        elif suffix == ".csv":
            names = pacsv.open_csv(path).schema.names
            table = pacsv.read_csv(path, convert_options=pacsv.ConvertOptions(
                include_columns=[c for c in columns if c in names]))
        elif suffix in HDF5_SUFFIXES:
            table = read_hdf5(path, columns=columns)
        else:
            table = read_table(path)  # refuses the file type
    except (pa.ArrowException, OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read: {(str(exc).splitlines() or [repr(exc)])[0]}") from exc
    for c in columns:
        if c not in table.column_names:
            raise InputError(f"{source}: missing column '{c}'")
    flags = np.column_stack([table.column(c).to_numpy(zero_copy_only=False) for c in columns[1:]])
    time = table.column("time").to_numpy(zero_copy_only=False).astype(float)
    period = float(np.median(np.diff(time))) if len(time) > 1 else float("nan")
    return np.nan_to_num(flags.astype(float)) != 0, period


def iter_file(path: str | Path, block_rows: int = 10_000) -> Iterator[pa.Table]:
    """A Parquet, CSV or HDF5 log as consecutive tables of ``block_rows`` rows (with the
    file's metadata), never read whole.

    Raises:
        InputError: an unreadable file, naming it and the row.
    """
    path = Path(path)
    reader = _RowReader(path, block_rows)
    start = 0
    while True:
        table = reader.rows(start, start + block_rows)
        if table.num_rows == 0:
            return
        yield table
        start += table.num_rows


def check_file(robot: Robot, path: str | Path, source: str | None = None, chunking: Chunking = Chunking(),
               max_gap: float = MAX_GAP, limit_margin: float = LIMIT_MARGIN) -> int:
    """Validate a log file against ``robot`` chunk by chunk, as :func:`estimate_file` does
    before estimating (:func:`~wbfriction.log.log_from_table`), in bounded memory. Returns
    its rows.

    Raises:
        InputError: the first fault, naming ``source`` (default ``path``), column and row.
    """
    path = Path(path)
    source = source or str(path)
    contact, period = _plan_columns(path, robot, source)
    reader = _RowReader(path, max(1024, min(chunking.rows, 65_536)))
    for c in plan_chunks(contact, chunking):
        log_from_table(reader.rows(c.read_start, c.read_stop), robot, source, max_gap, limit_margin,
                       first_row=c.read_start, period=period)
    return len(contact)


# worker state: the robot, loaded once per process
_ROBOT: dict[str, Robot] = {}


def _init_worker(spec: RobotSpec) -> None:
    _ROBOT["robot"] = spec.load()


def _estimate_chunk(robot: Robot, table: pa.Table, chunk: Chunk, source: str, options: EstimateOptions,
                    companion: bool, max_gap: float, limit_margin: float, period: float) -> pa.Table:
    log = log_from_table(table, robot, source, max_gap, limit_margin, first_row=chunk.read_start, period=period)
    est = estimate_log(robot, log, options, companion=companion, require_single_support=False)
    return est.to_table().slice(chunk.start - chunk.read_start, chunk.stop - chunk.start)


def _in_worker(args) -> pa.Table:
    return _estimate_chunk(_ROBOT["robot"], *args)


@dataclass
class ChunkedResult:
    """What :func:`estimate_file` did: rows, chunks, and their contact-change cuts."""

    rows: int
    chunks: int
    forced_cuts: int
    metadata: dict


def estimate_file(spec: RobotSpec, path: str | Path, output: str | Path, options: EstimateOptions = EstimateOptions(),
                  *, chunking: Chunking = Chunking(), companion: bool = True, max_gap: float = MAX_GAP,
                  limit_margin: float = LIMIT_MARGIN, extra_metadata: dict | None = None,
                  progress=None, robot: Robot | None = None, source: str | None = None) -> ChunkedResult:
    """Estimate a log file chunk by chunk into ``output`` (Parquet or CSV), whole or not at all.

    Args:
        spec: the robot, as worker processes load it.
        path: the log (Parquet, CSV or HDF5, read chunk by chunk).
        output: the friction table to write (:meth:`~wbfriction.estimate.FrictionEstimate.to_table`).
        options, companion: as :func:`~wbfriction.estimate.estimate_log`.
        chunking: chunk length, overlap at forced cuts, processes.
        max_gap, limit_margin: as :func:`~wbfriction.log.log_from_table`.
        extra_metadata: merged into the table's metadata (provenance).
        progress: optional callable receiving numbers of rows done.
        robot: ``spec`` already loaded in this process, if the caller has it.
        source: the name messages give the log (default ``path``; a bag converted to a
            temporary file is named as the bag).

    Raises:
        InputError: what reading, validating and estimating raise, naming the file and row;
            an output that is neither .parquet nor .csv. Nothing is written then.
    """
    path, output = Path(path), Path(output)
    if output.suffix.lower() not in (".parquet", ".pq", ".csv"):
        raise InputError(f"{output}: friction tables are written as .parquet or .csv")
    source = source or str(path)
    robot = robot if robot is not None else spec.load()
    contact, period = _plan_columns(path, robot, source)
    n = len(contact)
    chunks = plan_chunks(contact, chunking)
    del contact
    reader = _RowReader(path, max(1024, min(chunking.rows, 65_536)))
    first_meta: dict = {}

    def tables():
        args = lambda c: (reader.rows(c.read_start, c.read_stop), c, source, options, companion,  # noqa: E731
                          max_gap, limit_margin, period)
        if chunking.workers <= 1 or len(chunks) == 1:
            for c in chunks:
                yield _estimate_chunk(robot, *args(c))
            return
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(chunking.workers, mp_context=ctx, initializer=_init_worker,
                                 initargs=(spec,)) as pool:
            pending: deque = deque()
            for c in chunks:
                pending.append(pool.submit(_in_worker, args(c)))
                if len(pending) > chunking.workers:  # bounded read-ahead: bounded memory
                    yield pending.popleft().result()
            while pending:
                yield pending.popleft().result()

    def with_provenance():
        single = False
        for k, table in enumerate(tables()):
            single = single or bool(pc.any(table.column("unique")).as_py())
            if k == 0:
                meta = read_metadata(table, source)
                meta.update(extra_metadata or {})
                first_meta.update(meta)
                table = with_metadata(table, meta)
            yield table
            if progress is not None:
                progress(chunks[k].stop - chunks[k].start)
        if not single:  # raised before the rename: nothing is written
            raise no_single_support(robot, source)

    write_tables(output, with_provenance())
    return ChunkedResult(n, len(chunks), sum(1 for c in chunks if c.start - c.read_start > CONTEXT), first_meta)

"""Long logs in bounded memory: the estimate in chunks, on several cores, streamed to disk.

A log of an hour at 1 kHz (3.6 million rows for TALOS: about 2 GB of joint signals) is
never held whole. Its rows are cut into chunks; each chunk is read with a few rows of
context on either side, validated (:func:`~wbfriction.logs.log.log_from_table`, rows numbered
as in the file), estimated (:func:`~wbfriction.friction.estimate.estimate_log`), and its own rows
are appended to the output, which is renamed into place once complete.

**Cuts at contact changes make chunk borders change nothing.** Every stage stops at a
change of the contact flags anyway: no differentiation stencil or filter window spans
one (:func:`~wbfriction.signals.kinematics.straddling`), and the support phases and their
lift-off / touch-down margins (:func:`~wbfriction.signals.phases.segment`) are bounded by them.
So a chunk cut at a contact change, read with :data:`CONTEXT` rows of context (the
previous phase's last rows, the next phase's first), gives exactly the rows of the
whole-log estimate. A stretch with no contact change for twice the chunk length is cut
where it must, with ``overlap`` rows of context: exact for the finite-window schemes when
``overlap`` exceeds the window, within the Butterworth filter's decay otherwise.

**One clock for the whole log.** The stamps are read once, whole (:func:`plan_columns`), and
their clock decided once (:func:`~wbfriction.logs.clock.read_clock`, on the positions of the
first :data:`~wbfriction.logs.clock.ROUGHNESS_ROWS` rows): its sampling period, gaps, and
regularised times are the whole log's, and each chunk is given its rows of it
(:meth:`Clock.rows <wbfriction.logs.clock.Clock.rows>`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.clock import ROUGHNESS_ROWS, Clock, read_clock, table_stamps
from wbfriction.logs.foot_forces import read_foot_forces
from wbfriction.logs.log import check_schema, contact_flags_from_forces
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.tables import RowReader, TableFile, numeric_column, numeric_columns
from wbfriction.logs.temperature import screen_temperature
from wbfriction.model.robot import Robot

CONTEXT = 3
"""Rows of context either side of a cut at a contact change (central and backward
differences, the torque alignment and the phase margins need at most two)."""


CHUNKS_PER_WORKER = 4
"""Chunks per worker process below which a log is estimated in the command's own process: a
worker starts in about a second (an interpreter, its imports, the robot), as long as it takes to
estimate two chunks of the default length."""


@dataclass(frozen=True)
class Chunking:
    """How a long log is cut.

    Attributes:
        rows: target rows per chunk (the cut is at the first contact change after it).
        overlap: rows of context at a forced cut (no contact change within ``2 rows``); never
            reaching before the previous chunk's first row read (the log is read forwards,
            once): chunks shorter than the overlap get less context.
        workers: processes estimating chunks (1: in this process); used only for a log of at
            least :data:`CHUNKS_PER_WORKER` chunks per process (:meth:`processes`).

    Raises:
        InputError: ``rows`` or ``workers`` below 1 (named ``--chunk-rows``, ``--workers``), a
            negative ``overlap``.
    """

    rows: int = 10_000
    overlap: int = 2_000
    workers: int = 2

    def __post_init__(self) -> None:
        if self.rows < 1:
            raise InputError(f"--chunk-rows must be at least 1, got {self.rows}")
        if self.overlap < 0:
            raise InputError(f"the overlap of chunks must be at least 0 rows, got {self.overlap}")
        if self.workers < 1:
            raise InputError(f"--workers must be at least 1, got {self.workers}")

    def processes(self, chunks: int) -> int:
        """The processes that pay for a log of ``chunks`` chunks: :attr:`workers`, or 1 (this
        process) when fewer than :data:`CHUNKS_PER_WORKER` chunks would fall to each."""
        return self.workers if chunks >= CHUNKS_PER_WORKER * self.workers else 1


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
    chunks: list[Chunk] = []
    for i, (a, b) in enumerate(zip(cuts[:-1], cuts[1:])):
        start = max(0, a - context[i], chunks[-1].read_start if chunks else 0)  # read forwards
        chunks.append(Chunk(a, b, start, min(n, b + context[i + 1])))
    return chunks


@dataclass(frozen=True, eq=False)
class ColumnPlan:
    """What is read of a log file before it is cut into chunks (:func:`plan_columns`).

    Attributes:
        contact: contact flags (N, n_contacts) (a fixed base: always welded).
        clock: the whole log's clock (:func:`~wbfriction.logs.clock.read_clock`).
        first_positions: the positions of its first rows (:func:`first_positions`), or None.
        warnings: what its schema costs in accuracy (:func:`~wbfriction.logs.log.check_schema`).
        contact_from_forces: the flags come from the measured forces, not from ``contact.*`` columns
            (:mod:`wbfriction.logs.contacts`): the chunks are given them as columns
            (:func:`with_contact_columns`), so that the hysteresis runs once, over the whole log.
    """

    contact: np.ndarray
    clock: Clock
    first_positions: np.ndarray | None
    warnings: tuple[str, ...] = ()
    contact_from_forces: bool = False


def chunk_rows(reader: RowReader, robot: Robot, plan: ColumnPlan, chunk: Chunk) -> pa.Table:
    """The rows a chunk reads, with the whole log's contact flags as ``contact.<frame>`` columns when
    they come from the measured forces (:attr:`ColumnPlan.contact_from_forces`)."""
    table = reader.rows(chunk.read_start, chunk.read_stop)
    if plan.contact_from_forces:
        for i, f in enumerate(robot.contact_frames):
            flags = plan.contact[chunk.read_start:chunk.read_stop, i].astype(np.int8)
            table = table.append_column(f"contact.{f}", pa.array(flags))
    return table


def plan_columns(file: TableFile, robot: Robot, source: str, read: ReadOptions = ReadOptions()) -> ColumnPlan:
    """Check a log file's schema against ``robot`` (:func:`~wbfriction.logs.log.check_schema`:
    names and types, before any row is estimated), then read its contact columns alone to plan
    its chunks, the whole log's clock (:func:`~wbfriction.logs.clock.read_clock`: its stamps, in
    ``read.time_unit``, its gaps of ``read.max_gap``, its ``read.time_base``, and the positions of its first
    :data:`~wbfriction.logs.clock.ROUGHNESS_ROWS` rows when they are finite), and those positions
    (:func:`first_positions`, None when not finite).

    Raises:
        InputError: an unreadable file, what :func:`~wbfriction.logs.log.check_schema` refuses,
            a time column that :func:`~wbfriction.logs.clock.table_stamps` or
            :func:`~wbfriction.logs.clock.read_clock` refuses (rows numbered from the file's
            first), contact flags that are not numbers.
    """
    schema = file.schema()
    warnings = check_schema(schema, robot, source)
    from_forces = robot.floating_base and not any(f"contact.{f}" in schema.names for f in robot.contact_frames)
    feet = from_forces and not robot.ft_sensors  # the feet's forces (wbfriction.logs.foot_forces)
    if feet:
        columns = ["time"] + [c for c in schema.names if c.startswith("force.")]
    elif from_forces:  # no contact column: the flags from the measured forces (check_schema made sure)
        columns = ["time"] + [c for s in robot.ft_sensors for c in s.columns()]
    else:
        columns = ["time"] + ([f"contact.{f}" for f in robot.contact_frames] if robot.floating_base else [])
    table = file.read(columns)
    if feet:
        flags = contact_flags_from_forces(robot, None, read_foot_forces(table, robot, source))
    elif from_forces:
        wrench = numeric_columns(table, columns[1:], source)
        flags = contact_flags_from_forces(robot, wrench.reshape(len(wrench), -1, 6))
    else:
        flags = (numeric_columns(table, columns[1:], source)
                 if robot.floating_base else np.ones((table.num_rows, 1)))  # a fixed base: always welded
    warnings = warnings + _temperature_warnings(file, robot, source)
    first = first_positions(file, robot)
    clock = read_clock(table_stamps(table, source, unit=read.time_unit), source, max_gap=read.max_gap, q=first,
                       time_base=read.time_base)
    return ColumnPlan(flags != 0, clock, first, warnings, from_forces)


def _temperature_warnings(file: TableFile, robot: Robot, source: str) -> tuple[str, ...]:
    """The whole log's temperature columns screened (:func:`~wbfriction.logs.temperature.screen_temperature`), before
    any row is estimated: a column in kelvin or not a temperature refused, a glitch named once (each chunk leaves it
    out again as it reads its rows)."""
    names = [f"temperature.{n}" for n in robot.torque_controlled if f"temperature.{n}" in file.schema().names]
    if not names:
        return ()
    table = file.read(names)
    T = np.column_stack([numeric_column(table, c, source, finite=False) for c in names])
    return screen_temperature(T, [c.partition(".")[2] for c in names], source)[1]


def release_freed_memory() -> None:
    """Give back to the system what this process has freed but its allocators keep: Arrow's pool and the C
    heap (glibc's ``malloc_trim``; nothing where there is none). Planning an hour-long log reads its whole time
    and contact columns: about 250 MB that the reading process would otherwise hold while its workers run; each
    chunk it reads, sends and writes leaves more."""
    import ctypes

    pa.default_memory_pool().release_unused()
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):  # not glibc
        pass


def first_positions(file: TableFile, robot: Robot) -> np.ndarray | None:
    """The positions of the first :data:`~wbfriction.logs.clock.ROUGHNESS_ROWS` rows (M, n_act), from
    which the clock and the differentiation are decided, continuous joints unwrapped
    (:meth:`~wbfriction.model.layout.JointLayout.unwrap`: a wrap is no motion, and no noise), or None when a column is
    missing or not finite (the chunk that holds it says so)."""
    table = file.row_reader(ROUGHNESS_ROWS).rows(0, ROUGHNESS_ROWS)
    names = [f"q.{n}" for n in robot.actuated]
    if any(n not in table.column_names for n in names):
        return None
    try:
        q = np.column_stack([table.column(n).to_numpy(zero_copy_only=False).astype(float) for n in names])
    except (ValueError, TypeError):
        return None
    return robot.layout.unwrap(q) if np.all(np.isfinite(q)) else None

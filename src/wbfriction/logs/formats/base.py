"""What a log format is: how its files are recognised, read (whole, by columns, by row ranges) and written.

A format is one :class:`LogFormat`, registered once (:func:`~wbfriction.logs.formats.registry.register_format`);
the package reads and writes every file through the format the registry finds for its path
(:func:`~wbfriction.logs.formats.registry.format_of`), and looks at no suffix itself. A new format names itself
(:attr:`LogFormat.name`, :attr:`LogFormat.label`), says which paths are its own (:attr:`LogFormat.suffixes`, or
:meth:`LogFormat.detect`) and reads a file whole (:meth:`LogFormat.read`); what else it does not define has a
default built on that: its schema, and its row ranges (the file read whole once, then sliced: a long log is then
held whole while it is estimated in chunks). :meth:`LogFormat.write` makes it writable (:attr:`LogFormat.writable`),
:meth:`LogFormat.open_writer` streamable (:attr:`LogFormat.streamable`: tables appended one after the other).

Every format keeps a table's ``wbfriction`` metadata (:mod:`wbfriction.logs.metadata`): :meth:`LogFormat.read`
returns it in the table's schema, :meth:`LogFormat.write` stores it.

A log may be read through a map (``--map``): a table file through its map TOML (:mod:`wbfriction.logs.table_map`,
the default of :meth:`LogFormat.open_map`); a format whose files are not tables at all (a ROS 2 bag,
:attr:`LogFormat.needs_map`) only through one, by its own :meth:`LogFormat.read_log` and :meth:`LogFormat.log_blocks`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any, ClassVar, Protocol

import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.formats.catalog import FormatKind
from wbfriction.logs.metadata import read_metadata
from wbfriction.logs.table_map import TableMap, load_table_map
from wbfriction.model.robot import Robot


class RowReader(Protocol):
    """Row ranges of one file, read forwards: each call's ``start`` at or after the previous call's.

    Attributes:
        metadata: the file's schema metadata (the ``wbfriction`` key, :mod:`wbfriction.logs.metadata`), or None.
    """

    metadata: dict[bytes, bytes] | None

    def rows(self, start: int, stop: int) -> pa.Table:
        """Rows ``[start, stop)`` (fewer past the end, none beyond it), with the file's metadata."""
        ...


class TableWriter(Protocol):
    """A file being written table after table (:meth:`LogFormat.open_writer`), complete once closed."""

    def write_table(self, table: pa.Table) -> None:
        """Append ``table``'s rows (its columns those of the schema the writer was opened with)."""
        ...

    def close(self) -> None:
        """Finish the file."""
        ...


def unreadable(path: Path, exc: BaseException, row: int | None = None) -> InputError:
    """The error for a file that cannot be read: its name, the row where it failed (if known) and the first line
    of the library's reason."""
    at = "" if row is None else f" at row {row}"
    return InputError(f"{path}: cannot be read{at}: {(str(exc).splitlines() or [repr(exc)])[0]}")


class SlicedRows:
    """The row ranges of a table read whole once (a format that reads no part of a file alone)."""

    def __init__(self, table: pa.Table):
        self.table = table
        self.metadata: dict[bytes, bytes] | None = table.schema.metadata

    def rows(self, start: int, stop: int) -> pa.Table:
        """Rows ``[start, stop)`` of the table (a view), with its metadata."""
        start = min(start, self.table.num_rows)
        return self.table.slice(start, max(0, stop - start))


class BatchRows:
    """Row ranges of a file read forwards in record batches with a rolling buffer: the memory it holds is one range
    and what was read ahead of it.

    Args:
        path: the file (named in the errors).
        metadata: the file's schema metadata, given to every range.
        batches: the file's record batches, in order.
    """

    def __init__(self, path: Path, metadata: dict[bytes, bytes] | None, batches: Iterator[pa.RecordBatch]):
        self.path = path
        self.metadata = metadata
        self._batches = batches
        self._buffer: list[pa.RecordBatch] = []
        self._start = 0  # file row of the buffer's first row
        self._stop = 0

    def rows(self, start: int, stop: int) -> pa.Table:
        """Rows ``[start, stop)`` (``start`` never below an earlier call's), with the file's metadata.

        Raises:
            InputError: a batch that cannot be read, naming the file and the row it starts at.
        """
        while self._stop < stop:
            try:
                batch = next(self._batches)
            except StopIteration:
                break
            except (pa.ArrowException, OSError, ValueError) as exc:
                raise unreadable(self.path, exc, self._stop) from exc
            self._buffer.append(batch)
            self._stop += batch.num_rows
        while self._buffer and self._start + self._buffer[0].num_rows <= start:  # drop what is behind
            self._start += self._buffer.pop(0).num_rows
        if not self._buffer:  # past the end (a table without columns would slice to any length)
            return pa.table({})
        table = pa.Table.from_batches(self._buffer).slice(start - self._start, stop - start)
        return table.replace_schema_metadata(self.metadata) if self.metadata else table


class LogFormat(ABC):
    """A kind of log file (module docstring).

    Attributes:
        name: the format's one-word name (``parquet``), unique among the registered ones.
        label: how messages name it (``Parquet``).
        suffixes: the file name endings that are its own, lower case with the dot (``.parquet``, ``.pq``).
        writable: :meth:`write` writes a whole table.
        streamable: :meth:`open_writer` writes tables one after the other (a friction table, a converted bag).
        text: :meth:`write` keeps a table's text columns (a table of joints' names and statuses), read back as text.
        needs_map: its files are read only through a map (a ROS 2 bag's topics): :meth:`read_log` and
            :meth:`log_blocks` are its own, and it is not a table file (:meth:`read` refuses).
        detail: what else the command line's help says of its files (a ROS 2 bag: ``or a folder with
            metadata.yaml``), or "".

    A built-in format's class takes these from its kind in :mod:`~wbfriction.logs.formats.catalog` (which the help
    reads without importing the format): ``class ParquetFormat(LogFormat, kind=PARQUET)``.
    """

    name: ClassVar[str]
    label: ClassVar[str]
    suffixes: ClassVar[tuple[str, ...]] = ()
    writable: ClassVar[bool] = False
    streamable: ClassVar[bool] = False
    text: ClassVar[bool] = False
    needs_map: ClassVar[bool] = False
    detail: ClassVar[str] = ""

    def __init_subclass__(cls, kind: FormatKind | None = None, **kwargs: Any) -> None:
        """A subclass; with ``kind``, its name, label, suffixes and abilities are the kind's."""
        super().__init_subclass__(**kwargs)
        if kind is not None:
            cls.name, cls.label, cls.suffixes, cls.detail = kind.name, kind.label, kind.suffixes, kind.detail
            cls.writable, cls.streamable, cls.needs_map = kind.writable, kind.streamable, kind.needs_map
            cls.text = kind.text

    def __repr__(self) -> str:
        return f"<log format {self.name}>"

    def __str__(self) -> str:
        """The format's name (``parquet``), as messages and records print it."""
        return self.name

    # ------------------------------------------------------------ recognising
    def claims(self, path: Path) -> bool:
        """Whether ``path``'s name is one of this format's (its suffix, any case): a file to read or to write."""
        return path.suffix.lower() in self.suffixes

    def detect(self, path: Path) -> bool:
        """Whether the existing ``path`` is a file of this format: a file whose name it claims (:meth:`claims`)."""
        return path.is_file() and self.claims(path)

    def describe(self) -> str:
        """The format as an error message lists it: its label and suffixes (``Parquet .parquet .pq``)."""
        return " ".join((self.label, *self.suffixes))

    # ---------------------------------------------------------------- reading
    @abstractmethod
    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        """The whole table in ``path``, or only those of ``columns`` that it has (others skipped), its metadata in
        its schema.

        Args:
            columns: the columns to read (None: all).
            text_columns: columns whose cells are read as text, as written (no type inference: an id ``007``
                stays ``"007"``), for a format whose cells carry no type (CSV); others ignore it.

        Raises:
            InputError: unreadable content, naming the file.
        """

    def schema(self, path: Path) -> pa.Schema:
        """The table's columns, their types and its metadata (default: the file read whole).

        Raises:
            InputError: unreadable content, naming the file.
        """
        return self.read(path).schema

    def metadata(self, path: Path) -> dict:
        """The table's ``wbfriction`` metadata ({} if none; :func:`~wbfriction.logs.metadata.read_metadata`).

        Raises:
            InputError: unreadable content or metadata, naming the file.
        """
        return read_metadata(self.schema(path).empty_table(), str(path))

    def row_count(self, path: Path) -> int:
        """The table's rows when known without reading them (a Parquet footer), else 0."""
        return 0

    def row_reader(self, path: Path, batch_rows: int) -> RowReader:
        """A reader of row ranges, forwards (default: the file read whole once, :class:`SlicedRows`).

        Args:
            batch_rows: the rows a format reading by batches reads at a time.

        Raises:
            InputError: an unreadable file (here, or at the range where it fails).
        """
        return SlicedRows(self.read(path))

    def blocks(self, path: Path, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The table as consecutive tables of ``block_rows`` rows, each with the file's metadata.

        Raises:
            InputError: an unreadable file, naming it (and the row where it can).
        """
        reader = self.row_reader(path, block_rows)
        start = 0
        while True:
            table = reader.rows(start, start + block_rows)
            if table.num_rows == 0:
                return
            yield table
            start += table.num_rows

    # ---------------------------------------------------------------- writing
    def write(self, table: pa.Table, path: Path) -> None:
        """Write ``table`` whole, its metadata with it, into ``path`` (not atomic by itself: the callers write a
        temporary file, :func:`~wbfriction.logs.tables.write_table`).

        Raises:
            InputError: a format that writes no file (:attr:`writable` False).
            OSError: the system refused the write.
        """
        raise InputError(f"{path}: {self.label} files are read, not written")

    def open_writer(self, path: Path, schema: pa.Schema) -> TableWriter:
        """A writer of tables of ``schema`` (its metadata with them) appended one after the other into ``path``.

        Raises:
            InputError: a format that cannot stream (:attr:`streamable` False).
            OSError: the system refused the write.
        """
        raise InputError(f"{path}: {self.label} files are not written table after table")

    # ------------------------------------------------------------------- maps
    def open_map(self, path: Path, given: object, robot: Robot | None = None) -> object | None:
        """The map a log in ``path`` is read through (None: ``given`` None, the file's own columns): a table file's
        map TOML (:mod:`wbfriction.logs.table_map`), checked against the file's columns and, if given, ``robot``.

        Raises:
            InputError: a map that is not a TOML file (a bag's topic map), an unreadable map, a map entry naming a
                column the table does not have or a joint or frame ``robot`` does not (naming the map and the key).
        """
        if given is None:
            return None
        if not isinstance(given, str | Path):
            raise InputError(f"{path}: a table log is read through a map TOML file, not a bag's topic map")
        table_map = load_table_map(given)
        if robot is not None:
            table_map.check(robot)
        table_map.check_columns(list(self.schema(path).names), path)
        return table_map

    def read_log(self, path: Path, mapping: object | None = None) -> pa.Table:
        """The whole log as one table in the log format (:mod:`wbfriction.logs.log`), not validated: the file's
        table, through ``mapping`` (:meth:`open_map`) if given.

        Raises:
            InputError: an unreadable file, a mapped column that is not what the map says.
        """
        table = self.read(path)
        return table if mapping is None else _table_map(mapping).apply(table, path)

    def log_blocks(self, path: Path, mapping: object | None = None, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The log as consecutive tables of about ``block_rows`` rows, never read whole (:meth:`blocks`), through
        ``mapping`` if given, each block told the file row it starts at.

        Raises:
            InputError: an unreadable file, naming it (and the row where it can).
        """
        if mapping is None:
            yield from self.blocks(path, block_rows)
            return
        table_map, first_row = _table_map(mapping), 0
        for block in self.blocks(path, block_rows):
            yield table_map.apply(block, path, first_row)
            first_row += block.num_rows


def _table_map(mapping: object) -> TableMap:
    """``mapping`` as a table file's map (what :meth:`LogFormat.open_map` gives a table format)."""
    if not isinstance(mapping, TableMap):
        raise InputError(f"a table log is read through a map TOML file, not {type(mapping).__name__}")
    return mapping

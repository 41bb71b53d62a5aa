"""Table files: Parquet, CSV and HDF5 read and written whole or in row ranges, their metadata, atomic writes.

A table file's format is decided once, from its suffix (:class:`TableFile`): ``.parquet``/``.pq``
(Apache Parquet), ``.csv``, ``.h5``/``.hdf5``/``.he5`` (:mod:`wbfriction.logs.hdf5`). Every table
carries its JSON metadata under the schema key ``wbfriction`` (:func:`with_metadata`,
:func:`read_metadata`). Every output is written whole or not at all (:func:`write_atomic`), and an
output the system refuses to write (a full disk, ``ulimit -f``, a read-only folder, a path under a
file) is one :class:`~wbfriction.exceptions.OutputError` naming it (:func:`output_error`).
"""

from __future__ import annotations

import errno as errnos
import hashlib
import json
import os
import re
import secrets
import shutil
import socket
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Literal

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from wbfriction.exceptions import ColumnError, InputError, OutputError
from wbfriction.logs.hdf5 import SUFFIXES as HDF5_SUFFIXES
from wbfriction.logs.hdf5 import read_hdf5, write_hdf5

META_KEY = b"wbfriction"
TableFormat = Literal["parquet", "csv", "hdf5"]
"""The formats of a table file."""


# ------------------------------------------------------------------ metadata
CSV_METADATA = b"#wbfriction "
"""A CSV file's first line when it carries the ``wbfriction`` metadata (a CSV has no other place for
it: without it, a log's torque alignment, a table's smoother and provenance would be lost)."""


def _csv_metadata(path: Path) -> tuple[int, dict[bytes, bytes] | None]:
    """Rows to skip at the top of a CSV file and the metadata its first line carries (0, None: none)."""
    try:
        with open(path, "rb") as handle:
            first = handle.readline()
    except OSError as exc:
        raise _unreadable(path, exc) from exc
    if first.startswith(CSV_METADATA):
        return 1, {META_KEY: first[len(CSV_METADATA):].strip()}
    return 0, None


def _csv_options(path: Path, **kwargs) -> tuple[pacsv.ReadOptions, dict[bytes, bytes] | None]:
    skip, meta = _csv_metadata(path)
    return pacsv.ReadOptions(skip_rows=skip, **kwargs), meta


def _write_csv_header(handle, schema: pa.Schema) -> None:
    """The metadata line of a CSV file (:data:`CSV_METADATA`), if the table has metadata."""
    meta = (schema.metadata or {}).get(META_KEY)
    if meta is not None:
        handle.write(CSV_METADATA + meta.replace(b"\n", b" ") + b"\n")


def with_metadata(table: pa.Table, metadata: dict) -> pa.Table:
    """Attach ``metadata`` (JSON-serialisable) to ``table`` under the ``wbfriction`` key."""
    return table.replace_schema_metadata({META_KEY: json.dumps(metadata, sort_keys=True).encode()})


def read_metadata(table: pa.Table, source: str = "<table>") -> dict:
    """The ``wbfriction`` metadata of a table ({} if none)."""
    meta = table.schema.metadata or {}
    if META_KEY not in meta:
        return {}
    try:
        doc = json.loads(meta[META_KEY])
    except ValueError:
        raise InputError(f"{source}: the 'wbfriction' metadata is not JSON") from None
    if not isinstance(doc, dict):
        raise InputError(f"{source}: the 'wbfriction' metadata is not a JSON object")
    return doc


# ------------------------------------------------------------------- reading
TABLE_SUFFIXES = (".parquet", ".pq", ".csv", *HDF5_SUFFIXES)
_FORMATS: dict[str, TableFormat] = {".parquet": "parquet", ".pq": "parquet", ".csv": "csv",
                                     **{s: "hdf5" for s in HDF5_SUFFIXES}}


def table_format(path: str | Path) -> TableFormat:
    """The format of an existing table file, from its suffix.

    Raises:
        InputError: a missing file, or a type that is not Parquet, CSV or HDF5.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a table file (a ROS 2 bag folder needs --map)")
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    suffix = path.suffix.lower()
    if suffix not in _FORMATS:
        raise InputError(f"{path}: unknown file type '{suffix}' (expected .parquet, .csv or .h5)")
    return _FORMATS[suffix]


def _unreadable(path: Path, exc: BaseException, row: int | None = None) -> InputError:
    at = "" if row is None else f" at row {row}"
    return InputError(f"{path}: cannot be read{at}: {(str(exc).splitlines() or [repr(exc)])[0]}")


class TableFile:
    """A Parquet, CSV or HDF5 table file (format decided once, :func:`table_format`).

    Attributes:
        path: the file.
        format: ``parquet``, ``csv`` or ``hdf5``.

    Raises:
        InputError: a missing file or an unknown type (at construction).
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.format: TableFormat = table_format(self.path)

    def read(self, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        """The whole table, or only those of ``columns`` that it has (others are skipped).

        Args:
            columns: the columns to read (None: all).
            text_columns: columns a CSV file's cells are read from as text, as written (no type inference:
                an id ``007`` stays ``"007"``, not ``7``); ignored for Parquet and HDF5, whose columns carry
                their types.

        Raises:
            InputError: unreadable content, naming the file.
        """
        path = self.path
        if self.format == "hdf5":
            return read_hdf5(path, columns=columns)
        try:
            if self.format == "parquet":
                if columns is None:
                    table = pq.read_table(path)
                else:
                    names = pq.ParquetFile(path).schema_arrow.names
                    table = pq.read_table(path, columns=[c for c in columns if c in names])
            else:
                options, meta = _csv_options(path)
                types = {c: pa.string() for c in text_columns}
                if columns is None:
                    table = pacsv.read_csv(path, read_options=options,
                                           convert_options=pacsv.ConvertOptions(column_types=types))
                else:
                    names = pacsv.open_csv(path, read_options=options).schema.names
                    table = pacsv.read_csv(path, read_options=options, convert_options=pacsv.ConvertOptions(
                        include_columns=[c for c in columns if c in names], column_types=types))
                if meta is not None:
                    table = table.replace_schema_metadata(meta)
            _ = table.column_names  # decoded lazily: a damaged header fails here
            return table
        except (pa.ArrowException, OSError, ValueError) as exc:  # ValueError: e.g. damaged UTF-8 in the footer
            raise _unreadable(path, exc) from exc

    def schema(self) -> pa.Schema:
        """The table's columns and their types, and its metadata, without reading its rows (a CSV's
        types as inferred from its first block).

        Raises:
            InputError: unreadable content, naming the file.
        """
        if self.format == "hdf5":
            return read_hdf5(self.path, stop=0).schema
        try:
            if self.format == "parquet":
                return pq.ParquetFile(self.path).schema_arrow
            options, meta = _csv_options(self.path)
            schema = pacsv.open_csv(self.path, read_options=options).schema
            return schema.with_metadata(meta) if meta is not None else schema
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise _unreadable(self.path, exc) from exc

    def row_count(self) -> int:
        """Rows of a Parquet file, from its footer; 0 when not known without reading the file."""
        if self.format != "parquet":
            return 0
        try:
            return pq.ParquetFile(self.path).metadata.num_rows
        except (pa.ArrowException, OSError, ValueError):  # an unreadable file is reported when it is read
            return 0

    def row_reader(self, batch_rows: int) -> RowReader:
        """A reader of row ranges, forwards, in bounded memory (:class:`RowReader`)."""
        return RowReader(self, batch_rows)

    def blocks(self, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The table as consecutive tables of ``block_rows`` rows (with the file's metadata),
        never read whole.

        Raises:
            InputError: an unreadable file, naming it and the row.
        """
        reader = self.row_reader(block_rows)
        start = 0
        while True:
            table = reader.rows(start, start + block_rows)
            if table.num_rows == 0:
                return
            yield table
            start += table.num_rows


class RowReader:
    """Row ranges of a Parquet or CSV file, read forwards with a rolling buffer (the memory it
    holds is one range and what was read ahead of it); of an HDF5 file, read by slicing its
    datasets.

    Raises:
        InputError: an unreadable file (at construction or at the row where it fails).
    """

    def __init__(self, file: TableFile, batch_rows: int):
        self.path = file.path
        self._hdf5 = file.format == "hdf5"
        self.metadata: dict[bytes, bytes] | None
        if self._hdf5:
            self.metadata = read_hdf5(self.path, columns=[], stop=0).schema.metadata
            return
        try:
            if file.format == "parquet":
                # without pre-buffering: pyarrow would otherwise keep whole column chunks read ahead
                parquet = pq.ParquetFile(self.path, pre_buffer=False)
                self.metadata = parquet.schema_arrow.metadata
                self._batches: Iterator[pa.RecordBatch] = parquet.iter_batches(batch_size=batch_rows,
                                                                               use_threads=False)
            else:
                options, self.metadata = _csv_options(self.path, block_size=1 << 24)
                self._batches = iter(pacsv.open_csv(self.path, read_options=options))
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise _unreadable(self.path, exc) from exc
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
                raise _unreadable(self.path, exc, self._stop) from exc
            self._buffer.append(batch)
            self._stop += batch.num_rows
        while self._buffer and self._start + self._buffer[0].num_rows <= start:  # drop what is behind
            self._start += self._buffer.pop(0).num_rows
        if not self._buffer:  # past the end (a table without columns would slice to any length)
            return pa.table({})
        table = pa.Table.from_batches(self._buffer).slice(start - self._start, stop - start)
        return table.replace_schema_metadata(self.metadata) if self.metadata else table


def read_table(path: str | Path) -> pa.Table:
    """Read a Parquet, CSV or HDF5 file into an Arrow table (:meth:`TableFile.read`).

    Raises:
        InputError: missing file, unknown extension, or unreadable content.
    """
    return TableFile(path).read()


def numeric_columns(table: pa.Table, names: Sequence[str], source: str, first_row: int = 0,
                    finite: bool = True) -> np.ndarray:
    """Columns ``names`` side by side as float64 (N, len(names)), row-major: numeric columns (integers, floats,
    booleans) cast and copied once by Arrow (``RecordBatch.to_tensor``, nulls as NaN) and checked as one array;
    others column by column (:func:`numeric_column`, which says which is not numeric). The same values and
    errors as :func:`numeric_column` for each column in turn.

    Raises:
        InputError: as :func:`numeric_column`, for the first column (in ``names``' order) at fault.
    """
    def is_number(t: pa.DataType) -> bool:
        return pa.types.is_integer(t) or pa.types.is_floating(t) or pa.types.is_boolean(t)

    if not names:
        return np.empty((table.num_rows, 0))
    if not all(n in table.column_names and is_number(table.schema.field(n).type) for n in names):
        return np.column_stack([numeric_column(table, n, source, first_row, finite) for n in names])
    if not table.num_rows:
        return np.empty((0, len(names)))
    columns = [table.column(n).combine_chunks().cast(pa.float64(), safe=False) for n in names]  # numpy's astype
    batch = pa.RecordBatch.from_arrays(columns, names=list(names))
    values = np.asarray(batch.to_tensor(null_to_nan=True, row_major=True))  # row-major, as np.column_stack
    if finite:
        bad = ~np.isfinite(values)
        if bad.any():
            col = int(np.argmax(bad.any(axis=0)))
            numeric_column(table, names[col], source, first_row)  # raises, naming the column and the row
    return values


def numeric_column(table: pa.Table, name: str, source: str, first_row: int = 0, finite: bool = True) -> np.ndarray:
    """Column ``name`` as float64 (N,).

    Raises:
        InputError: a column that is not numeric, or (``finite``) holds NaN or inf, naming
            ``source``, the column and the first bad row (counted from ``first_row``).
    """
    try:
        col = table.column(name)
        values = col.to_numpy(zero_copy_only=False).astype(float)
    except (pa.ArrowException, ValueError, TypeError) as exc:
        raise ColumnError(source, name, None, f"column '{name}' is not numeric") from exc
    bad: np.ndarray | Sequence[int] = np.flatnonzero(~np.isfinite(values)) if finite else ()
    if len(bad):
        raise ColumnError(source, name, int(first_row + bad[0]),
                          f"column '{name}' has a non-finite value (NaN or inf) at row {first_row + bad[0]}")
    return values


# ------------------------------------------------------------------- writing
def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex), for provenance records; of a folder (a ROS 2 bag),
    over its files' relative names and bytes in name order."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file not found")
    digest = hashlib.sha256()
    files = [path] if not path.is_dir() else sorted(p for p in path.rglob("*") if p.is_file())
    for f in files:
        if f != path:
            digest.update(str(f.relative_to(path)).encode() + b"\0")
        with open(f, "rb") as handle:  # in blocks: a log of an hour is gigabytes
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()


# ----------------------------------------------------------- temporary files
_TEMPORARY = re.compile(r"\.(?:.+\.)?wbfriction-(?P<host>[A-Za-z0-9]*)-(?P<pid>\d+)-[0-9a-f]{8}(?:\.tmp.*)?", re.S)
"""The names of this tool's temporary files (``.{name}.wbfriction-{host}-{pid}-{token}.tmp{suffix}``)
and folders (``.wbfriction-{host}-{pid}-{token}``)."""


def _host() -> str:
    """This machine's name, letters and digits only (a folder may be shared between machines)."""
    return re.sub(r"[^A-Za-z0-9]", "", socket.gethostname())[:32]


def _temporary_name(folder: Path, stem: str = "", suffix: str = "") -> Path:
    """A fresh name in ``folder`` marked with this machine and process (:data:`_TEMPORARY`)."""
    return folder / f".{stem}wbfriction-{_host()}-{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def _alive(pid: int) -> bool:
    """Whether process ``pid`` of this machine exists (True when it cannot be told)."""
    if pid <= 0 or pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):  # PermissionError: another user's, alive
        return True
    return True


def remove_stale_temporaries(folder: str | Path) -> list[Path]:
    """Remove the temporary files and folders that this tool left in ``folder`` (not below) when
    a process writing them was killed (SIGKILL, power loss): those whose name carries this
    machine's name and the id of a process that no longer exists. Another machine's, or a live
    process's, are never touched (a process id used again keeps a stale file: the safe side).
    Returns the paths removed; a path that cannot be removed is left as it is.
    """
    folder = Path(folder)
    host = _host()
    try:
        names = [e.name for e in os.scandir(folder)]
    except OSError:
        return []
    removed = []
    for name in names:
        m = _TEMPORARY.fullmatch(name)
        if m is None or m["host"] != host or _alive(int(m["pid"])):
            continue
        path = folder / name
        try:
            if path.is_dir() and not path.is_symlink():
                shutil.rmtree(path)
            else:
                path.unlink()
        except OSError:
            continue
        removed.append(path)
    return removed


@contextmanager
def scratch_folder(near: str | Path | None = None) -> Iterator[Path]:
    """A new temporary folder ``.wbfriction-{host}-{pid}-{token}`` in folder ``near`` (the system's
    temporary folder if None), removed with its content on leaving, whatever the way out; those
    of killed processes are removed on entering (:func:`remove_stale_temporaries`).

    Raises:
        InputError: a folder ``near`` that does not exist.
        OutputError: a folder ``near`` in which no folder can be made (read-only, full), naming it.
    """
    folder = Path(tempfile.gettempdir() if near is None else near)
    if not folder.is_dir():
        raise InputError(f"{folder}: folder does not exist")
    remove_stale_temporaries(folder)
    path = _temporary_name(folder)
    try:
        path.mkdir()
    except OSError as exc:
        raise output_error(folder, exc) from exc
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)


def output_error(path: str | Path, exc: OSError, kept: bool = False) -> OutputError:
    """The :class:`~wbfriction.exceptions.OutputError` for an OSError raised while writing ``path``:
    its reason as the OS words it from the error's number (``[Errno 28] No space left on device``,
    whatever library raised it and whichever temporary file it names), else the error's first line.

    Args:
        path: the output the user named.
        exc: what the write raised.
        kept: a previous file at ``path`` is kept.
    """
    number = exc.errno if isinstance(exc.errno, int) else None
    if number is not None and number in errnos.errorcode:
        reason = f"[Errno {number}] {os.strerror(number)}"
    else:
        reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
    return OutputError(str(path), number, reason, kept)


def _names_other_file(exc: OSError, own: tuple[Path, ...]) -> bool:
    """``exc`` names a file other than ``own`` (the output, its temporary file, its folder): an
    input that could not be read while the output was written, not a fault of the output."""
    mine = {os.path.abspath(p) for p in own}
    for name in (exc.filename, exc.filename2):
        if name is None or isinstance(name, int):  # no name, or a file descriptor: the write's
            continue
        try:
            if os.path.abspath(os.fsdecode(name)) not in mine:
                return True
        except (TypeError, ValueError):
            return True
    return False


def _discard(path: Path) -> None:
    """Remove a temporary file if it is there (nothing if it cannot be: e.g. a path under a file)."""
    try:
        path.unlink(missing_ok=True)
    except OSError:
        pass


def make_folder(path: str | Path) -> Path:
    """Make an output folder and its parents (nothing if it exists).

    Raises:
        OutputError: a folder that cannot be made (under a file, read-only, full), naming it and the OS's reason.
    """
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise output_error(path, exc, kept=path.is_dir()) from exc
    return path


def remove_file(path: str | Path) -> None:
    """Remove an output file (nothing if there is none): an earlier output a new one replaces.

    Raises:
        OutputError: a file that cannot be removed (a read-only folder), naming it and the OS's reason.
    """
    path = Path(path)
    try:
        path.unlink(missing_ok=True)
    except OSError as exc:
        raise output_error(path, exc, kept=path.exists()) from exc


def write_atomic(path: str | Path, write) -> None:
    """Write a file whole or not at all.

    ``write(tmp_path)`` writes to a temporary file in the destination folder,
    ``.{name}.wbfriction-{host}-{pid}-{token}.tmp{suffix}`` (it ends like the destination: ``write``
    may read it back by its type), which is then renamed onto ``path`` (atomic on POSIX). On any
    error or interruption the temporary file is removed and ``path`` is left untouched; one left by
    a killed process is removed by a later write into the folder (:func:`remove_stale_temporaries`).
    The file is created with mode 0o666 less the umask (as ``open`` creates files), so colleagues
    read it when the umask allows.

    Raises:
        InputError: an output folder that does not exist.
        OutputError: the system refused the write (an OSError while the temporary file was made,
            written or renamed: a full disk or quota, a file over ``ulimit -f``, a read-only or
            unwritable folder, a path under a file), naming ``path`` and the OS's reason
            (:func:`output_error`). An OSError naming another file (an input read by ``write``) is
            raised as it is.
    """
    path = Path(path)
    if not path.parent.exists():
        raise InputError(f"{path}: output directory {path.parent} does not exist")
    remove_stale_temporaries(path.parent)
    tmp = _temporary_name(path.parent, f"{path.name[:100]}.", f".tmp{path.suffix}")
    try:
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))  # the umask applies
        write(tmp)
        os.replace(tmp, path)
    except OSError as exc:
        _discard(tmp)
        if _names_other_file(exc, (tmp, path, path.parent)):
            raise
        raise output_error(path, exc, kept=path.is_file()) from exc
    except BaseException:
        _discard(tmp)
        raise


def write_json(path: str | Path, doc: object) -> None:
    """Write a JSON document (indented by 2, keys in their order), whole or not at all.

    Raises:
        InputError: an output folder that does not exist.
        OutputError: the system refused the write (:func:`write_atomic`).
    """
    text = json.dumps(doc, indent=2)
    write_atomic(path, lambda tmp: tmp.write_text(text))


def write_table(table: pa.Table, path: str | Path) -> None:
    """Write an Arrow table as Parquet (CSV if ``path`` ends in .csv, its metadata in a first line
    :data:`CSV_METADATA`; HDF5 in .h5 or .hdf5), atomically.

    Raises:
        InputError: an output folder that does not exist.
        OutputError: the system refused the write (:func:`write_atomic`).
    """
    path = Path(path)
    if path.suffix.lower() == ".csv":
        def write_csv(tmp: Path) -> None:
            with open(tmp, "wb") as handle:
                _write_csv_header(handle, table.schema)
                pacsv.write_csv(table, handle)

        write_atomic(path, write_csv)
    elif path.suffix.lower() in HDF5_SUFFIXES:
        write_atomic(path, lambda tmp: write_hdf5(table, tmp))
    else:
        write_atomic(path, lambda tmp: pq.write_table(table, tmp, use_dictionary=dictionary_columns(table.schema)))


def dictionary_columns(schema: pa.Schema) -> list[str]:
    """The columns worth Parquet's dictionary encoding: all but the floating-point ones (measured
    signals rarely repeat a value; encoding them costs 2.8x the write time for a 17 % larger file)."""
    return [f.name for f in schema if not pa.types.is_floating(f.type)]


def write_tables(path: str | Path, tables: Iterable[pa.Table], check=None) -> int:
    """Stream tables with the same columns into one Parquet or CSV file, whole or not at
    all: the first table gives the schema and its metadata (later ones are cast to it);
    ``check(tmp_path)``, if given, runs on the complete temporary file before the rename and
    may raise to keep the previous output. Returns the rows written.

    Raises:
        InputError: an output that is neither .parquet nor .csv, or no table at all; what
            the tables' source or ``check`` raises.
        OutputError: the system refused the write (:func:`write_atomic`); the tables' source is
            not read further.
    """
    path = Path(path)
    if path.suffix.lower() not in (".parquet", ".pq", ".csv"):
        raise InputError(f"{path}: tables are streamed as .parquet or .csv")
    rows = 0

    def write(tmp: Path) -> None:
        nonlocal rows
        writer = None
        handle = None
        try:
            for table in tables:
                if writer is None:
                    schema = table.schema
                    if path.suffix.lower() == ".csv":
                        handle = open(tmp, "wb")  # noqa: SIM115 - closed below, after the writer
                        _write_csv_header(handle, schema)
                        writer = pacsv.CSVWriter(handle, schema)
                    else:
                        writer = pq.ParquetWriter(tmp, schema, use_dictionary=dictionary_columns(schema))
                writer.write_table(table.cast(schema) if table.schema != schema else table)
                rows += table.num_rows
        finally:
            if writer is not None:
                writer.close()
            if handle is not None:
                handle.close()
        if writer is None:
            raise InputError(f"{path}: nothing to write")
        if check is not None:
            check(tmp)

    write_atomic(path, write)
    return rows

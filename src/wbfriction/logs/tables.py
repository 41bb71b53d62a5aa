"""Table files: read whole or in row ranges through their format, their numeric columns, atomic writes.

A table file's format is decided once, by the registry of log formats (:func:`~wbfriction.logs.formats.format_of`:
Parquet, CSV, HDF5, NumPy and any format registered there): :class:`TableFile` reads it, :func:`write_table` and
:func:`write_tables` write one. Every table carries its JSON metadata under the schema key ``wbfriction``
(:mod:`wbfriction.logs.metadata`). Every output is written whole or not at all (:func:`write_atomic`), and an
output the system refuses to write (a full disk, ``ulimit -f``, a read-only folder, a path under a file) is one
:class:`~wbfriction.exceptions.OutputError` naming it (:func:`output_error`).
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

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError, OutputError
from wbfriction.logs.formats.base import LogFormat, RowReader, TableWriter
from wbfriction.logs.formats.registry import format_of, format_to_stream, format_to_write
from wbfriction.logs.metadata import META_KEY as META_KEY  # the metadata's names, importable from here as before
from wbfriction.logs.metadata import read_metadata as read_metadata
from wbfriction.logs.metadata import with_metadata as with_metadata


# ------------------------------------------------------------------- reading
def table_format(path: str | Path) -> LogFormat:
    """The format of an existing table file (:func:`~wbfriction.logs.formats.format_of`).

    Raises:
        InputError: a missing file, a type no registered format reads, or a file that is no table (a ROS 2 bag).
    """
    fmt = format_of(path)
    if fmt.needs_map:
        raise InputError(f"{path}: a {fmt.label} is not a table file: convert it first ('wbfriction convert')")
    return fmt


class TableFile:
    """A table file and its format (decided once, :func:`table_format`).

    Attributes:
        path: the file.
        format: its :class:`~wbfriction.logs.formats.LogFormat` (``format.name``: ``parquet``, ``csv``, ...).

    Raises:
        InputError: a missing file or an unknown type (at construction).
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.format: LogFormat = table_format(self.path)

    def read(self, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        """The whole table, or only those of ``columns`` that it has (others are skipped).

        Args:
            columns: the columns to read (None: all).
            text_columns: columns a CSV file's cells are read from as text, as written (no type inference:
                an id ``007`` stays ``"007"``, not ``7``); ignored by formats whose columns carry their types.

        Raises:
            InputError: unreadable content, naming the file.
        """
        return self.format.read(self.path, columns, text_columns)

    def schema(self) -> pa.Schema:
        """The table's columns and their types, and its metadata (without reading its rows where the format can:
        a CSV's types as inferred from its first block).

        Raises:
            InputError: unreadable content, naming the file.
        """
        return self.format.schema(self.path)

    def metadata(self) -> dict:
        """The table's ``wbfriction`` metadata ({} if none).

        Raises:
            InputError: unreadable content or metadata, naming the file.
        """
        return self.format.metadata(self.path)

    def row_count(self) -> int:
        """Rows of the table when known without reading it (a Parquet file's footer), else 0."""
        return self.format.row_count(self.path)

    def row_reader(self, batch_rows: int) -> RowReader:
        """A reader of row ranges, forwards (in bounded memory where the format reads ranges alone)."""
        return self.format.row_reader(self.path, batch_rows)

    def blocks(self, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The table as consecutive tables of ``block_rows`` rows (with the file's metadata).

        Raises:
            InputError: an unreadable file, naming it and the row.
        """
        return self.format.blocks(self.path, block_rows)


def read_table(path: str | Path) -> pa.Table:
    """Read a table file into an Arrow table (:meth:`TableFile.read`).

    Raises:
        InputError: missing file, unknown type, or unreadable content.
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


def finite_json(doc: object) -> object:
    """``doc`` with every number that is not finite (NaN, an infinity, NumPy's too) ``null``: no file the package
    writes holds ``NaN`` or ``Infinity``, which JSON does not have and strict readers refuse (issue 63). What a
    ``null`` means is its key's (docs/reference: a standard error that is not identifiable, a held-out RMS not
    scored...). Mappings, lists and tuples are walked; NumPy scalars and arrays become plain numbers and lists."""
    if isinstance(doc, dict):
        return {k: finite_json(v) for k, v in doc.items()}
    if isinstance(doc, (list, tuple)):
        return [finite_json(v) for v in doc]
    if isinstance(doc, np.ndarray):
        return finite_json(doc.tolist())
    if isinstance(doc, (bool, np.bool_)):
        return bool(doc)
    if isinstance(doc, (float, np.floating)):
        return float(doc) if np.isfinite(doc) else None
    if isinstance(doc, np.integer):
        return int(doc)
    return doc


def json_text(doc: object, indent: int = 2, sort_keys: bool = False) -> str:
    """The JSON text of ``doc`` as the package writes it (:func:`finite_json`: no ``NaN`` nor ``Infinity``)."""
    return json.dumps(finite_json(doc), indent=indent, sort_keys=sort_keys, allow_nan=False)


def write_json(path: str | Path, doc: object) -> None:
    """Write a JSON document (indented by 2, keys in their order), whole or not at all; a number that is not finite
    is written ``null`` (:func:`finite_json`).

    Raises:
        InputError: an output folder that does not exist.
        OutputError: the system refused the write (:func:`write_atomic`).
    """
    text = json_text(doc)
    write_atomic(path, lambda tmp: tmp.write_text(text))


def write_table(table: pa.Table, path: str | Path) -> None:
    """Write an Arrow table, atomically, in the format that claims ``path``'s name
    (:func:`~wbfriction.logs.formats.format_to_write`: ``.csv`` CSV, its metadata on its first line; ``.h5``
    HDF5; ``.npz`` NumPy; Parquet for any other).

    Raises:
        InputError: an output folder that does not exist; a name whose format writes no file.
        OutputError: the system refused the write (:func:`write_atomic`).
    """
    fmt = format_to_write(path)
    write_atomic(path, lambda tmp: fmt.write(table, tmp))


def write_tables(path: str | Path, tables: Iterable[pa.Table], check=None) -> int:
    """Stream tables with the same columns into one file (a format that streams:
    :func:`~wbfriction.logs.formats.format_to_stream`, Parquet or CSV), whole or not at
    all: the first table gives the schema and its metadata (later ones are cast to it);
    ``check(tmp_path)``, if given, runs on the complete temporary file before the rename and
    may raise to keep the previous output. Returns the rows written.

    Raises:
        InputError: an output in no format that streams, or no table at all; what
            the tables' source or ``check`` raises.
        OutputError: the system refused the write (:func:`write_atomic`); the tables' source is
            not read further.
    """
    path = Path(path)
    fmt = format_to_stream(path)
    rows = 0

    def write(tmp: Path) -> None:
        nonlocal rows
        writer: TableWriter | None = None
        try:
            for table in tables:
                if writer is None:
                    schema = table.schema
                    writer = fmt.open_writer(tmp, schema)
                writer.write_table(table.cast(schema) if table.schema != schema else table)
                rows += table.num_rows
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise InputError(f"{path}: nothing to write")
        if check is not None:
            check(tmp)

    write_atomic(path, write)
    return rows

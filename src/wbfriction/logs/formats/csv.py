"""CSV (``.csv``): a table as text, its types inferred when read (or kept as text, ``text_columns``), read by row
ranges in blocks, written whole or table after table. A CSV file has no place for metadata but its first line:
:data:`CSV_METADATA` and the JSON object (without it, a log's torque alignment, a friction table's smoother and
provenance would be lost)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import BinaryIO

import pyarrow as pa
import pyarrow.csv as pacsv

from wbfriction.logs.formats.base import BatchRows, LogFormat, RowReader, TableWriter, unreadable
from wbfriction.logs.formats.catalog import CSV
from wbfriction.logs.metadata import META_KEY

CSV_METADATA = b"#wbfriction "
"""A CSV file's first line when it carries the ``wbfriction`` metadata."""


def _csv_metadata(path: Path) -> tuple[int, dict[bytes, bytes] | None]:
    """Rows to skip at the top of a CSV file and the metadata its first line carries (0, None: none)."""
    try:
        with open(path, "rb") as handle:
            first = handle.readline()
    except OSError as exc:
        raise unreadable(path, exc) from exc
    if first.startswith(CSV_METADATA):
        return 1, {META_KEY: first[len(CSV_METADATA):].strip()}
    return 0, None


def _csv_options(path: Path, **kwargs) -> tuple[pacsv.ReadOptions, dict[bytes, bytes] | None]:
    skip, meta = _csv_metadata(path)
    return pacsv.ReadOptions(skip_rows=skip, **kwargs), meta


def _write_csv_header(handle: BinaryIO, schema: pa.Schema) -> None:
    """The metadata line of a CSV file (:data:`CSV_METADATA`), if the table has metadata."""
    meta = (schema.metadata or {}).get(META_KEY)
    if meta is not None:
        handle.write(CSV_METADATA + meta.replace(b"\n", b" ") + b"\n")


class CsvWriter:
    """A CSV file written table after table: its metadata line, then the rows (:class:`~.base.TableWriter`)."""

    def __init__(self, path: Path, schema: pa.Schema):
        self._handle = open(path, "wb")  # noqa: SIM115 - closed by close(), after the writer
        try:
            _write_csv_header(self._handle, schema)
            self._writer = pacsv.CSVWriter(self._handle, schema)
        except BaseException:
            self._handle.close()
            raise

    def write_table(self, table: pa.Table) -> None:
        self._writer.write_table(table)

    def close(self) -> None:
        try:
            self._writer.close()
        finally:
            self._handle.close()


class CsvFormat(LogFormat, kind=CSV):
    """CSV files (module docstring): ``.csv``, written whole or streamed."""

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        try:
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
            _ = table.column_names
            return table
        except (pa.ArrowException, OSError, ValueError) as exc:  # ValueError: e.g. damaged UTF-8
            raise unreadable(path, exc) from exc

    def schema(self, path: Path) -> pa.Schema:
        """The columns and their types as inferred from the file's first block, and its metadata."""
        try:
            options, meta = _csv_options(path)
            schema = pacsv.open_csv(path, read_options=options).schema
            return schema.with_metadata(meta) if meta is not None else schema
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise unreadable(path, exc) from exc

    def row_reader(self, path: Path, batch_rows: int) -> RowReader:
        try:
            options, metadata = _csv_options(path, block_size=1 << 24)
            return BatchRows(path, metadata, iter(pacsv.open_csv(path, read_options=options)))
        except (pa.ArrowException, OSError, ValueError) as exc:
            raise unreadable(path, exc) from exc

    def write(self, table: pa.Table, path: Path) -> None:
        with open(path, "wb") as handle:
            _write_csv_header(handle, table.schema)
            pacsv.write_csv(table, handle)

    def open_writer(self, path: Path, schema: pa.Schema) -> TableWriter:
        return CsvWriter(path, schema)

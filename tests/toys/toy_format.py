"""A toy log format, one file: Arrow's Feather (IPC) files, the package's metadata in the schema's."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pyarrow as pa
import pyarrow.feather as feather

from wbfriction.logs.formats.base import LogFormat


class Feather(LogFormat):
    """``.feather`` logs, read and written whole."""

    name = "feather"
    label = "Feather"
    suffixes = (".feather",)
    writable = True

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        return feather.read_table(path, columns=columns)

    def write(self, table: pa.Table, path: Path) -> None:
        feather.write_feather(table, path, compression="uncompressed")

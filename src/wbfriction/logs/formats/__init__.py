"""Log formats: one :class:`LogFormat` per kind of file (:mod:`.base`), one module each (:mod:`.parquet`,
:mod:`.csv`, :mod:`.hdf5`, :mod:`.npz`, :mod:`.bag`), and the registry a path's format is found in
(:mod:`.registry`: :func:`register_format` adds one, :func:`format_of` finds a file's)."""

from wbfriction.logs.formats.base import LogFormat, RowReader, TableWriter
from wbfriction.logs.formats.registry import (
    UnknownFormatError,
    format_of,
    format_to_stream,
    format_to_write,
    log_formats,
    register_format,
    stream_suffixes,
    unregister_format,
)

__all__ = ["LogFormat", "RowReader", "TableWriter", "UnknownFormatError", "format_of", "format_to_stream",
           "format_to_write", "log_formats", "register_format", "stream_suffixes", "unregister_format"]

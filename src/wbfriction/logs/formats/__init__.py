"""Log formats: one :class:`LogFormat` per kind of file (:mod:`.base`), one module each (:mod:`.parquet`,
:mod:`.csv`, :mod:`.hdf5`, :mod:`.npz`, :mod:`.bag`), the registry a path's format is found in (:mod:`.registry`:
:func:`register_format` adds one, :func:`format_of` finds a file's) and the catalogue of the registered formats'
kinds (:mod:`.catalog`: names, labels, suffixes), which imports nothing heavy: the command line's help reads it
without loading pyarrow. The names below are imported on first use."""

from __future__ import annotations

from typing import TYPE_CHECKING

import lazy_loader

if TYPE_CHECKING:
    from .base import LogFormat as LogFormat
    from .base import RowReader as RowReader
    from .base import TableWriter as TableWriter
    from .catalog import FormatKind as FormatKind
    from .catalog import format_kinds as format_kinds
    from .registry import UnknownFormatError as UnknownFormatError
    from .registry import find_format as find_format
    from .registry import format_of as format_of
    from .registry import format_to_stream as format_to_stream
    from .registry import format_to_write as format_to_write
    from .registry import log_formats as log_formats
    from .registry import register_format as register_format
    from .registry import stream_suffixes as stream_suffixes
    from .registry import unregister_format as unregister_format

MODULES = {
    "LogFormat": "base", "RowReader": "base", "TableWriter": "base",
    "FormatKind": "catalog", "format_kinds": "catalog",
    "UnknownFormatError": "registry", "find_format": "registry", "format_of": "registry",
    "format_to_stream": "registry", "format_to_write": "registry", "log_formats": "registry",
    "register_format": "registry", "stream_suffixes": "registry", "unregister_format": "registry",
}
"""Each public name and the module (of this package) that defines it."""

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__, submod_attrs={module: [n for n, m in MODULES.items() if m == module] for module in set(MODULES.values())})

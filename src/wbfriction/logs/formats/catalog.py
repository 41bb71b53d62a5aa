"""The log formats as the command line's help names them, in a module that imports nothing heavy (no pyarrow): each
registered format's name, label, suffixes and abilities (:class:`FormatKind`), in the order the registry tries them.

The built-in formats' kinds are declared here (:data:`BUILTIN`; each built-in class takes its own from it:
``class ParquetFormat(LogFormat, kind=PARQUET)``), so the help lists them without importing their modules;
:func:`~wbfriction.logs.formats.registry.register_format` adds the kind of every format it registers, and
:func:`~wbfriction.logs.formats.registry.unregister_format` takes it off. What the help says of the formats
(:func:`table_formats`, :func:`mapped_formats`, :func:`written`, :func:`written_suffixes`; the outputs' suffixes,
:mod:`wbfriction.pipeline.outputs`) is read from here: a registered format is in it, a hand-kept list nowhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from wbfriction.choices import spoken


@dataclass(frozen=True)
class FormatKind:
    """What a log format is, without its code.

    Attributes:
        name: the format's one-word name (``parquet``).
        label: how messages name it (``Parquet``).
        suffixes: the file name endings that are its own, lower case with the dot (``.parquet``, ``.pq``).
        writable: it writes a whole table; streamable: tables one after the other (a friction table); text: it
            keeps a table's text columns (a table of joints' names and statuses).
        needs_map: its files are read only through a map (``--map``: a ROS 2 bag's topics), not as tables.
        detail: what else the help says of its files (a ROS 2 bag: ``or a folder with metadata.yaml``), or "".
    """

    name: str
    label: str
    suffixes: tuple[str, ...]
    writable: bool = False
    streamable: bool = False
    needs_map: bool = False
    text: bool = False
    detail: str = ""

    @classmethod
    def of(cls, fmt: Any) -> FormatKind:
        """The kind of a :class:`~wbfriction.logs.formats.base.LogFormat` (its class attributes)."""
        return cls(fmt.name, fmt.label, tuple(fmt.suffixes), writable=bool(fmt.writable),
                   streamable=bool(fmt.streamable), needs_map=bool(fmt.needs_map), text=bool(fmt.text),
                   detail=fmt.detail)

    def words(self) -> str:
        """The format as the help names it: ``Parquet (.parquet, .pq)``."""
        said = ", ".join((*self.suffixes, self.detail) if self.detail else self.suffixes)
        return f"{self.label} ({said})" if said else self.label


PARQUET = FormatKind("parquet", "Parquet", (".parquet", ".pq"), writable=True, streamable=True, text=True)
CSV = FormatKind("csv", "CSV", (".csv",), writable=True, streamable=True, text=True)
HDF5 = FormatKind("hdf5", "HDF5", (".h5", ".hdf5", ".he5"), writable=True)
NPZ = FormatKind("npz", "NumPy", (".npz",), writable=True)
BAG = FormatKind("bag", "ROS 2 bag", (".mcap", ".db3"), needs_map=True, detail="or a folder with metadata.yaml")
BUILTIN: tuple[FormatKind, ...] = (PARQUET, CSV, HDF5, NPZ, BAG)
"""The built-in formats, in the order the registry tries them."""

KINDS: dict[str, FormatKind] = {kind.name: kind for kind in BUILTIN}
"""Name -> the kind of each registered format, in the order tried (kept by the registry)."""


def format_kinds() -> tuple[FormatKind, ...]:
    """The registered formats' kinds (the built-in ones before any module of theirs is imported), in order."""
    return tuple(KINDS.values())


def table_formats() -> str:
    """The formats a log is read from as a table, as the help names them: ``Parquet (.parquet, .pq), CSV (.csv),
    ... or NumPy (.npz)``."""
    return spoken(tuple(k.words() for k in format_kinds() if not k.needs_map))


def mapped_formats() -> str:
    """The formats read only through a map (``--map``), as the help names them: ``ROS 2 bag (.mcap, .db3, or a
    folder with metadata.yaml)``; "" without any."""
    kinds = tuple(k.words() for k in format_kinds() if k.needs_map)
    return spoken(kinds) if kinds else ""


def written(streamed: bool = False, text: bool = False) -> tuple[str, ...]:
    """The suffixes of the registered formats a table is written in (``streamed``: table after table, as a friction
    table or a converted log are; ``text``: its text columns kept, as a table of joints' names), in order:
    ``(".parquet", ".pq", ".csv")``."""
    return tuple(s for k in format_kinds() if (k.streamable if streamed else k.writable) and (k.text or not text)
                 for s in k.suffixes)


def written_suffixes(streamed: bool = False, text: bool = False) -> str:
    """:func:`written` as the help names them: ``.parquet, .pq or .csv``."""
    return spoken(written(streamed, text))

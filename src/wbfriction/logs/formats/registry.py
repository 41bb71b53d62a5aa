"""The log formats the package knows, and the one a path is in: every file is read and written through it.

Five are built in, in this order: Parquet, CSV, HDF5, NumPy ``.npz`` and ROS 2 bags (:mod:`.parquet`, :mod:`.csv`,
:mod:`.hdf5`, :mod:`.npz`, :mod:`.bag`). Another is one call away::

    from wbfriction.logs import LogFormat, register_format

    class Tsv(LogFormat):
        name, label, suffixes, writable = "tsv", "TSV", (".tsv",), True
        def read(self, path, columns=None, text_columns=()): ...
        def write(self, table, path): ...

    register_format(Tsv())

after which every function that takes a log reads (and, if the format writes, writes) ``.tsv`` files: a folder's
scan for logs (:func:`find_format`), and the command line's help, which lists the formats registered
(:mod:`.catalog`) as the command line is loaded. An installed package advertises a format under the entry-point group
:data:`ENTRY_POINT_GROUP` (``wbfriction.log_formats``): read, and its formats loaded, the first time a path is not
one of the formats registered so far (a log in a built-in format reads no entry point), or every format is asked
for.
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.exceptions import InputError
from wbfriction.logs.formats.bag import BagFormat
from wbfriction.logs.formats.base import LogFormat
from wbfriction.logs.formats.catalog import KINDS, FormatKind
from wbfriction.logs.formats.csv import CsvFormat
from wbfriction.logs.formats.hdf5 import Hdf5Format
from wbfriction.logs.formats.npz import NpzFormat
from wbfriction.logs.formats.parquet import ParquetFormat
from wbfriction.registry import Registry


class UnknownFormatError(InputError):
    """A path that no registered format reads (or, to write it, claims).

    Attributes:
        path: the file.
        suffix: its suffix, as given ('' without one).
        known: the registered formats, as :meth:`LogFormat.describe <wbfriction.logs.formats.base.LogFormat.describe>`
            words them.
    """

    def __init__(self, path: str, suffix: str, known: tuple[str, ...]):
        self.path = path
        self.suffix = suffix
        self.known = known
        super().__init__(f"{path}: unknown file type '{suffix}' (known formats: {'; '.join(known)})")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.path, self.suffix, self.known))


def check_suffixes(fmt: LogFormat) -> None:
    """Refuse a format that claims a suffix another registered format reads (what :func:`register_format` checks
    first; a name taken is the registry's to refuse).

    Raises:
        ValueError: naming the suffixes and the format that reads them.
    """
    # a name taken: FORMATS.register refuses it, naming it; the formats registered so far, no entry point loaded
    others = () if fmt.name in FORMATS.loaded() else FORMATS.registered()
    for other in others:
        shared = sorted(set(fmt.suffixes) & set(other.suffixes))
        if shared:
            raise ValueError(f"log format '{fmt.name}' claims {', '.join(shared)}, which format '{other.name}' "
                             "reads already")


def catalogue(fmt: LogFormat) -> None:
    """Put ``fmt``'s kind in the catalogue the command line's help reads (:mod:`~wbfriction.logs.formats.catalog`)."""
    KINDS[fmt.name] = FormatKind.of(fmt)


def uncatalogue(name: str) -> None:
    """Take the format ``name``'s kind off the catalogue the command line's help reads."""
    KINDS.pop(name, None)


ENTRY_POINT_GROUP = "wbfriction.log_formats"
"""The entry-point group under which an installed package advertises its log formats: each entry's name is the
format's and its object a :class:`~wbfriction.logs.formats.base.LogFormat` (an instance, or a class called without
arguments)."""

FORMATS: Registry[LogFormat] = Registry("log format", check=check_suffixes, on_register=catalogue,
                                        on_unregister=uncatalogue, entry_points=ENTRY_POINT_GROUP)
"""The registered formats by name, in the order they are tried: the built-in ones, those registered, those installed
packages advertise (loaded when a path is none of the others', or every format is asked for: one that does not load
is left out with one :class:`~wbfriction.registry.PluginWarning` line, the others used)."""

DEFAULT_FORMAT = "parquet"
"""The format a table is written in when no registered format claims its file's name."""


register_format = FORMATS.register
"""Add a format (a :class:`~wbfriction.logs.formats.base.LogFormat`) to those every path is looked up in, after those
registered before it (the first whose :meth:`~wbfriction.logs.formats.base.LogFormat.detect` accepts a path reads
it); returns it. Its kind joins the catalogue the command line's help reads (:mod:`~wbfriction.logs.formats.catalog`).
ValueError: a format of that name registered already, or a suffix another format claims (naming both)."""
unregister_format = FORMATS.unregister
"""Remove the format of a name from the registry; returns it (ValueError: none of that name)."""
log_formats = FORMATS.kinds
"""The registered formats, in the order they are tried."""


def _unknown(path: Path) -> UnknownFormatError:
    return UnknownFormatError(str(path), path.suffix.lower(), tuple(f.describe() for f in FORMATS))


def find_format(path: str | Path) -> LogFormat | None:
    """The first registered format that detects the existing file (or folder) ``path``
    (:meth:`~wbfriction.logs.formats.base.LogFormat.detect`), or None: what a folder's scan for logs asks of each of
    its files."""
    return FORMATS.first(lambda f: f.detect(Path(path)))


def format_of(path: str | Path) -> LogFormat:
    """The format of the existing file (or folder) ``path``: the first registered one that detects it
    (:func:`find_format`).

    Raises:
        InputError: a missing file; a folder no format reads (not a bag); :class:`UnknownFormatError`: a file no
            format reads, naming the file and every known format.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file not found")
    found = find_format(path)
    if found is not None:
        return found
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a table file (a ROS 2 bag folder needs --map)")
    raise _unknown(path)


def format_to_write(path: str | Path) -> LogFormat:
    """The format a table is written in at ``path``: the registered one that claims its name (its suffix), else
    :data:`DEFAULT_FORMAT`.

    Raises:
        InputError: a format that claims the name but writes no file (a ROS 2 bag).
    """
    path = Path(path)
    fmt = FORMATS.first(lambda f: f.claims(path)) or FORMATS.get(DEFAULT_FORMAT)
    if not fmt.writable:
        raise InputError(f"{path}: {fmt.label} files are read, not written")
    return fmt


def stream_suffixes() -> tuple[str, ...]:
    """The suffixes of the formats tables are streamed into (table after table: a friction table, a converted bag)."""
    return tuple(s for f in FORMATS if f.streamable for s in f.suffixes)


def format_to_stream(path: str | Path, what: str = "tables are streamed") -> LogFormat:
    """The format tables are written in, one after the other, at ``path``: the registered one that claims its name
    and can (:attr:`~wbfriction.logs.formats.base.LogFormat.streamable`).

    Args:
        what: what the message says is written so (``friction tables are written``).

    Raises:
        InputError: a name no such format claims, naming the file and the suffixes there are.
    """
    path = Path(path)
    fmt = FORMATS.first(lambda f: f.claims(path))
    if fmt is None or not fmt.streamable:
        raise InputError(f"{path}: {what} as {', '.join(stream_suffixes())}")
    return fmt


for _builtin in (ParquetFormat(), CsvFormat(), Hdf5Format(), NpzFormat(), BagFormat()):
    register_format(_builtin)

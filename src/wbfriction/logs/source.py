"""Where a log comes from: a file (or folder) in one of the registered log formats, decided once.

:func:`open_log` looks at a path once and finds its format (:func:`~wbfriction.logs.formats.format_of`: Parquet,
CSV, HDF5, NumPy, a ROS 2 bag, or any format registered); the rest of the package reads the log through the
:class:`LogSource` it returns, whole (:meth:`LogSource.read`, :func:`read_log`) or block by block
(:meth:`LogSource.blocks`). A map TOML (``--map``) given with a table file renames its joints and derives its
contact flags there, on every block (:mod:`wbfriction.logs.table_map`); a bag is read through its topic map
(:mod:`wbfriction.logs.bags`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pyarrow as pa

from wbfriction.logs.bags import BagMap
from wbfriction.logs.formats.base import LogFormat
from wbfriction.logs.formats.registry import format_of
from wbfriction.logs.log import Log, log_from_table
from wbfriction.logs.options import ReadOptions
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class LogSource:
    """A log file or bag whose format is known.

    Attributes:
        path: the file (or a bag's folder).
        format: its :class:`~wbfriction.logs.formats.LogFormat`.
        mapping: what it is read through: a bag's topic map (:class:`~wbfriction.logs.bags.BagMap`), a table
            file's map (:class:`~wbfriction.logs.table_map.TableMap`), or None (the file's own columns).
    """

    path: Path
    format: LogFormat
    mapping: object | None = None

    @property
    def is_mapped(self) -> bool:
        """A bag, or a table file read through a map: its blocks are not the file's own rows."""
        return self.mapping is not None

    def read(self) -> pa.Table:
        """The whole log as one table in the log format (:mod:`wbfriction.logs.log`), not validated.

        Raises:
            InputError: an unreadable file or bag.
        """
        return self.format.read_log(self.path, self.mapping)

    def blocks(self, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The log as consecutive tables of about ``block_rows`` rows, never read whole (a bag
        aligned as it is read, :func:`~wbfriction.logs.bags.iter_bag`).

        Raises:
            InputError: an unreadable file or bag, naming it (and the row where it can).
        """
        return self.format.log_blocks(self.path, self.mapping, block_rows)


def open_log(path: str | Path, bag_map: BagMap | str | Path | None = None, robot: Robot | None = None) -> LogSource:
    """What ``path`` is (:func:`~wbfriction.logs.formats.format_of`), and the map it is read through
    (:meth:`LogFormat.open_map <wbfriction.logs.formats.LogFormat.open_map>`): a ROS 2 bag (a folder with
    ``metadata.yaml``, or a ``.mcap``/``.db3`` file) through its topic map ``bag_map`` (a
    :class:`~wbfriction.logs.bags.BagMap` or its TOML file); a table file through the same map TOML if one is given
    (:mod:`wbfriction.logs.table_map`: joint renaming, contact flags from force columns), checked against the
    file's columns and, if given, ``robot``.

    Raises:
        InputError: a bag without a map, an unreadable map, a map entry naming a column the table does
            not have or a joint or frame ``robot`` does not (naming the map and the key), a missing file
            or an unknown file type (:class:`~wbfriction.logs.formats.UnknownFormatError`).
    """
    path = Path(path)
    fmt = format_of(path)
    return LogSource(path, fmt, fmt.open_map(path, bag_map, robot))


def read_log(path: str | Path, robot: Robot, bag_map: BagMap | str | Path | None = None,
             read: ReadOptions = ReadOptions()) -> Log:
    """Read and validate a log: a file in one of the log formats (:mod:`wbfriction.logs.formats`) holding the log
    format's columns (:mod:`wbfriction.logs.log`), or a ROS 2 bag with its topic map (:mod:`wbfriction.logs.bags`).

    Args:
        path: the file (or bag folder).
        robot: the robot whose names the columns must match.
        bag_map: a :class:`~wbfriction.logs.bags.BagMap` or its TOML file (needed for a bag; for a table
            file, its map TOML: :mod:`wbfriction.logs.table_map`).
        read: how the log is read (:class:`~wbfriction.logs.options.ReadOptions`,
            :func:`~wbfriction.logs.log.log_from_table`).

    Raises:
        InputError: see :func:`open_log`, :func:`~wbfriction.logs.log.log_from_table` and
            :func:`~wbfriction.logs.bags.read_bag`; messages start with the file name.
    """
    return log_from_table(open_log(path, bag_map, robot).read(), robot, str(path), read)

"""Where a log comes from: a table file (Parquet, CSV, HDF5) or a ROS 2 bag, decided once.

:func:`open_log` looks at a path once and says what it is (:data:`LogFormat`); the rest of
the package reads the log through the :class:`LogSource` it returns, whole
(:meth:`LogSource.read`, :func:`read_log`) or block by block (:meth:`LogSource.blocks`). A map TOML
(``--map``) given with a table file renames its joints and derives its contact flags there, on every
block (:mod:`wbfriction.logs.table_map`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.bags import BagMap, is_bag, iter_bag, load_bag_map, read_bag
from wbfriction.logs.clock import TimeBase, TimeUnit
from wbfriction.logs.log import Log, log_from_table
from wbfriction.logs.options import LIMIT_MARGIN, MAX_GAP
from wbfriction.logs.table_map import TableMap, load_table_map
from wbfriction.logs.tables import TableFile
from wbfriction.model.robot import Robot

LogFormat = Literal["parquet", "csv", "hdf5", "bag"]
"""The formats a log can come in."""


@dataclass(frozen=True)
class LogSource:
    """A log file or bag whose format is known.

    Attributes:
        path: the file (or a bag's folder).
        format: ``parquet``, ``csv``, ``hdf5`` or ``bag``.
        bag_map: the topic map of a bag (None for a table file).
        table_map: the map of a table file (joint names, contact flags), or None.
    """

    path: Path
    format: LogFormat
    bag_map: BagMap | None = None
    table_map: TableMap | None = None

    @property
    def is_bag(self) -> bool:
        return self.format == "bag"

    @property
    def is_mapped(self) -> bool:
        """A bag, or a table file read through a map: its blocks are not the file's own rows."""
        return self.is_bag or self.table_map is not None

    def table_file(self) -> TableFile:
        """The table file (not for a bag).

        Raises:
            InputError: a bag.
        """
        if self.is_bag:
            raise InputError(f"{self.path}: a ROS 2 bag is not a table file: convert it first ('wbfriction convert')")
        return TableFile(self.path)

    def read(self) -> pa.Table:
        """The whole log as one table in the log format (:mod:`wbfriction.logs.log`), not validated.

        Raises:
            InputError: an unreadable file or bag.
        """
        if self.bag_map is not None:
            return read_bag(self.path, self.bag_map)
        if self.table_map is not None:
            return self.table_map.apply(self.table_file().read(), self.path)
        return self.table_file().read()

    def blocks(self, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The log as consecutive tables of about ``block_rows`` rows, never read whole (a bag
        aligned as it is read, :func:`~wbfriction.logs.bags.iter_bag`).

        Raises:
            InputError: an unreadable file or bag, naming it (and the row where it can).
        """
        if self.bag_map is not None:
            return iter_bag(self.path, self.bag_map, block_rows)
        if self.table_map is not None:
            return _mapped(self.table_map, self.table_file().blocks(block_rows), self.path)
        return self.table_file().blocks(block_rows)


def _mapped(table_map: TableMap, blocks: Iterator[pa.Table], path: Path) -> Iterator[pa.Table]:
    """A table file's consecutive ``blocks`` through its map, each told the file row it starts at."""
    first_row = 0
    for block in blocks:
        yield table_map.apply(block, path, first_row)
        first_row += block.num_rows


def open_log(path: str | Path, bag_map: BagMap | str | Path | None = None, robot: Robot | None = None) -> LogSource:
    """What ``path`` is: a ROS 2 bag (a folder with ``metadata.yaml``, or a ``.mcap``/``.db3``
    file, :func:`~wbfriction.logs.bags.is_bag`) read through its topic map ``bag_map`` (a
    :class:`~wbfriction.logs.bags.BagMap` or its TOML file), else a table file, read through the
    same map TOML if one is given (:mod:`wbfriction.logs.table_map`: joint renaming, contact flags
    from force columns), checked against the file's columns and, if given, ``robot``.

    Raises:
        InputError: a bag without a map, an unreadable map, a map entry naming a column the table does
            not have or a joint or frame ``robot`` does not (naming the map and the key), a missing file
            or an unknown file type.
    """
    path = Path(path)
    if is_bag(path):
        if bag_map is None:
            raise InputError(f"{path}: a ROS 2 bag needs a topic map (--map MAP.toml)")
        return LogSource(path, "bag", bag_map if isinstance(bag_map, BagMap) else load_bag_map(bag_map))
    file = TableFile(path)
    if bag_map is None:
        return LogSource(path, file.format)
    if isinstance(bag_map, BagMap):
        raise InputError(f"{path}: a table log is read through a map TOML file, not a bag's topic map")
    table_map = load_table_map(bag_map)
    if robot is not None:
        table_map.check(robot)
    table_map.check_columns(list(file.schema().names), path)
    return LogSource(path, file.format, table_map=table_map)


def read_log(path: str | Path, robot: Robot, bag_map: BagMap | str | Path | None = None, max_gap: float = MAX_GAP,
             limit_margin: float = LIMIT_MARGIN, time_base: TimeBase = "auto", time_unit: TimeUnit | None = None
             ) -> Log:
    """Read and validate a log: a table file in the log format (:mod:`wbfriction.logs.log`), or
    a ROS 2 bag with its topic map (:mod:`wbfriction.logs.bags`).

    Args:
        path: the file (or bag folder).
        robot: the robot whose names the columns must match.
        bag_map: a :class:`~wbfriction.logs.bags.BagMap` or its TOML file (needed for a bag; for a table
            file, its map TOML: :mod:`wbfriction.logs.table_map`).
        max_gap, limit_margin, time_base, time_unit: see :func:`~wbfriction.logs.log.log_from_table`.

    Raises:
        InputError: see :func:`open_log`, :func:`~wbfriction.logs.log.log_from_table` and
            :func:`~wbfriction.logs.bags.read_bag`; messages start with the file name.
    """
    return log_from_table(open_log(path, bag_map, robot).read(), robot, str(path), max_gap, limit_margin,
                          time_base=time_base, time_unit=time_unit)

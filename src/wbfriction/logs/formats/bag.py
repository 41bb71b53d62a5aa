"""ROS 2 bags (:mod:`wbfriction.logs.bags`) as a log format: a folder with ``metadata.yaml``, or a ``.mcap`` /
``.db3`` file in one, read only through its topic map (``--map``), whole or block by block as it is aligned; never
written (``wbfriction convert`` writes a table log of it)."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.bags import BagMap, iter_bag, load_bag_map, read_bag
from wbfriction.logs.formats.base import LogFormat
from wbfriction.logs.formats.catalog import BAG
from wbfriction.model.robot import Robot


def _bag_map(path: Path, mapping: object) -> BagMap:
    if not isinstance(mapping, BagMap):
        raise InputError(f"{path}: a ROS 2 bag needs a topic map (--map MAP.toml)")
    return mapping


class BagFormat(LogFormat, kind=BAG):
    """ROS 2 bags, MCAP or sqlite3 (module docstring), read through a map, never written."""

    def detect(self, path: Path) -> bool:
        """A folder with ``metadata.yaml``, or a ``.mcap`` / ``.db3`` file."""
        if path.is_dir():
            return (path / "metadata.yaml").is_file()
        return super().detect(path)

    def describe(self) -> str:
        return f"{self.label}: a folder with metadata.yaml, or {' '.join(self.suffixes)}"

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        """Refused: a bag is read through its topic map (:meth:`read_log`).

        Raises:
            InputError: always, saying how it is read.
        """
        raise InputError(f"{path}: a ROS 2 bag is not a table file: convert it first ('wbfriction convert')")

    def open_map(self, path: Path, given: object, robot: Robot | None = None) -> BagMap:
        """The bag's topic map: ``given`` as it is, or read from its TOML file.

        Raises:
            InputError: no map given, an unreadable map (:func:`~wbfriction.logs.bags.load_bag_map`).
        """
        if given is None:
            raise InputError(f"{path}: a ROS 2 bag needs a topic map (--map MAP.toml)")
        if isinstance(given, BagMap):
            return given
        if not isinstance(given, str | Path):
            raise InputError(f"{path}: a ROS 2 bag's map is a TOML file, not {type(given).__name__}")
        return load_bag_map(given)

    def read_log(self, path: Path, mapping: object | None = None) -> pa.Table:
        """The bag as one table in the log format (:func:`~wbfriction.logs.bags.read_bag`)."""
        return read_bag(path, _bag_map(path, mapping))

    def log_blocks(self, path: Path, mapping: object | None = None, block_rows: int = 10_000) -> Iterator[pa.Table]:
        """The bag aligned as it is read (:func:`~wbfriction.logs.bags.iter_bag`)."""
        return iter_bag(path, _bag_map(path, mapping), block_rows)

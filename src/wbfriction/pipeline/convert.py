"""Files in, files out: a ROS 2 bag (or another log file) converted into a log file, checked against the robot."""

from __future__ import annotations

from pathlib import Path

from wbfriction.logs.bags import BagMap
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.source import open_log
from wbfriction.logs.tables import write_tables
from wbfriction.model.robot import Robot
from wbfriction.pipeline.estimate_step import check_file


def convert_log(robot: Robot, log: str | Path, output: str | Path, bag_map: BagMap | str | Path | None = None, *,
                read: ReadOptions = ReadOptions()) -> int:
    """Stream a log (a ROS 2 bag through its topic map, or a table file,
    through the same map TOML if given: joint renaming, contact flags) into ``output`` (Parquet
    or CSV) in the log format, check it against ``robot`` chunk by chunk
    (:func:`~wbfriction.pipeline.estimate_step.check_file`, as ``read`` says it is read) and only then rename it
    into place. Returns the rows written.

    Raises:
        InputError: an unreadable log or map, an output that is neither .parquet nor .csv, or
            what the check raises (naming ``log``, the column and the row). Nothing is written then.
    """
    source = open_log(log, bag_map, robot)
    return write_tables(output, source.blocks(),
                        check=lambda tmp: check_file(robot, tmp, str(log), read=read))

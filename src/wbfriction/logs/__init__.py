"""Logs as files: the log format and its validation (:mod:`.log`), table files and atomic writes
(:mod:`.tables`), HDF5 (:mod:`.hdf5`), ROS 2 bags (:mod:`.bags`), and :func:`open_log`, which
decides once what a path is (:mod:`.source`)."""

from wbfriction.logs.bags import BagMap, load_bag_map
from wbfriction.logs.log import Log, log_from_table, write_log
from wbfriction.logs.source import LogFormat, LogSource, open_log, read_log
from wbfriction.logs.tables import TableFile, read_table, write_table

__all__ = ["BagMap", "Log", "LogFormat", "LogSource", "TableFile", "load_bag_map", "log_from_table", "open_log",
           "read_log", "read_table", "write_log", "write_table"]

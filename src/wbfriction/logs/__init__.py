"""Logs as files: the log format and its validation (:mod:`.log`), the file formats a log comes in, one module
each, in a registry new ones join with one call (:mod:`.formats`: Parquet, CSV, HDF5, NumPy, ROS 2 bags;
:func:`register_format`), where a log's torque comes from, in a registry of its own (:mod:`.torque`:
:func:`register_torque_source`), table files and atomic writes (:mod:`.tables`), and :func:`open_log`, which decides
once what a path is (:mod:`.source`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

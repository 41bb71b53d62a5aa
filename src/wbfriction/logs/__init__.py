"""Logs as files: the log format and its validation (:mod:`.log`), table files and atomic writes
(:mod:`.tables`), HDF5 (:mod:`.hdf5`), ROS 2 bags (:mod:`.bags`), NumPy recordings (:mod:`.npz`), and
:func:`open_log`, which decides once what a path is (:mod:`.source`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""The choices a user makes about reading a log, in a module that imports nothing heavy: the command line
shows their defaults in its help without loading NumPy or pyarrow."""

MAX_GAP = 2.0
"""Default gap [sampling periods]: a time step at least this long (against the median of the
steps around it) splits a log into segments."""
LIMIT_MARGIN = 0.2
"""How far a position may pass its URDF limits before the log is refused [rad or m]."""

"""Names of :mod:`wbfriction.logs`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .bags import BagMap as BagMap
from .bags import load_bag_map as load_bag_map
from .log import Log as Log
from .log import log_from_table as log_from_table
from .log import write_log as write_log
from .npz import read_npz_recordings as read_npz_recordings
from .source import LogFormat as LogFormat
from .source import LogSource as LogSource
from .source import open_log as open_log
from .source import read_log as read_log
from .tables import TableFile as TableFile
from .tables import read_table as read_table
from .tables import write_table as write_table

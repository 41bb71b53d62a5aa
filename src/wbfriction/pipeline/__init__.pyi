"""Names of :mod:`wbfriction.pipeline`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .chunks import Chunking as Chunking
from .convert import convert_log as convert_log
from .estimate_step import RobotSpec as RobotSpec
from .estimate_step import check_file as check_file
from .estimate_step import estimate_file as estimate_file
from .estimate_step import table_log as table_log
from .fit_step import fit_file as fit_file
from .identify_step import identify_file as identify_file
from .predict_step import predict_file as predict_file

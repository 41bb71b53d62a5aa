"""Names of :mod:`wbfriction.pipeline`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .chunks import Chunking as Chunking
from .convert import convert_log as convert_log
from .estimate import RobotSpec as RobotSpec
from .estimate import check_file as check_file
from .estimate import estimate_file as estimate_file
from .estimate import table_log as table_log
from .fit import fit_file as fit_file
from .identify import identify_file as identify_file
from .predict import predict_file as predict_file

"""Files in, files out: what the command line runs on files, for long logs too: the estimate in
chunks on several processes (:mod:`.chunks`, :mod:`.estimate`), the fit (:mod:`.fit`), the
inertia identification (:mod:`.identify`), torque prediction on held-out logs (:mod:`.predict`),
exports (:mod:`.export`), bag conversion (:mod:`.convert`), each output with
its provenance (:mod:`.provenance`)."""

from wbfriction.pipeline.chunks import Chunking
from wbfriction.pipeline.convert import convert_log
from wbfriction.pipeline.estimate import RobotSpec, check_file, estimate_file, table_log
from wbfriction.pipeline.fit import fit_file
from wbfriction.pipeline.identify import identify_file
from wbfriction.pipeline.predict import predict_file

__all__ = ["Chunking", "RobotSpec", "check_file", "convert_log", "estimate_file", "fit_file", "identify_file",
           "predict_file", "table_log"]

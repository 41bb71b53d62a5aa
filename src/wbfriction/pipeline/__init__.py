"""Files in, files out: what the command line runs on files, for long logs too: the estimate in
chunks on several processes (:mod:`.chunks`, :mod:`.estimate_step`), the fit (:mod:`.fit_step`), the
inertia identification (:mod:`.identify_step`), torque prediction on held-out logs (:mod:`.predict_step`),
exports (:mod:`.export_step`), bag conversion (:mod:`.convert`), each output with
its provenance (:mod:`.provenance`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

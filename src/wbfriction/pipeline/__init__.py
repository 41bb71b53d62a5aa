"""Files in, files out: what the command line runs on files, for long logs too: the estimate in
chunks on several processes (:mod:`.chunks`, :mod:`.estimate`), the fit (:mod:`.fit`), the
inertia identification (:mod:`.identify`), torque prediction on held-out logs (:mod:`.predict`),
exports (:mod:`.export`), bag conversion (:mod:`.convert`), each output with
its provenance (:mod:`.provenance`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""Friction estimated from a log (log -> ``tau_f``): the models (:mod:`.models`, thesis 3.1-3.5), the estimate
from measured kinematics (:mod:`.estimate`, 5.10-5.13, 6.1), the momentum route (:mod:`.momentum`), the sensors'
routes (:mod:`.measured`), the choice of route (:mod:`.route`) and the friction table (:mod:`.io`). Fitting
models to the estimate is the next stage, :mod:`wbfriction.fit`."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""Friction: the models (:mod:`.models`, thesis 3.1-3.5) and their parameters per joint
(:mod:`.targets`), the estimate from measured kinematics (:mod:`.estimate`, 5.10-5.13, 6.1),
the fit of model (3.5) with standard errors (:mod:`.fit`, 6.4), the energy check
(:mod:`.energy`, 7.9), and the friction table and parameters JSON (:mod:`.io`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

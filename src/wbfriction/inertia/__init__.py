"""The inertia model: identified together with the friction from the logs' torques (thesis 2.4, ch. 8;
:mod:`.regressor`, :mod:`.least_squares`, :mod:`.consistency`, :mod:`.identification`), the loop
that re-estimates the friction with it (:mod:`.closed_loop`), the sensitivity of the estimate to
inertia errors (:mod:`.sensitivity`, 7.2), the corrected URDF (:mod:`.urdf`) and the
identification JSON (:mod:`.io`); the identified limbs kept only where held-out torques are
predicted better (:mod:`.validation`); solvers' stopping messages in words (:mod:`.solver`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

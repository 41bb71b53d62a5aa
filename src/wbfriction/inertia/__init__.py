"""The inertia model: identified together with the friction from the logs' torques (thesis 2.4, ch. 8;
:mod:`.identification`, from the log's samples (:mod:`.samples`), the regression's parameters and rows
(:mod:`.rows`, :mod:`.regressor`) compressed as they are built (:mod:`.system`, :mod:`.least_squares`), the
given model's best friction (:mod:`.best_friction`), the prior and its weight (:mod:`.prior`), every body
physical (:mod:`.consistency`), the parameters the log does not excite (:mod:`.excitation`)), the loop
that re-estimates the friction with it (:mod:`.closed_loop`), the sensitivity of the estimate to
inertia errors (:mod:`.sensitivity`, 7.2), the corrected URDF (:mod:`.urdf`) and the
identification JSON (:mod:`.io`, :mod:`.document`); the identified limbs kept only where held-out torques are
predicted better (:mod:`.held_out`, :mod:`.validation`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

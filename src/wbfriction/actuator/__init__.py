"""PD-driven actuators identified from their logs: armature, friction, encoder offsets and the drivers' delay, each
with its standard error, Cramér-Rao bound and status (issue 55): the momentum balance over windows
(:mod:`.rows`), its least squares and the delay's exact search (:mod:`.solve`), the identification and its verdicts
(:mod:`.identification`), the options (:mod:`.options`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""Fleets (issue 25): many logs of many robots, batched on Dask (:mod:`.batch`), one results dataset
(:mod:`.results`, :mod:`.schema`), and friction trends per joint with a change detector (:mod:`.trends`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""Fitting friction models to an estimate (``tau_f`` -> parameters): one model to one joint (:mod:`.solve`, thesis
6.4), the choice among the models by held-out error (:mod:`.selection`), every joint of an estimate
(:mod:`.joints`), the result (:mod:`.result`) and its verdict (:mod:`.status`), the Cramér-Rao bound
(:mod:`.bound`), terms beyond velocity (:mod:`.terms`, :mod:`.term_selection`), the energy check (:mod:`.energy`,
7.9), predictions (:mod:`.predict`) and the parameters JSON (:mod:`.params_file`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""The robot: a URDF with a free-flyer root, its joint roles and contact frames (:mod:`.robot`,
:mod:`.loading`; how each touches the ground, a registry of contact models: :mod:`.contacts`), the trees re-rooted
at a stance sole (:mod:`.rerooted`), the constrained floating-base dynamics (:mod:`.dynamics`, thesis 4.4-5.12), and
the built-in robots (``robots/``)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

"""Walking reference for a biped: footsteps, ZMP and LIPM centre of mass, swing feet, whole-body IK."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

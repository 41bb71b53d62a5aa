"""Reference motions, the ones the simulators play: a biped's walk (footsteps, ZMP and LIPM centre of mass, swing
feet, whole-body IK: :mod:`.reference`), a quadruped's gaits (:mod:`.quadruped`), joints following finite Fourier
series (:mod:`.fourier`), and a robot standing still on some of its feet while a swing leg follows such series, from
a square inverse kinematics per sample (:mod:`.support_ik`; a biped on one sole: :mod:`.single_support`, a quadruped
on three point feet: :mod:`.tripod_support`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

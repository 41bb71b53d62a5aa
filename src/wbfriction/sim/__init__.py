"""Simulators that write logs in the project's format: the ideal one (thesis 6.1), the realistic one on MuJoCo (thesis
6.2), a fixed-base arm tracking an excitation trajectory (:mod:`.arm`), a PD-driven robot hung with its base fixed
(:mod:`.hung`, on :mod:`.pd_robot`), and sensor models; the engines a rig's motion runs in, as registered kinds
(:mod:`.engines`; the rigs that run them: :mod:`wbfriction.rigs`). The replays of a log's set-points (the rollout
check, an exported MJCF replayed, refined) are :mod:`wbfriction.replay`'s."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

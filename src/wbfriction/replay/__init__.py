"""Replays of a log's set-points, the check of what an identification gives a simulator's user: the rollout of an
identified parameter set on the project's own MuJoCo model of a PD-driven robot (:mod:`.rollout`), the replay of an
exported MJCF as MuJoCo runs that file (:mod:`.mjcf`, the check ``wbfriction rollout`` runs), and that file's
friction and drive values refined on its own tracking error (:mod:`.refine`, ``wbfriction refine``), each checked
before it starts to be a replay of what it scores (:mod:`.feasibility`). It sits above
the simulators (:mod:`wbfriction.sim`) and the exports (:mod:`wbfriction.export`), both of which it runs."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
"""Names of :mod:`wbfriction.replay`, imported on first use (:func:`lazy_loader.attach_stub`)."""

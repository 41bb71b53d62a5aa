"""Exports of the identified friction and armature to where users simulate: the mapping of model
(3.5) to simulator fields (:mod:`.mapping`), one export target per file format (:mod:`.target`: one writer
signature), chosen by the output's suffix (:mod:`.registry`, where new formats plug in): the URDF's
``<dynamics>`` (:mod:`.urdf`), a MuJoCo model (:mod:`.mjcf`) and an Isaac Lab actuator dictionary as YAML
(:mod:`.isaac`); a PD-driven robot's motor drivers (gains, torque limits, delay, encoder offsets) where each holds
them (:mod:`.drive`)."""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)

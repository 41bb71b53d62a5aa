"""A robot's set-up, as registered kinds (:class:`Rig`): a fixed-base arm, a hung PD-driven robot, a biped on its
soles, a quadruped on point feet, and any a program registers (:func:`register_rig`). :func:`rig_for` decides a
robot's rig once; ``simulate``, ``excite``, ``identify`` and ``demo`` ask it. Nothing heavy is imported until an
operation runs."""

from wbfriction.rigs.base import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.rigs.registry import register_rig, rig_for, rigs, unregister_rig

__all__ = ["DemoOutput", "DesignOutput", "Rig", "RigProgress", "SimulationOutput", "register_rig", "rig_for", "rigs",
           "unregister_rig"]

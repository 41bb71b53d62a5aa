"""The simulators ``wbfriction simulate`` runs, as registered kinds (:class:`SimulatorKind`): the built-in ones (a
walking quadruped, a hung PD-driven robot, an arm, a walk ideal or on MuJoCo) and any a program registers
(:func:`register_simulator`). Nothing heavy is imported until a simulator runs."""

from wbfriction.sim.simulators.base import SimulationOutput, SimulationProgress, SimulatorKind
from wbfriction.sim.simulators.registry import (
    register_simulator,
    simulator_for,
    simulator_names,
    simulators,
    unregister_simulator,
)

__all__ = ["SimulationOutput", "SimulationProgress", "SimulatorKind", "register_simulator", "simulator_for",
           "simulator_names", "simulators", "unregister_simulator"]

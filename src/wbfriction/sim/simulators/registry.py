"""The simulators ``wbfriction simulate`` knows, and the one a robot runs in: every run asks the registry.

Five are built in, tried in this order: a robot on point feet walks as a quadruped (``quadruped``,
:mod:`.quadruped`), a PD-driven one hangs (``hung``), a fixed base is an arm tracking an excitation (``arm``,
:mod:`.fixed_base`), and the rest walks in the simulator ``--simulator`` names (``ideal`` or ``mujoco``,
:mod:`.walks`). Another is one call away::

    from wbfriction.sim.simulators import SimulationOutput, SimulatorKind, register_simulator

    class ToyArm(SimulatorKind):
        name, options, precedence = "toy-arm", ("simulator", "duration"), 25
        def claims(self, robot, actuator, simulator):
            return simulator == self.name and not robot.floating_base
        def run(self, robot, values, friction, progress):
            ...
            return SimulationOutput(table=table, summary=f"{table.num_rows} samples")

    register_simulator(ToyArm())

after which ``wbfriction simulate --simulator toy-arm`` (run in that process) runs it, and ``--simulator`` takes
its name. The registry imports nothing heavy: the command line reads the names as it is loaded.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry
from wbfriction.sim.simulators.base import SimulatorKind
from wbfriction.sim.simulators.fixed_base import ArmKind, HungKind
from wbfriction.sim.simulators.quadruped import QuadrupedKind
from wbfriction.sim.simulators.walks import IdealWalk, MujocoWalk

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot

SIMULATORS: Registry[SimulatorKind] = Registry("simulator", precedence=lambda k: k.precedence)
"""The registered simulators, in precedence order."""


def register_simulator(kind: SimulatorKind) -> SimulatorKind:
    """Add ``kind`` to the simulators every ``simulate`` asks, at its
    :attr:`~wbfriction.sim.simulators.base.SimulatorKind.precedence`. Returns it.

    Raises:
        ValueError: a simulator of that name, or of that precedence, registered already (naming it).
    """
    return SIMULATORS.add(kind)


def unregister_simulator(name: str) -> SimulatorKind:
    """Remove the simulator named ``name``; returns it.

    Raises:
        ValueError: no simulator of that name.
    """
    return SIMULATORS.remove(name)


def simulators() -> tuple[SimulatorKind, ...]:
    """The registered simulators, in precedence order."""
    return SIMULATORS.kinds()


def simulator_names() -> tuple[str, ...]:
    """The names ``--simulator`` takes: the registered simulators it chooses
    (:attr:`~wbfriction.sim.simulators.base.SimulatorKind.chosen`), in precedence order (``ideal``, ``mujoco``
    built in)."""
    return tuple(k.name for k in SIMULATORS if k.chosen)


def simulator_for(robot: Robot, actuator: str | None, simulator: str) -> SimulatorKind:
    """The simulator that runs ``robot`` driven by ``actuator`` (``torque``, ``pd``, or None: not given) with
    ``--simulator`` ``simulator``: the registered one of lowest precedence that
    :meth:`~wbfriction.sim.simulators.base.SimulatorKind.claims` it.

    Raises:
        InputError: none claims it, naming the robot and the simulators ``--simulator`` takes.
    """
    found = next((k for k in SIMULATORS if k.claims(robot, actuator, simulator)), None)
    if found is None:
        raise InputError(f"--simulator {simulator}: no simulator runs robot '{robot.name}' so (--simulator takes "
                         f"{', '.join(simulator_names())})")
    return found


for _builtin in (QuadrupedKind(), HungKind(), ArmKind(), IdealWalk(), MujocoWalk()):
    register_simulator(_builtin)

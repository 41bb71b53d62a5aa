"""The rigs every command asks, and the one a robot is on: :func:`rig_for` decides it once, from what the robot
declares (a floating base, its contact models' capabilities, a ``[pd]`` table) and how it is driven.

Four are built in, asked in this order: a quadruped on point feet (``quadruped``, :mod:`.quadruped`), a hung
PD-driven robot (``hung``, :mod:`.hung`), a fixed-base arm (``arm``, :mod:`.arm`) and a biped on its soles
(``biped``, :mod:`.biped`). Another is one call away (``docs/extending.md``)::

    from wbfriction.rigs import Rig, register_rig

    class HungArm(Rig):
        name, precedence = "hung-arm", 15
        simulation = HungArmSimulation   # a frozen dataclass of wbfriction.options.option fields
        def claims(self, robot, actuator):
            return not robot.floating_base and robot.name.startswith("lab-")
        def simulate(self, robot, options, engine, engine_options, progress):
            ...

    register_rig(HungArm())

The registry imports nothing heavy: the command line reads the rigs' options as it is loaded.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry
from wbfriction.rigs.arm import ArmRig
from wbfriction.rigs.base import Rig
from wbfriction.rigs.biped import BipedRig
from wbfriction.rigs.hung import HungRig
from wbfriction.rigs.quadruped import QuadrupedRig

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot

ENTRY_POINT_GROUP = "wbfriction.rigs"
"""The entry-point group under which an installed package advertises its rigs: each entry's name is the rig's and its
object a :class:`~wbfriction.rigs.base.Rig` (an instance, or a class called without arguments)."""

RIGS: Registry[Rig] = Registry("rig", precedence=lambda r: r.precedence, entry_points=ENTRY_POINT_GROUP)
"""The registered rigs, in precedence order: the built-in ones, those registered, those installed packages advertise
(read, and each loaded, the first time a robot's rig is decided, since one may come first; one that does not load is
left out with one :class:`~wbfriction.registry.PluginWarning` line, the others asked)."""


register_rig = RIGS.register
"""Add a rig (a :class:`~wbfriction.rigs.base.Rig`) to those every command asks, at its
:attr:`~wbfriction.rigs.base.Rig.precedence`; returns it (ValueError: a rig of that name, or of that precedence,
registered already, naming it)."""
unregister_rig = RIGS.unregister
"""Remove the rig of a name; returns it (ValueError: none of that name)."""
rigs = RIGS.kinds
"""The registered rigs, in precedence order."""


def rig_for(robot: Robot, actuator: str | None = None) -> Rig:
    """The rig ``robot`` driven by ``actuator`` (``--actuator``: ``torque``, ``pd``, or None: not given) is on: the
    registered one of lowest precedence that :meth:`~wbfriction.rigs.base.Rig.claims` it.

    Raises:
        InputError: none claims it, naming the robot, what it stands on and the rigs registered.
    """
    found = next((r for r in RIGS if r.claims(robot, actuator)), None)
    if found is None:
        base = f"a floating base on {robot.stands_on}" if robot.floating_base else "a fixed base"
        raise InputError(f"robot '{robot.name}' ({base}{', --actuator ' + actuator if actuator else ''}) is on no "
                         f"registered rig ({RIGS.listed()})")
    return found


for _builtin in (QuadrupedRig(), HungRig(), ArmRig(), BipedRig()):
    register_rig(_builtin)

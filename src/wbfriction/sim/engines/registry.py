"""The engines every rig's simulation asks: the project's ideal simulator and MuJoCo built in, any a program
registers (:func:`register_engine`) or an installed package advertises (under :data:`ENTRY_POINT_GROUP`,
``wbfriction.engines``) among them in precedence order."""

from __future__ import annotations

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry
from wbfriction.sim.engines.base import Engine
from wbfriction.sim.engines.ideal import IdealEngine
from wbfriction.sim.engines.mujoco import MujocoEngine

ENTRY_POINT_GROUP = "wbfriction.engines"
"""The entry-point group under which an installed package advertises its engines: each entry's name is the engine's
(what ``--simulator`` names) and its object an :class:`~wbfriction.sim.engines.base.Engine` (an instance, or a class
called without arguments)."""

ENGINES: Registry[Engine] = Registry("engine", precedence=lambda e: e.precedence, unknown=InputError,
                                     entry_points=ENTRY_POINT_GROUP)
"""The registered engines, in precedence order: the built-in ones, those registered, those installed packages
advertise (each loaded when ``--simulator`` names it, or every one when a rig's engines are asked for: one that does
not load is left out with one :class:`~wbfriction.registry.PluginWarning` line, the others run). The command line's
help, read as it starts, lists those registered then (:meth:`~wbfriction.registry.Registry.registered`): no entry
point read."""


engine_names = ENGINES.names
"""The names ``--simulator`` takes, in precedence order."""
engine_of = ENGINES.get
"""The engine ``--simulator`` names (:class:`~wbfriction.exceptions.InputError`: none of that name, listing those
registered)."""
engines = ENGINES.kinds
"""The registered engines, in precedence order."""
register_engine = ENGINES.register
"""Add an engine (an :class:`~wbfriction.sim.engines.base.Engine`) to those ``--simulator`` takes, at its precedence;
returns it (ValueError: an engine of that name, or of that precedence, registered already)."""
unregister_engine = ENGINES.unregister
"""Remove the engine of a name; returns it (ValueError: none of that name)."""


for _builtin in (IdealEngine(), MujocoEngine()):
    register_engine(_builtin)

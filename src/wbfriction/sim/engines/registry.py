"""The engines every rig's simulation asks: the project's ideal simulator and MuJoCo built in, any a program
registers (:func:`register_engine`) after them in precedence order."""

from __future__ import annotations

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry
from wbfriction.sim.engines.base import Engine
from wbfriction.sim.engines.ideal import IdealEngine
from wbfriction.sim.engines.mujoco import MujocoEngine

ENGINES: Registry[Engine] = Registry("engine", precedence=lambda e: e.precedence, unknown=InputError)
"""The registered engines, in precedence order."""


def register_engine(engine: Engine) -> Engine:
    """Add ``engine`` to those ``--simulator`` takes, at its precedence. Returns it.

    Raises:
        ValueError: an engine of that name, or of that precedence, registered already.
    """
    return ENGINES.register(engine)


def unregister_engine(name: str) -> Engine:
    """Remove the engine named ``name``; returns it.

    Raises:
        ValueError: no engine of that name.
    """
    return ENGINES.unregister(name)


def engines() -> tuple[Engine, ...]:
    """The registered engines, in precedence order."""
    return ENGINES.kinds()


def engine_names() -> tuple[str, ...]:
    """The names ``--simulator`` takes, in precedence order."""
    return ENGINES.names()


def engine_of(name: str) -> Engine:
    """The engine ``--simulator`` ``name`` names.

    Raises:
        InputError: none of that name, listing those registered.
    """
    return ENGINES.get(name)


for _builtin in (IdealEngine(), MujocoEngine()):
    register_engine(_builtin)

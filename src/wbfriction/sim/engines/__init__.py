"""The engines the rigs' motions run in (:class:`Engine`): the project's ideal simulator and MuJoCo built in, any a
program registers (:func:`register_engine`). Nothing heavy is imported until an engine runs."""

from wbfriction.sim.engines.base import Engine, WalkSettings
from wbfriction.sim.engines.registry import engine_names, engine_of, engines, register_engine, unregister_engine

__all__ = ["Engine", "WalkSettings", "engine_names", "engine_of", "engines", "register_engine", "unregister_engine"]

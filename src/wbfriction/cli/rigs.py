"""The options of a robot's rig on the command line (:mod:`wbfriction.rigs`): those given refused where the rig's
operation does not read them, the others, and any ``--rig-option NAME=VALUE``, built into its typed options."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

import typer

from wbfriction.cli.common import given_options, refuse_options, refuse_unread
from wbfriction.exceptions import InputError, OptionError
from wbfriction.options import motion_names, option_names, parse_option, read_options
from wbfriction.sim.engines.registry import ENGINES

RigOptionOpt = typer.Option([], "--rig-option", metavar="NAME=VALUE",
                            help="An option of the robot's rig by its name, for one no flag spells (a rig a program "
                                 "registered brings its own; repeat for each): e.g. --rig-option gait=walk.")


def rig_options(ctx: typer.Context, values: Mapping[str, Any], classes: tuple[type | None, ...], mode: str,
                shared: Collection[str], rig_option: list[str], play: Any = None,
                engine: bool = False) -> tuple[Any, ...]:
    """Each of ``classes`` (an operation's options dataclasses; None: none) built from the options the command line
    gave (``values``: the command's parameters by name) and the ``--rig-option`` texts, after refusing any option
    given that none of them reads (nor ``shared``, ``rig_option`` among them, nor, with an ``engine``,
    ``--simulator``), and, where a table is ``play``-ed, those that shape the motion.

    Raises:
        InputError: an option the operation does not read (naming ``mode`` and what it takes); a ``--rig-option``
            not of its options, or not of its type, or (with ``play``) one that shapes the motion.
        OptionError: a value outside its range.
    """
    takes = {name for cls in classes for name in option_names(cls)}
    refuse_options(ctx, mode, (takes - set(shared)) | ({"simulator"} if engine else set()), shared)
    if play is not None:
        refuse_unread(ctx, f"the set-points played ({play.name}) fix the motion",
                      [n for cls in classes for n in motion_names(cls)], "motion")
    given = {name: tuple(values[name]) if isinstance(values[name], list) else values[name]
             for name in given_options(ctx) if name in takes}
    parsed = dict(parse_option(tuple(c for c in classes if c is not None), text) for text in rig_option)
    motion = {n for cls in classes for n in motion_names(cls)}
    if play is not None and motion & parsed.keys():
        name = sorted(motion & parsed.keys())[0]
        raise InputError(f"--rig-option {name}: the set-points played ({play.name}) fix the motion: it takes no "
                         f"motion option")
    given.update(parsed)
    return tuple(None if cls is None else read_options(cls, given) for cls in classes)


def check_engine(simulator: str | None) -> None:
    """Refuse, before the robot is loaded, a ``--simulator`` that names no registered engine (None: not given); an
    engine an installed package advertises is loaded, so that one that does not load fails here.

    Raises:
        OptionError: listing the engines registered.
        EntryPointError: the engine's entry point gives none (:class:`~wbfriction.registry.EntryPointError`: one
            line naming it and its package).
    """
    if simulator is None:
        return
    if simulator not in ENGINES:
        raise OptionError("--simulator", simulator, f"one of {', '.join(ENGINES.names())}")
    ENGINES.get(simulator)

"""Exceptions raised by wbfriction.

Every error the user can fix by changing an input (a log, a URDF, a robot
configuration, a command-line option) is an :class:`InputError`; the CLI prints
its one-line message and exits with status 2.
"""

from __future__ import annotations


class WbfrictionError(Exception):
    """Base class of every exception raised on purpose by wbfriction."""


class InputError(WbfrictionError, ValueError):
    """Bad user input: the message names the file, column, row or option at fault."""


class ModelError(WbfrictionError):
    """A robot model that cannot be used by an algorithm (e.g. an unsupported joint type)."""


class SimulationError(WbfrictionError):
    """A simulation that cannot go on (e.g. the robot fell): the message says when and why."""

"""Exceptions raised by wbfriction.

Every error the user can fix by changing an input (a log, a URDF, a robot
configuration, a command-line option) is an :class:`InputError`; the CLI prints
its one-line message and exits with status 2. Where one column of a table is at fault,
the error is a :class:`ColumnError` that carries the file, the column and the row.
"""

from __future__ import annotations

__all__ = ["WbfrictionError", "InputError", "ColumnError", "ModelError", "SimulationError"]


class WbfrictionError(Exception):
    """Base class of every exception raised on purpose by wbfriction."""


class InputError(WbfrictionError, ValueError):
    """Bad user input: the message names the file, column, row or option at fault."""


class ColumnError(InputError):
    """A column of a log or table at fault: missing, not numeric, non-finite, out of range.

    Attributes:
        source: the file (or other source) the table came from.
        column: the column's name, e.g. ``q.leg_left_4_joint``.
        row: the first row at fault, counted from the file's first data row (0), or None
            when the whole column is (missing, not numeric).
        problem: what is wrong, as the message says it after ``source: ``.
    """

    def __init__(self, source: str, column: str, row: int | None, problem: str):
        self.source = source
        self.column = column
        self.row = row
        self.problem = problem
        super().__init__(f"{source}: {problem}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.source, self.column, self.row, self.problem))


class ModelError(WbfrictionError):
    """A robot model that cannot be used by an algorithm (e.g. an unsupported joint type)."""


class SimulationError(WbfrictionError):
    """A simulation that cannot go on (e.g. the robot fell): the message says when and why."""

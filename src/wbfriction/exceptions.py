"""Exceptions raised by wbfriction.

Every error the user can fix by changing an input (a log, a URDF, a robot
configuration, a command-line option) is an :class:`InputError`; the CLI prints
its one-line message and exits with status 2. Where one column of a table is at fault,
the error is a :class:`ColumnError` that carries the file, the column and the row. An output that
cannot be written (a full disk, a read-only folder, a path under a file) is an :class:`OutputError`, and a
Dask cluster that cannot go on (its scheduler gone) a :class:`ClusterError`: the environment, not the input;
the CLI prints their one line and exits with status 1 (each class's :attr:`~WbfrictionError.exit_status`).
"""

from __future__ import annotations

__all__ = ["WbfrictionError", "InputError", "OptionError", "ColumnError", "OutputError", "ClusterError", "ModelError",
           "SimulationError"]


class WbfrictionError(Exception):
    """Base class of every exception raised on purpose by wbfriction.

    Attributes:
        exit_status: the command's exit status when it ends with this error (2: the input; 1: the environment).
    """

    exit_status = 2


class InputError(WbfrictionError, ValueError):
    """Bad user input: the message names the file, column, row or option at fault."""


class OptionError(InputError):
    """An option's value refused, before any work: one of its choices or its range expected.

    Attributes:
        option: the option as the command line spells it, e.g. ``--diff`` (the options field ``diff``).
        value: the value given.
        expected: what the option takes, e.g. ``one of central, backward, savgol``.
    """

    def __init__(self, option: str, value: object, expected: str):
        self.option = option
        self.value = value
        self.expected = expected
        super().__init__(f"{option} must be {expected}, got {value!r}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.option, self.value, self.expected))


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


class OutputError(WbfrictionError):
    """An output that cannot be written, because of where it is written (the environment, not the
    input): the disk or the quota full, a file larger than the process may write (``ulimit -f``), a
    folder that is read-only or not writable, a path under a file. Nothing was written: a previous
    output at ``path`` is as it was. The message is ``{path}: cannot be written: [Errno N] reason``
    and says whether a previous file is kept.

    Attributes:
        path: the output (the file the user named, not the temporary file written first).
        errno: the OS's error number (``errno.ENOSPC``, ``errno.EFBIG``, ...), or None when the
            library that failed did not say.
        reason: the OS's reason, e.g. ``[Errno 28] No space left on device``.
        kept: a previous file at ``path`` is kept (False: there was none).
    """

    exit_status = 1

    def __init__(self, path: str, errno: int | None, reason: str, kept: bool = False):
        self.path = path
        self.errno = errno
        self.reason = reason
        self.kept = kept
        outcome = "the previous file is kept" if kept else "nothing written"
        super().__init__(f"{path}: cannot be written: {reason} ({outcome})")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.path, self.errno, self.reason, self.kept))


class ClusterError(WbfrictionError):
    """A Dask cluster that cannot run the rest of a batch (its scheduler went away): what was done is kept, the
    message says how much is left; the next run goes on from there."""

    exit_status = 1


class ModelError(WbfrictionError):
    """A robot model that cannot be used by an algorithm (e.g. an unsupported joint type)."""


class SimulationError(WbfrictionError):
    """A simulation that cannot go on (e.g. the robot fell): the message says when and why."""

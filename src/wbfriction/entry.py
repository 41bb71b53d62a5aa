"""The command's entry point: the signals that end a command are handled before anything else
is imported, then the command line (:mod:`wbfriction.cli`) runs.

Ctrl-C (SIGINT), SIGTERM and SIGHUP end the command with status 128 + the signal's number
(130, 143, 129: the shell's convention), never 0, and one line on standard error
(``interrupted (SIGINT)``), wherever they arrive: while the libraries are imported (seconds),
while a log is read, estimated or written. The handler raises :class:`Interrupted` in the main
thread; on its way up it removes a partly written output (the previous one stays:
:func:`wbfriction.logs.tables.write_atomic`) and kills the worker processes
(:func:`wbfriction.workers.process_pool`). Code that swallows the exception cannot turn the
status into 0; one raised inside an object's ``__del__`` (where Python could only print it) is
sent again. A second signal while the command ends ends it at once.

Before the first line of Python runs (the interpreter's start, ~40 ms) a Ctrl-C is Python's own.

This module imports only the standard library at its top: the console script and
``python -m wbfriction`` reach :func:`main` before NumPy, Pinocchio or SciPy are loaded (provided
the package's ``__init__`` imports nothing heavy).
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from types import FrameType
from typing import NoReturn

ENDING_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""The signals that end a command (SIGHUP: its terminal closed)."""


class Interrupted(BaseException):
    """A signal ended the command. A :class:`BaseException`, like :class:`KeyboardInterrupt`, so
    that no ``except Exception`` stops it; not a KeyboardInterrupt, so that the command-line
    library does not turn it into a return value.

    Attributes:
        signum: the signal's number.
    """

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


_received: list[int] = []
"""The ending signals received, in order."""
_leaving = [False]
"""Set once the command has returned or raised: a signal then ends the process at once."""
_said = [False]


def _say(signum: int) -> None:
    """The one line on standard error (once)."""
    if _said[0]:
        return
    _said[0] = True
    try:
        sys.stderr.write(f"interrupted ({signal.Signals(signum).name})\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed standard error
        pass


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    if _leaving[0]:
        _say(signum)
        os._exit(128 + signum)
    raise Interrupted(signum)


def _unraisable(hook: sys.UnraisableHookArgs) -> None:
    """An interruption raised where it cannot go on (an object's ``__del__``, a callback of the
    garbage collector): no traceback; the signal is sent again to this (the main) thread in a
    moment, from another thread (sent from here, it would be handled here, and lost again)."""
    if isinstance(hook.exc_value, Interrupted):
        again = threading.Timer(0.01, signal.pthread_kill, (threading.get_ident(), hook.exc_value.signum))
        again.daemon = True
        again.start()
        return
    sys.__unraisablehook__(hook)


def main() -> NoReturn:
    """Run the command line with the ending signals handled (see the module's description); exit
    with the command's status, or 128 + the signal's number if one ended it."""
    for sig in ENDING_SIGNALS:
        signal.signal(sig, _on_signal)
    sys.unraisablehook = _unraisable
    status: int | str | None = 0
    try:
        from wbfriction.cli import main as cli_main

        cli_main()
    except Interrupted:
        _leaving[0] = True
    except SystemExit as exc:
        _leaving[0] = True
        status = exc.code
    except BaseException:
        _leaving[0] = True
        if not _received:  # an error of its own: its traceback
            raise
    _leaving[0] = True
    if _received:
        gc.collect()  # close what the unwinding left suspended (a generator holding a process pool)
        _say(_received[0])
        sys.exit(128 + _received[0])
    sys.exit(status)

"""A command's progress on standard error, stage by stage (:class:`Stages`): on a terminal a bar per stage with
its share done, the time it has run and the time left (Rich, gone when the command ends); elsewhere (a pipe, a file,
CI) one plain line as each stage ends, with what it did and how long it took (``fit: 12 joints in 81.2 s``): no
carriage return, no colour, at most :data:`WIDTH` characters.

A stage is what the library announces through its progress callbacks (:mod:`wbfriction.progress`): a
:data:`~wbfriction.progress.StageProgress` starts one named stage (``Stages(label)``), a
:data:`~wbfriction.progress.Steps` one of a known number of items (:meth:`Stages.steps`, whose
:data:`~wbfriction.progress.Progress` it returns counts them, as the items are done: by a worker process, the
items it has finished). A stage ends as the next starts, or as the command's block ends; a command that fails
prints no line for the stage it failed in (the error says what happened). Results go to standard output, untouched.
"""

from __future__ import annotations

import time
from types import TracebackType

from rich.console import Console
from rich.progress import (
    BarColumn,
    SpinnerColumn,
    TaskID,
    TaskProgressColumn,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.progress import Progress as Bars

from wbfriction.progress import Progress

WIDTH = 100
"""The most characters of a stage's line (and of its label on a bar, less its columns)."""
LABEL = 48
"""The most characters of a stage's label beside its bar."""


def shortened(text: str, width: int) -> str:
    """``text`` cut to ``width`` characters, ``...`` at its end where cut."""
    return text if len(text) <= width else text[:width - 3].rstrip() + "..."


def stage_line(label: str, seconds: float, done: int | None = None, unit: str = "") -> str:
    """A stage's line when it ends (off a terminal): ``fit: 12 joints in 81.2 s``, or ``label: 3.4 s`` for a stage
    of no counted items; at most :data:`WIDTH` characters (the label shortened)."""
    tail = f"{seconds:.1f} s" if done is None else f"{done} {unit} in {seconds:.1f} s".replace("  ", " ")
    return f"{shortened(label, WIDTH - len(tail) - 2)}: {tail}"


class Stages:
    """The progress of one command's stages, shown on ``console`` (the command line's standard error): bars on a
    terminal, one line per stage ended elsewhere (module docstring). Used as a context manager around the work;
    called with a label it is a :data:`~wbfriction.progress.StageProgress`, its :meth:`steps` a
    :data:`~wbfriction.progress.Steps`."""

    def __init__(self, console: Console) -> None:
        self.console = console
        self.bars: Bars | None = None
        self.task: TaskID | None = None
        self.label: str | None = None
        self.unit = ""
        self.counted = False
        self.done = 0
        self.started = 0.0

    def __enter__(self) -> Stages:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> None:
        self.close(ended=kind is None)

    def __call__(self, label: str) -> None:
        """Start a stage called ``label`` of no counted items (ending the one before)."""
        self._start(label, None, "")

    def steps(self, label: str, total: int, unit: str = "") -> Progress:
        """Start a stage called ``label`` of ``total`` items of ``unit`` (``joints``, ``samples``), ending the one
        before; the callable returned is told of the items done (their number since its last call)."""
        self._start(label, max(int(total), 0), unit)
        return self.advance

    def advance(self, n: int) -> None:
        """``n`` more items of the current stage done."""
        self.done += n
        if self.bars is not None and self.task is not None:
            self.bars.advance(self.task, n)

    def end(self) -> None:
        """End the current stage (if any): its line off a terminal, its bar taken away on one."""
        if self.label is None:
            return
        if self.bars is not None and self.task is not None:
            self.bars.remove_task(self.task)
            self.task = None
        else:
            line = stage_line(self.label, time.perf_counter() - self.started, self.done if self.counted else None,
                              self.unit)
            self.console.print(line, markup=False, highlight=False, soft_wrap=True, emoji=False)
        self.label = None

    def close(self, ended: bool = True) -> None:
        """End the current stage (``ended``: it finished; else it failed and says nothing) and the bars."""
        if not ended:
            self.label = None
        self.end()
        if self.bars is not None:
            self.bars.stop()
            self.bars = None

    def _start(self, label: str, total: int | None, unit: str) -> None:
        self.end()
        self.label, self.unit, self.counted, self.done = label, unit, total is not None, 0
        self.started = time.perf_counter()
        if not self.console.is_terminal:
            return
        if self.bars is None:
            self.bars = Bars(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(), TaskProgressColumn(),
                             TextColumn("elapsed"), TimeElapsedColumn(), TextColumn("left"), TimeRemainingColumn(),
                             console=self.console, transient=True)
            self.bars.start()
        self.task = self.bars.add_task(shortened(label, LABEL), total=total)

"""Progress reporting of long computations: the callable types the library takes (:data:`Progress`,
:data:`StageProgress`, :data:`Steps`; the command line shows them, :mod:`wbfriction.cli.stages`), and a counting
helper."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TypeAlias

Progress: TypeAlias = Callable[[int], None]
"""Called with the number of samples (or rows) done since the last call."""

StageProgress: TypeAlias = Callable[[str], None]
"""Called with a short label as each stage of a long job starts."""

Steps: TypeAlias = Callable[[str, int, str], Progress]
"""Called as a stage of a known number of items starts, with its label, that number and the items' unit (``joints``,
``samples``); returns the :data:`Progress` to call with the items done since its last call (where workers do the
items, as each finishes). The stage ends as the next one starts, or the job ends."""


def counted(n: int, progress: Progress | None, every: int = 500) -> Iterator[int]:
    """``range(n)`` that calls ``progress(m)`` with the samples done every ``every`` samples,
    and with the remainder at the end (never if ``progress`` is None)."""
    for k in range(n):
        yield k
        if progress is not None and (k + 1) % every == 0:
            progress(every)
    if progress is not None and n % every:
        progress(n % every)

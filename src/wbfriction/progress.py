"""Progress reporting of long computations: the callable types the library takes, and a counting helper."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TypeAlias

Progress: TypeAlias = Callable[[int], None]
"""Called with the number of samples (or rows) done since the last call."""

StageProgress: TypeAlias = Callable[[str], None]
"""Called with a short label as each stage of a long job starts."""


def counted(n: int, progress: Progress | None, every: int = 500) -> Iterator[int]:
    """``range(n)`` that calls ``progress(m)`` with the samples done every ``every`` samples,
    and with the remainder at the end (never if ``progress`` is None)."""
    for k in range(n):
        yield k
        if progress is not None and (k + 1) % every == 0:
            progress(every)
    if progress is not None and n % every:
        progress(n % every)

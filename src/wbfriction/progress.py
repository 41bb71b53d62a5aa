"""Progress reporting of long per-sample loops."""

from __future__ import annotations

from collections.abc import Callable, Iterator


def counted(n: int, progress: Callable[[int], None] | None, every: int = 500) -> Iterator[int]:
    """``range(n)`` that calls ``progress(m)`` with the samples done every ``every`` samples,
    and with the remainder at the end (never if ``progress`` is None)."""
    for k in range(n):
        yield k
        if progress is not None and (k + 1) % every == 0:
            progress(every)
    if progress is not None and n % every:
        progress(n % every)

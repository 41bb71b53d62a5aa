"""Index arrays for per-sample loops (the walking IK, the simulators)."""

from __future__ import annotations

import numpy as np


def as_slice(index: np.ndarray | list[int]) -> slice | np.ndarray:
    """``index`` as a slice if it is a run of consecutive indices, else as an array.

    Indexing with a slice gives a view, several times cheaper than fancy indexing with
    the same indices: it matters in loops that run a thousand times per simulated second.
    """
    index = np.asarray(index, dtype=int)
    if index.size and np.array_equal(index, np.arange(index[0], index[0] + index.size)):
        return slice(int(index[0]), int(index[0]) + index.size)
    return index

"""The runs of a log: recordings that a long gap in the stamps splits apart (the KUKA's runs 1 and 2, 29 minutes
apart in one log), found once for every reader (the report's and the prediction's figures, the table's metadata,
the duration printed).

A step is a gap between runs when it is longer than :data:`GAP_STEPS` median steps and than :data:`GAP_SHARE` of
the log's recorded time (the steps that are not gaps): a dropped packet in a walk is no new run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

GAP_STEPS = 10.0
"""A time step longer than this many median steps may be a gap between recordings, not recorded time."""
GAP_SHARE = 0.05
"""... and is one when it is also longer than this share of the log's recorded time."""


@dataclass(frozen=True)
class Run:
    """One run of a log: its rows ``rows`` (a slice of the log's samples) and when it starts, ``start`` [s] from the
    log's first sample."""

    rows: slice
    start: float


def log_runs(time: np.ndarray) -> list[Run]:
    """The runs of a log whose stamps are ``time`` (N,) [s], increasing (module docstring): one run without a gap,
    none for an empty log."""
    t = np.asarray(time, dtype=float)
    if t.size == 0:
        return []
    steps = np.diff(t)
    if steps.size == 0:
        return [Run(slice(0, t.size), 0.0)]
    long = steps > GAP_STEPS * float(np.median(steps))
    recorded = float(steps[~long].sum())
    gap = long & (steps > GAP_SHARE * recorded)
    edges = [0, *(np.flatnonzero(gap) + 1).tolist(), t.size]
    return [Run(slice(a, b), float(t[a] - t[0])) for a, b in zip(edges[:-1], edges[1:])]


"""Gross outliers screened out of a fit: samples no friction model should be steered by.

A single torque sample of 1e6 N·m on a valid row (a logger's glitch, a sensor's overflow) drags a
least-squares fit anywhere (an offset of 385 N·m for a true 1 N·m); 1e300 overflows it. Friction
is bounded by the joint's own spread of values: a sample is screened when it lies beyond
:data:`SCREEN_MADS` scaled median absolute deviations (MAD x 1.4826: the standard deviation of
normal data) from the joint's median, and beyond :data:`SCREEN_FLOOR` times the median magnitude
(so that a joint whose friction barely varies keeps its samples). Only gross errors are caught:
anything friction could plausibly be is kept, and the count is reported per joint.
"""

from __future__ import annotations

import numpy as np

SCREEN_MADS = 50.0
"""Scaled median absolute deviations beyond which a sample is screened."""
SCREEN_FLOOR = 5.0
"""...and beyond this many times the median magnitude of the joint's friction."""


def gross_outliers(y: np.ndarray, use: np.ndarray) -> np.ndarray:
    """Samples of ``y`` (N,) [N·m] among ``use`` ((N,) bool) that are gross outliers (module
    docstring): (N,) bool, False outside ``use``; non-finite samples of ``use`` are outliers."""
    y = np.asarray(y, dtype=float)
    out = np.zeros(y.shape, dtype=bool)
    rows = np.flatnonzero(use)
    if rows.size == 0:
        return out
    values = y[rows]
    finite = np.isfinite(values)
    out[rows[~finite]] = True
    if finite.sum() < 3:
        return out
    v = values[finite]
    median = float(np.median(v))
    spread = 1.4826 * float(np.median(np.abs(v - median)))
    limit = max(SCREEN_MADS * spread, SCREEN_FLOOR * float(np.median(np.abs(v))))
    far = np.zeros(values.shape, dtype=bool)
    far[finite] = np.abs(v - median) > limit
    out[rows[far]] = True
    return out

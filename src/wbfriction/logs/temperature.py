"""A log's joint temperatures, screened as they are read (issue 53): units, plausibility and glitches.

A ``temperature.<joint>`` column holds the joint's motor or gear temperature in °C (:mod:`wbfriction.logs.log`).
Friction's temperature term (:mod:`~wbfriction.fit.terms`) and the fleet's trends read it; a value in another
unit, or one glitched sample, would move a fitted slope or a drift without a word. So each column is screened where
it is read, as the torques are:

* **Units and plausibility**: a column whose median lies outside :data:`~wbfriction.logs.options.PLAUSIBLE` (-60
  to 200 °C: a joint's motor or gearbox in use, class H insulation's 180 °C included) is refused, naming the
  column; one in kelvin (a median within :data:`KELVIN`) is told so.
* **Glitches**: a sample outside that range, or departing by more than :data:`GLITCH_STEP` (5 °C) from the
  running median of the :data:`GLITCH_ROWS` samples either side, is no temperature a joint had (a joint's thermal
  time constant is seconds to minutes; a sensor's quantisation is 1 °C or finer): it becomes NaN, not used by any
  fit, and a warning names the column, the rows and the first value. A column where more than
  :data:`GLITCH_SHARE` of the samples are such is not a temperature and is refused.

The screening is the same on every chunk of a log read in pieces (a sample's neighbours within the chunk's rows).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from wbfriction.exceptions import ColumnError
from wbfriction.logs.options import PLAUSIBLE

KELVIN = (200.0, 500.0)
"""A column whose median lies here, above :data:`PLAUSIBLE`, is in kelvin (-73 to 227 °C)."""
GLITCH_ROWS = 4
"""Samples either side of a sample whose median it is compared with."""
GLITCH_STEP = 5.0
"""How far [°C] a sample may depart from its neighbours' median: more than a joint warms or cools over a few
samples, more than a sensor's quantisation (1 °C or finer)."""
GLITCH_SHARE = 0.05
"""A column with more glitches than this share of its samples is refused: a signal, not a glitch."""


def _running_median(x: np.ndarray) -> np.ndarray:
    """The median of each sample's :data:`GLITCH_ROWS` neighbours either side and itself (mirrored at the ends: a
    glitch at an end is not its own neighbours)."""
    from scipy.ndimage import median_filter
    return median_filter(x, size=2 * GLITCH_ROWS + 1, mode="mirror")


def glitches(T: np.ndarray) -> np.ndarray:
    """(N,) bool: the samples of one temperature series ``T`` (N,) [°C] that are glitches (module docstring); NaN
    samples are not, and are left out of their neighbours' medians."""
    T = np.asarray(T, dtype=float)
    out = np.zeros(T.shape, dtype=bool)
    finite = np.flatnonzero(np.isfinite(T))
    if finite.size == 0:
        return out
    x = T[finite]
    low, high = PLAUSIBLE
    outside = (x < low) | (x > high)
    # the outliers outside the range do not pull the medians
    median = _running_median(np.where(outside, np.median(x[~outside]) if (~outside).any() else 0.0, x))
    out[finite] = outside | (np.abs(x - median) > GLITCH_STEP)
    return out


def screen_temperature(T: np.ndarray, joints: Sequence[str], source: str, first_row: int = 0
                       ) -> tuple[np.ndarray, tuple[str, ...]]:
    """A log's temperature columns screened (module docstring).

    Args:
        T: (N, n) the ``temperature.<joint>`` columns [°C], NaN where not logged.
        joints: (n,) the joints' names, for the messages.
        source: the log's name; first_row: the file row of ``T``'s first row.

    Returns:
        ``(T, warnings)``: a copy with the glitches NaN, and one line per column that had any (its rows and first
        value).

    Raises:
        ColumnError: a column whose median is not a plausible joint temperature in °C (kelvin said), or more than
            :data:`GLITCH_SHARE` of whose samples are glitches, naming the column and its first bad row.
    """
    T = np.array(T, dtype=float, copy=True)
    warnings: list[str] = []
    low, high = PLAUSIBLE
    for i, joint in enumerate(joints):
        column = f"temperature.{joint}"
        x = T[:, i]
        finite = np.isfinite(x)
        if not finite.any():
            continue
        median = float(np.median(x[finite]))
        if not low <= median <= high:
            row = first_row + int(np.flatnonzero(finite)[0])
            hint = (": kelvin? the log's temperatures are read in °C (subtract 273.15)" if KELVIN[0] <= median
                    <= KELVIN[1] else "")
            raise ColumnError(source, column, row, f"column '{column}' has median {median:.6g}, not a joint's "
                              f"temperature in °C ({low:g} to {high:g} °C){hint}")
        bad = glitches(x)
        if not bad.any():
            continue
        rows = np.flatnonzero(bad)
        first = first_row + int(rows[0])
        if rows.size > GLITCH_SHARE * finite.sum():
            raise ColumnError(source, column, first,
                              f"column '{column}': {rows.size} of {int(finite.sum())} samples depart by more than "
                              f"{GLITCH_STEP:g} °C from their neighbours or lie outside {low:g} to {high:g} °C "
                              f"(row {first}: {x[rows[0]]:.6g}): not a temperature read in °C")
        shown = ", ".join(str(first_row + int(r)) for r in rows[:3]) + (f" and {rows.size - 3} more"
                                                                        if rows.size > 3 else "")
        warnings.append(f"{source}: column '{column}': {rows.size} glitched sample{'s' if rows.size > 1 else ''} "
                        f"left out (row {shown}; {x[rows[0]]:.6g} °C against {np.nanmedian(x):.4g} °C around)")
        T[rows, i] = np.nan
    return T, tuple(warnings)


"""Repeated samples: rows a logger wrote again because it runs faster than the drives update.

A logger ticking every ``P_l`` reads the drives' latest sample at each of its ticks; drives that sample every
``P_d > P_l`` show each of their samples on one or more consecutive rows. A row identical to the previous one in
every column of a stream (every joint's angle, velocity and torque; :func:`repeated_rows`) is not a new
measurement. :func:`find_repeats` finds the runs of repeats, keeps the first row of each distinct sample, and
re-estimates the distinct samples' true times from the runs with the drives' own clock (:func:`fit_drive_clock`):

* a drive sample appears at the first logger tick after it was taken: its true time lies in
  ``(t_first_row - P_l, t_first_row]``;
* the drives' clock is regular: ``T_j = T0 + P_d n_j`` with whole tick numbers ``n_j``; a drive period that was
  held (no new sample: a run about twice as long) is a step of two ticks, a whole-period skip, not jitter.

The tick numbers come from rounding the steps to whole periods, then refining the period by least squares on the
whole tick numbers over prefixes of the samples that double (the tick numbers stay right as the period sharpens). A
single step is ambiguous when the logger is less than twice as fast as its drives, or a period was held, so the
rounding starts from several first prefixes (:data:`START_SIZES`) at either end, from the whole span, and from no
hold at all; of the clocks that explain every sample, the one holding the fewest periods is kept. At its tick
numbers the period is the one that puts the samples' delays in the narrowest band (a minimax line: delays spread
uniformly over a logger period fix it to O(1/K), least squares only to O(1/sqrt(K))), and ``T0`` is the middle of
the offsets that put every sample in its window. Near a rational ratio with holds (a logger within about 0.1 % of 2
or 3 times its drives' rate) several clocks explain every sample: the period is then fixed only to two windows over
the span, each re-estimated time to its window. The repeats are merged only when such a clock explains every sample
(:attr:`DriveClock.feasible`) with a period longer than the logger's by more than
:data:`~wbfriction.logs.clock.LATTICE_TOL`: repeats on a clock no slower than the logger's are the drives' own
values sampled again (a still robot, a quantised sensor), kept as rows. A logger less than that share faster than
its drives, or less than about 1.5 times as fast with many holds, is not told apart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from wbfriction.logs.clock import LATTICE_TOL

MIN_DISTINCT = 8
"""Distinct samples below which no drive clock is fitted (two unknowns and their check need a few)."""

START_SIZES = (32, 8, 16, 64, 128)
"""The first prefixes the clock's ticks are rounded on: a step misread in one (an ambiguous step: a logger less
than twice as fast as its drives, or a hold) is absent from another."""


@dataclass(frozen=True, eq=False)
class DriveClock:
    """The drives' clock fitted to the first rows of the distinct samples.

    Attributes:
        period: the drives' sampling period ``P_d`` [s].
        t0: the time of tick 0 [s] (in the stamps' time, relative or absolute as given).
        ticks: each distinct sample's tick number ``n_j`` (K,), from 0, strictly increasing; a step of 2 is a
            held period.
        times: the re-estimated sample times ``t0 + period * ticks`` (K,) [s].
        spread: the range of ``first-row stamp - times`` [s]: at most the logger period when the clock explains
            every sample.
        feasible: every sample's re-estimated time lies in its window ``(t_first - P_l, t_first]`` (within the
            stamps' own jitter).
    """

    period: float
    t0: float
    ticks: np.ndarray
    times: np.ndarray
    spread: float
    feasible: bool

    @property
    def holds(self) -> int:
        """Drive periods held (ticks without a new sample)."""
        return int(np.sum(np.diff(self.ticks) - 1))


@dataclass(frozen=True, eq=False)
class Repeats:
    """The repeated rows of one stream and its distinct samples.

    Attributes:
        repeat: (N,) bool, the row repeats the previous one in every column of the stream.
        first: (K,) the first row of each distinct sample.
        clock: the drives' clock fitted to the distinct samples, or None (too few, or no repeat).
        logger_period: the logger's period ``P_l`` [s] (median step of the rows' stamps).
    """

    repeat: np.ndarray
    first: np.ndarray
    clock: DriveClock | None
    logger_period: float

    @property
    def share(self) -> float:
        """The share of rows that repeat the previous one."""
        return float(np.mean(self.repeat)) if self.repeat.size else 0.0

    @property
    def merge(self) -> bool:
        """The repeats are a logger faster than the drives: some row repeats, a drive clock explains every
        distinct sample, and its period exceeds the logger's by more than :data:`LATTICE_TOL`."""
        c = self.clock
        return bool(self.repeat.any() and c is not None and c.feasible
                    and c.period > self.logger_period * (1.0 + LATTICE_TOL))

    def times(self, stamps: np.ndarray) -> np.ndarray:
        """The distinct samples' times (K,) [s]: the drive clock's when merged, else their first rows' stamps."""
        return self.clock.times if self.merge and self.clock is not None else np.asarray(stamps)[self.first]

    def describe(self, what: str = "rows") -> str:
        """One line: the share repeated, and what was made of it."""
        share = f"{self.share * 100:.0f} % of {what} repeat the previous sample"
        c = self.clock
        if self.merge and c is not None:
            held = f", {c.holds} period(s) held" if c.holds else ""
            return f"{share}: merged; drive period {c.period * 1e3:.2f} ms re-estimated{held}"
        if c is not None and c.feasible:
            return f"{share}: kept (the samples come at the logger's own period: values repeated, not rows)"
        return f"{share}: kept (no drive clock slower than the logger explains them)"


def repeated_rows(values: np.ndarray) -> np.ndarray:
    """Rows (N,) equal to the previous one in every column of ``values`` (N, m) (NaN equal to NaN); row 0 never.

    An empty ``m`` repeats nothing."""
    values = np.asarray(values, dtype=float)
    out = np.zeros(len(values), dtype=bool)
    if values.ndim != 2 or values.shape[1] == 0 or len(values) < 2:
        return out
    a, b = values[1:], values[:-1]
    out[1:] = np.all((a == b) | (np.isnan(a) & np.isnan(b)), axis=1)
    return out


def find_repeats(values: np.ndarray | None, stamps: np.ndarray, repeat: np.ndarray | None = None) -> Repeats:
    """The repeats of one stream (:func:`repeated_rows`) and the drives' clock of its distinct samples.

    Args:
        values: the stream's columns (N, m), one row per logger tick (None: ``repeat`` given).
        stamps: the rows' times (N,) [s], strictly increasing (the logger's ticks).
        repeat: the repeated rows (N,) when already found (:func:`repeated_rows`), else None.

    Returns:
        :class:`Repeats`; :attr:`Repeats.merge` says whether they are a logger faster than the drives.
    """
    stamps = np.asarray(stamps, dtype=float)
    if repeat is None:
        repeat = repeated_rows(np.zeros((len(stamps), 0)) if values is None else values)
    repeat = np.asarray(repeat, dtype=bool)
    first = np.flatnonzero(~repeat)
    steps = np.diff(stamps)
    logger = float(np.median(steps)) if steps.size else float("nan")
    clock = None
    if repeat.any() and first.size >= MIN_DISTINCT and np.isfinite(logger) and logger > 0:
        clock = fit_drive_clock(stamps[first], logger, _jitter(steps, logger))
    return Repeats(repeat, first, clock, logger)


def _jitter(steps: np.ndarray, logger: float) -> float:
    """How far the logger's own stamps stray from its ticks [s]: the largest deviation of an ordinary step
    (within half a period of the median) from the median."""
    ordinary = steps[np.abs(steps - logger) < 0.5 * logger]
    return float(np.max(np.abs(ordinary - logger))) if ordinary.size else 0.0


def fit_drive_clock(first: np.ndarray, logger_period: float, jitter: float = 0.0) -> DriveClock:
    """The drives' regular clock behind the first rows' stamps of the distinct samples (module docstring).

    Args:
        first: the stamps of the distinct samples' first rows (K,) [s], strictly increasing, K >= 2.
        logger_period: the logger's period ``P_l`` [s].
        jitter: how far the logger's stamps stray from its ticks [s] (0 for stamps made from a nominal rate).

    Returns:
        :class:`DriveClock`; ``feasible`` False when no regular clock puts every sample in its window.
    """
    t = np.asarray(first, dtype=float)
    rel = t - t[0]
    width = logger_period * (1.0 + LATTICE_TOL) + 2.0 * jitter
    back = rel[-1] - rel[::-1]  # the samples read from the end: a step misread near the start is not near it
    starts = [ticks for size in START_SIZES + (len(rel),) if size <= len(rel)
              for ticks in (_ticks_by_rounding(rel, logger_period, size),
                            _reversed(_ticks_by_rounding(back, logger_period, size)))]
    starts.append(np.arange(len(rel), dtype=float))  # no period held: the longest clock there can be
    clocks = [_clock(t, ticks, logger_period, width) for ticks in starts]
    feasible = [c for c in clocks if c.feasible]
    if feasible:  # the fewest periods held (a clock with more holds periods the drives did not), then the narrowest
        return min(feasible, key=lambda c: (c.holds, c.spread))
    return min(clocks, key=lambda c: c.spread)


def _clock(t: np.ndarray, ticks: np.ndarray, logger_period: float, width: float) -> DriveClock:
    """The clock at these tick numbers whose period puts the samples' delays in the narrowest band.

    The band's width ``max_j r_j - min_j r_j`` of the residuals ``r_j = t_j - t_0 - P n_j`` is convex in ``P``
    (a maximum of lines minus a minimum of lines); it is minimised around least squares' period. A true clock's
    delays lie within one logger period."""
    rel = t - t[0]
    ticks = (ticks - ticks[0]).astype(float)
    _, guess = _line(ticks, rel - 0.5 * logger_period)
    if guess > 0 and ticks[-1] > 0:
        def band(period: float) -> float:
            r = rel - period * ticks
            return float(np.max(r) - np.min(r))

        reach = 2.0 * logger_period / ticks[-1]  # least squares is within a band's width over the span
        best = minimize_scalar(band, bounds=(guess - reach, guess + reach), method="bounded",
                               options={"xatol": 1e-12 * guess})
        period = float(best.x) if best.fun <= band(guess) else guess
    else:
        period = guess
    resid = rel - period * ticks
    low = float(np.max(resid - logger_period))  # t0 > t_j - P_l - P n_j for every j
    high = float(np.min(resid))  # t0 <= t_j - P n_j
    spread = float(np.max(resid) - np.min(resid))
    feasible = bool(period > 0 and spread <= width)
    offset = 0.5 * (low + high)  # the band centred on the windows (any excess shared by both ends)
    times = t[0] + offset + period * ticks
    return DriveClock(period, float(t[0] + offset), ticks.astype(np.int64), times, spread, feasible)


def _reversed(ticks: np.ndarray) -> np.ndarray:
    """Tick numbers found on the samples read from the end, in the samples' order."""
    return ticks[-1] - ticks[::-1]


def _ticks_by_rounding(rel: np.ndarray, logger_period: float, size: int) -> np.ndarray:
    """Tick numbers from the steps rounded to whole periods, then least squares on prefixes that double (the
    ticks re-rounded from the sharper clock). Fast, and right unless a step is ambiguous (a logger less than
    twice as fast as its drives, with holds)."""
    steps = np.diff(rel)
    period = float(rel[-1] / max(len(rel) - 1, 1))
    for _ in range(20):  # whole periods per step, the period from the whole span
        m = np.maximum(1, np.rint(steps / period))
        new = float(rel[-1] / m.sum())
        if abs(new - period) <= 1e-12 * period:
            break
        period = new
    ticks = np.concatenate([[0.0], np.cumsum(np.maximum(1, np.rint(steps / period)))])
    centre = rel - 0.5 * logger_period  # the middle of each sample's window
    size = min(len(rel), size)
    while True:
        for _ in range(3):
            offset, period = _line(ticks[:size], centre[:size])
            if not period > 0:
                return ticks
            ticks = _monotone(np.rint((centre - offset) / period))
        if size == len(rel):
            return ticks
        size = min(2 * size, len(rel))


def _line(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Least-squares ``y ~ a + b x``: ``(a, b)``."""
    xm, ym = float(np.mean(x)), float(np.mean(y))
    dx = x - xm
    denom = float(np.dot(dx, dx))
    b = float(np.dot(dx, y - ym)) / denom if denom > 0 else 0.0
    return ym - b * xm, b


def _monotone(ticks: np.ndarray) -> np.ndarray:
    """Tick numbers made strictly increasing (two samples never share a tick)."""
    k = np.arange(len(ticks), dtype=float)
    return np.maximum.accumulate(ticks.astype(float) - k) + k

"""The clock behind a log's time stamps: what wrote them, and the time base derivatives are taken on.

Loggers write two kinds of irregular stamps, and they call for opposite treatments:

* **exact stamps of non-uniform samples** (kind ``skipping``): a controller's clock stamps each
  sample exactly, but samples are skipped (steps of 10 and 12 ms from a 2 ms clock read over a
  network) or taken at uneven instants (1 kHz data with 0.7-8.8 ms steps). The samples truly
  are non-uniform: derivatives are taken on the stamps as recorded
  (:mod:`wbfriction.signals.nonuniform`), never with a constant period.
* **receive-time stamps** (kind ``jittered``): uniform samples stamped when they arrived
  (3.2-6.8 ms steps around 5 ms). Differentiating on those stamps turns their scatter into
  acceleration noise: derivatives are taken on a regularised clock, a robust straight-line
  fit of time against sample index (:func:`regularise`: one period for the log, one offset
  per segment, the gaps excepted).

**Gaps** are decided by what the clock does: a step of at least ``max_gap`` local median steps splits
the log into segments, never differentiated across, unless it is a few ticks (up to :data:`MAX_SKIP`
median steps) of a clock whose stamps are whole ticks and taken as recorded: that clock skips samples,
and its skips are differentiated across on the stamps.

A log whose steps (gaps aside) all lie within :data:`JITTER` of their median is ``uniform`` and is
differentiated with that median step, as it always was. Otherwise :func:`read_clock` decides by
measuring: on which time base the positions' second differences are smoother
(:func:`roughness`, a ratio beyond :data:`VERDICT` decides); when the positions give no verdict,
stamps that are all whole multiples of a base period (:func:`lattice_period`: a clock's ticks) are
taken as recorded, stamps that stay within half a period of a straight line as receive times.
:attr:`Clock.reason` says in one line what was found and assumed; ``time_base`` overrides it.

Stamps are seconds (float64), Arrow timestamps, or integers in a unit the user states
(:func:`table_stamps`: ``--time-unit``; integers are kept as nanoseconds).
Epoch stamps (about 1.5e9 s) keep their precision: the clock works on stamps relative to the
first one (integers are subtracted as integers first).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.options import MAX_GAP, TIME_BASES, TIME_UNITS, TimeBase, TimeUnit
from wbfriction.logs.tables import numeric_column

ClockKind = Literal["uniform", "skipping", "jittered"]
"""What wrote a log's stamps (module docstring): a uniform clock, exact stamps of non-uniform
samples (taken as recorded), receive-time stamps of uniform samples (regularised)."""

JITTER = 0.05
"""Steps within this share of their median are a uniform clock."""
LATTICE_TOL = 0.05
"""How far (a share of the base period) a step may lie from a whole multiple of it."""
MAX_MULTIPLE = 12
"""The shortest base period tried is the median step over this."""
VERDICT = 1.2
"""Ratio of the roughness on the two time bases beyond which the smoother one is chosen."""
ROUGHNESS_ROWS = 20_000
"""Rows (from the first) on which the roughness is measured."""
LOCAL_STEPS = 101
"""Steps over which the local median step (the gaps' yardstick) is taken."""
MAX_SKIP = 4.0
"""A step of up to this many local median steps (up to three samples missed in a row), on a clock whose
stamps are whole ticks of one period and are taken as recorded, is samples the clock skipped, not a gap
(:func:`read_clock`)."""


@dataclass(frozen=True, eq=False)
class Clock:
    """A log's clock: the time base its derivatives are taken on, and why.

    Attributes:
        kind: what wrote the stamps (:data:`ClockKind`): ``uniform`` (differentiated with the
            constant :attr:`step`), ``skipping`` (on the stamps as recorded), ``jittered`` (on a
            regularised clock).
        t: the time base (N,) [s], relative to :attr:`t0`: the stamps as recorded (``uniform``,
            ``skipping``) or the regularised clock (``jittered``).
        t0: the first stamp of the whole log [s] (absolute, e.g. Unix epoch).
        period: the base period [s]: the uniform step; the period of the clock whose ticks the
            steps are multiples of (``skipping``; else the median step); the regularised period
            (``jittered``).
        step: the nominal sampling interval [s]: the median step, or the regularised period
            (``jittered``); a log's :attr:`~wbfriction.logs.log.Log.dt`.
        segments: half-open row ranges between time gaps, covering every row.
        reason: one line saying what was detected and assumed.
        roughness: RMS increments of the positions' second differences on the stamps as
            recorded and on the regularised clock [rad/s^2] (:func:`roughness`), or None (a
            uniform clock, or no positions to measure on).
        lattice: the base period of which every step is a whole multiple [s], or None.
    """

    kind: ClockKind
    t: np.ndarray
    t0: float
    period: float
    step: float
    segments: list[tuple[int, int]]
    reason: str
    roughness: tuple[float, float] | None = None
    lattice: float | None = None

    @property
    def uniform(self) -> bool:
        """The samples are differentiated with a constant period (:attr:`step`)."""
        return self.kind == "uniform"

    def __len__(self) -> int:
        return len(self.t)

    def rows(self, start: int, stop: int) -> Clock:
        """The clock of rows ``[start, stop)`` (a chunk of a long log): the whole log's time base
        and decision, its segments cut to the rows and counted from ``start``."""
        start, stop, _ = slice(start, stop).indices(len(self.t))
        segments = [(max(a, start) - start, min(b, stop) - start) for a, b in self.segments if a < stop and b > start]
        return replace(self, t=self.t[start:stop], segments=segments or [(0, max(stop - start, 0))])


# ------------------------------------------------------------------------- the stamps
_NS_PER = {"s": 10**9, "ms": 10**6, "us": 10**3, "ns": 1}
SECONDS_STEP = (1e-6, 0.5)
"""Median step [s] of a float ``time`` column read as seconds without a stated unit: outside it,
the column is refused (milliseconds or nanoseconds read as seconds would be off by 1e3 or 1e9)."""


def table_stamps(table: pa.Table, source: str, first_row: int = 0, unit: TimeUnit | None = None) -> np.ndarray:
    """The ``time`` column of a table as float64 seconds, or int64 nanoseconds (kept as integers,
    :func:`relative_stamps`), its unit checked:

    * an Arrow timestamp: its own unit, converted exactly to nanoseconds;
    * integers: ``unit`` must be given (no integer unit is safe to guess: ROS writes nanoseconds,
      many loggers milliseconds), converted exactly to nanoseconds;
    * floats: seconds, or ``unit``; without a unit, a median step outside :data:`SECONDS_STEP`
      is refused (it is not seconds).

    Raises:
        ColumnError: a missing, non-numeric or non-finite column, integers without ``unit``,
            float stamps that are not seconds, integers that overflow 64-bit nanoseconds.
        InputError: an unknown ``unit``.
    """
    if unit is not None and unit not in TIME_UNITS:
        raise InputError(f"--time-unit must be one of {', '.join(TIME_UNITS)}, got '{unit}'")
    if "time" not in table.column_names:
        raise ColumnError(source, "time", None, "missing column 'time'")
    col = table.column("time")
    if col.null_count == 0 and pa.types.is_timestamp(col.type):
        return col.cast(pa.timestamp("ns")).cast(pa.int64()).to_numpy(zero_copy_only=False).astype(np.int64)
    if col.null_count == 0 and pa.types.is_integer(col.type):
        if unit is None:
            raise ColumnError(source, "time", None, f"column 'time' holds integers ({col.type}) whose unit is not "
                              "known: give it with --time-unit s, ms, us or ns")
        values = col.to_numpy(zero_copy_only=False).astype(np.int64)
        factor = _NS_PER[unit]
        if values.size and np.abs(values).max() > np.iinfo(np.int64).max // factor:
            raise ColumnError(source, "time", None, f"column 'time' in {unit} overflows 64-bit nanoseconds")
        return values * factor
    seconds = numeric_column(table, "time", source, first_row)
    if unit is not None and unit != "s":
        return seconds * (1e-9 * _NS_PER[unit])
    if unit is None:
        step = np.diff(seconds[:ROUGHNESS_ROWS])
        step = step[step > 0]
        median = float(np.median(step)) if step.size else float("nan")
        if step.size and not SECONDS_STEP[0] <= median <= SECONDS_STEP[1]:
            raise ColumnError(source, "time", None, f"column 'time' steps by {median:.6g} (median): not seconds? "
                              "give its unit with --time-unit ms, us or ns (or --time-unit s if it is seconds)")
    return seconds


def relative_stamps(stamps: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Stamps relative to the first one, keeping their precision.

    Args:
        stamps: (N,) float seconds, or integer nanoseconds.

    Returns:
        ``(t, t0, steps)``: times since the first stamp (N,) [s], the first stamp [s], and the
        steps (N - 1,) [s] (integers subtracted as integers before the conversion).
    """
    stamps = np.asarray(stamps)
    if np.issubdtype(stamps.dtype, np.integer):
        ns = stamps.astype(np.int64)
        return (ns - ns[0]) * 1e-9, int(ns[0]) * 1e-9, np.diff(ns) * 1e-9
    stamps = stamps.astype(float)
    return stamps - stamps[0], float(stamps[0]), np.diff(stamps)


def _checked(stamps: np.ndarray, source: str, first_row: int) -> tuple[np.ndarray, float, np.ndarray]:
    """:func:`relative_stamps`, refusing too few rows and a non-finite, duplicated or decreasing stamp."""
    stamps = np.asarray(stamps)
    if stamps.size < 5:
        raise InputError(f"{source}: only {stamps.size} rows; at least 5 samples are needed")
    t, t0, step = relative_stamps(stamps)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise ColumnError(source, "time", int(first_row + bad[0]), f"column 'time' has a non-finite value "
                          f"(NaN or inf) at row {first_row + bad[0]}")
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        what = "duplicated" if step[k - 1] == 0 else "decreasing"
        raise ColumnError(source, "time", first_row + k, f"column 'time' has a {what} stamp at row {first_row + k} "
                          f"({t0 + t[k]:.15g} s after {t0 + t[k - 1]:.15g} s)")
    return t, t0, step


def _local_median(step: np.ndarray) -> np.ndarray:
    """The median of the :data:`LOCAL_STEPS` steps around each step (N - 1,)."""
    from scipy.ndimage import median_filter
    return median_filter(step, size=min(LOCAL_STEPS, step.size), mode="reflect")


def _gaps(step: np.ndarray, max_gap: float, rel_tol: float) -> np.ndarray:
    """Steps (N - 1,) at least ``max_gap`` (less ``rel_tol``) times the median of the steps around them."""
    return step >= (max_gap - rel_tol) * _local_median(step)


def _segments(gap: np.ndarray, n: int) -> list[tuple[int, int]]:
    edges = [0, *(np.flatnonzero(gap) + 1).tolist(), n]
    return list(zip(edges[:-1], edges[1:]))


def longest_segment(segments: list[tuple[int, int]] | None, rows: int) -> tuple[int, int]:
    """The longest of ``segments`` (half-open row ranges; None: one segment) within the first ``rows`` rows."""
    clipped = [(a, min(b, rows)) for a, b in segments or [(0, rows)] if a < rows]
    return max(clipped, key=lambda s: s[1] - s[0]) if clipped else (0, 0)


def split_at_gaps(stamps: np.ndarray, source: str, max_gap: float = MAX_GAP, rel_tol: float = JITTER,
                  first_row: int = 0) -> list[tuple[int, int]]:
    """Check a time column and split it at its gaps: steps of at least ``max_gap`` (less
    ``rel_tol``) times the local median step (of the :data:`LOCAL_STEPS` around it).

    Args:
        stamps: (N,) float seconds or integer nanoseconds.

    Returns:
        The segments as half-open row ranges ``[(a, b), ...]`` covering every row.

    Raises:
        InputError: fewer than 5 rows; ColumnError: a non-finite, duplicated or decreasing
            stamp, naming column ``time`` and the row (counted from ``first_row``).
    """
    _, _, step = _checked(stamps, source, first_row)
    return _segments(_gaps(step, max_gap, rel_tol), len(step) + 1)


# ---------------------------------------------------------------------- the measures
def lattice_period(steps: np.ndarray, tol: float = LATTICE_TOL, max_multiple: int = MAX_MULTIPLE) -> float | None:
    """The longest base period of which every step is a whole multiple (each within ``tol``
    periods of one), a clock's ticks; None when there is none.

    The periods tried are the median step over 1 ... ``max_multiple``, each refined by least
    squares over the steps' multiples (a shorter period would fit any stamps).

    Args:
        steps: time steps (M,) [s], gaps left out.
    """
    steps = np.asarray(steps, dtype=float)
    if steps.size == 0:
        return None
    med = float(np.percentile(steps, 50, method="lower"))
    for m in range(1, max_multiple + 1):
        n = np.rint(steps / (med / m))
        if np.any(n < 1):
            continue
        p = float(np.dot(n, steps) / np.dot(n, n))
        if np.all(np.abs(steps / p - n) <= tol):
            return p
    return None


def regularise(t: np.ndarray, segments: list[tuple[int, int]]) -> tuple[np.ndarray, float]:
    """A regularised clock: a robust straight-line fit of time against sample index,
    ``t_k ~ offset_j + period * (k - a_j)`` on segment ``[a_j, b_j)``: one period for the whole
    log, one offset per segment (the samples missed in a gap are not counted).

    The fit is Huber-robust (``scipy.optimize.least_squares(loss="huber")``, scale: 1.4826 x
    the median absolute residual of the least-squares fit), so that the few stamps delivered
    late do not tilt it.

    Args:
        t: stamps (N,) [s] relative to the first; segments: their row ranges.

    Returns:
        ``(t_reg, period)``: the regularised times (N,) [s] and the period [s].
    """
    import scipy.sparse as sp
    from scipy.optimize import least_squares
    n = len(t)
    seg = np.zeros(n, dtype=np.int64)
    idx = np.zeros(n)
    for j, (a, b) in enumerate(segments):
        seg[a:b] = j
        idx[a:b] = np.arange(b - a)
    count = np.bincount(seg, minlength=len(segments)).astype(float)
    mean_i = np.bincount(seg, idx, len(segments)) / count
    mean_t = np.bincount(seg, t, len(segments)) / count
    di = idx - mean_i[seg]
    spread = float(np.dot(di, di))
    period = float(np.dot(di, t - mean_t[seg])) / spread if spread > 0 else 0.0
    if not period > 0:  # every segment a single row
        period = float(np.median(np.diff(t)))
    x0 = np.r_[period, mean_t - period * mean_i]
    resid = x0[1:][seg] + period * idx - t
    scale = 1.4826 * float(np.median(np.abs(resid - np.median(resid))))
    if scale > 1e-6 * period:
        jac = sp.csr_matrix(sp.hstack([sp.csr_matrix(idx[:, None]),
                                       sp.csr_matrix((np.ones(n), (np.arange(n), seg)), shape=(n, len(segments)))]))
        fit = least_squares(lambda x: x[1:][seg] + x[0] * idx - t, x0, jac=lambda x: jac, loss="huber",
                            f_scale=scale, x_scale="jac", tr_solver="lsmr", method="trf")
        if fit.x[0] > 0:
            x0 = fit.x
    return x0[1:][seg] + x0[0] * idx, float(x0[0])


def roughness(t: np.ndarray, q: np.ndarray, segments: list[tuple[int, int]]) -> float:
    """How rough the positions' second differences are on the time base ``t``: the RMS of the
    increments of the non-uniform second divided differences
    ``2 ((q[k+1]-q[k]) / h2 - (q[k]-q[k-1]) / h1) / (h1 + h2)`` within each segment.

    A true acceleration changes little from one sample to the next; stamps that misplace the
    samples (or a regularised clock that misplaces exact ones) add a term of the order of
    ``qd * error / h^2`` that changes at every sample.

    Args:
        t: time base (N,) [s]; q: positions (M, n) of the first M <= N rows; segments: row
            ranges of ``t``.

    Returns:
        The roughness [q units / s^2], NaN if no segment has four rows within ``q``.
    """
    total, count = 0.0, 0
    for a, b in segments:
        b = min(b, len(q))
        if b - a < 4:
            continue
        h = np.diff(t[a:b])[:, None]
        d1 = np.diff(q[a:b], axis=0) / h
        d2 = 2.0 * np.diff(d1, axis=0) / (h[1:] + h[:-1])
        inc = np.diff(d2, axis=0)
        total += float(np.sum(inc**2))
        count += inc.size
    return math.sqrt(total / count) if count else math.nan


# ------------------------------------------------------------------------- the decision
def _ms(x: float) -> str:
    return f"{x * 1e3:.3g} ms"


def _times(x: float) -> str:
    return f"{x:.0f}x" if x >= 10 else f"{x:.2g}x"


@dataclass(frozen=True)
class _Evidence:
    """What the stamps and positions say (:func:`read_clock`)."""

    steps: np.ndarray  # the steps, gaps left out [s]
    median: float
    lattice: float | None
    period: float  # of the regularised clock
    bounded: bool  # the stamps stay within half a period of the regularised clock
    roughness: tuple[float, float] | None  # (recorded, regularised)
    uniform: bool = False  # every step within JITTER of the median

    @property
    def ratio(self) -> float:
        """Roughness on the stamps over roughness on the regularised clock (NaN: no measure)."""
        if self.roughness is None:
            return math.nan
        rec, reg = self.roughness
        return rec / reg if reg > 0 and rec > 0 else math.nan

    def measured(self) -> TimeBase | None:
        """The smoother time base, when the positions give a verdict."""
        if self.ratio >= VERDICT:
            return "regularised"
        if self.ratio <= 1.0 / VERDICT:
            return "recorded"
        return None

    def detected(self) -> TimeBase:
        """The time base the data call for: the measured one, else the stamps' structure."""
        return self.measured() or ("recorded" if self.lattice is not None or not self.bounded else "regularised")

    def describe(self, base: TimeBase) -> str:
        """What the stamps are, as the ``base`` they were taken to call for."""
        lo, hi = float(self.steps.min()), float(self.steps.max())
        span = f"{lo * 1e3:.2g}-{hi * 1e3:.2g} ms"
        if self.uniform:
            return f"uniform stamps every {_ms(self.median)} (steps {span})"
        if base == "regularised":
            return f"receive-time stamps scattered around a {_ms(self.period)} clock (steps {span})"
        if self.lattice is not None:
            ticks = np.rint(np.array([lo, hi]) / self.lattice).astype(int)
            return (f"exact stamps of a {_ms(self.lattice)} clock skipping samples (steps {span} = "
                    f"{ticks[0]}-{ticks[1]} ticks)")
        return f"exact stamps of non-uniform samples (steps {span}, median {_ms(self.median)})"

    def why(self, chosen: TimeBase) -> str:
        """The numbers behind the choice of ``chosen``."""
        r = self.ratio
        if math.isfinite(r) and self.measured() is not None:
            other = "on the stamps" if chosen == "regularised" else "on a regularised clock"
            better = r if chosen == "regularised" else 1.0 / r
            word = "smoother" if better >= 1.0 else "rougher"
            return f"second differences {_times(max(better, 1.0 / better))} {word} than {other}"
        if self.lattice is not None:
            structure = f"every step a whole number of {_ms(self.lattice)} ticks"
        elif self.bounded:
            structure = "the stamps within half a period of a straight line"
        else:
            structure = "the stamps drifting from any straight line"
        if math.isfinite(r):
            return f"second differences within {VERDICT - 1:.0%} on both time bases; {structure}"
        return f"no positions to compare; {structure}"


def read_clock(stamps: np.ndarray, source: str, *, max_gap: float = MAX_GAP, first_row: int = 0,
               q: np.ndarray | None = None, time_base: TimeBase = "auto") -> Clock:
    """Read a log's clock from its stamps, and its positions when the stamps are not uniform.

    Args:
        stamps: the ``time`` column (N,): float seconds or integer nanoseconds
            (:func:`table_stamps`).
        source: file name for the messages.
        max_gap: steps of at least this many local median steps split the log
            (:func:`split_at_gaps`), except the steps of up to :data:`MAX_SKIP` local median steps
            of a clock whose stamps are whole ticks taken as recorded: those are samples the clock
            skipped, differentiated across on the stamps (with a regularised clock, a skipped
            sample is a gap: the clock counts samples).
        first_row: row number of ``stamps[0]`` in its file, for the messages.
        q: positions (M, n) of the first M <= N rows [rad], to measure on which time base they
            are smoother (:func:`roughness`, on the first :data:`ROUGHNESS_ROWS`); None: decide
            from the stamps alone.
        time_base: ``auto`` (decide, module docstring), ``recorded`` (the stamps as they are,
            even uniform ones: kind ``skipping``) or ``regularised`` (kind ``jittered``).

    Returns:
        :class:`Clock`, with :attr:`Clock.reason`.

    Raises:
        InputError: fewer than 5 rows, an unknown ``time_base``; ColumnError: a non-finite,
            duplicated or decreasing stamp (column ``time``, the row counted from ``first_row``).
    """
    if time_base not in TIME_BASES:
        raise InputError(f"unknown time base '{time_base}': choose one of {', '.join(TIME_BASES)}")
    t, t0, step = _checked(stamps, source, first_row)
    local = _local_median(step)
    gap = step >= (max_gap - JITTER) * local
    skip = gap & (step <= (MAX_SKIP + JITTER) * local)
    if skip.any() and time_base != "regularised":
        # what the clock does decides: skipped ticks of a clock whose stamps are taken as recorded are
        # differentiated across (non-uniform formulas), never cut out of the log
        clock = _decide(t, t0, step, gap & ~skip, q, time_base)
        if clock.kind == "skipping" and clock.lattice is not None:
            return clock
    return _decide(t, t0, step, gap, q, time_base)


def _decide(t: np.ndarray, t0: float, step: np.ndarray, gap: np.ndarray, q: np.ndarray | None,
            time_base: TimeBase) -> Clock:
    """:func:`read_clock`'s decision, its gaps (N - 1,) given."""
    segments = _segments(gap, len(t))
    dt = float(np.median(step))
    inner = step[~gap]
    gaps = f"; {len(segments) - 1} gap(s) split it into {len(segments)} segments" if len(segments) > 1 else ""
    if time_base == "auto" and np.all(np.abs(inner - dt) <= JITTER * dt):
        return Clock("uniform", t, t0, dt, dt, segments,
                     f"time: uniform stamps every {_ms(dt)} (steps within {JITTER * 100:g} % of it){gaps}")
    t_reg, period = regularise(t, segments)
    rough = None
    if q is not None:
        qq = np.asarray(q, dtype=float)[:ROUGHNESS_ROWS]
        rough = (roughness(t, qq, segments), roughness(t_reg, qq, segments))
    ev = _Evidence(inner if inner.size else step, dt, lattice_period(inner), period,
                   bool(np.max(np.abs(t - t_reg)) < 0.5 * period), rough,
                   bool(np.all(np.abs(inner - dt) <= JITTER * dt)))
    detected = ev.detected()
    chosen = detected if time_base == "auto" else time_base
    asked = ", as asked" if time_base != "auto" else ""
    on = "a regularised clock" if chosen == "regularised" else "the stamps as recorded"
    reason = f"time: {ev.describe(detected)}; differentiating on {on}{asked} ({ev.why(chosen)}){gaps}"
    if chosen == "regularised":
        return Clock("jittered", t_reg, t0, period, period, segments, reason, rough, ev.lattice)
    return Clock("skipping", t, t0, ev.lattice or dt, dt, segments, reason, rough, ev.lattice)

"""Numbers as people read them: a value to the digits its standard error supports, in one format for the
terminal and the report (issue 39).

The standard error is rounded to one significant digit (two when that digit is 1: 0.14, not 0.1, which would
be off by 30 %), and the value to the same decimal place, written plainly or with a common power of ten,
whichever is shorter: ``0.180 ± 0.005``, ``38.5 ± 0.1``, ``0.099941 ± 0.000018``, ``(3.00 ± 0.10)e-07``.
Durations are the time recorded and, across gaps, the span (:func:`duration_text`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

GENERAL_DIGITS = 4
"""Significant digits of a value without a finite standard error."""


def _error_place(se: float) -> int:
    """The decimal exponent of the last digit kept: that of ``se``'s first significant digit, one lower when
    that digit is 1; the digit read once ``se`` is rounded to two (0.196 is 0.20: one digit, 0.2)."""
    exponent = math.floor(math.log10(se))
    leading = round(se / 10.0 ** (exponent - 1))  # two significant digits, 10 to 100
    if leading >= 100:
        exponent, leading = exponent + 1, 10
    return exponent - 1 if leading < 20 else exponent


def with_error(value: float, se: float | None) -> str:
    """``value ± se`` to the digits ``se`` supports (module docstring); ``± n.i.`` for an infinite error (not
    identifiable), the value alone to :data:`GENERAL_DIGITS` significant digits without one (None or 0)."""
    if not math.isfinite(value):
        return str(value)
    if se is None or se == 0.0:
        return f"{value:.{GENERAL_DIGITS}g}"
    if not math.isfinite(se):
        return f"{value:.{GENERAL_DIGITS}g} ± n.i."
    se = abs(se)
    place = _error_place(se)
    decimals = max(-place, 0)
    plain = f"{round(value, -place):.{decimals}f} ± {round(se, -place):.{decimals}f}"
    power = math.floor(math.log10(max(abs(value), se)))
    digits = max(power - place, 0)
    scale = 10.0**power
    scientific = f"({value / scale:.{digits}f} ± {se / scale:.{digits}f})e{power:+03d}"
    return plain if len(plain) <= len(scientific) else scientific


def bound_text(bound: float | None) -> str:
    """A Cramér-Rao standard deviation as a cell: ``± b`` to one or two significant digits (as a standard
    error), ``n.i.`` when infinite, empty when there is none."""
    if bound is None:
        return ""
    if not math.isfinite(bound):
        return "n.i."
    place = _error_place(bound)
    digits = math.floor(math.log10(round(bound, -place))) - place  # 1 after a leading 1, else 0
    return f"± {round(bound, -place):.{max(-place, 0)}f}" if -4 <= place <= 4 else f"± {bound:.{digits}e}"


P_FLOOR = 1e-12
"""A p-value below this is printed ``< 1e-12``: its digits are the floating point's, not the data's."""


def p_value_text(p: float) -> str:
    """A p-value in two significant digits, or ``< 1e-12`` below :data:`P_FLOOR` (not ``1.37e-67``)."""
    return f"< {P_FLOOR:g}" if p < P_FLOOR else f"{p:.2g}"


def duration_text(time: Sequence[float] | np.ndarray) -> str:
    """How long a log lasts: the time recorded (the sum of its steps, gaps left out) and, when gaps split it, the
    span from its first sample to its last and the number of recordings, e.g. ``50.3 s recorded in 2 runs over
    29.3 min``; time [s], increasing."""
    import numpy as np

    from wbfriction.logs.runs import GAP_STEPS, log_runs

    t = np.asarray(time, dtype=float)
    if len(t) < 2:
        return "0 s recorded"
    steps = np.diff(t)
    recorded = float(steps[steps <= GAP_STEPS * np.median(steps)].sum())
    runs = len(log_runs(t))
    if runs == 1:
        return f"{_seconds(recorded)} recorded"
    return f"{_seconds(recorded)} recorded in {runs} runs over {_seconds(float(t[-1] - t[0]))}"


def _seconds(s: float) -> str:
    """A duration in its unit: ``12.5 s``, ``29.3 min``, ``2.4 h``, ``3.1 days``."""
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if s >= 2 * size:
            return f"{s / size:.1f} {unit}"
    return f"{s:.1f} s"

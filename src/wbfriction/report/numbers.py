"""Numbers as people read them: a value to the digits its standard error supports, in one format for the
terminal and the report (issue 39).

The standard error is rounded to one significant digit (two when that digit is 1: 0.14, not 0.1, which would
be off by 30 %), and the value to the same decimal place; down to a last digit of 1e-5 and below 1e5 they are
written plainly, others with a common power of ten: ``0.180 ± 0.005``, ``38.5 ± 0.1``, ``(3.00 ± 0.10)e-07``."""

from __future__ import annotations

import math

PLAIN = (1e-5, 1e5)
"""Magnitudes written without a power of ten: from the smallest decimal shown to the largest value."""
GENERAL_DIGITS = 4
"""Significant digits of a value without a finite standard error."""


def _error_place(se: float) -> int:
    """The decimal exponent of the last digit kept: that of ``se``'s first significant digit, one lower when
    that digit is 1."""
    exponent = math.floor(math.log10(se))
    return exponent - 1 if se / 10.0**exponent < 2.0 else exponent


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
    top = max(abs(value), se)
    if 10.0**place >= PLAIN[0] and top < PLAIN[1]:
        decimals = max(-place, 0)
        return f"{round(value, -place):.{decimals}f} ± {round(se, -place):.{decimals}f}"
    power = math.floor(math.log10(top))
    decimals = max(power - place, 0)
    scale = 10.0**power
    return f"({value / scale:.{decimals}f} ± {se / scale:.{decimals}f})e{power:+03d}"


def bound_text(bound: float | None) -> str:
    """A Cramér-Rao standard deviation as a cell: ``± b`` to one or two significant digits (as a standard
    error), ``n.i.`` when infinite, empty when there is none."""
    if bound is None:
        return ""
    if not math.isfinite(bound):
        return "n.i."
    return f"± {bound:.2g}" if bound / 10.0 ** math.floor(math.log10(bound)) < 2.0 else f"± {bound:.1g}"

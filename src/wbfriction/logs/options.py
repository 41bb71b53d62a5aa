"""The choices a user makes about reading a log, in a module that imports nothing heavy: the command line
shows their defaults in its help without loading NumPy or pyarrow."""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Literal, get_args

from wbfriction.exceptions import OptionError

MAX_GAP = 2.0
"""Default gap [sampling periods]: a time step at least this long (against the median of the
steps around it) splits a log into segments."""
MAX_GAP_LEAST = 1.5
"""The shortest gap taken [sampling periods]: a shorter one would split a log at its clock's own jitter."""
LIMIT_MARGIN = 0.2
"""How far a position may pass its URDF limits before the log is refused [rad or m]."""

TimeBase = Literal["auto", "recorded", "regularised"]
"""The time base derivatives are taken on: decided from the data (``auto``), the stamps as
recorded, or a regularised clock (:func:`~wbfriction.logs.clock.regularise`)."""
TIME_BASES: tuple[TimeBase, ...] = get_args(TimeBase)
TimeUnit = Literal["s", "ms", "us", "ns"]
"""The unit of a numeric ``time`` column (``--time-unit``)."""
TIME_UNITS: tuple[TimeUnit, ...] = get_args(TimeUnit)
RepeatsPolicy = Literal["merge", "keep"]
"""What is made of rows that repeat the previous sample in every joint column (``--repeats``): merged into one
sample at its re-estimated time when a drive clock slower than the logger explains them
(:mod:`wbfriction.logs.repeats`), or kept as rows."""
REPEATS_POLICIES: tuple[RepeatsPolicy, ...] = get_args(RepeatsPolicy)
RATE_RANGE = (0.0, 1e5)
"""A logger's nominal rate [Hz] (``--rate``): above 0, at most 100 kHz (a robot's fastest bus is tens of kHz)."""


@dataclass(frozen=True)
class ReadOptions:
    """How a log is read, one value passed whole wherever a log is read (the command line's ``--max-gap``,
    ``--limit-margin``, ``--time-base``, ``--time-unit``, ``--repeats`` and ``--rate``). Checked where made.

    Attributes:
        max_gap: a time step of at least this many local median steps splits the log into segments, estimated
            apart (:func:`~wbfriction.logs.clock.split_at_gaps`) [sampling periods]; at least :data:`MAX_GAP_LEAST`.
        limit_margin: how far a position may pass its URDF limits before the log is refused
            (:func:`~wbfriction.logs.angles.check_limits`) [rad or m]; at least 0 (inf: not checked).
        time_base: the time base the positions are differentiated on (:data:`TimeBase`: decided from the data, the
            stamps as recorded, or a regularised clock; :func:`~wbfriction.logs.clock.read_clock`).
        time_unit: the unit of a numeric ``time`` column (:data:`TimeUnit`; None: seconds for floats, needed for
            integers; :func:`~wbfriction.logs.clock.table_stamps`).
        repeats: rows repeating the previous sample in every joint column merged (``merge``, when a drive clock
            slower than the logger explains them) or kept as rows (``keep``) (:data:`RepeatsPolicy`,
            :func:`~wbfriction.logs.raw_table.condition_raw_table`).
        rate: the logger's nominal rate [Hz] of a log without a ``time`` column (its rows are stamped
            ``k / rate``: exact ticks of the logger); None: a log must have a ``time`` column. Not used on a log
            that has one.

    Raises:
        OptionError: a value out of its range or not one of its choices, naming the option as the command line
            spells it.
    """

    max_gap: float = MAX_GAP
    limit_margin: float = LIMIT_MARGIN
    time_base: TimeBase = "auto"
    time_unit: TimeUnit | None = None
    repeats: RepeatsPolicy = "merge"
    rate: float | None = None

    def __post_init__(self) -> None:
        if not (isinstance(self.max_gap, numbers.Real) and self.max_gap >= MAX_GAP_LEAST):
            raise OptionError("--max-gap", self.max_gap, f"a number of sampling periods, at least {MAX_GAP_LEAST:g}")
        if not (isinstance(self.limit_margin, numbers.Real) and self.limit_margin >= 0):
            raise OptionError("--limit-margin", self.limit_margin, "a margin of at least 0 rad (or m; inf: none)")
        if self.time_base not in TIME_BASES:
            raise OptionError("--time-base", self.time_base, f"one of {', '.join(TIME_BASES)}")
        if self.time_unit is not None and self.time_unit not in TIME_UNITS:
            raise OptionError("--time-unit", self.time_unit, f"one of {', '.join(TIME_UNITS)}")
        if self.repeats not in REPEATS_POLICIES:
            raise OptionError("--repeats", self.repeats, f"one of {', '.join(REPEATS_POLICIES)}")
        low, high = RATE_RANGE
        if self.rate is not None and not (isinstance(self.rate, numbers.Real) and low < self.rate <= high):
            raise OptionError("--rate", self.rate, f"a logger's rate in Hz, above {low:g} and at most {high:g}")


PLAUSIBLE = (-60.0, 200.0)
"""The temperatures [°C] a robot joint's motor or gearbox is met at: from a cold store to class H insulation's
180 °C. A column centred outside is refused, a sample outside is a glitch."""


def check_reference_temperature(value: float | None, option: str = "--reference-temperature") -> None:
    """Refuse a reference temperature [°C] that no joint has: not finite, or outside :data:`PLAUSIBLE` (None: the
    data's median, accepted).

    Raises:
        OptionError: naming ``option``.
    """
    low, high = PLAUSIBLE
    if value is not None and not (math.isfinite(value) and low <= value <= high):
        raise OptionError(option, value, f"a joint's temperature in °C, {low:g} to {high:g}")

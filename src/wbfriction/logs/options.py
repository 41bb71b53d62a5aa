"""The choices a user makes about reading a log, in a module that imports nothing heavy: the command line
shows their defaults in its help without loading NumPy or pyarrow."""

from __future__ import annotations

import math
from typing import Literal, get_args

from wbfriction.exceptions import OptionError

MAX_GAP = 2.0
"""Default gap [sampling periods]: a time step at least this long (against the median of the
steps around it) splits a log into segments."""
LIMIT_MARGIN = 0.2
"""How far a position may pass its URDF limits before the log is refused [rad or m]."""

TimeBase = Literal["auto", "recorded", "regularised"]
"""The time base derivatives are taken on: decided from the data (``auto``), the stamps as
recorded, or a regularised clock (:func:`~wbfriction.logs.clock.regularise`)."""
TIME_BASES: tuple[TimeBase, ...] = get_args(TimeBase)
TimeUnit = Literal["s", "ms", "us", "ns"]
"""The unit of a numeric ``time`` column (``--time-unit``)."""
TIME_UNITS: tuple[TimeUnit, ...] = get_args(TimeUnit)

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

"""The physical range of every number a user gives: one table, one check (issue 65, class 2).

A robot's TOML, a log's gain columns and the command line's options each take numbers whose type alone admits
values no robot has: an armature of 1e6 kg·m², an encoder offset of 100 rad, a foot of 5 m, a physics step of
1e-12 s, a simulation of 1e9 s. Taken silently, they give a plausible wrong number, or fail late with a traceback.
:data:`RANGES` gives each quantity its unit and the span of physically meaningful values, with the reason for the
bounds; :func:`in_range` refuses anything outside it in one line naming the file and key, the column and row, or
the option. The bounds are physical, wide enough for any robot this package models (an industrial arm to a small
quadruped), and chosen on no data set.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

from wbfriction.exceptions import InputError, OptionError

if TYPE_CHECKING:
    import numpy as np

__all__ = ["Range", "RANGES", "in_range", "check_option", "check_options", "first_outside"]


@dataclass(frozen=True)
class Range:
    """The values a quantity may take: ``[low, high]`` (``(low, high]`` with ``low_open``), finite, whole numbers
    with ``integer``.

    Attributes:
        low, high: the bounds, in ``unit``.
        unit: the unit the value is given in ("" for a count).
        why: what the bounds stand for, said with a refusal.
        low_open: the low bound itself is refused (a duration, a step: > 0).
        integer: only whole numbers.
    """

    low: float
    high: float
    unit: str
    why: str
    low_open: bool = False
    integer: bool = False

    def holds(self, value: float) -> bool:
        """Whether ``value`` lies in the range (a NaN never does)."""
        above = value > self.low if self.low_open else value >= self.low
        return bool(above and value <= self.high and (not self.integer or float(value).is_integer()))

    def span(self) -> str:
        """The range as read: ``[0, 100] kg·m²``, ``(0, 3600] s``."""
        unit = f" {self.unit}" if self.unit else ""
        low, high = (f"{int(x)}" if self.integer else f"{x:g}" for x in (self.low, self.high))
        return f"{'(' if self.low_open else '['}{low}, {high}]{unit}"


RANGES: Mapping[str, Range] = MappingProxyType({
    "armature": Range(0.0, 100.0, "kg·m²", "a reflected rotor inertia: a large industrial arm's base joint has a "
                      "few tens of kg·m²"),
    "encoder_offset": Range(-math.pi, math.pi, "rad", "an encoder's zero mis-set by at most half a turn; more is "
                            "another zero, not an offset"),
    "foot_radius": Range(0.0, 0.25, "m", "a point foot's sphere: a quadruped's is a few centimetres"),
    "torque_constant": Range(0.0, 1e3, "N·m/A", "a motor's torque per ampere at the joint, its gear included",
                             low_open=True),
    "torque_scale_sd": Range(0.0, 0.5, "", "the logged torque's relative scale error, one standard deviation: a "
                             "torque constant or a sensor's calibration known to better than half its value"),
    "kp": Range(0.0, 1e5, "N·m/rad", "a driver's position gain, >= 0"),
    "kd": Range(0.0, 1e4, "N·m·s/rad", "a driver's velocity gain, >= 0"),
    "torque_limit": Range(0.0, 1e5, "N·m", "a driver's torque limit", low_open=True),
    "pd_delay": Range(0.0, 0.5, "s", "a driver's delay is milliseconds; half a second is a clock's error, not a "
                      "driver's"),
    "delay_ms": Range(0.0, 500.0, "ms", "a driver's delay is milliseconds; half a second is a clock's error, not a "
                      "driver's"),
    "physics_dt": Range(1e-5, 0.1, "s", "a simulator's physics step: 10 µs to 100 ms"),
    "encoder_bits": Range(8, 32, "", "an encoder's resolution in bits per turn", integer=True),
    "duration": Range(0.0, 3600.0, "s", "a simulated log of at most an hour (simulate longer logs in pieces)",
                      low_open=True),
    "seed": Range(0, 2**32 - 1, "", "a random generator's seed: a whole number >= 0", integer=True),
    "position_std": Range(0.0, 0.1, "rad", "an encoder's noise: far below a tenth of a radian"),
    "torque_std": Range(0.0, 100.0, "N·m", "a torque sensor's noise"),
    "velocity_std": Range(0.0, 10.0, "rad/s", "a driver's velocity noise"),
    "substeps": Range(1, 1000, "", "physics steps per control period", integer=True),
    "rate": Range(0.0, 1e4, "Hz", "a drivers' set-point rate: a control bus's cycle, at most 10 kHz; a driver's "
                  "faster current loop runs inside it", low_open=True),
    "period": Range(0.0, 3600.0, "s", "a periodic excitation's period: at most a recording (an hour)", low_open=True),
    "share": Range(0.0, 1.0, "", "a share of a range or of a limit", low_open=True),
})
"""Each quantity's :class:`Range`, by the name :func:`in_range` takes."""


def in_range(quantity: str, value: object, where: str) -> float:
    """``value`` as a float, checked against :data:`RANGES` ``[quantity]``.

    Args:
        quantity: a key of :data:`RANGES`.
        value: the number given (a TOML value, an option).
        where: what names it for the user: ``"robot.toml: [armature] FL_hip_joint"``, ``"--duration"``.

    Raises:
        InputError: not a finite number, or outside the range: one line naming ``where``, the value, the range and
            why.
    """
    rng = RANGES[quantity]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(f"{where}: must be a number in {rng.span()}, got {value!r}")
    if not rng.holds(float(value)):
        raise InputError(f"{where}: {value:g}{' ' + rng.unit if rng.unit else ''} is outside {rng.span()}: {rng.why}")
    return float(value)


def check_option(option: str, quantity: str, value: object) -> None:
    """Refuse an option's value outside :data:`RANGES` ``[quantity]`` (``option`` as the command line spells it,
    ``--duration``; None: not given, not checked).

    Raises:
        OptionError: naming the option, the range and why.
    """
    if value is None:
        return
    rng = RANGES[quantity]
    number = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if not (number and rng.holds(float(value))):  # type: ignore[arg-type]  # a finite number: checked
        raise OptionError(option, value, f"{'a whole number' if rng.integer else 'a number'} in {rng.span()} "
                          f"({rng.why})")


def check_options(options: Mapping[str, tuple[str, object]]) -> None:
    """Refuse, before any work, an option outside its range (:func:`check_option`): ``options`` maps each option's
    name (``"--duration"``) to its quantity and the value given (None: not given, not checked).

    Raises:
        OptionError: naming the first option at fault.
    """
    for option, (quantity, value) in options.items():
        check_option(option, quantity, value)


def first_outside(quantity: str, values: np.ndarray) -> int | None:
    """The flat index of the first of ``values`` outside :data:`RANGES` ``[quantity]`` (a NaN is missing data, not
    outside), or None."""
    import numpy as np  # the command line loads this module to check its options: numpy only when arrays come

    rng = RANGES[quantity]
    flat = np.asarray(values, dtype=float).ravel()
    low = flat <= rng.low if rng.low_open else flat < rng.low
    bad = np.flatnonzero(low | (flat > rng.high))
    return int(bad[0]) if bad.size else None

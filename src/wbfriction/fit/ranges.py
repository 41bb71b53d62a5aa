"""The ranges of the terms' signals a fit saw, and a table that uses the fit outside them (issue 53).

A term beyond velocity (:mod:`~wbfriction.fit.terms`) is a law fitted on the loads, angles and temperatures of
one log: beyond them it extrapolates (a temperature law fitted on 25-55 °C applied to a table in kelvin, 270 °C
past its range, predicted 3.78 N·m RMS "with friction" against 1.73 for the rigid body alone). A fit with terms stores
the ranges its samples covered (:class:`FittedRanges`, the parameters JSON's ``terms.ranges``), and a prediction says
where a table leaves them (:meth:`~wbfriction.fit.terms.TermFit.range_use`): a plain sentence per signal; well
outside (beyond a range by more than the range's width) the prediction is not ``ok`` (:data:`OUTSIDE`).

The signals and their units: the joint angle ``q`` [rad] (the ripple; compared after reduction modulo 2π into the
turn around its fitted angles, :func:`ripple_angle`), the load ``|tau_load|`` [N·m] (the
load term is a function of its magnitude), the temperature ``T`` [°C].

**Angles are points of a circle** (issue 65, class 8). A continuous joint's angle is known modulo 2π only: a log
holds it in (−π, π] or in [0, 2π), unwrapped from wherever its window (a segment, a chunk of a long log) starts, so
the same physical motion reaches a friction table on other branches, and one table may hold it on several (a motion
across π estimated in chunks: −6.62 to 0.34 rad where the joint turned over 0.67 rad; ``estimate`` now writes a
continuous joint's angle in (−π, π], but a table need not come from it). A range of angles is therefore the shortest
arc of the circle holding them (:func:`angle_arc`), a function of the angles modulo 2π alone, and a ripple is
evaluated at the angle reduced into that arc's turn (:func:`ripple_angle`): fit and prediction see the physical angle
only, whatever its branch (the same held-out rows, fitted on the log written both ways, predicted 0.2172 and 0.2185
N·m).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from wbfriction.model.layout import principal_angle

Span = tuple[float, float]
"""A closed range ``(low, high)``, ``low <= high``, in its signal's unit."""

SIGNALS: dict[str, tuple[str, str]] = {"angle": ("angle", "rad"), "load": ("load |tau_load|", "N·m"),
                                       "temperature": ("temperature", "°C")}
"""Each stored range's key, its name in a sentence and its unit."""
TERM_SIGNAL: dict[str, str] = {"ripple": "angle", "load": "load", "temperature": "temperature"}
"""The signal each term is a function of (``direction`` has none)."""
OUTSIDE = "outside fitted ranges"
"""A prediction's status where a kept term's signal is beyond its fitted range by more than the range's width."""


def _span(x: np.ndarray | None) -> Span | None:
    """``(min, max)`` of the finite values of ``x``; None without any."""
    if x is None:
        return None
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return (float(x.min()), float(x.max())) if x.size else None


@dataclass(frozen=True)
class FittedRanges:
    """The signals' ranges over the samples a joint's terms were fitted on; None: not logged.

    Attributes:
        angle: the arc of the joint's angles ``(q_low, q_high)`` [rad] (:func:`angle_arc`: ``(q_min, q_max)`` of a
            joint that stays within an arc, whatever branch the table holds its angles on).
        load: the load magnitude's ``(min |tau_load|, max |tau_load|)`` [N·m].
        temperature: ``(T_min, T_max)`` [°C].
    """

    angle: Span | None = None
    load: Span | None = None
    temperature: Span | None = None

    @classmethod
    def of(cls, use: np.ndarray, angle: np.ndarray | None = None, load: np.ndarray | None = None,
           temperature: np.ndarray | None = None) -> FittedRanges:
        """The ranges over the rows ``use`` (N,) bool of the joint angle [rad] (its arc, :func:`angle_arc`), its load
        torque ``tau_load`` [N·m] (its magnitude's range) and its temperature [°C], each (N,) or None (not logged)."""
        def pick(x: np.ndarray | None) -> np.ndarray | None:
            return None if x is None else np.asarray(x, dtype=float)[use]

        magnitude = None if load is None else np.abs(np.asarray(load, dtype=float))
        angles = pick(angle)
        return cls(None if angles is None else angle_arc(angles), _span(pick(magnitude)), _span(pick(temperature)))

    def get(self, signal: str) -> Span | None:
        """The range of ``signal`` (a key of :data:`SIGNALS`)."""
        return {"angle": self.angle, "load": self.load, "temperature": self.temperature}[signal]

    def to_dict(self) -> dict[str, list[float] | None]:
        """As the parameters JSON holds it: per signal ``[low, high]`` or ``null``."""
        return {k: None if (s := self.get(k)) is None else [s[0], s[1]] for k in SIGNALS}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> FittedRanges:
        """Inverse of :meth:`to_dict` (a missing signal: not logged).

        Raises:
            ValueError: not an object, an unknown key, a range that is not two finite numbers, low then high (a load
                range below zero); the message names the key (``ranges.<signal>``).
        """
        if not isinstance(d, Mapping):
            raise ValueError("ranges: not an object of signal ranges")
        unknown = sorted(set(d) - set(SIGNALS))
        if unknown:
            raise ValueError(f"ranges.{unknown[0]}: not a signal (ranges of {', '.join(SIGNALS)})")
        return cls(**{k: check_span(d.get(k), f"ranges.{k}", nonnegative=k == "load") for k in SIGNALS})


def angle_arc(q: np.ndarray) -> Span | None:
    """The shortest arc of the circle holding every finite angle of ``q`` (N,) [rad], as ``(low, high)``: it starts
    past the widest gap between the angles taken modulo 2π and runs round to the gap's other side; ``low`` in
    (−π, π], ``low <= high < low + 2π``. A function of the angles modulo 2π only: angles on other branches, or on
    several at once (a continuous joint, module docstring), give the same arc, up to rounding. Angles that never wrap,
    with no gap between them wider than the one their span leaves (a limited joint's), give ``(min, max)`` itself,
    moved by whole turns into ``low`` in (−π, π] (:func:`~wbfriction.model.layout.principal_angle`). None without any
    finite angle."""
    q = np.asarray(q, dtype=float)
    q = q[np.isfinite(q)]
    if not q.size:
        return None
    turn = np.mod(q, 2.0 * np.pi)
    order = np.argsort(turn, kind="stable")
    ordered = turn[order]
    gaps = np.diff(ordered, append=ordered[0] + 2.0 * np.pi)  # after each angle, the last one's round to the first
    widest = int(np.argmax(gaps))
    low = float(principal_angle(q[order[(widest + 1) % q.size]]))
    end = q[order[widest]]
    return low, float(end - 2.0 * np.pi * np.floor((end - low) / (2.0 * np.pi)))


def same_turn(q: np.ndarray, span: Span) -> np.ndarray:
    """The angles ``q`` (N,) [rad] reduced modulo 2π into the turn centred on ``span``: the same angles of a joint
    (of a periodic function of them), on the branch nearest the range."""
    middle = 0.5 * (span[0] + span[1])
    return np.asarray(q, dtype=float) - 2.0 * np.pi * np.round((np.asarray(q, dtype=float) - middle) / (2.0 * np.pi))


def ripple_angle(q: np.ndarray, q_range: Span | None) -> np.ndarray:
    """The angle ``q`` (N,) [rad] a ripple fitted on the angles of the arc ``q_range`` (:func:`angle_arc`) is evaluated
    at: reduced modulo 2π into the turn centred on ``q_range`` (:func:`same_turn`: a ripple, a series in ``sin(h q)``,
    ``cos(h q)``, is periodic in 2π, and a continuous joint logged on another branch is at the same angle), then held
    within ``q_range`` (beyond it the series is not known, its value at the nearest fitted angle going round the circle
    is kept); ``q`` as given without ``q_range``. With the arc, a function of ``q`` modulo 2π (up to rounding)."""
    q = np.asarray(q, dtype=float)
    return q if q_range is None else np.clip(same_turn(q, q_range), *q_range)


def check_span(value: Any, key: str, nonnegative: bool = False) -> Span | None:
    """``value`` (``null`` or ``[low, high]``) as a :data:`Span`.

    Raises:
        ValueError: not two finite numbers, low above high, or (``nonnegative``) low below zero; naming ``key``.
    """
    if value is None:
        return None
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise ValueError(f"{key} is {value!r}, not a range [low, high]")
    try:
        low, high = float(value[0]), float(value[1])
    except (TypeError, ValueError):
        raise ValueError(f"{key} is {value!r}, not a range [low, high] of numbers") from None
    if not (math.isfinite(low) and math.isfinite(high)):
        raise ValueError(f"{key} is {value!r}: not finite")
    if low > high:
        raise ValueError(f"{key} is [{low:g}, {high:g}]: reversed (low above high)")
    if nonnegative and low < 0:
        raise ValueError(f"{key} is [{low:g}, {high:g}]: a magnitude below zero")
    return low, high


@dataclass(frozen=True)
class SignalUse:
    """How a table's samples of one signal sit against the range a term was fitted on.

    Attributes:
        signal: the signal (a key of :data:`SIGNALS`).
        fitted: the fitted range.
        used: the table's range ``(min, max)`` over the samples predicted.
        share: the share of those samples outside ``fitted`` (0-1).
        beyond: how far the farthest one is outside ``fitted`` [the signal's unit] (0: none).
    """

    signal: str
    fitted: Span
    used: Span
    share: float
    beyond: float

    @property
    def far(self) -> bool:
        """Beyond the fitted range by more than its width: the term's law extrapolated, not interpolated."""
        return self.beyond > self.fitted[1] - self.fitted[0]

    def sentence(self, terms: str) -> str:
        """One plain sentence: what this table holds, what was fitted, how far outside and what that does."""
        name, unit = SIGNALS[self.signal]
        width = self.fitted[1] - self.fitted[0]
        # how far, in the fitted range's width: however many samples are outside, that is what the words say
        held = ("held at its value at the nearest fitted angle" if self.signal == "angle"
                else "extrapolated on those samples, farther than the fitted range is wide" if self.far
                else "extrapolated on those samples, by at most "
                     f"{100 * self.beyond / width if width > 0 else 0:.0f} % of the fitted range's width")
        return (f"{name} {self.used[0]:.3g} to {self.used[1]:.3g} {unit} in this table, fitted on "
                f"{self.fitted[0]:.3g} to {self.fitted[1]:.3g} {unit}: {100 * self.share:.3g} % of its samples "
                f"outside, up to {self.beyond:.3g} {unit} beyond; the {terms} term {held}")


@dataclass(frozen=True)
class RangeUse:
    """A table's use of one joint's terms against their fitted ranges
    (:meth:`~wbfriction.fit.terms.TermFit.range_use`).

    Attributes:
        joint: the joint.
        outside: each signal a kept term reads that leaves its fitted range (:class:`SignalUse`).
        unknown: the kept terms whose fitted range the parameters file does not record (an earlier version's).
    """

    joint: str
    outside: tuple[SignalUse, ...] = ()
    unknown: tuple[str, ...] = ()

    @property
    def far(self) -> bool:
        """Some signal is beyond its fitted range by more than the range's width (:data:`OUTSIDE`)."""
        return any(u.far for u in self.outside)

    def sentences(self) -> list[str]:
        """What a prediction says of it, one sentence each (none when every signal is within its range)."""
        names = {s: t for t, s in TERM_SIGNAL.items()}
        out = [u.sentence(names[u.signal]) for u in self.outside]
        if self.unknown:
            many = len(self.unknown) > 1
            out.append(f"the fitted range{'s' if many else ''} of its {', '.join(self.unknown)} term"
                       f"{'s are' if many else ' is'} not recorded (a parameters file of an earlier version): whether "
                       f"this table is within {'them' if many else 'it'} is not known")
        return out

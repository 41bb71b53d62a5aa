"""What ``identify --actuator pd --config-output`` writes: per joint and quantity, the identified value or the robot
TOML's, whichever predicts held-out blocks of the same log better.

The values a robot TOML holds for a PD-driven joint, its ``[armature]``, its ``[encoder_offset]`` and the drivers'
``[pd] delay``, are what ``estimate``, ``predict``, ``export`` and the simulators take afterwards. A status says how
well the log determines a value; it does not say whether the value or the TOML's is the better model of this robot
(an offset of 0.28 rad is ``weak`` as an encoder's error, and may still be the better stand-in for a URDF whose
masses are off; a TOML's delay of 0 is certainly wrong against a delay found at 11 ± 0.2 ms). So the choice is made
on the user's own log, by the balance the identification solves (:mod:`wbfriction.actuator.rows`), in a
blocked cross-validation:

* the balance's windows are cut into :data:`~wbfriction.fit.regression.HELD_OUT_BLOCKS` contiguous blocks in time;
  each block in turn is held out, the rest fitted, the block predicted; the score of a model is its weighted squared
  residual summed over every held-out block (rows weighted as the identification weights them: by each joint's
  residual RMS, so that joints of other torque scales count alike);
* **the delay** first (one for the robot): the delay searched on the fitted blocks against the TOML's held fixed,
  every other unknown fitted in both; the better is the delay written, and the one the rest is compared under;
* then **each joint's armature and encoder offset**, one at a time: free against held at the TOML's value, every
  other unknown fitted in both. An offset's column enters every joint's balance (gravity couples them), so the
  score is the whole balance's.

The identified value is written where two tests, each at :data:`~wbfriction.fit.selection.GAIN_Z` standard errors
(the project's one level for a held-out choice), reject the TOML's: it predicts the held-out blocks better, by more
than that many Newey-West standard errors of the lowering per window (:func:`~wbfriction.fit.regression.
held_out_gain`); and the TOML's value lies more than that many of the identified value's standard errors from it
(the log rejects the TOML's value). Either alone is not enough: a value fitted within its noise of a right TOML value
predicts held-out blocks a hair better or worse by chance (the hung Go2 whose TOML holds its true armature: lowerings
of 0.0-1.9 standard errors), and a value that absorbs a model error the log shows (a gain or a mass off: its standard
error grown by :mod:`wbfriction.actuator.law_check`) predicts better while lying far from the truth. Both scores, the
lowering with its standard error, and why, go into the identification's JSON. An armature the TOML does not state
(0: a geared drive's rotor always has one, so 0 is a value known to be wrong, not one to protect) is written wherever
it predicts the held-out blocks better, by any margin: on the real Go2, whose URDF's dynamics and logged gains
disagree (the law's scale 0.26-0.96), the armatures are uncertain (±60 % and more) and still predict the held-out
torque far better than none. Two exceptions, where the comparison
cannot be made: a value the log does not determine (``not excited``, or its joint did not move) keeps the TOML's; a
delay at the search's upper bound (the drivers' delay lies beyond ``--max-delay``) writes nothing, since every value
was fitted under a delay known to be short. And one where it cannot decide: an encoder offset is compared, and its
result in the JSON, but never written (:data:`CONFOUNDED`): the balance cannot tell it from an error of the URDF's
gravity model, which every real URDF has, so an offset that predicts better may only be standing in for masses.

Where the TOML's delay wins but the identified one was printed, the armatures and offsets written are solved again
on the whole log at the TOML's delay (:attr:`WrittenChoice.values` says which). The offsets' columns are the
gravity's linearisation about the identification's last offsets (:func:`~wbfriction.actuator.rows.balance_rows`):
a TOML offset far from them is scored to first order.

Blocked cross-validation for dependent data: Burman, Chow and Nolan, "A cross-validatory method for dependent data",
Biometrika 81(2), 1994; Roberts et al., "Cross-validation strategies for data with temporal, spatial, hierarchical,
or phylogenetic structure", Ecography 40, 2017.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
from scipy.optimize import lsq_linear

from wbfriction.actuator.options import ActuatorOptions
from wbfriction.actuator.rows import BalanceRows
from wbfriction.actuator.solve import KINDS, Design, bounds, design, search_delay
from wbfriction.fit.regression import HELD_OUT_BLOCKS, held_out_gain
from wbfriction.fit.selection import GAIN_Z

Source = Literal["identified", "given"]
WRITABLE = ("armature", "offset")
"""The per-joint quantities a robot TOML holds and ``--config-output`` decides (the delay is the robot's)."""
CONFOUNDED = ("offset",)
"""Quantities the balance cannot tell from the URDF's gravity model, compared and never written (module docstring):
an encoder offset ``o`` enters as ``g(q - o)``, and a mass or centre of mass off moves ``g`` the same way. On the
generalisation benchmark's hung Go2 (masses, centres of mass and inertias 0-20 % off), the offsets that passed both
tests lay farther from the truth than the TOML's 0 more often than nearer (issue 79's note)."""


@dataclass(frozen=True)
class WrittenValue:
    """One quantity's choice (module docstring).

    Attributes:
        kind: ``armature`` [kg·m²], ``offset`` [rad] or ``delay`` [s].
        joint: its joint ("" for the delay).
        identified: the identified value (at the delay written: module docstring).
        given: the robot TOML's (0 where it has none).
        source: which is written.
        held_out: the weighted squared residual over the held-out blocks with the identified value and with the
            given one (NaN where not compared).
        gain, gain_se: how much the identified value lowers the held-out squared residual per window, and that
            lowering's Newey-West standard error (NaN, inf where not compared).
        reason: why, in a phrase.
    """

    kind: str
    joint: str
    identified: float
    given: float
    source: Source
    held_out: tuple[float, float]
    gain: float
    gain_se: float
    reason: str

    @property
    def written(self) -> float:
        """The value written."""
        return self.identified if self.source == "identified" else self.given

    def to_dict(self) -> dict[str, Any]:
        finite = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
        return {"identified": self.identified, "given": self.given, "written": self.written, "source": self.source,
                "held_out": [finite(x) for x in self.held_out], "gain": finite(self.gain),
                "gain_se": finite(self.gain_se), "reason": self.reason}


@dataclass(frozen=True)
class WrittenChoice:
    """What ``--config-output`` writes (module docstring).

    Attributes:
        delay: the delay's choice (None: nothing is written, the delay at the search's upper bound).
        values: each joint's armature and offset (where fitted), in the balance's joint order.
        blocks: the held-out blocks the choices were scored on.
    """

    delay: WrittenValue | None
    values: tuple[WrittenValue, ...]
    blocks: int

    def of(self, kind: str) -> dict[str, float]:
        """The values of ``kind`` written from the identification, by joint (the TOML's own are left as they are)."""
        return {v.joint: v.written for v in self.values if v.kind == kind and v.source == "identified"}

    @property
    def written_delay(self) -> float | None:
        """The delay written [s], or None where the TOML's is kept or nothing is written."""
        return self.delay.written if self.delay is not None and self.delay.source == "identified" else None

    @property
    def kept(self) -> tuple[WrittenValue, ...]:
        """The values whose TOML's value is kept."""
        return tuple(v for v in ((self.delay,) if self.delay is not None else ()) + self.values
                     if v.source == "given")

    def to_dict(self) -> dict[str, Any]:
        return {"blocks": self.blocks, "delay": None if self.delay is None else self.delay.to_dict(),
                "joints": {j: {v.kind: v.to_dict() for v in self.values if v.joint == j}
                           for j in dict.fromkeys(v.joint for v in self.values)}}


@dataclass(frozen=True)
class _CrossValidation:
    """The balance's blocked cross-validation (module docstring): per held-out block, the design of the blocks fitted
    and of the one held out; rows weighted by ``weight`` (n,) of their joint; the unknowns' ``lower`` and ``upper``
    bounds."""

    rows: BalanceRows
    folds: tuple[tuple[Design, Design], ...]
    weight: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(cls, rows: BalanceRows, weight: np.ndarray, offsets: bool, offset_bound: float) -> _CrossValidation:
        windows = np.arange(len(rows.rest))
        folds = tuple((design(rows, np.setdiff1d(windows, b), offsets), design(rows, b, offsets))
                      for b in held_out_blocks(len(windows)))
        return cls(rows, folds, weight, *bounds(len(rows.joints), offsets, offset_bound))

    def searched_delays(self, options: ActuatorOptions) -> list[float]:
        """Each fold's delay searched on its fitted blocks (``options.delay`` where given)."""
        if options.delay is not None:
            return [options.delay] * len(self.folds)
        return [search_delay(self.rows, train, self.weight).delay for train, _ in self.folds]

    def score(self, delays: list[float], fixed: dict[int, float]) -> tuple[np.ndarray, np.ndarray]:
        """Each held-out window's weighted squared residual (summed over its joints) with each fold at its delay of
        ``delays`` [s] and the unknowns ``fixed`` (column -> value) held, and the windows."""
        rows, per_window, windows = self.rows, [], []
        for (train, test), d in zip(self.folds, delays):
            x = _solve(train.A, train.rhs(rows, rows.balance(d)), self.weight[train.joint], self.lower, self.upper,
                       fixed)
            e = (test.rhs(rows, rows.balance(d)) - test.A @ x) * self.weight[test.joint]
            used = np.unique(test.window)
            per_window.append(np.bincount(test.window, weights=e**2, minlength=len(rows.rest))[used])
            windows.append(used)
        return np.concatenate(per_window), np.concatenate(windows)


def held_out_blocks(count: int) -> list[np.ndarray]:
    """The windows ``0..count-1`` cut into at most :data:`HELD_OUT_BLOCKS` contiguous blocks of two windows or
    more."""
    k = max(2, min(HELD_OUT_BLOCKS, count // 2))
    return [b for b in np.array_split(np.arange(count), k) if len(b)]


def _solve(A: np.ndarray, y: np.ndarray, w: np.ndarray, lower: np.ndarray, upper: np.ndarray,
           fixed: dict[int, float]) -> np.ndarray:
    """The bounded weighted least squares with the unknowns ``fixed`` (column -> value) held."""
    free = np.ones(A.shape[1], dtype=bool)
    x = np.zeros(A.shape[1])
    for col, value in fixed.items():
        free[col] = False
        x[col] = value
    y = y - A[:, ~free] @ x[~free]
    Af = A[:, free] * w[:, None]
    active = np.any(Af != 0, axis=0)  # an empty column (a joint without rows here) stays at its lower bound
    cols = np.flatnonzero(free)[active]
    if len(cols):
        res = lsq_linear(Af[:, active], y * w, bounds=(lower[cols], upper[cols]), method="bvls", tol=1e-12)
        x[cols] = res.x
    return x


def choose_written(rows: BalanceRows, weight: np.ndarray, options: ActuatorOptions, offsets: bool,
                   given_armature: np.ndarray, given_offset: np.ndarray, given_delay: float,
                   identified: np.ndarray, se: np.ndarray, delay: float, delay_se: float,
                   excited: dict[str, np.ndarray],
                   delay_beyond: bool, delay_determined: bool = True) -> WrittenChoice:
    """Choose what ``--config-output`` writes (module docstring).

    Args:
        rows: the identification's balance (its last pass's).
        weight: (n,) each joint's rows' weight (the inverse of its residual RMS).
        options: the identification's options (``delay`` given: it is the identified delay).
        offsets: whether the offsets were fitted.
        given_armature, given_offset: (n,) the robot TOML's armature [kg·m²] and encoder offsets [rad], the
            balance's joint order.
        given_delay: the TOML's ``[pd] delay`` [s].
        identified, se: (P,) the identification's unknowns (:data:`~wbfriction.actuator.solve.KINDS` order) at
            ``delay``, and their standard errors.
        delay, delay_se: the delay identified [s] and its standard error [s].
        excited: per kind (``armature``, ``offset``), (n,) whether the log determines each joint's value.
        delay_beyond: the delay sits at the search's upper bound (nothing is written).
        delay_determined: whether the log determines the delay (not: the TOML's kept).

    Returns:
        :class:`WrittenChoice`.
    """
    n = len(rows.joints)
    kinds = [k for k in WRITABLE if k != "offset" or offsets]
    if delay_beyond:
        reason = "the delay is at the search's upper bound: every value was fitted under one known to be short"
        return WrittenChoice(None, tuple(_kept(kind, rows.joints[j], float(identified[KINDS.index(kind) * n + j]),
                                               float(_given(kind, j, given_armature, given_offset)), reason)
                                         for j in range(n) for kind in kinds), 0)
    cv = _CrossValidation.of(rows, weight, offsets, options.offset_bound)
    searched, held = cv.searched_delays(options), [given_delay] * len(cv.folds)
    free_score, win = cv.score(searched, {})
    given_score, _ = cv.score(held, {})
    delay_choice = _compare("delay", "", delay, delay_se, given_delay, free_score, given_score, win)
    if not delay_determined:
        delay_choice = replace(delay_choice, source="given", reason="the log does not determine it")
    delays, base = (searched, free_score) if delay_choice.source == "identified" else (held, given_score)
    if delay_choice.source == "given" and not np.isclose(given_delay, delay):
        # the values written with the TOML's delay are those the whole log gives under it
        whole = design(rows, np.arange(len(rows.rest)), offsets)
        identified = _solve(whole.A, whole.rhs(rows, rows.balance(given_delay)), weight[whole.joint], cv.lower,
                            cv.upper, {})
    values = []
    for j in range(n):
        for kind in kinds:
            col = KINDS.index(kind) * n + j
            given = float(_given(kind, j, given_armature, given_offset))
            if not excited[kind][j]:
                values.append(_kept(kind, rows.joints[j], float(identified[col]), given,
                                    "the log does not determine it"))
                continue
            held_score, _ = cv.score(delays, {col: given})
            value = _compare(kind, rows.joints[j], float(identified[col]), float(se[col]), given, base, held_score,
                             win, kind != "armature" or given > 0)
            if kind in CONFOUNDED and value.source == "identified":
                value = replace(value, source="given", reason=f"{value.reason}; but an encoder offset and the URDF's "
                                "gravity model (masses, centres of mass) close the balance alike, the log cannot tell "
                                "them apart: the TOML's kept")
            values.append(value)
    return WrittenChoice(delay_choice, tuple(values), len(cv.folds))


def _kept(kind: str, joint: str, identified: float, given: float, reason: str) -> WrittenValue:
    """The TOML's value kept without a comparison (module docstring's exceptions)."""
    return WrittenValue(kind, joint, identified, given, "given", (float("nan"), float("nan")), float("nan"),
                        float("inf"), reason)


def _given(kind: str, j: int, armature: np.ndarray, offset: np.ndarray) -> float:
    return armature[j] if kind == "armature" else offset[j]


def _compare(kind: str, joint: str, identified: float, se: float, given: float, free: np.ndarray,
             held: np.ndarray, windows: np.ndarray, stated: bool = True) -> WrittenValue:
    """The choice between the identified value (standard error ``se``; held-out squared residuals ``free`` per
    window) and the given one (``held``): the identified is written where both tests of the module docstring
    reject the given at :data:`~wbfriction.fit.selection.GAIN_Z` standard errors (the first alone where the TOML
    states no value: ``stated`` False)."""
    a, b = float(np.sum(free)), float(np.sum(held))
    order = np.argsort(windows, kind="stable")
    gain, gain_se = held_out_gain(np.sqrt(held[order]), np.sqrt(free[order]), windows[order])
    z = gain / gain_se if np.isfinite(gain_se) and gain_se > 0 else float("nan")
    apart = abs(identified - given) / se if se > 0 else float("inf")
    predicts = bool(z > GAIN_Z) if stated else a < b  # nothing stated: the better predictor, however slightly
    rejects = bool(apart > GAIN_Z) or not stated
    source: Source = "identified" if predicts and rejects else "given"
    if source == "identified":
        reason = (f"the TOML's {given:.4g} lies {apart:.1f} standard errors off" if stated else
                  f"the TOML states none ({given:.4g})") + (
            f", and the identified value predicts the held-out blocks better ({z:.1f} standard errors of the "
            "lowering)")
    elif not rejects:
        reason = f"the TOML's {given:.4g} lies within {GAIN_Z:g} standard errors of the identified value"
    elif not stated:
        reason = f"the identified value does not predict the held-out blocks better than none ({z:.1f})"
    else:
        reason = (f"the identified value does not predict the held-out blocks better than the TOML's {given:.4g} "
                  f"by {GAIN_Z:g} standard errors of the lowering ({z:.1f})")
    return WrittenValue(kind, joint, identified, given, source, (a, b), gain, gain_se, reason)

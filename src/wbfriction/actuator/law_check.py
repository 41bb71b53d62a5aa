"""The robot TOML's PD law checked against the log: the drivers' delay and gains the log shows against the ones
the TOML states, a disagreement named in one line with what else could explain it. The check changes no value and
no status: what ``--config-output`` writes is decided on held-out blocks of the log
(:mod:`wbfriction.actuator.written`).

The identification takes the gains of the TOML's ``[pd]`` (or the log's ``kp.<joint>``, ``kd.<joint>``) and
searches the delay itself. Two checks, both on the balance of :mod:`wbfriction.actuator.rows`:

* **gains**: the balance solved once more at the delay found with one more unknown per joint, the scale ``g`` of
  the PD law's impulse (``g (int k_p (q^des(t - d) - q_enc) - k_d qd) = Delta p - int b + I_a Delta qd + ...``):
  the rigid bodies' momentum and gravity set the torque's scale, so ``g`` says how much torque the drivers applied
  against what the TOML's law says (``kp`` 50 in a TOML whose drivers ran 25: ``g`` about 0.5). The URDF's masses
  and centres of mass set that scale too (a gravity model off by a factor reads as ``g`` off by its inverse), and so
  does an encoder offset the fit cannot take up: the log cannot tell these causes apart. A joint whose ``g`` is off
  1 by more than :data:`GAIN_TOL` and three of its standard errors is named, with the causes it may have. No
  factor between the causes is drawn (one chosen on any one robot would decide every other robot's result: on the
  real Aliengo ``g`` is 0.68-1.01 with the logged gains, on the real Go2 0.26-0.46 with its logged gains). What the
  disagreement does to the values is measured instead: where a joint's ``g`` differs from 1 by more than three of
  its standard errors (a test at the 0.3 % level), how far each of that joint's values moves when the scales are
  freed (:attr:`LawCheck.moved`) is a model error the log shows, added to their standard errors in quadrature
  (:mod:`wbfriction.actuator.identification`), as the nuisance model's sensitivity is.
* **delay**: the delay found against the TOML's ``[pd] delay``, apart by more than :data:`DELAY_TOL` periods and
  three standard errors. The identification's values are fitted at the delay found; the line says that
  ``estimate`` and ``predict`` with this TOML take another, and ``--config-output`` writes whichever of the two
  predicts the held-out blocks better.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wbfriction.actuator.rows import BalanceRows
from wbfriction.actuator.solve import Design, sandwich

GAIN_TOL = 0.1
"""A PD law's scale within this of 1 is not named (module docstring): a tenth of the torque, below the spread of
the URDF masses' errors that the real sets show (the Aliengo's ``g`` 0.68-1.01). It only decides whether a line is
printed; no value or status depends on it."""
DELAY_TOL = 0.5
"""A delay found within this many periods of the TOML's is the TOML's (module docstring): half a sample, the
resolution of a set-point's hold. The hung Go2's delay is found within 0.2 ms of its truth (a 5 ms period),
the real Aliengo's within 0.1 period of the peer's (2.64 periods)."""


@dataclass(frozen=True)
class LawCheck:
    """The TOML's PD law against the log (module docstring).

    Attributes:
        joints: the joints, the balance's order.
        gain: (n,) each joint's scale of the TOML's PD law the log shows (1: the TOML's).
        gain_se: (n,) their standard errors (:func:`~wbfriction.actuator.solve.sandwich`; inf: not determined).
        delay: the delay found [s] (None: given with ``--delay``, not checked).
        delay_se: its standard error [s].
        toml_delay: the TOML's ``[pd] delay`` [s].
        period: the log's period [s].
        moved: (P,) how far each of the identification's unknowns (:data:`~wbfriction.actuator.solve.KINDS` order)
            moves with the scales freed, where its joint's scale differs from 1 by more than three standard errors;
            0 elsewhere (module docstring).
    """

    joints: tuple[str, ...]
    gain: np.ndarray
    gain_se: np.ndarray
    delay: float | None
    delay_se: float
    toml_delay: float
    period: float
    moved: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def _beyond(self, low: float, high: float) -> tuple[str, ...]:
        off = np.abs(self.gain - 1.0)
        bad = ((self.gain < low) | (self.gain > high)) & (off > 3.0 * self.gain_se) & np.isfinite(self.gain_se)
        return tuple(j for j, b in zip(self.joints, bad) if b)

    @property
    def gains_off(self) -> tuple[str, ...]:
        """The joints whose law's scale is off 1 by more than :data:`GAIN_TOL` (named)."""
        return self._beyond(1.0 - GAIN_TOL, 1.0 + GAIN_TOL)

    @property
    def delay_differs(self) -> bool:
        """The delay found is not the TOML's."""
        if self.delay is None or not np.isfinite(self.delay_se):
            return False
        off = abs(self.delay - self.toml_delay)
        return off > DELAY_TOL * self.period and off > 3.0 * self.delay_se

    def lines(self) -> list[str]:
        """The mismatches, one line each (none: the law agrees with the log)."""
        out = []
        if self.gains_off:
            worst = max(self.gains_off, key=lambda j: abs(self.gain[self.joints.index(j)] - 1.0))
            k = self.joints.index(worst)
            out.append(f"the robot TOML's PD law and the URDF's dynamics disagree: the log's torque balance takes "
                       f"{self.gain[k]:.2f} ± {self.gain_se[k]:.2f} times the law's torque on {worst} "
                       f"({len(self.gains_off)} of {len(self.joints)} joints beyond {GAIN_TOL:.0%}): the drivers' "
                       "gains (kp, kd in [pd]), the URDF's masses and centres of mass, or an encoder offset "
                       "beyond --offset-bound; the log cannot tell which, and nothing is changed")
        if self.delay_differs:
            assert self.delay is not None
            out.append(f"the robot TOML's [pd] delay ({self.toml_delay * 1e3:.3g} ms) is not the drivers': the log "
                       f"shows {self.delay * 1e3:.3g} ± {self.delay_se * 1e3:.2g} ms; estimate and predict with "
                       "this TOML take the TOML's (--config-output writes the one that predicts held-out blocks of "
                       "the log better)")
        return out


def check_law(rows: BalanceRows, d: Design, weight: np.ndarray, delay: float, lags: int, found: bool,
              delay_se: float, toml_delay: float, excited: np.ndarray, x: np.ndarray) -> LawCheck:
    """Check the TOML's PD law against ``rows`` (module docstring) at the delay ``delay`` [s] (``found``: searched,
    with the standard error ``delay_se``; else given), rows weighted by ``weight`` (n,) of their joint, the
    sandwich's ``lags``; a joint not ``excited`` (n,) (:mod:`wbfriction.actuator.excitation`) has no scale
    determined (a joint held still balances its law against gravity and a friction anywhere within ``±F_c``).
    ``x`` (P,): the identification's unknowns at that delay, whose moves under free scales are measured."""
    n = len(rows.joints)
    dynamics = rows.rest + rows.feedback  # -Delta p + int b
    law = rows.balance(delay) - dynamics  # the set-point impulse less the feedback's: the law's impulse
    X = np.zeros((len(d.joint), n))
    X[np.arange(len(d.joint)), d.joint] = -law[d.window, d.joint]
    A = np.hstack([d.A, X])
    y = d.rhs(rows, dynamics)
    w = weight[d.joint]
    free, *_ = np.linalg.lstsq(A * w[:, None], y * w, rcond=None)
    e = y - A @ free
    count = np.maximum(np.bincount(d.joint, minlength=n), 1)
    rms = np.sqrt(np.bincount(d.joint, weights=e**2, minlength=n) / count)
    scale = np.where(rms > 0, rms, np.inf)[d.joint]
    cov = sandwich(A / scale[:, None], e / scale, d.window, lags)
    g, se = free[-n:], np.where(excited, np.sqrt(np.abs(np.diag(cov)[-n:])), np.inf)
    off = (np.abs(g - 1.0) > 3.0 * se) & np.isfinite(se)
    owner = np.arange(len(x)) % n  # each unknown's joint (KINDS blocks of n)
    moved = np.where(off[owner], np.abs(free[:-n] - x), 0.0)
    return LawCheck(rows.joints, g, se, delay if found else None, delay_se, toml_delay, rows.period, moved)

"""The robot TOML's PD law checked against the log (issue 63): the drivers' delay and gains the log shows against
the ones the TOML states, a mismatch named in one line rather than absorbed into the friction.

The identification takes the gains of the TOML's ``[pd]`` (or the log's ``kp.<joint>``, ``kd.<joint>``) and
searches the delay itself. Two checks, both on the balance of :mod:`wbfriction.actuator.rows`:

* **gains**: the balance solved once more at the delay found with one more unknown per joint, the scale ``g`` of
  the PD law's impulse (``g (int k_p (q^des(t - d) - q_enc) - k_d qd) = Delta p - int b + I_a Delta qd + ...``):
  the rigid bodies' momentum and gravity set the torque's scale, so ``g`` says how much torque the drivers applied
  against what the TOML's law says (``kp`` 50 in a TOML whose drivers ran 25: ``g`` about 0.5). The URDF's masses
  set that scale too: a ``g`` off 1 is the gains' or the masses' error, which the log cannot tell apart. A joint
  whose ``g`` is off 1 by more than :data:`GAIN_TOL` and three of its standard errors is named in a warning; beyond
  a factor :data:`GAIN_FACTOR` either way, more than the real robot's model error reaches, the law is contradicted:
  every value fitted under it is not ``ok`` (:func:`~wbfriction.actuator.identification.identify_actuators`).
* **delay**: the delay found against the TOML's ``[pd] delay``, apart by more than :data:`DELAY_TOL` periods and
  three standard errors. The identification's values are fitted at the delay found, not the TOML's, and keep their
  status; the line says that ``estimate`` and ``predict`` with this TOML take the wrong one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.actuator.rows import BalanceRows
from wbfriction.actuator.solve import Design, sandwich

GAIN_TOL = 0.1
"""A PD law's scale within this of 1 is not named (module docstring). Measured at issue 63 (the hung Go2 in MuJoCo,
4-5 s of ramps and chirps, a real driver's noise): ``g`` within 0.07 of 1 (three standard errors) on every joint
with the TOML's law; 0.43-0.56
with ``kp`` 50 against the drivers' 25. The real Aliengo (the logged gains, kp 25, kd 0.5): 0.68-1.01, nine joints
beyond 0.1, where the identification's offsets sit at their bound too: its URDF's masses or its drivers' torque are
off, and the warning says so."""
GAIN_FACTOR = 1.6
"""A PD law's scale beyond this factor either way (below 1/1.6 = 0.625 or above 1.6) contradicts the TOML's law
(module docstring): between the real Aliengo's lowest scale (0.68, a model error the log cannot lay on the gains)
and a TOML's gain off by two (0.43-0.56 on the hung Go2). A smaller error of the gains is named, not acted on."""
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
    """

    joints: tuple[str, ...]
    gain: np.ndarray
    gain_se: np.ndarray
    delay: float | None
    delay_se: float
    toml_delay: float
    period: float

    def _beyond(self, low: float, high: float) -> tuple[str, ...]:
        off = np.abs(self.gain - 1.0)
        bad = ((self.gain < low) | (self.gain > high)) & (off > 3.0 * self.gain_se) & np.isfinite(self.gain_se)
        return tuple(j for j, b in zip(self.joints, bad) if b)

    @property
    def gains_off(self) -> tuple[str, ...]:
        """The joints whose law's scale is off 1 by more than :data:`GAIN_TOL` (named)."""
        return self._beyond(1.0 - GAIN_TOL, 1.0 + GAIN_TOL)

    @property
    def gains_differ(self) -> tuple[str, ...]:
        """The joints whose law's scale contradicts the TOML's (beyond :data:`GAIN_FACTOR`: their values not ok)."""
        return self._beyond(1.0 / GAIN_FACTOR, GAIN_FACTOR)

    @property
    def delay_differs(self) -> bool:
        """The delay found is not the TOML's."""
        if self.delay is None or not np.isfinite(self.delay_se):
            return False
        off = abs(self.delay - self.toml_delay)
        return off > DELAY_TOL * self.period and off > 3.0 * self.delay_se

    def gain_reason(self, joint: str) -> str:
        """Why the values of ``joint`` fitted under the TOML's law are not ``ok`` ("" where they may be)."""
        if joint not in self.gains_differ:
            return ""
        g = float(self.gain[self.joints.index(joint)])
        return f"fitted under the TOML's PD law, but the drivers applied {g:.2f} ± "\
               f"{float(self.gain_se[self.joints.index(joint)]):.2f} times its torque (kp, kd)"

    def lines(self) -> list[str]:
        """The mismatches, one line each (none: the law agrees with the log)."""
        out = []
        if self.gains_off:
            worst = max(self.gains_off, key=lambda j: abs(np.log(self.gain[self.joints.index(j)])))
            g = self.gain[self.joints.index(worst)]
            head = (f"the robot TOML's [pd] gains are not the drivers': the log's torque is {g:.2f} times the "
                    f"TOML's PD law on {worst}" if self.gains_differ else
                    f"the robot TOML's PD law gives {g:.2f} times the torque the URDF's dynamics take on {worst}")
            tail = ("fix kp, kd in [pd] (or log kp.<joint>, kd.<joint>): the values fitted under them are not ok"
                    if self.gains_differ else
                    f"its [pd] gains or the URDF's masses are off (not acted on within a factor {GAIN_FACTOR:g})")
            out.append(f"{head} ({len(self.gains_off)} of {len(self.joints)} joints beyond {GAIN_TOL:.0%}); {tail}")
        if self.delay_differs:
            assert self.delay is not None
            out.append(f"the robot TOML's [pd] delay ({self.toml_delay * 1e3:.3g} ms) is not the drivers': the log "
                       f"shows {self.delay * 1e3:.3g} ± {self.delay_se * 1e3:.2g} ms; estimate and predict with "
                       "this TOML take the wrong one (--config-output writes the one found)")
        return out


def check_law(rows: BalanceRows, d: Design, weight: np.ndarray, delay: float, lags: int, found: bool,
              delay_se: float, toml_delay: float, excited: np.ndarray) -> LawCheck:
    """Check the TOML's PD law against ``rows`` (module docstring) at the delay ``delay`` [s] (``found``: searched,
    with the standard error ``delay_se``; else given), rows weighted by ``weight`` (n,) of their joint, the
    sandwich's ``lags``; a joint not ``excited`` (n,) (:mod:`wbfriction.actuator.excitation`) has no scale
    determined (a joint held still balances its law against gravity and a friction anywhere within ``±F_c``)."""
    n = len(rows.joints)
    dynamics = rows.rest + rows.feedback  # -Delta p + int b
    law = rows.balance(delay) - dynamics  # the set-point impulse less the feedback's: the law's impulse
    X = np.zeros((len(d.joint), n))
    X[np.arange(len(d.joint)), d.joint] = -law[d.window, d.joint]
    A = np.hstack([d.A, X])
    y = d.rhs(rows, dynamics)
    w = weight[d.joint]
    x, *_ = np.linalg.lstsq(A * w[:, None], y * w, rcond=None)
    e = y - A @ x
    count = np.maximum(np.bincount(d.joint, minlength=n), 1)
    rms = np.sqrt(np.bincount(d.joint, weights=e**2, minlength=n) / count)
    scale = np.where(rms > 0, rms, np.inf)[d.joint]
    cov = sandwich(A / scale[:, None], e / scale, d.window, lags)
    g, se = x[-n:], np.where(excited, np.sqrt(np.abs(np.diag(cov)[-n:])), np.inf)
    return LawCheck(rows.joints, g, se, delay if found else None, delay_se, toml_delay, rows.period)

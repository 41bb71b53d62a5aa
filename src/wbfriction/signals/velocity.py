"""Logged joint velocities (``qd.<joint>`` columns): how late they are against the positions.

Many robots log a velocity that their controller filtered (a low-pass, a Kalman filter, a
backward difference): it lags the positions. When such a velocity is used in place of the
differentiated one (``--velocity logged``), the friction's velocity axis is shifted by that
lag, which biases the Coulomb corner at zero velocity. This module measures the lag so that
it is stated, not assumed: the shift that best aligns the logged velocity with the central
difference of the positions (6.2), by cross-correlation over all joints, refined to a
fraction of a sample by a parabola through the peak.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class VelocityLag:
    """How late a logged velocity is.

    Attributes:
        samples: the lag [samples] (positive: the logged velocity describes an earlier instant
            than its row's stamp), to a fraction of a sample.
        seconds: the same [s] (``samples * period``).
        correlation: normalised correlation at the lag, in [-1, 1] (near 1: the logged
            velocity is the positions' derivative, delayed).
    """

    samples: float
    seconds: float
    correlation: float

    def describe(self) -> str:
        """One line for the user."""
        return (f"logged velocities lag the differentiated positions by {self.seconds * 1e3:.3g} ms "
                f"({self.samples:.2f} samples, correlation {self.correlation:.3f})")


def velocity_lag(qd_logged: np.ndarray, qd_reference: np.ndarray, period: float, max_lag: int = 50) -> VelocityLag:
    """The lag of logged velocities behind reference ones (e.g. central differences of the positions).

    Args:
        qd_logged: logged joint velocities (N, n) [rad/s].
        qd_reference: velocities describing each row's own instant (N, n) [rad/s]; NaN rows
            are left out.
        period: sampling period [s].
        max_lag: largest lag tried, each way [samples].

    Returns:
        :class:`VelocityLag`; ``samples`` maximises the summed correlation over the joints.
    """
    a = np.nan_to_num(np.asarray(qd_logged, dtype=float))
    b = np.nan_to_num(np.asarray(qd_reference, dtype=float))
    n = len(a)
    max_lag = int(min(max_lag, n // 4))
    lags = np.arange(-max_lag, max_lag + 1)
    score = np.empty(len(lags))
    for i, lag in enumerate(lags):  # logged row k + lag against reference row k
        x = a[max_lag + lag: n - max_lag + lag]
        y = b[max_lag: n - max_lag]
        score[i] = np.sum(x * y) / np.sqrt(np.sum(x * x) * np.sum(y * y) + 1e-300)
    k = int(np.argmax(score))
    frac = 0.0
    if 0 < k < len(lags) - 1:
        s0, s1, s2 = score[k - 1], score[k], score[k + 1]
        denom = s0 - 2 * s1 + s2
        frac = 0.5 * (s0 - s2) / denom if denom != 0 else 0.0
    samples = float(lags[k] + frac)
    return VelocityLag(samples, samples * period, float(score[k]))

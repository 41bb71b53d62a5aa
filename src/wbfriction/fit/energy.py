"""Energy consistency of a friction estimate (thesis 7.2, eq. 7.9, Fig. 7.4).

Friction dissipates energy: the power it extracts from the system is negative,

.. math:: P_f = \\dot q_{tc}^T \\tau_f < 0, \\qquad (7.9)

and so is each joint's own share ``qd_i tau_f,i`` for friction that depends on the joint's
own velocity. The thesis found estimates on the real robot that generate power, did not
find them in simulation with the exact model, and traced them to inertia-model errors
(:mod:`wbfriction.inertia.sensitivity`). This module measures, per joint:

* the **share of power-generating samples**: valid samples with ``qd (tau_f + tau_os) > 0``
  and ``|tau_f + tau_os|`` above a tolerance (a torque sensor's resolution: an estimate of
  nearly no friction has a random sign).
  ``tau_os`` is the torque offset of model (3.5) (sign convention of
  :mod:`wbfriction.friction.models`: ``tau_f = -f(qd)``, so ``tau_f + tau_os`` is minus the
  dissipative part). It is a sensor offset, not friction (thesis 7.2), and it would make even
  exact friction "generate power" wherever ``|f_diss(qd)| < |tau_os|``; it is removed with
  the identified value when one is given, else with 0.
* the **zero crossings** of the acceleration difference ``Delta qdd`` (5.12) against those of
  the velocity: with an exact model (and a mass matrix close to diagonal) they coincide and
  the two have opposite signs (Fig. 7.4a); the median time from each velocity crossing to
  the nearest crossing of ``Delta qdd`` in the same stretch of valid samples says how far
  they drift apart (Fig. 7.4b).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from wbfriction.fit.options import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE
from wbfriction.signals.filters import finite_runs


def generating_share(qd: np.ndarray, tau_f: np.ndarray, tau_os: float = 0.0,
                     tolerance: float = DEFAULT_TOLERANCE) -> float:
    """Share of the samples whose friction generates power: ``qd (tau_f + tau_os) > 0`` with
    ``|tau_f + tau_os| > tolerance``.

    Args:
        qd: joint velocities (N,) [rad/s]; tau_f: friction on the joint (N,) [N·m] (NaN
            samples are left out); tau_os: the model's torque offset [N·m], removed first;
        tolerance: smallest friction torque that counts [N·m].

    Returns:
        A share in [0, 1] of the finite samples; NaN without one.
    """
    friction = np.asarray(tau_f, dtype=float) + tau_os
    power = np.asarray(qd, dtype=float) * friction
    finite = np.isfinite(power)
    if not finite.any():
        return float("nan")
    return float(np.mean((power[finite] > 0) & (np.abs(friction[finite]) > tolerance)))


def zero_crossings(time: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Times where ``x`` changes sign, linearly interpolated, within the stretches where it is
    finite (a NaN gap ends a stretch) [s]."""
    out = []
    for a, b in finite_runs(x):
        t, y = time[a:b], x[a:b]
        k = np.flatnonzero(np.sign(y[1:]) * np.sign(y[:-1]) < 0)
        out.append(t[k] + (t[k + 1] - t[k]) * y[k] / (y[k] - y[k + 1]))
    return np.concatenate(out) if out else np.zeros(0)


def crossing_lags(time: np.ndarray, qd: np.ndarray, delta_qdd: np.ndarray) -> np.ndarray:
    """For each zero crossing of ``qd``, the signed time to the nearest zero crossing of
    ``delta_qdd`` in the same finite stretch of both (NaN if it has none) [s]."""
    lags = []
    both = np.where(np.isfinite(qd) & np.isfinite(delta_qdd), 0.0, np.nan)
    for a, b in finite_runs(both):
        tv = zero_crossings(time[a:b], qd[a:b])
        td = zero_crossings(time[a:b], delta_qdd[a:b])
        for t in tv:
            lags.append(float(td[np.argmin(np.abs(td - t))] - t) if td.size else float("nan"))
    return np.asarray(lags)


@dataclass
class JointEnergy:
    """Energy consistency of one joint's estimate.

    Attributes:
        joint: joint name.
        n_samples: valid samples.
        generating_share: share of them with ``qd (tau_f + tau_os) > 0`` (module docstring).
        tau_os: the offset removed [N·m].
        velocity_crossings: zero crossings of ``qd`` within valid stretches.
        delta_crossings: zero crossings of ``Delta qdd`` within valid stretches (None: no
            ``delta_qdd`` in the estimate).
        median_lag: median of ``|lag|`` over the velocity crossings (:func:`crossing_lags`) [s].
        opposite_share: share of valid samples where ``Delta qdd`` and ``qd`` have opposite
            signs (1 for Fig. 7.4a; None without ``delta_qdd``).
        threshold: the share above which the joint is flagged.
        ripple_removed: whether a fitted position ripple was taken out first (not friction).
    """

    joint: str
    n_samples: int
    generating_share: float
    tau_os: float
    velocity_crossings: int
    delta_crossings: int | None
    median_lag: float
    opposite_share: float | None
    threshold: float = DEFAULT_THRESHOLD
    ripple_removed: bool = False

    @property
    def flagged(self) -> bool:
        """True when the share of power-generating samples passes the threshold."""
        return bool(self.generating_share > self.threshold)

    def warning(self) -> str | None:
        """One line for a user, or None when the joint is not flagged."""
        if not self.flagged:
            return None
        return (f"{self.joint}: {100 * self.generating_share:.1f} % of its valid samples have friction that "
                f"generates power (eq. 7.9; threshold {100 * self.threshold:.0f} %): the inertia model, a "
                f"torque-sensor offset or the filtering is likely off (thesis 7.2)")


def energy_consistency(est, tau_os: dict[str, float] | None = None, threshold: float = DEFAULT_THRESHOLD,
                       tolerance: float = DEFAULT_TOLERANCE,
                       ripple: Mapping[str, np.ndarray] | None = None) -> list[JointEnergy]:
    """Energy consistency of every joint of a :class:`~wbfriction.friction.estimate.FrictionEstimate`
    on its valid samples.

    Args:
        est: the estimate (``delta_qdd`` optional).
        tau_os: identified torque offset per joint name [N·m] (default 0 for every joint).
        threshold: share above which a joint is flagged.
        tolerance: smallest friction torque that counts as generating power [N·m].
        ripple: per joint name, its fitted position ripple over the estimate's rows (N,) [N·m]
            (:func:`~wbfriction.fit.result.fitted_ripples`): a torque of the angle, not friction, taken out
            before the check (``tau_f + ripple``: the ripple's torque is ``-ripple``).
    """
    tau_os = tau_os or {}
    ripple = ripple or {}
    out = []
    for i, joint in enumerate(est.joints):
        v = est.valid[:, i]
        os_i = float(tau_os.get(joint, 0.0) or 0.0)
        qd = np.where(v, est.qd[:, i], np.nan)
        vel = len(zero_crossings(est.time, qd))
        delta_crossings = opposite = None
        lag = float("nan")
        if est.delta_qdd is not None:
            d = np.where(v, est.delta_qdd[:, i], np.nan)
            delta_crossings = len(zero_crossings(est.time, d))
            lags = crossing_lags(est.time, qd, d)
            lag = float(np.nanmedian(np.abs(lags))) if np.isfinite(lags).any() else float("nan")
            prod = (qd * d)[np.isfinite(qd * d)]
            opposite = float(np.mean(prod < 0)) if prod.size else float("nan")
        tau_f = est.tau_f[:, i] + ripple[joint] if joint in ripple else est.tau_f[:, i]
        share = generating_share(est.qd[v, i], tau_f[v], os_i, tolerance)
        out.append(JointEnergy(joint, int(v.sum()), share, os_i, vel, delta_crossings, lag, opposite, threshold,
                               joint in ripple))
    return out

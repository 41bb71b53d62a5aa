"""Measured kinematics: joint velocities and accelerations from logged positions (6.1.2).

The estimator compares a *measured* acceleration, obtained by numerically
differentiating the joint positions, with the one the model predicts (chapter 5).
This module holds the differentiation schemes and the alignment of every other
signal with what the derivative measures.

Differentiators map positions ``q`` (N, n) sampled every ``dt`` to ``(qd, qdd,
delay)``: ``qd[k]`` and ``qdd[k]`` are computed from samples up to ``k + lookahead``
and describe the instant ``k - delay`` (``delay`` in samples, integer). Rows whose
stencil leaves the log are NaN. New schemes (Savitzky-Golay, Butterworth: thesis 7.1)
register in :data:`DIFFERENTIATORS`.

Delay compensation (thesis 6.1.2): a causal scheme (backward differences) measures
the acceleration ``delay`` samples late. With ``compensate_delay=True`` every other
input is taken from the instant the derivative describes, i.e. the derivatives are
shifted back by ``delay`` rows. The first difference of a backward scheme keeps half
a sample of delay, which no integer shift removes (the thesis's residual error).

Torque alignment: a torque command held over each sampling period (zero-order hold)
makes the central second difference at ``k`` see the mean of ``tau[k-1]`` and
``tau[k]``: with piecewise-constant acceleration ``a`` over each period,
``(q[k+1] - 2 q[k] + q[k-1]) / dt^2 = (a[k-1] + a[k]) / 2``. The default alignment
``"zoh"`` therefore compares the acceleration with that mean; ``"sample"`` uses
``tau[k]`` (right for torques sampled from a continuous signal, and for a simulator that
integrates with semi-implicit Euler at the log rate, where the central second difference
at ``k`` is exactly the acceleration caused by ``tau[k]``). ``"auto"`` takes what the log's
metadata declares (the simulators write it), else ``"zoh"``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .exceptions import InputError
from .log import Log

Differentiator = Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, int]]


def central_differences(q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Central differences, eq. (6.2), applied for velocity and acceleration.

    ``qd[k] = (q[k+1] - q[k-1]) / (2 dt)``, ``qdd[k] = (q[k+1] - 2 q[k] + q[k-1]) / dt^2``
    (the second difference on a grid of step dt). Non-causal, zero delay; the first and
    last rows are NaN.
    """
    qd = np.full_like(q, np.nan, dtype=float)
    qdd = np.full_like(q, np.nan, dtype=float)
    qd[1:-1] = (q[2:] - q[:-2]) / (2.0 * dt)
    qdd[1:-1] = (q[2:] - 2.0 * q[1:-1] + q[:-2]) / dt**2
    return qd, qdd, 0


def backward_differences(q: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Backward differences, eq. (6.3), applied twice.

    ``qd[k] = (q[k] - q[k-1]) / dt`` (describes ``k - 1/2``) and
    ``qdd[k] = (qd[k] - qd[k-1]) / dt`` (describes ``k - 1``): causal, delay 1 sample.
    The first two rows are NaN.
    """
    qd = np.full_like(q, np.nan, dtype=float)
    qdd = np.full_like(q, np.nan, dtype=float)
    qd[1:] = (q[1:] - q[:-1]) / dt
    qdd[2:] = (qd[2:] - qd[1:-1]) / dt
    return qd, qdd, 1


DIFFERENTIATORS: dict[str, Differentiator] = {
    "central": central_differences,
    "backward": backward_differences,
}
TORQUE_ALIGNMENTS = ("zoh", "sample")


def align_torque(tau: np.ndarray, alignment: str = "zoh") -> np.ndarray:
    """Torques as seen by a central second difference at each row.

    Args:
        tau: torques (N, n) [N·m], ``tau[k]`` held over ``[t_k, t_k+1)`` for ``"zoh"``.
        alignment: ``"zoh"``: mean of ``tau[k-1]`` and ``tau[k]`` (row 0 is NaN);
            ``"sample"``: ``tau[k]`` itself.

    Raises:
        InputError: unknown alignment.
    """
    if alignment == "sample":
        return np.array(tau, dtype=float)
    if alignment == "zoh":
        out = np.full_like(tau, np.nan, dtype=float)
        out[1:] = 0.5 * (tau[1:] + tau[:-1])
        return out
    raise InputError(f"unknown torque alignment '{alignment}': choose one of {', '.join(TORQUE_ALIGNMENTS)}")


def _shift_back(x: np.ndarray, n: int) -> np.ndarray:
    """Row k of the result is row k + n of x (NaN past the end)."""
    if n == 0:
        return x
    out = np.full_like(x, np.nan)
    out[:-n] = x[n:]
    return out


@dataclass
class MeasuredKinematics:
    """Joint-space signals aligned on the same instants, ready for the estimator.

    Attributes:
        time: (N,) [s].
        q: joint positions (N, n_act) [rad].
        qd: joint velocities (N, n_act) [rad/s].
        qdd: measured joint accelerations ``qdd_msr`` (N, n_act) [rad/s^2].
        tau: torques of the torque-controlled joints, aligned (N, n_tc) [N·m].
        contact: contact flags (N, n_contacts).
        base: root poses (N, 7), or None.
        valid: rows where every signal is defined (N,).
        tau_f_true: true friction (N, n_tc), or None.
        metadata: carried from the log.
    """

    time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    contact: np.ndarray
    base: np.ndarray | None = None
    valid: np.ndarray | None = None
    tau_f_true: np.ndarray | None = None
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.valid is None:
            self.valid = (np.all(np.isfinite(self.qd), axis=1) & np.all(np.isfinite(self.qdd), axis=1)
                          & np.all(np.isfinite(self.tau), axis=1))


def measure(log: Log, diff: str = "central", *, compensate_delay: bool = True,
            torque_alignment: str = "auto") -> MeasuredKinematics:
    """Differentiate a log's joint positions and align the other signals (6.1.2).

    Args:
        log: a validated :class:`~wbfriction.log.Log`.
        diff: differentiation scheme, a key of :data:`DIFFERENTIATORS`, or ``"true"``:
            the log's true velocities and accelerations (simulated logs), with the
            torques as logged (``torque_alignment`` and delays do not apply).
        compensate_delay: shift the derivatives back by the scheme's delay so that they
            describe the same instant as the other inputs (thesis 6.1.2).
        torque_alignment: see :func:`align_torque`; ``"auto"``: the log's metadata key
            ``torque_alignment`` when a simulator wrote one, else ``"zoh"``.

    Raises:
        InputError: unknown scheme or alignment; ``"true"`` on a log without
            ``qd_true``/``qdd_true`` columns.
    """
    if diff == "true":
        if log.qd_true is None or log.qdd_true is None:
            raise InputError(f"{log.source}: diff 'true' needs the columns qd_true.* and qdd_true.* "
                             "(written by the simulators)")
        qd, qdd, tau = log.qd_true, log.qdd_true, log.tau
    else:
        try:
            differentiate = DIFFERENTIATORS[diff]
        except KeyError:
            raise InputError(f"unknown differentiation scheme '{diff}': choose one of "
                             f"{', '.join(DIFFERENTIATORS)}, true") from None
        if torque_alignment == "auto":
            torque_alignment = log.metadata.get("torque_alignment", "zoh")
        qd, qdd, delay = differentiate(log.q, log.dt)
        if compensate_delay:
            qd, qdd = _shift_back(qd, delay), _shift_back(qdd, delay)
        tau = align_torque(log.tau, torque_alignment)
    return MeasuredKinematics(
        time=log.time, q=log.q, qd=qd, qdd=qdd, tau=tau, contact=log.contact, base=log.base,
        tau_f_true=log.tau_f_true, metadata=dict(log.metadata))

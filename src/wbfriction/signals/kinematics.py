"""Measured kinematics: joint velocities and accelerations from logged positions (6.1.2).

The estimator compares a *measured* acceleration, obtained by numerically
differentiating the joint positions, with the one the model predicts (chapter 5).
This module holds the differentiation schemes and the alignment of every other
signal with what the derivative measures.

Schemes (:data:`SCHEMES`) map positions ``q`` (N, n) sampled every ``dt`` to
``(qd, qdd, delay)``: ``qd[k]`` and ``qdd[k]`` describe the instant ``k - delay``
(``delay`` in samples, integer); rows whose stencil leaves the log are NaN. ``central``
(6.2) and ``backward`` (6.3) differentiate the raw positions; ``savgol`` and
``butterworth`` add the zero-phase filters of thesis 7.1 (:mod:`wbfriction.signals.filters`).

Consistency (thesis 6.1.2): a filter applied to the measured acceleration must be applied,
with the same (zero) delay, to every signal it is compared with. With ``savgol`` the
positions, velocity and acceleration are the value and derivatives of one local fit
(7.1-7.8) and the torques go through the same fit's smoother; with ``butterworth`` the
positions and the central-difference velocity and acceleration (6.2) go through the
forward-backward low-pass, and the torques too. The estimate (5.13) is then the friction
seen through the filter (up to the filter's commutation with the slowly varying inertia and
gravity terms), and the identification passes its model through the same smoother
(:mod:`wbfriction.friction.fit`). No filter window spans a contact change: the rows whose
central stencil does (:func:`straddling`: an impact, a touch-down) are left out of every
filter, so that the rows within a window of them are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.signals.filters import SavgolSmoother, SavgolWeights, ZeroPhaseLowpass, savgol_differentiate


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


@dataclass(frozen=True)
class FilterOptions:
    """Parameters of the filtering schemes (thesis 7.1; defaults: the thesis's).

    Attributes:
        window: Savitzky-Golay window length L (odd) [samples].
        poly_order: Savitzky-Golay polynomial order k (>= 2).
        weights: Savitzky-Golay weights, ``uniform`` or ``gaussian``
            (:func:`~wbfriction.signals.filters.savgol_weights`).
        cutoff: Butterworth cutoff [Hz] (one pass, -3 dB).
        butter_order: Butterworth order n.
    """

    window: int = 151
    poly_order: int = 4
    weights: SavgolWeights = "uniform"
    cutoff: float = 10.0
    butter_order: int = 6


Smoother = SavgolSmoother | ZeroPhaseLowpass


def make_smoother(diff: Diff, filtering: FilterOptions, dt: float) -> Smoother | None:
    """The zero-phase smoother of a filtering scheme (``savgol``, ``butterworth``), else None.

    Raises:
        InputError: filter parameters that make no filter.
    """
    if diff == "savgol":
        return SavgolSmoother(filtering.window, filtering.poly_order, dt, filtering.weights)
    if diff == "butterworth":
        return ZeroPhaseLowpass(filtering.cutoff, filtering.butter_order, dt)
    return None


Scheme = Literal["central", "backward", "savgol", "butterworth"]
"""A differentiation scheme: plain differences, then the filtering ones (module docstring)."""
Diff = Literal["central", "backward", "savgol", "butterworth", "true"]
"""A scheme, or ``true``: the simulators' logged true velocities and accelerations."""
DIFFERENTIATORS = {"central": central_differences, "backward": backward_differences}
FILTERING_SCHEMES: tuple[Scheme, ...] = ("savgol", "butterworth")
SCHEMES: tuple[Scheme, ...] = get_args(Scheme)
"""Differentiation schemes by name: plain differences, then the filtering ones (module docstring)."""


def straddling(contact: np.ndarray) -> np.ndarray:
    """Rows (N,) whose central-difference stencil ``k-1 .. k+1`` spans a change of the
    contact flags: their derivatives mix two phases (an impact, a configuration change)."""
    change = np.zeros(len(contact), dtype=bool)
    change[1:] = np.any(contact[1:] != contact[:-1], axis=1)
    out = change.copy()
    out[:-1] |= change[1:]
    return out


TorqueAlignment = Literal["zoh", "sample"]
"""How torques are aligned with the central second difference (:func:`align_torque`)."""
TORQUE_ALIGNMENTS: tuple[TorqueAlignment, ...] = get_args(TorqueAlignment)


def align_torque(tau: np.ndarray, alignment: TorqueAlignment | str = "zoh") -> np.ndarray:
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
        smoother: the filtering scheme's zero-phase smoother, which every signal went
            through, or None (the identification filters the model with it).
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
    smoother: Smoother | None = None

    def __post_init__(self) -> None:
        if self.valid is None:
            self.valid = (np.all(np.isfinite(self.q), axis=1) & np.all(np.isfinite(self.qd), axis=1)
                          & np.all(np.isfinite(self.qdd), axis=1) & np.all(np.isfinite(self.tau), axis=1))


def _filtered(log: Log, tau: np.ndarray, smoother: Smoother, filtering: FilterOptions
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``q, qd, qdd, tau`` of a filtering scheme (module docstring); rows whose window reaches
    a row :func:`straddling` a contact change are NaN, except ``q`` (raw there)."""
    blank = straddling(log.contact)[:, None]
    qd_c, qdd_c, _ = central_differences(log.q, log.dt)
    qd_c, qdd_c = np.where(blank, np.nan, qd_c), np.where(blank, np.nan, qdd_c)
    if isinstance(smoother, SavgolSmoother):  # derivatives of one local fit (7.1-7.8)
        q_s, qd_s, qdd = savgol_differentiate(np.where(blank, np.nan, log.q), log.dt, filtering.window,
                                              filtering.poly_order, filtering.weights)
    else:  # central differences through the zero-phase low-pass (7.1.2)
        q_s, qd_s, qdd = smoother(np.where(blank, np.nan, log.q)), smoother(qd_c), smoother(qdd_c)
    tau = smoother(np.where(blank, np.nan, tau))
    return np.where(np.isfinite(q_s), q_s, log.q), qd_s, qdd, tau


def measure(log: Log, diff: Diff = "central", *, compensate_delay: bool = True,
            torque_alignment: TorqueAlignment | Literal["auto"] = "auto",
            filtering: FilterOptions = FilterOptions()) -> MeasuredKinematics:
    """Differentiate a log's joint positions and align the other signals (6.1.2, 7.1).

    Args:
        log: a validated :class:`~wbfriction.logs.log.Log`.
        diff: differentiation scheme, one of :data:`SCHEMES`, or ``"true"``: the log's
            true velocities and accelerations (simulated logs), with the torques as logged
            (``torque_alignment``, delays and filters do not apply).
        compensate_delay: shift the derivatives back by the scheme's delay so that they
            describe the same instant as the other inputs (thesis 6.1.2).
        torque_alignment: see :func:`align_torque`; ``"auto"``: the log's metadata key
            ``torque_alignment`` when a simulator wrote one, else ``"zoh"``.
        filtering: parameters of the ``savgol`` and ``butterworth`` schemes.

    Raises:
        InputError: unknown scheme or alignment, filter parameters that make no filter, a
            log too short for the filter; ``"true"`` on a log without
            ``qd_true``/``qdd_true`` columns.
    """
    q, smoother = log.q, None
    if diff == "true":
        if log.qd_true is None or log.qdd_true is None:
            raise InputError(f"{log.source}: diff 'true' needs the columns qd_true.* and qdd_true.* "
                             "(written by the simulators)")
        qd, qdd, tau = log.qd_true, log.qdd_true, log.tau
    else:
        if diff not in SCHEMES:
            raise InputError(f"unknown differentiation scheme '{diff}': choose one of {', '.join(SCHEMES)}, true")
        if torque_alignment == "auto":
            torque_alignment = log.metadata.get("torque_alignment", "zoh")
        smoother = make_smoother(diff, filtering, log.dt)
        tau = align_torque(log.tau, torque_alignment)
        if smoother is None:
            qd, qdd, delay = DIFFERENTIATORS[diff](log.q, log.dt)
            if compensate_delay:
                qd, qdd = _shift_back(qd, delay), _shift_back(qdd, delay)
        else:
            q, qd, qdd, tau = _filtered(log, tau, smoother, filtering)
    return MeasuredKinematics(
        time=log.time, q=q, qd=qd, qdd=qdd, tau=tau, contact=log.contact, base=log.base,
        tau_f_true=log.tau_f_true, metadata=dict(log.metadata), smoother=smoother)

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
(:mod:`wbfriction.fit`). No filter window spans a contact change: the rows whose
central stencil does (:func:`straddling`: an impact, a touch-down) are left out of every
filter, so that the rows within a window of them are NaN; there the velocity, the argument of
the friction model, falls back to the raw central (or three-point) difference, so that the fit,
which filters its model along time, loses one window around a contact change and not two.
Which signals are filtered was measured (issue 20, TALOS combined walk, worst leg F_v error):
the torque stays filtered (left raw, its content above the cutoff biases the estimate: 3.8 ->
7.7 % on the exact log with Savitzky-Golay 151), the velocity is the filter's (raw central
differences at 1e-4 rad noise blur the Coulomb corner: 100 %), filled in the margins as above.

Non-uniform samples: a log whose clock is not uniform (:class:`~wbfriction.logs.clock.Clock`:
exact stamps that skip samples, or receive-time stamps regularised) is differentiated on its
time base ``log.clock.t``, never with a constant period: the same schemes in their non-uniform
forms (:mod:`wbfriction.signals.nonuniform`: three-point differences, Savitzky-Golay fits on the
actual times, Butterworth through a uniform grid), and the ``zoh`` torque alignment weighs the
two held torques by how long each was held.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.signals import nonuniform
from wbfriction.signals.base_motion import base_twist_and_acceleration, continuous_quaternions
from wbfriction.signals.filters import SavgolSmoother, ZeroPhaseLowpass, savgol_differentiate
from wbfriction.signals.nonuniform import NonUniformSavgol, ResampledLowpass
from wbfriction.signals.options import (
    SCHEMES,
    TORQUE_ALIGNMENTS,
    VELOCITIES,
    Diff,
    FilterOptions,
    TorqueAlignment,
    Velocity,
)
from wbfriction.signals.velocity import velocity_lag
from wbfriction.signals.window import MomentumWindow


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


@dataclass(frozen=True, eq=False)
class PiecewiseSmoother:
    """The smoothers of consecutive stretches of one log (its segments), each on its own rows:
    what the non-uniform smoothers, tied to their samples' times, become when the stretches'
    estimates are joined (:func:`joined_smoother`).

    Attributes:
        parts: ``(start, stop, smoother)`` of each stretch's rows.
    """

    parts: tuple[tuple[int, int, Smoother | None], ...]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Each stretch of ``x`` (N, ...) through its own smoother (NaN without one)."""
        x = np.asarray(x, dtype=float)
        out = np.full_like(x, np.nan)
        for a, b, smoother in self.parts:
            if smoother is not None:
                out[a:b] = smoother(x[a:b])
        return out


Smoother = SavgolSmoother | ZeroPhaseLowpass | NonUniformSavgol | ResampledLowpass | MomentumWindow | PiecewiseSmoother


def joined_smoother(smoothers: list[Smoother | None], lengths: list[int]) -> Smoother | None:
    """One smoother for estimates of consecutive stretches joined along time: the first when every
    one is the same time-invariant filter (uniform samples, as before), else a
    :class:`PiecewiseSmoother` applying each to its own rows; None when none has one."""
    present = [s for s in smoothers if s is not None]
    if not present:
        return None
    first = present[0]
    if isinstance(first, SavgolSmoother | ZeroPhaseLowpass) and all(s == first for s in present):
        return first
    edges = np.cumsum([0, *lengths]).tolist()
    return PiecewiseSmoother(tuple((a, b, s) for a, b, s in zip(edges[:-1], edges[1:], smoothers)))


def make_smoother(diff: Diff, filtering: FilterOptions, dt: float, t: np.ndarray | None = None) -> Smoother | None:
    """The zero-phase smoother of a filtering scheme (``savgol``, ``butterworth``), else None.

    Args:
        dt: the sampling period [s] (non-uniform samples: the Butterworth grid's step).
        t: non-uniform sample times (N,) [s] (:attr:`~wbfriction.logs.clock.Clock.t`): the
            smoothers of :mod:`~wbfriction.signals.nonuniform` on them; None: uniform samples.

    Raises:
        InputError: filter parameters that make no filter.
    """
    if diff == "savgol":
        if t is not None:
            return NonUniformSavgol(t, filtering.window, filtering.poly_order, filtering.weights)
        return SavgolSmoother(filtering.window, filtering.poly_order, dt, filtering.weights)
    if diff == "butterworth":
        lowpass = ZeroPhaseLowpass(filtering.cutoff, filtering.butter_order, dt)
        return lowpass if t is None else ResampledLowpass(t, lowpass)
    return None


DIFFERENTIATORS = {"central": central_differences, "backward": backward_differences}
NONUNIFORM_DIFFERENTIATORS = {"central": nonuniform.three_point_differences,
                              "backward": nonuniform.backward_differences}
"""The same schemes on non-uniform sample times ``(q, t)`` (:mod:`~wbfriction.signals.nonuniform`)."""


def straddling(contact: np.ndarray) -> np.ndarray:
    """Rows (N,) whose central-difference stencil ``k-1 .. k+1`` spans a change of the
    contact flags: their derivatives mix two phases (an impact, a configuration change)."""
    change = np.zeros(len(contact), dtype=bool)
    change[1:] = np.any(contact[1:] != contact[:-1], axis=1)
    out = change.copy()
    out[:-1] |= change[1:]
    return out




def align_torque(tau: np.ndarray, alignment: TorqueAlignment | str = "zoh", t: np.ndarray | None = None) -> np.ndarray:
    """Torques as seen by a central second difference at each row.

    Args:
        tau: torques (N, n) [N·m], ``tau[k]`` held over ``[t_k, t_k+1)`` for ``"zoh"``.
        alignment: ``"zoh"``: mean of ``tau[k-1]`` and ``tau[k]`` (row 0 is NaN);
            ``"sample"``: ``tau[k]`` itself.
        t: non-uniform sample times (N,) [s], or None. With ``"zoh"``, the three-point second
            difference at ``k`` sees ``(h1 tau[k-1] + h2 tau[k]) / (h1 + h2)``, each torque
            weighed by how long it was held (``h1 = t_k - t_k-1``, ``h2 = t_k+1 - t_k``: exact
            for a double integrator); the first and last rows are NaN.

    Raises:
        InputError: unknown alignment.
    """
    if alignment == "sample":
        return np.array(tau, dtype=float)
    if alignment == "zoh":
        out = np.full_like(tau, np.nan, dtype=float)
        if t is None:
            out[1:] = 0.5 * (tau[1:] + tau[:-1])
        else:
            h = np.diff(np.asarray(t, dtype=float)).reshape((-1,) + (1,) * (np.ndim(tau) - 1))
            out[1:-1] = (h[:-1] * tau[:-2] + h[1:] * tau[1:-1]) / (h[:-1] + h[1:])
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
        base_qd, base_qdd: the base's twist and acceleration (N, 6) in the base frame, from its
            logged pose differentiated like the joints (:mod:`~wbfriction.signals.base_motion`;
            ``measure(..., base_motion=True)``), or None.
        wrench: the force-torque sensors' wrenches (N, n_sensors, 6) [N, N·m], aligned and filtered as
            the torques, or None.
        imu: with ``measure(..., imu=True)``, the IMU's angular velocity, its time derivative and its
            specific force (N, 9) [rad/s, rad/s^2, m/s^2] in its frame, through the joints' scheme; or None.
        foot_force: the feet's measured forces (N, n_contacts, 3) [N], world axes, NaN where not measured
            (:mod:`wbfriction.logs.foot_forces`), aligned and filtered as the torques, or None.
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
    base_qd: np.ndarray | None = None
    base_qdd: np.ndarray | None = None
    wrench: np.ndarray | None = None
    imu: np.ndarray | None = None
    foot_force: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.valid is None:
            self.valid = (np.all(np.isfinite(self.q), axis=1) & np.all(np.isfinite(self.qd), axis=1)
                          & np.all(np.isfinite(self.qdd), axis=1) & np.all(np.isfinite(self.tau), axis=1))


def _filtered(log: Log, tau: np.ndarray, smoother: Smoother, filtering: FilterOptions
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``q, qd, qdd, tau`` of a filtering scheme (module docstring); rows whose window reaches
    a row :func:`straddling` a contact change are NaN, except ``q`` and ``qd``, raw there (the
    positions and their central or three-point velocity, NaN only on the straddling rows): the fit
    filters its model f(qd) along time, and so keeps every sample one window from a contact change
    instead of two (the wiring measured in issue 20: Butterworth 20 Hz on 19-bit encoders, worst
    leg F_v 15.6 % with the velocity NaN in the margins, 6.0 % with it filled)."""
    blank = straddling(log.contact)[:, None]
    t = time_base(log)
    qd_c, qdd_c, _ = (central_differences(log.q, log.dt) if t is None
                      else NONUNIFORM_DIFFERENTIATORS["central"](log.q, t))
    qd_c, qdd_c = np.where(blank, np.nan, qd_c), np.where(blank, np.nan, qdd_c)
    if isinstance(smoother, NonUniformSavgol | ResampledLowpass):  # on the actual times (nonuniform)
        q_s, qd_s, qdd = smoother.differentiate(np.where(blank, np.nan, log.q))
    elif isinstance(smoother, SavgolSmoother):  # derivatives of one local fit (7.1-7.8)
        q_s, qd_s, qdd = savgol_differentiate(np.where(blank, np.nan, log.q), log.dt, filtering.window,
                                              filtering.poly_order, filtering.weights)
    else:  # central differences through the zero-phase low-pass (7.1.2), uniform samples
        q_s, qd_s, qdd = smoother(np.where(blank, np.nan, log.q)), smoother(qd_c), smoother(qdd_c)
    tau = smoother(np.where(blank, np.nan, tau))
    return np.where(np.isfinite(q_s), q_s, log.q), np.where(np.isfinite(qd_s), qd_s, qd_c), qdd, tau




def measure(log: Log, diff: Diff = "central", *, compensate_delay: bool = True,
            torque_alignment: TorqueAlignment | Literal["auto"] = "auto",
            filtering: FilterOptions = FilterOptions(), velocity: Velocity = "differentiated",
            base_motion: bool = False, imu: bool = False) -> MeasuredKinematics:
    """Differentiate a log's joint positions and align the other signals (6.1.2, 7.1).

    Args:
        log: a validated :class:`~wbfriction.logs.log.Log`; when its clock is not uniform
            (:attr:`~wbfriction.logs.log.Log.clock`), differentiated on ``log.clock.t`` (module
            docstring) and the clock's kind and reason are added to the metadata (``clock``).
        diff: differentiation scheme, one of :data:`SCHEMES`, or ``"true"``: the log's
            true velocities and accelerations (simulated logs), with the torques as logged
            (``torque_alignment``, delays and filters do not apply).
        compensate_delay: shift the derivatives back by the scheme's delay so that they
            describe the same instant as the other inputs (thesis 6.1.2).
        torque_alignment: see :func:`align_torque`; ``"auto"``: the log's metadata key
            ``torque_alignment`` when a simulator wrote one, else ``"zoh"``.
        filtering: parameters of the ``savgol`` and ``butterworth`` schemes.
        velocity: ``differentiated`` (the scheme's), or ``logged``: the log's ``qd.<joint>``
            columns as they are (the accelerations stay the scheme's); how late they are
            against the differentiated ones (:func:`~wbfriction.signals.velocity.velocity_lag`)
            is measured and stated in the metadata (``velocity``), not compensated.
        base_motion: also differentiate the logged base pose with the joints' scheme and filter
            (:mod:`~wbfriction.signals.base_motion`; ``"true"``: the log's ``base_qd_true`` and
            ``base_qdd_true``). The force-torque sensors' wrenches, when logged, are aligned and
            filtered as the torques are: a sensor's reading is its mean over the sampling period (its
            anti-aliasing), as a held torque is the period's torque.
        imu: also pass the log's IMU readings through: the gyro differentiated once with the joints'
            scheme and filter (the scheme is applied to its running integral, so that its rate and its
            derivative come out of the same filter as the joints' ``qd`` and ``qdd``), the specific force
            aligned and filtered as the torques; ``"true"``: the gyro as logged, its derivative by
            central differences.

    Raises:
        InputError: unknown scheme, alignment or velocity source, filter parameters that make
            no filter, a log too short for the filter; ``"true"`` on a log without
            ``qd_true``/``qdd_true`` columns; ``logged`` on a log without ``qd.<joint>`` columns;
            ``base_motion`` on a log without a base pose (with ``"true"``: without its true rates);
            ``imu`` on a log without ``imu.*`` columns.
    """
    _check_inputs(log, velocity, base_motion, imu)
    if diff == "true":
        return true_kinematics(log, base_motion, imu)
    if diff not in SCHEMES:
        raise InputError(f"unknown differentiation scheme '{diff}': choose one of {', '.join(SCHEMES)}, true")
    n, n_act, n_tc = len(log.time), log.q.shape[1], log.tau.shape[1]
    # the base pose, the gyro's integral, the wrenches and the specific force go through the joints' path,
    # as more columns: positions [joints, base pose, gyro integral], torques [joints, wrenches, acc]
    extra_q = ([continuous_quaternions(log.base)] if base_motion and log.base is not None else []) + \
        ([_running_integral(log.imu[:, :3], _times(log))] if imu and log.imu is not None else [])
    feet = None if log.foot_force is None else np.isfinite(log.foot_force[:1]).reshape(-1)  # measured components
    extra_tau = ([log.wrench.reshape(n, -1)] if log.wrench is not None else []) + \
        ([log.imu[:, 3:]] if imu and log.imu is not None else []) + \
        ([log.foot_force.reshape(n, -1)[:, feet]] if log.foot_force is not None and feet is not None else [])
    extended = replace(log, q=np.hstack([log.q, *extra_q]), tau=np.hstack([log.tau, *extra_tau]))
    q, qd, qdd, tau, smoother, metadata = _derivatives(extended, diff, compensate_delay, torque_alignment, filtering)
    base_qd = base_qdd = imu_rates = None
    if base_motion:
        base_qd, base_qdd = base_twist_and_acceleration(q[:, n_act:n_act + 7], qd[:, n_act:n_act + 7],
                                                        qdd[:, n_act:n_act + 7])
    n_w = 0 if log.wrench is None else log.wrench.shape[1] * 6
    wrench = None if log.wrench is None else tau[:, n_tc:n_tc + n_w].reshape(n, -1, 6)
    if imu:
        g = slice(q.shape[1] - 3, q.shape[1])
        imu_rates = np.hstack([qd[:, g], qdd[:, g], tau[:, n_tc + n_w:n_tc + n_w + 3]])
    foot_force = None
    if feet is not None:
        foot_force = np.full((n, feet.size), np.nan)
        foot_force[:, feet] = tau[:, tau.shape[1] - int(feet.sum()):]
        foot_force = foot_force.reshape(n, -1, 3)
    q, qd, qdd, tau = q[:, :n_act], qd[:, :n_act], qdd[:, :n_act], tau[:, :n_tc]
    if velocity == "logged":
        qd = logged_velocity(log, qd, metadata)
    return without_unsure(log, MeasuredKinematics(
        time=log.time, q=q, qd=qd, qdd=qdd, tau=tau, contact=log.contact, base=log.base,
        tau_f_true=log.tau_f_true, metadata=metadata, smoother=smoother, base_qd=base_qd, base_qdd=base_qdd,
        wrench=wrench, imu=imu_rates, foot_force=foot_force))


def _check_inputs(log: Log, velocity: Velocity, base_motion: bool, imu: bool) -> None:
    """Refuse a velocity source that is none, or signals :func:`measure` is asked for that the log does not have."""
    if velocity not in VELOCITIES:
        raise InputError(f"unknown velocity source '{velocity}': choose one of {', '.join(VELOCITIES)}")
    if velocity == "logged" and log.qd_logged is None:
        raise InputError(f"{log.source}: --velocity logged needs the columns qd.<joint> of every actuated joint")
    if base_motion and log.base is None:
        raise InputError(f"{log.source}: a measured base motion needs the base pose columns base.x ... base.qw")
    if imu and (log.imu is None or np.isnan(log.imu[:, 3:]).all()):
        what = "" if log.imu is None else " (the log has a gyro without an accelerometer)"
        raise InputError(f"{log.source}: --base-motion imu needs the columns imu.gyro_x ... imu.acc_z{what}")


def true_kinematics(log: Log, base_motion: bool = False, imu: bool = False) -> MeasuredKinematics:
    """The simulators' true velocities and accelerations (``diff="true"``), the torques as logged; with
    ``base_motion``, the base's true twist and acceleration; with ``imu``, the gyro as logged, its derivative by
    central differences (:func:`numpy.gradient`) and the specific force.

    Raises:
        InputError: a log without ``qd_true``/``qdd_true`` columns (with ``base_motion``: without its true rates).
    """
    if log.qd_true is None or log.qdd_true is None:
        raise InputError(f"{log.source}: diff 'true' needs the columns qd_true.* and qdd_true.* "
                         "(written by the simulators)")
    if base_motion and (log.base_qd_true is None or log.base_qdd_true is None):
        raise InputError(f"{log.source}: diff 'true' with a measured base motion needs the columns "
                         "base_qd_true.* and base_qdd_true.* (written by the simulators)")
    imu_rates = None
    if imu:
        assert log.imu is not None  # checked by measure
        imu_rates = np.hstack([log.imu[:, :3], np.gradient(log.imu[:, :3], log.time, axis=0), log.imu[:, 3:]])
    return without_unsure(log, MeasuredKinematics(
        time=log.time, q=log.q, qd=log.qd_true, qdd=log.qdd_true, tau=log.tau, contact=log.contact,
        base=log.base, tau_f_true=log.tau_f_true, metadata=dict(log.metadata), wrench=log.wrench,
        base_qd=log.base_qd_true if base_motion else None, base_qdd=log.base_qdd_true if base_motion else None,
        imu=imu_rates, foot_force=log.foot_force))


def without_unsure(log: Log, kin: MeasuredKinematics) -> MeasuredKinematics:
    """``kin`` with the log's rows whose contact flags are not sure (:attr:`Log.unsure
    <wbfriction.logs.log.Log.unsure>`) not valid: no route estimates them."""
    if log.unsure is not None:
        assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
        kin.valid = kin.valid & ~log.unsure
    return kin


def logged_velocity(log: Log, qd: np.ndarray, metadata: dict) -> np.ndarray:
    """The log's own velocities (``qd.<joint>``) where the scheme's ``qd`` (N, n_act) [rad/s] is defined (NaN
    elsewhere); how late they are against it (:func:`~wbfriction.signals.velocity.velocity_lag`) is stated in
    ``metadata["velocity"]``, not compensated."""
    assert log.qd_logged is not None  # checked by measure
    lag = velocity_lag(log.qd_logged, qd, log.dt)
    metadata["velocity"] = {"source": "logged", "lag_s": lag.seconds, "correlation": lag.correlation,
                            "reason": lag.describe()}
    return np.where(np.isfinite(qd), log.qd_logged, np.nan)


def _times(log: Log) -> np.ndarray:
    """The times (N,) [s] the log is differentiated on: its non-uniform time base, or its constant period's."""
    t = time_base(log)
    return log.dt * np.arange(len(log.time)) if t is None else t


def _running_integral(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The trapezoidal running integral of ``x`` (N, m) over the times ``t`` (N,), zero at the first row."""
    out = np.zeros_like(x, dtype=float)
    out[1:] = np.cumsum(0.5 * (x[1:] + x[:-1]) * np.diff(t)[:, None], axis=0)
    return out


def _derivatives(log: Log, diff: Diff, compensate_delay: bool, torque_alignment: TorqueAlignment | Literal["auto"],
                 filtering: FilterOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Smoother | None,
                                                    dict]:
    """``q, qd, qdd, tau``, the smoother and the metadata of :func:`measure` for a scheme of :data:`SCHEMES`."""
    q, smoother, metadata = log.q, None, dict(log.metadata)
    if torque_alignment == "auto":
        torque_alignment = log.metadata.get("torque_alignment", "zoh")
    t = time_base(log)
    if t is not None and log.clock is not None:
        metadata["clock"] = {"kind": log.clock.kind, "reason": log.clock.reason}
    smoother = make_smoother(diff, filtering, log.dt, t)
    tau = align_torque(log.tau, torque_alignment, t)
    if smoother is None:
        qd, qdd, delay = (DIFFERENTIATORS[diff](log.q, log.dt) if t is None
                          else NONUNIFORM_DIFFERENTIATORS[diff](log.q, t))
        if compensate_delay:
            qd, qdd = _shift_back(qd, delay), _shift_back(qdd, delay)
    else:
        q, qd, qdd, tau = _filtered(log, tau, smoother, filtering)
    return q, qd, qdd, tau, smoother, metadata


def time_base(log: Log) -> np.ndarray | None:
    """The non-uniform time base a log is differentiated on (N,) [s]: ``log.clock.t`` when its
    clock is not uniform; None (a constant period, ``log.dt``) otherwise.

    Raises:
        InputError: a clock of another length than the log.
    """
    clock = log.clock
    if clock is None or clock.uniform:
        return None
    if len(clock.t) != len(log.time):
        raise InputError(f"{log.source}: a clock of {len(clock.t)} samples for a log of {len(log.time)}")
    return clock.t

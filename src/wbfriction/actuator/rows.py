"""The momentum balance of PD-driven joints over short windows: a problem linear in the armature, the friction and
the encoder offsets at every set-point delay, and linear in the delay between two whole periods.

On a fixed-base tree (a robot hung with its base fixed), the generalized momentum of the rigid bodies
``p = M(q) qd`` obeys, joint by joint (:mod:`wbfriction.model.momentum`; De Luca and Mattone, ICRA 2003),

.. math::

    p_{t_1} - p_{t_0} + I_a (\\dot q_{t_1} - \\dot q_{t_0}) = \\int_{t_0}^{t_1} (\\tau + \\tau_f + b)\\, dt,
    \\qquad b = C(q, \\dot q)^T \\dot q - g(q),

with ``tau`` the driver's torque (:mod:`wbfriction.model.pd`), ``I_a`` the armature (the rotor's inertia through the
gear), ``tau_f = -(F_v qd + F_c tanh(a qd))`` a Coulomb-viscous friction (the nuisance model of the identification:
the family is fitted afterwards, :mod:`wbfriction.fit`) and the dynamics taken at the model's angle ``q = q_enc -
o``, the encoder's reading less its offset ``o``; linearised about a guess ``o_0`` (``g(q_enc - o) = g(q_enc - o_0)
- dg/dq (o - o_0)``), the balance over a window is

.. math::

    Y(d) = \\underbrace{\\int k_p q^{des}(t - d) + \\dots}_{\\text{set-point impulse}}
           - \\int (k_p q_{enc} + k_d \\dot q) - \\Delta p + \\int b
         = I_a \\Delta\\dot q + F_v \\int \\dot q + F_c \\int \\tanh(a \\dot q)
           - \\Big(\\int \\frac{dg}{dq}\\Big)(o - o_0).

No acceleration anywhere: the velocity of the dynamics is the positions' central difference (``velocity =
"positions"``: the encoder's readings, not filtered) or the driver's own (``"logged"``, ``qd.<joint>``, which a
driver may filter: the real Aliengo's lags, :class:`~wbfriction.actuator.options.ActuatorOptions`); the PD law's
damping term always takes the driver's. The
set-points are held by the driver (zero-order hold) and applied ``d`` late (or its whole law's torque, ``delayed =
"torque"``: then the law's impulse takes the set-points' place and no feedback is left, each step's the law's mean
over it, the feedback by the trapezoid as without: :func:`_law_mean`), so a step's impulse is the commanded value at
``t_i - d`` linearly interpolated, times the step (:func:`~wbfriction.model.pd.delayed`): between
two whole periods ``kT <= d <= (k+1)T`` the impulse is linear in ``d``, and the whole problem is a linear least
squares whose right-hand side moves along a segment: the delay's search is exact, interval by interval
(:mod:`wbfriction.actuator.solve`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.actuator.options import STEEPER, ActuatorOptions
from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.logs.torque import torque_kind
from wbfriction.model.momentum import momentum_and_drift
from wbfriction.model.robot import Robot
from wbfriction.signals.content import acceleration_content


@dataclass(frozen=True)
class BalanceRows:
    """The balance (module docstring) of the ``n`` PD-driven joints over ``W`` windows.

    Attributes:
        joints: the joints, in :attr:`PdDriver.joints <wbfriction.model.pd.PdDriver.joints>` order.
        setpoint: (K + 2, W, n) the set-point impulses at the whole delays ``0, T, ..., (K + 1) T`` [N·m·s].
        rest: (W, n) the rest of ``Y``: feedback impulse, less ``Delta p``, plus ``int b`` [N·m·s].
        dv: (W, n) the change of the driver's velocity over the window [rad/s] (the armature's column).
        qd: (W, n) ``int qd dt`` [rad] (the viscous column).
        coulomb: (W, n) ``int tanh(a qd) dt`` [s] (the Coulomb column).
        gravity: (W, n, n) ``int dg/dq dt`` [N·m·s/rad] (the offsets' columns, with a minus sign).
        usable: (W, n) no sample of the window clipped at the torque limit at any searched delay.
        feedback: (W, n) the PD law's feedback impulse ``int (k_p q_enc + k_d qd)`` [N·m·s] (in :attr:`rest` with a
            minus sign; zero with ``delayed = "torque"``, whose set-point impulse is the whole law's).
        speed: (W, n) each window's mean velocity from the encoder's positions, ``Delta q_enc / window`` [rad/s]
            (what the joint moved, whatever the velocity of the dynamics: :mod:`wbfriction.actuator.excitation`).
        sigma: (n,) the noise of one window's balance the sensors' noise predicts [N·m·s] (the Cramér-Rao bound's
            scale): ``sqrt((kp² σ_q² + kd² σ_qd²)(m - 1/2) T² + 2 M_jj² σ_v²)``, ``σ_qd`` the driver's velocity's
            white noise (its law's damping term), ``σ_v`` the dynamics' velocity's (the momentum's ends).
        position_noise, velocity_noise: (n,) the encoders' and the drivers' white noise [rad, rad/s].
        period: the sampling period T [s].
        start: (W,) the first sample of each window, in the log's rows.
        offset: (n,) the offsets ``o_0`` the dynamics were taken about [rad].
        coulomb_steep: (W, n) the Coulomb column with a slope :data:`~wbfriction.actuator.options.STEEPER` times as
            steep (the nuisance model's sensitivity, :mod:`wbfriction.actuator.identification`), or None.
    """

    joints: tuple[str, ...]
    setpoint: np.ndarray
    rest: np.ndarray
    dv: np.ndarray
    qd: np.ndarray
    coulomb: np.ndarray
    gravity: np.ndarray
    usable: np.ndarray
    feedback: np.ndarray
    speed: np.ndarray
    sigma: np.ndarray
    position_noise: np.ndarray
    velocity_noise: np.ndarray
    period: float
    start: np.ndarray
    offset: np.ndarray
    coulomb_steep: np.ndarray | None = None

    @property
    def max_steps(self) -> int:
        """K: the delay search spans ``[0, (K + 1) T]``."""
        return self.setpoint.shape[0] - 2

    def balance(self, delay: float) -> np.ndarray:
        """``Y(d)`` (W, n) [N·m·s] at the delay ``delay`` [s] (clamped to the searched span)."""
        x = min(max(delay / self.period, 0.0), self.max_steps + 1.0)
        k = min(int(np.floor(x)), self.max_steps)
        theta = x - k
        return (1.0 - theta) * self.setpoint[k] + theta * self.setpoint[k + 1] + self.rest

    def select(self, windows: np.ndarray) -> BalanceRows:
        """The windows ``windows`` (an index or mask over W)."""
        return BalanceRows(self.joints, self.setpoint[:, windows], self.rest[windows], self.dv[windows],
                           self.qd[windows], self.coulomb[windows], self.gravity[windows], self.usable[windows],
                           self.feedback[windows], self.speed[windows], self.sigma, self.position_noise,
                           self.velocity_noise, self.period, self.start[windows], self.offset,
                           None if self.coulomb_steep is None else self.coulomb_steep[windows])


def pd_joints(robot: Robot, log: Log) -> np.ndarray:
    """The PD-driven joints' positions in :attr:`Robot.actuated`, after checking that the log and robot allow an
    actuator identification.

    Raises:
        InputError: a robot without ``[pd]`` or on a floating base, a log whose torque is not the PD law's (a
            sensor's, the drivers' estimate, currents), an actuated joint that is not PD-driven.
    """
    if robot.pd is None:
        raise InputError(f"robot '{robot.name}' has no [pd] gains in its TOML: the actuator identification needs "
                         "the PD law (kp, kd: wbfriction.model.pd)")
    if robot.floating_base:
        raise InputError(f"robot '{robot.name}': the actuator identification needs a fixed base (the robot hung, "
                         "floating_base = false in its TOML)")
    if not torque_kind(log.torque_source).pd_law or log.setpoints is None:
        raise InputError(f"{log.source}: the torque comes from {log.torque_source} columns, not the PD law: the "
                         "actuator identification needs the set-points q_des.<joint> and no tau, tau_est or "
                         "current column")
    missing = [j for j in robot.actuated if j not in robot.pd.joints]
    if missing:
        raise InputError(f"robot '{robot.name}': joint '{missing[0]}' is actuated but not PD-driven ([pd] joints): "
                         "the actuator identification needs every joint's torque")
    return np.array([robot.actuated.index(j) for j in robot.pd.joints])


def _window_sum(x: np.ndarray, m: int, windows: int) -> np.ndarray:
    """Sums of ``m`` consecutive steps (N - 1, ...) into ``windows`` windows."""
    return x[: windows * m].reshape(windows, m, *x.shape[1:]).sum(axis=1)


def _dynamics(robot: Robot, q_model: np.ndarray, v: np.ndarray, index: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rigid-body momentum ``p``, drift ``b`` (N, n), gravity derivative ``dg/dq`` (N, n, n) of the joints
    ``index`` and ``M_jj`` (n,) (median), the armature left out (it is identified)."""
    model = pin.Model(robot.model)
    vi = robot.act_v_index[index]
    model.armature[vi] = 0.0
    data = model.createData()
    n_act = robot.n_act
    angles = np.zeros((len(q_model), n_act))
    angles[:, index] = q_model
    Q = np.array([robot.configuration(a) for a in angles])
    V = np.zeros((len(v), model.nv))
    V[:, vi] = v
    p, b, _ = momentum_and_drift(model, Q, V)
    dg = np.empty((len(Q), len(index), len(index)))
    for k, qk in enumerate(Q):
        dg[k] = pin.computeGeneralizedGravityDerivatives(model, data, qk)[np.ix_(vi, vi)]
    diag = [np.diag(pin.crba(model, data, qk))[vi] for qk in Q[::50]]
    return p[:, vi], b[:, vi], dg, np.median(diag, axis=0)


def balance_rows(robot: Robot, log: Log, offset: np.ndarray, options: ActuatorOptions) -> BalanceRows:
    """The balance (module docstring) of a log of a hung PD-driven robot, its dynamics taken about the encoder
    offsets ``offset`` (n,) [rad] of the PD-driven joints.

    Raises:
        InputError: what :func:`pd_joints` refuses; a log shorter than two windows plus the delay searched.
    """
    index = pd_joints(robot, log)
    driver = robot.pd
    assert driver is not None and log.setpoints is not None
    parts = []
    for a, b in (log.segments or [(0, len(log))]):
        found = _segment_rows(robot, log.rows(a, b), index, offset, options) if b - a >= 8 else None
        if found is not None:
            parts.append((a, found))
    if not parts:
        raise InputError(f"{log.source}: too short for an actuator identification: every stretch between gaps "
                         f"needs more than the delay searched ({options.max_delay:g} s) and two windows "
                         f"({options.window:g} s)")
    return _concatenate(parts)


def _segment_rows(robot: Robot, log: Log, index: np.ndarray, offset: np.ndarray, options: ActuatorOptions
                  ) -> dict | None:
    assert robot.pd is not None and log.setpoints is not None
    sp, driver = log.setpoints, robot.pd
    T = log.dt
    m = max(1, int(round(options.window / T)))
    K = int(np.ceil(options.max_delay / T)) if options.delay is None else int(np.ceil(options.delay / T))
    n_steps = len(log) - 1
    windows = n_steps // m
    first = int(np.ceil((K + 1) / m))  # windows whose delayed set-points reach before the stretch are dropped
    if windows - first < 2:
        return None
    q_enc = log.q[:, index] + robot.offset_vector[index]
    time = log.time if log.clock is None else log.clock.t  # receive-time jitter regularised (logs.clock)
    v = sp.qd if options.velocity == "logged" else np.gradient(q_enc, time, axis=0)
    kp = np.broadcast_to(driver.kp if sp.kp is None else sp.kp, q_enc.shape)
    kd = np.broadcast_to(driver.kd if sp.kd is None else sp.kd, q_enc.shape)
    command = kp * sp.q_des
    if sp.qd_des is not None:
        command = command + kd * sp.qd_des
    if sp.tau_ff is not None:
        command = command + sp.tau_ff
    feedback = kp * q_enc + kd * sp.qd  # the driver's law runs on its own velocity
    dt = np.diff(time)[:, None]
    trap = lambda x: 0.5 * (x[:-1] + x[1:]) * (dt if x.ndim == 2 else dt[:, :, None])  # noqa: E731
    held = command[:-1]  # each step's set-points: held from its first sample
    if options.delayed == "torque":  # the whole law held back: its clipped torque is what the delay shifts
        held = _law_mean(command, feedback, driver.torque_limit)
        command = np.clip(command - feedback, -driver.torque_limit, driver.torque_limit)
        feedback = np.zeros_like(feedback)
    steps = np.arange(n_steps)
    setpoint = np.stack([_window_sum(held[np.maximum(steps - k, 0)] * dt, m, windows) for k in range(K + 2)])
    p, b, dg, m_jj = _dynamics(robot, q_enc - offset, v, index)
    ends = np.arange(windows + 1) * m
    feedback_impulse = _window_sum(trap(feedback), m, windows)
    rest = -feedback_impulse - (p[ends[1:]] - p[ends[:-1]]) + _window_sum(trap(b), m, windows)
    torque = np.stack([command[np.maximum(np.arange(len(log)) - k, 0)] - feedback for k in range(K + 2)])
    # a law held back whole was clipped before its delay: the limit is reached, not passed

    clipped = np.any(np.abs(torque) >= driver.torque_limit, axis=0)  # (N, n)
    usable = ~_window_sum(np.maximum(clipped[:-1], clipped[1:]).astype(int), m, windows).astype(bool)
    sigma_q = _white_noise(q_enc, T)
    sigma_v = _white_noise(sp.qd, T)  # the driver's, in its law
    sigma_dyn = _white_noise(v, T)  # the dynamics', in the momentum
    kp0, kd0 = np.median(kp, axis=0), np.median(kd, axis=0)
    sigma = np.sqrt((kp0**2 * sigma_q**2 + kd0**2 * sigma_v**2) * (m - 0.5) * T**2 + 2 * m_jj**2 * sigma_dyn**2)
    keep = slice(first, windows)
    return {"setpoint": setpoint[:, keep], "rest": rest[keep], "dv": (v[ends[1:]] - v[ends[:-1]])[keep],
            "qd": _window_sum(trap(v), m, windows)[keep],
            "coulomb": _window_sum(tanh_impulse(v, dt, options.tanh_slope), m, windows)[keep],
            "coulomb_steep": _window_sum(tanh_impulse(v, dt, STEEPER * options.tanh_slope), m, windows)[keep],
            "gravity": _window_sum(trap(dg), m, windows)[keep], "usable": usable[keep],
            "feedback": feedback_impulse[keep],
            "speed": ((q_enc[ends[1:]] - q_enc[ends[:-1]]) / (time[ends[1:]] - time[ends[:-1]])[:, None])[keep],
            "sigma": sigma,
            "position_noise": sigma_q, "velocity_noise": sigma_v, "period": T, "start": ends[:-1][keep],
            "joints": tuple(robot.actuated[i] for i in index), "offset": np.asarray(offset, dtype=float)}


def _law_mean(command: np.ndarray, feedback: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """The whole law's mean torque over each step (N - 1, n) [N·m] (``delayed = "torque"``): the set-points'
    ``command`` (N, n) held from the step's first sample, the ``feedback`` (N, n) of the state, which moves within the
    step, by the trapezoid (as the set-points' delay's ``rest`` takes it), each end clipped at ``limit``.

    Held back by ``d``, the law's impulse over a step is then its impulse over the step ``d`` earlier: at ``d = 0``
    the balance of the set-points delayed. The feedback taken at the step's first sample instead (held as the
    set-points are) put it half a period early: ``kp T/2 qd`` more torque in the balance than the driver applied,
    which F_v took up (+21 % on the simulated Go2, kp 25, 200 Hz), and ``kd T/2 qdd``, which the armature took up.
    """
    held = command[:-1]
    return 0.5 * (np.clip(held - feedback[:-1], -limit, limit) + np.clip(held - feedback[1:], -limit, limit))


def tanh_impulse(v: np.ndarray, dt: np.ndarray, a: float) -> np.ndarray:
    """``int tanh(a qd) dt`` over each step (N - 1, n) [s] with the velocity ``v`` (N, n) linear between the samples:
    ``dt (log cosh(a v1) - log cosh(a v0)) / (a (v1 - v0))``, exact where the trapezoid is not (a reversal within a
    step, where ``tanh`` turns from -1 to 1); the midpoint's value where the velocity hardly changes."""
    x0, x1 = a * v[:-1], a * v[1:]
    dx = x1 - x0
    small = np.abs(dx) < 1e-6
    mean = np.where(small, np.tanh(0.5 * (x0 + x1)), (_log_cosh(x1) - _log_cosh(x0)) / np.where(small, 1.0, dx))
    return mean * dt


def _log_cosh(x: np.ndarray) -> np.ndarray:
    """``log cosh x``, without overflow."""
    ax = np.abs(x)
    return ax + np.log1p(np.exp(-2.0 * ax)) - np.log(2.0)


def _white_noise(x: np.ndarray, period: float) -> np.ndarray:
    """The white noise (n,) of each column of ``x`` (N, n) (:func:`~wbfriction.signals.content.acceleration_content`'s
    floor), zero where the stretch is too short to measure it."""
    try:
        return np.nan_to_num(acceleration_content(x, period).position_noise)
    except InputError:
        return np.zeros(x.shape[1])


def _concatenate(parts: list[tuple[int, dict]]) -> BalanceRows:
    rows = [r for _, r in parts]
    K = min(r["setpoint"].shape[0] for r in rows)
    longest = max(rows, key=lambda r: len(r["rest"]))
    cat = lambda key: np.concatenate([r[key] for r in rows])  # noqa: E731
    return BalanceRows(longest["joints"], np.concatenate([r["setpoint"][:K] for r in rows], axis=1), cat("rest"),
                       cat("dv"), cat("qd"), cat("coulomb"), cat("gravity"), cat("usable"), cat("feedback"),
                       cat("speed"), longest["sigma"], longest["position_noise"], longest["velocity_noise"],
                       longest["period"], np.concatenate([a + r["start"] for a, r in parts]), longest["offset"],
                       cat("coulomb_steep"))

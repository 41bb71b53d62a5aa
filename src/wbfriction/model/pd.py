"""A PD-driven joint's motor driver: the torque its PD law applies, with its set-points' delay and torque limit.

Most legged robots have no joint torque sensor (Unitree Go1/Go2/A1/Aliengo/G1/H1, Mini Cheetah-class actuators):
their motor drivers close a PD loop on the encoder, and their logs hold the set-points and the gains. The torque
the motor applies at the joint (gear included, on the motor side: the rotor's inertia and the whole drive's
friction are behind it) is then the PD law as the driver runs it (Isaac Lab's ``DelayedPDActuator``; PACE,
Bjelonic et al. 2025):

.. math::

    \\tau(t) = \\mathrm{clip}\\big(k_p\\,(q^{des}(t - d) - q(t)) + k_d\\,(\\dot q^{des}(t - d) - \\dot q(t))
               + \\tau_{ff}(t - d),\\; -\\tau_{max},\\; \\tau_{max}\\big)

with ``q`` the encoder's reading (the logged angle), ``qd`` the driver's own velocity, and each set-point held
from the instant it is commanded (zero-order hold) and applied ``d`` later (the bus and the driver's delay). A
driver may instead hold back its whole torque, the feedback with the set-points (``delayed = "torque"``: PACE's
actuator, ``tau(t) = clip(PD(t - d))``, the law on the state of ``t - d``); which one a robot's drivers do, the
actuator identification decides from the data (:mod:`wbfriction.actuator`).

**Per sample.** A log samples the torque at ``t_i``; the set-point the driver applied changes within a sample's
period whenever ``d`` is not a whole number of periods. The value a sample stands for is the mean of the applied
set-point over the sample's period ``[t_i - T/2, t_i + T/2]``: a box average of a zero-order hold is the linear
interpolation of the commanded samples, here at ``t_i - T/2 - d`` (:func:`delayed`). Integrated over a period by
the trapezoid (the momentum route's ``sample`` alignment) it gives the applied set-point's impulse exactly where
the set-point is linear over two periods.

**Encoder offset.** ``q_logged = q + offset`` [rad]: the driver's PD runs on the logged angle, the dynamics on the
model's angle ``q_logged - offset`` (``[encoder_offset]`` in the robot TOML).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np

Delayed = Literal["setpoints", "torque"]
"""What a driver's delay holds back: its set-points (Isaac Lab's ``DelayedPDActuator``) or its whole torque
(PACE's actuator)."""
DELAYED: tuple[Delayed, ...] = get_args(Delayed)


@dataclass(frozen=True, eq=False)
class PdDriver:
    """The motor drivers of a robot's PD-driven joints (``[pd]`` in the robot TOML).

    Attributes:
        joints: the PD-driven joints, in :attr:`Robot.actuated <wbfriction.model.robot.Robot.actuated>` order.
        kp: position gains (n,) [N·m/rad], one per joint of :attr:`joints`.
        kd: velocity gains (n,) [N·m·s/rad].
        delay: the set-points' delay [s]: at ``t`` the driver applies the set-point commanded at ``t - delay``
            (zero-order hold); at least 0.
        torque_limit: the torque the driver clips at (n,) [N·m] (inf: none); default the URDF's effort limits.
        delayed: what the delay holds back (:data:`Delayed`).
        delayed_known: whether the log it was identified on told what the delay holds back (``wbfriction identify
            --actuator pd``): False where set-points and torque delayed close its balance alike. On steady motion
            the two differ by a viscous torque ``kp delay qd`` (the set-point's lag ``delay qd`` times kp), which a
            friction fitted under either takes up: its F_v is then known only to within ``kp delay``
            (:func:`viscous_equivalent`; issue 63).

    Raises:
        ValueError: arrays of another length than :attr:`joints`, a negative or non-finite gain, a negative
            delay or torque limit (the robot TOML's reader names the file and key before this).
    """

    joints: tuple[str, ...]
    kp: np.ndarray
    kd: np.ndarray
    delay: float = 0.0
    torque_limit: np.ndarray = field(default_factory=lambda: np.empty(0))
    delayed: Delayed = "setpoints"
    delayed_known: bool = True

    def __post_init__(self) -> None:
        n = len(self.joints)
        limit = np.full(n, np.inf) if np.size(self.torque_limit) == 0 else self.torque_limit
        for name in ("kp", "kd"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.shape != (n,) or not np.all(np.isfinite(value)) or np.any(value < 0):
                raise ValueError(f"PdDriver.{name} must be {n} finite gains >= 0, got {value!r}")
            object.__setattr__(self, name, value)
        limit = np.asarray(limit, dtype=float)
        if limit.shape != (n,) or np.any(np.isnan(limit)) or np.any(limit <= 0):
            raise ValueError(f"PdDriver.torque_limit must be {n} limits > 0 [N·m], got {limit!r}")
        object.__setattr__(self, "torque_limit", limit)
        if not (np.isfinite(self.delay) and self.delay >= 0):
            raise ValueError(f"PdDriver.delay must be a finite delay >= 0 [s], got {self.delay!r}")
        if self.delayed not in DELAYED:
            raise ValueError(f"PdDriver.delayed must be one of {', '.join(DELAYED)}, got {self.delayed!r}")

    def with_delay(self, delay: float, delayed: Delayed | None = None) -> PdDriver:
        """The same drivers with the delay ``delay`` [s] (holding back ``delayed``, default as now)."""
        return PdDriver(self.joints, self.kp, self.kd, float(delay), self.torque_limit,
                        self.delayed if delayed is None else delayed, self.delayed_known)

    def viscous_equivalent(self) -> dict[str, float]:
        """Per joint, the viscous coefficient ``kp delay`` [N·m·s/rad] by which the set-points delayed and the torque
        delayed differ on steady motion (:attr:`delayed_known`): at speed ``qd`` a set-point held back by ``delay`` lags
        by ``delay qd``, so its law applies ``kp delay qd`` less than the whole law held back does."""
        return {j: float(k * self.delay) for j, k in zip(self.joints, self.kp)}


def delayed(values: np.ndarray, time: np.ndarray, delay: float) -> np.ndarray:
    """The set-points a driver applied, as each sample stands for them (module docstring): the mean over the
    sample's period ``[t_i - T/2, t_i + T/2]`` of the commanded samples held (zero-order hold) and delayed by
    ``delay``: the linear interpolation of ``values`` at ``t_i - T/2 - delay`` (``T`` the median step); before the
    log's first sample, its value.

    Args:
        values: the commanded set-points (N,) or (N, n), one row per sample.
        time: the sample times (N,) [s], increasing.
        delay: the set-points' delay [s], at least 0.

    Returns:
        The applied set-points, the shape of ``values``.
    """
    values = np.asarray(values, dtype=float)
    time = np.asarray(time, dtype=float)
    if len(time) < 2:
        return values.copy()
    period = float(np.median(np.diff(time)))
    at = time - 0.5 * period - float(delay)
    flat = values.reshape(len(time), -1)
    out = np.column_stack([np.interp(at, time, flat[:, k]) for k in range(flat.shape[1])])
    return out.reshape(values.shape)


def pd_torque(driver: PdDriver, time: np.ndarray, q: np.ndarray, qd: np.ndarray, q_des: np.ndarray,
              qd_des: np.ndarray | None = None, tau_ff: np.ndarray | None = None, *, kp: np.ndarray | None = None,
              kd: np.ndarray | None = None, delay: float | None = None) -> np.ndarray:
    """The torque the drivers apply at the samples (module docstring's law), set-points :func:`delayed`.

    Args:
        driver: the drivers (gains, delay, limits) of the ``n`` PD-driven joints.
        time: sample times (N,) [s].
        q: the encoder's angles (N, n) [rad] (the logged ``q.<joint>``, offset included).
        qd: the driver's velocities (N, n) [rad/s].
        q_des, qd_des, tau_ff: the commanded set-points (N, n) [rad, rad/s, N·m]; None: zero.
        kp, kd: gains logged per sample (N, n), replacing the driver's (they are not delayed: a gain is a
            setting, not a set-point); None: the driver's.
        delay: the set-points' delay [s]; None: the driver's.

    Returns:
        The motor torques at the joints (N, n) [N·m], clipped at the driver's limits.
    """
    d = driver.delay if delay is None else float(delay)
    kp_ = driver.kp if kp is None else kp
    kd_ = driver.kd if kd is None else kd
    if driver.delayed == "torque":  # the law on the samples, clipped, then held back whole
        law = kp_ * (q_des - q) - kd_ * qd
        law = law + (0.0 if qd_des is None else kd_ * qd_des) + (0.0 if tau_ff is None else tau_ff)
        return delayed(np.clip(law, -driver.torque_limit, driver.torque_limit), time, d)
    tau = kp_ * (delayed(q_des, time, d) - q) - kd_ * qd
    if qd_des is not None:
        tau = tau + kd_ * delayed(qd_des, time, d)
    if tau_ff is not None:
        tau = tau + delayed(tau_ff, time, d)
    return np.clip(tau, -driver.torque_limit, driver.torque_limit)


def parse_pd(table: object, actuated: list[str], groups: dict[str, tuple[str, ...]], effort_limit: np.ndarray,
             source: str) -> PdDriver | None:
    """The robot TOML's ``[pd]`` table as drivers, or None without one.

    Keys: ``kp`` [N·m/rad] and ``kd`` [N·m·s/rad], each a number for every PD-driven joint or a table of joint or
    group -> number (every PD-driven joint covered); ``delay`` [s] (default 0); ``delayed`` (what the delay holds
    back, :data:`Delayed`: ``setpoints`` by default, or ``torque``); ``delayed_known`` (true by default; false where the
    log ``identify`` found the delay on did not tell what it holds back: :attr:`PdDriver.delayed_known`); ``joints``
    (the PD-driven joints,
    default every actuated joint); ``torque_limit`` [N·m] (a number or a table as the gains; default the URDF's
    effort limits, none where the URDF gives 0).

    Args:
        table: the ``[pd]`` value.
        actuated: the model's actuated joints, in order.
        groups: the TOML's joint groups (group -> joints).
        effort_limit: the URDF's effort limit of each actuated joint (n_act,) [N·m].
        source: the file's name, for errors.

    Raises:
        InputError: a ``[pd]`` that is not a table, an unknown key, joint or group, a gain missing for a joint, a
            value outside its physical range (:data:`~wbfriction.quantities.RANGES`), naming the file and the key.
    """
    from wbfriction.exceptions import InputError
    from wbfriction.quantities import in_range

    if table is None:
        return None
    if not isinstance(table, dict):
        raise InputError(f"{source}: '[pd]' must be a table (kp, kd, delay, joints, torque_limit)")
    unknown = set(table) - {"kp", "kd", "delay", "joints", "torque_limit", "delayed", "delayed_known"}
    if unknown:
        raise InputError(f"{source}: [pd] has no key '{sorted(unknown)[0]}' (kp, kd, delay, delayed, delayed_known, "
                         "joints, torque_limit)")
    held_back = table.get("delayed", "setpoints")
    if held_back not in DELAYED:
        raise InputError(f"{source}: [pd] delayed must be one of {', '.join(DELAYED)}, got {held_back!r}")
    known = table.get("delayed_known", True)
    if not isinstance(known, bool):
        raise InputError(f"{source}: [pd] delayed_known must be true or false, got {known!r}")
    joints = table.get("joints", actuated)
    if not isinstance(joints, list) or any(j not in actuated for j in joints) or not joints:
        bad = next((j for j in joints if j not in actuated), joints) if isinstance(joints, list) else joints
        raise InputError(f"{source}: [pd] joints: '{bad}' is not an actuated joint of the model")
    joints = [j for j in actuated if j in set(joints)]
    limits = dict(zip(actuated, np.where(effort_limit > 0, effort_limit, np.inf)))

    def per_joint(key: str, default: dict[str, float] | None) -> np.ndarray:
        value = table.get(key)
        if value is None:
            if default is None:
                raise InputError(f"{source}: [pd] needs '{key}' (a number, or a table of joint or group = number)")
            return np.array([default[j] for j in joints])
        spread: dict[str, object] = {}
        if isinstance(value, dict):
            for name, v in value.items():
                members = groups.get(name, (name,))
                if any(m not in joints for m in members):
                    raise InputError(f"{source}: [pd] {key}: '{name}' is neither a PD-driven joint nor a group")
                spread |= dict.fromkeys(members, v)
        else:
            spread = dict.fromkeys(joints, value)
        missing = [j for j in joints if j not in spread]
        if missing:
            raise InputError(f"{source}: [pd] {key} gives no value for '{missing[0]}'")
        return np.array([in_range(key, spread[j], f"{source}: [pd] {key} of '{j}'") for j in joints])

    delay = in_range("pd_delay", table.get("delay", 0.0), f"{source}: [pd] delay")
    return PdDriver(tuple(joints), per_joint("kp", None), per_joint("kd", None), delay,
                    per_joint("torque_limit", limits), held_back, known)

"""A fixed-base arm simulated by Pinocchio: known friction and rotor inertia, an excitation trajectory, a
motor-current log (the ground truth of an arm's identification).

The arm is the robot's URDF on a fixed base (``pin.buildModelFromUrdf`` without a free flyer), its
``[locked_joints]`` removed (``pin.buildReducedModel``: the Panda's fingers). Its dynamics, with the
reflected rotor inertia ``armature`` [kg·m^2] of each drive on its joint's axis and friction (of any family: (3.5)
by default) in every joint:

.. math::

    (M(q) + \\mathrm{diag}(I_a))\\,\\ddot q + h(q, \\dot q) = \\tau_m + \\tau_f, \\qquad \\tau_f = -f(\\dot q)

(``tau_m`` the motor torque at the joint, gear included; ``pin.aba`` with ``model.armature`` set).

**Trajectory.** Each joint follows a finite Fourier series (:class:`~wbfriction.walking.fourier.FourierTrajectory`;
Swevers, Ganseman, Tukel, De Schutter & Van Brussel, *Optimal robot excitation and identification*, IEEE T-RA 13(5),
1997):

.. math::

    q_i(t) = q_{i,0} + \\sum_{l=1}^{L} \\frac{a_{il}}{\\omega_f l}\\sin(\\omega_f l t)
             - \\frac{b_{il}}{\\omega_f l}\\cos(\\omega_f l t),

periodic in ``2 pi / omega_f``, with random coefficients (seeded) constrained to start at rest
(``sum_l a_il = 0``, ``sum_l l b_il = 0``) and scaled into a share of each joint's position range and
velocity limit (:func:`excitation_trajectory`), or any trajectory given (``excite``'s design: :func:`simulate_arm`).

**Control.** At the log rate, computed torque from the reference (the arm's own model, armature
included, no friction compensation) plus a joint PD of a given bandwidth; the torque is held over the
period (zero-order hold).

**Physics.** Semi-implicit Euler at ``rate x substeps`` (10 kHz by default): ``v+ = v + h a(q, v)``,
``q+ = q + h v+``, friction from the velocity at the start of each step. The logged positions'
second difference over two periods is then exactly ``dt^2`` times the steps' accelerations averaged
with triangular weights.

**Log** (1 kHz by default, :mod:`wbfriction.logs.log` format, fixed base: no ``contact.*``, no
``base.*``): ``time``, ``q.<joint>`` with white noise of ``position_std`` read by encoders of ``encoder_bits`` per turn
(rounded to their resolution), ``current.<joint>`` = (``tau_m`` + torque noise) / torque constant [A], and the truth:
``tau_f_true.<joint>``, ``qd_true.<joint>``, ``qdd_true.<joint>`` (the state at the sample, the
acceleration under the torque held from it). The metadata names the friction, armature and torque
constants injected.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.fit.terms import TermFit
from wbfriction.friction.models import FrictionParams, ModelParams
from wbfriction.logs.tables import read_metadata, with_metadata
from wbfriction.model.loading import build_model
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import injected_friction, terms_truth, warm_up
from wbfriction.sim.options import SensorNoise
from wbfriction.walking.fourier import FourierTrajectory

GENERATOR = "wbfriction.sim.arm.simulate_arm"

Reference = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]
"""A reference motion: times ``t`` (N,) [s] to positions [rad], velocities [rad/s] and accelerations [rad/s^2],
each (N, n) in the robot's actuated order (a :class:`FourierTrajectory` is one)."""


@dataclass(frozen=True)
class ExcitationOptions:
    """The excitation trajectory (:func:`excitation_trajectory`).

    Attributes:
        period: period of the Fourier series [s] (fundamental ``omega_f = 2 pi / period``).
        harmonics: number of harmonics ``L`` (at least 2: starting at rest takes two of each joint's
            ``2 L`` coefficients).
        range_share: share of each joint's position range the trajectory spans at most (centred in it).
        velocity_share: share of each joint's velocity limit its speed reaches at most.
        excited: joints that move (None: all); the others stay at the middle of their range.
        seed: seed of the random coefficients.
    """

    period: float = 10.0
    harmonics: int = 5
    range_share: float = 0.7
    velocity_share: float = 0.6
    excited: tuple[str, ...] | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        if self.period <= 0 or self.harmonics < 2:
            raise InputError(f"excitation: period must be > 0 and harmonics >= 2, got {self.period}, "
                             f"{self.harmonics}")
        if not (0 < self.range_share <= 1 and 0 < self.velocity_share <= 1):
            raise InputError(f"excitation: range_share and velocity_share must be in (0, 1], got "
                             f"{self.range_share}, {self.velocity_share}")


def excitation_trajectory(lower: np.ndarray, upper: np.ndarray, velocity_limit: np.ndarray,
                          options: ExcitationOptions = ExcitationOptions(),
                          excited: np.ndarray | None = None) -> FourierTrajectory:
    """Random Fourier series (seeded) that start at rest and stay within ``range_share`` of each
    joint's range ``[lower, upper]`` [rad], centred in it, and within ``velocity_share`` of its velocity
    limit [rad/s] (module docstring; Swevers et al. 1997).

    Args:
        lower, upper, velocity_limit: per joint (n,).
        options: :class:`ExcitationOptions`.
        excited: boolean (n,): the joints that move (None: all).
    """
    n, L = len(lower), options.harmonics
    rng = np.random.default_rng(options.seed)
    a, b = rng.normal(size=(n, L)), rng.normal(size=(n, L))
    ell = np.arange(1, L + 1, dtype=float)
    a -= a.mean(axis=1, keepdims=True)  # qd(0) = sum_l a_l = 0
    b -= np.outer(b @ ell, ell) / (ell @ ell)  # qdd(0) ~ sum_l l b_l = 0
    omega = 2.0 * np.pi / options.period
    unit = FourierTrajectory(np.zeros(n), a, b, omega)
    q, qd, _ = unit(np.linspace(0.0, options.period, 2001))
    span = q.max(axis=0) - q.min(axis=0)
    scale = np.minimum(options.range_share * (upper - lower) / span,
                       options.velocity_share * velocity_limit / np.abs(qd).max(axis=0))
    if excited is not None:
        scale = np.where(excited, scale, 0.0)
    middle = 0.5 * (upper + lower) - scale * 0.5 * (q.max(axis=0) + q.min(axis=0))
    return FourierTrajectory(middle, a * scale[:, None], b * scale[:, None], omega)


@dataclass(frozen=True)
class ArmOptions:
    """Parameters of :func:`simulate_arm`.

    Attributes:
        duration: simulated time [s].
        rate: log and control rate [Hz].
        substeps: physics steps per control period (10 at 1 kHz: 10 kHz).
        bandwidth: joint PD bandwidth [Hz]; damping: its damping ratio (gains from the diagonal of
            ``M + diag(armature)`` at the trajectory's start).
        encoder_bits: encoder resolution in bits per turn (None: exact positions).
        position_std: standard deviation of the white noise on the logged positions [rad] (before the encoder's
            rounding; the controller tracks the true ones).
        torque_std: standard deviation of the noise on the motor torque [N·m] (logged as current).
        seed: seed of the noise.
        excitation: :class:`ExcitationOptions`.
        temperature: the joints' temperature at the log's start and end [°C], a linear warm-up logged as
            ``temperature.<joint>`` (what a ``temperature`` term of :func:`simulate_arm`'s ``terms`` sees); None: not
            logged.
    """

    duration: float = 10.0
    rate: float = 1000.0
    substeps: int = 10
    bandwidth: float = 8.0
    damping: float = 1.0
    encoder_bits: int | None = 19
    position_std: float = 0.0
    torque_std: float = 0.0
    seed: int = 0
    excitation: ExcitationOptions = ExcitationOptions()
    temperature: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.duration <= 0 or self.rate <= 0 or self.substeps < 1:
            raise InputError(f"arm simulation: duration and rate must be > 0 and substeps >= 1, got "
                             f"{self.duration}, {self.rate}, {self.substeps}")


@dataclass
class ArmSimulation:
    """What :func:`simulate_arm` produced.

    Attributes:
        table: the log (module docstring), metadata included.
        trajectory: the reference tracked (:func:`excitation_trajectory`'s, or the one given).
        q, qd, qdd: true positions [rad], velocities [rad/s], accelerations [rad/s^2] at the samples (N, n).
        tau_motor: motor torque held from each sample [N·m] (N, n), without noise.
        tau_f: friction at each sample [N·m] (N, n).
    """

    table: pa.Table
    trajectory: Reference
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau_motor: np.ndarray
    tau_f: np.ndarray


def arm_model(robot: Robot) -> pin.Model:
    """The fixed-base Pinocchio model of ``robot``'s URDF or MJCF (no free flyer), its locked joints removed
    at their positions, its joints in :attr:`Robot.actuated` order, without armature.

    Raises:
        InputError: a URDF whose joints (after locking) are not the robot's actuated ones.
    """
    model = build_model(robot.urdf, robot.model_format, free_flyer=False)
    if robot.locked_joints:
        q = pin.neutral(model)
        for name, value in robot.locked_joints.items():
            q[model.idx_qs[model.getJointId(name)]] = value
        model = pin.buildReducedModel(model, [model.getJointId(n) for n in robot.locked_joints], q)
    names = tuple(model.names[1:])
    if names != robot.actuated or model.nv != len(names) or model.nq != model.nv:
        raise InputError(f"{robot.urdf}: the fixed-base model's joints {names} are not the robot's {robot.actuated}")
    return model


def _armature(robot: Robot, armature: dict[str, float] | None) -> np.ndarray:
    """Armature per actuated joint [kg·m^2]: the given ones, else the robot's (its ``[armature]``)."""
    if armature is None:
        return np.array(robot.model.armature[robot.act_v_index], dtype=float)
    unknown = sorted(set(armature) - set(robot.actuated))
    if unknown:
        raise InputError(f"armature given for '{unknown[0]}', which is not a joint of {robot.name}")
    values = np.array([armature.get(n, 0.0) for n in robot.actuated], dtype=float)
    if np.any(values < 0) or not np.all(np.isfinite(values)):
        raise InputError(f"armature must be finite and >= 0, got {armature}")
    return values


def _torque_constants(robot: Robot) -> np.ndarray:
    missing = [n for n in robot.actuated if n not in robot.torque_constants]
    if missing:
        raise InputError(f"robot '{robot.name}' has no torque constant for '{missing[0]}' (its [torque_constants])")
    return np.array([robot.torque_constants[n] for n in robot.actuated])


def default_arm_friction(robot: Robot) -> dict[str, FrictionParams]:
    """Friction (3.5) injected by ``wbfriction simulate`` on an arm when no ``--friction`` is given:
    decreasing from the base to the wrist (joint i of n: F_v = 0.5 - 0.3 i/n [N·m·s/rad],
    F_c = 1.0 - 0.6 i/n [N·m]), S = 0.3, v_s = 0.05 rad/s, tau_os = 0.1 N·m, a = 40 s/rad."""
    n = len(robot.torque_controlled)
    return {j: FrictionParams(F_v=0.5 - 0.3 * i / n, F_c=1.0 - 0.6 * i / n, S=0.3, v_s=0.05, tau_os=0.1, a=40.0)
            for i, j in enumerate(robot.torque_controlled)}


def simulate_arm(robot: Robot, friction: Mapping[str, ModelParams], armature: dict[str, float] | None = None,
                 options: ArmOptions = ArmOptions(), progress: Progress | None = None,
                 terms: Mapping[str, TermFit] | None = None, trajectory: Reference | None = None) -> ArmSimulation:
    """Simulate ``robot`` as a fixed-base arm tracking an excitation trajectory (module docstring).

    Args:
        robot: a fixed-base robot (``floating_base = false``) with a torque constant per joint.
        friction: parameters per joint, of any friction family the registry knows (joints not named have none).
        armature: true reflected rotor inertia per joint [kg·m^2] (joints not named: 0); None: the
            robot's own (its ``[armature]``).
        options: :class:`ArmOptions`.
        progress: optional callable receiving numbers of samples done.
        terms: friction beyond velocity per joint (:class:`~wbfriction.fit.terms.TermFit`: its velocity model
            and its terms, the load being the joint's rigid-body torque ``M qdd + h = tau_motor + tau_f`` (of the
            previous physics step), the angle its true one, the temperature
            :attr:`ArmOptions.temperature`'s); it replaces ``friction`` for the joints it names. Recorded in the
            metadata's ``terms_true``.
        trajectory: the reference to track instead of :func:`excitation_trajectory`'s random one (then
            :attr:`ArmOptions.excitation` is unused): a :class:`FourierTrajectory` (``excite``'s design) or any
            :data:`Reference`; the arm starts in its state at ``t = 0``. The sensors' noise stays
            :class:`ArmOptions`' (``position_std = torque_std = 0``, ``encoder_bits = None``: exact).

    Returns:
        :class:`ArmSimulation` with ``round(duration * rate)`` samples.

    Raises:
        InputError: a floating-base robot, a joint without torque constant, friction, terms or armature for
            an unknown joint, a negative armature, a temperature term without :attr:`ArmOptions.temperature`, a
            ``trajectory`` whose arrays are not (N, n_act) and finite.
    """
    if robot.floating_base:
        raise InputError(f"robot '{robot.name}' has a floating base: simulate_arm needs floating_base = false")
    terms = dict(terms or {})
    unknown = sorted((set(friction) | set(terms)) - set(robot.actuated))
    if unknown:
        raise InputError(f"friction given for '{unknown[0]}', which is not a joint of {robot.name}")
    if options.temperature is None and any("temperature" in t.kept for t in terms.values()):
        raise InputError("a temperature term needs the joints' temperature: give ArmOptions.temperature")
    model = arm_model(robot)
    model.armature = _armature(robot, armature)
    k_t = _torque_constants(robot)
    injected = injected_friction(robot, friction, terms, robot.actuated)
    traj = trajectory if trajectory is not None else excitation_trajectory(
        model.lowerPositionLimit, model.upperPositionLimit, model.velocityLimit, options.excitation,
        None if options.excitation.excited is None else np.isin(robot.actuated, options.excitation.excited))
    time, dt = _times(options)
    n = len(time)
    q_ref, qd_ref, qdd_ref = _sampled(traj, time, model.nv)
    data = model.createData()
    ff = np.array([pin.rnea(model, data, q_ref[k], qd_ref[k], qdd_ref[k]) for k in range(n)])
    inertia = np.diag(pin.crba(model, data, q_ref[0]))  # armature included
    w = 2.0 * np.pi * options.bandwidth
    kp, kd = inertia * w ** 2, 2.0 * options.damping * w * inertia

    nv, h = model.nv, dt / options.substeps
    Q, V, A, T, F = (np.empty((n, nv)) for _ in range(5))
    q, v = q_ref[0].copy(), qd_ref[0].copy()
    tau_f = np.zeros(nv)
    warm = warm_up(options.temperature, n)
    f = injected.joints
    for k in counted(n, progress):
        tau = ff[k] + kp * (q_ref[k] - q) + kd * (qd_ref[k] - v)
        for s in range(options.substeps):
            if f:
                friction_f = injected.torque(v[f])
                if injected.beyond:  # the load: the rigid-body torque M qdd + h = tau + tau_f, of the last step
                    friction_f = injected.with_terms(friction_f, v[f], q[f], tau[f] + tau_f[f],
                                                     0.0 if warm is None else float(warm[k]))
                tau_f[f] = friction_f
            a = pin.aba(model, data, q, v, tau + tau_f)
            if s == 0:
                Q[k], V[k], A[k], T[k], F[k] = q, v, a, tau, tau_f
            v = v + h * a
            q = q + h * v
    table = _table(robot, time, Q, V, A, T, F, k_t, model.armature, injected.params, options)
    return ArmSimulation(_completed(table, robot, warm, terms, trajectory), traj, Q, V, A, T, F)


def _times(options: ArmOptions) -> tuple[np.ndarray, float]:
    """The log's sample times (N,) [s] and period [s]."""
    dt = 1.0 / options.rate
    return np.arange(int(round(options.duration * options.rate))) * dt, dt


def _completed(table: pa.Table, robot: Robot, warm: np.ndarray | None, terms: Mapping[str, TermFit],
               trajectory: Reference | None) -> pa.Table:
    """The log with its temperature columns, and the terms and trajectory injected in its metadata."""
    meta = read_metadata(table)
    if warm is not None:
        for j in robot.actuated:
            table = table.append_column(f"temperature.{j}", pa.array(warm))
    if terms:
        meta["terms_true"] = terms_truth(terms)
    if trajectory is not None:  # options.excitation did not make it
        meta["trajectory"] = _described(trajectory)
    return with_metadata(table, meta)


def _sampled(trajectory: Reference, time: np.ndarray, nv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A reference's positions, velocities and accelerations at ``time`` (N,), each checked (N, nv) and finite."""
    q, qd, qdd = (np.asarray(x, dtype=float) for x in trajectory(time))
    if any(x.shape != (len(time), nv) or not np.all(np.isfinite(x)) for x in (q, qd, qdd)):
        raise InputError(f"the trajectory given must give finite ({len(time)}, {nv}) positions, velocities and "
                         f"accelerations, got shapes {q.shape}, {qd.shape}, {qdd.shape}")
    return q, qd, qdd


def _described(trajectory: Reference) -> dict:
    """The metadata's record of a trajectory given: a Fourier series' coefficients, else its type's name."""
    if isinstance(trajectory, FourierTrajectory):
        return {"kind": "fourier", "center": trajectory.center.tolist(), "a": trajectory.a.tolist(),
                "b": trajectory.b.tolist(), "omega": float(trajectory.omega)}
    return {"kind": type(trajectory).__name__}


def _table(robot: Robot, time: np.ndarray, Q: np.ndarray, V: np.ndarray, A: np.ndarray, T: np.ndarray,
           F: np.ndarray, k_t: np.ndarray, armature: np.ndarray, friction: Mapping[str, ModelParams],
           options: ArmOptions) -> pa.Table:
    """The log table of a run: encoder positions, currents of the noisy motor torques, the truth."""
    noise = SensorNoise(position_std=options.position_std, encoder_bits=options.encoder_bits,
                        torque_std=options.torque_std, seed=options.seed)
    eps_q, eps_tau = noise.draw(len(time), Q.shape[1], T.shape[1])
    q_log, current = noise.encoder(Q + eps_q), (T + eps_tau) / k_t
    cols: dict[str, np.ndarray] = {"time": time}
    for prefix, x in (("q", q_log), ("current", current), ("tau_f_true", F), ("qd_true", V), ("qdd_true", A)):
        cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(robot.actuated)})
    meta = {"generator": GENERATOR, "options": asdict(options), "robot": robot.name, "urdf": Path(robot.urdf).name,
            "torque_alignment": "zoh",  # the motor torque is held over the substeps of each period
            "dynamics": "(M(q) + diag(armature)) qdd + h(q, qd) = tau_motor + tau_f; tau_f = -f(qd); "
                        "current = (tau_motor + noise) / torque_constant",
            "friction_true": {j: p.to_target() for j, p in friction.items()},
            "armature_true": dict(zip(robot.actuated, map(float, armature))),
            "torque_constants": dict(zip(robot.actuated, map(float, k_t))),
            "sensor_noise": asdict(noise)}
    return with_metadata(pa.table(cols), meta)

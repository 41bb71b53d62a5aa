"""What both simulators share: the injected friction, the result, the log they write and its recording."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import cast

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.targets import friction_by_group
from wbfriction.fit.terms import TermFit
from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import FrictionParams, ModelParams, stack_params
from wbfriction.logs.log import Log
from wbfriction.model.force_torque import sensor_readings
from wbfriction.model.imu import imu_readings
from wbfriction.model.robot import Robot
from wbfriction.walking import WalkingReference
from wbfriction.walking.indexing import as_slice


@dataclass(frozen=True)
class FamilyColumns:
    """The joints of one friction family among an :class:`InjectedFriction`'s, its parameters stacked.

    Attributes:
        columns: the joints' positions (n_cols,) among the injected ones.
        family: their family, from the registry (:func:`~wbfriction.friction.families.registry.family`).
        x: their parameters (P, n_cols) in the order of the family's names (each row broadcasts over the joints).
        delta_s: their Stribeck exponents (n_cols,) (2 for a family without one, which ignores it).
    """

    columns: np.ndarray
    family: FrictionFamily
    x: np.ndarray
    delta_s: np.ndarray

    def torque(self, qd: np.ndarray) -> np.ndarray:
        """``tau_f = -f(qd)`` [N·m] of these joints from their velocities (..., n_cols) [rad/s]: the family's own
        characteristic (:meth:`~wbfriction.friction.families.base.FrictionFamily.values`)."""
        return -self.family.values(self.x, qd, self.delta_s)


def family_columns(params: Sequence[ModelParamsBase]) -> list[FamilyColumns]:
    """The joints of ``params`` (one per joint) grouped by family, in the order each family first appears: every
    joint in exactly one group, whatever family it is (any the registry knows).

    Raises:
        UnknownFamilyError: parameters of a family the registry does not know.
    """
    out = []
    for model in dict.fromkeys(p.model for p in params):
        columns = np.array([i for i, p in enumerate(params) if p.model == model])
        of_model = [params[i] for i in columns]
        out.append(FamilyColumns(columns, family(model), np.array([p.as_vector() for p in of_model]).T,
                                 np.array([float(getattr(p, "delta_s", 2.0)) for p in of_model])))
    return out


@dataclass
class InjectedFriction:
    """Friction a simulator applies to some torque-controlled joints: any friction family's the registry knows
    (:mod:`~wbfriction.friction.families`: the built-in ones, (3.5) among them, and those registered), its
    characteristic as the family computes it (a sign function applied as it is: where the joint would stop, the
    simulator's steps make it chatter about zero velocity, a joint that sticks).

    Attributes:
        params: parameters per joint name.
        joints: their indices among the torque-controlled joints.
        terms: per joint with friction beyond velocity (:class:`~wbfriction.fit.terms.TermFit`), its model
            and terms (:meth:`with_terms`); its ``params`` are the joint's in :attr:`params`.
    """

    params: dict[str, ModelParams]
    joints: list[int]
    terms: dict[str, TermFit] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.beyond = [(col, self.terms[joint]) for col, joint in enumerate(self.params) if joint in self.terms]
        self._gaussian = bool(self.params) and all(type(p) is FrictionParams and p.delta_s == 2.0
                                                   for p in self.params.values())
        if self._gaussian:
            self._stacked = stack_params(cast(list[FrictionParams], list(self.params.values())))
            n = len(self.joints)
            p = {k: np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy() for k, v in self._stacked.items()}
            # (3.5)'s constants, the additive ones negated (tau_f = -f: see torque)
            self._c = (1.0 / p["v_s"], -(p["F_c"] * p["S"]), -p["F_c"], p["a"], -p["tau_os"], -p["F_v"])
        # the others: each joint's family, the joints of one family at once
        self._groups = family_columns(list(self.params.values()))

    def torque(self, qd: np.ndarray) -> np.ndarray:
        """``tau_f = -f(qd)`` of the joints, from their velocities (n_f,) [rad/s] (a new array).

        The simulators call this at every physics step: with (3.5)'s Gaussian Stribeck exponent
        (``delta_s = 2``, the thesis's) on every joint it runs in place on two (n_f,) arrays, the same
        numbers as :func:`~wbfriction.friction.models.coulomb_viscous_stribeck` in fewer operations:
        ``-(F_v qd + tanh(a qd) (F_c + F_c S exp(-(qd / v_s)^2)) + tau_os)`` with the sign carried
        by the constants (``-F_v``, ``-F_c``, ...): a negated factor or term gives the negated product
        or sum bit for bit (IEEE rounding is symmetric), so no final negation."""
        if not self._gaussian or qd.ndim != 1:
            return self._torque_by_model(qd)
        inv_vs, m_FcS, m_Fc, a, m_tau_os, m_Fv = self._c
        multiply, add = np.multiply, np.add
        e = multiply(qd, inv_vs)
        np.square(e, out=e)
        np.negative(e, out=e)
        np.exp(e, out=e)
        multiply(e, m_FcS, out=e)
        add(e, m_Fc, out=e)  # -F_c (1 + S exp(-(qd / v_s)^2))
        out = multiply(qd, a)
        np.tanh(out, out=out)
        multiply(out, e, out=out)
        add(out, m_tau_os, out=out)
        return add(out, multiply(qd, m_Fv, out=e), out=out)

    def _torque_by_model(self, qd: np.ndarray) -> np.ndarray:
        """:meth:`torque` of any families and shapes (..., n_f): each family's joints at once."""
        if len(self._groups) == 1:  # one family on every joint: its columns are 0, 1, ..., n_f - 1
            return self._groups[0].torque(qd)
        out = np.zeros(np.shape(qd))
        for group in self._groups:  # every joint is one group's
            out[..., group.columns] = group.torque(qd[..., group.columns])
        return out

    def with_terms(self, tau_f: np.ndarray, qd: np.ndarray, q: np.ndarray, load: np.ndarray,
                   temperature: float) -> np.ndarray:
        """``tau_f`` (n_f,) of :meth:`torque` with the joints of :attr:`terms` given their whole friction
        (:meth:`~wbfriction.fit.terms.TermFit.torque_at`), from their velocities, angles [rad], loads (the
        rigid-body torque ``M qdd + h = tau_motor + tau_f``, the last step's) [N·m] (n_f,) and the temperature
        [°C]."""
        for col, fit in self.beyond:
            tau_f[col] = fit.torque_at(float(qd[col]), float(q[col]), float(load[col]), temperature)
        return tau_f


def injected_friction(robot: Robot, friction: Mapping[str, ModelParams] | None,
                      terms: Mapping[str, TermFit] | None = None, joints: Sequence[str] | None = None
                      ) -> InjectedFriction:
    """Friction to inject: the given parameters per joint or, by default, the thesis's targets
    (Table 6.1) on the leg joint groups; ``terms`` per joint replace its parameters by theirs and add friction
    beyond velocity.

    Args:
        joints: the joints friction may be injected on (default: the torque-controlled ones); the indices are
            among them.

    Raises:
        InputError: an entry for a joint that is not one of ``joints``.
    """
    joints = robot.torque_controlled if joints is None else tuple(joints)
    friction = dict(friction_by_group(robot.groups) if friction is None else friction)
    terms = dict(terms or {})
    friction.update({j: t.params for j, t in terms.items()})
    for joint in friction:
        if joint not in joints:
            raise InputError(f"friction given for '{joint}', which is not a torque-controlled joint")
    return InjectedFriction(friction, [joints.index(j) for j in friction], terms)


def terms_truth(terms: Mapping[str, TermFit]) -> dict[str, dict]:
    """The terms a simulator injected, as its log's ``terms_true`` metadata records them."""
    return {j: {"kept": list(t.kept), "harmonics": t.harmonics, "coefficients": t.coefficients,
                "reference_temperature": t.reference_temperature} for j, t in terms.items()}


def warm_up(temperature: tuple[float, float] | None, n: int) -> np.ndarray | None:
    """The joints' temperature at each of ``n`` samples [°C]: linear from ``temperature[0]`` to ``[1]``; None
    without."""
    return None if temperature is None else np.linspace(temperature[0], temperature[1], n)


@dataclass
class Pull:
    """An interval where a welded foot pulled on the ground (negative normal force)."""

    frame: str
    start: float
    end: float
    samples: int
    min_force: float  # [N]
    double_support: int = 0  # of the samples, those with every foot in contact


@dataclass
class SimulationResult:
    """A simulated walk.

    Attributes:
        log: the log, in the project's format.
        wrench: contact wrenches (N, n_contacts, 6) in the soles' LOCAL frames [N, N·m],
            zero off contact; ``wrench[..., 2]`` is the normal force.
        q: simulated configurations (N, nq); v: velocities (N, nv).
        reference: the walking reference.
        tau_motor: the torques the motors applied (N, n_tc) [N·m], truth: held over each period; the log's
            ``tau`` is them plus sensor noise, or what a torque sensor read of them (MuJoCo).
    """

    log: Log
    wrench: np.ndarray
    q: np.ndarray
    v: np.ndarray
    reference: WalkingReference
    contact_frames: tuple[str, ...] = field(default_factory=tuple)
    tau_motor: np.ndarray | None = None

    def pulls(self, threshold: float = 0.0) -> list[Pull]:
        """Intervals where a foot in contact had a normal force below ``threshold`` [N]."""
        out = []
        for c, frame in enumerate(self.contact_frames):
            bad = self.log.contact[:, c] & (self.wrench[:, c, 2] < threshold)
            edges = np.flatnonzero(np.diff(np.r_[0, bad.astype(np.int8), 0]))
            for s, e in zip(edges[::2], edges[1::2]):
                out.append(Pull(frame, float(self.log.time[s]), float(self.log.time[e - 1]), int(e - s),
                                float(self.wrench[s:e, c, 2].min()), int(self.log.contact[s:e].all(axis=1).sum())))
        return out


def simulated_log(robot: Robot, reference: WalkingReference, Q: np.ndarray, V: np.ndarray, A: np.ndarray,
                  tau: np.ndarray, tau_f: np.ndarray, contact: np.ndarray, friction: InjectedFriction,
                  generator: str, options, log_base: bool, wrench: np.ndarray | None = None,
                  imu: np.ndarray | None = None, **metadata) -> Log:
    """A simulated walk in the log format: joint angles and the true joint velocities and
    accelerations from the full states ``Q`` (N, nq), ``V``, ``A`` (N, nv), torques and
    friction of the torque-controlled joints, contact flags, the base pose and its true twist and
    acceleration if ``log_base``, the force-torque sensors' ``wrench`` (N, n_sensors, 6) and the ``imu``'s
    readings (N, 6) if given;
    metadata: the generator, its options, the gait, the true friction, and ``metadata``."""
    iq, iv = robot.act_q_index, robot.act_v_index
    meta = {"generator": generator, "options": asdict(options), "gait": asdict(reference.plan.options),
            "friction_true": {j: p.to_target() for j, p in friction.params.items()}, **metadata}
    base = (Q[:, :7].copy(), V[:, :6].copy(), A[:, :6].copy()) if log_base else (None, None, None)
    return Log(reference.time.copy(), Q[:, iq], tau, contact, base[0], tau_f, meta,
               source=generator.rsplit(".", 1)[-1], qd_true=V[:, iv], qdd_true=A[:, iv], wrench=wrench,
               base_qd_true=base[1], base_qdd_true=base[2], imu=imu)


class Recording:
    """The signals both simulators log at every sample, and the result they make at the end.

    Attributes:
        tau: measured torques of the torque-controlled joints (N, n_tc) [N·m].
        tau_f: friction applied to them (N, n_tc) [N·m], zero on the joints without.
        wrench: contact wrenches (N, n_contacts, 6), as :attr:`SimulationResult.wrench`.
    """

    def __init__(self, robot: Robot, reference: WalkingReference, friction: InjectedFriction,
                 temperature: tuple[float, float] | None = None) -> None:
        """Empty buffers for the ``len(reference)`` samples of a walk of ``robot``; ``temperature``: the joints'
        warm-up (:func:`warm_up`, its samples :attr:`temperature`)."""
        n, n_tc = len(reference), robot.tc_index.size
        self.robot, self.reference, self.friction = robot, reference, friction
        self.temperature = warm_up(temperature, n)
        if self.temperature is None and any("temperature" in t.kept for t in friction.terms.values()):
            raise InputError("a temperature term needs the joints' temperature: give the options' temperature")
        self.tau = np.empty((n, n_tc))
        self.tau_f = np.zeros((n, n_tc))
        self.wrench = np.zeros((n, len(robot.contact_frames), 6))
        self._friction_columns = as_slice(friction.joints)

    def record_torques(self, k: int, tau: np.ndarray, tau_f: np.ndarray | None) -> None:
        """Log sample ``k``'s measured torques and the friction of the joints that have some."""
        self.tau[k] = tau
        if self.friction.joints:
            self.tau_f[k, self._friction_columns] = tau_f

    def result(self, Q: np.ndarray, V: np.ndarray, A: np.ndarray, contact: np.ndarray, generator: str, options,
               *, Q_log: np.ndarray | None = None, tau_noise: np.ndarray | None = None, log_sensors: bool = False,
               log_imu: bool = False, sensor_wrench: np.ndarray | None = None, imu: np.ndarray | None = None,
               tau_sensed: np.ndarray | None = None, **metadata) -> SimulationResult:
        """The :func:`simulated_log` of the true states ``Q``, ``V``, ``A`` (its configurations ``Q_log`` if
        given, its torques, or the torque sensors' readings ``tau_sensed`` of them, plus ``tau_noise`` if
        given) and the :class:`SimulationResult` around it.
        With ``log_sensors``, the log carries what the robot's force-torque sensors measure
        (:func:`~wbfriction.model.force_torque.sensor_readings` of :attr:`wrench`, which must then be
        the contact wrenches that go with ``A``); with ``log_imu``, what the robot's IMU reads
        (:func:`~wbfriction.model.imu.imu_readings`); ``sensor_wrench`` (N, n_sensors, 6) and ``imu`` (N, 6),
        what a simulator's own sensors measured, are logged as they are."""
        tau = self.tau if tau_sensed is None else tau_sensed
        tau = tau if tau_noise is None else tau + tau_noise
        wrench = sensor_wrench if sensor_wrench is not None and sensor_wrench.shape[1] else None
        if log_sensors and self.robot.ft_sensors:
            wrench = sensor_readings(self.robot.model, self.robot.ft_sensors, self.robot.contact_frames, Q, V, A,
                                     self.wrench)
        if log_imu and self.robot.imu is not None:
            imu = imu_readings(self.robot.model, self.robot.imu, Q, V, A)
        if self.friction.terms:
            metadata["terms_true"] = terms_truth(self.friction.terms)
        log = simulated_log(self.robot, self.reference, Q if Q_log is None else Q_log, V, A, tau, self.tau_f, contact,
                            self.friction, generator, options, options.log_base, wrench, imu, **metadata)
        if self.temperature is not None:
            log.temperature = np.repeat(self.temperature[:, None], self.tau.shape[1], axis=1)
        return SimulationResult(log, self.wrench, Q, V, self.reference, tuple(self.robot.contact_frames),
                                self.tau.copy())


def require_point_feet(robot: Robot, simulator: str) -> None:
    """Refuse a robot whose contact frames are not all point feet (``contact_model = "point"``): the quadruped
    simulators model a foot as a sphere touching the ground at a point, and cannot simulate another contact model
    (a sole, or one registered in a program: :mod:`wbfriction.model.contacts`), whatever its estimation.

    Raises:
        InputError: the first other contact model, naming it and its frame.
    """
    other = next(((f, m) for f, m in zip(robot.contact_frames, robot.contact_models) if m.name != "point"), None)
    if other is not None:
        frame, kind = other
        raise InputError(f"robot '{robot.name}': {simulator} simulates point feet only (contact_model = \"point\"), "
                         f"not contact model '{kind.name}' of '{frame}': {kind.what}")

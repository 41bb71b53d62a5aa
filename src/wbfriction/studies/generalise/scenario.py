"""A scenario of the generalisation benchmark drawn from an integer seed (:func:`draw`), and the seed's set
(:func:`split`).

Everything of a scenario is drawn from ``numpy.random.default_rng(seed)`` in a fixed order, so the same seed gives
the same :class:`Scenario` (and, simulated, the same log bytes: :mod:`wbfriction.studies.generalise.simulate`).

**Classes** (:data:`CLASSES`): ``arm`` (a fixed-base arm, the built-in Panda or a random serial chain of 3-7
revolute joints, simulated on MuJoCo tracking a Fourier excitation with computed torque and PD; the tool runs
``estimate`` then ``fit``) and ``pd`` (the built-in Go2 hung with its base fixed, its joints PD-driven, the hung
simulator :mod:`wbfriction.sim.hung`; the tool runs ``identify --actuator pd``), ``crawl`` (the built-in
``go2_walking`` crawling, or standing, on point feet, ``wbfriction simulate --simulator mujoco``; ``estimate`` then
``fit``) and ``humanoid`` (TALOS walking forward on its soles, the same; friction on its legs). Drawn 50, 35, 10
and 5 % of the time (:data:`CLASS_WEIGHTS`; a Panda in 30 % of the arms). The walking classes' simulators take
friction of the velocity alone (Coulomb–viscous, Stribeck, an asymmetric Coulomb level), their torque from a
sensor, no armature; their ``duration`` is seconds for the crawl and steps for TALOS.

**Split** (:func:`split`): a seed is in ``tuning`` when the first byte of the SHA-256 of ``"wbfriction-generalise:"``
followed by its decimal digits is even, else in ``test``: about half each, each seed in one set only, whatever the
draw and the version of NumPy.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, replace
from typing import Literal, get_args

import numpy as np

from wbfriction.studies.generalise.laws import LAWS, VELOCITY_LAWS, JointLaw, Law, draw_law

RobotClass = Literal["arm", "pd", "crawl", "humanoid"]
CLASSES: tuple[RobotClass, ...] = get_args(RobotClass)
CLASS_WEIGHTS = (0.5, 0.35, 0.1, 0.05)
"""How often each of :data:`CLASSES` is drawn."""
Excitation = Literal["good", "poor", "still"]
EXCITATIONS: tuple[Excitation, ...] = get_args(Excitation)
SetName = Literal["tuning", "test"]
SETS: tuple[SetName, ...] = get_args(SetName)
PANDA_JOINTS = 7
GO2_JOINTS = 12
WALKERS = {"crawl": "go2_walking", "humanoid": "talos"}
"""The built-in robot of each walking class."""


def split(seed: int) -> SetName:
    """The set of ``seed`` (module docstring): ``"tuning"`` or ``"test"``, stable and disjoint."""
    digest = hashlib.sha256(f"wbfriction-generalise:{int(seed)}".encode()).digest()
    return "tuning" if digest[0] % 2 == 0 else "test"


@dataclass(frozen=True)
class Scenario:
    """One drawn scenario (every field from :func:`draw`).

    Attributes:
        seed: the integer it was drawn from.
        robot_class: ``arm`` or ``pd``; robot: ``panda``, ``chain`` or ``go2``; n_joints: its joints.
        chain_seed: the seed of the random chain's URDF (:func:`~wbfriction.studies.generalise.urdf.chain_urdf`).
        perturbation: the share (0-0.2) the given model's masses, centres of mass and inertias are off by.
        law: the friction law of every joint; laws: each joint's (:class:`~wbfriction.studies.generalise.laws.
            JointLaw`), in the robot's joint order.
        warm_up: the joints' temperature at the log's start and end [°C] (not logged).
        excitation: ``good`` (long, fast, many harmonics or ramps and chirps), ``poor`` (short, slow, one speed),
            ``still`` (almost still).
        duration [s], rate [Hz], substeps: the log and the physics steps per sample (a walk: its seconds, or
            TALOS's steps; its rate and physics step are the simulator's own, ``rate`` and ``substeps`` unused).
        armature: the simulated rotor inertia per joint [kg·m²] (the tool's TOML has none).
        sensor: ``current`` (motor current times a torque constant the TOML gives ``k_t_error`` off; the rotor in the
            dynamics), ``torque`` (a joint torque sensor after the rotor: no armature) or ``pd`` (the drivers' law).
        k_t_error: the TOML's torque constant over the true one, less 1.
        encoder_bits: the encoders' bits per turn (None: exact); position_std [rad]; torque_std [N·m]: white noise.
        torque_delay: how much later than the positions the torque is logged [s] (arm).
        clock_jitter: the log's stamps late by up to this [s] (receive-time stamps, uniform).
        velocity_std: the drivers' velocity noise [rad/s] (pd).
        encoder_offset: the logged angle minus the model's per joint [rad] (pd; the TOML has none).
        delay: the drivers' delay [s]; delayed: what it holds back; given_delay: the TOML's.
        kp, kd: the drivers' gains [N·m/rad, N·m·s/rad]; gain_error: the TOML's gains over the true ones, less 1.
        excitation_seed, noise_seed: the excitation's and the sensors' seeds.
    """

    seed: int
    robot_class: RobotClass
    robot: str
    n_joints: int
    chain_seed: int
    perturbation: float
    law: Law
    laws: tuple[JointLaw, ...]
    warm_up: tuple[float, float]
    excitation: Excitation
    duration: float
    rate: float
    substeps: int
    armature: tuple[float, ...]
    sensor: str
    k_t_error: float
    encoder_bits: int | None
    position_std: float
    torque_std: float
    torque_delay: float
    clock_jitter: float
    velocity_std: float
    encoder_offset: tuple[float, ...]
    delay: float
    delayed: str
    given_delay: float
    kp: float
    kd: float
    gain_error: float
    excitation_seed: int
    noise_seed: int

    @property
    def set(self) -> SetName:
        """:func:`split` of :attr:`seed`."""
        return split(self.seed)

    @property
    def name(self) -> str:
        """A short name: ``<seed>-<robot>-<law>-<excitation>``."""
        return f"{self.seed}-{self.robot}-{self.law}-{self.excitation}"


def _pick(rng: np.random.Generator, options: tuple, weights: tuple[float, ...] | None = None):
    return options[int(rng.choice(len(options), p=None if weights is None else np.asarray(weights)))]


def _friction_levels(rng: np.random.Generator, robot_class: RobotClass, robot: str, n: int
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's Coulomb level F_c [N·m] and viscous coefficient F_v [N·m·s/rad], drawn for the robot's drives."""
    if robot_class == "humanoid":  # TALOS's legs: larger drives
        return rng.uniform(0.5, 3.0, n), rng.uniform(0.1, 1.0, n)
    if robot_class == "arm":
        F_c, F_v = rng.uniform(0.3, 2.5, n), rng.uniform(0.1, 1.2, n)
        if robot == "panda":  # the wrist's drives are small
            F_c[4:], F_v[4:] = 0.3 * F_c[4:], 0.3 * F_v[4:]
        return F_c, F_v
    return rng.uniform(0.2, 0.7, n), rng.uniform(0.1, 0.4, n)


def draw(seed: int) -> Scenario:
    """The scenario of ``seed`` (module docstring; ranges in the code)."""
    rng = np.random.default_rng(seed)
    robot_class: RobotClass = _pick(rng, CLASSES, CLASS_WEIGHTS)
    if robot_class == "arm":
        robot = "panda" if rng.uniform() < 0.3 else "chain"
        n = PANDA_JOINTS if robot == "panda" else int(rng.integers(3, 8))
    elif robot_class == "pd":
        robot, n = "go2", GO2_JOINTS
    else:
        robot, n = WALKERS[robot_class], GO2_JOINTS  # the Go2's joints, TALOS's legs
    chain_seed = int(rng.integers(2**31))
    perturbation = float(rng.uniform(0.0, 0.2))
    law: Law = _pick(rng, LAWS if robot_class == "arm" else VELOCITY_LAWS)
    F_c, F_v = _friction_levels(rng, robot_class, robot, n)
    laws = tuple(draw_law(rng, law, float(c), float(v)) for c, v in zip(F_c, F_v))
    if robot_class != "arm":  # the other simulators' friction is (3.5): an asymmetric Coulomb level, one F_v
        laws = tuple(replace(x, F_v_neg=x.F_v) for x in laws)
    warm_up = (25.0, float(25.0 + rng.uniform(10.0, 30.0))) if law == "temperature" else (25.0, 25.0)
    excitation: Excitation = _pick(rng, EXCITATIONS, (0.6, 0.25, 0.15) if robot_class != "humanoid" else
                                   (0.6, 0.4, 0.0))
    if robot_class == "arm":
        duration = float({"good": rng.uniform(12.0, 20.0), "poor": rng.uniform(6.0, 10.0),
                          "still": rng.uniform(8.0, 12.0)}[excitation])
        rate = float(_pick(rng, (200.0, 250.0, 500.0)))
        substeps = int(round(10000.0 / rate))  # 10 kHz physics: a 2 kHz one chattered at reversals (F_v 2x off)
        sensor = "current" if rng.uniform() < 0.6 else "torque"
        armature = tuple(float(x) for x in (rng.uniform(0.02, 0.4, n) if sensor == "current" else np.zeros(n)))
        if robot == "panda" and sensor == "current":
            armature = tuple(a * (0.3 if i >= 4 else 1.0) for i, a in enumerate(armature))
        k_t_error = float(rng.uniform(-0.05, 0.05)) if sensor == "current" else 0.0
        encoder_bits = _pick(rng, (None, 16, 19, 21))
        position_std = float(_pick(rng, (0.0, 0.0, 2e-5, 1e-4)))
        torque_std = float(_pick(rng, (0.0, 0.02, 0.05, 0.2)))
        torque_delay = float(_pick(rng, (0.0, 0.0, 1.0, 2.0))) / rate
        clock_jitter = float(_pick(rng, (0.0, 0.0, 0.2))) / rate
        velocity_std, offset = 0.0, tuple(0.0 for _ in range(n))
        delay = given_delay = 0.0
        delayed, kp, kd, gain_error = "setpoints", 0.0, 0.0, 0.0
    elif robot_class != "pd":
        duration = float({"good": rng.uniform(6.0, 8.0), "poor": rng.uniform(3.0, 4.0), "still": 4.0}[excitation])
        if robot_class == "humanoid":  # steps, not seconds
            duration = float({"good": 3, "poor": 1}[excitation])
        rate, substeps, sensor = 1000.0, 1, "torque"
        armature = tuple(0.0 for _ in range(n))
        k_t_error, position_std, torque_delay, clock_jitter, velocity_std = 0.0, 0.0, 0.0, 0.0, 0.0
        encoder_bits = _pick(rng, (None, 19, 16))
        torque_std = float(_pick(rng, (0.0, 0.05, 0.2)))
        offset = tuple(0.0 for _ in range(n))
        delay = given_delay = 0.0
        delayed, kp, kd, gain_error = "setpoints", 0.0, 0.0, 0.0
    else:
        duration = float({"good": rng.uniform(10.0, 15.0), "poor": rng.uniform(5.0, 7.0),
                          "still": rng.uniform(6.0, 8.0)}[excitation])
        rate, substeps, sensor = 200.0, 5, "pd"
        armature = tuple(float(x) for x in rng.uniform(0.008, 0.025, n))
        k_t_error, torque_std, torque_delay = 0.0, 0.0, 0.0
        encoder_bits = _pick(rng, (None, 19, 19, 16))
        position_std = 0.0
        velocity_std = float(_pick(rng, (0.0, 0.04, 0.08, 0.15)))
        clock_jitter = float(_pick(rng, (0.0, 0.0, 0.0015)))
        offset = tuple(float(x) for x in rng.uniform(-0.04, 0.04, n))
        delay = float(rng.uniform(0.0, 0.025))
        delayed = "setpoints" if rng.uniform() < 0.7 else "torque"
        given_delay = float(_pick(rng, (0.0, delay, 0.012)))
        kp, kd = float(rng.uniform(15.0, 40.0)), float(rng.uniform(0.3, 1.0))
        gain_error = float(rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 0.2)) if rng.uniform() < 0.3 else 0.0
    return Scenario(seed=int(seed), robot_class=robot_class, robot=robot, n_joints=n, chain_seed=chain_seed,
                    perturbation=perturbation, law=law, laws=laws, warm_up=warm_up, excitation=excitation,
                    duration=round(duration, 3), rate=rate, substeps=substeps, armature=armature, sensor=sensor,
                    k_t_error=k_t_error, encoder_bits=encoder_bits, position_std=position_std, torque_std=torque_std,
                    torque_delay=torque_delay, clock_jitter=clock_jitter, velocity_std=velocity_std,
                    encoder_offset=offset, delay=delay, delayed=delayed, given_delay=given_delay, kp=kp, kd=kd,
                    gain_error=gain_error, excitation_seed=int(rng.integers(2**31)),
                    noise_seed=int(rng.integers(2**31)))

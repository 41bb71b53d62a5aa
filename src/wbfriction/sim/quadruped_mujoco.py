"""A walking quadruped on MuJoCo: soft point contacts, foot force sensors, an IMU, sensor noise, known friction per
joint, torque-driven or PD-driven (issue 56, item 2).

**Model** (:func:`~wbfriction.sim.quadruped_mjcf.build_quadruped_model`): the robot's URDF with a free joint, a ground
plane and a sphere per foot round the foot frame's origin (soft contacts, ``condim`` 3; firm ones with
``options.contacts = "firm"``: :func:`~wbfriction.sim.quadruped_mjcf.firm_contacts`).

**Controller**, at the log's samples (the reference's ``dt``), on the encoders' angles and the drivers' velocities
(the base's true pose and twist: the simulator does not model a state estimator): the ideal simulator's balance
controller (:class:`~wbfriction.sim.quadruped_control.BalanceController`: whole-body inverse dynamics, the planned
stance feet standing, PD tasks on the base, the swing feet and the joints; ``options.gains``) plus, with
``options.compensate``, the friction of the reference's velocities. **Torque-driven**: ``tau = clip(tau_c + kp
(q_ref - q_enc) + kd (qd_ref - qd_drv))`` (``options.kp``, ``kd``; clipped at the URDF's effort limits), held over
the period; the log's ``tau`` is that command (the joint torque sensor sits before the friction), plus its noise.
With more than one physics step per period, the first step (the switch at ``t_k``) takes the mean of the previous
and the new command, so that the command acts over ``[t_k, t_k+1)`` as a real robot's zero-order hold
(``torque_alignment = "zoh"``; MuJoCo's semi-implicit Euler otherwise applies it half a physics step early as the
positions see it: the ideal simulator's module docstring, issue 63), and the sample is recorded (``mj_forward``)
under the command itself.
**PD-driven**: the drivers (:mod:`wbfriction.sim.pd_robot`'s law; gains, delay and limits from the robot's
``[pd]``) are sent ``q_des = q_ref`` (encoder's coordinates), ``qd_des = qd_ref`` and ``tau_ff`` = the controller's
torque, their PD on top (as a Unitree low-level command; the ideal simulator's drivers instead get the ``tau_ff``
that cancels their PD at the command: on MuJoCo that left the trot to the controller alone, 4 times the tracking
error, and a trot with the base gains (50, 10) fell at 6.7 s); at every physics step they apply
``clip(kp (q_des - q_enc) + kd (qd_des - qd_drv) + tau_ff)`` on that step's readings, each set-point as
``options.setpoints`` says (``"model"``: :func:`~wbfriction.model.pd.pd_torque`'s, so that the law on the logged
columns gives the torque applied at the samples exactly; ``"held"``: :func:`~wbfriction.sim.pd_robot.step_setpoints`).
The log then has ``q_des``/``qd_des``/``tau_ff`` and no torque.

**Friction** per joint (any family the registry knows, :class:`~wbfriction.sim.common.InjectedFriction`),
``tau_f = -f(qd)`` of each physics step's velocity applied as a generalised force (``qfrc_applied``), logged
(``tau_f_true``) at the samples. Not MuJoCo's ``frictionloss`` and ``damping``: the friction-loss constraint's force
is not a function of the velocity (it sticks, and leads the velocity by its time constant), so the truth would not
be the model fitted; an applied torque is exactly ``-f(qd)`` in the step's equations.

**The log**, at each sample the physics step that starts at it (the truth then balances exactly at the samples:
``M(q) qdd + h(q, qd) = S^T (tau + tau_f) + sum_c J_c^T f_c`` with ``J_c`` at the contact points):

* ``q.<joint>`` the encoders (quantised), ``qd.<joint>`` the drivers' velocities, ``tau.<joint>`` (torque-driven)
  or ``q_des``/``qd_des``/``tau_ff`` (PD-driven);
* ``base.*`` the true pose, ``base_qd_true.*``/``base_qdd_true.*`` its twist and acceleration in Pinocchio's
  free-flyer convention (base frame: MuJoCo's world-frame linear velocity turned);
* ``imu.*`` MuJoCo's gyro and accelerometer at the IMU frame (plus noise);
* foot forces (``options.foot_forces``): the ground's force on each foot, world axes, summed over the foot's
  contacts (``mj_contactForce``), plus noise; the normal alone (``"normal"``, Unitree's foot sensors) or all three;
* ``contact.<frame>``: the measured normal force with hysteresis (:func:`wbfriction.logs.contacts.hysteresis`, the
  robot's thresholds);
* the truth: ``tau_f_true``, ``qd_true``, ``qdd_true``.

**Noise** (off by default; :data:`UNITREE_NOISE` a real Go2's order of magnitude): see :class:`QuadrupedNoise`.
"""

from __future__ import annotations

import copy
import time as _time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, OptionError, SimulationError
from wbfriction.logs.contacts import default_thresholds, hysteresis
from wbfriction.logs.log import Log
from wbfriction.logs.pd import PdSetpoints
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, injected_friction, require_point_feet
from wbfriction.sim.mujoco_model import MujocoRobot
from wbfriction.sim.options import SensorNoise
from wbfriction.sim.pd_robot import joint_values, step_setpoints
from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun, default_quadruped_friction
from wbfriction.sim.quadruped_control import BalanceController
from wbfriction.sim.quadruped_mjcf import build_quadruped_model, firm_contacts
from wbfriction.walking.quadruped import QuadrupedReference

LWA = pin.LOCAL_WORLD_ALIGNED

FALL_HEIGHT = 0.5
"""The run stops (:class:`~wbfriction.exceptions.SimulationError`) when the base drops below this share of its
initial height."""


GENERATOR = "wbfriction.sim.quadruped_mujoco.simulate_quadruped_mujoco"


@dataclass(frozen=True)
class QuadrupedNoise:
    """A walking robot's sensor errors (all off by default; :data:`UNITREE_NOISE` a real Go2's order).

    Attributes:
        position_std: white noise on the encoders' angles [rad], before their rounding.
        encoder_resolution: the encoders' step [rad] (the angle rounded to it), or None (exact).
        velocity_std: white noise on the drivers' joint velocities [rad/s].
        torque_std: white noise on the logged joint torques [N·m] (torque-driven: the torque sensors).
        gyro_std: white noise on the IMU's angular velocity [rad/s]; acc_std: on its specific force [m/s^2].
        force_std: white noise on each logged foot force component [N].
        seed: the noise generator's seed.

    The encoders and the drivers' velocities are read at every physics step (the PD drivers act on each; the
    controller on those of the samples'), the others at the samples; the log holds what the controller used.

    Raises:
        InputError: a negative standard deviation, a resolution that is not > 0.
    """

    position_std: float = 0.0
    encoder_resolution: float | None = None
    velocity_std: float = 0.0
    torque_std: float = 0.0
    gyro_std: float = 0.0
    acc_std: float = 0.0
    force_std: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("position_std", "velocity_std", "torque_std", "gyro_std", "acc_std", "force_std"):
            if not float(getattr(self, name)) >= 0:
                raise InputError(f"quadruped noise {name} must be >= 0, got {getattr(self, name)!r}")
        if self.encoder_resolution is not None and not self.encoder_resolution > 0:
            raise InputError(f"quadruped noise encoder_resolution must be > 0, got {self.encoder_resolution!r}")

    @classmethod
    def from_sensor_noise(cls, noise: SensorNoise | None) -> QuadrupedNoise:
        """The options' :class:`~wbfriction.sim.options.SensorNoise` (angles, encoder, torques) as this noise
        (None: exact)."""
        if noise is None:
            return cls()
        return cls(position_std=noise.position_std, encoder_resolution=noise.resolution, torque_std=noise.torque_std,
                   seed=noise.seed)

    def draw(self, n: int, substeps: int, n_act: int, n_feet: int) -> dict[str, np.ndarray | None]:
        """The errors of ``n`` samples of ``substeps`` physics steps, from :attr:`seed` (None where off):
        ``position``, ``velocity`` (n * substeps, n_act); ``torque`` (n, n_act); ``imu`` (n, 6); ``force``
        (n, n_feet, 3)."""
        rng = np.random.default_rng(self.seed)
        shapes = {"position": ((n * substeps, n_act), self.position_std),
                  "velocity": ((n * substeps, n_act), self.velocity_std), "torque": ((n, n_act), self.torque_std),
                  "imu": ((n, 6), np.r_[[self.gyro_std] * 3, [self.acc_std] * 3]),
                  "force": ((n, n_feet, 3), self.force_std)}
        return {k: (rng.normal(0.0, 1.0, shape) * std if np.any(std) else None) for k, (shape, std) in shapes.items()}


UNITREE_NOISE = QuadrupedNoise(encoder_resolution=2.0 * np.pi / 2**15, velocity_std=0.02, torque_std=0.05,
                               gyro_std=0.005, acc_std=0.05, force_std=2.0)
"""A Unitree-like robot's sensors: the joint encoders on a 15-bit lattice (2 pi / 2^15 = 1.9e-4 rad), the drivers'
velocity within 0.02 rad/s, the torque within 0.05 N·m, the IMU within 0.005 rad/s and 0.05 m/s^2 (a MEMS IMU's
white noise at 500 Hz), the foot forces within 2 N."""


@dataclass
class MujocoQuadrupedRun(QuadrupedRun):
    """A quadruped simulated on MuJoCo (:class:`~wbfriction.sim.quadruped.QuadrupedRun`; ``snap`` empty: MuJoCo's
    feet land where they land).

    Attributes:
        contact_point: where the ground's force acts on each foot (N, 4, 3) [m], world (MuJoCo's contact point,
            about the foot's radius below the foot frame's origin), NaN in the air.
        imu_true: the IMU's exact readings (N, 6) (MuJoCo's gyro and accelerometer), or (N, 0) without an IMU.
        seconds: the simulation's wall-clock time [s].
    """

    contact_point: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 3)))
    imu_true: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    seconds: float = 0.0


class _Sim:
    """One run of :func:`simulate_quadruped_mujoco`: the MuJoCo model and data, the controller, the drivers, the
    sensors' errors and the buffers (module docstring)."""

    def __init__(self, robot: Robot, reference: QuadrupedReference, options: QuadrupedOptions,
                 noise: QuadrupedNoise, mjr: MujocoRobot | None) -> None:
        import mujoco
        self.robot, self.ref, self.options, self.noise = robot, reference, options, noise
        self.dt = dt = float(reference.dt)
        self.substeps = int(round(dt / options.physics_dt))
        if self.substeps < 1 or abs(self.substeps * options.physics_dt - dt) > 1e-9 * dt:
            raise OptionError("--physics-dt", options.physics_dt, f"a whole fraction of the log's period {dt:g} s")
        self.h = dt / self.substeps
        self.mjr = mjr or build_quadruped_model(robot, self.h)
        self.model = copy.copy(self.mjr.model)  # the settings below must not leak into a shared model
        self.model.opt.timestep = self.h
        if options.contacts == "firm":
            firm_contacts(self.model)
        armature = joint_values(robot, options.armature, dict(zip(robot.actuated,
                                                                  robot.model.armature[robot.act_v_index])),
                                "armature")
        self.model.dof_armature[self.mjr.dof_index] = armature
        pmodel = pin.Model(robot.model)  # the controller's model: the same armature
        pmodel.armature[robot.act_v_index] = armature
        self.controller = BalanceController(robot, pmodel, reference, options.gains)
        friction = default_quadruped_friction(robot) if options.friction is None else options.friction
        self.injected: InjectedFriction = injected_friction(robot, friction, joints=robot.actuated)
        self.compensation = np.zeros((len(reference), robot.n_act))  # the motors' share against the reference's
        if options.compensate and self.injected.joints:
            self.compensation[:, self.injected.joints] = -self.injected.torque(
                reference.qd[:, self.injected.joints])
        self.cols_f = np.array(self.injected.joints, dtype=int)
        self.dof_f = self.mjr.dof_index[self.cols_f]
        self.offset = joint_values(robot, None, robot.encoder_offset, "encoder offset")
        q_ref, v_ref, _ = reference.full(robot)
        n, m, nf = len(reference), robot.n_act, len(robot.contact_frames)
        self.errors = noise.draw(n, self.substeps, m, nf)
        self.driver = robot.pd if options.drive == "pd" else None
        if options.drive == "pd" and (robot.pd is None or robot.pd.joints != robot.actuated):
            raise InputError(f"robot '{robot.name}': --drive pd needs a [pd] table driving every joint "
                             "(wbfriction.model.pd)")
        if self.driver is not None and self.driver.delayed == "torque" and self.driver.delay > 0:
            raise InputError(f"robot '{robot.name}': a driver delaying its whole torque ([pd] delayed = torque) is "
                             "not simulated here yet")
        self.data = mujoco.MjData(self.model)
        self.data.qpos[:] = self.mjr.qpos(q_ref[0])
        self.data.qvel[:] = self.mjr.velocity_map(q_ref[0]) @ v_ref[0]
        mujoco.mj_forward(self.model, self.data)
        self.z0 = float(self.data.qpos[2])
        self.foot_geoms = {g: c for c, g in enumerate(self.mjr.sole_geoms)}
        # the buffers: the state and acceleration of each sample's first physics step, what the sensors read
        self.Q, self.V, self.A = (np.zeros((n, k)) for k in (robot.model.nq, robot.model.nv, robot.model.nv))
        self.q_enc, self.qd_drv, self.tau, self.tau_f = (np.zeros((n, m)) for _ in range(4))
        self.commands = tuple(np.zeros((n, m)) for _ in range(3))  # q_des (encoder's), qd_des, tau_ff
        self.force, self.point = np.zeros((n, nf, 3)), np.full((n, nf, 3), np.nan)
        self.imu = np.zeros((n, len(self.mjr.imu_index)))

    def read_joints(self, step: int) -> tuple[np.ndarray, np.ndarray]:
        """The encoders' angles (the logged ones: offset, noise, rounding) and the drivers' velocities at physics
        step ``step``."""
        data, e = self.data, self.errors
        q = data.qpos[self.mjr.qpos_index] + self.offset
        if e["position"] is not None:
            q += e["position"][step]
        r = self.noise.encoder_resolution
        if r is not None:
            q = np.round(q / r) * r
        qd = data.qvel[self.mjr.dof_index].copy()
        if e["velocity"] is not None:
            qd += e["velocity"][step]
        return q, qd

    def control(self, k: int, q_enc: np.ndarray, qd_drv: np.ndarray) -> np.ndarray:
        """Sample ``k``'s torque (n_act,) [N·m]: the balance controller's on the measured joints and the true base
        (the planned stance feet standing), plus the friction of the reference's velocities if
        ``options.compensate``."""
        robot, data, mjr = self.robot, self.data, self.mjr
        q = mjr.q(data.qpos)
        q[robot.act_q_index] = q_enc - self.offset
        v = mjr.v(data.qpos, data.qvel)
        v[robot.act_v_index] = qd_drv
        return self.controller.torque(k, q, v, np.flatnonzero(self.ref.contact[k])) + self.compensation[k]

    def setpoints(self, k: int) -> list[np.ndarray]:
        """The set-points ``q_des``, ``qd_des``, ``tau_ff`` (substeps, n_act) the drivers apply at sample ``k``'s
        physics steps: ``options.setpoints = "held"``, held and delayed
        (:func:`~wbfriction.sim.pd_robot.step_setpoints`); ``"model"``, the commands linearly interpolated at
        ``t - T/2 - delay`` (:func:`~wbfriction.model.pd.delayed`'s: at the samples, what
        :func:`~wbfriction.model.pd.pd_torque` takes), held at the last command arrived where that needs a later one
        (as the ideal simulator's drivers)."""
        assert self.driver is not None
        first, last = k * self.substeps, (k + 1) * self.substeps
        if self.options.setpoints == "held":
            return [step_setpoints(x[:k + 1], self.substeps, self.driver.delay / self.h, first, last)
                    for x in self.commands]
        at = (np.arange(first, last) * self.h - 0.5 * self.dt - self.driver.delay) / self.dt  # in samples
        i0 = np.floor(at).astype(int)
        w = (at - i0)[:, None]
        out = []
        for x in self.commands:
            a, b = x[np.clip(i0, 0, k)], x[np.clip(i0 + 1, 0, k)]
            out.append(a + w * (b - a))
        return out

    def period(self, k: int) -> None:
        """Sample ``k``: read the sensors, command, the physics steps (the first one recorded)."""
        import mujoco
        model, data, opt, s0 = self.model, self.data, self.options, k * self.substeps
        q_enc, qd_drv = self.read_joints(s0)
        tau = self.control(k, q_enc, qd_drv)
        q_des, qd_des, tau_ff = self.commands
        if self.driver is None:
            tau = np.clip(tau + opt.kp * (q_des[k] - q_enc) + opt.kd * (qd_des[k] - qd_drv), -self.limit, self.limit)
        else:  # the controller's torque as the feed-forward, the drivers' PD on top (Unitree's low-level command)
            d = self.driver
            tau_ff[k] = tau
            q_des, qd_des, ff = self.setpoints(k)
        # torque-driven, physics steps within the period: the switch at t_k takes the trapezoid's half step (module
        # docstring), the sample is recorded under the command
        half = 0.5 * (self.tau[k - 1] + tau) if self.driver is None and k and self.substeps > 1 else None
        for j in range(self.substeps):
            if self.driver is not None:
                if j:
                    q_enc, qd_drv = self.read_joints(s0 + j)
                tau = d.kp * (q_des[j] - q_enc) - d.kd * qd_drv  # pd_torque's order
                tau = np.clip(tau + d.kd * qd_des[j] + ff[j], -d.torque_limit, d.torque_limit)
            data.ctrl[:] = tau
            tau_f = self.injected.torque(data.qvel[self.dof_f])
            data.qfrc_applied[self.dof_f] = tau_f
            if j == 0:
                qpos, qvel = data.qpos.copy(), data.qvel.copy()
                if half is not None:
                    mujoco.mj_forward(model, data)
                    self.record(k, qpos, qvel, q_enc, qd_drv, tau, tau_f)
                    data.ctrl[:] = half
            mujoco.mj_step(model, data)
            if j == 0 and half is None:
                self.record(k, qpos, qvel, q_enc, qd_drv, tau, tau_f)

    def record(self, k: int, qpos: np.ndarray, qvel: np.ndarray, q_enc: np.ndarray, qd_drv: np.ndarray,
               tau: np.ndarray, tau_f: np.ndarray) -> None:
        """Log sample ``k``'s first physics step: state, acceleration, readings, torques, the feet's forces (each
        foot's contacts summed, ``mj_contactForce`` turned into world axes: the ground's force on the foot) and
        where they act, the IMU."""
        import mujoco
        mjr, data, robot = self.mjr, self.data, self.robot
        self.Q[k], self.V[k] = mjr.q(qpos), mjr.v(qpos, qvel)
        self.A[k, robot.act_v_index] = data.qacc[mjr.dof_index]
        self.A[k, :6] = mjr.base_acceleration(qpos, qvel, data.qacc[:6])
        self.q_enc[k], self.qd_drv[k], self.tau[k] = q_enc, qd_drv, tau
        self.tau_f[k, self.cols_f] = tau_f
        self.imu[k] = data.sensordata[mjr.imu_index]
        f6 = np.empty(6)
        for i in range(data.ncon):
            con = data.contact[i]
            g1, g2 = int(con.geom[0]), int(con.geom[1])
            if g2 in self.foot_geoms:  # the normal points from geom1 to geom2: the force is geom1's on geom2
                foot, sign = self.foot_geoms[g2], 1.0
            elif g1 in self.foot_geoms:
                foot, sign = self.foot_geoms[g1], -1.0
            else:
                continue
            mujoco.mj_contactForce(self.model, data, i, f6)
            self.force[k, foot] += sign * (con.frame.reshape(3, 3).T @ f6[:3])
            self.point[k, foot] = con.pos

    def run(self, progress: Progress | None) -> float:
        """Every sample; returns the wall-clock time [s].

        Raises:
            SimulationError: the base below :data:`FALL_HEIGHT` of its initial height (a fall), or not finite.
        """
        start = _time.perf_counter()
        lo = self.robot.model.effortLimit[self.robot.act_v_index]
        self.limit = np.where((lo > 0) & (lo < 1e300), lo, np.inf)
        self.commands[0][:] = self.ref.q + self.offset  # the PD's target, in the encoder's coordinates
        self.commands[1][:] = self.ref.qd
        for k in counted(len(self.ref), progress):
            self.period(k)
            z = float(self.data.qpos[2])
            if not (np.isfinite(z) and z > FALL_HEIGHT * self.z0):
                raise SimulationError(f"the quadruped fell (or the simulation diverged) at t = {self.dt * k:.3f} s")
        return _time.perf_counter() - start

    def result(self, seconds: float) -> MujocoQuadrupedRun:
        """The log (module docstring) and the run around it."""
        robot, ref, opt, e = self.robot, self.ref, self.options, self.errors
        iv = robot.act_v_index
        Q, V, A = self.Q, self.V, self.A
        sensed = self.force if e["force"] is None else self.force + e["force"]
        on, off = default_thresholds(robot)
        contact = hysteresis(sensed[..., 2], on, off)
        foot_force = None
        if opt.foot_forces != "none":
            foot_force = sensed.copy()
            if opt.foot_forces == "normal":
                foot_force[..., :2] = np.nan
        imu = None
        if opt.imu and robot.imu is not None:
            imu = self.imu if e["imu"] is None else self.imu + e["imu"]
        meta = {"generator": GENERATOR, "robot": robot.name, "options": opt.metadata(), "gait": asdict(ref.options),
                "drive": opt.drive, "simulator": "mujoco",
                "friction_true": {j: p.to_target() for j, p in self.injected.params.items()},
                "armature_true": dict(zip(robot.actuated, self.model.dof_armature[self.mjr.dof_index].tolist())),
                "physics_step": self.h, "noise": asdict(self.noise),
                "feet": {"radius": float(self.model.geom_size[self.mjr.sole_geoms[0], 0]),
                         "friction": float(self.model.geom_friction[self.mjr.sole_geoms[0], 0]),
                         "contact_force": "summed mj_contactForce, world axes, the ground's on the foot",
                         **({} if opt.contacts == "soft" else  # soft: the bytes written before the option
                            {"cone": "elliptic", "impratio": float(self.model.opt.impratio),
                             "timeconst": float(self.model.geom_solref[self.mjr.sole_geoms[0], 0])})},
                "contact_source": f"foot normal force: on above {on:.4g} N, off below {off:.4g} N"}
        common: dict[str, Any] = dict(
            base=Q[:, :7].copy(), tau_f_true=self.tau_f.copy(), source=GENERATOR.rsplit(".", 1)[-1],
            qd_true=V[:, iv].copy(), qdd_true=A[:, iv].copy(), base_qd_true=V[:, :6].copy(),
            base_qdd_true=A[:, :6].copy(), imu=imu, foot_force=foot_force, qd_logged=self.qd_drv.copy())
        q_model = self.q_enc - self.offset  # Log.q holds the model's angles (its table adds the offset back)
        if self.driver is None:
            meta["torque_alignment"] = "sample" if self.substeps == 1 else "zoh"
            tau = self.tau if e["torque"] is None else self.tau + e["torque"]
            log = Log(ref.time.copy(), q_model, tau, contact, metadata=meta, **common)
        else:
            d = self.driver
            meta["torque_alignment"] = "sample"
            meta["encoder_offset_true"] = dict(zip(robot.actuated, self.offset.tolist()))
            meta["pd_true"] = {"kp": d.kp.tolist(), "kd": d.kd.tolist(), "delay": d.delay,
                               "setpoints": opt.setpoints}
            setpoints = PdSetpoints(self.commands[0].copy(), self.qd_drv.copy(), self.commands[1].copy(),
                                    self.commands[2].copy())
            tau = setpoints.torque(d, ref.time, self.q_enc)
            log = Log(ref.time.copy(), q_model, tau, contact, metadata=meta, torque_source="pd", setpoints=setpoints,
                      **common)
        return MujocoQuadrupedRun(log, ref, self.force.copy(), Q.copy(), V.copy(), A.copy(), self.tau.copy(),
                                  self.tau_f.copy(), np.zeros(0), self.point.copy(), self.imu.copy(), seconds)


def simulate_quadruped_mujoco(robot: Robot, reference: QuadrupedReference,
                              options: QuadrupedOptions = QuadrupedOptions(), noise: QuadrupedNoise | None = None,
                              mjr: MujocoRobot | None = None, progress: Progress | None = None) -> MujocoQuadrupedRun:
    """Simulate a quadruped following ``reference`` on MuJoCo (module docstring).

    Args:
        robot: a floating-base robot on point feet (``contact_model = "point"``), every joint actuated, with a
            ``[pd]`` for ``drive = "pd"``; e.g. the built-in ``go2_walking``.
        reference: :func:`~wbfriction.walking.quadruped.quadruped_reference` of the robot.
        options: :class:`~wbfriction.sim.quadruped.QuadrupedOptions` (``baumgarte`` unused: the contacts are
            MuJoCo's); its ``noise`` (angles, encoder, torques) is taken when ``noise`` is None.
        noise: :class:`QuadrupedNoise`, every sensor's (e.g. :data:`UNITREE_NOISE`); None: the options'.
        mjr: the model (:func:`~wbfriction.sim.quadruped_mjcf.build_quadruped_model`, not changed); None: built.
        progress: optional callable receiving numbers of samples done.

    Returns:
        :class:`MujocoQuadrupedRun`, one log row per reference sample.

    Raises:
        InputError: a robot that is not such a quadruped, friction or armature for a joint it does not have, PD
            drivers that delay their whole torque.
        OptionError: a physics step that does not divide the reference's period.
        SimulationError: the robot fell or the simulation diverged (the message gives the time).
    """
    if not robot.floating_base or not robot.contact_frames:
        raise InputError(f"robot '{robot.name}': the quadruped simulator needs a floating base and point feet "
                         "(contact_model = \"point\")")
    require_point_feet(robot, "the quadruped simulator on MuJoCo")
    if robot.torque_controlled != robot.actuated:
        raise InputError(f"robot '{robot.name}': the quadruped simulator drives every joint: none may be "
                         "position-controlled")
    sim = _Sim(robot, reference, options, QuadrupedNoise.from_sensor_noise(options.noise) if noise is None else noise,
               mjr)
    seconds = sim.run(progress)
    return sim.result(seconds)

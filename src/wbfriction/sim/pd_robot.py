"""A fixed-base robot whose joints are driven by PD motor drivers, on MuJoCo: its model (:func:`build_pd_robot`) and
its run under commanded set-points (:class:`PdRun`), what the hung robot's simulator (:mod:`wbfriction.sim.hung`)
and the rollout check (:mod:`wbfriction.replay.rollout`) both use: one way to build and run such a robot.

**Model.** The robot's URDF as MuJoCo reads it (:func:`wbfriction.model.mjspec.urdf_spec`: kinematic tree and
inertias; visual and collision geometry, the URDF's ``<dynamics>`` dropped) with its root link welded to the world
(no free joint), gravity, no contact and no joint limit (the set-points stay inside the ranges: nothing but the
drivers and friction acts on the joints), one motor per joint (its ``ctrl`` the joint torque [N·m], unclipped: the
driver clips), the armature per joint (``dof_armature``: ``(M(q) + diag(I_a)) qdd + h = tau + tau_f``), MuJoCo's
semi-implicit Euler. Every joint of the robot must be PD-driven (``[pd]`` in its TOML).

**The drivers** (:mod:`wbfriction.model.pd`, Isaac Lab's ``DelayedPDActuator``). Set-points ``q_des``, ``qd_des``,
``tau_ff`` are commanded at the samples ``t_i``, each held (zero-order hold) and applied from ``t_i + d``. At every
physics step ``[t_s, t_s + h)`` the driver reads its encoder (the logged angle ``q + b``, ``b`` the encoder
offset, plus the encoder's noise and rounding) and its velocity (``qd`` plus its noise), and applies

.. math::

    \\tau_s = \\mathrm{clip}\\big(k_p (\\bar q^{des}_s - q^{enc}_s) + k_d (\\bar{\\dot q}^{des}_s - \\dot q^{drv}_s)
              + \\bar\\tau^{ff}_s,\\; \\pm\\tau_{max}\\big)

over the step, the bars the mean over the step of the held set-point delayed by ``d`` (:func:`step_setpoints`):
the held value itself when ``d`` is a whole number of physics steps, else the two values it switches between,
weighted by the parts of the step each holds (a delay simulated to any value, not rounded to the step). Before the
first sample, the first set-point.

**Friction** on every joint, the project's two ways (:mod:`wbfriction.sim.mujoco_sim`): ``"model"``, any family's
``tau_f = -f(qd)`` (:class:`~wbfriction.sim.common.InjectedFriction`) of the step's velocity applied as a
generalised force (``qfrc_applied``); ``"mujoco"``, MuJoCo's ``frictionloss`` and ``damping``
(:func:`~wbfriction.sim.mujoco_sim.set_mujoco_friction`; read back by
:func:`~wbfriction.sim.mujoco_sim.mujoco_friction_torque`).

**Recorded** at each sample (the physics step that starts at ``t_i``): the state (angles, velocities), the
encoder's and the driver's readings, the torque and the friction applied over that step, and its acceleration.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from wbfriction.exceptions import InputError, ModelError, SimulationError
from wbfriction.friction.models import ModelParams
from wbfriction.model.mjspec import urdf_spec
from wbfriction.model.pd import PdDriver
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, injected_friction
from wbfriction.sim.mujoco_model import route_mujoco_warnings
from wbfriction.sim.mujoco_sim import mujoco_friction_torque, set_mujoco_friction
from wbfriction.sim.options import FrictionMode
from wbfriction.walking.indexing import as_slice

if TYPE_CHECKING:
    from collections.abc import Mapping

    import mujoco


@dataclass(frozen=True, eq=False)
class PdMujocoRobot:
    """A PD-driven fixed-base robot's MuJoCo model (module docstring), not changed by the runs on it.

    Attributes:
        robot: the robot (its :attr:`~wbfriction.model.robot.Robot.pd` drives every joint).
        model: the compiled ``mujoco.MjModel`` (armature zero, no friction: each run sets its own on a copy).
        qpos_index, dof_index: MuJoCo ``qpos`` and ``qvel`` addresses of each joint, in
            :attr:`Robot.actuated <wbfriction.model.robot.Robot.actuated>` order; actuator ``i`` drives joint ``i``.
    """

    robot: Robot
    model: mujoco.MjModel
    qpos_index: np.ndarray
    dof_index: np.ndarray

    @property
    def driver(self) -> PdDriver:
        """The robot's drivers (its TOML's ``[pd]``)."""
        assert self.robot.pd is not None  # checked by build_pd_robot
        return self.robot.pd


def build_pd_robot(robot: Robot, timestep: float = 1e-3) -> PdMujocoRobot:
    """The MuJoCo model of a fixed-base robot whose joints are all PD-driven (module docstring).

    Args:
        robot: a robot with ``floating_base = false`` and a ``[pd]`` driving every actuated joint, loaded from a URDF.
        timestep: the physics step [s] (a run sets its own).

    Raises:
        InputError: a floating base, no ``[pd]`` or one that leaves a joint undriven, locked joints, an MJCF.
        ModelError: a URDF MuJoCo cannot read, a joint it does not have.
    """
    import mujoco
    if robot.floating_base:
        raise InputError(f"robot '{robot.name}' has a floating base: a hung PD-driven robot needs "
                         "floating_base = false")
    if robot.pd is None or robot.pd.joints != robot.actuated:
        undriven = [j for j in robot.actuated if robot.pd is None or j not in robot.pd.joints]
        raise InputError(f"robot '{robot.name}': joint '{undriven[0]}' is not PD-driven: the PD-driven robot's "
                         "simulator needs a [pd] table driving every joint (wbfriction.model.pd)")
    if robot.locked_joints:
        raise InputError(f"robot '{robot.name}' has locked joints: the PD-driven robot's simulator takes every "
                         "joint of its URDF")
    route_mujoco_warnings()
    spec = urdf_spec(robot.require_urdf("the PD-driven robot's MuJoCo model"), free_joint=False)
    spec.option.timestep = timestep
    spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    for joint in spec.joints:
        joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    for name in robot.actuated:
        motor = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.set_to_motor()
    try:
        mj = spec.compile()
    except Exception as exc:
        raise ModelError(f"{robot.urdf}: MuJoCo cannot compile the model: {' '.join(str(exc).split())}") from None
    ids = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, name) for name in robot.actuated]
    if min(ids) < 0 or mj.njnt != len(ids):
        raise ModelError(f"{robot.urdf}: MuJoCo's joints are not the robot's {robot.actuated}")
    return PdMujocoRobot(robot, mj, np.array(mj.jnt_qposadr[ids]), np.array(mj.jnt_dofadr[ids]))


def step_setpoints(values: np.ndarray, substeps: int, delay_steps: float, first: int, last: int) -> np.ndarray:
    """The set-point each physics step ``s`` in ``[first, last)`` applies (module docstring): the mean over the step
    of the commanded samples (``values`` (N, n), sample ``i`` commanded at step ``i * substeps``) held and delayed
    by ``delay_steps`` physics steps; before the first sample, its value.

    A delay within 1e-6 of a whole number of steps is taken as that number: the held values themselves, exactly.

    Returns:
        (last - first, n).
    """
    nearest = round(delay_steps)
    delay = float(nearest) if abs(delay_steps - nearest) < 1e-6 else float(delay_steps)
    u = np.arange(first, last, dtype=float) - delay  # each step's start, in steps of the commands' time
    j0 = np.floor(u / substeps)
    w = np.clip(u + 1.0 - (j0 + 1.0) * substeps, 0.0, 1.0)  # the part of the step after the next switch
    n = len(values)
    a = values[np.clip(j0, 0, n - 1).astype(int)]
    b = values[np.clip(j0 + 1, 0, n - 1).astype(int)]
    return np.where(w[:, None] > 0, a + w[:, None] * (b - a), a)


@dataclass
class StepNoise:
    """The errors of a run's sensors at every physics step.

    Attributes:
        position: white noise on the encoder's reading (n_steps, n) [rad], or None.
        velocity: white noise on the driver's velocity (n_steps, n) [rad/s], or None.
        resolution: the encoder's step per joint (n,) [rad], or None (exact).
    """

    position: np.ndarray | None = None
    velocity: np.ndarray | None = None
    resolution: np.ndarray | None = None


@dataclass
class PdTrajectory:
    """What a run recorded at its samples (each (N, n), joints in :attr:`Robot.actuated` order; the physics step that
    starts at each sample).

    Attributes:
        q, qd: the true angles (the model's) [rad] and velocities [rad/s].
        qdd: the step's accelerations [rad/s^2].
        q_encoder: what the encoders read (the logged angle: ``q`` + offset, noise, rounding) [rad].
        qd_driver: the drivers' velocities [rad/s].
        tau: the drivers' torques applied over the step [N·m] (clipped).
        tau_f: the friction applied over the step [N·m] (``tau_f = -f(qd)``).
        q_des, qd_des: the set-points the step applied (delayed, held) [rad, rad/s].
    """

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    q_encoder: np.ndarray
    qd_driver: np.ndarray
    tau: np.ndarray
    tau_f: np.ndarray
    q_des: np.ndarray
    qd_des: np.ndarray


@dataclass(frozen=True, eq=False)
class Commands:
    """The set-points commanded at the samples, each (N, n) [rad, rad/s, N·m]; ``kp``, ``kd`` (N, n): gains logged
    per sample (not delayed: settings), or None (the driver's)."""

    q_des: np.ndarray
    qd_des: np.ndarray
    tau_ff: np.ndarray
    kp: np.ndarray | None = None
    kd: np.ndarray | None = None


def joint_values(robot: Robot, given: Mapping[str, float] | None, own: Mapping[str, float], what: str) -> np.ndarray:
    """Per joint (n_act,) in :attr:`Robot.actuated` order: the values ``given`` (joints not named: 0), else the
    robot's own ``own`` (armature, encoder offsets).

    Raises:
        InputError: a value for a joint the robot does not have, naming it and ``what``.
    """
    values = own if given is None else given
    unknown = sorted(set(values) - set(robot.actuated))
    if unknown:
        raise InputError(f"{what} given for '{unknown[0]}', which is not a joint of {robot.name}")
    return np.array([float(values.get(j, 0.0)) for j in robot.actuated])


class PdRun:
    """Runs of a PD-driven robot (module docstring) with given drives: armature, encoder offsets, drivers, friction.

    Args:
        mjr: the robot's MuJoCo model (:func:`build_pd_robot`; copied, not changed).
        period: the samples' period [s]; substeps: physics steps per period.
        driver: the drivers (gains, delay, limits) of every joint.
        armature: per joint (n,) [kg·m^2]; offset: the encoders' offsets (n,) [rad].
        friction: the parameters per joint, of any friction family the registry knows (joints not named: none).
        friction_mode: :data:`~wbfriction.sim.options.FRICTION_MODES`; friction_timeconst: for ``"mujoco"`` [s].
        torque_delay: delay the PD's torque instead of the set-points (PACE's actuator, a peer's model: the law runs
            on the set-points as commanded and its torque, feedback and set-point alike, is applied the driver's
            delay later, rounded to whole physics steps; before the first, the first torque); None: as the drivers'
            ``delayed`` says (:mod:`wbfriction.model.pd`).

    Raises:
        InputError: friction for an unknown joint; Stribeck or offset parameters with MuJoCo's friction.
        UnknownFamilyError: parameters of a family the registry does not know.
    """

    def __init__(self, mjr: PdMujocoRobot, period: float, substeps: int, driver: PdDriver, armature: np.ndarray,
                 offset: np.ndarray, friction: Mapping[str, ModelParams], friction_mode: FrictionMode = "model",
                 friction_timeconst: float | None = None, torque_delay: bool | None = None) -> None:
        import mujoco
        self.mjr, self.driver, self.substeps = mjr, driver, substeps
        torque_delay = driver.delayed == "torque" if torque_delay is None else torque_delay
        self.torque_delay = int(round(driver.delay * substeps / period)) if torque_delay else None
        self.period, self.h = period, period / substeps
        self.offset = np.asarray(offset, dtype=float)
        self.model = copy.copy(mjr.model)
        self.model.opt.timestep = self.h
        self.model.dof_armature[mjr.dof_index] = armature
        # the constants MuJoCo derives from the mass matrix at qpos0 (dof_invweight0: the friction-loss constraint's
        # softness, R = (1 - solimp[0]) / solimp[0] * dof_invweight0) with this armature, as a model compiled with
        # it has them (an exported MJCF): without, MuJoCo's friction would be that of the armature compiled before
        mujoco.mj_setConst(self.model, mujoco.MjData(self.model))
        self.injected: InjectedFriction = injected_friction(mjr.robot, friction, joints=mjr.robot.actuated)
        self.native = friction_mode == "mujoco"
        dof_f = mjr.dof_index[self.injected.joints]
        self.dof_f = as_slice(dof_f)
        if self.native and self.injected.joints:
            set_mujoco_friction(self.model, dof_f, self.injected, friction_timeconst)
        self.qpos, self.dof = as_slice(mjr.qpos_index), as_slice(mjr.dof_index)
        self.columns_f = as_slice(self.injected.joints)
        self._step = mujoco.mj_step

    def run(self, commands: Commands, start: int, stop: int, q0: np.ndarray, qd0: np.ndarray,
            noise: StepNoise | None = None, progress: Progress | None = None) -> PdTrajectory:
        """Run samples ``[start, stop)`` of ``commands`` from the true state ``q0`` [rad], ``qd0`` [rad/s] (n,) at
        sample ``start`` (the commands before it are the delayed set-points' history).

        Args:
            noise: the sensors' errors at each of the ``(stop - start) * substeps`` physics steps; None: exact.
            progress: optional callable receiving numbers of samples done.

        Raises:
            SimulationError: the state diverged (not finite).
        """
        import mujoco
        first, last = start * self.substeps, stop * self.substeps
        delay_steps = self.driver.delay / self.h if self.torque_delay is None else 0.0
        setpoint = [step_setpoints(x, self.substeps, delay_steps, first, last)
                    for x in (commands.q_des, commands.qd_des, commands.tau_ff)]
        data = mujoco.MjData(self.model)
        data.qpos[self.qpos], data.qvel[self.dof] = q0, qd0
        n, m = stop - start, len(q0)
        out = PdTrajectory(*(np.empty((n, m)) for _ in range(9)))
        loop = _Loop(self, data, commands, setpoint, noise or StepNoise(), first)
        for k in counted(n, progress):
            loop.period(k, out)
        return out


class _Loop:
    """The physics steps of one :meth:`PdRun.run`: what every step uses, fetched once."""

    def __init__(self, run: PdRun, data: mujoco.MjData, commands: Commands, setpoint: list[np.ndarray],
                 noise: StepNoise, first: int) -> None:
        self.run, self.data, self.noise, self.first = run, data, noise, first
        self.q_des, self.qd_des, self.tau_ff = setpoint
        d = run.driver
        self.kp, self.kd = commands.kp, commands.kd
        self.gains = (d.kp, d.kd)
        self.limit = d.torque_limit
        self.offset = run.offset
        lag = run.torque_delay
        self.delayed = None if lag is None else np.empty((lag + 1, len(self.limit)))  # the torques computed, a ring

    def period(self, k: int, out: PdTrajectory) -> None:
        """The ``substeps`` physics steps of sample ``k`` (the run's ``k``-th); the first one recorded in ``out``."""
        run, data, noise = self.run, self.data, self.noise
        step, model = run._step, run.model
        sample = self.first // run.substeps + k
        kp = self.gains[0] if self.kp is None else self.kp[sample]
        kd = self.gains[1] if self.kd is None else self.kd[sample]
        for j in range(run.substeps):
            s = k * run.substeps + j
            q, v = data.qpos[run.qpos].copy(), data.qvel[run.dof].copy()
            q_enc = q + self.offset
            if noise.position is not None:
                q_enc += noise.position[s]
            if noise.resolution is not None:
                q_enc = np.round(q_enc / noise.resolution) * noise.resolution
            v_drv = v if noise.velocity is None else v + noise.velocity[s]
            tau = np.clip(kp * (self.q_des[s] - q_enc) + kd * (self.qd_des[s] - v_drv) + self.tau_ff[s],
                          -self.limit, self.limit)
            if self.delayed is not None:
                ring = len(self.delayed)
                self.delayed[s % ring] = tau
                tau = self.delayed[(s - ring + 1) % ring if s >= ring - 1 else 0].copy()
            data.ctrl[:] = tau
            tau_f = np.zeros_like(v)
            if run.injected.joints and not run.native:
                tau_f[run.columns_f] = applied = run.injected.torque(v[run.columns_f])
                data.qfrc_applied[run.dof_f] = applied
            step(model, data)
            if run.native and run.injected.joints:
                tau_f[run.columns_f] = mujoco_friction_torque(data, run.dof_f)
            if j == 0:
                out.q[k], out.qd[k], out.qdd[k] = q, v, data.qacc[run.dof]
                out.q_encoder[k], out.qd_driver[k], out.tau[k], out.tau_f[k] = q_enc, v_drv, tau, tau_f
                out.q_des[k], out.qd_des[k] = self.q_des[s], self.qd_des[s]
        if not np.isfinite(data.qvel).all():
            raise SimulationError(f"the PD-driven robot's simulation diverged at sample {sample}")

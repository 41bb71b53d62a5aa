"""The realistic simulator (thesis 6.2) on MuJoCo: real foot contacts, sensors, delays.

The same walking reference and controller as the ideal simulator
(:mod:`wbfriction.sim.ideal`): feed-forward torques from the constrained inverse dynamics
of the reference plus joint PD, computed at the log rate from the measured joint
positions (velocities: their backward difference) and held over the period; the physics
runs ``substeps`` MuJoCo steps per period on the model of
:mod:`wbfriction.sim.mujoco_model` (soft contacts, sliding and torsional friction under
box soles; one motor per joint). Differences forced by real contacts:

* the PD gains follow the *measured* contact state (a sole is in contact when its normal
  force exceeds ``contact_threshold``), not the planned one: the stance gains, designed
  for a foot on the ground, make a foot still in the air unstable;
* the gains are those of :func:`~wbfriction.sim.control.pd_gains` clipped at
  ``max_gains`` (soft contacts do not give a stance leg the welded foot's stiffness) and
  at the digital stability limit of a PD held over a period ``dt`` on the joint's *free*
  inertia ``I`` (the mass matrix diagonal: the subtree the joint moves, the foot for an
  ankle): ``kd <= I / dt``, ``kp <= I / dt^2``. A stance ankle's gains, designed for the
  whole body, blew up a foot rocking on its edge at a turning step's touch-down (measured);
* the position-controlled joints follow their reference through a stiff PD (gains from
  their inertia at the reference bandwidth), not as a constraint;
* optionally (``balance``, per robot), the stance ankles right the base from the IMU
  (:func:`~wbfriction.sim.control.attitude_ankle_torques`): the damping the ankle PD
  cannot have on a light foot. The TORO-like robot, whose feet and ankle roll inertia are
  small, falls without it (measured: a forward walk at 9.2 s, a sideways one at 6.9 s).
  The ankles are each leg's last two joints.

Friction, two independent implementations (:data:`FRICTION_MODES`):

* ``"model"``: eq. (3.5) of the given parameters, applied as a generalised force at every
  physics step from that step's velocity;
* ``"mujoco"``: MuJoCo's own joint friction, ``frictionloss = F_c`` (Coulomb friction
  solved as a constraint) and ``damping = F_v`` (explicit: ``eulerdamp`` disabled, so the
  damper force is exactly the one applied); the parameters must have ``S = 0`` and
  ``tau_os = 0``. ``tau_f_true`` is the friction-loss constraint force plus the damper force.

Sensors (:class:`~wbfriction.sim.sensors.SensorNoise`, off by default): the controller
and the log see the same noisy, quantised positions, the log noisy torques (the
controller acts on its sensors: position noise becomes vibration). A ``delay`` holds every
command that long (whole control periods) before the motors apply it.

The log holds the measured contact flags (normal force over the threshold, from the
soles' touch sensors at the last physics step of each period: they differ from the plan
by up to 100 ms around a switch, thesis 6.2), the measured positions, the torques the
motors applied at the period's first physics step (plus sensor noise) and, as truth, the
friction applied at that step (``tau_f_true``) and the joint velocities and
accelerations of that step.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from typing import Literal, get_args

import mujoco
import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation

from wbfriction.exceptions import InputError, SimulationError
from wbfriction.friction.models import FrictionParams
from wbfriction.friction.targets import friction_by_group
from wbfriction.model.robot import Robot
from wbfriction.progress import counted
from wbfriction.sim.common import InjectedFriction, SimulationResult, injected_friction, simulated_log
from wbfriction.sim.control import attitude_ankle_torques, pd_from_inertia, pd_gains, ramp_gains, reference_feedforward
from wbfriction.sim.mujoco_model import MujocoRobot, build_mujoco_robot
from wbfriction.sim.sensors import SensorNoise
from wbfriction.walking import WalkingReference

FrictionMode = Literal["model", "mujoco"]
"""How the MuJoCo simulator applies friction (module docstring)."""
FRICTION_MODES: tuple[FrictionMode, ...] = get_args(FrictionMode)


@dataclass(frozen=True)
class MujocoOptions:
    """Parameters of :func:`simulate_mujoco`.

    Attributes:
        substeps: physics steps per control period (the physics step is ``dt / substeps``).
        bandwidth: PD bandwidth [Hz]; damping: its damping ratio.
        max_gains: (kp [N·m/rad], kd [N·m·s/rad]) caps of every joint's gains.
        gain_blend: time over which rising gains ramp to a new contact state's [s].
        contact_threshold: normal force above which a sole counts as in contact [N].
        friction: ``"model"`` (eq. 3.5 as a joint torque) or ``"mujoco"`` (MuJoCo's
            ``frictionloss`` and ``damping``), module docstring.
        sensors: sensor noise of the controller's and the log's measurements.
        delay: time from a measurement to the command computed from it acting [s], a
            whole number of control periods.
        balance: (K [N·m/rad], D [N·m·s/rad]) of the base-attitude stabiliser on the
            stance ankles (:func:`~wbfriction.sim.control.attitude_ankle_torques`); None:
            the robot's :attr:`~wbfriction.model.robot.Robot.balance_gains`.
        fall_height: the simulation stops with an error when the base drops below this
            share of its initial height.
        log_base: write the base pose to the log.
    """

    substeps: int = 4
    bandwidth: float = 10.0
    damping: float = 0.9
    max_gains: tuple[float, float] = (3000.0, 60.0)
    gain_blend: float = 0.1
    contact_threshold: float = 50.0
    friction: FrictionMode = "model"
    sensors: SensorNoise = SensorNoise()
    delay: float = 0.0
    balance: tuple[float, float] | None = None
    fall_height: float = 0.5
    log_base: bool = True

    def __post_init__(self) -> None:
        if self.substeps < 1:
            raise InputError(f"substeps must be at least 1, got {self.substeps}")
        if self.contact_threshold <= 0:
            raise InputError("the contact threshold must be a positive force [N]")
        if self.friction not in FRICTION_MODES:
            raise InputError(f"friction must be one of {', '.join(FRICTION_MODES)}, got '{self.friction}'")
        if self.delay < 0:
            raise InputError(f"the delay must be >= 0 s, got {self.delay}")

    def delay_periods(self, dt: float) -> int:
        """:attr:`delay` in control periods of ``dt`` seconds.

        Raises:
            InputError: the delay is not a whole number of periods.
        """
        d = self.delay / dt
        if abs(d - round(d)) > 1e-6:
            raise InputError(f"the delay ({self.delay * 1e3:g} ms) must be a multiple of the control period "
                             f"({dt * 1e3:g} ms)")
        return int(round(d))


def set_mujoco_friction(model: mujoco.MjModel, dofs: np.ndarray, injected: InjectedFriction) -> None:
    """Set MuJoCo's ``frictionloss`` and ``damping`` of ``dofs`` from (3.5) parameters."""
    for dof, (joint, p) in zip(dofs, injected.params.items()):
        if p.S != 0 or p.tau_os != 0:
            raise InputError(f"friction of '{joint}': MuJoCo's joint friction has no Stribeck term (S) and "
                             "no offset (tau_os); give S = 0 and tau_os = 0, or use the 'model' friction")
        model.dof_frictionloss[dof], model.dof_damping[dof] = p.F_c, p.F_v
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)


def mujoco_friction_torque(data: mujoco.MjData, dofs: np.ndarray) -> np.ndarray:
    """Joint friction MuJoCo applied on ``dofs`` at the last step [N·m]: the friction-loss
    constraint forces (rows ``mjCNSTR_FRICTION_DOF``, whose Jacobian is the dof's unit
    vector) plus the damper forces."""
    rows = np.flatnonzero(data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF)
    force = data.qfrc_damper.copy()
    force[data.efc_id[rows]] += data.efc_force[rows]
    return force[dofs]


def simulate_mujoco(robot: Robot, reference: WalkingReference, friction: dict[str, FrictionParams] | None = None,
                    options: MujocoOptions = MujocoOptions(), mjr: MujocoRobot | None = None,
                    progress=None) -> SimulationResult:
    """Simulate a walk on MuJoCo (module docstring).

    Args:
        robot: the robot the reference was planned for.
        reference: :func:`~wbfriction.walking.walking_reference` output.
        friction: parameters per torque-controlled joint; default: Table 6.1 on the legs
            (for ``options.friction == "mujoco"``: its F_c and F_v only).
        options: :class:`MujocoOptions`.
        mjr: a prebuilt MuJoCo model (not modified; default: built from ``robot``).
        progress: optional callable receiving numbers of samples done.

    Returns:
        A :class:`~wbfriction.sim.common.SimulationResult`; its ``wrench`` holds the soles'
        normal forces in ``[..., 2]`` (the rest zero).

    Raises:
        InputError: friction on a joint that is not torque-controlled; Stribeck or offset
            parameters with MuJoCo's friction; a delay that is not whole periods.
        SimulationError: the robot fell (the message gives the time).
    """
    native = options.friction == "mujoco"
    if friction is None and native:
        friction = {j: dataclasses.replace(p, S=0.0, tau_os=0.0) for j, p in friction_by_group(robot.groups).items()}
    injected = injected_friction(robot, friction)
    ref, n, dt = reference, len(reference), reference.dt
    delay = options.delay_periods(dt)
    mjr = mjr or build_mujoco_robot(robot)
    model = copy.copy(mjr.model)  # the settings below must not leak into a shared model
    model.opt.timestep = dt / options.substeps
    iq, iv, tc, pc = robot.act_q_index, robot.act_v_index, robot.tc_index, robot.pc_index
    nc, n_act = len(robot.contact_frames), len(robot.actuated)
    joints_f = injected.joints
    dof_f = mjr.dof_index[tc][joints_f]
    if native:
        set_mujoco_friction(model, dof_f, injected)
    data = mujoco.MjData(model)

    # base-attitude stabiliser: each leg's last two joints (the ankle), the reference base attitude
    balance = robot.balance_gains if options.balance is None else options.balance
    stabilise = any(balance)
    if stabilise:
        ankles = [np.array([robot.actuated.index(j) for j in robot.limb(f)[-2:]]) for f in robot.contact_frames]
        ankle_jnt = [mjr.joint_ids[a] for a in ankles]
        R_ref = Rotation.from_quat(ref.q[:, 3:7]).as_matrix()
        w_ref = np.einsum("nij,nj->ni", R_ref, ref.v[:, 3:6])  # world frame

    # the controller: feed-forward, PD gains per contact state
    tau_ff = reference_feedforward(robot, ref)
    free = np.diag(pin.crba(robot.model, robot.model.createData(), ref.q[0]))[iv]  # inertia, upstream held
    kp_max = np.minimum(options.max_gains[0], free[tc] / dt**2)
    kd_max = np.minimum(options.max_gains[1], free[tc] / dt)
    gains = {state: (np.minimum(kp, kp_max), np.minimum(kd, kd_max))
             for state, (kp, kd) in pd_gains(robot, ref.q[0], options.bandwidth, options.damping).items()}
    kp_act, kd_act = np.zeros(n_act), np.zeros(n_act)
    kp_act[pc], kd_act[pc] = pd_from_inertia(free[pc], options.bandwidth, options.damping)
    q_ref, v_ref = ref.q[:, iq], ref.v[:, iv]
    eps_q, eps_tau = options.sensors.draw(n, n_act, tc.size)

    data.qpos[:] = mjr.qpos(ref.q[0])
    data.qvel[:] = mjr.velocity_map(ref.q[0]) @ ref.v[0]
    mujoco.mj_forward(model, data)
    z0 = data.qpos[2]

    qpos, qvel = np.empty((n, model.nq)), np.empty((n, model.nv))
    q_meas, qdd = np.empty((n, n_act)), np.empty((n, n_act))
    tau_log, tau_f_log = np.empty((n, tc.size)), np.zeros((n, tc.size))
    contact, force = np.zeros((n, nc), dtype=bool), np.zeros((n, nc))
    commands = np.zeros((delay + 1, n_act))  # ring buffer: the command of period k acts at k + delay
    state, k_switch, before = None, 0, None
    kp_act[tc], kd_act[tc] = gains[tuple(bool(x) for x in ref.contact[0])]
    tau_f = np.zeros(len(joints_f))
    torque_friction = bool(joints_f) and not native  # (3.5) applied by us at every physics step
    bad_qacc = int(mujoco.mjtWarning.mjWARN_BADQACC)
    for k in counted(n, progress):
        qpos[k], qvel[k] = data.qpos, data.qvel
        q_meas[k] = options.sensors.encoder(data.qpos[mjr.qpos_index] + eps_q[k])
        qd_meas = (q_meas[k] - q_meas[k - 1]) / dt if k > 0 else v_ref[0]
        # the controller knows the contact measured over the last period (the plan at first)
        last = contact[k - 1] if k > 0 and contact[k - 1].any() else ref.contact[k]
        measured = tuple(bool(x) for x in last)
        if measured != state:
            state, k_switch, before = measured, k, (kp_act[tc].copy(), kd_act[tc].copy())
        if (k - k_switch) * dt <= options.gain_blend + dt:
            kp_act[tc], kd_act[tc] = ramp_gains(before, gains[state], (k - k_switch) * dt, options.gain_blend)
        command = tau_ff[k] + kp_act * (q_ref[k] - q_meas[k]) + kd_act * (v_ref[k] - qd_meas)
        if stabilise:
            R = data.xmat[mjr.base_body].reshape(3, 3)
            load = (force[k - 1] if k > 0 else np.ones(nc)) * last
            for a, t in zip(ankles, attitude_ankle_torques(R, R @ data.qvel[3:6], R_ref[k], w_ref[k], balance,
                                                           [data.xaxis[j] for j in ankle_jnt], load)):
                command[a] += t
        commands[k % (delay + 1)] = command
        data.ctrl[:] = commands[(k - delay) % (delay + 1)] if k >= delay else tau_ff[k]  # at first: feed-forward
        for s in range(options.substeps):
            if torque_friction:
                tau_f = injected.torque(data.qvel[dof_f])
                data.qfrc_applied[dof_f] = tau_f
            mujoco.mj_step(model, data)
            if s == 0:
                qdd[k] = data.qacc[mjr.dof_index]
                tau_log[k] = data.actuator_force[tc]
                tau_f_log[k, joints_f] = mujoco_friction_torque(data, dof_f) if native else tau_f
        # the soles' normal forces over this period, from its last step
        force[k] = data.sensordata[mjr.touch_index]
        contact[k] = force[k] > options.contact_threshold
        if (not np.isfinite(data.qpos).all() or data.qpos[2] < options.fall_height * z0
                or data.warning.number[bad_qacc] > 0):
            raise SimulationError(f"the robot fell (or the simulation diverged) at t = {ref.time[k]:.3f} s")

    Q, V = mjr.q(qpos), mjr.v(qpos, qvel)
    Q_meas = Q.copy()
    Q_meas[:, iq] = q_meas
    A = np.full((n, robot.model.nv), np.nan)
    A[:, iv] = qdd
    log = simulated_log(robot, ref, Q_meas, V, A, tau_log + eps_tau, tau_f_log, contact, injected,
                        "wbfriction.sim.mujoco_sim.simulate_mujoco", options, options.log_base,
                        torque_alignment="zoh",  # the torque is held over the substeps of each period
                        contact_source=f"sole normal force > {options.contact_threshold:g} N")
    wrench = np.zeros((n, nc, 6))
    wrench[:, :, 2] = force
    return SimulationResult(log, wrench, Q, V, ref, tuple(robot.contact_frames))

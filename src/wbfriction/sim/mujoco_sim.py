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

* ``"model"``: eq. (3.5) of the given parameters, or any model of :mod:`~wbfriction.friction.models`, applied as
  a generalised force at every physics step from that step's velocity (a sign function applied as it is: a joint
  that would stop chatters about zero velocity, as a sticking joint does);
* ``"mujoco"``: MuJoCo's own joint friction, ``frictionloss = F_c`` (Coulomb friction
  solved as a constraint: a joint sticks) and ``damping = F_v`` (explicit: ``eulerdamp`` disabled, so the
  damper force is exactly the one applied); the parameters must have no Stribeck term and
  ``tau_os = 0``. ``tau_f_true`` is the friction-loss constraint force plus the damper force. The constraint's
  time constant (``friction_timeconst``) is two physics steps by default, not MuJoCo's 0.02 s: with MuJoCo's,
  the constraint's force follows the sign of ``qd + qdd / b`` (``b`` about 105 1/s), a friction that leads the
  velocity by 10 ms, which no friction law of the velocity describes.

Sensors (:class:`~wbfriction.sim.sensors.SensorNoise`, off by default): the controller
and the log see the same noisy, quantised positions, the log noisy torques (the
controller acts on its sensors: position noise becomes vibration). A ``delay`` holds every
command that long (whole control periods) before the motors apply it.

The log holds the measured contact flags (normal force over the threshold, from the
soles' touch sensors at the last physics step of each period: they differ from the plan
by up to 100 ms around a switch, thesis 6.2), the measured positions (at each period's first
physics step), the torque sensors' readings of the motor torques (plus sensor noise), the
force-torque sensors' and the IMU's readings, each a weighted mean over the physics steps around
the sample that matches the positions' central second difference (:func:`matched_weights`;
``torque_alignment = "sample"``), and, as truth, the friction applied at the first step
(``tau_f_true``) and the joint velocities and accelerations of that step.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, SimulationError
from wbfriction.fit.targets import friction_by_group
from wbfriction.fit.terms import TermFit
from wbfriction.friction.models import ModelParams
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, Recording, SimulationResult, injected_friction
from wbfriction.sim.control import attitude_ankle_torques, pd_from_inertia, pd_gains, ramp_gains, reference_feedforward
from wbfriction.sim.mujoco_model import MujocoRobot, build_mujoco_robot
from wbfriction.sim.options import MujocoOptions
from wbfriction.walking import WalkingReference
from wbfriction.walking.indexing import as_slice

if TYPE_CHECKING:
    import mujoco


def matched_weights(substeps: int) -> np.ndarray:
    """How much a reading at each physics step of a period counts in the period's sample and the next (n, 2).

    With ``n`` semi-implicit Euler steps per period (MuJoCo's integrators update positions with the new
    velocity), the central second difference of the positions logged at the periods' first steps is exactly
    a weighted mean of the steps' accelerations: step ``j`` steps after sample ``k``'s first one weighs
    ``(n - |j|) / n^2`` (a discrete hat of half-width one period). A sensor reading averaged with these
    weights (a sensor whose anti-aliasing filter matches the position sampling, without lag) is what the
    central second difference sees: a step ``s`` of period ``k`` counts ``(n - s) / n^2`` in sample ``k``
    and ``s / n^2`` in sample ``k + 1``. A motor torque held over the periods reads
    ``(n - 1) / (2n) tau[k-1] + (n + 1) / (2n) tau[k]`` (the continuous limit is the ``zoh`` alignment's
    mean); logging the period's first step instead against ``zoh`` left an error of ``(tau[k] - tau[k-1]) / 2n``,
    which a stance hip's gravity torque turns into a false viscous term (hip roll F_v 9-11 % off, measured).
    """
    s = np.arange(substeps)
    return np.column_stack([substeps - s, s]) / substeps**2


def set_mujoco_friction(model: mujoco.MjModel, dofs: np.ndarray, injected: InjectedFriction,
                        timeconst: float | None = None) -> None:
    """Set MuJoCo's ``frictionloss`` and ``damping`` of ``dofs`` from Coulomb-viscous parameters (of any model
    without a Stribeck effect or an offset), and the friction-loss constraint's time constant (``solreffriction``
    ``timeconst`` [s], damping ratio 1; None: two physics steps, the stiffest MuJoCo integrates stably)."""
    import mujoco
    for dof, (joint, p) in zip(dofs, injected.params.items()):
        q = p.quantities()
        if q["S"] != 0 or q["tau_os"] != 0:
            raise InputError(f"friction of '{joint}': MuJoCo's joint friction has no Stribeck term (S, F_s) and "
                             "no offset (tau_os); give S = 0 and tau_os = 0, or use the 'model' friction")
        model.dof_frictionloss[dof], model.dof_damping[dof] = q["F_c"], q["F_v"]
        model.dof_solref[dof] = (2.0 * model.opt.timestep if timeconst is None else timeconst, 1.0)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)


def mujoco_friction_torque(data: mujoco.MjData, dofs: np.ndarray | slice) -> np.ndarray:
    """Joint friction MuJoCo applied on ``dofs`` at the last step [N·m]: the friction-loss
    constraint forces (rows ``mjCNSTR_FRICTION_DOF``, whose Jacobian is the dof's unit
    vector) plus the damper forces.

    The constraint type is compared as an integer: against MuJoCo's enum object NumPy compares element by
    element in Python (160 us a call, measured; 2 us as an integer), the same rows."""
    import mujoco
    rows = (data.efc_type[:data.nefc] == int(mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF)).nonzero()[0]
    force = data.qfrc_damper.copy()
    force[data.efc_id[rows]] += data.efc_force[rows]
    return force[dofs]


class MatchedMeans:
    """The :func:`matched_weights` means (n, m) of a signal read at every physics step, reduced in blocks.

    The simulation writes each period's readings into :meth:`period`'s rows (substeps, m); every
    ``block`` periods (and at the last one) they are reduced at once. The sums add the terms in the order
    a running sum over the steps would (sample ``k``: the previous period's steps, then its own, each
    ``weight * reading``), so the means are the same numbers, with one array copy per step in Python.
    Memory: ``block + 1`` periods of readings.
    """

    def __init__(self, n: int, substeps: int, m: int, block: int = 1024) -> None:
        """Means of ``n`` periods of ``substeps`` readings of ``m`` values."""
        self.weights = matched_weights(substeps)
        self.out = np.zeros((n, m))
        self.block = min(block, n)
        self.raw = np.zeros((self.block + 1, substeps, m))  # row 0: the period before the block's first
        self.start = 0

    def period(self, k: int) -> np.ndarray:
        """Where the readings of period ``k``'s physics steps go (substeps, m): a view to write into."""
        return self.raw[k - self.start + 1]

    def done(self, k: int) -> None:
        """Period ``k``'s readings are in: reduce the block if it is full or ``k`` is the last period."""
        stop = k + 1
        if stop - self.start == self.block or stop == len(self.out):
            raw = self.raw[:stop - self.start + 1]
            acc = self.out[self.start:stop]
            for s, w in enumerate(self.weights[:, 1]):  # the previous period's steps, in order
                acc += w * raw[:-1, s]
            for s, w in enumerate(self.weights[:, 0]):  # then the period's own
                acc += w * raw[1:, s]
            self.raw[0] = raw[-1]
            self.start = stop


class MujocoRun:
    """One run of :func:`simulate_mujoco`: the MuJoCo model and data, the controller, the state and the log."""

    def __init__(self, robot: Robot, reference: WalkingReference, friction: Mapping[str, ModelParams] | None,
                 options: MujocoOptions, mjr: MujocoRobot | None, terms: Mapping[str, TermFit] | None = None) -> None:
        """Set up the model (friction), the stabiliser, the controller, the initial state and the log buffers."""
        import mujoco
        self.native = native = options.friction == "mujoco"
        if friction is None and native:
            friction = {j: dataclasses.replace(p, S=0.0, tau_os=0.0)
                        for j, p in friction_by_group(robot.groups).items()}
        if terms and native:
            raise InputError("terms beyond velocity need the 'model' friction (MuJoCo's own joint friction has none)")
        self.injected = injected_friction(robot, friction, terms)
        self.robot, self.ref, self.options = robot, reference, options
        self.n, self.dt = len(reference), reference.dt
        self.delay = options.delay_periods(self.dt)
        self.mjr = mjr or build_mujoco_robot(robot)
        self.model = copy.copy(self.mjr.model)  # the settings below must not leak into a shared model
        self.model.opt.timestep = self.dt / options.substeps
        self.tc, self.pc = robot.tc_index, robot.pc_index
        self.nc, self.n_act = len(robot.contact_frames), len(robot.actuated)
        self.joints_f = self.injected.joints
        dof_f = self.mjr.dof_index[self.tc][self.joints_f]
        self.dof_f = as_slice(dof_f)
        self.qpos_f = as_slice(self.mjr.qpos_index[self.tc][self.joints_f])
        if native:
            set_mujoco_friction(self.model, dof_f, self.injected, options.friction_timeconst)
        if options.sole_timeconst is not None:
            self.model.geom_solref[list(self.mjr.sole_geoms), 0] = options.sole_timeconst
        self.data = mujoco.MjData(self.model)
        self._setup_stabiliser()
        self._setup_controller()
        self._setup_state()

    def _setup_stabiliser(self) -> None:
        """The base-attitude stabiliser: each leg's last two joints (the ankle), the reference base attitude
        (SciPy's rotations imported only for a robot that has one)."""
        robot, ref = self.robot, self.ref
        self.balance = robot.balance_gains if self.options.balance is None else self.options.balance
        self.stabilise = any(self.balance)
        if self.stabilise:
            from scipy.spatial.transform import Rotation
            self.ankles = [np.array([robot.actuated.index(j) for j in robot.limb(f)[-2:]])
                           for f in robot.contact_frames]
            self.ankle_jnt = [self.mjr.joint_ids[a] for a in self.ankles]
            self.R_ref = Rotation.from_quat(ref.q[:, 3:7]).as_matrix()
            self.w_ref = np.einsum("nij,nj->ni", self.R_ref, ref.v[:, 3:6])  # world frame

    def _setup_controller(self) -> None:
        """The controller: feed-forward, PD gains per contact state (capped), the sensor noise."""
        robot, ref, options, dt, tc, pc = self.robot, self.ref, self.options, self.dt, self.tc, self.pc
        iq, iv = robot.act_q_index, robot.act_v_index
        self.tau_ff = reference_feedforward(robot, ref)
        free = np.diag(pin.crba(robot.model, robot.model.createData(), ref.q[0]))[iv]  # inertia, upstream held
        kp_max = np.minimum(options.max_gains[0], free[tc] / dt**2)
        kd_max = np.minimum(options.max_gains[1], free[tc] / dt)
        self.gains = {state: (np.minimum(kp, kp_max), np.minimum(kd, kd_max))
                      for state, (kp, kd) in pd_gains(robot, ref.q[0], options.bandwidth, options.damping).items()}
        self.kp_act, self.kd_act = np.zeros(self.n_act), np.zeros(self.n_act)
        self.kp_act[pc], self.kd_act[pc] = pd_from_inertia(free[pc], options.bandwidth, options.damping)
        self.q_ref, self.v_ref = ref.q[:, iq], ref.v[:, iv]
        self.eps_q, self.eps_tau = options.sensors.draw(self.n, self.n_act, tc.size)

    def _setup_state(self) -> None:
        """The initial state (the reference's first sample), the log buffers, the controller's state."""
        import mujoco
        model, data, mjr, ref, n, nc, n_act = self.model, self.data, self.mjr, self.ref, self.n, self.nc, self.n_act
        data.qpos[:] = mjr.qpos(ref.q[0])
        data.qvel[:] = mjr.velocity_map(ref.q[0]) @ ref.v[0]
        mujoco.mj_forward(model, data)
        self.z0 = data.qpos[2]

        self.qpos, self.qvel = np.empty((n, model.nq)), np.empty((n, model.nv))
        self.q_meas = np.empty((n, n_act))
        self.qacc = np.empty((n, model.nv))  # at each period's first physics step
        self.tau_motor = np.empty((n, model.nu))  # the motors' torques (actuators in Robot.actuated order), held
        self.tau_f_first = np.zeros((n, len(self.joints_f)))  # friction applied at each period's first step
        # what MuJoCo's sensors (sensordata: touch, force-torque, IMU) and the torque sensors read, averaged
        self.sensor_means = MatchedMeans(n, self.options.substeps, model.nsensordata)
        self.motor_means = MatchedMeans(n, self.options.substeps, model.nu)
        self.recording = Recording(self.robot, ref, self.injected, self.options.temperature)
        self.contact, self.force = np.zeros((n, nc), dtype=bool), np.zeros((n, nc))
        self.commands = np.zeros((self.delay + 1, n_act))  # ring buffer: the command of period k acts at k + delay
        self.state: tuple[bool, ...] | None  # the contact state the gains are scheduled for
        self.before: tuple[np.ndarray, np.ndarray] | None  # the gains (kp, kd) when it began, at period k_switch
        self.state, self.k_switch, self.before = None, 0, None
        self.kp_act[self.tc], self.kd_act[self.tc] = self.gains[tuple(bool(x) for x in ref.contact[0])]
        self.torque_friction = bool(self.joints_f) and not self.native  # (3.5) applied by us at every physics step
        self.measured = tuple(bool(x) for x in ref.contact[0])  # the contacts sensed over the last period
        self.noisy_q = bool(self.eps_q.any())
        self.quantised = self.options.sensors.resolution is not None
        self.qpos_act = as_slice(mjr.qpos_index)
        self.touch = as_slice(mjr.touch_index)
        self.bad_qacc = data.warning.number[int(mujoco.mjtWarning.mjWARN_BADQACC):][:1]  # a view: the count
        # what every physics step uses, fetched once (the loop runs four times per simulated millisecond)
        self._stepping = (mujoco.mj_step, model, data, data.sensordata, data.actuator_force)

    def sample(self, k: int) -> None:
        """Run the control period of sample ``k``: measure, command, step the physics, sense the contacts."""
        qd_meas = self.measure(k)
        self.actuate(k, self.control(k, qd_meas))
        self.physics(k)
        self.sense_contacts(k)

    def actuate(self, k: int, command: np.ndarray) -> None:
        """Queue the command of period ``k`` and give the motors the one ``delay`` periods old."""
        d = self.delay
        self.commands[k % (d + 1)] = command
        self.data.ctrl[:] = self.commands[(k - d) % (d + 1)] if k >= d else self.tau_ff[k]  # at first: feed-forward

    def measure(self, k: int) -> np.ndarray:
        """Log the state at the start of period ``k`` and the measured positions; the measured velocities."""
        data, q = self.data, self.q_meas[k]
        self.qpos[k], self.qvel[k], q[:] = data.qpos, data.qvel, data.qpos[self.qpos_act]
        if self.noisy_q:
            q += self.eps_q[k]
        if self.quantised:
            q[:] = self.options.sensors.encoder(q)
        return (q - self.q_meas[k - 1]) / self.dt if k > 0 else self.v_ref[0]

    def control(self, k: int, qd_meas: np.ndarray) -> np.ndarray:
        """The command of period ``k``: feed-forward, PD on the measurements, the attitude stabiliser."""
        # the controller knows the contact measured over the last period (the plan at first)
        last = self.measured if k > 0 and any(self.measured) else tuple(self.ref.contact[k].tolist())
        self.schedule_gains(k, last)
        command = (self.tau_ff[k] + self.kp_act * (self.q_ref[k] - self.q_meas[k])
                   + self.kd_act * (self.v_ref[k] - qd_meas))
        if self.stabilise:
            data = self.data
            R = data.xmat[self.mjr.base_body].reshape(3, 3)
            load = (self.force[k - 1] if k > 0 else np.ones(self.nc)) * np.array(last)
            torques = attitude_ankle_torques(R, R @ data.qvel[3:6], self.R_ref[k], self.w_ref[k], self.balance,
                                             [data.xaxis[j] for j in self.ankle_jnt], load)
            for a, t in zip(self.ankles, torques):
                command[a] += t
        return command

    def schedule_gains(self, k: int, measured: tuple[bool, ...]) -> None:
        """The torque-controlled joints' gains at period ``k``, ramping since the last change of ``measured``."""
        tc, dt, blend = self.tc, self.dt, self.options.gain_blend
        if measured != self.state:
            self.state, self.k_switch, self.before = measured, k, (self.kp_act[tc].copy(), self.kd_act[tc].copy())
        assert self.state is not None and self.before is not None  # set above at the first call
        if (k - self.k_switch) * dt <= blend + dt:
            self.kp_act[tc], self.kd_act[tc] = ramp_gains(self.before, self.gains[self.state],
                                                          (k - self.k_switch) * dt, blend)

    def physics(self, k: int) -> None:
        """The physics steps of period ``k``, with the friction of eq. (3.5) if ours; the first one is logged
        (:meth:`record`). Every step's sensor readings (MuJoCo's sensors, the motor torques) go to the
        matched means (:class:`MatchedMeans`)."""
        step, model, data, sensordata, motor = self._stepping
        sensed, motors = self.sensor_means.period(k), self.motor_means.period(k)
        friction = self.apply_friction if self.torque_friction else None
        for s in range(len(sensed)):
            if friction is not None:
                tau_f = friction(k)
                if s == 0:
                    self.tau_f_first[k] = tau_f
            step(model, data)  # the sensors are computed with the step's qacc, before its integration
            if s == 0:
                self.record(k)
            sensed[s], motors[s] = sensordata, motor
        self.sensor_means.done(k)
        self.motor_means.done(k)

    def apply_friction(self, k: int) -> np.ndarray:
        """Apply the injected friction (n_f,) [N·m] of the velocities of this physics step (period ``k``) as
        generalised forces (``qfrc_applied``) and return it."""
        data, dof_f, injected = self.data, self.dof_f, self.injected
        qvel, applied = data.qvel, data.qfrc_applied
        tau_f = injected.torque(qvel[dof_f])
        if injected.beyond:  # the load: the rigid-body torque, motor's and friction's, of the last step
            warm = self.recording.temperature
            tau_f = injected.with_terms(tau_f, qvel[dof_f], data.qpos[self.qpos_f],
                                        data.qfrc_actuator[dof_f] + applied[dof_f],
                                        0.0 if warm is None else float(warm[k]))
        applied[dof_f] = tau_f
        return tau_f

    def record(self, k: int) -> None:
        """Log the period's first physics step: accelerations, motor torques, MuJoCo's friction if used."""
        data = self.data
        self.qacc[k], self.tau_motor[k] = data.qacc, data.actuator_force
        if self.native:
            self.tau_f_first[k] = mujoco_friction_torque(data, self.dof_f)

    def sense_contacts(self, k: int) -> None:
        """The soles' normal forces over period ``k``, from its last step, and the contacts; stop at a fall.

        Raises:
            SimulationError: the robot fell or the simulation diverged.
        """
        data, force, contact = self.data, self.force[k], self.contact[k]
        force[:] = data.sensordata[self.touch]
        np.greater(force, self.options.contact_threshold, out=contact)
        self.measured = tuple(contact.tolist())
        if (not math.isfinite(data.qpos.sum()) or data.qpos[2] < self.options.fall_height * self.z0
                or self.bad_qacc[0] > 0):  # a sum is finite only if every term is (or overflows: diverged too)
            raise SimulationError(f"the robot fell (or the simulation diverged) at t = {self.ref.time[k]:.3f} s")

    def result(self) -> SimulationResult:
        """The log (measured positions and contacts, noisy torques) and the result of the run."""
        robot, mjr, recording = self.robot, self.mjr, self.recording
        Q, V = mjr.q(self.qpos), mjr.v(self.qpos, self.qvel)
        # what Recording.record_torques would have logged sample by sample
        recording.tau[:] = self.tau_motor[:, self.tc]
        recording.tau_f[:, self.joints_f] = self.tau_f_first
        # sample 0 has no period before it: its readings' weights sum to this
        first = matched_weights(self.options.substeps)[:, 0].sum()
        sensed, tau_sensed = self.sensor_means.out, self.motor_means.out[:, self.tc]
        sensed[0] /= first
        tau_sensed[0] /= first
        ft, imu_read = mjr.wrenches(sensed), sensed[:, mjr.imu_index]
        Q_meas = Q.copy()
        Q_meas[:, robot.act_q_index] = self.q_meas
        A = np.full((self.n, robot.model.nv), np.nan)
        A[:, robot.act_v_index] = self.qacc[:, mjr.dof_index]
        A[:, :6] = mjr.base_acceleration(self.qpos, self.qvel, self.qacc[:, :6])
        recording.wrench[:, :, 2] = self.force
        drift, ft_offset = self.options.imperfections(self.n, self.dt, self.tc.size, len(robot.ft_sensors))
        imu = imu_read + self.options.imu_errors(self.n) if imu_read.shape[1] and self.options.imu else None
        return recording.result(Q, V, A, self.contact, "wbfriction.sim.mujoco_sim.simulate_mujoco", self.options,
                                Q_log=Q_meas, tau_noise=self.eps_tau + drift,
                                sensor_wrench=ft + ft_offset if self.options.force_torque else None,
                                imu=imu, tau_sensed=tau_sensed,
                                torque_alignment="sample",  # readings matched to the positions' sampling
                                contact_source=f"sole normal force > {self.options.contact_threshold:g} N")


def simulate_mujoco(robot: Robot, reference: WalkingReference, friction: Mapping[str, ModelParams] | None = None,
                    options: MujocoOptions = MujocoOptions(), mjr: MujocoRobot | None = None,
                    progress: Progress | None = None, terms: Mapping[str, TermFit] | None = None) -> SimulationResult:
    """Simulate a walk on MuJoCo (module docstring).

    Args:
        robot: the robot the reference was planned for.
        reference: :func:`~wbfriction.walking.walking_reference` output.
        friction: parameters per torque-controlled joint; default: Table 6.1 on the legs
            (for ``options.friction == "mujoco"``: its F_c and F_v only).
        options: :class:`MujocoOptions`.
        mjr: a prebuilt MuJoCo model (not modified; default: built from ``robot``).
        progress: optional callable receiving numbers of samples done.
        terms: friction beyond velocity per torque-controlled joint (``options.friction == "model"`` only;
            :func:`~wbfriction.sim.ideal.simulate_ideal`'s), logged as the metadata's ``terms_true``.

    Returns:
        A :class:`~wbfriction.sim.common.SimulationResult`; its ``wrench`` holds the soles'
        normal forces in ``[..., 2]`` (the rest zero).

    Raises:
        InputError: friction on a joint that is not torque-controlled; Stribeck or offset
            parameters with MuJoCo's friction; terms with MuJoCo's friction, or a temperature term without the
            options' temperature; a delay that is not whole periods.
        SimulationError: the robot fell (the message gives the time).
    """
    run = MujocoRun(robot, reference, friction, options, mjr, terms)
    for k in counted(len(reference), progress):
        run.sample(k)
    return run.result()

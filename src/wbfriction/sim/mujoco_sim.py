"""The realistic simulator (thesis 6.2) on MuJoCo: real foot contacts, contact flags measured.

The same walking reference and controller as the ideal simulator
(:mod:`wbfriction.sim.ideal`): feed-forward torques from the constrained inverse dynamics
of the reference plus joint PD, computed at the log rate and held over the period; the
physics runs ``substeps`` MuJoCo steps per period on the model of
:mod:`wbfriction.sim.mujoco_model` (soft contacts, sliding and torsional friction under
box soles). Differences forced by real contacts:

* the PD gains follow the *measured* contact state (a sole is in contact when its normal
  force exceeds ``contact_threshold``), not the planned one: the stance gains, designed
  for a foot on the ground, make a foot still in the air unstable;
* the gains are those of :func:`~wbfriction.sim.control.pd_gains` clipped at
  ``max_gains`` (soft contacts do not give a stance leg the welded foot's stiffness);
* the position-controlled joints follow their reference through a stiff PD (gains from
  their inertia at the reference bandwidth), not as a constraint.

Friction (3.5) acts on the chosen joints at every physics step as a generalised force,
from the velocity of that step. The log holds the measured contact flags (normal force
over the threshold, thesis 6.2: they differ from the plan by up to 100 ms around a
switch; read at the last physics step of each period), the friction applied at the first
physics step of each period (``tau_f_true``), and the true joint velocities and
accelerations of that step.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pinocchio as pin

from ..exceptions import InputError, SimulationError
from ..friction import FrictionParams
from ..progress import counted
from ..robot import Robot
from ..walking import WalkingReference
from .common import SimulationResult, injected_friction, simulated_log
from .control import pd_from_inertia, pd_gains, ramp_gains, reference_feedforward
from .mujoco_model import MujocoRobot, build_mujoco_robot


@dataclass(frozen=True)
class MujocoOptions:
    """Parameters of :func:`simulate_mujoco`.

    Attributes:
        substeps: physics steps per control period (the physics step is ``dt / substeps``).
        bandwidth: PD bandwidth [Hz]; damping: its damping ratio.
        max_gains: (kp [N·m/rad], kd [N·m·s/rad]) caps of every joint's gains.
        gain_blend: time over which rising gains ramp to a new contact state's [s].
        contact_threshold: normal force above which a sole counts as in contact [N].
        fall_height: the simulation stops with an error when the base drops below this
            share of its initial height.
        log_base: write the base pose to the log.
    """

    substeps: int = 10
    bandwidth: float = 10.0
    damping: float = 0.9
    max_gains: tuple[float, float] = (3000.0, 60.0)
    gain_blend: float = 0.1
    contact_threshold: float = 50.0
    fall_height: float = 0.5
    log_base: bool = True

    def __post_init__(self) -> None:
        if self.substeps < 1:
            raise InputError(f"substeps must be at least 1, got {self.substeps}")
        if self.contact_threshold <= 0:
            raise InputError("the contact threshold must be a positive force [N]")


def sole_forces(mjr: MujocoRobot, data: mujoco.MjData) -> np.ndarray:
    """Normal force of each sole on the ground (n_contacts,) [N]."""
    out = np.zeros(len(mjr.sole_geoms))
    f6 = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        for s, g in enumerate(mjr.sole_geoms):
            if g == c.geom1 or g == c.geom2:
                mujoco.mj_contactForce(mjr.model, data, i, f6)
                out[s] += f6[0]
    return out


def simulate_mujoco(robot: Robot, reference: WalkingReference, friction: dict[str, FrictionParams] | None = None,
                    options: MujocoOptions = MujocoOptions(), mjr: MujocoRobot | None = None,
                    progress=None) -> SimulationResult:
    """Simulate a walk on MuJoCo (module docstring).

    Args:
        robot: the robot the reference was planned for.
        reference: :func:`~wbfriction.walking.walking_reference` output.
        friction: parameters per torque-controlled joint; default: Table 6.1 on the legs.
        options: :class:`MujocoOptions`.
        mjr: a prebuilt MuJoCo model (default: built from ``robot`` at the physics step).
        progress: optional callable receiving numbers of samples done.

    Returns:
        A :class:`~wbfriction.sim.common.SimulationResult`; its ``wrench`` holds the soles'
        normal forces in ``[..., 2]`` (the rest zero).

    Raises:
        InputError: friction on a joint that is not torque-controlled.
        SimulationError: the robot fell (the message gives the time).
    """
    injected = injected_friction(robot, friction)
    ref, n, dt = reference, len(reference), reference.dt
    mjr = mjr or build_mujoco_robot(robot, timestep=dt / options.substeps)
    model, data = mjr.model, mujoco.MjData(mjr.model)
    model.opt.timestep = dt / options.substeps
    nc = len(robot.contact_frames)
    iq, iv, tc, pc = robot.act_q_index, robot.act_v_index, robot.tc_index, robot.pc_index
    dof_tc, dof_pc = mjr.dof_index[tc], mjr.dof_index[pc]
    joints_f = injected.joints
    dof_f = dof_tc[joints_f]

    tau_ff = reference_feedforward(robot, ref)
    kp_max, kd_max = options.max_gains
    gains = {state: (np.minimum(kp, kp_max), np.minimum(kd, kd_max))
             for state, (kp, kd) in pd_gains(robot, ref.q[0], options.bandwidth, options.damping).items()}
    M = pin.crba(robot.model, robot.model.createData(), ref.q[0])
    kp_pc, kd_pc = pd_from_inertia(np.diag(M)[iv[pc]], options.bandwidth, options.damping)
    q_ref, v_ref = ref.q[:, iq], ref.v[:, iv]

    data.qpos[:] = mjr.qpos(ref.q[0])
    data.qvel[:] = mjr.velocity_map(ref.q[0]) @ ref.v[0]
    mujoco.mj_forward(model, data)
    z0 = data.qpos[2]

    Q, V, A = np.empty((n, robot.model.nq)), np.empty((n, robot.model.nv)), np.empty((n, robot.model.nv))
    tau_log, tau_f_log = np.empty((n, tc.size)), np.zeros((n, tc.size))
    contact, force = np.zeros((n, nc), dtype=bool), np.zeros((n, nc))
    state = None
    kp, kd = gains[tuple(bool(x) for x in ref.contact[0])]
    tau = np.zeros(model.nv)
    for k in counted(n, progress):
        q = mjr.q(data.qpos)
        v = mjr.v(data.qpos, data.qvel)
        # the controller knows the contact measured over the last period (the plan at first)
        last = contact[k - 1] if k > 0 and contact[k - 1].any() else ref.contact[k]
        measured = tuple(bool(x) for x in last)
        if measured != state:
            state, k_switch, before = measured, k, (kp, kd)
        kp, kd = ramp_gains(before, gains[state], (k - k_switch) * dt, options.gain_blend)
        angles, qd = q[iq], v[iv]
        tau_cmd = tau_ff[k, tc] + kp * (q_ref[k, tc] - angles[tc]) + kd * (v_ref[k, tc] - qd[tc])
        tau[:] = 0.0
        tau[dof_tc] = tau_cmd
        tau[dof_pc] = tau_ff[k, pc] + kp_pc * (q_ref[k, pc] - angles[pc]) + kd_pc * (v_ref[k, pc] - qd[pc])
        for s in range(options.substeps):
            data.qfrc_applied[:] = tau
            if joints_f:
                tau_f = injected.torque(data.qvel[dof_f])
                data.qfrc_applied[dof_f] += tau_f
            mujoco.mj_step(model, data)
            if s == options.substeps - 1:  # the soles' forces over this period, from its last step
                force[k] = sole_forces(mjr, data)
                contact[k] = force[k] > options.contact_threshold
            if s == 0:
                Q[k], V[k] = q, v
                A[k, iv] = data.qacc[mjr.dof_index]
                tau_log[k] = tau_cmd
                if joints_f:
                    tau_f_log[k, joints_f] = tau_f
        if not np.isfinite(data.qpos).all() or data.qpos[2] < options.fall_height * z0 or data.warning.number[
                int(mujoco.mjtWarning.mjWARN_BADQACC)] > 0:
            raise SimulationError(f"the robot fell (or the simulation diverged) at t = {ref.time[k]:.3f} s")

    log = simulated_log(robot, ref, Q, V, A, tau_log, tau_f_log, contact, injected,
                        "wbfriction.sim.mujoco_sim.simulate_mujoco", options, options.log_base,
                        torque_alignment="zoh",  # the torque is held over the substeps of each period
                        contact_source=f"sole normal force > {options.contact_threshold:g} N")
    wrench = np.zeros((n, nc, 6))
    wrench[:, :, 2] = force
    return SimulationResult(log, wrench, Q, V, ref, tuple(robot.contact_frames))

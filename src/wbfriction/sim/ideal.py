"""The ideal simulator (thesis 6.1): rigid contacts solved exactly, friction (3.5) injected.

Each physics step solves the constrained forward dynamics with ``pin.constraintDynamics``:
every foot in contact is welded flat to the ground at its planned footprint (6D
constraint, Baumgarte correction), and the position-controlled joints follow their
reference exactly, as a constraint: their acceleration is set to the reference's (with
the same Baumgarte correction), the torque that achieves it found from the same KKT
factorisation (``constraint_chol.solve``). At touch-down the landing foot is anchored
flat on its planned footprint (so that errors do not add up step after step) and the
configuration projected onto that anchor: the foot snaps by its tracking error, about a
millimetre, at the touch-down sample (a double-support sample, never used in single
support). At every logged sample the velocity is projected onto the constraints
(``pin.impulseDynamics``: the plastic impact at touch-down, the integration drift
otherwise), so the logged state satisfies ``J v = 0`` exactly and the Baumgarte term only
corrects the drift between samples.

The controller (:mod:`wbfriction.sim.control`) runs at the log rate ``1 / dt``; its torque
is held over the period. Friction ``tau_f = -f(qd)`` of eq. (3.5) acts on the chosen joints
at every physics step, from the velocity at the start of the step. Integration:

* ``semi-implicit`` Euler: ``v+ = v + h a(q, v)``, ``q+ = q ⊕ h v+`` (default);
* ``explicit`` (forward) Euler, as in the thesis: ``q+ = q ⊕ h v``, ``v+ = v + h a(q, v)``.

The log carries the measured torques of the torque-controlled joints (the command: the
torque sensor sits before the friction), the planned contact flags, the friction applied
(``tau_f_true``), and the true joint velocities and accelerations at every sample
(``qd_true``, ``qdd_true``), so that differentiation errors can be told apart from the
estimator's. The true acceleration is the constrained dynamics' without the Baumgarte
term (thesis 6.1.1: computed as in (5.10) with the friction added), which the stance
foot's zero acceleration in the estimator assumes.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from wbfriction.fit.terms import TermFit
from wbfriction.friction.models import ModelParams
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, Recording, SimulationResult, injected_friction
from wbfriction.sim.control import contact_jacobian, gain_schedule, pd_gains, reference_feedforward
from wbfriction.sim.options import IdealOptions
from wbfriction.walking import WalkingReference
from wbfriction.walking.indexing import as_slice
from wbfriction.walking.swing import foot_placement


def _project_configuration(robot: Robot, data: pin.Data, q: np.ndarray, contacts: np.ndarray,
                           anchors: dict[int, pin.SE3], iterations: int = 3) -> np.ndarray:
    """Move ``q`` by the least joint motion (position-controlled joints excluded) that puts
    the active soles exactly on their anchors (Gauss-Newton on the 6D placement errors)."""
    model = robot.model
    cols = np.setdiff1d(np.arange(model.nv), robot.act_v_index[robot.pc_index])
    for _ in range(iterations):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        active = np.flatnonzero(contacts)
        e = np.concatenate([pin.log6(anchors[int(c)].actInv(data.oMf[robot.contact_frame_ids[c]])).vector
                            for c in active])
        J = contact_jacobian(robot, data, contacts)
        dq = np.zeros(model.nv)
        dq[cols] = -np.linalg.lstsq(J[:, cols], e, rcond=None)[0]
        q = pin.integrate(model, q, dq)
    return q


def _solve_small(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``A^-1 b`` for the tiny systems of the position-controlled joints (closed form up to 2x2)."""
    if A.shape == (1, 1):
        return b / A[0, 0]
    if A.shape == (2, 2):
        (a00, a01), (a10, a11) = A.tolist()
        b0, b1 = b.tolist()
        det = a00 * a11 - a01 * a10
        return np.array([(a11 * b0 - a01 * b1) / det, (a00 * b1 - a10 * b0) / det])
    return np.linalg.solve(A, b)


def contact_constraints(robot: Robot, data: pin.Data, active: np.ndarray, anchors: dict[int, pin.SE3],
                        baumgarte: tuple[float, float]
                        ) -> tuple[pin.StdVec_RigidConstraintModel, pin.StdVec_RigidConstraintData]:
    """6D rigid constraints welding the ``active`` soles to their anchors, initialised in ``data``.

    Returned as Pinocchio's own vectors: a Python list would be converted (copied) at every
    dynamics call, a third of ``constraintDynamics``'s time on TALOS."""
    models = pin.StdVec_RigidConstraintModel()
    for c in np.flatnonzero(active):
        fr = robot.model.frames[robot.contact_frame_ids[c]]
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, robot.model, fr.parentJoint, fr.placement,
                                      0, anchors[int(c)], pin.LOCAL)
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(*baumgarte))
        models.append(cm)
    datas = pin.StdVec_RigidConstraintData()
    for cm in models:
        datas.append(cm.createData())
    pin.initConstraintDynamics(robot.model, data, models, datas)
    return models, datas


def unstack_wrenches(stacked: np.ndarray, contact: np.ndarray, wrench: np.ndarray) -> None:
    """Write the wrenches of the active feet, stacked in contact order per sample (N, 6 n_contacts),
    into ``wrench`` (N, n_contacts, 6) at their feet (the rows of inactive feet untouched)."""
    slot = np.cumsum(contact, axis=1) - 1  # position of each active foot in the stack
    stacked = stacked.reshape(len(stacked), -1, 6)
    for c in range(contact.shape[1]):
        rows = np.flatnonzero(contact[:, c])
        wrench[rows, c] = stacked[rows, slot[rows, c]]


class _IdealRun:
    """One run of :func:`simulate_ideal`: the model, the controller, the contacts, the state and the log."""

    def __init__(self, robot: Robot, reference: WalkingReference, injected: InjectedFriction,
                 options: IdealOptions) -> None:
        """Set up the controller, the reference per sample, the initial state and the log buffers."""
        self.robot, self.ref, self.injected, self.options = robot, reference, injected, options
        self.model = robot.model
        self.data = self.model.createData()
        n, dt = len(reference), reference.dt
        self.h = dt / options.substeps

        tau_ff = reference_feedforward(robot, reference)
        gains = pd_gains(robot, reference.q[0], options.bandwidth, options.damping)
        kp, kd = gain_schedule(gains, reference.contact, dt, options.gain_blend)
        self.bkp, self.bkd = options.baumgarte

        iv, iq = robot.act_v_index, robot.act_q_index
        tc, self.pc = robot.tc_index, robot.pc_index
        self.iv_tc, self.iv_pc = as_slice(iv[tc]), as_slice(iv[self.pc])
        self.joints_f = injected.joints
        self.iv_f = as_slice(iv[tc][self.joints_f])
        self.iq_f = as_slice(iq[tc][self.joints_f])
        self.settings = pin.ProximalSettings(1e-12, 1e-10, 50)
        self.semi_implicit = options.integrator == "semi-implicit"
        self.project_every_sample = options.projection == "sample"
        # one PD law per sample on the actuated joints, torque-controlled then position-controlled:
        # u = offset + kp (q_ref - q) + kd (v_ref - v); for the former the torque command
        # (feed-forward plus PD), for the latter the stabilised reference acceleration (the
        # Baumgarte gains). The reference and gains are contiguous per sample.
        ref, act, ones = reference, np.concatenate([tc, self.pc]), np.ones((n, self.pc.size))
        self.iq_act, self.iv_act = as_slice(iq[act]), as_slice(iv[act])
        self.pd_offset = np.hstack([tau_ff[:, tc], ref.a[:, iv[self.pc]]])
        self.pd_kp, self.pd_kd = np.hstack([kp, self.bkp * ones]), np.hstack([kd, self.bkd * ones])
        self.pd_q, self.pd_v = np.ascontiguousarray(ref.q[:, iq[act]]), np.ascontiguousarray(ref.v[:, iv[act]])
        self.switches = set(np.flatnonzero(np.any(np.diff(ref.contact, axis=0, prepend=False), axis=1)).tolist())

        self.Q = np.empty((n, self.model.nq))
        self.V = np.empty((n, self.model.nv))
        self.A = np.empty((n, self.model.nv))
        self.lam = np.zeros((n, 6 * len(robot.contact_frames)))  # logged wrenches of the active feet, stacked
        self.recording = Recording(robot, reference, injected, options.temperature)
        self.q, self.v = ref.q[0].copy(), ref.v[0].copy()
        self.anchors: dict[int, pin.SE3] = {}
        self.active = np.zeros(len(robot.contact_frames), bool)
        self.tau_pc = tau_ff[0, self.pc].copy()
        self.tau = np.zeros(self.model.nv)
        self.tau_f: np.ndarray | None = None

    def run(self, progress: Progress | None = None) -> None:
        """Simulate every sample: contact changes, velocity projection, control, physics steps, log.

        Per control period ``k`` (the module docstring): the velocity is projected onto the
        contacts, the controller's torque (feed-forward plus PD) is held over the
        ``substeps`` physics steps; each step solves the constrained dynamics with friction,
        gives the position-controlled joints their reference acceleration (stabilised) from
        the same KKT factorisation, and integrates; the first step of the period is logged.
        The loop runs a thousand times per simulated second: the state, the buffers and
        Pinocchio's functions are held in locals.
        """
        model, data, settings, opts = self.model, self.data, self.settings, self.options
        impulse_dynamics, constraint_dynamics, integrate = pin.impulseDynamics, pin.constraintDynamics, pin.integrate
        add, negative, subtract = np.add, np.negative, np.subtract
        iv_tc, iv_pc, iv_f, iq_act, iv_act = self.iv_tc, self.iv_pc, self.iv_f, self.iq_act, self.iv_act
        offset, kp, kd, q_ref, v_ref = self.pd_offset, self.pd_kp, self.pd_kd, self.pd_q, self.pd_v
        n_tc, h, friction = self.robot.tc_index.size, self.h, self.injected.torque if self.joints_f else None
        position_controlled, semi_implicit, project = self.pc.size > 0, self.semi_implicit, self.project_every_sample
        Q, V, A, lam_log, record_torques = self.Q, self.V, self.A, self.lam, self.recording.record_torques
        switches, tau, tau_pc, tau_f = self.switches, self.tau, self.tau_pc, self.tau_f
        q, v = self.q, self.v
        beyond, iq_f, joints_f = (self.injected.with_terms if self.injected.beyond else None), self.iq_f, self.joints_f
        warm = self.recording.temperature
        if beyond is not None and tau_f is None:
            tau_f = np.zeros(len(joints_f))
        for k in counted(len(self.ref), progress):
            switch = k in switches
            if switch:
                self.q = q
                self.switch_contacts(k)
                q, cmodels, cdatas, n_lam, rows_pc, rhs, baumgarte = (
                    self.q, self.cmodels, self.cdatas, self.n_lam, self.rows_pc, self.rhs, self.baumgarte_rhs)
                kkt_rows_f, kkt_rows_a = slice(0, n_lam), slice(n_lam, None)
            # velocity onto the constraints (plastic impact at touch-down, drift otherwise)
            if switch or project:
                v = impulse_dynamics(model, data, q, v, cmodels, cdatas, 0.0, settings).copy()
            for s in range(opts.substeps):
                u = offset[k] + kp[k] * (q_ref[k] - q[iq_act]) + kd[k] * (v_ref[k] - v[iv_act])
                if s == 0:  # the torque command, held over the period
                    tau_cmd = u[:n_tc]
                tau[iv_tc] = tau_cmd
                if friction is not None:
                    if beyond is not None:  # the load: the rigid-body torque tau_motor + tau_f, of the last step
                        tau_f = beyond(friction(v[iv_f]), v[iv_f], q[iq_f], tau_cmd[joints_f] + tau_f,
                                       0.0 if warm is None else float(warm[k]))
                    else:
                        tau_f = friction(v[iv_f])
                    tau[iv_f] += tau_f
                tau[iv_pc] = tau_pc
                a = constraint_dynamics(model, data, q, v, tau, cmodels, cdatas, settings)
                lam = data.lambda_c
                if s == 0:  # Pinocchio's contact_acceleration_error is -(Kp placement + Kd velocity error)
                    for cd, out in baumgarte:
                        negative(cd.contact_acceleration_error.np, out=out)
                # unit-torque responses of the position-controlled joints, and the Baumgarte term's
                X = data.constraint_chol.solve(rhs)
                if position_controlled:  # acceleration = reference, stabilised (u's last entries)
                    delta = _solve_small(X[rows_pc, :-1], u[n_tc:] - a[iv_pc])
                    dX = X[:, :-1] @ delta  # the response: forces, then accelerations
                    a, lam = a + dX[kkt_rows_a], lam - dX[kkt_rows_f]
                    tau_pc = tau_pc + delta
                if s == 0:  # log: the true acceleration and wrenches (the Baumgarte term taken off both)
                    Q[k], V[k] = q, v
                    add(a, X[kkt_rows_a, -1], out=A[k])
                    subtract(lam, X[kkt_rows_f, -1], out=lam_log[k, :n_lam])
                    record_torques(k, tau_cmd, tau_f)
                if semi_implicit:
                    v = v + h * a
                    q = integrate(model, q, h * v)
                else:
                    q = integrate(model, q, h * v)
                    v = v + h * a
        self.q, self.v, self.tau_pc, self.tau_f = q, v, tau_pc, tau_f

    def switch_contacts(self, k: int) -> None:
        """Anchor the feet landing at sample ``k``, project onto them, and rebuild the contact constraints."""
        ref = self.ref
        landing = ref.contact[k] & ~self.active
        for c in np.flatnonzero(landing):
            self.anchors[int(c)] = foot_placement(ref.feet[k, c])  # planned footprint, flat, z = 0
        self.active = ref.contact[k].copy()
        if landing.any():
            self.q = _project_configuration(self.robot, self.data, self.q, self.active, self.anchors)
        self.cmodels, self.cdatas = contact_constraints(self.robot, self.data, self.active, self.anchors,
                                                        self.options.baumgarte)
        self.n_lam = 6 * int(self.active.sum())
        # one right-hand side per position-controlled joint (unit torque) and one for
        # the contacts' Baumgarte term
        self.rhs = np.zeros((self.n_lam + self.model.nv, self.pc.size + 1))
        rows_pc = self.n_lam + self.robot.act_v_index[self.pc]  # KKT rows of their accelerations
        self.rhs[rows_pc, np.arange(self.pc.size)] = 1.0
        self.rows_pc = as_slice(rows_pc)
        # each contact's data (a reference: iterating Pinocchio's vector costs microseconds) and
        # its rows of the Baumgarte right-hand side (a view)
        self.baumgarte_rhs = [(self.cdatas[i], self.rhs[6 * i:6 * i + 6, -1]) for i in range(len(self.cdatas))]

    def result(self) -> SimulationResult:
        """The log (planned contacts) and the result of the run."""
        unstack_wrenches(self.lam, self.ref.contact, self.recording.wrench)
        # semi-implicit Euler at the log rate: the central second difference at k is the
        # acceleration tau[k] caused; otherwise the torque is held over several steps
        alignment = "sample" if self.semi_implicit and self.options.substeps == 1 else "zoh"
        return self.recording.result(self.Q, self.V, self.A, self.ref.contact.copy(),
                                     "wbfriction.sim.ideal.simulate_ideal", self.options, torque_alignment=alignment,
                                     log_sensors=self.options.force_torque, log_imu=self.options.imu)


def simulate_ideal(robot: Robot, reference: WalkingReference,
                   friction: Mapping[str, ModelParams] | None = None,
                   options: IdealOptions = IdealOptions(), progress: Progress | None = None,
                   terms: Mapping[str, TermFit] | None = None) -> SimulationResult:
    """Simulate a walk in the ideal simulator (module docstring).

    Args:
        robot: the robot the reference was planned for.
        reference: :func:`~wbfriction.walking.walking_reference` output.
        friction: parameters per torque-controlled joint name; default: the thesis's
            targets (Table 6.1) on the leg joint groups, none elsewhere.
        options: :class:`IdealOptions`.
        progress: optional callable receiving numbers of samples done.
        terms: friction beyond velocity per torque-controlled joint (:class:`~wbfriction.fit.terms.TermFit`:
            its model replaces the joint's ``friction``; the load is the joint's rigid-body torque
            ``tau_motor + tau_f`` of the previous physics step, the angle its true one, the temperature the
            options' warm-up), logged as the metadata's ``terms_true``.

    Returns:
        A :class:`SimulationResult` whose log has ``len(reference)`` samples.

    Raises:
        InputError: a friction entry for a joint that is not torque-controlled; a temperature term without the
            options' temperature.
    """
    run = _IdealRun(robot, reference, injected_friction(robot, friction, terms), options)
    run.run(progress)
    return run.result()

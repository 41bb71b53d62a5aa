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

import numpy as np
import pinocchio as pin

from wbfriction.friction.models import FrictionParams
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, Recording, SimulationResult, injected_friction
from wbfriction.sim.control import contact_jacobian, gain_schedule, pd_gains, reference_feedforward
from wbfriction.sim.options import IdealOptions
from wbfriction.walking import WalkingReference
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


def _constraints(robot: Robot, data: pin.Data, active: np.ndarray, anchors: dict[int, pin.SE3],
                 baumgarte: tuple[float, float]) -> tuple[list, list]:
    """6D rigid constraints welding the ``active`` soles to their anchors, initialised in ``data``."""
    models = []
    for c in np.flatnonzero(active):
        fr = robot.model.frames[robot.contact_frame_ids[c]]
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, robot.model, fr.parentJoint, fr.placement,
                                      0, anchors[int(c)], pin.LOCAL)
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(*baumgarte))
        models.append(cm)
    datas = [cm.createData() for cm in models]
    pin.initConstraintDynamics(robot.model, data, models, datas)
    return models, datas


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
        self.kp_all, self.kd_all = gain_schedule(gains, reference.contact, dt, options.gain_blend)
        self.bkp, self.bkd = options.baumgarte

        iv, iq = robot.act_v_index, robot.act_q_index
        tc, self.pc = robot.tc_index, robot.pc_index
        self.iv_tc, self.iv_pc, self.iq_tc, self.iq_pc = iv[tc], iv[self.pc], iq[tc], iq[self.pc]
        self.joints_f = injected.joints
        self.iv_f = self.iv_tc[self.joints_f]
        self.settings = pin.ProximalSettings(1e-12, 1e-10, 50)
        self.semi_implicit = options.integrator == "semi-implicit"
        self.project_every_sample = options.projection == "sample"
        # the reference, contiguous per sample
        ref = reference
        self.ff_tc = np.ascontiguousarray(tau_ff[:, tc])
        self.q_ref_tc = np.ascontiguousarray(ref.q[:, self.iq_tc])
        self.v_ref_tc = np.ascontiguousarray(ref.v[:, self.iv_tc])
        self.q_ref_pc, self.v_ref_pc, self.a_ref_pc = ref.q[:, self.iq_pc], ref.v[:, self.iv_pc], ref.a[:, self.iv_pc]
        self.switches = set(np.flatnonzero(np.any(np.diff(ref.contact, axis=0, prepend=False), axis=1)).tolist())

        self.Q = np.empty((n, self.model.nq))
        self.V = np.empty((n, self.model.nv))
        self.A = np.empty((n, self.model.nv))
        self.recording = Recording(robot, reference, injected)
        self.q, self.v = ref.q[0].copy(), ref.v[0].copy()
        self.anchors: dict[int, pin.SE3] = {}
        self.active = np.zeros(len(robot.contact_frames), bool)
        self.tau_pc = tau_ff[0, self.pc].copy()
        self.tau = np.zeros(self.model.nv)
        self.tau_f: np.ndarray | None = None

    def sample(self, k: int) -> None:
        """Run the control period of sample ``k``: contact changes, projection, control, physics steps."""
        switch = k in self.switches
        if switch:
            self.switch_contacts(k)
        # velocity onto the constraints (plastic impact at touch-down, drift otherwise)
        if switch or self.project_every_sample:
            self.v = pin.impulseDynamics(self.model, self.data, self.q, self.v, self.cmodels, self.cdatas, 0.0,
                                         self.settings).copy()
        tau_cmd = self.control(k)
        for s in range(self.options.substeps):
            self.step(k, s == 0, tau_cmd)

    def switch_contacts(self, k: int) -> None:
        """Anchor the feet landing at sample ``k``, project onto them, and rebuild the contact constraints."""
        ref = self.ref
        landing = ref.contact[k] & ~self.active
        for c in np.flatnonzero(landing):
            self.anchors[int(c)] = foot_placement(ref.feet[k, c])  # planned footprint, flat, z = 0
        self.active = ref.contact[k].copy()
        if landing.any():
            self.q = _project_configuration(self.robot, self.data, self.q, self.active, self.anchors)
        self.cmodels, self.cdatas = _constraints(self.robot, self.data, self.active, self.anchors,
                                                 self.options.baumgarte)
        self.n_lam = 6 * int(self.active.sum())
        # one right-hand side per position-controlled joint (unit torque) and one for
        # the contacts' Baumgarte term
        self.rhs = np.zeros((self.n_lam + self.model.nv, self.pc.size + 1))
        self.rhs[self.n_lam + self.iv_pc, np.arange(self.pc.size)] = 1.0

    def control(self, k: int) -> np.ndarray:
        """The torque command of the torque-controlled joints at sample ``k``: feed-forward plus PD."""
        return (self.ff_tc[k] + self.kp_all[k] * (self.q_ref_tc[k] - self.q[self.iq_tc])
                + self.kd_all[k] * (self.v_ref_tc[k] - self.v[self.iv_tc]))

    def step(self, k: int, first: bool, tau_cmd: np.ndarray) -> None:
        """One physics step of period ``k`` under ``tau_cmd``; the ``first`` one is the logged sample."""
        a, X, lam = self.dynamics(first, tau_cmd)
        if self.pc.size:  # position-controlled joints: acceleration = reference, stabilised
            lam = self.position_control(k, a, X, lam)
        if first:
            self.record(k, tau_cmd, a, X, lam)
        h = self.h
        if self.semi_implicit:
            self.v = self.v + h * a
            self.q = pin.integrate(self.model, self.q, h * self.v)
        else:
            self.q = pin.integrate(self.model, self.q, h * self.v)
            self.v = self.v + h * a

    def dynamics(self, first: bool, tau_cmd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Constrained forward dynamics with friction: the acceleration, the KKT solves, the contact forces."""
        tau = self.tau
        tau[self.iv_tc] = tau_cmd
        if self.joints_f:
            self.tau_f = self.injected.torque(self.v[self.iv_f])
            tau[self.iv_f] += self.tau_f
        tau[self.iv_pc] = self.tau_pc
        a = pin.constraintDynamics(self.model, self.data, self.q, self.v, tau, self.cmodels, self.cdatas,
                                   self.settings).copy()
        if first:
            self.rhs[:self.n_lam, -1] = np.concatenate([self.bkp * cd.contact_placement_error.vector
                                                        + self.bkd * cd.contact_velocity_error.vector
                                                        for cd in self.cdatas])
        X = self.data.constraint_chol.solve(self.rhs)
        return a, X, self.data.lambda_c

    def position_control(self, k: int, a: np.ndarray, X: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """Give the position-controlled joints the reference acceleration (``a`` in place); the new forces."""
        n_lam, iv_pc = self.n_lam, self.iv_pc
        a_des = (self.a_ref_pc[k] + self.bkd * (self.v_ref_pc[k] - self.v[iv_pc])
                 + self.bkp * (self.q_ref_pc[k] - self.q[self.iq_pc]))
        delta = _solve_small(X[n_lam + iv_pc, :-1], a_des - a[iv_pc])
        a += X[n_lam:, :-1] @ delta
        lam = lam - X[:n_lam, :-1] @ delta
        self.tau_pc = self.tau_pc + delta
        return lam

    def record(self, k: int, tau_cmd: np.ndarray, a: np.ndarray, X: np.ndarray, lam: np.ndarray) -> None:
        """Log sample ``k``: the state, the true acceleration (without the Baumgarte term), torques, wrenches."""
        self.Q[k], self.V[k], self.A[k] = self.q, self.v, a + X[self.n_lam:, -1]
        self.recording.record_torques(k, tau_cmd, self.tau_f)
        # the wrenches that go with that acceleration (the Baumgarte term taken off both)
        self.recording.wrench[k, self.active] = (lam - X[:self.n_lam, -1]).reshape(-1, 6)

    def result(self) -> SimulationResult:
        """The log (planned contacts) and the result of the run."""
        # semi-implicit Euler at the log rate: the central second difference at k is the
        # acceleration tau[k] caused; otherwise the torque is held over several steps
        alignment = "sample" if self.semi_implicit and self.options.substeps == 1 else "zoh"
        return self.recording.result(self.Q, self.V, self.A, self.ref.contact.copy(),
                                     "wbfriction.sim.ideal.simulate_ideal", self.options, torque_alignment=alignment,
                                     log_sensors=self.options.force_torque, log_imu=self.options.imu)


def simulate_ideal(robot: Robot, reference: WalkingReference,
                   friction: dict[str, FrictionParams] | None = None,
                   options: IdealOptions = IdealOptions(), progress: Progress | None = None) -> SimulationResult:
    """Simulate a walk in the ideal simulator (module docstring).

    Args:
        robot: the robot the reference was planned for.
        reference: :func:`~wbfriction.walking.walking_reference` output.
        friction: parameters per torque-controlled joint name; default: the thesis's
            targets (Table 6.1) on the leg joint groups, none elsewhere.
        options: :class:`IdealOptions`.
        progress: optional callable receiving numbers of samples done.

    Returns:
        A :class:`SimulationResult` whose log has ``len(reference)`` samples.

    Raises:
        InputError: a friction entry for a joint that is not torque-controlled.
    """
    run = _IdealRun(robot, reference, injected_friction(robot, friction), options)
    for k in counted(len(reference), progress):
        run.sample(k)
    return run.result()

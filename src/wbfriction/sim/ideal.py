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

from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.friction.models import FrictionParams
from wbfriction.model.robot import Robot
from wbfriction.progress import counted
from wbfriction.sim.common import SimulationResult, injected_friction, simulated_log
from wbfriction.sim.control import contact_jacobian, gain_schedule, pd_gains, reference_feedforward
from wbfriction.walking import WalkingReference
from wbfriction.walking.swing import foot_placement

Integrator = Literal["semi-implicit", "explicit"]
"""Euler integration of the ideal simulator."""
INTEGRATORS: tuple[Integrator, ...] = get_args(Integrator)


@dataclass(frozen=True)
class IdealOptions:
    """Parameters of :func:`simulate_ideal`.

    Attributes:
        substeps: physics steps per control period (the study uses 10: see
            :data:`wbfriction.studies.simulation.SIMULATOR`).
        integrator: one of :data:`INTEGRATORS`. With one explicit Euler step per sample
            the central second difference at ``k`` is the acceleration of sample ``k - 1``,
            which no torque alignment matches (the thesis's setting: F_v up to 25 % off in
            the study); with several substeps the log approaches continuous time.
        bandwidth: joint PD bandwidth [Hz]; damping: its damping ratio.
        gain_blend: time over which PD gains rise to those of a new contact state [s]
            (a landing leg's small tracking error times the stance gains would
            otherwise pull the foot on the ground); falling gains apply at once.
        baumgarte: (Kp [1/s^2], Kd [1/s]) of the contact and position-control constraints.
        log_base: write the base pose to the log.
        projection: ``"sample"``: project the velocity onto the constraints at every
            logged sample (the logged state satisfies ``J v = 0`` exactly: ground truth to
            1e-9 N·m); ``"touch-down"``: only at contact changes, Baumgarte correcting the
            drift (truth to about 1e-4 N·m).
    """

    substeps: int = 1
    integrator: Integrator = "semi-implicit"
    bandwidth: float = 15.0
    damping: float = 0.9
    gain_blend: float = 0.1
    baumgarte: tuple[float, float] = (400.0, 40.0)
    log_base: bool = True
    projection: str = "sample"

    def __post_init__(self) -> None:
        if self.integrator not in INTEGRATORS:
            raise InputError(f"unknown integrator '{self.integrator}': choose one of {', '.join(INTEGRATORS)}")
        if self.projection not in ("sample", "touch-down"):
            raise InputError(f"unknown projection '{self.projection}': choose sample or touch-down")
        if self.substeps < 1:
            raise InputError(f"substeps must be at least 1, got {self.substeps}")


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
        e = np.concatenate([pin.log6(anchors[c].actInv(data.oMf[robot.contact_frame_ids[c]])).vector
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
                 baumgarte: tuple[float, float]):
    models = []
    for c in np.flatnonzero(active):
        fr = robot.model.frames[robot.contact_frame_ids[c]]
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, robot.model, fr.parentJoint, fr.placement,
                                      0, anchors[c], pin.LOCAL)
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(*baumgarte))
        models.append(cm)
    datas = [cm.createData() for cm in models]
    pin.initConstraintDynamics(robot.model, data, models, datas)
    return models, datas


def simulate_ideal(robot: Robot, reference: WalkingReference,
                   friction: dict[str, FrictionParams] | None = None,
                   options: IdealOptions = IdealOptions(), progress=None) -> SimulationResult:
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
    injected = injected_friction(robot, friction)
    model = robot.model
    data = model.createData()
    ref = reference
    n, dt = len(ref), ref.dt
    h = dt / options.substeps
    nc = len(robot.contact_frames)

    tau_ff = reference_feedforward(robot, ref)
    gains = pd_gains(robot, ref.q[0], options.bandwidth, options.damping)
    kp_all, kd_all = gain_schedule(gains, ref.contact, dt, options.gain_blend)
    bkp, bkd = options.baumgarte

    iv, iq = robot.act_v_index, robot.act_q_index
    tc, pc = robot.tc_index, robot.pc_index
    iv_tc, iv_pc, iq_tc, iq_pc = iv[tc], iv[pc], iq[tc], iq[pc]
    joints_f = injected.joints
    iv_f = iv_tc[joints_f]
    settings = pin.ProximalSettings(1e-12, 1e-10, 50)
    semi_implicit = options.integrator == "semi-implicit"
    project_every_sample = options.projection == "sample"
    # the reference, contiguous per sample
    ff_tc = np.ascontiguousarray(tau_ff[:, tc])
    q_ref_tc, v_ref_tc = np.ascontiguousarray(ref.q[:, iq_tc]), np.ascontiguousarray(ref.v[:, iv_tc])
    q_ref_pc, v_ref_pc, a_ref_pc = ref.q[:, iq_pc], ref.v[:, iv_pc], ref.a[:, iv_pc]
    switches = set(np.flatnonzero(np.any(np.diff(ref.contact, axis=0, prepend=False), axis=1)).tolist())

    Q = np.empty((n, model.nq))
    V = np.empty((n, model.nv))
    A = np.empty((n, model.nv))
    tau_log = np.empty((n, tc.size))
    tau_f_log = np.zeros((n, tc.size))
    wrench = np.zeros((n, nc, 6))
    q, v = ref.q[0].copy(), ref.v[0].copy()
    anchors: dict[int, pin.SE3] = {}
    active = np.zeros(nc, bool)
    tau_pc = tau_ff[0, pc].copy()
    tau = np.zeros(model.nv)
    for k in counted(n, progress):
        switch = k in switches
        if switch:
            landing = ref.contact[k] & ~active
            for c in np.flatnonzero(landing):
                anchors[c] = foot_placement(ref.feet[k, c])  # planned footprint, flat, z = 0
            active = ref.contact[k].copy()
            if landing.any():
                q = _project_configuration(robot, data, q, active, anchors)
            cmodels, cdatas = _constraints(robot, data, active, anchors, options.baumgarte)
            n_lam = 6 * int(active.sum())
            # one right-hand side per position-controlled joint (unit torque) and one for
            # the contacts' Baumgarte term
            rhs = np.zeros((n_lam + model.nv, pc.size + 1))
            rhs[n_lam + iv_pc, np.arange(pc.size)] = 1.0
        # velocity onto the constraints (plastic impact at touch-down, drift otherwise)
        if switch or project_every_sample:
            v = pin.impulseDynamics(model, data, q, v, cmodels, cdatas, 0.0, settings).copy()
        tau_cmd = ff_tc[k] + kp_all[k] * (q_ref_tc[k] - q[iq_tc]) + kd_all[k] * (v_ref_tc[k] - v[iv_tc])
        for s in range(options.substeps):
            first = s == 0
            tau[iv_tc] = tau_cmd
            if joints_f:
                tau_f = injected.torque(v[iv_f])
                tau[iv_f] += tau_f
            tau[iv_pc] = tau_pc
            a = pin.constraintDynamics(model, data, q, v, tau, cmodels, cdatas, settings).copy()
            if first:
                rhs[:n_lam, -1] = np.concatenate([bkp * cd.contact_placement_error.vector
                                                  + bkd * cd.contact_velocity_error.vector for cd in cdatas])
            X = data.constraint_chol.solve(rhs)
            lam = data.lambda_c
            if pc.size:  # position-controlled joints: acceleration = reference, stabilised
                a_des = a_ref_pc[k] + bkd * (v_ref_pc[k] - v[iv_pc]) + bkp * (q_ref_pc[k] - q[iq_pc])
                delta = _solve_small(X[n_lam + iv_pc, :-1], a_des - a[iv_pc])
                a += X[n_lam:, :-1] @ delta
                lam = lam - X[:n_lam, :-1] @ delta
                tau_pc = tau_pc + delta
            if first:  # the logged sample; true acceleration: without the Baumgarte term
                Q[k], V[k], A[k] = q, v, a + X[n_lam:, -1]
                tau_log[k] = tau_cmd
                if joints_f:
                    tau_f_log[k, joints_f] = tau_f
                wrench[k, active] = lam.reshape(-1, 6)
            if semi_implicit:
                v = v + h * a
                q = pin.integrate(model, q, h * v)
            else:
                q = pin.integrate(model, q, h * v)
                v = v + h * a

    # semi-implicit Euler at the log rate: the central second difference at k is the
    # acceleration tau[k] caused; otherwise the torque is held over several steps
    alignment = "sample" if semi_implicit and options.substeps == 1 else "zoh"
    log = simulated_log(robot, ref, Q, V, A, tau_log, tau_f_log, ref.contact.copy(), injected,
                        "wbfriction.sim.ideal.simulate_ideal", options, options.log_base, torque_alignment=alignment)
    return SimulationResult(log, wrench, Q, V, ref, tuple(robot.contact_frames))

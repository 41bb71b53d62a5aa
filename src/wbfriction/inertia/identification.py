"""The inertia model and the friction identified together from walking logs (thesis 2.4, ch. 8).

The thesis found its real-robot friction estimates limited by an inaccurate inertia
model, and proposed a direct identification of the dynamic parameters. The inverse
dynamics are linear in the bodies' inertial parameters
``pi_b = (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)`` (about the body's
joint frame; ``pin.Inertia.toDynamicParameters`` order) and, for a fixed tanh slope
``a``, in the Coulomb, viscous and offset parameters of the friction model (3.5)
without its Stribeck term.

**The equations that hold without the contact forces.** In single support the stance
foot is welded to the ground and the robot is a fixed-base tree rooted at it
(:mod:`wbfriction.model.stance`); every joint row of that tree's inverse dynamics is free of
the contact wrench (which acts at the root). That is the floating-base dynamics
projected into the null space of the stance foot's Jacobian, in the coordinates of the
joint velocities. For torque-controlled joint ``i``:

.. math::

    Y_i(q, \\dot q, \\ddot q)\\,\\pi + F_{v,i}\\,\\dot q_i + F_{c,i}\\tanh(a\\,\\dot q_i) + \\tau_{os,i}
    = \\tau_i - I_{a,i}\\,\\ddot q_i

(``Y`` from ``pin.computeJointTorqueRegressor`` on the stance-rooted tree, its columns
mapped back to the original bodies; ``I_a`` the armature; ``tau_f = -f(qd)`` as in
:mod:`wbfriction.friction.models`). Position-controlled joints' rows are left out: their
torques are not logged. Stacked over the samples, the system is compressed as it is
built (a QR factorization of the rows seen so far), so long logs need memory of the
size of the parameter vector only.

**Base parameters.** A walk does not excite every parameter; the identifiable
combinations are found numerically by QR with column pivoting of the compressed
regressor (:func:`base_parameters`).

**Physical consistency and prior.** Each body's parameters are written through the
log-Cholesky parametrisation (Rucker & Wensing, *Smooth parameterization of rigid-body
inertia*, IEEE RA-L 2022; ``pin.LogCholeskyParameters``), so every estimate is a
physical rigid body (positive mass, positive-definite pseudo-inertia: the triangle
inequalities hold). A Tikhonov prior pulls the inertias toward the given model where
the data say nothing: its weight is ``prior`` times the largest squared singular value
of the scaled regressor, so only directions weaker than ``sqrt(prior)`` of the
best-excited one follow the prior. The URDF says nothing of friction: the friction
parameters get only the vanishing weight :data:`~wbfriction.inertia.consistency.FRICTION_PRIOR` (which fixes those of a
joint that never moves). Pulled as hard as the inertias toward the friction that best
explains the data with the given model, they kept that model's error: on the demo's
walk, a 5.4 % error of an ankle's offset became 2.4 % without it. The problem is solved
with ``scipy.optimize.least_squares``.

**Choosing the prior.** Too weak a prior lets the barely excited bodies (arms that
hardly move in a walk) take any value that fits the noise of the model; too strong a
one keeps the model error. By default the weight is chosen from :data:`PRIOR_GRID` by
validation: fitted on the training samples but the last ``validation`` share of their
time span, scored by the torque residual on that share (contiguous in time, so that
neighbouring, correlated samples do not score their own fit), then refitted on all of
them. The compressed systems give every score without another pass over the log. The
weights are tried from strong to weak, and the search stops at the first weight that
scores worse than the best. (Each fit starts from the linear solution: started from a
neighbouring weight's, the non-linear solve stalls short of it.)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
from scipy.optimize import lsq_linear

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import EstimateOptions
from wbfriction.inertia.consistency import FRICTION, STRIBECK, ConsistentFit, fit_consistent, friction_lower_bounds
from wbfriction.inertia.least_squares import BaseParameters, CompressedLeastSquares, base_parameters
from wbfriction.inertia.regressor import body_parameters, stance_regressor, with_body_parameters
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.model.stance import stance_frame_pose
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics, measure
from wbfriction.signals.phases import segment

PRIOR_GRID = (1e-10, 1e-9, 1e-8, 1e-7, 1e-6)
"""Relative prior weights tried when :attr:`InertialOptions.prior` is None."""


@dataclass(frozen=True)
class InertialOptions:
    """Options of :func:`identify_inertia`.

    Attributes:
        tanh_slope: ``a`` of the Coulomb term ``F_c tanh(a qd)`` [s/rad].
        stribeck_velocity: ``v_s`` [rad/s] of a Stribeck term ``(F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2)``
            identified with the others (3.5 with ``delta_s = 2``; ``F_s - F_c = S F_c``), for
            example the one the acceleration route's fit found; None: no Stribeck term.
        stribeck_joints: the joints given the Stribeck term (None: every torque-controlled
            one). A joint that never moves faster than ``v_s`` cannot tell it from Coulomb
            friction: their columns would cancel with huge opposite values.
        stride: every ``stride``-th single-support sample enters the regression (1 kHz
            logs are far denser than the dynamics need).
        holdout: share of the log, at its end, kept out of the regression to compare the
            models' torque predictions.
        prior: relative weight of the prior toward the given model (:func:`fit_consistent`);
            None: chosen from :data:`PRIOR_GRID` by validation (module docstring).
        validation: share of the training samples' time span, at its end, that scores
            the priors of the grid.
        rank_tolerance: relative pivot below which a parameter is not identifiable
            (:func:`base_parameters`).
        min_mass: smallest mass a body's starting point gets [kg].
        block: samples per block of the compressed regression.
    """

    tanh_slope: float = 40.0
    stribeck_velocity: float | None = None
    stribeck_joints: tuple[str, ...] | None = None
    stride: int = 5
    holdout: float = 0.2
    prior: float | None = None
    validation: float = 0.25
    rank_tolerance: float = 1e-8
    min_mass: float = 1e-3
    block: int = 200


@dataclass
class TorqueFit:
    """RMS of measured minus predicted joint torques per torque-controlled joint [N·m]."""

    given: np.ndarray
    given_with_friction: np.ndarray
    identified: np.ndarray
    samples: int


@dataclass
class InertialIdentification:
    """What :func:`identify_inertia` found.

    Attributes:
        robot: the robot with the identified inertias (same structure as the given one).
        bodies: body names (the Pinocchio joint carrying each body) (nb,).
        pi_given, pi: inertial parameters of the given and identified model (nb, 10).
        friction_names: the friction parameters (:func:`friction_names`), k of them.
        friction: identified friction parameters per torque-controlled joint (n_tc, k).
        friction_given_model: the physical friction (:data:`~wbfriction.inertia.consistency.FRICTION_LOWER`) that best
            explains the data with the given inertias (n_tc, k).
        base: the base parameters, over ``(pi.ravel(), friction.ravel())``.
        holdout: torque predictions on the held-out samples.
        samples: single-support samples in the regression.
        message: the optimizer's.
        prior: the prior's relative weight used.
        prior_scores: with the prior chosen by validation, the RMS torque residual on the
            validation samples for each weight tried [N·m].
    """

    robot: Robot
    bodies: tuple[str, ...]
    pi_given: np.ndarray
    pi: np.ndarray
    friction_names: tuple[str, ...]
    friction: np.ndarray
    friction_given_model: np.ndarray
    base: BaseParameters
    holdout: TorqueFit
    samples: int
    message: str
    prior: float
    prior_scores: dict[float, float] = field(default_factory=dict)


def friction_names(options: InertialOptions) -> tuple[str, ...]:
    """The friction parameters identified per joint with ``options``."""
    return FRICTION + ((STRIBECK,) if options.stribeck_velocity is not None else ())


def _friction_columns(qd_tc: np.ndarray, options: InertialOptions, stribeck: np.ndarray | None = None) -> np.ndarray:
    """(N, n_tc, k n_tc): joint ``i``'s row holds ``qd_i, tanh(a qd_i), 1`` (and the Stribeck
    column ``tanh(a qd_i) exp(-(qd_i / v_s)^2)`` where ``stribeck[i]``, else zero) in its ``k``
    columns, ``f(qd) = columns @ params``."""
    n, m = qd_tc.shape
    k = len(friction_names(options))
    out = np.zeros((n, m, k * m))
    idx = np.arange(m)
    coulomb = np.tanh(options.tanh_slope * qd_tc)
    out[:, idx, k * idx] = qd_tc
    out[:, idx, k * idx + 1] = coulomb
    out[:, idx, k * idx + 2] = 1.0
    if k == 4:
        on = np.ones(m, dtype=bool) if stribeck is None else stribeck
        out[:, idx, k * idx + 3] = coulomb * np.exp(-(qd_tc / options.stribeck_velocity) ** 2) * on
    return out


def _split(robot: Robot, log: Log, est: EstimateOptions, opts: InertialOptions):
    """Per log part: its kinematics, stance, and the training, validation and held-out
    single-support rows."""
    span = log.time[-1] - log.time[0]
    cut = log.time[0] + (1.0 - opts.holdout) * span
    cut_validation = log.time[0] + (1.0 - opts.holdout) * (1.0 - opts.validation) * span
    out = []
    for part in log.parts():
        try:
            kin = measure(part, est.diff, compensate_delay=est.compensate_delay,
                          torque_alignment=est.torque_alignment, filtering=est.filtering)
        except InputError:
            continue  # too short for the scheme: nothing to learn from it
        phases = segment(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
        use = kin.valid & phases.keep
        train = np.zeros_like(use)
        idx = np.flatnonzero(use & (part.time < cut))
        train[idx[:: opts.stride]] = True
        held = use & (part.time >= cut)
        validation = train & (part.time >= cut_validation)
        out.append((kin, phases.stance, train & ~validation, validation, held))
    return out


def _rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, c: int, options: InertialOptions):
    """Regressor rows (rooted parameters), friction columns and right-hand side of samples ``r``."""
    reg = stance_regressor(robot, c)
    tc = robot.tc_index
    pose = stance_frame_pose(robot, reg.stance, kin.q[r], None if kin.base is None else kin.base[r])
    Y = reg.joint_rows(pose, kin.q[r], kin.qd[r], kin.qdd[r])[:, tc]
    stribeck = None if options.stribeck_joints is None else np.isin(robot.torque_controlled, options.stribeck_joints)
    F = _friction_columns(kin.qd[r][:, tc], options, stribeck)
    arm = robot.model.armature[robot.act_v_index][tc]
    b = kin.tau[r] - arm * kin.qdd[r][:, tc]
    return Y, F, b


def identify_inertia(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                     options: InertialOptions = InertialOptions(),
                     progress: Progress | None = None) -> InertialIdentification:
    """Identify every body's inertial parameters and the joints' Coulomb, viscous and
    offset friction from a walking log (module docstring), starting from and regularised
    toward ``robot``'s model.

    Args:
        robot: the given model.
        log: a log with single-support stretches.
        estimate_options: differentiation, torque alignment and phase margins, as for the
            friction estimate (:class:`~wbfriction.friction.estimate.EstimateOptions`).
        options: :class:`InertialOptions`.
        progress: optional callable receiving numbers of samples done.

    Returns:
        :class:`InertialIdentification`.

    Raises:
        InputError: no single-support sample to learn from, or none held out.
    """
    parts = _split(robot, log, estimate_options, options)
    nb, n_tc = robot.model.njoints - 1, len(robot.torque_controlled)
    k = len(friction_names(options))
    p_in = 10 * nb
    fitting = _system(robot, parts, 2, options, progress)
    validating = _system(robot, parts, 3, options, progress)
    samples = (fitting.rows + validating.rows) // n_tc
    if samples == 0:
        raise InputError(f"{log.source}: no single-support sample to identify the inertia model from")
    total = CompressedLeastSquares(fitting.n)
    for system in (fitting, validating):
        total.absorb(system)
    R, z = total.R, total.z
    pi0 = body_parameters(robot.model)
    # physical friction that best explains the data with the given inertias: the start, and the given model's best case
    friction0 = lsq_linear(R[:, p_in:], z - R[:, :p_in] @ pi0.ravel(), bounds=(friction_lower_bounds(k, n_tc), np.inf),
                           method="bvls").x.reshape(n_tc, k)
    base = base_parameters(R, options.rank_tolerance)
    prior, scores = options.prior, {}
    if prior is None:
        if fitting.rows == 0 or validating.rows == 0:
            raise InputError(f"{log.source}: too few single-support samples to choose the prior by validation "
                             "(give one)")
        for weight in sorted(PRIOR_GRID, reverse=True):  # strong to weak
            trial = fit_consistent(fitting.R, fitting.z, pi0, friction0, weight, options.min_mass)
            scores[weight] = validating.rms(np.concatenate([trial.pi.ravel(), trial.friction.ravel()]))
            if scores[weight] > min(scores.values()):
                break  # past the best weight: weaker priors only fit the noise more closely
        prior = min(scores, key=scores.__getitem__)
    fit = fit_consistent(R, z, pi0, friction0, prior, options.min_mass)
    if k == len(FRICTION) + 1 and options.stribeck_joints is not None:  # no column: no Stribeck term, not a bound
        fit.friction[~np.isin(robot.torque_controlled, options.stribeck_joints), -1] = 0.0
    identified = dataclasses.replace(robot, model=with_body_parameters(robot.model, fit.pi), cache={})
    holdout = _torque_fit(robot, parts, pi0, friction0, fit, options)
    if holdout.samples == 0:
        raise InputError(f"{log.source}: no single-support sample in the held-out {options.holdout:.0%} of the log")
    return InertialIdentification(identified, tuple(robot.model.names[1:]), pi0, fit.pi, friction_names(options),
                                  fit.friction, friction0, base, holdout, samples, fit.message, prior, scores)


def _system(robot: Robot, parts, which: int, options: InertialOptions,
            progress: Progress | None = None) -> CompressedLeastSquares:
    """The compressed system of the rows ``part[which]`` of every part (:func:`_split`), in
    the original bodies' parameters: per stance, built in its rooted parameters, then mapped."""
    nb, n_tc = robot.model.njoints - 1, len(robot.torque_controlled)
    k = len(friction_names(options))
    p = 10 * nb + k * n_tc
    systems = {c: CompressedLeastSquares(p) for c in range(len(robot.contact_frames))}
    for part in parts:
        kin, stance, rows = part[0], part[1], part[which]
        for c, system in systems.items():
            r = np.flatnonzero(rows & (stance == c))
            for start in range(0, r.size, options.block):
                rr = r[start:start + options.block]
                Y, F, b = _rows(robot, kin, rr, c, options)
                system.add(np.concatenate([Y, F], axis=2).reshape(-1, p), b.ravel())
                if progress is not None:
                    progress(rr.size)
    total = CompressedLeastSquares(p)
    for c, system in systems.items():
        if system.rows:
            total.absorb(system, scipy.linalg.block_diag(stance_regressor(robot, c).to_rooted, np.eye(k * n_tc)))
    return total


def _torque_fit(robot: Robot, parts, pi0: np.ndarray, friction0: np.ndarray, fit: ConsistentFit,
                options: InertialOptions) -> TorqueFit:
    """RMS torque errors of the given model (without and with its best friction) and of the
    identified one on the held-out samples."""
    n_tc = len(robot.torque_controlled)
    sq = np.zeros((3, n_tc))
    count = 0
    for part in parts:
        kin, stance, *_, rows = part
        for c in range(len(robot.contact_frames)):
            r = np.flatnonzero(rows & (stance == c))
            for start in range(0, r.size, 1000):
                rr = r[start:start + 1000]
                Y, F, b = _rows(robot, kin, rr, c, options)
                T = stance_regressor(robot, c).to_rooted
                given = Y @ (T @ pi0.ravel())
                preds = (given, given + F @ friction0.ravel(), Y @ (T @ fit.pi.ravel()) + F @ fit.friction.ravel())
                for k, pred in enumerate(preds):
                    sq[k] += np.sum((pred - b) ** 2, axis=0)
                count += rr.size
    rms = np.sqrt(sq / max(count, 1))
    return TorqueFit(rms[0], rms[1], rms[2], count)

"""The inertia model, friction and rotor inertia identified together from walking or arm logs (thesis 2.4, ch. 8).

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
joint velocities. (A fixed-base robot, an arm, is one permanent single support welded at its
root link.) For torque-controlled joint ``i``:

.. math::

    Y_i(q, \\dot q, \\ddot q)\\,\\pi + F_{v,i}\\,\\dot q_i + F_{c,i}\\tanh(a\\,\\dot q_i) + \\tau_{os,i}
    = \\tau_i - I_{a,i}\\,\\ddot q_i

(``Y`` from ``pin.computeJointTorqueRegressor`` on the stance-rooted tree, its columns
mapped back to the original bodies; ``I_a`` the armature; ``tau_f = -f(qd)`` as in
:mod:`wbfriction.friction.models`). Position-controlled joints' rows are left out: their
torques are not logged. Stacked over the samples, the system is compressed as it is
built (a QR factorization of the rows seen so far, each joint's over the columns its rows can
be non-zero in: :func:`_system`), so long logs need memory of the size of the parameter vector only.

**Base parameters.** A walk does not excite every parameter; the identifiable
combinations are found numerically by QR with column pivoting of the compressed
regressor (:func:`~wbfriction.inertia.least_squares.base_parameters`).

**Armature.** Torques from motor currents hold the drives' reflected rotor inertia: joint ``i``'s
row gains ``I_{a,i} qdd_i``. It is known (``model.armature``, the robot's ``[armature]``: moved to
the right-hand side), ignored (``"none"``: link-side torque sensors do not see it), or identified:
one column per joint, ``I_{a,i} >= 0``. (A first joint about the gravity axis cannot tell its
armature from its link's inertia about that axis: the two are reported as not excited together.)

**Physical consistency and prior.** Every estimate is a physical rigid body: each body's
pseudo-inertia is constrained positive semidefinite (positive mass, principal moments that satisfy
the triangle inequalities; the linear matrix inequality of Wensing et al., IEEE RA-L 2018), and keeps
a share of the given body's (``J(pi) - link_margin J(pi_0)`` semidefinite,
:attr:`~wbfriction.inertia.options.InertialOptions.link_margin`): a link stays a link where its data
determine only combinations with its neighbours (the base parameters). A Gaussian
prior pulls the model toward the given one where the data say little: its standard deviations are stated
on each body's mass, centre of mass and rotational inertia about the centre of mass, and on each joint's
armature and friction
(:class:`~wbfriction.inertia.consistency.PriorUncertainty`). Its weight is ``prior`` times the
residual variance of the data (the least-squares residual per row of the unregularised fit over the base
parameters, :func:`residual_variance`):
``prior = 1`` is the posterior of independent residuals; correlated ones (neighbouring samples, a
model error) count less, a larger ``prior``. (A prior scaled per parameter about the joint frame,
and weighted by ``1e-9`` of the largest squared singular value, let a real arm's masses carry
what its data asked of the regrouped parameters, down to -100 %:
:mod:`~wbfriction.inertia.consistency`.) The URDF says nothing of friction: the friction
parameters get a weak prior (a standard deviation of the joint's RMS torque) toward the friction
that best explains the data with the given model; it keeps a joint that hardly moves in the
training samples from a friction its motion elsewhere contradicts (a vanishing one let a joint of
the demo's walk take 38 N·m·s/rad). The problem is convex (a quadratic over semidefinite cones and bounds)
and is solved exactly by Clarabel (:func:`~wbfriction.inertia.consistency.fit_consistent`).

**What the data do not determine.** The parameters whose data information is below the prior's
(:func:`~wbfriction.inertia.excitation.unexcited_parameters`) are reported by body and parameter,
with the ones they act with: the fit keeps them near the prior.

**Choosing the prior.** Too weak a prior lets the barely excited bodies take any value that fits
the noise of the model; too strong a one keeps the model error. By default the weight is chosen
from :data:`PRIOR_GRID` by validation: fitted on the training samples but the last ``validation``
share of their time span, scored by the torque residual on that share (contiguous in time, so
that neighbouring, correlated samples do not score their own fit), then refitted on all of them.
The compressed systems give every score without another pass over the log, and one decomposition of the
training system's gives every weight's fit (:class:`~wbfriction.inertia.consistency.RegularisedProblem`). The
weights are tried from strong to weak, and the search stops at the first weight that scores worse than the
best; the weight chosen is the strongest whose score is within ``options.prior_tolerance`` (2 %) of the best. A
weaker prior is a model further from the given one, and has to earn it, as a richer friction model does under
``--model auto``: on the KUKA LWR4+ logs the scores of the weights 10 and 1 differ by less than that, and the
weaker prior predicted the held-out run 3 worse on three joints (the README's KUKA commands; derivations 15).

**Kept only where held-out data improve** (issue 24). On a log the given model already explains, the fit
moves the model by noise, and predicted held-out torques worse on most leg joints of a simulated walk. The
identified inertias are therefore kept per limb (an unbranched chain of bodies) only where the model predicts
the held-out samples better than the given model with its best friction (by 1 % over all joints, no
joint more than 5 % worse: :mod:`~wbfriction.inertia.validation`); the other limbs stay as given, and the
friction (and armature) is the one that best explains the training data with the inertias kept. A conic
solve that stops short of its minimum says so in the message (:class:`~wbfriction.fit.solver.SolverOutcome`),
and the gate is what keeps its result honest.

**Same bytes whatever the BLAS thread count** (issue 37). OpenBLAS's threads split the blocked QR
factorizations, the SVDs of the non-linear solve's steps and the long products differently from one
thread, and round differently: on a TALOS walk the compressed regressor's factor moved by 7 % of its
largest entry (in the rows of the dependent columns, which rounding sets), the pivoting chose other
columns among near ties and the fit before the gate ended up to 1.7 % apart, so that the URDF and the
JSON differed with the thread count. :func:`identify_inertia` therefore runs on one BLAS thread
(``threadpoolctl``); on a shared 2-core machine that was also several times faster
(``benchmarks/bench_identify.py --blas``). The figures that rounding alone would set are taken where
they do not depend on it: the residual over the base parameters, the condition number of the
identifiable part (:mod:`~wbfriction.inertia.least_squares`), and no information for a parameter
that acts only with others (:func:`~wbfriction.inertia.excitation.unexcited_parameters`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import pinocchio as pin
from threadpoolctl import threadpool_limits

from wbfriction.exceptions import InputError
from wbfriction.fit.solver import SolverOutcome
from wbfriction.friction.estimate import resolve_differentiation
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.consistency import (
    FRICTION,
    STRIBECK,
    Prior,
    RegularisedProblem,
    friction_lower_bounds,
    prior_model,
)
from wbfriction.inertia.excitation import Unexcited, parameter_names, unexcited_parameters
from wbfriction.inertia.least_squares import BaseParameters, CompressedLeastSquares
from wbfriction.inertia.options import ArmatureMode, InertialOptions
from wbfriction.inertia.regressor import body_parameters, stance_regressor, with_body_parameters
from wbfriction.inertia.validation import Validation, limbs, validate_groups
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.model.stance import stance_frame_pose
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics, measure
from wbfriction.signals.phases import segment
from wbfriction.signals.spectrum import amplitude_spectrum, longest_run

PRIOR_GRID = (1e4, 1e3, 1e2, 1e1, 1.0)
"""Weights of the prior, in units of the data's residual variance, tried when :attr:`InertialOptions.prior`
is None."""
PRIOR_TOLERANCE = 0.02
"""The prior chosen by validation is the strongest whose score is within this relative margin of the best: a
weaker prior, a model further from the given one, has to predict the validation samples better by more
(the parsimony of ``--model auto``, :data:`~wbfriction.fit.options.SELECTION_TOLERANCE`)."""
NOISY_ACCELERATION = 0.1
"""Share of a joint's acceleration power in the upper half of the band (above a quarter of the sampling
rate, where a robot's motion has next to none) from which the accelerations count as noisy
(:attr:`InertialIdentification.acceleration_noise`)."""
@dataclass
class TorqueFit:
    """RMS of measured minus predicted held-out joint torques per torque-controlled joint [N·m] (n_tc,):
    the given model (its armature included, no friction), the given model with its best friction (the
    physical friction, and armature when identified, that best explains the training data with the given
    inertias), the identified model (the fit's inertias and friction) and the validated one (the inertias
    the gate kept, :mod:`~wbfriction.inertia.validation`, with their best friction: the model written)."""

    given: np.ndarray
    given_with_friction: np.ndarray
    identified: np.ndarray
    samples: int
    validated: np.ndarray | None = None


@dataclass
class InertialIdentification:
    """What :func:`identify_inertia` found.

    Attributes:
        robot: the robot with the validated inertias (same structure as the given one: the identified
            ones of the limbs the held-out data kept, the given ones elsewhere,
            :mod:`~wbfriction.inertia.validation`) and, with ``armature = "identify"``, the validated
            model's armature in its ``model.armature``.
        bodies: body names (the Pinocchio joint carrying each body) (nb,).
        pi_given, pi: inertial parameters of the given and the validated model (nb, 10) (about each
            body's joint frame, :func:`~wbfriction.inertia.regressor.body_parameters` order; kg, kg·m,
            kg·m^2): what is written to the URDF.
        friction_names: the friction parameters (:func:`friction_names`), k of them.
        friction: the validated model's friction per torque-controlled joint (n_tc, k): the physical
            friction that best explains the training data with its inertias (all limbs kept: the
            identified inertias'; none: :attr:`friction_given_model`).
        friction_given_model: the physical friction (:data:`~wbfriction.inertia.consistency.FRICTION_LOWER`) that best
            explains the data with the given inertias (n_tc, k).
        base: the base parameters, over ``(pi.ravel(), friction.ravel()[, armature])``.
        holdout: torque predictions on the held-out samples.
        samples: single-support samples in the regression.
        message: how the fit went, in words (the non-linear solver's stopping message translated,
            :func:`~wbfriction.fit.solver.explain_solver`, and the accelerations' noise).
        prior: the prior's weight used (in units of the residual variance).
        prior_scores: with the prior chosen by validation, the RMS torque residual on the
            validation samples for each weight tried [N·m].
        armature_mode: :attr:`InertialOptions.armature`.
        armature_given, armature: per torque-controlled joint, the model's and the one used or
            identified [kg·m^2] (n_tc,) (zeros with ``"none"``).
        unexcited: the parameters the data do not determine beyond the prior
            (:func:`~wbfriction.inertia.excitation.unexcited_parameters`).
        residual_std: RMS residual per row of the unregularised least squares over the base parameters
            [N·m] (the prior's unit; :func:`residual_variance`).
        acceleration_noise: per torque-controlled joint, the share of its acceleration's power (as
            differentiated) above a quarter of the sampling rate (n_tc,). Noise in the accelerations
            is noise in the regressor: least squares then shrinks every inertia toward zero (errors
            in variables); above :data:`NOISY_ACCELERATION` the message says so (filter them:
            ``diff = "auto"`` or ``"butterworth"``).
        pi_fit, friction_fit: the fit's inertial parameters (nb, 10) and friction (n_tc, k) before the gate.
        validation: the gate's decision per limb (:func:`~wbfriction.inertia.validation.validate_groups`).
        solver: why the non-linear solver stopped (:class:`~wbfriction.fit.solver.SolverOutcome`;
            ``raw`` empty when the linear solution was physical and no solver ran).
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
    armature_mode: ArmatureMode = "known"
    armature_given: np.ndarray = field(default_factory=lambda: np.zeros(0))
    armature: np.ndarray = field(default_factory=lambda: np.zeros(0))
    unexcited: tuple[Unexcited, ...] = ()
    residual_std: float = float("nan")
    acceleration_noise: np.ndarray = field(default_factory=lambda: np.zeros(0))
    pi_fit: np.ndarray = field(default_factory=lambda: np.zeros((0, 10)))
    friction_fit: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    validation: Validation | None = None
    solver: SolverOutcome | None = None


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


def _armature_columns(qdd_tc: np.ndarray) -> np.ndarray:
    """(N, n_tc, n_tc): joint ``i``'s row holds ``qdd_i`` in column ``i`` (the armature's)."""
    n, m = qdd_tc.shape
    out = np.zeros((n, m, m))
    out[:, np.arange(m), np.arange(m)] = qdd_tc
    return out


def given_armature(robot: Robot) -> np.ndarray:
    """The model's armature of the torque-controlled joints (n_tc,) [kg·m^2]."""
    return np.array(robot.model.armature[robot.act_v_index][robot.tc_index], dtype=float)


def armature_scale(robot: Robot) -> np.ndarray:
    """Per torque-controlled joint, the larger of its given armature and the largest diagonal entry
    of the given model's joint-space inertia over the actuated joints (armature left out) at the
    reference configuration (neutral if none) [kg·m^2] (n_tc,): the unit of the armature's prior. (A
    drive's reflected rotor inertia, its gear ratio squared times its rotor's, need not be smaller
    than its link's: a wrist joint's often is not.)"""
    model = pin.Model(robot.model)
    model.armature = np.zeros(model.nv)
    q = robot.q_reference if robot.q_reference is not None else pin.neutral(model)
    M = pin.crba(model, model.createData(), q)
    largest = float(np.max(np.diag(M)[robot.act_v_index]))
    return np.maximum(given_armature(robot), largest)


@dataclass
class _Part:
    """A log part's kinematics and stance, its single-support rows usable for the regression
    (``use``), and among them the training, validation and held-out rows (N,) (:func:`_split`)."""

    kin: MeasuredKinematics
    stance: np.ndarray
    use: np.ndarray
    train: np.ndarray
    validation: np.ndarray
    held: np.ndarray


def _split(robot: Robot, log: Log, est: EstimateOptions, opts: InertialOptions) -> list[_Part]:
    """Per log part: its kinematics, stance, and the training, validation and held-out
    single-support rows."""
    est, _ = resolve_differentiation(est, log)  # diff "auto": chosen once for the whole log
    assert est.diff != "auto"
    # the shares count recorded time, not the gaps between segments (a log made of several runs)
    active = _active_time(log)
    cut = (1.0 - opts.holdout) * active[-1]
    cut_validation = (1.0 - opts.holdout) * (1.0 - opts.validation) * active[-1]
    out = []
    for (a, b), part in zip(log.segments or [(0, len(log))], log.parts()):
        t_active = active[a:b]
        try:
            kin = measure(part, est.diff, compensate_delay=est.compensate_delay,
                          torque_alignment=est.torque_alignment, filtering=est.filtering, velocity=est.velocity)
        except InputError:
            continue  # too short for the scheme: nothing to learn from it
        phases = segment(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
        assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
        use = kin.valid & phases.keep
        train = np.zeros_like(use)
        idx = np.flatnonzero(use & (t_active < cut))
        train[idx[:: opts.stride]] = True
        held = use & (t_active >= cut)
        validation = train & (t_active >= cut_validation)
        out.append(_Part(kin, phases.stance, use, train & ~validation, validation, held))
    return out


def _active_time(log: Log) -> np.ndarray:
    """Time since the log's start without its gaps (N,) [s]: each segment continues where the last ended."""
    active = np.empty(len(log))
    start = 0.0
    for a, b in log.segments or [(0, len(log))]:
        active[a:b] = start + (log.time[a:b] - log.time[a])
        start = active[b - 1] + log.dt
    return active


@dataclass
class LogSamples:
    """What the identifications of one log with one given model share (the closed loop's passes differ
    only in the Stribeck term): the log's kinematics and its training, validation and held-out samples
    (:func:`_split`), made once by :func:`log_samples`. (The regressor rows are not kept: a long log's
    would need memory of the size of the data, which the compressed least squares avoids.)

    Attributes:
        robot: the given model.
        log: the log.
        key: the options the parts were split with (differentiation, holdout, validation, stride).
        parts: :func:`_split`'s parts.
    """

    robot: Robot
    log: Log
    key: tuple
    parts: list[_Part]

    def matches(self, robot: Robot, log: Log, estimate_options: EstimateOptions, options: InertialOptions) -> bool:
        """Whether these are the samples :func:`identify_inertia` would split from its arguments."""
        return self.robot is robot and self.log is log and self.key == _split_key(estimate_options, options)


def _split_key(estimate_options: EstimateOptions, options: InertialOptions) -> tuple:
    """The options :func:`_split` depends on."""
    return estimate_options, options.holdout, options.validation, options.stride


def log_samples(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                options: InertialOptions = InertialOptions()) -> LogSamples:
    """The samples several :func:`identify_inertia` calls on ``log`` with the given model ``robot`` share
    (:class:`LogSamples`); ``options``' Stribeck term may differ between the calls, not its holdout,
    validation or stride."""
    return LogSamples(robot, log, _split_key(estimate_options, options),
                      _split(robot, log, estimate_options, options))


def _rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, c: int, options: InertialOptions):
    """Regressor rows (rooted parameters), columns of the other parameters (friction, armature when
    identified) and right-hand side of samples ``r``."""
    reg = stance_regressor(robot, c)
    tc = robot.tc_index
    pose = stance_frame_pose(robot, reg.stance, kin.q[r], None if kin.base is None else kin.base[r])
    Y = reg.joint_rows(pose, kin.q[r], kin.qd[r], kin.qdd[r])[:, tc]
    stribeck = None if options.stribeck_joints is None else np.isin(robot.torque_controlled, options.stribeck_joints)
    C = _friction_columns(kin.qd[r][:, tc], options, stribeck)
    qdd_tc = kin.qdd[r][:, tc]
    b = kin.tau[r]
    if options.armature == "identify":
        C = np.concatenate([C, _armature_columns(qdd_tc)], axis=2)
    elif options.armature == "known":
        b = b - given_armature(robot) * qdd_tc
    return Y, C, b


def residual_variance(system: CompressedLeastSquares, base: BaseParameters) -> float:
    """The residual variance per row of the unregularised least squares [N·m^2]: the smallest residual
    over the base parameters ``base`` of ``system`` (its
    :meth:`~wbfriction.inertia.least_squares.CompressedLeastSquares.base_parameters`;
    :meth:`~wbfriction.inertia.least_squares.CompressedLeastSquares.residual`: not a figure of the rounding)
    over the rows left after them (at least 1e-12 of the mean square right-hand side)."""
    if system.rows == 0:
        return 0.0
    total = float(system.z @ system.z) + system.residual_floor
    return max(system.residual(base) / max(system.rows - base.count, 1), 1e-12 * total / system.rows)


def friction_scale(robot: Robot, torque_rms: np.ndarray, k: int) -> np.ndarray:
    """The unit of the friction's prior (n_tc, k): per torque-controlled joint its RMS torque
    ``torque_rms`` (n_tc,) [N·m] (at least 1e-3), over its velocity limit [rad/s] (1 if it has
    none) for ``F_v``; the order of :func:`friction_names`."""
    limit = robot.model.velocityLimit[robot.act_v_index[robot.tc_index]]
    limit = np.where(np.isfinite(limit) & (limit > 0), limit, 1.0)
    scale = np.repeat(np.maximum(torque_rms, 1e-3)[:, None], k, axis=1)
    scale[:, 0] /= limit
    return scale


def _prior(robot: Robot, pi0: np.ndarray, friction0: np.ndarray, torque_rms: np.ndarray,
           options: InertialOptions) -> Prior:
    """The prior: the given bodies, the given model's best friction and, when identified, the given
    armature (:class:`~wbfriction.inertia.consistency.PriorUncertainty`)."""
    k = friction0.shape[1]
    rest0 = friction0.ravel()
    std = options.uncertainty.friction * friction_scale(robot, torque_rms, k).ravel()
    if options.armature == "identify":
        rest0 = np.concatenate([rest0, given_armature(robot)])
        std = np.concatenate([std, options.uncertainty.armature * armature_scale(robot)])
    return prior_model(pi0, rest0, std, options.uncertainty, options.min_mass)


def identify_inertia(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                     options: InertialOptions = InertialOptions(),
                     progress: Progress | None = None, shared: LogSamples | None = None,
                     blas_threads: int | None = 1) -> InertialIdentification:
    """Identify every body's inertial parameters, the joints' Coulomb, viscous and offset friction
    and, if asked, their armature from a log with single-support stretches (a walk) or of a fixed-base
    robot (module docstring), starting from and regularised toward ``robot``'s model.

    Args:
        robot: the given model.
        log: a log with single-support stretches (any log of a fixed-base robot).
        estimate_options: differentiation, torque alignment and phase margins, as for the
            friction estimate (:class:`~wbfriction.friction.estimate.EstimateOptions`).
        options: :class:`InertialOptions`.
        progress: optional callable receiving numbers of samples done.
        shared: the log's samples shared with other identifications of the same log and given model
            (:func:`log_samples`: the closed loop's passes); None: split here.
        blas_threads: the BLAS threads the solves run on: 1 (module docstring, *Same bytes*: the result
            does not depend on the machine), or None: as many as the process has (faster on a large
            model; the last digits, and a limb's validation near its threshold, may then depend on them).

    Returns:
        :class:`InertialIdentification`: its ``robot``/``pi``/``friction`` are the validated model's (the
        identified limbs that predict held-out torques better, the given ones elsewhere; module docstring),
        ``pi_fit``/``friction_fit`` the fit's, ``validation`` the decision per limb.

    Raises:
        InputError: no single-support sample to learn from, or none held out.

    """
    if blas_threads is not None:
        with threadpool_limits(blas_threads, user_api="blas"):
            return identify_inertia(robot, log, estimate_options, options, progress, shared, None)
    if shared is None:
        shared = log_samples(robot, log, estimate_options, options)
    elif not shared.matches(robot, log, estimate_options, options):
        raise ValueError("samples split from another robot, log or options")
    parts = shared.parts
    nb, n_tc = robot.model.njoints - 1, len(robot.torque_controlled)
    k = len(friction_names(options))
    p_in = 10 * nb
    fitting = _system(robot, shared, "train", options, progress)
    validating = _system(robot, shared, "validation", options, progress)
    samples = (fitting.rows + validating.rows) // n_tc
    if samples == 0:
        raise InputError(f"{log.source}: no single-support sample to identify the inertia model from")
    total = CompressedLeastSquares(fitting.n)
    for system in (fitting, validating):
        total.absorb(system)
    R, z = total.R, total.z
    pi0 = body_parameters(robot.model)
    lower = np.concatenate([np.full(p_in, -np.inf), friction_lower_bounds(k, n_tc),
                            np.zeros(fitting.n - p_in - k * n_tc)])  # armature >= 0
    # physical friction (and armature) that best explains the data with the given inertias: the start,
    # and the given model's best case
    best_rest_of = _BestRest(R, z, lower, p_in, _own_columns(robot, options))
    friction0 = best_rest_of(pi0)[:k * n_tc].reshape(n_tc, k)
    prior_of = _prior(robot, pi0, friction0, _torque_rms(robot, parts), options)
    base = total.base_parameters(options.rank_tolerance)
    prior, scores = options.prior, {}
    if prior is None:
        if fitting.rows == 0 or validating.rows == 0:
            raise InputError(f"{log.source}: too few single-support samples to choose the prior by validation "
                             "(give one)")
        variance = residual_variance(fitting, fitting.base_parameters(options.rank_tolerance))
        trials = RegularisedProblem(fitting.R, fitting.z, prior_of, lower)  # one decomposition for every weight
        for weight in sorted(PRIOR_GRID, reverse=True):  # strong to weak
            trial = trials.fit(weight * variance, options.link_margin)
            scores[weight] = validating.rms(trial.x)
            if scores[weight] > min(scores.values()):
                break  # past the best weight: weaker priors only fit the noise more closely
        prior = max(w for w, score in scores.items() if score <= (1 + options.prior_tolerance) * min(scores.values()))
    variance = residual_variance(total, base)
    fit = RegularisedProblem(R, z, prior_of, lower).fit(prior * variance, options.link_margin)
    bodies = tuple(robot.model.names[1:])
    groups = limbs(robot.model)
    held = _held_out(robot, shared, pi0, fit.pi, groups, options)
    if held.samples == 0:
        raise InputError(f"{log.source}: no single-support sample in the held-out {options.holdout:.0%} of the log")
    best_rest: dict[tuple[bool, ...], np.ndarray] = {}

    def model_of(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inertias with the limbs ``mask`` identified, the others given, and their best friction."""
        key = tuple(bool(x) for x in mask)
        pi = pi0.copy()
        for g in np.flatnonzero(mask):
            pi[list(groups[g].bodies)] = fit.pi[list(groups[g].bodies)]
        if key not in best_rest:
            best_rest[key] = best_rest_of(pi)
        return pi, best_rest[key]

    validation = validate_groups(groups, bodies, robot.torque_controlled, held.measured,
                                 lambda mask: held.predict(mask, model_of(mask)[1]))
    pi_valid, rest_valid = model_of(validation.kept)
    rest_best = model_of(np.zeros(len(groups), dtype=bool))[1]
    friction0 = rest_best[:k * n_tc].reshape(n_tc, k)
    holdout = held.torque_fit(rest_best, fit.rest, validation.kept, rest_valid)
    friction_fit = fit.rest[:k * n_tc].reshape(n_tc, k).copy()
    friction = rest_valid[:k * n_tc].reshape(n_tc, k).copy()
    if k == len(FRICTION) + 1 and options.stribeck_joints is not None:  # no column: no Stribeck term, not a bound
        for f in (friction, friction_fit):
            f[~np.isin(robot.torque_controlled, options.stribeck_joints), -1] = 0.0
    arm_given = given_armature(robot)
    armature = {"identify": rest_valid[k * n_tc:], "known": arm_given, "none": np.zeros(n_tc)}[options.armature]
    model = with_body_parameters(robot.model, pi_valid)
    if options.armature == "identify":
        full = model.armature.copy()
        full[robot.act_v_index[robot.tc_index]] = armature
        model.armature = full
    identified = dataclasses.replace(robot, model=model, cache={})
    names = parameter_names(bodies, _rest_names(robot, options))
    unexcited = unexcited_parameters(R, prior_of, prior * variance, names)
    noise = acceleration_noise([(part.kin, part.use) for part in parts], robot.tc_index)
    solver = fit.solver or SolverOutcome("", None, True,
                                         "not needed: the linear least-squares solution is physically consistent")
    message = fit.message
    if not solver.converged:
        message += "; kept only where held-out data improve"
    if np.any(noise > NOISY_ACCELERATION):
        worst = int(np.argmax(noise))
        message += (f"; noisy accelerations ({robot.torque_controlled[worst]}: {noise[worst]:.0%} of their power "
                    f"above {0.25 / log.dt:.0f} Hz) shrink the identified inertias: filter them (diff 'auto' or "
                    "'butterworth')")
    return InertialIdentification(
        identified, bodies, pi0, pi_valid, friction_names(options), friction, friction0, base, holdout, samples,
        message, prior, scores, options.armature, arm_given, np.array(armature, dtype=float), unexcited,
        float(np.sqrt(variance)), noise, pi_fit=fit.pi, friction_fit=friction_fit, validation=validation,
        solver=solver)


class _BestRest:
    """The physical friction (and armature when identified) that best explains the compressed system
    ``R`` (p, p), ``z`` (p,) with given inertias: ``min |R_rest x - (z - R_in pi)|`` over ``x >= lower``.

    The problem splits by joint: a joint's friction and armature columns act on its own rows only, so
    the columns of two joints are orthogonal (``R_i^T R_j = A_i^T A_j = 0``) and each joint's
    parameters solve a bounded least squares of their own, here reduced to k x k (``R_j = Q_j T_j``):
    the same minimum as the whole bounded problem, for a few k x k solves instead of a p x (k n_tc)
    one per candidate model. A joint whose unbounded minimum keeps the bounds (the usual case) takes it
    by one triangular solve; the others by a bounded least squares (BVLS)."""

    def __init__(self, R: np.ndarray, z: np.ndarray, lower: np.ndarray, p_in: int, columns: np.ndarray):
        import scipy.linalg
        self.R, self.z, self.p_in = R, z, p_in
        self.columns = list(columns)  # each joint's own columns (:func:`_own_columns`)
        self.n_rest = R.shape[1] - p_in
        self.lower = lower[p_in:]
        self.factors = [scipy.linalg.qr(R[:, p_in + cols], mode="economic") for cols in self.columns]

    def __call__(self, pi: np.ndarray) -> np.ndarray:
        """The best rest parameters (k n_tc [+ n_tc],) for the inertias ``pi`` (nb, 10)."""
        import scipy.linalg
        from scipy.optimize import lsq_linear
        rhs = self.z - self.R[:, :self.p_in] @ pi.ravel()
        out = np.zeros(self.n_rest)
        for cols, (Q, T) in zip(self.columns, self.factors):
            y, lo = Q.T @ rhs, self.lower[cols]
            if not np.any(T):
                continue  # a joint without rows: nothing to fit
            pivots = np.abs(np.diag(T))
            if pivots.min() > 1e-12 * pivots.max():
                x = scipy.linalg.solve_triangular(T, y, check_finite=False)
                if np.all(x >= lo):
                    out[cols] = x
                    continue
            out[cols] = lsq_linear(T, y, bounds=(lo, np.full(len(cols), np.inf)), method="bvls").x
        return out


def acceleration_noise(stretches: list[tuple[MeasuredKinematics, np.ndarray]], columns: np.ndarray) -> np.ndarray:
    """Share of the power of the accelerations ``qdd[:, columns]`` above a quarter of the sampling
    rate (len(columns),), over the longest run of the rows each part's mask selects (the regression's:
    single support, impacts left out) (zeros without 8 such rows)."""
    high, total = np.zeros(len(columns)), np.zeros(len(columns))
    for kin, rows in stretches:
        a, b = longest_run(rows & np.all(np.isfinite(kin.qdd[:, columns]), axis=1))
        if b - a < 8:
            continue
        freq, amp = amplitude_spectrum(kin.qdd[a:b][:, columns], float(np.median(np.diff(kin.time))))
        power = amp ** 2
        high += power[freq > freq[-1] / 2].sum(axis=0)
        total += power[1:].sum(axis=0)
    return np.divide(high, total, out=np.zeros_like(high), where=total > 0)


def _torque_rms(robot: Robot, parts: list[_Part]) -> np.ndarray:
    """RMS measured torque of each torque-controlled joint over the regression's samples (n_tc,) [N·m]."""
    sq, count = np.zeros(len(robot.torque_controlled)), 0
    for part in parts:
        rows = part.train | part.validation
        sq += np.sum(part.kin.tau[rows] ** 2, axis=0)
        count += int(rows.sum())
    return np.sqrt(sq / max(count, 1))


def _rest_names(robot: Robot, options: InertialOptions) -> tuple[str, ...]:
    """``<joint>.<friction parameter>`` per torque-controlled joint, then ``<joint>.armature`` if identified."""
    names = tuple(f"{j}.{p}" for j in robot.torque_controlled for p in friction_names(options))
    if options.armature == "identify":
        names += tuple(f"{j}.armature" for j in robot.torque_controlled)
    return names


def _own_columns(robot: Robot, options: InertialOptions) -> np.ndarray:
    """Each torque-controlled joint's own columns among the parameters after the bodies' (n_tc, k[+1]):
    its ``k`` friction parameters, then its armature when identified (:func:`_rest_names`' order)."""
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    armature = [[k * n_tc + i] for i in range(n_tc)] if options.armature == "identify" else [[]] * n_tc
    return np.array([[k * i + c for c in range(k)] + armature[i] for i in range(n_tc)], dtype=int)


def _system(robot: Robot, samples: LogSamples, which: Literal["train", "validation"], options: InertialOptions,
            progress: Progress | None = None) -> CompressedLeastSquares:
    """The compressed system of the rows ``which`` of every part of ``samples`` (:func:`_split`), in
    the original bodies' parameters.

    Each joint's rows of each stance are compressed on their own, over the columns they can be non-zero in:
    the rooted bodies' parameters beyond the joint (:attr:`~wbfriction.inertia.regressor.StanceRegressor.pattern`)
    and its own friction and armature (:func:`_own_columns`). A QR costs the square of its columns per row, and
    a joint's row is zero in most of them (on TALOS 8 to 317 of the 330 inertial columns, all but 4 of the 120
    friction ones): about a tenth of the work of compressing the whole rows. The joints' factors are then mapped
    to the original parameters and merged in one QR (the stacked rows' least squares, the same up to rounding)."""
    p_in = 10 * (robot.model.njoints - 1)
    p = p_in + len(_rest_names(robot, options))
    own = _own_columns(robot, options)
    merged = []
    for c in range(len(robot.contact_frames)):
        reg = stance_regressor(robot, c)
        inertial = [np.flatnonzero(reg.pattern[i]) for i in robot.tc_index]
        systems = [CompressedLeastSquares(cols.size + own.shape[1], min_rows=4 * (cols.size + own.shape[1]))
                   for cols in inertial]
        for part in samples.parts:
            r = np.flatnonzero(getattr(part, which) & (part.stance == c))
            for start in range(0, r.size, options.block):
                rr = r[start:start + options.block]
                Y, C, b = _rows(robot, part.kin, rr, c, options)
                for i, system in enumerate(systems):
                    system.add(np.column_stack([Y[:, i, inertial[i]], C[:, i, own[i]]]), b[:, i])
                if progress is not None:
                    progress(rr.size)
        for i, system in enumerate(systems):
            to_joint = np.zeros((system.n, p))  # the joint's columns from the original parameters
            to_joint[:inertial[i].size, :p_in] = reg.to_rooted[inertial[i]]
            to_joint[np.arange(inertial[i].size, system.n), p_in + own[i]] = 1.0
            merged.append((system, to_joint))
    total = CompressedLeastSquares(p)
    total.absorb_all(merged)
    return total


@dataclass
class _HeldOut:
    """The held-out samples, stacked, in the form every candidate model's prediction needs [N·m]: the
    measured torques (less a known armature's share) ``measured`` (N, n_tc); the given inertias'
    prediction ``given`` (N, n_tc) and the given armature's share ``given_armature`` (N, n_tc, zeros
    unless identified); each limb's identified change of the prediction ``effects`` (n_groups, N, n_tc)
    (the torques are linear in the inertias); each joint's own friction (and armature) columns
    ``features`` (N, n_tc, k[+1]) (:func:`_friction_columns`, :func:`_armature_columns`)."""

    measured: np.ndarray
    given: np.ndarray
    effects: np.ndarray
    features: np.ndarray
    given_armature: np.ndarray
    armature: bool

    @property
    def samples(self) -> int:
        return int(self.measured.shape[0])

    def friction(self, rest: np.ndarray) -> np.ndarray:
        """The torques (N, n_tc) of the friction (and armature) ``rest`` (k per joint, then one armature
        per joint when identified: the regression's order)."""
        n_tc, kk = self.features.shape[1:]
        k = kk - int(self.armature)
        per_joint = rest[:k * n_tc].reshape(n_tc, k)
        if self.armature:
            per_joint = np.column_stack([per_joint, rest[k * n_tc:]])
        return np.einsum("nik,ik->ni", self.features, per_joint)

    def predict(self, mask: np.ndarray, rest: np.ndarray) -> np.ndarray:
        """The held-out torques (N, n_tc) of the given inertias with the limbs ``mask`` (n_groups,) identified,
        and the friction ``rest``."""
        return self.given + self.effects[np.asarray(mask, dtype=bool)].sum(axis=0) + self.friction(rest)

    def torque_fit(self, rest_best: np.ndarray, rest_fit: np.ndarray, kept: np.ndarray,
                   rest_valid: np.ndarray) -> TorqueFit:
        """Per joint RMS of the given model, it with ``rest_best``, the identified one (every limb, the fit's
        ``rest_fit``) and the validated one (the limbs ``kept``, ``rest_valid``)."""
        G = self.effects.shape[0]
        rms = lambda pred: np.sqrt(np.mean((pred - self.measured) ** 2, axis=0))  # noqa: E731
        return TorqueFit(rms(self.given + self.given_armature), rms(self.predict(np.zeros(G, bool), rest_best)),
                         rms(self.predict(np.ones(G, bool), rest_fit)), self.samples,
                         rms(self.predict(kept, rest_valid)))


def _held_out(robot: Robot, samples: LogSamples, pi0: np.ndarray, pi_fit: np.ndarray, groups,
              options: InertialOptions) -> _HeldOut:
    """The held-out samples' arrays (:class:`_HeldOut`) of the parts of ``samples``."""
    n_tc = len(robot.torque_controlled)
    arm = options.armature == "identify"
    cols = _own_columns(robot, options)
    idx = np.arange(n_tc)[:, None]
    deltas = []
    for g in groups:
        d = np.zeros_like(pi0)
        d[list(g.bodies)] = pi_fit[list(g.bodies)] - pi0[list(g.bodies)]
        deltas.append(d.ravel())
    D = np.array(deltas).T if deltas else np.zeros((pi0.size, 0))  # (10 nb, G)
    out: dict[str, list[np.ndarray]] = {"measured": [], "given": [], "effects": [], "features": [], "arm": []}
    for part in samples.parts:
        kin, stance, rows = part.kin, part.stance, part.held
        for c in range(len(robot.contact_frames)):
            r = np.flatnonzero(rows & (stance == c))
            for start in range(0, r.size, 1000):
                rr = r[start:start + 1000]
                Y, C, b = _rows(robot, kin, rr, c, options)
                T = stance_regressor(robot, c).to_rooted
                out["measured"].append(b)
                out["given"].append(Y @ (T @ pi0.ravel()))
                out["effects"].append(np.moveaxis(Y @ (T @ D), 2, 0))
                out["features"].append(C[:, idx, cols])
                qdd = kin.qdd[rr][:, robot.tc_index]
                out["arm"].append(given_armature(robot) * qdd if arm else np.zeros_like(qdd))
    kk = cols.shape[1]
    if not out["measured"]:
        empty = np.zeros((0, n_tc))
        return _HeldOut(empty, empty, np.zeros((len(groups), 0, n_tc)), np.zeros((0, n_tc, kk)), empty, arm)
    return _HeldOut(np.concatenate(out["measured"]), np.concatenate(out["given"]),
                    np.concatenate(out["effects"], axis=1), np.concatenate(out["features"]),
                    np.concatenate(out["arm"]), arm)

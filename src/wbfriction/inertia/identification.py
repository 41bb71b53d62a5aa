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
(:mod:`wbfriction.model.rerooted`); every joint row of that tree's inverse dynamics is free of
the contact wrench (which acts at the root). That is the floating-base dynamics
projected into the null space of the stance foot's Jacobian, in the coordinates of the
joint velocities. (A fixed-base robot, an arm, is one permanent single support welded at its
root link.) A robot on point feet (a quadruped, issue 56) gives no tree rooted at a foot; with its base's motion
measured (its logged pose, or the IMU), the floating model's joint rows hold every acceleration, and joint
``i``'s row is free of the contact forces wherever no foot whose force is unknown is down on its limb (a leg in the
air; a stance leg whose foot logs its 3-D force, moved to the right-hand side as ``J^T f``:
:func:`~wbfriction.inertia.rows.floating_rows`). For torque-controlled joint ``i``:

.. math::

    Y_i(q, \\dot q, \\ddot q)\\,\\pi + F_{v,i}\\,\\dot q_i + F_{c,i}\\tanh(a\\,\\dot q_i) + \\tau_{os,i}
    = \\tau_i - I_{a,i}\\,\\ddot q_i

(``Y`` from ``pin.computeJointTorqueRegressor`` on the stance-rooted tree, its columns
mapped back to the original bodies; ``I_a`` the armature; ``tau_f = -f(qd)`` as in
:mod:`wbfriction.friction.models`). Position-controlled joints' rows are left out: their
torques are not logged. Stacked over the samples, the system is compressed as it is
built (a QR factorization of the rows seen so far, each joint's over the columns its rows can
be non-zero in: :mod:`~wbfriction.inertia.system`), so long logs need memory of the size of the parameter
vector only.

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
parameters, :func:`~wbfriction.inertia.prior.residual_variance`):
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
from :data:`~wbfriction.inertia.prior.PRIOR_GRID` by validation (:func:`~wbfriction.inertia.prior.choose_prior`):
fitted on the training samples but the last ``validation`` share of their time span, scored by the torque
residual on that share (contiguous in time, so that neighbouring, correlated samples do not score their own
fit), then refitted on all of them.
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

import numpy as np
from threadpoolctl import threadpool_limits

from wbfriction.exceptions import InputError
from wbfriction.fit.solver import SolverOutcome
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.best_friction import BestRest
from wbfriction.inertia.consistency import ConsistentFit, RegularisedProblem
from wbfriction.inertia.excitation import Unexcited, parameter_names, unexcited_parameters
from wbfriction.inertia.held_out import TorqueFit, validate_limbs
from wbfriction.inertia.least_squares import BaseParameters, CompressedLeastSquares
from wbfriction.inertia.options import ArmatureMode, InertialOptions
from wbfriction.inertia.prior import choose_prior, given_prior, residual_variance
from wbfriction.inertia.regressor import body_parameters, with_body_parameters
from wbfriction.inertia.rows import (
    friction_names,
    given_armature,
    joint_friction,
    lower_bounds,
    own_columns,
    rest_names,
)
from wbfriction.inertia.samples import LogSamples, log_samples, one_way_joints, torque_rms, usable_samples
from wbfriction.inertia.system import compressed_system
from wbfriction.inertia.validation import Validation
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics
from wbfriction.signals.spectrum import amplitude_spectrum, longest_run

NOISY_ACCELERATION = 0.1
"""Share of a joint's acceleration power in the upper half of the band (above a quarter of the sampling
rate, where a robot's motion has next to none) from which the accelerations count as noisy
(:attr:`InertialIdentification.acceleration_noise`)."""


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
        friction_names: the friction parameters (:func:`~wbfriction.inertia.rows.friction_names`), k of them.
        friction: the validated model's friction per torque-controlled joint (n_tc, k): the physical
            friction that best explains the training data with its inertias (all limbs kept: the
            identified inertias'; none: :attr:`friction_given_model`).
        friction_given_model: the physical friction (:data:`~wbfriction.inertia.consistency.FRICTION_LOWER`) that best
            explains the data with the given inertias (n_tc, k).
        base: the base parameters, over ``(pi.ravel(), friction.ravel()[, armature])``.
        holdout: torque predictions on the held-out samples (:class:`~wbfriction.inertia.held_out.TorqueFit`).
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
            [N·m] (the prior's unit; :func:`~wbfriction.inertia.prior.residual_variance`).
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
            (:func:`~wbfriction.inertia.samples.log_samples`: the closed loop's passes); None: split here.
        blas_threads: the BLAS threads the solves run on: 1 (module docstring, *Same bytes*: the result
            does not depend on the machine), or None: as many as the process has (faster on a large
            model; the last digits, and a limb's validation near its threshold, may then depend on them).

    Returns:
        :class:`InertialIdentification`: its ``robot``/``pi``/``friction`` are the validated model's (the
        identified limbs that predict held-out torques better, the given ones elsewhere; module docstring),
        ``pi_fit``/``friction_fit`` the fit's, ``validation`` the decision per limb.

    Raises:
        InputError: no single-support sample to learn from (on point feet: no joint's row free of unknown contact
            forces), or none held out; a robot on point feet without the base's measured motion.

    """
    if blas_threads is not None:
        with threadpool_limits(blas_threads, user_api="blas"):
            return identify_inertia(robot, log, estimate_options, options, progress, shared, None)
    if shared is None:
        shared = log_samples(robot, log, estimate_options, options)
    elif not shared.matches(robot, log, estimate_options, options):
        raise ValueError("samples split from another robot, log or options")
    options = dataclasses.replace(options, one_way_joints=one_way_joints(robot, shared.parts))
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    fitting, validating, total, samples = training_systems(robot, shared, options, progress, log.source)
    pi0 = body_parameters(robot.model)
    lower = lower_bounds(robot, options)
    # physical friction (and armature) that best explains the data with the given inertias: the start,
    # and the given model's best case
    best_rest_of = BestRest(total.R, total.z, lower, pi0.size, own_columns(robot, options))
    friction0 = best_rest_of(pi0)[:k * n_tc].reshape(n_tc, k)
    prior_of = given_prior(robot, pi0, friction0, torque_rms(robot, shared.parts), options)
    base = total.base_parameters(options.rank_tolerance)
    prior, scores = choose_prior(fitting, validating, prior_of, lower, options, log.source)
    variance = residual_variance(total, base)
    fit = RegularisedProblem(total.R, total.z, prior_of, lower).fit(prior * variance, options.link_margin)
    gated = validate_limbs(robot, shared, pi0, fit, best_rest_of, options, log.source)
    armature = identified_armature(gated.rest, robot, options)
    bodies = tuple(robot.model.names[1:])
    unexcited = unexcited_parameters(total.R, prior_of, prior * variance,
                                     parameter_names(bodies, rest_names(robot, options)))
    noise = acceleration_noise([(part.kin, part.use) for part in shared.parts], robot.tc_index)
    solver = fit.solver or SolverOutcome("", None, True,
                                         "not needed: the linear least-squares solution is physically consistent")
    return InertialIdentification(
        validated_robot(robot, gated.pi, armature, options), bodies, pi0, gated.pi, friction_names(options),
        joint_friction(gated.rest, robot, options), gated.rest_given[:k * n_tc].reshape(n_tc, k), base,
        gated.holdout, samples, fit_message(fit, solver, noise, robot, log.dt, options), prior, scores,
        options.armature, given_armature(robot), np.array(armature, dtype=float), unexcited,
        float(np.sqrt(variance)), noise,
        pi_fit=fit.pi, friction_fit=joint_friction(fit.rest, robot, options), validation=gated.validation,
        solver=solver)


def training_systems(robot: Robot, samples: LogSamples, options: InertialOptions, progress: Progress | None = None,
                     source: str = "log") -> tuple[CompressedLeastSquares, CompressedLeastSquares,
                                                   CompressedLeastSquares, int]:
    """The compressed systems of the training rows, of the validation rows and of both
    (:func:`~wbfriction.inertia.system.compressed_system`), and the number of samples in them.

    Raises:
        InputError: no single-support sample in the training and validation rows (naming ``source``).
    """
    fitting = compressed_system(robot, samples, "train", options, progress)
    validating = compressed_system(robot, samples, "validation", options, progress)
    count = sum(int(np.sum((part.train | part.validation) & (part.stance >= 0))) for part in samples.parts)
    if count == 0:
        raise InputError(f"{source}: no {usable_samples(robot)} to identify the inertia model from")
    total = CompressedLeastSquares(fitting.n)
    for system in (fitting, validating):
        total.absorb(system)
    return fitting, validating, total, count


def identified_armature(rest: np.ndarray, robot: Robot, options: InertialOptions) -> np.ndarray:
    """The armature per torque-controlled joint (n_tc,) [kg·m^2] of a model whose parameters after the bodies' are
    ``rest``: its own with ``armature = "identify"``, the given one with ``"known"``, zeros with ``"none"``."""
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    return {"identify": rest[k * n_tc:], "known": given_armature(robot), "none": np.zeros(n_tc)}[options.armature]


def validated_robot(robot: Robot, pi: np.ndarray, armature: np.ndarray, options: InertialOptions) -> Robot:
    """``robot`` with the inertial parameters ``pi`` (nb, 10) and, with ``armature = "identify"``, the
    torque-controlled joints' ``armature`` (n_tc,) [kg·m^2] in its ``model.armature``."""
    model = with_body_parameters(robot.model, pi)
    if options.armature == "identify":
        full = model.armature.copy()
        full[robot.act_v_index[robot.tc_index]] = armature
        model.armature = full
    return dataclasses.replace(robot, model=model, cache={})


def fit_message(fit: ConsistentFit, solver: SolverOutcome, noise: np.ndarray, robot: Robot, dt: float,
                options: InertialOptions) -> str:
    """How the fit went, in words: the fit's message, the joints that moved one way
    (:attr:`~wbfriction.inertia.options.InertialOptions.one_way_joints`), that the gate keeps its result honest when
    the solver stopped short, and the worst joint's noisy accelerations (:data:`NOISY_ACCELERATION` of ``noise``
    (n_tc,), the log sampled every ``dt`` [s])."""
    message = fit.message
    if options.one_way_joints:
        message += (f"; {', '.join(options.one_way_joints)} moved one way: their offset held at 0, F_c their "
                    "friction's level")
    if not solver.converged:
        message += "; kept only where held-out data improve"
    if np.any(noise > NOISY_ACCELERATION):
        worst = int(np.argmax(noise))
        message += (f"; noisy accelerations ({robot.torque_controlled[worst]}: {noise[worst]:.0%} of their power "
                    f"above {0.25 / dt:.0f} Hz) shrink the identified inertias: filter them (diff 'auto' or "
                    "'butterworth')")
    return message


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

"""The identification's prior toward the given model, and its weight chosen by validation
(:mod:`wbfriction.inertia.identification`, *Physical consistency and prior* and *Choosing the prior*).

The prior is centred on the given bodies, the given model's best friction and, when identified, the given
armature; its standard deviations are stated per body (:class:`~wbfriction.inertia.options.PriorUncertainty`)
and, for the friction and armature, in units of each joint's own scale (:func:`friction_scale`,
:func:`armature_scale`). Its weight is in units of the data's residual variance (:func:`residual_variance`):
given, or chosen from :data:`PRIOR_GRID` by the torque residual on the validation samples
(:func:`choose_prior`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.inertia.consistency import Prior, RegularisedProblem, prior_model
from wbfriction.inertia.least_squares import BaseParameters, CompressedLeastSquares
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.rows import given_armature
from wbfriction.model.robot import Robot

PRIOR_GRID = (1e4, 1e3, 1e2, 1e1, 1.0)
"""Weights of the prior, in units of the data's residual variance, tried when :attr:`InertialOptions.prior`
is None."""
PRIOR_TOLERANCE = 0.02
"""The prior chosen by validation is the strongest whose score is within this relative margin of the best: a
weaker prior, a model further from the given one, has to predict the validation samples better by more
(the parsimony of ``--model auto``, :data:`~wbfriction.fit.options.SELECTION_TOLERANCE`)."""


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
    none) for ``F_v``; the order of :func:`~wbfriction.inertia.rows.friction_names`."""
    limit = robot.model.velocityLimit[robot.act_v_index[robot.tc_index]]
    limit = np.where(np.isfinite(limit) & (limit > 0), limit, 1.0)
    scale = np.repeat(np.maximum(torque_rms, 1e-3)[:, None], k, axis=1)
    scale[:, 0] /= limit
    return scale


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


def given_prior(robot: Robot, pi0: np.ndarray, friction0: np.ndarray, torque_rms: np.ndarray,
                options: InertialOptions) -> Prior:
    """The prior: the given bodies ``pi0`` (nb, 10), the given model's best friction ``friction0`` (n_tc, k) and,
    when identified, the given armature, with the standard deviations of ``options.uncertainty``
    (:class:`~wbfriction.inertia.consistency.PriorUncertainty`) in the units of :func:`friction_scale` (from the
    joints' RMS torques ``torque_rms`` (n_tc,) [N·m]) and :func:`armature_scale`."""
    k = friction0.shape[1]
    rest0 = friction0.ravel()
    std = options.uncertainty.friction * friction_scale(robot, torque_rms, k).ravel()
    if options.armature == "identify":
        rest0 = np.concatenate([rest0, given_armature(robot)])
        std = np.concatenate([std, options.uncertainty.armature * armature_scale(robot)])
    return prior_model(pi0, rest0, std, options.uncertainty, options.min_mass)


def choose_prior(fitting: CompressedLeastSquares, validating: CompressedLeastSquares, prior: Prior,
                 lower: np.ndarray, options: InertialOptions, source: str = "log") -> tuple[float, dict[float, float]]:
    """The prior's weight [units of the residual variance] and, when chosen here, each weight's score.

    ``options.prior`` if given (no scores). Otherwise the weights of :data:`PRIOR_GRID` are fitted on the
    ``fitting`` system (its residual variance the unit, :func:`residual_variance`), from strong to weak, and
    scored by the RMS torque residual of the ``validating`` system [N·m]; the search stops at the first weight
    that scores worse than the best; the weight chosen is the strongest within ``options.prior_tolerance`` of
    the best score (module docstring). One decomposition serves every weight
    (:class:`~wbfriction.inertia.consistency.RegularisedProblem`).

    Args:
        fitting, validating: the compressed systems of the training and the validation rows.
        prior: the prior (:func:`given_prior`).
        lower: lower bounds of the parameters (p,).
        options: :attr:`~InertialOptions.prior`, ``prior_tolerance``, ``rank_tolerance``, ``link_margin``.
        source: what names the log in errors.

    Raises:
        InputError: no prior given and no training or no validation rows to choose one on.
    """
    if options.prior is not None:
        return options.prior, {}
    if fitting.rows == 0 or validating.rows == 0:
        raise InputError(f"{source}: too few samples to learn from (single support; on point feet, a joint free of "
                         "unknown contact forces) to choose the prior by validation (give one)")
    variance = residual_variance(fitting, fitting.base_parameters(options.rank_tolerance))
    trials = RegularisedProblem(fitting.R, fitting.z, prior, lower)  # one decomposition for every weight
    scores: dict[float, float] = {}
    for weight in sorted(PRIOR_GRID, reverse=True):  # strong to weak
        trial = trials.fit(weight * variance, options.link_margin)
        scores[weight] = validating.rms(trial.x)
        if scores[weight] > min(scores.values()):
            break  # past the best weight: weaker priors only fit the noise more closely
    best = min(scores.values())
    return max(w for w, score in scores.items() if score <= (1 + options.prior_tolerance) * best), scores

"""The held-out samples (the end of the log, never used to identify) and the gate run on them: the identified
inertias kept per limb only where they predict the held-out torques better (:mod:`wbfriction.inertia.validation`;
:mod:`wbfriction.inertia.identification`, *Kept only where held-out data improve*).

The torques are linear in the inertias and in the friction: the held-out rows are stacked once
(:func:`held_out`), with each limb's identified change of the prediction, and every candidate model of the gate
(limbs identified or given, with the best friction of its inertias: :class:`LimbModels`) is predicted from them
without another pass over the log.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.inertia.best_friction import BestRest
from wbfriction.inertia.consistency import ConsistentFit
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.regressor import regressor_of, row_groups
from wbfriction.inertia.rows import friction_rows, given_armature, own_columns, row_mask, sample_rows
from wbfriction.inertia.samples import LogSamples, usable_samples
from wbfriction.inertia.validation import BodyGroup, Validation, limbs, validate_groups
from wbfriction.model.robot import Robot


@dataclass
class TorqueFit:
    """RMS of measured minus predicted held-out joint torques per torque-controlled joint [N·m] (n_tc,):
    the given model (its armature included, no friction), the given model with its best friction (the
    physical friction, and armature when identified, that best explains the training data with the given
    inertias), the identified model (the fit's inertias and friction) and the validated one (the inertias
    the gate kept, :mod:`~wbfriction.inertia.validation`, with their best friction: the model written), over
    ``samples`` held-out samples."""

    given: np.ndarray
    given_with_friction: np.ndarray
    identified: np.ndarray
    samples: int
    validated: np.ndarray | None = None


@dataclass
class HeldOut:
    """The held-out samples, stacked, in the form every candidate model's prediction needs [N·m]: the
    measured torques (less a known armature's share) ``measured`` (N, n_tc), NaN where a joint's row does not hold
    (point feet: :attr:`~wbfriction.inertia.samples.Part.rows`); the given inertias'
    prediction ``given`` (N, n_tc) and the given armature's share ``given_armature`` (N, n_tc, zeros
    unless identified); each limb's identified change of the prediction ``effects`` (n_groups, N, n_tc)
    (the torques are linear in the inertias); each joint's own friction (and armature) columns
    ``features`` (N, n_tc, k[+1]) (:func:`~wbfriction.inertia.rows.friction_columns`,
    :func:`~wbfriction.inertia.rows.armature_columns`)."""

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
        rms = lambda pred: np.sqrt(np.nanmean((pred - self.measured) ** 2, axis=0))  # noqa: E731
        return TorqueFit(rms(self.given + self.given_armature), rms(self.predict(np.zeros(G, bool), rest_best)),
                         rms(self.predict(np.ones(G, bool), rest_fit)), self.samples,
                         rms(self.predict(kept, rest_valid)))


def held_out(robot: Robot, samples: LogSamples, pi0: np.ndarray, pi_fit: np.ndarray, groups: Sequence[BodyGroup],
             options: InertialOptions) -> HeldOut:
    """The held-out samples' arrays (:class:`HeldOut`) of the parts of ``samples``, for the given inertias
    ``pi0`` (nb, 10) and the limbs ``groups`` of the fit's ``pi_fit`` (nb, 10)."""
    n_tc = len(robot.torque_controlled)
    arm = options.armature == "identify"
    cols = own_columns(robot, options)
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
        for c in row_groups(robot):
            r = np.flatnonzero(rows & (stance == c))
            features = friction_rows(robot, kin, r, options)  # once: a global smoother filters the whole part
            for start in range(0, r.size, 1000):
                rr = r[start:start + 1000]
                Y, C, b = sample_rows(robot, kin, rr, c, options, features[start:start + 1000])
                T = regressor_of(robot, c).to_rooted
                mask = row_mask(part.holds(rr), C, b)
                out["measured"].append(b if mask is None else np.where(mask, b, np.nan))
                out["given"].append(Y @ (T @ pi0.ravel()))
                out["effects"].append(np.moveaxis(Y @ (T @ D), 2, 0))
                out["features"].append(C[:, idx, cols] if mask is None else np.nan_to_num(C[:, idx, cols]))
                qdd = kin.qdd[rr][:, robot.tc_index]
                out["arm"].append(given_armature(robot) * qdd if arm else np.zeros_like(qdd))
    kk = cols.shape[1]
    if not out["measured"]:
        empty = np.zeros((0, n_tc))
        return HeldOut(empty, empty, np.zeros((len(groups), 0, n_tc)), np.zeros((0, n_tc, kk)), empty, arm)
    return HeldOut(np.concatenate(out["measured"]), np.concatenate(out["given"]),
                   np.concatenate(out["effects"], axis=1), np.concatenate(out["features"]),
                   np.concatenate(out["arm"]), arm)


class LimbModels:
    """The gate's candidate models: the inertias with the limbs of a mask identified (the fit's), the others given,
    and the best friction (and armature) of those inertias, each computed once.

    Args:
        pi0, pi_fit: the given and the fit's inertial parameters (nb, 10).
        groups: the limbs (:func:`~wbfriction.inertia.validation.limbs`).
        best_rest: the best friction of given inertias (:class:`~wbfriction.inertia.best_friction.BestRest`).
    """

    def __init__(self, pi0: np.ndarray, pi_fit: np.ndarray, groups: Sequence[BodyGroup], best_rest: BestRest):
        self.pi0, self.pi_fit, self.groups, self.best_rest = pi0, pi_fit, groups, best_rest
        self.rests: dict[tuple[bool, ...], np.ndarray] = {}

    def __call__(self, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inertias (nb, 10) with the limbs ``mask`` (n_groups,) identified, the others given, and their best
        friction (and armature) (k n_tc [+ n_tc],)."""
        key = tuple(bool(x) for x in mask)
        pi = self.pi0.copy()
        for g in np.flatnonzero(mask):
            bodies = list(self.groups[int(g)].bodies)
            pi[bodies] = self.pi_fit[bodies]
        if key not in self.rests:
            self.rests[key] = self.best_rest(pi)
        return pi, self.rests[key]


@dataclass(frozen=True)
class Gated:
    """What the gate kept (:func:`validate_limbs`).

    Attributes:
        validation: the decision per limb (:class:`~wbfriction.inertia.validation.Validation`).
        pi: the validated inertias (nb, 10): the kept limbs' identified, the others given.
        rest: their best friction (and armature) (k n_tc [+ n_tc],).
        rest_given: the given inertias' best friction (and armature) (k n_tc [+ n_tc],).
        holdout: the held-out torque RMS per joint of the given, identified and validated models.
    """

    validation: Validation
    pi: np.ndarray
    rest: np.ndarray
    rest_given: np.ndarray
    holdout: TorqueFit


def validate_limbs(robot: Robot, samples: LogSamples, pi0: np.ndarray, fit: ConsistentFit, best_rest: BestRest,
                   options: InertialOptions, source: str = "log") -> Gated:
    """Keep the fit's inertias per limb only where they predict the held-out samples better than the given model
    with its best friction (:func:`~wbfriction.inertia.validation.validate_groups`, on the robot's limbs).

    Args:
        robot: the given model.
        samples: the log's samples (their held-out rows).
        pi0: the given inertial parameters (nb, 10).
        fit: the identification's fit (inertias and friction over all the training rows).
        best_rest: the best friction of given inertias on the training rows.
        options: the identification's.
        source: what names the log in errors.

    Raises:
        InputError: no usable sample in the held-out share of the log
            (:func:`~wbfriction.inertia.samples.usable_samples`).
    """
    bodies = tuple(robot.model.names[1:])
    groups = limbs(robot.model)
    held = held_out(robot, samples, pi0, fit.pi, groups, options)
    if held.samples == 0:
        raise InputError(f"{source}: no {usable_samples(robot)} in the held-out {options.holdout:.0%} of the log")
    model_of = LimbModels(pi0, fit.pi, groups, best_rest)
    validation = validate_groups(groups, bodies, robot.torque_controlled, held.measured,
                                 lambda mask: held.predict(mask, model_of(mask)[1]))
    pi_valid, rest_valid = model_of(validation.kept)
    rest_best = model_of(np.zeros(len(groups), dtype=bool))[1]
    holdout = held.torque_fit(rest_best, fit.rest, validation.kept, rest_valid)
    return Gated(validation, pi_valid, rest_valid, rest_best, holdout)

"""Torques predicted by an inertia model and a friction model, against the measured ones.

A model of the robot's dynamics (the URDF's inertias, armature included) and of its friction
predicts each joint's torque from the measured motion,

.. math:: \\tau_{pred} = M(q)\\ddot q + h(q, \\dot q) - \\tau_{f,model}(\\dot q)
          = M(q)\\ddot q + h(q, \\dot q) + f(\\dot q),

(sign convention of :mod:`wbfriction.friction.models`: ``tau_f = -f(qd)``). The estimate
(5.13) is ``tau_f = M qdd + h - tau``, so the prediction error is the estimated friction less
the model's, ``tau - tau_pred = -(tau_f - tau_f,model)``: on a log the model was not fitted
on (held-out data), its RMS says how well the model *predicts*, the test a real robot's model
must pass (thesis ch. 7: exact in simulation, unphysical on the robot).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.fit.holdout import MIN_HELD_OUT, PredictionCheck, prediction_check, prediction_variance
from wbfriction.fit.joints import fit_joints, stick_margin
from wbfriction.fit.options import PASS_ROWS
from wbfriction.fit.ranges import OUTSIDE, RangeUse
from wbfriction.fit.result import FitResult
from wbfriction.fit.selection import held_out_residuals
from wbfriction.fit.solve import fitted_rows, model_gradient, shown_friction
from wbfriction.fit.status import MIN_SPEED, joint_speed
from wbfriction.fit.terms import TermFit, term_signals
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.noise import joint_noises


class FrictionCurve(Protocol):
    """Anything that gives the friction characteristic ``f(qd)`` [N·m] (a model's parameters)."""

    def f(self, qd: ArrayLike) -> np.ndarray: ...


@dataclass(frozen=True)
class TorquePrediction:
    """How well a model predicts a log's torques, per joint.

    Attributes:
        joints: joint names (n,).
        samples: valid samples per joint (n,).
        rms: RMS of measured - predicted torque with the friction model [N·m] (n,); NaN for a
            joint without a friction model or without a valid sample.
        rms_rigid_body: the same with the rigid-body model alone (no friction) [N·m] (n,).
        rms_torque: RMS of the measured torque itself [N·m] (n,), for scale.
        status: per joint, the status of the fit whose model predicts (:mod:`~wbfriction.fit.status`; "" when
            not known): a prediction by a fit that is not ``ok`` is no better than that fit.
        terms: per joint, the terms beyond velocity its model predicted with (:mod:`~wbfriction.fit.terms`).
        checks: per joint, whether the fit predicts this log as well as its noise and its standard errors allow
            (:func:`other_log_checks`), or None (not checked: no fit, the joint still in this log).
        ranges: per joint, where this log's signals leave the ranges its terms were fitted on
            (:meth:`~wbfriction.fit.terms.TermFit.range_use`), or None (no term kept). A joint ``ok`` by its fit
            but used well outside them (beyond a range by more than its width) has the status
            :data:`~wbfriction.fit.ranges.OUTSIDE` instead, whoever sets :attr:`status`.
    """

    joints: tuple[str, ...]
    samples: np.ndarray
    rms: np.ndarray
    rms_rigid_body: np.ndarray
    rms_torque: np.ndarray
    status: tuple[str, ...] = ()
    terms: tuple[tuple[str, ...], ...] = ()
    checks: tuple[PredictionCheck | None, ...] = ()
    ranges: tuple[RangeUse | None, ...] = ()

    def __post_init__(self) -> None:
        if self.status and self.ranges:  # a fit's ok does not cover a log beyond what it was fitted on
            object.__setattr__(self, "status", tuple(
                OUTSIDE if status == "ok" and use is not None and use.far else status
                for status, use in zip(self.status, self.ranges, strict=True)))

    def overall(self, rms: np.ndarray) -> float:
        """The RMS over every joint's valid samples of one of the per-joint RMS arrays (``rms`` or
        ``rms_rigid_body``), each joint weighted by its samples: the root of the pooled mean square [N·m]; the
        joints without a value (NaN) left out, NaN when none has one."""
        ok = np.isfinite(rms) & (self.samples > 0)
        if not ok.any():
            return float("nan")
        return float(np.sqrt(np.sum(self.samples[ok] * rms[ok] ** 2) / np.sum(self.samples[ok])))


def _rms(x: np.ndarray, valid: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x[valid] ** 2))) if valid.any() else float("nan")


def predicted_friction(est: FrictionEstimate, joint: int, curve: FrictionCurve | TermFit,
                       valid: np.ndarray) -> np.ndarray:
    """What a friction model predicts of the estimate ``est.tau_f[:, joint]`` [N·m] (N,), the sign convention's
    ``tau_f``: ``-f(qd)`` of a velocity model; a model with terms beyond velocity (:class:`TermFit`) on ``est``'s
    angles, loads and temperatures, the ripple and the offset included (:meth:`TermFit.torque`); through the
    estimate's smoother where it has one (the estimate is the friction seen through it), over the samples ``valid``
    (N,) bool (NaN where the smoother has no value). What :func:`predict_torques` scores and the report draws."""
    if isinstance(curve, TermFit):
        model = curve.torque(est.qd[:, joint], term_signals(est, joint))
    else:
        model = -curve.f(est.qd[:, joint])
    if est.smoother is not None:
        model = est.smoother(np.where(valid, model, np.nan)[:, None])[:, 0]
    return np.asarray(model, dtype=float)


def predict_torques(est: FrictionEstimate, friction: Mapping[str, FrictionCurve | TermFit],
                    tau: np.ndarray | None = None, source: str = "the friction table") -> TorquePrediction:
    """Torque prediction errors of a model on the valid samples of an estimate made with its inertias.

    Args:
        est: the friction estimate of a log, made with the model's URDF (its ``tau_f`` is
            ``M qdd + h - tau``); with a filtering scheme, the model goes through its smoother.
        friction: joint -> friction model (its ``f(qd)``), e.g. the fitted parameters of
            :func:`~wbfriction.fit.params_file.read_params`, or a model with terms beyond velocity
            (:class:`~wbfriction.fit.terms.TermFit`: its torque on ``est``'s angles, torques and temperatures,
            the ripple included; where they leave the ranges it was fitted on, :attr:`TorquePrediction.ranges`
            says so); joints without one get NaN.
        source: where ``est`` was read from, for the messages.

    Raises:
        InputError: a model with terms whose signals ``est`` lacks (naming the column).
        tau: the measured torques (N, n) [N·m], for :attr:`TorquePrediction.rms_torque` only
            (NaN if None).

    Returns:
        :class:`TorquePrediction`.
    """
    n = len(est.joints)
    rms, rigid, scale = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    samples = est.valid.sum(axis=0)
    ranges: list[RangeUse | None] = [None] * n
    for i, joint in enumerate(est.joints):
        valid = est.valid[:, i] & np.isfinite(est.tau_f[:, i])
        rigid[i] = _rms(est.tau_f[:, i], valid)
        if joint in friction:
            curve = friction[joint]
            if isinstance(curve, TermFit):  # with its terms beyond velocity, on this log's signals
                signals = term_signals(est, i)
                curve.check_signals(signals, joint, source)
                ranges[i] = curve.range_use(signals, valid, joint)
            model = predicted_friction(est, i, curve, valid)
            if est.smoother is not None:  # where the filter has no value
                valid &= np.isfinite(model)
            rms[i] = _rms(est.tau_f[:, i] - model, valid)
        if tau is not None:
            scale[i] = _rms(tau[:, i], valid)
    terms = tuple(m.kept if isinstance(m := friction.get(j), TermFit) else () for j in est.joints)
    return TorquePrediction(tuple(est.joints), samples, rms, rigid, scale, terms=terms, ranges=tuple(ranges))


FASTER = 1.25
"""A held-out log whose 95th percentile of speed is beyond this many times the fit's is said to be faster."""


def other_log_checks(est: FrictionEstimate, fits: Mapping[str, FitResult], name: str = "this log",
                     workers: int = 1) -> tuple[PredictionCheck | None, ...]:
    """Per joint of ``est`` (a log the fits were not fitted on, estimated with their inertias), whether its fit
    predicts it as well as the noise and its standard errors allow (:mod:`~wbfriction.fit.holdout`): the fit's
    model (with its terms where it kept some) against the same model fitted on ``est`` itself, on the samples that
    fit uses (the joint moving; where it may stick, static friction, no function of the velocity, left out), both
    as its expectation under this log's velocity noise and through its smoother. None for a joint without a fitted
    model, or still in this log (below :data:`~wbfriction.fit.status.MIN_SPEED`).

    Args:
        est: the held-out log's friction estimate.
        fits: the fits, by joint (``wbfriction fit`` of other logs).
        name: the log, as the reasons name it.
        workers: processes refitting the joints side by side.
    """
    joints = [j for j in est.joints if j in fits and fits[j].params is not None]
    idx = [est.joints.index(j) for j in joints]
    noise = joint_noises(est.metadata.get("noise"), est.estimation_route)
    refits = fit_joints(joints, est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx], smoother=est.smoother,
                        model=[fits[j].model for j in joints], noise=noise, stick_margin=stick_margin(est),
                        workers=workers, later=False,
                        pass_rows=max((fits[j].pass_rows for j in joints), default=PASS_ROWS))
    out: dict[str, PredictionCheck | None] = {}
    for j, i, refit in zip(joints, idx, refits):
        fit, qd, tau_f = fits[j], est.qd[:, i], est.tau_f[:, i]
        sigma = noise[j].velocity if j in noise else 0.0
        use = fitted_rows(qd, tau_f, est.valid[:, i], est.smoother, refit.stick_speed, stick_margin(est),
                          fit.pass_rows)[0]
        if refit.params is None or joint_speed(qd[use]) < MIN_SPEED or use.sum() < MIN_HELD_OUT:
            out[j] = None
            continue
        terms = fit.kept_terms
        if terms is not None:  # the model it predicts with, through the smoother as its velocity part
            model = terms.torque(qd, term_signals(est, i))
            if est.smoother is not None:
                model = est.smoother(model[:, None])[:, 0]
            e_model = (tau_f - model)[use]
        else:
            assert fit.params is not None
            e_model = held_out_residuals(fit.params, qd, tau_f, use, est.smoother, sigma)
        e_best = held_out_residuals(refit.params, qd, tau_f, use, est.smoother, sigma)
        variance = (0.0 if fit.covariance is None else
                    prediction_variance(model_gradient(fit, qd, use, est.smoother, sigma), fit.covariance))
        speed = joint_speed(qd[use])
        note = (f"it moves up to {speed:.2g} rad/s there (95 %), its fit's samples up to {fit.speed:.2g}: beyond the "
                "speeds it was fitted on" if fit.speed is not None and speed > FASTER * fit.speed else "")
        out[j] = prediction_check(name, e_model, e_best, variance, np.flatnonzero(use), note=note,
                                  friction=shown_friction(fit.reported(), qd[use]))
    return tuple(out.get(j) for j in est.joints)

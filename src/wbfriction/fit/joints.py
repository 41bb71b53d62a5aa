"""Every joint of a friction estimate fitted (:func:`fit_estimate`, :func:`fit_joints`): the joints' fits run in
parallel, each checked on the other route, on its later stretch and with its terms beyond velocity."""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any, cast

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.options import AUTO, PASS_ROWS, SELECTION_TOLERANCE, STICK_FLOOR, FitOptions, ModelChoice
from wbfriction.fit.ranges import FittedRanges
from wbfriction.fit.result import ROUTE_PARAMS, FitResult, check_routes
from wbfriction.fit.route_spread import route_spread
from wbfriction.fit.screen import gross_outliers
from wbfriction.fit.selection import SPREAD, fit_friction, later_stretch
from wbfriction.fit.smoothing import smoother_half_width
from wbfriction.fit.solve import fitted_rows, stick_speed
from wbfriction.fit.term_selection import fit_terms, refit_terms
from wbfriction.fit.terms import TermFit, term_signals
from wbfriction.fit.torque_scale import torque_scale_spread
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.families.registry import families
from wbfriction.friction.models import (
    ModelName,
    ModelParams,
    target_from_dict,
)
from wbfriction.friction.noise import JointNoise, joint_noises
from wbfriction.progress import Progress, Steps
from wbfriction.workers import process_pool


def _fit_column(args: tuple, later: bool = True) -> FitResult:
    """One joint's :func:`fit_friction` (a :func:`_column_tasks` task) and, with ``later``, its
    :func:`later_stretch`."""
    qd, tau_f, valid, kwargs = args
    fit = fit_friction(qd, tau_f, mask=valid, **kwargs)
    if later:
        fit.later = later_stretch(fit, qd, tau_f, valid, kwargs)
    return fit


def _fit_routes(args: tuple) -> tuple[FitResult, FitResult | None]:
    """One joint's fit (a :func:`_column_tasks` task) with its later stretch checked, and its model's fit on the
    other route's estimate (a task of that route, or None)."""
    task, other = args
    fit = _fit_column(task)
    if other is None:
        return fit, None
    qd, tau_f, valid, kwargs = other
    return fit, _fit_column((qd, tau_f, valid, {**kwargs, "model": fit.model}), later=False)


def _column_tasks(joints, qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray, models: Sequence[ModelChoice], *,
                  delta_s: float, min_samples: int, smoother, fixed: dict[str, float] | None,
                  selection_tolerance: float, noise: Mapping[str, JointNoise] | None,
                  stick_margin: int | None, still: ModelName | None = None,
                  pass_rows: float = PASS_ROWS, score_slow: bool = True,
                  stick_floor: float = STICK_FLOOR) -> list[tuple]:
    """One :func:`_fit_column` task per joint (:func:`fit_joints`'s arguments). With ``auto``, its candidates (every
    family) are loaded here, before the joints are fitted side by side: a plugin that gives none left out once, its
    one line said in this process (:meth:`~wbfriction.registry.Registry.kinds`)."""
    if AUTO in models:
        families()
    noise = noise or {}
    tasks = []
    for i, joint in enumerate(joints):
        jn = noise.get(joint)
        sigma = 0.0 if jn is None else jn.velocity
        stick = {} if stick_margin is None else {"stick": stick_speed(sigma, stick_floor), "stick_margin": stick_margin,
                                                 "pass_rows": pass_rows, "score_slow": score_slow}
        tasks.append((qd[:, i], tau_f[:, i], valid[:, i],
                      dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother, fixed=fixed,
                           model=models[i], selection_tolerance=selection_tolerance, velocity_noise=sigma, noise=jn,
                           still=still, **stick)))
    return tasks


def _run(fn, tasks: list, workers: int, progress: Progress | None = None) -> list:
    """``fn`` over ``tasks``, on ``workers`` processes side by side (one task at a time to each), in order;
    ``progress`` told of each result as it comes (in order)."""
    tell = progress or (lambda n: None)
    results = []
    if workers > 1 and len(tasks) > 1:
        with process_pool(min(workers, len(tasks)), "fork") as pool:
            for result in pool.map(fn, tasks):
                results.append(result)
                tell(1)
        return results
    for task in tasks:
        results.append(fn(task))
        tell(1)
    return results


def _with_truth(joints, fitted: list[FitResult], qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray,
                tau_f_true: np.ndarray | None, targets: Mapping[str, ModelParams] | None) -> list[FitResult]:
    """``fitted`` with their errors against the true friction and parameters, where known (:func:`fit_joints`)."""
    for i, (joint, res) in enumerate(zip(joints, fitted)):
        m = valid[:, i] & np.isfinite(tau_f[:, i]) & np.isfinite(qd[:, i])
        m &= ~gross_outliers(-tau_f[:, i], m)  # the samples the fit used
        if tau_f_true is not None and np.isfinite(tau_f_true[m, i]).all() and m.any():
            res.rms_error_vs_true = float(np.sqrt(np.mean((tau_f[m, i] - tau_f_true[m, i]) ** 2)))
            if res.params is not None:
                res.rms_model_vs_true = float(np.sqrt(np.mean((res.params.torque(qd[m, i]) - tau_f_true[m, i]) ** 2)))
        if targets and joint in targets:
            res.target = targets[joint]
    return fitted


def fit_joints(joints, qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray, *,
               tau_f_true: np.ndarray | None = None, targets: Mapping[str, ModelParams] | None = None,
               delta_s: float = 2.0, min_samples: int = 20, smoother=None,
               fixed: dict[str, float] | None = None, workers: int = 1,
               model: ModelChoice | Sequence[ModelName] = "thesis",
               selection_tolerance: float = SELECTION_TOLERANCE, noise: Mapping[str, JointNoise] | None = None,
               stick_margin: int | None = None, later: bool = True,
               pass_rows: float = PASS_ROWS) -> list[FitResult]:
    """Fit every joint of a friction estimate on its valid samples.

    Args:
        joints: names (n,).
        qd, tau_f, valid: (N, n) arrays of a :class:`~wbfriction.friction.estimate.FrictionEstimate`
            (the whole time series: with ``smoother`` the model is filtered along it).
        tau_f_true: (N, n) true friction (NaN columns for unknown) or None.
        targets: true parameters (any model's) per joint name, when known.
        smoother: the estimate's smoother (``FrictionEstimate.smoother``) or None.
        fixed: parameters held instead of fitted (:func:`fit_friction`).
        workers: processes fitting joints side by side (each fit is independent of the
            others: the results do not depend on it).
        model, selection_tolerance: the model, or ``auto`` and its tolerance (:func:`fit_friction`); or one model
            per joint.
        noise: what is known of each joint's noise (:func:`~wbfriction.friction.noise.joint_noises`): its velocity
            noise corrects the model (errors in variables) and sets the speed a joint may stick below, and the fit
            carries its Cramér-Rao bound; a joint without: neither.
        stick_margin: with it, samples within that many rows of a speed a joint may stick at
            (:func:`stick_speed`) are left out (:func:`stuck_rows`); None: none.
        later: each fit checked on its later stretch (:func:`later_stretch`).
        pass_rows: reversals crossing the sticking band within so many rows are not left out (:func:`stuck_rows`).

    Raises:
        InputError: what :func:`fit_friction` raises.
    """
    models = [model] * len(joints) if isinstance(model, str) else list(model)
    tasks = _column_tasks(joints, qd, tau_f, valid, cast(Sequence[ModelChoice], models), delta_s=delta_s,
                          min_samples=min_samples, smoother=smoother, fixed=fixed,
                          selection_tolerance=selection_tolerance, noise=noise, stick_margin=stick_margin,
                          pass_rows=pass_rows)
    fit = functools.partial(_fit_column, later=later)
    return _with_truth(joints, _run(fit, tasks, workers), qd, tau_f, valid, tau_f_true, targets)


def stick_margin(est: FrictionEstimate) -> int:
    """Rows a sticking sample reaches in ``est``'s fit (:func:`stuck_rows`): its smoother's half width, and the
    velocity filter's where the velocity went through another one (the momentum route), or the central difference's
    stencil without a smoother."""
    margin = smoother_half_width(est.smoother)
    if est.estimation_route == "momentum":  # the metadata the table was read with (its smoother checked them)
        margin += int(est.metadata["estimate_options"]["momentum"]["velocity_window"]) // 2
    elif est.smoother is None:
        margin += 1
    return margin


def no_sample_reason(est: FrictionEstimate) -> str:
    """Why a joint of ``est`` has no valid sample, in the estimate's terms: a humanoid's ``--mask swing`` counts a
    joint only while its leg swings (a leg that stood throughout has none, however far it moved)."""
    options = est.metadata.get("estimate_options", {})
    legs = est.contact is not None and est.contact.shape[1] == 2 and bool(np.any(est.phase == "single"))
    if legs and isinstance(options, dict) and options.get("mask") == "swing":
        return ("no valid sample: the estimate's --mask swing counts a joint only while its leg swings (estimate with "
                "--mask single to count its stance too)")
    return "no valid sample in the friction table"


def fit_estimate(est: FrictionEstimate, options: FitOptions = FitOptions(), *, workers: int = 1,
                 joints: Sequence[str] | None = None, fixed: dict[str, float] | None = None,
                 targets: Mapping[str, ModelParams] | None = None,
                 still: ModelName | None = None, progress: Steps | None = None) -> list[FitResult]:
    """Fit every joint of an estimate (:func:`fit_joints` on its valid samples, on ``workers``
    processes); its ``tau_f_true`` and ``friction_true`` metadata, when present (simulated
    logs), give the errors against truth.

    With the estimate's noise record (:func:`~wbfriction.friction.noise.noise_record`), each fit corrects the model
    for its velocity's noise, leaves out the samples where its joint may stick, and carries its Cramér-Rao bound.
    With the other route's estimate (:attr:`~wbfriction.friction.estimate.FrictionEstimate.route_check`), each
    joint's model is fitted there too and the two compared (:attr:`FitResult.route_check`,
    :func:`~wbfriction.fit.result.check_routes`).

    Args:
        options: the model, its choice and the fit's thresholds (:class:`~wbfriction.fit.options.FitOptions`;
            its defaults are ``wbfriction fit``'s).
        workers: processes fitting joints side by side.
        joints: the joints to fit (default: every one of the estimate), in this order.
        fixed: parameters held instead of fitted (:func:`fit_friction`).
        targets: the true parameters per joint, instead of the metadata's ``friction_true``.
        still: the model of a joint that hardly moved, instead of ``options``' named model (:func:`fit_friction`).
        progress: told of its stages, each counted in joints (:data:`~wbfriction.progress.Steps`): ``fit``, then
            ``terms`` (with ``options.terms``) and ``fallback fits`` (``auto``, where some fit is not ``ok``).

    Raises:
        InputError: ``friction_true`` metadata that are not a model's parameters; an unknown model or joint; a
            damaged noise record.
    """
    if targets is None:
        targets = {j: target_from_dict(p) for j, p in est.metadata.get("friction_true", {}).items()}
    names = list(est.joints if joints is None else joints)
    unknown = [j for j in names if j not in est.joints]
    if unknown:
        raise InputError(f"no joint '{unknown[0]}' in the friction estimate")
    idx = [est.joints.index(j) for j in names]
    record = est.metadata.get("noise")
    truth = None if est.tau_f_true is None else est.tau_f_true[:, idx]
    common: dict[str, Any] = dict(delta_s=options.delta_s, min_samples=options.min_samples, fixed=fixed,
                                  selection_tolerance=options.selection_tolerance, still=still,
                                  pass_rows=options.pass_rows, score_slow=options.score_slow,
                                  stick_floor=options.stick_floor)
    tasks = _column_tasks(names, est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx], [options.model] * len(idx),
                          smoother=est.smoother, noise=joint_noises(record, est.estimation_route),
                          stick_margin=stick_margin(est), **common)
    check = est.route_check
    others: Sequence[tuple | None] = [None] * len(idx)
    if check is not None:  # each joint's model fitted on the other route too, in the same task
        others = _column_tasks(names, check.qd[:, idx], check.tau_f[:, idx], check.valid[:, idx],
                               [options.model] * len(idx), smoother=check.smoother,
                               noise=joint_noises(record, check.estimation_route), stick_margin=stick_margin(check),
                               **common)
    pairs = _run(_fit_routes, list(zip(tasks, others)), workers, None if progress is None else
                 progress("fit", len(tasks), "joints"))
    fits = _with_truth(names, [fit for fit, _ in pairs], est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx], truth,
                       targets)
    checked = [other for _, other in pairs]
    for f, other, k in zip(fits, checked, idx):
        if f.params is None and not est.valid[:, k].any():
            f.message = no_sample_reason(est)
        f.route = est.estimation_route
        f.unmeasured = str(est.metadata.get("noise_unmeasured", ""))  # never ok then (issue 53)
        if check is not None and other is not None:
            other.route = check.estimation_route
            check_routes(f, other)
    if options.terms.terms:
        fits = _with_terms(fits, checked, tasks, others, est, idx, truth, targets, options,
                           None if progress is None else progress("terms", len(fits), "joints"))
    fits = _with_torque_source(fits, est)  # before the fallbacks: its spread can make a fit weak
    if options.model == AUTO:
        _with_fallbacks(fits, tasks, others, est, idx, truth, targets, workers, progress)
    return fits


def _with_terms(fits: list[FitResult], checked: Sequence[FitResult | None], tasks: list[tuple],
                others: Sequence[tuple | None], est: FrictionEstimate, idx: list[int], truth: np.ndarray | None,
                targets: Mapping[str, ModelParams] | None, options: FitOptions,
                progress: Progress | None = None) -> list[FitResult]:
    """``fits`` with their terms beyond velocity (:func:`_joint_terms`), each joint's velocity model chosen and fitted
    again with the terms' torque taken out while that predicts better (:data:`TERM_REFITS`, :func:`_better_refit`);
    ``progress`` told of each joint done."""
    fits = list(fits)
    names = [f.joint for f in fits]
    for k, (f, i, maybe) in enumerate(zip(fits, idx, checked)):
        f.terms = _joint_terms(est, i, f, maybe, options)
        for _ in range(TERM_REFITS):  # the velocity model chosen and fitted again with the terms' torque taken out
            if f.kept_terms is None:
                break
            task = _without_terms(tasks[k], f.kept_terms, est, i)
            refit = _with_truth([names[k]], [_fit_column(task)], est.qd[:, [i]], est.tau_f[:, [i]],
                                est.valid[:, [i]], None if truth is None else truth[:, [k]], targets)[0]
            refit.route, refit.route_check, refit.unmeasured = f.route, f.route_check, f.unmeasured
            refit.route_spread = {} if f.route_check is None else route_spread(
                refit.params.to_dict(), f.route_check.params, ROUTE_PARAMS) if refit.params is not None else {}
            if refit.params is None or not refit.success:  # a refit that did not converge: the fit before it
                break
            other_task = others[k]
            if other_task is not None and refit.model != f.model:  # the other route's refit of this model
                qd_o, tau_o, valid_o, kwargs_o = other_task
                maybe = _fit_column((qd_o, tau_o, valid_o, {**kwargs_o, "model": refit.model}), later=False)
            refit.terms = _joint_terms(est, i, refit, maybe, options)
            if not _better_refit(refit, f):
                break
            fits[k] = f = refit
        if progress is not None:
            progress(1)
    return fits


NO_FALLBACK: tuple[str, ...] = ("ok", "not excited")
"""Statuses of a fit chosen by ``model="auto"`` that get no :attr:`~wbfriction.fit.result.FitResult.fallback`:
``ok`` (it is what is used) and ``not excited`` (no friction in the data, whatever the family)."""


def _with_fallbacks(fits: list[FitResult], tasks: list[tuple], others: Sequence[tuple | None], est: FrictionEstimate,
                    idx: list[int], truth: np.ndarray | None, targets: Mapping[str, ModelParams] | None,
                    workers: int, progress: Steps | None = None) -> None:
    """Set :attr:`FitResult.fallback` of each fit chosen by ``model="auto"`` that is not ``ok``: the simplest family's
    fit of its column (its task of ``tasks``, and of ``others`` on the other route) with no terms, fitted side by side
    on ``workers`` processes as the chosen fits are, and checked as they are; none where the chosen fit is ``ok`` or
    not excited, or is that family's without terms.

    The family chosen predicted the held-out blocks better than this one (or kept terms that did): its F_c and F_v
    are where a model error the simplest fit does not resolve may put them. Their distance to that fit's is its model
    spread, whole (:func:`~wbfriction.fit.selection.family_spread` with the roles turned: another family that fits
    the data better carries its whole distance), so that a fit the data prefer another curve to is not ``ok`` on
    its tight statistical errors (on the project's crawl with 3-D foot forces, a hip's Coulomb-viscous fit was
    ``ok`` 15 % and 79 % off F_c and F_v beside a (3.5) fit 15 % and 16 % off, ``weak``)."""
    simplest = families()[0].name
    wanted = [k for k, f in enumerate(fits)
              if f.verdict().status not in NO_FALLBACK and not (f.model == simplest and f.kept_terms is None)]
    tell = None if progress is None or not wanted else progress("fallback fits", len(wanted), "joints")
    pairs = _run(_fit_routes, [((*tasks[k][:3], {**tasks[k][3], "model": simplest}), others[k]) for k in wanted],
                 workers, tell)
    for k, (simple, checked) in zip(wanted, pairs):
        fit, i = fits[k], idx[k]
        simple = _with_truth([fit.joint], [simple], est.qd[:, [i]], est.tau_f[:, [i]], est.valid[:, [i]],
                             None if truth is None else truth[:, [k]], targets)[0]
        simple.route, simple.unmeasured = fit.route, fit.unmeasured
        if checked is not None and est.route_check is not None:
            checked.route = est.route_check.estimation_route
            check_routes(simple, checked)
        chosen = fit.reported().params
        if simple.params is not None and chosen is not None:  # the chosen family predicts the held-out blocks better
            theirs, mine = chosen.to_dict(), simple.params.to_dict()
            simple.model_spread = {n: math.hypot(simple.model_spread.get(n, 0.0), abs(mine[n] - theirs[n]))
                                   for n in SPREAD if n in mine and n in theirs}
        fit.fallback = _with_torque_source([simple], est)[0]


def _with_torque_source(fits: list[FitResult], est: FrictionEstimate) -> list[FitResult]:
    """``fits`` with what their torque's source leaves unknown in their ``model_spread`` (in quadrature): F_v's
    :func:`delay_structure_spread`, and F_c's and F_v's from the torque's scale where the robot TOML gives its
    ``[torque_scale_sd]`` (:func:`~wbfriction.fit.torque_scale.torque_scale_spread`, on the samples each fit used)."""
    structure = delay_structure_spread(est.metadata)
    torque = est.metadata.get("torque_source") or {}
    scale_sd = (torque.get("scale_sd") or {}) if isinstance(torque, Mapping) else {}
    for f in fits:
        if f.params is None:
            continue
        unknown = [("F_v", structure[f.joint])] if f.joint in structure and "F_v" in f.params.names else []
        if f.joint in scale_sd and est.tau is not None:
            i = est.joints.index(f.joint)
            rows = fitted_rows(est.qd[:, i], est.tau_f[:, i], est.valid[:, i], est.smoother, f.stick_speed,
                               stick_margin(est), f.pass_rows)[0]
            free = [n for n, se in f.stderr.items() if np.isfinite(se) and se > 0 and not f.at_bound.get(n)]
            unknown += torque_scale_spread(f.params, est.qd[:, i], est.tau[:, i], rows, float(scale_sd[f.joint]),
                                           free, smoother=est.smoother, velocity_noise=f.velocity_noise,
                                           magnitudes=SPREAD).items()
        for n, v in unknown:
            f.model_spread = {**f.model_spread, n: math.hypot(f.model_spread.get(n, 0.0), v)}
    return fits


def delay_structure_spread(metadata: Mapping[str, Any]) -> dict[str, float]:
    """Per joint, the viscous coefficient [N·m·s/rad] by which an estimate's torque would differ had its PD drivers'
    delay held back the other part of their law (``kp delay``,
    :meth:`~wbfriction.model.pd.PdDriver.viscous_equivalent`), where the log the delay was identified on did not
    tell which (its ``torque_source`` metadata: ``delayed_known`` false); {} otherwise. On steady motion the
    friction's F_v takes that torque up whole, so it is F_v's model error
    (:attr:`~wbfriction.fit.result.FitResult.model_spread`; issue 63: on the real Aliengo, F_v 0 on ten joints with
    the set-points delayed, 0.14-0.61 with the torque, 0.33 higher where both are interior; ``kp delay`` 0.28)."""
    torque = metadata.get("torque_source") or {}
    if not isinstance(torque, Mapping) or torque.get("delayed_known") is not False:
        return {}
    return {str(j): float(v) for j, v in (torque.get("viscous_equivalent") or {}).items()}


UNUSABLE: tuple[str, ...] = ("failed", "at bound", "not excited")


def _better_refit(refit: FitResult, fit: FitResult) -> bool:
    """Whether a joint's refit with its terms' torque taken out (:data:`TERM_REFITS`) replaces ``fit``: its model with
    its terms predicts the later stretch no worse (:attr:`~wbfriction.fit.terms.TermFit.held_out_rms`), and its
    status is usable where ``fit``'s was (issue 52: on a UR10e's shoulder, its gravity load of 100 N·m, a refit ended
    at a bound 36 % off the published curve, the next one stopped at its evaluation limit)."""
    if refit.terms is None or fit.terms is None:
        return False
    if refit.verdict().status in UNUSABLE and fit.verdict().status not in UNUSABLE:
        return False
    return bool(refit.terms.held_out_rms[1] <= fit.terms.held_out_rms[1])


TERM_REFITS = 2
"""How many times a joint that kept terms has its velocity model chosen and fitted again on the estimate less the
terms' torque, and its terms fitted again with it (issue 52: chosen without the terms, the velocity model takes what
the load leaves: on the Panda with a load term on every joint, ``auto`` took a Coulomb-viscous model for a Stribeck
one, whose missing Stribeck drop then predicted another log 3 to 8 times worse than the noise)."""


def _without_terms(task: tuple, terms: TermFit, est: FrictionEstimate, i: int) -> tuple:
    """``task`` (a :func:`_column_tasks` task of joint column ``i`` of ``est``) with the estimate less the torque of
    ``terms``' kept terms (their part beyond the velocity model, the ripple included; through the estimate's smoother
    as the fit's model goes)."""
    qd, tau_f, valid, kwargs = task
    signals = term_signals(est, i)
    part = terms.torque(est.qd[:, i], signals) + terms.params.f(est.qd[:, i])  # tau_f = -f: the terms' share
    if est.smoother is not None:
        part = np.asarray(est.smoother(np.where(valid & np.isfinite(part), part, np.nan)[:, None]))[:, 0]
    ok = np.isfinite(part)
    return qd, np.where(ok, tau_f - np.where(ok, part, 0.0), np.nan), valid & ok, kwargs


def _joint_terms(est: FrictionEstimate, i: int, fit: FitResult, other: FitResult | None,
                 options: FitOptions) -> TermFit | None:
    """The terms beyond velocity of joint column ``i`` of ``est``
    (:func:`~wbfriction.fit.term_selection.fit_terms`) on the samples its fit used, and refitted on the other
    route's estimate with that route's model (``other``), with the ranges of its signals on those samples
    (:class:`~wbfriction.fit.ranges.FittedRanges`); None for a joint not fitted or not excited."""
    if fit.params is None or fit.verdict().status in ("not excited", "failed"):
        return None
    signals = term_signals(est, i)
    use = fitted_rows(est.qd[:, i], est.tau_f[:, i], est.valid[:, i], est.smoother, fit.stick_speed,
                      stick_margin(est), fit.pass_rows)[0]
    terms = fit_terms(fit.params, est.qd[:, i], est.tau_f[:, i], use, signals, options.terms, est.smoother)
    terms = replace(terms, ranges=FittedRanges.of(use, signals.q, signals.tau_load, signals.temperature))
    if terms.kept and fit.crb:  # adding terms can only raise the velocity coefficients' bound (issue 63)
        terms = replace(terms, stderr={n: max(se, fit.crb[n]) if np.isfinite(fit.crb.get(n, np.nan)) else se
                                       for n, se in terms.stderr.items()})
    check = est.route_check
    if check is not None and other is not None and other.params is not None and terms.kept:
        rows = fitted_rows(check.qd[:, i], check.tau_f[:, i], check.valid[:, i], check.smoother, other.stick_speed,
                           stick_margin(check), other.pass_rows)[0]
        terms = replace(terms, check=refit_terms(terms, other.params, check.qd[:, i], check.tau_f[:, i], rows, signals,
                                                 check.estimation_route, check.smoother))
    return terms

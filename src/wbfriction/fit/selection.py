"""The choice among the models by held-out error (``model="auto"``), and a joint's fit whatever its model.

The valid samples are cut into contiguous blocks in time; every third is held out
(:func:`~wbfriction.fit.regression.held_out_split`, deterministic), every friction family
(:func:`~wbfriction.friction.families.registry.families`: the built-in ones and those registered, simplest first) is
fitted on the others, and its RMS error on the held-out blocks compared (:func:`held_out_rms`). The simplest model
whose held-out RMS is within ``selection_tolerance`` (relative, default
:data:`~wbfriction.fit.options.SELECTION_TOLERANCE`) of the best is chosen (:func:`choose_model`, the reason recorded
in :class:`~wbfriction.fit.result.ModelSelection`) and fitted again on every valid sample, as if it had been named.
Whole blocks, not scattered samples, are held out: residuals correlated in time (filtered estimates) would otherwise
let the held-out error see the fit's noise. With too few samples to hold a block out, or for a joint that hardly
moved (below :data:`~wbfriction.fit.status.MIN_SPEED`: ``not excited``, no velocity model in its data), the simplest
model is fitted. A model with a parameter at a bound (a magnitude at zero included: in a richer model it has often
traded its level for a shape parameter) gives way to the best simpler one whose parameters are all interior unless it
predicts clearly better (:func:`prefer_interior`); a model with a transition its data do not resolve is no candidate
(:mod:`~wbfriction.fit.transition`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.holdout import (
    LATER,
    MIN_HELD_OUT,
    PredictionCheck,
    prediction_check,
    prediction_variance,
    split_later,
)
from wbfriction.fit.options import AUTO, PASS_ROWS, SELECTION_TOLERANCE
from wbfriction.fit.regression import (
    held_out_gain,
    held_out_split,
)
from wbfriction.fit.result import FitResult, HeldOutScore, ModelSelection
from wbfriction.fit.solve import (
    blas_controller,
    fit_model,
    fitted_rows,
    model_fixed,
    model_gradient,
    shown_friction,
)
from wbfriction.fit.status import MIN_SPEED, reverse_share, search_bounds
from wbfriction.fit.transition import unresolved
from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.registry import families, family
from wbfriction.friction.models import ModelName, ModelParamsBase
from wbfriction.friction.noise import JointNoise


def held_out_residuals(params: ModelParamsBase, qd: np.ndarray, tau_f: np.ndarray, rows: np.ndarray, smoother=None,
                       velocity_noise: float = 0.0) -> np.ndarray:
    """(model friction torque - ``tau_f``) [N·m] on the samples ``rows`` ((N,) bool), in time order (the model's
    torque is ``-f``: the residual is ``f + tau_f``).

    Args:
        params: a model's parameters (:data:`~wbfriction.friction.models.ModelParams`).
        qd, tau_f: the whole time series (N,) [rad/s], [N·m].
        rows: the samples scored.
        smoother: the estimate's smoother or None; the model goes through it along the whole
            series before it is scored, as in the fit.
        velocity_noise: the velocity's noise [rad/s]: the model's expectation under it, as in the fit
            (:mod:`~wbfriction.fit.eiv`).
    """
    f = family(params.model).expected_values(params.as_vector(), np.asarray(qd, dtype=float), velocity_noise,
                                             getattr(params, "delta_s", 2.0))
    if smoother is not None:
        f = smoother(f)
    return (f + np.asarray(tau_f, dtype=float))[np.asarray(rows, dtype=bool)]


def held_out_rms(params: ModelParamsBase, qd: np.ndarray, tau_f: np.ndarray, rows: np.ndarray, smoother=None,
                 velocity_noise: float = 0.0) -> float:
    """RMS [N·m] of :func:`held_out_residuals` (NaN for no sample)."""
    r = held_out_residuals(params, qd, tau_f, rows, smoother, velocity_noise)
    return float(np.sqrt(np.mean(r**2))) if r.size else float("nan")


GAIN_Z = 2.0
"""A model with a parameter at a bound must lower the held-out mean square by more than this many standard errors
of the lowering to be chosen over a simpler model whose parameters are all interior (:func:`prefer_interior`)."""


def choose_model(scores: tuple[HeldOutScore, ...], tolerance: float = SELECTION_TOLERANCE) -> tuple[ModelName, str]:
    """The simplest model (first in ``scores``) whose held-out RMS is within ``tolerance``
    (relative) of the smallest, and the reason, one sentence.

    Raises:
        InputError: no score is finite.
    """
    finite = [s for s in scores if np.isfinite(s.held_out_rms)]
    if not finite:
        raise InputError("no model could be scored on held-out samples")
    best = min(finite, key=lambda s: s.held_out_rms)
    chosen = next(s for s in finite if s.held_out_rms <= (1.0 + tolerance) * best.held_out_rms)
    rms = "held-out RMS [N·m]: " + ", ".join(f"{s.model} {s.held_out_rms:.4g}" for s in scores)
    if chosen is best:
        reason = f"{chosen.model}: the smallest held-out RMS"
        if scores.index(chosen) > 0:
            reason += f"; simpler models exceed it by more than {100 * tolerance:g} %"
    else:
        excess = 100.0 * (chosen.held_out_rms / best.held_out_rms - 1.0)
        reason = (f"{chosen.model}: the simplest model within {100 * tolerance:g} % of the smallest held-out RMS "
                  f"({best.model}'s; +{excess:.2g} %)")
    reason += f"; {rms}"
    return chosen.model, reason


def fit_friction(qd: np.ndarray, tau_f: np.ndarray, *, delta_s: float = 2.0, joint: str = "",
                 x0: np.ndarray | None = None, min_samples: int = 20, mask: np.ndarray | None = None,
                 smoother=None, fixed: dict[str, float] | None = None, model: str = "thesis",
                 selection_tolerance: float = SELECTION_TOLERANCE, velocity_noise: float = 0.0,
                 stick: float = 0.0, stick_margin: int = 0, pass_rows: float = PASS_ROWS,
                 score_slow: bool = True, noise: JointNoise | None = None,
                 still: ModelName | None = None) -> FitResult:
    """Fit a friction model to friction estimates of one joint (eq. 6.4).

    Args:
        qd: joint velocities (N,) [rad/s].
        tau_f: friction torques on the joint (N,) [N·m] (``tau_f = -f(qd)``).
        delta_s: Stribeck exponent, fixed (thesis: 2).
        joint: name, for the result.
        x0: a starting point in the order of the model's names (:data:`~wbfriction.friction.models.PARAM_NAMES`
            for (3.5)); by default the variable projection's (:func:`~wbfriction.fit.projection.projected_start`).
            Not with ``model="auto"``.
        min_samples: fewer samples give a result without parameters.
        mask: (N,) samples to fit (default: every finite one); gross outliers among them are
            left out and counted (:func:`~wbfriction.fit.screen.gross_outliers`,
            :attr:`FitResult.n_screened`).
        smoother: the zero-phase smoother ``tau_f`` went through
            (:attr:`~wbfriction.friction.estimate.FrictionEstimate.smoother`), or None; ``qd`` and
            ``tau_f`` are then whole time series, ``qd`` NaN where the estimate was left out
            of the smoothing, and the model goes through the same smoother before it is
            compared (module docstring). Samples where the smoothed model is undefined are
            not used.
        fixed: parameters held at a value instead of fitted (standard error 0), e.g.
            ``{"S": 0, "v_s": 0.1, "tau_os": 0}`` for a Coulomb-viscous model (3.5). With
            ``model="auto"`` each candidate holds those it has.
        model: a friction family's name (:func:`~wbfriction.friction.families.registry.family`): ``thesis`` (3.5),
            ``stribeck``, ``coulomb-viscous`` or one registered; or ``auto`` (chosen by held-out error among every
            family, module docstring).
        selection_tolerance: with ``auto``, the relative excess of held-out RMS over the best
            within which the simpler model is chosen.
        velocity_noise: the standard deviation of the noise in ``qd`` [rad/s]: the model compared is its expectation
            under that noise (errors in variables, :mod:`~wbfriction.fit.eiv`); 0: the model itself.
        stick, stick_margin, pass_rows: samples within ``stick_margin`` rows of a speed below ``stick`` [rad/s] are
            left out, but for reversals crossing that band within ``pass_rows`` rows (:func:`stuck_rows`), and
            counted (:attr:`FitResult.n_stuck`); 0: none. Not for a joint that hardly moved
            (:data:`~wbfriction.fit.status.MIN_SPEED`: ``not excited``), whose every sample gives its offset.
        score_slow: with ``auto``, the held-out blocks' samples left out that way are scored too (what ``predict``
            scores: a model with no Coulomb step there misses them).
        noise: what is known of the estimate's noise (:class:`~wbfriction.friction.noise.JointNoise`): the fit then
            carries its Cramér-Rao bound (:attr:`FitResult.crb`); None: no bound.
        still: the model fitted instead of the one named (from its own start, not ``x0``) when the joint hardly
            moved (status ``not excited``: its data hold no velocity model, only an offset; ``auto`` then takes the
            simplest model anyway); None: the model named.

    Returns:
        :class:`FitResult`.

    Raises:
        UnknownFamilyError: a model that is no family's (nor ``auto``).
        InputError: a name in ``fixed`` that is not the model's (for ``auto``: no model's), ``x0`` with ``auto``,
            a ``stribeck`` F_s held without F_c.
    """
    named = None if model == AUTO else family(model)
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use, screened, stuck, speed = fitted_rows(qd, tau_f, mask, smoother, stick, stick_margin, pass_rows)
    kwargs: dict[str, Any] = dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother,
                                  fixed=fixed, sigma=velocity_noise, noise=noise)
    # One BLAS thread: the solver's many small (N x p) factorizations run several times
    # slower on OpenBLAS's threads than on one (30 TALOS joints of a 10-step walk: 78 s
    # against 14 s on 2 cores); fit joints side by side instead (fit_estimate's workers).
    with blas_controller().limit(limits=1, user_api="blas"):
        if named is None:
            if x0 is not None:
                raise InputError("x0 needs a named model, not 'auto'")
            res = _fit_auto(qd, y, use, tolerance=selection_tolerance, speed=speed,
                            stuck=stuck if score_slow else None, **kwargs)
        else:
            res = fit_named(named, qd, y, use, x0=x0, still=still if speed < MIN_SPEED else None, **kwargs)
    res.n_screened, res.n_stuck = int(screened.sum()), int(stuck.sum())
    res.speed, res.velocity_noise, res.reverse = speed, float(velocity_noise), reverse_share(qd[use])
    res.stick_speed, res.pass_rows = float(stick), float(pass_rows)
    return res


def fit_named(fam: FrictionFamily, qd: np.ndarray, y: np.ndarray, use: np.ndarray, *, x0: np.ndarray | None,
              still: ModelName | None, fixed: dict[str, float] | None, **kwargs: Any) -> FitResult:
    """``fit_friction`` of the family ``fam`` named on the usable samples ``use`` of ``y = -tau_f``; with ``still``
    (a joint that hardly moved), that family instead, from its own start, holding those of ``fixed`` it has (the
    names held are checked against ``fam`` all the same). ``kwargs``: :func:`~wbfriction.fit.solve.fit_model`'s."""
    model = fam.name
    if still is not None:
        fam.check_fixed(fixed)
        model, x0, fixed = still, None, model_fixed(still, fixed)
    return fit_model(model, qd, y, use, x0=x0, fixed=fixed, **kwargs)


def _fit_auto(qd: np.ndarray, y: np.ndarray, use: np.ndarray, *, delta_s: float, joint: str, min_samples: int,
              smoother, fixed: dict[str, float] | None, tolerance: float, sigma: float = 0.0,
              noise: JointNoise | None = None, speed: float = np.inf,
              stuck: np.ndarray | None = None) -> FitResult:
    """``fit_friction(model="auto")`` on the usable samples ``use`` (module docstring); a joint whose ``speed``
    [rad/s] (:func:`fitted_rows`) is below :data:`~wbfriction.fit.status.MIN_SPEED` gets the simplest model. The
    candidates: every family (:func:`~wbfriction.friction.families.registry.families`), simplest first."""
    fixed = dict(fixed or {})
    candidates = [f.name for f in families()]
    known = {n for f in families() for n in f.names}
    if set(fixed) - known:
        raise InputError(f"unknown parameter(s) to fix: {', '.join(sorted(set(fixed) - known))}")
    held = {m: model_fixed(m, fixed) for m in candidates}
    kwargs = dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother, sigma=sigma)
    train, held_out = held_out_split(use)
    scored = held_out
    if stuck is not None and stuck.any():  # the slow samples of the held-out blocks are scored too (issue 52)
        _, scored = held_out_split(use | stuck)
        scored &= np.isfinite(qd) & np.isfinite(y)
    n_train, n_held_out = int(train.sum()), int(held_out.sum())
    simplest = candidates[0]
    why = None
    if min(n_train, n_held_out) < max(min_samples, 7):
        why = f"too few samples ({int(use.sum())}) to hold any out"
    elif speed < MIN_SPEED:
        why = (f"the joint hardly moved (|qd| at most {speed:.2g} rad/s on 95 % of its samples): no model can be "
               "chosen, its offset is what the data give")
    if why is not None:
        res = fit_model(simplest, qd, y, use, fixed=held[simplest], noise=noise, **kwargs)
        res.selection = ModelSelection(simplest, f"{simplest}: {why}", (), tolerance, n_train, n_held_out)
        return res
    trained = {m: fit_model(m, qd, y, train, fixed=held[m], **kwargs) for m in candidates}
    residuals = {m: held_out_residuals(r.params, qd, -y, scored, smoother, sigma) for m, r in trained.items()
                 if r.params is not None}
    scores = tuple(HeldOutScore(m, float(np.sqrt(np.mean(residuals[m] ** 2))) if m in residuals else float("nan"),
                                r.bounded(),
                                () if r.params is None else unresolved(r.params, qd[train], sigma))
                   for m, r in trained.items())
    # the choice among every candidate, an unresolved one included (how well the data can be fitted); where that
    # choice's transition is not resolved, the choice among those resolved
    eligible = tuple(s for s in scores if not s.unresolved) or scores
    chosen, reason = choose_model(scores, tolerance)
    if chosen not in {s.model for s in eligible}:
        chosen, reason = choose_model(eligible, tolerance)
    chosen, reason = prefer_interior(chosen, reason, eligible, residuals, np.flatnonzero(scored))
    left = [f"{s.model} ({'; '.join(s.unresolved)})" for s in scores if s.unresolved]
    if left:
        reason += "; not candidates, transitions the data do not resolve: " + ", ".join(left)
    res = fit_model(chosen, qd, y, use, fixed=held[chosen], noise=noise, **kwargs)  # as if the model had been named
    if res.params is not None and (bounded := search_bounds(res)):
        reason += f"; at a bound: {', '.join(bounded)}"
    res.selection = ModelSelection(chosen, reason, scores, tolerance, n_train, n_held_out)
    if res.params is not None:
        res.model_spread = family_spread(trained, chosen, {s.model for s in eligible}, residuals,
                                         np.flatnonzero(scored))
    return res


SPREAD = ("F_c", "F_v")
"""The magnitudes whose spread over the candidate families a fit carries (:func:`family_spread`)."""


def family_spread(trained: Mapping[ModelName, FitResult], chosen: ModelName, candidates: set[ModelName],
                  residuals: Mapping[ModelName, np.ndarray], rows: np.ndarray) -> dict[str, float]:
    """Per magnitude of :data:`SPREAD`, how far the model ``chosen``'s value may be from the joint's for a model error
    the data do not resolve [its unit]; {} without another candidate family.

    Each other candidate family ``m`` (fitted on the same training blocks, ``trained``; one that failed or whose
    transition the data do not resolve is none) puts the magnitude at a distance ``|theta_m - theta_chosen|``. Its
    curve is as far from the chosen one's as its held-out mean square exceeds it, ``G = RMS_m^2 - RMS_chosen^2``
    (``residuals``: each family's held-out residuals on the rows ``rows``, in time order); the chosen curve misses the
    data by ``E = RMS_chosen^2 - sigma^2`` beyond their noise (``sigma^2`` from the differences of adjacent held-out
    residuals: half their mean square, the white noise's variance, a slow model error cancelled). A model error of
    the chosen curve's own size ``sqrt(E)`` moves the magnitude by about ``|theta_m - theta_chosen| sqrt(E / G)``
    (the shift scaled from the other family's curve distance, to first order), at most the whole distance. The
    largest over the candidates is the spread.

    Why (issue 63): the held-out error tells which family predicts the estimate best, not which one's F_c and F_v
    are the joint's. Errors of the estimate that change with speed (a stance leg's soft contact, an inertia error)
    are fitted best by a richer curve, whose F_c and F_v then trade against its shape: on the project's crawl on soft
    point feet with 3-D foot forces, a (3.5) fit whose held-out RMS was 30 % below the Coulomb-viscous one's put F_c
    3.8 % off with a standard error of 0.7 %, the Coulomb-viscous fit 1.3 % off. A family that fits to the noise
    (``E`` near 0: the curve's shape is the data's) keeps its own standard error; one that misses the data by as much
    as the families differ carries their difference, and the standard error a user reads says so
    (:meth:`~wbfriction.fit.result.FitResult.read_stderr`).
    """
    mine = trained[chosen]
    if mine.params is None or not mine.success or chosen not in residuals:
        return {}
    r = np.asarray(residuals[chosen], dtype=float)
    rows = np.asarray(rows)
    adjacent = np.diff(rows) == 1
    noise = 0.5 * float(np.mean(np.diff(r)[adjacent] ** 2)) if adjacent.any() else 0.0
    mean_square = float(np.mean(r**2)) if r.size else float("nan")
    misfit = max(mean_square - noise, 0.0)
    values = mine.params.to_dict()
    spread: dict[str, float] = {}
    for m, other in trained.items():
        if m == chosen or m not in candidates or m not in residuals or other.params is None or not other.success:
            continue
        gap = float(np.mean(np.asarray(residuals[m], dtype=float) ** 2)) - mean_square
        share = 1.0 if gap <= misfit else math.sqrt(misfit / gap)
        theirs = other.params.to_dict()
        for n in SPREAD:
            if n in values and n in theirs and np.isfinite(theirs[n]) and np.isfinite(share):
                spread[n] = max(spread.get(n, 0.0), share * abs(float(values[n]) - float(theirs[n])))
    return spread


def prefer_interior(chosen: ModelName, reason: str, scores: tuple[HeldOutScore, ...],
                    residuals: dict[ModelName, np.ndarray], rows: np.ndarray) -> tuple[ModelName, str]:
    """The rule of issue 38: a model chosen with a parameter at a bound (:attr:`HeldOutScore.at_bound`, a magnitude at
    its floor of zero included) gives way to the best-scoring simpler model whose parameters are all interior, unless
    it lowers the held-out mean square by more than :data:`GAIN_Z` standard errors of that lowering
    (:func:`held_out_gain`)."""
    by_model = {s.model: s for s in scores}
    if not by_model[chosen].at_bound:
        return chosen, reason
    simpler = [s for s in scores[:[s.model for s in scores].index(chosen)]
               if not s.at_bound and s.model in residuals and np.isfinite(s.held_out_rms)]
    if not simpler:
        return chosen, reason
    alternative = min(simpler, key=lambda s: s.held_out_rms)
    gain, se = held_out_gain(residuals[alternative.model], residuals[chosen], rows)
    if gain > GAIN_Z * se:
        return chosen, reason + (f"; its held-out gain over {alternative.model} ({gain:.3g} N²·m², {gain / se:.1f} "
                                 f"standard errors) outweighs its bound ({', '.join(by_model[chosen].at_bound)})")
    scores_text = reason[reason.find("held-out RMS [N·m]:"):] if "held-out RMS [N·m]:" in reason else ""
    return alternative.model, (f"{alternative.model}: {chosen} leaves {', '.join(by_model[chosen].at_bound)} at a "
                               f"bound and lowers the held-out mean square by {gain:.3g} ± {se:.2g} N²·m², within "
                               f"{GAIN_Z:g} standard errors" + (f"; {scores_text}" if scores_text else ""))


def later_stretch(fit: FitResult, qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray,
                  kwargs: Mapping[str, Any]) -> PredictionCheck | None:
    """How ``fit`` (of :func:`fit_friction` on ``qd``, ``tau_f``, ``valid`` with ``kwargs``) predicts its later
    stretch (:mod:`~wbfriction.fit.holdout`): its model fitted on the samples before the last
    :data:`~wbfriction.fit.holdout.LATER` of those it used, with the same options, and scored on them; None for
    a fit without parameters, a joint that hardly moved, too few samples on either side or an early fit that failed.
    """
    if fit.params is None or fit.speed is None or fit.speed < MIN_SPEED or not fit.success:
        return None
    smoother, sigma = kwargs.get("smoother"), float(kwargs.get("velocity_noise", 0.0))
    use = fitted_rows(qd, tau_f, valid, smoother, fit.stick_speed, int(kwargs.get("stick_margin", 0)),
                      fit.pass_rows)[0]
    before, later = split_later(use, LATER)
    if int((use & before).sum()) < MIN_HELD_OUT or int(later.sum()) < MIN_HELD_OUT:
        return None
    # from the whole fit's optimum: the early samples' is near it (the grid search would find the same basin)
    early = fit_friction(qd, tau_f, mask=valid & before, **{**kwargs, "model": fit.model, "noise": None,
                                                             "x0": fit.params.as_vector(),
                                                             "fixed": model_fixed(fit.model, kwargs.get("fixed"))})
    if early.params is None or not early.success or early.covariance is None:
        return None
    share = round(float(later.sum()) / float(use.sum()), 3)
    return prediction_check(f"the last {100 * share:.0f} % of its samples",
                            held_out_residuals(early.params, qd, tau_f, later, smoother, sigma),
                            held_out_residuals(fit.params, qd, tau_f, later, smoother, sigma),
                            prediction_variance(model_gradient(early, qd, later, smoother, sigma), early.covariance),
                            np.flatnonzero(later), share, friction=shown_friction(fit, qd[later]))

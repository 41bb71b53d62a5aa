"""Which terms beyond velocity a joint keeps, and their fit (issue 40; the terms themselves:
:mod:`~wbfriction.fit.terms`).

**Which terms are kept**: stepwise selection on blocked held-out samples (the split of the model choice,
:func:`~wbfriction.fit.regression.held_out_split`), with the model choice's rule: forward, the term that lowers the
held-out RMS most joins while it lowers it by more than :attr:`TermOptions.tolerance`; backward, a term whose
leaving raises it by less leaves (a load term that stood in for a ripple, their regressors alike); the ripple has
the fewest harmonics whose held-out RMS is within the tolerance of the smallest. The load and temperature terms,
like the ripple, are tried only where, fitted on the samples moving one way, they predict those moving the other
(:func:`direction_gain`): a law of the load or the temperature holds both ways, a residual that follows a repeated
trajectory does not (on the KUKA LWR4+, the rigid-body torque's "load" term on lwr_2 passed the held-out blocks,
whose twins were in training, and made run 3 worse by 6 %). Then every coefficient is fitted on every sample, with
standard errors from the fit's Newey-West sandwich; the velocity model's magnitudes (F_c, F_v) that the terms would
drive below zero are held at zero (:attr:`~wbfriction.fit.terms.TermFit.at_bound`).

The temperature term's law (linear or exponential, :func:`~wbfriction.fit.terms.temperature_shape`) is chosen
last, on the same held-out blocks (:class:`_TemperatureLaw`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from wbfriction.fit.options import TermOptions
from wbfriction.fit.regression import (
    correlation_lag,
    covariance_errors,
    parameter_covariance,
)
from wbfriction.fit.status import MIN_SPEED, ROUTE_Z, TERM_WEAK
from wbfriction.fit.terms import (
    NOT_TRIED,
    SIGNAL_COLUMNS,
    TERM_COEFFICIENTS,
    TermCheck,
    TermFit,
    TermSignals,
    coulomb_shape,
    fourier,
    temperature_shape,
    temperature_shape_rate,
    term_basis,
    velocity_basis,
    with_coefficients,
)
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import TERMS, Term


def _design(params: ModelParams, qd: np.ndarray, signals: TermSignals, terms: tuple[Term, ...], harmonics: int,
            t_ref: float, smoother=None, rate: float = 0.0) -> tuple[tuple[str, ...], np.ndarray, int]:
    """The joint design ``[B | Phi_1 | ...]`` (N, k + m), its names, and ``k`` (the velocity model's count);
    ``rate``: the temperature law's (:func:`temperature_shape`)."""
    names, B, _ = velocity_basis(params, qd)
    blocks, all_names = [B], list(names)
    for term in terms:
        n, X = term_basis(term, params, qd, signals, harmonics=harmonics, reference_temperature=t_ref,
                          temperature_rate=rate)
        blocks.append(X)
        all_names += n
    X = np.column_stack(blocks)
    if smoother is not None:  # the estimate went through it: so does the model, along the whole series
        X = smoother(X)
    return tuple(all_names), X, len(names)


MAX_CONDITION = 1e3
"""The largest condition number of a ripple's regressors (a constant and ``H`` harmonics, columns scaled) on the
angles fitted: over part of a turn the harmonics grow alike, and more of them than the angles tell apart give
amplitudes of hundreds of N·m that cancel."""


def ripple_condition(q: np.ndarray, harmonics: int) -> float:
    """The condition number of ``[1, sin q, cos q, ..., sin Hq, cos Hq]`` (columns scaled to unit norm) on ``q``."""
    F = fourier(q, harmonics, constant=True)
    return float(np.linalg.cond(F / np.maximum(np.linalg.norm(F, axis=0), 1e-300)))


def direction_gain(residual: np.ndarray, qd: np.ndarray, use: np.ndarray, F: np.ndarray, smoother=None) -> float:
    """How much a term's regressors ``F`` (N, k) (a column of ones first), fitted on the friction's residual
    ``y - f`` (N,) [N·m] of the samples moving one way, lower the residual's RMS on those moving the other way, each
    way's mean taken out (the smaller of the two ways; relative, 1: all of it). A torque of the angle, a Coulomb
    level that grows with the load or falls with the temperature, is the same law whichever way the joint moves; a
    residual that follows the
    trajectory (a model error, a log that repeats one motion, whose held-out blocks have twins in training) is not,
    and does not carry over: its gain is about zero or negative. ``smoother``: the estimate's (the regressors go
    through it as the model does)."""
    if smoother is not None:
        F = np.nan_to_num(smoother(F))
    gains = []
    moving = use & (np.abs(qd) > MIN_SPEED)  # a sample at rest has no direction
    for train, test in ((moving & (qd > 0), moving & (qd < 0)), (moving & (qd < 0), moving & (qd > 0))):
        if train.sum() <= F.shape[1] or test.sum() < 2:
            return float("nan")
        c = _solve(F[train], residual[train])
        before = residual[test] - residual[test].mean()
        after = residual[test] - F[test] @ c
        after = after - after.mean()  # each way its own level: a Coulomb level the velocity model took flips sign
        spread = float(np.mean(before**2))
        if not spread > 0.0:  # nothing left to predict that way
            return float("nan")
        gains.append(1.0 - float(np.sqrt(np.mean(after**2) / spread)))
    return min(gains)


def _carries(gain: float) -> str:
    """How far a term carried over between the directions of motion (:func:`direction_gain`), as its reason says."""
    return ("too few samples moving each way to tell" if not np.isfinite(gain)
            else f"{100 * gain:+.2g} %")


MIN_TERM_SAMPLES = 20
"""Fewer moving samples than this (the fit's own least, :attr:`~wbfriction.fit.options.FitOptions.min_samples`)
and no term is tried: none could be fitted on some and judged on the later ones."""


def _solve(X: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(X, y, rcond=None)[0]


def fit_terms(params: ModelParams, qd: np.ndarray, tau_f: np.ndarray, use: np.ndarray, signals: TermSignals,
              options: TermOptions = TermOptions(), smoother=None) -> TermFit:
    """The terms beyond velocity that held-out samples support, fitted with the velocity model's linear
    coefficients (module docstring).

    Args:
        params: the velocity model's fit (:attr:`~wbfriction.fit.result.FitResult.params`).
        qd: joint velocity (N,) [rad/s]; tau_f: the friction estimate (N,) [N·m] (``tau_f = -f``).
        use: (N,) samples to fit (valid, not stuck), in time order; those not finite or at rest (:func:`_moving`)
            are left out.
        signals: the terms' signals, the same rows.
        options: which terms to try.
        smoother: the zero-phase smoother the estimate went through
            (:attr:`~wbfriction.friction.estimated.FrictionEstimate.smoother`), or None: ``qd``, ``tau_f`` and the
            signals are then whole time series and the model's regressors go through it before they are compared
            (as the fit's model does); the samples where they are undefined are not used.

    Returns:
        the :class:`TermFit`; with no term kept, ``params`` unchanged.
    """
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = _moving(use, qd, y, signals)
    if smoother is None:
        qd_ = np.where(use, qd, 0.0)
    else:  # the whole series through the smoother: rows it leaves undefined are not used
        qd_ = qd
        _, X0, _ = _design(params, qd_, signals, tuple(t for t in signals.logged() if t in options.terms), 1, 0.0,
                           smoother)
        use &= np.isfinite(X0).all(axis=1)
    y_ = np.where(use, y, 0.0)
    candidates = tuple(t for t in options.terms if t in signals.logged())
    moving = int(use.sum())
    if candidates and moving < MIN_TERM_SAMPLES:  # nothing to fit on and hold out
        return TermFit(params, reasons={t: f"{NOT_TRIED}: {moving} moving samples, fewer than {MIN_TERM_SAMPLES}"
                                        for t in options.terms})
    t_ref = None
    if "temperature" in candidates and signals.temperature is not None:
        t_ref = (float(np.median(signals.temperature[use])) if options.reference_temperature is None
                 else options.reference_temperature)
    train, test = later_split(use)
    designs: dict[tuple[tuple[Term, ...], int], tuple[tuple[str, ...], np.ndarray, int]] = {}

    def design(terms: tuple[Term, ...], h: int) -> tuple[tuple[str, ...], np.ndarray, int]:
        """:func:`_design` of ``terms`` (in :data:`TERMS` order) with ``h`` harmonics, built (and smoothed) once."""
        key = (tuple(t for t in TERMS if t in terms), h if "ripple" in terms else 0)
        if key not in designs:
            designs[key] = _design(params, qd_, signals, key[0], key[1], t_ref or 0.0, smoother)
        return designs[key]

    def score(terms: tuple[Term, ...], h: int) -> float:
        """The held-out RMS of the model of ``terms`` fitted on the training samples."""
        _, X, _ = design(terms, h)
        r = y_[test] - X[test] @ _solve(X[train], y_[train])
        return float(np.sqrt(np.mean(r**2))) if r.size else float("nan")

    counts: tuple[int, ...] = ()  # the ripple's harmonic counts its angles tell apart
    if "ripple" in candidates and signals.q is not None:
        counts = tuple(h for h in range(1, options.max_harmonic + 1)
                       if ripple_condition(np.asarray(signals.q)[use], h) <= MAX_CONDITION)
    cache: dict[tuple[Term, ...], dict[int, float]] = {}

    def direction_gains(terms: tuple[Term, ...]) -> dict[int, float]:
        """Per harmonic count, how far a ripple carries over between the directions of motion
        (:func:`direction_gain`) on what the friction with every friction term tried leaves (issue 52: a load left in
        the residual, a torque that changes sign with the direction and follows the angle, made a true ripple predict
        the other direction 21 % worse on the Panda's wrist; ``terms`` is not read)."""
        friction = tuple(t for t in candidates if t != "ripple")
        if friction not in cache:
            X = np.nan_to_num(design(friction, 0)[1])
            left = y_ - X @ _solve(X[use], y_[use])
            cache[friction] = {h: direction_gain(left, qd_, use, fourier(np.asarray(signals.q), h, constant=True),
                                                 smoother) for h in counts}
        return cache[friction]

    def best_harmonics(terms: tuple[Term, ...]) -> tuple[float, int]:
        """The held-out RMS of ``terms`` and the ripple's ``H`` that gives it (0 without a ripple, or when no count
        holds whichever way the joint moves: then the terms' without it)."""
        if "ripple" not in terms:
            return score(terms, 0), 0
        allowed = [h for h, g in direction_gains(terms).items() if g > options.tolerance]
        if not allowed:  # no ripple holds here: the terms without it
            return score(tuple(t for t in terms if t != "ripple"), 0), 0
        scores: dict[int, float] = {h: score(terms, h) for h in allowed}
        best_rms = min(scores.values())
        h: int = min(count for count, rms in scores.items() if rms <= (1.0 + options.tolerance) * best_rms)
        return scores[h], h  # the fewest harmonics within the tolerance of the best

    base_rms = score((), 0)
    tol = options.tolerance
    reasons: dict[str, str] = {term: f"{NOT_TRIED}: no {SIGNAL_COLUMNS[term]}.<joint> column"
                               for term in options.terms if term not in candidates}
    gains: dict[tuple[Term, tuple[Term, ...]], float] = {}

    def carry_over(term: Term, others: tuple[Term, ...]) -> float:
        """How far ``term`` (load or temperature: laws that hold whichever way the joint moves) carries over between
        the directions of motion (:func:`direction_gain`) on what the friction with every other term tried leaves,
        the ripple with the most harmonics its angles tell apart (issue 52: each left in the residual hid the other;
        ``others`` is not read)."""
        friction = tuple(t for t in candidates if t != term and (t != "ripple" or counts))
        if (term, friction) not in gains:
            X0 = np.nan_to_num(design(friction, max(counts, default=0))[1])
            left = y_ - X0 @ _solve(X0[use], y_[use])
            _, X = term_basis(term, params, qd_, signals, reference_temperature=t_ref or 0.0)
            gains[term, friction] = direction_gain(left, qd_, use, np.column_stack([np.ones(len(qd_)),
                                                                                    np.nan_to_num(X)]), smoother)
        return gains[term, friction]

    def holds(term: Term, others: tuple[Term, ...]) -> bool:
        return term not in ("load", "temperature") or carry_over(term, others) > tol

    def select(tried: tuple[Term, ...]) -> tuple[list[Term], float, int]:
        """Forward, then backward selection among ``tried``: the terms kept, their held-out RMS, the harmonics."""
        kept: list[Term] = []
        current, harmonics = base_rms, 0
        remaining = list(tried)
        while remaining:  # forward: the term that lowers the held-out RMS most, while it lowers it by more than tol
            trials = {term: best_harmonics((*kept, term)) for term in remaining if holds(term, tuple(kept))}
            if not trials:
                break
            best = min(trials, key=lambda t: trials[t][0])
            if not trials[best][0] < (1.0 - tol) * current:
                break
            kept.append(best)
            current, harmonics = trials[best]
            remaining.remove(best)
        while len(kept) > 1:  # backward: a term another has made redundant leaves (a load that stood for a ripple)
            without = {term: best_harmonics(tuple(t for t in kept if t != term)) for term in kept}
            weakest = min(without, key=lambda t: without[t][0])
            if not without[weakest][0] < (1.0 + tol) * current:
                break
            kept.remove(weakest)
            current, harmonics = without[weakest]
        return kept, current, harmonics

    def displaced(terms: tuple[Term, ...], h: int) -> str | None:
        names, X, k = design(terms, h)
        return displaced_part(names, X[use], y_[use], k, nonnegative_solve(X[use], y_[use], names)[1], options)

    refused: list[Term] = []
    while True:  # a term that is no friction, takes the friction's place, is too small or not determined: refused
        kept, current, harmonics = select(tuple(t for t in candidates if t not in refused))
        if not kept:
            break
        names, X, k = design(tuple(kept), harmonics)
        coef, _ = nonnegative_solve(X[use], y_[use], names)
        bad = _unphysical(with_coefficients(params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))), signals,
                          use, t_ref or 0.0)  # a friction term that makes the friction generate power (eq. 7.9)
        if bad is None and "ripple" in kept:
            bad = ripple_in_place(kept, harmonics, displaced, best_harmonics)
        bad = bad or _negligible(names, X[use], coef, k, options) or undetermined_term(
            names, X, y_, use, k, kept, harmonics, signals)
        if bad is None:
            break
        refused.append(bad[0])
        reasons[bad[0]] = f"not kept: {bad[1]}"
    if "ripple" in candidates and "ripple" not in kept:
        ripples = direction_gains(tuple(kept))
        if not any(g > tol for g in ripples.values()):
            best = max((g for g in ripples.values() if np.isfinite(g)), default=float("nan"))
            reasons["ripple"] = ("not kept: fitted on one direction of motion it does not predict the other by more "
                                 f"than {100 * tol:g} % (best {_carries(best)}): not a torque of the angle")
    for term in candidates:
        if term not in kept and term not in reasons and not holds(term, tuple(kept)):
            reasons[term] = ("not kept: fitted on one direction of motion it does not predict the other by more "
                             f"than {100 * tol:g} % ({_carries(carry_over(term, tuple(kept)))}): not a law of the "
                             f"{term}")
        if term in reasons:
            continue
        if term in kept:
            rms_without = best_harmonics(tuple(t for t in kept if t != term))[0]
            reasons[term] = (f"kept: held-out RMS {current:.4g} N·m with it, {rms_without:.4g} without "
                             f"(+{100 * (rms_without / current - 1):.2g} %)"
                             + (f"; {harmonics} harmonics" if term == "ripple" else ""))
        else:
            rms_with = best_harmonics((*kept, term))[0]
            reasons[term] = (f"not kept: held-out RMS {current:.4g} N·m without it, {rms_with:.4g} with "
                             f"({100 * (rms_with / current - 1):+.2g} %; kept from -{100 * tol:g} %)")
    kept_sorted = tuple(t for t in TERMS if t in kept)
    if not kept_sorted:
        return TermFit(params, reference_temperature=t_ref, reasons=reasons, held_out_rms=(base_rms, base_rms))
    rate = 0.0
    if "temperature" in kept_sorted and options.temperature_law != "linear":
        law = _TemperatureLaw(params, qd_, y_, use, signals, kept_sorted, harmonics, t_ref or 0.0, smoother)
        rate, note, rms = law.choose(train, test, options)
        reasons["temperature"] += note
        current = rms if rate else current
    names, X, k = _design(params, qd_, signals, kept_sorted, harmonics, t_ref or 0.0, smoother, rate)
    coef, cov, held = _final(X, y_, use, names, None if rate == 0.0 else partial(law.rate_column, rate, names))
    refitted = with_coefficients(params, coef[:k])
    coefficients = dict(zip(names[k:], map(float, coef[k:])))
    stderr = dict(zip(names, map(float, covariance_errors(cov))))
    if rate != 0.0:
        coefficients["rate_T"], stderr["rate_T"] = rate, float(np.sqrt(max(cov[-1, -1], 0.0)))
    later = later_check(X, y_, names, k, kept_sorted, train, test, options,
                        None if rate == 0.0 else partial(law.rate_column, rate, names))
    q_range = None
    derived = _derived(refitted, coefficients)
    if "ripple" in kept_sorted and signals.q is not None:
        q_used = np.asarray(signals.q, dtype=float)[use]
        q_range = (float(q_used.min()), float(q_used.max()))
        derived["ripple_rms"], stderr["ripple_rms"] = ripple_size(q_used, harmonics, names, coef, cov)
    return TermFit(refitted, kept_sorted, harmonics, coefficients, stderr, derived, t_ref, q_range, reasons,
                   (base_rms, current), at_bound=held, covariance=cov, later=later)


LATER_SHARE = 0.3
"""The share of a joint's samples, the last in time, its terms are chosen on (:func:`later_split`)."""


def later_split(use: np.ndarray, share: float = LATER_SHARE) -> tuple[np.ndarray, np.ndarray]:
    """The samples ``use`` (N,) bool, in time order, cut in two: the first ``1 - share`` of them to fit, the last
    ``share`` to predict (issue 52: a term is kept where it predicts a later stretch it was not fitted on, not only
    blocks interleaved with those it was fitted on, whose twins a repeated motion puts in training)."""
    rows = np.flatnonzero(use)
    train, test = np.zeros(len(use), dtype=bool), np.zeros(len(use), dtype=bool)
    cut = int(round((1.0 - share) * rows.size))
    train[rows[:cut]] = True
    test[rows[cut:]] = True
    return train, test


def later_check(X: np.ndarray, y: np.ndarray, names: tuple[str, ...], k: int, kept: tuple[Term, ...],
                head: np.ndarray, tail: np.ndarray, options: TermOptions,
                rate_column: Callable[[np.ndarray], np.ndarray] | None = None) -> dict[str, tuple[float, float]]:
    """Per kept term, how far its torque fitted on the samples ``head`` departs on the later ones ``tail`` from its
    torque fitted on ``tail`` itself, and how far their standard errors allow (issue 52): ``(d, allowed)`` [N·m],
    ``d`` the RMS over ``tail`` of ``X_term⊥ (c_head - c_tail)``, ``X_term⊥`` the term's regressors on ``tail`` less
    their projection on the other coefficients' (what no other coefficient can take: a ripple's mean that the offset
    trades with is not the ripple's departure), ``allowed`` :data:`ROUTE_Z` times the RMS of its standard deviation
    through both fits' covariances (Newey-West), and at least :data:`~wbfriction.fit.status.TERM_WEAK` of the
    tail's own residual RMS (the noise: a departure below it changes a prediction by a few percent; the Newey-West
    errors miss an estimate's errors that repeat with the motion) and :attr:`TermOptions.min_torque`. A law of the
    load, the angle or the temperature is the same law later; a term that stood in for something else is not. Empty when
    either stretch is too short to fit the model."""
    if min(head.sum(), tail.sum()) <= 2 * X.shape[1]:
        return {}
    X = np.nan_to_num(X)
    fits = [_final(X, y, rows, names, rate_column)[:2] for rows in (head, tail)]
    (c_h, C_h), (c_t, C_t) = fits
    noise = TERM_WEAK * float(np.sqrt(np.mean((y[tail] - X[tail] @ c_t) ** 2)))
    out: dict[str, tuple[float, float]] = {}
    for term in kept:
        cols = [i for i, n in enumerate(names) if i >= k and _term_of(n) == term]
        rest = [i for i in range(X.shape[1]) if i not in cols]
        Xt, Xo = X[tail][:, cols], X[tail][:, rest]
        Xt = Xt - Xo @ _solve(Xo, Xt)
        d = Xt @ (c_h[cols] - c_t[cols])
        C = (C_h + C_t)[np.ix_(cols, cols)]
        var = np.einsum("ij,jk,ik->i", Xt, C, Xt) if np.all(np.isfinite(C)) else np.full(len(Xt), np.inf)
        out[term] = (float(np.sqrt(np.mean(d**2))),
                     max(ROUTE_Z * float(np.sqrt(np.mean(var))), noise, options.min_torque))
    return out


NONNEGATIVE = ("F_v", "F_c", "F_cS")
"""The velocity model's linear coefficients that are magnitudes (the fit's bounds): refitted with the terms, one
that would go below zero is held at zero (:attr:`TermFit.at_bound`)."""


def nonnegative_solve(X: np.ndarray, y: np.ndarray, names: tuple[str, ...]) -> tuple[np.ndarray, tuple[str, ...]]:
    """Least squares with the :data:`NONNEGATIVE` coefficients at zero where they would go below: the most negative
    held at zero and the rest refitted, until none is; and the names held. ``F_c`` of (3.5) held at zero holds its
    Stribeck part ``F_cS = F_c S`` with it: a Stribeck rise without a Coulomb level is no (3.5) (its ``S`` would be
    infinite; :func:`~wbfriction.fit.terms.with_coefficients` would drop it)."""
    free = np.ones(len(names), dtype=bool)
    while True:
        coef = np.zeros(len(names))
        coef[free] = _solve(X[:, free], y)
        negative = [i for i, n in enumerate(names) if n in NONNEGATIVE and free[i] and coef[i] < 0]
        if not negative:
            return coef, tuple(n for n, f in zip(names, free) if not f)
        worst = min(negative, key=lambda i: coef[i])
        free[worst] = False
        if names[worst] == "F_c" and "F_cS" in names:
            free[names.index("F_cS")] = False


def _moving(use: np.ndarray, qd: np.ndarray, y: np.ndarray, signals: TermSignals) -> np.ndarray:
    """The samples of ``use`` the terms are fitted on: finite, signals too, and moving (``|qd|`` above
    :data:`~wbfriction.fit.status.MIN_SPEED`): a joint at rest has static friction, any value up to its static
    level, which no law of the load or the temperature of the moving friction describes (on the ideal simulator's
    noise-free walk, the 20 samples of 3,900 about the knees' reversals bias F_L by 5 %)."""
    use = np.asarray(use, dtype=bool) & np.isfinite(qd) & np.isfinite(y) & (np.abs(qd) > MIN_SPEED)
    for signal in (signals.q, signals.tau_load, signals.temperature):
        if signal is not None:
            use &= np.isfinite(signal)
    return use


def _final(X: np.ndarray, y: np.ndarray, use: np.ndarray, names: tuple[str, ...],
           rate_column: Callable[[np.ndarray], np.ndarray] | None = None,
           ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """The coefficients on every sample ``use`` (:func:`nonnegative_solve`), their covariance (residuals correlated
    over a filter's window: Newey-West, as the fit's; zero for one held at zero) and the names held. With
    ``rate_column`` (the model's derivative (N,) in the temperature law's rate, given the coefficients), the
    covariance is that of the coefficients and the rate (last): the full Jacobian's, the rate fitted too."""
    coef, held = nonnegative_solve(X[use], y[use], names)
    free = np.array([n not in held for n in names])
    residual = y[use] - X[use] @ coef
    rows = np.flatnonzero(use)
    J = X[use]
    if rate_column is not None:
        J = np.column_stack([J, rate_column(coef)[use]])
        free = np.append(free, True)
    cov = np.zeros((len(free), len(free)))
    cov[np.ix_(free, free)] = parameter_covariance(J[:, free], residual, rows=rows,
                                                   max_lag=correlation_lag(residual, rows))
    return coef, cov, held


RATE_SPAN = 3.0
"""The exponential temperature law's rate is searched within ``RATE_SPAN`` over the largest ``|T - T_ref|`` met
[1/°C]: a level that changes by up to ``e^3`` (20 times) over the temperatures logged, beyond any grease's."""


@dataclass(frozen=True)
class _TemperatureLaw:
    """The exponential temperature law of a fit's kept terms (:func:`temperature_shape`): its rate found by variable
    projection (the coefficients solved at each rate) and kept where held-out samples say so."""

    params: ModelParams
    qd: np.ndarray
    y: np.ndarray
    use: np.ndarray
    signals: TermSignals
    terms: tuple[Term, ...]
    harmonics: int
    t_ref: float
    smoother: Any = None

    def design(self, rate: float) -> tuple[tuple[str, ...], np.ndarray, int]:
        """:func:`_design` of the kept terms at ``rate``, undefined rows at zero (they are not used)."""
        names, X, k = _design(self.params, self.qd, self.signals, self.terms, self.harmonics, self.t_ref,
                              self.smoother, rate)
        return names, np.nan_to_num(X), k

    def residual(self, rate: float, train: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """The residual (on ``rows``) of the coefficients fitted on ``train`` at ``rate``."""
        _, X, _ = self.design(rate)
        return self.y[rows] - X[rows] @ _solve(X[train], self.y[train])

    def choose(self, train: np.ndarray, test: np.ndarray, options: TermOptions) -> tuple[float, str, float]:
        """The rate (0: the linear law), a phrase for the temperature term's reason and the exponential's held-out
        RMS [N·m] (NaN when no rate was searched): the exponential when
        ``options.temperature_law`` asks for it, or (``auto``) when fitted on ``train`` it lowers the held-out RMS
        on ``test`` by more than the tolerance, keeps every level physical, and its rate fitted on every sample is
        determined (its standard error at most :data:`~wbfriction.fit.status.TERM_WEAK` of it: on the ideal
        simulator's noise-free walk, a linear law's knee "improved" by 2 % with a rate of 0.0009 ± 0.0005 /°C)."""
        from scipy.optimize import minimize_scalar
        dT = np.asarray(self.signals.temperature, dtype=float)[self.use] - self.t_ref
        span = float(np.max(np.abs(dT))) if dT.size else 0.0
        if not span > 0.0:
            return 0.0, "", float("nan")
        bound = RATE_SPAN / span
        found = minimize_scalar(lambda r: float(np.sum(self.residual(r, train, train) ** 2)), bounds=(-bound, bound),
                                method="bounded", options={"xatol": 1e-6 * bound})
        rate = float(found.x)
        rms = {law: float(np.sqrt(np.mean(self.residual(r, train, test) ** 2))) for law, r in
               (("linear", 0.0), ("exponential", rate))}
        # chosen on a later stretch (temperatures the fit did not see), the rate itself is every sample's
        rate = float(minimize_scalar(lambda r: float(np.sum(self.residual(r, self.use, self.use) ** 2)),
                                     bounds=(-bound, bound), method="bounded", options={"xatol": 1e-6 * bound}).x)
        names, X, k = self.design(rate)
        coef, _ = nonnegative_solve(X[self.use], self.y[self.use], names)
        unphysical = _unphysical(with_coefficients(self.params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))),
                                 self.signals, self.use, self.t_ref, rate)
        versus = (f"held-out RMS {rms['exponential']:.4g} N·m exponential (rate {rate:.3g} /°C), {rms['linear']:.4g} "
                  "linear")
        if unphysical is not None:
            return 0.0, f"; law linear: the exponential's levels go below zero ({versus})", rms["exponential"]
        if options.temperature_law == "exponential":
            return rate, f"; law exponential (asked): {versus}", rms["exponential"]
        if not rms["exponential"] < (1.0 - options.tolerance) * rms["linear"]:
            return 0.0, f"; law linear: {versus}", rms["exponential"]
        _, cov, _ = _final(X, self.y, self.use, names, partial(self.rate_column, rate, names))
        se = float(np.sqrt(max(cov[-1, -1], 0.0)))
        if not se <= TERM_WEAK * abs(rate):
            return 0.0, (f"; law linear: the exponential's rate is not determined ({rate:.3g} ±{se:.2g} /°C; "
                         f"{versus})"), rms["exponential"]
        return rate, f"; law exponential: {versus}", rms["exponential"]

    def rate_column(self, rate: float, names: tuple[str, ...], coef: np.ndarray) -> np.ndarray:
        """The model's derivative in the rate (N,), at the coefficients ``coef`` (``names``' order)."""
        dT = np.asarray(self.signals.temperature, dtype=float) - self.t_ref
        g = coulomb_shape(self.params, self.qd)
        c = dict(zip(names, coef))
        column = (c["F_cT"] * g + c["F_vT"] * self.qd) * temperature_shape_rate(dT, rate)
        return column if self.smoother is None else np.asarray(self.smoother(column[:, None]))[:, 0]


def ripple_size(q: np.ndarray, harmonics: int, names: tuple[str, ...], coef: np.ndarray,
                cov: np.ndarray) -> tuple[float, float]:
    """The ripple's standard deviation over the angles ``q`` it was fitted on [N·m], and its standard error (the
    delta method through the coefficients' covariance): a size its harmonics, correlated over part of a turn, do not
    blur as their amplitudes' errors do."""
    at = [names.index(f"ripple_{f}{h}") for h in range(1, harmonics + 1) for f in ("sin", "cos")]
    F = fourier(q, harmonics)
    ripple = F @ coef[at]
    size = float(np.std(ripple))
    if size == 0.0:
        return 0.0, math.inf
    gradient = (F - F.mean(axis=0)).T @ (ripple - ripple.mean()) / (len(q) * size)
    variance = float(gradient @ cov[np.ix_(at, at)] @ gradient)
    return size, math.sqrt(max(variance, 0.0)) if np.isfinite(variance) else math.inf


def refit_terms(fit: TermFit, params: ModelParams, qd: np.ndarray, tau_f: np.ndarray, use: np.ndarray,
                signals: TermSignals, route: str, smoother=None) -> TermCheck | None:
    """The terms ``fit`` kept, with its harmonics and reference temperature, fitted with the velocity model
    ``params`` (the other route's fit of the same joint) on another estimate of the same samples: what
    :attr:`TermFit.check` compares. Arguments as :func:`fit_terms`'s; None when no term is kept or no sample is
    left."""
    if not fit.kept:
        return None
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = _moving(use, qd, y, signals)
    qd_ = qd if smoother is not None else np.where(use, qd, 0.0)
    names, X, k = _design(params, qd_, signals, fit.kept, fit.harmonics, fit.reference_temperature or 0.0,
                          smoother, fit.temperature_rate)
    use &= np.isfinite(X).all(axis=1)
    if use.sum() <= X.shape[1]:
        return None
    coef, cov, _ = _final(X, np.where(use, y, 0.0), use, names)
    coefficients = dict(zip(names, map(float, coef)))
    stderr = dict(zip(names, map(float, covariance_errors(cov))))
    if "ripple" in fit.kept and signals.q is not None:
        coefficients["ripple_rms"], stderr["ripple_rms"] = ripple_size(np.asarray(signals.q, dtype=float)[use],
                                                                      fit.harmonics, names, coef, cov)
    return TermCheck(route, coefficients, stderr)


def _unphysical(params: ModelParams, c: dict[str, float], signals: TermSignals, use: np.ndarray,
                t_ref: float, rate: float = 0.0) -> tuple[Term, str] | None:
    """The first friction term whose levels go below zero on the samples (a viscous level in a direction, a Coulomb
    level under a load met, a level at a temperature met) and what goes below; None when all stay physical."""
    F_c, F_v = params.F_c, params.F_v
    if "dF_v" in c and min(F_v + c["dF_v"], F_v - c["dF_v"]) < 0:
        return "direction", (f"a viscous level below zero in one direction (F_v {F_v:.3g}, dF_v {c['dF_v']:.3g}): "
                             "not friction")
    if "F_L" in c and signals.tau_load is not None:
        lowest = F_c + c["F_L"] * float(np.max(np.abs(np.asarray(signals.tau_load)[use])))
        if lowest < 0:
            return "load", f"a Coulomb level below zero under the largest load met ({lowest:.3g} N·m): not friction"
    if "F_cT" in c and signals.temperature is not None:
        phi = temperature_shape(np.asarray(signals.temperature, dtype=float)[use] - t_ref, rate)
        levels = (F_c + c["F_cT"] * phi, F_v + c["F_vT"] * phi)
        if min(float(np.min(x)) for x in levels) < 0:
            return "temperature", "a Coulomb or viscous level below zero at a temperature met: not friction"
    return None


FRICTION_PARTS = {"Coulomb": ("F_c", "F_cS", "F_s"), "viscous": ("F_v",)}
"""The velocity model's coefficients by the part of the friction they make (:func:`displaced_part`)."""


def displaced_part(names: tuple[str, ...], X: np.ndarray, y: np.ndarray, k: int, held: tuple[str, ...],
                options: TermOptions) -> str | None:
    """The part of the velocity model's friction (:data:`FRICTION_PARTS`) that the terms take the place of, or None:
    with them every coefficient of that part is held at zero (``held``, :func:`nonnegative_solve`) where, fitted
    without them, the part carries a torque that matters (above :attr:`TermOptions.min_effect` of the friction and
    :attr:`TermOptions.min_torque`, as :func:`_negligible`). The data then cannot tell the terms from the friction: a
    3-harmonic ripple on the Panda's flange, over the 2.7 rad its excitation swept, took the whole Coulomb level
    (0.28 N·m at every speed in its estimate, as published) and left a viscous line 50 % off the published curve
    (issue 52). One coefficient of a part held (F_cS of (3.5), its Coulomb level F_c still there) takes nothing.
    ``X`` (n, p), ``y`` (n,): the design and the friction on the samples fitted; ``k``: the velocity model's
    columns."""
    alone, _ = nonnegative_solve(X[:, :k], y, names[:k])
    friction = float(np.sqrt(np.mean((X[:, :k] @ alone) ** 2)))
    for part, members in FRICTION_PARTS.items():
        cols = [i for i, n in enumerate(names[:k]) if n in members]
        if not cols or not all(names[i] in held for i in cols):
            continue
        if float(np.sqrt(np.mean((X[:, cols] @ alone[cols]) ** 2))) >= max(options.min_effect * friction,
                                                                            options.min_torque):
            return part
    return None


def ripple_in_place(kept: list[Term], harmonics: int, displaced: Callable[[tuple[Term, ...], int], str | None],
                     best_harmonics: Callable[[tuple[Term, ...]], tuple[float, int]]) -> tuple[Term, str] | None:
    """The ripple and why, when with it a whole part of the velocity model's friction is held at zero where alone
    it matters (:func:`displaced_part`) and without it not: an angle's torque over part of a turn that follows the
    direction of motion takes the friction's place, which the data cannot tell apart (the Panda's flange). A law of
    the load or the temperature that takes all of the Coulomb level is friction still (a Coulomb level
    proportional to the load), and stays. ``displaced(terms, H)`` and ``best_harmonics(terms)``:
    :func:`fit_terms`'s."""
    lost = displaced(tuple(kept), harmonics)
    others = tuple(t for t in kept if t != "ripple")
    if lost is None or displaced(others, best_harmonics(others)[1]) is not None:
        return None
    return "ripple", (f"with it the velocity model's {lost} friction is held at zero where, fitted without it, it "
                      "matters: an angle's torque that follows the direction of motion takes the friction's place, "
                      "which the data cannot tell apart")


def undetermined_term(names: tuple[str, ...], X: np.ndarray, y: np.ndarray, use: np.ndarray, k: int, kept: list[Term],
                      harmonics: int, signals: TermSignals) -> tuple[Term, str] | None:
    """The first kept term no value of which the data determine: each coefficient (the ripple: its size,
    :func:`ripple_size`) with a standard error (fitted on every sample ``use``, :func:`_final`) above
    :data:`~wbfriction.fit.status.TERM_WEAK` of its value; None when each is. It lowered the held-out RMS
    by chance, and would be printed ``weak`` (issue 52: a UR10e shoulder's direction term, dF_v -1.03 ±0.76
    N·m·s/rad, took the viscous level's place and moved its curve 6 % from the published one)."""
    coef, cov, _ = _final(X, y, use, names)
    se = covariance_errors(cov)
    for term in TERMS:
        if term not in kept:
            continue
        if term == "ripple" and signals.q is not None:
            values = [ripple_size(np.asarray(signals.q, dtype=float)[use], harmonics, names, coef, cov)]
        else:
            values = [(float(coef[i]), float(se[i])) for i, n in enumerate(names) if i >= k and _term_of(n) == term]
        if values and not any(e <= TERM_WEAK * abs(v) for v, e in values):
            shown = ", ".join(f"{v:.3g} ±{e:.2g}" for v, e in values)
            return term, (f"its coefficients are not determined ({shown}: standard errors above "
                          f"{100 * TERM_WEAK:g} % of the values): it predicts the held-out samples better by chance")
    return None


def _negligible(names: tuple[str, ...], X: np.ndarray, coef: np.ndarray, k: int,
                options: TermOptions) -> tuple[Term, str] | None:
    """The kept term whose torque over the samples (the standard deviation of its regressors times its
    coefficients, ``X`` (n, p) the design on them) is the smallest, if it is below :attr:`TermOptions.min_effect`
    of the velocity model's friction or below :attr:`TermOptions.min_torque`: a term too small to matter (on
    noise-free data, the 2 % rule alone keeps terms of a thousandth of the friction); None when every term
    matters."""
    friction = float(np.sqrt(np.mean((X[:, :k] @ coef[:k]) ** 2)))
    effects: dict[Term, float] = {}
    for term in TERMS:
        cols = [i for i, n in enumerate(names) if i >= k and _term_of(n) == term]
        if cols:
            effects[term] = float(np.std(X[:, cols] @ coef[cols]))  # its mean is the offset's to take
    if not effects:
        return None
    term = min(effects, key=lambda t: effects[t])
    if effects[term] >= max(options.min_effect * friction, options.min_torque):
        return None
    return term, (f"its torque ({effects[term]:.2g} N·m standard deviation) is below "
                  f"{100 * options.min_effect:g} % of the friction's ({friction:.2g} N·m) or {options.min_torque:g} "
                  "N·m: too small to matter")


def _term_of(name: str) -> Term:
    """The term a coefficient belongs to."""
    if name.startswith("ripple"):
        return "ripple"
    if name == "rate_T":
        return "temperature"
    return next(t for t, names in TERM_COEFFICIENTS.items() if name in names)


def _derived(params: ModelParams, c: dict[str, float]) -> dict[str, float]:
    """The physical parameters of the coefficients (:attr:`TermFit.derived`)."""
    out: dict[str, float] = {}
    F_c, F_v = params.F_c, params.F_v
    if "F_L" in c:
        out["k_L"] = c["F_L"] / F_c if F_c else float("nan")
    if "dF_v" in c:
        out.update({"F_v+": F_v + c["dF_v"], "F_v-": F_v - c["dF_v"], "F_c+": F_c + params.tau_os,
                    "F_c-": F_c - params.tau_os})
    if "F_cT" in c:
        out["k_Tc"] = c["F_cT"] / F_c if F_c else float("nan")
        out["k_Tv"] = c["F_vT"] / F_v if F_v else float("nan")
    return out

"""Which terms beyond velocity a joint keeps, and their fit (issue 40; the terms themselves:
:mod:`~wbfriction.fit.terms`).

**Which terms are kept**: stepwise selection on blocked held-out samples (the split of the model choice,
:func:`~wbfriction.fit.regression.held_out_split`), with the model choice's rule: forward, the term that lowers the
held-out RMS most joins while it lowers it by more than :attr:`TermOptions.tolerance`; backward, a term whose
leaving raises it by less leaves (a load term that stood in for a ripple, their regressors alike); the ripple has
the fewest harmonics whose held-out RMS is within the tolerance of the smallest. The load and temperature terms,
like the ripple, are tried only where, fitted on the samples moving one way, they predict those moving the other
(:func:`~wbfriction.fit.term_checks.direction_gain`): a law of the load or the temperature holds both ways, a
residual that follows a repeated trajectory does not (on the KUKA LWR4+, the rigid-body torque's "load" term on
lwr_2 passed the held-out blocks, whose twins were in training, and made run 3 worse by 6 %). Then every
coefficient is fitted on every sample, with standard errors from the fit's Newey-West sandwich; the velocity
model's magnitudes (F_c, F_v) that the terms would drive below zero are held at zero
(:attr:`~wbfriction.fit.terms.TermFit.at_bound`).

The temperature term's law (linear or exponential, :func:`~wbfriction.fit.terms.temperature_shape`) is chosen last,
on the same held-out blocks (:class:`~wbfriction.fit.temperature_law.ExponentialLaw`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from wbfriction.fit.block_spread import linear_block_spread
from wbfriction.fit.options import TermOptions
from wbfriction.fit.ranges import angle_arc
from wbfriction.fit.regression import covariance_errors
from wbfriction.fit.temperature_law import ExponentialLaw
from wbfriction.fit.term_checks import (
    MAX_CONDITION,
    carries,
    direction_gain,
    displaced_part,
    later_check,
    later_split,
    negligible_term,
    ripple_condition,
    ripple_in_place,
    undetermined_term,
    unphysical_term,
)
from wbfriction.fit.term_design import (
    derived_parameters,
    final_fit,
    moving_samples,
    nonnegative_solve,
    ripple_size,
    solve_lstsq,
    term_design,
)
from wbfriction.fit.terms import (
    NOT_TRIED,
    SIGNAL_COLUMNS,
    TermCheck,
    TermFit,
    TermSignals,
    fourier,
    term_basis,
    with_coefficients,
)
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import TERMS, Term

MIN_TERM_SAMPLES = 20
"""Fewer moving samples than this (the fit's own least, :attr:`~wbfriction.fit.options.FitOptions.min_samples`)
and no term is tried: none could be fitted on some and judged on the later ones."""


def fit_terms(params: ModelParams, qd: np.ndarray, tau_f: np.ndarray, use: np.ndarray, signals: TermSignals,
              options: TermOptions = TermOptions(), smoother=None) -> TermFit:
    """The terms beyond velocity that held-out samples support, fitted with the velocity model's linear
    coefficients (module docstring).

    Args:
        params: the velocity model's fit (:attr:`~wbfriction.fit.result.FitResult.params`).
        qd: joint velocity (N,) [rad/s]; tau_f: the friction estimate (N,) [N·m] (``tau_f = -f``).
        use: (N,) samples to fit (valid, not stuck), in time order; those not finite or at rest
            (:func:`~wbfriction.fit.term_design.moving_samples`) are left out.
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
    use = moving_samples(use, qd, y, signals)
    if smoother is None:
        qd_ = np.where(use, qd, 0.0)
    else:  # the whole series through the smoother: rows it leaves undefined are not used
        qd_ = qd
        _, X0, _ = term_design(params, qd_, signals, tuple(t for t in signals.logged() if t in options.terms), 1,
                               0.0, smoother)
        use &= np.isfinite(X0).all(axis=1)
    candidates = tuple(t for t in options.terms if t in signals.logged())
    moving = int(use.sum())
    if candidates and moving < MIN_TERM_SAMPLES:  # nothing to fit on and hold out
        return TermFit(params, reasons={t: f"{NOT_TRIED}: {moving} moving samples, fewer than {MIN_TERM_SAMPLES}"
                                        for t in options.terms})
    t_ref = None
    if "temperature" in candidates and signals.temperature is not None:
        t_ref = (float(np.median(signals.temperature[use])) if options.reference_temperature is None
                 else options.reference_temperature)
    search = TermSearch(params, qd_, np.where(use, y, 0.0), use, signals, candidates, t_ref, options, smoother)
    kept, current, harmonics = search.refuse_until_sound()
    search.explain(kept, current, harmonics)
    return search.final(tuple(t for t in TERMS if t in kept), current, harmonics)


@dataclass
class TermSearch:
    """The stepwise search of one joint's terms (module docstring) on its samples ``use``: the designs built once,
    the direction checks cached, and each term's reason as it is decided.

    Attributes:
        params: the velocity model's fit; qd: the velocity (N,) [rad/s] (zero off ``use`` without a smoother);
        y: ``-tau_f`` (N,) [N·m], zero off ``use``; use: (N,) the samples fitted; signals: the terms' signals;
        candidates: the terms tried (asked for and logged); t_ref: the temperature term's reference [°C] or None;
        options: the selection's; smoother: the estimate's, or None.
    """

    params: ModelParams
    qd: np.ndarray
    y: np.ndarray
    use: np.ndarray
    signals: TermSignals
    candidates: tuple[Term, ...]
    t_ref: float | None
    options: TermOptions
    smoother: Any = None
    reasons: dict[str, str] = field(default_factory=dict)
    designs: dict[tuple[tuple[Term, ...], int], tuple[tuple[str, ...], np.ndarray, int]] = field(default_factory=dict)
    ripple_gains: dict[tuple[Term, ...], dict[int, float]] = field(default_factory=dict)
    gains: dict[tuple[Term, tuple[Term, ...]], float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.train, self.test = later_split(self.use)
        self.counts: tuple[int, ...] = ()  # the ripple's harmonic counts its angles tell apart
        if "ripple" in self.candidates and self.signals.q is not None:
            self.counts = tuple(h for h in range(1, self.options.max_harmonic + 1)
                                if ripple_condition(np.asarray(self.signals.q)[self.use], h) <= MAX_CONDITION)
        self.base_rms = self.score((), 0)
        self.reasons.update({term: f"{NOT_TRIED}: no {SIGNAL_COLUMNS[term]}.<joint> column"
                             for term in self.options.terms if term not in self.candidates})

    def design(self, terms: tuple[Term, ...], h: int) -> tuple[tuple[str, ...], np.ndarray, int]:
        """:func:`~wbfriction.fit.term_design.term_design` of ``terms`` (in :data:`TERMS` order) with ``h``
        harmonics, built (and smoothed) once."""
        key = (tuple(t for t in TERMS if t in terms), h if "ripple" in terms else 0)
        if key not in self.designs:
            self.designs[key] = term_design(self.params, self.qd, self.signals, key[0], key[1], self.t_ref or 0.0,
                                            self.smoother)
        return self.designs[key]

    def score(self, terms: tuple[Term, ...], h: int) -> float:
        """The held-out RMS of the model of ``terms`` fitted on the training samples."""
        _, X, _ = self.design(terms, h)
        r = self.y[self.test] - X[self.test] @ solve_lstsq(X[self.train], self.y[self.train])
        return float(np.sqrt(np.mean(r**2))) if r.size else float("nan")

    def direction_gains(self) -> dict[int, float]:
        """Per harmonic count, how far a ripple carries over between the directions of motion
        (:func:`~wbfriction.fit.term_checks.direction_gain`) on what the friction with every friction term tried
        leaves (issue 52: a load left in the residual, a torque that changes sign with the direction and follows the
        angle, made a true ripple predict the other direction 21 % worse on the Panda's wrist)."""
        friction = tuple(t for t in self.candidates if t != "ripple")
        if friction not in self.ripple_gains:
            X = np.nan_to_num(self.design(friction, 0)[1])
            left = self.y - X @ solve_lstsq(X[self.use], self.y[self.use])
            self.ripple_gains[friction] = {
                h: direction_gain(left, self.qd, self.use, fourier(np.asarray(self.signals.q), h, constant=True),
                                  self.smoother) for h in self.counts}
        return self.ripple_gains[friction]

    def best_harmonics(self, terms: tuple[Term, ...]) -> tuple[float, int]:
        """The held-out RMS of ``terms`` and the ripple's ``H`` that gives it (0 without a ripple, or when no count
        holds whichever way the joint moves: then the terms' without it)."""
        if "ripple" not in terms:
            return self.score(terms, 0), 0
        allowed = [h for h, g in self.direction_gains().items() if g > self.options.tolerance]
        if not allowed:  # no ripple holds here: the terms without it
            return self.score(tuple(t for t in terms if t != "ripple"), 0), 0
        scores: dict[int, float] = {h: self.score(terms, h) for h in allowed}
        best_rms = min(scores.values())
        h: int = min(count for count, rms in scores.items() if rms <= (1.0 + self.options.tolerance) * best_rms)
        return scores[h], h  # the fewest harmonics within the tolerance of the best

    def carry_over(self, term: Term) -> float:
        """How far ``term`` (load or temperature: laws that hold whichever way the joint moves) carries over between
        the directions of motion (:func:`~wbfriction.fit.term_checks.direction_gain`) on what the friction with
        every other term tried leaves, the ripple with the most harmonics its angles tell apart (issue 52: each
        left in the residual hid the other)."""
        friction = tuple(t for t in self.candidates if t != term and (t != "ripple" or self.counts))
        if (term, friction) not in self.gains:
            X0 = np.nan_to_num(self.design(friction, max(self.counts, default=0))[1])
            left = self.y - X0 @ solve_lstsq(X0[self.use], self.y[self.use])
            _, X = term_basis(term, self.params, self.qd, self.signals, reference_temperature=self.t_ref or 0.0)
            self.gains[term, friction] = direction_gain(
                left, self.qd, self.use, np.column_stack([np.ones(len(self.qd)), np.nan_to_num(X)]), self.smoother)
        return self.gains[term, friction]

    def holds(self, term: Term) -> bool:
        """Whether ``term`` may be tried: a ripple always; a load or temperature law where it carries over."""
        return term not in ("load", "temperature") or self.carry_over(term) > self.options.tolerance

    def select(self, tried: tuple[Term, ...]) -> tuple[list[Term], float, int]:
        """Forward, then backward selection among ``tried``: the terms kept, their held-out RMS, the harmonics."""
        tol = self.options.tolerance
        kept: list[Term] = []
        current, harmonics = self.base_rms, 0
        remaining = list(tried)
        while remaining:  # forward: the term that lowers the held-out RMS most, while it lowers it by more than tol
            trials = {term: self.best_harmonics((*kept, term)) for term in remaining if self.holds(term)}
            if not trials:
                break
            best = min(trials, key=lambda t: trials[t][0])
            if not trials[best][0] < (1.0 - tol) * current:
                break
            kept.append(best)
            current, harmonics = trials[best]
            remaining.remove(best)
        while len(kept) > 1:  # backward: a term another has made redundant leaves (a load that stood for a ripple)
            without = {term: self.best_harmonics(tuple(t for t in kept if t != term)) for term in kept}
            weakest = min(without, key=lambda t: without[t][0])
            if not without[weakest][0] < (1.0 + tol) * current:
                break
            kept.remove(weakest)
            current, harmonics = without[weakest]
        return kept, current, harmonics

    def displaced(self, terms: tuple[Term, ...], h: int) -> str | None:
        """:func:`~wbfriction.fit.term_checks.displaced_part` of ``terms`` with ``h`` harmonics."""
        names, X, k = self.design(terms, h)
        use, y = self.use, self.y
        return displaced_part(names, X[use], y[use], k, nonnegative_solve(X[use], y[use], names)[1], self.options)

    def unsound(self, kept: list[Term], harmonics: int) -> tuple[Term, str] | None:
        """The first kept term that is no friction, takes the friction's place, is too small or not determined,
        and why; None when every kept term is sound."""
        use, y = self.use, self.y
        names, X, k = self.design(tuple(kept), harmonics)
        coef, _ = nonnegative_solve(X[use], y[use], names)
        bad = unphysical_term(with_coefficients(self.params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))),
                              self.signals, use, self.t_ref or 0.0)  # friction that generates power (eq. 7.9)
        if bad is None and "ripple" in kept:
            bad = ripple_in_place(kept, harmonics, self.displaced, self.best_harmonics)
        return bad or negligible_term(names, X[use], coef, k, self.options) or undetermined_term(
            names, X, y, use, k, kept, harmonics, self.signals)

    def refuse_until_sound(self) -> tuple[list[Term], float, int]:
        """:meth:`select` again without each unsound term (:meth:`unsound`, its reason recorded) until the terms
        kept are sound: the terms, their held-out RMS and the ripple's harmonics."""
        refused: list[Term] = []
        while True:
            kept, current, harmonics = self.select(tuple(t for t in self.candidates if t not in refused))
            bad = self.unsound(kept, harmonics) if kept else None
            if bad is None:
                return kept, current, harmonics
            refused.append(bad[0])
            self.reasons[bad[0]] = f"not kept: {bad[1]}"

    def explain(self, kept: list[Term], current: float, harmonics: int) -> None:
        """Each tried term's reason, kept or not, where :meth:`refuse_until_sound` gave none."""
        tol = self.options.tolerance
        if "ripple" in self.candidates and "ripple" not in kept:
            ripples = self.direction_gains()
            if not any(g > tol for g in ripples.values()):
                best = max((g for g in ripples.values() if np.isfinite(g)), default=float("nan"))
                self.reasons["ripple"] = ("not kept: fitted on one direction of motion it does not predict the other "
                                          f"by more than {100 * tol:g} % (best {carries(best)}): not a torque of the "
                                          "angle")
        for term in self.candidates:
            if term not in kept and term not in self.reasons and not self.holds(term):
                self.reasons[term] = ("not kept: fitted on one direction of motion it does not predict the other by "
                                      f"more than {100 * tol:g} % ({carries(self.carry_over(term))}): not a law of "
                                      f"the {term}")
            if term in self.reasons:
                continue
            if term in kept:
                rms_without = self.best_harmonics(tuple(t for t in kept if t != term))[0]
                self.reasons[term] = (f"kept: held-out RMS {current:.4g} N·m with it, {rms_without:.4g} without "
                                      f"({_change(rms_without, current)})"
                                      + (f"; {harmonics} harmonics" if term == "ripple" else ""))
            else:
                rms_with = self.best_harmonics((*kept, term))[0]
                self.reasons[term] = (f"not kept: held-out RMS {current:.4g} N·m without it, {rms_with:.4g} with "
                                      f"({_change(rms_with, current)}; kept from -{100 * tol:g} %)")

    def final(self, kept: tuple[Term, ...], current: float, harmonics: int) -> TermFit:
        """The :class:`TermFit` of the terms ``kept`` (in :data:`TERMS` order): the temperature law chosen, every
        coefficient fitted on every sample, the later stretch checked."""
        params, use, y, t_ref = self.params, self.use, self.y, self.t_ref
        if not kept:
            return TermFit(params, reference_temperature=t_ref, reasons=self.reasons,
                           held_out_rms=(self.base_rms, self.base_rms))
        rate, rate_column = 0.0, None
        if "temperature" in kept and self.options.temperature_law != "linear":
            law = ExponentialLaw(params, self.qd, y, use, self.signals, kept, harmonics, t_ref or 0.0, self.smoother)
            rate, note, rms = law.choose(self.train, self.test, self.options)
            self.reasons["temperature"] += note
            current = rms if rate else current
        names, X, k = term_design(params, self.qd, self.signals, kept, harmonics, t_ref or 0.0, self.smoother, rate)
        if rate != 0.0:
            rate_column = partial(law.rate_column, rate, names)
        coef, cov, held = final_fit(X, y, use, names, rate_column)
        blocks = linear_block_spread(X, y, use, coef, np.array([n not in held for n in names]))
        refitted = with_coefficients(params, coef[:k])
        coefficients = dict(zip(names[k:], map(float, coef[k:])))
        stderr = dict(zip(names, map(float, covariance_errors(cov))))
        if rate != 0.0:
            coefficients["rate_T"], stderr["rate_T"] = rate, float(np.sqrt(max(cov[-1, -1], 0.0)))
        later = later_check(X, y, names, k, kept, self.train, self.test, self.options, rate_column)
        q_range = None
        derived = derived_parameters(refitted, coefficients)
        if "ripple" in kept and self.signals.q is not None:
            q_used = np.asarray(self.signals.q, dtype=float)[use]
            q_range = angle_arc(q_used)  # the physical angles' arc, whatever branches the table holds them on
            derived["ripple_rms"], stderr["ripple_rms"] = ripple_size(q_used, harmonics, names, coef, cov)
        return TermFit(refitted, kept, harmonics, coefficients, stderr, derived, t_ref, q_range, self.reasons,
                       (self.base_rms, current), at_bound=held, covariance=cov, later=later,
                       block_spread={n: float(b) for n, b in zip(names, blocks) if b > 0})


def _change(rms: float, current: float) -> str:
    """``rms`` against ``current`` [N·m] as a signed percentage; ``exact`` where the current held-out RMS is zero (a
    noise-free table the velocity model fits exactly: a friction of zero, issue 63)."""
    if current > 0:
        return f"{100 * (rms / current - 1):+.2g} %"
    return "both exact" if rms == 0 else "exact as it is"


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
    use = moving_samples(use, qd, y, signals)
    qd_ = qd if smoother is not None else np.where(use, qd, 0.0)
    names, X, k = term_design(params, qd_, signals, fit.kept, fit.harmonics, fit.reference_temperature or 0.0,
                          smoother, fit.temperature_rate)
    use &= np.isfinite(X).all(axis=1)
    if use.sum() <= X.shape[1]:
        return None
    coef, cov, held = final_fit(X, np.where(use, y, 0.0), use, names)
    blocks = linear_block_spread(X, np.where(use, y, 0.0), use, coef, np.array([n not in held for n in names]))
    coefficients = dict(zip(names, map(float, coef)))
    stderr = dict(zip(names, map(float, covariance_errors(cov))))
    if "ripple" in fit.kept and signals.q is not None:
        coefficients["ripple_rms"], stderr["ripple_rms"] = ripple_size(np.asarray(signals.q, dtype=float)[use],
                                                                      fit.harmonics, names, coef, cov)
    return TermCheck(route, coefficients, stderr, {n: float(b) for n, b in zip(names, blocks) if b > 0})



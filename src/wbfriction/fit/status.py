"""A verdict on every fit (issue 24): whether its numbers can be used, and why not in one phrase.

A fit that failed must not print as a result. Each :class:`~wbfriction.fit.result.FitResult` gets one
status, the first that applies:

* ``not excited``: too few valid samples to fit, or the joint hardly moved (95th percentile of ``|qd|``
  below :data:`MIN_SPEED`): its friction is not in these data;
* ``failed``: the solver stopped without converging (its message translated, :func:`solver_phrase`);
* ``at bound``: a parameter was left on a bound of the fit's search (its value is the bound's, not the
  data's), named. A magnitude at its floor of zero (F_c, F_v, S, F_s = 0: no such friction found) is a
  result, not a bound of the search, unless the data press it below zero (freed of the floor it would lie more than
  :data:`~wbfriction.fit.solve.PRESS_Z` standard errors below: :func:`~wbfriction.fit.solve.pressed_floors`; the
  data's friction then falls with the speed, which the model cannot draw); so is a slope at its upper bound (the
  tanh slope ``a`` of (3.5)): a step sharper than the data resolve is Coulomb friction (``sgn``), the step is the
  finding (:meth:`~wbfriction.fit.result.FitResult.steps`);
* ``routes disagree`` (issue 38): the same model fitted on the other route's estimate (the acceleration
  route's for the momentum route, and the other way round) differs on F_c or F_v by more than
  :data:`ROUTE_Z` combined statistical errors (each route's Newey-West error raised to its block jackknife's,
  :mod:`~wbfriction.fit.block_spread`) and :data:`ROUTE_REL`
  of the value: one of them is biased beyond what either route shows of itself; both values are given. The
  difference is also in the read error of every fit that has the other route (:mod:`~wbfriction.fit.route_spread`:
  not in what the check tests, which would make it vacuous);
* ``does not predict`` (issue 52): the same model fitted on the earliest samples predicts the last
  :data:`~wbfriction.fit.holdout.LATER` of them worse than the noise and its standard errors allow, beyond
  :data:`~wbfriction.fit.holdout.HOLDOUT_Z` standard errors, by more than
  :data:`~wbfriction.fit.holdout.HOLDOUT_EXCESS` of what is allowed and by more than
  :data:`~wbfriction.fit.holdout.HOLDOUT_FRICTION` of the joint's friction
  (:mod:`~wbfriction.fit.holdout`): the friction changed over the log, or a model error the standard errors
  do not see (the errors and held-out RMS given); a term beyond velocity that departs on the later stretch makes
  its joint so too (:mod:`~wbfriction.fit.term_selection`);
* ``weak``: the joint moved one way (the other on fewer than :data:`MIN_REVERSE` of its samples: its Coulomb
  friction and offset are not separable, whatever their standard errors say), or
  a parameter a user reads (F_c, F_v; tau_os against F_c) has a standard error (with ``model="auto"`` the
  statistical one, the larger of the Newey-West and the block jackknife's, the model family's spread and the routes'
  in quadrature: ``FitResult.read_stderr``), or a Cramér-Rao bound
  (:mod:`~wbfriction.fit.bound`: what the data allow any unbiased estimator), above :data:`WEAK` of its
  (non-zero) value, or is not identifiable (infinite standard error); a magnitude at zero whose standard error
  or bound stands for more than :data:`WEAK` of the friction the joint shows (``F_c``'s in N·m, ``F_v``'s times
  the joint's speed or :data:`READ_SPEED`, against the friction's odd part at the joint's speed and the residual's
  RMS: ``F_c = 0 ± 1.1`` beside a friction of 1 N·m is no finding);
  a fit on an estimate whose positions' noise could not be measured (a log, or its stretches between time gaps,
  too short: no Cramér-Rao bound to hold its standard errors to) is ``weak`` too, and says so (issue 53);
* ``ok``: none of these.

A fit that kept terms beyond velocity (:mod:`~wbfriction.fit.terms`) is judged on the model it predicts and
exports with: its velocity coefficients refitted with the terms (their standard errors; the other route's refit of
them) and each term's own status; its non-linear parameters (``a``, ``v_s``) are the velocity fit's, at a bound if
they were.

The table, the parameters JSON (``status``, ``status_reason``) and the report show it; a fit that is not
``ok`` is shown dimmed there, with its reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Literal, Protocol, cast, get_args

import numpy as np

from wbfriction.fit.block_spread import statistical_error
from wbfriction.fit.holdout import HOLDOUT_EXCESS, HOLDOUT_FRICTION, HOLDOUT_Z
from wbfriction.fit.route_spread import route_spread
from wbfriction.fit.solver import explain_solver

FitStatus = Literal["ok", "weak", "does not predict", "routes disagree", "at bound", "not excited", "failed"]
"""A fit's verdict (module docstring)."""
FIT_STATUSES: tuple[FitStatus, ...] = get_args(FitStatus)
MIN_SPEED = 0.02
"""A joint whose 95th percentile of ``|qd|`` over the fitted samples is below this [rad/s] is not excited."""


MIN_REVERSE = 0.05
"""A joint whose fitted samples move the other way on fewer than this share of them (:func:`reverse_share`) cannot
separate its Coulomb friction from its offset: ``F_c sgn(qd)`` and ``tau_os`` are then one column but for those few
samples, and the two numbers rest on them (on 5 % the pair's information is a fifth of an even log's). A walking
quadruped's thigh seen only while its leg swings (issue 56) moves one way; no real arm's log comes near
(measured in the issue's note)."""


def reverse_share(qd: np.ndarray) -> float:
    """The share of samples ``qd`` (n,) [rad/s] moving the less frequent way (``qd`` of the sign fewer of them have;
    zero counts as neither); 0.5 for none."""
    qd = np.asarray(qd, dtype=float)
    up, down = int(np.sum(qd > 0)), int(np.sum(qd < 0))
    return min(up, down) / (up + down) if up + down else 0.5


def joint_speed(qd: np.ndarray) -> float:
    """How much a joint moved: the 95th percentile of ``|qd|`` over samples ``qd`` (n,) [rad/s]; 0 for none.
    Below :data:`MIN_SPEED` the joint is not excited (the fit's status, the report's joints that did not move)."""
    qd = np.asarray(qd, dtype=float)
    return float(np.percentile(np.abs(qd), 95)) if qd.size else 0.0
ROUTE_Z = 3.0
"""Two routes disagree on a parameter beyond this many standard errors of their difference (each route's own
statistical error, the larger of its Newey-West and block-jackknife ones, combined as if independent: the routes share
the data's noise, so the difference's is smaller and the rule errs towards agreement). Not the read errors: they
carry the difference itself (:mod:`~wbfriction.fit.route_spread`)."""
ROUTE_REL = 0.02
"""... and beyond this share of the parameter's value: a difference below 2 % is no bias worth a status (the
routes' own quadratures differ by less)."""


def routes_disagree(a: float, se_a: float, b: float, se_b: float, z: float = ROUTE_Z, rel: float = ROUTE_REL) -> bool:
    """Whether two routes' values of one parameter disagree: they differ by more than ``z`` (:data:`ROUTE_Z`)
    combined standard errors (``se_a``, ``se_b``: each route's statistical error,
    :func:`~wbfriction.fit.block_spread.statistical_error`) and by more than ``rel`` (:data:`ROUTE_REL`) of the
    larger."""
    return abs(a - b) > z * math.hypot(se_a, se_b) and abs(a - b) > rel * max(abs(a), abs(b))


def read_error(stderr: float, model_spread: float = 0.0, block: float = 0.0, route: float = 0.0) -> float:
    """The standard error a user reads [the parameter's unit] (issue 63), in quadrature: the statistical one, the
    larger of the Newey-West ``stderr`` and the block jackknife's ``block``
    (:func:`~wbfriction.fit.block_spread.statistical_error`); the model error the data do not resolve
    (``model_spread``, :attr:`~wbfriction.fit.result.FitResult.model_spread`); the routes' difference's share
    (``route``, :mod:`~wbfriction.fit.route_spread`)."""
    return math.hypot(statistical_error(stderr, block), model_spread, route)


PROMISE = 0.20
"""The promise of ``ok`` (docs/explanation/statuses.md): an ``ok`` F_c or F_v lies within this share of the truth
about 19 times in 20, as far as the log's own spread (statistical, between time blocks, between the routes, between
the model families) shows its error; a bias none of them sees (a friction law no family holds, a model of the robot
off) is outside it, and the generalisation benchmark counts how often."""
WEAK = PROMISE / 2
"""A user-facing parameter whose standard error (or Cramér-Rao bound) exceeds this share of its value makes a fit
weak. Set by the promise of ``ok`` (:data:`PROMISE`), not fitted: the truth lies within two read errors about 95 % of
the time, so a read error at most ``PROMISE / 2`` of the value keeps it within ``PROMISE``. Checked on the
generalisation benchmark's tuning seeds (``docs/measurements/generalise.md``): the ``ok`` values outside ±20 % of the
truth were 10.7 % of them at 0.25 and are 6.5 % at 0.10, fewer in every class."""
TERM_WEAK = 0.5
"""The same for a term beyond velocity's coefficients (:mod:`~wbfriction.fit.terms`): a term is kept by the
held-out samples it predicts, and its coefficient's standard error above half its value makes it weak."""
READ = ("F_c", "F_v")
"""The magnitudes a user reads off a fit (tau_os is judged against F_c: it may be zero)."""
ZERO_FLOOR = ("F_v", "F_c", "S", "F_s")
"""Magnitudes whose lower bound is zero: there, the data say "none of this friction"."""
ZERO = 1e-6
"""A magnitude below this (in its unit) is at its floor of zero."""
READ_SPEED = 1.0
"""The speed [rad/s] a viscous coefficient at zero is judged at, or the joint's own if it moved faster: a user
reads F_v = 0 as no viscous friction at any speed, not only at the few the log saw."""


@dataclass(frozen=True)
class StatusThresholds:
    """The thresholds the statuses are decided by (module docstring), the defaults chosen across the real datasets
    and the simulators (README, *Defaults chosen across the data*; ``benchmarks/study_defaults.py``).

    Attributes:
        weak: a standard error or Cramér-Rao bound above this share of its value makes a fit ``weak``.
        route_z, route_rel: the routes disagree beyond this many combined standard errors and this share.
        holdout_z, holdout_excess, holdout_friction: a fit does not predict its later stretch beyond this many
            standard errors, this share of what the noise and its standard errors allow, and an excess of this share
            of its friction (:mod:`~wbfriction.fit.holdout`).
    """

    weak: float = WEAK
    route_z: float = ROUTE_Z
    route_rel: float = ROUTE_REL
    holdout_z: float = HOLDOUT_Z
    holdout_excess: float = HOLDOUT_EXCESS
    holdout_friction: float = HOLDOUT_FRICTION


DEFAULT_THRESHOLDS = StatusThresholds()


class Fit(Protocol):
    """What a verdict reads of a fit (:class:`~wbfriction.fit.result.FitResult`)."""

    params: Any
    success: bool
    message: str
    stderr: dict[str, float]
    speed: float | None
    crb: dict[str, float]
    route_check: Any
    rms_residual: float
    later: Any
    at_bound: dict[str, bool]
    pressed: dict[str, tuple[float, float]]
    model_spread: dict[str, float]
    block_spread: dict[str, float]
    route_spread: dict[str, float]

    def bounded(self) -> tuple[str, ...]: ...

    def steps(self) -> tuple[str, ...]: ...


@dataclass(frozen=True)
class FitVerdict:
    """A fit's status and the reason, one phrase ("" when ``ok``)."""

    status: FitStatus
    reason: str = ""

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def __str__(self) -> str:
        return self.status + (f": {self.reason}" if self.reason else "")


def solver_phrase(message: str) -> str:
    """What ``scipy.optimize.least_squares``' message means for the result, in one phrase: "the solver "
    and :func:`~wbfriction.fit.solver.explain_solver`'s meaning."""
    return "the solver " + explain_solver(message).meaning


def fit_verdict(fit: Fit, thresholds: StatusThresholds = DEFAULT_THRESHOLDS) -> FitVerdict:
    """The status of ``fit`` and its reason (module docstring), decided by ``thresholds``."""
    if fit.params is None:
        return FitVerdict("not excited", fit.message or "not fitted")
    if fit.speed is not None and fit.speed < MIN_SPEED:
        return FitVerdict("not excited", f"it hardly moved (|qd| at most {fit.speed:.2g} rad/s on 95 % of "
                                         "its samples)")
    if not fit.success:
        return FitVerdict("failed", solver_phrase(fit.message))
    terms = getattr(fit, "kept_terms", None)
    if terms is not None:
        return _with_terms(fit, terms, thresholds)
    values = fit.params.to_dict()
    bounded = search_bounds(fit)
    if bounded:
        return FitVerdict("at bound", "at a bound of the fit: " + bound_phrase(fit, bounded))
    check = fit.route_check
    disagree = _disagreeing(fit, values, thresholds)
    if check is not None and disagree:
        return FitVerdict("routes disagree", check.describe(fit, disagree))
    if fit.later is not None and not fit.later.predicts_at(thresholds.holdout_z, thresholds.holdout_excess,
                                                                thresholds.holdout_friction):
        return FitVerdict("does not predict", fit.later.describe())
    weak = _weak(fit, values, thresholds.weak)
    return _weak_verdict(fit, weak)


def search_bounds(fit: Fit) -> list[str]:
    """The parameters of ``fit`` (with parameters) left on a bound of the fit's search: its
    :meth:`~wbfriction.fit.result.FitResult.bounded` less a magnitude at its floor of zero (:data:`ZERO_FLOOR`: no
    such friction found, a result) that the data do not press below it (``fit.pressed``) and a slope at its step
    bound (:meth:`~wbfriction.fit.result.FitResult.steps`: Coulomb friction). What makes a fit ``at bound``."""
    return [n for n in fit.bounded() if not (n in ZERO_FLOOR and n not in fit.pressed) and n not in fit.steps()]


def bound_phrase(fit: Fit, names: list[str]) -> str:
    """``names`` (of :func:`search_bounds`) as the status's reason gives them: a magnitude pressed against its floor
    with the value the data ask for (``F_v at zero, the data ask for -0.2 ± 0.02``)."""
    pressed = fit.pressed
    return ", ".join(f"{n} at zero, the data ask for {pressed[n][0]:.2g} ± {pressed[n][1]:.1g}" if n in pressed else n
                     for n in names)


def _weak_verdict(fit: Fit, weak: list[str]) -> FitVerdict:
    """``weak`` for a joint that moved one way (:data:`MIN_REVERSE`), the large standard errors ``weak`` or a noise
    not measured (``fit.unmeasured``), else ``ok``."""
    unmeasured = str(getattr(fit, "unmeasured", "") or "")
    reverse, names = getattr(fit, "reverse", None), fit.params.names
    one_way = [f"it moved one way (the other on {100 * reverse:.1f} % of its samples): F_c and tau_os are not "
               "separable"] if reverse is not None and reverse < MIN_REVERSE and {"F_c", "tau_os"} <= set(names) else []
    reasons = ([unmeasured] if unmeasured else []) + one_way + (
        ["large standard errors: " + ", ".join(weak)] if weak else [])
    return FitVerdict("weak", "; ".join(reasons)) if reasons else FitVerdict("ok")


HELD = ("a", "v_s")
"""The parameters a refit with terms beyond velocity holds at the velocity fit's values (the non-linear ones): one
at a bound there is at it in the refit."""


def _disagreeing(fit: Fit, values: dict[str, float], thresholds: StatusThresholds) -> tuple[str, ...]:
    """The parameters on which ``fit``'s routes disagree (:func:`routes_disagree` at ``thresholds``)."""
    check = fit.route_check
    if check is None or check.params is None:
        return ()
    theirs = getattr(check, "block_spread", {}) or {}
    return tuple(n for n in READ if n in values and n in check.params and routes_disagree(
        values[n], statistical_error(fit.stderr.get(n, np.inf), fit.block_spread.get(n, 0.0)), check.params[n],
        statistical_error(check.stderr.get(n, np.inf), theirs.get(n, 0.0)), thresholds.route_z,
        thresholds.route_rel))


def _with_terms(fit: Fit, terms: Any, thresholds: StatusThresholds = DEFAULT_THRESHOLDS) -> FitVerdict:
    """The verdict of a fit that kept terms beyond velocity (:class:`~wbfriction.fit.terms.TermFit`): of the
    model it predicts and exports with, the velocity coefficients refitted with the terms (their standard errors,
    the other route's refit of them) and each term's own (:meth:`~wbfriction.fit.terms.TermFit.verdicts`)."""
    values = terms.params.to_dict()
    # and the velocity fit's pressed magnitudes, where the refit left them at zero too
    bounded = [n for n in fit.bounded() if n in HELD and n not in fit.steps()] + [
        n for n in fit.pressed if n in terms.at_bound]
    if bounded:
        return FitVerdict("at bound", "at a bound of the fit: " + bound_phrase(fit, bounded))
    check = terms.check
    others = {t: v for t, v in terms.verdicts().items() if not v.ok}
    mine = {n: statistical_error(se, terms.block_spread.get(n, 0.0)) for n, se in terms.stderr.items()}
    theirs = {} if check is None else {n: statistical_error(se, check.block_spread.get(n, 0.0))
                                       for n, se in check.stderr.items()}
    disagree = [] if check is None else [
        f"{n} {values[n]:.3g} ±{mine.get(n, np.inf):.2g} against {check.coefficients[n]:.3g} "
        f"±{theirs.get(n, np.inf):.2g} ({check.route})" for n in READ
        if n in check.coefficients and routes_disagree(values[n], mine.get(n, np.inf), check.coefficients[n],
                                                       theirs.get(n, np.inf), thresholds.route_z,
                                                       thresholds.route_rel)]
    disagree += [f"{t}: {v.reason}" for t, v in others.items() if v.status == "routes disagree"]
    if disagree:
        return FitVerdict("routes disagree", "; ".join(disagree))
    if fit.later is not None and not fit.later.predicts_at(thresholds.holdout_z, thresholds.holdout_excess,
                                                                thresholds.holdout_friction):
        return FitVerdict("does not predict", fit.later.describe())
    later = [f"{t}: {v.reason}" for t, v in others.items() if v.status == "does not predict"]
    if later:
        return FitVerdict("does not predict", "; ".join(later))
    # over part of a turn a ripple's harmonics have a mean the offset trades with: their sum is determined (the
    # energy check removes both), the offset alone is not, and it is no friction a user reads
    judged = [n for n in values if n in terms.stderr and not (n == "tau_os" and "ripple" in terms.kept)]
    view = SimpleNamespace(params=terms.params, stderr={n: terms.stderr[n] for n in judged}, crb={}, speed=fit.speed,
                           rms_residual=fit.rms_residual, at_bound={n: True for n in terms.at_bound},
                           model_spread=fit.model_spread, block_spread=terms.block_spread,
                           route_spread={} if check is None else route_spread(values, check.coefficients, READ))
    weak = _weak(cast(Fit, view), values, thresholds.weak) + [f"{t} {v.reason.removeprefix('large standard errors: ')}"
                                             for t, v in others.items() if v.status == "weak"]
    return _weak_verdict(fit, weak)


def _weak(fit: Fit, values: dict[str, float], limit: float = WEAK) -> list[str]:
    """What makes ``fit`` weak (module docstring) at ``limit`` (:data:`WEAK`), one phrase each."""
    speed = fit.speed or 0.0
    odd = 0.5 * float(fit.params.f(speed) - fit.params.f(-speed))  # the friction the joint shows at its speed
    scale = max(abs(odd), fit.rms_residual if np.isfinite(fit.rms_residual) else 0.0)
    out = []
    for name in (n for n in READ if n in fit.stderr):
        # a magnitude its fit left at its floor is zero (1e-5 of an F_v is the solver's, not the data's)
        value = 0.0 if fit.at_bound.get(name) else abs(values[name])
        family = fit.model_spread.get(name, 0.0)  # the model error the data do not resolve, in quadrature (issue 63)
        read = read_error(fit.stderr[name], family, fit.block_spread.get(name, 0.0), fit.route_spread.get(name, 0.0))
        for bound, spread in ((False, read), (True, fit.crb.get(name, 0.0))):
            at_best = " at best (Cramér-Rao)" if bound else ""
            if not np.isfinite(spread):
                out.append(f"{name} not identifiable{at_best}")
                break
            if value >= ZERO and spread > limit * value:
                of_family = f" (model error ±{100 * family / value:.0f} %)" if not bound and family > ZERO else ""
                out.append(f"{name} ±{100 * spread / value:.0f} %{at_best}{of_family}")
                break
            # a magnitude at zero: against the friction it would make at the speed a user reads it at
            share = spread * (max(speed, READ_SPEED) if name == "F_v" else 1.0)
            if value < ZERO and share > limit * scale:
                out.append(f"{name} 0 ±{spread:.2g}{at_best} ({share:.2g} N·m against {scale:.2g} N·m of friction)")
                break
    se_os, f_c = fit.stderr.get("tau_os", 0.0), abs(values.get("F_c", 0.0))
    if not np.isfinite(se_os):
        out.append("tau_os not identifiable")
    elif f_c >= ZERO and se_os > limit * f_c:
        out.append(f"tau_os ±{se_os:.2g} N·m against F_c {f_c:.2g}")
    return out

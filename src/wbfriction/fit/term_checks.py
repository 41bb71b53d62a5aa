"""What a term beyond velocity must show to be kept (issues 40 and 52): that it holds whichever way the joint moves
(:func:`direction_gain`), that its ripple's harmonics are told apart (:func:`ripple_condition`), that it predicts a
later stretch it was not fitted on (:func:`later_check`), keeps the friction physical (:func:`unphysical_term`),
does not take the velocity model's place (:func:`displaced_part`, :func:`ripple_in_place`), is determined
(:func:`undetermined_term`) and matters (:func:`negligible_term`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from wbfriction.fit.options import TermOptions
from wbfriction.fit.regression import (
    covariance_errors,
)
from wbfriction.fit.status import MIN_SPEED, ROUTE_Z, TERM_WEAK
from wbfriction.fit.term_design import final_fit, nonnegative_solve, ripple_size, solve_lstsq, term_of
from wbfriction.fit.terms import (
    TermSignals,
    fourier,
    temperature_shape,
)
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import TERMS, Term

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
        c = solve_lstsq(F[train], residual[train])
        before = residual[test] - residual[test].mean()
        after = residual[test] - F[test] @ c
        after = after - after.mean()  # each way its own level: a Coulomb level the velocity model took flips sign
        spread = float(np.mean(before**2))
        if not spread > 0.0:  # nothing left to predict that way
            return float("nan")
        gains.append(1.0 - float(np.sqrt(np.mean(after**2) / spread)))
    return min(gains)


def carries(gain: float) -> str:
    """How far a term carried over between the directions of motion (:func:`direction_gain`), as its reason says."""
    return ("too few samples moving each way to tell" if not np.isfinite(gain)
            else f"{100 * gain:+.2g} %")


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
    fits = [final_fit(X, y, rows, names, rate_column)[:2] for rows in (head, tail)]
    (c_h, C_h), (c_t, C_t) = fits
    noise = TERM_WEAK * float(np.sqrt(np.mean((y[tail] - X[tail] @ c_t) ** 2)))
    out: dict[str, tuple[float, float]] = {}
    for term in kept:
        cols = [i for i, n in enumerate(names) if i >= k and term_of(n) == term]
        rest = [i for i in range(X.shape[1]) if i not in cols]
        Xt, Xo = X[tail][:, cols], X[tail][:, rest]
        Xt = Xt - Xo @ solve_lstsq(Xo, Xt)
        d = Xt @ (c_h[cols] - c_t[cols])
        C = (C_h + C_t)[np.ix_(cols, cols)]
        var = np.einsum("ij,jk,ik->i", Xt, C, Xt) if np.all(np.isfinite(C)) else np.full(len(Xt), np.inf)
        out[term] = (float(np.sqrt(np.mean(d**2))),
                     max(ROUTE_Z * float(np.sqrt(np.mean(var))), noise, options.min_torque))
    return out


def unphysical_term(params: ModelParams, c: dict[str, float], signals: TermSignals, use: np.ndarray,
                t_ref: float, rate: float = 0.0) -> tuple[Term, str] | None:
    """The first friction term whose levels go below zero on the samples (a viscous level in a direction, a Coulomb
    level under a load met, a level at a temperature met) and what goes below; None when all stay physical."""
    quantities = params.quantities()  # any family's (a family without a Coulomb level: 0)
    F_c, F_v = quantities["F_c"], quantities["F_v"]
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
    :attr:`TermOptions.min_torque`, as :func:`negligible_term`). The data then cannot tell the terms from the
    friction: a 3-harmonic ripple on the Panda's flange, over the 2.7 rad its excitation swept, took the whole
    Coulomb level (0.28 N·m at every speed in its estimate, as published) and left a viscous line 50 % off the
    published curve (issue 52). One coefficient of a part held (F_cS of (3.5), its Coulomb level F_c still there)
    takes nothing. ``X`` (n, p), ``y`` (n,): the design and the friction on the samples fitted; ``k``: the velocity
    model's columns."""
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
    :func:`ripple_size`) with a standard error (fitted on every sample ``use``, :func:`final_fit`) above
    :data:`~wbfriction.fit.status.TERM_WEAK` of its value; None when each is. It lowered the held-out RMS
    by chance, and would be printed ``weak`` (issue 52: a UR10e shoulder's direction term, dF_v -1.03 ±0.76
    N·m·s/rad, took the viscous level's place and moved its curve 6 % from the published one)."""
    coef, cov, _ = final_fit(X, y, use, names)
    se = covariance_errors(cov)
    for term in TERMS:
        if term not in kept:
            continue
        if term == "ripple" and signals.q is not None:
            values = [ripple_size(np.asarray(signals.q, dtype=float)[use], harmonics, names, coef, cov)]
        else:
            values = [(float(coef[i]), float(se[i])) for i, n in enumerate(names) if i >= k and term_of(n) == term]
        if values and not any(e <= TERM_WEAK * abs(v) for v, e in values):
            shown = ", ".join(f"{v:.3g} ±{e:.2g}" for v, e in values)
            return term, (f"its coefficients are not determined ({shown}: standard errors above "
                          f"{100 * TERM_WEAK:g} % of the values): it predicts the held-out samples better by chance")
    return None


def negligible_term(names: tuple[str, ...], X: np.ndarray, coef: np.ndarray, k: int,
                options: TermOptions) -> tuple[Term, str] | None:
    """The kept term whose torque over the samples (the standard deviation of its regressors times its
    coefficients, ``X`` (n, p) the design on them) is the smallest, if it is below :attr:`TermOptions.min_effect`
    of the velocity model's friction or below :attr:`TermOptions.min_torque`: a term too small to matter (on
    noise-free data, the 2 % rule alone keeps terms of a thousandth of the friction); None when every term
    matters."""
    friction = float(np.sqrt(np.mean((X[:, :k] @ coef[:k]) ** 2)))
    effects: dict[Term, float] = {}
    for term in TERMS:
        cols = [i for i, n in enumerate(names) if i >= k and term_of(n) == term]
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

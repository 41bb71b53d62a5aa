"""The linear regression of a joint's terms beyond velocity (issue 40): the joint design ``[B | Phi_1 | ...]`` of
the velocity model's linear coefficients and the terms' (:func:`term_design`), the samples it is fitted on
(:func:`moving_samples`), least squares with the friction's magnitudes kept non-negative
(:func:`nonnegative_solve`), the coefficients' Newey-West covariance (:func:`final_fit`), and what the coefficients
make (:func:`ripple_size`, :func:`derived_parameters`). :mod:`~wbfriction.fit.term_selection` chooses the terms with
them; :mod:`~wbfriction.fit.term_checks` judges them."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from wbfriction.fit.regression import (
    correlation_lag,
    parameter_covariance,
)
from wbfriction.fit.status import MIN_SPEED
from wbfriction.fit.terms import (
    TERM_COEFFICIENTS,
    TermSignals,
    fourier,
    term_basis,
    velocity_basis,
)
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import Term


def term_design(params: ModelParams, qd: np.ndarray, signals: TermSignals, terms: tuple[Term, ...], harmonics: int,
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


def solve_lstsq(X: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(X, y, rcond=None)[0]


NONNEGATIVE = ("F_v", "F_c", "F_cS", "F_s")
"""The velocity model's linear coefficients that are magnitudes (the fit's bounds): refitted with the terms, one
that would go below zero is held at zero (:attr:`TermFit.at_bound`). The Stribeck curve's static level ``F_s`` is
one: refitted free with a ripple on a humanoid's torso roll it came out -0.048 N·m, which ``predict``, ``export``
and ``report`` refuse (:mod:`~wbfriction.fit.params_check`, issue 63): ``fit`` does not write it."""


def nonnegative_solve(X: np.ndarray, y: np.ndarray, names: tuple[str, ...]) -> tuple[np.ndarray, tuple[str, ...]]:
    """Least squares with the :data:`NONNEGATIVE` coefficients at zero where they would go below: the most negative
    held at zero and the rest refitted, until none is; and the names held. ``F_c`` of (3.5) held at zero holds its
    Stribeck part ``F_cS = F_c S`` with it: a Stribeck rise without a Coulomb level is no (3.5) (its ``S`` would be
    infinite; :func:`~wbfriction.fit.terms.with_coefficients` would drop it)."""
    free = np.ones(len(names), dtype=bool)
    while True:
        coef = np.zeros(len(names))
        coef[free] = solve_lstsq(X[:, free], y)
        negative = [i for i, n in enumerate(names) if n in NONNEGATIVE and free[i] and coef[i] < 0]
        if not negative:
            return coef, tuple(n for n, f in zip(names, free) if not f)
        worst = min(negative, key=lambda i: coef[i])
        free[worst] = False
        if names[worst] == "F_c" and "F_cS" in names:
            free[names.index("F_cS")] = False


def moving_samples(use: np.ndarray, qd: np.ndarray, y: np.ndarray, signals: TermSignals) -> np.ndarray:
    """The samples of ``use`` the terms are fitted on: finite, signals too, and moving (``|qd|`` above
    :data:`~wbfriction.fit.status.MIN_SPEED`): a joint at rest has static friction, any value up to its static
    level, which no law of the load or the temperature of the moving friction describes (on the ideal simulator's
    noise-free walk, the 20 samples of 3,900 about the knees' reversals bias F_L by 5 %)."""
    use = np.asarray(use, dtype=bool) & np.isfinite(qd) & np.isfinite(y) & (np.abs(qd) > MIN_SPEED)
    for signal in (signals.q, signals.tau_load, signals.temperature):
        if signal is not None:
            use &= np.isfinite(signal)
    return use


def final_fit(X: np.ndarray, y: np.ndarray, use: np.ndarray, names: tuple[str, ...],
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


def term_of(name: str) -> Term:
    """The term a coefficient belongs to."""
    if name.startswith("ripple"):
        return "ripple"
    if name == "rate_T":
        return "temperature"
    return next(t for t, names in TERM_COEFFICIENTS.items() if name in names)


def derived_parameters(params: ModelParams, c: dict[str, float]) -> dict[str, float]:
    """The physical parameters of the coefficients (:attr:`TermFit.derived`)."""
    out: dict[str, float] = {}
    levels = params.quantities()  # any family's (a family without a Coulomb level: 0)
    F_c, F_v, tau_os = levels["F_c"], levels["F_v"], levels["tau_os"]
    if "F_L" in c:
        out["k_L"] = c["F_L"] / F_c if F_c else float("nan")
    if "dF_v" in c:
        out.update({"F_v+": F_v + c["dF_v"], "F_v-": F_v - c["dF_v"], "F_c+": F_c + tau_os,
                    "F_c-": F_c - tau_os})
    if "F_cT" in c:
        out["k_Tc"] = c["F_cT"] / F_c if F_c else float("nan")
        out["k_Tv"] = c["F_vT"] / F_v if F_v else float("nan")
    return out

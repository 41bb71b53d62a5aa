"""The temperature term's law (issue 40): linear, or exponential with its rate found by variable projection and kept
where held-out samples say so (:class:`ExponentialLaw`; the law itself:
:func:`~wbfriction.fit.terms.temperature_shape`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from wbfriction.fit.options import TermOptions
from wbfriction.fit.status import TERM_WEAK
from wbfriction.fit.term_checks import unphysical_term
from wbfriction.fit.term_design import final_fit, nonnegative_solve, solve_lstsq, term_design
from wbfriction.fit.terms import (
    TermSignals,
    coulomb_shape,
    temperature_shape_rate,
    with_coefficients,
)
from wbfriction.friction.models import ModelParams
from wbfriction.friction.options import Term

RATE_SPAN = 3.0
"""The exponential temperature law's rate is searched within ``RATE_SPAN`` over the largest ``|T - T_ref|`` met
[1/°C]: a level that changes by up to ``e^3`` (20 times) over the temperatures logged, beyond any grease's."""


@dataclass(frozen=True)
class ExponentialLaw:
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
        """:func:`term_design` of the kept terms at ``rate``, undefined rows at zero (they are not used)."""
        names, X, k = term_design(self.params, self.qd, self.signals, self.terms, self.harmonics, self.t_ref,
                              self.smoother, rate)
        return names, np.nan_to_num(X), k

    def residual(self, rate: float, train: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """The residual (on ``rows``) of the coefficients fitted on ``train`` at ``rate``."""
        _, X, _ = self.design(rate)
        return self.y[rows] - X[rows] @ solve_lstsq(X[train], self.y[train])

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
        unphysical = unphysical_term(with_coefficients(self.params, coef[:k]),
                                     dict(zip(names[k:], map(float, coef[k:]))), self.signals, self.use, self.t_ref,
                                     rate)
        versus = (f"held-out RMS {rms['exponential']:.4g} N·m exponential (rate {rate:.3g} /°C), {rms['linear']:.4g} "
                  "linear")
        if unphysical is not None:
            return 0.0, f"; law linear: the exponential's levels go below zero ({versus})", rms["exponential"]
        if options.temperature_law == "exponential":
            return rate, f"; law exponential (asked): {versus}", rms["exponential"]
        if not rms["exponential"] < (1.0 - options.tolerance) * rms["linear"]:
            return 0.0, f"; law linear: {versus}", rms["exponential"]
        _, cov, _ = final_fit(X, self.y, self.use, names, partial(self.rate_column, rate, names))
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

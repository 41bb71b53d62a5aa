"""Identification of a friction model from estimated friction (thesis 6.2.2, eq. 6.4), and the
choice among the models by held-out error.

Per joint, ``scipy.optimize.least_squares(method="trf")`` fits the characteristic ``f(qd; p)``
of one of the models of :mod:`wbfriction.friction.models` (``coulomb-viscous``, ``stribeck``
or the thesis's (3.5)) to ``-tau_f`` over the valid samples (sign convention of that module),
with bounds, from one start: the minimum over the non-linear parameters ``(v_s, a)`` with the linear ones solved
exactly (variable projection, :mod:`wbfriction.friction.projection`: a coarse grid, then a local search). Each
parameter gets a standard error from the Jacobian at
the solution,

.. math:: \\operatorname{cov}(\\hat p) = s^2 (J^T J)^{-1}, \\qquad s^2 = \\frac{\\|r\\|^2}{N - p},

computed through the SVD of J, with a Newey-West correction for residuals correlated in
time (filtered estimates above all; :func:`standard_errors`); a parameter with a component
in the numerical null space of J (e.g. ``v_s`` when ``S = 0``, or the Stribeck parameters when the data never
leave the Stribeck region) gets an infinite standard error: the data cannot identify it.

The bounds (:func:`model_bounds`) keep friction dissipative (F_v, F_c >= 0) and the Stribeck
effect a drop from static to Coulomb friction: (3.5)'s ``S >= 0``, and the Stribeck model's
``F_s >= F_c``, fitted as ``F_s - F_c >= 0`` (its standard error is F_s's own). A parameter that
ends on one of its bounds (e.g. ``S = 50`` with ``F_c -> 0``, what (3.5) gives on a real arm's
noisy log and on any friction whose static level decays to no Coulomb level; the Stribeck
model's F_s at F_c: no Stribeck drop) is flagged in :attr:`FitResult.at_bound`: its value is
the bound's, not the data's.

**Model choice** (``model="auto"``): the valid samples are cut into :data:`HELD_OUT_BLOCKS`
contiguous blocks in time; every :data:`HELD_OUT_PERIOD`-th (the 2nd, 5th, 8th) is held out
(:func:`held_out_split`, deterministic), every model is fitted on the others, and its RMS error
on the held-out blocks compared (:func:`held_out_rms`). The simplest model whose held-out RMS
is within ``selection_tolerance`` (relative, default :data:`SELECTION_TOLERANCE`) of the best
is chosen (:func:`choose_model`, the reason recorded in :class:`ModelSelection`) and fitted
again on every valid sample, as if it had been named. Whole blocks, not scattered samples, are
held out: residuals correlated in time (filtered estimates) would otherwise let the held-out
error see the fit's noise. With too few samples to hold a block out (fewer than
``min_samples`` on either side), or for a joint that hardly moved (below
:data:`~wbfriction.friction.status.MIN_SPEED`: ``not excited``, no velocity model in its data), the simplest model
is fitted.

Filtered estimates (thesis 7.1) are compared with the model filtered the same way: when
the friction went through a zero-phase smoother ``H``, the fit minimises
``|H(f(qd; p))[valid] + tau_f[valid]|^2`` over the whole time series, as in
the parallel filtering of robot identification (the filter applied to observations and
model alike), so that the smoothing of the model's jumps at velocity reversals (Coulomb,
Stribeck) is not mistaken for a different model. The start is searched on that same filtered objective.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Generic, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.exceptions import InputError
from wbfriction.friction.bound import BATCH, JointNoise, cramer_rao, torque_noise
from wbfriction.friction.eiv import expected_jacobian, expected_values
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.holdout import (
    LATER,
    MIN_HELD_OUT,
    PredictionCheck,
    prediction_check,
    prediction_variance,
    split_later,
)
from wbfriction.friction.models import (
    MODEL_NAMES,
    MODEL_PARAMS,
    ModelName,
    ModelParams,
    ModelParamsBase,
    ParamsT,
    check_model,
    model_jacobian,
    target_from_dict,
)
from wbfriction.friction.noise import joint_noises
from wbfriction.friction.options import MODEL_CHOICES, PASS_ROWS, SELECTION_TOLERANCE, FitOptions, ModelChoice
from wbfriction.friction.projection import BASINS, Projection, projected_start
from wbfriction.friction.ranges import FittedRanges
from wbfriction.friction.regression import (
    correlation_lag,
    covariance_errors,
    held_out_gain,
    held_out_split,
    parameter_covariance,
)
from wbfriction.friction.screen import gross_outliers
from wbfriction.friction.smoothing import row_smoothing, smoother_half_width
from wbfriction.friction.status import HELD, MIN_SPEED, FitVerdict, fit_verdict, joint_speed, routes_disagree
from wbfriction.friction.term_selection import fit_terms, refit_terms
from wbfriction.friction.terms import TermFit, term_signals
from wbfriction.workers import process_pool

AT_BOUND_RTOL = 1e-6
"""A parameter within ``AT_BOUND_RTOL * max(1, |bound|)`` of a bound is at it."""

AT_BOUND_SSR = 0.01
"""An identifiable parameter is also at a bound when moving it there raises the sum of squared
residuals by less than ``AT_BOUND_SSR`` residual variances (for a linear model: it is less than
``sqrt(AT_BOUND_SSR) = 0.1`` standard errors from it); the solver's iterates stay strictly inside
the bounds and may stop short of one in a flat direction (e.g. S = 49.97 of 50)."""

AT_BOUND_NEAR = 1e-3
"""A parameter the data do not identify (infinite standard error) is at a bound within
``AT_BOUND_NEAR * max(1, |bound|)`` of it."""

LOWER = np.array([0.0, 0.0, 0.0, 1e-4, -np.inf, 1e-2])
UPPER = np.array([np.inf, np.inf, 50.0, 100.0, np.inf, 1e4])
"""Bounds of (F_v, F_c, S, v_s, tau_os, a) of model (3.5): dissipative viscous and Coulomb parts, static
friction at least the Coulomb level (S >= 0: the Stribeck effect is a drop from static to
Coulomb friction), positive Stribeck velocity and tanh slope. The fit further bounds ``v_s``
by the largest speed in the data: a Stribeck velocity beyond it is not identifiable, and
the Stribeck term would otherwise mimic viscous friction (S < 0, v_s large)."""

_BOUNDS: dict[ModelName, tuple[np.ndarray, np.ndarray]] = {
    "coulomb-viscous": (np.array([0.0, 0.0, -np.inf]), np.array([np.inf, np.inf, np.inf])),
    # the fit's coordinates: F_s is fitted as the Stribeck drop F_s - F_c >= 0 (module docstring)
    "stribeck": (np.array([0.0, 0.0, 0.0, 1e-4, -np.inf]), np.array([np.inf, np.inf, np.inf, 100.0, np.inf])),
    "thesis": (LOWER, UPPER),
}
STEP_SLOPES = ("a",)
"""Slopes whose upper bound means a step (:meth:`FitResult.steps`)."""
_V_S = {"coulomb-viscous": None, "stribeck": 3, "thesis": 3}  # position of v_s, bounded by the data's speed
_FIXED_COLUMNS: dict[ModelName, tuple[int, ...]] = {
    "coulomb-viscous": (0, 1, 2), "stribeck": (0, 4), "thesis": (0, 4)}
"""Columns of :func:`model_jacobian` that do not depend on the parameters: the model is linear in
those (F_v: ``qd``; F_c of the Coulomb-viscous model: ``sgn(qd)``; tau_os: 1)."""


def model_bounds(qd: np.ndarray, model: ModelName = "thesis") -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of ``model``'s parameters, in the fit's coordinates, for velocities
    ``qd`` (N,) [rad/s]: :data:`LOWER`, :data:`UPPER` for (3.5); for ``coulomb-viscous``
    F_v, F_c >= 0; for ``stribeck`` F_v, F_c >= 0, ``F_s >= F_c`` (its coordinate is F_s - F_c >= 0)
    and v_s in [1e-4, 100]; ``v_s`` at most the largest speed in ``qd``."""
    lower, upper = (b.copy() for b in _BOUNDS[model])
    i = _V_S[model]
    if i is not None:
        upper[i] = max(float(np.max(np.abs(qd))), 2 * lower[i])
    return lower, upper


def to_fit_coordinates(model: ModelName, x: np.ndarray) -> np.ndarray:
    """The fit's coordinates of ``model``'s parameters ``x`` (P,) (in the order of its names, e.g.
    :data:`~wbfriction.friction.models.STRIBECK_NAMES`): the Stribeck model's F_s becomes F_s - F_c, so
    that ``F_s >= F_c`` is a bound; the others as they are."""
    z = np.array(x, dtype=float)
    if model == "stribeck":
        z[2] = x[2] - x[1]
    return z


def from_fit_coordinates(model: ModelName, z: np.ndarray) -> np.ndarray:
    """The model's parameters (P,) from the fit's coordinates ``z`` (P,): inverse of :func:`to_fit_coordinates`."""
    x = np.array(z, dtype=float)
    if model == "stribeck":
        x[2] = z[1] + z[2]
    return x


def fit_coordinates_jacobian(model: ModelName, jac: np.ndarray) -> np.ndarray:
    """The Jacobian (N, P) in the fit's coordinates from ``jac`` (N, P) in the model's (the chain rule of
    :func:`from_fit_coordinates`)."""
    if model == "stribeck":
        jac = jac.copy()
        jac[:, 1] += jac[:, 2]
    return jac


@dataclass(frozen=True)
class HeldOutScore:
    """One model's fit on the training blocks, scored on the held-out ones.

    Attributes:
        model: the model.
        held_out_rms: RMS of (model - estimate) over the held-out samples [N·m] (NaN: no fit).
        at_bound: the parameters that fit left at a bound.
    """

    model: ModelName
    held_out_rms: float
    at_bound: tuple[str, ...] = ()


@dataclass(frozen=True)
class ModelSelection:
    """How ``model="auto"`` chose a joint's model (module docstring).

    Attributes:
        chosen: the model fitted.
        reason: why, in one sentence.
        scores: every candidate's held-out score, simplest model first (empty when too few samples).
        tolerance: relative excess over the best held-out RMS within which a simpler model wins.
        n_train, n_held_out: samples the candidates were fitted on and scored on.
    """

    chosen: ModelName
    reason: str
    scores: tuple[HeldOutScore, ...] = ()
    tolerance: float = SELECTION_TOLERANCE
    n_train: int = 0
    n_held_out: int = 0


ROUTE_PARAMS = ("F_c", "F_v")
"""The parameters the routes are compared on: those a user reads."""


@dataclass(frozen=True)
class RouteCheck:
    """The same model fitted on the other route's estimate (issue 38).

    Attributes:
        route: that route (``acceleration`` or ``momentum``).
        params: its parameters, by name (None: not fitted there).
        stderr: their standard errors.
        disagree: the parameters of :data:`ROUTE_PARAMS` on which the routes disagree (:func:`compare_routes`).
    """

    route: str
    params: dict[str, float] | None
    stderr: dict[str, float]
    disagree: tuple[str, ...] = ()

    def describe(self, fit: FitResult, names: Sequence[str] | None = None) -> str:
        """One phrase: each disagreeing parameter (``names``, default :attr:`disagree`) with both routes' values and
        standard errors."""
        if fit.params is None or self.params is None:
            return ""
        mine = fit.params.to_dict()
        theirs = self.params
        return "; ".join(f"{n} {mine[n]:.3g} ±{fit.stderr.get(n, np.inf):.2g} ({fit.route}) against "
                         f"{theirs[n]:.3g} ±{self.stderr.get(n, np.inf):.2g} ({self.route})"
                         for n in (self.disagree if names is None else names))


def compare_routes(fit: FitResult, other: FitResult) -> RouteCheck:
    """``other`` (the same joint and model on the other route's estimate) as ``fit``'s :class:`RouteCheck`: a
    parameter of :data:`ROUTE_PARAMS` disagrees where the two values differ by more than :data:`ROUTE_Z` combined
    standard errors and more than :data:`ROUTE_REL` of the larger."""
    if other.params is None:
        return RouteCheck(other.route, None, {})
    theirs = other.params.to_dict()
    disagree: list[str] = []
    if fit.params is not None:
        mine = fit.params.to_dict()
        for n in ROUTE_PARAMS:
            a, b = mine.get(n), theirs.get(n)
            if a is None or b is None:
                continue
            if routes_disagree(a, fit.stderr.get(n, np.inf), b, other.stderr.get(n, np.inf)):
                disagree.append(n)
    return RouteCheck(other.route, theirs, dict(other.stderr), tuple(disagree))


@dataclass
class FitResult(Generic[ParamsT]):
    """Identified parameters of one joint.

    Attributes:
        joint: joint name.
        n_samples: number of samples used.
        params: identified parameters of :attr:`model` (:class:`~wbfriction.friction.models.FrictionParams`
            for (3.5)), or None if too few samples.
        stderr: standard error of each parameter (``inf``: not identifiable).
        rms_residual: RMS of the fit residual [N·m].
        success, message: from ``least_squares``.
        rms_error_vs_true: RMS of (estimated - true) friction over the samples used [N·m],
            when the log had ``tau_f_true``.
        rms_model_vs_true: RMS of (fitted model torque - true friction) [N·m], likewise.
        target: the friction parameters injected by a simulator (any model's), when known.
        model: the model fitted (that of :attr:`params` when there are any).
        at_bound: per parameter, whether the fit left it on one of its bounds (its value is
            then the bound's, not the data's; held parameters are not).
        selection: how ``model="auto"`` chose the model, or None.
        n_screened: valid samples left out as gross outliers
            (:func:`~wbfriction.friction.screen.gross_outliers`), not in :attr:`n_samples`.
        speed: the 95th percentile of ``|qd|`` over the samples fitted and those left out as sticking [rad/s]
            (how much the joint moved), or
            None (not known: a parameters file of an earlier version).
        covariance: the parameters' covariance (p, p) in :attr:`params`' order (held ones: 0; ``inf`` rows
            for one that is not identifiable; :func:`parameter_covariance`), or None (not fitted, or read
            from a parameters file, which keeps only the standard errors).
        crb: per parameter, the Cramér-Rao bound's standard deviation (:mod:`~wbfriction.friction.bound`: what
            any unbiased estimator from these data is held to; ``inf``: not identifiable); empty without a noise
            model.
        torque_noise: the torque's white noise the bound takes [N·m] (:func:`~wbfriction.friction.bound.torque_noise`),
            or None.
        route: the estimate's route (``acceleration`` or ``momentum``).
        route_check: the same model fitted on the other route's estimate, and where the two disagree
            (:class:`RouteCheck`), or None.
        velocity_noise: the velocity noise the model's expectation took [rad/s]
            (:mod:`~wbfriction.friction.eiv`; 0: the model itself).
        stick_speed: samples whose window holds a speed below this [rad/s] were left out (:func:`stuck_rows`).
        pass_rows: but for reversals crossing that band within so many rows (:func:`stuck_rows`).
        n_stuck: valid samples so left out.
        terms: the terms beyond velocity kept with this model (:mod:`~wbfriction.friction.terms`; its
            :attr:`~wbfriction.friction.terms.TermFit.params` are this model's linear coefficients refitted with
            them), or None: none tried.
        later: how the same model fitted on the earliest samples predicts the last ones
            (:mod:`~wbfriction.friction.holdout`, :func:`later_stretch`), or None: not checked.
        unmeasured: why the estimate's noise is not known (its positions' noise not measured: no Cramér-Rao bound),
            or "": the fit is then never ``ok`` (:func:`~wbfriction.friction.status.fit_verdict`).
    """

    joint: str
    n_samples: int
    params: ParamsT | None = None
    stderr: dict[str, float] = field(default_factory=dict)
    rms_residual: float = float("nan")
    success: bool = False
    message: str = ""
    rms_error_vs_true: float | None = None
    rms_model_vs_true: float | None = None
    target: ModelParams | None = None
    model: ModelName = "thesis"
    at_bound: dict[str, bool] = field(default_factory=dict)
    selection: ModelSelection | None = None
    n_screened: int = 0
    speed: float | None = None
    covariance: np.ndarray | None = field(default=None, repr=False, compare=False)
    crb: dict[str, float] = field(default_factory=dict)
    torque_noise: float | None = None
    route: str = "acceleration"
    route_check: RouteCheck | None = None
    velocity_noise: float = 0.0
    stick_speed: float = 0.0
    n_stuck: int = 0
    pass_rows: float = PASS_ROWS
    terms: TermFit | None = None
    later: PredictionCheck | None = None
    unmeasured: str = ""

    def __post_init__(self) -> None:
        if self.params is not None:
            self.model = self.params.model

    @property
    def kept_terms(self) -> TermFit | None:
        """:attr:`terms` when they kept any (the model predictions and exports use), else None."""
        return self.terms if self.terms is not None and self.terms.kept else None

    def reported(self) -> FitResult:
        """This fit as its numbers are shown: with terms kept (:attr:`kept_terms`), the model its status judges and
        predictions and exports use, its velocity model refitted with them (at zero load and ``T_ref``, without the
        ripple), their standard errors, the velocity fit's bounds on the parameters the refit holds (``a``,
        ``v_s``) and the refit's zeros, the other route's refit, no Cramér-Rao bound (the velocity model's alone);
        else itself. Its :meth:`verdict` is this fit's."""
        terms = self.kept_terms
        if terms is None:
            return self
        names = terms.params.names
        check = terms.check
        return replace(self, params=cast(ParamsT, terms.params),
                       stderr={n: terms.stderr[n] for n in names if n in terms.stderr},
                       at_bound={n: bool(self.at_bound.get(n)) if n in HELD else n in terms.at_bound for n in names},
                       crb={}, covariance=None,
                       route_check=None if check is None else RouteCheck(
                           check.route, {n: v for n, v in check.coefficients.items() if n in names},
                           {n: v for n, v in check.stderr.items() if n in names}))

    def dissipative(self, v: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The model's dissipative friction at the speeds ``v`` [rad/s], ``(f(v) - f(-v)) / 2`` [N·m] (free of the
        offset; positive where friction dissipates), and its standard error from :attr:`covariance` (the delta
        method), each of ``v``'s shape: NaN without parameters; the error NaN without a covariance, ``inf`` where it
        is not finite (a parameter not identifiable)."""
        v = np.asarray(v, dtype=float)
        if self.params is None:
            return np.full(v.shape, np.nan), np.full(v.shape, np.nan)
        x, model = self.params.as_vector(), self.params.model
        value = 0.5 * (self.params.f(v) - self.params.f(-v))
        if self.covariance is None:
            return value, np.full(v.shape, np.nan)
        flat = v.ravel()
        delta_s = getattr(self.params, "delta_s", 2.0)
        g = 0.5 * (model_jacobian(x, flat, delta_s, model) - model_jacobian(x, -flat, delta_s, model))
        # a parameter that is not identifiable (infinite variance) counts where the curve depends on it at these
        # speeds, and makes its error infinite there; elsewhere (a step's slope beyond its first samples) not
        known = np.isfinite(np.diag(self.covariance))
        cov = np.where(np.outer(known, known), self.covariance, 0.0)
        var = np.einsum("ij,jk,ik->i", g, cov, g)
        unknown = np.any(np.abs(g[:, ~known]) > 1e-12 * (1.0 + np.abs(value.ravel()[:, None])), axis=1)
        return value, np.where(unknown, np.inf, np.sqrt(np.maximum(var, 0.0))).reshape(v.shape)

    def bounded(self) -> tuple[str, ...]:
        """Names of the parameters at a bound (:attr:`at_bound`)."""
        return tuple(n for n, at in self.at_bound.items() if at)

    def steps(self) -> tuple[str, ...]:
        """The slopes at their upper bound (:data:`STEP_SLOPES`: (3.5)'s tanh slope ``a``): a step sharper than the
        data resolve, which is Coulomb friction (``sgn``), not a failure of the fit; its status does not count it
        as a bound (:func:`~wbfriction.friction.status.fit_verdict`) and the tables show it as a step."""
        if self.params is None:
            return ()
        upper = dict(zip(MODEL_PARAMS[self.model].names, _BOUNDS[self.model][1]))
        return tuple(n for n in STEP_SLOPES if self.at_bound.get(n) and n in upper
                     and getattr(self.params, n) >= 0.5 * upper[n])

    def verdict(self) -> FitVerdict:
        """Whether these numbers can be used: ``ok``, ``weak``, ``at bound``, ``not excited`` or ``failed``,
        and why (:func:`~wbfriction.friction.status.fit_verdict`)."""
        return fit_verdict(self)

    def error_percent(self) -> dict[str, float] | None:
        """Relative error of each parameter against :attr:`target` [%] (Tables 6.1, 6.2); for a
        model other than (3.5), against the target's values under its names
        (:meth:`~wbfriction.friction.models.FrictionParams.values_in`)."""
        if self.params is None or self.target is None:
            return None
        target = self.target.values_in(self.model)
        out = {}
        for name in self.params.names:
            t, p = target[name], getattr(self.params, name)
            out[name] = 100.0 * abs(p - t) / abs(t) if t != 0 else float("nan")
        return out


def fitted_offsets(fits) -> dict[str, float]:
    """The identified torque offset ``tau_os`` [N·m] of every fitted joint, by name (joints
    without parameters left out; with terms, the offset fitted with them): what
    :func:`~wbfriction.friction.energy.energy_consistency` removes."""
    return {f.joint: (f.terms.params if f.terms is not None else f.params).tau_os for f in fits
            if f.params is not None}


def fitted_ripples(est: FrictionEstimate, fits, source: str = "the friction table") -> dict[str, np.ndarray]:
    """The position ripple (:mod:`~wbfriction.friction.terms`) of every joint of ``est`` whose fit kept one, over
    its rows (N,) [N·m]: not friction, what :func:`~wbfriction.friction.energy.energy_consistency` takes out.

    Raises:
        InputError: ``est`` (read from ``source``) without the joint's angle.
    """
    out = {}
    for f in fits:
        if f.terms is not None and "ripple" in f.terms.kept and f.joint in est.joints:
            i = est.joints.index(f.joint)
            signals = term_signals(est, i)
            f.terms.check_signals(signals, f.joint, source)
            out[f.joint] = f.terms.ripple(est.qd[:, i], signals)
    return out


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
            (:mod:`~wbfriction.friction.eiv`).
    """
    f = expected_values(params.as_vector(), np.asarray(qd, dtype=float), velocity_noise,
                        getattr(params, "delta_s", 2.0), params.model)
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
of the lowering to be chosen over a simpler model whose parameters are all interior (:func:`choose_model`)."""


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


def _solve(residual, jacobian, start, bounds, max_nfev):
    from scipy.optimize import least_squares
    start = np.clip(start, bounds[0] + 1e-12, bounds[1] - 1e-12)
    return least_squares(residual, start, jac=jacobian, bounds=bounds, method="trf", x_scale="jac",
                         ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=max_nfev)


def _step_polish(best, residual, jacobian, bounds, slopes: list[int]):
    """``best`` (a :func:`_solve` result), or the solve from it with each slope of ``slopes`` (free coordinates) that
    ended beyond half its upper bound moved onto that bound, where that lowers the cost: towards a step sharper than
    the data resolve the cost falls so slowly that the solver's ``ftol`` stops it on the way (a TALOS knee stopped
    at ``a`` = 7700 s/rad, its cost 1.2e-5 above the step's at the bound, 10000)."""
    moved = best.x.copy()
    for i in slopes:
        if 0.5 * bounds[1][i] <= moved[i] < bounds[1][i]:
            moved[i] = bounds[1][i]
    if np.array_equal(moved, best.x):
        return best
    other = _solve(residual, jacobian, moved, bounds, 300)
    return other if other.cost < best.cost else best


def filtered_problem(qd: np.ndarray, y: np.ndarray, use: np.ndarray, smoother, delta_s: float,
                     model: ModelName = "thesis", velocity_noise: float = 0.0):
    """Residual (n_use,) and Jacobian (n_use, p) (the model's coordinates) of the model passed through
    ``smoother`` along the whole series ``qd`` (N,), on the rows ``use`` (module docstring); with ``velocity_noise``
    [rad/s] the model's expectation under it (:mod:`~wbfriction.friction.eiv`).

    The smoother is linear and filters each column alone, so the columns of the Jacobian that do
    not depend on the parameters (:data:`_FIXED_COLUMNS`: the regressors ``qd``, ``sgn(qd)``, 1) are
    filtered once, the others at every call; the residual filters the model's values alone. The model is evaluated
    on the samples the rows depend on alone (:func:`~wbfriction.friction.smoothing.row_smoothing`)."""
    rows = np.flatnonzero(use)
    smoothing = row_smoothing(smoother, qd.size, rows)
    v, y_rows = qd[smoothing.support], y[rows]
    fixed_columns = list(_FIXED_COLUMNS[model])
    filtered_fixed: list[np.ndarray] = []  # the smoothed fixed columns, on the rows used

    def residual(x: np.ndarray) -> np.ndarray:
        return smoothing(expected_values(x, v, velocity_noise, delta_s, model)) - y_rows

    def jacobian(x: np.ndarray) -> np.ndarray:
        jac = expected_jacobian(x, v, velocity_noise, delta_s, model)
        varying = np.ones(jac.shape[1], dtype=bool)
        varying[fixed_columns] = False
        if not filtered_fixed:
            filtered_fixed.append(smoothing(jac[:, fixed_columns]))
        out = np.empty((rows.size, jac.shape[1]))
        out[:, fixed_columns] = filtered_fixed[0]
        if varying.any():
            out[:, varying] = smoothing(jac[:, varying])
        return out

    return residual, jacobian


STICK_SIGMAS = 3.0
"""A joint may stick (its friction any value up to the static level, no function of a velocity) where its
measured speed is below this many standard deviations of the velocity's noise (:func:`stuck_rows`)."""
STICK_FLOOR = 3e-3
"""... and never below this speed [rad/s]: what a sticking joint creeps or chatters at in a simulator (MuJoCo's
soft friction-loss constraint creeps; a sign function applied at every physics step makes a stuck joint chatter,
up to 2e-3 rad/s on TALOS's hip roll at 4 kHz, and at 1e-3 rad/s its noise-free F_v came out 15 % off, at 2e-3
and 3e-3 0.0 %)."""


def stick_speed(velocity_noise: float) -> float:
    """The speed [rad/s] below which a sample may be sticking: :data:`STICK_SIGMAS` standard deviations of the
    velocity noise [rad/s], at least :data:`STICK_FLOOR`."""
    return max(STICK_SIGMAS * velocity_noise, STICK_FLOOR)


EDGE_ROWS = 3
"""Rows either side of a slow stretch over which the velocity's rate of change is measured (:func:`stuck_rows`)."""


def stuck_rows(qd: np.ndarray, speed: float, margin: int, pass_rows: float = PASS_ROWS) -> np.ndarray:
    """(N,) the samples within ``margin`` rows of a stretch where the joint may have stuck: its speed ``|qd|`` below
    ``speed`` [rad/s] longer than a pass through zero takes. A joint at rest has static friction, any value up to
    its static level, which no model of the velocity predicts, and a filter spreads it over its window (``margin``:
    the smoother's and the velocity filter's half widths). A reversal that passes through zero (the speed below
    ``speed`` for no longer than twice what crossing the band ``+-speed`` takes at the velocity's rate of change
    around it, the sign changed across it) holds no static friction: its samples are the model's, the Coulomb
    step's, through the smoother as the fit passes it (issue 52: on a UR10e's 100 Hz log every reversal left out
    with its 16-sample margins took a fifth of the samples, those that tell Coulomb from viscous friction, and
    moved F_c by 5-20 %)."""
    from scipy.ndimage import maximum_filter1d
    v = np.nan_to_num(np.asarray(qd, dtype=float), nan=np.inf)
    slow = np.abs(v) < speed
    if not slow.any():
        return slow
    stuck = slow.copy()
    edges = np.diff(np.concatenate([[0], slow.astype(np.int8), [0]]))
    for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):  # slow on [a, b)
        if a == 0 or b == v.size or not (np.isfinite(v[a - 1]) and np.isfinite(v[b])):
            continue
        if np.sign(v[a - 1]) == np.sign(v[b]):
            continue  # slowed down and went on: it may have stuck
        before, after = v[max(a - 1 - EDGE_ROWS, 0):a], v[b:b + EDGE_ROWS + 1]
        rates = [abs(x[-1] - x[0]) / (x.size - 1) for x in (before, after) if x.size > 1 and np.all(np.isfinite(x))]
        rate = max(rates, default=0.0)  # per row, entering or leaving the band
        crossing = 2.0 * speed / rate if rate > 0 else np.inf  # rows a pass through the band takes
        if crossing <= pass_rows and b - a <= 1.0 + 2.0 * crossing:
            stuck[a:b] = False  # a pass through zero
    if margin <= 0 or not stuck.any():
        return stuck
    return maximum_filter1d(stuck, 2 * margin + 1, mode="constant", cval=False)


def fitted_rows(qd: np.ndarray, tau_f: np.ndarray, mask: np.ndarray | None = None, smoother=None,
                stick: float = 0.0, margin: int = 0, pass_rows: float = PASS_ROWS
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The samples a fit uses (:func:`fit_friction`'s arguments), and why the others are not.

    Returns:
        ``(use, screened, stuck, speed)``: (N,) the samples fitted; the gross outliers left out
        (:func:`~wbfriction.friction.screen.gross_outliers`); those where the joint may stick (:func:`stuck_rows`,
        only for a joint that moved); how much the joint moved (:func:`~wbfriction.friction.status.joint_speed`
        over the samples fitted and the stuck ones) [rad/s].
    """
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = np.isfinite(qd) & np.isfinite(y)
    if mask is not None:
        use &= np.asarray(mask, dtype=bool)
    screened = gross_outliers(y, use)
    use &= ~screened
    if smoother is not None:
        use &= np.isfinite(smoother(qd))
    # how much the joint moved, its slow samples included; one that hardly moved has no velocity model to fit
    # (status ``not excited``), and every sample gives its offset (the energy check's, eq. 7.9)
    speed = joint_speed(qd[use])
    sticks = stick > 0 and speed >= MIN_SPEED
    stuck = stuck_rows(qd, stick, margin, pass_rows) & use if sticks else np.zeros_like(use)
    return use & ~stuck, screened, stuck, speed


def _at_bound(z: np.ndarray, bounds: tuple[np.ndarray, np.ndarray], residual, identifiable: np.ndarray
              ) -> np.ndarray:
    """(p,) bool: which of the fitted ``z`` (the fit's coordinates) are at a bound: within
    :data:`AT_BOUND_RTOL` of it, or so close that moving it onto the bound (the others kept)
    raises the sum of squared residuals by less than :data:`AT_BOUND_SSR` residual variances;
    a parameter the data do not identify (``identifiable`` False: it changes no residual
    wherever it is) when within :data:`AT_BOUND_NEAR` of it."""
    lower, upper = bounds
    r = residual(z)
    ssr = float(r @ r)
    s2 = ssr / max(r.size - z.size, 1)
    out = np.zeros(z.size, dtype=bool)
    for i in range(z.size):
        near = [b for b in (lower[i], upper[i]) if np.isfinite(b)]
        if not near:
            continue
        b = min(near, key=lambda b: abs(z[i] - b))
        scale = max(1.0, abs(b))
        if abs(z[i] - b) <= (AT_BOUND_RTOL if identifiable[i] else AT_BOUND_NEAR) * scale:
            out[i] = True
        elif identifiable[i]:
            snapped = z.copy()
            snapped[i] = b
            r = residual(snapped)
            out[i] = bool(float(r @ r) - ssr <= AT_BOUND_SSR * s2)
    return out


def fit_friction(qd: np.ndarray, tau_f: np.ndarray, *, delta_s: float = 2.0, joint: str = "",
                 x0: np.ndarray | None = None, min_samples: int = 20, mask: np.ndarray | None = None,
                 smoother=None, fixed: dict[str, float] | None = None, model: ModelChoice = "thesis",
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
        x0: a starting point in the order of the model's names
            (:data:`~wbfriction.friction.models.PARAM_NAMES` for (3.5)); by default several
            (:func:`initial_guesses`), the best fit is kept. Not with ``model="auto"``.
        min_samples: fewer samples give a result without parameters.
        mask: (N,) samples to fit (default: every finite one); gross outliers among them are
            left out and counted (:func:`~wbfriction.friction.screen.gross_outliers`,
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
        model: the model (:data:`ModelChoice`): ``thesis`` (3.5), ``stribeck``,
            ``coulomb-viscous``, or ``auto`` (chosen by held-out error, module docstring).
        selection_tolerance: with ``auto``, the relative excess of held-out RMS over the best
            within which the simpler model is chosen.
        velocity_noise: the standard deviation of the noise in ``qd`` [rad/s]: the model compared is its expectation
            under that noise (errors in variables, :mod:`~wbfriction.friction.eiv`); 0: the model itself.
        stick, stick_margin, pass_rows: samples within ``stick_margin`` rows of a speed below ``stick`` [rad/s] are
            left out, but for reversals crossing that band within ``pass_rows`` rows
        score_slow: with ``auto``, the held-out blocks' samples left out that way are scored too (what ``predict``
            scores: a model with no Coulomb step there misses them)
            (:func:`stuck_rows`) and counted (:attr:`FitResult.n_stuck`); 0: none. Not for a joint that hardly
            moved (:data:`~wbfriction.friction.status.MIN_SPEED`: ``not excited``), whose every sample gives its
            offset.
        noise: what is known of the estimate's noise (:class:`~wbfriction.friction.bound.JointNoise`): the fit then
            carries its Cramér-Rao bound (:attr:`FitResult.crb`); None: no bound.
        still: the model fitted instead of the one named (from its own start, not ``x0``) when the joint hardly
            moved (status ``not excited``: its data hold no velocity model, only an offset; ``auto`` then takes the
            simplest model anyway); None: the model named.

    Returns:
        :class:`FitResult`.

    Raises:
        InputError: an unknown model, a name in ``fixed`` that is not the model's (for
            ``auto``: no model's), ``x0`` with ``auto``, a ``stribeck`` F_s held without F_c.
    """
    if model not in MODEL_CHOICES:
        raise InputError(f"model must be one of {', '.join(MODEL_CHOICES)}, got '{model}'")
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use, screened, stuck, speed = fitted_rows(qd, tau_f, mask, smoother, stick, stick_margin, pass_rows)
    # One BLAS thread: the solver's many small (N x p) factorizations run several times
    # slower on OpenBLAS's threads than on one (30 TALOS joints of a 10-step walk: 78 s
    # against 14 s on 2 cores); fit joints side by side instead (fit_estimate's workers).
    with blas_controller().limit(limits=1, user_api="blas"):
        if model == "auto":
            if x0 is not None:
                raise InputError("x0 needs a named model, not 'auto'")
            res = _fit_auto(qd, y, use, delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother,
                            fixed=fixed, tolerance=selection_tolerance, sigma=velocity_noise, noise=noise,
                            speed=speed, stuck=stuck if score_slow else None)
        else:
            if still is not None and speed < MIN_SPEED:  # held names checked against the model named all the same
                check_fixed(check_model(model), fixed)
                model, x0, fixed = still, None, model_fixed(still, fixed)
            res = _fit_model(check_model(model), qd, y, use, delta_s=delta_s, joint=joint, x0=x0,
                             min_samples=min_samples, smoother=smoother, fixed=fixed, sigma=velocity_noise,
                             noise=noise)
    res.n_screened = int(screened.sum())
    res.speed = speed
    res.velocity_noise, res.stick_speed, res.n_stuck = float(velocity_noise), float(stick), int(stuck.sum())
    res.pass_rows = float(pass_rows)
    return res


def check_fixed(model: ModelName, fixed: Mapping[str, float] | None) -> dict[str, float]:
    """``fixed`` (parameter name: value held) as a dict, checked against ``model``'s names.

    Raises:
        InputError: a name that is not ``model``'s; a ``stribeck`` F_s held without F_c.
    """
    fixed = dict(fixed or {})
    names = MODEL_PARAMS[model].names
    if set(fixed) - set(names):
        raise InputError(f"unknown parameter(s) of the {model} model to fix: "
                         f"{', '.join(sorted(set(fixed) - set(names)))}")
    if model == "stribeck" and "F_s" in fixed and "F_c" not in fixed:
        raise InputError("the stribeck model's F_s can be held only with F_c held too")
    return fixed


def model_fixed(model: ModelName, fixed: Mapping[str, float] | None) -> dict[str, float]:
    """The entries of ``fixed`` that are ``model``'s parameters (``auto``'s candidates, ``still``'s model)."""
    return {k: v for k, v in (fixed or {}).items() if k in MODEL_PARAMS[model].names}


@functools.cache
def blas_controller():
    """threadpoolctl's view of the BLAS libraries this process has loaded (SciPy's solvers' included), inspected
    once: each fit limits them to one thread (:func:`fit_friction`), and inspecting them is most of a limit's cost
    (about 1 ms)."""
    import scipy.linalg  # noqa: F401  (the LAPACK the fit factorises with, loaded before it is inspected)
    import scipy.optimize  # noqa: F401
    from threadpoolctl import ThreadpoolController
    return ThreadpoolController()


def _fit_auto(qd: np.ndarray, y: np.ndarray, use: np.ndarray, *, delta_s: float, joint: str, min_samples: int,
              smoother, fixed: dict[str, float] | None, tolerance: float, sigma: float = 0.0,
              noise: JointNoise | None = None, speed: float = np.inf,
              stuck: np.ndarray | None = None) -> FitResult:
    """``fit_friction(model="auto")`` on the usable samples ``use`` (module docstring); a joint whose ``speed``
    [rad/s] (:func:`fitted_rows`) is below :data:`~wbfriction.friction.status.MIN_SPEED` gets the simplest model."""
    fixed = dict(fixed or {})
    known = {n for m in MODEL_NAMES for n in MODEL_PARAMS[m].names}
    if set(fixed) - known:
        raise InputError(f"unknown parameter(s) to fix: {', '.join(sorted(set(fixed) - known))}")
    held = {m: model_fixed(m, fixed) for m in MODEL_NAMES}
    kwargs = dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother, sigma=sigma)
    train, held_out = held_out_split(use)
    scored = held_out
    if stuck is not None and stuck.any():  # the slow samples of the held-out blocks are scored too (issue 52)
        _, scored = held_out_split(use | stuck)
        scored &= np.isfinite(qd) & np.isfinite(y)
    n_train, n_held_out = int(train.sum()), int(held_out.sum())
    simplest = MODEL_NAMES[0]
    why = None
    if min(n_train, n_held_out) < max(min_samples, 7):
        why = f"too few samples ({int(use.sum())}) to hold any out"
    elif speed < MIN_SPEED:
        why = (f"the joint hardly moved (|qd| at most {speed:.2g} rad/s on 95 % of its samples): no model can be "
               "chosen, its offset is what the data give")
    if why is not None:
        res = _fit_model(simplest, qd, y, use, fixed=held[simplest], noise=noise, **kwargs)
        res.selection = ModelSelection(simplest, f"{simplest}: {why}", (), tolerance, n_train, n_held_out)
        return res
    trained = {m: _fit_model(m, qd, y, train, fixed=held[m], **kwargs) for m in MODEL_NAMES}
    residuals = {m: held_out_residuals(r.params, qd, -y, scored, smoother, sigma) for m, r in trained.items()
                 if r.params is not None}
    scores = tuple(HeldOutScore(m, float(np.sqrt(np.mean(residuals[m] ** 2))) if m in residuals else float("nan"),
                                r.bounded()) for m, r in trained.items())
    chosen, reason = choose_model(scores, tolerance)
    chosen, reason = prefer_interior(chosen, reason, scores, residuals, np.flatnonzero(scored))
    res = _fit_model(chosen, qd, y, use, fixed=held[chosen], noise=noise, **kwargs)  # as if the model had been named
    if res.bounded():
        reason += f"; at a bound: {', '.join(res.bounded())}"
    res.selection = ModelSelection(chosen, reason, scores, tolerance, n_train, n_held_out)
    return res


def prefer_interior(chosen: ModelName, reason: str, scores: tuple[HeldOutScore, ...],
                         residuals: dict[ModelName, np.ndarray], rows: np.ndarray) -> tuple[ModelName, str]:
    """The rule of issue 38: a model chosen with a parameter at a bound gives way to the best-scoring simpler model
    whose parameters are all interior, unless it lowers the held-out mean square by more than :data:`GAIN_Z`
    standard errors of that lowering (:func:`held_out_gain`)."""
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


def _fit_model(model: ModelName, qd: np.ndarray, y: np.ndarray, use: np.ndarray, *, delta_s: float = 2.0,
               joint: str = "", x0: np.ndarray | None = None, min_samples: int = 20, smoother=None,
               fixed: dict[str, float] | None = None, sigma: float = 0.0,
               noise: JointNoise | None = None) -> FitResult:
    """:func:`fit_friction` of one model to ``y = -tau_f`` on the usable samples ``use``, on the threads it is given."""
    names = MODEL_PARAMS[model].names
    fixed = check_fixed(model, fixed)
    free = np.array([name not in fixed for name in names])
    held = to_fit_coordinates(model, np.array([float(fixed.get(name, 0.0)) for name in names]))

    def full(z: np.ndarray) -> np.ndarray:
        """The model's parameters from the free ones in the fit's coordinates."""
        x = held.copy()
        x[free] = z
        return from_fit_coordinates(model, x)

    n = int(use.sum())
    v, yu = qd[use], y[use]
    speed = joint_speed(v)
    if n < max(min_samples, len(names) + 1):
        return FitResult(joint, n, message=f"only {n} valid samples", model=model, speed=speed)
    lower, upper = model_bounds(v, model)
    bounds = (lower[free], upper[free])
    rows = np.flatnonzero(use)
    if smoother is None:
        residual = lambda z: expected_values(full(z), v, sigma, delta_s, model) - yu  # noqa: E731
        model_jac = lambda z: expected_jacobian(full(z), v, sigma, delta_s, model)  # noqa: E731
        projection = Projection(model, v, yu, np.arange(n), None, sigma, delta_s, held, free, lower, upper)
    else:
        f_residual, f_jacobian = filtered_problem(qd, y, use, smoother, delta_s, model, sigma)
        residual = lambda z: f_residual(full(z))  # noqa: E731
        model_jac = lambda z: f_jacobian(full(z))  # noqa: E731
        projection = Projection(model, qd, y, rows, smoother, sigma, delta_s, held, free, lower, upper)
    jacobian = lambda z: fit_coordinates_jacobian(model, model_jac(z))[:, free]  # noqa: E731
    # one start: the given one, or the minimum over the non-linear parameters with the linear ones solved
    # (variable projection, :mod:`~wbfriction.friction.projection`), then the fit over every free parameter
    start = to_fit_coordinates(model, np.asarray(x0, dtype=float)) if x0 is not None else projected_start(
        projection, float(np.percentile(np.abs(v), 90)), BASINS if speed >= MIN_SPEED else 1)
    best = _step_polish(_solve(residual, jacobian, start[free], bounds, 300), residual, jacobian, bounds,
                        [i for i, n in enumerate(np.array(names)[free]) if n in STEP_SLOPES])
    # residuals correlated over the filter's window, or over the span of a model error;
    # standard errors of the model's own parameters (F_s, not F_s - F_c)
    cov = np.zeros((len(names), len(names)))
    cov[np.ix_(free, free)] = parameter_covariance(model_jac(best.x)[:, free], best.fun, rows=rows,
                                                   max_lag=correlation_lag(best.fun, rows))
    se = covariance_errors(cov)
    at_bound = np.zeros(len(names), dtype=bool)
    at_bound[free] = _at_bound(best.x, bounds, residual, np.isfinite(se[free]))
    res = FitResult(
        joint=joint, n_samples=n, params=MODEL_PARAMS[model].from_vector(full(best.x), delta_s),
        stderr=dict(zip(names, map(float, se))), rms_residual=float(np.sqrt(np.mean(best.fun**2))),
        success=bool(best.success), message=str(best.message), model=model,
        at_bound=dict(zip(names, map(bool, at_bound))), speed=speed, covariance=cov)
    if noise is not None:
        sigma_tau = torque_noise(best.fun, rows, max(BATCH, 4 * (2 * smoother_half_width(smoother) + 1)))
        res.torque_noise = sigma_tau
        if np.isfinite(sigma_tau):
            bound = np.zeros(len(names))
            exact = model_jacobian(full(best.x), v, delta_s, model)[:, free]  # the bound: velocities known
            bound[free] = covariance_errors(cramer_rao(exact, rows, noise.with_torque(sigma_tau)))
            res.crb = dict(zip(names, map(float, bound)))
    return res


def later_stretch(fit: FitResult, qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray,
                  kwargs: Mapping[str, Any]) -> PredictionCheck | None:
    """How ``fit`` (of :func:`fit_friction` on ``qd``, ``tau_f``, ``valid`` with ``kwargs``) predicts its later
    stretch (:mod:`~wbfriction.friction.holdout`): its model fitted on the samples before the last
    :data:`~wbfriction.friction.holdout.LATER` of those it used, with the same options, and scored on them; None for
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


def shown_friction(fit: FitResult, qd: np.ndarray) -> float:
    """The friction ``fit``'s model shows at the speeds ``qd`` [rad/s]: its odd part at their 95th percentile of
    ``|qd|`` [N·m] (what a prediction's excess is judged against: :mod:`~wbfriction.friction.holdout`)."""
    value = fit.dissipative(np.array([joint_speed(qd)]))[0]
    return float(abs(value[0])) if np.isfinite(value[0]) else 0.0


def model_gradient(fit: FitResult, qd: np.ndarray, rows: np.ndarray, smoother=None,
                   velocity_noise: float = 0.0) -> np.ndarray:
    """The gradient (n, p) of ``fit``'s model (its expectation under ``velocity_noise`` [rad/s], through
    ``smoother`` along the series ``qd`` (N,) as in the fit) with respect to its parameters, on the samples ``rows``
    ((N,) bool, n of them)."""
    assert fit.params is not None
    x, delta_s = fit.params.as_vector(), getattr(fit.params, "delta_s", 2.0)
    if smoother is None:
        return expected_jacobian(x, qd[rows], velocity_noise, delta_s, fit.model)
    return filtered_problem(qd, np.zeros_like(qd), rows, smoother, delta_s, fit.model, velocity_noise)[1](x)


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
                  pass_rows: float = PASS_ROWS, score_slow: bool = True) -> list[tuple]:
    """One :func:`_fit_column` task per joint (:func:`fit_joints`'s arguments)."""
    noise = noise or {}
    tasks = []
    for i, joint in enumerate(joints):
        jn = noise.get(joint)
        sigma = 0.0 if jn is None else jn.velocity
        stick = {} if stick_margin is None else {"stick": stick_speed(sigma), "stick_margin": stick_margin,
                                                 "pass_rows": pass_rows, "score_slow": score_slow}
        tasks.append((qd[:, i], tau_f[:, i], valid[:, i],
                      dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother, fixed=fixed,
                           model=models[i], selection_tolerance=selection_tolerance, velocity_noise=sigma, noise=jn,
                           still=still, **stick)))
    return tasks


def _run(fn, tasks: list, workers: int) -> list:
    """``fn`` over ``tasks``, on ``workers`` processes side by side (one task at a time to each), in order."""
    if workers > 1 and len(tasks) > 1:
        with process_pool(min(workers, len(tasks)), "fork") as pool:
            return list(pool.map(fn, tasks))
    return [fn(task) for task in tasks]


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


def fit_estimate(est: FrictionEstimate, options: FitOptions = FitOptions(), *, workers: int = 1,
                 joints: Sequence[str] | None = None, fixed: dict[str, float] | None = None,
                 targets: Mapping[str, ModelParams] | None = None,
                 still: ModelName | None = None) -> list[FitResult]:
    """Fit every joint of an estimate (:func:`fit_joints` on its valid samples, on ``workers``
    processes); its ``tau_f_true`` and ``friction_true`` metadata, when present (simulated
    logs), give the errors against truth.

    With the estimate's noise record (:func:`~wbfriction.friction.noise.noise_record`), each fit corrects the model
    for its velocity's noise, leaves out the samples where its joint may stick, and carries its Cramér-Rao bound.
    With the other route's estimate (:attr:`~wbfriction.friction.estimate.FrictionEstimate.route_check`), each
    joint's model is fitted there too and the two compared (:attr:`FitResult.route_check`, :func:`compare_routes`).

    Args:
        options: the model, its choice and the fit's thresholds (:class:`~wbfriction.friction.options.FitOptions`;
            its defaults are ``wbfriction fit``'s).
        workers: processes fitting joints side by side.
        joints: the joints to fit (default: every one of the estimate), in this order.
        fixed: parameters held instead of fitted (:func:`fit_friction`).
        targets: the true parameters per joint, instead of the metadata's ``friction_true``.
        still: the model of a joint that hardly moved, instead of ``options``' named model (:func:`fit_friction`).

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
                                  pass_rows=options.pass_rows, score_slow=options.score_slow)
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
    pairs = _run(_fit_routes, list(zip(tasks, others)), workers)
    fits = _with_truth(names, [fit for fit, _ in pairs], est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx], truth,
                       targets)
    checked = [other for _, other in pairs]
    for f, other in zip(fits, checked):
        f.route = est.estimation_route
        f.unmeasured = str(est.metadata.get("noise_unmeasured", ""))  # never ok then (issue 53)
        if check is not None and other is not None:
            other.route = check.estimation_route
            f.route_check = compare_routes(f, other)
    if options.terms.terms:
        for k, (f, i, maybe) in enumerate(zip(fits, idx, checked)):
            f.terms = _joint_terms(est, i, f, maybe, options)
            for _ in range(TERM_REFITS):  # the velocity model chosen and fitted again with the terms' torque taken out
                if f.kept_terms is None:
                    break
                task = _without_terms(tasks[k], f.kept_terms, est, i)
                refit = _with_truth([names[k]], [_fit_column(task)], est.qd[:, [i]], est.tau_f[:, [i]],
                                    est.valid[:, [i]], None if truth is None else truth[:, [k]], targets)[0]
                refit.route, refit.route_check, refit.unmeasured = f.route, f.route_check, f.unmeasured
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
    return fits


UNUSABLE: tuple[str, ...] = ("failed", "at bound", "not excited")


def _better_refit(refit: FitResult, fit: FitResult) -> bool:
    """Whether a joint's refit with its terms' torque taken out (:data:`TERM_REFITS`) replaces ``fit``: its model with
    its terms predicts the later stretch no worse (:attr:`~wbfriction.friction.terms.TermFit.held_out_rms`), and its
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
    (:func:`~wbfriction.friction.term_selection.fit_terms`) on the samples its fit used, and refitted on the other
    route's estimate with that route's model (``other``), with the ranges of its signals on those samples
    (:class:`~wbfriction.friction.ranges.FittedRanges`); None for a joint not fitted or not excited."""
    if fit.params is None or fit.verdict().status in ("not excited", "failed"):
        return None
    signals = term_signals(est, i)
    use = fitted_rows(est.qd[:, i], est.tau_f[:, i], est.valid[:, i], est.smoother, fit.stick_speed,
                      stick_margin(est), fit.pass_rows)[0]
    terms = fit_terms(fit.params, est.qd[:, i], est.tau_f[:, i], use, signals, options.terms, est.smoother)
    terms = replace(terms, ranges=FittedRanges.of(use, signals.q, signals.tau_load, signals.temperature))
    check = est.route_check
    if check is not None and other is not None and other.params is not None and terms.kept:
        rows = fitted_rows(check.qd[:, i], check.tau_f[:, i], check.valid[:, i], check.smoother, other.stick_speed,
                           stick_margin(check), other.pass_rows)[0]
        terms = replace(terms, check=refit_terms(terms, other.params, check.qd[:, i], check.tau_f[:, i], rows, signals,
                                                 check.estimation_route, check.smoother))
    return terms

"""A joint's fit as a value: :class:`FitResult` (parameters, standard errors, Cramér-Rao bounds, the route check,
the held-out checks and the verdict), and how its model was chosen (:class:`ModelSelection`,
:class:`HeldOutScore`) or checked against the other route (:class:`RouteCheck`). Every later stage reads fits
through this type (the report, the exports, the parameters JSON)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Generic, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.fit.block_spread import statistical_error
from wbfriction.fit.holdout import (
    PredictionCheck,
)
from wbfriction.fit.options import PASS_ROWS, SELECTION_TOLERANCE
from wbfriction.fit.route_spread import route_spread
from wbfriction.fit.status import HELD, FitVerdict, fit_verdict, read_error, routes_disagree
from wbfriction.fit.terms import TermFit, term_signals
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import (
    ModelName,
    ModelParams,
    ParamsT,
)


@dataclass(frozen=True)
class HeldOutScore:
    """One model's fit on the training blocks, scored on the held-out ones.

    Attributes:
        model: the model.
        held_out_rms: RMS of (model - estimate) over the held-out samples [N·m] (NaN: no fit).
        at_bound: the parameters that fit left at a bound (:meth:`FitResult.bounded`: a magnitude at its floor of zero
            included).
        unresolved: the transitions the training samples do not resolve (:func:`~wbfriction.fit.transition.unresolved`):
            a model with one is no candidate.
    """

    model: ModelName
    held_out_rms: float
    at_bound: tuple[str, ...] = ()
    unresolved: tuple[str, ...] = ()


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
        block_spread: their block-jackknife standard errors (:mod:`~wbfriction.fit.block_spread`; empty: not known,
            a parameters file of an earlier version).
    """

    route: str
    params: dict[str, float] | None
    stderr: dict[str, float]
    disagree: tuple[str, ...] = ()
    block_spread: dict[str, float] = field(default_factory=dict)

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
    parameter of :data:`ROUTE_PARAMS` disagrees where the two values differ by more than
    :data:`~wbfriction.fit.status.ROUTE_Z` combined statistical errors (each route's Newey-West error raised to its
    block jackknife's) and more than :data:`~wbfriction.fit.status.ROUTE_REL` of the larger."""
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
            if routes_disagree(a, statistical_error(fit.stderr.get(n, np.inf), fit.block_spread.get(n, 0.0)), b,
                               statistical_error(other.stderr.get(n, np.inf), other.block_spread.get(n, 0.0))):
                disagree.append(n)
    return RouteCheck(other.route, theirs, dict(other.stderr), tuple(disagree), dict(other.block_spread))


def check_routes(fit: FitResult, other: FitResult) -> None:
    """Set ``fit``'s :attr:`~FitResult.route_check` (:func:`compare_routes` with ``other``, the same joint and model
    on the other route's estimate) and its :attr:`~FitResult.route_spread` (:mod:`~wbfriction.fit.route_spread`)."""
    fit.route_check = compare_routes(fit, other)
    fit.route_spread = {} if fit.params is None else route_spread(fit.params.to_dict(), fit.route_check.params,
                                                                  ROUTE_PARAMS)


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
            (:func:`~wbfriction.fit.screen.gross_outliers`), not in :attr:`n_samples`.
        speed: the 95th percentile of ``|qd|`` over the samples fitted and those left out as sticking [rad/s]
            (how much the joint moved), or
            None (not known: a parameters file of an earlier version).
        reverse: the share of the fitted samples moving the less frequent way
            (:func:`~wbfriction.fit.status.reverse_share`), or None (not known: a parameters file of an earlier
            version).
        covariance: the parameters' covariance (p, p) in :attr:`params`' order (held ones: 0; ``inf`` rows
            for one that is not identifiable; :func:`parameter_covariance`), or None (not fitted, or read
            from a parameters file, which keeps only the standard errors).
        crb: per parameter, the Cramér-Rao bound's standard deviation (:mod:`~wbfriction.fit.bound`: what
            any unbiased estimator from these data is held to; ``inf``: not identifiable); empty without a noise
            model.
        torque_noise: the torque's white noise the bound takes [N·m] (:func:`~wbfriction.fit.bound.torque_noise`),
            or None.
        route: the estimate's route (``acceleration`` or ``momentum``).
        route_check: the same model fitted on the other route's estimate, and where the two disagree
            (:class:`RouteCheck`), or None.
        velocity_noise: the velocity noise the model's expectation took [rad/s]
            (:mod:`~wbfriction.fit.eiv`; 0: the model itself).
        stick_speed: samples whose window holds a speed below this [rad/s] were left out (:func:`stuck_rows`).
        pass_rows: but for reversals crossing that band within so many rows (:func:`stuck_rows`).
        n_stuck: valid samples so left out.
        terms: the terms beyond velocity kept with this model (:mod:`~wbfriction.fit.terms`; its
            :attr:`~wbfriction.fit.terms.TermFit.params` are this model's linear coefficients refitted with
            them), or None: none tried.
        later: how the same model fitted on the earliest samples predicts the last ones
            (:mod:`~wbfriction.fit.holdout`, :func:`later_stretch`), or None: not checked.
        unmeasured: why the estimate's noise is not known (its positions' noise not measured: no Cramér-Rao bound),
            or "": the fit is then never ``ok`` (:func:`~wbfriction.fit.status.fit_verdict`).
        pressed: the magnitudes at their floor of zero that the data press below it
            (:func:`~wbfriction.fit.solve.pressed_floors`): name -> (the value without the floor, its standard
            error); such a zero is a bound of the model, not a finding, and the fit is ``at bound``.
        model_spread: with ``model="auto"``, per magnitude a user reads (F_c, F_v), how far it moves between the
            model chosen and the other candidate families (:func:`~wbfriction.fit.selection.family_spread`): the
            model error the data do not resolve; and F_v's, where the PD drivers' delay holds back a part of their law
            the log did not tell (:func:`~wbfriction.fit.joints.delay_structure_spread`), ``kp delay`` with it in
            quadrature. The standard error a user reads (:meth:`read_stderr`) adds it in quadrature to
            :attr:`stderr`; the route check and the predictions use :attr:`stderr` (issue 63).
        block_spread: per interior parameter, the delete-one-block jackknife's standard error over the log's time
            blocks (:mod:`~wbfriction.fit.block_spread`): what the log shows of an error that changes over it; the
            read error's statistical part is the larger of it and :attr:`stderr`; empty: not computed (too few
            samples for its blocks, or a parameters file of an earlier version).
        route_spread: per magnitude a user reads (F_c, F_v), the share of the two routes' difference
            (:mod:`~wbfriction.fit.route_spread`, :func:`check_routes`) that the read error carries as the estimate's
            bias; empty: no other route.
        fallback: with ``model="auto"``, where the model chosen is not ``ok``: the simplest family (the first of
            :func:`~wbfriction.friction.families.registry.families`, Coulomb-viscous) fitted on the same samples
            without terms, with its own checks (route, later stretch) and its distance to the chosen fit's F_c and F_v
            in its :attr:`model_spread` (the chosen family predicted better), or None. It is what an export writes for
            the joint when it is ``ok``, or when neither is and both statuses are included: the model with the fewest
            parameters the data must carry (:func:`~wbfriction.export.mapping.select_fits`; issue 64).
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
    reverse: float | None = None
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
    pressed: dict[str, tuple[float, float]] = field(default_factory=dict)
    model_spread: dict[str, float] = field(default_factory=dict)
    fallback: FitResult | None = None
    block_spread: dict[str, float] = field(default_factory=dict)
    route_spread: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.params is not None:
            self.model = self.params.model

    @property
    def kept_terms(self) -> TermFit | None:
        """:attr:`terms` when they kept any (the model predictions and exports use), else None."""
        return self.terms if self.terms is not None and self.terms.kept else None

    def read_stderr(self) -> dict[str, float]:
        """The standard errors a user reads, per parameter (:func:`~wbfriction.fit.status.read_error`): the larger of
        :attr:`stderr` and :attr:`block_spread`, :attr:`model_spread` and :attr:`route_spread` in quadrature (the
        statistical spread, the model family's and the routes'; issue 63)."""
        return {n: read_error(se, self.model_spread.get(n, 0.0), self.block_spread.get(n, 0.0),
                              self.route_spread.get(n, 0.0)) for n, se in self.stderr.items()}

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
        route_check = None if check is None else RouteCheck(
            check.route, {n: v for n, v in check.coefficients.items() if n in names},
            {n: v for n, v in check.stderr.items() if n in names},
            block_spread={n: v for n, v in check.block_spread.items() if n in names})
        return replace(self, params=cast(ParamsT, terms.params),
                       stderr={n: terms.stderr[n] for n in names if n in terms.stderr},
                       at_bound={n: bool(self.at_bound.get(n)) if n in HELD else n in terms.at_bound for n in names},
                       crb={}, covariance=None, route_check=route_check,
                       block_spread={n: v for n, v in terms.block_spread.items() if n in names},
                       route_spread={} if route_check is None else route_spread(
                           terms.params.to_dict(), route_check.params, ROUTE_PARAMS))

    def dissipative(self, v: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The model's dissipative friction at the speeds ``v`` [rad/s], ``(f(v) - f(-v)) / 2`` [N·m] (free of the
        offset; positive where friction dissipates), and its standard error from :attr:`covariance` (the delta
        method), each of ``v``'s shape: NaN without parameters; the error NaN without a covariance, ``inf`` where it
        is not finite (a parameter not identifiable)."""
        v = np.asarray(v, dtype=float)
        if self.params is None:
            return np.full(v.shape, np.nan), np.full(v.shape, np.nan)
        x, fam = self.params.as_vector(), family(self.params.model)
        value = 0.5 * (self.params.f(v) - self.params.f(-v))
        if self.covariance is None:
            return value, np.full(v.shape, np.nan)
        flat = v.ravel()
        delta_s = getattr(self.params, "delta_s", 2.0)
        g = 0.5 * (fam.jacobian(x, flat, delta_s) - fam.jacobian(x, -flat, delta_s))
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
        """The slopes at their upper bound (the family's
        :attr:`~wbfriction.friction.families.base.FrictionFamily.step_slopes`: (3.5)'s tanh slope ``a``): a step
        sharper than the data resolve, which is Coulomb friction (``sgn``), not a failure of the fit; its status does
        not count it as a bound (:func:`~wbfriction.fit.status.fit_verdict`) and the tables show it as a step."""
        if self.params is None:
            return ()
        fam = family(self.model)
        upper = dict(zip(fam.names, fam.upper))
        return tuple(n for n in fam.step_slopes if self.at_bound.get(n) and n in upper
                     and getattr(self.params, n) >= 0.5 * upper[n])

    def verdict(self) -> FitVerdict:
        """Whether these numbers can be used: ``ok``, ``weak``, ``at bound``, ``not excited`` or ``failed``,
        and why (:func:`~wbfriction.fit.status.fit_verdict`)."""
        return fit_verdict(self)

    def error_percent(self) -> dict[str, float] | None:
        """Relative error of each parameter against :attr:`target` [%] (Tables 6.1, 6.2); for a
        model other than the target's, against the target's values under its names
        (:meth:`~wbfriction.friction.families.params.ModelParamsBase.values_in`): a parameter the target has no
        counterpart of (a plugin family's own, fitted to a built-in family's truth) is left out, none made up."""
        if self.params is None or self.target is None:
            return None
        target = self.target.values_in(self.model)
        out = {}
        for name in (n for n in self.params.names if n in target):
            t, p = target[name], getattr(self.params, name)
            out[name] = 100.0 * abs(p - t) / abs(t) if t != 0 else float("nan")
        return out


def fitted_offsets(fits) -> dict[str, float]:
    """The identified torque offset ``tau_os`` [N·m] of every fitted joint, by name (joints
    without parameters left out; with terms, the offset fitted with them): what
    :func:`~wbfriction.fit.energy.energy_consistency` removes."""
    return {f.joint: (f.terms.params if f.terms is not None else f.params).tau_os for f in fits
            if f.params is not None}


def fitted_ripples(est: FrictionEstimate, fits, source: str = "the friction table") -> dict[str, np.ndarray]:
    """The position ripple (:mod:`~wbfriction.fit.terms`) of every joint of ``est`` whose fit kept one, over
    its rows (N,) [N·m]: not friction, what :func:`~wbfriction.fit.energy.energy_consistency` takes out.

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

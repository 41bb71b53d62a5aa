"""One model fitted to one joint's friction (thesis 6.2.2, eq. 6.4).

Per joint, ``scipy.optimize.least_squares(method="trf")`` fits the characteristic ``f(qd; p)``
of one of the friction families of :mod:`wbfriction.friction.families` (``coulomb-viscous``, ``stribeck``,
the thesis's (3.5), or one registered) to ``-tau_f`` over the valid samples (sign convention of
:mod:`wbfriction.friction.models`), with the family's bounds in its fit's coordinates
(:mod:`~wbfriction.fit.coordinates`), from one start: the minimum over the non-linear parameters
(the built-in families' ``(v_s, a)``) with the linear ones solved exactly (variable projection,
:mod:`wbfriction.fit.projection`: a coarse grid, then a local search). Each parameter gets a standard error from
the Jacobian at the solution,

.. math:: \\operatorname{cov}(\\hat p) = s^2 (J^T J)^{-1}, \\qquad s^2 = \\frac{\\|r\\|^2}{N - p},

computed through the SVD of J, with a Newey-West correction for residuals correlated in
time (filtered estimates above all; :mod:`~wbfriction.fit.regression`); a parameter with a component
in the numerical null space of J (e.g. ``v_s`` when ``S = 0``, or the Stribeck parameters when the data never
leave the Stribeck region) gets an infinite standard error: the data cannot identify it. Where the fit carries its
Cramér-Rao bound (:mod:`~wbfriction.fit.bound`), no standard error is below it: the covariance is scaled up to it
(:func:`~wbfriction.fit.bound.at_least_bound`, issue 63). Each interior parameter also gets its block spread, a
delete-one-block jackknife over the log's time blocks (:mod:`~wbfriction.fit.block_spread`): the standard error a
user reads is the larger of the two (:meth:`~wbfriction.fit.result.FitResult.read_stderr`).

Filtered estimates (thesis 7.1) are compared with the model filtered the same way: when
the friction went through a zero-phase smoother ``H``, the fit minimises
``|H(f(qd; p))[valid] + tau_f[valid]|^2`` over the whole time series, as in
the parallel filtering of robot identification (the filter applied to observations and
model alike), so that the smoothing of the model's jumps at velocity reversals (Coulomb,
Stribeck) is not mistaken for a different model (:func:`filtered_problem`). The start is searched on that same
filtered objective. Samples where the joint may stick are left out (:func:`stuck_rows`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping

import numpy as np

from wbfriction.fit.block_spread import block_spread
from wbfriction.fit.bound import BATCH, at_least_bound, cramer_rao, torque_noise
from wbfriction.fit.coordinates import (
    AT_BOUND_NEAR,
    AT_BOUND_RTOL,
    AT_BOUND_SSR,
)
from wbfriction.fit.options import PASS_ROWS, STICK_FLOOR
from wbfriction.fit.projection import BASINS, Projection, projected_start
from wbfriction.fit.regression import (
    correlation_lag,
    covariance_errors,
    parameter_covariance,
)
from wbfriction.fit.result import FitResult
from wbfriction.fit.screen import gross_outliers
from wbfriction.fit.smoothing import row_smoothing, smoother_half_width
from wbfriction.fit.status import MIN_SPEED, ZERO_FLOOR, joint_speed
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelName
from wbfriction.friction.noise import JointNoise


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
    [rad/s] the model's expectation under it (:mod:`~wbfriction.fit.eiv`).

    The smoother is linear and filters each column alone, so the columns of the Jacobian that do
    not depend on the parameters (the family's
    :attr:`~wbfriction.friction.families.base.FrictionFamily.constant_columns`: the regressors ``qd``, ``sgn(qd)``,
    1) are filtered once, the others at every call; the residual filters the model's values alone. The model is
    evaluated on the samples the rows depend on alone (:func:`~wbfriction.fit.smoothing.row_smoothing`)."""
    fam = family(model)
    rows = np.flatnonzero(use)
    smoothing = row_smoothing(smoother, qd.size, rows)
    v, y_rows = qd[smoothing.support], y[rows]
    fixed_columns = list(fam.positions(fam.constant_columns))
    filtered_fixed: list[np.ndarray] = []  # the smoothed fixed columns, on the rows used

    def residual(x: np.ndarray) -> np.ndarray:
        return smoothing(fam.expected_values(x, v, velocity_noise, delta_s)) - y_rows

    def jacobian(x: np.ndarray) -> np.ndarray:
        jac = fam.expected_jacobian(x, v, velocity_noise, delta_s)
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





def stick_speed(velocity_noise: float, floor: float = STICK_FLOOR) -> float:
    """The speed [rad/s] below which a sample may be sticking: :data:`STICK_SIGMAS` standard deviations of the
    velocity noise [rad/s], at least ``floor`` [rad/s] (:data:`~wbfriction.fit.options.STICK_FLOOR`)."""
    return max(STICK_SIGMAS * velocity_noise, floor)


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
        (:func:`~wbfriction.fit.screen.gross_outliers`); those where the joint may stick (:func:`stuck_rows`,
        only for a joint that moved); how much the joint moved (:func:`~wbfriction.fit.status.joint_speed`
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


PRESS_Z = 3.0
"""A magnitude held at its floor of zero whose fit, freed of that floor, would go below zero by more than this many of
its standard errors is pressed against the floor (:func:`pressed_floors`): a bound of the model, not a finding."""


def pressed_floors(z: np.ndarray, r: np.ndarray, jacobian: Callable[[np.ndarray], np.ndarray], floors: list[int],
                   names: np.ndarray, rows: np.ndarray) -> dict[str, tuple[float, float]]:
    """The magnitudes at their floor of zero that the data press against it: for each of ``floors`` (indices into
    the free parameters ``z`` (p,) in the fit's coordinates, at a lower bound of 0), the value one Gauss-Newton step
    from the optimum without bounds would give, where it lies below zero by more than :data:`PRESS_Z` standard
    errors (the Newey-West sandwich at the optimum, as the fit's own), as ``{name: (that value, its standard
    error)}`` in the fit's coordinates (the model's own for F_v and F_c).

    A Coulomb-viscous fit with F_v = 0 is no finding of "no viscous friction" when the data's friction falls with
    the speed (a Stribeck curve, or an estimate that is not the window's average of a friction of the velocity):
    the same fit freed of the floor puts F_v at -0.2 ± 0.02 (the real Aliengo's momentum route, issue 63). Exact for
    a model linear in those parameters (the Coulomb-viscous one), one step for the others.

    Args:
        z: (p,) the optimum; r: (n,) its residuals (model - target) on the fitted ``rows`` (n,) of the series;
        jacobian: ``z -> (n, p)``, their Jacobian in the fit's coordinates (evaluated only when a magnitude is at its
            floor); names: (p,) the free parameters' names.
    """
    if not floors or r.size <= z.size:
        return {}
    jac = jacobian(z)
    step = np.linalg.lstsq(jac, -r, rcond=None)[0]
    freed = r + jac @ step  # the residuals without the floor
    cov = parameter_covariance(jac, freed, rows=rows, max_lag=correlation_lag(freed, rows))
    out = {}
    for i in floors:
        se = float(np.sqrt(cov[i, i])) if cov[i, i] > 0 else float("inf")
        free_value = float(z[i] + step[i])
        if np.isfinite(se) and free_value < -PRESS_Z * se:
            out[str(names[i])] = (free_value, se)
    return out


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


def check_fixed(model: ModelName, fixed: Mapping[str, float] | None) -> dict[str, float]:
    """``fixed`` (parameter name: value held) as a dict, checked against ``model``'s names
    (:meth:`~wbfriction.friction.families.base.FrictionFamily.check_fixed`).

    Raises:
        InputError: a name that is not ``model``'s; a parameter held without the one it goes with (a ``stribeck`` F_s
            held without F_c).
    """
    return family(model).check_fixed(fixed)


def model_fixed(model: ModelName, fixed: Mapping[str, float] | None) -> dict[str, float]:
    """The entries of ``fixed`` that are ``model``'s parameters (``auto``'s candidates, ``still``'s model)."""
    names = family(model).names
    return {k: v for k, v in (fixed or {}).items() if k in names}


@functools.cache
def blas_controller():
    """threadpoolctl's view of the BLAS libraries this process has loaded (SciPy's solvers' included), inspected
    once: each fit limits them to one thread (:func:`fit_friction`), and inspecting them is most of a limit's cost
    (about 1 ms)."""
    import scipy.linalg  # noqa: F401  (the LAPACK the fit factorises with, loaded before it is inspected)
    import scipy.optimize  # noqa: F401
    from threadpoolctl import ThreadpoolController
    return ThreadpoolController()


def fit_model(model: ModelName, qd: np.ndarray, y: np.ndarray, use: np.ndarray, *, delta_s: float = 2.0,
               joint: str = "", x0: np.ndarray | None = None, min_samples: int = 20, smoother=None,
               fixed: dict[str, float] | None = None, sigma: float = 0.0,
               noise: JointNoise | None = None) -> FitResult:
    """:func:`fit_friction` of one model to ``y = -tau_f`` on the usable samples ``use``, on the threads it is given.

    Raises:
        UnknownFamilyError: no family named ``model``.
        InputError: a name in ``fixed`` that is not the model's (:func:`check_fixed`).
    """
    fam = family(model)
    names = fam.names
    fixed = fam.check_fixed(fixed)
    free = np.array([name not in fixed for name in names])
    held = fam.to_fit(np.array([float(fixed.get(name, 0.0)) for name in names]))

    def full(z: np.ndarray) -> np.ndarray:
        """The model's parameters from the free ones in the fit's coordinates."""
        x = held.copy()
        x[free] = z
        return fam.from_fit(x)

    n = int(use.sum())
    v, yu = qd[use], y[use]
    speed = joint_speed(v)
    if n < max(min_samples, len(names) + 1):
        return FitResult(joint, n, message=f"only {n} valid samples", model=model, speed=speed)
    lower, upper = fam.bounds(v)
    bounds = (lower[free], upper[free])
    rows = np.flatnonzero(use)
    if smoother is None:
        residual = lambda z: fam.expected_values(full(z), v, sigma, delta_s) - yu  # noqa: E731
        model_jac = lambda z: fam.expected_jacobian(full(z), v, sigma, delta_s)  # noqa: E731
        projection = Projection(model, v, yu, np.arange(n), None, sigma, delta_s, held, free, lower, upper)
    else:
        f_residual, f_jacobian = filtered_problem(qd, y, use, smoother, delta_s, model, sigma)
        residual = lambda z: f_residual(full(z))  # noqa: E731
        model_jac = lambda z: f_jacobian(full(z))  # noqa: E731
        projection = Projection(model, qd, y, rows, smoother, sigma, delta_s, held, free, lower, upper)
    jacobian = lambda z: fam.fit_jacobian(model_jac(z))[:, free]  # noqa: E731
    # one start: the given one, or the minimum over the non-linear parameters with the linear ones solved
    # (variable projection, :mod:`~wbfriction.fit.projection`), then the fit over every free parameter
    start = fam.to_fit(np.asarray(x0, dtype=float)) if x0 is not None else projected_start(
        projection, float(np.percentile(np.abs(v), 90)), BASINS if speed >= MIN_SPEED else 1)
    best = _step_polish(_solve(residual, jacobian, start[free], bounds, 300), residual, jacobian, bounds,
                        [i for i, n in enumerate(np.array(names)[free]) if n in fam.step_slopes])
    # residuals correlated over the filter's window, or over the span of a model error;
    # standard errors of the model's own parameters (F_s, not F_s - F_c)
    cov = np.zeros((len(names), len(names)))
    lag, jac_free = correlation_lag(best.fun, rows), model_jac(best.x)[:, free]
    cov[np.ix_(free, free)] = parameter_covariance(jac_free, best.fun, rows=rows, max_lag=lag)
    se = covariance_errors(cov)
    at_bound = np.zeros(len(names), dtype=bool)
    at_bound[free] = _at_bound(best.x, bounds, residual, np.isfinite(se[free]))
    # what the log shows of an error that changes over it: the blocks' jackknife, the interior parameters stepped
    blocks = np.zeros(len(names))
    blocks[free] = block_spread(jac_free, best.fun, ~at_bound[free] & np.isfinite(se[free]), lag)
    free_names = np.array(names)[free]
    floors = [i for i, (name, at) in enumerate(zip(free_names, at_bound[free]))
              if at and name in ZERO_FLOOR and bounds[0][i] == 0.0]
    res = FitResult(
        joint=joint, n_samples=n, params=fam.params(full(best.x), delta_s),
        stderr=dict(zip(names, map(float, se))), rms_residual=float(np.sqrt(np.mean(best.fun**2))),
        success=bool(best.success), message=str(best.message), model=model,
        at_bound=dict(zip(names, map(bool, at_bound))), speed=speed, covariance=cov,
        pressed=pressed_floors(best.x, best.fun, jacobian, floors, free_names, rows),
        block_spread={n: float(b) for n, b in zip(names, blocks) if b > 0})
    if noise is not None:
        sigma_tau = torque_noise(best.fun, rows, max(BATCH, 4 * (2 * smoother_half_width(smoother) + 1)))
        res.torque_noise = sigma_tau
        if np.isfinite(sigma_tau):
            bound = np.zeros(len(names))
            exact = fam.jacobian(full(best.x), v, delta_s)[:, free]  # the bound: velocities known
            bound[free] = covariance_errors(cramer_rao(exact, rows, noise.with_torque(sigma_tau)))
            res.crb = dict(zip(names, map(float, bound)))
            # no standard error below what any unbiased estimator reaches (issue 63)
            res.covariance = at_least_bound(cov, bound)
            res.stderr = dict(zip(names, map(float, np.maximum(covariance_errors(res.covariance), bound))))
    return res


def shown_friction(fit: FitResult, qd: np.ndarray) -> float:
    """The friction ``fit``'s model shows at the speeds ``qd`` [rad/s]: its odd part at their 95th percentile of
    ``|qd|`` [N·m] (what a prediction's excess is judged against: :mod:`~wbfriction.fit.holdout`)."""
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
        return family(fit.model).expected_jacobian(x, qd[rows], velocity_noise, delta_s)
    return filtered_problem(qd, np.zeros_like(qd), rows, smoother, delta_s, fit.model, velocity_noise)[1](x)

"""Identification of the friction model (3.5) from estimated friction (thesis 6.2.2, eq. 6.4).

Per joint, ``scipy.optimize.least_squares(method="trf")`` fits the characteristic
``f(qd; p)`` of eq. (3.5) to ``-tau_f`` over the valid samples (sign convention of
:mod:`wbfriction.friction.models`), with bounds, from several starts. Each parameter gets a
standard error from the Jacobian at the solution,

.. math:: \\operatorname{cov}(\\hat p) = s^2 (J^T J)^{-1}, \\qquad s^2 = \\frac{\\|r\\|^2}{N - 6},

computed through the SVD of J, with a Newey-West correction for residuals correlated in
time (filtered estimates above all; :func:`standard_errors`); a parameter with a component
in the numerical null space of J (e.g. ``v_s`` when ``S = 0``, or the Stribeck parameters when the data never
leave the Stribeck region) gets an infinite standard error: the data cannot identify it.

Filtered estimates (thesis 7.1) are compared with the model filtered the same way: when
the friction went through a zero-phase smoother ``H``, the fit minimises
``|H(f(qd; p))[valid] + tau_f[valid]|^2`` over the whole time series, as in
the parallel filtering of robot identification (the filter applied to observations and
model alike), so that the smoothing of the model's jumps at velocity reversals (Coulomb,
Stribeck) is not mistaken for a different model. The unfiltered fit on the same samples
gives the starting point.
"""

from __future__ import annotations

import itertools
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares
from threadpoolctl import threadpool_limits

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import PARAM_NAMES, FrictionParams, coulomb_viscous_stribeck

LOWER = np.array([0.0, 0.0, 0.0, 1e-4, -np.inf, 1e-2])
UPPER = np.array([np.inf, np.inf, 50.0, 100.0, np.inf, 1e4])
"""Bounds of (F_v, F_c, S, v_s, tau_os, a): dissipative viscous and Coulomb parts, static
friction at least the Coulomb level (S >= 0: the Stribeck effect is a drop from static to
Coulomb friction), positive Stribeck velocity and tanh slope. The fit further bounds ``v_s``
by the largest speed in the data: a Stribeck velocity beyond it is not identifiable, and
the Stribeck term would otherwise mimic viscous friction (S < 0, v_s large)."""


def _bounds(qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    upper = UPPER.copy()
    upper[3] = max(float(np.max(np.abs(qd))), 2 * LOWER[3])
    return LOWER, upper


@dataclass
class FitResult:
    """Identified parameters of one joint.

    Attributes:
        joint: joint name.
        n_samples: number of samples used.
        params: identified :class:`FrictionParams`, or None if too few samples.
        stderr: standard error of each parameter (``inf``: not identifiable).
        rms_residual: RMS of the fit residual [N·m].
        success, message: from ``least_squares``.
        rms_error_vs_true: RMS of (estimated - true) friction over the samples used [N·m],
            when the log had ``tau_f_true``.
        rms_model_vs_true: RMS of (fitted model torque - true friction) [N·m], likewise.
        target: the friction parameters injected by a simulator, when known.
    """

    joint: str
    n_samples: int
    params: FrictionParams | None = None
    stderr: dict[str, float] = field(default_factory=dict)
    rms_residual: float = float("nan")
    success: bool = False
    message: str = ""
    rms_error_vs_true: float | None = None
    rms_model_vs_true: float | None = None
    target: FrictionParams | None = None

    def error_percent(self) -> dict[str, float] | None:
        """Relative error of each parameter against :attr:`target` [%] (Tables 6.1, 6.2)."""
        if self.params is None or self.target is None:
            return None
        out = {}
        for name in PARAM_NAMES:
            t, p = getattr(self.target, name), getattr(self.params, name)
            out[name] = 100.0 * abs(p - t) / abs(t) if t != 0 else float("nan")
        return out


def fitted_offsets(fits) -> dict[str, float]:
    """The identified torque offset ``tau_os`` [N·m] of every fitted joint, by name (joints
    without parameters left out): what :func:`~wbfriction.friction.energy.energy_consistency` removes."""
    return {f.joint: f.params.tau_os for f in fits if f.params is not None}


def model_values(x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
    """Model (3.5) ``f(qd)`` [N·m] for the parameter vector ``x`` (6,) in
    :data:`~wbfriction.friction.models.PARAM_NAMES` order, ``qd`` (N,) [rad/s]."""
    return coulomb_viscous_stribeck(qd, x[0], x[1], x[2], x[3], x[4], x[5], delta_s)


def model_jacobian(x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
    """Jacobian (N, 6) of :func:`model_values` with respect to ``x``, analytic."""
    F_v, F_c, S, v_s, _, a = x
    th = np.tanh(a * qd)
    u = np.abs(qd / v_s)
    e = np.exp(-u**delta_s)
    J = np.empty((qd.size, 6))
    J[:, 0] = qd
    J[:, 1] = th * (1.0 + S * e)
    J[:, 2] = F_c * th * e
    # d/dv_s of exp(-(|qd|/v_s)^d) = e * d * u^d / v_s
    J[:, 3] = F_c * th * S * e * delta_s * u**delta_s / v_s
    J[:, 4] = 1.0
    J[:, 5] = F_c * (1.0 - th**2) * qd * (1.0 + S * e)
    return J


def standard_errors(jac: np.ndarray, residual: np.ndarray, rtol: float = 1e-9, rows: np.ndarray | None = None,
                    max_lag: int = 0) -> np.ndarray:
    """Standard errors from the Jacobian at a least-squares solution (module docstring).

    With ``max_lag > 0`` the residuals may be correlated in time (a filtered estimate, or
    model error that varies slowly): the covariance is the Newey-West sandwich
    ``(J^T J)^+ [sum_l w_l G_l] (J^T J)^+`` with Bartlett weights ``w_l = 1 - l / (max_lag + 1)``
    over the products of the gradients ``g_t = J_t r_t`` of samples ``l`` rows apart in the
    time series (``rows``: their indices in it; only truly consecutive pairs count).

    Returns:
        (p,) standard errors; ``inf`` for a parameter with a component in the numerical
        null space of ``J`` (not identifiable).
    """
    n, p = jac.shape
    _, sv, Vt = np.linalg.svd(jac, full_matrices=False)
    keep = sv > rtol * sv[0] if sv[0] > 0 else np.zeros_like(sv, dtype=bool)
    V = Vt.T
    null = V[:, ~keep]
    unidentifiable = (np.abs(null) > 1e-6).any(axis=1) if null.size else np.zeros(p, dtype=bool)
    if max_lag <= 0:
        s2 = float(residual @ residual) / max(n - p, 1)
        var = (V[:, keep] ** 2 / sv[keep] ** 2).sum(axis=1) * s2
    else:
        rows = np.arange(n) if rows is None else np.asarray(rows)
        g = jac * residual[:, None] * np.sqrt(n / max(n - p, 1))
        meat = g.T @ g
        for lag in range(1, min(max_lag, n - 1) + 1):
            pair = rows[lag:] - rows[:-lag] == lag
            if pair.any():
                c = g[lag:][pair].T @ g[:-lag][pair]
                meat += (1.0 - lag / (max_lag + 1.0)) * (c + c.T)
        bread = (V[:, keep] / sv[keep] ** 2) @ V[:, keep].T  # (J^T J)^+
        var = np.clip(np.diag(bread @ meat @ bread), 0.0, None)
    return np.where(unidentifiable, np.inf, np.sqrt(var))


def correlation_lag(residual: np.ndarray, rows: np.ndarray, threshold: float = 0.05, cap: int = 2000) -> int:
    """Largest lag worth summing in :func:`standard_errors`: twice the lag at which the
    residuals' autocorrelation (over samples truly that many rows apart) first falls below
    ``threshold``, and at least Newey and West's rule of thumb ``4 (n / 100)^(2/9)``."""
    n = len(residual)
    rule = int(4 * (n / 100.0) ** (2.0 / 9.0))
    var = float(residual @ residual) / max(n, 1)
    if var == 0:
        return rule
    for lag in range(1, min(cap, n - 1) + 1):
        pair = rows[lag:] - rows[:-lag] == lag
        if pair.sum() < 10 or float(residual[lag:][pair] @ residual[:-lag][pair]) / pair.sum() < threshold * var:
            return max(rule, 2 * lag)
    return max(rule, 2 * cap)


def initial_guesses(qd: np.ndarray, y: np.ndarray) -> list[np.ndarray]:
    """Starting points: a linear Coulomb-viscous-offset fit times a grid of (S, v_s, a)."""
    A = np.column_stack([qd, np.sign(qd), np.ones_like(qd)])
    (F_v, F_c, tau_os), *_ = np.linalg.lstsq(A, y, rcond=None)
    F_v, F_c = max(F_v, 0.0), max(F_c, 1e-3)
    scale = max(np.percentile(np.abs(qd), 90), 1e-3)
    starts = []
    for S, vs_frac, a_mul in itertools.product((0.2, 1.0), (0.05, 0.2, 0.5), (5.0, 50.0)):
        a = min(max(a_mul / scale, LOWER[5] * 10), UPPER[5] / 10)
        starts.append(np.clip([F_v, F_c, S, vs_frac * scale, tau_os, a], LOWER + 1e-9, UPPER - 1e-9))
    return starts


def _solve(residual, jacobian, start, bounds, max_nfev):
    start = np.clip(start, bounds[0] + 1e-12, bounds[1] - 1e-12)
    return least_squares(residual, start, jac=jacobian, bounds=bounds, method="trf", x_scale="jac",
                         ftol=1e-10, xtol=1e-10, gtol=1e-10, max_nfev=max_nfev)


def _filtered_problem(qd: np.ndarray, y: np.ndarray, use: np.ndarray, smoother, delta_s: float):
    """Residual and Jacobian of the model passed through ``smoother``, on the rows ``use``."""
    rows = np.flatnonzero(use)

    def both(x):
        cols = np.column_stack([model_values(x, qd, delta_s), model_jacobian(x, qd, delta_s)])
        return smoother(cols)[rows]

    cache: dict[bytes, np.ndarray] = {}

    def values(x):
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = both(x)
        return cache[key]

    return (lambda x: values(x)[:, 0] - y[rows]), (lambda x: values(x)[:, 1:])


def fit_friction(qd: np.ndarray, tau_f: np.ndarray, *, delta_s: float = 2.0, joint: str = "",
                 x0: np.ndarray | None = None, min_samples: int = 20, mask: np.ndarray | None = None,
                 smoother=None, fixed: dict[str, float] | None = None) -> FitResult:
    """Fit model (3.5) to friction estimates of one joint (eq. 6.4).

    Args:
        qd: joint velocities (N,) [rad/s].
        tau_f: friction torques on the joint (N,) [N·m] (``tau_f = -f(qd)``).
        delta_s: Stribeck exponent, fixed (thesis: 2).
        joint: name, for the result.
        x0: a starting point (6,) in :data:`~wbfriction.friction.models.PARAM_NAMES` order; by
            default several (:func:`initial_guesses`), the best fit is kept.
        min_samples: fewer samples give a result without parameters.
        mask: (N,) samples to fit (default: every finite one).
        smoother: the zero-phase smoother ``tau_f`` went through
            (:attr:`~wbfriction.friction.estimate.FrictionEstimate.smoother`), or None; ``qd`` and
            ``tau_f`` are then whole time series, ``qd`` NaN where the estimate was left out
            of the smoothing, and the model goes through the same smoother before it is
            compared (module docstring). Samples where the smoothed model is undefined are
            not used.
        fixed: parameters held at a value instead of fitted (standard error 0), e.g.
            ``{"S": 0, "v_s": 0.1, "tau_os": 0}`` for a Coulomb-viscous model.

    Returns:
        :class:`FitResult`.

    Raises:
        InputError: an unknown name in ``fixed``.
    """
    # One BLAS thread: the solver's many small (N x 6) factorizations run several times
    # slower on OpenBLAS's threads than on one (30 TALOS joints of a 10-step walk: 78 s
    # against 14 s on 2 cores); fit joints side by side instead (fit_estimate's workers).
    with threadpool_limits(1, user_api="blas"):
        return _fit_friction(qd, tau_f, delta_s=delta_s, joint=joint, x0=x0, min_samples=min_samples, mask=mask,
                             smoother=smoother, fixed=fixed)


def _fit_friction(qd: np.ndarray, tau_f: np.ndarray, *, delta_s: float = 2.0, joint: str = "",
                 x0: np.ndarray | None = None, min_samples: int = 20, mask: np.ndarray | None = None,
                 smoother=None, fixed: dict[str, float] | None = None) -> FitResult:
    """:func:`fit_friction`, on the threads it is given."""
    fixed = dict(fixed or {})
    if set(fixed) - set(PARAM_NAMES):
        raise InputError(f"unknown parameter(s) to fix: {', '.join(sorted(set(fixed) - set(PARAM_NAMES)))}")
    free = np.array([name not in fixed for name in PARAM_NAMES])
    held = np.array([float(fixed.get(name, 0.0)) for name in PARAM_NAMES])

    def full(z: np.ndarray) -> np.ndarray:
        x = held.copy()
        x[free] = z
        return x

    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = np.isfinite(qd) & np.isfinite(y)
    if mask is not None:
        use &= np.asarray(mask, dtype=bool)
    if smoother is not None:
        use &= np.isfinite(smoother(qd))
    n = int(use.sum())
    if n < max(min_samples, 7):
        return FitResult(joint, n, message=f"only {n} valid samples")
    v, yu = qd[use], y[use]
    starts = [np.asarray(x0, dtype=float)] if x0 is not None else initial_guesses(v, yu)
    starts = list({tuple(x[free]): x[free] for x in starts}.values())  # distinct over the free ones
    residual = lambda z: model_values(full(z), v, delta_s) - yu  # noqa: E731
    jacobian = lambda z: model_jacobian(full(z), v, delta_s)[:, free]  # noqa: E731
    bounds = tuple(b[free] for b in _bounds(v))
    # a short run from every start, then the two best refined
    if len(starts) > 1:
        short = sorted((_solve(residual, jacobian, s, bounds, 30) for s in starts), key=lambda r: r.cost)
        starts = [r.x for r in short[:2]]
    best = min((_solve(residual, jacobian, s, bounds, 300) for s in starts), key=lambda r: r.cost)
    if smoother is not None:
        f_residual, f_jacobian = _filtered_problem(qd, y, use, smoother, delta_s)
        residual, jacobian = (lambda z: f_residual(full(z))), (lambda z: f_jacobian(full(z))[:, free])
        best = _solve(residual, jacobian, best.x, bounds, 200)
    # residuals correlated over the filter's window, or over the span of a model error
    rows = np.flatnonzero(use)
    se = np.zeros(len(PARAM_NAMES))
    se[free] = standard_errors(jacobian(best.x), best.fun, rows=rows, max_lag=correlation_lag(best.fun, rows))
    return FitResult(
        joint=joint, n_samples=n, params=FrictionParams.from_vector(full(best.x), delta_s),
        stderr=dict(zip(PARAM_NAMES, map(float, se))), rms_residual=float(np.sqrt(np.mean(best.fun**2))),
        success=bool(best.success), message=str(best.message))


def _fit_column(args: tuple) -> FitResult:
    qd, tau_f, valid, kwargs = args
    return fit_friction(qd, tau_f, mask=valid, **kwargs)


def fit_joints(joints, qd: np.ndarray, tau_f: np.ndarray, valid: np.ndarray, *,
                 tau_f_true: np.ndarray | None = None, targets: dict[str, FrictionParams] | None = None,
                 delta_s: float = 2.0, min_samples: int = 20, smoother=None,
                 fixed: dict[str, float] | None = None, workers: int = 1) -> list[FitResult]:
    """Fit every joint of a friction estimate on its valid samples.

    Args:
        joints: names (n,).
        qd, tau_f, valid: (N, n) arrays of a :class:`~wbfriction.friction.estimate.FrictionEstimate`
            (the whole time series: with ``smoother`` the model is filtered along it).
        tau_f_true: (N, n) true friction (NaN columns for unknown) or None.
        targets: true parameters per joint name, when known.
        smoother: the estimate's smoother (``FrictionEstimate.smoother``) or None.
        fixed: parameters held instead of fitted (:func:`fit_friction`).
        workers: processes fitting joints side by side (each fit is independent of the
            others: the results do not depend on it).
    """
    tasks = [(qd[:, i], tau_f[:, i], valid[:, i],
              dict(delta_s=delta_s, joint=joint, min_samples=min_samples, smoother=smoother, fixed=fixed))
             for i, joint in enumerate(joints)]
    if workers > 1 and len(tasks) > 1:
        with ProcessPoolExecutor(min(workers, len(tasks)), mp_context=multiprocessing.get_context("fork")) as pool:
            fitted = list(pool.map(_fit_column, tasks))
    else:
        fitted = [_fit_column(task) for task in tasks]
    out = []
    for i, (joint, res) in enumerate(zip(joints, fitted)):
        m = valid[:, i] & np.isfinite(tau_f[:, i]) & np.isfinite(qd[:, i])
        if tau_f_true is not None and np.isfinite(tau_f_true[m, i]).all() and m.any():
            res.rms_error_vs_true = float(np.sqrt(np.mean((tau_f[m, i] - tau_f_true[m, i]) ** 2)))
            if res.params is not None:
                res.rms_model_vs_true = float(np.sqrt(np.mean((res.params.torque(qd[m, i]) - tau_f_true[m, i]) ** 2)))
        if targets and joint in targets:
            res.target = targets[joint]
        out.append(res)
    return out


def fit_estimate(est: FrictionEstimate, *, delta_s: float = 2.0, min_samples: int = 20,
                 workers: int = 1) -> list[FitResult]:
    """Fit every joint of an estimate (:func:`fit_joints` on its valid samples, on ``workers``
    processes); its ``tau_f_true`` and ``friction_true`` metadata, when present (simulated
    logs), give the errors against truth.

    Raises:
        InputError: ``friction_true`` metadata that are not parameters of (3.5).
    """
    targets = {j: FrictionParams.from_dict(p) for j, p in est.metadata.get("friction_true", {}).items()}
    return fit_joints(est.joints, est.qd, est.tau_f, est.valid, tau_f_true=est.tau_f_true, targets=targets,
                      delta_s=delta_s, min_samples=min_samples, smoother=est.smoother, workers=workers)

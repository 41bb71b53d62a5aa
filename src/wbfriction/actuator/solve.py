"""The balance's linear least squares (:mod:`wbfriction.actuator.rows`): the design, the exact delay search, the
bounded solution and its covariances.

Unknowns, in this order: the armature ``I_a`` of each of the ``n`` joints [kg·m²], ``F_v`` [N·m·s/rad], ``F_c``
[N·m], then (where fitted) the encoder offsets ``o`` [rad]. Each row is one joint's balance over one window, weighted
by the inverse of that joint's noise: the residuals' own RMS for the standard errors, the noise the sensors predict
for the Cramér-Rao bound (:attr:`BalanceRows.sigma <wbfriction.actuator.rows.BalanceRows.sigma>`).

**Standard errors under correlated residuals.** A window's residual is mostly model error (the simulator's
discretisation, a friction that sticks, a driver's filter), correlated over the windows of a ramp: the covariance
is a heteroscedasticity- and autocorrelation-consistent sandwich (Newey and West, 1987), the scores summed over the
joints of each window (the joints' residuals of one instant correlate through the offsets' columns) and their
cross-products kept up to :func:`hac_lags` windows apart with Bartlett weights (:func:`sandwich`). The
variance of each value is raised to its delete-one-block jackknife's over contiguous time blocks of the windows
(:func:`block_grown`, :mod:`wbfriction.fit.block_spread`): a model error that changes slowly over the log (a gravity
model off while the posture drifts, a friction law the columns do not hold) moves the values by more than its small
correlation at each lag shows the sandwich. The identification reports no standard error below its Cramér-Rao
bound (``max(se, crb)``: :mod:`wbfriction.actuator.identification`).

**Delay.** Between two whole periods, ``kT <= d <= (k+1)T``, the right-hand side is ``y_k + theta (y_{k+1} - y_k)``
and the residual of the linear problem's projection is ``r(theta) = r_k + theta Delta r``: the squared residual is a
parabola in ``theta``, minimised in closed form on each interval; the best interval's minimum is the delay, its
curvature ``|Delta r|² / T²`` the delay's information (profile likelihood: ``var(d) = s² / curvature``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import lsq_linear

from wbfriction.actuator.rows import BalanceRows
from wbfriction.fit.block_spread import block_count, jackknife_shifts, jackknife_spread, t_scale

KINDS = ("armature", "F_v", "F_c", "offset")
"""The unknowns' kinds, in the design's column order (module docstring)."""


@dataclass(frozen=True)
class Design:
    """The balance's design for the usable rows: ``A`` (R, P), each row's joint and window, the offsets fitted."""

    A: np.ndarray
    joint: np.ndarray
    window: np.ndarray
    offsets: bool

    def rhs(self, rows: BalanceRows, balance: np.ndarray) -> np.ndarray:
        """The right-hand side (R,) [N·m·s] of the balance ``balance`` (W, n): the offsets' linearisation point
        moved to it, so the offsets solved for are the offsets themselves."""
        shifted = balance - np.einsum("wjk,k->wj", rows.gravity, rows.offset) if self.offsets else balance
        return shifted[self.window, self.joint]


def design(rows: BalanceRows, windows: np.ndarray, offsets: bool, steep: bool = False) -> Design:
    """The design of the usable rows of ``windows`` (indices into W) (module docstring); ``steep``: the Coulomb
    column :attr:`~wbfriction.actuator.rows.BalanceRows.coulomb_steep`."""
    n = len(rows.joints)
    usable = rows.usable[windows]
    w_idx, j_idx = np.nonzero(usable)
    window = windows[w_idx]
    A = np.zeros((len(window), (4 if offsets else 3) * n))
    r = np.arange(len(window))
    A[r, j_idx] = rows.dv[window, j_idx]
    A[r, n + j_idx] = rows.qd[window, j_idx]
    coulomb = rows.coulomb_steep if steep and rows.coulomb_steep is not None else rows.coulomb
    A[r, 2 * n + j_idx] = coulomb[window, j_idx]
    if offsets:
        A[:, 3 * n:] = -rows.gravity[window, j_idx, :]
    return Design(A, j_idx, window, offsets)


@dataclass(frozen=True)
class DelaySearch:
    """The delay minimising the weighted squared residual, and its profile.

    Attributes:
        delay: the delay [s].
        curvature: the weighted squared residual's second derivative in the delay, halved [1/s²] (weights
            ``1/sigma``: ``var(d) = s² / curvature``).
        profile: (K + 2, 2) the delay [s] and the weighted squared residual at every whole period.
    """

    delay: float
    curvature: float
    profile: np.ndarray


def search_delay(rows: BalanceRows, d: Design, weight: np.ndarray) -> DelaySearch:
    """The exact search of the delay over ``[0, (K+1) T]`` (module docstring), rows weighted by ``weight`` (n,) of
    their joint."""
    w = weight[d.joint]
    Q, _ = np.linalg.qr(d.A * w[:, None])

    def residual(x: np.ndarray) -> np.ndarray:
        return x - Q @ (Q.T @ x)

    K = rows.max_steps
    r = [residual(w * d.rhs(rows, rows.setpoint[k] + rows.rest)) for k in range(K + 2)]
    best = (np.inf, 0.0, 0.0)
    for k in range(K + 1):
        dr = r[k + 1] - r[k]
        denominator = float(dr @ dr)
        theta = 0.0 if denominator == 0 else float(np.clip(-(r[k] @ dr) / denominator, 0.0, 1.0))
        rss = float(np.sum((r[k] + theta * dr) ** 2))
        if rss < best[0]:
            best = (rss, (k + theta) * rows.period, denominator / rows.period**2)
    profile = np.array([[k * rows.period, float(x @ x)] for k, x in enumerate(r)])
    return DelaySearch(best[1], best[2], profile)


@dataclass(frozen=True)
class Solution:
    """The bounded solution of the balance and its covariances.

    Attributes:
        x: (P,) the unknowns (module docstring's order).
        at_bound: (P,) whether each sits on a bound of the search.
        covariance: (P, P) from the residuals (each joint's rows weighted by its residual RMS).
        bound: (P, P) the Cramér-Rao bound's covariance (rows weighted by the noise the sensors predict).
        rms: (n,) each joint's residual RMS [N·m·s per window].
        rows: (n,) each joint's rows used.
    """

    x: np.ndarray
    at_bound: np.ndarray
    covariance: np.ndarray
    bound: np.ndarray
    rms: np.ndarray
    rows: np.ndarray


def bounds(n: int, offsets: bool, offset_bound: float) -> tuple[np.ndarray, np.ndarray]:
    """The search's bounds: armature, F_v, F_c at least 0; offsets within ``offset_bound`` [rad]."""
    lower = np.concatenate([np.zeros(3 * n), np.full(n if offsets else 0, -offset_bound)])
    upper = np.concatenate([np.full(3 * n, np.inf), np.full(n if offsets else 0, offset_bound)])
    return lower, upper


def solve(d: Design, y: np.ndarray, weight: np.ndarray, predicted: np.ndarray, offset_bound: float,
          lags: int = 0) -> Solution:
    """The bounded weighted least squares of the balance (rows weighted by ``weight`` (n,) of their joint), its
    covariance from each joint's residuals (:func:`sandwich` with ``lags`` windows of autocorrelation) and its
    Cramér-Rao bound from ``predicted`` (n,), the sensors' noise of one window's balance [N·m·s]."""
    n = len(weight)
    w = weight[d.joint]
    lower, upper = bounds(n, d.offsets, offset_bound)
    res = lsq_linear(d.A * w[:, None], y * w, bounds=(lower, upper), method="bvls", tol=1e-12)
    x = res.x
    span = np.maximum(np.abs(x), 1e-12)
    at_bound = (np.abs(x - upper) < 1e-9 * span) | ((np.abs(x - lower) < 1e-9 * span) & (lower != 0))
    e = y - d.A @ x
    count = np.bincount(d.joint, minlength=n)
    dof = max(len(y) - d.A.shape[1], 1) / max(len(y), 1)
    rms = np.sqrt(np.bincount(d.joint, weights=e**2, minlength=n) / np.maximum(count * dof, 1))
    scale = _safe(rms)[d.joint]
    return Solution(x, at_bound, sandwich(d.A / scale[:, None], e / scale, d.window, lags),
                    _inverse(d.A / _safe(predicted)[d.joint][:, None]), rms, count)


HAC_SPAN = 0.5
"""The longest lag of the sandwich's autocorrelation [s] (:func:`hac_lags`): a ramp's half reversal period on the
set-points this is for (reversals every 0.2-1.5 s; the real Aliengo's likewise): a model error that follows the
motion changes sign at the reversals. A physical span, not fitted on data."""


def hac_lags(windows: int, window: float) -> int:
    """The sandwich's longest lag in windows: :data:`HAC_SPAN` over the window ``window`` [s], at most a quarter
    of the log's ``windows`` (a lag as long as the log estimates nothing)."""
    return max(0, min(int(round(HAC_SPAN / window)), windows // 4))


def sandwich(X: np.ndarray, e: np.ndarray, window: np.ndarray, lags: int) -> np.ndarray:
    """The autocorrelation-consistent covariance (P, P) of a least squares of the weighted design ``X`` (R, P) with
    weighted residuals ``e`` (R,), whose rows fall in the windows ``window`` (R,) (module docstring): ``B S B``
    with ``B = (X^T X)^-1`` (:func:`_inverse`: infinite where the rows determine nothing) and ``S`` the
    Bartlett-weighted sum of the windows' score products up to ``lags`` apart; returned as ``B`` with each
    parameter's variance grown to the sandwich's, never shrunk (a correlation estimated to shrink the error is not
    taken), so the matrix stays a covariance."""
    bread = _inverse(X)
    finite = np.isfinite(np.diag(bread))
    if len(e) == 0 or not finite.any():
        return bread
    first = int(window.min())
    scores = np.zeros((int(window.max()) - first + 1, X.shape[1]))
    np.add.at(scores, window - first, X * e[:, None])
    meat = scores.T @ scores
    for lag in range(1, lags + 1):
        c = scores[lag:].T @ scores[:-lag]
        meat += (1.0 - lag / (lags + 1)) * (c + c.T)
    b = bread[np.ix_(finite, finite)]
    hac = np.diag(b @ meat[np.ix_(finite, finite)] @ b)
    grow = np.sqrt(np.maximum(hac, np.diag(b)) / np.maximum(np.diag(b), 1e-300))
    cov = bread.copy()
    cov[np.ix_(finite, finite)] = b * np.outer(grow, grow)
    return cov


def block_grown(sol: Solution, d: Design, y: np.ndarray, weight: np.ndarray, lags: int) -> Solution:
    """``sol`` with each value's variance raised to its block jackknife's (module docstring): the windows cut into
    contiguous time blocks of at least ``lags`` windows (:func:`~wbfriction.fit.block_spread.block_count`), each
    block's rows (every joint's of its windows) left out in turn from the weighted least squares of ``d`` (R, P),
    ``y`` (R,) and the joints' ``weight`` (n,), on the normal scale (:func:`~wbfriction.fit.block_spread.t_scale`);
    values on a bound of the search, at a floor of zero or not determined are not stepped. Never lowers a variance;
    ``sol`` unchanged with too few windows for the blocks."""
    active = ~sol.at_bound & (np.abs(sol.x) > 1e-12) & np.isfinite(np.diag(sol.covariance))
    first, count = int(d.window.min()), int(np.ptp(d.window)) + 1 if len(d.window) else 0
    k = block_count(count, lags, 0)
    if k == 0 or not active.any():
        return sol
    w = weight[d.joint]
    labels = (d.window - first) * k // count
    shifts = jackknife_shifts(d.A * w[:, None], (d.A @ sol.x - y) * w, active, k, labels=labels)
    spread = t_scale(k) * jackknife_spread(shifts)
    grow = np.sqrt(np.maximum(spread**2, np.diag(sol.covariance)) / np.maximum(np.diag(sol.covariance), 1e-300))
    grow = np.where(np.isfinite(grow), grow, 1.0)
    return replace(sol, covariance=sol.covariance * np.outer(grow, grow))


def _safe(x: np.ndarray) -> np.ndarray:
    return np.where(x > 0, x, np.inf)


def _inverse(A: np.ndarray) -> np.ndarray:
    """``(A^T A)^-1``, infinite on the diagonal of a direction the rows do not determine."""
    info = A.T @ A
    try:
        cov = np.linalg.inv(info)
    except np.linalg.LinAlgError:
        cov = np.linalg.pinv(info)
    bad = ~np.isfinite(np.diag(cov)) | (np.diag(info) == 0)
    cov[bad, bad] = np.inf
    return cov

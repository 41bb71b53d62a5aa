"""The balance's linear least squares (:mod:`wbfriction.actuator.rows`): the design, the exact delay search, the
bounded solution and its covariances.

Unknowns, in this order: the armature ``I_a`` of each of the ``n`` joints [kg·m²], ``F_v`` [N·m·s/rad], ``F_c``
[N·m], then (where fitted) the encoder offsets ``o`` [rad]. Each row is one joint's balance over one window, weighted
by the inverse of that joint's noise (:class:`Weighted`): the residuals' own RMS for the standard errors, the noise
the sensors predict for the Cramér-Rao bound (:attr:`BalanceRows.sigma <wbfriction.actuator.rows.BalanceRows.sigma>`).

**Delay.** Between two whole periods, ``kT <= d <= (k+1)T``, the right-hand side is ``y_k + theta (y_{k+1} - y_k)``
and the residual of the linear problem's projection is ``r(theta) = r_k + theta Delta r``: the squared residual is a
parabola in ``theta``, minimised in closed form on each interval; the best interval's minimum is the delay, its
curvature ``|Delta r|² / T²`` the delay's information (profile likelihood: ``var(d) = s² / curvature``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from wbfriction.actuator.rows import BalanceRows

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


def design(rows: BalanceRows, windows: np.ndarray, offsets: bool) -> Design:
    """The design of the usable rows of ``windows`` (indices into W) (module docstring)."""
    n = len(rows.joints)
    usable = rows.usable[windows]
    w_idx, j_idx = np.nonzero(usable)
    window = windows[w_idx]
    A = np.zeros((len(window), (4 if offsets else 3) * n))
    r = np.arange(len(window))
    A[r, j_idx] = rows.dv[window, j_idx]
    A[r, n + j_idx] = rows.qd[window, j_idx]
    A[r, 2 * n + j_idx] = rows.coulomb[window, j_idx]
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


def solve(d: Design, y: np.ndarray, weight: np.ndarray, predicted: np.ndarray, offset_bound: float) -> Solution:
    """The bounded weighted least squares of the balance (rows weighted by ``weight`` (n,) of their joint), its
    covariance from each joint's residual RMS and its Cramér-Rao bound from ``predicted`` (n,), the sensors'
    noise of one window's balance [N·m·s]."""
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
    return Solution(x, at_bound, _inverse(d.A / _safe(rms)[d.joint][:, None]),
                    _inverse(d.A / _safe(predicted)[d.joint][:, None]), rms, count)


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

"""The Cramér-Rao bound of a friction fit: how well the data can determine each parameter (issue 38).

Whatever the route, the friction ``tau_f`` of a joint is measured sample by sample with two noises: the torque
sensor's, white (``sigma_tau``), and the positions', which the equations of motion see through the joint's
inertia and a second derivative. Per sample (variance ``P`` per unit bandwidth of the sampling, a white noise of
variance ``s^2`` having ``P = s^2``) the estimate's noise spectrum is

.. math::

    P(f) = \\sigma_\\tau^2 + \\big(M \\sigma_q\\, G(f)\\big)^2, \\qquad
    G(f) = \\frac{4 \\sin^2(\\pi f \\Delta t)}{\\Delta t^2},

``M`` the joint's effective inertia (the norm of its row of the joint-space inertia matrix: every joint's
position noise reaches it) and ``sigma_q`` the positions' white noise (:mod:`wbfriction.signals.choice`): white
noise plus a moving average of order 2, whose covariance over a run of samples is banded,
``Sigma = sigma_tau^2 I + (M sigma_q / dt^2)^2 T`` (``T`` the second difference's: 6 on the diagonal, -4 and 1
beside). For a model ``f(qd; p)`` at the velocities the log shows, the Fisher information over the runs of
consecutive samples the fit uses is ``I = sum_runs J^T Sigma^-1 J`` (:func:`fisher_information`, exact), and the
bound is ``I^{-1}``: no unbiased estimator of these parameters from these data has a smaller
covariance, whatever route and filter it takes. Parameters with a component in the numerical null space of
``I`` get an infinite bound (not identifiable). It assumes the velocities known (the model's argument exact):
the errors in variables of :mod:`wbfriction.fit.eiv` only add to it.

``sigma_q`` is measured from the positions' spectrum, ``M`` from the model; ``sigma_tau`` cannot be told from the
torques alone (a controller's torque responds to the same noise), so :func:`torque_noise` takes it from the fit's
residual at zero frequency, where the positions' noise has no share: the residual also holds any slow model
error, which makes the bound larger, never smaller.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from wbfriction.friction.noise import NoiseModel

BATCH = 64
"""Fewest consecutive samples per batch of :func:`torque_noise` (at least four windows of the smoother)."""


def torque_noise(residual: np.ndarray, rows: np.ndarray, batch: int = BATCH, floor: float = 1e-6) -> float:
    """``sigma_tau`` [N·m] from a fit's residual ``residual`` (n,) at the samples ``rows`` (n,) (their indices in the
    log, increasing): its spectrum at zero frequency, by Hann-tapered batch means: ``sigma_tau^2 = mean_b (sum_t w_t
    r_t)^2 / sum_t w_t^2`` over the batches of ``batch`` consecutive samples. At zero frequency the torque's white
    noise is whole (through a zero-phase smoother of unit gain) and the positions' noise, seen through a derivative,
    is absent; the taper keeps it out at the batches' ends too (summed by parts, a derivative's share falls as
    ``1 / batch^2`` instead of ``1 / batch``). Whatever model error varies slowly is in it (a larger bound, never a
    smaller one). Without one whole batch, each run of a quarter batch or more is a batch of its own length; NaN
    without one; at least ``floor``."""
    rows = np.asarray(rows)
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(rows) != 1) + 1, [len(rows)]])
    runs = list(zip(cuts[:-1], cuts[1:]))
    blocks = [(a + k, a + k + batch) for a, b in runs for k in range(0, b - a - batch + 1, batch)]
    if not blocks:  # runs shorter than a batch (a log cut by contact changes and sticking)
        blocks = [(a, b) for a, b in runs if b - a >= max(batch // 4, 4)]
    if not blocks:
        return float("nan")
    total = weight = 0.0
    for a, b in blocks:
        w = np.sin(np.pi * (np.arange(b - a) + 0.5) / (b - a)) ** 2  # Hann, zero at both ends
        total += float(w @ residual[a:b]) ** 2
        weight += float(w @ w)
    return max(math.sqrt(total / weight), floor)


def fisher_information(jac: np.ndarray, rows: np.ndarray, noise: NoiseModel) -> np.ndarray:
    """The Fisher information (p, p) of the model's Jacobian ``jac`` (n, p) at the samples ``rows`` (n,) (their
    indices in the log, increasing: each run of consecutive rows one stationary stretch), the noise's covariance
    within a run ``sigma_tau^2 I + (M sigma_q / dt^2)^2 T``, ``T`` the second difference's (bands 6, -4, 1): exactly
    ``J^T Sigma^-1 J``, by a banded Cholesky solve per run (LAPACK's ``pbtrf`` then ``pbtrs``: what
    ``scipy.linalg.solveh_banded`` does, the factor kept for the next run of that length and noise)."""
    from scipy.linalg import cho_solve_banded
    rows = np.asarray(rows)
    n, p = jac.shape
    info = np.zeros((p, p))
    c = (noise.inertia * noise.position / noise.dt**2) ** 2
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(rows) != 1) + 1, [n]])
    for a, b in zip(cuts[:-1], cuts[1:]):
        J = jac[a:b]
        if c == 0.0:
            info += J.T @ J / noise.torque**2
            continue
        info += J.T @ cho_solve_banded((_noise_factor(c, noise.torque**2, b - a), False), J)
    return info


@lru_cache(maxsize=32)
def _noise_factor(c: float, white: float, n: int) -> np.ndarray:
    """The upper banded Cholesky factor (3, n) of ``white I + c T`` over ``n`` consecutive samples
    (:func:`fisher_information`); read-only, shared by the calls with the same noise and length (a design's
    optimiser asks for the same one thousands of times)."""
    from scipy.linalg import cholesky_banded
    bands = np.empty((3, n))
    bands[0], bands[1], bands[2] = c, -4.0 * c, 6.0 * c + white
    factor = cholesky_banded(bands, lower=False)
    factor.flags.writeable = False
    return factor


def cramer_rao(jac: np.ndarray, rows: np.ndarray, noise: NoiseModel, rtol: float = 1e-9) -> np.ndarray:
    """The bound's covariance (p, p): the pseudo-inverse of :func:`fisher_information` scaled to a unit diagonal; the
    rows and columns of a parameter with a component in its numerical null space (relative eigenvalue below
    ``rtol``) are ``inf``."""
    info = fisher_information(jac, rows, noise)
    scale = np.sqrt(np.clip(np.diag(info), 0.0, None))
    scale[scale == 0] = 1.0
    info = info / np.outer(scale, scale)  # unit diagonal: the parameters' units do not decide what is identifiable
    w, V = np.linalg.eigh(info)
    keep = w > rtol * w.max() if w.size and w.max() > 0 else np.zeros_like(w, dtype=bool)
    with np.errstate(over="ignore"):  # a parameter with next to no information: a bound of inf, which it is
        cov = (V[:, keep] / w[keep]) @ V[:, keep].T / np.outer(scale, scale)
    null = V[:, ~keep]
    bad = (np.abs(null) > 1e-6).any(axis=1) if null.size else np.zeros(jac.shape[1], dtype=bool)
    cov[bad, :] = np.inf
    cov[:, bad] = np.inf
    return cov


def at_least_bound(covariance: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """``covariance`` (p, p) scaled so that no standard error falls below its Cramér-Rao bound ``bound`` (p,)
    (standard deviations; 0 or not finite: no bound): ``D C D`` with ``D = diag(max(1, b_i / s_i))``, which keeps the
    correlations (issue 63). The residuals' sandwich sees the torque's noise and the model's error as the fit's
    residual shows them; the bound sees the positions' noise through the equations of motion, which the residual of
    a filtered or momentum estimate shows smoothed away: where the bound is the larger, no unbiased estimator could
    do better than it, and a standard error below it claims what the data cannot carry (the README's tour: F_v 0.180
    ± 0.005 against an injected 0.2, a bound of 0.008)."""
    cov = np.array(covariance, dtype=float)
    se = np.sqrt(np.abs(np.diag(cov)))
    b = np.nan_to_num(np.asarray(bound, dtype=float), nan=0.0, posinf=0.0)
    scale = np.ones_like(se)
    raise_ = np.isfinite(se) & (se > 0) & (b > se)
    scale[raise_] = b[raise_] / se[raise_]
    with np.errstate(invalid="ignore"):
        return cov * np.outer(scale, scale)

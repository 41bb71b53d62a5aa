"""The block spread of a fit's parameters: a delete-one-block jackknife over contiguous time blocks of the samples it
used, linearised at the optimum (what the log shows of an error that changes over it).

The Newey-West standard error (:func:`~wbfriction.fit.regression.parameter_covariance`) sums the residuals'
correlation up to a lag where it has fallen below 5 %; an error of the estimate that changes slowly over the log (a
stance leg's creep, a drift of the friction, a differentiation error that follows the gait) is correlated at every
lag by a little, below that threshold, and its sum over thousands of lags is what moves the parameters. The block
jackknife sees it without a model of the correlation: the valid samples, in time order, are cut into ``K``
contiguous blocks of (nearly) equal counts (as :func:`~wbfriction.fit.regression.held_out_split` cuts them), the fit
is repeated without each block in turn, and the spread of the ``K`` values is the parameters' standard error
(Künsch 1989, *The jackknife and the bootstrap for general stationary observations*, Ann. Statist. 17, 1217-1241,
for the non-overlapping blocks; Efron 1982, *The Jackknife, the Bootstrap and Other Resampling Plans*, SIAM, ch. 3,
for the variance formula)

.. math:: v_{JK} = \\frac{K - 1}{K} \\sum_k (\\hat\\theta_{(k)} - \\bar\\theta)^2 .

Each deleted block's fit is one Gauss-Newton step from the whole fit's optimum with its Jacobian ``J`` (n, p) and
residual ``r`` (n,) (model - data): at the optimum ``J^T r = 0`` over the interior parameters, so without the rows
``k``,

.. math:: \\hat\\theta_{(k)} - \\hat\\theta = (J^T J - J_k^T J_k)^{-1} J_k^T r_k ,

exact for a model linear in its parameters (Coulomb-viscous), to first order for the others; ``K`` small solves of
(p, p), nothing refitted. Parameters at a bound, held or not identifiable are left out of the step (their spread 0:
their status says what they are).

The number of blocks: :data:`BLOCKS` (the model choice's cut, :data:`~wbfriction.fit.regression.HELD_OUT_BLOCKS`),
fewer where a block would be shorter than the residuals' correlation lag (the Newey-West lag,
:func:`~wbfriction.fit.regression.correlation_lag`: itself twice the lag where their autocorrelation falls below 5 %;
the blocks must be nearly independent for the formula to hold), none below :data:`MIN_BLOCKS`. With ``K`` blocks the
variance estimate has ``K - 1`` degrees of freedom: the interval it gives is Student's, ``theta ± t_{K-1} v_JK^(1/2)``
(Efron 1982, ch. 3; Künsch 1989, sec. 3), whose 95 % quantile ``t_{9}`` is 2.26 at ten blocks, not the normal 1.96,
and its own relative error about ``1 / sqrt(2 (K - 1))`` (24 %). The spread is therefore given on the normal scale,
the jackknife's standard error times ``t_{K-1} / z`` (both at 97.5 %, :func:`t_scale`: 1.15 at ten blocks), so that ±2
of it, as a user reads any standard error, is the jackknife's 95 % interval; it enters the read error as the larger of
it and the Newey-West one (:func:`statistical_error`), never alone below the latter.
"""

from __future__ import annotations

import math

import numpy as np

from wbfriction.fit.regression import HELD_OUT_BLOCKS

BLOCKS = HELD_OUT_BLOCKS
"""Contiguous blocks the fitted samples are cut into (at most)."""
MIN_BLOCKS = 5
"""Fewer blocks than this give no block spread (four degrees of freedom: its own relative error above 35 %)."""


def block_labels(n: int, n_blocks: int) -> np.ndarray:
    """(n,) the block of each of ``n`` samples in time order: ``n_blocks`` contiguous blocks of (nearly) equal counts
    (the cut of :func:`~wbfriction.fit.regression.held_out_split`)."""
    return np.arange(n) * n_blocks // max(n, 1)


def block_count(n: int, lag: int, p: int, blocks: int = BLOCKS) -> int:
    """How many blocks ``n`` samples are cut into: ``blocks``, fewer so that each is at least the residuals'
    correlation ``lag`` [samples] long (:func:`~wbfriction.fit.regression.correlation_lag`: twice the lag where their
    autocorrelation falls below 5 %) and holds more than ``p`` samples; 0 below :data:`MIN_BLOCKS`."""
    longest = max(lag, p + 1, 1)
    k = min(blocks, n // longest)
    return k if k >= MIN_BLOCKS else 0


def jackknife_shifts(jac: np.ndarray, residual: np.ndarray, active: np.ndarray, n_blocks: int,
                     rtol: float = 1e-12, labels: np.ndarray | None = None) -> np.ndarray:
    """The delete-one-block shifts ``theta_(k) - theta`` (K, p) of a least-squares fit (module docstring).

    Args:
        jac: (n, p) the Jacobian of the model's values at the optimum on the fitted samples, in time order
            [the values' unit per the parameter's].
        residual: (n,) model - data at the optimum, the same samples.
        active: (p,) bool, the parameters stepped (interior, free, identifiable); the others' shifts are 0.
        n_blocks: ``K`` contiguous blocks (:func:`block_labels`).
        rtol: eigenvalues of the column-scaled normal matrix below this share of the largest are dropped (its
            numerical null space: 1e-12, a singular value of 1e-6 of the largest).
        labels: (n,) each row's block in ``0 .. K-1``, for rows not in time order (several series' rows of one
            instant: :mod:`wbfriction.actuator.solve`); default :func:`block_labels` of the row order.

    Returns:
        (K, p) in the parameters' units.
    """
    jac, residual = np.asarray(jac, dtype=float), np.asarray(residual, dtype=float)
    n, p = jac.shape
    out = np.zeros((n_blocks, p))
    cols = np.flatnonzero(np.asarray(active, dtype=bool))
    if cols.size == 0 or n_blocks < 2:
        return out
    J = jac[:, cols]
    scale = np.sqrt(np.sum(J**2, axis=0))
    scale[scale == 0] = 1.0
    Js = J / scale  # unit columns: the parameters' units do not set the conditioning
    full = Js.T @ Js
    labels = block_labels(n, n_blocks) if labels is None else np.asarray(labels)
    for k in range(n_blocks):
        rows = labels == k
        Jk, rk = Js[rows], residual[rows]
        A = full - Jk.T @ Jk
        w, V = np.linalg.eigh(A)
        keep = w > rtol * w.max() if w.size and w.max() > 0 else np.zeros_like(w, dtype=bool)
        step = (V[:, keep] / w[keep]) @ (V[:, keep].T @ (Jk.T @ rk))
        out[k, cols] = step / scale
    return out


def jackknife_spread(shifts: np.ndarray) -> np.ndarray:
    """(p,) the delete-one-block jackknife's standard error ``sqrt((K - 1) / K sum_k (s_k - mean s)^2)`` of shifts
    (K, p) (:func:`jackknife_shifts`; Efron 1982, eq. 3.2 with the blocks as the units); zeros for ``K < 2``."""
    shifts = np.asarray(shifts, dtype=float)
    k = shifts.shape[0]
    if k < 2:
        return np.zeros(shifts.shape[1])
    centred = shifts - shifts.mean(axis=0)
    return np.sqrt((k - 1) / k * np.sum(centred**2, axis=0))


def t_scale(n_blocks: int, level: float = 0.975) -> float:
    """``t_{K-1}(level) / z(level)``: the factor that puts a jackknife's standard error of ``K = n_blocks`` blocks
    (``K - 1`` degrees of freedom) on the normal scale (module docstring; 1.154 at ten blocks, 1.42 at five)."""
    from scipy.stats import norm, t

    return float(t.ppf(level, n_blocks - 1) / norm.ppf(level))


def block_spread(jac: np.ndarray, residual: np.ndarray, active: np.ndarray, lag: int,
                 blocks: int = BLOCKS) -> np.ndarray:
    """(p,) each parameter's block-jackknife standard error [its unit] from a fit's Jacobian (n, p) and residual
    (n,) at the optimum on its samples in time order, ``active`` (p,) the parameters stepped, ``lag`` the residuals'
    correlation lag [samples] (:func:`~wbfriction.fit.regression.correlation_lag`): the blocks of
    :func:`block_count`, on the normal scale (:func:`t_scale`); zeros where there are too few (module docstring)."""
    n, p = np.shape(jac)
    k = block_count(n, lag, int(np.sum(active)), blocks)
    if k == 0:
        return np.zeros(p)
    return t_scale(k) * jackknife_spread(jackknife_shifts(jac, residual, active, k))


def statistical_error(stderr: float, block: float = 0.0) -> float:
    """The statistical standard error a user reads: the larger of the Newey-West one (raised to its Cramér-Rao bound,
    ``stderr``) and the block jackknife's (``block``), in the parameter's unit. The larger, not a sum: both estimate
    the same sampling spread, the jackknife's also that of an error which changes slowly over the log."""
    if not math.isfinite(stderr):
        return stderr
    return max(stderr, block if math.isfinite(block) else 0.0)


def linear_block_spread(X: np.ndarray, y: np.ndarray, use: np.ndarray, coef: np.ndarray,
                        free: np.ndarray) -> np.ndarray:
    """(p,) :func:`block_spread` of a linear least-squares fit ``y ~ X coef`` on the samples ``use`` ((N,) bool, in
    time order) of a design ``X`` (N, p) and target ``y`` (N,): the coefficients ``free`` (p,) bool stepped (those held
    at zero: 0); the correlation lag of its residuals (:func:`~wbfriction.fit.regression.correlation_lag`). Exact
    (the model is linear): each block's shift is the refit without it. The terms' refits
    (:func:`~wbfriction.fit.term_design.final_fit`) take it."""
    from wbfriction.fit.regression import correlation_lag

    use = np.asarray(use, dtype=bool)
    rows = np.flatnonzero(use)
    J = np.asarray(X, dtype=float)[use]
    residual = J @ np.asarray(coef, dtype=float) - np.asarray(y, dtype=float)[use]  # model - data
    return block_spread(J, residual, np.asarray(free, dtype=bool), correlation_lag(residual, rows))

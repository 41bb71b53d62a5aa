"""Linear-regression statistics shared by the fits: standard errors robust to residuals correlated in time
(Newey-West), and the blocked held-out split the model and term choices are scored on.

A least-squares fit's parameters have the covariance

.. math:: \\operatorname{cov}(\\hat p) = s^2 (J^T J)^{-1}, \\qquad s^2 = \\frac{\\|r\\|^2}{N - p},

computed through the SVD of the Jacobian ``J`` (N, p) at the solution; with residuals correlated in time (a
filtered estimate, a slowly varying model error) the Newey-West sandwich replaces it (:func:`parameter_covariance`).
A parameter with a component in the numerical null space of ``J`` is not identifiable: its standard error is
``inf``.
"""

from __future__ import annotations

import math

import numpy as np

HELD_OUT_BLOCKS = 10
"""Contiguous blocks (in time) the valid samples are cut into for the model choice."""

HELD_OUT_PERIOD = 3
"""Block ``k`` is held out when ``k % HELD_OUT_PERIOD == 1`` (blocks 1, 4, 7 of 0..9: 30 %)."""


def parameter_covariance(jac: np.ndarray, residual: np.ndarray, rtol: float = 1e-9, rows: np.ndarray | None = None,
                         max_lag: int = 0) -> np.ndarray:
    """Covariance (p, p) of the parameters from the Jacobian at a least-squares solution (module docstring).

    With ``max_lag > 0`` the residuals may be correlated in time (a filtered estimate, or
    model error that varies slowly): the covariance is the Newey-West sandwich
    ``(J^T J)^+ [sum_l w_l G_l] (J^T J)^+`` with Bartlett weights ``w_l = 1 - l / (max_lag + 1)``
    over the products of the gradients ``g_t = J_t r_t`` of samples ``l`` rows apart in the
    time series (``rows``: their indices in it; only truly consecutive pairs count).

    Returns:
        (p, p) covariance; the rows and columns of a parameter with a component in the numerical
        null space of ``J`` (not identifiable) are ``inf``.
    """
    n, p = jac.shape
    U, sv, Vt = np.linalg.svd(jac, full_matrices=False)
    keep = sv > rtol * sv[0] if sv[0] > 0 else np.zeros_like(sv, dtype=bool)
    V = Vt.T
    null = V[:, ~keep]
    unidentifiable = (np.abs(null) > 1e-6).any(axis=1) if null.size else np.zeros(p, dtype=bool)
    half = V[:, keep] / sv[keep]  # (J^T J)^+ = half half^T
    if max_lag <= 0:
        cov = half @ half.T * (float(residual @ residual) / max(n - p, 1))
    else:
        # the sandwich in the SVD's coordinates, J = U S V^T: (J^T J)^+ J^T W J (J^T J)^+ = half (U^T W U) half^T.
        # Formed as bread @ (J^T W J) @ bread, the meat's rounding times two breads of 1/s_min^2 made a covariance
        # with negative eigenvalues of 1e9 where the offset and a ripple's cos q were nearly one column (issue 63)
        rows = np.arange(n) if rows is None else np.asarray(rows)
        g = U[:, keep] * residual[:, None] * np.sqrt(n / max(n - p, 1))
        lagged = lagged_products(g, rows, max_lag)
        cov = half @ (g.T @ g + lagged + lagged.T) @ half.T
    cov[unidentifiable, :] = np.inf
    cov[:, unidentifiable] = np.inf
    return cov


def standard_errors(jac: np.ndarray, residual: np.ndarray, rtol: float = 1e-9, rows: np.ndarray | None = None,
                    max_lag: int = 0) -> np.ndarray:
    """Standard errors (p,) from the Jacobian at a least-squares solution: the square roots of the diagonal of
    :func:`parameter_covariance` (``inf`` for a parameter that is not identifiable)."""
    return covariance_errors(parameter_covariance(jac, residual, rtol, rows, max_lag))


def covariance_errors(cov: np.ndarray) -> np.ndarray:
    """Standard errors (p,): the square roots of a covariance's diagonal (``inf`` stays ``inf``)."""
    return np.sqrt(np.clip(np.diag(cov), 0.0, None))


def lagged_products(g: np.ndarray, rows: np.ndarray, max_lag: int) -> np.ndarray:
    """``sum_{l=1}^{L} w_l sum_t g_{t+l} g_t^T`` over the pairs of samples ``l`` rows apart with no
    row missing between them, Bartlett weights ``w_l = 1 - l / (max_lag + 1)``, ``L = min(max_lag, n - 1)``
    (the lagged terms of the Newey-West sum in :func:`standard_errors`).

    Args:
        g: per-sample gradients (n, p); rows: their rows in the time series (n,), increasing.

    Each run of consecutive rows is cross-correlated with itself through the FFT (all lags at
    once): equal to the sum over pairs to rounding (tests/fit/test_fit.py), in
    ``O(n log n)`` instead of ``O(n L)``.
    """
    n, p = g.shape
    lags_max = min(max_lag, n - 1)
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(rows) != 1) + 1, [n]])
    out = np.zeros((p, p))
    for a, b in zip(cuts[:-1], cuts[1:]):
        lags = min(lags_max, b - a - 1)
        if lags < 1:
            continue
        size = 1 << int(np.ceil(np.log2(b - a + lags)))  # no wrap-around up to the largest lag
        F = np.fft.rfft(g[a:b], size, axis=0)
        products = np.fft.irfft(F[:, :, None] * np.conj(F[:, None, :]), size, axis=0)[1:lags + 1]
        out += np.tensordot(1.0 - np.arange(1, lags + 1) / (max_lag + 1.0), products, axes=1)
    return out


def correlation_lag(residual: np.ndarray, rows: np.ndarray, threshold: float = 0.05, cap: int = 2000) -> int:
    """Largest lag worth summing in :func:`standard_errors`: twice the lag at which the
    residuals' autocorrelation (over samples truly that many rows apart) first falls below
    ``threshold``, and at least Newey and West's rule of thumb ``4 (n / 100)^(2/9)``.

    The first :data:`DIRECT_LAGS` lags are summed pair by pair; the longer ones, where slowly varying residuals
    take the search, through the FFT over each run of consecutive rows (all lags at once,
    :func:`autocorrelation_sums`). A lag whose FFT sum lies within rounding of the threshold is summed pair by
    pair again: the lag is the sum over pairs' (tests/fit/test_regression.py)."""
    n = len(residual)
    rule = int(4 * (n / 100.0) ** (2.0 / 9.0))
    power = float(residual @ residual)
    var = power / max(n, 1)
    if var == 0:
        return rule
    top = min(cap, n - 1)

    def falls(lag: int) -> bool:
        pair = rows[lag:] - rows[:-lag] == lag
        return bool(pair.sum() < 10 or float(residual[lag:][pair] @ residual[:-lag][pair]) / pair.sum()
                    < threshold * var)

    for lag in range(1, min(top, DIRECT_LAGS) + 1):
        if falls(lag):
            return max(rule, 2 * lag)
    if top > DIRECT_LAGS:
        sums, counts = autocorrelation_sums(residual, rows, top)
        rounding = 1e-9 * power  # far above the FFT's error on a sum of products (about 1e-15 of the power)
        for lag in range(DIRECT_LAGS + 1, top + 1):
            gap = sums[lag] - threshold * var * counts[lag]
            if counts[lag] < 10 or (gap < 0 if abs(gap) > rounding else falls(lag)):
                return max(rule, 2 * lag)
    return max(rule, 2 * cap)


DIRECT_LAGS = 32
"""Lags :func:`correlation_lag` sums pair by pair before it turns to the FFT (most residuals decorrelate sooner)."""


def autocorrelation_sums(x: np.ndarray, rows: np.ndarray, max_lag: int) -> tuple[np.ndarray, np.ndarray]:
    """For each lag ``0..max_lag``, the sum of ``x[i] x[j]`` (the FFT's, to rounding) and the number of pairs
    ``i < j`` of the samples ``x`` (n,) at ``rows`` (n,) (increasing) that lag apart in rows and in order (in one
    run of consecutive rows): two (max_lag + 1,) arrays, the counts exact."""
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(rows) != 1) + 1, [len(x)]])
    sums = np.zeros(max_lag + 1)
    for a, b in zip(cuts[:-1], cuts[1:]):
        lags = min(max_lag, b - a - 1)
        size = 1 << int(np.ceil(np.log2(b - a + lags)))  # no wrap-around up to the largest lag
        F = np.fft.rfft(x[a:b], size)
        sums[:lags + 1] += np.fft.irfft(F * np.conj(F), size)[:lags + 1]
    lengths = np.bincount(np.diff(cuts), minlength=max_lag + 2)
    longer = np.cumsum(lengths[::-1])[::-1]  # runs longer than each length - 1
    samples = np.cumsum((lengths * np.arange(lengths.size))[::-1])[::-1]
    lag = np.arange(max_lag + 1)
    counts = samples[lag + 1] - lag * longer[lag + 1]  # sum over runs longer than lag of (length - lag)
    return sums, counts


def held_out_split(use: np.ndarray, n_blocks: int = HELD_OUT_BLOCKS,
                   period: int = HELD_OUT_PERIOD) -> tuple[np.ndarray, np.ndarray]:
    """Training and held-out samples for the model choice (:mod:`~wbfriction.fit`) and the terms'
    (:mod:`~wbfriction.fit.terms`).

    The samples ``use`` (N,) bool, in time order, are cut into ``n_blocks`` contiguous blocks of
    (nearly) equal counts; block ``k`` is held out when ``k % period == 1``.

    Returns:
        (train, held_out): (N,) bool masks, disjoint, whose union is ``use``.
    """
    rows = np.flatnonzero(use)
    block = np.arange(rows.size) * n_blocks // max(rows.size, 1)
    train, held_out = np.zeros(len(use), dtype=bool), np.zeros(len(use), dtype=bool)
    out = block % period == 1
    held_out[rows[out]] = True
    train[rows[~out]] = True
    return train, held_out


def held_out_gain(simpler: np.ndarray, other: np.ndarray, rows: np.ndarray) -> tuple[float, float]:
    """How much ``other``'s held-out residuals (n,) lower the mean square of ``simpler``'s (n,), on the samples
    ``rows`` (n,) of the series, and the standard error of that lowering: the mean of ``d = simpler^2 - other^2``
    and its Newey-West standard error (the residuals are correlated over a filter's window) [N²·m²]."""
    d = np.asarray(simpler, dtype=float) ** 2 - np.asarray(other, dtype=float) ** 2
    n = d.size
    if n < 2:
        return float("nan"), float("inf")
    centred = (d - d.mean())[:, None]
    lag = correlation_lag(centred[:, 0], rows)
    long_run = float(centred[:, 0] @ centred[:, 0] + 2.0 * lagged_products(centred, rows, lag)[0, 0])
    return float(d.mean()), math.sqrt(max(long_run, 0.0)) / n

"""The Newey-West sum of the fit's standard errors through the FFT equals the sum over pairs of samples."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.regression import correlation_lag, lagged_products


def _pairs(g: np.ndarray, rows: np.ndarray, max_lag: int) -> np.ndarray:
    """The definition: for each lag, the products of samples that lag apart in rows and in order."""
    n, p = g.shape
    out = np.zeros((p, p))
    for lag in range(1, min(max_lag, n - 1) + 1):
        for k in range(n - lag):
            if rows[k + lag] - rows[k] == lag:
                out += (1.0 - lag / (max_lag + 1.0)) * np.outer(g[k + lag], g[k])
    return out


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 120), p=st.integers(1, 4), max_lag=st.integers(0, 150), gap_share=st.floats(0.0, 0.4),
       seed=st.integers(0, 2**32 - 1))
def test_lagged_products_equal_the_sum_over_pairs(n, p, max_lag, gap_share, seed):
    rng = np.random.default_rng(seed)
    rows = np.cumsum(1 + (rng.random(n) < gap_share) * rng.integers(1, 4, n))
    g = np.cumsum(rng.normal(size=(n, p)), axis=0) * rng.uniform(0.1, 10.0, p)  # correlated in time
    expected = _pairs(g, rows, max_lag)
    got = lagged_products(g, rows, max_lag)
    scale = float(np.sum(g * g)) + 1e-300
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * scale)


def _lag_by_definition(r: np.ndarray, rows: np.ndarray, threshold: float, cap: int) -> int:
    """Twice the first lag whose autocorrelation over the pairs truly that many rows apart (ten at
    least) falls below the threshold, the cap when none does, and at least Newey and West's rule."""
    n = len(r)
    rule = int(4 * (n / 100.0) ** (2.0 / 9.0))
    var = sum(x * x for x in r) / n
    if var == 0:
        return rule
    where = {int(k): i for i, k in enumerate(rows)}
    for lag in range(1, min(cap, n - 1) + 1):
        pairs = [(i, where[k + lag]) for i, k in enumerate(rows) if k + lag in where and where[k + lag] == i + lag]
        if len(pairs) < 10 or sum(r[i] * r[j] for i, j in pairs) / len(pairs) < threshold * var:
            return max(rule, 2 * lag)
    return max(rule, 2 * cap)


def test_correlation_lag_by_its_definition():
    """A sine of period 200 samples decorrelates near a quarter period; white noise at once; zeros give
    the rule; a gap leaves pairs out; the cap bounds the search."""
    rng = np.random.default_rng(40)
    k = np.arange(3000)
    sine = np.sin(2 * np.pi * k / 200) + 0.05 * rng.normal(size=k.size)
    rows = np.r_[k[:1500], 1600 + k[1500:]]
    cases = [(sine, k, 0.05, 2000), (sine, rows, 0.05, 2000), (sine, k, 0.3, 2000), (sine, k, 0.05, 20),
             (rng.normal(size=k.size), k, 0.05, 2000), (np.zeros(500), np.arange(500), 0.05, 2000),
             (sine[:30], k[:30], 0.05, 2000)]
    for r, rws, threshold, cap in cases:
        assert correlation_lag(r, rws, threshold, cap) == _lag_by_definition(r, rws, threshold, cap)
    assert 90 <= correlation_lag(sine, k) <= 102  # about twice a quarter period


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 400), gap_share=st.floats(0.0, 0.5), kind=st.sampled_from(["white", "walk", "sine", "ties"]),
       threshold=st.sampled_from([0.05, 0.3, 0.0, 1.0]), cap=st.integers(1, 300), seed=st.integers(0, 2**32 - 1))
def test_correlation_lag_by_its_definition_with_gaps(n, gap_share, kind, threshold, cap, seed):
    """The FFT's sums and the exact check of the lags near the threshold give the definition's lag, runs of
    rows cut by gaps of 1-4 rows included."""
    rng = np.random.default_rng(seed)
    rows = np.cumsum(1 + (rng.random(n) < gap_share) * rng.integers(1, 5, n))
    r = {"white": rng.normal(size=n), "walk": np.cumsum(rng.normal(size=n)),
         "sine": np.sin(np.arange(n) / rng.uniform(1, 50)) + 0.1 * rng.normal(size=n),
         "ties": np.round(rng.normal(size=n))}[kind]
    assert correlation_lag(r, rows, threshold, cap) == _lag_by_definition(r, rows, threshold, cap)

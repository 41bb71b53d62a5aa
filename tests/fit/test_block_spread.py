"""The block spread (:mod:`wbfriction.fit.block_spread`): a delete-one-block jackknife over the log's time blocks,
linearised at the optimum, on cases whose answer is known.

* exact for a linear model: each block's shift is the refit without it;
* stationary white noise: the jackknife's variance is that of least squares, ``s^2 (J^T J)^-1`` (the exact one for
  a fixed design), on average over many logs, within what ``K - 1 = 9`` degrees of freedom allow;
* a viscous coefficient that wanders slowly over the log (a stationary Ornstein-Uhlenbeck process about its value,
  correlated over 100 samples, far beyond the 5 % the Newey-West lag is cut at): ±2 of the read error's statistical
  part cover the truth at least as often as the Newey-West error alone, and near the nominal share;
* equivariance (hypothesis): a parameter's unit scales its spread, the blocks' order does not matter to it.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import lfilter

from wbfriction.fit.block_spread import (
    BLOCKS,
    MIN_BLOCKS,
    block_count,
    block_labels,
    block_spread,
    jackknife_shifts,
    jackknife_spread,
    linear_block_spread,
    statistical_error,
    t_scale,
)
from wbfriction.fit.regression import correlation_lag, covariance_errors, parameter_covariance
from wbfriction.fit.selection import fit_friction

N = 4000
T = np.arange(N) * 5e-3
QD = 1.5 * np.sin(2 * np.pi * 0.7 * T) + 0.5 * np.sin(2 * np.pi * 1.9 * T)
"""20 s of a joint swinging both ways at up to 2 rad/s [rad/s]."""
J = np.column_stack([QD, np.sign(QD), np.ones(N)])
"""The Coulomb-viscous design (F_v, F_c, tau_os): linear in its parameters."""
ROWS = np.arange(N)
TRUE = np.array([0.2, 1.0, 0.1])


def _fit(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    theta = np.linalg.lstsq(J, y, rcond=None)[0]
    return theta, J @ theta - y


def test_the_linearised_shift_is_the_refit_without_the_block():
    rng = np.random.default_rng(0)
    y = J @ TRUE + 0.05 * rng.normal(size=N)
    theta, r = _fit(y)
    shifts = jackknife_shifts(J, r, np.ones(3, dtype=bool), BLOCKS)
    labels = block_labels(N, BLOCKS)
    refits = np.array([np.linalg.lstsq(J[labels != k], y[labels != k], rcond=None)[0] - theta for k in range(BLOCKS)])
    np.testing.assert_allclose(shifts, refits, rtol=1e-8, atol=1e-14)
    # a parameter not stepped keeps its value: shift 0
    assert np.all(jackknife_shifts(J, r, np.array([True, True, False]), BLOCKS)[:, 2] == 0.0)


def test_the_blocks_are_contiguous_and_nearly_equal():
    labels = block_labels(1003, 10)
    assert np.all(np.diff(labels) >= 0) and set(labels) == set(range(10))
    counts = np.bincount(labels)
    assert counts.max() - counts.min() <= 1


def test_the_count_keeps_blocks_longer_than_the_correlation_lag():
    assert block_count(4000, 10, 3) == BLOCKS
    assert block_count(4000, 600, 3) == 6  # 4000 // 600
    assert block_count(4000, 1000, 3) == 0  # 4 blocks: fewer than MIN_BLOCKS
    assert block_count(30, 1, 6) == 0 and MIN_BLOCKS == 5
    assert np.all(block_spread(J[:100], np.ones(100), np.ones(3, dtype=bool), lag=40) == 0.0)


def test_on_white_noise_the_jackknife_is_the_least_squares_error():
    """Over 400 logs of white noise (sigma 0.05 N·m) on a fixed design, the jackknife's variance (its standard error
    before the t scale) averages to the exact ``sigma^2 (J^T J)^-1``: each log's estimate is a chi-square of about 9
    degrees of freedom over 9 (relative standard deviation 0.47), their mean's 0.024; 0.1 is four of those."""
    sigma = 0.05
    exact = sigma * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    rng = np.random.default_rng(1)
    variances = []
    for _ in range(400):
        _, r = _fit(J @ TRUE + sigma * rng.normal(size=N))
        variances.append((block_spread(J, r, np.ones(3, dtype=bool), correlation_lag(r, ROWS)) / t_scale(BLOCKS)) ** 2)
    ratio = np.mean(variances, axis=0) / exact**2
    np.testing.assert_allclose(ratio, 1.0, atol=0.1)


def _wandering(seed: int, share: float, tau: float) -> np.ndarray:
    """The torque of F_v wandering about 0.2 by ``share`` (a stationary Ornstein-Uhlenbeck process of correlation
    time ``tau`` samples) with F_c 1, tau_os 0.1 and white noise 0.05 N·m; the truth is TRUE (the process's mean)."""
    rng = np.random.default_rng(seed)
    phi = np.exp(-1.0 / tau)
    burn = int(10 * tau)
    g = lfilter([np.sqrt(1.0 - phi**2)], [1.0, -phi], rng.normal(size=N + burn))[burn:]
    return (TRUE[0] * (1.0 + share * g)) * QD + TRUE[1] * np.sign(QD) + TRUE[2] + 0.05 * rng.normal(size=N)


def test_a_slowly_wandering_friction_is_covered():
    """F_v wandering by 20 % over 100-sample spells (the log 4000): the Newey-West error, its lag cut where the
    residuals' correlation falls below 5 %, covers F_v's truth on fewer of 300 logs than ±2 statistical errors with
    the block jackknife (the larger of the two), which cover it on 85 % or more (a t of 9 degrees of freedom: 92 %
    nominal; a binomial of 300 at 0.92 falls below 0.87 with probability 0.002)."""
    covered_hac = covered = 0
    for seed in range(300):
        theta, r = _fit(_wandering(seed, 0.2, 100.0))
        lag = correlation_lag(r, ROWS)
        hac = covariance_errors(parameter_covariance(J, r, rows=ROWS, max_lag=lag))[0]
        block = block_spread(J, r, np.ones(3, dtype=bool), lag)[0]
        error = abs(theta[0] - TRUE[0])
        covered_hac += error <= 2.0 * hac
        covered += error <= 2.0 * statistical_error(hac, block)
    assert covered > covered_hac
    assert covered / 300 >= 0.85


def test_the_fit_carries_the_block_spread_of_its_interior_parameters():
    """``fit_friction`` on a Coulomb-viscous log: a block spread per interior parameter, within a factor the nine
    degrees of freedom allow (beyond the chi-square's 0.1 % tails, sqrt(2.1 / 9) and sqrt(27.9 / 9), 0.48-1.76, times
    the t scale 1.154: 0.4-2.1) of the Newey-West error on white noise."""
    rng = np.random.default_rng(3)
    tau_f = -(J @ TRUE) + 0.05 * rng.normal(size=N)
    fit = fit_friction(QD, tau_f, model="coulomb-viscous")
    assert set(fit.block_spread) == {"F_v", "F_c", "tau_os"}
    for name, value in fit.block_spread.items():
        assert 0.4 * fit.stderr[name] <= value <= 2.1 * fit.stderr[name], name


def test_the_linear_form_is_the_refit_without_each_block():
    rng = np.random.default_rng(4)
    y = J @ TRUE + 0.05 * rng.normal(size=N)
    use = np.ones(N, dtype=bool)
    use[::7] = False  # rows missing: the blocks are of the samples used, in time order
    coef = np.linalg.lstsq(J[use], y[use], rcond=None)[0]
    spread = linear_block_spread(J, y, use, coef, np.ones(3, dtype=bool))
    labels = block_labels(int(use.sum()), BLOCKS)
    Ju, yu = J[use], y[use]
    refits = np.array([np.linalg.lstsq(Ju[labels != k], yu[labels != k], rcond=None)[0] for k in range(BLOCKS)])
    np.testing.assert_allclose(spread, t_scale(BLOCKS) * jackknife_spread(refits - coef), rtol=1e-8)


def test_the_scale_is_students_over_the_normal():
    """t_9(0.975) = 2.262, z(0.975) = 1.960 (the tables)."""
    assert t_scale(10) == pytest.approx(2.262 / 1.960, abs=1e-3)
    assert t_scale(1000) == pytest.approx(1.0, abs=2e-3)


@settings(max_examples=30, deadline=None)
@given(scale=st.floats(1e-3, 1e3), seed=st.integers(0, 2**16))
def test_a_parameters_unit_scales_its_spread(scale, seed):
    """Measuring F_v in another unit (its column divided by ``scale``, its value times it) multiplies its spread by
    ``scale`` and leaves the others'."""
    rng = np.random.default_rng(seed)
    r = 0.05 * rng.normal(size=N)
    r -= J @ np.linalg.lstsq(J, r, rcond=None)[0]  # a residual at an optimum: J^T r = 0
    active = np.ones(3, dtype=bool)
    base = block_spread(J, r, active, 5)
    scaled = block_spread(J / np.array([scale, 1.0, 1.0]), r, active, 5)
    np.testing.assert_allclose(scaled, base * np.array([scale, 1.0, 1.0]), rtol=1e-6)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**16), k=st.integers(2, 20))
def test_the_spread_does_not_depend_on_the_blocks_order(seed, k):
    shifts = np.random.default_rng(seed).normal(size=(k, 3))
    np.testing.assert_allclose(jackknife_spread(shifts[::-1]), jackknife_spread(shifts), rtol=1e-12)
    np.testing.assert_allclose(jackknife_spread(shifts + 5.0), jackknife_spread(shifts), rtol=1e-9)


def test_the_statistical_error_is_the_larger_never_a_sum():
    assert statistical_error(0.1, 0.3) == 0.3 and statistical_error(0.3, 0.1) == 0.3
    assert statistical_error(np.inf, 0.1) == np.inf
    assert statistical_error(0.1, np.nan) == 0.1


def test_stationary_noise_gives_no_spread_above_what_its_blocks_show():
    """On white noise alone the block spread is about the Newey-West error times the t scale (1.154): its mean over 50
    logs below 1.3 of the Newey-West's (a jackknife's standard error averages slightly below sigma, and 50 of them
    have a relative error of 0.024 each way: the read error does not inflate honest errors beyond the t interval)."""
    rng = np.random.default_rng(5)
    ratios = []
    for _ in range(50):
        _, r = _fit(J @ TRUE + 0.05 * rng.normal(size=N))
        lag = correlation_lag(r, ROWS)
        hac = covariance_errors(parameter_covariance(J, r, rows=ROWS, max_lag=lag))
        ratios.append(block_spread(J, r, np.ones(3, dtype=bool), lag) / hac)
    assert np.all(np.mean(ratios, axis=0) < 1.3)

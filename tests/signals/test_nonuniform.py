"""Derivatives and filters on non-uniform sample times: exact on polynomials, the uniform schemes
when the times are uniform, and the motion's derivatives on jittered instants."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.signals.filters import ZeroPhaseLowpass, savgol_differentiate
from wbfriction.signals.kinematics import central_differences
from wbfriction.signals.nonuniform import (
    NonUniformSavgol,
    ResampledLowpass,
    backward_differences,
    three_point_differences,
)
from wbfriction.signals.nonuniform import savgol_differentiate as savgol_on_times


def _stamps(steps: list[float], dt: float = 1e-3) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.asarray(steps) * dt)])


steps_strategy = st.lists(st.floats(0.2, 5.0), min_size=30, max_size=60)


@settings(max_examples=60, deadline=None)
@given(steps=steps_strategy, c=st.tuples(*[st.floats(-5, 5)] * 3))
def test_three_point_differences_are_exact_on_quadratics(steps, c):
    t = _stamps(steps)
    q = (c[0] + c[1] * t + c[2] * t**2)[:, None]
    qd, qdd, delay = three_point_differences(q, t)
    assert delay == 0 and np.isnan(qd[[0, -1]]).all() and np.isnan(qdd[[0, -1]]).all()
    np.testing.assert_allclose(qd[1:-1, 0], c[1] + 2 * c[2] * t[1:-1], atol=1e-7)
    np.testing.assert_allclose(qdd[1:-1, 0], 2 * c[2], atol=1e-4)


@settings(max_examples=60, deadline=None)
@given(steps=steps_strategy, order=st.integers(2, 4), half=st.integers(3, 8),
       weights=st.sampled_from(["uniform", "gaussian"]), seed=st.integers(0, 2**16))
def test_savgol_on_actual_times_is_exact_on_polynomials_of_its_order(steps, order, half, weights, seed):
    """A polynomial of the filter's order is its own local fit, whatever the sample times:
    value and first two derivatives are exact."""
    t = _stamps(steps)
    c = np.random.default_rng(seed).uniform(-1, 1, order + 1)
    tc = t - t.mean()  # centred, so that the coefficients are of comparable weight
    scale = np.ptp(t)
    x = np.polynomial.polynomial.polyval(tc / scale, c)
    xd = np.polynomial.polynomial.polyval(tc / scale, np.polynomial.polynomial.polyder(c)) / scale
    xdd = np.polynomial.polynomial.polyval(tc / scale, np.polynomial.polynomial.polyder(c, 2)) / scale**2
    xs, d1, d2 = savgol_on_times(x, t, 2 * half + 1, order, weights)
    inner = slice(half, len(t) - half)
    assert np.isnan(xs[:half]).all() and np.isnan(d2[len(t) - half:]).all()
    np.testing.assert_allclose(xs[inner], x[inner], atol=1e-9 * np.abs(x).max() + 1e-12)
    np.testing.assert_allclose(d1[inner], xd[inner], atol=1e-7 * np.abs(xd).max() + 1e-9)
    np.testing.assert_allclose(d2[inner], xdd[inner], atol=1e-5 * np.abs(xdd).max() + 1e-7)


@pytest.mark.parametrize("weights", ["uniform", "gaussian"])
def test_savgol_on_uniform_times_is_the_uniform_filter(weights):
    """Two routes: the local fits on actual (here uniform) times and the thesis's fixed kernels."""
    dt = 2e-3
    t = np.arange(400) * dt
    x = np.random.default_rng(0).normal(size=(400, 3))
    uniform = savgol_differentiate(x, dt, 31, 4, weights)
    on_times = savgol_on_times(x, t, 31, 4, weights)
    for a, b in zip(uniform, on_times):
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
        np.testing.assert_allclose(b, a, rtol=1e-8, atol=1e-8 * np.nanmax(np.abs(a)))


def test_savgol_smoother_is_the_value_of_the_fit_and_skips_non_finite_windows():
    t = _stamps(np.random.default_rng(1).uniform(0.5, 1.5, 299))
    x = np.sin(20 * t)
    smoother = NonUniformSavgol(t, 21, 3, "gaussian")
    np.testing.assert_array_equal(smoother(x), smoother.differentiate(x)[0])
    x[150] = np.nan
    y = smoother(x)
    assert np.isnan(y[140:161]).all() and np.isfinite(y[[139, 161]]).all()


def test_backward_differences_delayed_are_the_three_point_second_difference():
    t = _stamps(np.random.default_rng(2).uniform(0.5, 2.0, 99))
    q = np.sin(7 * t)[:, None]
    _, qdd_b, delay = backward_differences(q, t)
    _, qdd_c, _ = three_point_differences(q, t)
    assert delay == 1
    np.testing.assert_allclose(qdd_b[2:], qdd_c[1:-1], rtol=1e-12)


def test_three_point_differences_on_uniform_times_are_central_differences():
    dt = 1e-3
    q = np.random.default_rng(3).normal(size=(50, 2))
    a, b = three_point_differences(q, np.arange(50) * dt), central_differences(q, dt)
    np.testing.assert_allclose(a[0][1:-1], b[0][1:-1], rtol=1e-9)
    np.testing.assert_allclose(a[1][1:-1], b[1][1:-1], rtol=1e-6, atol=1e-6 * np.abs(b[1][1:-1]).max())


def test_resampled_lowpass_on_uniform_times_is_the_lowpass():
    """On uniform samples the grid is the samples: the spline round trip changes nothing."""
    dt = 1e-3
    t = np.arange(3000) * dt
    x = np.random.default_rng(4).normal(size=(3000, 2))
    lowpass = ZeroPhaseLowpass(20.0, 4, dt)
    a, b = lowpass(x), ResampledLowpass(t, lowpass)(x)
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    np.testing.assert_allclose(b, a, atol=1e-9)


def test_resampled_lowpass_passes_and_differentiates_a_slow_motion_on_jittered_instants():
    """Samples at instants 0.5-1.5 ms apart (stamped exactly): a 2 Hz motion, far below the 20 Hz
    cutoff, comes back with its derivatives, as from uniform samples of it."""
    t = _stamps(np.random.default_rng(5).uniform(0.5, 1.5, 3999))
    w = 2 * math.pi * 2.0
    q = np.sin(w * t)
    f = ResampledLowpass(t, ZeroPhaseLowpass(20.0, 6, 1e-3))
    qs, qd, qdd = f.differentiate(q)
    ok = np.isfinite(qdd)
    assert ok.sum() > 0.8 * len(t)
    rms = lambda x: float(np.sqrt(np.mean(x**2)))  # noqa: E731
    assert rms(qs[ok] - q[ok]) < 1e-3 * rms(q[ok])
    assert rms(qd[ok] - w * np.cos(w * t[ok])) < 1e-3 * w * rms(q[ok])
    assert rms(qdd[ok] + w**2 * q[ok]) < 1e-2 * w**2 * rms(q[ok])

"""The momentum route's window (issue 38) against its definition."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.signals.window import MomentumWindow, hann_steps


def explicit(impulses: np.ndarray, dt: np.ndarray, m: int) -> np.ndarray:
    """The definition, sample by sample."""
    w = hann_steps(m)
    n = len(impulses) + 1
    out = np.full(n, np.nan)
    for k in range(m, n - m):
        steps = slice(k - m, k + m)
        out[k] = w @ impulses[steps] / (w @ dt[steps])
    return out


@settings(max_examples=40, deadline=None)
@given(m=st.integers(1, 12), n=st.integers(2, 80), seed=st.integers(0, 2**16), uniform=st.booleans())
def test_the_window_is_its_definition(m, n, seed, uniform):
    rng = np.random.default_rng(seed)
    t = np.cumsum(np.r_[0.0, np.full(n - 1, 1e-3) if uniform else rng.uniform(0.5e-3, 3e-3, n - 1)])
    window = MomentumWindow(m, 1e-3, None if uniform else t)
    impulses = rng.standard_normal(n - 1) * 1e-3
    np.testing.assert_allclose(window.over_steps(impulses), explicit(impulses, np.diff(t), m), rtol=1e-10,
                               atol=1e-14)


def test_weights_vanish_at_both_ends_and_their_first_difference_too():
    """Hann over the steps: the momenta enter through the weights' differences (summation by parts), which are
    small and vanish at the window's ends."""
    for m in (1, 5, 50):
        w = hann_steps(m)
        assert len(w) == 2 * m and np.allclose(w, w[::-1])
        assert w[0] == pytest.approx(math.sin(math.pi / (4 * m)) ** 2)
        p = np.random.default_rng(m).standard_normal(2 * m + 1)
        # sum_j w_j (p_{j+1} - p_j) = -sum_j (w_j - w_{j-1}) p_j with w_{-1} = w_{2m} = 0
        lhs = w @ np.diff(p)
        rhs = -(np.r_[w, 0.0] - np.r_[0.0, w]) @ p
        assert lhs == pytest.approx(rhs, abs=1e-12)


def test_a_signal_linear_in_time_passes_unchanged_and_the_kernel_sums_to_one():
    t = np.arange(200) * 1e-3
    for m in (1, 7, 40):
        window = MomentumWindow(m, 1e-3)
        x = 3.0 - 2.0 * t
        out = window(x)
        np.testing.assert_allclose(out[m:-m], x[m:-m], atol=1e-12)
        assert np.isnan(out[:m]).all() and np.isnan(out[-m:]).all()
        c = window.kernel()
        assert len(c) == 2 * m + 1 and c.sum() == pytest.approx(1.0) and np.allclose(c, c[::-1])
        np.testing.assert_allclose(window(np.sin(40 * t))[m:-m], np.convolve(np.sin(40 * t), c, "valid"), atol=1e-12)


def test_a_nan_blanks_only_the_windows_that_hold_it():
    window = MomentumWindow(3, 1e-3)
    x = np.ones(30)
    x[15] = np.nan
    out = window(x)
    # the steps 14 and 15 touch sample 15; windows of samples 12 .. 18 hold one of them
    assert np.isnan(out[12:19]).all() and np.isfinite(out[3:12]).all() and np.isfinite(out[19:27]).all()


def test_the_cutoff_is_where_the_gain_is_half_power_and_shrinks_with_the_window():
    cutoffs = []
    for m in (5, 25, 50):
        window = MomentumWindow(m, 1e-3)
        assert float(window.gain(window.cutoff)) == pytest.approx(1 / math.sqrt(2), abs=1e-9)
        assert float(window.gain(0.0)) == pytest.approx(1.0)
        cutoffs.append(window.cutoff)
    assert cutoffs[0] > cutoffs[1] > cutoffs[2]
    # a Hann window of 2m steps: its -3 dB frequency is about 0.72 / (2 m dt)
    assert cutoffs[2] == pytest.approx(0.72 / 0.1, rel=0.05)


def test_a_window_that_cannot_be_is_refused():
    with pytest.raises(InputError, match="at least 3 samples"):
        MomentumWindow(0, 1e-3)
    with pytest.raises(InputError, match="period"):
        MomentumWindow(2, 0.0)
    with pytest.raises(InputError, match="clock of 5 samples for 6 rows"):
        MomentumWindow(2, 1e-3, np.arange(5) * 1e-3)(np.ones(6))
    assert np.isnan(MomentumWindow(5, 1e-3)(np.ones(8))).all()  # shorter than the window


def test_the_cutoff_of_a_long_window_takes_little_memory_and_time():
    """Issue 53: the -3 dB frequency of a 100 001-sample window (its gain once took a 64m x 2m grid: 2.3 TiB)
    is found in a moment, where theory puts it (about 0.72 / (2 m dt) for the Hann window over 2m steps)."""
    import time
    window = MomentumWindow(50_000, 1e-3)
    start = time.perf_counter()
    assert window.cutoff == pytest.approx(0.72 / (2 * 50_000 * 1e-3), rel=0.05)
    assert float(window.gain(window.cutoff)) == pytest.approx(1 / math.sqrt(2), abs=1e-9)
    assert time.perf_counter() - start < 5.0

"""A smoother seen from the rows a fit uses (issue 41): the output on the rows from the input on their support
alone is the whole series' output, and nothing outside the support reaches the rows."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.smoothing import row_smoothing, smoother_reach
from wbfriction.signals.filters import SavgolSmoother, ZeroPhaseLowpass
from wbfriction.signals.kinematics import PiecewiseSmoother
from wbfriction.signals.nonuniform import NonUniformSavgol, ResampledLowpass
from wbfriction.signals.window import MomentumWindow

N, DT = 600, 1e-3
T = np.cumsum(np.r_[0.0, DT * (1.0 + 0.2 * np.sin(np.arange(N - 1)))])  # a jittered clock

SMOOTHERS = {
    "savgol": SavgolSmoother(11, 3, DT),
    "lowpass": ZeroPhaseLowpass(40.0, 4, DT),
    "momentum": MomentumWindow(3, DT),
    "momentum, jittered": MomentumWindow(2, DT, T),
    "savgol, jittered": NonUniformSavgol(T, 9, 2),
    "piecewise": PiecewiseSmoother(((0, 300, SavgolSmoother(7, 2, DT)), (300, N, MomentumWindow(4, DT)))),
    "resampled": ResampledLowpass(T, ZeroPhaseLowpass(40.0, 4, DT)),
}


def _signal(seed: int) -> np.ndarray:
    """A smooth signal with noise and a gap the smoothers leave out (NaN)."""
    rng = np.random.default_rng(seed)
    x = np.sin(np.linspace(0.0, 9.0, N)) + 0.1 * rng.normal(size=N)
    x[250:258] = np.nan
    return x


def _rows(smoother, x: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """The rows a fit would use: finite after the smoother, and kept."""
    return np.flatnonzero(np.isfinite(smoother(x)) & keep)


@pytest.mark.parametrize("name", list(SMOOTHERS))
@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**16), stride=st.integers(2, 40), at=st.integers(0, N - 1))
def test_the_rows_see_their_support_alone(name, seed, stride, at):
    """Rows kept in bursts (single-support stretches): the smoothed signal on them from its support equals the
    whole series' smoothing, to the FFT's rounding; and a spike anywhere outside the support leaves them unchanged."""
    smoother = SMOOTHERS[name]
    x = _signal(seed)
    rows = _rows(smoother, x, (np.arange(N) // stride) % 3 == 0)
    if rows.size == 0:
        return
    smoothing = row_smoothing(smoother, N, rows)
    whole = smoother(x)[rows]
    np.testing.assert_allclose(smoothing(x[smoothing.support]), whole, rtol=0, atol=1e-13)
    if not smoothing.support[at] and np.isfinite(x[at]):
        spiked = x.copy()
        spiked[at] += 1e3
        np.testing.assert_allclose(smoother(spiked)[rows], whole, rtol=0, atol=1e-9)


def test_a_local_smoother_reaches_its_half_width_and_a_spline_everything():
    assert smoother_reach(SMOOTHERS["savgol"]) == 5 and smoother_reach(SMOOTHERS["momentum"]) == 3
    assert smoother_reach(SMOOTHERS["piecewise"]) == 4
    assert smoother_reach(SMOOTHERS["resampled"]) is None and smoother_reach(SMOOTHERS["lowpass"]) is None
    assert smoother_reach(PiecewiseSmoother(((0, 10, SMOOTHERS["resampled"]), (10, 20, None)))) is None
    rows = np.array([100, 101, 400])
    support = row_smoothing(SMOOTHERS["savgol"], N, rows).support
    np.testing.assert_array_equal(np.flatnonzero(support), np.r_[95:107, 395:406])
    assert row_smoothing(SMOOTHERS["resampled"], N, rows).support.all()

"""The weighted Savitzky-Golay route (thesis 7.4-7.8) against weighted polynomial fits computed in the test.

``test_filters.py`` checks the formulas with all-ones weights against ``scipy.signal.savgol_coeffs``, and
polynomials with a loose tolerance; here the weights are not uniform
(``"gaussian"``: a bell of standard deviation N / 2 samples, or an explicit symmetric array), the value and
derivatives at each window's centre are those of ``numpy.polynomial.Polynomial.fit`` with those weights,
and polynomials of degree up to k come back to rounding error.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.signals.filters import SavgolSmoother, savgol_differentiate, savgol_kernels

DT = 2e-3


def _weights(kind: str, half: int, rng: np.random.Generator) -> tuple[str | np.ndarray, np.ndarray]:
    """The filter's argument and the weights of the squared residuals it stands for (2 half + 1,)."""
    m = np.arange(-half, half + 1)
    if kind == "gaussian":
        return "gaussian", np.exp(-0.5 * (m / (half / 2.0)) ** 2)
    w = rng.uniform(0.05, 3.0, half + 1)
    w = np.r_[w[:0:-1], w]  # symmetric about the centre: zero phase
    return w, w


def weighted_fit_at_centre(y: np.ndarray, order: int, w: np.ndarray) -> np.ndarray:
    """Value, first and second derivative [per s, per s^2] at the centre of the polynomial of degree
    ``order`` minimising sum_m w_m (y_m - p(m DT))^2 (numpy scales the residuals by its ``w``: sqrt)."""
    half = len(y) // 2
    p = np.polynomial.Polynomial.fit(np.arange(-half, half + 1) * DT, y, order, w=np.sqrt(w))
    return np.array([p(0.0), p.deriv(1)(0.0), p.deriv(2)(0.0)])


@given(half=st.integers(2, 40), order=st.integers(2, 6), kind=st.sampled_from(["gaussian", "array"]),
       seed=st.integers(0, 2**32 - 1))
@settings(max_examples=40, deadline=None)
def test_weighted_savgol_is_the_weighted_local_fit(half, order, kind, seed):
    window = 2 * half + 1
    if order >= window:
        return
    rng = np.random.default_rng(seed)
    arg, w = _weights(kind, half, rng)
    x = rng.standard_normal((200, 2))
    out = savgol_differentiate(x, DT, window, order, arg)
    rows = rng.choice(np.arange(half, len(x) - half), 12, replace=False)
    for col in range(2):
        ref = np.array([weighted_fit_at_centre(x[r - half:r + half + 1, col], order, w) for r in rows])  # (12, 3)
        for d in range(3):
            scale = np.abs(ref[:, d]).max()
            np.testing.assert_allclose(out[d][rows, col], ref[:, d], rtol=0, atol=1e-10 * scale,
                                       err_msg=f"derivative {d}")
    if kind == "gaussian":  # the smoother (named weights only) is the value of the same fit
        np.testing.assert_allclose(SavgolSmoother(window, order, DT, "gaussian")(x), out[0], rtol=0,
                                   atol=1e-12 * np.nanmax(np.abs(out[0])), equal_nan=True)
    # no full window at the edges, no value
    assert np.all(np.isnan(out[2][:half])) and np.all(np.isnan(out[2][len(x) - half:]))
    assert np.all(np.isfinite(out[2][half:len(x) - half]))


@given(half=st.integers(2, 40), order=st.integers(2, 6), degree=st.integers(0, 6),
       kind=st.sampled_from(["gaussian", "array"]), seed=st.integers(0, 2**32 - 1))
@settings(max_examples=60, deadline=None)
def test_weighted_savgol_reproduces_polynomials_up_to_its_order(half, order, degree, kind, seed):
    """A polynomial of degree <= k is its own weighted fit: value and derivatives to rounding error (the
    bound: 1e-12 of the kernel's absolute sum times the signal's largest value)."""
    window = 2 * half + 1
    if order >= window or degree > order:
        return
    rng = np.random.default_rng(seed)
    arg, _ = _weights(kind, half, rng)
    t = np.arange(300) * DT - 0.3
    p = np.polynomial.Polynomial(rng.uniform(-2.0, 2.0, degree + 1) / 0.3 ** np.arange(degree + 1))
    x = p(t)
    out = savgol_differentiate(x, DT, window, order, arg)
    h = savgol_kernels(window, order, DT, arg)
    inner = slice(half, len(t) - half)
    for d in range(3):
        want = p.deriv(d)(t) if d <= degree else np.zeros_like(t)
        bound = 1e-12 * np.abs(h[d]).sum() * np.abs(x).max()
        np.testing.assert_allclose(out[d][inner], want[inner], rtol=0, atol=bound, err_msg=f"derivative {d}")
        if d <= degree and np.abs(want).max() > 0:
            assert bound < 1e-5 * np.abs(want[inner]).max()  # tight: not a tolerance that hides a wrong kernel


def test_gaussian_weights_change_the_filter():
    """The bell is not the uniform fit in disguise: the kernels differ, and both reproduce a quartic."""
    g = savgol_kernels(31, 4, DT, "gaussian")
    u = savgol_kernels(31, 4, DT, "uniform")
    assert np.abs(g - u).max(axis=1).min() > 1e-2 * np.abs(u).max(axis=1).min()
    m = np.arange(-15, 16)
    for h in (g, u):
        np.testing.assert_allclose([h[0] @ (m * DT) ** j for j in range(5)], [1, 0, 0, 0, 0], atol=1e-9)

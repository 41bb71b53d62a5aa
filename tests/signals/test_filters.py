"""Zero-phase filters (thesis 7.1): exact on polynomials, zero delay, noise as designed."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import freqz, savgol_coeffs, sosfreqz

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.signals.filters import (
    SavgolSmoother,
    ZeroPhaseLowpass,
    fir,
    savgol_differentiate,
    savgol_kernels,
    savgol_weights,
)
from wbfriction.signals.kinematics import central_differences, measure, straddling
from wbfriction.signals.options import FilterOptions
from wbfriction.signals.spectrum import amplitude_spectrum, suggest_cutoff

DT = 1e-3


def _phase_and_gain(y: np.ndarray, t: np.ndarray, f: float) -> tuple[float, float]:
    """Phase [rad] and amplitude of ``y`` against sin(2 pi f t), by least squares."""
    A = np.column_stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)])
    (a, b), *_ = np.linalg.lstsq(A, y, rcond=None)
    return float(np.arctan2(b, a)), float(np.hypot(a, b))


@given(half=st.integers(2, 40), order=st.integers(2, 6), weights=st.sampled_from(["uniform", "gaussian"]),
       coefs=st.lists(st.floats(-2, 2), min_size=7, max_size=7))
@settings(max_examples=40, deadline=None)
def test_savgol_is_exact_on_polynomials_of_its_order(half, order, weights, coefs):
    window = 2 * half + 1
    if order >= window:
        return
    t = np.arange(300) * DT - 0.15
    c = np.array(coefs[:order + 1])
    p = np.polynomial.Polynomial(c)
    x_s, xd, xdd = savgol_differentiate(p(t), DT, window, order, weights)
    inner = slice(half, len(t) - half)
    scale = 1 + np.abs(c).sum() * 1e3  # derivatives of t^k grow with 1/dt
    assert np.allclose(x_s[inner], p(t)[inner], atol=1e-9 * scale)
    assert np.allclose(xd[inner], p.deriv(1)(t)[inner], atol=1e-7 * scale)
    assert np.allclose(xdd[inner], p.deriv(2)(t)[inner], atol=1e-4 * scale)
    # edges: no full window, no value (never extrapolated)
    assert np.all(np.isnan(x_s[:half])) and np.all(np.isnan(xdd[-half:]))


@pytest.mark.parametrize("window,order", [(5, 2), (21, 4), (151, 4), (31, 6)])
def test_weighted_route_equals_scipy_for_uniform_weights(window, order):
    """(7.5)-(7.6) written out, with W = I, against scipy.signal.savgol_coeffs. SciPy fits on raw sample indices,
    whose Vandermonde matrix at L = 151, k = 4 has a condition number of 2e7 (ours: the abscissa scaled to
    [-1, 1]): SciPy 1.17 with NumPy 2.4 is 2e-9 of the largest coefficient off there, hence 1e-8."""
    ones = np.ones(window)  # an explicit array takes the weighted route
    for d in range(3):
        ours = savgol_kernels(window, order, DT, ones)[d]
        ref = savgol_coeffs(window, order, deriv=d, delta=DT, use="dot")
        assert np.allclose(ours, ref, rtol=1e-9, atol=1e-8 * np.abs(ref).max())


@pytest.mark.parametrize("window,order", [(2501, 4), (20001, 4), (501, 6)])
def test_long_windows_reproduce_polynomials(window, order):
    """A Savitzky-Golay fit of order k returns any polynomial of degree <= k, its slope and curvature
    exactly. scipy's ``savgol_coeffs`` on raw indices lost the constant term from about 2 500 samples
    at order 4 and 500 at order 6 (a smoother of gain 0 at 0 Hz: issue 37, the brentq ValueError of
    ``--diff auto`` on a log stamped 1 us apart, and silently wrong smoothing with ``--window``)."""
    for dt in (1e-3, 1e-6):
        h = savgol_kernels(window, order, dt)
        t = (np.arange(window) - window // 2) * dt
        coef = np.random.default_rng(window).normal(0.0, 1.0, order + 1) / (window * dt) ** np.arange(order + 1)
        p = np.polynomial.Polynomial(coef)
        for d in range(3):
            scale = math.factorial(d) / (window * dt) ** d  # of the d-th derivative at the centre
            assert h[d] @ p(t) == pytest.approx(p.deriv(d)(0.0), rel=1e-8, abs=1e-8 * scale)


def test_savgol_weights_must_keep_zero_phase():
    with pytest.raises(InputError, match="symmetric"):
        savgol_weights(5, np.array([1, 2, 3, 4, 5.0]))
    with pytest.raises(InputError, match="odd"):
        savgol_kernels(10, 2, DT)
    with pytest.raises(InputError, match="order"):
        savgol_kernels(5, 1, DT)


def test_butterworth_differentiates_cubics_exactly_away_from_the_edges():
    """Central differences are exact for the velocity of a quadratic and the acceleration of
    a cubic (linear); a zero-phase low-pass with unit gain at 0 Hz keeps a line unchanged."""
    t = np.arange(4000) * DT
    q = 0.3 + 0.5 * t - 0.7 * t**2 + 0.4 * t**3
    lowpass = ZeroPhaseLowpass(10.0, 6, DT)
    qd_c, qdd_c, _ = central_differences(q, DT)
    qdd, qd = lowpass(qdd_c), lowpass(qd_c)
    hw = lowpass.half_width
    assert np.all(np.isnan(qdd[:hw + 1])) and np.all(np.isnan(qdd[-hw - 1:]))
    inner = slice(3 * hw, len(t) - 3 * hw)  # away from the edges: the padding's start-up has settled
    assert np.abs(qdd[inner] - (-1.4 + 2.4 * t[inner])).max() < 1e-6
    q2 = 0.3 + 0.5 * t - 0.7 * t**2
    assert np.abs(lowpass(central_differences(q2, DT)[0])[inner] - (0.5 - 1.4 * t[inner])).max() < 1e-9
    assert np.isfinite(qd[hw + 1])


@pytest.mark.parametrize("smoother", [SavgolSmoother(151, 4, DT), SavgolSmoother(101, 4, DT, "gaussian"),
                                      ZeroPhaseLowpass(10.0, 6, DT), ZeroPhaseLowpass(20.0, 4, DT)],
                         ids=["savgol", "savgol-gaussian", "butter-10", "butter-20"])
def test_a_sine_below_the_cutoff_keeps_phase_and_the_designed_gain(smoother):
    t = np.arange(20000) * DT
    f = 1.7  # Hz, a walking-like frequency
    y = smoother(np.sin(2 * np.pi * f * t))
    inner = np.zeros_like(t, dtype=bool)
    inner[3 * smoother.half_width:-3 * smoother.half_width] = True  # away from the edges
    phase, gain = _phase_and_gain(y[inner], t[inner], f)
    assert abs(phase) < 1e-9
    if isinstance(smoother, SavgolSmoother):
        _, H = freqz(smoother.kernel(), worN=[f], fs=1 / DT)
        designed = abs(H[0])
    else:
        _, H = sosfreqz(smoother.sos, worN=[f], fs=1 / DT)
        designed = abs(H[0]) ** 2  # forward and backward
    assert abs(gain - designed) < 1e-6 and designed > 0.99


@pytest.mark.parametrize("smoother", [SavgolSmoother(51, 4, DT), ZeroPhaseLowpass(10.0, 6, DT)],
                         ids=["savgol", "butterworth"])
def test_white_noise_is_attenuated_as_designed(smoother):
    rng = np.random.default_rng(0)
    x = rng.normal(0.0, 1.0, 400_000)
    y = smoother(x)
    measured = np.nanstd(y)
    if isinstance(smoother, SavgolSmoother):
        designed = np.sqrt(np.sum(smoother.kernel() ** 2))
    else:
        _, H = sosfreqz(smoother.sos, worN=8192, fs=1 / DT)
        designed = np.sqrt(np.mean(np.abs(H) ** 4))  # |H|^2 per pass, two passes
    assert abs(measured / designed - 1) < 0.03


def test_savgol_second_derivative_noise_gain():
    """Differentiating noise: std(x_dd) = sigma * |h_2| (the thesis's 1/dt^2 growth, tamed)."""
    rng = np.random.default_rng(1)
    sigma = 1e-4
    x = rng.normal(0.0, sigma, 200_000)
    _, _, xdd = savgol_differentiate(x, DT, 151, 4)
    designed = sigma * np.linalg.norm(savgol_kernels(151, 4, DT)[2])
    assert abs(np.nanstd(xdd) / designed - 1) < 0.03
    _, qdd_c, _ = central_differences(x[:, None], DT)
    assert np.nanstd(qdd_c) > 1000 * designed  # what central differences would give


def test_filters_never_cross_a_gap():
    t = np.arange(3000) * DT
    x = np.sin(2 * np.pi * 2 * t)
    x[1500] = np.nan
    lowpass = ZeroPhaseLowpass(20.0, 6, DT)
    y = lowpass(x)
    hw = lowpass.half_width
    assert np.all(np.isnan(y[1500 - hw:1501 + hw])) and np.isfinite(y[1500 - hw - 1]) and np.isfinite(y[1501 + hw])
    s = SavgolSmoother(51, 4, DT)(x)
    assert np.all(np.isnan(s[1500 - 25:1501 + 25])) and np.isfinite(s[1500 - 26]) and np.isfinite(s[1501 + 25])


def test_amplitude_spectrum_and_cutoff_suggestion():
    rng = np.random.default_rng(2)
    t = np.arange(60_000) * DT
    # a step-frequency fundamental and harmonics up to 8 Hz (power 100 / k), then white noise
    x = sum(10.0 / np.sqrt(k) * np.sin(2 * np.pi * k * 1.0 * t + k) for k in range(1, 9)) + rng.normal(0, 0.5, t.size)
    freq, amp = amplitude_spectrum(x, DT)
    assert abs(amp[np.argmin(np.abs(freq - 1.0))] - 10.0) < 0.05
    assert suggest_cutoff(freq, amp) == pytest.approx(8.0, abs=0.05)  # the last harmonic holds 4.6 %
    assert suggest_cutoff(freq, amp, tail=0.05) == pytest.approx(7.0, abs=0.05)  # 8 Hz alone is under 5 %


def test_the_cutoff_is_where_the_content_meets_a_broadband_floor():
    """A walk's content below 8 Hz, a quiet band, then broadband noise from 60 Hz that holds most of the power
    (what a controller makes of noisy positions; issue 39: the cutoff was suggested at 473 Hz): the content
    ends inside the quiet band, where the spectrum dips below the floor; the same content without the
    broadband noise gives the same end."""
    rng = np.random.default_rng(3)
    t = np.arange(20_000) * DT
    content = sum(10.0 / np.sqrt(k) * np.sin(2 * np.pi * k * 1.0 * t + k) for k in range(1, 9))
    white = rng.normal(0, 1.0, t.size)
    spectrum = np.fft.rfft(white)
    spectrum[np.fft.rfftfreq(t.size, DT) < 60.0] *= 0.01  # quiet below 60 Hz
    broadband = np.fft.irfft(spectrum, t.size) * 40.0
    freq, amp = amplitude_spectrum(content + broadband, DT)
    assert np.sum(amp[freq > 60] ** 2) > 2 * np.sum(amp[(freq > 0) & (freq < 9)] ** 2)  # the floor's power rules
    cutoff = suggest_cutoff(freq, amp)
    assert 8.0 <= cutoff < 20.0, cutoff
    assert suggest_cutoff(*amplitude_spectrum(content + 0.01 * broadband, DT)) == pytest.approx(8.0, abs=0.05)


def _log_with_contacts(q: np.ndarray, switch: int) -> Log:
    n = len(q)
    contact = np.zeros((n, 2), dtype=bool)
    contact[:, 0] = True
    contact[:switch, 1] = True
    return Log(np.arange(n) * DT, q, np.zeros((n, 1)), contact)


def test_filtering_schemes_leave_out_windows_across_a_contact_change():
    """An impact-like kink at a contact change must not leak into rows whose window would
    span it: those rows are NaN, the others exact on a polynomial."""
    n, switch = 2000, 1000
    t = np.arange(n) * DT
    q = (0.2 * t**2 + np.where(t >= switch * DT, 0.05 * (t - switch * DT), 0.0))[:, None]
    assert straddling(_log_with_contacts(q, switch).contact).sum() == 2
    kin = measure(_log_with_contacts(q, switch), "savgol", filtering=FilterOptions(window=51, poly_order=4))
    bad = np.flatnonzero(~np.isfinite(kin.qdd[:, 0]))
    assert set(range(switch - 1 - 25, switch + 1 + 25)) <= set(bad)
    ok = np.isfinite(kin.qdd[:, 0])
    assert np.allclose(kin.qdd[ok, 0], 0.4, atol=1e-6)


@pytest.mark.parametrize("taps", [3, 11, 171])
def test_fir_is_its_definition(taps):
    """y[t] = sum_m h[m] x[t - N + m], NaN where the window is not whole inside x or holds a NaN."""
    rng = np.random.default_rng(taps)
    x = rng.normal(size=(600, 3))
    x[300, 1] = np.nan
    h = rng.normal(size=taps)
    n = taps // 2
    expected = np.full_like(x, np.nan)
    for t in range(n, len(x) - n):
        expected[t] = h @ x[t - n:t + n + 1]
    got = fir(x, h)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_the_overlap_add_and_the_hann_window_are_scipy_signals_to_the_last_bit():
    """Issue 41: :func:`convolve_same` (without ``scipy.signal``) gives ``oaconvolve(mode="same")``'s bytes on
    signals short and long (one FFT, overlap-add), 1-D and several columns; :func:`periodic_hann` gives
    ``windows.hann(sym=False)``'s."""
    from scipy.signal import oaconvolve
    from scipy.signal.windows import hann

    from wbfriction.signals.filters import convolve_same
    from wbfriction.signals.spectrum import periodic_hann

    rng = np.random.default_rng(41)
    for n in (1, 2, 7, 64, 257, 4096, 4399, 20_000):
        for m in (1, 2, 5, 31, 161, 401):
            for shape in ((n,), (n, 7), (n, 3, 2)):
                if m > n:
                    continue
                x, h = rng.normal(size=shape), rng.normal(size=m)
                expected = oaconvolve(x, h.reshape((-1,) + (1,) * (x.ndim - 1)), mode="same", axes=0)
                assert convolve_same(x, h).tobytes() == expected.tobytes(), (n, m, shape)
    assert all(periodic_hann(n).tobytes() == hann(n, sym=False).tobytes() for n in range(2000))

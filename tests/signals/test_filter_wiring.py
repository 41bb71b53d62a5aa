"""Which signal each filtering scheme filters, value by value, against filters written out in the test.

Extends ``test_kinematics.py::test_filter_wiring_around_a_contact_change`` (which pins the NaN margins
and the torque against the scheme's own smoother) to every signal and to independent references:

* Savitzky-Golay: q, qd and qdd are the value and the first two derivatives of ONE local polynomial fit
  of the positions (weighted least squares on the window's times, ``numpy.linalg.lstsq``), tau the
  value of the same fit of the torques;
* Butterworth: q, the central-difference qd and qdd (6.2), and tau, each through the forward-backward
  low-pass (``scipy.signal.filtfilt`` on the transfer function, not the library's second-order
  sections), each finite run apart, its half-width blanked at both ends;

and, where a window reaches a row straddling the contact change, q raw and qd the raw central
difference (NaN only on the straddling rows), qdd and tau NaN.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view
from scipy.signal import butter, filtfilt

from wbfriction.logs.log import Log
from wbfriction.signals.kinematics import measure
from wbfriction.signals.options import FilterOptions

DT, N, K = 1e-3, 1200, 600  # period [s], samples, first sample of the new contact state


def _log(seed: int = 2) -> tuple[Log, np.ndarray]:
    t = np.arange(N) * DT
    rng = np.random.default_rng(seed)
    q = np.column_stack([np.sin(2 * np.pi * 1.3 * t), 0.5 * np.cos(2 * np.pi * 0.7 * t)]) + rng.normal(0, 1e-6, (N, 2))
    tau = np.column_stack([np.sin(2 * np.pi * 2.0 * t), np.cos(2 * np.pi * 0.5 * t)]) + rng.normal(0, 0.3, (N, 2))
    contact = np.zeros((N, 1), dtype=bool)
    contact[K:] = True
    return Log(t, q, tau, contact), np.array([K - 1, K])  # rows whose central stencil straddles the change


def _blanked(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
    out = np.array(x, dtype=float)
    out[rows] = np.nan
    return out


def _central(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    qd, qdd = np.full_like(q, np.nan), np.full_like(q, np.nan)
    qd[1:-1] = (q[2:] - q[:-2]) / (2 * DT)
    qdd[1:-1] = (q[2:] - 2 * q[1:-1] + q[:-2]) / DT**2
    return qd, qdd


def local_fit(x: np.ndarray, window: int, order: int, weights: np.ndarray) -> np.ndarray:
    """Value, first and second time derivatives at the centre of the weighted least-squares polynomial
    fitted to each window of ``x`` (N, n) (3, N, n); NaN without a whole window of finite samples."""
    half = window // 2
    tm = np.arange(-half, half + 1) * DT
    V = np.vander(tm, order + 1, increasing=True)  # p(t) = sum c_j t^j
    sw = np.sqrt(weights)
    windows = sliding_window_view(x, window, axis=0)  # (N - 2 half, n, window)
    rows, n = windows.shape[:2]
    y = np.moveaxis(windows, -1, 0).reshape(window, -1)
    ok = np.all(np.isfinite(y), axis=0)
    coef = np.full((order + 1, y.shape[1]), np.nan)
    coef[:, ok] = np.linalg.lstsq(sw[:, None] * V, sw[:, None] * y[:, ok], rcond=None)[0]
    out = np.full((3, *x.shape), np.nan)
    for d, c in enumerate((coef[0], coef[1], 2.0 * coef[2])):
        out[d, half:half + rows] = c.reshape(rows, n)
    return out


def lowpass(x: np.ndarray, cutoff: float, order: int, half_width: int) -> np.ndarray:
    """Forward-backward Butterworth of each finite run of ``x`` (odd extension of twice the half-width),
    ``half_width`` rows blanked at both ends of each run."""
    b, a = butter(order, cutoff, fs=1.0 / DT)
    out = np.full_like(x, np.nan)
    finite = np.r_[False, np.all(np.isfinite(x), axis=1), False]
    edges = np.flatnonzero(np.diff(finite.astype(int)))
    for s, e in zip(edges[::2], edges[1::2]):
        if e - s > 2 * half_width:
            out[s:e] = filtfilt(b, a, x[s:e], axis=0, padtype="odd", padlen=min(2 * half_width, e - s - 1))
            out[s:s + half_width] = np.nan
            out[e - half_width:e] = np.nan
    return out


def _close(got: np.ndarray, want: np.ndarray, rel: float, name: str) -> None:
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=f"{name}: NaN rows")
    scale = np.nanmax(np.abs(want))
    np.testing.assert_allclose(got, want, rtol=0, atol=rel * scale, equal_nan=True, err_msg=name)


@pytest.mark.parametrize("weights", ["uniform", "gaussian"])
def test_savgol_scheme_is_one_local_fit_of_positions_and_torques(weights):
    log, straddle = _log()
    window, order = 51, 4
    kin = measure(log, "savgol", filtering=FilterOptions(window=window, poly_order=order, weights=weights),
                  torque_alignment="sample")
    half = window // 2
    m = np.arange(-half, half + 1)
    w = np.ones(window) if weights == "uniform" else np.exp(-0.5 * (m / (half / 2)) ** 2)  # std N/2 samples
    q_fit = local_fit(_blanked(log.q, straddle), window, order, w)
    tau_fit = local_fit(_blanked(log.tau, straddle), window, order, w)
    qd_c = _blanked(_central(log.q)[0], straddle)
    assert np.isfinite(q_fit[0]).sum() > 0.8 * q_fit[0].size
    _close(kin.q, np.where(np.isfinite(q_fit[0]), q_fit[0], log.q), 1e-9, "q")
    _close(kin.qd, np.where(np.isfinite(q_fit[1]), q_fit[1], qd_c), 1e-9, "qd")
    _close(kin.qdd, q_fit[2], 1e-8, "qdd")
    _close(kin.tau, tau_fit[0], 1e-9, "tau")


def test_butterworth_scheme_filters_positions_differences_and_torques():
    log, straddle = _log()
    cutoff, order = 20.0, 4
    kin = measure(log, "butterworth", filtering=FilterOptions(cutoff=cutoff, butter_order=order),
                  torque_alignment="sample")
    hw = kin.smoother.half_width
    assert 10 < hw < 100
    qd_c, qdd_c = (_blanked(x, straddle) for x in _central(log.q))
    q_f = lowpass(_blanked(log.q, straddle), cutoff, order, hw)
    qd_f, qdd_f = lowpass(qd_c, cutoff, order, hw), lowpass(qdd_c, cutoff, order, hw)
    tau_f = lowpass(_blanked(log.tau, straddle), cutoff, order, hw)
    assert np.isfinite(qdd_f).sum() > 0.6 * qdd_f.size
    _close(kin.q, np.where(np.isfinite(q_f), q_f, log.q), 1e-9, "q")
    _close(kin.qd, np.where(np.isfinite(qd_f), qd_f, qd_c), 1e-9, "qd")
    _close(kin.qdd, qdd_f, 1e-9, "qdd")
    _close(kin.tau, tau_f, 1e-9, "tau")
    # the low-pass does something to each signal: none is left raw away from the contact change
    inner = np.isfinite(qdd_f).all(axis=1)
    for got, raw in ((kin.q, log.q), (kin.qd, qd_c), (kin.qdd, qdd_c), (kin.tau, log.tau)):
        assert np.abs(got[inner] - raw[inner]).max() > 1e3 * 1e-10 * np.abs(raw[inner]).max()

"""Zero-phase filters for differentiating noisy logs, and the spectrum that tunes them (thesis 7.1).

Real joint-position logs are noisy and the estimator differentiates them twice, which
amplifies noise by about ``1 / dt^2``. Offline, a filter need not be causal: a zero-phase
filter removes noise without shifting the signal in time, which the estimator cannot
tolerate (6.1.2). Two designs of the thesis:

* **Savitzky-Golay** (7.1.1, eq. 7.1-7.8): a polynomial of order ``k`` fitted by (weighted)
  least squares to a window of ``L = 2N + 1`` samples; its value and derivatives at the
  centre are fixed weighted sums of the window (the impulse responses ``h_d``):

  .. math:: \\hat x^{(d)}[t] = \\sum_{m=-N}^{N} h_d[m]\\, x[t + m], \\qquad
            h_d = \\frac{d!}{\\Delta t^d}\\, e_d^T (T^T W T)^{-1} T^T W,

  with ``T`` the Vandermonde matrix of (7.3) and ``W`` the diagonal of weights (7.4-7.6).
  Symmetric weights keep the phase zero. Only samples with a full window are computed
  (the thesis's choice); the ``N`` first and last are NaN.
* **Butterworth, forward and backward** (7.1.2): the central-difference acceleration (6.2)
  through a low-pass Butterworth filter of order ``n`` run forward and backward
  (``scipy.signal.sosfiltfilt``, second-order sections), which cancels its phase. The
  cutoff is that of one pass (-3 dB); the two passes attenuate it by -6 dB.

The cutoff is read from the amplitude spectrum of the estimated acceleration (Fig. 7.1):
:func:`~wbfriction.signals.spectrum.suggest_cutoff` finds where its content ends.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.signals.options import WEIGHTS, SavgolWeights

TAIL = 0.01
"""An IIR filter's half-width: where less than this share of its impulse response's
absolute sum lies beyond (samples closer than that to an edge or a contact change are
not trusted)."""


# ----------------------------------------------------------------------- Savitzky-Golay
def savgol_weights(window: int, weights: SavgolWeights | np.ndarray = "uniform") -> np.ndarray:
    """Weights ``w`` (L,) of the least-squares fit (7.4).

    Args:
        window: odd window length L.
        weights: ``"uniform"`` (the thesis's W = I), ``"gaussian"`` (a bell of standard
            deviation N / 2 samples, N = (L - 1) / 2: the window's ends weigh e^-2), or an
            array (L,) of positive weights, symmetric about the centre.

    Raises:
        InputError: unknown name, wrong length, a non-positive or asymmetric array.
    """
    n = (window - 1) // 2
    if isinstance(weights, str):
        if weights == "uniform":
            return np.ones(window)
        if weights == "gaussian":
            m = np.arange(-n, n + 1)
            return np.exp(-0.5 * (m / max(n / 2.0, 1e-12)) ** 2)
        raise InputError(f"unknown Savitzky-Golay weights '{weights}': choose one of {', '.join(WEIGHTS)} or an array")
    w = np.asarray(weights, dtype=float)
    if w.shape != (window,) or np.any(w <= 0) or not np.allclose(w, w[::-1]):
        raise InputError(f"Savitzky-Golay weights must be {window} positive values, symmetric about the centre "
                         "(zero phase)")
    return w


def _check_savgol(window: int, order: int, deriv: int) -> None:
    if window < 3 or window % 2 == 0:
        raise InputError(f"Savitzky-Golay window (--window) must be odd and at least 3, got {window}")
    if not deriv <= order < window:
        raise InputError(f"Savitzky-Golay order (--poly-order) must be at least {deriv} (the derivative) and below "
                         f"the window "
                         f"{window}, got {order}")


def savgol_kernels(window: int, order: int, dt: float, weights: SavgolWeights | np.ndarray = "uniform",
                   max_deriv: int = 2) -> np.ndarray:
    """Impulse responses ``h_d`` (max_deriv + 1, L) of the value and the derivatives at the
    window's centre (module docstring), in time order: ``x^(d)[t] = h_d . x[t-N : t+N+1]``.

    The weighted least-squares fit (7.5)-(7.6) is solved by a QR decomposition of
    ``W^(1/2) T`` on the abscissa scaled to ``m / N`` in [-1, 1], so that long windows stay
    well conditioned (``scipy.signal.savgol_coeffs`` on raw sample indices loses the constant
    term from about 2 500 samples at order 4 and 500 at order 6: a smoother whose gain at 0 Hz
    is 0).

    Args:
        window: odd window length L; order: polynomial order k (``max_deriv <= k < L``).
        dt: sampling period [s]; derivative d is in units of x / s^d.

    Raises:
        InputError: a window, order or weights that do not make a filter.
    """
    from scipy.linalg import solve_triangular
    _check_savgol(window, order, max_deriv)
    root = np.sqrt(savgol_weights(window, weights))
    n = (window - 1) // 2
    T = np.vander(np.arange(-n, n + 1) / n, order + 1, increasing=True)
    Q, R = np.linalg.qr(root[:, None] * T)
    B = solve_triangular(R, Q.T * root)  # (k+1, L): coefficients a of (7.5) in powers of m / N
    return np.array([math.factorial(d) * B[d] / (n * dt) ** d for d in range(max_deriv + 1)])


def savgol_differentiate(x: np.ndarray, dt: float, window: int, order: int,
                         weights: SavgolWeights | np.ndarray = "uniform") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Savitzky-Golay smoothing, first and second derivatives of ``x`` (N_samples, ...) along axis 0.

    Returns:
        ``(x_s, xd, xdd)``, same shape as ``x``; the ``(window - 1) / 2`` first and last
        rows (no full window) are NaN.
    """
    h = savgol_kernels(window, order, dt, weights)
    return fir(x, h[0]), fir(x, h[1]), fir(x, h[2])


def fir(x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """``y[t] = sum_m h[m] x[t - N + m]`` along axis 0 (FFT overlap-add, :func:`convolve_same`), NaN where the
    window (2N + 1 samples) is not whole inside ``x`` or holds a non-finite value."""
    from scipy.ndimage import maximum_filter1d
    x = np.asarray(x, dtype=float)
    n = len(h) // 2
    if len(x) < len(h):  # no whole window
        return np.full(x.shape, np.nan)
    bad = ~np.isfinite(x)
    y = convolve_same(np.where(bad, 0.0, x), h[::-1])
    if bad.any():
        y[maximum_filter1d(bad, size=len(h), axis=0, mode="constant", cval=False)] = np.nan
    y[:n] = np.nan
    y[len(y) - n:] = np.nan
    return y


def convolve_same(x: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The convolution of ``x`` (N, ...) with a kernel ``h`` (L <= N,) along axis 0, its central N rows:
    ``scipy.signal.oaconvolve(x, h[:, None, ...], mode="same", axes=0)`` to the last bit (the same block
    lengths and FFTs, ``scipy.fft``), without importing ``scipy.signal`` (about 0.5 s of a process's start).

    FFT overlap-add: ``x`` cut in blocks of ``B - L + 1`` rows, each convolved by FFTs of length ``B`` (the
    length that minimises ``B log(2B) / (B - L + 1)``), the ``L - 1`` rows each block spills into the next added
    to it; one FFT of the whole (``B >= N + L - 1`` rounded up to a fast length) when a single block would do.
    """
    from scipy import fft
    x = np.asarray(x, dtype=float)
    h = np.asarray(h, dtype=float).reshape((-1,) + (1,) * (x.ndim - 1))
    n, m = len(x), len(h)
    if m > n:
        raise ValueError(f"a kernel of {m} taps is longer than the {n} rows it convolves")
    if n == 1 or m == 1:  # nothing to convolve along: oaconvolve's plain product
        full = x * h
    elif (block := _overlap_add_block(n, m, fft)) is None:
        full = _fft_convolve(x, h, fft)
    else:
        step, overlap = block - m + 1, m - 1
        steps = math.ceil((n + 1) / step) if n > step else 1
        if n > step and (block - overlap) * steps < n + m - 1:
            steps += 1
        padded = np.pad(x, [(0, steps * step - n)] + [(0, 0)] * (x.ndim - 1)) if n > step else x
        blocks = padded.reshape((steps, step) + x.shape[1:])
        out = fft.irfftn(fft.rfftn(blocks, [block], axes=[1]) * fft.rfftn(h[None], [block], axes=[1]), [block],
                         axes=[1])
        kept, spill = out[:, :block - overlap], out[:, block - overlap:]
        kept[1:, :overlap] += spill[:-1]
        full = kept.reshape((steps * (block - overlap),) + x.shape[1:])[:n + m - 1]
    start = (len(full) - n) // 2
    return full[start:start + n].copy()


def _fft_convolve(x: np.ndarray, h: np.ndarray, fft) -> np.ndarray:
    """The full convolution (N + L - 1, ...) by one FFT of a fast length (``scipy.signal.fftconvolve``'s)."""
    size = len(x) + len(h) - 1
    length = fft.next_fast_len(size, True)
    return fft.irfftn(fft.rfftn(x, [length], axes=[0]) * fft.rfftn(h, [length], axes=[0]), [length], axes=[0])[:size]


def _overlap_add_block(n: int, m: int, fft) -> int | None:
    """``oaconvolve``'s FFT length for a signal of ``n`` rows and a kernel of ``m`` (``1 < m < n``), or None where
    it convolves in one FFT: ``-K W_{-1}(-1 / (2 e K))`` rounded up to a fast length, ``K = m - 1`` (the minimum of
    ``B log(2B) / (B - K)``)."""
    from scipy.special import lambertw
    if m >= n / 2:
        return None
    overlap = m - 1
    block = fft.next_fast_len(math.ceil(-overlap * lambertw(-1 / (2 * math.e * overlap), k=-1).real))
    return None if block >= n else block


# ------------------------------------------------------------------------- Butterworth
@dataclass(frozen=True)
class ZeroPhaseLowpass:
    """Order-``order`` Butterworth low-pass, run forward and backward (7.1.2).

    Attributes:
        cutoff: -3 dB frequency of one pass [Hz]; order: filter order; dt: sampling period [s].
    """

    cutoff: float
    order: int
    dt: float

    def __post_init__(self) -> None:
        nyquist = 0.5 / self.dt
        if not 0 < self.cutoff < nyquist:
            raise InputError(f"Butterworth cutoff (--cutoff) must be between 0 and the Nyquist frequency "
                             f"{nyquist:g} Hz, "
                             f"got {self.cutoff:g}")
        if self.order < 1:
            raise InputError(f"Butterworth order (--butter-order) must be at least 1, got {self.order}")

    @cached_property
    def sos(self) -> np.ndarray:
        """Second-order sections of one pass."""
        from scipy.signal import butter
        return butter(self.order, self.cutoff, btype="low", fs=1.0 / self.dt, output="sos")

    @cached_property
    def half_width(self) -> int:
        """Samples on each side beyond which the forward-backward impulse response holds
        less than :data:`TAIL` of its absolute sum."""
        from scipy.signal import sosfiltfilt
        m = int(20 * self.order / (self.cutoff * self.dt)) + 1
        impulse = np.zeros(2 * m + 1)
        impulse[m] = 1.0
        a = np.abs(sosfiltfilt(self.sos, impulse))
        inside = np.cumsum(np.r_[a[m], a[m + 1:] + a[m - 1::-1]])  # |h| within +-k samples
        return int(np.argmax(a.sum() - inside <= TAIL * a.sum()))

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Filter ``x`` (N_samples, ...) along axis 0, zero phase, each run of finite rows
        apart (never across a gap); the :attr:`half_width` rows at both ends of every run
        (where the filter would lean on extrapolated padding) and runs too short for the
        filter are NaN."""
        from scipy.signal import sosfiltfilt
        x = np.asarray(x, dtype=float)
        out = np.full_like(x, np.nan)
        hw = self.half_width
        sos = self.sos
        for a, b in finite_runs(x):
            if b - a > 2 * hw:  # padding (odd extension) long enough for the start-up transient to settle
                out[a:b] = sosfiltfilt(sos, x[a:b], axis=0, padlen=min(2 * hw, b - a - 1))
                out[a:a + hw] = np.nan
                out[b - hw:b] = np.nan
        return out


@dataclass(frozen=True)
class SavgolSmoother:
    """The Savitzky-Golay smoother (value at the centre of the local fit, eq. 7.7-7.8).

    Attributes:
        window: odd window length L; order: polynomial order k; weights: see
            :func:`savgol_weights`; dt: sampling period [s].
    """

    window: int
    order: int
    dt: float
    weights: SavgolWeights = "uniform"

    def __post_init__(self) -> None:
        _check_savgol(self.window, self.order, 0)
        savgol_weights(self.window, self.weights)

    @property
    def half_width(self) -> int:
        return (self.window - 1) // 2

    def kernel(self) -> np.ndarray:
        """Impulse response h_0 (L,), symmetric."""
        return self._kernel.copy()

    @cached_property
    def _kernel(self) -> np.ndarray:
        return savgol_kernels(self.window, self.order, self.dt, self.weights, max_deriv=0)[0]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Smooth ``x`` (N_samples, ...) along axis 0; rows without a full window of finite
        samples are NaN."""
        return fir(x, self._kernel)


def finite_runs(x: np.ndarray) -> list[tuple[int, int]]:
    """Half-open ranges [a, b) of the runs of rows of ``x`` (N_samples, ...) that are finite."""
    finite = np.all(np.isfinite(np.asarray(x).reshape(len(x), -1)), axis=1)
    edges = np.diff(np.concatenate(([0], finite.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))

"""Derivatives and zero-phase filters on non-uniform sample times (exact stamps that skip samples).

The schemes of :mod:`wbfriction.signals.kinematics` and :mod:`wbfriction.signals.filters`
assume a constant period. When a log's samples truly are non-uniform
(:class:`~wbfriction.logs.clock.Clock` of kind ``skipping``), or are differentiated on a
regularised clock that is not exactly uniform (``jittered``), they are taken on the actual times
``t`` instead:

* **three-point differences** (the non-uniform forms of 6.2 and 6.3): the derivatives at
  ``t_k`` of the parabola through ``(t_{k-1}, t_k, t_{k+1})``, with ``h1 = t_k - t_{k-1}``,
  ``h2 = t_{k+1} - t_k``:

  .. math:: \\dot q_k = \\frac{-h_2}{h_1 (h_1 + h_2)} q_{k-1} + \\frac{h_2 - h_1}{h_1 h_2} q_k
                       + \\frac{h_1}{h_2 (h_1 + h_2)} q_{k+1}, \\qquad
            \\ddot q_k = \\frac{2}{h_1 + h_2} \\Big(\\frac{q_{k+1} - q_k}{h_2}
                        - \\frac{q_k - q_{k-1}}{h_1}\\Big);

  exact on quadratics; equal to (6.2) when ``h1 = h2``.
* **Savitzky-Golay on the actual times** (7.1-7.8 with ``T`` built from ``t - t_k`` instead of
  ``m dt``): around each sample, a polynomial of order ``k`` fitted by weighted least squares to
  the ``L = 2N + 1`` samples of the window (weights by sample offset, as the uniform filter's:
  :func:`~wbfriction.signals.filters.savgol_weights`); value and first two derivatives of the
  fit at that sample. Exact on polynomials of order ``k``; the uniform filter when ``t`` is
  uniform. Each sample has its own impulse response (computed by a QR factorisation of the
  scaled Vandermonde matrix, in blocks of rows), applied as a banded sparse matrix.
* **Butterworth through a uniform grid** (7.1.2 needs one): each run of finite samples is
  resampled onto the grid ``t_a + j dt`` by a cubic spline (``scipy.interpolate.CubicSpline``,
  not-a-knot ends), differentiated there by central differences (6.2) and filtered forward and
  backward (:class:`~wbfriction.signals.filters.ZeroPhaseLowpass`), and brought back to the
  sample times by a cubic spline through the filtered grid.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.signals.filters import ZeroPhaseLowpass, finite_runs, savgol_weights
from wbfriction.signals.options import SavgolWeights

if TYPE_CHECKING:
    import scipy.sparse as sp

BLOCK = 4096
"""Rows whose Savitzky-Golay impulse responses are computed at once."""
CACHE = 5_000_000
"""Impulse-response entries (rows x window) a smoother keeps between calls (as sparse matrices,
about 16 bytes each); beyond, they are recomputed block by block at each call (long logs in
bounded memory)."""


# ---------------------------------------------------------------- three-point differences
def _steps(t: np.ndarray, n: int) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.shape != (n,):
        raise InputError(f"time base of {t.shape[0] if t.ndim == 1 else t.shape} samples for {n} samples")
    return np.diff(t)


def three_point_differences(q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Non-uniform central differences (module docstring), the form of (6.2) on times ``t``.

    Args:
        q: samples (N, ...) along axis 0; t: their times (N,) [s], increasing.

    Returns:
        ``(qd, qdd, 0)``: first and second derivatives (N, ...) at ``t_k`` (zero delay), NaN on
        the first and last rows.
    """
    q = np.asarray(q, dtype=float)
    h = _steps(t, len(q)).reshape((-1,) + (1,) * (q.ndim - 1))
    h1, h2 = h[:-1], h[1:]
    qm, q0, qp = q[:-2], q[1:-1], q[2:]
    qd = np.full_like(q, np.nan)
    qdd = np.full_like(q, np.nan)
    qd[1:-1] = (-h2 / (h1 * (h1 + h2)) * qm + (h2 - h1) / (h1 * h2) * q0 + h1 / (h2 * (h1 + h2)) * qp)
    qdd[1:-1] = 2.0 / (h1 + h2) * ((qp - q0) / h2 - (q0 - qm) / h1)
    return qd, qdd, 0


def backward_differences(q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Non-uniform backward differences, the form of (6.3) on times ``t``.

    ``qd[k] = (q[k] - q[k-1]) / (t[k] - t[k-1])`` (describes the middle of the step) and
    ``qdd[k] = (qd[k] - qd[k-1]) / ((t[k] - t[k-2]) / 2)`` (describes ``t[k-1]``: it is the
    three-point second difference there); causal, delay 1 sample, the first two rows NaN.
    """
    q = np.asarray(q, dtype=float)
    h = _steps(t, len(q)).reshape((-1,) + (1,) * (q.ndim - 1))
    qd = np.full_like(q, np.nan)
    qdd = np.full_like(q, np.nan)
    qd[1:] = (q[1:] - q[:-1]) / h
    qdd[2:] = (qd[2:] - qd[1:-1]) / (0.5 * (h[1:] + h[:-1]))
    return qd, qdd, 1


# ---------------------------------------------------------------------- Savitzky-Golay
def savgol_responses(t: np.ndarray, window: int, order: int, weights: SavgolWeights | np.ndarray = "uniform",
                     max_deriv: int = 2, rows: tuple[int, int] | None = None) -> np.ndarray:
    """Impulse responses of the local fits at the samples ``rows`` (default: all).

    Row ``k`` (with a whole window, ``N <= k < len(t) - N``) gives ``x^(d)(t_k) =
    H[k, d] . x[k-N : k+N+1]``: the value (d = 0) and derivatives (in units of x / s^d) at
    ``t_k`` of the order-``order`` polynomial fitted by weighted least squares to the window on
    its actual times. Rows without a whole window are NaN.

    Args:
        t: sample times (n,) [s], increasing.
        window: odd window length L [samples]; order: polynomial order (``max_deriv <= order < L``).
        weights: see :func:`~wbfriction.signals.filters.savgol_weights` (by sample offset).
        rows: ``(start, stop)``, the samples to compute.

    Returns:
        (stop - start, max_deriv + 1, L).

    Raises:
        InputError: a window, order or weights that do not make a filter.
    """
    if window < 3 or window % 2 == 0:
        raise InputError(f"Savitzky-Golay window (--window) must be odd and at least 3, got {window}")
    if not max_deriv <= order < window:
        raise InputError(f"Savitzky-Golay order (--poly-order) must be at least {max_deriv} (the derivative) and below "
                         f"the window "
                         f"{window}, got {order}")
    t = np.asarray(t, dtype=float)
    w = np.sqrt(savgol_weights(window, weights))
    half = (window - 1) // 2
    start, stop = rows if rows is not None else (0, len(t))
    out = np.full((stop - start, max_deriv + 1, window), np.nan)
    a, b = max(start, half), min(stop, len(t) - half)
    if b <= a:
        return out
    centre = np.arange(a, b)
    offset = t[centre[:, None] + np.arange(-half, half + 1)] - t[centre][:, None]  # (B, L) [s]
    scale = np.max(np.abs(offset), axis=1, keepdims=True)  # the fit in tau = offset / scale in [-1, 1]
    V = (offset / scale)[..., None] ** np.arange(order + 1)  # (B, L, order + 1)
    Q, R = np.linalg.qr(w[None, :, None] * V)
    coef = np.linalg.solve(R, np.swapaxes(Q, 1, 2)) * w  # (B, order + 1, L): polynomial coefficients
    for d in range(max_deriv + 1):
        out[a - start:b - start, d] = math.factorial(d) * coef[:, d] / scale**d
    return out


@dataclass(frozen=True)
class _Block:
    """The local fits of rows ``[start, start + len(inner))`` as sparse (rows x N) matrices, one per
    derivative (row k applies its impulse response to the window around it); ``inner``: the rows
    with a whole window."""

    start: int
    inner: np.ndarray
    matrices: tuple[sp.csr_matrix, ...]

    def apply(self, flat: np.ndarray, d: int) -> np.ndarray:
        y = self.matrices[d] @ flat
        y[~self.inner] = np.nan
        return np.where(np.isfinite(y), y, np.nan)  # a non-finite sample in the window: NaN


def _blocks(t: np.ndarray, window: int, order: int, weights: SavgolWeights | np.ndarray,
            max_deriv: int) -> list[_Block]:
    import scipy.sparse as sp
    n, half = len(t), (window - 1) // 2
    out = []
    for start in range(0, n, BLOCK):
        H = savgol_responses(t, window, order, weights, max_deriv, (start, min(start + BLOCK, n)))
        inner = np.isfinite(H[:, 0]).all(axis=1)
        rows = np.flatnonzero(inner)
        cols = (rows[:, None] + start - half + np.arange(window)).ravel()
        indptr = np.r_[0, np.cumsum(np.where(inner, window, 0))]
        out.append(_Block(start, inner, tuple(sp.csr_matrix((H[inner, d].ravel(), cols, indptr), shape=(len(H), n))
                                              for d in range(max_deriv + 1))))
    return out


def _through(blocks: list[_Block], x: np.ndarray, max_deriv: int) -> list[np.ndarray]:
    """``x`` (N, ...) through every block's fits: value and derivatives (N, ...) each."""
    flat = np.asarray(x, dtype=float).reshape(len(x), -1)
    out = [np.full(flat.shape, np.nan) for _ in range(max_deriv + 1)]
    for block in blocks:
        for d in range(max_deriv + 1):
            out[d][block.start:block.start + len(block.inner)] = block.apply(flat, d)
    return [y.reshape(np.shape(x)) for y in out]


@dataclass(frozen=True, eq=False)
class NonUniformSavgol:
    """Savitzky-Golay on the actual sample times (module docstring): the smoother (value of the
    local fit, called on signals) and the differentiator (:meth:`differentiate`).

    Attributes:
        t: sample times (N,) [s]; window: odd window length L [samples]; order: polynomial
        order; weights: ``uniform`` or ``gaussian`` (by sample offset).
    """

    t: np.ndarray
    window: int
    order: int
    weights: SavgolWeights = "uniform"

    def __post_init__(self) -> None:
        savgol_responses(self.t[:0], self.window, self.order, self.weights, max_deriv=0)

    @property
    def half_width(self) -> int:
        return (self.window - 1) // 2

    @cached_property
    def _value_blocks(self) -> list[_Block] | None:
        return _blocks(self.t, self.window, self.order, self.weights, 0) if len(self.t) * self.window <= CACHE else None

    def _check(self, x: np.ndarray) -> None:
        if len(x) != len(self.t):
            raise InputError(f"a signal of {len(x)} samples through a Savitzky-Golay filter on {len(self.t)} "
                             "sample times")

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The value of the local fit at every sample of ``x`` (N, ...) along axis 0; rows without
        a whole window of finite samples are NaN."""
        self._check(x)
        blocks = self._value_blocks or _blocks(self.t, self.window, self.order, self.weights, 0)
        return _through(blocks, x, 0)[0]

    def differentiate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Value, first and second derivatives [x / s^d] of the local fits, (N, ...) each."""
        self._check(x)
        xs, xd, xdd = _through(_blocks(self.t, self.window, self.order, self.weights, 2), x, 2)
        return xs, xd, xdd


def savgol_differentiate(x: np.ndarray, t: np.ndarray, window: int, order: int,
                         weights: SavgolWeights | np.ndarray = "uniform") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Savitzky-Golay smoothing, first and second derivatives of ``x`` (N, ...) on its sample
    times ``t`` (N,) [s]; the ``(window - 1) / 2`` first and last rows are NaN.

    Raises:
        InputError: a window, order or weights that do not make a filter.
    """
    xs, xd, xdd = _through(_blocks(np.asarray(t, dtype=float), window, order, weights, 2), x, 2)
    return xs, xd, xdd


# ------------------------------------------------------------------------- Butterworth
@dataclass(frozen=True, eq=False)
class ResampledLowpass:
    """The zero-phase Butterworth low-pass (7.1.2) on non-uniform samples, through a uniform
    grid (module docstring): resampled by cubic spline, filtered, brought back by cubic spline.

    Attributes:
        t: sample times (N,) [s]; lowpass: the filter on the grid, whose ``dt`` is the grid step.
    """

    t: np.ndarray
    lowpass: ZeroPhaseLowpass

    @property
    def dt(self) -> float:
        return self.lowpass.dt

    def _through_grid(self, x: np.ndarray, on_grid: Callable[[np.ndarray], list[np.ndarray]]) -> list[np.ndarray]:
        """Each finite run of ``x`` (N, ...) resampled onto the grid, mapped there by ``on_grid``
        to signals on the grid, each brought back to the sample times of the run (NaN beyond the
        finite part of the grid signal)."""
        from scipy.interpolate import CubicSpline
        x = np.asarray(x, dtype=float)
        if len(x) != len(self.t):
            raise InputError(f"a signal of {len(x)} samples through a low-pass filter on {len(self.t)} sample times")
        outs: list[np.ndarray] | None = None
        for a, b in finite_runs(x):
            if b - a < 4:
                continue
            ts = self.t[a:b]
            grid = ts[0] + self.dt * np.arange(int(np.floor((ts[-1] - ts[0]) / self.dt + 1e-9)) + 1)
            results = on_grid(CubicSpline(ts, x[a:b], axis=0)(grid))
            if outs is None:
                outs = [np.full(x.shape, np.nan) for _ in results]
            for out, y in zip(outs, results):
                for ga, gb in finite_runs(y):
                    if gb - ga < 4:
                        continue
                    inside = (ts >= grid[ga] - 1e-12 * self.dt) & (ts <= grid[gb - 1] + 1e-12 * self.dt)
                    out[a:b][inside] = CubicSpline(grid[ga:gb], y[ga:gb], axis=0)(ts[inside])
        return outs if outs is not None else [np.full(x.shape, np.nan)]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``x`` (N, ...) filtered along axis 0, zero phase, each run of finite rows apart; rows
        where the filter on the grid is not trusted (its ends) are NaN."""
        return self._through_grid(x, lambda g: [self.lowpass(g)])[0]

    def differentiate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocity and acceleration: central differences (6.2) on the grid, each
        through the low-pass, brought back to the sample times; (N, ...) each."""
        def on_grid(g: np.ndarray) -> list[np.ndarray]:
            gd = np.full_like(g, np.nan)
            gdd = np.full_like(g, np.nan)
            gd[1:-1] = (g[2:] - g[:-2]) / (2.0 * self.dt)
            gdd[1:-1] = (g[2:] - 2.0 * g[1:-1] + g[:-2]) / self.dt**2
            return [self.lowpass(g), self.lowpass(gd), self.lowpass(gdd)]

        out = self._through_grid(q, on_grid)
        if len(out) == 1:
            out = out * 3
        return out[0], out[1], out[2]

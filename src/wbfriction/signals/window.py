"""The momentum route's window: a zero-phase weighted mean over the steps between samples (issue 38).

The generalized-momentum route (:mod:`wbfriction.friction.momentum`) knows, for every step
``[t_i, t_i+1]`` between two consecutive samples, the impulse of the friction over it,
``F_i = int tau_f dt``, as a difference of two momenta less the integral of the known torques. One
step's impulse holds the momenta's velocity noise divided by one step; a window averages it. The
estimate at sample ``k`` is the weighted mean friction over the ``2m`` steps around it:

.. math::

    \\hat\\tau_f(t_k) = \\frac{\\sum_{j=0}^{2m-1} w_j\\, F_{k-m+j}}{\\sum_{j=0}^{2m-1} w_j\\, \\Delta t_{k-m+j}},
    \\qquad w_j = \\cos^2\\Big(\\frac{\\pi}{2}\\, \\frac{j + 1/2 - m}{m}\\Big),

a Hann window over the steps (samples ``k - m`` to ``k + m``), symmetric: zero phase, no lag. Summed by
parts, ``sum_j w_j (p_{i+1} - p_i) = -sum_i (w_i - w_{i-1}) p_i``: the momenta enter through the
differences of neighbouring weights, which a Hann window keeps small (its weights vanish at both ends, and
so does their first difference), so the velocity noise is averaged over the whole window rather than
taken at its two ends, as a boxcar's ``Delta p`` would.

The same operator applied to a signal sampled at the samples (:meth:`MomentumWindow.__call__`: each step's
mean by the trapezoid rule, then the window) is what the fit compares the model with (the parallel filtering
of :mod:`wbfriction.fit`): a linear, time-invariant smoother of ``2m + 1`` samples on a uniform clock,
its weights scaled by each step's duration on a non-uniform one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from wbfriction.exceptions import InputError


def hann_steps(half_width: int) -> np.ndarray:
    """The window's weights ``w_j`` (2m,) over the ``2m`` steps around a sample (module docstring), not
    normalised; ``half_width`` is ``m`` >= 1."""
    u = (np.arange(2 * half_width) + 0.5 - half_width) / half_width
    return np.cos(0.5 * np.pi * u) ** 2


def _window_sums(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``y[s] = sum_j w_j x[s + j]`` along axis 0 for every ``s`` whose ``len(w)`` rows (even) are inside ``x``
    and finite (NaN otherwise): (len(x) - len(w) + 1, ...). Summed directly (``scipy.ndimage.correlate1d``), not by
    FFT: each sum's rounding does not depend on the array's length, so a long log estimated in chunks gives the
    whole log's numbers to the last bit."""
    from scipy.ndimage import correlate1d
    m = len(w) // 2
    bad = ~np.isfinite(x)
    full = correlate1d(np.where(bad, 0.0, x), np.r_[w, 0.0], axis=0, mode="constant", cval=0.0)
    y = full[m:len(x) - m + 1]
    if bad.any():
        y[np.lib.stride_tricks.sliding_window_view(bad, len(w), axis=0).any(axis=-1)] = np.nan
    return y


@dataclass(frozen=True, eq=False)
class MomentumWindow:
    """The weighted mean over the ``2m`` steps around each sample (module docstring).

    Attributes:
        half_width: ``m`` [samples]: the window spans the samples ``k - m`` to ``k + m`` (``2m + 1``).
        dt: the sampling period [s] (a non-uniform clock's nominal step).
        t: the sample times (N,) [s] of a non-uniform clock, or None (every step ``dt``).

    Raises:
        InputError: a half width below 1 or a non-positive period.
    """

    half_width: int
    dt: float
    t: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.half_width < 1:
            raise InputError(f"momentum window (--momentum-window) must span at least 3 samples, got "
                             f"{2 * self.half_width + 1}")
        if not self.dt > 0:
            raise InputError(f"momentum window: the sampling period must be > 0 s, got {self.dt}")

    @property
    def length(self) -> int:
        """Samples the window spans, ``2m + 1``."""
        return 2 * self.half_width + 1

    @cached_property
    def weights(self) -> np.ndarray:
        """``w_j`` (2m,): the Hann window over the steps (:func:`hann_steps`)."""
        return hann_steps(self.half_width)

    def step_durations(self, n: int) -> np.ndarray:
        """``Delta t_i`` (n - 1,) [s] of ``n`` samples."""
        if self.t is None:
            return np.full(n - 1, self.dt)
        if len(self.t) != n:
            raise InputError(f"momentum window: a clock of {len(self.t)} samples for {n} rows")
        return np.diff(np.asarray(self.t, dtype=float))

    def over_steps(self, impulses: np.ndarray) -> np.ndarray:
        """The mean ``sum w F / sum w Delta t`` around each sample.

        Args:
            impulses: ``F_i`` (N - 1, ...) over each step [unit·s], NaN where not known.

        Returns:
            (N, ...) [unit]: NaN on the ``m`` first and last rows and wherever the window holds a NaN.
        """
        impulses = np.asarray(impulses, dtype=float)
        n = len(impulses) + 1
        m = self.half_width
        out = np.full((n, *impulses.shape[1:]), np.nan)
        if n - 1 < 2 * m:
            return out
        total = self._durations_summed(n)
        out[m:n - m] = _window_sums(impulses, self.weights) / total.reshape((-1,) + (1,) * (impulses.ndim - 1))
        return out

    def _durations_summed(self, n: int) -> np.ndarray:
        """``sum_j w_j Delta t`` around each sample of ``n`` (:meth:`over_steps`' denominator), computed once per
        ``n`` (the fits filter many signals through one window)."""
        cache = self.__dict__.setdefault("_totals", {})
        if n not in cache:
            cache[n] = _window_sums(self.step_durations(n), self.weights)
            cache[n].setflags(write=False)
        return cache[n]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``x`` (N, ...) sampled at the samples through the window: each step's trapezoid ``(x_i + x_i+1) / 2
        Delta t_i``, then :meth:`over_steps`; NaN where the window reaches beyond ``x`` or a NaN."""
        x = np.asarray(x, dtype=float)
        dt = self.step_durations(len(x)).reshape((-1,) + (1,) * (x.ndim - 1))
        return self.over_steps(0.5 * (x[1:] + x[:-1]) * dt)

    def kernel(self) -> np.ndarray:
        """The weights (2m + 1,) of :meth:`__call__` on a uniform clock, by sample offset ``-m .. m``: symmetric,
        summing to 1."""
        w = self.weights
        c = 0.5 * (np.r_[w, 0.0] + np.r_[0.0, w])
        return c / w.sum()

    def gain(self, freq: np.ndarray | float) -> np.ndarray:
        """Amplitude gain of :meth:`kernel` at ``freq`` [Hz] (real: the kernel is symmetric)."""
        m = np.arange(-self.half_width, self.half_width + 1)
        return np.cos(2.0 * np.pi * np.multiply.outer(freq, m) * self.dt) @ self.kernel()

    @cached_property
    def cutoff(self) -> float:
        """The -3 dB frequency [Hz] of :meth:`kernel`: the bandwidth of the momentum route's per-sample
        estimate (its lag is zero)."""
        from scipy.optimize import brentq
        half_power = 1.0 / math.sqrt(2.0)
        nyquist = 0.5 / self.dt
        grid = np.linspace(0.0, nyquist, 64 * self.half_width + 1)
        # the gain on the grid a block at a time (a block x window matrix: a few MB however long the window), up to
        # the first point below half power (near the grid's start: about 0.72 / (2 m dt) of the Nyquist frequency's
        # 0.5 / dt)
        block = max(16, 2**19 // self.length)
        for start in range(0, grid.size, block):
            below = np.flatnonzero(self.gain(grid[start:start + block]) < half_power)
            if below.size:
                i = start + int(below[0])
                return float(brentq(lambda f: float(self.gain(f)) - half_power, grid[i - 1], grid[i],
                                    xtol=1e-9 * grid[i]))
        return nyquist

"""The estimate's smoother seen from the rows a fit uses (issue 41).

A fit through a smoother (:func:`~wbfriction.fit.solve.filtered_problem`, the variable projection of
:mod:`~wbfriction.fit.projection`) compares the data on its rows with the model passed through the smoother
along the whole series. A Savitzky-Golay fit and the momentum route's window are local: their output on a row
depends on the samples within their half width of it alone. The model is then needed only on the rows widened by
that reach (the *support*), zero elsewhere: the same values on the rows, to rounding (a Savitzky-Golay filter
convolves by FFT), for a fraction of the model's evaluations on a log that walks in single support part of the
time. A Butterworth filter's response and the cubic splines of
:class:`~wbfriction.signals.nonuniform.ResampledLowpass` never end: the model is then evaluated everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.signals.filters import SavgolSmoother
from wbfriction.signals.kinematics import PiecewiseSmoother, Smoother
from wbfriction.signals.nonuniform import NonUniformSavgol, ResampledLowpass
from wbfriction.signals.window import MomentumWindow


def smoother_half_width(smoother: Smoother | None) -> int:
    """Samples a smoother reaches on each side (0 without one), on its own grid for a resampling one."""
    if smoother is None:
        return 0
    if isinstance(smoother, PiecewiseSmoother):
        return max((smoother_half_width(s) for *_, s in smoother.parts), default=0)
    if isinstance(smoother, ResampledLowpass):
        return smoother.lowpass.half_width
    return int(smoother.half_width)


LOCAL = (SavgolSmoother, NonUniformSavgol, MomentumWindow)
"""The smoothers whose output on a row is a weighted sum of the samples within their half width, exactly."""


def smoother_reach(smoother: Smoother | None) -> int | None:
    """Samples of the series a smoother's output on one row depends on, on each side (0 without one); None where it
    depends on its whole run: a Butterworth filter's response (:class:`~wbfriction.signals.filters.ZeroPhaseLowpass`,
    whose half width only bounds the bulk of it) and a cubic spline's
    (:class:`~wbfriction.signals.nonuniform.ResampledLowpass`) never end."""
    if smoother is None:
        return 0
    if isinstance(smoother, PiecewiseSmoother):
        reaches = [smoother_reach(s) for *_, s in smoother.parts]
        return None if None in reaches else max((r for r in reaches if r is not None), default=0)
    return smoother_half_width(smoother) if isinstance(smoother, LOCAL) else None


@dataclass(frozen=True, eq=False)
class RowSmoothing:
    """A smoother's output on the rows fitted, from its input on the samples they depend on.

    Attributes:
        smoother: the estimate's smoother (linear, along axis 0 of the whole series).
        rows: the rows fitted (n,) (indices into the series).
        support: the samples (N,) bool the output on ``rows`` depends on (:func:`row_smoothing`).
    """

    smoother: Smoother
    rows: np.ndarray
    support: np.ndarray

    def __call__(self, columns: np.ndarray) -> np.ndarray:
        """``columns`` (S, ...) given on :attr:`support` through the smoother (zero elsewhere), on the rows (n, ...)."""
        whole = np.zeros((self.support.size, *columns.shape[1:]))
        whole[self.support] = columns
        return self.smoother(whole)[self.rows]


def row_smoothing(smoother: Smoother, size: int, rows: np.ndarray) -> RowSmoothing:
    """:class:`RowSmoothing` of ``smoother`` on a series of ``size`` samples for ``rows`` (increasing): its support
    is the rows widened by :func:`smoother_reach`, or every sample."""
    reach = smoother_reach(smoother)
    if reach is None:
        return RowSmoothing(smoother, rows, np.ones(size, dtype=bool))
    fitted = np.zeros(size + 1, dtype=np.int64)
    fitted[np.asarray(rows) + 1] = 1
    before = np.cumsum(fitted)  # rows fitted before each sample
    i = np.arange(size)
    return RowSmoothing(smoother, rows, before[np.minimum(i + reach + 1, size)] > before[np.maximum(i - reach, 0)])

"""Has a series changed, and from when: a generalised likelihood-ratio test of a constant against a constant
followed by a change from an unknown onset, of one of two shapes (:data:`SHAPES`), weighted by the standard errors.
The fleet's trends (:mod:`wbfriction.fleet.trends`) run it on each joint's quantities over its logs.

* ``hinge``: a linear drift from the onset (a "broken-stick" regression: Hinkley 1971, "Inference in two-phase
  regression", JASA 66; the weighted form of Julious 2001, "Inference and estimation in a changepoint regression
  problem", The Statistician 50): wear that grows;
* ``step``: a jump at the onset, constant after it (a mean shift: Hinkley 1970, "Inference about the change-point
  in a sequence of random variables", Biometrika 57): a part replaced, a seal damaged, a gearbox refilled.

Both have two coefficients and one onset: the information criteria (AIC, BIC) of the two, each at its best onset,
differ only by their residual sums of squares, so the shape chosen is the one with the larger ``F_k``. The test:

* points ``y_i`` at times ``t_i`` [days], errors ``e_i ~ N(0, phi se_i^2)`` with an unknown scale ``phi``
  (the fits' standard errors may be off by a common factor: Newey-West, a model that trades parameters);
* for each candidate onset ``k`` (at least :attr:`ChangeSettings.min_before` points before, at least
  :attr:`ChangeSettings.min_after` from it on), the hinge regressor ``x_i = max(0, t_i - t_{k-1})`` (zero up to
  the last log before the onset, growing from the first drifted log on) or the step regressor ``x_i = [i >= k]``;
* the statistic ``F_k = (RSS_0 - RSS_k) / (RSS_k / (n - 2 - 2m))`` with weighted residual sums of squares, ``m``
  covariates in both models (the logs' temperatures, where they are known and spread: a value measured warm is
  compared with one measured cold at one reference temperature, :func:`detect_change`), and their products with
  the change's regressor in the changed one (wear scales a friction level and its temperature slope alike); the
  onset is the ``k`` of the largest ``F_k``;
* its p-value, exact for this model whatever ``phi`` (``F_k`` does not depend on it): the share of
  :meth:`ChangeSettings.draws` series of pure noise ``se_i z_i`` (seeded: the same input gives the same
  output) whose largest ``F_k``, over the same shapes and onsets, reaches the observed one, on the same times and
  weights (the choice of shape paid for in the p-value).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime
from typing import Protocol

import numpy as np
from threadpoolctl import threadpool_limits

from wbfriction.fleet.options import Shape
from wbfriction.logs.options import PLAUSIBLE

DAY = 86_400.0
"""Seconds per day: the series' time unit."""



class ChangeSettings(Protocol):
    """What the test reads of its options (:class:`~wbfriction.fleet.trends.TrendOptions` has them)."""

    @property
    def min_points(self) -> int:
        """Fewer finite points: no test."""
        ...

    @property
    def min_before(self) -> int:
        """Points before a candidate onset."""
        ...

    @property
    def min_after(self) -> int:
        """Points from a candidate onset on."""
        ...

    @property
    def seed(self) -> int:
        """Of the p-value's noise series."""
        ...

    @property
    def shapes(self) -> tuple[Shape, ...]:
        """The shapes of change tested (:data:`SHAPES`)."""
        ...

    def draws(self) -> int:
        """Noise series of the p-value's Monte Carlo."""
        ...


@dataclass(frozen=True)
class ChangePoint:
    """The best change of one series (module docstring).

    Attributes:
        quantity: the series' quantity.
        onset: index (into the series' logs) of the first changed log; onset_time: its start time.
        baseline: the fitted value before the onset.
        change, change_se: the fitted change at the last log (a step's size, a hinge's drift by then), and its
            standard error (same unit).
        statistic: the largest ``F_k``; p_value: its Monte Carlo p-value.
        shape: ``hinge`` or ``step``, whichever fits better (module docstring).
        relative: ``change`` over the baseline (over F_c's baseline for ``tau_os``); NaN where the baseline is
            not told from zero (within two of its standard errors): a relative change is then meaningless, and
            :attr:`change` (in the quantity's unit, :data:`UNITS`) says it.
        reference_temperature: the temperature [°C] ``baseline`` and ``change`` are at, where the series' logs'
            temperatures entered the test (:func:`detect_change`); None: they did not.
        temperature_slope, temperature_slope_se: the value's change per °C found with the change, and its standard
            error (NaN without temperatures).
        temperature_note: why the series' temperatures did not enter its test although it has some (some logs
            without one; temperatures that cannot be told from a change, :func:`confounded_onset`), or "".
    """

    quantity: str
    onset: int
    onset_time: datetime
    baseline: float
    change: float
    change_se: float
    statistic: float
    p_value: float
    relative: float
    shape: Shape = "hinge"
    reference_temperature: float | None = None
    temperature_slope: float = float("nan")
    temperature_slope_se: float = float("nan")
    temperature_note: str = ""


def _regressor(shape: Shape, t: np.ndarray, k: int) -> np.ndarray:
    """The change's regressor for an onset at log ``k`` (module docstring)."""
    if shape == "step":
        return (np.arange(t.size) >= k).astype(float)
    return np.maximum(0.0, t - t[k - 1])


def _change_columns(shape: Shape, t: np.ndarray, k: int, w: np.ndarray, covariates: np.ndarray | None) -> np.ndarray:
    """The change's weighted columns for an onset at log ``k``: its regressor ``x_k``, and with covariates their
    products with it (the change scales what depends on them: a worn joint's friction falls with the temperature in
    proportion to its level)."""
    x = _regressor(shape, t, k)
    columns = [x * w] + ([] if covariates is None else [x * c * w for c in np.atleast_2d(covariates.T)])
    return np.column_stack(columns)


def candidate_onsets(t: np.ndarray, min_before: int, min_after: int, shape: Shape) -> np.ndarray:
    """The candidate onsets (c,) of one shape on times ``t`` (n,): ``min_before`` logs before, ``min_after`` from
    it on; not a hinge from the last log's time (zero at every log), nor a step between two logs at one time."""
    onsets = np.arange(min_before, t.size - min_after + 1)
    if shape == "hinge":
        return onsets[t[-1] > t[onsets - 1]]
    return onsets[t[onsets] > t[onsets - 1]]


def change_scan(t: np.ndarray, y: np.ndarray, se: np.ndarray, min_before: int, min_after: int,
                shape: Shape = "hinge", covariates: np.ndarray | None = None, fits: bool = True
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The statistics ``F_k`` of every candidate onset of one shape (module docstring) for the columns of ``y``.

    Args:
        t: (n,) increasing times [days]; y: (n,) or (n, r) values; se: (n,) standard errors (> 0).
        shape: ``hinge`` or ``step``.
        covariates: (n, m) what the values depend on besides the change, in both models (the logs' temperature
            less a reference: :func:`detect_change`), or None.

    Returns:
        ``(onsets, F, fits)``: the candidate onsets (c,), ``F`` (c,) or (c, r), and per onset the weighted
        least-squares coefficients (c, 2 + 2m) or (c, 2 + 2m, r) of ``[1, covariates, x_k, x_k covariates]``
        (baseline at zero covariates, the covariates' slopes, the slope per day of a hinge or the size of a step, and
        how the change scales the slopes). An onset whose
        hinge would be zero at every log (no log after the time of the one before it), or a step between two logs
        at one time, is no candidate: ``c`` may be 0. With ``fits`` False the coefficients are not solved for (a
        p-value's noise series need ``F`` alone): (c, 0) or (c, 0, r).
    """
    n = t.size
    w = 1.0 / se
    Y = (y if y.ndim == 2 else y[:, None]) * w[:, None]
    Z = np.column_stack([w] + ([] if covariates is None else [c * w for c in np.atleast_2d(covariates.T)]))
    # RSS_0: the null model's fit (the weighted mean, and the covariates') removed
    Q0, _ = np.linalg.qr(Z)
    r0 = Y - Q0 @ (Q0.T @ Y)
    rss0 = np.einsum("ij,ij->j", r0, r0)
    dof = n - 2 * Z.shape[1]
    yy = np.einsum("ij,ij->j", Y, Y)
    onsets = candidate_onsets(t, min_before, min_after, shape)
    F = np.empty((onsets.size, Y.shape[1]))
    coef = np.empty((onsets.size, 2 * Z.shape[1] if fits else 0, Y.shape[1]))  # [1, covariates], the change's as many
    for c, k in enumerate(onsets):
        X = np.column_stack([Z, _change_columns(shape, t, int(k), w, covariates)])
        Q, R = np.linalg.qr(X)
        QtY = Q.T @ Y
        rss = np.maximum(yy - np.einsum("ij,ij->j", QtY, QtY), 1e-300)
        F[c] = (rss0 - rss) / (rss / dof)
        if fits:
            coef[c] = np.linalg.solve(R, QtY)
    if y.ndim == 1:
        return onsets, F[:, 0], coef[:, :, 0]
    return onsets, F, coef


def hinge_scan(t: np.ndarray, y: np.ndarray, se: np.ndarray, min_before: int, min_after: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`change_scan` of the hinge."""
    return change_scan(t, y, se, min_before, min_after, "hinge")


FIRST_PASS = 1000
"""Noise series of the p-value's first pass: a statistic that :data:`CLEAR` of them reach is no drift, and the
full :meth:`ChangeSettings.draws` are drawn only for the others (most series of a fleet are constant)."""
CLEAR = 20


def null_p_value(t: np.ndarray, se: np.ndarray, statistic: float, options: ChangeSettings,
                 covariates: np.ndarray | None = None) -> float:
    """The share of series of pure noise ``se_i z_i`` on times ``t`` whose largest ``F_k`` (over the shapes of
    :attr:`ChangeSettings.shapes`) reaches ``statistic``
    (seeded by :attr:`ChangeSettings.seed`; ``(1 + hits) / (1 + draws)``): :data:`FIRST_PASS` series first, the
    rest of :meth:`ChangeSettings.draws` only when fewer than :data:`CLEAR` of them reached it, in blocks of
    :data:`BLOCK` series (memory bounded whatever the number). On one BLAS thread: the products of a scan's
    thousands of series are split by columns, the same numbers on any thread count, and two threads took four times
    the processor time (a 2-core machine running a test suite on both)."""
    with threadpool_limits(1, user_api="blas"):
        return _null_p_value(t, se, statistic, options, covariates)


def _null_p_value(t: np.ndarray, se: np.ndarray, statistic: float, options: ChangeSettings,
                  covariates: np.ndarray | None) -> float:
    rng = np.random.default_rng(options.seed)
    total = options.draws()
    hits, draws = 0, 0
    while draws < total and not (draws >= FIRST_PASS and hits >= CLEAR):
        size = min(FIRST_PASS if draws == 0 else BLOCK, total - draws)
        noise = se[:, None] * rng.standard_normal((t.size, size))
        largest = np.full(size, -np.inf)
        for shape in options.shapes:
            _, F_null, _ = change_scan(t, noise, se, options.min_before, options.min_after, shape, covariates,
                                       fits=False)
            if F_null.shape[0]:
                largest = np.maximum(largest, F_null.max(axis=0))
        hits += int(np.sum(largest >= statistic))
        draws += size
    return (1 + hits) / (1 + draws)


COLLINEAR = 1e-8
"""A design whose smallest singular value, its columns scaled to unit length, is below this share of its largest has
columns that one another make: its coefficients are not determined (:func:`confounded_onset`)."""


def confounded_onset(t: np.ndarray, se: np.ndarray, covariates: np.ndarray, options: ChangeSettings) -> int | None:
    """The first candidate onset (over :attr:`ChangeSettings.shapes`) at which the covariates cannot be told from the
    change: the test's design ``[1, covariates, x_k, x_k covariates]`` is singular (:data:`COLLINEAR`). Temperatures
    that take one value before the onset and another after it (two seasons, a lab moved) are a step; temperatures
    that follow the time are a hinge. None: every onset's design is regular."""
    w = 1.0 / se
    Z = np.column_stack([w] + [c * w for c in np.atleast_2d(covariates.T)])
    for shape in options.shapes:
        for k in candidate_onsets(t, options.min_before, options.min_after, shape):
            X = np.column_stack([Z, _change_columns(shape, t, int(k), w, covariates)])
            norms = np.linalg.norm(X, axis=0)
            if np.any(norms == 0.0):
                return int(k)
            sv = np.linalg.svd(X / norms, compute_uv=False)
            if sv[-1] < COLLINEAR * sv[0]:
                return int(k)
    return None


BLOCK = 50_000
"""Noise series drawn at a time after the first pass."""


TEMPERATURE_SPREAD = 1.0
"""The least standard deviation [°C] of a series' temperatures for them to enter its test as a covariate: logs
recorded at one temperature say nothing of its effect (and make the covariate the constant's twin)."""


def _temperature_covariate(t: np.ndarray, se: np.ndarray, time: list[datetime], T: np.ndarray,
                           options: ChangeSettings, reference_temperature: float | None
                           ) -> tuple[np.ndarray | None, float | None, str]:
    """The temperature covariate of a series' points (:func:`detect_change`): ``(covariates (n, 1), T_ref, "")``
    where it enters the test, else ``(None, None, note)`` with why not ("" where the temperatures do not spread)."""
    logged = np.isfinite(T)
    implausible = logged & ((T < PLAUSIBLE[0]) | (T > PLAUSIBLE[1]))
    if implausible.any():  # results written before logs were screened (kelvin)
        i = int(np.flatnonzero(implausible)[0])
        return None, None, (f"temperature left out: {T[i]:.6g} °C of the log at {time[i]:%Y-%m-%d %H:%M} is no "
                            f"joint's temperature ({PLAUSIBLE[0]:g} to {PLAUSIBLE[1]:g} °C; kelvin?)")
    if not logged.any():
        return None, None, ""
    if not logged.all():
        return None, None, (f"temperature left out: {int((~logged).sum())} of its {T.size} logs have none (each "
                            "value is compared at no one temperature)")
    if float(np.std(T)) < TEMPERATURE_SPREAD:
        return None, None, ""
    t_ref = float(np.median(T)) if reference_temperature is None else reference_temperature
    covariates = (T - t_ref)[:, None]
    k = confounded_onset(t, se, covariates, options)
    if k is not None:
        return None, None, (f"temperature left out: it cannot be told from a change at {time[k]:%Y-%m-%d} (the "
                            "logs' temperatures step or drift with the time there)")
    return covariates, t_ref, ""


def detect_change(time: list[datetime], y: np.ndarray, se: np.ndarray, quantity: str,
                  options: ChangeSettings, scale: float | None = None, temperature: np.ndarray | None = None,
                  reference_temperature: float | None = None) -> ChangePoint | None:
    """The best change of a series (over :attr:`ChangeSettings.shapes` and onsets) and its p-value (module
    docstring); None with too few finite points.

    Args:
        time: (n,) the points' times, increasing; y, se: (n,) values and standard errors (non-finite ones and
            non-positive standard errors are left out).
        quantity: the series' name, recorded.
        scale: the baseline the relative change is measured against (default: the fitted baseline).
        temperature: (n,) the temperature [°C] each point's value was measured at, or None. Where every point has
            one and they spread by :data:`TEMPERATURE_SPREAD` or more, the value's linear dependence on it enters
            both models (Bittencourt & Axelsson 2014: temperature changes friction more than wear does): the
            baseline and the change are then those at ``reference_temperature`` (default: the points' median),
            stated in :attr:`ChangePoint.reference_temperature` with the slope found. Where some points have none,
            one is no joint's (kelvin), or the temperatures cannot be told from a change (:func:`confounded_onset`),
            they are left out and :attr:`ChangePoint.temperature_note` says why.
    """
    ok = np.isfinite(y) & np.isfinite(se) & (se > 0)
    idx = np.flatnonzero(ok)
    if idx.size < max(options.min_points, options.min_before + options.min_after):
        return None
    t0 = time[idx[0]]
    t = np.array([(time[i] - t0).total_seconds() / DAY for i in idx])
    yy, ss = y[idx], se[idx]
    covariates, t_ref, note = None, None, ""
    if temperature is not None:
        covariates, t_ref, note = _temperature_covariate(t, ss, [time[i] for i in idx], temperature[idx], options,
                                                         reference_temperature)
    best: tuple[float, Shape, int, np.ndarray] | None = None
    for shape in options.shapes:
        onsets, F, coef = change_scan(t, yy, ss, options.min_before, options.min_after, shape, covariates)
        if onsets.size and (best is None or float(F.max()) > best[0]):
            c = int(np.argmax(F))
            best = (float(F[c]), shape, int(onsets[c]), coef[c])
    if best is None:  # the logs after the first candidate onset all at one time
        return None
    statistic, shape, k, b = best
    p = null_p_value(t, ss, statistic, options, covariates)
    # the change at the last log and its standard error, the residual scale phi estimated
    w = 1.0 / ss
    m = 0 if covariates is None else covariates.shape[1]
    X = np.column_stack([w] + ([] if covariates is None else [covariates[:, 0] * w])
                        + [_change_columns(shape, t, k, w, covariates)])
    resid = yy * w - X @ b
    phi = float(resid @ resid) / max(idx.size - X.shape[1], 1)
    cov = phi * np.linalg.inv(X.T @ X)
    at = 1 + m  # the change's coefficient: after the baseline and the slopes
    base, size = float(b[0]), float(b[at])
    at_last = float(X[-1, at] / w[-1])  # the regressor at the last log: the hinge's span, or 1
    change = float(size * at_last)
    if scale is None:  # against the fitted baseline, where it is told from zero
        ref = abs(float(base)) if abs(float(base)) > 2 * np.sqrt(cov[0, 0]) else 0.0
    else:
        ref = abs(scale) if np.isfinite(scale) else 0.0
    slope = (float(b[1]), float(np.sqrt(cov[1, 1]))) if covariates is not None else (float("nan"), float("nan"))
    return ChangePoint(quantity, int(idx[k]), time[idx[k]], base, change,
                       float(np.sqrt(cov[at, at]) * at_last), statistic, float(p),
                       change / ref if ref > 0 else float("nan"), shape, t_ref, *slope, note)

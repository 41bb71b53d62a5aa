"""The stance feet's velocity noise, read from their disagreement (issue 82, item 2; :mod:`.leg_odometry`).

Each confident stance foot gives the base's linear velocity (:func:`~wbfriction.signals.leg_odometry.
stance_velocities`); how far it is to be trusted is read from how far it disagrees with the other stance feet of its
sample. Two levels:

* **The stance level** (:func:`pooled_spread`): the robust spread of the feet about their mean over every sample with
  two feet or more, per world axis. Most stance samples are far from any touch-down or lift-off, so that this is the
  noise of a foot that stands: on noise-free joints and firm ground a fraction of a mm/s.
* **The transients** (:func:`stance_noise`): a foot that has just landed is still stopping (the contact's time
  constant, the impact), and a foot about to lift off is already unloading; an inferred flag can also be a sample or
  two early. Such a foot is off by far more than the stance level (on the firm twin 3-90 mm/s against 0.1-0.8). Its
  noise is read as a function of its distance in samples to its own touch-down (and, separately, to its own
  lift-off): each foot's deviation from the mean of the other feet of its sample (scaled by ``sqrt((n - 1) / n)``,
  the standard deviation of one of ``n`` equally noisy feet), robustly (1.4826 times the median absolute value) in
  bins of octaves of the distance (1, 2, 3-4, 5-8, ... samples: sample by sample where a transient changes fast,
  more samples pooled where it has settled, no width chosen); from the change outward while a bin's spread exceeds
  the stance level (the first that does not ends the transient: the foot is then a standing foot), made
  non-increasing away from the change (a transient does not grow away from its cause; the least-squares monotone
  fit weighted by their counts, SciPy's ``isotonic_regression``). A foot's noise is the larger of its two
  transients' and the stance level.

Without this, every foot near a touch-down is an outlier to the stance level: the chi-square gate
(:data:`~wbfriction.signals.leg_odometry.GATE`) rejects every foot of such samples and the smoother bridges them by
its model alone (on the firm twin's clean trot, contacts inferred, 38 % of the speed; 3.0 % with these levels).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import isotonic_regression

from wbfriction.signals.phases import true_runs


def pooled_spread(velocities: np.ndarray) -> np.ndarray:
    """The stance feet's velocity noise (3,) [m/s] per axis: their spread about their mean over the samples with two
    or more measuring feet (``velocities`` (N, n_c, 3), NaN for a foot not measuring), robustly: each deviation
    scaled by ``sqrt(n / (n - 1))`` (the mean of ``n`` takes ``1 / n`` of its variance), then 1.4826 times their
    median absolute value (a normal's standard deviation; a foot slipping or landing does not count); NaN where no
    sample has two."""
    n = np.sum(np.isfinite(velocities[..., 0]), axis=1)
    rows = n >= 2
    if not rows.any():
        return np.full(3, np.nan)
    v = velocities[rows]
    deviation = (v - np.nanmean(v, axis=1, keepdims=True)) * np.sqrt(n[rows] / (n[rows] - 1))[:, None, None]
    return 1.4826 * np.nanmedian(np.abs(deviation).reshape(-1, 3), axis=0)


def run_distances(measuring: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each measuring sample's distance [samples] to its foot's own start and end of measuring (touch-down and
    lift-off), ``(after, before)`` (N, n_c): 1 at the first (last) sample of a run; inf for a run that starts (ends)
    with the log (no change seen); NaN where the foot does not measure (``measuring`` (N, n_c) bool)."""
    n = len(measuring)
    after, before = np.full(measuring.shape, np.nan), np.full(measuring.shape, np.nan)
    for c in range(measuring.shape[1]):
        for a, b in true_runs(measuring[:, c]):
            after[a:b, c] = np.arange(1, b - a + 1) if a > 0 else np.inf
            before[a:b, c] = np.arange(b - a, 0, -1) if b < n else np.inf
    return after, before


def leave_one_out(velocities: np.ndarray) -> np.ndarray:
    """Each measuring foot's deviation from the mean of the other measuring feet of its sample (N, n_c, 3) [m/s],
    scaled by ``sqrt((n - 1) / n)`` (``n`` feet equally noisy: the foot's own standard deviation); NaN where the foot
    does not measure or measures alone."""
    measuring = np.isfinite(velocities[..., 0])
    n = measuring.sum(axis=1)
    v = np.where(measuring[..., None], velocities, 0.0)
    others = (v.sum(axis=1, keepdims=True) - v) / np.maximum(n - 1, 1)[:, None, None]
    out = (velocities - others) * np.sqrt(np.maximum(n - 1, 1) / np.maximum(n, 1))[:, None, None]
    out[n < 2] = np.nan
    return out


def transient(deviation: np.ndarray, distance: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """The noise (M, 3) [m/s] of M measuring feet at ``distance`` (M,) samples from their change (inf: none), from
    their deviations (M, 3) (NaN: not known) (module docstring): octaves of the distance from the change outward
    while their robust spread exceeds ``floor`` (3,), non-increasing; ``floor`` beyond."""
    finite = np.isfinite(distance)
    octave = np.full(len(distance), -1)
    octave[finite] = np.ceil(np.log2(distance[finite])).astype(int)
    known = np.isfinite(deviation[:, 0])
    out = np.tile(np.asarray(floor, dtype=float), (len(distance), 1))
    for axis in range(3):
        spreads, counts, bins = [], [], []
        for j in range(int(octave.max()) + 1):
            rows = known & (octave == j)
            if not rows.any():
                continue
            spread = 1.4826 * float(np.median(np.abs(deviation[rows, axis])))
            if not spread > floor[axis]:
                break
            spreads.append(spread)
            counts.append(int(rows.sum()))
            bins.append(j)
        if not spreads:
            continue
        fit = isotonic_regression(np.array(spreads), weights=np.array(counts, dtype=float), increasing=False).x
        for j, sd in zip(bins, fit):
            out[octave == j, axis] = sd
    return out


def stance_noise(velocities: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Each measuring foot's velocity noise (N, n_c, 3) [m/s] per world axis (module docstring): the larger of the
    stance level ``floor`` (3,) (:func:`pooled_spread`) and its transients after its touch-down and before its
    lift-off; NaN where the foot does not measure (``velocities`` (N, n_c, 3), NaN there)."""
    measuring = np.isfinite(velocities[..., 0])
    deviation = leave_one_out(velocities)[measuring]
    out = np.full(velocities.shape, np.nan)
    out[measuring] = floor
    for distance in run_distances(measuring):
        out[measuring] = np.fmax(out[measuring], transient(deviation, distance[measuring], floor))
    return out

"""Streams at several rates in one table: each column group sampled by its own source, put on the joints' clock.

A robot's logger writes every source on each of its rows: the drives' joints, the IMU, the feet's force counts.
A source slower than the logger repeats its last sample on the rows in between, at its own rate (78 % of an IMU's
rows where the joints repeat 56 %). Each stream's repeats are found on its own columns
(:func:`~wbfriction.logs.repeats.find_repeats`), its distinct samples' times re-estimated from its own runs, and
its values resampled at the joints' sample times by linear interpolation (:func:`resample`), so that no signal is
taken at another's instant. An angle (``imu.roll``, ``imu.pitch``, ``imu.yaw``) is unwrapped before it is
interpolated and wrapped back after; a quaternion (``imu.qx`` ... ``imu.qw``) is kept on one hemisphere, then
interpolated and normalised. Before a stream's first sample or after its last, its nearest sample is held.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

STREAMS: dict[str, tuple[str, ...]] = {"imu": ("imu",), "foot_count": ("foot_count",)}
"""The streams other than the joints', by name: the column prefixes each one's columns carry."""
ANGLE_COLUMNS = ("imu.roll", "imu.pitch", "imu.yaw")
"""Columns that are angles [rad], unwrapped before they are interpolated."""
QUATERNION_COLUMNS = ("imu.qx", "imu.qy", "imu.qz", "imu.qw")
"""A unit quaternion's columns (x, y, z, w): one hemisphere, normalised after interpolation."""


def stream_columns(names: Sequence[str], stream: str) -> list[str]:
    """The columns of ``names`` that belong to ``stream`` (:data:`STREAMS`), in their order."""
    prefixes = STREAMS[stream]
    return [n for n in names if n.partition(".")[0] in prefixes]


def resample(times: np.ndarray, values: np.ndarray, at: np.ndarray, names: Sequence[str]) -> np.ndarray:
    """A stream's samples ``values`` (K, m) taken at ``times`` (K,) [s], linearly interpolated at ``at`` (M,) [s].

    Args:
        names: the m columns' names: those in :data:`ANGLE_COLUMNS` are unwrapped first and wrapped back to
            (-pi, pi] after; the four of :data:`QUATERNION_COLUMNS`, if all there, kept on one hemisphere and
            normalised after.

    Returns:
        (M, m) float64; outside ``[times[0], times[-1]]`` the nearest sample is held.
    """
    values = np.array(values, dtype=float, copy=True)
    names = list(names)
    angles = [i for i, n in enumerate(names) if n in ANGLE_COLUMNS]
    if angles:
        values[:, angles] = np.unwrap(values[:, angles], axis=0)
    quat = [names.index(n) for n in QUATERNION_COLUMNS] if all(n in names for n in QUATERNION_COLUMNS) else []
    if quat:
        values[:, quat] = hemisphere(values[:, quat])
    out = np.column_stack([np.interp(at, times, values[:, i]) for i in range(values.shape[1])]) \
        if values.shape[1] else np.empty((len(at), 0))
    if angles:
        out[:, angles] = np.angle(np.exp(1j * out[:, angles]))
    if quat:
        out[:, quat] /= np.linalg.norm(out[:, quat], axis=1, keepdims=True)
    return out


def hemisphere(quat: np.ndarray) -> np.ndarray:
    """Unit quaternions (K, 4) with each one's sign chosen nearest the previous one (q and -q are one
    orientation: interpolating between opposite signs passes through zero)."""
    quat = np.array(quat, dtype=float, copy=True)
    if len(quat) < 2:
        return quat
    flip = np.sum(quat[1:] * quat[:-1], axis=1) < 0
    sign = np.concatenate([[1.0], np.cumprod(np.where(flip, -1.0, 1.0))])
    return quat * sign[:, None]

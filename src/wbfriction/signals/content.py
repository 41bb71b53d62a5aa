"""The positions' acceleration content and white noise, read from their spectrum (thesis 7.1, Fig. 7.1): what
:func:`~wbfriction.signals.choice.choose_differentiation` measures before it chooses (its module docstring, step 1).

The acceleration of the positions by central second differences holds the motion at low frequencies and the
position noise above it (:func:`second_difference_gain`); :func:`acceleration_content` splits their averaged,
Hann-tapered spectrum into the two (:class:`AccelerationContent`), and :func:`white_position_noise` reads the
position noise from short frames, robust to a walk's impacts (:func:`contact_changes`: the rows where they are).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from wbfriction.exceptions import InputError
from wbfriction.signals.spectrum import amplitude_spectrum, longest_run, periodic_hann, suggest_cutoff

SEGMENT = 1.0
"""Length of the averaged spectrum's segments [s] (its frequency resolution: 1 / SEGMENT)."""
MIN_SEGMENT = 64
"""Fewest samples per segment."""
MIN_SEGMENTS = 7
"""Fewest half-overlapping segments averaged (the segment is shortened to reach it)."""
NOISE_MARGIN = 2.0
"""Content is the amplitude above this many times the noise model (averaged over 7 or more
segments, a noise bin's power exceeds 4 times its mean with a probability below 1e-4)."""
FRAME = 128
"""Samples per frame of :func:`white_position_noise` (half-overlapping, Hann-tapered): short enough that a
walk's impacts, a few samples each, spoil few of them (at 1 kHz, two frames of the 12 of a 0.8 s step), long
enough that a motion's content leaks into the upper half of the band by about 1e-5 of its amplitude (sines of
1-20 Hz at 1 kHz: 1e-11 rad of position noise where there is none)."""


# ------------------------------------------------------------------ the positions' spectrum
def second_difference_gain(freq: np.ndarray, dt: float) -> np.ndarray:
    """Amplitude gain ``|G(f)| = 4 sin^2(pi f dt) / dt^2`` [1/s^2] of the central second
    difference (6.2) at ``freq`` (F,) [Hz]: white position noise of standard deviation
    ``sigma`` comes out with the amplitude ``sigma |G|`` (up to the spectrum's scale)."""
    return 4.0 * np.sin(np.pi * np.asarray(freq, dtype=float) * dt) ** 2 / dt**2


def tapered_gain(gain: np.ndarray) -> np.ndarray:
    """The amplitude gain ``gain`` (F,) of white noise on the DFT bins 0 ... L/2 of a segment of even
    length L, as a Hann-tapered spectrum sees it: the periodic Hann window's DFT is L/2 at 0 and -L/4 at
    +-1 bin, so the expected power of bin k mixes its neighbours,
    ``sqrt((4 G_k^2 + G_{k-1}^2 + G_{k+1}^2) / 6)`` (the spectrum mirrored at 0 Hz and at the Nyquist
    frequency). Where ``G`` varies slowly that is ``G``; near 0 Hz, where the second difference's gain
    rises as ``f^2``, it is not: at 1 bin 1.8 times ``G``, and at 0 Hz not 0."""
    g2 = np.asarray(gain, dtype=float) ** 2
    mirrored = np.r_[g2[1], g2, g2[-2]]
    return np.sqrt((4.0 * g2 + mirrored[:-2] + mirrored[2:]) / 6.0)


def white_position_noise(acc: np.ndarray, dt: float, frame: int = FRAME, changes: np.ndarray | None = None
                         ) -> np.ndarray:
    """The white position noise ``sigma`` (n,) [rad] in the central second differences ``acc`` (N, n) [rad/s^2]
    of positions sampled every ``dt`` [s], robust to sparse events (:mod:`~wbfriction.signals.choice`, step 1): per
    half-overlapping Hann-tapered frame of ``frame`` samples, the median over the upper half of the band of
    ``(amplitude / |G|)^2`` (a white noise's power per bin is exponential: its median is ``ln 2`` times its mean),
    then the median over the frames. Fewer rows than a frame: one frame of them all (even length).

    ``changes`` (N + 2,): the position rows where a contact flag changes (:func:`contact_changes`): the second
    differences that straddle one (a touch-down's velocity step) are left out of their frames (zeroed, each frame's
    power scaled back by its taper's share kept). A trot's feet switch every 0.25 s, so that every frame of a
    500 Hz log held an impact and the median over frames measured the impacts (8e-5 rad on the ideal trot, against
    the 3.5e-6 rad of its 19-bit encoders; 3.8e-6 with them left out). Where every frame straddles changes (flags
    that flicker), nothing is measured: NaN."""
    acc = np.asarray(acc, dtype=float)
    length = min(frame, len(acc) - len(acc) % 2)
    taper = periodic_hann(length)
    kept = np.ones(len(acc))
    if changes is not None:
        for k in np.flatnonzero(changes):  # a step between rows k - 1 and k: in acc[k - 2], acc[k - 1], one each side
            kept[max(k - 3, 0):max(k + 1, 0)] = 0.0
        acc = acc * kept[:, None]
    frames = sliding_window_view(acc, length, axis=0)[::length // 2]  # (M, n, L)
    share = (sliding_window_view(kept, length)[::length // 2] @ taper**2) / np.sum(taper**2)  # (M,)
    tapered = np.moveaxis(frames, -1, 0) * taper[:, None, None]
    freq, amp = amplitude_spectrum(tapered, dt)  # (F, M, n)
    gain = tapered_gain(second_difference_gain(freq, dt))
    upper = freq >= freq[-1] / 2
    per_frame = np.median((amp[upper] / gain[upper, None, None]) ** 2, axis=0) / math.log(2.0)  # (M, n)
    if changes is not None:  # a frame mostly left out measures little
        counted = share > 0.5 if np.any(share > 0.5) else share > 0
        if not np.any(counted):  # every frame straddles contact changes (flags that flicker): nothing measured
            return np.full(acc.shape[1], np.nan)
        per_frame = per_frame[counted] / share[counted, None]
    # E amp^2 of white noise through a Hann taper: 4 sigma^2 |G|^2 sum(w^2) / L^2, sum(w^2) = 3 L / 8
    return np.sqrt(np.median(per_frame, axis=0) * length / 1.5)


def contact_changes(contact: np.ndarray | None) -> np.ndarray | None:
    """(N,) the rows where some contact flag differs from the row before (a touch-down's impact, a lift-off), or None
    without flags or change (a fixed base, a log that stays in one phase)."""
    if contact is None or contact.ndim != 2 or not contact.shape[1] or len(contact) < 2:
        return None
    out = np.zeros(len(contact), dtype=bool)
    out[1:] = np.any(contact[1:] != contact[:-1], axis=1)
    return out if out.any() else None


@dataclass
class AccelerationContent:
    """The averaged acceleration spectrum of some positions, split into content and noise.

    Attributes:
        freq: frequencies (F,) [Hz].
        amplitude: power-averaged amplitude spectrum of the central second difference (F, n)
            [rad/s^2] (Hann-tapered segments: a sine of amplitude A shows as about A / 2).
        noise: the white-noise model's amplitude (F, n) [rad/s^2] (:func:`tapered_gain`).
        excess: the content: amplitude above ``margin`` times the noise model (F, n) [rad/s^2].
        content_end: where each joint's content ends (n,) [Hz] (the Nyquist frequency for a
            joint without content).
        position_noise: standard deviation of the white position noise (n,) [rad]
            (:func:`white_position_noise`: not the level of ``noise``, which a walk's impacts raise).
        moving: joints with content (n,).
        segment: samples per segment; n_segments: segments averaged.
    """

    freq: np.ndarray
    amplitude: np.ndarray
    noise: np.ndarray
    excess: np.ndarray
    content_end: np.ndarray
    position_noise: np.ndarray
    moving: np.ndarray
    segment: int
    n_segments: int


def _segment_length(n: int, dt: float, segment: float) -> int:
    want = max(int(round(segment / dt)), MIN_SEGMENT)
    fit = 2 * n // (MIN_SEGMENTS + 1)  # half-overlapping: 2 n / L - 1 segments
    length = min(want, fit)
    return length - length % 2


def acceleration_content(q: np.ndarray, dt: float, tail: float = 0.01, segment: float = SEGMENT,
                         margin: float = NOISE_MARGIN, changes: np.ndarray | None = None) -> AccelerationContent:
    """Content and noise of the acceleration of positions ``q`` (N, n) or (N,) [rad] sampled
    every ``dt`` [s] (:mod:`~wbfriction.signals.choice`, step 1), over their longest run of finite rows;
    ``changes`` (N,): the rows where a contact flag changes, left out of the noise (:func:`white_position_noise`).

    Raises:
        InputError: fewer than ``MIN_SEGMENT (MIN_SEGMENTS + 1) / 2 + 2`` = 258 finite rows
            in a row, a non-positive ``dt`` or ``segment``, ``tail`` outside (0, 1).
    """
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[:, None]
    if not (dt > 0 and segment > 0):
        raise InputError(f"differentiation choice: the sample period and segment must be > 0, got {dt}, {segment}")
    a, b = longest_run(np.all(np.isfinite(q), axis=1))
    seg = _segment_length(b - a - 2, dt, segment)
    if seg < MIN_SEGMENT:
        raise InputError(f"differentiation choice: {b - a} consecutive finite samples, need at least "
                         f"{MIN_SEGMENT * (MIN_SEGMENTS + 1) // 2 + 2}")
    x = q[a:b]
    acc = (x[2:] - 2.0 * x[1:-1] + x[:-2]) / dt**2
    windows = sliding_window_view(acc, seg, axis=0)[::seg // 2]  # (M, n, seg)
    tapered = np.moveaxis(windows, -1, 0) * periodic_hann(seg)[:, None, None]
    freq, amp = amplitude_spectrum(tapered, dt)  # (F, M, n)
    amp = np.sqrt(np.mean(amp**2, axis=1))
    gain = tapered_gain(second_difference_gain(freq, dt))
    upper = freq >= freq[-1] / 2
    level = np.median(amp[upper] / gain[upper, None], axis=0)  # (n,)
    noise = level[None, :] * gain[:, None]
    excess = np.sqrt(np.clip(amp**2 - (margin * noise) ** 2, 0.0, None))
    moving = np.sum(excess**2, axis=0) > 0
    ends = np.array([suggest_cutoff(freq, excess[:, i], tail) if moving[i] else float(freq[-1])
                     for i in range(amp.shape[1])])
    return AccelerationContent(freq, amp, noise, excess, ends,
                               white_position_noise(acc, dt, changes=None if changes is None else changes[a:b]),
                               moving, seg, windows.shape[0])


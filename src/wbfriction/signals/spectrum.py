"""Amplitude spectrum of the estimated joint acceleration, and the cutoff it suggests (thesis Fig. 7.1).

The thesis tunes the low-pass of the measured acceleration on the spectrum of the
*estimated* one, ``qdd_est`` of (5.10): computed by the model from the measured torques, it
is far less disturbed than the twice-differentiated positions, and it shows where the
motion's content ends. Above it there is nothing to keep
(:func:`suggest_cutoff`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.model.dynamics import constrained_dynamics
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.signals.filters import finite_runs
from wbfriction.signals.kinematics import measure


def periodic_hann(length: int) -> np.ndarray:
    """The periodic Hann window (length,), ``0.5 - 0.5 cos(2 pi k / length)``: ``scipy.signal.windows.hann(length,
    sym=False)`` to the last bit (the same operations), without importing ``scipy.signal``."""
    if length <= 1:
        return np.ones(max(length, 0))
    angle = np.linspace(-np.pi, np.pi, length + 1)
    w = np.zeros(length + 1)
    for k, a in enumerate((0.5, 0.5)):  # scipy's general cosine window, term by term
        w += a * np.cos(k * angle)
    return w[:-1]


def amplitude_spectrum(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of ``x`` (N_samples, ...) along axis 0 (Fig. 7.1).

    The mean is removed; a sine of amplitude A at a bin frequency shows as A.

    Returns:
        ``(freq [Hz] (N//2 + 1,), amplitude (N//2 + 1, ...))`` in the units of ``x``.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    amp = np.abs(np.fft.rfft(x - x.mean(axis=0), axis=0)) * 2.0 / n
    amp[0] /= 2.0
    return np.fft.rfftfreq(n, dt), amp


DIP_WIDTH = 2.0
"""Band [Hz] the spectrum is smoothed over to find where its content dips below a broadband floor."""
DIP_DEPTH = 0.5
"""A dip is the smoothed amplitude below this share of the floor (a noisy floor's smoothed amplitude stays near
it)."""


def suggest_cutoff(freq: np.ndarray, amp: np.ndarray, tail: float = 0.01) -> float:
    """Where the content of one amplitude spectrum ends [Hz] (Fig. 7.1): the frequency below
    which all but ``tail`` of its power above the noise floor lies.

    The noise floor is the median amplitude over the upper half of the band. Above the
    returned frequency the spectrum holds no distinguishable content: a low-pass cutoff for
    the measured acceleration. (The thesis read 10 Hz off the spectra of TORO's walk.) When a broadband
    floor holds most of the power (a noisy log), the content ends where the smoothed spectrum first dips
    below half the floor, if it does before.

    Args:
        freq, amp: from :func:`amplitude_spectrum` (one joint).
        tail: share of the power left above the cutoff.

    Raises:
        InputError: a spectrum with fewer than 8 bins, or ``tail`` outside (0, 1).
    """
    freq, amp = np.asarray(freq), np.asarray(amp)
    if freq.size < 8:
        raise InputError("spectrum: too few samples to suggest a cutoff")
    if not 0 < tail < 1:
        raise InputError(f"spectrum: the power share left above the cutoff must be in (0, 1), got {tail}")
    floor = float(np.median(amp[freq >= freq[-1] / 2]))
    power = np.clip(amp**2 - floor**2, 0.0, None)
    power[0] = 0.0
    total = power.sum()
    if total <= 0:
        return float(freq[-1])
    end = float(freq[np.searchsorted(np.cumsum(power), (1.0 - tail) * total)])
    # a broadband floor (noise, or a vibration the controller makes of it) can hold most of the power: the
    # content then ends where the spectrum, smoothed over DIP_WIDTH, first dips below half the floor
    bins = max(3, int(round(DIP_WIDTH / (freq[1] - freq[0]))))
    smooth = np.sqrt(np.convolve(amp**2, np.ones(bins) / bins, mode="same"))
    dip = np.flatnonzero((smooth < DIP_DEPTH * floor) & (freq > bins * (freq[1] - freq[0])))
    return min(end, float(freq[dip[0]])) if dip.size else end


MIN_SAMPLES = 64
"""Fewest consecutive samples a spectrum is computed over."""
BROADBAND = 0.5
"""Share of the Nyquist frequency from which a spectrum's content is broadband: no cutoff to suggest."""


def longest_run(mask: np.ndarray) -> tuple[int, int]:
    """The longest run of True values of ``mask`` (N,), as ``[a, b)``; ``(0, 0)`` if there is none."""
    runs = finite_runs(np.where(mask, 0.0, np.nan))
    return max(runs, key=lambda r: r[1] - r[0]) if runs else (0, 0)


def joint_spectra(x: np.ndarray, dt: float, tail: float = 0.01) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Amplitude spectra of the columns of ``x`` (N, n) and the cutoff each suggests.

    Returns:
        ``(freq [Hz] (F,), amplitude (F, n), cutoff [Hz] (n,))`` (:func:`amplitude_spectrum`,
        :func:`suggest_cutoff`).
    """
    freq, amp = amplitude_spectrum(x, dt)
    cutoff = np.array([suggest_cutoff(freq, amp[:, i], tail) for i in range(amp.shape[1])])
    return freq, amp, cutoff


@dataclass
class AccelerationSpectrum:
    """Spectra of the estimated acceleration of some joints.

    Attributes:
        joints: joint names (n,).
        freq: frequencies (F,) [Hz].
        amplitude: one-sided amplitude spectra (F, n) [rad/s^2].
        cutoff: suggested cutoff per joint (n,) [Hz].
        span: (start, stop) times of the stretch analysed [s].
    """

    joints: tuple[str, ...]
    freq: np.ndarray
    amplitude: np.ndarray
    cutoff: np.ndarray
    span: tuple[float, float]

    @property
    def suggestion(self) -> float:
        """One cutoff for all the joints: the median of theirs [Hz] (robust to a joint whose
        estimated acceleration carries impacts; the thesis read its 10 Hz off representative
        joints, the knee and the hip pitch)."""
        return float(np.median(self.cutoff))

    @property
    def nyquist(self) -> float:
        """The highest frequency of the spectra [Hz]."""
        return float(self.freq[-1])

    @property
    def cutoff_found(self) -> bool:
        """Whether the content ends well inside the band (below :data:`BROADBAND` of the Nyquist frequency): a
        low-pass filter there removes what lies above it. Content that reaches the top of the band (noise the
        controller turned into motion, a broadband vibration) has no cutoff to suggest."""
        return self.suggestion < BROADBAND * self.nyquist

    @property
    def shown_band(self) -> float:
        """The highest frequency a figure of the spectra shows [Hz]: every joint's cutoff with a margin, at
        least 50 Hz (the thesis's Fig. 7.1), at most the Nyquist frequency."""
        return float(min(self.nyquist, max(50.0, 1.25 * float(np.max(self.cutoff)))))


def acceleration_spectrum(robot: Robot, log: Log, joints: list[str] | None = None, tail: float = 0.01,
                          progress: Progress | None = None) -> AccelerationSpectrum:
    """Spectrum of ``qdd_est`` (5.10) per joint over the longest stretch with a foot on the ground.

    Args:
        robot: the robot; log: a validated log.
        joints: torque-controlled joints to analyse (default: all of them).
        tail: share of the power left above the suggested cutoff
            (:func:`suggest_cutoff`).
        progress: optional callable receiving numbers of samples done.

    Raises:
        InputError: an unknown joint, or fewer than 64 samples with a foot on the ground.
    """
    names = list(robot.torque_controlled) if joints is None else list(joints)
    unknown = [j for j in names if j not in robot.torque_controlled]
    if unknown:
        raise InputError(f"{log.source}: '{unknown[0]}' is not a torque-controlled joint of {robot.name}")
    kin = measure(log, "central")
    assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
    a, b = longest_run(kin.valid & kin.contact.any(axis=1))
    if b - a < MIN_SAMPLES:
        raise InputError(f"{log.source}: fewer than 64 consecutive samples with a foot on the ground")
    rows = slice(a, b)
    dyn = constrained_dynamics(robot, kin.q[rows], kin.qd[rows], kin.qdd[rows], kin.tau[rows], kin.contact[rows],
                               None if kin.base is None else kin.base[rows], with_Mmod_inv=False, progress=progress)
    cols = [robot.actuated.index(j) for j in names]
    freq, amp, cutoff = joint_spectra(dyn.qdd_est[:, cols], log.dt, tail)
    return AccelerationSpectrum(tuple(names), freq, amp, cutoff, (float(log.time[a]), float(log.time[b - 1])))

"""Choosing the differentiation from the data: the scheme, its window or cutoff, and why (thesis 7.1, Fig. 7.1).

A fixed default fails on some log: central differences (6.2) drown a noisy 1 kHz encoder's
acceleration in noise, a long filter costs samples at every contact change and bends a fast
motion. :func:`choose_differentiation` reads the positions and decides, deterministically:

1. **Content and noise** (:mod:`wbfriction.signals.content`). The acceleration of the positions by central second
   differences holds the motion at low frequencies and the position noise above it: white position noise
   of standard deviation ``sigma`` [rad] leaves the second difference with the amplitude
   ``sigma |G(f)|``, ``G(f) = 4 sin^2(pi f dt) / dt^2``, which rises as ``f^2``. The amplitude
   spectrum (:func:`~wbfriction.signals.spectrum.amplitude_spectrum`) is averaged in power
   over half-overlapping Hann-tapered segments (Welch's method), so that a noise bin rarely
   stands out; the taper mixes each bin with its neighbours
   (:func:`~wbfriction.signals.content.tapered_gain`: near 0 Hz the noise is not ``sigma |G|``); the noise level
   is read from the median of ``amplitude / |G|`` over the upper half of the band; what stands above
   :data:`~wbfriction.signals.content.NOISE_MARGIN` times that noise model is the content, and
   :func:`~wbfriction.signals.spectrum.suggest_cutoff` finds where it ends
   (all but ``tail`` of its power below): where the spectrum meets the noise floor. The
   position noise ``sigma`` itself is read the same way from short frames
   (:data:`~wbfriction.signals.content.FRAME` samples), each frame's upper band on its own, and is the median over
   the frames (:func:`~wbfriction.signals.content.white_position_noise`): a velocity step (a foot's impact, a
   simulator's projection at touch-down) is white in the second difference too, and a whole segment's spectrum
   would count a walk's impacts as noise (on an exact simulated walk, a hip's ``sigma`` of 7e-6 rad against 2e-8
   rad of the joints that do not touch the ground).
2. **Noise left.** Each scheme leaves ``sigma`` times its noise gain in the acceleration (RMS):
   ``sqrt(6) / dt^2`` for central differences, the norm of the Savitzky-Golay second-derivative
   kernel (7.7-7.8), the forward-backward Butterworth's (7.1.2) ``|B(f)|^2`` over the central
   difference integrated over the band.
3. **The choice.** Central differences when they leave at most ``target`` (default
   :data:`NOISE_TARGET`); else the least filtering that does: the shortest Savitzky-Golay window
   (order ``k``) or the highest Butterworth cutoff (one pass, -3 dB). The window's -3 dB
   frequency is computed from its impulse response (:func:`savgol_cutoff`; Schafer's
   ``f_3dB ~ (k + 1) / (3.2 L - 4.6) fs`` is the start of :func:`savgol_window`: R. W.
   Schafer, "What is a Savitzky-Golay filter?", IEEE Signal Processing Magazine 28(4), 2011).
   Savitzky-Golay is the default family: at the same -3 dB frequency its window is about three
   times shorter than the Butterworth's impulse response (the 1 % tail of
   :attr:`~wbfriction.signals.filters.ZeroPhaseLowpass.half_width`: 240 samples at 10 Hz and
   1 kHz against 76), so it loses fewer samples at every contact change, and the Butterworth's
   padding at the ends of every run lets the position noise in there.

The content's end is reported, not obeyed: cutting at it, the first design, measured worse.
On the simulated combined walk (TALOS, 10 steps per direction, Table 6.1 friction on the leg
joints, 1 kHz, 19-bit encoders, 0.05 N·m torque noise; the velocity filtered and central
differences in the filter's margins; worst leg F_v error, mean over noise seeds 3-5) the
simulator's torques, held over each 1 ms step, put real content up to 100 Hz,
and the window cut there (17 samples) gave 9.9 %, against 5.8 / 4.2 / 4.1 % for 31 / 51 / 101
samples; with 1e-4 rad of position noise, windows of 101 / 151 / 171 / 201 / 251 samples
(noise left 0.092 / 0.034 / 0.025 / 0.016 / 0.009 rad/s^2) gave 42 / 16 / 25 / 27 / 42 %: too
little filtering lets noise in, more loses samples and bends the motion. The noise target of
0.03 rad/s^2 picks 159 and 39 samples there (19.8 % and 4.8 %), 65 samples with 1e-5 rad
(5.2 %), and central differences on the exact log (its impacts are not noise:
:func:`~wbfriction.signals.content.white_position_noise`).

Every choice is printable (:attr:`DiffChoice.reason`), carries the numbers behind it
(:meth:`DiffChoice.to_dict`), and is overridden by passing the scheme and its options explicitly.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields, replace
from typing import Any, Literal, get_args

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.logs.clock import longest_segment
from wbfriction.logs.log import Log
from wbfriction.signals.content import SEGMENT, acceleration_content, contact_changes, second_difference_gain
from wbfriction.signals.filters import ZeroPhaseLowpass, savgol_kernels
from wbfriction.signals.options import NOISE_TARGET, FilterOptions, SavgolWeights

ChosenScheme = Literal["central", "savgol", "butterworth"]
"""What :func:`choose_differentiation` picks."""
Preference = Literal["auto", "savgol", "butterworth"]
"""The filter family to use when a filter is needed; ``auto``: Savitzky-Golay (module docstring)."""
PREFERENCES: tuple[Preference, ...] = get_args(Preference)


# ---------------------------------------------------------------------- schemes' noise gains
def central_noise_gain(dt: float) -> float:
    """RMS acceleration [1/s^2] the central second difference (6.2) makes of unit white position
    noise: ``sqrt(1 + 4 + 1) / dt^2``."""
    return math.sqrt(6.0) / dt**2


def savgol_noise_gain(window: int, order: int, dt: float, weights: SavgolWeights = "uniform") -> float:
    """RMS acceleration [1/s^2] the Savitzky-Golay second derivative (7.7-7.8) makes of unit
    white position noise: the norm of its kernel."""
    return float(np.linalg.norm(savgol_kernels(window, order, dt, weights)[2]))


def butterworth_noise_gain(cutoff: float, order: int, dt: float, n_freq: int = 4097) -> float:
    """RMS acceleration [1/s^2] the ``butterworth`` scheme (the central second difference run
    forward and backward through the low-pass, 7.1.2) makes of unit white position noise:
    ``sqrt(2 dt int_0^{fs/2} (|B(f)|^2 |G(f)|)^2 df)`` on ``n_freq`` frequencies (trapezoids)."""
    from scipy.signal import sosfreqz
    freq = np.linspace(0.0, 0.5 / dt, n_freq)
    _, b = sosfreqz(ZeroPhaseLowpass(cutoff, order, dt).sos, worN=freq, fs=1.0 / dt)
    power = (np.abs(b) ** 2 * second_difference_gain(freq, dt)) ** 2
    return math.sqrt(2.0 * dt * float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(freq))))


def butterworth_velocity_gain(cutoff: float, order: int, dt: float, n_freq: int = 4097) -> float:
    """RMS velocity [1/s] the ``butterworth`` scheme (the central first difference through the forward-backward
    low-pass) makes of unit white position noise: ``sqrt(2 dt int_0^{fs/2} (|B(f)|^2 |D(f)|)^2 df)``,
    ``|D(f)| = sin(2 pi f dt) / dt``."""
    from scipy.signal import sosfreqz
    freq = np.linspace(0.0, 0.5 / dt, n_freq)
    _, b = sosfreqz(ZeroPhaseLowpass(cutoff, order, dt).sos, worN=freq, fs=1.0 / dt)
    power = (np.abs(b) ** 2 * np.sin(2.0 * np.pi * freq * dt) / dt) ** 2
    return math.sqrt(2.0 * dt * float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(freq))))


# --------------------------------------------------------------------- Savitzky-Golay windows
def savgol_cutoff(window: int, order: int, dt: float, weights: SavgolWeights = "uniform") -> float:
    """-3 dB frequency [Hz] of the Savitzky-Golay smoother (value at the centre of the local fit,
    7.7-7.8), from its impulse response: the first frequency where its gain falls to 1/sqrt(2)
    (the Nyquist frequency if it never does).

    Raises:
        InputError: a window, order or weights that make no filter.
    """
    from scipy.optimize import brentq
    h = savgol_kernels(window, order, dt, weights, max_deriv=0)[0]
    m = np.arange(len(h)) - len(h) // 2
    half_power = 1.0 / math.sqrt(2.0)

    def gain(f: np.ndarray | float) -> np.ndarray:  # the symmetric kernel's response is real
        return np.cos(2.0 * np.pi * np.multiply.outer(f, m) * dt) @ h

    nyquist = 0.5 / dt
    top = min(nyquist, 4.0 * (order + 1) / (window * dt))  # beyond Schafer's estimate, well past -3 dB
    grid = np.linspace(0.0, top, 257)
    below = np.flatnonzero(gain(grid) < half_power)
    if below.size == 0:
        if top >= nyquist:
            return nyquist
        grid = np.linspace(0.0, nyquist, 16 * window + 1)
        below = np.flatnonzero(gain(grid) < half_power)
        if below.size == 0:
            return nyquist
    i = int(below[0])
    return float(brentq(lambda f: float(gain(f)) - half_power, grid[i - 1], grid[i], xtol=1e-9 * nyquist))


def schafer_window(cutoff: float, order: int, dt: float) -> float:
    """Window length (real) whose -3 dB frequency Schafer's approximation puts at ``cutoff``
    [Hz]: ``cutoff dt = (k + 1) / (3.2 L - 4.6)`` (even k; module docstring)."""
    return ((order + 1) / (cutoff * dt) + 4.6) / 3.2


def savgol_window(cutoff: float, order: int, dt: float, weights: SavgolWeights = "uniform",
                  max_window: int | None = None) -> int:
    """The odd Savitzky-Golay window whose -3 dB frequency (:func:`savgol_cutoff`) is nearest
    ``cutoff`` [Hz] (in ratio; the shorter on a tie), at least ``order + 2`` (rounded up to odd)
    and at most ``max_window``: from Schafer's estimate (:func:`schafer_window`), step by 2
    while that gets nearer (the -3 dB frequency falls as the window grows).

    Raises:
        InputError: a non-positive cutoff or one at or above the Nyquist frequency.
    """
    if not 0 < cutoff < 0.5 / dt:
        raise InputError(f"Savitzky-Golay cutoff must be between 0 and the Nyquist frequency {0.5 / dt:g} Hz, "
                         f"got {cutoff:g}")
    smallest = order + 2 + (order + 1) % 2
    largest = max(smallest, (max_window or 2**31) - (1 - (max_window or 1) % 2))

    def score(w: int) -> tuple[float, int]:  # nearer in ratio, then shorter
        return abs(math.log(savgol_cutoff(w, order, dt, weights) / cutoff)), w

    w = int(round(schafer_window(cutoff, order, dt)))
    w = min(max(w + (1 - w % 2), smallest), largest)
    best = score(w)
    while True:
        nearest = min((score(x) for x in (w - 2, w + 2) if smallest <= x <= largest), default=best)
        if nearest >= best:
            return w
        best, w = nearest, nearest[1]


def _shortest(ok: Callable[[int], bool], lo: int, hi: int) -> int | None:
    """The smallest odd ``w`` in ``[lo, hi]`` (odd bounds) with ``ok(w)``, by bisection
    (``ok`` monotone), or None."""
    if not ok(hi):
        return None
    while hi - lo > 2:
        mid = lo + 2 * ((hi - lo) // 4)
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return lo if ok(lo) else hi


# ------------------------------------------------------------------------------- the choice
@dataclass(frozen=True)
class DiffChoice:
    """A differentiation scheme chosen from the data, and why.

    Attributes:
        scheme: ``central``, ``savgol`` or ``butterworth`` (what ``measure(diff=...)`` takes).
        filtering: the filter's options (``window``/``poly_order``/``weights`` or
            ``cutoff``/``butter_order`` set; defaults elsewhere).
        reason: one printable line: what was chosen and why.
        content_end: where the positions' acceleration content ends [Hz] (median over the
            moving joints; NaN if none moves): reported.
        content_ends: the same per joint [Hz] (n,).
        position_noise: white position noise ``sigma`` [rad] (median over the moving joints).
        target: the noise target [rad/s^2].
        noise_central: RMS noise central differences leave in the acceleration [rad/s^2].
        noise_left: the same for the chosen scheme [rad/s^2].
        filter_cutoff: -3 dB frequency of the chosen filter [Hz] (NaN for central differences).
        reached: whether the chosen scheme meets the target (False: the longest window or
            lowest cutoff allowed).
        sample_rate: 1 / dt [Hz].
        n_joints: joints analysed; n_moving: those with content.
    """

    scheme: ChosenScheme
    filtering: FilterOptions
    reason: str
    content_end: float
    content_ends: tuple[float, ...]
    position_noise: float
    target: float
    noise_central: float
    noise_left: float
    filter_cutoff: float
    reached: bool
    sample_rate: float
    n_joints: int
    n_moving: int

    def __str__(self) -> str:
        return self.reason

    @classmethod
    def fallback(cls, reason: str) -> DiffChoice:
        """Central differences without a measurement (a log too short to measure its noise), saying why."""
        nan = float("nan")
        return cls("central", FilterOptions(), reason, nan, (), nan, NOISE_TARGET, nan, nan, nan, False, nan, 0, 0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record (for a log's or a table's metadata): every field, ``filtering`` as a
        dict; NaN and inf as None."""
        out: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, FilterOptions):
                value = asdict(value)
            elif isinstance(value, tuple):
                value = [v if math.isfinite(v) else None for v in value]
            elif isinstance(value, float) and not math.isfinite(value):
                value = None
            out[f.name] = value
        return out


def _positions(source: Log | np.ndarray, dt: float | None, changes: np.ndarray | None
               ) -> tuple[np.ndarray, float, np.ndarray | None]:
    """The positions, their period and their contact changes (a log's own, over its longest segment)."""
    if isinstance(source, Log):
        a, b = longest_segment(source.segments, len(source.time))
        changes = contact_changes(source.contact[a:b]) if changes is None else changes
        return source.q[a:b], source.dt if dt is None else dt, changes
    if dt is None:
        raise InputError("differentiation choice: positions given as an array need the sample period dt")
    return np.asarray(source, dtype=float), dt, changes


def savgol_choice(sigma: float, dt: float, order: int, weights: SavgolWeights, target: float,
                  longest: int) -> tuple[FilterOptions, float, bool]:
    """The Savitzky-Golay window (order ``order``) whose second derivative leaves at most ``target`` [rad/s^2]
    of a white position noise ``sigma`` [rad]: the shortest (bisection: the kernel's norm falls as the window
    grows), else the ``longest``; returns its options, the noise it leaves and whether it meets the target."""
    smallest = order + 2 + (order + 1) % 2
    left = lambda w: sigma * savgol_noise_gain(w, order, dt, weights)  # noqa: E731
    window = _shortest(lambda w: left(w) <= target, smallest, max(smallest, longest))
    reached = window is not None
    window = window if window is not None else max(smallest, longest)
    return FilterOptions(window=window, poly_order=order, weights=weights), left(window), reached


def _butterworth(sigma: float, dt: float, order: int, target: float, lowest: float
                 ) -> tuple[FilterOptions, float, bool]:
    """The highest cutoff (4 significant digits) whose noise left meets the target, else ``lowest``."""
    left = lambda fc: sigma * butterworth_noise_gain(fc, order, dt)  # noqa: E731
    if left(lowest) > target:
        return FilterOptions(cutoff=lowest, butter_order=order), left(lowest), False
    lo, hi = math.log(lowest), math.log(0.499 / dt)  # left(exp(lo)) <= target
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if left(math.exp(mid)) <= target else (lo, mid)
    step = 10.0 ** (math.floor(math.log10(math.exp(lo))) - 3)  # of the fourth significant digit
    cutoff = float(f"{math.floor(math.exp(lo) / step) * step:.4g}")  # rounded down: it meets the target too
    return FilterOptions(cutoff=cutoff, butter_order=order), left(cutoff), True


def choose_differentiation(source: Log | np.ndarray, dt: float | None = None, *, prefer: Preference = "auto",
                           columns: Sequence[int] | None = None, target: float = NOISE_TARGET,
                           tail: float = 0.01, segment: float = SEGMENT, poly_order: int = 4,
                           weights: SavgolWeights = "uniform", butter_order: int = 6,
                           changes: np.ndarray | None = None) -> DiffChoice:
    """Choose the differentiation scheme and its window or cutoff from the positions (module docstring).

    Deterministic: the same positions give the same choice.

    Args:
        source: a :class:`~wbfriction.logs.log.Log` (its positions ``q``, longest segment, and
            its ``dt``) or positions (N, n) or (N,) [rad].
        dt: sampling period [s] (required for an array; overrides the log's).
        prefer: the filter family when a filter is needed (``auto``: Savitzky-Golay).
        columns: the joints (columns of ``q``) to analyse; default all.
        target: most RMS noise left in the acceleration [rad/s^2].
        tail: share of the content's power left above its end
            (:func:`~wbfriction.signals.spectrum.suggest_cutoff`).
        segment: length of the averaged spectrum's segments [s].
        poly_order, weights: the Savitzky-Golay fit's; butter_order: the Butterworth's.
        changes: (N,) the rows where a contact flag changes (:func:`~wbfriction.signals.content.contact_changes`),
            left out of the noise; default a log's own, none for an array.

    Raises:
        InputError: an unknown preference or column, a non-positive target, too few samples
            (:func:`~wbfriction.signals.content.acceleration_content`).
    """
    if prefer not in PREFERENCES:
        raise InputError(f"unknown filter preference '{prefer}': choose one of {', '.join(PREFERENCES)}")
    if not target > 0:
        raise InputError(f"differentiation choice: the noise target must be > 0 rad/s^2, got {target}")
    q, dt, changes = _positions(source, dt, changes)
    if q.ndim == 1:
        q = q[:, None]
    if columns is not None:
        bad = [c for c in columns if not -q.shape[1] <= c < q.shape[1]]
        if bad:
            raise InputError(f"differentiation choice: column {bad[0]} is not one of the {q.shape[1]} joints")
        q = q[:, list(columns)]
    content = acceleration_content(q, dt, tail, segment, changes=changes)
    fs, m = 1.0 / dt, content.moving
    if not m.any():
        sigma = float(np.median(content.position_noise))
        return DiffChoice("central", FilterOptions(), "central differences: the positions hold no motion above "
                          "their noise", math.nan, tuple(float(c) for c in content.content_end), sigma, target,
                          sigma * central_noise_gain(dt), sigma * central_noise_gain(dt), math.nan, True, fs,
                          int(q.shape[1]), 0)
    sigma = float(np.median(content.position_noise[m]))
    end = float(np.median(content.content_end[m]))
    central = sigma * central_noise_gain(dt)
    choice = DiffChoice("central", FilterOptions(), "", end, tuple(float(c) for c in content.content_end), sigma,
                        target, central, central, math.nan, True, fs, int(q.shape[1]), int(m.sum()))
    facts = (f"position noise {sigma:.2g} rad at {fs:.4g} Hz; the acceleration's content ends at {end:.3g} Hz "
             f"(median of {choice.n_moving} joints, {content.content_end[m].min():.3g}-"
             f"{content.content_end[m].max():.3g} Hz)")
    if central <= target:
        return replace(choice, reason=f"central differences: they leave {central:.2g} rad/s^2 of noise in the "
                                      f"acceleration (target {target:g}); {facts}")
    if prefer == "butterworth":
        options, left, reached = _butterworth(sigma, dt, butter_order, target, lowest=float(content.freq[1]))
        f3, label = options.cutoff, f"butterworth {options.cutoff:.4g} Hz order {butter_order}"
    else:
        options, left, reached = savgol_choice(sigma, dt, poly_order, weights, target, longest=len(q) // 2 * 2 - 1)
        f3 = savgol_cutoff(options.window, poly_order, dt, weights)
        label = (f"savgol L={options.window} k={poly_order}" + ("" if weights == "uniform" else f" {weights}")
                 + f" (-3 dB at {f3:.3g} Hz)")
    why = "the least filtering that meets the noise target" if reached else "the most filtering allowed"
    return replace(choice, scheme="butterworth" if prefer == "butterworth" else "savgol", filtering=options,
                   noise_left=left, filter_cutoff=f3, reached=reached,
                   reason=f"{label}, {why}: it leaves {left:.2g} rad/s^2 of noise in the acceleration (target "
                          f"{target:g}; central differences {central:.3g}); {facts}")


# ------------------------------------------------------------- the momentum route's smoothing
VELOCITY_NOISE_TARGET = 0.002
"""Most RMS noise the momentum route's velocity filter may leave [rad/s] (issue 38): the velocity is the
friction model's argument, and a noisy argument inside ``sgn``/``tanh`` biases the fit (errors in variables,
corrected in :mod:`wbfriction.fit` but only to first order); with 1e-4 rad of position noise at
1 kHz it picks a 57-sample window (61 measured best in issue 38's study, 0.0018 rad/s)."""
MOMENTUM_ORDER = 4
"""Polynomial order of the momentum route's Savitzky-Golay velocity."""


def velocity_noise_gain(window: int, dt: float, order: int = MOMENTUM_ORDER,
                        weights: SavgolWeights = "uniform") -> float:
    """RMS velocity [1/s] the Savitzky-Golay first derivative makes of unit white position noise: the norm
    of its kernel."""
    return float(np.linalg.norm(savgol_kernels(window, order, dt, weights, max_deriv=1)[1]))


def momentum_noise_gain(velocity_window: int, half_width: int, dt: float, order: int = MOMENTUM_ORDER) -> float:
    """RMS acceleration [1/s^2] the momentum route leaves of unit white position noise, per unit inertia: the
    norm of the Savitzky-Golay velocity kernel convolved with the window's differences,
    ``-sum (w_i - w_{i-1}) qd_i / sum w dt`` (:mod:`wbfriction.signals.window`)."""
    from wbfriction.signals.window import hann_steps
    d1 = savgol_kernels(velocity_window, order, dt, "uniform", max_deriv=1)[1]
    w = hann_steps(half_width)
    return float(np.linalg.norm(np.convolve(np.r_[w, 0.0] - np.r_[0.0, w], d1)) / (w.sum() * dt))


@dataclass(frozen=True)
class MomentumSmoothing:
    """The momentum route's two windows, chosen from the position noise (:func:`choose_momentum_smoothing`).

    Attributes:
        velocity_window: the Savitzky-Golay window of the velocity [samples, odd] (order :data:`MOMENTUM_ORDER`).
        window: the momentum window's length ``2m + 1`` [samples, odd] (:mod:`wbfriction.signals.window`).
        velocity_noise: RMS noise the velocity filter leaves [rad/s].
        noise_left: RMS acceleration noise the route leaves per unit inertia [rad/s^2].
        reached: both targets met (False: the longest windows allowed).
    """

    velocity_window: int
    window: int
    velocity_noise: float
    noise_left: float
    reached: bool


def choose_momentum_smoothing(sigma: float, dt: float, n_samples: int, *,
                              velocity_target: float = VELOCITY_NOISE_TARGET, target: float = NOISE_TARGET,
                              velocity_window: int | None = None, window: int | None = None) -> MomentumSmoothing:
    """The shortest velocity window that leaves at most ``velocity_target`` of a white position noise ``sigma``
    [rad], then the shortest momentum window that leaves at most ``target`` in the acceleration (both by
    bisection: the noise left falls as a window grows), each at most half the log; a window given is kept.

    Raises:
        InputError: a negative ``sigma``, a log too short for the shortest windows.
    """
    if not sigma >= 0:
        raise InputError(f"momentum smoothing: the position noise must be >= 0 rad, got {sigma}")
    smallest = MOMENTUM_ORDER + 2 + (MOMENTUM_ORDER + 1) % 2
    longest = max(smallest, (n_samples // 4) * 2 - 1)
    reached = True
    if velocity_window is None:
        found = _shortest(lambda w: sigma * velocity_noise_gain(w, dt) <= velocity_target, smallest, longest)
        reached &= found is not None
        velocity_window = found if found is not None else longest
    longest_half = max(1, (n_samples // 4))
    if window is None:
        ok = lambda h: sigma * momentum_noise_gain(velocity_window, h, dt) <= target  # noqa: E731
        found = _shortest(lambda w: ok((w - 1) // 2), 3, 2 * longest_half + 1)
        reached &= found is not None
        window = found if found is not None else 2 * longest_half + 1
    return MomentumSmoothing(velocity_window, window, sigma * velocity_noise_gain(velocity_window, dt),
                             sigma * momentum_noise_gain(velocity_window, (window - 1) // 2, dt), reached)

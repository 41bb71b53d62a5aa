"""Tests of the differentiation choice: content end against known signals, noise level recovered,
Savitzky-Golay cutoffs against an independent frequency response, determinism, real logs."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import freqz, savgol_coeffs

from helpers import KUKA
from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.signals.choice import (
    butterworth_noise_gain,
    central_noise_gain,
    choose_differentiation,
    savgol_cutoff,
    savgol_noise_gain,
    savgol_window,
    schafer_window,
    second_difference_gain,
)
from wbfriction.signals.filters import ZeroPhaseLowpass, savgol_differentiate
from wbfriction.signals.kinematics import central_differences
from wbfriction.studies.common import TORQUE_STD

DT = 1e-3
N = 20_000
SIGMA = 1e-4  # rad


def sines(f_max: float, sigma: float = SIGMA, n_joints: int = 3, seed: int = 0, a0: float = 0.02) -> np.ndarray:
    """Positions (N, n_joints) [rad]: sines at 1, 2, ... f_max Hz of amplitude ``a0 / f^2`` (the
    same acceleration amplitude ``a0 (2 pi)^2`` on every line), random phases, plus white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) * DT
    freqs = np.arange(1.0, f_max + 0.5)
    phases = rng.uniform(0, 2 * np.pi, (len(freqs), n_joints))
    q = np.zeros((N, n_joints))
    for k, f in enumerate(freqs):
        q += (a0 / f**2) * np.sin(2 * np.pi * f * t[:, None] + phases[k])
    return q + rng.normal(0.0, sigma, q.shape)


def noise_corner(f_max: float, sigma: float, a0: float = 0.02, segment: int = 1000) -> float:
    """Where white position noise, through the second difference, rises to the content's top line
    (analytic): a sine of amplitude A shows as ``A |G| / 2`` in a Hann-tapered amplitude spectrum
    (coherent gain 1/2); white noise as ``sigma |G| sqrt(1.5 / L)`` in RMS per bin (sum of w^2 = 3 L / 8)."""
    line = 0.5 * (a0 / f_max**2) * second_difference_gain(np.array([f_max]), DT)[0]
    g = line / (sigma * math.sqrt(1.5 / segment))  # |G(f_n)|
    return math.asin(math.sqrt(g * DT**2 / 4.0)) / (math.pi * DT)


def interior_rms(lowpass: ZeroPhaseLowpass, x: np.ndarray) -> float:
    """RMS of ``lowpass(x)`` more than 10 half-widths from the ends: near them the filter's odd
    padding about a noisy end sample leaves far more noise (reported in issue 20)."""
    margin = 10 * lowpass.half_width
    return float(np.sqrt(np.nanmean(lowpass(x)[margin:-margin] ** 2)))


@pytest.mark.parametrize("f_max", [5.0, 12.0, 25.0])
def test_content_ends_between_the_content_and_the_noise_corner(f_max):
    choice = choose_differentiation(sines(f_max), DT)
    corner = noise_corner(f_max, SIGMA)
    assert corner > 2 * f_max  # the test's premise: content and noise apart
    assert f_max <= choice.content_end <= corner, choice.reason


def test_filter_leaves_at_most_the_target_and_is_the_least_filtering():
    """Ground truth: the chosen Savitzky-Golay window, run by the project's differentiator on
    pure white noise of the estimated level, leaves at most the target; two samples shorter, more."""
    choice = choose_differentiation(sines(8.0), DT)
    assert choice.scheme == "savgol" and choice.reached
    noise = np.random.default_rng(7).normal(0.0, choice.position_noise, (200_000, 1))
    window, order = choice.filtering.window, choice.filtering.poly_order
    left = np.sqrt(np.nanmean(savgol_differentiate(noise, DT, window, order)[2] ** 2))
    assert left == pytest.approx(choice.noise_left, rel=0.02)
    assert left <= 1.02 * choice.target
    shorter = np.sqrt(np.nanmean(savgol_differentiate(noise, DT, window - 2, order)[2] ** 2))
    assert shorter > 0.98 * choice.target
    # the -3 dB frequency it reports, against scipy's frequency response of the same window
    w, h = freqz(savgol_coeffs(window, order), worN=2**16, fs=1 / DT)
    assert choice.filter_cutoff == pytest.approx(w[np.argmax(np.abs(h) < 1 / math.sqrt(2))], abs=0.05)
    assert choice.reason.startswith(f"savgol L={window} k=4")


def test_the_default_target_keeps_the_acceleration_noise_below_the_torque_sensors():
    """What NOISE_TARGET means (issue 37: 0.3 instead of 0.03 passed every test): the acceleration noise the
    default choice leaves, through a joint inertia of 1 kg·m^2, is below the studies' torque-sensor noise
    (TORQUE_STD, 0.05 N·m): positions with the studies' noise (1e-4 rad) add less to the friction estimate
    than the torques do. Measured with the chosen filter on white noise of that level, not by the choice's
    own noise estimate."""
    choice = choose_differentiation(sines(8.0, sigma=1e-4), DT)
    assert choice.scheme == "savgol"
    noise = np.random.default_rng(11).normal(0.0, 1e-4, (200_000, 1))
    qdd = savgol_differentiate(noise, DT, choice.filtering.window, choice.filtering.poly_order)[2]
    inertia = 1.0  # kg m^2
    assert inertia * np.sqrt(np.nanmean(qdd**2)) < TORQUE_STD


def test_the_default_target_picks_a_window_the_walk_study_found_best():
    """The module docstring's measurement (TALOS combined walk, 1 kHz, 1e-4 rad of position noise): windows
    of 101 / 151 / 171 / 201 samples gave a worst leg F_v error of 42 / 16 / 25 / 27 %: shorter lets noise
    in, longer loses samples. The default target picks a window between 101 and 201 there (a target ten
    times larger or smaller would not)."""
    assert 101 < choose_differentiation(sines(8.0, sigma=1e-4), DT).filtering.window < 201


def test_butterworth_preference_meets_the_target():
    choice = choose_differentiation(sines(8.0), DT, prefer="butterworth", butter_order=4)
    assert choice.scheme == "butterworth" and choice.filtering.butter_order == 4
    noise = np.random.default_rng(8).normal(0.0, choice.position_noise, (100_000, 1))
    _, qdd, _ = central_differences(noise, DT)
    left = interior_rms(ZeroPhaseLowpass(choice.filtering.cutoff, 4, DT), qdd)
    assert left == pytest.approx(choice.noise_left, rel=0.03)
    assert left <= 1.03 * choice.target
    assert interior_rms(ZeroPhaseLowpass(choice.filtering.cutoff * 1.01, 4, DT), qdd) > 0.99 * choice.target


@pytest.mark.parametrize("sigma", [1e-5, 1e-4, 1e-3])
def test_position_noise_recovered(sigma):
    choice = choose_differentiation(sines(8.0, sigma), DT)
    assert choice.position_noise == pytest.approx(sigma, rel=0.05)


def test_noise_free_fast_log_keeps_central_differences():
    choice = choose_differentiation(sines(20.0, sigma=0.0), DT)
    assert choice.scheme == "central"
    assert math.isnan(choice.filter_cutoff)
    assert choice.noise_central < 1e-6 * choice.target  # no noise: only the taper's leakage in the upper band


def test_noise_gains_against_filtered_white_noise():
    noise = np.random.default_rng(9).normal(0.0, 1.0, (200_000, 1))
    _, qdd, _ = central_differences(noise, DT)
    assert np.sqrt(np.nanmean(qdd**2)) == pytest.approx(central_noise_gain(DT), rel=0.01)
    for window in (21, 101):
        rms = np.sqrt(np.nanmean(savgol_differentiate(noise, DT, window, 4)[2] ** 2))
        assert rms == pytest.approx(savgol_noise_gain(window, 4, DT), rel=0.01)
    for cutoff in (10.0, 40.0):
        assert interior_rms(ZeroPhaseLowpass(cutoff, 6, DT), qdd) == pytest.approx(
            butterworth_noise_gain(cutoff, 6, DT), rel=0.02)


def test_same_input_same_choice():
    q = sines(10.0, seed=3)
    assert choose_differentiation(q, DT) == choose_differentiation(q.copy(), DT)


@settings(max_examples=6, deadline=None)
@given(order=st.permutations([0, 1, 2]), low=st.floats(2e-5, 3e-4), factor=st.floats(1.5, 10.0))
def test_more_noise_longer_window_and_joint_order_irrelevant(order, low, factor):
    """The window grows with the position noise; reordering the joints changes nothing."""
    quiet = choose_differentiation(sines(8.0, low, seed=4), DT)
    loud = choose_differentiation(sines(8.0, low * factor, seed=4)[:, order], DT)
    assert loud.filtering.window >= quiet.filtering.window
    again = choose_differentiation(sines(8.0, low, seed=4)[:, order], DT)
    assert (again.scheme, again.filtering, again.content_end) == (quiet.scheme, quiet.filtering, quiet.content_end)
    assert again.content_ends == tuple(quiet.content_ends[i] for i in order)


def test_log_input_uses_its_longest_segment_and_period():
    q = sines(10.0, seed=5)
    bad = q.copy()
    bad[:3000] = np.random.default_rng(0).normal(0, 1e-2, (3000, 3))  # a noisy first segment
    log = Log(time=np.arange(N) * DT, q=bad, tau=np.zeros((N, 3)), contact=np.ones((N, 1), bool),
              segments=[(0, 3000), (3000, N)])
    assert choose_differentiation(log).filtering == choose_differentiation(q[3000:], DT).filtering


def test_savgol_cutoff_matches_schafer_and_scipy():
    for order in (2, 4, 6):
        for window in (51, 101, 151, 301):
            f3 = savgol_cutoff(window, order, DT)
            w, h = freqz(savgol_coeffs(window, order), worN=2**17, fs=1 / DT)
            assert abs(np.abs(h[np.argmin(np.abs(w - f3))]) - 1 / math.sqrt(2)) < 1e-3
            # Schafer (2011): within 15 % of the exact value for even orders and M >= 25
            assert schafer_window(f3, order, DT) == pytest.approx(window, rel=0.15)


def legendre_smoother(window: int, order: int) -> np.ndarray:
    """The least-squares smoother's kernel (value at the centre), through an independent route: the
    pseudo-inverse (SVD) of a Legendre Vandermonde matrix on [-1, 1]."""
    x = np.linspace(-1.0, 1.0, window)
    return np.polynomial.legendre.legvander(np.zeros(1), order)[0] @ np.linalg.pinv(
        np.polynomial.legendre.legvander(x, order))


def test_log_stamped_one_microsecond_apart_gets_a_choice_and_its_true_cutoff():
    """Issue 37: noisy positions stamped 1 us apart (the shortest step read as seconds) need the
    longest window; ``--diff auto`` then died in brentq (a ValueError traceback) on that window's
    -3 dB frequency. The choice says the target is not reached, and its -3 dB frequency is that of the
    true least-squares smoother."""
    dt, n = 1e-6, 3000
    t = np.arange(n) * dt
    q = 0.1 * np.sin(2 * np.pi * 1000.0 * t)[:, None] + np.random.default_rng(1).normal(0.0, 1e-4, (n, 1))
    choice = choose_differentiation(q, dt)
    assert choice.scheme == "savgol" and not choice.reached and "the most filtering allowed" in choice.reason
    window = choice.filtering.window
    assert window == n - 1  # the longest odd window: 1e-4 rad at 1 MHz is far above the target
    w, h = freqz(legendre_smoother(window, 4), worN=2**16, fs=1 / dt)
    assert choice.filter_cutoff == pytest.approx(w[np.argmax(np.abs(h) < 1 / math.sqrt(2))], rel=2e-3)


def test_savgol_window_is_the_nearest():
    for cutoff in (3.0, 10.0, 33.0):
        w = savgol_window(cutoff, 4, DT)
        miss = [abs(math.log(savgol_cutoff(L, 4, DT) / cutoff)) for L in (w - 2, w, w + 2)]
        assert w % 2 == 1 and miss[1] <= min(miss[0], miss[2])


def test_bad_inputs():
    with pytest.raises(InputError, match="sample period"):
        choose_differentiation(np.zeros((1000, 2)))
    with pytest.raises(InputError, match="preference"):
        choose_differentiation(sines(5.0), DT, prefer="kalman")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="consecutive finite samples"):
        choose_differentiation(sines(5.0)[:200], DT)
    with pytest.raises(InputError, match="column 5"):
        choose_differentiation(sines(5.0), DT, columns=[5])
    with pytest.raises(InputError, match="noise target"):
        choose_differentiation(sines(5.0), DT, target=0.0)
    with pytest.raises(InputError, match="Nyquist"):
        savgol_window(600.0, 4, DT)




@pytest.mark.skipif(not (KUKA / "measurements_1.npz").exists(), reason=f"KUKA LWR4+ logs not found in {KUKA}")
def test_kuka_runs_of_the_same_trajectory_get_the_same_choice():
    """Runs 1 and 2 repeat one trajectory (the data's README): the same choice. The stamps are
    irregular around 5 ms; the time base is taken as ``k * 5 ms`` for now."""
    choices = [choose_differentiation(np.load(KUKA / f"measurements_{r}.npz")["positions"], 0.005) for r in (1, 2, 3)]
    for r, c in zip((1, 2, 3), choices):
        print(f"KUKA run {r}: {c.reason}")
    assert choices[0].scheme == choices[1].scheme
    assert choices[0].filtering == choices[1].filtering
    assert abs(choices[0].content_end - choices[1].content_end) <= 1.0


def test_record_is_json_ready_and_rebuilds_the_options():
    import json

    from wbfriction.signals.options import FilterOptions

    for q in (sines(10.0), sines(10.0, sigma=0.0)):
        choice = choose_differentiation(q, DT)
        record = json.loads(json.dumps(choice.to_dict(), allow_nan=False))
        assert record["scheme"] == choice.scheme and record["reason"] == choice.reason
        assert FilterOptions(**record["filtering"]) == choice.filtering

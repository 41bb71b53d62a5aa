"""The differentiation window bounded by the shortest swing it must resolve (issue 82): a window chosen from the noise
longer than half the shortest swing is bounded to it and said in one line; a window given that no swing can hold is
refused naming it, not the feet's forces."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli
from wbfriction.exceptions import OptionError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions, MomentumOptions
from wbfriction.signals.options import FilterOptions
from wbfriction.signals.phase_window import log_swings, samples_left, window_bound

NOISE = 1e-3
"""Position noise [rad] added to the ideal trot: the noise alone chooses windows of about 230 samples (0.45 s)
against swings of 124 (0.25 s)."""
MARGINS = dict(base_motion="logged", lift_off_skip=0.02, touch_down_skip=0.02)


@given(samples=st.integers(4, 100_000))
def test_the_bound_leaves_a_phase_at_least_what_it_costs(samples):
    """The largest odd window that a phase keeps as many samples of as the window costs it (L + 1 <= P - 1 - L)."""
    w = window_bound(samples)
    assert w % 2 == 1 and w >= 1
    assert samples_left(w, samples) >= w + 1
    assert samples_left(w + 2, samples) < w + 3


@settings(max_examples=50, deadline=None)
@given(runs=st.lists(st.tuples(st.booleans(), st.integers(1, 30)), min_size=1, max_size=12))
def test_swings_are_the_complete_runs_off_the_ground(runs):
    """Flags built from runs: every run off the ground between two changes is a swing, of its length; the first and
    last runs (not complete) are not."""
    flags = np.concatenate([np.full(n, on) for on, n in runs])
    starts = np.cumsum([0] + [n for _, n in runs])[:-1]
    merged = []  # runs of equal flags merged, as the flags read
    for (on, n), s in zip(runs, starts):
        if merged and merged[-1][0] == on:
            merged[-1][2] += n
        else:
            merged.append([on, s, n])
    expected = [(int(s), n) for on, s, n in merged[1:-1] if not on]
    swings = log_swings(flags[:, None], ("foot",), 0.01)
    assert [(s.start, s.samples) for s in swings.swings] == expected


@pytest.fixture(scope="module")
def trot():
    """The ideal go2 trot (3 s, 500 Hz, swings of 0.25 s), with and without position noise."""
    from wbfriction.model.loading import load_robot
    from wbfriction.studies.quadruped import QuadrupedCase, case_robot, simulate_case

    case = QuadrupedCase(gait="trot", duration=3.0)
    robot = case_robot(load_robot("go2_walking"), case)
    log = simulate_case(robot, case).log
    rng = np.random.default_rng(0)
    return robot, log, dataclasses.replace(log, q=log.q + NOISE * rng.normal(size=log.q.shape))


@pytest.mark.parametrize("route", ["acceleration", "momentum"])
def test_a_window_chosen_longer_than_a_swing_is_bounded(trot, route):
    """The noise alone chooses windows longer than the swings: before, no sample was estimated and the refusal blamed
    the feet's forces; bounded to half the shortest swing, every joint is estimated in the swings, and the metadata
    says what was bounded, from what to what, by which swing."""
    robot, _, noisy = trot
    est = estimate_log(robot, noisy, EstimateOptions(route=route, **MARGINS))
    assert est.valid.any(axis=0).all()
    shortest = log_swings(noisy.contact, robot.contact_frames, noisy.dt).shortest()
    bound = est.metadata["window_bound"]
    assert [b["what"] for b in bound["bounds"]] == ["the differentiation's savgol window",
                                                    "the momentum route's windows"]
    assert all(b["before"] > shortest.samples - 1 and b["after"] == window_bound(shortest.samples) == 61
               and b["swing_samples"] == shortest.samples for b in bound["bounds"])
    assert est.metadata["differentiation"]["filtering"]["window"] == 61
    momentum = est.metadata["route"]
    assert momentum["velocity_window"] + momentum["window"] - 1 == 61
    assert "\n" not in bound["warning"] and "longer than half the shortest swing (FL_foot, 124 samples" in \
        bound["warning"]


def test_the_bound_does_not_bind_on_the_simulators_noise(trot):
    """Without the added noise (the trot as simulated) the windows are shorter than the bound: nothing bounded,
    nothing said."""
    robot, log, _ = trot
    est = estimate_log(robot, log, EstimateOptions(**MARGINS))
    assert "window_bound" not in est.metadata


@pytest.mark.parametrize("options, flag", [
    (dict(diff="savgol", filtering=FilterOptions(window=251), route="acceleration"), "--window"),
    (dict(route="momentum", momentum=MomentumOptions(velocity_window=61, window=121)), "--momentum-window"),
])
def test_a_window_given_that_no_swing_holds_is_refused_naming_it(trot, options, flag):
    """A window given longer than every swing: one line naming the option, its span, the longest swing and the
    window to give; not the feet's forces."""
    robot, _, noisy = trot
    with pytest.raises(OptionError) as info:
        estimate_log(robot, noisy, EstimateOptions(**options, **MARGINS))
    line = str(info.value)
    assert info.value.option == flag and line.startswith(f"{flag} must be at most 61 (half the shortest swing")
    assert "is longer than every swing, the longest 124 samples, 0.248 s (FL_foot)" in line and "force" not in line


def test_the_command_line_says_it_in_one_line(trot, tmp_path, capsys):
    """``estimate`` of the noisy trot: one warning line naming the windows before and after and the swing."""
    from wbfriction.logs.log import write_log

    robot, _, noisy = trot
    log = tmp_path / "trot.parquet"
    write_log(noisy, robot, log)
    code, err = run_cli(capsys, "estimate", log, "--robot", "go2_walking", "--lift-off", "0.02", "--touch-down",
                        "0.02", "--base-motion", "logged", "-o", tmp_path / "f.parquet")
    assert code == 0
    lines = [ln for ln in err.splitlines() if "window chosen from the noise" in ln]
    assert len(lines) == 1 and "-> 61 (0.122 s)" in lines[0] and "(FL_foot, 124 samples, 0.248 s" in lines[0]


def test_a_swing_the_margins_leave_nothing_of_does_not_bound_the_window():
    """A foot's bounce of 22 samples (0.044 s, a noisy MuJoCo walk's) beside swings of 119: with the default margins
    (0.10 + 0.05 s) nothing of the bounce is estimated, and the shortest swing that bounds the window is a real one."""
    flags = np.ones((600, 1), dtype=bool)
    flags[100:122] = False
    flags[300:419] = False
    swings = log_swings(flags, ("foot",), 0.002)
    assert [s.samples for s in swings.swings] == [22, 119]
    assert swings.shortest().samples == 22
    assert swings.shortest(margins=0.15).samples == 119


@settings(max_examples=50, deadline=None)
@given(runs=st.lists(st.tuples(st.booleans(), st.integers(1, 40)), min_size=1, max_size=10),
       lag=st.integers(0, 8), lift_off=st.integers(0, 6), touch_down=st.integers(0, 6))
def test_stretches_are_the_swinging_rows_outside_every_margin(runs, lag, lift_off, touch_down):
    """Two feet, the second's flags the first's ``lag`` rows late: the stretches are exactly the complete runs of rows
    with a foot off the ground outside every switch's margins (signals.phases.settled), each as long as its run."""
    from wbfriction.signals.phases import settled

    first = np.concatenate([np.full(n, on) for on, n in runs])
    contact = np.column_stack([first, np.r_[np.full(lag, first[0]), first][:first.size]])
    dt = 0.01
    margins = (lift_off * dt, touch_down * dt)
    swings = log_swings(contact, ("A", "B"), dt, None, margins)
    keep = settled(np.arange(first.size) * dt, contact, *margins) & ~contact.all(axis=1)
    padded = np.r_[False, keep, False]
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    expected = [(a, b - a) for a, b in zip(edges[::2], edges[1::2]) if a > 0 and b < first.size]
    assert [(s.start, s.samples) for s in swings.stretches] == expected
    assert all(abs(s.seconds - s.samples * dt) < 1e-12 for s in swings.stretches)


def test_the_momentum_window_is_bounded_by_the_shortest_stretch():
    """A momentum window longer than half the shortest stretch estimated while a foot swings is bounded to it, and
    said; one shorter is kept; a window given is kept."""
    from wbfriction.friction.window_bound import bound_windows
    from wbfriction.signals.phase_window import Swing, Swings

    swings = Swings((Swing("A", 10, 200, 0.4),), (Swing("A+B", 60, 24, 0.048), Swing("A+B", 400, 60, 0.12)))
    given = EstimateOptions(route="momentum")
    options = dataclasses.replace(given, momentum=MomentumOptions(window=19, velocity_window=7))
    out, _, _, bounds = bound_windows(given, options, None, None, swings, 0.002)
    assert out.momentum.window == window_bound(24) == 11 and out.momentum.velocity_window == 7
    assert len(bounds) == 1 and bounds[0].stretch and "shortest stretch" in bounds[0].phrase()
    short = dataclasses.replace(options, momentum=MomentumOptions(window=9, velocity_window=7))
    assert bound_windows(given, short, None, None, swings, 0.002)[0].momentum.window == 9
    asked = dataclasses.replace(given, momentum=MomentumOptions(window=19))
    assert bound_windows(asked, options, None, None, swings, 0.002)[0].momentum.window == 19


def test_margins_that_leave_no_row_of_any_swing_are_refused_naming_them(trot):
    """Margins as long as the swings (a small robot's swings against the thesis's margins): one line naming
    ``--lift-off`` and ``--touch-down`` and the longest swing, before the work; not "no valid sample" after it."""
    robot, _, noisy = trot
    with pytest.raises(OptionError) as info:
        estimate_log(robot, noisy, EstimateOptions(base_motion="logged", lift_off_skip=0.15, touch_down_skip=0.1))
    line = str(info.value)
    assert info.value.option == "--lift-off" and info.value.value == 0.15
    assert "--touch-down (0.1 s)" in line and "the longest 124 samples, 0.248 s, FL_foot" in line
    estimate_log(robot, noisy, EstimateOptions(base_motion="logged", lift_off_skip=0.05, touch_down_skip=0.05))

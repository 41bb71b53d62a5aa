"""Repeated samples (wbfriction.logs.repeats): a logger faster than the drives, its repeats found exactly and the
drives' sample times re-estimated from the runs, holds recognised as whole periods."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from helpers import logger_sampling
from wbfriction.logs.clock import LATTICE_TOL
from wbfriction.logs.repeats import find_repeats, repeated_rows


@pytest.mark.parametrize("noise", [0.0, 1e-3])
@pytest.mark.parametrize("hold", [0.0, 0.03])
def test_a_2ms_drive_read_by_a_1_22ms_logger_is_found_exactly(noise, hold):
    stamps, values, true, shown = logger_sampling(2e-3, 1.22e-3, 22.0, hold, noise=noise)
    found = find_repeats(values, stamps)
    truth = np.concatenate([[False], np.diff(shown) == 0])
    np.testing.assert_array_equal(found.repeat, truth)  # the repeat mask is the truth
    assert found.merge and found.clock is not None
    assert found.clock.period == pytest.approx(2e-3, rel=1e-5)
    # the held periods counted as whole-period skips: every tick step is 1, or 2 where a period was held
    assert found.clock.holds == int(np.sum(np.diff(np.unique(shown)) - 1)) + _held(true, 2e-3)
    err = np.abs(found.times(stamps) - true[np.unique(shown)])
    assert err.max() < 0.1 * 1.22e-3  # within a tenth of the logger's period
    assert "merged; drive period 2.00 ms re-estimated" in found.describe()


def _held(true: np.ndarray, drive: float) -> int:
    """Drive periods held between the samples (none shown skipped: every sample is shown at this ratio)."""
    return int(np.sum(np.rint(np.diff(true) / drive) - 1))


def test_only_rows_equal_in_every_column_repeat():
    """A still robot's quantised encoder repeats its angle, not its torque: no repeat."""
    rng = np.random.default_rng(1)
    q = np.round(rng.normal(scale=1e-4, size=200), 3)  # quantised: mostly equal to the previous
    tau = rng.normal(size=200)
    assert repeated_rows(q[:, None]).mean() > 0.5
    assert not repeated_rows(np.column_stack([q, tau])).any()
    found = find_repeats(np.column_stack([q, tau]), 1e-3 * np.arange(200))
    assert not found.merge and found.first.size == 200


def test_repeats_at_the_loggers_own_period_are_kept():
    """Values repeated on a clock no slower than the logger's (a still stretch, sensors that repeat by chance) are
    rows, not repeats of a logger faster than the drives."""
    rng = np.random.default_rng(2)
    values = rng.normal(size=(3000, 2))
    values[rng.random(3000) < 0.05] = np.nan  # made equal to the previous below
    for k in np.flatnonzero(np.isnan(values[:, 0])):
        values[k] = values[k - 1] if k else 0.0
    still = np.vstack([np.zeros((400, 2)), values])  # and a still start, one long run
    found = find_repeats(still, 1e-3 * np.arange(len(still)))
    assert found.repeat.any() and not found.merge
    assert "kept" in found.describe()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(drive=st.floats(1.5e-3, 5e-3), ratio=st.floats(1.5, 4.0), hold=st.sampled_from([0.0, 0.01, 0.05]),
       phase=st.floats(0.0, 1.0), seed=st.integers(0, 1000))
@example(drive=0.00390625, ratio=1.5546875, hold=0.05, phase=0.75, seed=849)  # a step misread by rounding
@example(drive=0.0036926139374955573, ratio=2.023551390966379, hold=0.0, phase=0.5711078240273729, seed=307)
@example(drive=0.002387418499341829, ratio=2.0007513657768, hold=0.0, phase=0.2865949204654039, seed=991)
@example(drive=0.0022240138884349436, ratio=1.997102059059157, hold=0.05, phase=0.1042598370728598, seed=28)
@example(drive=0.004990220654889142, ratio=1.5952104947597685, hold=0.05, phase=0.3511698467384696, seed=904)
def test_any_drive_clock_read_by_a_faster_logger_is_found(drive, ratio, hold, phase, seed):
    logger = drive / ratio
    stamps, values, true, shown = logger_sampling(drive, logger, 600 * drive, hold, phase * drive, 1e-3, seed)
    found = find_repeats(values, stamps)
    np.testing.assert_array_equal(found.repeat, np.concatenate([[False], np.diff(shown) == 0]))
    assert found.merge
    # what the stamps fix: a clock explaining every sample puts each in its window (one logger period, within
    # LATTICE_TOL), so two such clocks differ by at most two windows over the span (near a rational ratio with
    # holds, several do); the re-estimated times lie in their windows
    window = (1 + LATTICE_TOL) * logger
    assert found.clock is not None
    assert found.clock.period == pytest.approx(drive, rel=2 * window / (stamps[-1] - stamps[0]))
    err = np.abs(found.times(stamps) - true[np.unique(shown)])
    assert err.max() <= window and np.median(err) <= 0.5 * logger


def test_merged_samples_are_read_as_the_drives_clock_not_as_jitter():
    """The issue's clock: the repeats removed by hand, the first rows' stamps (logger ticks, 1-3 of them a sample)
    read as receive-time jitter, regularised and cut into pieces; at the re-estimated times, one 2 ms clock whose
    held periods are whole skips, on the stamps as recorded, in one piece."""
    from wbfriction.logs.clock import read_clock

    stamps, values, true, shown = logger_sampling(2e-3, 1.22e-3, 22.0, 0.02)
    found = find_repeats(values, stamps)
    q = np.sin(2 * true[np.unique(shown)])[:, None] + 1e-4 * np.random.default_rng(0).normal(size=(found.first.size, 1))
    by_hand = read_clock(stamps[found.first], "by hand", q=q)
    assert by_hand.kind == "jittered" and len(by_hand.segments) > 10  # the symptom
    clock = read_clock(found.times(stamps), "merged", q=q)
    assert clock.kind == "skipping" and clock.lattice == pytest.approx(2e-3, rel=1e-4)
    assert len(clock.segments) == 1 and "2 ms clock skipping samples" in clock.reason

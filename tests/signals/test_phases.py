"""Support phases and masks (thesis 5.3, 6.2.1): analytic contact sequences, and properties over random ones."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.signals.phases import joint_mask, segment

DT = 1e-3


def sequence(*runs: tuple[int, tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Time (N,) and contact flags (N, 2) of runs of (samples, (left, right))."""
    contact = np.vstack([np.tile(np.array(flags, dtype=bool), (n, 1)) for n, flags in runs])
    return np.arange(len(contact)) * DT, contact


def test_a_walk_of_phases_and_its_margins():
    """double 100 | left 200 | double 100 | right 200 | flight 50 | double 50: each single-support run
    loses 100 samples (0.10 s) after its lift-off and 50 (0.05 s) before its touch-down."""
    time, contact = sequence((100, (1, 1)), (200, (1, 0)), (100, (1, 1)), (200, (0, 1)), (50, (0, 0)), (50, (1, 1)))
    ph = segment(time, contact, lift_off_skip=0.10, touch_down_skip=0.05)
    labels = ph.labels()
    assert (labels[:100] == "double").all() and (labels[100:300] == "single").all()
    assert (labels[300:400] == "double").all() and (labels[400:600] == "single").all()
    assert (labels[600:650] == "flight").all() and (labels[650:] == "double").all()
    assert (ph.stance[100:300] == 0).all() and (ph.stance[400:600] == 1).all()
    assert (ph.stance[:100] == -1).all() and (ph.stance[600:] == -1).all()
    np.testing.assert_array_equal(np.flatnonzero(ph.keep), np.r_[200:250, 500:550])


def test_runs_at_the_ends_of_the_log_are_not_trimmed_there():
    """A single-support run that starts the log has no lift-off in it, one that ends it no touch-down."""
    time, contact = sequence((120, (0, 1)), (30, (1, 1)), (120, (1, 0)))
    ph = segment(time, contact, 0.10, 0.05)
    np.testing.assert_array_equal(np.flatnonzero(ph.keep), np.r_[0:70, 250:270])


def test_a_stance_change_without_double_support_splits_the_run():
    """Left then right with no double support between: two runs, each trimmed at the switch."""
    time, contact = sequence((200, (1, 0)), (200, (0, 1)))
    ph = segment(time, contact, 0.10, 0.05)
    np.testing.assert_array_equal(np.flatnonzero(ph.keep), np.r_[0:150, 300:400])


def test_swing_mask_leaves_out_the_stance_leg(talos):
    """``swing``: while the left foot stands, the left leg's joints do not count; the rest do; ``single``:
    every joint counts."""
    time, contact = sequence((300, (1, 0)))
    ph = segment(time, contact)
    swing = joint_mask(ph, talos.limb_mask, "swing")
    single = joint_mask(ph, talos.limb_mask, "single")
    left_leg = talos.limb_mask[0]
    assert left_leg.sum() == 6
    assert not swing[:, left_leg].any() and swing[:, ~left_leg].all()
    assert single.all()


def test_bad_margins_and_masks_are_input_errors(talos):
    time, contact = sequence((10, (1, 0)))
    with pytest.raises(InputError, match="margins must be >= 0"):
        segment(time, contact, lift_off_skip=-0.1)
    with pytest.raises(InputError, match="unknown mask 'legs'"):
        joint_mask(segment(time, contact), talos.limb_mask, "legs")  # type: ignore[arg-type]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(1, 80), st.sampled_from([(0, 0), (1, 0), (0, 1), (1, 1)])), min_size=1,
                max_size=12),
       st.floats(0.0, 0.05), st.floats(0.0, 0.05))
def test_kept_samples_are_single_support_away_from_every_switch(runs, lift_off, touch_down):
    """Kept samples are single-support samples whose stance foot stayed down for at least ``lift_off`` before
    them (unless the run starts the log) and stays down for more than ``touch_down`` after them (unless
    the run ends the log)."""
    time, contact = sequence(*runs)
    ph = segment(time, contact, lift_off, touch_down)
    assert not (ph.keep & ~ph.single).any()
    assert ((ph.stance >= 0) == ph.single).all()
    n = len(time)
    for k in np.flatnonzero(ph.keep):
        same = (ph.stance == ph.stance[k])
        a = k
        while a > 0 and same[a - 1]:
            a -= 1
        b = k + 1
        while b < n and same[b]:
            b += 1
        assert a == 0 or time[k] - time[a] >= lift_off - 1e-9
        assert b == n or time[b] - time[k] > touch_down + 1e-9

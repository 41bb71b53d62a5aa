"""Logs with time gaps are estimated segment by segment, never differentiated across a gap."""

from __future__ import annotations

import re

import numpy as np
import pyarrow as pa
import pytest

from wbfriction.exceptions import InputError, OptionError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions, MomentumOptions
from wbfriction.logs.log import log_from_table
from wbfriction.signals.options import FilterOptions


def _drop(talos, log, start: int, stop: int, n: int):
    """The first ``n`` rows of ``log`` without rows [start, stop): a gap in the time column."""
    table = log.to_table(talos).slice(0, n)
    keep = np.r_[np.arange(start), np.arange(stop, n)]
    return log_from_table(table.take(pa.array(keep)), talos, "gapped")


@pytest.mark.parametrize("diff", ["central", "savgol"])
def test_gapped_log_is_its_segments_estimated_apart(talos, combined_walk, diff):
    n, a, b = 6000, 3000, 3040  # 40 ms of dropped samples
    log = _drop(talos, combined_walk.log, a, b, n)
    assert log.segments == [(0, a), (a, n - (b - a))]
    opts = EstimateOptions(diff=diff)
    whole = estimate_log(talos, log, opts)
    first, second = (estimate_log(talos, part, opts) for part in log.parts())
    for name in ("tau_f", "qd", "delta_qdd"):
        got, parts = getattr(whole, name), np.concatenate([getattr(first, name), getattr(second, name)])
        np.testing.assert_array_equal(got, parts)
    # the lift-off and touch-down margins apply at the gap (the feet's motion in it is not known):
    # the only samples the parts-as-logs keep and the gapped log drops lie within them
    apart = np.concatenate([first.valid, second.valid])
    assert not (whole.valid & ~apart).any()
    rows = np.flatnonzero((apart & ~whole.valid).any(axis=1))
    margins = (log.time[rows] >= log.time[a - 1] - opts.touch_down_skip - 2e-3) & (
        log.time[rows] <= log.time[a] + opts.lift_off_skip + 2e-3)
    assert rows.size and margins.all()
    # nothing differentiated across the gap: the rows at its edges have no derivative
    assert np.isnan(whole.qd[a - 1]).all() and np.isnan(whole.qd[a]).all()
    # and the estimate away from the gap is that of the log without a gap
    ref = estimate_log(talos, log_from_table(combined_walk.log.to_table(talos).slice(0, n), talos, "x"), opts)
    # (to rounding: the sampling period is the median step of each segment's own stamps)
    np.testing.assert_allclose(whole.tau_f[:a - 200], ref.tau_f[:a - 200], atol=1e-9, rtol=1e-9)
    np.testing.assert_allclose(whole.tau_f[-500:], ref.tau_f[-500:], atol=1e-9, rtol=1e-9)


def test_a_segment_that_cannot_be_estimated_is_left_blank(talos, combined_walk):
    """A 30-sample segment is too short for a 151-sample Savitzky-Golay window: its rows are NaN
    and invalid, the rest is estimated. Through central differences the same segment (double
    support) is estimated, not unique, never valid. A log of double support only is refused."""
    log = combined_walk.log
    ds = int(np.flatnonzero(log.contact.all(axis=1))[0])  # double support at the start
    table = log.to_table(talos)
    rows = np.r_[np.arange(ds, ds + 30), np.arange(3000, 6000)]
    gapped = log_from_table(table.take(pa.array(rows)), talos, "gapped")
    assert gapped.segments == [(0, 30), (30, 3030)]
    est = estimate_log(talos, gapped, EstimateOptions(diff="savgol"))
    assert np.isnan(est.tau_f[:30]).all() and not est.valid[:30].any()
    assert est.valid[30:].any()
    central = estimate_log(talos, gapped, EstimateOptions(diff="central", route="acceleration"))
    assert np.isfinite(central.tau_f[1:29]).all() and not central.unique[:30].any() and not central.valid[:30].any()
    only = log_from_table(table.take(pa.array(np.r_[np.arange(ds, ds + 30), np.arange(ds + 100, ds + 130)])),
                          talos, "gapped")
    with pytest.raises(InputError, match="gapped: no single-support sample"):
        estimate_log(talos, only, EstimateOptions())


@pytest.fixture(scope="module")
def panda_sim():
    """3 s of the built-in Panda (the arm simulator: 1 kHz, 19-bit encoders, no torque noise)."""
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.arm import ArmOptions, ExcitationOptions, default_arm_friction, simulate_arm
    robot = load_robot("panda")
    options = ArmOptions(duration=3.0, excitation=ExcitationOptions(period=3.0))
    return robot, simulate_arm(robot, default_arm_friction(robot), options=options).table


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def test_an_arm_logged_by_a_clock_that_skips_one_sample_in_seven(panda_sim):
    """Issue 53: a Panda log with one sample in seven dropped (exact 1 ms stamps) at the default max_gap is
    one segment, differentiated on its stamps: the injected friction comes back at its samples, as from the
    whole log."""
    robot, table = panda_sim
    keep = np.flatnonzero(np.arange(table.num_rows) % 7 != 3)
    log = log_from_table(table.take(pa.array(keep)), robot, "skip7")
    assert log.segments == [(0, keep.size)] and log.clock.kind == "skipping"
    for route in ("acceleration", "momentum"):
        est = estimate_log(robot, log, EstimateOptions(route=route))
        assert est.valid.mean() > 0.8, route
        truth = est.tau_f_true
        for j in range(len(est.joints)):
            v = est.valid[:, j]
            assert _rms(est.tau_f[v, j] - truth[v, j]) < 0.1 * _rms(truth[v, j]), (route, est.joints[j])


def test_a_gap_costs_an_arm_no_contact_margins(panda_sim):
    """A fixed-base arm has no contacts to lift off or touch down: a 40 ms dropout costs only the rows the
    differentiation cannot reach, as if each segment were a log of its own."""
    robot, table = panda_sim
    n, a, b = 2500, 1200, 1240
    keep = np.r_[np.arange(a), np.arange(b, n)]
    log = log_from_table(table.take(pa.array(keep)), robot, "gapped")
    assert log.segments == [(0, a), (a, n - (b - a))]
    opts = EstimateOptions(diff="central", route="acceleration")
    whole = estimate_log(robot, log, opts)
    apart = np.concatenate([estimate_log(robot, part, opts).valid for part in log.parts()])
    np.testing.assert_array_equal(whole.valid, apart)
    assert whole.valid[a + 1:a + 100].all() and whole.valid[a - 100:a - 1].all()


@pytest.mark.parametrize(("options", "message"), [
    (dict(route="momentum", momentum=MomentumOptions(None, 99_999)),
     "--momentum-window must be at most the 1000 samples of the log's longest stretch without a time gap, "
     "got 99999"),
    (dict(route="momentum", momentum=MomentumOptions(5_001, None)), "--velocity-window must be at most the 1000"),
    (dict(route="momentum", momentum=MomentumOptions(501, 601)),
     "--momentum-window must be at most the 1000 samples of the log's longest stretch without a time gap, less "
     "--velocity-window 501 - 1, got 601"),
    (dict(route="acceleration", diff="savgol", filtering=FilterOptions(window=2_001)),
     "--window must be at most the 1000 samples"),
    (dict(route="acceleration", diff="butterworth", filtering=FilterOptions(cutoff=0.05)),
     "--cutoff must be high enough for the filter's response"),
    (dict(route="acceleration", diff="butterworth", filtering=FilterOptions(cutoff=1e-6)),
     "--cutoff must be high enough for the filter's response"),
])
def test_a_window_no_stretch_of_the_log_holds_is_refused_naming_the_option(panda_sim, options, message):
    """Issue 53: a window longer than the log (a 2.3 TiB allocation for --momentum-window 99999, or 'no
    single-support sample' on an arm) is refused in one line naming the option, before the work."""
    import time
    robot, table = panda_sim
    log = log_from_table(table.slice(0, 1000), robot, "short")
    start = time.perf_counter()
    with pytest.raises(OptionError, match=re.escape(message)):
        estimate_log(robot, log, EstimateOptions(**options))
    assert time.perf_counter() - start < 8.0  # the noise measured, nothing estimated


def test_stretches_too_short_for_any_window_are_refused_in_one_line(panda_sim):
    """Five-sample stretches between 10 ms dropouts: the momentum route's least windows (7 and 3 samples) do
    not fit; the one line says how long the stretches are, not 'no single-support sample'."""
    robot, table = panda_sim
    k = np.arange(table.num_rows)
    log = log_from_table(table.take(pa.array(np.flatnonzero(k % 15 < 5))), robot, "seg5")
    with pytest.raises(InputError, match=re.escape("seg5: the longest stretch without a time gap has 5 samples, "
                                                   "fewer than the momentum route's windows")):
        estimate_log(robot, log, EstimateOptions(route="momentum"))


def test_a_fit_on_stretches_too_short_to_measure_the_noise_is_never_ok(panda_sim):
    """Issue 53: 10 ms dropouts every 60 ms leave 50-sample stretches, too short to measure the positions' noise
    (no Cramér-Rao bound, central differences): no fit is called ok, each says why."""
    from wbfriction.fit.joints import fit_estimate
    robot, table = panda_sim
    k = np.arange(table.num_rows)
    log = log_from_table(table.take(pa.array(np.flatnonzero(k % 60 < 50))), robot, "drop10")
    assert len(log.segments) > 40 and max(b - a for a, b in log.segments) == 50
    est = estimate_log(robot, log)
    verdicts = [f.verdict() for f in fit_estimate(est)]
    assert all(v.status not in ("ok",) for v in verdicts), verdicts
    weak = [v for v in verdicts if v.status == "weak"]
    assert weak and all("the positions' noise could not be measured: the longest stretch without a time gap has 50 "
                        "samples" in v.reason for v in weak), verdicts


def test_an_arm_is_told_why_nothing_was_estimated_without_contacts_or_masks(panda_sim):
    """Issue 53: on a fixed base (always welded) the error names the windows, not contact columns or --mask."""
    from wbfriction.friction.estimated import no_single_support
    robot, _ = panda_sim
    message = str(no_single_support(robot, "arm.parquet"))
    assert message.startswith("arm.parquet: no sample with defined derivatives: every stretch between time gaps")
    assert "contact." not in message and "--mask" not in message

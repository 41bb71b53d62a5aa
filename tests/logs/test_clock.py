"""The clock behind a log's stamps: uniform, exact stamps that skip samples, receive-time jitter;
decided by measuring, said in one line, overridable; epoch stamps keep their precision; and,
end to end, the friction of a simulated walk logged either way is that of the walk logged
uniformly."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import KUKA
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.clock import VERDICT, lattice_period, read_clock, split_at_gaps
from wbfriction.logs.log import log_from_table


def _motion(t):
    w, a = np.array([2.1, 5.3, 0.7]), np.array([0.5, 0.2, 1.0])
    return a * np.sin(w * t[:, None] + 1.0)


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def test_uniform_stamps():
    t = np.arange(500) * 1e-3 + np.random.default_rng(0).uniform(0, 2e-5, 500)  # 2 % jitter
    clock = read_clock(t, "u")
    assert clock.kind == "uniform" and clock.uniform and clock.roughness is None
    assert clock.step == float(np.median(np.diff(t))) and clock.segments == [(0, 500)]
    np.testing.assert_array_equal(clock.t, t - t[0])
    assert clock.reason.startswith("time: uniform stamps every 1 ms")


@pytest.mark.parametrize("with_positions", [True, False])
def test_a_clock_that_skips_samples(with_positions):
    """Steps of 10 and 12 ms from a 2 ms clock, stamped exactly: taken as recorded, the 2 ms
    clock found (from the positions' roughness, or without positions from the steps' lattice)."""
    rng = np.random.default_rng(1)
    t = 1.7e9 + np.concatenate([[0.0], np.cumsum(rng.choice([10, 12], 999))]) * 2e-3 / 2
    clock = read_clock(t, "a", q=_motion(t - t[0]) if with_positions else None)
    assert clock.kind == "skipping"
    assert clock.lattice == pytest.approx(2e-3, rel=1e-6) and clock.period == clock.lattice
    np.testing.assert_array_equal(clock.t, t - t[0])
    assert "exact stamps of a 2 ms clock skipping samples (steps 10-12 ms = 5-6 ticks)" in clock.reason
    assert "differentiating on the stamps as recorded" in clock.reason
    if with_positions:
        rec, reg = clock.roughness
        assert reg > VERDICT * rec
    else:
        assert clock.roughness is None and "no positions to compare" in clock.reason


def test_samples_at_jittered_instants_stamped_exactly():
    """1 kHz data whose samples were taken 0.7-8.8 ms apart (no common base period): the
    positions are smoother on the stamps than on any regularised clock."""
    rng = np.random.default_rng(2)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.7, 1.3, 3000))]) * 1e-3
    t[1000:] += 7.5e-3  # one step of 8.2-8.8 ms, a gap unless max_gap says otherwise
    clock = read_clock(t, "a", q=_motion(t), max_gap=10)
    assert clock.kind == "skipping" and clock.lattice is None and clock.segments == [(0, 3001)]
    rec, reg = clock.roughness
    assert reg > 100 * rec
    assert "exact stamps of non-uniform samples (steps 0.7-8.8 ms" in clock.reason
    assert read_clock(t, "a", q=_motion(t)).segments == [(0, 1000), (1000, 3001)]


@pytest.mark.parametrize("with_positions", [True, False])
def test_receive_time_stamps_are_regularised(with_positions):
    """Uniform 5 ms samples stamped on arrival, 0-1.8 ms late, Unix epoch: a regularised clock, the
    period recovered, the regular times recovered up to a constant (the mean latency)."""
    rng = np.random.default_rng(3)
    k = np.arange(5000)
    stamps = 1.46e9 + k * 5e-3 + rng.uniform(0.0, 1.8e-3, k.size)
    clock = read_clock(stamps, "b", q=_motion(k * 5e-3) if with_positions else None)
    assert clock.kind == "jittered" and clock.lattice is None
    assert clock.period == pytest.approx(5e-3, rel=1e-5) and clock.step == clock.period
    offset = clock.t - k * 5e-3
    assert np.ptp(offset) < 0.05 * 1.8e-3  # the stamps scatter over 1.8 ms
    assert "receive-time stamps scattered around a 5 ms clock" in clock.reason
    assert "differentiating on a regularised clock" in clock.reason
    if with_positions:
        rec, reg = clock.roughness
        assert rec > 100 * reg
        assert "x smoother than on the stamps" in clock.reason


def test_the_time_base_can_be_forced_and_the_reason_says_so():
    rng = np.random.default_rng(4)
    k = np.arange(2000)
    stamps = k * 5e-3 + rng.uniform(0.0, 1.8e-3, k.size)
    q = _motion(k * 5e-3)
    forced = read_clock(stamps, "b", q=q, time_base="recorded")
    assert forced.kind == "skipping"
    np.testing.assert_array_equal(forced.t, stamps - stamps[0])
    assert "receive-time stamps" in forced.reason and "as recorded, as asked" in forced.reason
    assert "x rougher than on a regularised clock" in forced.reason
    uniform = np.arange(100) * 1e-3
    assert read_clock(uniform, "u", time_base="regularised").kind == "jittered"
    with pytest.raises(InputError, match="unknown time base 'exact'"):
        read_clock(uniform, "u", time_base="exact")  # type: ignore[arg-type]


@settings(max_examples=80, deadline=None)
@given(steps=st.lists(st.floats(1e-4, 10.0), min_size=4, max_size=300), base=st.sampled_from(["auto", "recorded",
                                                                                               "regularised"]))
def test_any_increasing_stamps_give_a_clock(steps, base):
    """Whatever the steps: segments cover every row in order, the time base increases within
    each segment, and a uniform clock keeps the stamps."""
    t = np.concatenate([[0.0], np.cumsum(steps)])
    clock = read_clock(t, "h", q=_motion(t), time_base=base)
    edges = [a for a, _ in clock.segments] + [clock.segments[-1][1]]
    assert edges[0] == 0 and edges[-1] == len(t) and all(b == c for (_, b), (c, _) in zip(clock.segments[:-1],
                                                                                          clock.segments[1:]))
    for a, b in clock.segments:
        assert np.all(np.diff(clock.t[a:b]) > 0)
    assert clock.step > 0 and clock.period > 0 and clock.reason.startswith("time: ")
    if clock.kind != "jittered":
        np.testing.assert_array_equal(clock.t, t)


def test_lattice_period():
    assert lattice_period(np.array([10e-3, 12e-3, 10e-3, 14e-3])) == pytest.approx(2e-3)
    assert lattice_period(np.array([1e-3, 2e-3, 3e-3, 1e-3])) == pytest.approx(1e-3)
    assert lattice_period(np.random.default_rng(5).uniform(3.2e-3, 6.8e-3, 500)) is None


def test_gaps_are_measured_against_the_local_median_step():
    """A pause splits the log; a change of rate (1 ms, then 2 ms steps) does not."""
    t = np.concatenate([np.arange(300) * 1e-3, 0.5 + np.arange(300) * 1e-3])
    assert split_at_gaps(t, "g") == [(0, 300), (300, 600)]
    t = np.concatenate([np.arange(300) * 1e-3, 0.3 + np.arange(300) * 2e-3])
    assert split_at_gaps(t, "g") == [(0, 600)]
    clock = read_clock(t, "g")
    assert clock.kind == "skipping" and clock.lattice == pytest.approx(1e-3)


@pytest.mark.parametrize("integer", [False, True])
def test_duplicated_and_decreasing_stamps_are_refused(integer):
    t = np.arange(50) * 1_000_000 + 1_700_000_000_000_000_000 if integer else np.arange(50) * 1e-3
    for edit, what in ((lambda s: s.__setitem__(10, s[9]), "duplicated"),
                       (lambda s: s.__setitem__(10, s[9] - s[1] + s[0]), "decreasing")):
        s = t.copy()
        edit(s)
        with pytest.raises(ColumnError, match=f"column 'time' has a {what} stamp at row 110") as err:
            read_clock(s, "x.parquet", first_row=100)
        assert err.value.column == "time" and err.value.row == 110
    with pytest.raises(InputError, match="only 4 rows"):
        read_clock(t[:4], "x")


def test_epoch_stamps_keep_their_precision():
    """Integer nanoseconds are subtracted as integers: the same clock as the same stamps counted
    from zero; float epoch seconds give the clock of their offsets to the stamps' own rounding."""
    rng = np.random.default_rng(6)
    ns = 1_700_000_000_000_000_000 + np.arange(3000) * 5_000_000 + rng.integers(0, 1_800_000, 3000)
    a, b = read_clock(ns, "ns"), read_clock(ns - ns[0], "ns")
    assert a.kind == b.kind == "jittered" and a.t0 == pytest.approx(1.7e9)
    np.testing.assert_array_equal(a.t, b.t)
    assert a.period == b.period
    exact = np.arange(3000, dtype=np.int64) * 1_000_000 + 1_700_000_000_123_456_789
    clock = read_clock(exact, "ns")
    assert clock.kind == "uniform" and clock.step == 1e-3
    np.testing.assert_allclose(clock.t, np.arange(3000) * 1e-3, rtol=0, atol=1e-15)
    seconds = 1.46e9 + (ns - ns[0]) * 1e-9
    c = read_clock(seconds, "s")
    np.testing.assert_allclose(c.t, b.t, rtol=0, atol=1e-6)  # float64 epoch seconds: 0.24 us apart
    assert c.period == pytest.approx(b.period, rel=1e-9)


def test_rows_of_a_clock_keep_the_whole_logs_times():
    rng = np.random.default_rng(7)
    stamps = np.arange(1000) * 5e-3 + rng.uniform(0, 1.8e-3, 1000)
    stamps[600:] += 1.0  # a gap
    clock = read_clock(stamps, "r")
    assert clock.kind == "jittered" and clock.segments == [(0, 600), (600, 1000)]
    part = clock.rows(500, 800)
    np.testing.assert_array_equal(part.t, clock.t[500:800])
    assert part.segments == [(0, 100), (100, 300)] and part.reason == clock.reason and part.t0 == clock.t0
    assert clock.rows(0, 100).segments == [(0, 100)]


@pytest.mark.skipif(not KUKA.is_dir(), reason=f"real KUKA logs not found at {KUKA} (set WBFRICTION_REAL_DATA)")
@pytest.mark.parametrize("run", [1, 2, 3])
def test_kuka_logs_are_receive_time_stamps(run):
    """The KUKA LWR4+ logs (epoch stamps, 3.2-6.8 ms steps around 5 ms): the positions are far
    smoother on a regularised 5 ms clock than on the stamps."""
    data = np.load(KUKA / f"measurements_{run}.npz")
    clock = read_clock(data["times"], f"measurements_{run}.npz", q=data["positions"])
    assert clock.kind == "jittered" and clock.period == pytest.approx(5e-3, rel=1e-4)
    rec, reg = clock.roughness
    assert rec > 10 * reg
    assert clock.reason.startswith("time: receive-time stamps scattered around a 5 ms clock")


# ------------------------------------------------------------------ end to end: friction
@pytest.fixture(scope="module")
def walk_table(talos, combined_walk):
    """The first 6 s of the simulated walk (1 kHz, true friction on the legs) as a table."""
    return combined_walk.log.to_table(talos).slice(0, 6000)


@pytest.mark.parametrize("diff", ["central", "savgol"])
def test_friction_of_a_walk_logged_by_a_clock_that_skips_samples(talos, walk_table, diff):
    """Samples taken at jittered instants (every 2 ms, one in two taken 1 ms late) and stamped
    exactly: the friction equals that of the same walk logged uniformly every 2 ms, at the
    instants both have, within 1 % RMS (central differences: 1.2 %, their first-order error
    on steps of 1 to 3 ms); estimated with a constant period, at least twice that."""
    late = np.random.default_rng(8).integers(0, 2, 3000)
    skipping = log_from_table(walk_table.take(pa.array(2 * np.arange(3000) + late)), talos, "a")
    uniform = log_from_table(walk_table.take(pa.array(2 * np.arange(3000))), talos, "u")
    assert skipping.clock.kind == "skipping" and uniform.clock.kind == "uniform"
    opts = EstimateOptions(diff=diff)
    a, u = estimate_log(talos, skipping, opts), estimate_log(talos, uniform, opts)
    both = (late == 0)[:, None] & a.valid & u.valid
    assert both.sum() > 10_000
    tol = 1.2e-2 if diff == "central" else 1e-2
    assert _rms(a.tau_f[both] - u.tau_f[both]) < tol * _rms(u.tau_f[both])
    skipping.clock = None  # a constant period, as before
    naive = estimate_log(talos, skipping, opts)
    both &= naive.valid
    assert _rms(naive.tau_f[both] - u.tau_f[both]) > 2 * tol * _rms(u.tau_f[both])


@pytest.mark.parametrize("diff", ["central", "savgol"])
def test_friction_of_a_walk_logged_with_receive_time_stamps(talos, walk_table, diff):
    """The uniform 1 kHz samples stamped on arrival (epoch, 0-0.4 ms late): the friction equals
    that of the walk logged uniformly within 1 % RMS; on the stamps as recorded, off by at least
    twice that."""
    n = walk_table.num_rows
    time = walk_table.column("time").to_numpy()
    late = 1.46e9 + time + np.random.default_rng(9).uniform(0.0, 0.4e-3, n)
    stamped = walk_table.set_column(walk_table.column_names.index("time"), "time", pa.array(late))
    jittered = log_from_table(stamped, talos, "b")
    assert jittered.clock.kind == "jittered"
    opts = EstimateOptions(diff=diff)
    b, u = estimate_log(talos, jittered, opts), estimate_log(talos, log_from_table(walk_table, talos, "u"), opts)
    both = b.valid & u.valid
    assert both.sum() > 20_000
    assert _rms(b.tau_f[both] - u.tau_f[both]) < 1e-2 * _rms(u.tau_f[both])
    recorded = estimate_log(talos, log_from_table(stamped, talos, "b", time_base="recorded"), opts)
    both &= recorded.valid
    assert _rms(recorded.tau_f[both] - u.tau_f[both]) > 2e-2 * _rms(u.tau_f[both])

"""Differentiation schemes, delay compensation, torque alignment and phase masks."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.logs.clock import read_clock
from wbfriction.logs.log import Log
from wbfriction.signals.kinematics import align_torque, central_differences, measure
from wbfriction.signals.nonuniform import three_point_differences
from wbfriction.signals.options import FilterOptions
from wbfriction.signals.phases import joint_mask, segment

DT = 1e-3


@given(st.floats(-5, 5), st.floats(-5, 5), st.floats(-5, 5))
def test_central_differences_exact_on_quadratics(c0, c1, c2):
    t = np.arange(50) * DT
    q = (c0 + c1 * t + c2 * t**2)[:, None]
    qd, qdd, delay = central_differences(q, DT)
    assert delay == 0
    np.testing.assert_allclose(qd[1:-1, 0], c1 + 2 * c2 * t[1:-1], atol=1e-8)
    np.testing.assert_allclose(qdd[1:-1, 0], 2 * c2, atol=1e-5)
    assert np.isnan(qd[[0, -1]]).all() and np.isnan(qdd[[0, -1]]).all()


def _log(q, tau=None):
    n = len(q)
    tau = np.zeros((n, 1)) if tau is None else tau
    return Log(time=np.arange(n) * DT, q=q, tau=tau, contact=np.ones((n, 1), dtype=bool))


def test_backward_compensated_acceleration_equals_central():
    t = np.arange(200) * DT
    q = np.sin(3 * t)[:, None]
    c = measure(_log(q), "central")
    b = measure(_log(q), "backward", compensate_delay=True)
    np.testing.assert_allclose(b.qdd[1:-1], c.qdd[1:-1], atol=1e-9)
    # velocity keeps half a sample of delay: forward difference, error ~ dt/2 * qdd
    err_b = np.nanmax(np.abs(b.qd[:, 0] - 3 * np.cos(3 * t)))
    err_c = np.nanmax(np.abs(c.qd[:, 0] - 3 * np.cos(3 * t)))
    assert err_c < 1e-5 < err_b < 9 * DT / 2 * 1.01


def test_backward_uncompensated_lags_one_sample():
    t = np.arange(200) * DT
    q = np.sin(3 * t)[:, None]
    b = measure(_log(q), "backward", compensate_delay=False)
    np.testing.assert_allclose(b.qdd[2:, 0], -9 * np.sin(3 * (t[2:] - DT)), atol=1e-4)


def test_zoh_alignment_matches_held_torque():
    """A double integrator driven by a held input: the second difference sees the mean."""
    rng = np.random.default_rng(0)
    u = rng.normal(0, 1, 100)  # acceleration held over each period (exact integration)
    q, v = [0.0], 0.0
    for k in range(99):
        q.append(q[-1] + v * DT + 0.5 * u[k] * DT**2)
        v += u[k] * DT
    q = np.array(q)[:, None]
    _, qdd, _ = central_differences(q, DT)
    np.testing.assert_allclose(qdd[1:-1, 0], align_torque(u[:, None], "zoh")[1:-1, 0], atol=1e-6)
    assert np.abs(qdd[1:-1, 0] - u[1:-1]).max() > 0.1  # "sample" alignment would be wrong


def test_unknown_scheme_and_alignment_raise():
    q = np.zeros((10, 1))
    with pytest.raises(InputError, match="differentiation scheme"):
        measure(_log(q), "spline")
    with pytest.raises(InputError, match="torque alignment"):
        align_torque(q, "foh")


def test_segment_drops_margins_around_switches():
    t = np.arange(1000) * DT
    contact = np.ones((1000, 2), dtype=bool)
    contact[200:700, 1] = False  # single support on contact 0 from 0.2 s to 0.7 s
    ph = segment(t, contact, 0.10, 0.05)
    kept = np.flatnonzero(ph.keep)
    assert kept[0] == 300 and kept[-1] == 649
    assert (ph.stance[200:700] == 0).all() and (ph.stance[:200] == -1).all()
    assert list(ph.labels()[[0, 300]]) == ["double", "single"]
    limb = np.array([[True, False, False], [False, True, False]])  # joint 2 on no limb
    swing = joint_mask(ph, limb, "swing")
    single = joint_mask(ph, limb, "single")
    assert not swing[300, 0] and swing[300, 1] and swing[300, 2]
    assert single[300].all() and not single[100].any()


def test_segment_does_not_trim_at_log_edges():
    t = np.arange(100) * DT
    contact = np.zeros((100, 2), dtype=bool)
    contact[:, 0] = True
    assert segment(t, contact).keep.all()


# ------------------------------------------------------------- non-uniform sample times
def _motion(t):
    """A smooth motion of three joints: q, qd, qdd at times t (N,)."""
    w, a = np.array([2.1, 5.3, 0.7]), np.array([0.5, 0.2, 1.0])
    phase = w * t[:, None] + 1.0
    return a * np.sin(phase), a * w * np.cos(phase), -a * w**2 * np.sin(phase)


def _clocked(stamps, q, tau=None, **kw):
    n = len(stamps)
    clock = read_clock(stamps, "test", q=q, **kw)
    return Log(time=np.asarray(stamps, dtype=float), q=q, tau=np.zeros((n, 1)) if tau is None else tau,
               contact=np.ones((n, 1), dtype=bool), clock=clock)


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


FILTERS = FilterOptions(window=51, cutoff=20.0)


def test_zoh_alignment_on_non_uniform_steps_matches_held_torque():
    """A double integrator driven by a held input over uneven periods: the three-point second
    difference sees each torque weighed by how long it was held."""
    rng = np.random.default_rng(1)
    h = rng.uniform(0.5, 2.0, 99) * DT
    t = np.concatenate([[0.0], np.cumsum(h)])
    u = rng.normal(0, 1, 100)
    q, v = [0.0], 0.0
    for k in range(99):
        q.append(q[-1] + v * h[k] + 0.5 * u[k] * h[k] ** 2)
        v += u[k] * h[k]
    _, qdd, _ = three_point_differences(np.array(q)[:, None], t)
    np.testing.assert_allclose(qdd[1:-1, 0], align_torque(u[:, None], "zoh", t)[1:-1, 0], atol=1e-6)
    assert np.abs(qdd[1:-1, 0] - align_torque(u[:, None], "zoh")[1:-1, 0]).max() > 0.1  # the plain mean is wrong


@pytest.mark.parametrize("diff", ["central", "backward", "savgol", "butterworth"])
def test_samples_at_jittered_instants_stamped_exactly(diff):
    """Kind (a): samples taken 0.7-1.3 ms apart and stamped exactly are differentiated on their
    stamps; the derivatives equal those of the same motion logged uniformly (which are the
    motion's own, checked too) within 1 % RMS. Differentiated with a constant period, they would not be."""
    rng = np.random.default_rng(2)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.7, 1.3, 3999))]) * DT
    q, qd, qdd = _motion(t)
    log = _clocked(t, q)
    assert log.clock.kind == "skipping" and "differentiating on the stamps as recorded" in log.clock.reason
    m = measure(log, diff, filtering=FILTERS)
    tu = np.arange(4000) * DT
    _, qd_u, qdd_u = _motion(tu)
    u = measure(Log(time=tu, q=_motion(tu)[0], tau=np.zeros((4000, 1)), contact=np.ones((4000, 1), dtype=bool)),
                diff, filtering=FILTERS)
    ok, ok_u = np.isfinite(m.qdd).all(axis=1), np.isfinite(u.qdd).all(axis=1)
    assert ok.sum() > 3500
    assert _rms(u.qdd[ok_u] - qdd_u[ok_u]) < 1e-3 * _rms(qdd_u)  # the uniform log: the motion's derivatives
    tol = 1e-2 if diff != "backward" else 2e-2  # backward: a velocity half a step late, as on uniform samples
    assert _rms(m.qd[ok] - qd[ok]) < tol * _rms(qd[ok])
    assert _rms(m.qdd[ok] - qdd[ok]) < 1e-2 * _rms(qdd[ok])
    naive = measure(Log(time=t, q=q, tau=log.tau, contact=log.contact), diff, filtering=FILTERS)
    ok = np.isfinite(naive.qdd).all(axis=1)
    assert _rms(naive.qdd[ok] - qdd[ok]) > 0.1 * _rms(qdd[ok])


@pytest.mark.parametrize("diff", ["central", "savgol", "butterworth"])
def test_uniform_samples_with_receive_time_stamps(diff):
    """Kind (b): uniform 5 ms samples stamped on arrival, 0-1.8 ms late (Unix epoch), are
    differentiated on the regularised clock: the derivatives equal those of the same samples
    logged uniformly within 1 % RMS; on the stamps as recorded they would be far off."""
    rng = np.random.default_rng(3)
    k = np.arange(3000)
    q, _, _ = _motion(k * 5e-3)
    stamps = 1.46e9 + k * 5e-3 + rng.uniform(0.0, 1.8e-3, k.size)
    log = _clocked(stamps, q)
    assert log.clock.kind == "jittered" and "regularised clock" in log.clock.reason
    assert log.dt == pytest.approx(5e-3, rel=1e-5)
    m = measure(log, diff, filtering=FILTERS)
    u = measure(Log(time=k * 5e-3, q=q, tau=log.tau, contact=log.contact), diff, filtering=FILTERS)
    ok = np.isfinite(m.qdd).all(axis=1) & np.isfinite(u.qdd).all(axis=1)
    assert ok.sum() > 2500
    assert _rms(m.qd[ok] - u.qd[ok]) < 1e-2 * _rms(u.qd[ok])
    assert _rms(m.qdd[ok] - u.qdd[ok]) < 1e-2 * _rms(u.qdd[ok])
    recorded = measure(_clocked(stamps, q, time_base="recorded"), diff, filtering=FILTERS)
    assert recorded.metadata["clock"]["kind"] == "skipping"
    ok = np.isfinite(recorded.qdd).all(axis=1) & np.isfinite(u.qdd).all(axis=1)
    assert _rms(recorded.qdd[ok] - u.qdd[ok]) > 2e-2 * _rms(u.qdd[ok])


@pytest.mark.parametrize("diff", ["central", "backward", "savgol", "butterworth"])
def test_a_uniform_clock_changes_nothing(diff):
    """A uniform clock is differentiated with its constant period, bit for bit as a log without one."""
    rng = np.random.default_rng(4)
    t = np.arange(2000) * DT
    q = _motion(t)[0] + rng.normal(0, 1e-6, (2000, 3))
    tau = rng.normal(0, 1, (2000, 3))
    clocked = _clocked(t, q, tau)
    assert clocked.clock.kind == "uniform"
    a = measure(clocked, diff, filtering=FILTERS)
    b = measure(Log(time=t, q=q, tau=tau, contact=clocked.contact), diff, filtering=FILTERS)
    for name in ("q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.metadata == b.metadata and a.smoother == b.smoother


@pytest.mark.parametrize("kind", ["skipping", "jittered"])
@pytest.mark.parametrize("diff", ["central", "savgol", "butterworth"])
def test_chunks_of_a_non_uniform_log_equal_the_whole(kind, diff):
    """A chunk cut at contact changes (as the long-log pipeline cuts them), given its rows of the
    whole log's clock (Clock.rows) and 3 rows of context, gives the whole log's derivatives to
    1e-10; a chunk's own regularised clock would not."""
    rng = np.random.default_rng(5)
    n = 3000
    if kind == "skipping":
        stamps = np.concatenate([[0.0], np.cumsum(rng.choice([10e-3, 12e-3], n - 1))])
        q = _motion(stamps)[0]
    else:
        stamps = 1.46e9 + np.arange(n) * 5e-3 + rng.uniform(0.0, 1.8e-3, n)
        q = _motion(np.arange(n) * 5e-3)[0]
    a, b, context = 1000, 2000, 3
    whole = _clocked(stamps, q)
    whole.contact = np.ones((n, 2), dtype=bool)
    whole.contact[a:b, 1] = False  # contact changes at rows a and b
    assert whole.clock.kind == kind
    ref = measure(whole, diff, filtering=FILTERS)
    chunk = measure(whole.rows(a - context, b + context), diff, filtering=FILTERS)
    for name in ("qd", "qdd"):
        got, want = getattr(chunk, name)[context:-context], getattr(ref, name)[a:b]
        ok = np.isfinite(want)
        assert ok.sum() > 600
        np.testing.assert_array_equal(np.isfinite(got), ok)
        np.testing.assert_allclose(got[ok], want[ok], rtol=1e-10, atol=1e-10 * np.abs(want[ok]).max())
    if kind == "jittered":
        own = read_clock(stamps[a - context:b + context], "chunk", q=q[a - context:b + context])
        assert np.abs(np.diff(own.t) - np.diff(whole.clock.t[a - context:b + context])).max() > 1e-9


@pytest.mark.parametrize("diff, filtering", [("savgol", FilterOptions(window=51, poly_order=4)),
                                             ("butterworth", FilterOptions(cutoff=20.0, butter_order=4))])
def test_filter_wiring_around_a_contact_change(diff, filtering):
    """Which signals a filtering scheme filters (issue 20's measurement, pinned): q, qdd and tau
    through the smoother; qd the filter's, but the raw central difference within the filter's
    margin of a contact change (where the filtered signals are NaN), NaN only on the rows whose
    stencil straddles it."""
    dt, n, k = 1e-3, 1200, 600
    t = np.arange(n) * dt
    rng = np.random.default_rng(2)
    q = np.column_stack([np.sin(2 * np.pi * 1.3 * t), 0.5 * np.cos(2 * np.pi * 0.7 * t)]) + rng.normal(0, 1e-6, (n, 2))
    tau = rng.normal(0, 1.0, (n, 2))
    contact = np.zeros((n, 1), dtype=bool)
    contact[k:] = True
    kin = measure(Log(t, q, tau, contact), diff, filtering=filtering, torque_alignment="sample")
    hw = kin.smoother.half_width
    qd_c = central_differences(q, dt)[0]
    straddle = np.array([k - 1, k])
    assert np.all(np.isnan(kin.qd[straddle]))
    margin = np.r_[k - 1 - hw:k - 1, k + 1:k + 1 + hw]
    assert np.all(np.isnan(kin.qdd[margin])) and np.all(np.isnan(kin.tau[margin]))
    assert np.allclose(kin.qd[margin], qd_c[margin], rtol=0, atol=1e-12)  # raw velocity in the margins
    inner = np.r_[2 * hw + 5:k - 2 * hw, k + 2 * hw:n - 2 * hw]
    assert np.all(np.isfinite(kin.qdd[inner])) and np.all(np.isfinite(kin.tau[inner]))
    assert not np.allclose(kin.qd[inner], qd_c[inner], rtol=0, atol=1e-9)  # the filter's velocity away from it
    smoothed = kin.smoother(np.where(np.arange(n)[:, None] < k - 1, tau, np.nan))
    first = np.r_[2 * hw + 5:k - 2 * hw]
    assert np.allclose(kin.tau[first], smoothed[first], rtol=0, atol=1e-12)  # the torque is filtered

"""Differentiation schemes, delay compensation, torque alignment and phase masks."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.signals.kinematics import align_torque, central_differences, measure
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

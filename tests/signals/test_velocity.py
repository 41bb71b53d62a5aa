"""The lag of logged velocities: a known delay is found, to a fraction of a sample."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.signals.kinematics import central_differences
from wbfriction.signals.velocity import velocity_lag


@settings(max_examples=25, deadline=None)
@given(delay=st.floats(0.0, 8.0), seed=st.integers(0, 1000))
def test_a_known_delay_is_found(delay, seed):
    rng = np.random.default_rng(seed)
    dt, n = 0.005, 3000
    t = np.arange(n) * dt
    f, phase = rng.uniform(0.1, 0.8, 3), rng.uniform(0, 2 * np.pi, 3)
    w = 2 * np.pi * f
    q = np.sin(w * t[:, None] + phase) / w
    qd_logged = np.cos(w * (t[:, None] - delay * dt) + phase)  # the velocity of delay samples ago
    qd_ref, _, _ = central_differences(q, dt)
    lag = velocity_lag(qd_logged, qd_ref, dt)
    assert lag.samples == pytest.approx(delay, abs=0.05)
    assert lag.seconds == pytest.approx(delay * dt, abs=0.05 * dt)
    assert lag.correlation > 0.99

"""The design space of ``excite`` (:mod:`wbfriction.excite.trajectory`): every vector of free variables is a Fourier
series at rest at both ends of each period, and the map is invertible (hypothesis)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.excite.trajectory import FourierSpace

finite = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 3), harmonics=st.integers(2, 7), period=st.floats(0.5, 20.0), data=st.data())
def test_every_design_starts_and_ends_at_rest_and_maps_back(n, harmonics, period, data):
    space = FourierSpace(n, harmonics, 2 * np.pi / period)
    x = np.array(data.draw(st.lists(finite, min_size=n * space.per_joint, max_size=n * space.per_joint)))
    traj = space.trajectory(x)
    q, qd, qdd = traj(np.array([0.0, period]))
    np.testing.assert_allclose(qd, 0.0, atol=1e-9)
    np.testing.assert_allclose(qdd, 0.0, atol=1e-9 * max(1.0, space.omega * harmonics))
    np.testing.assert_allclose(q[0], q[1], atol=1e-9)  # one period: where it started
    np.testing.assert_allclose(space.variables(traj), x, atol=1e-9)

"""The prior in physical parameters: its Jacobian against ``pin.Inertia`` (finite differences), and its
unit, one standard deviation of a body's mass, centre of mass or inertia about the centre of mass."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.inertia.consistency import PHYSICAL, body_prior, physical_jacobian
from wbfriction.inertia.options import PriorUncertainty

_PAIRS = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def _inertia(values) -> pin.Inertia:
    m, a, b, c, x, y, z, rx, ry, rz = values
    box = pin.Inertia.FromBox(m, a, b, c)
    return pin.SE3(pin.rpy.rpyToMatrix(rx, ry, rz), np.array([x, y, z])).act(box)


inertias = st.tuples(st.floats(0.05, 50), st.floats(0.01, 1), st.floats(0.01, 1), st.floats(0.01, 1),
                     *[st.floats(-1, 1)] * 3, *[st.floats(-3, 3)] * 3).map(_inertia)


def _phi(inertia: pin.Inertia) -> np.ndarray:
    return np.array([inertia.mass, *inertia.lever, *(inertia.inertia[i, j] for i, j in _PAIRS)])


def _pi(phi: np.ndarray) -> np.ndarray:
    """Dynamic parameters of physical ones, through ``pin.Inertia`` (the independent route)."""
    I = np.zeros((3, 3))
    for k, (i, j) in enumerate(_PAIRS):
        I[i, j] = I[j, i] = phi[4 + k]
    return pin.Inertia(phi[0], phi[1:4], I).toDynamicParameters()


@settings(max_examples=40, deadline=None)
@given(inertia=inertias)
def test_physical_jacobian_is_the_derivative_of_the_dynamic_parameters(inertia):
    phi = _phi(inertia)
    h = 1e-6 * np.maximum(np.abs(phi), 1e-3)
    numeric = np.column_stack([(_pi(phi + h[k] * np.eye(10)[k]) - _pi(phi - h[k] * np.eye(10)[k])) / (2 * h[k])
                               for k in range(10)])
    J = physical_jacobian(inertia.toDynamicParameters())
    assert np.allclose(J, numeric, rtol=1e-6, atol=1e-6 * np.abs(J).max())


@settings(max_examples=40, deadline=None)
@given(inertia=inertias, k=st.integers(0, 9))
def test_one_standard_deviation_of_a_physical_parameter_costs_one(inertia, k):
    """Moving one physical parameter (mass, a coordinate of the centre of mass, an entry of the
    inertia about it) by a small share of its standard deviation moves ``|L dpi|`` by that share."""
    unc = PriorUncertainty(mass=0.1, com=0.05, inertia=0.5)
    std, L = body_prior(inertia.toDynamicParameters(), unc)
    moment = np.linalg.eigvalsh(inertia.inertia)[-1]
    expected = [unc.mass * inertia.mass] + [unc.com] * 3 + [unc.inertia * max(moment, 0.4 * inertia.mass * 1e-4)] * 6
    assert np.allclose(std, expected)
    phi = _phi(inertia)
    step = 1e-6 * std[k] * np.eye(10)[k]  # small: the map from physical to dynamic parameters is not linear
    dpi = _pi(phi + step) - _pi(phi)
    assert np.linalg.norm(L @ dpi) == pytest.approx(1e-6, rel=1e-4), PHYSICAL[k]


def test_a_massless_body_is_measured_at_a_small_sphere():
    std, L = body_prior(np.zeros(10), min_mass=1e-3)
    assert std[0] == pytest.approx(1e-4) and np.all(np.isfinite(L))


@pytest.mark.parametrize("margin", [-0.1, 1.0, float("nan")])
def test_a_link_margin_outside_its_range_is_refused(margin):
    from wbfriction.exceptions import OptionError
    from wbfriction.inertia.options import InertialOptions

    with pytest.raises(OptionError, match="--link-margin must be at least 0 and below 1"):
        InertialOptions(link_margin=margin)

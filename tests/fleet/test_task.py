"""One log's rows (issue 25): the friction at reference speeds and its standard error, analytic cases."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.result import FitResult
from wbfriction.fleet.task import reference_friction
from wbfriction.friction.models import CoulombViscousParams, FrictionParams


@settings(max_examples=50, deadline=None)
@given(F_v=st.floats(0.0, 2.0), F_c=st.floats(0.0, 5.0), tau_os=st.floats(-1.0, 1.0), v=st.floats(0.01, 3.0),
       seed=st.integers(0, 2**32 - 1))
def test_coulomb_viscous_friction_at_a_speed_is_linear(F_v, F_c, tau_os, v, seed):
    """(f(v) - f(-v)) / 2 = F_c + F_v v exactly, and its variance v^2 C_vv + C_cc + 2 v C_vc (the delta method
    is exact for a model linear in its parameters); the offset drops out."""
    A = np.random.default_rng(seed).normal(size=(3, 3))
    cov = A @ A.T  # order (F_v, F_c, tau_os)
    fit = FitResult("j", 100, CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=tau_os), covariance=cov)
    value, se = reference_friction(fit, v)
    assert np.isclose(value, F_c + F_v * v, rtol=1e-12, atol=1e-12)
    assert np.isclose(se**2, v * v * cov[0, 0] + cov[1, 1] + 2 * v * cov[0, 1], rtol=1e-9, atol=1e-12)


def test_the_thesis_model_at_a_speed_matches_finite_differences():
    """The delta method's gradient for model (3.5) against central finite differences of the parameters."""
    p = FrictionParams(F_v=0.2, F_c=0.8, S=0.2, v_s=0.2, tau_os=0.5, a=40.0)
    x = p.as_vector()
    v = 0.15
    g = np.empty(x.size)
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(x[i]))
        up, down = x.copy(), x.copy()
        up[i] += h
        down[i] -= h
        f = [reference_friction(FitResult("j", 1, FrictionParams.from_vector(y), covariance=np.zeros((6, 6))), v)[0]
             for y in (up, down)]
        g[i] = (f[0] - f[1]) / (2 * h)
    cov = np.diag(np.arange(1.0, 7.0)) * 1e-4
    _, se = reference_friction(FitResult("j", 1, p, covariance=cov), v)
    assert np.isclose(se, np.sqrt(g @ cov @ g), rtol=1e-6)
    assert g[4] == 0.0  # tau_os does not move it


def test_no_covariance_no_standard_error():
    fit = FitResult("j", 1, CoulombViscousParams(F_v=0.1, F_c=1.0, tau_os=0.0))
    value, se = reference_friction(fit, 0.5)
    assert value == 1.05 and np.isnan(se)
    assert np.isnan(reference_friction(FitResult("j", 1), 0.5)).all()  # not fitted

"""Energy consistency (thesis 7.2, eq. 7.9, Fig. 7.4): analytic cases, and the ideal simulator."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.energy import crossing_lags, energy_consistency, generating_share, zero_crossings
from wbfriction.fit.joints import fit_joints
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.models import FrictionParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.sensitivity import inertia_sensitivity
from wbfriction.studies.common import leg_joints


@settings(max_examples=50, deadline=None)
@given(F_v=st.floats(0, 5), F_c=st.floats(0, 20), S=st.floats(0, 3), v_s=st.floats(1e-3, 1), a=st.floats(1, 1e3),
       tau_os=st.floats(-5, 5), seed=st.integers(0, 2**16))
def test_dissipative_friction_never_generates_power_once_the_offset_is_removed(F_v, F_c, S, v_s, a, tau_os, seed):
    qd = np.random.default_rng(seed).normal(0.0, 1.0, 200)
    tau_f = FrictionParams(F_v, F_c, S, v_s, tau_os, a).torque(qd)
    assert generating_share(qd, tau_f, tau_os, tolerance=0.0) == 0.0


def test_an_offset_left_in_generates_power_where_it_outweighs_friction():
    """Viscous friction 2 N·m·s/rad and an offset of 1 N·m: ``-qd (2 qd + 1) > 0`` for
    ``qd`` in (-0.5, 0), a quarter of velocities uniform on [-1, 1]."""
    qd = np.linspace(-1.0, 1.0, 100_001)
    tau_f = FrictionParams(F_v=2.0, tau_os=1.0).torque(qd)
    assert generating_share(qd, tau_f, tolerance=0.0) == pytest.approx(0.25, abs=1e-4)
    # the tolerance drops |2 qd + 1| <= 0.01, i.e. qd within 0.005 of -0.5
    assert generating_share(qd, tau_f, tolerance=0.01) == pytest.approx(0.2475, abs=1e-4)
    assert generating_share(qd, tau_f, tau_os=1.0) == 0.0


def test_generating_share_counts_the_samples_with_positive_power():
    qd = np.array([1.0, -1.0, 2.0, -2.0, np.nan])
    tau_f = np.array([-1.0, -1.0, 1.0, 1.0, 1.0])
    assert generating_share(qd, tau_f) == pytest.approx(0.5)  # samples 1 and 2
    # friction below the tolerance has no reliable sign: it never counts
    assert generating_share(qd, 1e-3 * tau_f) == 0.0
    assert generating_share(qd, 1e-3 * tau_f, tolerance=0.0) == pytest.approx(0.5)
    assert np.isnan(generating_share(np.array([np.nan]), np.array([1.0])))


def test_zero_crossings_and_lags_of_shifted_sines():
    t = np.arange(0, 2.0, 1e-3)
    qd = np.sin(2 * np.pi * t)  # crosses at 0.5, 1.0, 1.5
    delta = -np.sin(2 * np.pi * (t - 0.01))  # opposite sign, 10 ms late
    np.testing.assert_allclose(zero_crossings(t, qd), [0.5, 1.0, 1.5], atol=1e-6)
    np.testing.assert_allclose(crossing_lags(t, qd, delta), [0.01, 0.01, 0.01], atol=1e-6)
    gap = qd.copy()
    gap[990:1010] = np.nan  # the crossing at 1.0 falls in a gap: not counted
    np.testing.assert_allclose(zero_crossings(t, gap), [0.5, 1.5], atol=1e-6)


@pytest.fixture(scope="module")
def walk_estimate(talos, combined_walk):
    est = estimate_log(talos, combined_walk.log, EstimateOptions(diff="central", route="acceleration"),
                       companion=True)
    legs = [j for j, _, _ in leg_joints(talos)]
    idx = [est.joints.index(j) for j in legs]
    fits = fit_joints(legs, est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx])
    return est, legs, {f.joint: f.params.tau_os for f in fits}


def test_exact_model_dissipates_in_swing(walk_estimate):
    """Ideal simulator, the true inertia model: under 1 % of each leg joint's swing-phase samples
    generate power (the rest: velocity sign errors of the central difference at reversals), and
    Delta qdd and qd of the knees have opposite signs (Fig. 7.4a)."""
    est, legs, tau_os = walk_estimate
    energy = {e.joint: e for e in energy_consistency(est, tau_os)}
    shares = {j: energy[j].generating_share for j in legs}
    print({j: f"{100 * s:.2f} %" for j, s in shares.items()})
    assert max(shares.values()) < 0.01
    assert not any(energy[j].flagged for j in legs)
    for knee in ("leg_left_4_joint", "leg_right_4_joint"):
        assert energy[knee].opposite_share > 0.99
        assert energy[knee].median_lag < 5e-3
        assert energy[knee].velocity_crossings >= 3


def test_rotational_inertia_error_makes_friction_generate_power(talos, combined_walk, walk_estimate):
    """Thesis 7.2: with every body's principal moments of inertia 10 % too large the share of
    power-generating samples rises, and the most affected joint is flagged."""
    est, legs, tau_os = walk_estimate
    scaled = inertia_sensitivity(talos, combined_walk.log, [1.1], "rotational",
                                 EstimateOptions(diff="central", route="acceleration")).estimates[1]
    before = {e.joint: e for e in energy_consistency(est, tau_os)}
    after = {e.joint: e for e in energy_consistency(scaled, tau_os)}
    print({j: f"{100 * before[j].generating_share:.2f} -> {100 * after[j].generating_share:.2f} %" for j in legs})
    assert sum(after[j].generating_share for j in legs) > 3 * sum(before[j].generating_share for j in legs)
    assert any(after[j].flagged for j in legs)
    flagged = [after[j] for j in legs if after[j].flagged]
    assert "generates power" in flagged[0].warning()


@given(st.floats(0.05, 0.2), st.floats(0.1, 1.0), st.floats(1.5, 4.0), st.integers(0, 2**16))
@settings(max_examples=25, deadline=None)
def test_a_ripple_is_left_out_of_the_check(viscous_ratio, F_c, ripple_ratio, seed):
    """Dissipative friction (``F_v = viscous_ratio F_c`` at speeds up to 1.6 rad/s) plus a position ripple larger
    than it (``ripple_ratio`` times F_c): with the ripple in,
    the friction "generates power" on many samples; with the fitted ripple taken out (:func:`fitted_ripples`, the
    ripple the fit kept), on none: the check of eq. 7.9 judges friction, not a torque of the angle."""
    from wbfriction.fit.result import FitResult, fitted_ripples
    from wbfriction.fit.terms import TermFit
    from wbfriction.friction.estimated import FrictionEstimate
    from wbfriction.friction.models import CoulombViscousParams

    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, 1e-3)
    w, phase = rng.uniform(0.3, 0.8), rng.uniform(0, 2 * np.pi)
    q = 2.0 * np.sin(w * t + phase)
    qd = 2.0 * w * np.cos(w * t + phase)
    params = CoulombViscousParams(F_v=viscous_ratio * F_c, F_c=F_c)
    c = {"ripple_sin1": ripple_ratio * F_c, "ripple_cos1": 0.0}
    terms = TermFit(params, ("ripple",), 1, c, {"ripple_sin1": 0.0, "ripple_cos1": 0.0})
    tau_f = -(params.f(qd) + ripple_ratio * F_c * np.sin(q))
    n = len(t)
    est = FrictionEstimate(("j",), t, qd[:, None], tau_f[:, None], np.ones((n, 1), bool), np.full(n, "single"),
                           np.ones(n, bool), np.zeros((n, 0), bool), (), q=q[:, None])
    fit = FitResult("j", n, params, terms=terms)
    with_ripple = energy_consistency(est, {"j": 0.0})[0]
    without = energy_consistency(est, {"j": 0.0}, ripple=fitted_ripples(est, [fit]))[0]
    assert with_ripple.generating_share > 0.05 and not with_ripple.ripple_removed
    assert without.generating_share == 0.0 and without.ripple_removed

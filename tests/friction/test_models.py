"""Properties of the friction models of chapter 3 and of their identification."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.fit.joints import fit_joints
from wbfriction.fit.regression import standard_errors
from wbfriction.fit.selection import fit_friction
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import (
    MODEL_NAMES,
    CoulombViscousParams,
    FrictionParams,
    StribeckParams,
    coulomb,
    coulomb_viscous,
    coulomb_viscous_stribeck,
    friction_torque,
    model_jacobian,
    model_values,
    params_from_dict,
    stribeck,
    stribeck_viscous,
    viscous,
)

pos = st.floats(0.01, 10.0)
vel = st.floats(-20.0, 20.0).filter(lambda x: abs(x) > 1e-2)
BIG_A = 1e9  # tanh(a qd) == sgn(qd) to double precision for |qd| > 1e-2


@given(vel, pos)
def test_smooth_reduces_to_coulomb(qd, F_c):
    assert np.isclose(coulomb_viscous_stribeck(qd, 0.0, F_c, 0.0, 1.0, 0.0, BIG_A), coulomb(qd, F_c), rtol=1e-12)


@given(st.floats(-20.0, 20.0), pos)
def test_smooth_reduces_to_viscous(qd, F_v):
    assert np.isclose(coulomb_viscous_stribeck(qd, F_v, 0.0, 0.3, 1.0, 0.0, 40.0), viscous(qd, F_v), rtol=1e-12, atol=0)


@given(vel, pos, st.floats(0.0, 5.0), st.floats(0.01, 2.0), st.sampled_from([1.0, 2.0, 0.5]))
def test_smooth_reduces_to_stribeck(qd, F_c, S, v_s, delta_s):
    expected = stribeck(qd, F_c, (1.0 + S) * F_c, v_s, delta_s)
    assert np.isclose(coulomb_viscous_stribeck(qd, 0.0, F_c, S, v_s, 0.0, BIG_A, delta_s), expected, rtol=1e-12)


@given(st.floats(-20.0, 20.0), pos, pos, st.floats(0.0, 5.0), st.floats(0.01, 2.0), st.floats(0.1, 1000.0))
def test_smooth_is_odd_without_offset(qd, F_v, F_c, S, v_s, a):
    f = lambda x: coulomb_viscous_stribeck(x, F_v, F_c, S, v_s, 0.0, a)  # noqa: E731
    assert np.isclose(f(-qd), -f(qd), rtol=1e-12, atol=1e-15)


@given(st.floats(-20.0, 20.0), pos, pos, st.floats(0.0, 5.0), st.floats(0.01, 2.0), st.floats(0.1, 1000.0))
def test_dissipative_without_offset(qd, F_v, F_c, S, v_s, a):
    """qd * tau_f <= 0 (eq. 7.9) for positive parameters and no offset."""
    p = FrictionParams(F_v, F_c, S, v_s, 0.0, a)
    assert qd * p.torque(qd) <= 0.0


@given(vel, pos, pos, st.floats(-1.0, 1.0))
def test_coulomb_viscous_is_the_stribeck_model_without_a_stribeck_drop(qd, F_v, F_c, tau_os):
    """(3.1) + (3.2): the (3.3) + (3.2) model with F_s = F_c, and the sum of its parts."""
    expected = coulomb(qd, F_c) + viscous(qd, F_v) + tau_os
    assert np.isclose(coulomb_viscous(qd, F_v, F_c, tau_os), expected, rtol=1e-12, atol=1e-12)
    assert np.isclose(stribeck_viscous(qd, F_v, F_c, F_c, 0.3, tau_os), expected, rtol=1e-12, atol=1e-12)


@given(vel, pos, pos, st.floats(0.0, 5.0), st.floats(0.01, 2.0), st.floats(-1.0, 1.0))
def test_stribeck_model_is_the_thesis_model_with_a_sharp_tanh(qd, F_v, F_c, S, v_s, tau_os):
    """(3.5) with tanh(a qd) -> sgn(qd) is (3.3) + (3.2) with F_s = (1 + S) F_c, as
    ``FrictionParams.values_in`` writes it."""
    thesis = FrictionParams(F_v, F_c, S, v_s, tau_os, BIG_A)
    same = StribeckParams(**thesis.values_in("stribeck"))
    assert np.isclose(same.f(qd), thesis.f(qd), rtol=1e-12, atol=1e-12)


@given(st.floats(-20.0, 20.0), pos, pos, st.floats(0.0, 5.0), st.floats(0.01, 2.0))
def test_new_models_are_dissipative_without_offset(qd, F_v, F_c, drop, v_s):
    assert qd * CoulombViscousParams(F_v, F_c).torque(qd) <= 0.0
    assert qd * StribeckParams(F_v, F_c, F_c + drop, v_s).torque(qd) <= 0.0


@pytest.mark.parametrize("model", MODEL_NAMES)
def test_parameters_convert_to_vectors_and_dicts_and_back(model):
    cls = family(model).params_class
    x = np.arange(1.0, len(cls.names) + 1)
    p = cls.from_vector(x, delta_s=1.5)
    assert p.model == model and np.array_equal(p.as_vector(), x)
    assert params_from_dict(model, p.to_dict()) == p
    assert getattr(p, "delta_s", 1.5) == 1.5
    with pytest.raises(InputError, match=f"unknown friction parameter.*{model}"):
        params_from_dict(model, {"F_x": 1.0})
    with pytest.raises(InputError, match="model must be one of"):
        params_from_dict("lugre", {})


def test_friction_torque_vectorised_matches_per_joint():
    rng = np.random.default_rng(0)
    params = [FrictionParams(0.2, 0.8, 0.2, 0.2, 0.8, 40.0), FrictionParams(0.1, 0.1, 0.5, 0.1, -0.1, 20.0)]
    qd = rng.normal(0, 1, (50, 2))
    out = friction_torque(qd, params)
    for j, p in enumerate(params):
        np.testing.assert_allclose(out[:, j], p.torque(qd[:, j]), rtol=1e-14)


@pytest.mark.parametrize(("model", "x"), [("thesis", [0.2, 0.8, 0.3, 0.25, 0.1, 30.0]),
                                          ("stribeck", [0.2, 0.8, 1.3, 0.25, 0.1]),
                                          ("coulomb-viscous", [0.2, 0.8, 0.1])])
def test_analytic_jacobian_matches_finite_differences(model, x):
    rng = np.random.default_rng(1)
    qd = rng.uniform(-2, 2, 200)
    x = np.array(x)
    f = lambda x: family(model).params(x, delta_s=2.0).f(qd)  # noqa: E731
    J = model_jacobian(x, qd, 2.0, model)
    assert J.shape == (qd.size, x.size)
    np.testing.assert_array_equal(model_values(x, qd, 2.0, model), f(x))
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(x[i]))
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        fd = (f(xp) - f(xm)) / (2 * h)
        np.testing.assert_allclose(J[:, i], fd, rtol=1e-5, atol=1e-7)


@settings(max_examples=25, deadline=None)
@given(F_v=st.floats(0.0, 1.0), F_c=st.floats(0.1, 2.0), S=st.floats(0.1, 1.0), v_s=st.floats(0.05, 0.5),
       tau_os=st.floats(-1.0, 1.0), a=st.floats(10.0, 100.0))
@example(F_v=0.5, F_c=0.1015625, S=0.21875, v_s=0.05078125, tau_os=0.0, a=10.0)  # a 6 x 6 grid's miss (issue 41)
def test_fit_recovers_noiseless_parameters(F_v, F_c, S, v_s, tau_os, a):
    truth = FrictionParams(F_v, F_c, S, v_s, tau_os, a)
    qd = np.linspace(-8 * v_s - 0.5, 8 * v_s + 0.5, 2001)
    res = fit_friction(qd, truth.torque(qd))
    assert res.success
    np.testing.assert_allclose(res.params.as_vector(), truth.as_vector(), rtol=1e-4, atol=1e-6)
    assert res.rms_residual < 1e-6


def test_joints_fitted_side_by_side_equal_the_serial_fits():
    """Three joints with different friction, one without any: workers change nothing, and
    each joint gets its own truth back."""
    rng = np.random.default_rng(3)
    truths = [FrictionParams(0.2, 0.8, 0.2, 0.2, 0.8, 40.0), FrictionParams(0.1, 0.3, 0.5, 0.1, -0.2, 60.0),
              FrictionParams(0.0, 0.0, 0.0, 0.1, 0.0, 40.0)]
    qd = rng.uniform(-2.0, 2.0, (3000, 3))
    tau_f = np.column_stack([t.torque(qd[:, i]) for i, t in enumerate(truths)]) + rng.normal(0, 0.01, qd.shape)
    valid = np.ones(qd.shape, dtype=bool)
    serial = fit_joints(["a", "b", "c"], qd, tau_f, valid)
    parallel = fit_joints(["a", "b", "c"], qd, tau_f, valid, workers=2)
    for s, p in zip(serial, parallel):
        assert s.joint == p.joint
        np.testing.assert_array_equal(s.params.as_vector(), p.params.as_vector())
    for res, t in zip(serial[:2], truths):
        np.testing.assert_allclose(res.params.as_vector()[[0, 1, 4]], t.as_vector()[[0, 1, 4]], rtol=0.05, atol=0.01)
    assert abs(serial[2].params.F_c) < 0.01 and abs(serial[2].params.tau_os) < 0.01


def test_fit_marks_unidentifiable_parameters():
    """Without a Stribeck bump (S = 0) v_s cannot be identified: infinite standard error."""
    qd = np.linspace(-2, 2, 1001)
    truth = FrictionParams(0.2, 0.8, 0.0, 0.2, 0.1, 40.0)
    rng = np.random.default_rng(0)
    res = fit_friction(qd, truth.torque(qd) + rng.normal(0, 0.01, qd.size),
                       x0=np.array([0.2, 0.8, 0.0, 0.2, 0.1, 40.0]))
    assert res.params.S < 0.05 or res.stderr["v_s"] > 1.0
    # a column of zeros in the Jacobian is an unidentifiable direction
    J = model_jacobian(np.array([0.2, 0.8, 0.0, 0.2, 0.1, 40.0]), qd, 2.0)
    se = standard_errors(J, rng.normal(0, 0.01, qd.size))
    assert np.isinf(se[3]) and np.isfinite(se[[0, 1, 4, 5]]).all()


def test_fit_standard_errors_cover_truth_with_noise():
    rng = np.random.default_rng(7)
    truth = FrictionParams(0.2, 0.8, 0.2, 0.2, 0.8, 40.0)
    qd = rng.uniform(-2.0, 2.0, 4000)
    res = fit_friction(qd, truth.torque(qd) + rng.normal(0, 0.05, qd.size))
    z = np.abs(res.params.as_vector() - truth.as_vector()) / np.array([res.stderr[k] for k in
                                                                     ("F_v", "F_c", "S", "v_s", "tau_os", "a")])
    assert np.all(z < 5.0), z


def test_standard_errors_account_for_correlated_residuals():
    """Residuals correlated over ~100 samples (a filtered estimate): the Newey-West standard
    errors cover the truth about as often as they should, the white-noise formula does not."""
    truth = FrictionParams(0.2, 0.8, 0.2, 0.2, 0.8, 40.0)
    t = np.arange(6000) * 1e-3
    qd = 1.2 * np.sin(2 * np.pi * 0.7 * t) + 0.3 * np.sin(2 * np.pi * 1.9 * t)
    box = np.ones(101) / np.sqrt(101)
    inside_hac, inside_white = [], []
    for seed in range(16):
        rng = np.random.default_rng(seed)
        noise = 0.05 * np.convolve(rng.normal(size=t.size + 100), box, mode="valid")
        res = fit_friction(qd, truth.torque(qd) + noise, x0=truth.as_vector())
        x = res.params.as_vector()
        err = np.abs(x - truth.as_vector())[[0, 1, 4]]
        se_hac = np.array([res.stderr[k] for k in ("F_v", "F_c", "tau_os")])
        J = model_jacobian(x, qd, 2.0)
        r = model_values(x, qd, 2.0) + (truth.torque(qd) + noise)
        se_white = standard_errors(J, r)[[0, 1, 4]]
        inside_hac.append(err < 2 * se_hac)
        inside_white.append(err < 2 * se_white)
    assert np.mean(inside_hac) > 0.8 and np.mean(inside_white) < 0.5, (np.mean(inside_hac), np.mean(inside_white))


@settings(max_examples=15, deadline=None)
@given(st.floats(0.05, 2.0), st.floats(0.1, 3.0), st.floats(10.0, 100.0), st.integers(0, 2**16))
def test_coulomb_viscous_fit_with_held_parameters(F_v, F_c, a, seed):
    """Holding S, v_s and tau_os (MuJoCo's frictionloss + damping has none) recovers F_v,
    F_c and a from noisy data, keeps the held values exactly, and gives them zero error."""
    rng = np.random.default_rng(seed)
    qd = rng.uniform(-2.0, 2.0, 3000)
    truth = FrictionParams(F_v=F_v, F_c=F_c, a=a)
    tau_f = truth.torque(qd) + rng.normal(0.0, 0.01, qd.size)
    fixed = {"S": 0.0, "v_s": 0.1, "tau_os": 0.0}
    res = fit_friction(qd, tau_f, fixed=fixed)
    for name, value in fixed.items():
        assert getattr(res.params, name) == value and res.stderr[name] == 0.0
    assert abs(res.params.F_v - F_v) < 5 * res.stderr["F_v"] + 1e-3
    assert abs(res.params.F_c - F_c) < 5 * res.stderr["F_c"] + 1e-3
    assert abs(res.params.F_c - F_c) / F_c < 0.02 and abs(res.params.F_v - F_v) / F_v < 0.05


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**16))
def test_injected_friction_fast_path_equals_the_model(seed):
    """The simulators' in-place evaluation of (3.5), per physics step, is ``-coulomb_viscous_stribeck``."""
    from wbfriction.sim.common import InjectedFriction

    rng = np.random.default_rng(seed)
    params = {f"j{i}": FrictionParams(F_v=rng.uniform(0, 1), F_c=rng.uniform(0, 2), S=rng.uniform(0, 1),
                                      v_s=rng.uniform(0.05, 1), tau_os=rng.normal(), a=rng.uniform(5, 100))
              for i in range(5)}
    injected = InjectedFriction(params, list(range(5)))
    qd = rng.normal(0, 2, 5)
    expected = np.array([p.torque(v) for p, v in zip(params.values(), qd)])
    np.testing.assert_allclose(injected.torque(qd), expected, rtol=1e-12, atol=1e-14)


@given(qd=st.one_of(st.floats(-10, 10), st.sampled_from([0.0, -0.0, float("nan"), 1e-300, -1e-300])),
       F_v=st.floats(0, 2), F_c=st.floats(0, 2), tau_os=st.floats(-1, 1))
@settings(max_examples=200, deadline=None)
def test_one_velocity_in_floats_is_the_characteristic_bit_for_bit(qd, F_v, F_c, tau_os):
    """``f_at`` (a simulator's physics step) gives the number ``f`` gives, to the bit (NaN for NaN)."""
    for p in (CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=tau_os),
              FrictionParams(F_v=F_v, F_c=F_c, S=0.3, v_s=0.05, tau_os=tau_os, a=40.0)):
        expected = float(p.f(qd))
        assert np.array_equal(np.float64(p.f_at(qd)), np.float64(expected), equal_nan=True)
        assert np.signbit(p.f_at(qd)) == np.signbit(expected)

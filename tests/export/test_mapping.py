"""Model (3.5) to simulator fields: the fields are the model's limits, non-dissipative friction refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.export.mapping import JointExport, joint_export, joint_exports
from wbfriction.fit.result import FitResult
from wbfriction.friction.models import CoulombViscousParams, FrictionParams, StribeckParams

positive = st.floats(0.01, 50.0)


@settings(max_examples=50, deadline=None, derandomize=True)
@given(F_v=positive, F_c=positive, S=st.floats(0.0, 3.0), v_s=st.floats(0.01, 0.5), tau_os=st.floats(-5, 5),
       armature=st.floats(0.0, 2.0))
def test_fields_are_the_limits_of_model_3_5(F_v, F_c, S, v_s, tau_os, armature):
    """Evaluated through the model itself: far beyond the Stribeck velocity and the tanh's width,
    f(qd) - tau_os = Coulomb sgn(qd) + viscous qd; just off rest (tanh saturated, the Stribeck
    exponential still 1), f - tau_os = the static level; the offset is not in any field."""
    p = FrictionParams(F_v=F_v, F_c=F_c, S=S, v_s=v_s, tau_os=tau_os, a=1e12)
    exp = joint_export("j", p, armature)
    fast = 200.0 * v_s  # exp(-200^2) = 0
    for qd in (fast, -fast):
        assert exp.coulomb * np.sign(qd) + exp.viscous * qd == pytest.approx(float(p.f(qd)) - tau_os, rel=1e-12)
    slow = 1e-6 * v_s  # tanh(a qd) = 1 to 1e-13, exp(-(qd / v_s)^2) = 1 - 1e-12
    assert exp.static == pytest.approx(float(p.f(slow)) - tau_os - F_v * slow, rel=1e-9)
    assert exp.armature == armature and exp.params == p


@settings(max_examples=30, deadline=None, derandomize=True)
@given(F_v=positive, F_c=positive, rise=st.floats(0.0, 20.0), v_s=st.floats(0.01, 0.5), tau_os=st.floats(-5, 5))
def test_the_other_models_map_to_their_limits_too(F_v, F_c, rise, v_s, tau_os):
    """The Stribeck model's static level is its F_s (f just off rest), the Coulomb-viscous
    model's is F_c; both keep F_v and F_c as in (3.5)."""
    stribeck = StribeckParams(F_v=F_v, F_c=F_c, F_s=F_c + rise, v_s=v_s, tau_os=tau_os)
    plain = CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=tau_os)
    for p in (stribeck, plain):
        exp = joint_export("j", p)
        fast, slow = 200.0 * v_s, 1e-9 * v_s
        assert exp.coulomb + exp.viscous * fast == pytest.approx(float(p.f(fast)) - tau_os, rel=1e-12)
        assert exp.static == pytest.approx(float(p.f(slow)) - tau_os - F_v * slow, rel=1e-9)


def test_fit_results_as_read_from_the_parameters_json():
    """A FitResult's parameters are used; a fit without parameters exports no friction (only an
    armature if one is given), and a joint with neither is left out."""
    fits = {"a": FitResult("a", 100, params=FrictionParams(F_v=0.2, F_c=1.5, S=0.5), success=True),
            "b": FitResult("b", 3), "c": FitResult("c", 2)}
    out = joint_exports(fits, {"b": 0.03})
    assert list(out) == ["a", "b"]
    assert (out["a"].viscous, out["a"].coulomb, out["a"].static, out["a"].armature) == (0.2, 1.5, 2.25, None)
    assert out["b"].has_friction is False and out["b"].armature == 0.03


def test_robot_order_and_unknown_joints(kuka):
    p = FrictionParams(F_v=1.0, F_c=1.0)
    out = joint_exports({"lwr_3_joint": p, "lwr_1_joint": p}, {"lwr_0_joint": 0.1}, kuka)
    assert list(out) == ["lwr_0_joint", "lwr_1_joint", "lwr_3_joint"]
    with pytest.raises(InputError, match="'elbow' is not an actuated joint of robot 'kuka_lwr4'"):
        joint_exports({"elbow": p}, None, kuka)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(bad=st.sampled_from(["F_v", "F_c", "S"]), value=st.floats(-100.0, -1e-9))
def test_non_dissipative_friction_is_refused(bad, value):
    """F_v < 0, F_c < 0, or S < -1 (a negative static level: generating near rest): refused,
    one line naming the joint."""
    values = dict(F_v=0.5, F_c=0.8, S=0.2)
    values[bad] = value - 1.0 if bad == "S" else value
    with pytest.raises(InputError, match="^joint 'knee': .*< 0: friction that is not dissipative is not exported$"):
        joint_export("knee", FrictionParams(**values))


@pytest.mark.parametrize("value", [-1e-3, math.nan, math.inf])
def test_bad_armature_is_refused(value):
    with pytest.raises(InputError, match="^joint 'knee': armature"):
        joint_exports({}, {"knee": value})


def test_friction_given_in_part_is_refused():
    with pytest.raises(InputError, match="go together"):
        JointExport("knee", viscous=1.0)


def test_a_fit_with_terms_exports_its_reference_levels_and_says_what_is_dropped():
    """No simulator holds the terms beyond velocity: a fit that kept some exports its velocity model refitted with
    them (the levels at zero load and T_ref, not the fit's own levels averaged over the log's conditions), and its
    note names the terms dropped and those conditions."""
    from wbfriction.export.mapping import status_note
    from wbfriction.fit.terms import TermFit

    refitted = CoulombViscousParams(F_v=0.25, F_c=0.8, tau_os=0.1)
    terms = TermFit(refitted, ("load", "temperature"), 0, {"F_L": 0.02, "F_cT": -0.008, "F_vT": -0.004},
                    reference_temperature=40.0)
    fit = FitResult("a", 100, params=CoulombViscousParams(F_v=0.2, F_c=1.1, tau_os=0.1), success=True, terms=terms)
    exp = joint_export("a", fit)
    assert (exp.viscous, exp.coulomb, exp.static) == (0.25, 0.8, 0.8) and exp.dropped == ("load", "temperature")
    note = status_note(exp)
    assert note is not None and "dropped" in note and "load, temperature" in note
    assert "zero load, T_ref 40 °C" in note
    plain = joint_export("a", FitResult("a", 100, params=fit.params, success=True))
    assert plain.coulomb == 1.1 and plain.dropped == () and "dropped" not in (status_note(plain) or "")

"""A verdict on every fit (issue 24, item 2): ``ok`` where the injected friction is recovered, and each way a
fit cannot be used named with its reason."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import fit_from_dict, fit_to_dict
from wbfriction.fit.result import FitResult, compare_routes
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.status import (
    FIT_STATUSES,
    MIN_SPEED,
    PROMISE,
    WEAK,
    ZERO,
    FitVerdict,
    fit_verdict,
    joint_speed,
    solver_phrase,
)
from wbfriction.friction.models import CoulombViscousParams, FrictionParams

TRUE = FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=0.3, a=40.0)


def _data(amplitude: float, n: int = 4000, noise: float = 0.005, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A joint swept sinusoidally at ``amplitude`` [rad/s] with friction ``TRUE`` (tau_f = -f(qd)) and noise."""
    rng = np.random.default_rng(seed)
    qd = amplitude * np.sin(np.linspace(0, 12 * np.pi, n))
    return qd, TRUE.torque(qd) + noise * rng.normal(size=n)


def test_a_well_excited_joint_is_ok_and_its_friction_recovered():
    fit = fit_friction(*_data(1.0))
    assert fit.verdict().status == "ok" and fit.verdict().reason == ""
    assert abs(fit.params.F_c - TRUE.F_c) < 0.01 and abs(fit.params.F_v - TRUE.F_v) < 0.01


def test_a_joint_that_hardly_moved_is_not_excited():
    fit = fit_friction(*_data(0.5 * MIN_SPEED))
    verdict = fit.verdict()
    assert verdict.status == "not excited" and "hardly moved" in verdict.reason


def test_still_gives_a_joint_that_hardly_moved_the_model_named_for_it_and_its_offset():
    """``still="coulomb-viscous"`` (the closed loop's): a joint below MIN_SPEED is fitted with that model, and its
    fit is the named model's on the same data, with the offset that data give; a joint that moved keeps (3.5)."""
    qd, tau_f = _data(0.5 * MIN_SPEED)
    fit = fit_friction(qd, tau_f, model="thesis", still="coulomb-viscous", fixed={"S": 0.0, "F_c": 1.0})
    named = fit_friction(qd, tau_f, model="coulomb-viscous", fixed={"F_c": 1.0})
    assert fit.model == "coulomb-viscous" and fit.verdict().status == "not excited"
    assert fit.params == named.params and fit.stderr == named.stderr
    # least squares with an offset: the model's mean is the data's, and the data's is the true friction's
    assert abs(np.mean(fit.params.torque(qd)) - np.mean(tau_f)) < 1e-9
    assert abs(np.mean(fit.params.torque(qd)) - np.mean(TRUE.torque(qd))) < 1e-3
    moved = fit_friction(*_data(1.0), model="thesis", still="coulomb-viscous")
    assert moved.model == "thesis" and moved.verdict().status == "ok"



@pytest.mark.parametrize("speed", [0.5 * MIN_SPEED, 1.0])
def test_still_checks_the_held_names_against_the_model_named_whether_the_joint_moved_or_not(speed):
    """A name the model named does not have is refused for a joint that hardly moved as for one that moved, though
    the model ``still`` gives it would not use it either."""
    with pytest.raises(InputError, match="unknown parameter.*thesis.*: F_s"):
        fit_friction(*_data(speed), model="thesis", still="coulomb-viscous", fixed={"F_s": 1.0})

def test_too_few_samples_is_not_excited():
    qd, tau_f = _data(1.0, n=10)
    verdict = fit_friction(qd, tau_f).verdict()
    assert verdict.status == "not excited" and "only 10 valid samples" in verdict.reason


def test_a_jump_sharper_than_the_data_resolve_is_coulomb_friction_not_a_bound():
    """Issue 52: pure Coulomb friction (a sign function) fitted with (3.5): the tanh slope runs to its upper bound,
    a step sharper than the data resolve. That is the finding, not a failure: F_c and F_v are recovered, their
    standard errors finite, the fit ``ok`` (and so exported), the slope shown as a step; a slope at its lower bound
    is still a bound."""
    from wbfriction.report.terminal import fit_tables

    qd = np.linspace(-1, 1, 2001)
    fit = fit_friction(qd, -np.sign(qd) * 1.0 - 0.2 * qd, model="thesis", fixed={"S": 0.0, "v_s": 0.1})
    assert fit.at_bound["a"] and fit.steps() == ("a",) and fit.verdict().status == "ok"
    assert fit.params.F_c == pytest.approx(1.0, rel=1e-6) and fit.params.F_v == pytest.approx(0.2, rel=1e-6)
    value, se = fit.dissipative(np.array([0.1, 0.5]))
    np.testing.assert_allclose(value, [1.02, 1.1], rtol=1e-6)
    assert np.all(np.isfinite(se))  # the slope's variance does not reach the curve beyond the step
    row = next(t for t in fit_tables([fit]) if t.title == "Offset and Stribeck terms")
    assert "step" in [c for col in row.columns for c in col._cells]
    gentle = dataclasses.replace(fit, params=dataclasses.replace(fit.params, a=0.01))
    assert gentle.steps() == () and gentle.verdict().status == "at bound"


def test_noise_larger_than_the_viscous_torque_makes_a_weak_fit():
    fit = fit_friction(*_data(0.3, n=300, noise=0.5, seed=3), model="coulomb-viscous")
    verdict = fit.verdict()
    assert verdict.status == "weak" and "F_v" in verdict.reason


def test_a_solver_that_did_not_converge_failed_and_says_why():
    fit = dataclasses.replace(fit_friction(*_data(1.0)), success=False,
                              message="The maximum number of function evaluations is exceeded.")
    assert fit.verdict().status == "failed"
    assert fit.verdict().reason == ("the solver stopped at its evaluation limit before converging: the parameters "
                                    "are not a minimum of the fit")
    assert solver_phrase("Something new.") == ("the solver stopped (the solver said: Something new); whether at a "
                                               "minimum is not known")


def test_zero_friction_found_is_a_result_not_a_bound():
    """A joint without viscous friction: F_v at its floor of zero is what the data say."""
    qd, _ = _data(1.0)
    p = dataclasses.replace(TRUE, F_v=0.0)
    fit = fit_friction(qd, p.torque(qd), model="coulomb-viscous")
    assert fit.params.F_v < 1e-6 and fit.verdict().status == "ok"


def test_the_json_carries_the_status_and_reads_back_the_same_verdict():
    fit = fit_friction(*_data(0.5 * MIN_SPEED))
    d = fit_to_dict(fit)
    assert (d["status"], d["status_reason"]) == (fit.verdict().status, fit.verdict().reason)
    assert fit_from_dict("j", d).verdict() == fit.verdict()


@settings(max_examples=100, deadline=None)
@given(fitted=st.booleans(), success=st.booleans(), speed=st.one_of(st.none(), st.floats(0, 5)),
       se=st.floats(0, 10) | st.just(float("inf")), bound=st.sampled_from(["", "a", "F_c", "v_s"]))
def test_every_fit_has_one_status_and_a_reason_unless_ok(fitted, success, speed, se, bound):
    params = TRUE if fitted else None
    fit = FitResult("j", 100, params=params, success=success, speed=speed, message="x",
                    stderr={n: se for n in TRUE.names} if fitted else {},
                    at_bound={n: n == bound for n in TRUE.names} if fitted else {})
    verdict = fit_verdict(fit)
    assert verdict.status in FIT_STATUSES and (verdict.reason == "") == verdict.ok
    if verdict.ok:
        assert fitted and success and (speed is None or speed >= MIN_SPEED) and not bound and se <= 0.25 * TRUE.F_v


# ---------------------------------------------------------------- each rule at its definition (issue 37)
def _fit(F_c: float = 1.0, F_v: float = 0.2, se: dict | None = None, at_bound: tuple[str, ...] = (),
         speed: float = 1.0) -> FitResult:
    """A converged Coulomb-viscous fit with the given values and standard errors (no solver run)."""
    params = CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=0.1)
    stderr = {"F_v": 0.01, "F_c": 0.01, "tau_os": 0.01} if se is None else se
    return FitResult("j", 1000, params, stderr, success=True, at_bound={n: n in at_bound for n in params.names},
                     speed=speed)


def test_joint_speed_is_the_95th_percentile_of_the_speed():
    """|qd| of 0, 0.01, ..., 1 rad/s (either sign): its 95th percentile is 0.95 exactly; no sample, no motion."""
    qd = np.linspace(0.0, 1.0, 101) * np.where(np.arange(101) % 2, 1.0, -1.0)
    assert joint_speed(qd) == pytest.approx(0.95, abs=1e-12)
    assert joint_speed(np.array([])) == 0.0


def test_not_excited_means_below_the_minimum_speed():
    assert _fit(speed=MIN_SPEED).verdict().status == "ok"
    assert _fit(speed=np.nextafter(MIN_SPEED, 0.0)).verdict().status == "not excited"


def test_a_magnitude_at_its_floor_is_a_finding_unless_the_data_press_it():
    """F_v on its floor of zero (the solver's 1e-6 or 1e-4 of it alike) is "no viscous friction" (ok), judged as a
    zero; pressed below it by the data (issue 63: freed of the floor it would be -0.2 ± 0.02), a bound."""
    assert _fit(F_v=np.nextafter(ZERO, 0.0), at_bound=("F_v",)).verdict().status == "ok"
    assert _fit(F_v=1e-4, at_bound=("F_v",)).verdict().status == "ok"
    pressed = _fit(F_v=1e-4, at_bound=("F_v",))
    pressed.pressed = {"F_v": (-0.2, 0.02)}
    assert pressed.verdict() == FitVerdict("at bound", "at a bound of the fit: F_v at zero, the data ask for -0.2 "
                                                       "± 0.02")


def test_weak_means_a_standard_error_above_a_tenth_of_the_value():
    """F_v = 2 with a standard error of exactly 0.2 (10 %: half the promise of ok, ±20 % at two standard errors) is
    ok; of 0.3 (15 %) weak, and the reason says 15 %."""
    assert WEAK == 0.1 and WEAK == PROMISE / 2
    assert _fit(F_v=2.0, se={"F_v": 0.2, "F_c": 0.0, "tau_os": 0.0}).verdict().status == "ok"
    assert _fit(F_v=2.0, se={"F_v": 0.3, "F_c": 0.0, "tau_os": 0.0}).verdict() == FitVerdict(
        "weak", "large standard errors: F_v ±15 %")
    # a value at ZERO is still judged (only one below it is "none"), its error against it
    assert _fit(F_v=ZERO, se={"F_v": 1.0, "F_c": 0.0, "tau_os": 0.0}).verdict().status == "weak"


def test_the_offset_is_judged_against_the_coulomb_friction():
    """tau_os's standard error against F_c (tau_os itself may be 0): above F_c / 10 weak, at it or without a
    standard error (held) not; F_c at ZERO still a scale."""
    assert _fit(F_c=2.0, se={"F_v": 0.0, "F_c": 0.0, "tau_os": 0.2}).verdict().status == "ok"
    assert _fit(F_c=2.0, se={"F_v": 0.0, "F_c": 0.0, "tau_os": 0.3}).verdict() == FitVerdict(
        "weak", "large standard errors: tau_os ±0.3 N·m against F_c 2")
    assert _fit(F_c=2.0, se={"F_v": 0.0, "F_c": 0.0}).verdict().status == "ok"
    assert _fit(F_c=1.0, se={"F_v": 0.0, "F_c": 0.0}).verdict().status == "ok"
    assert _fit(F_c=ZERO, se={"F_v": 0.0, "F_c": 0.0, "tau_os": 1e-3}).verdict().status == "weak"
    assert _fit(F_c=0.0, se={"F_v": 0.0, "F_c": 0.0, "tau_os": 1e-3}).verdict().status == "ok"


# ------------------------------------------------------------------ issue 38: bias, bounds, zeros
def _cv_fit(F_v=0.3, F_c=1.0, se=(0.01, 0.02, 0.01), crb=None, speed=1.0, check=None, rms=0.05) -> FitResult:
    params = CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=0.1)
    return FitResult("j", 1000, params=params, stderr=dict(zip(("F_v", "F_c", "tau_os"), se)), rms_residual=rms,
                     success=True, message="ok", at_bound={"F_v": False, "F_c": False, "tau_os": False}, speed=speed,
                     crb=crb or {}, route="momentum", route_check=check)


def test_two_routes_that_disagree_are_not_ok_and_say_both_values():
    """F_c 1.0 ± 0.02 against 0.8 ± 0.02: 7 combined standard errors and 20 % apart."""
    other = _cv_fit(F_c=0.8)
    other.route = "acceleration"
    fit = _cv_fit()
    fit.route_check = compare_routes(fit, other)
    verdict = fit.verdict()
    assert fit.route_check.disagree == ("F_c",) and verdict.status == "routes disagree"
    assert verdict.reason == "F_c 1 ±0.02 (momentum) against 0.8 ±0.02 (acceleration)"
    # within 3 combined standard errors, or within 2 % of the value, they agree
    for F_c, se in ((0.92, 0.02), (0.985, 0.001)):
        near = _cv_fit(F_c=F_c, se=(0.01, se, 0.01))
        fit.route_check = compare_routes(fit, near)
        assert fit.route_check.disagree == () and fit.verdict().ok, F_c
    # a bound comes first: its value is the bound's
    bounded = _cv_fit()
    bounded.at_bound["tau_os"] = True
    bounded.route_check = compare_routes(bounded, other)
    assert bounded.verdict().status == "at bound"


def test_a_bound_beyond_a_tenth_of_the_value_is_weak_whatever_the_standard_error():
    fit = _cv_fit(crb={"F_v": 0.045, "F_c": 0.01, "tau_os": 0.01})
    verdict = fit.verdict()
    assert verdict.status == "weak" and "F_v ±15 % at best (Cramér-Rao)" in verdict.reason
    assert _cv_fit(crb={"F_v": 0.027, "F_c": 0.01}).verdict().ok
    assert "F_c not identifiable at best" in _cv_fit(crb={"F_c": np.inf}).verdict().reason


def test_a_magnitude_at_zero_is_weak_when_its_spread_outweighs_the_friction():
    """The KUKA's lwr_3 before issue 38: F_c = 0 ± 1.1 beside 0.5 N·m of friction, F_v = 0 ± 2 at 1 rad/s: no
    finding; F_c = 0 ± 0.01: one."""
    verdict = _cv_fit(F_v=0.5, F_c=0.0, se=(0.01, 1.1, 0.01)).verdict()
    assert verdict.status == "weak" and "F_c 0 ±1.1 (1.1 N·m against 0.5 N·m of friction)" in verdict.reason
    assert "F_v 0 ±2 (2 N·m" in _cv_fit(F_v=0.0, F_c=0.5, se=(2.0, 0.01, 0.01)).verdict().reason
    assert _cv_fit(F_v=0.5, F_c=0.0, se=(0.01, 0.01, 0.01)).verdict().ok
    # a frictionless joint: its residual is the scale
    assert _cv_fit(F_v=0.0, F_c=0.0, se=(0.001, 0.001, 0.001), rms=0.01).verdict().ok


def test_the_new_fields_read_back_from_the_json():
    other = _cv_fit(F_c=0.8)
    other.route = "acceleration"
    fit = _cv_fit(crb={"F_v": 0.004, "F_c": np.inf, "tau_os": 0.002})
    fit.route_check = compare_routes(fit, other)
    fit.torque_noise, fit.velocity_noise, fit.stick_speed, fit.n_stuck = 0.05, 0.0018, 0.0054, 321
    back = fit_from_dict("j", fit_to_dict(fit))
    for name in ("crb", "route", "route_check", "torque_noise", "velocity_noise", "stick_speed", "n_stuck"):
        assert getattr(back, name) == getattr(fit, name), name
    assert back.verdict() == fit.verdict()


def test_the_thresholds_decide_each_rule():
    """Issue 52: the statuses' thresholds are values (:class:`StatusThresholds`) a study can vary; each rule follows
    its own: a standard error of 30 % is ``weak`` at 0.25 (the default) and not at 0.5; routes 5 % apart by 4.5
    standard errors disagree at 2 % and not at 6 %; a later stretch 8 % off by 5 standard errors does not predict at
    5 % and does at 10 %."""
    from wbfriction.fit.holdout import PredictionCheck
    from wbfriction.fit.result import RouteCheck
    from wbfriction.fit.status import DEFAULT_THRESHOLDS, StatusThresholds

    fit = _fit(se={"F_v": 0.06, "F_c": 0.01, "tau_os": 0.01})  # F_v = 0.2 ± 0.06: 30 %
    assert fit_verdict(fit).status == "weak" and fit_verdict(fit, StatusThresholds(weak=0.5)).ok
    routes = dataclasses.replace(_fit(), route_check=RouteCheck("momentum", {"F_c": 1.05, "F_v": 0.2},
                                                                {"F_c": 0.005, "F_v": 0.01}))
    verdict = fit_verdict(routes)
    assert verdict.status == "routes disagree" and "F_c 1 ±0.01 (acceleration)" in verdict.reason
    assert fit_verdict(routes, StatusThresholds(route_rel=0.06)).ok
    check = PredictionCheck("the last 30 % of its samples", 300, 0.108, 0.1, 5.0, 0.3)
    later = dataclasses.replace(_fit(), later=check)
    assert fit_verdict(later).status == "does not predict"
    assert fit_verdict(later, StatusThresholds(holdout_excess=0.1)).ok
    assert fit_verdict(later, DEFAULT_THRESHOLDS) == later.verdict()

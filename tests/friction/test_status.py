"""A verdict on every fit (issue 24, item 2): ``ok`` where the injected friction is recovered, and each way a
fit cannot be used named with its reason."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.friction.fit import FitResult, fit_friction
from wbfriction.friction.io import fit_from_dict, fit_to_dict
from wbfriction.friction.models import FrictionParams
from wbfriction.friction.status import FIT_STATUSES, MIN_SPEED, fit_verdict, solver_phrase

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


def test_too_few_samples_is_not_excited():
    qd, tau_f = _data(1.0, n=10)
    verdict = fit_friction(qd, tau_f).verdict()
    assert verdict.status == "not excited" and "only 10 valid samples" in verdict.reason


def test_a_jump_sharper_than_the_bounds_leaves_a_at_its_bound():
    """Pure Coulomb friction (a sign function) fitted with (3.5): the tanh slope runs to its upper bound."""
    qd = np.linspace(-1, 1, 2001)
    fit = fit_friction(qd, -np.sign(qd) * 1.0 - 0.2 * qd)
    assert fit.verdict().status == "at bound" and "a" in fit.verdict().reason.split(": ")[-1].split(", ")


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
        assert fitted and success and (speed is None or speed >= MIN_SPEED) and not bound and se <= 0.5 * TRUE.F_v

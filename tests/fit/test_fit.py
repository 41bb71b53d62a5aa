"""The fit of each friction model, the flags of parameters at their bounds, and the choice of
model by held-out error (wbfriction.fit)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.fit.coordinates import (
    fit_coordinates_jacobian,
    from_fit_coordinates,
    model_bounds,
    to_fit_coordinates,
)
from wbfriction.fit.joints import fit_estimate, fit_joints
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.fit.regression import held_out_gain, held_out_split, parameter_covariance, standard_errors
from wbfriction.fit.result import FitResult, HeldOutScore, ModelSelection, fitted_offsets
from wbfriction.fit.selection import choose_model, fit_friction, held_out_rms, prefer_interior
from wbfriction.fit.solve import STICK_FLOOR, filtered_problem, stick_speed
from wbfriction.fit.status import fit_verdict, search_bounds
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.families.thesis import THESIS
from wbfriction.friction.models import (
    CoulombViscousParams,
    FrictionParams,
    StribeckParams,
    model_jacobian,
    model_values,
)
from wbfriction.signals.filters import SavgolSmoother

DT = 2e-3
T = np.arange(4000) * DT
QD = 1.2 * np.sin(2 * np.pi * 0.31 * T) + 0.4 * np.sin(2 * np.pi * 1.7 * T + 0.5)
"""A joint's velocity over 8 s [rad/s]: slow and fast swings, reversals at several accelerations."""


def _truth(model: str, rng: np.random.Generator):
    F_v, F_c, tau_os = rng.uniform(0.05, 1.0), rng.uniform(0.2, 2.0), rng.uniform(-1.0, 1.0)
    if model == "coulomb-viscous":
        return CoulombViscousParams(F_v, F_c, tau_os)
    if model == "stribeck":
        return StribeckParams(F_v, F_c, F_c * rng.uniform(1.3, 2.0), rng.uniform(0.1, 0.3), tau_os)
    return FrictionParams(F_v, F_c, rng.uniform(0.3, 1.0), rng.uniform(0.1, 0.3), tau_os, rng.uniform(10.0, 60.0))


@settings(max_examples=10, deadline=None)
@given(st.sampled_from(["coulomb-viscous", "stribeck"]), st.integers(0, 2**16))
def test_each_model_recovers_its_injected_parameters_noise_free(model, seed):
    """Data made by a model, fitted with that model: its parameters come back, none at a bound."""
    truth = _truth(model, np.random.default_rng(seed))
    res = fit_friction(QD, truth.torque(QD), model=model)
    assert res.success and res.model == model and isinstance(res.params, type(truth))
    np.testing.assert_allclose(res.params.as_vector(), truth.as_vector(), rtol=1e-5, atol=1e-7)
    assert res.rms_residual < 1e-6 and res.bounded() == ()


@pytest.mark.parametrize("model", ["coulomb-viscous", "stribeck", "thesis"])
def test_each_model_recovers_its_injected_parameters_with_noise(model):
    """Noise 0.03 N·m: every parameter within 5 standard errors (and 10 %) of the injected one."""
    for seed in range(2):
        rng = np.random.default_rng(seed)
        truth = _truth(model, rng)
        res = fit_friction(QD, truth.torque(QD) + rng.normal(0.0, 0.03, QD.size), model=model)
        assert res.model == model and res.bounded() == (), res
        for name in truth.names:
            est, true, se = getattr(res.params, name), getattr(truth, name), res.stderr[name]
            assert abs(est - true) < 5 * se and abs(est - true) < 0.1 * max(abs(true), 0.1), (name, est, true, se)


def test_coulomb_viscous_truth_runs_the_thesis_fit_into_bounds_and_auto_takes_coulomb_viscous():
    """(3.5) holds Coulomb friction only as a -> infinity: fitted to exact sgn data its slope
    ends at the bound, and says so; ``auto`` fits the model that made the data, off its bounds."""
    truth = CoulombViscousParams(F_v=0.3, F_c=0.8, tau_os=0.2)
    thesis = fit_friction(QD, truth.torque(QD), model="thesis")
    assert thesis.at_bound["a"] and thesis.params.a > 0.999 * THESIS.upper[THESIS.index("a")]
    for seed in range(3):
        rng = np.random.default_rng(seed)
        tau_f = truth.torque(QD) + rng.normal(0.0, 0.05, QD.size)
        auto = fit_friction(QD, tau_f, model="auto")
        assert auto.model == "coulomb-viscous" and auto.selection.chosen == "coulomb-viscous"
        assert auto.bounded() == () and not any(auto.at_bound.values())
        np.testing.assert_allclose(auto.params.as_vector(), truth.as_vector(), atol=0.01)
        assert [s.model for s in auto.selection.scores] == ["coulomb-viscous", "stribeck", "thesis"]
        assert auto.selection.reason.startswith("coulomb-viscous:")


def test_stribeck_truth_without_coulomb_level_is_the_real_arm_symptom():
    """Static friction that decays to no Coulomb level (F_c = 0): (3.5) can only write it as
    F_c -> 0 with S at its bound 50 (what a real arm's log gave); it is flagged, and ``auto``
    takes the Stribeck model, which holds it exactly."""
    truth = StribeckParams(F_v=0.4, F_c=0.0, F_s=1.0, v_s=0.15, tau_os=0.3)
    rng = np.random.default_rng(4)
    tau_f = truth.torque(QD) + rng.normal(0.0, 0.03, QD.size)
    thesis = fit_friction(QD, tau_f, model="thesis")
    assert thesis.at_bound["S"] and thesis.params.S == pytest.approx(50.0) and thesis.params.F_c < 0.05
    auto = fit_friction(QD, tau_f, model="auto")
    assert auto.model == "stribeck"
    assert abs(auto.params.F_s - 1.0) < 0.05 and abs(auto.params.v_s - 0.15) < 0.02 and auto.params.F_c < 0.05


@pytest.mark.parametrize("truth", [StribeckParams(F_v=0.3, F_c=0.6, F_s=1.2, v_s=0.15, tau_os=-0.2),
                                   FrictionParams(F_v=0.3, F_c=0.6, S=1.0, v_s=0.15, tau_os=-0.2, a=30.0)])
def test_stribeck_truth_makes_auto_pick_a_stribeck_model(truth):
    rng = np.random.default_rng(1)
    tau_f = truth.torque(QD) + rng.normal(0.0, 0.05, QD.size)
    auto = fit_friction(QD, tau_f, model="auto")
    assert auto.model in ("stribeck", "thesis")
    cv = next(s for s in auto.selection.scores if s.model == "coulomb-viscous")
    assert cv.held_out_rms > 1.5 * min(s.held_out_rms for s in auto.selection.scores)
    values = truth.values_in(auto.model) if isinstance(truth, FrictionParams) else truth.to_dict()
    for name in ("F_c", "v_s", "tau_os"):
        assert abs(getattr(auto.params, name) - values[name]) < 0.1 * abs(values[name]), name


def test_held_out_blocks_are_contiguous_disjoint_and_cover_the_valid_samples():
    use = np.ones(1000, dtype=bool)
    use[[3, 500, 501, 977]] = False
    train, held_out = held_out_split(use)
    assert not (train & held_out).any() and np.array_equal(train | held_out, use)
    # three held-out blocks of a tenth each: three runs of held-out samples among the usable
    # ones in time order, the first block trained on
    flags = held_out[np.flatnonzero(use)].astype(int)
    starts, ends = np.flatnonzero(np.diff(flags) == 1) + 1, np.flatnonzero(np.diff(flags) == -1) + 1
    assert len(starts) == len(ends) == 3 and flags[0] == 0
    assert all(abs((e - b) - 99.6) <= 1 for b, e in zip(starts, ends))
    assert all(abs(b - k * 99.6) <= 1 for b, k in zip(starts, (1, 4, 7)))


def test_held_out_errors_come_from_samples_the_fits_did_not_see():
    """Wrecking the held-out samples' estimates changes no candidate's fit: each score is the
    training fit (identical to a fit on the clean data) evaluated on the wrecked samples."""
    truth = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.0, v_s=0.15, tau_os=0.1)
    rng = np.random.default_rng(2)
    tau_f = truth.torque(QD) + rng.normal(0.0, 0.05, QD.size)
    use = np.ones(QD.size, dtype=bool)
    train, held_out = held_out_split(use)
    wrecked = tau_f.copy()
    wrecked[held_out] = rng.normal(0.0, 5.0, held_out.sum())  # wrecked, yet no gross outlier (screened)
    auto = fit_friction(QD, wrecked, model="auto", selection_tolerance=0.0)
    assert auto.selection.n_train == train.sum() and auto.selection.n_held_out == held_out.sum()
    for score in auto.selection.scores:
        clean = fit_friction(QD, tau_f, mask=train, model=score.model)
        assert score.held_out_rms == pytest.approx(held_out_rms(clean.params, QD, wrecked, held_out), rel=1e-9)
        assert score.held_out_rms > 4.0  # scored on the wrecked samples, fitted without them


def test_auto_fits_the_chosen_model_as_if_it_had_been_named():
    truth = FrictionParams(F_v=0.2, F_c=0.5, S=0.8, v_s=0.2, tau_os=0.1, a=20.0)
    rng = np.random.default_rng(3)
    tau_f = truth.torque(QD) + rng.normal(0.0, 0.05, QD.size)
    auto = fit_friction(QD, tau_f, model="auto")
    named = fit_friction(QD, tau_f, model=auto.model)
    assert auto.params == named.params and auto.stderr == named.stderr and auto.at_bound == named.at_bound
    assert auto.n_samples == QD.size and named.selection is None


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.01, 10.0), min_size=3, max_size=3), st.floats(0.0, 0.5))
def test_choose_model_takes_the_simplest_within_tolerance_of_the_best(rms, tolerance):
    scores = tuple(HeldOutScore(m, r) for m, r in zip(("coulomb-viscous", "stribeck", "thesis"), rms))
    chosen, reason = choose_model(scores, tolerance)
    i = [s.model for s in scores].index(chosen)
    assert rms[i] <= (1 + tolerance) * min(rms)
    assert all(r > (1 + tolerance) * min(rms) for r in rms[:i])
    assert reason.startswith(f"{chosen}:")


def test_choose_model_by_hand():
    scores = (HeldOutScore("coulomb-viscous", 1.015), HeldOutScore("stribeck", 1.0), HeldOutScore("thesis", 0.999))
    assert choose_model(scores, 0.02)[0] == "coulomb-viscous"
    assert choose_model(scores, 0.01)[0] == "stribeck"
    assert choose_model(scores, 0.0)[0] == "thesis"
    assert choose_model((HeldOutScore("coulomb-viscous", np.nan), HeldOutScore("stribeck", 2.0)))[0] == "stribeck"
    with pytest.raises(InputError, match="no model"):
        choose_model((HeldOutScore("thesis", np.nan),))


def test_parameters_pressed_against_a_bound_are_flagged():
    """Friction with a negative viscous slope: the fit's F_v stops at its bound 0 and is flagged;
    a pure viscous friction leaves F_c at 0, flagged; friction inside the bounds flags nothing."""
    rng = np.random.default_rng(0)
    noise = rng.normal(0.0, 0.02, QD.size)
    negative = fit_friction(QD, -(-0.3 * QD + 0.8 * np.sign(QD)) + noise, model="coulomb-viscous")
    assert negative.at_bound == {"F_v": True, "F_c": False, "tau_os": False} and negative.params.F_v < 1e-6
    viscous = fit_friction(QD, CoulombViscousParams(0.3, 0.0, 0.1).torque(QD), model="coulomb-viscous")
    assert viscous.bounded() == ("F_c",)
    inside = fit_friction(QD, CoulombViscousParams(0.3, 0.5, 0.1).torque(QD) + noise, model="coulomb-viscous")
    assert inside.bounded() == ()
    # the Stribeck model's static friction is bounded below by the Coulomb level
    flat = fit_friction(QD, CoulombViscousParams(0.3, 0.5, 0.1).torque(QD), model="stribeck")
    assert flat.at_bound["F_s"] and flat.params.F_s == pytest.approx(flat.params.F_c, abs=1e-6)


def test_stribeck_model_through_the_estimate_smoother():
    """A smoothed estimate is fitted by the model smoothed alike: the injected parameters come back."""
    truth = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.0, v_s=0.15, tau_os=0.1)
    smoother = SavgolSmoother(51, 3, DT)
    res = fit_friction(QD, smoother(truth.torque(QD)), smoother=smoother, model="stribeck")
    np.testing.assert_allclose(res.params.as_vector(), truth.as_vector(), rtol=1e-4, atol=1e-6)
    assert res.n_samples == QD.size - 50  # the smoother's half windows at both ends


def test_error_percent_compares_each_model_with_the_targets_values_under_its_names():
    target = FrictionParams(F_v=0.2, F_c=1.0, S=0.5, v_s=0.2, tau_os=0.4, a=40.0)
    fit = fit_joints(["j"], QD[:, None], StribeckParams(0.22, 1.0, 1.65, 0.2, 0.4).torque(QD)[:, None],
                     np.ones((QD.size, 1), dtype=bool), targets={"j": target}, model="stribeck")[0]
    err = fit.error_percent()
    assert set(err) == {"F_v", "F_c", "F_s", "v_s", "tau_os"}
    assert err["F_s"] == pytest.approx(10.0, rel=1e-4) and err["F_v"] == pytest.approx(10.0, rel=1e-4)
    assert err["F_c"] == pytest.approx(0.0, abs=1e-3)


def test_bad_model_options_are_refused():
    tau_f = -QD
    with pytest.raises(InputError, match="model must be one of"):
        fit_friction(QD, tau_f, model="lugre")
    with pytest.raises(InputError, match="x0"):
        fit_friction(QD, tau_f, model="auto", x0=np.zeros(3))
    with pytest.raises(InputError, match="F_s can be held only with F_c"):
        fit_friction(QD, tau_f, model="stribeck", fixed={"F_s": 1.0})
    with pytest.raises(InputError, match="unknown parameter"):
        fit_friction(QD, tau_f, model="coulomb-viscous", fixed={"S": 0.0})
    with pytest.raises(InputError, match="unknown parameter"):
        fit_friction(QD, tau_f, model="auto", fixed={"b": 0.0})


def test_auto_holds_in_each_candidate_the_parameters_it_has():
    truth = CoulombViscousParams(F_v=0.3, F_c=0.8, tau_os=0.0)
    rng = np.random.default_rng(5)
    res = fit_friction(QD, truth.torque(QD) + rng.normal(0, 0.02, QD.size), model="auto",
                       fixed={"tau_os": 0.0, "S": 0.0})
    assert res.params.tau_os == 0.0 and res.stderr["tau_os"] == 0.0 and not res.at_bound["tau_os"]


def test_too_few_samples_to_hold_out_fit_the_simplest_model():
    res = fit_friction(QD[:40], -QD[:40], model="auto", min_samples=20)
    assert res.model == "coulomb-viscous" and "too few samples" in res.selection.reason
    assert res.selection.scores == ()


_POINTS = {"coulomb-viscous": [0.3, 0.5, 0.05], "stribeck": [0.3, 0.5, 0.9, 0.15, 0.05],
           "thesis": [0.3, 0.5, 0.4, 0.15, 0.05, 30.0]}


@pytest.mark.parametrize("model", ["coulomb-viscous", "stribeck", "thesis"])
def test_filtered_problem_smooths_what_changes_only(model):
    """The filtered fit's residual and Jacobian equal the model and its whole Jacobian smoothed
    together, although the parameter-free columns are smoothed once and the model is evaluated where the rows
    reach alone: to the FFT convolution's rounding."""
    from wbfriction.fit.solve import filtered_problem
    from wbfriction.friction.models import model_jacobian, model_values
    smoother = SavgolSmoother(11, 4, DT)
    qd = QD.copy()
    qd[1000:1010] = np.nan  # a gap the smoother leaves out
    y = smoother(model_values(1.1 * np.array(_POINTS[model]), qd, 2.0, model))
    use = np.isfinite(y)
    residual, jacobian = filtered_problem(qd, y, use, smoother, 2.0, model)
    rows = np.flatnonzero(use)
    for scale in (1.0, 1.3, 0.7):  # several points: the fixed columns are cached at the first
        x = scale * np.array(_POINTS[model])
        both = smoother(np.column_stack([model_values(x, qd, 2.0, model), model_jacobian(x, qd, 2.0, model)]))[rows]
        np.testing.assert_allclose(residual(x), both[:, 0] - y[rows], rtol=0, atol=1e-14 * np.abs(both).max())
        np.testing.assert_allclose(jacobian(x), both[:, 1:], rtol=0, atol=1e-14 * np.abs(both).max())


# ------------------------------------------------------------- each part at its definition (issue 37)
def test_a_result_takes_its_models_name_and_offsets_come_from_the_fitted():
    fit = FitResult("a", 100, CoulombViscousParams(0.1, 0.5, -0.2))
    assert fit.model == "coulomb-viscous" and FitResult("b", 3).model == "thesis"
    assert fitted_offsets([fit, FitResult("b", 3)]) == {"a": -0.2}
    assert fit.verdict() == fit_verdict(fit)


def test_error_percent_needs_parameters_and_a_target_and_is_undefined_at_zero():
    target = FrictionParams(F_v=0.2, F_c=1.0, S=0.0, v_s=0.2, tau_os=0.0, a=40.0)
    fit = FitResult("j", 100, FrictionParams(0.3, 1.5, 0.1, 0.2, 0.1, 40.0), target=target)
    err = fit.error_percent()
    assert err["F_v"] == pytest.approx(50.0) and err["F_c"] == pytest.approx(50.0) and err["a"] == 0.0
    assert np.isnan(err["S"]) and np.isnan(err["tau_os"])
    assert FitResult("j", 3, target=target).error_percent() is None
    assert FitResult("j", 100, FrictionParams(0.3, 1.5, 0.1, 0.2, 0.1, 40.0)).error_percent() is None


def test_model_bounds_default_and_the_stribeck_velocity_bound():
    lower, upper = model_bounds(QD)
    assert len(lower) == 6 and upper[3] == pytest.approx(np.abs(QD).max())  # (3.5), v_s at most the fastest
    assert model_bounds(np.full(10, 1e-5), "stribeck")[1][3] == pytest.approx(2e-4)  # at least twice its floor
    assert np.isinf(model_bounds(QD, "coulomb-viscous")[1]).all()


def test_held_out_rms_by_hand():
    params = CoulombViscousParams(0.3, 0.5, 0.1)
    tau_f = -params.f(QD) + 0.05 * np.cos(7 * T)
    smooth = SavgolSmoother(21, 2, DT)
    rows = ((np.arange(QD.size) % 3 == 1) & np.isfinite(smooth(QD))).astype(int)  # a 0/1 mask given as integers
    r = (smooth(params.f(QD)) + tau_f)[rows == 1]
    assert held_out_rms(params, QD, tau_f, rows, smooth) == pytest.approx(np.sqrt(np.mean(r**2)), rel=1e-12)
    r = (params.f(QD) + tau_f)[rows == 1]
    assert held_out_rms(params, list(QD), list(tau_f), rows) == pytest.approx(np.sqrt(np.mean(r**2)), rel=1e-12)
    assert np.isnan(held_out_rms(params, QD, tau_f, np.zeros(QD.size, dtype=bool)))


def test_choose_model_says_why_in_numbers():
    cv, sb, th = "coulomb-viscous", "stribeck", "thesis"
    model, reason = choose_model((HeldOutScore(cv, 1.05), HeldOutScore(sb, 1.0), HeldOutScore(th, 0.99)), 0.02)
    assert model == sb
    assert reason == ("stribeck: the simplest model within 2 % of the smallest held-out RMS (thesis's; +1 %); "
                      "held-out RMS [N·m]: coulomb-viscous 1.05, stribeck 1, thesis 0.99")
    model, reason = choose_model((HeldOutScore(cv, 1.1), HeldOutScore(sb, 1.0), HeldOutScore(th, 1.05)), 0.02)
    assert reason.startswith("stribeck: the smallest held-out RMS; simpler models exceed it by more than 2 %; ")
    model, reason = choose_model((HeldOutScore(cv, 1.0), HeldOutScore(sb, 1.1), HeldOutScore(th, 1.05)), 0.02)
    assert reason.startswith("coulomb-viscous: the smallest held-out RMS; held-out RMS")


def _covariance_by_hand(J, r, rows, max_lag):
    """The Newey-West sandwich written out: pairs of samples l rows apart, Bartlett weights."""
    n, p = J.shape
    g = J * r[:, None] * np.sqrt(n / (n - p))
    meat = g.T @ g
    for a in range(n):
        for b in range(n):
            lag = rows[b] - rows[a]
            if 0 < lag <= max_lag and b - a == lag:  # no row missing between them
                w = 1.0 - lag / (max_lag + 1.0)
                meat += w * (np.outer(g[b], g[a]) + np.outer(g[a], g[b]))
    bread = np.linalg.inv(J.T @ J)
    return bread @ meat @ bread


def test_parameter_covariance_by_its_definition():
    """s^2 (J^T J)^-1 against numpy's inverse, at any scale of J; the Newey-West sandwich against the sum
    over pairs; a parameter in the null space of J (a zero column, or two equal columns) infinite, the
    others not."""
    rng = np.random.default_rng(30)
    J, r = rng.normal(size=(40, 3)), rng.normal(size=40)
    for scale in (1.0, 1e-6):
        expected = (r @ r) / 37 * np.linalg.inv((scale * J).T @ (scale * J))
        np.testing.assert_allclose(parameter_covariance(scale * J, r), expected, rtol=1e-9)
        np.testing.assert_allclose(standard_errors(scale * J, r), np.sqrt(np.diag(expected)), rtol=1e-9)
    rows = np.r_[np.arange(20), 25 + np.arange(20)]  # a gap: no pair across it
    for max_lag in (1, 3):
        np.testing.assert_allclose(parameter_covariance(J, r, rows=rows, max_lag=max_lag),
                                   _covariance_by_hand(J, r, rows, max_lag), rtol=1e-9)
        np.testing.assert_allclose(parameter_covariance(J, r, max_lag=max_lag),
                                   _covariance_by_hand(J, r, np.arange(40), max_lag), rtol=1e-9)
    for bad, infinite in ((np.c_[J[:, :2], np.zeros(40)], [False, False, True]),
                          (np.c_[J[:, :2], J[:, 1]], [False, True, True])):
        se = standard_errors(bad, r)
        assert list(np.isinf(se)) == infinite
    assert np.isinf(standard_errors(np.zeros((40, 3)), r)).all()


def test_held_parameters_are_the_values_given():
    """Held values are the model's own (F_s, not F_s - F_c): they come back as given, standard error 0."""
    truth = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.0, v_s=0.15, tau_os=0.1)
    res = fit_friction(QD, truth.torque(QD), model="stribeck", fixed={"F_c": 0.6, "F_s": 1.0})
    assert (res.params.F_c, res.params.F_s) == (0.6, 1.0) and res.stderr["F_s"] == 0.0
    np.testing.assert_allclose(res.params.as_vector(), truth.as_vector(), rtol=1e-6, atol=1e-8)
    thesis = FrictionParams(F_v=0.3, F_c=1.0, S=0.5, v_s=0.2, tau_os=0.1, a=40.0)
    res = fit_friction(QD, thesis.torque(QD), fixed={"F_c": 1.0, "S": 0.5})
    assert (res.params.F_c, res.params.S) == (1.0, 0.5)


@pytest.mark.parametrize("model", ["coulomb-viscous", "stribeck", "thesis"])
def test_the_jacobian_in_the_fits_coordinates_is_the_derivative_there(model):
    """Central differences of the model's values in the fit's coordinates (the Stribeck model's F_s - F_c):
    the Jacobian the solver is given."""
    x = {"coulomb-viscous": [0.3, 0.5, 0.1], "stribeck": [0.3, 0.6, 1.0, 0.15, 0.1],
         "thesis": [0.3, 1.0, 0.5, 0.2, 0.1, 40.0]}[model]
    z = to_fit_coordinates(model, np.array(x))
    jac = fit_coordinates_jacobian(model, model_jacobian(from_fit_coordinates(model, z), QD, 2.0, model))
    for i in range(len(z)):
        h = 1e-6 * max(1.0, abs(z[i]))
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        numeric = (model_values(from_fit_coordinates(model, up), QD, 2.0, model)
                   - model_values(from_fit_coordinates(model, down), QD, 2.0, model)) / (2 * h)
        np.testing.assert_allclose(jac[:, i], numeric, atol=1e-5 * max(1.0, np.abs(numeric).max()))
    np.testing.assert_allclose(from_fit_coordinates(model, z), x, rtol=1e-15)


def test_filtered_problem_of_the_default_model():
    truth = FrictionParams(F_v=0.3, F_c=1.0, S=0.5, v_s=0.2, tau_os=0.1, a=40.0)
    smooth = SavgolSmoother(21, 2, DT)
    use = np.isfinite(smooth(QD))
    residual, jacobian = filtered_problem(QD, smooth(truth.f(QD)), use, smooth, 2.0)
    assert np.abs(residual(truth.as_vector())).max() < 1e-12 and jacobian(truth.as_vector()).shape == (use.sum(), 6)


def _two_joints():
    rng = np.random.default_rng(31)
    params = [CoulombViscousParams(0.3, 0.5, 0.1), CoulombViscousParams(0.1, 0.8, -0.2)]
    qd = np.column_stack([QD, -0.7 * QD])
    truth = np.column_stack([p.torque(qd[:, i]) for i, p in enumerate(params)])
    tau_f = truth + rng.normal(0.0, 0.05, truth.shape)
    tau_f[100, 0] = 1e6  # a gross outlier: left out of the fit and of the errors
    valid = np.ones(qd.shape, dtype=bool)
    valid[:300, 1] = False
    return qd, tau_f, valid, truth


def test_fit_joints_errors_against_truth_on_the_samples_fitted():
    qd, tau_f, valid, truth = _two_joints()
    true_nan = truth.copy()
    true_nan[:, 1] = np.nan  # no truth for the second joint
    target = CoulombViscousParams(0.3, 0.5, 0.1)
    fits = fit_joints(["a", "b"], qd, tau_f, valid, tau_f_true=true_nan, model="coulomb-viscous",
                      targets={"a": FrictionParams(F_v=0.3, F_c=0.5, tau_os=0.1)})
    used = np.ones(qd.shape[0], dtype=bool)
    used[100] = False
    err = tau_f[used, 0] - truth[used, 0]
    assert fits[0].rms_error_vs_true == pytest.approx(np.sqrt(np.mean(err**2)), rel=1e-12)
    model_err = fits[0].params.torque(qd[used, 0]) - truth[used, 0]
    assert fits[0].rms_model_vs_true == pytest.approx(np.sqrt(np.mean(model_err**2)), rel=1e-12)
    assert fits[1].rms_error_vs_true is None and fits[1].rms_model_vs_true is None
    assert fits[0].target is not None and fits[0].target.F_c == target.F_c and fits[1].target is None
    assert fits[0].n_screened == 1 and fits[1].n_samples == qd.shape[0] - 300


def test_fit_joints_on_worker_processes_gives_the_same_fits():
    qd, tau_f, valid, truth = _two_joints()
    kwargs = dict(tau_f_true=truth, model="coulomb-viscous")
    assert fit_joints(["a", "b"], qd, tau_f, valid, workers=2, **kwargs) == fit_joints(["a", "b"], qd, tau_f,
                                                                                         valid, **kwargs)


def test_fit_estimate_fits_every_joint_with_its_targets_and_options():
    qd, tau_f, valid, truth = _two_joints()
    n = qd.shape[0]
    est = FrictionEstimate(("a", "b"), T, qd, tau_f, valid, np.zeros(n, dtype=int), np.ones(n, dtype=bool),
                           np.ones((n, 1), dtype=bool), ("sole",), tau_f_true=truth,
                           metadata={"friction_true": {"a": FrictionParams(F_v=0.3, F_c=0.5).to_dict()}})
    options = dict(delta_s=1.5, min_samples=3000, model="thesis", selection_tolerance=0.1)
    # no smoother: a sticking sample reaches one row either side (the central difference's stencil); no noise record
    expected = fit_joints(("a", "b"), qd, tau_f, valid, tau_f_true=truth, **options,
                          targets={"a": FrictionParams(F_v=0.3, F_c=0.5)}, stick_margin=1)
    assert fit_estimate(est, FitOptions(**options, terms=TermOptions(terms=()))) == expected  # fit_joints: no terms
    assert [f.params is None for f in fit_estimate(est, FitOptions(min_samples=3800))] == [False, True]
    # the default is 'wbfriction fit's: the model chosen per joint on held-out data, the terms the log allows tried
    # (this one has no angle, load or temperature: the direction alone)
    plain = fit_estimate(est, FitOptions(terms=TermOptions(terms=())))
    assert plain == fit_joints(("a", "b"), qd, tau_f, valid, tau_f_true=truth, model="auto",
                               targets={"a": FrictionParams(F_v=0.3, F_c=0.5)}, stick_margin=1)
    for f in fit_estimate(est):  # the others said not tried, each for want of its signal (issue 53)
        assert f.terms is not None and {t for t, why in f.terms.reasons.items() if not why.startswith("not tried")} \
            == {"direction"}
        assert f.terms.reasons["temperature"] == "not tried: no temperature.<joint> column"


def test_auto_passes_every_option_to_its_candidates():
    """With a smoother, a joint name, another Stribeck exponent, fewer samples allowed and an offset held,
    the model chosen is fitted as if it had been named with the same options; every candidate's score is
    its fit on the training blocks, smoothed alike, with the parameters it left at a bound."""
    truth = FrictionParams(F_v=0.3, F_c=0.6, S=1.0, v_s=0.15, tau_os=0.1, a=30.0, delta_s=1.5)
    smooth = SavgolSmoother(31, 2, DT)
    tau_f = smooth(truth.torque(QD)) + np.random.default_rng(41).normal(0.0, 0.02, QD.size)
    options = dict(smoother=smooth, joint="k", delta_s=1.5, min_samples=30, fixed={"tau_os": 0.1})
    auto = fit_friction(QD, tau_f, model="auto", selection_tolerance=0.07, **options)
    sel = auto.selection
    assert (auto.joint, sel.chosen, sel.tolerance) == ("k", auto.model, 0.07)
    named = fit_friction(QD, tau_f, model=auto.model, **options)
    assert auto.params == named.params and auto.stderr == named.stderr and auto.params.tau_os == 0.1
    use = np.isfinite(smooth(QD))
    train, held_out = held_out_split(use)
    assert (sel.n_train, sel.n_held_out) == (train.sum(), held_out.sum())
    for score in sel.scores:
        fit = fit_friction(QD, tau_f, mask=train, model=score.model, **options)
        assert score.held_out_rms == pytest.approx(held_out_rms(fit.params, QD, tau_f, held_out, smooth), rel=1e-9)
        assert score.at_bound == fit.bounded()
    assert sel.reason.startswith(f"{auto.model}: ")


def _valid_count_with_smallest_side(side: int) -> int:
    """A number of valid samples whose smaller split (training or held out) has exactly ``side`` samples."""
    return next(n for n in range(side, 20 * side) if min(s.sum() for s in held_out_split(np.ones(n, bool))) == side)


@pytest.mark.parametrize("min_samples,side", [(20, 20), (5, 7)])
def test_auto_holds_out_when_each_side_has_enough_samples(min_samples, side):
    """Each side needs at least max(min_samples, 7) samples: exactly that many is enough; one fewer is not,
    and then the simplest model is fitted with the options given, said."""
    for n, enough in ((_valid_count_with_smallest_side(side), True), (_valid_count_with_smallest_side(side - 1),
                                                                      False)):
        qd = QD[:n * 10:10]
        tau_f = CoulombViscousParams(0.3, 0.5, 0.1).torque(qd)
        res = fit_friction(qd, tau_f, model="auto", min_samples=min_samples, fixed={"tau_os": 0.1}, joint="j",
                           selection_tolerance=0.05)
        assert bool(res.selection.scores) == enough, n
        assert res.params.tau_os == 0.1 and res.joint == "j" and res.selection.tolerance == 0.05
        if not enough:
            train, held_out = held_out_split(np.ones(n, bool))
            assert res.selection == ModelSelection("coulomb-viscous", f"coulomb-viscous: too few samples ({n}) to "
                                                   "hold any out", (), 0.05, train.sum(), held_out.sum())


def test_a_bounded_model_must_beat_a_simpler_interior_one_beyond_the_noise_of_the_comparison():
    """Issue 38's rule: the tolerance picks the Stribeck model, one of its parameters at a bound; the Coulomb-viscous
    model, every parameter interior, is taken instead unless the Stribeck model lowers the held-out mean square by
    more than two standard errors of that lowering (Newey-West over the held-out samples)."""
    rng = np.random.default_rng(5)
    rows = np.arange(3000)
    simple = rng.normal(0.0, 0.1, rows.size)
    scores = (HeldOutScore("coulomb-viscous", 0.1), HeldOutScore("stribeck", 0.097, ("F_c",)),
              HeldOutScore("thesis", 0.099, ("S",)))
    close = simple * 0.999 + rng.normal(0.0, 0.01, rows.size)  # a lowering well within its noise
    chosen, reason = prefer_interior("stribeck", "stribeck: the simplest (x; +1 %); held-out RMS [N·m]: a 1, b 2",
                                     scores, {"coulomb-viscous": simple, "stribeck": close}, rows)
    assert chosen == "coulomb-viscous" and reason.startswith("coulomb-viscous: stribeck leaves F_c at a bound")
    assert reason.endswith("within 2 standard errors; held-out RMS [N·m]: a 1, b 2")
    gain, se = held_out_gain(simple, close, rows)
    assert gain < 2 * se
    far = simple * 0.7  # a lowering of half the mean square: far beyond its noise
    chosen, reason = prefer_interior("stribeck", "stribeck: ...", scores, {"coulomb-viscous": simple,
                                                                           "stribeck": far}, rows)
    assert chosen == "stribeck" and "outweighs its bound (F_c)" in reason
    # an interior choice stands as it is
    assert prefer_interior("coulomb-viscous", "r", scores, {}, rows) == ("coulomb-viscous", "r")


def test_a_magnitude_at_its_floor_of_zero_is_no_bound_for_the_status():
    """A Coulomb-viscous fit with F_v = 0 (no viscous friction found) is at a bound of its fit (what the automatic
    choice weighs) but not of its search (:func:`search_bounds`: its status is not ``at bound``)."""
    fit = FitResult(joint="j", n_samples=100, success=True, rms_residual=0.01, model="coulomb-viscous",
                    params=CoulombViscousParams(0.0, 0.5, 0.0),
                    stderr={"F_v": 0.01, "F_c": 0.01, "tau_os": 0.01},
                    at_bound={"F_v": True, "F_c": False, "tau_os": False})
    assert fit.bounded() == ("F_v",) and search_bounds(fit) == []


def test_the_held_out_gain_and_its_standard_error_by_hand():
    """White residuals: the mean of the difference of squares and its plain standard error (no correlation to sum)."""
    rng = np.random.default_rng(6)
    a, b = rng.normal(0, 1.0, 5000), rng.normal(0, 0.9, 5000)
    gain, se = held_out_gain(a, b, np.arange(5000))
    d = a**2 - b**2
    assert gain == pytest.approx(d.mean(), rel=1e-12)
    assert se == pytest.approx(d.std() / np.sqrt(d.size), rel=0.2)


def _stick_slip(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A joint that slides (Coulomb-viscous friction F_c 0.8, F_v 0.2 of its velocity) and sticks in turn: 0.4 s
    sliding at up to 0.5 rad/s, then 0.3 s stuck, chattering at up to 2e-3 rad/s (a sign applied at every
    physics step) while its friction is anything within the static level 1.2 N·m. Returns (qd, tau_f)."""
    rng = np.random.default_rng(seed)
    qd, tau_f = [], []
    for k in range(40):
        slide = 0.5 * np.sin(np.pi * np.arange(400) / 400) * (1 if k % 2 else -1)
        chatter = 2e-3 * rng.uniform(-1.0, 1.0, 300)
        qd += [slide, chatter]
        tau_f += [-(0.2 * slide + 0.8 * np.sign(slide)), rng.uniform(-1.2, 1.2, 300)]
    return np.concatenate(qd), np.concatenate(tau_f)


def test_sticking_samples_are_left_out_and_the_sliding_ones_give_the_truth():
    """Stuck samples (friction any value within the static level) left out: F_c and F_v exact; kept, they bias the
    fit; the floor of the sticking speed is above a simulator's chatter."""
    qd, tau_f = _stick_slip()
    kept = fit_friction(qd, tau_f, model="coulomb-viscous")
    out = fit_friction(qd, tau_f, model="coulomb-viscous", stick=stick_speed(0.0), stick_margin=1)
    assert stick_speed(0.0) == STICK_FLOOR > 2e-3
    assert out.n_samples + out.n_stuck == 28_000  # every chattering sample, and the sliding ones beside them
    assert 12_000 <= out.n_stuck <= 12_000 + 40 * 4
    assert out.params.F_c == pytest.approx(0.8, rel=1e-3) and out.params.F_v == pytest.approx(0.2, rel=1e-3)
    assert abs(kept.params.F_v / 0.2 - 1.0) > 0.05


def test_a_reversal_that_passes_through_zero_is_not_sticking():
    """Issue 52: a joint that reverses through zero without stopping (a 100 Hz log of a sweep, a rate of 0.02 rad/s
    per row at the reversals) holds no static friction: its slow samples and their neighbours stay in the fit (a
    UR10e's log lost a fifth of its samples so, its F_c 5-20 % off), and a smoothed fit recovers the friction; the
    stretches where the same joint stops for a while (below the sticking speed for 40 rows) are left out with their
    margin."""
    from wbfriction.fit.solve import stuck_rows

    t = np.arange(6000) * 0.01
    qd = 0.6 * np.sin(2 * np.pi * 0.5 * t + 0.3)  # through zero at 1.9 rad/s^2: 0.019 rad/s a row
    assert not stuck_rows(qd, STICK_FLOOR, 16).any()
    stopped = qd.copy()
    stopped[1000:1040] = 1e-3 * np.sin(np.arange(40))  # stuck, chattering
    rows = stuck_rows(stopped, STICK_FLOOR, 16)
    assert rows[1000:1040].all() and rows[1000 - 16] and not rows[1000 - 17 - 5] and rows.sum() <= 40 + 2 * 16 + 4
    tau_f = -(0.3 * qd + 1.0 * np.sign(qd))
    fit = fit_friction(qd, tau_f, model="coulomb-viscous", stick=STICK_FLOOR, stick_margin=16)
    assert fit.n_stuck == 0
    assert fit.params.F_c == pytest.approx(1.0, rel=1e-6) and fit.params.F_v == pytest.approx(0.3, rel=1e-6)


def test_a_joint_that_hardly_moved_keeps_its_slow_samples():
    """Below the excitation speed there is no velocity model to fit: no sample is left out as sticking (its
    offset comes from all of them), and its speed counts them."""
    rng = np.random.default_rng(1)
    qd = 2e-3 * rng.uniform(-1.0, 1.0, 2000)
    res = fit_friction(qd, 0.15 + 0.01 * rng.normal(size=qd.size), model="coulomb-viscous",
                       stick=stick_speed(0.0), stick_margin=1)
    assert res.n_stuck == 0 and res.n_samples == 2000
    assert res.verdict().status == "not excited"

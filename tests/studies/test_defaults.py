"""The default-choosing study (issue 52): a value is chosen over every dataset, and each dataset left out gets the
value chosen without it."""

from __future__ import annotations

import pytest

from wbfriction.studies.default_cases import Setting
from wbfriction.studies.defaults import KNOBS, Knob, choose


def knob(stage="fit") -> Knob:
    return Knob("x", stage, (0.0, 1.0, 2.0), 1.0, lambda s, v: s)


def test_the_value_best_over_every_dataset_is_chosen_and_each_left_out_scored():
    """Three datasets: 2.0 is best on two, the default on the third. Over all, 2.0 wins; left out, the lone dataset
    that disagrees is scored with the others' choice (and shows it is worse for it), each of the others with the
    value the rest choose."""
    losses = {0.0: {"a": 2.0, "b": 2.0, "c": 2.0}, 1.0: {"a": 1.0, "b": 1.0, "c": 1.0},
              2.0: {"a": 0.5, "b": 0.5, "c": 1.5}}
    choice = choose(knob(), losses)
    assert choice.best == 2.0 and choice.scores[2.0] == pytest.approx((0.5 + 0.5 + 1.5) / 3)
    assert choice.left_out["c"] == (2.0, 1.5)  # chosen on a and b, 50 % worse on c
    assert choice.left_out["a"] == (1.0, 1.0)  # b and c: 2.0's mean (0.5 + 1.5) / 2 ties the default's: the default
    # without a, the default: 2.0 rests on a (with b), not on every dataset: today's default stays
    assert choice.chosen == 1.0


def test_a_value_every_fold_agrees_on_replaces_the_default_if_it_matters():
    agreed = {0.0: {"a": 2.0, "b": 2.0, "c": 2.0}, 1.0: {"a": 1.0, "b": 1.0, "c": 1.0},
              2.0: {"a": 0.5, "b": 0.6, "c": 0.9}}
    assert choose(knob(), agreed).chosen == 2.0
    slight = {0.0: {"a": 2.0, "b": 2.0}, 1.0: {"a": 1.0, "b": 1.0}, 2.0: {"a": 0.995, "b": 0.996}}
    choice = choose(knob(), slight)
    assert choice.best == 2.0 and choice.chosen == 1.0  # 0.5 %: within the noise of a few percent


def test_a_tie_keeps_the_default():
    losses = {0.0: {"a": 1.0}, 1.0: {"a": 1.0}, 2.0: {"a": 1.0}}
    assert choose(knob(), losses).chosen == 1.0


def test_statuses_are_scored_by_their_loss_not_a_ratio():
    """A status threshold's loss can be zero: its values are compared as they are."""
    losses = {0.0: {"a": 0.0, "b": 0.4}, 1.0: {"a": 0.2, "b": 0.2}, 2.0: {"a": 0.5, "b": 0.0}}
    choice = choose(knob("status"), losses)
    assert choice.scores == {0.0: 0.2, 1.0: 0.2, 2.0: 0.25} and choice.best == 1.0  # tie: the default
    assert choice.left_out["a"] == (2.0, 0.5) and choice.left_out["b"] == (0.0, 0.4)


def test_every_knob_sets_its_option_and_lists_todays_default():
    """Each knob's default is today's value of the option it sets (a study of another value than the one the code
    uses would choose nothing)."""
    from wbfriction.fit.options import FitOptions, TermOptions
    from wbfriction.fit.status import DEFAULT_THRESHOLDS
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.inertia.options import InertialOptions

    current = {"link_margin": InertialOptions().link_margin, "prior_tolerance": InertialOptions().prior_tolerance,
               "noise_target": EstimateOptions().noise_target,
               "selection_tolerance": FitOptions().selection_tolerance, "pass_rows": FitOptions().pass_rows,
               "terms": "auto" if FitOptions().terms == TermOptions() else "none",
               "term_min_torque": FitOptions().terms.min_torque, "score_slow": FitOptions().score_slow,
               "term_tolerance": FitOptions().terms.tolerance, "stick_floor": FitOptions().stick_floor,
               "weak": DEFAULT_THRESHOLDS.weak, "holdout_excess": DEFAULT_THRESHOLDS.holdout_excess,
               "holdout_friction": DEFAULT_THRESHOLDS.holdout_friction,
               "route_rel": DEFAULT_THRESHOLDS.route_rel}
    assert {k.name for k in KNOBS} == set(current)
    for k in KNOBS:
        assert k.default == current[k.name] and k.default in k.values, k.name
        for v in k.values:
            assert k.set(Setting(), v) != Setting() or v == k.default, (k.name, v)

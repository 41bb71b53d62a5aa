"""Every options class refuses a bad value where it is defined, with one line naming the option (issue 39): the
API and the command line refuse the same values. Property tests over each class's choice fields (every
``Literal``-typed field, read from its type hints, so a new choice is covered when it is added) and its ranges."""

from __future__ import annotations

import pickle
import types
import typing

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.choices import check_range, flag
from wbfriction.exceptions import InputError, OptionError
from wbfriction.fit.options import FitOptions
from wbfriction.fleet.options import BatchOptions
from wbfriction.friction.options import EstimateOptions, MomentumOptions
from wbfriction.inertia.options import InertialOptions
from wbfriction.signals.options import FilterOptions
from wbfriction.sim.options import IdealOptions, MujocoOptions
from wbfriction.walking.options import GaitOptions

CLASSES = (EstimateOptions, FitOptions, FilterOptions, MomentumOptions, InertialOptions, IdealOptions, MujocoOptions,
           GaitOptions, BatchOptions)
OPTION = {(MujocoOptions, "friction"): "--mujoco-friction"}
"""Fields whose command-line option is not spelt as the field."""


def choice_fields(cls) -> list[tuple[str, tuple[str, ...]]]:
    """The fields of ``cls`` whose type is a ``Literal`` (alone or with None), with their choices."""
    out = []
    for name, hint in typing.get_type_hints(cls).items():
        union = typing.get_origin(hint) in (typing.Union, types.UnionType)
        args = [a for a in typing.get_args(hint) if a is not type(None)] if union else [hint]
        if len(args) == 1 and typing.get_origin(args[0]) is typing.Literal:
            out.append((name, typing.get_args(args[0])))
    return out


FIELDS = [(cls, name, choices) for cls in CLASSES for name, choices in choice_fields(cls)]


def test_every_options_class_has_its_choices_read_from_its_type_hints():
    names = {(cls.__name__, name) for cls, name, _ in FIELDS}
    assert {("EstimateOptions", n) for n in ("diff", "torque_alignment", "mask", "method", "velocity", "base_motion",
                                             "route")} <= names
    assert {("FitOptions", "model"), ("FilterOptions", "weights"), ("InertialOptions", "armature"),
            ("IdealOptions", "integrator"), ("IdealOptions", "projection"), ("MujocoOptions", "friction"),
            ("GaitOptions", "gait")} <= names


@pytest.mark.parametrize(("cls", "name", "choices"), FIELDS, ids=[f"{c.__name__}.{n}" for c, n, _ in FIELDS])
@given(value=st.text(min_size=1, max_size=12))
def test_a_value_outside_the_choices_is_refused_with_one_line_naming_the_option(cls, name, choices, value):
    if value in choices:
        assert getattr(cls(**{name: value}), name) == value  # each choice is taken
        return
    with pytest.raises(OptionError) as info:
        cls(**{name: value})
    message = str(info.value)
    option = OPTION.get((cls, name), flag(name))
    assert "\n" not in message and message.startswith(f"{option} must be one of {', '.join(choices)}")
    assert info.value.option == option and info.value.value == value


@pytest.mark.parametrize(("cls", "name", "choices"), FIELDS, ids=[f"{c.__name__}.{n}" for c, n, _ in FIELDS])
def test_every_choice_is_taken(cls, name, choices):
    for value in choices:
        if cls is EstimateOptions and name == "diff":
            assert EstimateOptions(diff=value).diff == value
        else:
            assert getattr(cls(**{name: value}), name) == value


RANGES = [  # (class, field, a strategy of bad values)
    (FilterOptions, "window", st.integers(-5, 2) | st.integers(2, 400).map(lambda n: 2 * n)),
    (FilterOptions, "poly_order", st.integers(-3, 1) | st.integers(151, 400)),
    (FilterOptions, "cutoff", st.floats(-1e3, 0.0)),
    (FilterOptions, "butter_order", st.integers(-3, 0)),
    (FitOptions, "selection_tolerance", st.floats(-10, -1e-9)),
    (FitOptions, "min_samples", st.integers(-10, 0)),
    (FitOptions, "delta_s", st.floats(-10, 0.0)),
    (EstimateOptions, "lift_off_skip", st.floats(-10, -1e-9)),
    (EstimateOptions, "touch_down_skip", st.floats(-10, -1e-9)),
    (EstimateOptions, "ds_weight", st.floats(-10, 0.0)),
    (EstimateOptions, "ds_regularization", st.floats(-10, -1e-9)),
    (MomentumOptions, "velocity_window", st.integers(-5, 6) | st.integers(4, 100).map(lambda n: 2 * n)),
    (MomentumOptions, "window", st.integers(-5, 2) | st.integers(2, 100).map(lambda n: 2 * n)),
]


@pytest.mark.parametrize(("cls", "name", "bad"), RANGES, ids=[f"{c.__name__}.{n}" for c, n, _ in RANGES])
@given(data=st.data())
def test_a_value_out_of_its_range_is_refused_with_one_line_naming_the_option(cls, name, bad, data):
    value = data.draw(bad)
    with pytest.raises(OptionError) as info:
        cls(**{name: value})
    option = {"window": "--momentum-window"}.get(name, flag(name)) if cls is MomentumOptions else flag(name)
    assert "\n" not in str(info.value) and str(info.value).startswith(f"{option} must be ")
    assert info.value.option == option and info.value.value == value


def test_defaults_are_valid_and_a_filter_is_not_dropped_silently_by_auto():
    for cls in CLASSES:
        cls()  # the defaults pass their own checks
    assert EstimateOptions().diff == "auto" and FitOptions().model == "auto"
    assert BatchOptions().estimate == EstimateOptions() and BatchOptions().fit == FitOptions()
    EstimateOptions(diff="savgol", filtering=FilterOptions(window=101))  # a filter with its scheme: taken
    for given_filter, option in ((FilterOptions(window=101), "--window"), (FilterOptions(cutoff=5.0), "--cutoff"),
                                 (FilterOptions(weights="gaussian"), "--weights")):
        with pytest.raises(OptionError, match=f"^{option} must be given with --diff savgol or butterworth"):
            EstimateOptions(filtering=given_filter)


def test_check_range_names_both_bounds_and_is_an_input_error():
    with pytest.raises(InputError, match=r"^--x must be >= 0 and <= 1, got 2$"):
        check_range("x", 2, low=0, high=1)
    with pytest.raises(OptionError, match=r"^--x must be > 0, got 0$"):
        check_range("x", 0, low=0, strict=True)
    check_range("x", 0, low=0)
    back = pickle.loads(pickle.dumps(OptionError("--x", 1, "odd")))  # across worker processes, with its data
    assert (back.option, back.value, back.expected, str(back)) == ("--x", 1, "odd", "--x must be odd, got 1")

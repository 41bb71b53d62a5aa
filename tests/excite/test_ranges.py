"""Issue 81, class 5: ``excite``'s numbers were outside the value ranges: ``--duration 1e9`` a MemoryError traceback,
``--duration 1e6`` past a minute, ``--rate 1e9`` killed for memory, ``--rate 0`` a ZeroDivisionError. Every number
of every rig's design options is now a quantity (:data:`wbfriction.quantities.RANGES`), refused outside its range
before any work in one line naming the option; the samples a design simulates are bounded by the memory it may hold
(:func:`~wbfriction.excite.options.check_design_size`); a Fourier period must put its highest harmonic below half
the rate."""

from __future__ import annotations

import dataclasses
import math
import typing

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli_printed, said
from test_quantities import inside, outside
from wbfriction.exceptions import InputError, OptionError
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.options import DESIGN_MEMORY, JOINT_SAMPLE, check_design_size, design_samples
from wbfriction.options import flag_of, read_options
from wbfriction.rigs import Rig, rigs

DESIGNS = [r.design_options for r in rigs() if r.design_options is not None]
NUMBERS = [(cls, f) for cls in DESIGNS for f in dataclasses.fields(cls)
           if typing.get_type_hints(cls)[f.name] in (float, int)]
"""Every number of every built-in rig's design options (a hung robot's, an arm's, a biped's, a quadruped's)."""


def test_every_number_of_a_design_is_a_quantity():
    assert {f.name for _, f in NUMBERS} == {"duration", "rate", "period", "torque_share", "seed"}
    assert all(f.metadata.get("quantity") is not None for _, f in NUMBERS)


@settings(max_examples=60, deadline=None)
@given(data=st.data(), number=st.sampled_from(NUMBERS))
def test_each_number_takes_its_range_and_refuses_the_rest_naming_the_option(data, number):
    cls, f = number
    quantity = f.metadata["quantity"]
    value = data.draw(inside(quantity))
    assert getattr(read_options(cls, {f.name: value}), f.name) == value
    bad = data.draw(outside(quantity))
    with pytest.raises(OptionError, match=rf"^{flag_of(f.name)} must be ") as err:
        read_options(cls, {f.name: bad})
    assert "\n" not in str(err.value)


@settings(max_examples=30, deadline=None)
@given(good=inside("share"), bad=outside("share"))
def test_each_amplitude_is_a_share(good, bad):
    cls = next(c for c in DESIGNS if "amplitude" in {f.name for f in dataclasses.fields(c)})
    assert read_options(cls, {"amplitude": (good,)}).amplitude == (good,)
    with pytest.raises(OptionError, match=r"^--amplitude must be "):
        read_options(cls, {"amplitude": (0.5, bad)})


@settings(max_examples=60, deadline=None)
@given(joints=st.integers(1, 60), duration=inside("duration"), rate=inside("rate"))
def test_a_design_holds_at_most_its_memory(joints, duration, rate):
    most = design_samples(joints)
    assert most * joints * JOINT_SAMPLE <= DESIGN_MEMORY < (most + 1) * joints * JOINT_SAMPLE
    if duration * rate <= most:
        check_design_size("r", joints, duration, rate)
    else:
        with pytest.raises(OptionError, match=r"^--rate must be at most .* Hz over .*what a design may hold"):
            check_design_size("r", joints, duration, rate, "--rate")


@settings(max_examples=60, deadline=None)
@given(rate=inside("rate"), period=inside("period"), harmonics=st.integers(1, 10))
def test_a_period_puts_its_highest_harmonic_below_half_the_rate(rate, period, harmonics):
    try:
        ExciteOptions(duration=period, rate=rate, period=period, harmonics=harmonics)  # one period
    except InputError as err:
        assert period * rate <= 2 * harmonics and str(err).startswith(f"--period {period:g}: its series' highest")
    else:
        assert period * rate > 2 * harmonics


@pytest.fixture
def no_design(monkeypatch):
    """Any rig's design fails the test: a refusal comes before the work."""
    def never(*args, **kwargs):
        raise AssertionError("the design ran")

    monkeypatch.setattr(Rig, "design", never)
    for rig in rigs():
        monkeypatch.setattr(type(rig), "design", never)


@pytest.mark.parametrize(("robot", "given", "option"), [
    ("go2", ("--rate", "0"), "--rate"), ("go2", ("--rate", "1e9"), "--rate"),
    ("go2", ("--duration", "1e9"), "--duration"), ("go2", ("--duration", "1e6"), "--duration"),
    ("go2", ("--duration", "0"), "--duration"), ("go2", ("--duration", "nan"), "--duration"),
    ("go2", ("--duration", "1000"), "--duration"), ("go2", ("--rate", "9000"), "--rate"),
    ("go2", ("--amplitude", "0"), "--amplitude"), ("go2", ("--torque-share", "1.5"), "--torque-share"),
    ("go2", ("--seed", "-1"), "--seed"), ("panda", ("--period", "0"), "--period"),
    ("panda", ("--rate", "0"), "--rate"), ("panda", ("--period", "inf"), "--period"),
    ("go2_walking", ("--period", "0"), "--period"), ("go2_walking", ("--rate", "1e9"), "--rate"),
])
def test_out_of_range_is_one_line_naming_the_option_before_the_work(capsys, tmp_path, no_design, robot, given,
                                                                     option):
    code, _, err = run_cli_printed(capsys, "excite", "--robot", robot, *given, "-o", tmp_path / "d.parquet")
    lines = said(err)
    assert code == 2 and len(lines) == 1 and lines[0].startswith(f"error: {option} must be "), err
    assert not (tmp_path / "d.parquet").exists()


def test_the_memory_bound_names_the_robots_joints(capsys, tmp_path, no_design):
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--duration", "1000", "-o",
                                   tmp_path / "d.parquet")
    most = design_samples(12)
    assert code == 2 and f"at most {most / 200:.6g} s at 200 Hz: {most} samples of the 12 joints of robot 'go2'" in err
    assert math.isclose(most, DESIGN_MEMORY / 12e3, rel_tol=1e-4)

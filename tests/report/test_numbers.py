"""Numbers to the digits their standard error supports, one format (issue 39): parsed back, a value is within
half its last digit of the truth, its error within the rounding of one or two significant digits, both with
the same decimals; durations say the time recorded and the span across gaps."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.report.numbers import bound_text, duration_text, with_error

PATTERN = re.compile(r"^\(?(-?\d+(?:\.(\d+))?) ± (\d+(?:\.(\d+))?)\)?(?:e([+-]\d+))?$")


@given(value=st.floats(-1e9, 1e9, allow_nan=False), se=st.floats(1e-12, 1e9))
def test_the_value_keeps_the_digits_its_error_supports(value, se):
    text = with_error(value, se)
    match = PATTERN.match(text)
    assert match, text
    v, v_dec, e, e_dec, power = match.groups()
    assert len(v_dec or "") == len(e_dec or ""), text  # one decimal place for both
    scale = 10.0 ** int(power) if power else 1.0
    shown = float(e) * scale
    assert shown > 0, text
    exponent = math.floor(math.log10(shown) + 1e-12)
    leading_one = shown / 10.0**exponent < 2
    place = 10.0 ** (exponent - 1 if leading_one else exponent)  # the error's last digit: two when the first is 1
    units = shown / place
    assert abs(units - round(units)) < 1e-6 and (10 <= round(units) <= 19 if leading_one else round(units) <= 9), text
    tolerance = 0.5 * place * (1 + 1e-6) + 1e-9 * abs(value)
    assert abs(shown - se) <= tolerance, text  # the error rounded (0.196 reads 0.2: one digit, its first is 2)
    assert abs(float(v) * scale - value) <= tolerance, text


def test_known_cases():
    assert with_error(0.18, 0.005) == "0.180 ± 0.005"
    assert with_error(1.012, 0.003) == "1.012 ± 0.003"
    assert with_error(39.8, 0.14) == "39.80 ± 0.14"  # a leading 1: two digits
    assert with_error(12345.6, 23) == "12350 ± 20"
    assert with_error(3.0, 0.196) == "3.0 ± 0.2"  # 0.196 rounds to 0.20: its first digit is 2, one digit
    assert with_error(3.0, 0.0996) == "3.00 ± 0.10"
    assert with_error(3e-7, 1e-8) == "(3.00 ± 0.10)e-07"
    assert with_error(2.098e-55, 510) == "0 ± 500"
    assert with_error(1.5, math.inf) == "1.5 ± n.i." and with_error(3.0, None) == "3"
    assert bound_text(0.0013) == "± 0.0013" and bound_text(0.004) == "± 0.004" and bound_text(math.inf) == "n.i."
    assert bound_text(None) == ""
    assert bound_text(0.196) == "± 0.2" and bound_text(0.14) == "± 0.14" and bound_text(2.3e-7) == "± 2e-07"
    assert bound_text(1.4e9) == "± 1.4e+09" and bound_text(38.0) == "± 40"


def test_a_duration_is_the_time_recorded_and_the_span_across_gaps():
    assert duration_text(np.arange(0, 31.8, 0.001)) == "31.8 s recorded"
    runs = np.concatenate([np.arange(0, 25, 0.005), 1758 + np.arange(0, 25, 0.005)])  # two runs 29 min apart
    assert duration_text(runs) == "50.0 s recorded in 2 runs over 29.7 min"
    assert duration_text([0.0]) == "0 s recorded"
    assert duration_text(np.arange(0, 7201, 1.0)) == "2.0 h recorded"


@pytest.mark.parametrize("value", [0.0, -2.5, 1e6])
def test_no_error_means_four_significant_digits(value):
    assert with_error(value, 0.0) == f"{value:.4g}"

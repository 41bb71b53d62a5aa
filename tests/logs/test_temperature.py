"""A log's temperatures screened as they are read (issue 53): a glitched sample left out and named, a column in
kelvin or no temperature at all refused by name, every plausible series kept as it is."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.exceptions import ColumnError, OptionError
from wbfriction.logs.options import PLAUSIBLE, check_reference_temperature
from wbfriction.logs.temperature import GLITCH_STEP, screen_temperature


def warming(n: int = 2000, start: float = 25.0, end: float = 55.0, step: float = 0.1) -> np.ndarray:
    """A joint warming from ``start`` to ``end`` °C, read by a sensor of ``step`` °C resolution."""
    return np.round(np.linspace(start, end, n) / step) * step


def test_a_glitched_sample_is_left_out_and_named():
    T = np.column_stack([warming(), warming(start=30.0, end=31.0)])
    T[700, 0] = 6553.5  # a sensor's all-ones word
    T[1200, 1] = -40.0
    out, warnings = screen_temperature(T, ["j0", "j1"], "log.parquet", first_row=100)
    assert np.isnan(out[700, 0]) and np.isnan(out[1200, 1])
    assert np.isnan(out).sum() == 2 and np.array_equal(out[~np.isnan(out)], T[~np.isnan(out)])
    assert len(warnings) == 2
    assert "temperature.j0" in warnings[0] and "row 800" in warnings[0] and "6553.5 °C" in warnings[0]
    assert "temperature.j1" in warnings[1] and "row 1300" in warnings[1] and "-40 °C" in warnings[1]
    assert T[700, 0] == 6553.5  # the input is not touched


def test_a_column_in_kelvin_is_refused_by_name():
    T = (warming() + 273.15)[:, None]
    with pytest.raises(ColumnError, match=r"temperature\.j0.*kelvin") as info:
        screen_temperature(T, ["j0"], "log.parquet")
    assert info.value.column == "temperature.j0" and info.value.row == 0


def test_a_column_of_glitches_is_no_temperature():
    T = warming()[:, None].copy()
    T[::10, 0] += 50.0
    with pytest.raises(ColumnError, match="not a temperature"):
        screen_temperature(T, ["j0"], "log.parquet")


@given(start=st.floats(PLAUSIBLE[0] + 10, PLAUSIBLE[1] - 40), rise=st.floats(-10.0, 30.0),
       resolution=st.sampled_from([0.01, 0.1, 0.5, 1.0]), two=st.booleans(), n=st.integers(20, 600),
       glitches=st.lists(st.tuples(st.integers(0, 599), st.floats(GLITCH_STEP * 3, 1000.0)), max_size=3))
def test_plausible_series_are_kept_and_glitches_found(start, rise, resolution, two, n, glitches):
    """A joint warming or cooling at any rate a log of at least 20 samples can hold, at any sensor resolution, or
    two values (one step), keeps every sample; glitches far from it (more than three times the step) are exactly the
    samples left out."""
    T = warming(n, start, start + rise, resolution)
    if two:
        T = np.where(np.arange(n) < n // 2, start, start + rise)
    bad = {i % n: size for i, size in glitches if not (two and abs(i % n - n // 2) <= 4)}
    if len(bad) > 0.05 * n:
        return
    glitched = T.copy()
    for i, size in bad.items():
        glitched[i] += size
    out, warnings = screen_temperature(glitched[:, None], ["j"], "log")
    assert set(np.flatnonzero(np.isnan(out[:, 0]))) == set(bad)
    assert len(warnings) == (1 if bad else 0)
    keep = ~np.isnan(out[:, 0])
    assert np.array_equal(out[keep, 0], T[keep])


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -300.0, 1e6])
def test_a_reference_temperature_no_joint_has_is_refused(value):
    with pytest.raises(OptionError, match="--reference-temperature"):
        check_reference_temperature(value)
    check_reference_temperature(None)
    check_reference_temperature(40.0)

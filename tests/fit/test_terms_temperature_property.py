"""Random temperature series through the temperature term (issue 53): whatever the series (constant, two values, a
warm-up, glitched, in kelvin, logged on some joints only), the fit gives the right answer or refuses the column in
one line; never a warning, a NaN in the parameters JSON, or a slope the friction does not have."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import ColumnError
from wbfriction.fit.options import TermOptions
from wbfriction.fit.term_selection import fit_terms
from wbfriction.fit.terms import TermSignals
from wbfriction.friction.models import CoulombViscousParams
from wbfriction.logs.temperature import screen_temperature

N = 3000
F_CT = -0.01
"""The truth: F_c falls by 0.01 N·m per °C from 1 N·m at 40 °C."""
VELOCITY = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0)
KINDS = ("constant", "two values", "warm-up", "glitched warm-up", "kelvin", "not logged")


def _temperature(kind: str, low: float, spread: float, rng) -> np.ndarray | None:
    i = np.arange(N)
    warm = low + spread * i / N
    if kind == "constant":
        return np.full(N, low)
    if kind == "two values":
        return np.where(i < N // 2, low, low + spread)
    if kind == "glitched warm-up":
        warm = warm.copy()
        warm[rng.integers(0, N, 3)] = 6553.5
        return warm
    if kind == "kelvin":
        return warm + 273.15
    return None if kind == "not logged" else warm


@settings(max_examples=30, deadline=None)
@given(kind=st.sampled_from(KINDS), low=st.floats(0.0, 60.0), spread=st.floats(0.0, 40.0), seed=st.integers(0, 99))
def test_any_temperature_series_gives_the_slope_or_a_reason(kind, low, spread, seed):
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 0.005
    qd = 1.5 * np.sin(2 * np.pi * 0.4 * t) + 0.3 * np.sin(2 * np.pi * 1.3 * t)
    T = _temperature(kind, low, spread, rng)
    if T is not None:
        try:
            T = screen_temperature(T[:, None], ["j"], "log.parquet")[0][:, 0]
        except ColumnError as exc:  # refused in one line naming the column
            assert kind == "kelvin" and "temperature.j" in str(exc) and "\n" not in str(exc)
            return
        assert kind != "kelvin"
    true_T = np.nan_to_num(T, nan=40.0) if T is not None else np.full(N, 40.0)
    F_c = 1.0 + F_CT * (true_T - 40.0)
    tau_f = -(F_c * np.sign(qd) + 0.2 * qd) + 0.01 * rng.standard_normal(N)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = fit_terms(VELOCITY, qd, tau_f, np.ones(N, dtype=bool), TermSignals(temperature=T),
                        TermOptions(terms=("temperature",), reference_temperature=40.0, temperature_law="linear"))
    json.dumps(fit.to_dict(), allow_nan=False)  # no NaN, no Infinity in the parameters JSON
    assert fit.reasons.get("temperature"), fit.reasons
    if kind == "not logged":
        assert fit.reasons["temperature"].startswith("not tried")
    elif "temperature" in fit.kept:
        assert fit.coefficients["F_cT"] == pytest.approx(F_CT, abs=max(4 * fit.stderr["F_cT"], 1e-3))
    elif np.nanstd(T) > 3.0:  # a slope of 0.01 N·m/°C over more than 3 °C stands well above 0.01 N·m of noise
        pytest.fail(f"the temperature term was not kept over {np.nanstd(T):.1f} °C: {fit.reasons}")

"""Temperatures the change-point test cannot use (issue 53): two values (two seasons, a lab moved), values that follow
the wear, some logs without one, units or references no joint has. The trends are found with the temperature left out
and the reason said, never a singular matrix, a NaN or a drift that is not there."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from helpers import said
from wbfriction.exceptions import OptionError
from wbfriction.fleet.change_point import confounded_onset, detect_change
from wbfriction.fleet.trends import TrendOptions

T0 = datetime(2026, 1, 1, tzinfo=UTC)
N = 20
DAYS = [T0 + timedelta(days=i) for i in range(N)]
SE = np.full(N, 0.02)
OPTIONS = TrendOptions(replicates=2000, quantities=("F_c",))
NOISE = np.random.default_rng(7).standard_normal(N)


def _series(step: float = 0.0, at: int = 10, drift: float = 0.0) -> np.ndarray:
    """F_c of a joint: 1 N·m, a step of ``step`` at log ``at`` and a drift of ``drift`` per log from it, and the
    standard errors' noise (fixed)."""
    i = np.arange(N)
    return 1.0 + step * (i >= at) + drift * np.maximum(i - at + 1, 0) + SE * NOISE


def test_two_temperatures_that_step_with_a_worn_joint_leave_the_temperature_out_and_find_the_step():
    """Reproduced: ``LinAlgError: Singular matrix`` where the temperature steps at the onset (10 °C before, 30 °C
    from log 10 on). The step of the wear is found at its log, the temperature left out and the reason given."""
    T = np.where(np.arange(N) >= 10, 30.0, 10.0)
    cp = detect_change(DAYS, _series(step=0.3), SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None and cp.p_value < OPTIONS.alpha
    assert cp.onset == 10 and cp.change == pytest.approx(0.3, abs=4 * cp.change_se)
    assert cp.reference_temperature is None and np.isnan(cp.temperature_slope)
    assert "cannot be told from a change" in cp.temperature_note and "2026-01-" in cp.temperature_note


def test_temperatures_that_follow_the_wear_are_left_out_of_a_drift():
    """Reproduced: temperatures constant, then rising 2 °C per day as the joint wears from log 8 (a worn gear runs
    warm): the hinge from that log is the temperature's column (``LinAlgError`` before)."""
    T = 20.0 + 2.0 * np.maximum(np.arange(N) - 7, 0)
    cp = detect_change(DAYS, _series(drift=-0.02, at=8), SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None and np.isfinite([cp.baseline, cp.change, cp.change_se, cp.statistic]).all()
    assert "cannot be told" in cp.temperature_note and cp.reference_temperature is None


def test_temperatures_that_spread_apart_from_the_change_enter_the_test():
    """Temperatures that vary from log to log (not with the change): they enter, no note."""
    T = 25.0 + 10.0 * np.sin(np.arange(N))
    cp = detect_change(DAYS, _series(step=0.3), SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None and cp.temperature_note == "" and cp.reference_temperature == pytest.approx(np.median(T))
    assert confounded_onset(np.arange(N, dtype=float), SE, (T - 25.0)[:, None], OPTIONS) is None


def test_some_logs_without_a_temperature_is_said():
    """Reproduced: a series whose temperatures are in 5 logs of 20 lost the covariate without a word."""
    T = np.where(np.arange(N) < 5, 30.0 + np.arange(N), np.nan)
    cp = detect_change(DAYS, _series(), SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None and cp.reference_temperature is None
    assert cp.temperature_note.startswith("temperature left out: 15 of its 20 logs have none")


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -300.0, 1e6])
def test_a_reference_temperature_no_joint_has_is_refused(value):
    with pytest.raises(OptionError, match="--reference-temperature"):
        TrendOptions(reference_temperature=value)


def test_a_reference_temperature_without_the_temperature_is_refused():
    with pytest.raises(OptionError, match="--no-temperature"):
        TrendOptions(temperature=False, reference_temperature=40.0)


KINDS = ("constant", "two values", "linear", "partial", "random", "kelvin-like jump")


@given(kind=st.sampled_from(KINDS), at=st.integers(3, N - 3), low=st.floats(-20.0, 80.0),
       spread=st.floats(0.0, 40.0), wear=st.booleans())
def test_any_temperature_series_gives_trends_or_a_reason(kind, at, low, spread, wear):
    """Over random temperature series through the change-point test: a finite result, the temperature used or its
    note given, and no drift flagged on a constant joint (the values' noise is fixed: its p-value is calibrated)."""
    i = np.arange(N)
    T = {"constant": np.full(N, low), "two values": np.where(i >= at, low + spread, low),
         "linear": low + spread * i / N, "partial": np.where(i < at, low + spread * np.cos(i), np.nan),
         "random": low + spread * np.random.default_rng(at).random(N),
         "kelvin-like jump": np.where(i >= at, low + 273.15, low)}[kind]
    y = _series(step=0.3 if wear else 0.0, at=at)
    cp = detect_change(DAYS, y, SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None
    assert np.isfinite([cp.baseline, cp.change, cp.change_se, cp.statistic, cp.p_value]).all()
    used = cp.reference_temperature is not None
    assert used != bool(cp.temperature_note) or (not used and np.nanstd(T) < 1.0 and kind != "partial")
    if not wear:
        assert cp.p_value > OPTIONS.alpha / 10 or abs(cp.change) < 4 * SE[0]


def _trends(*args: str, cwd):
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "wbfriction", "trends", *args], cwd=cwd, capture_output=True,
                          text=True)


def test_trends_of_a_robot_moved_to_a_warmer_lab_as_it_wore(tmp_path, synthetic_results):
    """Reproduced through the command (exit 1, ``LinAlgError``): 12 logs, the robot at 15 °C for 6 and at 35 °C from
    the day its joint j0 lost 30 % of its friction. The drift is found, the temperature's absence said."""
    synthetic_results(tmp_path / "results", 12, F_c=lambda i: 1.0 if i < 6 else 0.7,
                      temperature=lambda i: 15.0 if i < 6 else 35.0)
    res = _trends("results", "-o", "t.html", "--table", "t.parquet", cwd=tmp_path)
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    assert "drift: r1 j0: " in res.stderr and "-30.0 %" in res.stderr
    note = [line for line in " ".join(res.stderr.split("\n")).split("note:")[1:] if "temperature left out" in line]
    assert note and "cannot be told from a change at 2026-01-07" in " ".join(note[0].split())
    import pyarrow.parquet as pq

    table = pq.read_table(tmp_path / "t.parquet")
    assert all("cannot be told" in n for n in table.column("temperature_note").to_pylist())


@pytest.mark.parametrize("value", ["nan", "inf", "-300", "1e6"])
def test_trends_refuse_a_reference_temperature_no_joint_has(tmp_path, synthetic_results, value):
    """Reproduced: ``--reference-temperature nan`` gave "7 of 14 joints drifted" with changes of NaN."""
    synthetic_results(tmp_path / "results", 10, temperature=lambda i: 20.0 + 3 * (i % 4))
    res = _trends("results", "-o", "t.html", f"--reference-temperature={value}", cwd=tmp_path)
    assert res.returncode == 2 and "--reference-temperature" in res.stderr, res.stderr
    assert len(said(res.stderr)) == 1 and not (tmp_path / "t.html").exists()


def test_a_fleet_that_turned_to_kelvin_is_said():
    """Reproduced: °C for 10 logs, then K: "reference 176.075 °C". Results written before the logs were screened
    still hold such values: the temperature is left out and the first implausible log named."""
    T = np.where(np.arange(N) < 10, 25.0, 298.15)
    cp = detect_change(DAYS, _series(), SE, "F_c", OPTIONS, temperature=T)
    assert cp is not None and cp.reference_temperature is None
    assert "298.15 °C of the log at 2026-01-11" in cp.temperature_note and "kelvin" in cp.temperature_note

"""The change detector (issue 25): analytic hinges, false alarms on constant series, drifts found with their
onset, invariance to a common scale of the standard errors; end to end on a simulated arm fleet."""

from __future__ import annotations

import dataclasses
from datetime import UTC, datetime, timedelta

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fleet.batch import run_batch
from wbfriction.fleet.manifest import read_manifest
from wbfriction.fleet.results import read_results
from wbfriction.fleet.trends import TrendOptions, detect_change, fleet_trends
from wbfriction.logs.tables import write_table
from wbfriction.model.loading import load_robot
from wbfriction.report.trends import write_trends_html
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

DAYS = [datetime(2026, 1, 1, tzinfo=UTC) + timedelta(days=i) for i in range(25)]
FAST = TrendOptions(replicates=10_000)


def ramp(n: int, last: int, change: float) -> np.ndarray:
    """A drift over the last ``last`` of ``n`` logs, reaching ``change`` at the last (issue 25's shape)."""
    k = np.arange(n) - (n - last) + 1
    return change * np.clip(k, 0, None) / last


def test_an_exact_hinge_is_found_exactly():
    y = 2.0 + ramp(25, 10, 0.6)
    cp = detect_change(DAYS, y + 1e-9 * np.sin(np.arange(25)), np.full(25, 0.01), "F_c", FAST)
    assert cp is not None and cp.onset == 15 and cp.onset_time == DAYS[15]
    assert cp.baseline == pytest.approx(2.0, abs=1e-6) and cp.change == pytest.approx(0.6, rel=1e-6)
    assert cp.relative == pytest.approx(0.3, rel=1e-6) and cp.p_value < 1e-3


def test_constant_series_raise_few_false_alarms():
    """200 constant series, scatter 1.5x the stated standard errors (which vary 4x between logs): at most 2
    p-values below 1e-3 (expected 0.2; 3 or more has probability about 1e-3)."""
    rng = np.random.default_rng(7)
    alarms = 0
    for _ in range(200):
        se = 0.05 * rng.uniform(0.5, 2.0, 25)
        cp = detect_change(DAYS, 1.0 + 1.5 * se * rng.standard_normal(25), se, "F_v", FAST)
        alarms += cp is not None and cp.p_value < 1e-3
    assert alarms <= 2


@pytest.mark.parametrize("change, last", [(0.30, 10), (0.50, 8)])
def test_issue_drifts_are_found_within_three_logs(change, last):
    rng = np.random.default_rng(3)
    for _ in range(20):
        se = np.full(25, 0.025)
        cp = detect_change(DAYS, 1.0 + ramp(25, last, change) + se * rng.standard_normal(25), se, "F_c", FAST)
        assert cp is not None and cp.p_value < 1e-3 / 6
        assert abs(cp.onset - (25 - last)) <= 3
        assert cp.relative == pytest.approx(change, abs=4 * cp.change_se)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), factor=st.floats(0.1, 10.0))
def test_a_common_scale_of_the_standard_errors_changes_nothing(seed, factor):
    rng = np.random.default_rng(seed)
    se = 0.05 * rng.uniform(0.5, 2.0, 25)
    y = 1.0 + ramp(25, 8, 0.2) + se * rng.standard_normal(25)
    a, b = (detect_change(DAYS, y, s, "F_v", FAST) for s in (se, factor * se))
    assert a is not None and b is not None
    assert (a.onset, a.p_value) == (b.onset, b.p_value)
    assert a.statistic == pytest.approx(b.statistic, rel=1e-9)


def test_points_without_value_or_error_are_left_out():
    se = np.full(25, 0.02)
    y = 1.0 + ramp(25, 10, 0.3) + se * np.random.default_rng(1).standard_normal(25)
    y[3], se[7], se[9] = np.nan, np.inf, 0.0
    cp = detect_change(DAYS, y, se, "F_c", FAST)
    assert cp is not None and cp.p_value < 1e-3
    assert detect_change(DAYS[:5], y[:5], se[:5], "F_c", FAST) is None  # too few points


@pytest.mark.slow
def test_an_arm_fleet_flags_the_joint_that_drifted(tmp_path):
    """Two simulated Panda arms, 12 logs each: the fourth joint of arm-1 gets F_c +40 % over its last 5 logs.
    The trends flag that joint alone (of 14), with the onset within 2 logs; the page is the same bytes twice."""
    robot = load_robot("panda")
    base = default_arm_friction(robot)
    lines = ["log,robot_id,start_time,robot"]
    for r in range(2):
        for i in range(12):
            friction = dict(base)
            if r == 1:
                p = base["panda_joint4"]
                friction["panda_joint4"] = dataclasses.replace(p, F_c=p.F_c * (1 + ramp(12, 5, 0.4)[i]))
            sim = simulate_arm(robot, friction, options=ArmOptions(duration=3.0, seed=100 * r + i, torque_std=0.01))
            write_table(sim.table, tmp_path / f"{r}_{i}.parquet")
            lines.append(f"{r}_{i}.parquet,arm-{r},{DAYS[i].isoformat()},panda")
    (tmp_path / "m.csv").write_text("\n".join(lines) + "\n")
    run_batch(read_manifest(tmp_path / "m.csv"), tmp_path / "results", engine="serial")
    trends = fleet_trends(read_results(tmp_path / "results"))
    assert [(j.robot_id, j.joint) for j in trends.flagged] == [("arm-1", "panda_joint4")]
    assert abs(trends.flagged[0].drifts[0].onset - 7) <= 2
    write_trends_html(trends, tmp_path / "a.html")
    write_trends_html(fleet_trends(read_results(tmp_path / "results")), tmp_path / "b.html")
    page = (tmp_path / "a.html").read_text()
    assert (tmp_path / "a.html").read_bytes() == (tmp_path / "b.html").read_bytes()
    assert page.index("arm-1") < page.index("panda_joint4") and "<script" not in page

"""The change detector (issue 25): analytic hinges, false alarms on constant series, drifts found with their
onset, invariance to a common scale of the standard errors; the trends of a results table and their page (end to
end on simulated arms: tests/test_examples.py, fleet_trends.py)."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.fleet.change_point import detect_change
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.fleet.trends import TrendOptions, fleet_trends
from wbfriction.report.trends import write_trends_html

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


def synthetic_results(drift: float) -> pa.Table:
    """A results table of 2 robots x 2 joints x 25 logs, constant but for robot r1's j1, whose F_c and friction at
    0.3 rad/s grow by ``drift`` over the last 10 logs."""
    rng = np.random.default_rng(11)
    rows: dict[str, list] = {n: [] for n in RESULT_SCHEMA.names}
    for robot_id in ("r0", "r1"):
        for joint in ("j0", "j1"):
            grow = 1.0 + (ramp(25, 10, drift) if (robot_id, joint) == ("r1", "j1") else np.zeros(25))
            for i, t in enumerate(DAYS):
                values = {"F_c": 1.0 * grow[i], "F_v": 0.2, "tau_os": 0.1, "f_at_0.1": 1.02 * grow[i],
                          "f_at_0.3": 1.06 * grow[i], "f_at_1": float("nan")}
                row = {n: float("nan") for n in RESULT_SCHEMA.names}
                row.update(robot_id=robot_id, log=f"{robot_id}/{i}", start_time=t, key=f"{robot_id}{i}",
                           log_sha256="", robot_sha256="", options_sha256="", joint=joint, model="thesis",
                           route="acceleration",
                           status="ok", n_samples=1000, version="test")
                for q, v in values.items():
                    row[q] = v + 0.02 * v * rng.standard_normal()
                    row[q + "_se"] = 0.02 * v
                for n in RESULT_SCHEMA.names:
                    rows[n].append(row[n])
    return pa.Table.from_pydict(rows, schema=RESULT_SCHEMA)


def test_fleet_trends_flag_the_drifted_joint_first_and_the_page_is_reproducible(tmp_path):
    trends = fleet_trends(synthetic_results(0.3), FAST)
    assert [(j.robot_id, j.joint) for j in trends.flagged] == [("r1", "j1")]
    assert (trends.joints[0].robot_id, trends.joints[0].joint) == ("r1", "j1")  # flagged first
    assert abs(trends.flagged[0].drifts[0].onset - 15) <= 3
    table = trends.to_table()
    assert table.num_rows == 4 * 5  # 4 joints x 5 quantities with points (f_at_1 has none)
    write_trends_html(trends, tmp_path / "a.html")
    write_trends_html(fleet_trends(synthetic_results(0.3), FAST), tmp_path / "b.html")
    assert (tmp_path / "a.html").read_bytes() == (tmp_path / "b.html").read_bytes()
    page = (tmp_path / "a.html").read_text()
    assert "<script" not in page and page.index("r1 j1") < page.index('id="r0"')
    assert fleet_trends(synthetic_results(0.0), FAST).flagged == []


def test_a_table_that_is_not_results_is_refused():
    with pytest.raises(InputError, match="not a fleet's results: no column"):
        fleet_trends(pa.table({"robot_id": ["a"]}))


def _series_table(values: dict[str, np.ndarray], se: float = 0.02, times: list[datetime] | None = None
                  ) -> pa.Table:
    """One robot's joint over ``len(values[q])`` logs: the quantities given (standard error ``se``),
    the others absent (NaN)."""
    n = len(next(iter(values.values())))
    times = times or DAYS[:n]
    rows: dict[str, list] = {name: [] for name in RESULT_SCHEMA.names}
    for i in range(n):
        row = {name: float("nan") for name in RESULT_SCHEMA.names}
        row.update(robot_id="r", log=f"log{i}", start_time=times[i], key=f"k{i}", log_sha256=f"h{i}",
                   robot_sha256="", options_sha256="", joint="j", model="thesis", route="acceleration", status="ok",
                   n_samples=1000, version="test")
        for q, v in values.items():
            row[q], row[q + "_se"] = float(v[i]), se
        for name in RESULT_SCHEMA.names:
            rows[name].append(row[name])
    return pa.Table.from_pydict(rows, schema=RESULT_SCHEMA)


def test_a_joint_is_flagged_against_alpha_over_its_quantities():
    """Bonferroni (issue 37: flagging at p < alpha passed every test): a drift of one quantity among m with
    alpha / m <= p < alpha is not flagged; the same drift is with alpha m times larger."""
    options = TrendOptions(replicates=10_000, min_change=0.0)
    rng = np.random.default_rng(5)
    quiet = {q: 1.0 + 0.02 * rng.standard_normal(25) for q in ("F_v", "tau_os", "f_at_0.1", "f_at_0.3")}
    m = 1 + len(quiet)
    noise = 0.02 * rng.standard_normal(25)
    lo, hi = 0.0, 0.2  # drift sizes: p >= alpha at lo, p < alpha / m at hi; bisected into the band between
    for _ in range(40):
        change = 0.5 * (lo + hi)
        y = 1.0 + ramp(25, 10, change) + noise
        cp = detect_change(DAYS, y, np.full(25, 0.02), "F_c", options)
        assert cp is not None
        if cp.p_value >= 1e-3:
            lo = change
        elif cp.p_value < 1e-3 / m:
            hi = change
        else:
            break
    else:
        pytest.fail("no series with a p-value between alpha / m and alpha")
    table = _series_table({"F_c": y, **quiet})
    (joint,) = fleet_trends(table, options).joints
    assert len(joint.tests) == m and joint.tests["F_c"].p_value == cp.p_value
    assert not joint.flagged
    assert fleet_trends(table, TrendOptions(alpha=1e-3 * m, replicates=10_000, min_change=0.0)).joints[0].flagged


def test_logs_at_one_start_time_are_no_hinge():
    """Issue 37: four or more logs of a series with one start time raised LinAlgError."""
    one = [DAYS[0]] * 10
    rng = np.random.default_rng(2)
    assert detect_change(one, 1.0 + 0.01 * rng.standard_normal(10), np.full(10, 0.01), "F_c", FAST) is None
    times = DAYS[:8] + [DAYS[8]] * 6  # the last six at one time: onsets within them have no hinge
    y = np.r_[np.ones(8), np.full(6, 1.5)] + 0.01 * rng.standard_normal(14)
    cp = detect_change(times, y, np.full(14, 0.01), "F_c", FAST)
    assert cp is not None and cp.onset == 8 and cp.p_value < 1e-3
    trends = fleet_trends(_series_table({"F_c": 1.0 + 0.01 * rng.standard_normal(10)}, times=one), FAST)
    assert trends.tested == [] and "none of the 1 robot joints could be tested" in trends.summary()


def test_a_change_from_a_baseline_of_zero_has_no_relative_size():
    """Issue 37: a relative change was printed as +2437644803610612224.0 % when F_c was about 0."""
    rng = np.random.default_rng(4)
    y = 1e-19 * rng.standard_normal(25) + ramp(25, 10, 0.5) + 0.01 * rng.standard_normal(25)
    cp = detect_change(DAYS, y, np.full(25, 0.01), "F_c", FAST)
    assert cp is not None and np.isnan(cp.relative) and cp.change == pytest.approx(0.5, abs=5 * cp.change_se)
    (joint,) = fleet_trends(_series_table({"F_c": y}, se=0.01), FAST).joints
    assert joint.flagged  # significant, from zero: a drift whatever its relative size
    constant = 2.0 + 0.01 * rng.standard_normal(25)
    assert detect_change(DAYS, constant, np.full(25, 0.01), "F_c", FAST).relative == pytest.approx(0.0, abs=0.02)


def test_a_small_alpha_draws_enough_noise_series():
    """Issue 37: --alpha below about 3e-4 was refused for 'replicates' with no option to set them."""
    assert TrendOptions().draws() == 20_000
    small = TrendOptions(alpha=1e-5)
    assert small.draws() >= 3 * 6 / 1e-5
    with pytest.raises(InputError, match="--replicates 50000 cannot resolve --alpha 1e-05 over 6 quantities: give "
                                         "at least 600000"):
        TrendOptions(alpha=1e-5, replicates=50_000)
    y = 1.0 + ramp(25, 10, 0.3) + 0.01 * np.random.default_rng(1).standard_normal(25)
    cp = detect_change(DAYS, y, np.full(25, 0.01), "F_c", small)
    assert cp is not None and cp.p_value < 1e-5 / 6  # resolved below alpha / m


def test_the_summary_counts_tested_joints():
    trends = fleet_trends(synthetic_results(0.3), FAST)
    assert trends.summary() == "1 of 4 tested robot joints drifted"


def test_the_summary_says_what_an_untested_joint_lacks():
    """Issue 53, class 12: ten logs at one start time were said to be 'fewer than 8 usable logs'. What is short is
    start times: the summary says how many usable logs and at how many start times; a joint with too few logs is
    said to have too few."""
    rng = np.random.default_rng(3)
    one = [DAYS[0]] * 10
    trends = fleet_trends(_series_table({"F_c": 1.0 + 0.01 * rng.standard_normal(10)}, times=one), FAST)
    assert trends.summary() == ("none of the 1 robot joints could be tested (each has its 10 usable logs at 1 start "
                                "time: a change over time needs logs at several): no drift can be told")
    few = _series_table({"F_c": 1.0 + 0.01 * rng.standard_normal(5)})
    assert fleet_trends(few, FAST).summary() == ("none of the 1 robot joints could be tested (each has fewer than 8 "
                                                 "usable logs): no drift can be told")
    tested = _series_table({"F_c": 1.0 + 0.01 * rng.standard_normal(10)})
    mixed = pa.concat_tables([tested, _renamed(few, "k"), _renamed(_series_table(
        {"F_c": 1.0 + 0.01 * rng.standard_normal(10)}, times=one), "l")])
    assert fleet_trends(mixed, FAST).summary() == ("0 of 1 tested robot joints drifted (2 not tested: 1 with fewer "
                                                   "than 8 usable logs, 1 with its 10 usable logs at 1 start time)")


def _renamed(table: pa.Table, joint: str) -> pa.Table:
    return table.set_column(table.schema.get_field_index("joint"), "joint", pa.array([joint] * table.num_rows))


def test_a_trends_page_of_joints_no_font_draws_warns_nothing(tmp_path):
    """Issue 53, class 15: a CJK joint name put matplotlib's missing-glyph warnings on standard error."""
    import warnings

    rng = np.random.default_rng(6)
    table = _renamed(_series_table({"F_c": 1.0 + 0.01 * rng.standard_normal(10)}), "左膝关节")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_trends_html(fleet_trends(table, FAST), tmp_path / "t.html")
    assert "左膝关节" in (tmp_path / "t.html").read_text()  # the page's text names it

"""The change detector's numbers against independent computations (issue 37, mutation testing of
``fleet/trends.py``; the test itself now in ``fleet/change_point.py``): the hinge statistics and coefficients by
``numpy.linalg.lstsq`` onset by onset, the change's standard error from the weighted least-squares covariance
written out, the Monte Carlo p-value recounted from the documented draws; the decisions (what is a point, what
is flagged, in which order) against their rules."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.fleet.change_point import detect_change, hinge_scan, null_p_value
from wbfriction.fleet.schema import RESULT_SCHEMA
from wbfriction.fleet.trends import QUANTITIES, TrendOptions, fleet_trends, joint_trend

T0 = datetime(2026, 1, 1, tzinfo=UTC)
ONE = TrendOptions(alpha=0.05, quantities=("F_c",), replicates=2000, shapes=("hinge",))
"""One quantity, the hinge alone, few noise series: fast, and the p-value still resolves alpha."""


def reference_scan(t: np.ndarray, y: np.ndarray, se: np.ndarray, min_before: int, min_after: int
                   ) -> dict[int, tuple[float, np.ndarray, np.ndarray]]:
    """Per candidate onset ``k`` (``min_before`` points before it, ``min_after`` from it on, a hinge that is not
    zero at every point): ``F_k``, the weighted least-squares coefficients of ``[1, max(0, t - t_{k-1})]`` and
    the design's weighted matrix, each fit by ``numpy.linalg.lstsq``."""
    n = t.size
    w = 1.0 / se
    b = y * w
    mean = np.linalg.lstsq(w[:, None], b, rcond=None)[0]
    rss0 = float(np.sum((b - w * mean[0]) ** 2))
    out = {}
    for k in range(min_before, n - min_after + 1):
        x = np.maximum(0.0, t - t[k - 1])
        if not np.any(x > 0):
            continue
        A = np.column_stack([w, x * w])
        coef = np.linalg.lstsq(A, b, rcond=None)[0]
        rss = float(np.sum((b - A @ coef) ** 2))
        out[k] = ((rss0 - rss) / (rss / (n - 2)), coef, A)
    return out


def days(t: np.ndarray) -> list[datetime]:
    return [T0 + timedelta(days=float(d)) for d in t]


@st.composite
def series(draw, n_min: int = 8, n_max: int = 16):
    """Times [days] (increasing, ties allowed), values, standard errors from 1e-3 to 10 times the scatter."""
    n = draw(st.integers(n_min, n_max))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    steps = rng.choice([0.0, 0.5, 1.0, 3.0], size=n - 1, p=[0.15, 0.25, 0.4, 0.2])
    t = np.r_[0.0, np.cumsum(steps)]
    scatter = 0.05
    y = 1.0 + draw(st.floats(-1.0, 1.0)) * np.maximum(0.0, t - t[n // 2]) / max(t[-1], 1.0) \
        + scatter * rng.standard_normal(n)
    se = scatter * draw(st.sampled_from([1e-3, 0.5, 1.0, 10.0])) * rng.uniform(0.5, 2.0, n)
    return t, y, se


@settings(max_examples=60, deadline=None)
@given(data=series(), min_before=st.integers(1, 3), min_after=st.integers(1, 3))
def test_the_hinge_statistics_are_least_squares_onset_by_onset(data, min_before, min_after):
    """F_k = (RSS_0 - RSS_k) / (RSS_k / (n - 2)) and the coefficients of every candidate onset, one and several
    columns at once; the onsets those with enough points on both sides and a hinge that is not zero."""
    t, y, se = data
    ref = reference_scan(t, y, se, min_before, min_after)
    onsets, F, coef = hinge_scan(t, y, se, min_before, min_after)
    assert onsets.tolist() == list(ref)
    for c, k in enumerate(onsets):
        assert F[c] == pytest.approx(ref[k][0], rel=1e-6, abs=1e-9 * t.size)  # F's rounding: eps (F + n)
        np.testing.assert_allclose(coef[c], ref[k][1], rtol=1e-7, atol=1e-9)
    Y = np.column_stack([y, 2.0 - y, y[::-1]])
    _, F2, coef2 = hinge_scan(t, Y, se, min_before, min_after)
    for j in range(3):
        _, Fj, cj = hinge_scan(t, Y[:, j], se, min_before, min_after)
        np.testing.assert_allclose(F2[:, j], Fj, rtol=1e-9, atol=1e-9 * t.size)
        np.testing.assert_allclose(coef2[:, :, j], cj, rtol=1e-9, atol=1e-12)


def reference_change(t: np.ndarray, y: np.ndarray, se: np.ndarray, min_before: int = 3, min_after: int = 3) -> dict:
    """The best hinge of a series, written out: the onset of the largest F_k, its baseline, the change at the last
    point (slope times the time since the last log before the onset) and its standard error from
    ``phi (A^T A)^-1`` with ``phi`` the weighted residual sum of squares over ``n - 2``."""
    ref = reference_scan(t, y, se, min_before, min_after)
    k = max(ref, key=lambda j: ref[j][0])
    F, coef, A = ref[k]
    resid = y / se - A @ coef
    phi = float(resid @ resid) / (t.size - 2)
    cov = phi * np.linalg.inv(A.T @ A)
    span = t[-1] - t[k - 1]
    return {"onset": k, "statistic": F, "baseline": coef[0], "change": coef[1] * span,
            "change_se": np.sqrt(cov[1, 1]) * span, "baseline_se": np.sqrt(cov[0, 0])}


@settings(max_examples=40, deadline=None)
@given(data=series(12, 20), gap=st.integers(0, 3))
def test_the_best_hinge_its_change_and_standard_error(data, gap):
    """detect_change against the written-out hinge (points without a value left out first)."""
    t, y, se = data
    y = y.copy()
    y[gap] = np.nan  # a point with no value: its time is no point either
    keep = np.isfinite(y)
    cp = detect_change(days(t), y, se, "F_c", ONE)
    ref = reference_change(t[keep] - t[keep][0], y[keep], se[keep])
    idx = np.flatnonzero(keep)
    assert cp is not None
    assert cp.onset == idx[ref["onset"]] and cp.onset_time == days(t)[idx[ref["onset"]]]
    assert cp.statistic == pytest.approx(ref["statistic"], rel=1e-6, abs=1e-9)
    for name in ("baseline", "change", "change_se"):
        assert getattr(cp, name) == pytest.approx(ref[name], rel=1e-6, abs=1e-9), name
    told = abs(ref["baseline"]) > 2 * ref["baseline_se"]
    if told:
        assert cp.relative == pytest.approx(ref["change"] / abs(ref["baseline"]), rel=1e-6, abs=1e-12)
    else:
        assert np.isnan(cp.relative)


def test_three_points_one_degree_of_freedom():
    """The residual scale phi is the weighted RSS over n - 2, down to n = 3 (one onset either side)."""
    t = np.array([0.0, 1.0, 2.0])
    y = np.array([1.0, 1.02, 1.5])
    se = np.full(3, 0.01)
    options = TrendOptions(alpha=0.05, quantities=("F_c",), replicates=2000, min_points=3, min_before=1,
                           min_after=1)
    cp = detect_change(days(t), y, se, "F_c", options)
    ref = reference_change(t, y, se, 1, 1)
    assert cp is not None and cp.onset == ref["onset"]
    assert cp.change_se == pytest.approx(ref["change_se"], rel=1e-6)


@pytest.mark.parametrize("sigmas, told", [(2.5, True), (1.5, False), (-2.5, True), (-1.5, False)])
def test_a_relative_change_needs_a_baseline_two_standard_errors_from_zero(sigmas, told):
    """Adding a constant to a series moves its fitted baseline and nothing else (the residuals, the onset, the
    covariance): the baseline put at 2.5 and 1.5 of its standard errors from zero."""
    rng = np.random.default_rng(3)
    t = np.arange(20.0)
    se = np.full(20, 0.05)
    y = np.maximum(0.0, t - 11) * 0.05 + 0.05 * rng.standard_normal(20)
    ref = reference_change(t, y, se)
    shift = sigmas * ref["baseline_se"] - ref["baseline"]
    cp = detect_change(days(t), y + shift, se, "F_c", ONE)
    assert cp is not None and cp.baseline == pytest.approx(sigmas * ref["baseline_se"], rel=1e-6)
    if told:
        assert cp.relative == pytest.approx(ref["change"] / abs(cp.baseline), rel=1e-6)
    else:
        assert np.isnan(cp.relative)


def test_a_relative_change_against_a_scale_given():
    rng = np.random.default_rng(8)
    t = np.arange(16.0)
    se = np.full(16, 0.05)
    y = np.maximum(0.0, t - 9) * 0.1 + 0.05 * rng.standard_normal(16)
    change = reference_change(t, y, se)["change"]
    for scale, relative in ((2.0, change / 2.0), (-4.0, change / 4.0), (0.0, np.nan), (np.nan, np.nan),
                            (np.inf, np.nan)):
        cp = detect_change(days(t), y, se, "tau_os", ONE, scale=scale)
        assert cp is not None
        np.testing.assert_allclose(cp.relative, relative, rtol=1e-9, err_msg=f"scale {scale}")


def test_too_few_points_or_no_hinge_is_no_test():
    """At least ``max(min_points, min_before + min_after)`` finite points with a positive standard error."""
    t = np.arange(10.0)
    y = 1.0 + 0.01 * np.random.default_rng(1).standard_normal(10)
    se = np.full(10, 0.01)
    options = TrendOptions(alpha=0.05, quantities=("F_c",), replicates=2000, min_points=8)
    assert detect_change(days(t[:8]), y[:8], se[:8], "F_c", options) is not None
    assert detect_change(days(t[:7]), y[:7], se[:7], "F_c", options) is None
    few = TrendOptions(alpha=0.05, quantities=("F_c",), replicates=2000, min_points=2, min_before=4, min_after=3)
    assert detect_change(days(t[:7]), y[:7], se[:7], "F_c", few) is not None
    assert detect_change(days(t[:6]), y[:6], se[:6], "F_c", few) is None
    for bad in (np.nan, np.inf, 0.0, -0.01):
        s = se[:8].copy()
        s[4] = bad
        assert detect_change(days(t[:8]), y[:8], s, "F_c", options) is None, bad


def reference_null_maxima(t: np.ndarray, se: np.ndarray, seed: int, blocks: list[int], min_before: int = 3,
                          min_after: int = 3) -> np.ndarray:
    """The largest F_k of each noise series ``se_i z_i``, drawn from ``default_rng(seed)`` as (n, size) blocks of
    the sizes given, each F_k by lstsq (all series of a block at once)."""
    rng = np.random.default_rng(seed)
    w = 1.0 / se
    n = t.size
    out = []
    for size in blocks:
        B = rng.standard_normal((n, size))  # (se z) / se
        rss0 = np.sum((B - np.outer(w, w @ B) / (w @ w)) ** 2, axis=0)
        best = np.full(size, -np.inf)
        for k in range(min_before, n - min_after + 1):
            x = np.maximum(0.0, t - t[k - 1])
            if not np.any(x > 0):
                continue
            A = np.column_stack([w, x * w])
            coef = np.linalg.lstsq(A, B, rcond=None)[0]
            rss = np.sum((B - A @ coef) ** 2, axis=0)
            best = np.maximum(best, (rss0 - rss) / (rss / (n - 2)))
        out.append(best)
    return np.concatenate(out)


P_TIMES = np.array([0.0, 1, 2, 3, 5, 6, 7, 8, 9, 12, 13, 14])
P_SE = 0.01 * np.array([1.0, 2, 1, 1, 3, 1, 1, 2, 1, 1, 1, 2])


def test_the_p_value_counts_the_first_thousand_noise_series_then_stops_at_twenty():
    """A statistic that exactly 20 of the first 1000 noise series reach: (1 + 20) / (1 + 1000), no more drawn;
    one that 19 reach: all the draws (1000, then 1000 more here), (1 + hits) / (1 + 2000)."""
    first = reference_null_maxima(P_TIMES, P_SE, seed=0, blocks=[1000])
    both = np.r_[first, reference_null_maxima(P_TIMES, P_SE, seed=0, blocks=[1000, 1000])[1000:]]
    top = np.sort(first)[::-1]
    twenty, nineteen = 0.5 * (top[19] + top[20]), 0.5 * (top[18] + top[19])  # between two series: no rounding
    assert null_p_value(P_TIMES, P_SE, float(twenty), ONE) == pytest.approx(21 / 1001, rel=1e-12)
    for statistic in (nineteen, top[0] + 1.0):
        assert null_p_value(P_TIMES, P_SE, float(statistic), ONE) == \
            pytest.approx((1 + np.sum(both >= statistic)) / 2001, rel=1e-12)
    assert null_p_value(P_TIMES, P_SE, -np.inf, ONE) == 1.0  # every series reaches it: the first pass is enough
    assert null_p_value(P_TIMES, P_SE, np.inf, ONE) == pytest.approx(1 / 2001, rel=1e-12)


def test_a_noise_series_that_equals_the_statistic_reaches_it():
    """Ties count as reaching: the statistic set to exactly the 20th largest of the first thousand noise series'
    maxima (computed from the same draws as the p-value draws them) stops at the first pass."""
    rng = np.random.default_rng(0)
    noise = P_SE[:, None] * rng.standard_normal((P_TIMES.size, 1000))
    _, F, _ = hinge_scan(P_TIMES, noise, P_SE, 3, 3)
    twentieth = float(np.sort(F.max(axis=0))[::-1][19])
    assert null_p_value(P_TIMES, P_SE, twentieth, ONE) == pytest.approx(21 / 1001, rel=1e-12)


def test_the_p_value_draws_the_rest_in_blocks_and_follows_the_seed():
    """Past the first pass the series come in blocks of at most 50 000 (here 1000, 50 000, then the 9000 left)."""
    options = TrendOptions(alpha=0.05, quantities=("F_c",), replicates=60_000, seed=5, shapes=("hinge",))
    maxima = reference_null_maxima(P_TIMES, P_SE, seed=5, blocks=[1000, 50_000, 9000])
    top = np.sort(maxima)[::-1]
    statistic = float(0.5 * (top[2] + top[3]))  # three series reach it
    assert null_p_value(P_TIMES, P_SE, statistic, options) == pytest.approx(4 / 60_001, rel=1e-12)


def test_the_number_of_noise_series():
    """Enough for the smallest p-value, 1 / (draws + 1), to fall below alpha / m (m the quantities), and by
    default three times that (at least 20 000)."""
    assert TrendOptions(alpha=1e-5).least_replicates() == 600_000
    assert TrendOptions(alpha=1e-5).draws() == 1_800_000
    assert TrendOptions(alpha=1e-3).draws() == 20_000
    assert TrendOptions(alpha=1e-4, quantities=("F_c", "F_v")).draws() == 60_000
    assert TrendOptions(alpha=1e-5, replicates=700_000, shapes=("hinge",)).draws() == 700_000
    TrendOptions(alpha=1e-5, replicates=600_000, shapes=("hinge",))  # enough
    with pytest.raises(InputError, match="--replicates 599999 cannot resolve --alpha 1e-05 over 6 quantities"):
        TrendOptions(alpha=1e-5, replicates=599_999, shapes=("hinge",))
    for alpha in (0.0, 1.0, -0.1, 1.5):
        with pytest.raises(InputError, match="--alpha must be in"):
            TrendOptions(alpha=alpha)
    with pytest.raises(InputError, match="unknown quantities"):
        TrendOptions(quantities=("F_c", "mu"))


def results_table(rows: list[dict]) -> pa.Table:
    """Result rows (:data:`RESULT_SCHEMA`) from the fields given, every other float NaN."""
    columns: dict[str, list] = {name: [] for name in RESULT_SCHEMA.names}
    for given_row in rows:
        row = {name: float("nan") for name in RESULT_SCHEMA.names}
        row.update(robot_id="r", log="l", key="k", log_sha256="", robot_sha256="", options_sha256="", joint="j",
                   model="thesis", route="acceleration", status="ok", n_samples=100, version="test")
        row.update(given_row)
        for name in RESULT_SCHEMA.names:
            columns[name].append(row[name])
    return pa.Table.from_pydict(columns, schema=RESULT_SCHEMA)


def test_the_points_of_a_series():
    """A point per log whose fit is usable (ok, weak, at bound) and whose value and standard error are finite,
    the error positive; a model parameter only from the logs of the joint's most frequent model, the friction at
    a speed from every model; in time order, logs at one time by path."""
    statuses = ["ok", "weak", "at bound", "not excited", "failed", "ok", "ok", "ok", "ok", "ok"]
    models = ["thesis"] * 6 + ["coulomb-viscous"] * 2 + ["thesis"] * 2
    se = [0.1, 0.1, 0.1, 0.1, 0.1, 0.0, 0.1, 0.1, np.inf, 0.1]
    rows = [dict(log=f"log{9 - i}", start_time=T0 + timedelta(days=i // 2), status=statuses[i], model=models[i],
                 F_c=float(i), F_c_se=se[i], **{"f_at_0.3": 10.0 + i, "f_at_0.3_se": se[i]}) for i in range(10)]
    rows[3]["F_c"] = np.nan
    order = np.random.default_rng(0).permutation(10)
    joint = joint_trend("r", "j", results_table([rows[i] for i in order]))
    # sorted by time, then path: log9/log8 share day 0 -> log8 first, and so on
    expected = [1, 0, 3, 2, 5, 4, 7, 6, 9, 8]
    assert joint.series["F_c"].time == [rows[i]["start_time"] for i in expected]
    assert [(q, s.quantity) for q, s in joint.series.items()] == [(q, q) for q in QUANTITIES]
    used_f_c = [i in (0, 1, 2, 9) for i in expected]  # 3-4 not usable, 5 se 0, 6-7 another model, 8 se inf
    used_f_at = [i in (0, 1, 2, 6, 7, 9) for i in expected]
    assert joint.series["F_c"].used.tolist() == used_f_c
    assert joint.series["f_at_0.3"].used.tolist() == used_f_at
    np.testing.assert_array_equal(joint.series["F_c"].value, [float(i) if u else np.nan
                                                             for i, u in zip(expected, used_f_c)])
    np.testing.assert_array_equal(joint.series["f_at_0.3"].se, [se[i] if u else np.nan
                                                               for i, u in zip(expected, used_f_at)])


def test_the_most_frequent_model_among_usable_fits():
    """Three usable Coulomb-viscous fits outvote two usable thesis fits, whatever five failed thesis fits say; a
    joint without a usable fit has no point."""
    models = ["coulomb-viscous"] * 3 + ["thesis"] * 7
    statuses = ["ok"] * 5 + ["failed"] * 5
    rows = [dict(log=f"{i}", start_time=T0 + timedelta(days=i), model=models[i], status=statuses[i], F_c=1.0,
                 F_c_se=0.1, **{"f_at_0.1": 1.0, "f_at_0.1_se": 0.1}) for i in range(10)]
    joint = joint_trend("r", "j", results_table(rows))
    assert joint.series["F_c"].used.tolist() == [True] * 3 + [False] * 7
    assert joint.series["f_at_0.1"].used.tolist() == [True] * 5 + [False] * 5
    joint = joint_trend("r", "j", results_table([{**r, "status": "failed"} for r in rows]))
    assert not any(s.used.any() for s in joint.series.values()) and joint.tests == {} and not joint.flagged


def test_series_times_are_utc_whatever_the_local_zone(monkeypatch):
    import time

    rows = [dict(log=f"{i}", start_time=T0 + timedelta(days=i), F_c=1.0, F_c_se=0.1) for i in range(3)]
    monkeypatch.setenv("TZ", "Asia/Kolkata")
    time.tzset()
    try:
        joint = joint_trend("r", "j", results_table(rows))
    finally:
        monkeypatch.undo()
        time.tzset()
    assert [t.utcoffset() for t in joint.series["F_c"].time] == [timedelta(0)] * 3


def drift_rows(n: int = 20, onset: int = 12, drift: float = 0.5, seed: int = 0, **extra) -> list[dict]:
    """One joint's rows: F_c 2 with a drift of ``drift`` from ``onset`` on; tau_os 0 with the same drift; F_v
    constant; 2 % errors."""
    rng = np.random.default_rng(seed)
    ramp = drift * np.maximum(0.0, np.arange(n) - onset + 1) / (n - onset)
    rows = []
    for i in range(n):
        rows.append(dict(log=f"{i:02d}", start_time=T0 + timedelta(days=i), F_c=2.0 + 0.04 * rng.standard_normal(),
                         F_c_se=0.04, tau_os=ramp[i] + 0.04 * rng.standard_normal(), tau_os_se=0.04,
                         F_v=0.5 + 0.01 * rng.standard_normal(), F_v_se=0.01, **extra))
    return rows


def test_an_offset_is_measured_against_the_coulomb_friction():
    """tau_os drifts from zero: its relative change is the change over the median of F_c's points."""
    rows = drift_rows()
    options = TrendOptions(alpha=0.05, quantities=("F_c", "F_v", "tau_os"), replicates=2000)
    joint = joint_trend("r", "j", results_table(rows), options)
    t = np.arange(20.0)
    tau = np.array([r["tau_os"] for r in rows])
    ref = reference_change(t, tau, np.full(20, 0.04))
    median = float(np.median([r["F_c"] for r in rows]))
    cp = joint.tests["tau_os"]
    assert cp.change == pytest.approx(ref["change"], rel=1e-9)
    assert cp.relative == pytest.approx(ref["change"] / median, rel=1e-9)
    assert joint.drifts[0] is cp
    # without F_c's points, against tau_os's own baseline (not told from zero here: no relative change)
    no_f_c = joint_trend("r", "j", results_table([{**r, "F_c": np.nan} for r in rows]), options)
    assert np.isnan(no_f_c.tests["tau_os"].relative) and no_f_c.flagged



def test_a_joint_is_flagged_by_its_rule():
    """Flagged: the quantities whose p-value is below alpha / m (m the quantities tested) and whose change reaches
    min_change of the baseline in size, most significant first. Random joints of one to three drifting
    quantities, alpha 0.3 so that p-values just below and just above alpha / m are met (checked)."""
    alpha = 0.3
    options = TrendOptions(alpha=alpha, quantities=("F_c", "F_v", "tau_os"), replicates=2000, min_change=0.02,
                           shapes=("hinge",))
    rng = np.random.default_rng(12)
    seen = set()
    for case in range(45):
        m = 1 + case % 3
        drift = rng.choice([-1.0, 1.0]) * rng.uniform(0.0, 0.02, size=3)
        rows = drift_rows(seed=case, drift=0.0)
        for i, r in enumerate(rows):
            grow = max(0.0, i - 11) / 8
            r.update(F_c=r["F_c"] * (1 + drift[0] * grow), F_v=r["F_v"] * (1 + drift[1] * grow) if m > 1 else np.nan,
                     tau_os=r["tau_os"] + 2 * drift[2] * grow if m > 2 else np.nan)
        joint = joint_trend("r", "j", results_table(rows), options)
        assert len(joint.tests) == m
        expected = sorted((cp for cp in joint.tests.values() if cp.p_value < alpha / m
                           and (np.isnan(cp.relative) or abs(cp.relative) >= 0.02)),
                          key=lambda cp: (cp.p_value, -cp.statistic))
        assert joint.drifts == tuple(expected)
        assert joint.onset_time == (expected[0].onset_time if expected else None)
        for cp in joint.tests.values():
            if abs(cp.relative) >= 0.02:
                seen.add((m, "just below" if alpha / (m + 1) <= cp.p_value < alpha / m else
                          "just above" if alpha / m <= cp.p_value < alpha / max(m - 1, 1 / 3) else ""))
    assert {(1, "just below"), (2, "just below"), (3, "just below"), (2, "just above"), (3, "just above")} <= seen


def test_a_significant_change_is_flagged_when_large_enough_either_way():
    """min_change 10 %: a fall of 20 % is flagged, a rise of 3 % measured to 0.1 % is significant but not."""
    options = TrendOptions(alpha=0.01, quantities=("F_c",), replicates=2000, min_change=0.10)
    rng = np.random.default_rng(6)
    for size, noise, flagged in ((-0.2, 0.01, True), (0.03, 0.001, False), (0.2, 0.01, True)):
        rows = [dict(log=f"{i:02d}", start_time=T0 + timedelta(days=i), F_c_se=2 * noise,
                     F_c=2.0 * (1 + size * max(0, i - 11) / 8) + 2 * noise * rng.standard_normal()) for i in range(20)]
        joint = joint_trend("r", "j", results_table(rows), options)
        cp = joint.tests["F_c"]
        assert cp.p_value < 0.01 and cp.relative == pytest.approx(size, abs=4 * cp.change_se / 2.0)
        assert joint.flagged == flagged and joint.drifts == ((cp,) if flagged else ())


def test_a_p_value_at_alpha_or_a_change_at_min_change():
    """Flagged: a p-value *below* alpha / m, a change *at least* min_change: a p-value equal to alpha is not, a
    change equal to min_change is (the p-value does not depend on alpha when the draws are given)."""
    rows = drift_rows(drift=0.0)
    rng = np.random.default_rng(9)
    for i, r in enumerate(rows):
        r.update(F_c=2.0 * (1 + 0.03 * max(0, i - 11) / 8) + 0.04 * rng.standard_normal(), tau_os=np.nan)
    table = results_table(rows)

    def joint(alpha, min_change):
        return joint_trend("r", "j", table, TrendOptions(alpha=alpha, quantities=("F_c",), replicates=2000,
                                                         min_change=min_change))

    cp = joint(0.5, 0.0).tests["F_c"]
    assert 0 < cp.p_value < 0.5 and abs(cp.relative) > 0
    assert not joint(cp.p_value, 0.0).flagged and joint(np.nextafter(cp.p_value, 1), 0.0).flagged
    size = abs(cp.relative)
    assert joint(0.5, size).flagged and not joint(0.5, np.nextafter(size, 1)).flagged


def test_drifts_of_equal_p_value_the_larger_statistic_first():
    """Two quantities drifting far beyond every noise series (both at the smallest p-value): the one whose F is
    larger is the joint's drift, its onset the joint's."""
    options = TrendOptions(alpha=0.05, quantities=("F_c", "F_v"), replicates=2000)
    for f_v_noise, first in ((0.004, "F_c"), (0.0002, "F_v")):
        rows = drift_rows(drift=0.0)
        rng = np.random.default_rng(1)
        for i, r in enumerate(rows):
            r.update(F_c=2.0 * (1 + 0.5 * max(0, i - 13) / 6) + 0.004 * rng.standard_normal(),
                     F_v=0.5 * (1 + 0.5 * max(0, i - 9) / 10) + f_v_noise * rng.standard_normal())
        joint = joint_trend("r", "j", results_table(rows), options)
        a, b = joint.tests["F_c"], joint.tests["F_v"]
        assert a.p_value == b.p_value == 1 / 2001
        assert (a.statistic > b.statistic) == (first == "F_c")
        assert joint.drifts[0] is joint.tests[first] and joint.onset_time == joint.tests[first].onset_time


def fleet_rows() -> list[dict]:
    """Robots b (j: F_c drifts from log 10), a (j1: drifts from log 14; j2 constant), c (j: constant)."""
    rows = []
    for robot, joint, onset in (("c", "j", None), ("a", "j2", None), ("a", "j1", 14), ("b", "j", 10)):
        for i, r in enumerate(drift_rows(seed=len(rows), drift=0.0)):
            if onset is not None:
                r["F_c"] *= 1 + 0.4 * max(0, i - onset + 1) / (20 - onset)
            r.update(robot_id=robot, joint=joint, log=f"{robot}{joint}{i:02d}", tau_os=np.nan)
            rows.append(r)
    return rows


def test_fleet_trends_order_and_table():
    """Flagged joints first, the earliest onset first; then by robot and joint. The table: a row per joint and
    tested quantity, the hinge's numbers, its points and last value, whether it is a drift."""
    options = TrendOptions(alpha=0.01, quantities=("F_c", "F_v"), replicates=2000)
    rows = fleet_rows()
    trends = fleet_trends(results_table(rows), options)
    assert [(j.robot_id, j.joint) for j in trends.joints] == [("b", "j"), ("a", "j1"), ("a", "j2"), ("c", "j")]
    assert [(j.robot_id, j.joint) for j in trends.flagged] == [("b", "j"), ("a", "j1")]
    b, a = (j.onset_time for j in trends.flagged)
    assert abs(b - (T0 + timedelta(days=10))).days <= 1 and abs(a - (T0 + timedelta(days=14))).days <= 1
    assert trends.summary() == "2 of 4 tested robot joints drifted"
    table = trends.to_table().to_pylist()
    assert len(table) == 8
    for row, (j, q) in zip(table, [(joint, q) for joint in trends.joints for q in joint.tests]):
        cp = j.tests[q]
        mine = [r for r in rows if (r["robot_id"], r["joint"]) == (j.robot_id, j.joint)]
        assert (row["robot_id"], row["joint"], row["quantity"]) == (j.robot_id, j.joint, q)
        assert row["points"] == 20 and row["last_value"] == mine[-1][q]
        assert row["flagged"] == (cp in j.drifts) == (q == "F_c" and j.robot_id in "ab" and j.joint != "j2")
        assert row["onset_time"] == cp.onset_time and row["onset_time"].tzinfo is not None
        for column, value in (("baseline", cp.baseline), ("change", cp.change), ("change_se", cp.change_se),
                              ("relative_change", cp.relative), ("p_value", cp.p_value)):
            assert row[column] == value, column
    # the rows of each joint are its own: its series from its rows alone
    b = trends.joints[0]
    assert b.series["F_c"].value.tolist() == [r["F_c"] for r in rows if r["robot_id"] == "b"]


def test_untested_joints_are_counted_apart():
    rows = fleet_rows()
    rows = [r for r in rows if not (r["robot_id"] == "c" and int(r["log"][-2:]) >= 7)]  # c: 7 logs
    options = TrendOptions(alpha=0.01, quantities=("F_c",), replicates=2000)
    trends = fleet_trends(results_table(rows), options)
    assert [(j.robot_id, j.joint) for j in trends.tested] == [("b", "j"), ("a", "j1"), ("a", "j2")]
    assert trends.summary() == "2 of 3 tested robot joints drifted (1 not tested: 1 with fewer than 8 usable logs)"
    assert trends.to_table().num_rows == 3


def test_the_table_has_its_columns_and_types_when_nothing_was_tested():
    options = TrendOptions(alpha=0.01, quantities=("F_c",), replicates=2000)
    full = fleet_trends(results_table(fleet_rows()), options).to_table()
    empty = fleet_trends(results_table(fleet_rows()[:5]), options).to_table()  # 5 logs: no test
    assert empty.num_rows == 0 and full.num_rows == 4 and empty.schema == full.schema


def test_an_offset_without_coulomb_points_is_measured_against_its_own_baseline():
    """With F_c not followed, or without a point, tau_os's relative change is over its own fitted baseline
    (here 1 N·m, told from zero)."""
    rows = drift_rows()
    for r in rows:
        r.update(tau_os=r["tau_os"] + 1.0, F_c=np.nan)
    tau = np.array([r["tau_os"] for r in rows])
    ref = reference_change(np.arange(20.0), tau, np.full(20, 0.04))
    for quantities in (("F_c", "tau_os"), ("tau_os",)):
        options = TrendOptions(alpha=0.05, quantities=quantities, replicates=2000, shapes=("hinge",))
        cp = joint_trend("r", "j", results_table(rows), options).tests["tau_os"]
        assert cp.relative == pytest.approx(ref["change"] / abs(ref["baseline"]), rel=1e-9), quantities


def test_a_table_missing_one_column_is_refused_naming_it():
    table = results_table(drift_rows())
    with pytest.raises(InputError, match="not a fleet's results: no column 'version'"):
        fleet_trends(table.drop_columns(["version"]))
    with pytest.raises(InputError, match="the results hold no log"):
        fleet_trends(table.slice(0, 0))

"""The ranges a fit's terms were fitted on, and a prediction outside them (issue 53, classes 4 and 7): a ripple is a
function of the angle modulo 2π, so a continuous joint logged on another branch predicts the same; ``predict`` says in
a plain sentence where a table leaves the fitted temperatures, loads and angles, and well outside them (beyond a range
by more than its width) the prediction is not ``ok``. The angles' range is an arc of the circle (issue 65, class 8):
a table holding them on several branches at once fits and predicts as one holding them on one."""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import run_cli_printed
from term_params import (
    COEFFICIENTS,
    JOINT,
    Q_RANGE,
    T_REF,
    edited,
    motion,
    motion_estimate,
    params_file,
    table_file,
    term_fit,
)
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.fit.predict import predict_torques
from wbfriction.fit.ranges import OUTSIDE, FittedRanges, angle_arc, ripple_angle
from wbfriction.fit.terms import TermSignals

N = 400


def _ripple(q: np.ndarray) -> np.ndarray:
    """The ripple of :data:`term_params.COEFFICIENTS` at the angles ``q``, from its definition."""
    c = COEFFICIENTS
    return sum(c[f"ripple_sin{h}"] * np.sin(h * q) + c[f"ripple_cos{h}"] * np.cos(h * q) for h in (1, 2))


@pytest.mark.parametrize("turns", [-2, -1, 1, 3])
def test_a_ripple_is_the_same_on_every_branch_of_the_angle(turns):
    """Class 4: ``predict`` held an angle logged 2π away at the edge of the fitted angles (0.09 N·m RMS on one
    branch, 0.19 on the other). Inside the fitted angles on any branch: the ripple at that angle."""
    fit = term_fit(("ripple",))
    q = np.linspace(0.6, 2.4, 50)
    shifted = q + 2 * np.pi * turns
    qd = np.ones_like(q)
    np.testing.assert_allclose(fit.ripple(qd, TermSignals(q=shifted)), _ripple(q), atol=1e-12)
    assert [fit.torque_at(1.0, float(a)) for a in shifted] == pytest.approx(list(fit.torque(qd, TermSignals(q=q))))
    np.testing.assert_allclose(ripple_angle(shifted, Q_RANGE), q, atol=1e-12)
    assert not fit.range_use(TermSignals(q=shifted), np.ones(len(q), bool)).outside


def test_outside_its_angles_on_any_branch_a_ripple_is_held_at_the_nearest():
    """Beyond the fitted angles (0.5-2.5 rad) the ripple is held at the nearest fitted angle going round the circle:
    3.0 rad (0.5 past 2.5) holds 2.5; -1.0 rad (1.5 short of 0.5, 2.78 past 2.5 the other way) holds 0.5; -2.0 rad
    (2.5 short of 0.5, but 2π - 4.5 = 1.78 past 2.5 the other way) holds 2.5; on any branch."""
    q = np.array([3.0, -1.0, -2.0])
    for turns in (0, 1, -2):
        np.testing.assert_allclose(ripple_angle(q + 2 * np.pi * turns, Q_RANGE), [2.5, 0.5, 2.5], atol=1e-12)


def test_the_fitted_ranges_are_those_of_the_rows_fitted():
    use = np.array([True, True, False, True])
    ranges = FittedRanges.of(use, np.array([0.1, -0.3, 9.0, 0.2]), np.array([-20.0, 5.0, 99.0, 1.0]),
                             np.array([30.0, 31.0, 80.0, 29.5]))
    assert ranges == FittedRanges(angle=(-0.3, 0.2), load=(1.0, 20.0), temperature=(29.5, 31.0))
    assert FittedRanges.from_dict(json.loads(json.dumps(ranges.to_dict()))) == ranges
    assert FittedRanges.of(use) == FittedRanges()  # nothing logged: no range


TWO_PI = 2 * np.pi
WRAPS = {"pi": lambda x: x - TWO_PI * np.ceil((x - np.pi) / TWO_PI), "2pi": lambda x: np.mod(x, TWO_PI)}
"""A logger's angle in (−π, π] and in [0, 2π), each from its definition."""
RIPPLE_ONLY = {**COEFFICIENTS, "F_L": 0.0}
"""The joint's friction without its load term (its temperature held at ``T_REF``): the velocity law and the ripple."""


def test_the_arc_of_angles_is_that_of_the_physical_angles():
    """A joint swept over 2.8-3.5 rad, across π: its arc is (2.8, 3.5) however the angles are written, in (−π, π], in
    [0, 2π), a turn away, or half on one branch and half on another (a log unwrapped in chunks: its min and max were
    −3.48 and 3.5, a range wider than the motion by 2π - 0.7). Angles that never wrap give their min and max."""
    q = np.linspace(2.8, 3.5, 71)
    for written in (q, WRAPS["pi"](q), WRAPS["2pi"](q), q + 3 * TWO_PI, np.where(np.arange(71) < 30, q, q - TWO_PI)):
        np.testing.assert_allclose(angle_arc(written), (2.8, 3.5), rtol=0, atol=1e-12)
    assert angle_arc(np.array([0.1, -0.3, np.nan, 0.2])) == (-0.3, 0.2)  # exactly
    assert angle_arc(np.array([-2.48, -1.41, -2.0])) == (-2.48, -1.41)
    np.testing.assert_allclose(angle_arc(np.linspace(3.2, 3.4, 5)), (3.2 - TWO_PI, 3.4 - TWO_PI), rtol=0, atol=1e-12)
    low, high = angle_arc(np.linspace(-10.0, 10.0, 2001))  # more than a turn: every angle but less than a step
    assert -np.pi < low <= np.pi and TWO_PI - 0.011 < high - low < TWO_PI
    assert angle_arc(np.array([np.nan])) is None and angle_arc(np.array([1.0])) == (1.0, 1.0)


def test_a_fit_on_angles_held_on_two_branches_is_the_fit_on_one():
    """A joint swept over 2.5-4.3 rad (its angle logged 1.9 rad from the one its ripple is written in), its table's
    angles half on one branch and half a turn lower (the (−π, π] log estimated in two chunks): the same arc,
    coefficients and prediction of a wider swing (2.2-4.6 rad, logged in (−π, π]; beyond the fitted angles the ripple
    is held at their edge) as the table on one branch. Before issue 65, class 8, the range was −3.78 to 4.3 rad, wider
    than a turn, so nothing was held: the same rows predicted to 0.0101 N·m RMS, against 0.0218 by the fit of the
    table on one branch."""
    temperature = np.full(2000, T_REF)
    q = motion(2000)[2] + 1.9
    options = FitOptions(model="coulomb-viscous", terms=TermOptions(terms=("ripple",)))
    one, two = (fit_estimate(motion_estimate(temperature, x, c=RIPPLE_ONLY), options)[0].terms
                for x in (q, np.where(np.arange(2000) < 1000, q, q - TWO_PI)))
    assert one is not None and two is not None and one.kept == two.kept == ("ripple",)
    np.testing.assert_allclose(two.q_range, one.q_range, rtol=0, atol=1e-12)
    np.testing.assert_allclose(one.q_range, (2.5, 4.3), atol=1e-3)
    for name, value in one.coefficients.items():
        assert two.coefficients[name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    wider = WRAPS["pi"](motion(2000, swing=1.2)[2] + 1.9)
    held = motion_estimate(temperature, wider, seed=1, c=RIPPLE_ONLY, swing=1.2)
    a, b = (predict_torques(held, {JOINT: fit}) for fit in (one, two))
    assert b.rms[0] == pytest.approx(a.rms[0], rel=1e-12)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ranges")
    good = params_file(folder / "params.json", term_fit())
    old = edited(good, lambda e: e["terms"].pop("ranges"), folder / "old.json")
    tables = {name: table_file(folder / f"{name}.parquet", np.linspace(lo, hi, N))
              for name, (lo, hi) in {"inside": (25.0, 55.0), "warmer": (50.0, 65.0), "hot": (100.0, 130.0)}.items()}
    tables["branch"] = table_file(folder / "branch.parquet", np.linspace(25.0, 55.0, N), q_shift=-2 * np.pi)
    return good, old, tables


def _predict(capsys, table, params):
    code, printed, err = run_cli_printed(capsys, "predict", table, "--params", params)
    assert code == 0, err
    row = next(ln for ln in printed.splitlines() if ln.strip().startswith(JOINT))
    return row, " ".join(err.split())


def test_a_table_well_outside_the_fitted_temperatures_is_not_ok_and_says_so(files, capsys):
    """Class 7: fitted on 25-55 °C, a table at 100-130 °C (75 °C beyond, more than the 30 °C width) was predicted with
    status ok and no word; now its status is 'outside fitted ranges' and a sentence gives both ranges."""
    good, _, tables = files
    row, err = _predict(capsys, tables["hot"], good)
    assert row.rstrip().endswith(OUTSIDE), row
    assert (f"{JOINT}: temperature 100 to 130 °C in this table, fitted on 25 to 55 °C: 100 % of its samples outside, "
            "up to 75 °C beyond; the temperature term extrapolated on those samples, farther than the fitted range is "
            "wide") in err, err


def test_a_table_a_little_outside_is_said_and_stays_ok(files, capsys):
    """50-65 °C against 25-55: 10 °C beyond (a third of the width), on the two thirds of the samples above 55 °C."""
    good, _, tables = files
    row, err = _predict(capsys, tables["warmer"], good)
    assert row.rstrip().endswith(" ok"), row
    # the words follow the numbers: two thirds of the samples outside, none farther than a third of the width
    assert "temperature 50 to 65 °C in this table, fitted on 25 to 55 °C: 66.5 % of its samples outside, up to 10 °C" \
           " beyond; the temperature term extrapolated on those samples, by at most 33 % of the fitted range's " \
           "width" in err, err
    assert OUTSIDE not in err


def test_inside_the_fitted_ranges_nothing_is_said_and_another_branch_predicts_the_same(files, capsys):
    """Within every range (the angles on another branch too): ok, no sentence, and the same RMS on both branches, at
    the tables' noise (0.01 N·m)."""
    from wbfriction.pipeline.predict_step import predict_file

    good, _, tables = files
    row, err = _predict(capsys, tables["inside"], good)
    assert row.rstrip().endswith(" ok") and "fitted on" not in err, err
    inside, branch = predict_file(tables["inside"], good), predict_file(tables["branch"], good)
    assert branch.rms[0] == pytest.approx(inside.rms[0], rel=1e-9) and inside.rms[0] < 0.011
    assert branch.status == ("ok",) and branch.ranges[0] is not None and not branch.ranges[0].outside


def test_a_file_without_ranges_says_they_are_not_known(files, capsys):
    """A parameters file of an earlier version: the ranges of its load and temperature terms are unknown, said so
    (the ripple's angles were always stored)."""
    _, old, tables = files
    row, err = _predict(capsys, tables["hot"], old)
    assert row.rstrip().endswith(" ok"), row
    assert (f"{JOINT}: the fitted ranges of its load, temperature terms are not recorded (a parameters file of an "
            "earlier version): whether this table is within them is not known") in err, err


def test_fit_stores_the_ranges_of_the_samples_it_fitted(tmp_path, capsys):
    """``fit --terms all`` on a joint swinging over 0.6-2.4 rad under 0-25 N·m while warming from 25 to 55 °C (the
    three terms in its friction): the three ranges stored are those, to the samples left out at the reversals."""
    table = table_file(tmp_path / "friction.parquet", np.linspace(25.0, 55.0, 2000))
    params = tmp_path / "fitted.json"
    code, _, err = run_cli_printed(capsys, "fit", table, "-o", params, "--terms", "all", "--model", "coulomb-viscous",
                                   "--reference-temperature", "40", "--workers", "1")
    assert code == 0, err
    terms = json.loads(params.read_text())["joints"][JOINT]["terms"]
    assert terms["kept"] == ["load", "ripple", "temperature"]
    for key, (lo, hi), slack in (("angle", (0.6, 2.4), 0.01), ("load", (0.0, 25.0), 0.1),
                                 ("temperature", (25.0, 55.0), 0.1)):
        got = terms["ranges"][key]
        assert lo <= got[0] <= lo + slack and hi - slack <= got[1] <= hi, (key, got)

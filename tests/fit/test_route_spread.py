"""The routes' difference in the read error (:mod:`wbfriction.fit.route_spread`), and what ``routes disagree`` then
tests: the difference against each route's own statistical errors (the Newey-West and block-jackknife ones), never
against the route spread, which is the difference itself (the check would be vacuous)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.params_file import fit_from_dict, fit_to_dict
from wbfriction.fit.result import FitResult, check_routes
from wbfriction.fit.route_spread import ROUTE_SHARE, route_spread
from wbfriction.fit.status import read_error
from wbfriction.friction.models import CoulombViscousParams


def _fit(F_c: float = 1.0, F_v: float = 0.3, se: float = 0.002, block: float = 0.0, route: str = "momentum"
         ) -> FitResult:
    return FitResult("j", 4000, params=CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=0.0),
                     stderr={"F_v": se * F_v, "F_c": se * F_c, "tau_os": 0.001}, rms_residual=0.05, success=True,
                     message="ok", at_bound={"F_v": False, "F_c": False, "tau_os": False}, speed=1.0, route=route,
                     block_spread={} if not block else {"F_v": block * F_v, "F_c": block * F_c})


def _checked(mine: FitResult, theirs: FitResult) -> FitResult:
    check_routes(mine, theirs)
    return mine


def test_the_spread_is_the_share_of_the_difference():
    assert ROUTE_SHARE == pytest.approx(1.0 / math.sqrt(2.0))
    assert route_spread({"F_c": 1.0, "F_v": 0.3}, {"F_c": 0.96, "F_v": 0.3}, ("F_c", "F_v")) == pytest.approx(
        {"F_c": 0.04 / math.sqrt(2.0), "F_v": 0.0})
    assert route_spread({"F_c": 1.0}, None, ("F_c",)) == {}
    assert route_spread({"F_c": 1.0}, {"F_c": math.nan}, ("F_c",)) == {}


def test_a_route_that_alone_is_biased_is_covered_by_two_read_errors():
    """One route unbiased, the other off by ``b``: ±2 of either's read error (the route spread alone, whatever its
    statistical error) reach the truth: 2 |b| / sqrt(2) = sqrt(2) |b| >= |b| from the biased one, and from the
    other, which is the truth."""
    truth = 1.0
    for b in (0.01, 0.05, 0.3):
        biased, clean = _fit(F_c=truth + b, route="acceleration"), _fit(F_c=truth)
        for mine, theirs in ((biased, clean), (clean, biased)):
            fit = _checked(mine, theirs)
            assert abs(fit.params.F_c - truth) <= 2.0 * fit.read_stderr()["F_c"] + 1e-12


def test_exchangeable_biases_are_covered_as_the_docstring_says():
    """Both routes biased, independently, one variance: the route spread alone puts ±2 of it about the truth with
    probability 0.76 (the normal model of the module docstring), measured over 20000 draws within 0.01."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(2, 20000))
    covered = np.abs(a) <= 2.0 * ROUTE_SHARE * np.abs(a - b)
    assert covered.mean() == pytest.approx(0.76, abs=0.01)


def test_the_read_error_carries_the_routes_difference():
    fit = _checked(_fit(F_c=1.0, se=0.002), _fit(F_c=0.95, se=0.002, route="acceleration"))
    assert fit.route_spread["F_c"] == pytest.approx(0.05 / math.sqrt(2.0))
    assert fit.read_stderr()["F_c"] == pytest.approx(math.hypot(0.002, 0.05 / math.sqrt(2.0)))
    assert read_error(0.002, 0.0, 0.004, 0.0) == 0.004  # the block spread: the larger, not a sum


def test_routes_within_what_the_blocks_show_agree():
    """5 % apart, each route's Newey-West error 0.2 %: 18 combined errors, they disagree; with a block spread of 2 %
    on each (the values wander over the log by so much), 1.8 combined errors: they agree, and the fit is ok with
    the difference in its read error."""
    tight = _checked(_fit(F_c=1.0), _fit(F_c=0.95, route="acceleration"))
    assert tight.route_check.disagree == ("F_c",) and tight.verdict().status == "routes disagree"
    wide = _checked(_fit(F_c=1.0, block=0.02), _fit(F_c=0.95, block=0.02, route="acceleration"))
    assert wide.route_check.disagree == () and wide.verdict().ok


def test_routes_far_apart_still_disagree_though_the_read_error_carries_them():
    """30 % apart with block spreads of 2 %: the read error (the route spread 21 %) would cover the difference in
    one standard error, yet the check tests the difference against the blocks' errors: 10 of them, they disagree."""
    fit = _checked(_fit(F_c=1.0, block=0.02), _fit(F_c=0.7, block=0.02, route="acceleration"))
    assert fit.read_stderr()["F_c"] > 0.3 / 2
    assert fit.route_check.disagree == ("F_c",) and fit.verdict().status == "routes disagree"


@settings(max_examples=40, deadline=None)
@given(gap=st.floats(0.0, 0.5), block=st.floats(0.0, 0.05))
def test_the_check_is_never_vacuous(gap, block):
    """Whatever the blocks' spread, routes apart by more than 3 combined statistical errors and 2 % disagree: the
    route spread never enters what the check tests."""
    fit = _checked(_fit(F_c=1.0, block=block), _fit(F_c=1.0 - gap, block=block, route="acceleration"))
    stat = math.hypot(max(0.002, block), max(0.002, block) * (1.0 - gap))
    expected = gap > 3.0 * stat and gap > 0.02
    assert ("F_c" in fit.route_check.disagree) == expected


def test_the_spreads_read_back_from_the_json_and_old_files_read_without_them():
    fit = _checked(_fit(F_c=1.0, block=0.01), _fit(F_c=0.97, block=0.01, route="acceleration"))
    d = fit_to_dict(fit)
    assert set(d["block_spread"]) == {"F_v", "F_c"} and set(d["route_spread"]) == {"F_v", "F_c"}
    assert set(d["route_check"]["block_spread"]) == {"F_v", "F_c"}
    back = fit_from_dict("j", d)
    assert back.block_spread == fit.block_spread and back.route_spread == fit.route_spread
    assert back.route_check == fit.route_check and back.read_stderr() == fit.read_stderr()
    assert back.verdict() == fit.verdict()
    for key in ("block_spread", "route_spread"):
        del d[key]
    del d["route_check"]["block_spread"]
    old = fit_from_dict("j", d)  # a file of an earlier version: its errors as they were
    assert old.block_spread == {} and old.route_spread == {} and old.read_stderr() == old.stderr

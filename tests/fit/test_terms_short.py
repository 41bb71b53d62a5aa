"""Terms on fits too short to hold them (issue 53): ``RuntimeWarning: invalid value encountered in scalar divide`` on
standard error and a reason of ``+nan %``. Every short or one-sided series gives reasons in words and no warning."""

from __future__ import annotations

import warnings

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.fit.term_selection import MIN_TERM_SAMPLES, fit_terms
from wbfriction.fit.terms import NOT_TRIED, TermSignals
from wbfriction.friction.models import CoulombViscousParams

VELOCITY = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0)


def _series(n: int, cycles: float, noise: float, seed: int):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    qd = np.sin(2 * np.pi * cycles * np.arange(n) / n)
    tau_f = -(np.sign(qd) + 0.2 * qd) + noise * rng.standard_normal(n)
    return qd, tau_f, TermSignals(q=np.cumsum(qd) * 0.01, tau_load=rng.standard_normal(n), temperature=30.0 + t)


@given(n=st.integers(2, 60), cycles=st.floats(0.2, 4.0), noise=st.sampled_from([0.0, 0.01]), seed=st.integers(0, 9))
def test_short_series_give_reasons_and_no_warning(n, cycles, noise, seed):
    qd, tau_f, signals = _series(n, cycles, noise, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = fit_terms(VELOCITY, qd, tau_f, np.ones(n, dtype=bool), signals)
    assert set(fit.reasons) == {"load", "direction", "ripple", "temperature"}
    assert not any("nan" in why for why in fit.reasons.values()), fit.reasons


def test_too_few_moving_samples_try_no_term():
    qd, tau_f, signals = _series(MIN_TERM_SAMPLES - 1, 1.0, 0.01, 0)
    fit = fit_terms(VELOCITY, qd, tau_f, np.ones(qd.size, dtype=bool), signals)
    assert fit.kept == () and all(why.startswith(NOT_TRIED) and "fewer than 20" in why
                                  for why in fit.reasons.values())


def test_one_direction_of_motion_says_so():
    qd, tau_f, signals = _series(200, 0.4, 0.01, 0)  # under half a cycle: the joint moves one way
    fit = fit_terms(VELOCITY, np.abs(qd) + 0.1, tau_f, np.ones(200, dtype=bool), signals)
    assert "too few samples moving each way to tell" in fit.reasons["ripple"]

"""Any branch of a continuous joint's angle gives the same fit and prediction (issue 65, class 8): the angles of the
fitted table written in (−π, π], in [0, 2π) or as swept, each stretch of rows (a chunk, a segment, unwrapped from its
own first row) a whole number of turns away, and the held-out table's likewise: the ripple's arc, its coefficients,
the held-out prediction and what it says of the fitted angles are those of the angles as swept, to rounding.

The joint swings over 2.5-4.3 rad (across π), its friction a two-harmonic ripple of the angle beside its velocity law
(:func:`term_params.physical_friction`); the held-out log swings wider (2.2-4.6 rad: beyond the fitted angles the
ripple is held at their edge, where the arc decides what is held).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from term_params import COEFFICIENTS, JOINT, T_REF, motion, motion_estimate
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, TermOptions
from wbfriction.fit.predict import predicted_friction
from wbfriction.fit.terms import TermFit, term_signals

N = 1000
TWO_PI = 2 * np.pi
ZERO = 1.9
"""Where the logged angle's zero sits from the one the ripple is written in [rad]: the sweep crosses π."""
RIPPLE_ONLY = {**COEFFICIENTS, "F_L": 0.0}
OPTIONS = FitOptions(model="coulomb-viscous", terms=TermOptions(terms=("ripple",), max_harmonic=2))
WRAPS = {"as swept": lambda x: x, "(-pi, pi]": lambda x: x - TWO_PI * np.ceil((x - np.pi) / TWO_PI),
         "[0, 2pi)": lambda x: np.mod(x, TWO_PI)}
SWEPT = motion(N)[2] + ZERO
HELD_SWEPT = motion(N, swing=1.2)[2] + ZERO


def _written(q: np.ndarray, wrap: str, turns: list[int]) -> np.ndarray:
    """``q`` written as a logger in ``wrap`` would, then its rows cut into ``len(turns)`` stretches, each moved by its
    number of turns."""
    stretch = np.minimum(np.arange(len(q)) * len(turns) // len(q), len(turns) - 1)
    return WRAPS[wrap](q) + TWO_PI * np.asarray(turns)[stretch]


def _fit(q_logged: np.ndarray) -> TermFit:
    terms = fit_estimate(motion_estimate(np.full(N, T_REF), q_logged, c=RIPPLE_ONLY), OPTIONS)[0].terms
    assert terms is not None
    return terms


@pytest.fixture(scope="module")
def swept():
    """The fit of the angles as swept, and its prediction of the held-out rows as swept."""
    fit = _fit(SWEPT)
    assert fit.kept == ("ripple",) and fit.harmonics == 2
    held = motion_estimate(np.full(N, T_REF), HELD_SWEPT, seed=1, c=RIPPLE_ONLY, swing=1.2)
    valid = held.valid[:, 0]
    use = fit.range_use(term_signals(held, 0), valid, JOINT)
    assert use.outside and 0.1 < use.outside[0].share < 0.5  # some held-out angles beyond the fitted ones
    return fit, predicted_friction(held, 0, fit, valid), use


@settings(max_examples=25, deadline=None)
@given(wrap=st.sampled_from(sorted(WRAPS)), turns=st.lists(st.integers(-3, 3), min_size=1, max_size=6),
       held_wrap=st.sampled_from(sorted(WRAPS)), held_turns=st.lists(st.integers(-3, 3), min_size=1, max_size=3))
def test_any_branch_and_wrap_gives_the_same_fit_and_prediction(swept, wrap, turns, held_wrap, held_turns):
    reference, predicted, use = swept
    fit = _fit(_written(SWEPT, wrap, turns))
    assert fit.kept == reference.kept and fit.harmonics == reference.harmonics
    assert fit.q_range is not None and reference.q_range is not None
    np.testing.assert_allclose(fit.q_range, reference.q_range, rtol=0, atol=1e-9)
    for name, value in reference.coefficients.items():
        assert fit.coefficients[name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    held = motion_estimate(np.full(N, T_REF), _written(HELD_SWEPT, held_wrap, held_turns), seed=1, c=RIPPLE_ONLY,
                           swing=1.2)
    valid = held.valid[:, 0]
    np.testing.assert_allclose(predicted_friction(held, 0, fit, valid), predicted, rtol=0, atol=1e-9)
    outside = fit.range_use(term_signals(held, 0), valid, JOINT).outside
    assert len(outside) == 1 and outside[0].share == use.outside[0].share
    np.testing.assert_allclose(outside[0].used, use.outside[0].used, rtol=0, atol=1e-9)

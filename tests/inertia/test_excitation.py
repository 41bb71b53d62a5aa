"""Parameters the data do not determine: found on a regressor built with known dependencies (a column
twice another, one that never acts, one barely acting), with the partners that keep the torques."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.inertia.consistency import PHYSICAL, prior_model
from wbfriction.inertia.excitation import parameter_names, physical_std, unexcited_parameters
from wbfriction.inertia.least_squares import CompressedLeastSquares


def _system(eps: float):
    """Rows over one body (10, full rank) and four other parameters a, b = 2 a, c = 0, d = eps x random,
    with standard deviations 1, 1, 1, 1 and a unit body."""
    rng = np.random.default_rng(0)
    n = 2000
    A = rng.normal(size=(n, 14))
    A[:, 11] = 2.0 * A[:, 10]
    A[:, 12] = 0.0
    A[:, 13] *= eps
    ls = CompressedLeastSquares(14)
    ls.add(A, rng.normal(size=n))
    body = pin.Inertia.FromBox(1.0, 0.3, 0.2, 0.1).toDynamicParameters()
    prior = prior_model(body[None], np.zeros(4), np.ones(4))
    return A, ls.R, prior


def test_dependent_and_silent_parameters_are_named_with_their_partners():
    A, R, prior = _system(eps=1.0)
    names = parameter_names(["body"], ["a", "b", "c", "d"])
    assert names[:10] == tuple(f"body.{p}" for p in PHYSICAL) and names[10:] == ("a", "b", "c", "d")
    found = {u.parameter: u for u in unexcited_parameters(R, prior, 1e-6, names)}
    assert set(found) == {"a", "c"}
    assert found["c"].partners == {} and found["c"].information == 0.0
    assert found["a"].partners == {"b": pytest.approx(-0.5)}
    assert found["a"].information == 0.0  # it acts only with b: no information of its own, not rounding's
    # the definition: moving a by 1 and b by its coefficient leaves every torque unchanged
    assert np.abs(A[:, 10] + found["a"].partners["b"] * A[:, 11]).max() < 1e-12
    assert np.allclose(physical_std(prior)[10:], 1.0)


@pytest.mark.parametrize(("weight", "reported"), [(1e-6, False), (1e2, True)])
def test_a_barely_acting_parameter_is_reported_when_the_prior_outweighs_its_data(weight, reported):
    """``d`` moves the torques by 1e-3 per standard deviation over 2000 rows: about 0.045 of
    information, below a prior of weight 100 (10 residual units per standard deviation) and above one of 1e-6."""
    _, R, prior = _system(eps=1e-3)
    names = parameter_names(["body"], ["a", "b", "c", "d"])
    found = {u.parameter: u for u in unexcited_parameters(R, prior, weight, names)}
    assert ("d" in found) == reported
    if reported:
        assert 0.0 < found["d"].information < 1.0

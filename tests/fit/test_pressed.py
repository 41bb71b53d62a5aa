"""A magnitude held at its floor of zero: a finding ("no such friction") or a bound the data press against (issue 63).

The real Aliengo's momentum route gave Coulomb-viscous fits with F_v = 0 called `ok` on 8 of 12 joints while the
same fits freed of the floor put F_v at -0.07 to -0.6 (the data's friction falls with the speed there); the PACE
peer's viscous coefficients are 0.24-0.31. Such a zero is the model's bound, not the data's value.
"""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.fit.params_file import fit_from_dict, fit_to_dict
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.solve import PRESS_Z
from wbfriction.fit.status import search_bounds

T = np.arange(6000) * 2e-3
QD = 0.8 * np.sin(2 * np.pi * 0.4 * T) + 0.3 * np.sin(2 * np.pi * 1.3 * T)
"""12 s of a joint swinging both ways at up to 1.1 rad/s [rad/s]."""


def _tau_f(f_c: float, slope: float, noise: float, seed: int) -> np.ndarray:
    """The friction torque ``tau_f = -(f_c sgn(qd) + slope qd)`` plus white noise [N·m]."""
    rng = np.random.default_rng(seed)
    return -(f_c * np.sign(QD) + slope * QD) + rng.normal(0.0, noise, QD.size)


def test_a_friction_falling_with_the_speed_presses_f_v_against_its_floor():
    """Coulomb friction 0.5 N·m falling by 0.2 N·m per rad/s: the Coulomb-viscous fit holds F_v at 0, and freed of
    the floor it would be -0.2 (exact: the model is linear in F_v), far more than 3 standard errors below zero; the
    fit is ``at bound`` and says what the data ask for."""
    fit = fit_friction(QD, _tau_f(0.5, -0.2, 0.02, 0), model="coulomb-viscous")
    assert fit.params.F_v < 1e-12 and fit.at_bound["F_v"]
    value, se = fit.pressed["F_v"]
    assert value == pytest.approx(-0.2, abs=3 * se) and value < -PRESS_Z * se
    assert search_bounds(fit) == ["F_v"]
    verdict = fit.verdict()
    assert verdict.status == "at bound" and "F_v at zero, the data ask for -0.2" in verdict.reason


@pytest.mark.parametrize("seed", range(12))
def test_no_viscous_friction_is_a_finding_not_a_bound(seed):
    """Pure Coulomb friction with noise: F_v at (or near) zero is what the data say; the floor is not pressed
    (beyond 3 standard errors: a one-sided chance of 0.13 % per fit) and the fit is not ``at bound``."""
    fit = fit_friction(QD, _tau_f(0.5, 0.0, 0.05, seed), model="coulomb-viscous")
    assert fit.pressed == {}
    assert fit.verdict().status != "at bound"


def test_a_positive_viscous_friction_is_never_pressed():
    fit = fit_friction(QD, _tau_f(0.5, 0.3, 0.02, 1), model="coulomb-viscous")
    assert fit.params.F_v == pytest.approx(0.3, rel=0.05) and fit.pressed == {}


def test_what_is_pressed_is_written_and_read_back():
    fit = fit_friction(QD, _tau_f(0.5, -0.2, 0.02, 2), model="coulomb-viscous")
    back = fit_from_dict(fit.joint, fit_to_dict(fit))
    assert back.pressed.keys() == fit.pressed.keys() == {"F_v"}
    assert back.pressed["F_v"] == pytest.approx(fit.pressed["F_v"])
    assert back.verdict() == fit.verdict()

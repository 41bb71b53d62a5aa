"""Normal-only foot forces, as Unitree robots log them (issue 63): on the ideal simulator's trot and walk, whose
feet drift micrometres off one height (a stance conditioned 1e6-1e9), every swinging leg stays determined and its
friction is the injected one; the stance legs stay not determined; a walk is estimated; a stance that determines
nothing says so in a quadruped's words, not a humanoid's "single-support"."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.model import load_robot
from wbfriction.sim.quadruped import QuadrupedOptions, simulate_quadruped
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

TRUE = EstimateOptions(diff="true", route="acceleration", base_motion="logged", check_route=False)
LEGS = ("FL", "FR", "RL", "RR")


@pytest.fixture(scope="module")
def robot():
    return load_robot("go2_walking")


def normal_only(robot, gait: str, duration: float):
    """``gait`` simulated for ``duration`` [s], the feet's normal forces alone logged."""
    reference = quadruped_reference(robot, GaitOptions(gait=gait, duration=duration))
    return simulate_quadruped(robot, reference, QuadrupedOptions(foot_forces="normal")).log


def swinging(robot, contact: np.ndarray) -> np.ndarray:
    """(N, n_act) the joints of a leg whose foot is off the ground."""
    legs = np.array([[name.startswith(leg + "_") for name in robot.torque_controlled] for leg in LEGS])
    return (~contact.astype(bool)).astype(float) @ legs.astype(float) > 0


@pytest.mark.parametrize("gait, duration", [("trot", 2.0), ("walk", 3.0)])
def test_swinging_legs_determined_and_exact(robot, gait, duration):
    """Each swinging leg determined on at least 95 % of its evaluated swing samples (0-1 % before: the stance's
    conditioning dropped whole samples), a stance leg on none, and the friction where determined equal to the
    injected one (the simulator's truth, 1e-6 N·m)."""
    log = normal_only(robot, gait, duration)
    assert np.isfinite(log.foot_force[..., 2]).all() and np.isnan(log.foot_force[..., :2]).all()
    est = estimate_log(robot, log, TRUE)
    counted = np.isfinite(est.cond)
    swing = swinging(robot, est.contact) & counted[:, None]
    stance = ~swinging(robot, est.contact) & counted[:, None] & est.contact.any(axis=1)[:, None]
    assert swing.any(axis=0).all()  # every leg swings in the log
    share = (est.determined & swing).sum(axis=0) / swing.sum(axis=0)
    assert share.min() >= 0.95, share
    two_or_more = est.contact.sum(axis=1) >= 2
    assert not est.determined[stance & two_or_more[:, None]].any()  # flat ground: normal forces leave them free
    assert est.valid.any(axis=0).all()  # every joint estimated
    err = np.abs(est.tau_f - est.tau_f_true)[est.valid]
    assert err.max() < 1e-6


def test_a_stance_that_determines_nothing_says_so_on_point_feet(robot):
    """Four feet down, normal forces alone: no joint determined, and the one line names the foot forces and the
    margins, not a humanoid's single support."""
    log = normal_only(robot, "stand", 1.5)
    with pytest.raises(InputError, match="no sample determines any joint's friction") as error:
        estimate_log(robot, log, TRUE)
    assert "single-support" not in str(error.value) and "force.FL_foot.x|y|z" in str(error.value)

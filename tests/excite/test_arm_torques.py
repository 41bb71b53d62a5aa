"""Issue 81, class 7: ``excite`` on an arm whose logs carry joint torques (its TOML without ``[torque_constants]``)
asked for the constants after its whole design (``robot 'z1' has no torque constant for 'joint1'``). The prediction
now simulates the log as the robot's own carry their torque (:func:`~wbfriction.excite.predict_arm.recorded`):
currents where every joint has a constant, else the joints' torques, the same torque either way."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import wbfriction
from wbfriction.excite.predict_arm import REAL_ARM, predict_arm, recorded
from wbfriction.sim.arm import ExcitationOptions, default_arm_friction, excitation_trajectory

JOINT = "panda_joint4"
"""The joint predicted (the others held: the fit of one joint keeps the test short)."""


@pytest.fixture(scope="module")
def arms():
    """The Panda (a torque constant on every joint), the same arm without them, and a 2 s excitation of ``JOINT``."""
    panda = wbfriction.load_robot("panda")
    bare = dataclasses.replace(panda, torque_constants={}, cache={})
    lower, upper = panda.angle_limits
    trajectory = excitation_trajectory(lower, upper, panda.model.velocityLimit[panda.act_v_index],
                                       ExcitationOptions(period=2.0, excited=(JOINT,)),
                                       np.isin(panda.actuated, (JOINT,)))
    return panda, bare, trajectory


def test_an_arm_without_torque_constants_logs_its_torques(arms):
    panda, bare, trajectory = arms
    options = dataclasses.replace(REAL_ARM, duration=2.0)
    friction = default_arm_friction(panda)
    with_currents, with_torques = (recorded(r, friction, trajectory, options) for r in (panda, bare))
    assert f"current.{JOINT}" in with_currents.column_names and f"tau.{JOINT}" not in with_currents.column_names
    assert f"tau.{JOINT}" in with_torques.column_names and f"current.{JOINT}" not in with_torques.column_names
    for joint in panda.actuated:  # the same torque: current x constant
        np.testing.assert_allclose(with_torques.column(f"tau.{joint}").to_numpy(),
                                   with_currents.column(f"current.{joint}").to_numpy() * panda.torque_constants[joint],
                                   rtol=1e-12, atol=1e-12)


def test_its_prediction_is_the_one_with_constants(arms):
    panda, bare, trajectory = arms
    options = dataclasses.replace(REAL_ARM, duration=2.0)
    friction = default_arm_friction(panda)
    expected, found = (predict_arm(r, friction, trajectory, options, joints=(JOINT,)) for r in (panda, bare))
    assert found.models == expected.models and set(found.joints) == {JOINT}
    for name, p in expected.joints[JOINT].items():
        q = found.joints[JOINT][name]
        assert (q.status, q.reason) == (p.status, p.reason)
        np.testing.assert_allclose([q.value, q.se, q.bound], [p.value, p.se, p.bound], rtol=1e-6)

"""A TOML's ``[angle_limits]`` (:attr:`wbfriction.model.robot.Robot.angle_bounds`): limits where the URDF gives none
or others, read wherever limits are; a table that is not limits is one line naming the file and the joint."""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np
import pytest

import wbfriction
from helpers import REAL_DATA, needs_data
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.angles import check_limits
from wbfriction.model.loading import build_robot


def go2_with(limits: object) -> wbfriction.Robot:
    cfg = tomllib.loads(resources.files("wbfriction.model.robots").joinpath("go2.toml").read_text())
    return build_robot(wbfriction.load_robot("go2").urdf, {**cfg, "angle_limits": limits}, source="my.toml")


def test_the_tomls_limits_replace_the_urdfs_and_no_other():
    urdf = wbfriction.load_robot("go2")
    robot = go2_with({"FL_thigh_joint": [-0.5, 2.2]})
    k = robot.actuated.index("FL_thigh_joint")
    lower, upper = robot.angle_limits
    assert (lower[k], upper[k]) == (-0.5, 2.2)
    others = np.arange(robot.n_act) != k
    np.testing.assert_array_equal(lower[others], urdf.angle_limits[0][others])
    np.testing.assert_array_equal(upper[others], urdf.angle_limits[1][others])


@needs_data("unitree_aliengo")
def test_a_continuous_joint_gets_limits():
    # the real Aliengo's thighs are continuous in its URDF: no limits, until the TOML gives them
    urdf = REAL_DATA / "unitree_aliengo" / "aliengo.urdf"
    cfg = {"name": "aliengo", "floating_base": False}
    free = build_robot(urdf, cfg)
    k = free.actuated.index("FL_thigh_joint")
    assert np.isinf(free.angle_limits[0][k])
    bounded = build_robot(urdf, {**cfg, "angle_limits": {"FL_thigh_joint": [0.4, 1.3]}})
    assert bounded.angle_limits[0][k] == 0.4 and bounded.angle_limits[1][k] == 1.3
    # a continuous joint's angle is checked on whatever turn it is logged: a turn away is the same angle
    lower, upper = bounded.angle_limits
    q = np.tile(np.where(np.isfinite(lower), 0.5 * (lower + upper), 0.0), (3, 1))
    q[:, k] = [0.5, 1.2 - 2 * np.pi, 0.9 + 4 * np.pi]
    check_limits(q, bounded, "log.parquet")
    q[1, k] = 2.0 - 2 * np.pi  # 0.7 rad beyond the upper limit, a turn away
    with pytest.raises(ColumnError, match="column 'q.FL_thigh_joint' is .* at row 1, beyond its limits"):
        check_limits(q, bounded, "log.parquet")


@pytest.mark.parametrize("limits, message", [
    ({"FL_thigh_joint": [2.0, 1.0]}, r"my.toml: \[angle_limits\] FL_thigh_joint = \[2.0, 1.0\]: give \[lower, upper\]"),
    ({"FL_thigh_joint": 1.0}, r"FL_thigh_joint = 1.0: give \[lower, upper\]"),
    ({"FL_thigh_joint": [0.0, float("inf")]}, r"FL_thigh_joint = \[0.0, inf\]"),
    ({"nose_joint": [0.0, 1.0]}, r"my.toml: unknown joint in \[angle_limits\] 'nose_joint'"),
    ([0.0, 1.0], r"'\[angle_limits\]' must be a table"),
])
def test_limits_that_are_not_are_refused_naming_the_file_and_joint(limits, message):
    with pytest.raises(InputError, match=message):
        go2_with(limits)

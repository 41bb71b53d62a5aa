"""The robot model: the built-in TALOS, configuration errors, joint layouts, another URDF of a built-in robot."""

from __future__ import annotations

import os

import numpy as np
import pytest

from wbfriction.exceptions import InputError
from wbfriction.model.loading import build_robot, load_robot


def test_talos_builtin(talos):
    assert talos.n_act == 32 and len(talos.torque_controlled) == 30
    assert talos.position_controlled == ("head_1_joint", "head_2_joint")
    assert talos.contact_frames == ("left_sole_link", "right_sole_link")
    assert talos.limb("right_sole_link") == tuple(f"leg_right_{i}_joint" for i in range(1, 7))
    assert abs(sum(i.mass for i in talos.model.inertias) - 90.272192) < 1e-6


def test_config_errors(talos):
    with pytest.raises(InputError, match="both torque- and position-controlled"):
        build_robot(talos.urdf, {"contact_frames": ["left_sole_link"], "position_controlled": ["head_1_joint"],
                                 "torque_controlled": ["head_1_joint"]})
    with pytest.raises(InputError, match="unknown contact frame 'foot'"):
        build_robot(talos.urdf, {"contact_frames": ["foot"]})
    with pytest.raises(InputError, match="'contact_frames' is missing"):
        build_robot(talos.urdf, {})


def test_angles_invert_configuration(talos):
    rng = np.random.default_rng(0)
    angles = rng.uniform(*talos.angle_limits, size=(5, talos.n_act))
    np.testing.assert_array_equal(talos.angles(talos.configuration(angles)), angles)
    assert talos.reference_angles[talos.actuated.index("leg_left_4_joint")] > 0.8  # half-sitting knee


def test_a_built_in_robot_on_another_urdf(talos, tmp_path):
    """``--robot talos --urdf FILE``: TALOS's configuration on another URDF of it (as an
    identified model is written); a URDF of another robot is refused by name."""
    other = load_robot("talos", urdf=talos.urdf)
    assert other.actuated == talos.actuated and other.torque_controlled == talos.torque_controlled
    assert other.contact_frames == talos.contact_frames and other.groups == talos.groups
    (tmp_path / "small.urdf").write_text("<robot name='x'><link name='a'/></robot>")
    with pytest.raises(InputError, match="unknown"):
        load_robot("talos", urdf=tmp_path / "small.urdf")
    (tmp_path / "c.toml").write_text('contact_frames = ["left_sole_link", "right_sole_link"]\n')
    with pytest.raises(InputError, match="no 'urdf' in the robot TOML: give the robot's --urdf"):
        load_robot(config=tmp_path / "c.toml")


def test_a_robot_toml_that_names_its_urdf(talos, tmp_path):
    """``--config`` alone: the TOML's ``urdf``, relative to the TOML or in ``example-robot-data``, is loaded
    with that TOML's roles (here TALOS's own TOML, written elsewhere: the built-in robot again)."""
    from importlib import resources
    text = resources.files("wbfriction.model.robots").joinpath("talos.toml").read_text()
    (tmp_path / "package.toml").write_text(text)
    relative = os.path.relpath(talos.urdf, tmp_path)
    (tmp_path / "relative.toml").write_text(text.replace(
        'urdf = "example-robot-data:talos_data/robots/talos_reduced.urdf"', f'urdf = "{relative}"'))
    for name in ("package.toml", "relative.toml"):
        robot = load_robot(config=tmp_path / name)
        assert robot.actuated == talos.actuated and robot.torque_controlled == talos.torque_controlled
        assert robot.contact_frames == talos.contact_frames and robot.groups == talos.groups


def test_a_robot_is_named_one_way(tmp_path):
    """``--robot``, ``--urdf``, ``--config`` and ``--mjcf`` become a robot through one function (issue 54):
    :meth:`RobotSpec.given`, whose ``load`` the command line's ``robot_of`` and the worker processes both call."""
    from wbfriction.cli.common import robot_of
    from wbfriction.model.loading import RobotSpec

    assert RobotSpec.given("panda") == RobotSpec("panda")
    config = tmp_path / "arm.toml"
    spec = RobotSpec.given("talos", "arm.urdf", config)
    assert spec == RobotSpec(None, "arm.urdf", str(config)) and hash(spec) == hash(RobotSpec(None, "arm.urdf",
                                                                                            str(config)))
    panda = robot_of("panda", None, None)
    assert panda.name == RobotSpec.given("panda").load().name == "panda"
    with pytest.raises(InputError, match="unknown robot 'nobody'"):
        robot_of("nobody", None, None)

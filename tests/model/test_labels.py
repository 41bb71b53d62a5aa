"""Joint labels: the robot TOML's [labels] over the joints' names, refused when they would mislead."""

from __future__ import annotations

import pytest

from wbfriction.exceptions import InputError
from wbfriction.model.labels import default_label, parse_labels
from wbfriction.model.loading import load_robot

JOINTS = ("leg_left_4_joint", "left_knee", "waist")


def test_default_labels_are_the_names_read_aloud():
    assert [default_label(j) for j in JOINTS] == ["leg left 4", "left knee", "waist"]


def test_given_labels_override_the_default_and_the_rest_keep_theirs():
    labels = parse_labels({"leg_left_4_joint": " left knee (TALOS) "}, JOINTS, "robot.toml")
    assert labels == {"leg_left_4_joint": "left knee (TALOS)", "left_knee": "left knee", "waist": "waist"}


@pytest.mark.parametrize(("value", "message"), [
    ({"elbow": "elbow"}, "robot.toml: \\[labels\\] names 'elbow', which is not a joint of the model"),
    ({"waist": ""}, "robot.toml: \\[labels\\] waist must be a non-empty string"),
    ({"waist": 3}, "robot.toml: \\[labels\\] waist must be a non-empty string"),
    ({"leg_left_4_joint": "left knee"}, "gives 'leg_left_4_joint' and 'left_knee' the same label 'left knee'"),
    (["waist"], "robot.toml: \\[labels\\] must be a table"),
])
def test_bad_labels_are_refused_naming_the_file_and_key(value, message):
    with pytest.raises(InputError, match=message):
        parse_labels(value, JOINTS, "robot.toml")


@pytest.mark.parametrize("name", ["talos", "toro", "panda"])
def test_built_in_robots_label_every_joint_distinctly(name):
    robot = load_robot(name)
    labels = [robot.label(j) for j in robot.actuated]
    assert len(set(labels)) == len(labels)
    assert all(label and "_joint" not in label for label in labels)


def test_talos_legs_read_as_the_thesis_names_them():
    talos = load_robot("talos")
    assert talos.label("leg_right_4_joint") == "right knee"
    assert talos.label("leg_left_1_joint") == "left hip yaw"

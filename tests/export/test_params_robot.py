"""Issue 65, class 1: parameters meet a robot through one check (:func:`~wbfriction.fit.params_file.read_robot_params`).
A Go2's fit exported with another robot of the same joints' names was written as that robot's friction ("exported the
friction of 12 joints (12 ok)"); it is now refused in one line naming the file and both robots, nothing written."""

from __future__ import annotations

import pytest

from helpers import run_cli
from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import read_robot_params, write_params
from wbfriction.model import load_robot


def params_of(path, robot: str, urdf: str, fit_of):
    """Ok fits of every Go2 joint, recorded as fitted for ``robot`` with the model file ``urdf``."""
    write_params(path, [fit_of(j, "ok") for j in load_robot("go2").actuated],
                 {"provenance": {"robot": robot, "urdf": urdf}})
    return path


def test_another_robots_parameters_are_refused_before_anything_is_written(tmp_path, capsys, fit_of):
    """An Aliengo's fit (its own URDF) exported for the Go2, whose joints have the same names."""
    params = params_of(tmp_path / "aliengo.json", "aliengo", str(tmp_path / "aliengo.urdf"), fit_of)
    out = tmp_path / "go2.xml"
    code, err = run_cli(capsys, "export", params, "--robot", "go2", "-o", out)
    assert code == 2 and not out.exists()
    assert err.strip() == (f"error: {params}: parameters of robot 'aliengo' ({tmp_path / 'aliengo.urdf'}), not of "
                           f"'go2' ({load_robot('go2').urdf}): give the robot model they were fitted with")


def test_the_same_model_file_under_another_name_is_the_same_robot(tmp_path, capsys, fit_of):
    """The hung Go2's fit exported for the walking Go2 (one URDF, two TOMLs), as the exports how-to's ``panda`` fit
    for its ``panda_pd``: accepted."""
    go2 = load_robot("go2")
    params = params_of(tmp_path / "go2.json", "go2", str(go2.urdf), fit_of)
    for robot in ("go2", "go2_walking"):
        out = tmp_path / f"{robot}.xml"
        code, err = run_cli(capsys, "export", params, "--robot", robot, "-o", out)
        assert code == 0 and out.exists(), err


def test_a_file_without_a_recorded_robot_is_checked_by_its_joints(tmp_path, fit_of):
    """A hand-written file records no robot: its joints must be the robot's."""
    path = tmp_path / "hand.json"
    write_params(path, [fit_of("FL_hip_joint", "ok")])
    assert set(read_robot_params(path, "go2", load_robot("go2").actuated)) == {"FL_hip_joint"}
    with pytest.raises(InputError, match="hand.json: joint 'FL_hip_joint' is not an actuated joint of robot 'panda'"):
        read_robot_params(path, "panda", load_robot("panda").actuated)

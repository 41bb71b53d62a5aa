"""A robot whose model lacks a contact frame its TOML names is refused when it is loaded, in one line naming the robot,
the frame, the model's file and the feet it has (issue 82: a URDF with its toes commented out said nothing until the
contact columns were missing)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from helpers import run_cli
from wbfriction.exceptions import InputError
from wbfriction.model.loading import example_robot_data_dir, load_robot

GO2 = "go2_description/urdf/go2.urdf"
LEGS = ("FL", "FR", "RL", "RR")


def go2_copy(tmp_path: Path, feet: str | None) -> Path:
    """go2's URDF from example-robot-data copied into ``tmp_path``: its foot links and their fixed joints removed
    (``feet`` None), or renamed ``<leg>_<feet>``."""
    text = (example_robot_data_dir() / GO2).read_text()
    for leg in LEGS:
        if feet is None:
            text, n = re.subn(rf'<link\s+name="{leg}_foot">.*?</link>', "", text, flags=re.S)
            text, m = re.subn(rf'<joint\s+name="{leg}_foot_joint".*?</joint>', "", text, flags=re.S)
            assert n == m == 1
        else:
            text = text.replace(f'"{leg}_foot"', f'"{leg}_{feet}"')
    path = tmp_path / "go2.urdf"
    path.write_text(text)
    return path


def test_a_model_without_its_feet_is_refused_at_load(tmp_path):
    """The feet removed: the line names the robot, the first foot, the file, and says the model has none."""
    urdf = go2_copy(tmp_path, None)
    with pytest.raises(InputError) as info:
        load_robot("go2_walking", urdf=urdf)
    line = str(info.value)
    assert "\n" not in line
    assert "robot 'go2_walking'" in line and "unknown contact frame 'FL_foot'" in line and str(urdf) in line
    assert "no frame ending in foot/toe" in line


def test_feet_of_another_name_are_listed_and_the_closest_suggested(tmp_path):
    """The feet renamed FL_toe ...: the line lists them and suggests FL_toe for FL_foot."""
    urdf = go2_copy(tmp_path, "toe")
    toml = tmp_path / "dog.toml"
    toml.write_text(f'name = "dog"\nurdf = "{urdf.name}"\ncontact_frames = ["FL_foot", "FR_foot", "RL_foot", '
                    '"RR_foot"]\ncontact_model = "point"\n')
    with pytest.raises(InputError) as info:
        load_robot(config=toml)
    line = str(info.value)
    assert "robot 'dog'" in line and "unknown contact frame 'FL_foot'" in line
    assert "its frames ending in foot/toe/sole/ankle: FL_toe, FR_toe, RL_toe, RR_toe" in line
    assert "did you mean 'FL_toe'" in line


def test_the_command_line_refuses_it_in_one_line_before_any_work(tmp_path, capsys):
    """``estimate`` with the footless model: a non-zero exit, one line, the log never read (it is no table)."""
    urdf = go2_copy(tmp_path, None)
    log = tmp_path / "log.parquet"
    log.write_text("not a table")
    code, text = run_cli(capsys, "estimate", str(log), "--robot", "go2_walking", "--urdf", str(urdf), "-o",
                         str(tmp_path / "f.parquet"))
    assert code != 0 and text.count("\n") == 1 and "unknown contact frame 'FL_foot'" in text

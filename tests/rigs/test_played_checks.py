"""``simulate --play`` checks a set-points table before it simulates, as ``identify`` checks a log (issue 81, class
4): a table made for another robot (its metadata's ``robot``) and set-points beyond the joints' limits (degrees for
radians) are one line naming the table, the robot and, for a set-point, its column and row; nothing is written."""

from __future__ import annotations

from importlib import resources

import numpy as np

import wbfriction
from helpers import run_cli, said
from wbfriction.logs.setpoint_table import setpoint_table
from wbfriction.logs.tables import write_table


def _design(go2, path, scale: float = 1.0):
    """A short table of the hung Go2 (0.1 s at 500 Hz), its set-points about its limits' middles, times ``scale``."""
    lower, upper = go2.angle_limits
    t = np.arange(50) / 500.0
    q = (lower + upper) / 2 + 0.2 * np.sin(2 * np.pi * t)[:, None] + go2.offset_vector
    write_table(setpoint_table(go2.name, go2.actuated, t, scale * q, np.zeros_like(q), kind="hung PD-driven"), path)
    return path


def test_a_go2_design_is_not_played_on_another_robot(capsys, tmp_path):
    """The Aliengo of round 5: another robot with the Go2's joints' names (here the Go2's TOML under another
    name)."""
    go2 = wbfriction.load_robot("go2")
    text = resources.files("wbfriction.model.robots").joinpath("go2.toml").read_text()
    config = tmp_path / "aliengo.toml"
    config.write_text(text.replace('name = "go2"', 'name = "aliengo"'))
    table = _design(go2, tmp_path / "go2_excite.parquet")
    out = tmp_path / "played.parquet"
    code, err = run_cli(capsys, "simulate", "--config", config, "--play", table, "-o", out)
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert f"{table}: set-points made for robot 'go2' (its metadata), not for robot 'aliengo'" in lines[0], err
    assert not out.exists()
    code, err = run_cli(capsys, "simulate", "--robot", "go2", "--play", table, "-o", out)
    assert code == 0 and out.exists(), err


def test_set_points_in_degrees_are_not_played(capsys, tmp_path):
    """Degrees for radians: the calves far beyond their limits (before: played to -129 rad, a log written that
    ``identify`` refused)."""
    go2 = wbfriction.load_robot("go2")
    table = _design(go2, tmp_path / "degrees.csv", 180 / np.pi)
    out = tmp_path / "played.parquet"
    code, err = run_cli(capsys, "simulate", "--robot", "go2", "--play", table, "-o", out)
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    # the first joint beyond its limits: the front left hip at its second set-point, (0.02 + 0.2 sin(2π/500)) x 57.3
    assert f"{table}: column 'q_des.FL_hip_joint' is 1.28991 at row 1, beyond its limits" in lines[0], err
    assert "wrong units (degrees for radians)?" in lines[0] and "robot 'go2'" in lines[0]
    assert not out.exists()

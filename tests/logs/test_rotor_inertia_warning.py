"""Torques from the motors' currents on a robot whose TOML gives no ``[armature]`` are named in one line before the work
(issue 82): the rotors' inertia torque (armature x qdd) is then in what is estimated. A warning, not a refusal."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from helpers import run_cli
from wbfriction.logs.log import check_schema, log_from_table
from wbfriction.logs.tables import write_table
from wbfriction.model.loading import load_robot


def panda_without_armature(tmp_path: Path) -> Path:
    """The built-in Panda's TOML with its ``[armature]`` table removed."""
    from importlib import resources

    text = resources.files("wbfriction.model.robots").joinpath("panda.toml").read_text()
    text, n = re.subn(r"\n\[armature\]\n(panda_joint\d = [\d.]+\n)+", "\n", text)
    assert n == 1
    path = tmp_path / "panda_bare.toml"
    path.write_text(text)
    return path


def columns(robot, prefix: str, n: int = 400) -> pa.Table:
    """A short, smooth log of ``robot`` whose torques are ``<prefix>.<joint>``."""
    t = np.arange(n) * 1e-3
    cols = {"time": t}
    for i, j in enumerate(robot.actuated):
        lo, hi = robot.angle_limits[0][i], robot.angle_limits[1][i]
        cols[f"q.{j}"] = 0.5 * (lo + hi) + 0.2 * np.sin(2 * np.pi * t + i)
        cols[f"{prefix}.{j}"] = 0.5 * np.cos(2 * np.pi * t + i)
    return pa.table(cols)


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    bare = load_robot(config=panda_without_armature(tmp_path_factory.mktemp("bare")))
    return load_robot("panda"), bare


@pytest.mark.parametrize("prefix", ["current", "tau_est"])
def test_currents_without_armature_are_named_once(robots, prefix):
    """Currents or the drivers' estimates on the Panda without [armature]: one line naming the source, the robot and
    the joints; with its [armature], or with joint torque sensors (tau.*), none."""
    panda, bare = robots
    table = columns(bare, prefix)
    warnings = [w for w in check_schema(table.schema, bare, "arm.parquet") if "armature" in w]
    assert len(warnings) == 1 and "\n" not in warnings[0]
    line = warnings[0]
    assert line.startswith("arm.parquet: the torques are ") and "robot 'panda'" in line
    assert "no [armature] for 7 of its 7 torque-controlled joints (panda_joint1, panda_joint2, panda_joint3 and 4 " \
           "more)" in line
    assert log_from_table(table, bare, "arm.parquet").warnings == tuple(warnings)  # read, nothing refused
    assert not [w for w in check_schema(table.schema, panda, "arm.parquet") if "armature" in w]
    assert not [w for w in check_schema(columns(bare, "tau").schema, bare, "arm.parquet") if "armature" in w]


def test_estimate_says_it_before_the_numbers(robots, tmp_path, capsys):
    """``estimate`` of a current log on the bare Panda: the line is printed, and the estimate is made."""
    _, bare = robots
    log = tmp_path / "arm.parquet"
    write_table(columns(bare, "current", 2000), log)
    code, err = run_cli(capsys, "estimate", log, "--config", panda_without_armature(tmp_path), "-o",
                        tmp_path / "f.parquet")
    assert code == 0 and (tmp_path / "f.parquet").exists()
    assert err.count("rotor inertia torque (armature x qdd)") == 1


def test_identify_says_it_unless_it_identifies_the_armature(robots, tmp_path):
    from wbfriction.inertia.options import InertialOptions
    from wbfriction.pipeline.identify_step import rotor_inertia_notes

    _, bare = robots
    log = tmp_path / "arm.parquet"
    write_table(columns(bare, "current"), log)
    assert len(rotor_inertia_notes(bare, log, InertialOptions())) == 1
    assert rotor_inertia_notes(bare, log, InertialOptions(armature="identify")) == ()

"""What ``demo`` shows of each built-in rig, against the truth its simulation injected: an arm's fitted friction, a
hung robot's identified actuators (the biped's and the quadruped's studies have tests of their own:
``tests/test_cli.py``, ``tests/studies/test_quadruped.py``); a rig that shows nothing is one line."""

from __future__ import annotations

import re

import pytest

from helpers import run_cli_printed
from wbfriction.exceptions import InputError
from wbfriction.model.loading import load_robot
from wbfriction.rigs import Rig, RigProgress


def found_and_true(out: str, names: tuple[str, ...]) -> dict[str, list[tuple[float, float, float, str]]]:
    """Each joint's row of a demo's table and the truth's row under it: (value, se, truth, status) per column of
    ``names`` (a status not ``ok`` named in the line after the table: ``not ok: FL_calf_joint offset (weak)``)."""
    rows: dict[str, list[tuple[float, float, float, str]]] = {}
    lines = out.splitlines()
    named = re.findall(r"(\w+) (\w+) \((weak|at bound|not excited|failed|does not predict)\)", out)
    statuses = {(joint, name): status for joint, name, status in named}
    for k, line in enumerate(lines[:-1]):
        truth = lines[k + 1].split()
        found = re.findall(r"(-?[\d.]+) ± (\S+)", line)
        if found and truth[:1] == ["true"]:
            joint = line.split()[0]
            rows[joint] = [(float(v), float(se), float(t), statuses.get((joint, n), "ok"))
                           for (v, se), t, n in zip(found, truth[1:], names, strict=True)]
    return rows


def test_the_arms_demo_fits_the_friction_it_injected(tmp_path, capsys):
    """The Panda, 6 s: every joint's F_c and F_v ``ok`` and within 2 % of the truth, and within 4 standard errors."""
    code, out, err = run_cli_printed(capsys, "demo", "--robot", "panda", "--rig-option", "duration=6", "-o",
                                     tmp_path / "arm")
    assert code == 0, err
    rows = found_and_true(out, ("F_c", "F_v"))
    assert set(rows) == set(load_robot("panda").actuated), out
    for joint, found in rows.items():
        for value, se, truth, status in found:
            assert status == "ok" and abs(value - truth) <= max(0.02 * abs(truth), 4 * se), (joint, value, truth, se)
    assert (tmp_path / "arm" / "arm.parquet").exists()


def test_the_hung_robots_demo_identifies_its_actuators(tmp_path, capsys):
    """The hung Go2, 12 s: every ``ok`` armature, F_c and F_v within 4 of its standard errors of the truth (printed
    to one digit), nine in ten within 5 %; the delay within a physics step (1 ms) of it."""
    code, out, err = run_cli_printed(capsys, "demo", "--robot", "go2", "--rig-option", "duration=12", "-o",
                                     tmp_path / "hung")
    assert code == 0, err
    rows = found_and_true(out, ("armature", "F_c", "F_v", "offset"))
    assert len(rows) == 12, out
    checked = [(joint, value, se, truth) for joint, found in rows.items() for value, se, truth, status in found[:3]
               if status == "ok"]
    assert len(checked) >= 30, out
    assert all(abs(value - truth) <= 4 * se for _, value, se, truth in checked), checked
    assert sum(abs(value - truth) <= 0.05 * abs(truth) for _, value, _, truth in checked) >= 0.9 * len(checked)
    delay = re.search(r"^delay ([\d.]+) ± \S+ ms, truth 12 ms$", out, re.M)
    assert delay and abs(float(delay.group(1)) - 12.0) < 1.0, out


def test_a_rig_without_a_demo_says_so(tmp_path):
    class Bare(Rig):
        name, precedence = "bare", 99

    with pytest.raises(InputError, match="robot 'panda' is on rig 'bare': demo shows nothing of it"):
        Bare().demo(load_robot("panda"), None, None, tmp_path, RigProgress())

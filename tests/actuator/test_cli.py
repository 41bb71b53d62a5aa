"""``wbfriction identify --actuator pd`` as a user runs it: a hung Go2 simulated (the built-in ``go2``), its actuators
identified, the TOML written, the friction estimated with it; bad input refused in one line before any work."""

from __future__ import annotations

import re
import tomllib

import pytest

from helpers import assert_one_line_error, run, strict_json


def test_simulate_identify_estimate(tmp_path):
    assert run("simulate", "--robot", "go2", "-o", "hung.parquet", "--duration", "6", cwd=tmp_path).returncode == 0
    done = run("identify", "hung.parquet", "--robot", "go2", "--actuator", "pd", "--json", "actuator.json",
               "--config-output", "identified.toml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "delay" in done.stdout and "armature" in done.stdout
    doc = strict_json(tmp_path / "actuator.json")  # no NaN nor Infinity (issue 63)
    truth = 0.012  # the built-in go2's [pd] delay, which the simulator injects
    assert abs(doc["delay"]["value"] - truth) < 0.001 and doc["delay"]["status"] == "ok"
    written = tomllib.loads((tmp_path / "identified.toml").read_text())
    choice = doc["written"]  # each value against the TOML's (here the simulator's truth) on held-out blocks
    assert written["pd"]["delay"] == choice["delay"]["written"] and abs(written["pd"]["delay"] - truth) < 0.001
    assert {j: written["armature"][j] for j in choice["joints"]} == {
        j: v["armature"]["written"] for j, v in choice["joints"].items()}
    estimated = run("estimate", "hung.parquet", "--config", "identified.toml", "-o", "friction.parquet", cwd=tmp_path)
    assert estimated.returncode == 0, estimated.stderr
    assert "torque: the drivers' PD law" in estimated.stderr
    assert "warning:" not in estimated.stderr  # the law identified is the drivers'
    text = (tmp_path / "identified.toml").read_text()
    (tmp_path / "late.toml").write_text(re.sub(r"(?m)^delay = .*$", "delay = 0.0", text))
    wrong = run("estimate", "hung.parquet", "--config", "late.toml", "-o", "wrong.parquet", cwd=tmp_path)
    assert wrong.returncode == 0, wrong.stderr
    lines = [line for line in wrong.stderr.splitlines() if line.startswith("warning:")]
    assert len(lines) == 1 and "[pd] delay (0 ms) is not the drivers'" in lines[0]  # issue 63


def test_drivers_later_than_the_search_write_nothing_and_say_so(tmp_path):
    """Issue 63: drivers 80 ms late, the search to 50 ms: a one-line warning naming --max-delay, and the TOML written
    keeps the robot's own delay, armatures and offsets (none fitted under a delay at its bound)."""
    import wbfriction

    assert run("simulate", "--robot", "go2", "-o", "late.parquet", "--duration", "4", "--delay", "80",
               cwd=tmp_path).returncode == 0
    done = run("identify", "late.parquet", "--robot", "go2", "--actuator", "pd", "--config-output", "late.toml",
               cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    warnings = [line for line in done.stderr.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "--max-delay" in warnings[0]
    written = tomllib.loads((tmp_path / "late.toml").read_text())
    go2 = wbfriction.load_robot("go2")
    assert written["pd"]["delay"] == go2.pd.delay
    assert written["armature"] == pytest.approx(dict(zip(go2.actuated, go2.model.armature[go2.act_v_index])))
    assert written["encoder_offset"] == go2.encoder_offset


def test_a_robot_without_pd_gains_is_refused_in_one_line(tmp_path):
    assert run("simulate", "--robot", "panda", "-o", "arm.parquet", "--duration", "1", cwd=tmp_path).returncode == 0
    res = run("identify", "arm.parquet", "--robot", "panda", "--actuator", "pd", cwd=tmp_path)
    assert_one_line_error(res, "no [pd] gains")


def test_a_bad_option_is_refused_before_any_work(tmp_path):
    (tmp_path / "log.parquet").write_bytes(b"")
    res = run("identify", "log.parquet", "--robot", "go2", "--actuator", "pd", "--velocity", "fast", cwd=tmp_path)
    assert_one_line_error(res, "--velocity")

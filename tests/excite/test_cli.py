"""``wbfriction excite`` as a user runs it (:mod:`wbfriction.cli.excite`): the set-points it writes are what
``simulate --play`` plays, in both formats, the JSON holds every joint's prediction, and what it cannot design is one
line before any work."""

from __future__ import annotations

import json

import numpy as np
import pyarrow.parquet as pq
import pytest

import wbfriction
from helpers import assert_stages, run_cli_printed
from wbfriction.logs.setpoint_table import read_setpoint_table


def test_a_design_written_then_played(cli, capsys, tmp_path):
    out = cli("excite", "--robot", "go2", "--duration", "4", "--amplitude", "0.8", "-o", tmp_path / "d.parquet",
              "-o", tmp_path / "d.csv", "--json", tmp_path / "d.json", "--figure", tmp_path / "d.png")
    assert "worst: " in out and "of its limit" in out
    go2 = wbfriction.load_robot("go2")
    parquet, csv = (read_setpoint_table(tmp_path / f"d.{s}", go2) for s in ("parquet", "csv"))
    np.testing.assert_array_equal(parquet.q_des, csv.q_des)
    assert parquet.rate == pytest.approx(200.0, rel=1e-12) and parquet.duration == pytest.approx(4.0, rel=1e-12)
    lower, upper = go2.angle_limits
    model = parquet.q_des - go2.offset_vector
    assert np.all((model >= lower) & (model <= upper))
    doc = json.loads((tmp_path / "d.json").read_text())
    assert set(doc["predicted"]) == set(go2.actuated) and doc["worst"]["share"] > 0
    assert set(doc["margins"]["FL_calf_joint"]) == {"position", "velocity", "torque"}
    assert (tmp_path / "d.png").stat().st_size > 10_000
    cli("simulate", "--robot", "go2", "--play", tmp_path / "d.csv", "-o", tmp_path / "played.parquet")
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2", "--play", tmp_path / "d.csv", "--duration",
                                   "5", "-o", tmp_path / "other.parquet")
    assert code == 2 and "--duration: the set-points played (d.csv) fix the motion: it takes no motion option" in err
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2", "--play", tmp_path / "d.csv", "--rig-option",
                                   "duration=5", "-o", tmp_path / "other.parquet")  # by its name too (issue 81)
    assert code == 2 and "--rig-option duration: the set-points played (d.csv) fix the motion" in err
    assert not (tmp_path / "other.parquet").exists()
    played = pq.read_table(tmp_path / "played.parquet")
    assert played.num_rows == 800
    np.testing.assert_allclose(played.column("q_des.FL_calf_joint").to_numpy(), parquet.q_des[:, 2])


def test_what_cannot_be_designed_is_one_line_before_the_work(capsys, tmp_path):
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--swing", "FR", "-o", tmp_path / "d.parquet")
    assert code == 2 and "--swing: robot 'go2' is a hung PD-driven robot (fixed base, [pd]): it takes" in err
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--duration", "1", "-o", tmp_path / "d.parquet")
    assert code == 2 and "--duration 1: the design needs at least" in err
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--duration", "2", "--amplitude", "0.95",
                                   "--torque-share", "0.05", "-o", tmp_path / "d.parquet")
    assert code == 2 and "every candidate passes a limit or 5% of a torque limit" in err
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--period", "5", "-o", tmp_path / "d.parquet")
    assert code == 2 and "--period: robot 'go2' is a hung PD-driven robot (fixed base, [pd]): it takes" in err
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2", "--play", tmp_path / "missing.parquet",
                                   "-o", tmp_path / "x.parquet")
    assert code == 2 and "missing.parquet" in err
    assert not (tmp_path / "d.parquet").exists() and not (tmp_path / "x.parquet").exists()


def test_an_arms_design_written_then_played(cli, capsys, tmp_path):
    """A Panda: a Fourier design, its series in the table, played by the arm simulator along it."""
    code, out, err = run_cli_printed(capsys, "excite", "--robot", "panda", "--duration", "4", "--period", "4", "-o",
                                     tmp_path / "arm.csv", "--json", tmp_path / "arm.json")
    assert code == 0, err
    assert "worst: panda_joint" in out
    assert int(assert_stages(err, "design", "predicting what")["design"]["items"]) == 7  # the arm's joints, each told
    panda = wbfriction.load_robot("panda")
    table = read_setpoint_table(tmp_path / "arm.csv", panda)
    assert table.rate == pytest.approx(1000.0, rel=1e-12) and table.fourier is not None
    doc = json.loads((tmp_path / "arm.json").read_text())
    assert set(doc["predicted"]) == set(panda.actuated) and doc["kind"] == "fixed-base arm"
    cli("simulate", "--robot", "panda", "--play", tmp_path / "arm.csv", "-o", tmp_path / "played.parquet")
    played = pq.read_table(tmp_path / "played.parquet")
    assert played.num_rows == 4000
    q = played.column("q.panda_joint4").to_numpy()
    assert np.max(np.abs(q - table.q_des[:, 3])) < 0.01  # the arm tracks the design (its PD at 10 Hz bandwidth)
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "panda", "--amplitude", "0.5", "-o",
                                   tmp_path / "x.csv")
    assert code == 2 and ("--amplitude: robot 'panda' is a fixed-base arm (torque-driven, an excitation trajectory): "
                          "it takes --duration") in err

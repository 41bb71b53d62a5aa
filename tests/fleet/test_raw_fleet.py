"""A fleet of walking robots' raw logs (no contact flags, no base pose, the IMU's orientation): each log made the
project's log as ``estimate`` makes it (:func:`~wbfriction.pipeline.raw_log.prepared_log`), the rows those of the
``estimate`` and ``fit`` commands on the same log."""

from __future__ import annotations

import json
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.fleet.batch import run_batch
from wbfriction.fleet.manifest import read_manifest
from wbfriction.fleet.results import read_results

TOML = Path(str(resources.files("wbfriction.model.robots").joinpath("go2_logged.toml")))  # the built-in twin's
RATE = 1 / 1.22e-3


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wbfriction", *args], cwd=cwd, capture_output=True, text=True)


@pytest.mark.slow
def test_a_raw_walking_log_in_a_fleet_gives_the_commands_rows(tmp_path):
    done = _cli("simulate", "--robot", str(TOML), "--simulator", "mujoco", "--gait", "walk", "--duration", "6",
                "--logger", "raw", "-o", "raw.parquet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    table = pq.read_table(tmp_path / "raw.parquet")  # the logger's own stamps: a fleet's manifest has no rate
    table = table.append_column("time", pa.array(np.arange(table.num_rows) / RATE))
    pq.write_table(table, tmp_path / "walk.parquet")
    (tmp_path / "manifest.csv").write_text("log,robot_id,start_time,config\n"
                                           f"walk.parquet,go2-1,2026-03-01T08:00:00+00:00,{TOML}\n")
    results = tmp_path / "results"
    summary = run_batch(read_manifest(tmp_path / "manifest.csv"), results, engine="serial")
    assert (summary.processed, summary.failed) == (1, [])
    for argv in (["estimate", "walk.parquet", "--robot", str(TOML), "-o", "f.parquet"],
                 ["fit", "f.parquet", "-o", "p.json"]):
        assert (run := _cli(*argv, cwd=tmp_path)).returncode == 0, run.stderr
    fits = json.loads((tmp_path / "p.json").read_text())["joints"]
    rows = read_results(results).table.to_pylist()
    assert {r["joint"] for r in rows} == set(fits)
    for row in rows:
        fit = fits[row["joint"]]
        assert row["status"] == fit["status"] and row["n_samples"] == fit["n_samples"]
        if fit.get("params"):
            for name in ("F_c", "F_v"):
                assert row[name] == pytest.approx(fit["params"][name], rel=1e-9, abs=1e-12)

"""``wbfriction batch`` and ``wbfriction trends`` on bad input: one line naming what is at fault, exit status 2,
nothing written."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


def wbfriction(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wbfriction", *args], cwd=cwd, capture_output=True, text=True)


@pytest.mark.parametrize("manifest, message", [
    (None, "m.csv: file not found"),
    ("log,robot_id,start_time,robot\na.parquet,r1,2026-03-01T08:00:00,talos\n",
     "row 0, column 'start_time'"),
    ("log,robot_id,start_time,robot\nmissing.parquet,r1,2026-03-01T08:00:00Z,talos\n", "row 0, column 'log'"),
    ("log,robot_id,start_time,robot\na.parquet,r1,2026-03-01T08:00:00Z,atlas\n", "manifest row 0: "),
])
def test_a_bad_manifest_is_one_line_and_nothing_is_written(tmp_path, manifest, message):
    (tmp_path / "a.parquet").write_bytes(b"")
    if manifest is not None:
        (tmp_path / "m.csv").write_text(manifest)
    res = wbfriction("batch", "m.csv", "-o", "results", cwd=tmp_path)
    assert res.returncode == 2 and message in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and not (tmp_path / "results").exists()


def test_trends_need_results_and_an_html_page(tmp_path):
    (tmp_path / "empty").mkdir()
    res = wbfriction("trends", "empty", "-o", "t.html", cwd=tmp_path)
    assert res.returncode == 2 and "empty: no results" in res.stderr
    res = wbfriction("trends", "empty", "-o", "t.txt", cwd=tmp_path)
    assert res.returncode == 2 and "-o t.txt: the trends page is written as .html" in res.stderr
    assert not (tmp_path / "t.html").exists()

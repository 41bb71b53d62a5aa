"""Manifests and scanned folders (issue 25): every fault one line naming the manifest, row and column, before
any log is processed."""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.exceptions import InputError
from wbfriction.fleet.manifest import read_manifest, scan_folder
from wbfriction.pipeline.estimate import RobotSpec

HEAD = "log,robot_id,start_time,robot"


@pytest.fixture
def folder(tmp_path) -> Path:
    (tmp_path / "a.parquet").write_bytes(b"")
    (tmp_path / "b.csv").write_text("time\n0\n")
    return tmp_path


def _manifest(folder: Path, *rows: str, head: str = HEAD) -> Path:
    path = folder / "m.csv"
    path.write_text("\n".join([head, *rows]) + "\n")
    return path


def test_a_manifest_gives_paths_robots_times_and_options(folder):
    path = _manifest(folder, "a.parquet,r1,2026-03-01T08:00:00+02:00,talos,savgol,thesis",
                     "b.csv,r-2,2026-03-01T08:00:00Z,panda,,", head=HEAD + ",diff,model")
    a, b = read_manifest(path)
    assert a.log == folder / "a.parquet" and a.robot_id == "r1" and a.robot == RobotSpec("talos")
    assert a.start_time == datetime(2026, 3, 1, 6, 0, tzinfo=UTC)
    assert a.options == {"diff": "savgol", "model": "thesis"} and b.options == {}
    assert (a.row, b.row) == (0, 1)


def test_a_parquet_manifest_with_timestamps(folder):
    t = pa.array([datetime(2026, 3, 1, 8, tzinfo=UTC)], pa.timestamp("ns", tz="UTC"))
    pq.write_table(pa.table({"log": ["a.parquet"], "robot_id": ["r1"], "start_time": t, "robot": ["talos"]}),
                   folder / "m.parquet")
    (entry,) = read_manifest(folder / "m.parquet")
    assert entry.start_time == datetime(2026, 3, 1, 8, tzinfo=UTC)


@pytest.mark.parametrize("rows, head, message", [
    (["a.parquet,r1,talos"], "log,robot_id,robot", "no column 'start_time'"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos,1"], HEAD + ",speed", "unknown manifest column 'speed'"),
    (["a.parquet,r1,2026-03-01T08:00:00,talos"], HEAD, "row 0, column 'start_time'"),
    (["a.parquet,r1,yesterday,talos"], HEAD, "row 0, column 'start_time': 'yesterday' is not an ISO 8601"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos", "c.parquet,r1,2026-03-01T08:00:00Z,talos"], HEAD,
     "row 1, column 'log'"),
    (["a.parquet,r/1,2026-03-01T08:00:00Z,talos"], HEAD, "row 0, column 'robot_id'"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,"], HEAD, "row 0: no robot"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos", "a.parquet,r2,2026-03-01T09:00:00Z,talos"], HEAD,
     "row 1, column 'log'"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos,fast"], HEAD + ",diff", "row 0, column 'diff'"),
    (["a.txt,r1,2026-03-01T08:00:00Z,talos"], HEAD, "row 0, column 'log'"),
])
def test_a_bad_manifest_is_one_line_naming_row_and_column(folder, rows, head, message):
    (folder / "a.txt").write_text("")
    with pytest.raises(InputError) as err:
        read_manifest(_manifest(folder, *rows, head=head))
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_folder_is_scanned_by_robot(tmp_path):
    for robot_id, name in (("r1", "x.parquet"), ("r2", "y.parquet")):
        (tmp_path / robot_id).mkdir()
        t = pa.array([datetime(2026, 3, 1, 8, tzinfo=UTC), datetime(2026, 3, 1, 9, tzinfo=UTC)],
                     pa.timestamp("ns", tz="UTC"))
        pq.write_table(pa.table({"time": t}), tmp_path / robot_id / name)
    entries = scan_folder(tmp_path, RobotSpec("talos"))
    assert [(e.robot_id, e.log.name, e.start_time.hour) for e in entries] == [("r1", "x.parquet", 8),
                                                                             ("r2", "y.parquet", 8)]
    pq.write_table(pa.table({"time": [0.0, 0.001]}), tmp_path / "r2" / "z.parquet")
    with pytest.raises(InputError, match="z.parquet: column 'time' holds no dates"):
        scan_folder(tmp_path, RobotSpec("talos"))

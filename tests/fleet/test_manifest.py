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
from wbfriction.pipeline.estimate_step import RobotSpec

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
    entries = scan_folder(tmp_path, RobotSpec("talos")).entries
    assert [(e.robot_id, e.log.name, e.start_time.hour) for e in entries] == [("r1", "x.parquet", 8),
                                                                             ("r2", "y.parquet", 8)]
    pq.write_table(pa.table({"time": [0.0, 0.001]}), tmp_path / "r2" / "z.parquet")
    with pytest.raises(InputError, match="z.parquet: column 'time' holds no dates"):
        scan_folder(tmp_path, RobotSpec("talos"))


def test_robot_ids_are_text_as_written(folder):
    """Issue 37: a CSV reader made '001' and '1' one robot, and '007' the float 7.0 once an id parsed as a
    float."""
    for name in ("c.parquet", "d.parquet", "e.parquet"):
        (folder / name).write_bytes(b"")
    path = _manifest(folder, "a.parquet,001,2026-03-01T08:00:00Z,talos", "b.csv,1,2026-03-01T08:00:00Z,talos",
                     "c.parquet,007,2026-03-01T08:00:00Z,talos", "d.parquet,2.5,2026-03-01T08:00:00Z,talos",
                     "e.parquet,1e3,2026-03-01T08:00:00Z,talos")
    assert [e.robot_id for e in read_manifest(path)] == ["001", "1", "007", "2.5", "1e3"]


def test_a_parquet_manifest_of_numeric_ids(folder):
    t = pa.array([datetime(2026, 3, 1, 8, tzinfo=UTC)], pa.timestamp("ns", tz="UTC"))
    for ids, expected in ((pa.array([7], pa.int64()), "7"), (pa.array([7.0]), None)):
        pq.write_table(pa.table({"log": ["a.parquet"], "robot_id": ids, "start_time": t, "robot": ["talos"]}),
                       folder / "m.parquet")
        if expected is not None:
            assert read_manifest(folder / "m.parquet")[0].robot_id == expected
        else:
            with pytest.raises(InputError, match="column 'robot_id' holds double values, not text"):
                read_manifest(folder / "m.parquet")


@pytest.mark.parametrize("rows, head, message", [
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos,panda.toml"], HEAD + ",config",
     "row 0, columns 'robot' and 'config': give a built-in robot ('talos') or a robot TOML ('panda.toml'), not both"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos", "b.csv,r1,2300-01-01T00:00:00Z,talos"], HEAD,
     "row 1, column 'start_time': 2300-01-01T00:00:00+00:00 is out of range (1970 to 2262)"),
    (["a.parquet,r1,2026-03-01T08:00:00Z,talos", "b.csv,r1,2026-03-01 08:00:00,talos"], HEAD,
     "row 1, column 'start_time': '2026-03-01 08:00:00' has no time zone"),
])
def test_conflicting_or_impossible_rows_are_refused(folder, rows, head, message):
    (folder / "panda.toml").write_text("")
    with pytest.raises(InputError) as err:
        read_manifest(_manifest(folder, *rows, head=head))
    assert message in str(err.value) and "\n" not in str(err.value)


def _dated_log(path: Path, hour: int = 8) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    t = pa.array([datetime(2026, 3, 1, hour, tzinfo=UTC)] * 2, pa.timestamp("ns", tz="UTC"))
    pq.write_table(pa.table({"time": t}), path)


def test_every_file_or_folder_a_scan_passes_over_is_said(tmp_path):
    """Issue 37: a scan skipped robot folders whose names fail the id pattern ('arm 1', 'armé') without a word,
    and a results folder inside the scanned one was read as a robot's logs by the next scan."""
    from wbfriction.logs.tables import with_metadata, write_table

    _dated_log(tmp_path / "r1" / "x.parquet")
    _dated_log(tmp_path / "arm 1" / "y.parquet")
    _dated_log(tmp_path / "armé" / "y.parquet")
    _dated_log(tmp_path / "loose.parquet")
    (tmp_path / "r1" / "notes.txt").write_text("")
    write_table(with_metadata(pa.table({"time": [0.0]}), {"estimate_options": {}}), tmp_path / "r1" / "f.parquet")
    _dated_log(tmp_path / "results" / "r1" / "k.parquet")
    _dated_log(tmp_path / ".hidden" / "z.parquet")
    scan = scan_folder(tmp_path, RobotSpec("talos"), exclude=[tmp_path / "results"])
    assert [(e.robot_id, e.log.name) for e in scan.entries] == [("r1", "x.parquet")]
    said = {p.path.relative_to(tmp_path).as_posix(): p.reason for p in scan.skipped}
    assert set(said) == {"arm 1", "armé", "loose.parquet", "r1/notes.txt", "r1/f.parquet", "results"}
    assert "not a robot id" in said["arm 1"] and "not a robot id" in said["armé"]
    assert "not in a robot's folder" in said["loose.parquet"] and "friction table" in said["r1/f.parquet"]
    assert said["results"] == "this batch's output, not logs"


def test_a_scanned_log_dated_beyond_2262_is_refused(tmp_path):
    (tmp_path / "r1").mkdir()
    t = pa.array([datetime(2300, 1, 1, tzinfo=UTC)], pa.timestamp("s", tz="UTC"))
    pq.write_table(pa.table({"time": t}), tmp_path / "r1" / "x.parquet")
    with pytest.raises(InputError, match=r"x.parquet: column 'time': 2300-01-01T00:00:00\+00:00 is out of range"):
        scan_folder(tmp_path, RobotSpec("talos"))


def test_a_start_time_is_a_datetime_to_the_microsecond_below(tmp_path):
    """Nanosecond stamps: the start time is a plain datetime floored to the microsecond, whatever is installed
    (Arrow gives pandas' Timestamp where pandas is, and a key made of it would differ by machine)."""
    from wbfriction.fleet.manifest import log_start_time

    ns = 1_460_034_856_877_161_999
    pq.write_table(pa.table({"time": pa.array([ns, ns + 5_000_000], pa.timestamp("ns", tz="UTC"))}),
                   tmp_path / "x.parquet")
    t = log_start_time(tmp_path / "x.parquet")
    assert type(t) is datetime and t == datetime(2016, 4, 7, 13, 14, 16, 877161, tzinfo=UTC)
    pq.write_table(pa.table({"log": ["x.parquet"], "robot_id": ["r"], "start_time": pa.array([ns], pa.timestamp(
        "ns", tz="UTC")), "robot": ["talos"]}), tmp_path / "m.parquet")
    (entry,) = read_manifest(tmp_path / "m.parquet")
    assert type(entry.start_time) is datetime and entry.start_time == t


def test_a_robot_id_too_long_for_a_folder_name_is_refused_before_any_log_runs(folder):
    """Issue 53: a 300-character robot id names a results folder no file system holds (``File name too long``,
    once the log had run): refused as the manifest is read, naming the row and column; 128 characters pass."""
    ok = "r" * 128
    assert read_manifest(_manifest(folder, f"a.parquet,{ok},2026-03-01T08:00:00Z,talos"))[0].robot_id == ok
    with pytest.raises(InputError, match=r"row 0, column 'robot_id': 'rrr.*' is not a robot id \(at most 128 "):
        read_manifest(_manifest(folder, f"a.parquet,{'r' * 300},2026-03-01T08:00:00Z,talos"))


def _dated_table() -> pa.Table:
    return pa.table({"time": pa.array([datetime(2026, 3, 1, 8, tzinfo=UTC)] * 2, pa.timestamp("ns", tz="UTC"))})


def test_a_scan_finds_every_registered_formats_logs(tmp_path):
    """Issue 65: the scan kept its own list of suffixes and passed over the built-in ``.npz`` logs as "not a log"; a
    log of any format the registry holds (every built-in table format, a toy registered in the test) is found, a
    ROS 2 bag (a file, or a folder: said once) is said as one (it needs a map a batch does not take), a file no
    format reads is said."""
    from toys.toy_format import Feather
    from wbfriction.logs import register_format, unregister_format
    from wbfriction.logs.tables import write_table

    logs = ["a.parquet", "b.pq", "c.csv", "d.npz", "e.feather"]  # HDF5 holds no dates: its logs need a manifest
    (tmp_path / "r1").mkdir()
    register_format(Feather())
    try:
        for name in logs:
            write_table(_dated_table(), tmp_path / "r1" / name)
        (tmp_path / "r1" / "run.mcap").write_bytes(b"")
        (tmp_path / "r1" / "bag").mkdir()
        (tmp_path / "r1" / "bag" / "metadata.yaml").write_text("")
        (tmp_path / "r1" / "bag" / "bag_0.db3").write_bytes(b"")
        (tmp_path / "r1" / "notes.txt").write_text("")
        scan = scan_folder(tmp_path, RobotSpec("talos"))
    finally:
        unregister_format("feather")
    assert [e.log.name for e in scan.entries] == logs
    said = {p.path.name: p.reason for p in scan.skipped}
    assert set(said) == {"run.mcap", "bag", "notes.txt"}
    assert all("ROS 2 bag" in said[n] and "map" in said[n] for n in ("run.mcap", "bag"))
    assert "NumPy (.npz)" in said["notes.txt"]  # the formats there are, from the registry

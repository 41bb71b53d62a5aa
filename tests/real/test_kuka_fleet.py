"""A fleet of real logs (issue 37): the three KUKA LWR4+ runs (../shared/real-data) as one robot's folder,
scanned, batched, read back by any Parquet reader, and batched again.

The runs' stamps are Unix epoch seconds: written as timestamps, they give each log its start time (April 2016),
so the folder needs no manifest. A copy of run 1 under another robot and a folder whose name is not a robot id
are the faults a real fleet folder has; there is no ground-truth friction, so what must hold is what the data
can check: the copy's numbers are run 1's, the start times are the recordings' own, a second batch computes
nothing, and runs 1 and 2 (one trajectory run twice, 29 min apart) agree where their torques do: the wrist
(joints 4-6, friction at 0.3 rad/s within 2-7 %, a fit that kept a load term read at the log's mean load; joints
0-3, whose torques differ by 0.2 N·m RMS between the runs, 9-44 %: the friction changed, README's KUKA section).
"""

from __future__ import annotations

import shutil
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from helpers import KUKA_CONFIG, KUKA_URDF, kuka_table, needs_kuka, run
from wbfriction.fleet.results import read_results

pytestmark = [needs_kuka, pytest.mark.slow]


def dated(table: pa.Table) -> pa.Table:
    """The log with its epoch stamps as UTC timestamps [ns] (rounded to the nanosecond)."""
    ns = np.round(table.column("time").to_numpy() * 1e9).astype(np.int64)
    return table.set_column(0, "time", pa.array(ns, pa.timestamp("ns", tz="UTC")))


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("kuka_fleet")
    for i in (1, 2, 3):
        (folder / "lwr4").mkdir(exist_ok=True)
        pq.write_table(dated(kuka_table(i)), folder / "lwr4" / f"run{i}.parquet")
    (folder / "lwr4-copy").mkdir()
    shutil.copy(folder / "lwr4" / "run1.parquet", folder / "lwr4-copy" / "run1.parquet")
    (folder / "lwr 4 (old)").mkdir()
    shutil.copy(folder / "lwr4" / "run3.parquet", folder / "lwr 4 (old)" / "run3.parquet")
    return folder


def test_a_folder_of_real_logs_is_batched_once_and_read_by_any_reader(fleet, tmp_path):
    results = tmp_path / "results"
    args = ("batch", fleet, "--urdf", KUKA_URDF, "--config", KUKA_CONFIG, "-o", results, "--serial")
    first = run(*args)
    assert first.returncode == 0, first.stderr
    assert f"skipped: {fleet / 'lwr 4 (old)'}: not a robot id" in first.stderr
    assert "has the same bytes as" in first.stderr and "4 logs processed (0 failed)" in first.stderr
    table = read_results(results).table
    assert sorted(set(table.column("robot_id").to_pylist())) == ["lwr4", "lwr4-copy"] and table.num_rows == 4 * 7
    for i in (1, 2, 3):  # each log's start time is its first stamp, as recorded
        rows = table.filter(pc.equal(table.column("log"), str(fleet / "lwr4" / f"run{i}.parquet")))
        first_ns = round(float(kuka_table(i).column("time")[0].as_py()) * 1e9)
        expected = datetime(1970, 1, 1, tzinfo=UTC) + timedelta(microseconds=first_ns // 1000)
        assert rows.column("start_time").cast(pa.int64())[0].as_py() == first_ns // 1000 * 1000
        assert expected.year == 2016 and expected.month == 4
    one, copy = (table.filter(pc.equal(table.column("log"), str(fleet / r / "run1.parquet")))
                 for r in ("lwr4", "lwr4-copy"))
    for name in ("F_c", "F_v", "tau_os", "f_at_0.3", "status"):
        assert one.column(name).to_pylist() == copy.column(name).to_pylist()  # the same bytes, the same numbers
    pandas = pytest.importorskip("pandas")
    assert len(pandas.read_parquet(results)) == 4 * 7
    again = run(*args)
    assert again.returncode == 0 and "0 logs processed (0 failed), 4 already done" in again.stderr, again.stderr
    by_run = {i: table.filter(pc.equal(table.column("log"), str(fleet / "lwr4" / f"run{i}.parquet"))).to_pylist()
              for i in (1, 2)}
    for a, b in zip(by_run[1], by_run[2]):  # the wrist repeats its torques: its friction must repeat too
        if a["joint"] in ("lwr_4_joint", "lwr_5_joint", "lwr_6_joint"):
            assert a["f_at_0.3"] == pytest.approx(b["f_at_0.3"], rel=0.10), (a, b)
    trends = run("trends", results, "-o", tmp_path / "trends.html")
    assert "none of the 14 robot joints could be tested" in trends.stderr, trends.stderr

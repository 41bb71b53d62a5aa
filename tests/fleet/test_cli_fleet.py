"""``wbfriction batch`` and ``wbfriction trends`` on bad input: one line naming what is at fault, exit status 2,
nothing written."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from helpers import assert_stages, said


def wbfriction(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wbfriction", *args], cwd=cwd, capture_output=True, text=True)


@pytest.mark.parametrize("manifest, message", [
    (None, "m.csv: file not found"),
    ("log,robot_id,start_time,robot\na.parquet,r1,2026-03-01T08:00:00,talos\n",
     "row 0, column 'start_time'"),
    ("log,robot_id,start_time,robot\nmissing.parquet,r1,2026-03-01T08:00:00Z,talos\n", "row 0, column 'log'"),
    ("log,robot_id,start_time,robot\na.parquet,r1,2026-03-01T08:00:00Z,atlas\n", "manifest row 0 (a.parquet): "),
])
def test_a_bad_manifest_is_one_line_and_nothing_is_written(tmp_path, manifest, message):
    (tmp_path / "a.parquet").write_bytes(b"")
    if manifest is not None:
        (tmp_path / "m.csv").write_text(manifest)
    res = wbfriction("batch", "m.csv", "-o", "results", cwd=tmp_path)
    assert res.returncode == 2 and message in res.stderr, res.stderr
    assert len(said(res.stderr)) == 1 and not (tmp_path / "results").exists()


def test_trends_need_results_and_an_html_page(tmp_path):
    (tmp_path / "empty").mkdir()
    res = wbfriction("trends", "empty", "-o", "t.html", cwd=tmp_path)
    assert res.returncode == 2 and "empty: no results" in res.stderr
    res = wbfriction("trends", "empty", "-o", "t.txt", cwd=tmp_path)
    assert res.returncode == 2 and "-o t.txt: a page is written as .html or .htm, not '.txt'" in res.stderr
    assert not (tmp_path / "t.html").exists()


@pytest.mark.parametrize("args, message", [
    (["--serial", "--scheduler", "tcp://127.0.0.1:8786"], "--scheduler and --serial: "),
    (["--serial", "--workers", "3"], "--workers: the local cluster's, not used with --serial"),
    (["--scheduler", "foo bar"], "--scheduler 'foo bar': not a scheduler's address"),
    (["--scheduler", "tcp://127.0.0.1:9"], "--scheduler tcp://127.0.0.1:9: no Dask scheduler answered within 10 s"),
    (["-o", "file.txt/results"], "-o file.txt/results: under file.txt, which is a file, not a folder"),
    (["-o", "file.txt"], "-o file.txt: not a folder"),
    (["--reference-temperature", "nan"], "--reference-temperature must be a joint's temperature in °C"),
    (["--terms", "load", "--max-harmonic", "6"], "--max-harmonic must be left out without the ripple term"),
])
def test_batch_faults_are_one_line_within_seconds(arm_fleet, tmp_path, args, message):
    """Issue 37: --scheduler was ignored with --serial; a wrong scheduler address raised OSError after 30 s or
    ValueError; -o under a file raised NotADirectoryError."""
    folder, _ = arm_fleet
    (tmp_path / "file.txt").write_text("x")
    argv = ["batch", str(folder / "manifest.csv"), *args]
    if "-o" not in args:
        argv += ["-o", "results"]
    res = wbfriction(*argv, cwd=tmp_path)
    assert res.returncode == 2 and message in res.stderr, res.stderr
    assert len(said(res.stderr)) == 1 and "Traceback" not in res.stderr
    assert not (tmp_path / "results").exists()
    assert (tmp_path / "file.txt").read_text() == "x"


def test_trends_say_what_they_leave_out(tmp_path, synthetic_results):
    """A truncated part (issue 37: ArrowInvalid) and a stray Parquet file (TypeError) are named, one line each;
    the trends of the rest are written."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    parts = synthetic_results(tmp_path / "results", 10)
    parts[3].write_bytes(parts[3].read_bytes()[:100])
    pq.write_table(pa.table({"x": [1]}), tmp_path / "results" / "r1" / "stray.parquet")
    res = wbfriction("trends", "results", "-o", "t.html", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "reading results", "testing", "writing t.html")  # piped: a line per stage (issue 67)
    left = [line for line in res.stderr.splitlines() if line.startswith("left out:")]
    assert len(left) == 2 and "unreadable" in left[0] and "stray.parquet: not a result" in left[1]
    assert "0 of 2 tested robot joints drifted" in res.stderr and (tmp_path / "t.html").exists()


def test_trends_that_cannot_test_say_so(tmp_path, synthetic_results):
    """Issue 37: '0 of 14 robot joints drifted' was printed when none could be tested."""
    synthetic_results(tmp_path / "results", 3)
    res = wbfriction("trends", "results", "-o", "t.html", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "reading results", "testing", "writing t.html")  # piped: a line per stage (issue 67)
    assert "none of the 2 robot joints could be tested (each has fewer than 8 usable logs)" in res.stderr


def test_an_absent_scheduler_is_said_within_its_timeout():
    """Issue 37: an address where no scheduler listens raised OSError after Dask's 30 s."""
    import time

    from wbfriction.exceptions import InputError
    from wbfriction.fleet.batch import connect

    start = time.monotonic()
    with pytest.raises(InputError, match="no Dask scheduler answered within 1 s"):
        connect("tcp://127.0.0.1:9", timeout=1.0)
    assert time.monotonic() - start < 10  # the timeout given, not Dask's 30 s


@pytest.mark.slow
def test_a_scheduler_that_goes_away_is_one_line(arm_fleet, tmp_path):
    """A real `dask scheduler` and `dask worker`, the scheduler killed once the first result is written: the
    batch ends with one line saying how much was done (status 1), instead of a reconnection traceback and a
    failure per log; the result written is whole, and the next run goes on from it."""
    import signal
    import socket
    import time

    folder, _ = arm_fleet
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    bin_dir = Path(sys.executable).parent
    scheduler = subprocess.Popen([bin_dir / "dask", "scheduler", "--port", str(port), "--dashboard-address", ":0"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    worker = subprocess.Popen([bin_dir / "dask", "worker", address, "--nworkers", "1", "--nthreads", "1"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        batch = subprocess.Popen([sys.executable, "-m", "wbfriction", "batch", str(folder / "manifest.csv"), "-o",
                                  "results", "--scheduler", address], cwd=tmp_path, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 300
        while not list((tmp_path / "results").glob("*/*.parquet")) and time.monotonic() < deadline:
            assert batch.poll() is None, batch.communicate()
            time.sleep(0.1)
        os.killpg(scheduler.pid, signal.SIGKILL)
        _, err = batch.communicate(timeout=120)
    finally:
        for p in (scheduler, worker):
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    lines = said(err)
    assert batch.returncode == 1 and len(lines) == 1, err
    assert f"error: the Dask scheduler {address} went away: " in lines[0] and "run the batch again" in lines[0]
    from wbfriction.fleet.results import read_parts

    assert [p.problem for p in read_parts(tmp_path / "results")] == [""] * len(read_parts(tmp_path / "results"))


def test_trends_of_logs_at_one_start_time_say_so(tmp_path, synthetic_results):
    """Issue 53, classes 8 and 12: ten logs listed at one start time gave 'fewer than 8 usable logs' and no word of
    the shared time. One note says the start time holds several logs, and the summary says what is short."""
    import pyarrow.parquet as pq

    from wbfriction.fleet.results import write_part

    parts = synthetic_results(tmp_path / "results", 10)
    first = pq.read_table(parts[0]).column("start_time")
    for part in parts:
        table = pq.read_table(part).replace_schema_metadata(None)
        table = table.set_column(table.schema.get_field_index("start_time"), "start_time", first)
        part.unlink()
        write_part(tmp_path / "results", table)
    res = wbfriction("trends", "results", "-o", "t.html", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "reading results", "testing", "writing t.html")  # piped: a line per stage (issue 67)
    notes = [line for line in res.stderr.splitlines() if line.startswith("note:")]
    assert len(notes) == 1 and notes[0].startswith("note: robot r1: 1 start time holds the results of several logs")
    assert "none of the 2 robot joints could be tested (each has its 10 usable logs at 1 start time" in res.stderr

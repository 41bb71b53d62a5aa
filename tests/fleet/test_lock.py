"""One batch at a time into a results folder (issue 53, class 17): two concurrent batches of the same logs with other
options left two results per log. The second is refused with one line; a lock its batch no longer holds (killed) is
taken over; the lock is gone when a batch ends."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helpers import said
from wbfriction.exceptions import InputError
from wbfriction.fleet.batch import run_batch
from wbfriction.fleet.lock import lock_path, results_lock
from wbfriction.fleet.manifest import read_manifest


def _start(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "wbfriction", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def test_a_second_batch_into_running_results_is_refused_with_one_line(arm_fleet, tmp_path):
    folder, _ = arm_fleet
    manifest = str(folder / "manifest.csv")
    first = _start("batch", manifest, "-o", "results", "--serial", cwd=tmp_path)
    deadline = time.monotonic() + 60
    while not lock_path(tmp_path / "results").exists() and first.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert first.poll() is None, "the first batch ended before the second could start"
    second = subprocess.run([sys.executable, "-m", "wbfriction", "batch", manifest, "-o", "results", "--serial",
                             "--model", "coulomb-viscous"], cwd=tmp_path, capture_output=True, text=True)
    assert second.returncode == 2, second.stderr
    assert len(said(second.stderr)) == 1 and "Traceback" not in second.stderr
    assert f"results: another batch is writing these results (process {first.pid} on {socket.gethostname()}, " \
           "since " in second.stderr, second.stderr
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    assert len(list((tmp_path / "results").glob("*/*.parquet"))) == 3  # one result per log, the first batch's
    assert not lock_path(tmp_path / "results").exists()


def test_a_lock_whose_batch_ended_is_taken_over(arm_fleet, tmp_path):
    """A lock file left by a batch killed with SIGKILL (its process gone, its flock with it) stops nothing."""
    folder, _ = arm_fleet
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    results = tmp_path / "results"
    results.mkdir()
    lock_path(results).write_text(json.dumps({"pid": gone.pid, "host": socket.gethostname(), "started": "then"}))
    summary = run_batch(read_manifest(folder / "manifest.csv")[:1], results, engine="serial")
    assert summary.processed == 1 and not summary.failed
    assert os.listdir(results) == ["arm-1"]  # the lock removed


def test_a_held_lock_refuses_and_a_failed_start_leaves_no_folder(arm_fleet, tmp_path):
    folder, _ = arm_fleet
    entries = read_manifest(folder / "manifest.csv")[:1]
    with results_lock(tmp_path / "results"):
        with pytest.raises(InputError, match=f"another batch is writing these results \\(process {os.getpid()} "):
            run_batch(entries, tmp_path / "results", engine="serial")
    assert os.listdir(tmp_path / "results") == []  # the lock removed
    with pytest.raises(InputError, match="--workers must be at least 1"):
        run_batch(entries, tmp_path / "other", workers=0)
    with pytest.raises(InputError, match="--scheduler 'foo bar': not a scheduler's address"):
        run_batch(entries, tmp_path / "other", scheduler="foo bar")
    assert not (tmp_path / "other").exists()

"""Long logs in chunks: the same numbers as the whole-log estimate, rows named as in the file,
outputs whole or not at all, and the same bytes on a re-run."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import read_friction_table
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import write_log
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import read_table, write_table
from wbfriction.pipeline.chunks import CHUNKS_PER_WORKER, CONTEXT, Chunking, plan_chunks
from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
from wbfriction.signals.options import FilterOptions


@settings(max_examples=60, deadline=None)
@given(flags=st.lists(st.sampled_from([(1, 0), (1, 1), (0, 1)]), min_size=1, max_size=400),
       runs=st.integers(1, 30), rows=st.integers(5, 200))
def test_chunks_cover_the_log_and_cut_at_contact_changes(flags, runs, rows):
    contact = np.repeat(np.array(flags, dtype=bool), runs, axis=0)
    chunking = Chunking(rows=rows, overlap=7)
    chunks = plan_chunks(contact, chunking)
    assert chunks[0].start == 0 and chunks[-1].stop == len(contact)
    n = len(contact)
    for a, b in zip(chunks[:-1], chunks[1:]):
        assert a.stop == b.start
        changed = bool(np.any(contact[b.start] != contact[b.start - 1]))
        context = CONTEXT if changed else 7
        assert b.read_start == max(0, b.start - context) and a.read_stop == min(n, b.start + context)
        if not changed:  # a forced cut only where no contact change comes within twice the length
            window = contact[a.start:a.start + 2 * rows + 1]
            assert not np.any(np.any(window[1:] != window[:-1], axis=1)[rows - 1:])
    for c in chunks:
        assert c.read_start <= c.start < c.stop <= c.read_stop


@pytest.fixture(scope="module")
def walk_file(talos, combined_walk, tmp_path_factory):
    path = tmp_path_factory.mktemp("chunked") / "walk.parquet"
    write_log(combined_walk.log, talos, path)
    return path


@pytest.mark.parametrize("diff,workers", [("central", 1), ("savgol", 2), ("butterworth", 1)])
def test_chunked_estimate_equals_the_whole_log_estimate(talos, walk_file, tmp_path, diff, workers):
    opts = EstimateOptions(diff=diff, filtering=FilterOptions(cutoff=20.0))
    result = estimate_file(RobotSpec("talos"), walk_file, tmp_path / "f.parquet", opts,
                           chunking=Chunking(rows=1500, workers=workers), companion=True)
    assert result.chunks > 5 and result.forced_cuts == 0
    chunked = read_friction_table(read_table(tmp_path / "f.parquet"))
    whole = estimate_log(talos, read_log(walk_file, talos), opts, companion=True)
    for name in ("tau_f", "qd", "qdd", "delta_qdd", "companion_delta_qdd"):
        a, b = getattr(chunked, name), getattr(whole, name)
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
        assert np.nanmax(np.abs(a - b)) <= 1e-9, name
    np.testing.assert_array_equal(chunked.valid, whole.valid)
    np.testing.assert_array_equal(chunked.phase, whole.phase)


def test_rows_are_named_as_in_the_file_and_nothing_is_written(talos, combined_walk, walk_file, tmp_path):
    out = tmp_path / "f.parquet"
    out.write_bytes(b"previous result")
    table = pq.read_table(walk_file)
    col = table.column_names.index("q.leg_left_4_joint")
    values = table.column(col).to_numpy().copy()
    values[9000] = np.nan  # in a late chunk: earlier chunks are estimated before it is read
    bad = tmp_path / "bad.parquet"
    write_table(table.set_column(col, "q.leg_left_4_joint", pa.array(values)), bad)
    with pytest.raises(InputError, match="column 'q.leg_left_4_joint' has a non-finite value .* at row 9000"):
        estimate_file(RobotSpec("talos"), bad, out, chunking=Chunking(rows=1500, workers=1))
    assert out.read_bytes() == b"previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.parquet", "f.parquet"]


def test_same_input_same_bytes(walk_file, tmp_path):
    for name in ("a.parquet", "b.parquet"):
        estimate_file(RobotSpec("talos"), walk_file, tmp_path / name, chunking=Chunking(rows=4000, workers=1))
    assert (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b.parquet").read_bytes()


def test_a_run_stopped_midway_leaves_the_previous_output(walk_file, tmp_path):
    """SIGTERM while chunks are being written: the previous result stays, no partial file is left."""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "f.parquet"
    out.write_bytes(b"previous result")
    proc = subprocess.Popen([sys.executable, "-m", "wbfriction", "estimate", str(walk_file), "-o", str(out),
                             "--chunk-rows", "300", "--workers", "1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".f.parquet.*.tmp*")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert proc.poll() is None, "finished before it could be stopped"
    time.sleep(0.5)  # a few chunks written
    os.kill(proc.pid, signal.SIGTERM)
    assert proc.wait(60) == 128 + signal.SIGTERM
    assert out.read_bytes() == b"previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.parquet"]


def test_every_log_format_is_chunked_to_the_same_table(talos, combined_walk, walk_file, tmp_path):
    """CSV and both HDF5 layouts, read chunk by chunk, give the Parquet log's friction table."""
    import h5py

    from wbfriction.logs.formats.hdf5 import read_hdf5

    table = pq.read_table(walk_file)
    write_table(table, tmp_path / "walk.csv")
    write_table(table, tmp_path / "walk.h5")
    with h5py.File(tmp_path / "walk2d.h5", "w") as f:
        ds = f.create_dataset("log", data=np.column_stack([table.column(c).to_numpy() for c in table.column_names]))
        ds.attrs["names"] = table.column_names
    part = read_hdf5(tmp_path / "walk2d.h5", columns=["time", "q.leg_left_4_joint"], start=1000, stop=1200)
    assert part.column_names == ["time", "q.leg_left_4_joint"]
    np.testing.assert_array_equal(part.column("q.leg_left_4_joint").to_numpy(),
                                  table.column("q.leg_left_4_joint").to_numpy()[1000:1200])
    chunking = Chunking(rows=1500, workers=1)
    estimate_file(RobotSpec("talos"), walk_file, tmp_path / "ref.parquet", chunking=chunking)
    ref = pq.read_table(tmp_path / "ref.parquet")
    for name in ("walk.csv", "walk.h5", "walk2d.h5"):
        estimate_file(RobotSpec("talos"), tmp_path / name, tmp_path / "f.parquet", chunking=chunking)
        got = pq.read_table(tmp_path / "f.parquet")
        for c in ("tau_f.leg_left_4_joint", "delta_qdd.leg_right_1_joint", "valid.leg_right_3_joint", "phase"):
            np.testing.assert_array_equal(got.column(c).to_numpy(zero_copy_only=False),
                                          ref.column(c).to_numpy(zero_copy_only=False), err_msg=(name, c))


def test_workers_start_only_when_each_gets_enough_chunks(walk_file, tmp_path, monkeypatch):
    """Two workers are started for a log of at least 4 chunks each, none for fewer (their start-up would
    cost more than they save); the friction table is the same either way."""
    import wbfriction.pipeline.estimate_step as module

    started: list[int] = []
    real = module.process_pool
    monkeypatch.setattr(module, "process_pool", lambda workers, *a: started.append(workers) or real(workers, *a))
    opts = EstimateOptions(diff="central")
    few = estimate_file(RobotSpec("talos"), walk_file, tmp_path / "few.parquet", opts,
                        chunking=Chunking(rows=4000, workers=2))
    assert few.chunks < 2 * CHUNKS_PER_WORKER and started == []
    many = estimate_file(RobotSpec("talos"), walk_file, tmp_path / "many.parquet", opts,
                         chunking=Chunking(rows=1000, workers=2))
    assert many.chunks >= 2 * CHUNKS_PER_WORKER and started == [2]
    a, b = (read_friction_table(read_table(tmp_path / f"{n}.parquet")) for n in ("few", "many"))
    for name in ("tau_f", "delta_qdd", "qd"):
        np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0, atol=1e-9, err_msg=name)
    np.testing.assert_array_equal(a.valid, b.valid)


def test_the_file_and_the_log_decide_through_one_function(talos, walk_file, tmp_path, monkeypatch):
    """``estimate_file`` and ``estimate_log`` decide the differentiation, the route and the noise once per log
    through :func:`~wbfriction.friction.decision.decide_log` (issue 54): on a log of one stretch no longer than
    the rows a file's plan reads, the same positions, the same decision, the same metadata; only what the two
    hand it differs (the noise's rows, the rows bounding the route's windows), said by the call."""
    import wbfriction.friction.decision as decision
    import wbfriction.friction.estimate as in_memory
    import wbfriction.pipeline.estimate_step as from_file
    from wbfriction.logs.clock import ROUGHNESS_ROWS

    calls: list[dict] = []

    def spy(robot, options, positions, dt, **kw):
        calls.append({"rows": None if positions is None else len(positions), **kw})
        return decision.decide_log(robot, options, positions, dt, **kw)

    for module in (in_memory, from_file):
        monkeypatch.setattr(module, "decide_log", spy)
    log = read_log(walk_file, talos)
    assert len(log) <= ROUGHNESS_ROWS and log.segments in (None, [(0, len(log))])
    whole = estimate_log(talos, log)
    estimate_file(RobotSpec("talos"), walk_file, tmp_path / "f.parquet", chunking=Chunking(rows=4000, workers=1))
    chunked = read_friction_table(read_table(tmp_path / "f.parquet"))
    assert [c.get("route_rows") for c in calls] == [len(log), None]  # the whole log's rows; the file's: its first ones
    assert calls[0]["rows"] == calls[1]["rows"] == len(log)
    for key in ("differentiation", "route", "noise"):  # as JSON: the table's metadata is
        assert chunked.metadata[key] == json.loads(json.dumps(whole.metadata[key])), key

"""An output the system refuses to write is one line, exit status 1, the previous output kept (issue 37, item 8).

A full disk is a file size limit here (``ulimit -f``: RLIMIT_FSIZE in the command's process; Python ignores
SIGXFSZ, so the write fails with EFBIG where a full disk fails with ENOSPC: the same path through
:func:`~wbfriction.logs.tables.write_atomic`). Before issue 37 each of these was a traceback. The mapping of
every OS error (ENOSPC, EROFS, EACCES, ENOTDIR, ...) is tested where it arises, in ``tests/logs/test_write_atomic.py``.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

from helpers import run_cli, said

LIMIT = 1024
"""Bytes a file of the command may grow to: below every output written here, above nothing it reads."""


def _limited(*args, cwd: Path) -> subprocess.CompletedProcess:
    """``wbfriction ARGS`` in a process whose files cannot grow beyond :data:`LIMIT` bytes."""
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))

    return subprocess.run([sys.executable, "-m", "wbfriction", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, preexec_fn=limit, env=dict(os.environ, COLUMNS="200", PYTHONDONTWRITEBYTECODE="1"))


def _refused_write(res: subprocess.CompletedProcess, folder: Path, out: Path) -> None:
    """One line on standard error naming ``out`` and the OS's reason, status 1, no traceback, the previous
    output byte for byte, and no file other than those that were there."""
    lines = said(res.stderr)
    assert res.returncode == 1, res.stderr
    assert lines == [f"error: {out.name}: cannot be written: [Errno 27] File too large (the previous file is kept)"], \
        res.stderr
    assert out.read_bytes() == b"previous " + out.name.encode()


@pytest.fixture(scope="module")
def arm(tmp_path_factory) -> Path:
    """A folder with a 3 s Panda log, its friction table and its parameters, as the commands write them."""
    from wbfriction.fit.options import FitOptions
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.pipeline.chunks import Chunking
    from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
    from wbfriction.pipeline.fit_step import fit_file
    from wbfriction.pipeline.provenance import log_provenance
    from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

    folder = tmp_path_factory.mktemp("write_errors")
    robot = load_robot("panda")
    sim = simulate_arm(robot, default_arm_friction(robot), options=ArmOptions(duration=3.0, seed=1))
    write_table(sim.table, folder / "arm.parquet")
    estimate_file(RobotSpec("panda"), folder / "arm.parquet", folder / "friction.parquet",
                  chunking=Chunking(workers=1),
                  extra_metadata={"provenance": log_provenance(folder / "arm.parquet", robot)})
    fit_file(folder / "friction.parquet", folder / "params.json", FitOptions(model="coulomb-viscous"))
    renamed = [n.replace("panda_joint1", "J1") for n in sim.table.column_names]  # a log read through a --map
    write_table(sim.table.rename_columns(renamed), folder / "renamed.parquet")
    (folder / "map.toml").write_text('[joint_states]\nrename = { J1 = "panda_joint1" }\n')
    return folder


INPUTS = ("arm.parquet", "friction.parquet", "params.json", "renamed.parquet", "map.toml")


@pytest.mark.parametrize("command", ["estimate", "estimate --map", "fit", "report"])
def test_a_full_disk_is_one_line_and_keeps_the_previous_output(arm, tmp_path, command):
    """With --map, the log is first streamed into a temporary Parquet log beside the output (as large as the
    log): the write that fails first, named as the output it was for."""
    folder = tmp_path
    for name in INPUTS:
        (folder / name).write_bytes((arm / name).read_bytes())
    out, args = {
        "estimate": ("out.parquet", ("arm.parquet", "--robot", "panda", "--workers", "1")),
        "estimate --map": ("out.parquet", ("renamed.parquet", "--map", "map.toml", "--robot", "panda")),
        "fit": ("out.json", ("friction.parquet", "--model", "coulomb-viscous", "--workers", "1")),
        "report": ("out.html", ("friction.parquet", "--params", "params.json")),
    }[command]
    (folder / out).write_bytes(b"previous " + out.encode())
    before = sorted(p.name for p in folder.iterdir())
    res = _limited(command.split()[0], *args, "-o", out, cwd=folder)
    _refused_write(res, folder, folder / out)
    assert sorted(p.name for p in folder.iterdir()) == before
    for name in INPUTS:
        assert (folder / name).read_bytes() == (arm / name).read_bytes()  # inputs untouched


def test_trends_on_a_full_disk_is_one_line_and_keeps_the_previous_page(arm, tmp_path):
    """A results folder of two logs of one arm (``batch --serial``), then ``trends`` with its files limited."""
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

    robot = load_robot("panda")
    (tmp_path / "a1.parquet").write_bytes((arm / "arm.parquet").read_bytes())
    write_table(simulate_arm(robot, default_arm_friction(robot), options=ArmOptions(duration=3.0, seed=2)).table,
                tmp_path / "a2.parquet")
    (tmp_path / "manifest.csv").write_text("log,robot_id,start_time,robot\n"
                                           "a1.parquet,arm-1,2026-03-01T08:00:00+00:00,panda\n"
                                           "a2.parquet,arm-1,2026-03-02T08:00:00+00:00,panda\n")
    done = subprocess.run([sys.executable, "-m", "wbfriction", "batch", "manifest.csv", "-o", "results", "--serial",
                           "--model", "coulomb-viscous"], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    (tmp_path / "trends.html").write_bytes(b"previous trends.html")
    before = sorted(p.name for p in tmp_path.iterdir())
    _refused_write(_limited("trends", "results", "-o", "trends.html", cwd=tmp_path), tmp_path, tmp_path / "trends.html")
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_an_output_folder_under_a_file_is_one_line(tmp_path, capsys):
    """A study's output folder under a file (NotADirectoryError where the folder is made): one line, status 1,
    before any walk is simulated."""
    (tmp_path / "notes.txt").write_bytes(b"a file")
    code, err = run_cli(capsys, "demo", "--steps", "1", "-o", tmp_path / "notes.txt" / "demo")
    lines = said(err)
    assert code == 1 and lines == [f"error: {tmp_path}/notes.txt/demo: cannot be written: [Errno 20] Not a "
                                   "directory (nothing written)"], err
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


@pytest.mark.parametrize("engine", [("--serial",), ()], ids=["serial", "dask"])
def test_a_batch_on_a_full_disk_stops_with_one_line(arm, tmp_path, engine):
    """A batch whose results cannot be written (the disk full) stops at once with the one line, status 1,
    instead of recording every log as failed (a failure record could not be written either)."""
    (tmp_path / "a1.parquet").write_bytes((arm / "arm.parquet").read_bytes())
    (tmp_path / "manifest.csv").write_text("log,robot_id,start_time,robot\n"
                                           "a1.parquet,arm-1,2026-03-01T08:00:00+00:00,panda\n")
    res = _limited("batch", "manifest.csv", "-o", "results", *engine, cwd=tmp_path)
    lines = said(res.stderr)
    assert res.returncode == 1 and len(lines) == 1, res.stderr
    assert lines[0].startswith("error: ") and "cannot be written: [Errno 27] File too large" in lines[0]
    assert not list((tmp_path / "results").rglob("*.parquet")) and not (tmp_path / "results-failed").exists()

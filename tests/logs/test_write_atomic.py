"""Outputs written whole or not at all, with the umask's mode; the temporary files of killed writers
removed by a later write, never those of a live one (issue 21, classes 3 and 9)."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from wbfriction.logs.tables import (
    TableFile,
    remove_stale_temporaries,
    scratch_folder,
    write_atomic,
    write_json,
    write_table,
    write_tables,
)

TABLE = pa.table({"time": np.arange(10) * 1e-3, "a": np.arange(10.0)})
WRITERS = {
    "json": lambda path: write_json(path.with_suffix(".json"), {"a": 1}),
    "parquet": lambda path: write_table(TABLE, path.with_suffix(".parquet")),
    "csv": lambda path: write_table(TABLE, path.with_suffix(".csv")),
    "hdf5": lambda path: write_table(TABLE, path.with_suffix(".h5")),
    "streamed": lambda path: write_tables(path.with_suffix(".parquet"), [TABLE, TABLE]),
}


@pytest.mark.parametrize("writer", WRITERS)
@pytest.mark.parametrize(("umask", "mode"), [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)],
                         ids=["umask 022", "umask 077", "umask 002"])
def test_an_output_has_the_mode_the_umask_allows(tmp_path, writer, umask, mode):
    old = os.umask(umask)
    try:
        WRITERS[writer](tmp_path / "out")
    finally:
        os.umask(old)
    (out,) = tmp_path.iterdir()
    assert out.stat().st_mode & 0o777 == mode


class Stop(BaseException):
    """Like an interruption: not an Exception."""


@pytest.mark.parametrize("error", [ValueError, Stop])
def test_a_write_that_fails_keeps_the_previous_output_and_leaves_nothing(tmp_path, error):
    out = tmp_path / "t.parquet"
    out.write_bytes(b"previous")

    def write(tmp: Path) -> None:
        tmp.write_bytes(b"half")
        raise error

    with pytest.raises(error):
        write_atomic(out, write)
    assert [p.name for p in tmp_path.iterdir()] == ["t.parquet"] and out.read_bytes() == b"previous"


WRITER = """
import sys, time
from pathlib import Path
from wbfriction.logs.tables import write_atomic
def write(tmp):
    tmp.write_bytes(b"half")
    print(tmp.name, flush=True)
    time.sleep(60)
write_atomic(Path(sys.argv[1]), write)
"""


def _writing(path: Path) -> tuple[subprocess.Popen, str]:
    """A process in the middle of writing ``path``, and the name of its temporary file."""
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(path)], stdout=subprocess.PIPE, text=True)
    return proc, proc.stdout.readline().strip()


def test_a_killed_writers_file_is_removed_by_the_next_write_a_live_ones_kept(tmp_path):
    """Two writers in one folder; one is killed (SIGKILL: nothing of it runs after). The next
    write removes the killed one's temporary file; the live one's, another machine's of the same
    process id, and files of other tools stay."""
    killed, killed_tmp = _writing(tmp_path / "a.parquet")
    live, live_tmp = _writing(tmp_path / "b.csv")
    try:
        killed.send_signal(signal.SIGKILL)
        killed.wait(10)
        assert killed_tmp.startswith(".a.parquet.") and f"-{killed.pid}-" in killed_tmp
        elsewhere = re.sub(r"wbfriction-[A-Za-z0-9]*-", "wbfriction-elsewhere-", killed_tmp)
        assert elsewhere != killed_tmp
        (tmp_path / elsewhere).write_bytes(b"another machine's")
        others = [".a.parquet.abc123.tmp.parquet", ".wbfriction-x1y2z3ab", f".notes.{killed.pid}.tmp"]
        for name in others:
            (tmp_path / name).write_bytes(b"")
        assert (tmp_path / killed_tmp).exists() and (tmp_path / live_tmp).exists()
        write_json(tmp_path / "c.json", {})
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["c.json", live_tmp, elsewhere, *others])
        assert (tmp_path / live_tmp).read_bytes() == b"half"
    finally:
        live.kill()
        live.wait(10)
    assert remove_stale_temporaries(tmp_path) == [tmp_path / live_tmp]  # once its writer is gone


def test_a_scratch_folder_is_removed_on_leaving_and_a_killed_ones_on_entering(tmp_path):
    with pytest.raises(Stop):
        with scratch_folder(tmp_path) as folder:
            (folder / "log.parquet").write_bytes(b"x")
            raise Stop
    assert list(tmp_path.iterdir()) == []
    script = "import sys, time\nfrom wbfriction.logs.tables import scratch_folder\n" \
             "with scratch_folder(sys.argv[1]) as f:\n    print(f.name, flush=True)\n    time.sleep(60)\n"
    proc = subprocess.Popen([sys.executable, "-c", script, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    name = proc.stdout.readline().strip()
    (tmp_path / name / "log.parquet").write_bytes(b"x")
    proc.kill()
    proc.wait(10)
    assert [p.name for p in tmp_path.iterdir()] == [name]
    with scratch_folder(tmp_path) as folder:
        write_table(TABLE, folder / "t.parquet")
        assert [p.name for p in tmp_path.iterdir()] == [folder.name]
        assert TableFile(folder / "t.parquet").read().equals(TABLE)
    assert list(tmp_path.iterdir()) == []

"""Outputs written whole or not at all, with the umask's mode; the temporary files of killed writers
removed by a later write, never those of a live one (issue 21, classes 3 and 9)."""

from __future__ import annotations

import errno
import json
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from wbfriction.exceptions import OutputError
from wbfriction.logs.tables import (
    TableFile,
    make_folder,
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


# ------------------------------------------------ issue 37: an output the system refuses is one OutputError
REFUSED = {errno.ENOSPC: "disk full", errno.EDQUOT: "quota", errno.EFBIG: "ulimit -f", errno.EACCES: "not writable",
           errno.EROFS: "read-only", errno.EIO: "device"}


def _expected(out: Path, number: int, kept: bool) -> str:
    return (f"{out}: cannot be written: [Errno {number}] {os.strerror(number)} "
            f"({'the previous file is kept' if kept else 'nothing written'})")


@pytest.mark.parametrize("number", REFUSED, ids=REFUSED.values())
@pytest.mark.parametrize("where", ["write", "rename"])
@pytest.mark.parametrize("previous", [True, False], ids=["previous", "none"])
def test_an_os_error_while_writing_is_one_output_error(tmp_path, monkeypatch, number, where, previous):
    """Whether the data's write or the rename fails (an injected OSError with the OS's number and, as the
    OS gives it, the temporary file's name): one OutputError naming the output, not the temporary file,
    with the OS's reason; the previous file byte for byte, no temporary file left."""
    out = tmp_path / "t.parquet"
    if previous:
        out.write_bytes(b"previous")

    def write(tmp: Path) -> None:
        tmp.write_bytes(b"half")
        if where == "write":
            raise OSError(number, os.strerror(number))

    def refuse(src, dst):
        raise OSError(number, os.strerror(number), src, None, dst)

    if where == "rename":
        monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(OutputError) as info:
        write_atomic(out, write)
    e = info.value
    assert (e.path, e.errno, e.kept) == (str(out), number, previous)
    assert str(e) == _expected(out, number, previous)
    assert [p.name for p in tmp_path.iterdir()] == (["t.parquet"] if previous else [])
    assert not previous or out.read_bytes() == b"previous"
    again = pickle.loads(pickle.dumps(e))  # crosses process pools with its data
    assert (type(again), again.path, again.errno, again.reason, again.kept, str(again)) == \
        (OutputError, e.path, e.errno, e.reason, e.kept, str(e))


def test_an_input_that_fails_while_an_output_is_written_is_not_the_outputs_fault(tmp_path):
    """An OSError naming another file (an input read while the output is streamed) is raised as it is."""
    out = tmp_path / "t.parquet"
    elsewhere = tmp_path / "in" / "log.parquet"

    def write(tmp: Path) -> None:
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(elsewhere))

    with pytest.raises(PermissionError) as info:
        write_atomic(out, write)
    assert not isinstance(info.value, OutputError) and info.value.filename == str(elsewhere)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("writer", WRITERS)
def test_an_output_under_a_file_is_one_output_error(tmp_path, writer):
    (tmp_path / "notes.txt").write_bytes(b"a file")
    with pytest.raises(OutputError) as info:
        WRITERS[writer](tmp_path / "notes.txt" / "out")
    assert info.value.errno == errno.ENOTDIR and "notes.txt/out." in info.value.path
    assert str(info.value).endswith(": cannot be written: [Errno 20] Not a directory (nothing written)")
    with pytest.raises(OutputError, match=r"notes.txt/a/b: cannot be written: \[Errno 20\] Not a directory"):
        make_folder(tmp_path / "notes.txt" / "a" / "b")
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


OVER_LIMIT = """
import json, os, resource, sys
from pathlib import Path
import numpy as np
import pyarrow as pa
from wbfriction.exceptions import OutputError
from wbfriction.logs.tables import write_atomic, write_json, write_table, write_tables
import matplotlib.pyplot as plt

folder = Path(sys.argv[1])
big = pa.table({"time": np.arange(20000) * 1e-3, "a": np.random.default_rng(0).normal(size=20000)})
fig = plt.figure(figsize=(8, 6))
plt.plot(np.random.default_rng(1).normal(size=5000))
writers = {
    "out.json": lambda p: write_json(p, {"a": list(range(5000))}),
    "out.parquet": lambda p: write_table(big, p),
    "out.csv": lambda p: write_table(big, p),
    "out.h5": lambda p: write_table(big, p),
    "streamed.parquet": lambda p: write_tables(p, [big, big]),
    "streamed.csv": lambda p: write_tables(p, [big, big]),
    "out.png": lambda p: write_atomic(p, lambda tmp: fig.savefig(tmp, format="png")),
}
resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))
found = {}
for name, write in writers.items():
    try:
        write(folder / name)
        found[name] = None
    except OutputError as exc:
        found[name] = [exc.path, exc.errno, str(exc)]
print(json.dumps(found))
"""


def test_a_file_over_ulimit_f_is_one_output_error_from_every_writer(tmp_path):
    """A real EFBIG (``ulimit -f``: Python ignores SIGXFSZ, so the write fails) from every writer: pyarrow's
    Parquet and CSV, streamed or whole, h5py (which words it as a RuntimeError), matplotlib, plain text.
    Each previous file is kept byte for byte, no temporary file left."""
    names = ["out.json", "out.parquet", "out.csv", "out.h5", "streamed.parquet", "streamed.csv", "out.png"]
    for name in names:
        (tmp_path / name).write_bytes(b"previous " + name.encode())
    res = subprocess.run([sys.executable, "-c", OVER_LIMIT, str(tmp_path)], capture_output=True, text=True,
                         env=dict(os.environ, MPLBACKEND="Agg"))
    assert res.returncode == 0, res.stderr
    found = json.loads(res.stdout)
    for name in names:
        out = tmp_path / name
        assert found[name] == [str(out), errno.EFBIG, _expected(out, errno.EFBIG, True)], name
        assert out.read_bytes() == b"previous " + name.encode()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)


ON_SMALL_DISK = """
import json, subprocess, sys
from pathlib import Path
import numpy as np
import pyarrow as pa
from wbfriction.exceptions import OutputError
from wbfriction.logs.tables import write_table, write_tables

folder = Path(sys.argv[1])
if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(folder)]).returncode:
    sys.exit(77)
out = folder / "out.parquet"
out.write_bytes(b"previous")
big = pa.table({"a": np.random.default_rng(0).normal(size=100_000)})
found = {}
for case, write in (("full", lambda: write_table(big, out)), ("full, streamed", lambda: write_tables(out, [big] * 3))):
    try:
        write()
    except OutputError as exc:
        found[case] = [exc.errno, str(exc)]
subprocess.run(["mount", "-o", "remount,ro", str(folder)], check=True)
for case, write in (("read-only", lambda: write_table(big.slice(0, 10), out)),
                    ("read-only, streamed", lambda: write_tables(out, [big.slice(0, 10)]))):
    try:
        write()
    except OutputError as exc:
        found[case] = [exc.errno, str(exc)]
found["listing"] = sorted(p.name for p in folder.iterdir())
found["previous"] = out.read_text()
print(json.dumps(found))
"""


def test_a_full_disk_and_a_read_only_folder_are_one_output_error(tmp_path):
    """A real ENOSPC (a 256 KiB tmpfs) and a real EROFS (remounted read-only; as root, a folder's mode
    would not stop the write), in a mount namespace of their own: the previous file kept, nothing left."""
    if shutil.which("unshare") is None or subprocess.run(["unshare", "--mount", "true"]).returncode:
        pytest.skip("no mount namespace here (unshare needs root or user namespaces)")
    res = subprocess.run(["unshare", "--mount", "--propagation", "private", sys.executable, "-c", ON_SMALL_DISK,
                          str(tmp_path)], capture_output=True, text=True)
    if res.returncode == 77:
        pytest.skip("tmpfs cannot be mounted here")
    assert res.returncode == 0, res.stderr
    found = json.loads(res.stdout)
    out = tmp_path / "out.parquet"
    for case, number in (("full", errno.ENOSPC), ("full, streamed", errno.ENOSPC), ("read-only", errno.EROFS),
                         ("read-only, streamed", errno.EROFS)):
        assert found[case] == [number, _expected(out, number, True)], case
    assert found["listing"] == ["out.parquet"] and found["previous"] == "previous"

"""One batch at a time into a results folder (issue 53): two batches writing one folder at once, each planning
from what the other had not written yet, left two results per log.

:func:`results_lock` holds ``RESULTS/.wbfriction-batch.lock`` while a batch runs: an exclusive ``flock`` on it,
which the system releases when the process ends however it ends (a lock left by a killed batch is stale and
taken over), and in it the holder's process id, machine and start time, which the refusal names. The file is
removed when the batch ends. Where the file system has no ``flock``, the process id decides: a lock naming a
process of this machine that no longer exists is stale.

A hidden file: a folder scan, :func:`~wbfriction.fleet.results.read_parts` and Parquet readers pass over it.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from wbfriction.exceptions import InputError
from wbfriction.logs.tables import make_folder, output_error

LOCK_NAME = ".wbfriction-batch.lock"
"""The lock's file, in the results folder."""


def lock_path(results: str | Path) -> Path:
    """Where the lock of the batch writing ``results`` is."""
    return Path(results) / LOCK_NAME


@contextmanager
def results_lock(results: str | Path) -> Iterator[Path]:
    """Hold the lock of the results folder ``results`` (made if absent) while the block runs; the lock file is
    removed after it, and the folder too if it was made here and the block raised with the folder empty (nothing
    written).

    Raises:
        InputError: another live batch holds the lock, naming the option ``-o``, the folder and that batch's
            process (wait for it, or write into another folder).
        OutputError: a lock file that cannot be made.
    """
    results = Path(results)
    made = not results.exists()
    make_folder(results)
    path = lock_path(results)
    try:
        fd = _acquire(path, results)
    except BaseException:
        _remove_if_empty(results, made)
        raise
    try:
        yield path
    except BaseException:
        _release(fd, path)
        _remove_if_empty(results, made)
        raise
    _release(fd, path)


def _acquire(path: Path, results: Path) -> int:
    """The open lock file, locked and naming this process."""
    for _ in range(5):  # the holder removed the file between our open and our lock: open it again
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise output_error(path, exc) from exc
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):  # no flock here: by process id
                holder = _holder(path)
                if holder is not None and _running(holder):
                    os.close(fd)
                    raise _refusal(results, holder) from None
                _write(fd, path)
                return fd
            holder = _holder(path)
            os.close(fd)
            raise _refusal(results, holder) from None
        try:
            same = os.fstat(fd).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:
            _write(fd, path)
            return fd
        os.close(fd)
    raise InputError(f"-o {results}: its batch lock ({path}) keeps changing: another batch is starting there")


def _write(fd: int, path: Path) -> None:
    """This process as the lock's holder."""
    doc = {"pid": os.getpid(), "host": socket.gethostname(), "started": datetime.now(UTC).isoformat(timespec="seconds")}
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(doc) + "\n").encode(), 0)
    except OSError as exc:
        os.close(fd)
        raise output_error(path, exc) from exc


def _holder(path: Path) -> dict[str, Any] | None:
    """What the lock file says of its holder (None: nothing readable)."""
    try:
        doc = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None


def _running(holder: dict[str, Any]) -> bool:
    """Whether the holder a lock names may be running: another machine's (it cannot be told from here), or a
    process of this one that exists."""
    pid = holder.get("pid")
    if holder.get("host") != socket.gethostname() or not isinstance(pid, int):
        return True
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # another user's
        return True
    return True


def _refusal(results: Path, holder: dict[str, Any] | None) -> InputError:
    who = (f"process {holder.get('pid')} on {holder.get('host')}, since {holder.get('started')}"
           if holder is not None else "its process not named yet")
    return InputError(f"-o {results}: another batch is writing these results ({who}): wait for it to end, or "
                      "write into another folder")


def _release(fd: int, path: Path) -> None:
    """The lock file removed (while still locked: a batch waiting on it opens a new one), then unlocked."""
    try:
        path.unlink(missing_ok=True)
    except OSError:
        pass
    os.close(fd)


def _remove_if_empty(results: Path, made: bool) -> None:
    if made:
        try:
            results.rmdir()
        except OSError:
            pass

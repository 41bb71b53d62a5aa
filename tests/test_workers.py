"""Worker processes end with their parent, whatever ends it (issue 21, class 3).

The parent is a real process killed with SIGKILL (nothing of it runs after); its workers are
found in /proc by their parent's id and their start time (an id used again is another process).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from helpers import ended_within
from wbfriction.workers import POLL_PERIOD, process_pool


def _start_time(pid: int) -> str | None:
    """The start time of a live process (None: none, or a zombie)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return None if fields[0] == "Z" else fields[19]


def _live(pids: list[int]) -> dict[int, str | None]:
    """The processes with their start times, read while they run."""
    starts = {p: _start_time(p) for p in pids}
    assert all(starts.values()), f"not running: {starts}"
    return starts


def _seconds_to_end(starts: dict[int, str | None], limit: float) -> float:
    t0 = time.monotonic()
    while any(_start_time(p) == s for p, s in starts.items()) and time.monotonic() - t0 < limit:
        time.sleep(0.01)
    return time.monotonic() - t0


PARENT = """
import multiprocessing, sys, time
from wbfriction.workers import process_pool
with process_pool(2, sys.argv[1]) as pool:
    futures = [pool.submit(time.sleep, 60) for _ in range(2)]
    print(*sorted(p.pid for p in multiprocessing.active_children()), flush=True)
    futures[0].result()
"""


@pytest.mark.parametrize("context", ["spawn", "fork"])
def test_busy_workers_end_when_their_parent_is_killed(context):
    """SIGKILL of the parent while its two workers are busy: both gone well within 5 s (the kernel
    kills them at once on Linux)."""
    parent = subprocess.Popen([sys.executable, "-c", PARENT, context], stdout=subprocess.PIPE, text=True)
    try:
        pids = [int(p) for p in parent.stdout.readline().split()]
        assert len(pids) == 2
        time.sleep(0.3 if context == "fork" else 2.0)  # spawned workers: past their imports, sleeping
        starts = _live(pids)
        parent.kill()
        parent.wait(10)
        waited = _seconds_to_end(starts, 5.0)
        assert waited < 5.0, f"workers {pids} alive 5 s after their parent's SIGKILL"
        print(f"{context}: workers gone {waited:.3f} s after SIGKILL")
    finally:
        parent.kill()


ORPHAN = """
import multiprocessing, os, sys, time
from wbfriction.workers import end_with_parent
def child(parent, mechanism):
    end_with_parent(parent, mechanism)
    time.sleep(60)
if __name__ == "__main__":
    p = multiprocessing.get_context("fork").Process(target=child, args=(os.getpid(), sys.argv[1]))
    p.start()
    time.sleep(0.2)
    print(p.pid, flush=True)
    time.sleep(60)
"""


@pytest.mark.parametrize("mechanism", ["prctl", "poll"])
def test_each_mechanism_ends_a_child_with_its_parent(mechanism, tmp_path):
    """The kernel's parent-death signal (Linux) and the polling thread (elsewhere) both end a child
    whose parent was killed: at once, or within the polling period."""
    script = tmp_path / "orphan.py"
    script.write_text(textwrap.dedent(ORPHAN))
    parent = subprocess.Popen([sys.executable, str(script), mechanism], stdout=subprocess.PIPE, text=True)
    try:
        starts = _live([int(parent.stdout.readline())])
        parent.kill()
        parent.wait(10)
        assert _seconds_to_end(starts, 5.0) < (1.0 if mechanism == "prctl" else POLL_PERIOD + 1.0)
    finally:
        parent.kill()


def test_a_worker_whose_parent_is_already_gone_leaves_at_once():
    """A process told its parent is one that is not (the parent ended before the tie) exits 1
    before running anything else."""
    res = subprocess.run([sys.executable, "-c", "from wbfriction.workers import end_with_parent\n"
                          "end_with_parent(1)\nprint('still running')"], capture_output=True, text=True, timeout=60)
    assert (res.returncode, res.stdout) == (1, "")


def test_workers_run_the_initializer_and_leave_ctrl_c_to_the_parent(tmp_path):
    """Every worker ran ``initializer(*initargs)`` (its working folder) and ignores SIGINT (the
    terminal's Ctrl-C reaches it too; the parent decides); the results are the plain loop's."""
    with process_pool(2, "spawn", os.chdir, (str(tmp_path),)) as pool:
        folders = list(pool.map(os.path.realpath, ["."] * 8))
        handlers = list(pool.map(signal.getsignal, [signal.SIGINT, signal.SIGTERM] * 4))
        squares = list(pool.map(pow, range(50), [2] * 50))
    assert folders == [os.path.realpath(tmp_path)] * 8
    assert handlers == [signal.SIG_IGN, signal.SIG_DFL] * 4
    assert squares == [k * k for k in range(50)]


def test_map_gives_the_results_in_order_in_chunks_or_not_and_keeps_its_timeout():
    """The pool's ``map`` (which cancels nothing when left early) keeps the executor's contract: the
    results in the arguments' order whatever the chunk size, a chunk size below 1 refused, a
    timeout for all the results raised as TimeoutError (and the block left by it at once)."""
    with process_pool(2, "fork") as pool:
        assert list(pool.map(pow, range(50), [2] * 50, chunksize=7)) == [k * k for k in range(50)]
        assert list(pool.map(divmod, range(5), [3] * 9, chunksize=10)) == [divmod(k, 3) for k in range(5)]
        assert list(pool.map(abs, [])) == []
        with pytest.raises(ValueError, match="chunksize"):
            pool.map(abs, [1], chunksize=0)
    t0 = time.monotonic()
    with pytest.raises(TimeoutError):
        with process_pool(1, "fork") as pool:
            list(pool.map(time.sleep, [0.0, 30.0], timeout=1.0))
    assert 1.0 <= time.monotonic() - t0 < 10.0


def test_leaving_by_an_exception_kills_busy_workers_at_once():
    """An error (or an interruption) in the block does not wait for the work in progress: the busy
    workers are killed and the error goes on."""
    before = {p.pid for p in multiprocessing.active_children()}
    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="stop"):
        with process_pool(2, "fork") as pool:
            futures = [pool.submit(time.sleep, 30) for _ in range(2)]
            time.sleep(0.3)
            pids = [p.pid for p in multiprocessing.active_children() if p.pid not in before]
            raise RuntimeError("stop")
    assert time.monotonic() - t0 < 10.0
    assert len(pids) == 2 and not any(_start_time(p) for p in pids if p is not None)
    assert all(f.done() for f in futures)


LEFT_EARLY = """
import signal, sys, time
from wbfriction.workers import process_pool

def work(blob):
    time.sleep(30)
    return len(blob)

def stop(signum, frame):
    raise KeyboardInterrupt

if __name__ == "__main__":
    signal.signal(signal.SIGALRM, stop)
    try:
        with process_pool(2, sys.argv[1]) as pool:
            signal.setitimer(signal.ITIMER_REAL, 1.0)
            print(sum(pool.map(work, [bytes(1 << 20)] * 8)))
    except KeyboardInterrupt:
        print("stopped", flush=True)
"""


@pytest.mark.parametrize("context", ["spawn", "fork"])
def test_leaving_a_map_early_ends_at_once_without_a_thread_traceback(context, tmp_path):
    """An interruption while ``pool.map`` waits for busy workers, with tasks still queued and arguments
    larger than a pipe holds (the pool's feeding thread blocked on a pipe that no worker reads any
    more): the block is left at once, the process exits at once, and no thread prints a traceback
    (issue 37: Python 3.11's pool thread failed with ``InvalidStateError`` on the futures that
    ``Executor.map`` had cancelled, before it could unblock the feeding thread; the exit then waited
    for that thread forever)."""
    script = tmp_path / "left_early.py"
    script.write_text(textwrap.dedent(LEFT_EARLY))
    t0 = time.monotonic()
    proc = subprocess.Popen([sys.executable, str(script), context], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    out, err = ended_within(proc, 20, "it started (interrupted after 1 s)")
    assert (proc.returncode, out, err) == (0, "stopped\n", "")
    assert time.monotonic() - t0 < 10.0


def test_a_dask_worker_drops_only_the_finalizer_failure_of_a_client_whose_loop_closed():
    """An interrupted batch's worker (issue 37): the ``IOLoop is closed`` failure of a
    ``distributed.Client`` finalizer is not printed; any other unraisable exception still is, a
    ``Client.__del__`` failing otherwise included."""
    from types import SimpleNamespace

    from distributed import Client

    from wbfriction.workers import dask_setup

    seen: list[object] = []
    previous = sys.unraisablehook
    sys.unraisablehook = seen.append
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        dask_setup(None)
        closed = SimpleNamespace(object=Client.__del__, exc_value=RuntimeError("IOLoop is closed"))
        other_error = SimpleNamespace(object=Client.__del__, exc_value=RuntimeError("something else"))
        other_object = SimpleNamespace(object=len, exc_value=RuntimeError("IOLoop is closed"))
        for unraisable in (closed, other_error, other_object):
            sys.unraisablehook(unraisable)
    finally:
        sys.unraisablehook = previous
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    assert seen == [other_error, other_object]


def test_heap_for_arrays_undoes_dasks_malloc_setting():
    """A process started as a ``dask worker`` starts its workers (``MALLOC_TRIM_THRESHOLD_=65536``) maps every
    1 MiB array afresh: its pages fault in each time. After :func:`heap_for_arrays`, the arrays come from the heap
    and fault once; without the variable there is nothing to undo."""
    script = textwrap.dedent("""
        import resource, numpy as np
        from wbfriction.workers import heap_for_arrays
        def faults():
            before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            for _ in range(200):
                np.ones(1 << 17).sum()
            return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
        first = faults()
        print(heap_for_arrays(), first, faults(), faults())
    """)
    env = {**os.environ, "MALLOC_TRIM_THRESHOLD_": "65536"}
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True).stdout
    undone, mapped, _, heap = out.split()
    assert undone == "True" and int(mapped) > 200 * 200 and int(heap) < int(mapped) / 20
    env.pop("MALLOC_TRIM_THRESHOLD_")
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True).stdout
    assert out.split()[0] == "False"

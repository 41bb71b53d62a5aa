"""Interruptions (issue 21, class 3): a command ended by Ctrl-C exits 130, by SIGTERM 143, with one
line on stderr, its output absent or the previous one kept, no traceback, even while it imports
its libraries; a command killed by SIGKILL leaves no process behind, and the temporary file it
left is removed by the next write into the folder.

A signal while a process pool fits or draws (``fit``, ``report``) ends the command as quickly
(issue 37: it printed a thread's traceback, then hung).

Mechanisms: :mod:`wbfriction.entry` (signals handled before anything is imported),
:mod:`wbfriction.workers` (workers end with their parent; a pool's teardown that nothing races),
:func:`wbfriction.logs.tables.write_atomic`.
Every run is a real ``python -m wbfriction`` process, signalled as a terminal or a supervisor would.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from helpers import ended_within, run, said
from wbfriction.logs.tables import write_json

ESTIMATE = ("estimate", "--workers", "2", "--chunk-rows", "800")
"""A chunked estimate on two spawned workers (the simulated log has about nine chunks: enough for
workers to pay, :meth:`~wbfriction.pipeline.chunks.Chunking.processes`)."""


@pytest.fixture(scope="module")
def walk_log(tmp_path_factory) -> Path:
    """A simulated walk of 7.8 s (7801 samples)."""
    path = tmp_path_factory.mktemp("interruption") / "walk.parquet"
    res = run("simulate", "-o", path, "--gait", "combined", "--steps", "2")
    assert res.returncode == 0, res.stderr
    return path


@pytest.fixture(scope="module")
def friction_table(walk_log) -> Path:
    """The walk's friction estimate (30 joints: ``fit`` and ``report`` keep two workers busy for a minute)."""
    path = walk_log.parent / "friction.parquet"
    res = run("estimate", walk_log, "--robot", "talos", "-o", path)
    assert res.returncode == 0, res.stderr
    return path


# ------------------------------------------------------------------ processes, read from /proc
def _stat(pid: int) -> tuple[str, int, str] | None:
    """(state, parent id, start time) of a process, None if there is none."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = text.rsplit(")", 1)[1].split()
    return fields[0], int(fields[1]), fields[19]


def _children(pid: int) -> dict[int, str]:
    """The processes whose parent is ``pid``, with their start times (a process id used again is
    another process)."""
    out = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and (s := _stat(int(entry.name))) is not None and s[1] == pid:
            out[int(entry.name)] = s[2]
    return out


def _cpu_ticks(pid: int) -> int:
    """The CPU time a process has used (user + system), in clock ticks; 0 if it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0
    return int(fields[11]) + int(fields[12])


def _group(pgid: int) -> list[int]:
    """The live processes of process group ``pgid``."""
    out = []
    for entry in Path("/proc").iterdir():
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split() if entry.name.isdigit() else None
        except OSError:
            continue
        if fields is not None and int(fields[2]) == pgid and fields[0] != "Z":
            out.append(int(entry.name))
    return out


def _alive(processes: dict[int, str]) -> list[int]:
    return [p for p, start in processes.items() if (s := _stat(p)) is not None and s[0] != "Z" and s[2] == start]


def _wait_gone(processes: dict[int, str], limit: float) -> float:
    """Seconds until none of ``processes`` is alive (at most ``limit``)."""
    t0 = time.monotonic()
    while _alive(processes) and time.monotonic() - t0 < limit:
        time.sleep(0.01)
    return time.monotonic() - t0


def _caught(pid: int, signum: int) -> bool:
    """Whether process ``pid`` has a handler for ``signum`` (SigCgt of /proc/PID/status)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    return False


def _start(*args, cwd: Path) -> subprocess.Popen:
    """``wbfriction ARGS`` in a process group of its own (as a shell starts a job)."""
    return subprocess.Popen([sys.executable, "-m", "wbfriction", *map(str, args)], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def _mid_run(proc: subprocess.Popen, folder: Path, output: str) -> dict[int, str]:
    """Wait until the output is being written and both workers run; their ids (and the resource
    tracker's)."""
    deadline = time.monotonic() + 60
    while proc.poll() is None and time.monotonic() < deadline:
        if list(folder.glob(f".{output}.*.tmp*")) and len(kids := _children(proc.pid)) >= 3:
            return kids
        time.sleep(0.02)
    pytest.fail(f"the run ended or stalled before it could be interrupted: {proc.poll()}")


def _pool_busy(proc: subprocess.Popen, workers: int = 2) -> dict[int, str]:
    """Wait until ``workers`` children of the command have each computed for 50 ms (its pool's tasks
    are under way, others queued behind them); their ids."""
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline:
        kids = _children(proc.pid)
        if len(kids) >= workers and sum(_cpu_ticks(p) >= 5 for p in kids) >= workers:
            return kids
        time.sleep(0.02)
    pytest.fail(f"the run ended or stalled before its pool worked: {proc.poll()}")


def _stderr_lines(text: str) -> list[str]:
    """The lines a command said on standard error, those of the stages it ended before the signal left out."""
    return said(text)


# ------------------------------------------------------------------ tests
@pytest.mark.parametrize(("signum", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False)],
                         ids=["ctrl-c to the job", "sigterm to the command"])
def test_a_signal_mid_run_exits_128_plus_its_number_and_keeps_the_previous_output(walk_log, tmp_path, signum,
                                                                                  group):
    """Ctrl-C reaches every process of the job (the workers too), SIGTERM only the command: either
    way status 128 + n, one line, the previous output byte for byte, no temporary file, no worker."""
    out = tmp_path / "f.parquet"
    out.write_bytes(b"previous result")
    proc = _start(*ESTIMATE, walk_log, "-o", out, cwd=tmp_path)
    kids = _mid_run(proc, tmp_path, out.name)
    (os.killpg if group else os.kill)(proc.pid, signum)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signum, err
    assert _stderr_lines(err) == [f"interrupted ({signal.Signals(signum).name})"], err
    assert out.read_bytes() == b"previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.parquet"]
    assert _wait_gone(kids, 5.0) < 5.0, f"left alive: {_alive(kids)}"


@pytest.mark.parametrize(("command", "output"), [("fit", "p.json"), ("report", "r.html")])
@pytest.mark.parametrize(("signum", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False)],
                         ids=["ctrl-c to the job", "sigterm to the command"])
def test_a_signal_while_the_pool_works_ends_the_command_within_seconds(friction_table, tmp_path, command, output,
                                                                       signum, group):
    """``fit`` and ``report`` interrupted while their two forked workers fit or draw, joints still
    queued: the command ends within 10 s with 128 + n and the one line (no thread's traceback), no
    process of its group is left, the previous output is kept byte for byte, nothing else written
    (issue 37: an ``InvalidStateError`` traceback from the pool's thread, then a hang at exit)."""
    name = signal.Signals(signum).name
    out = tmp_path / output
    out.write_bytes(b"previous result")
    proc = _start(command, friction_table, "-o", out, "--workers", "2", cwd=tmp_path)
    kids = _pool_busy(proc)
    (os.killpg if group else os.kill)(proc.pid, signum)
    t0 = time.monotonic()
    _, err = ended_within(proc, 30, name)  # its workers hold standard error too
    took = time.monotonic() - t0
    assert proc.returncode == 128 + signum, err
    assert _stderr_lines(err) == [f"interrupted ({name})"], err
    assert took < 10.0, f"ended {took:.1f} s after {name}"
    assert _wait_gone(kids, 5.0) < 5.0, f"left alive: {_alive(kids)}"
    assert _group(proc.pid) == []
    assert out.read_bytes() == b"previous result"
    assert sorted(p.name for p in tmp_path.iterdir()) == [output]
    print(f"{command}: ended {took:.2f} s after {name}")


@pytest.fixture(scope="module")
def arm_manifest(tmp_path_factory) -> Path:
    """A manifest of four simulated Panda logs of 3 s (a batch of them keeps two Dask workers busy)."""
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

    folder = tmp_path_factory.mktemp("fleet")
    robot = load_robot("panda")
    lines = ["log,robot_id,start_time,robot"]
    for seed in range(4):
        sim = simulate_arm(robot, default_arm_friction(robot), options=ArmOptions(duration=3.0, seed=seed))
        write_table(sim.table, folder / f"{seed}.parquet")
        lines.append(f"{seed}.parquet,arm-{seed % 2},2026-03-0{seed + 1}T08:00:00Z,panda")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder / "manifest.csv"


@pytest.mark.parametrize(("signum", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False)],
                         ids=["ctrl-c to the job", "sigterm to the command"])
def test_a_signal_while_a_batch_runs_on_dask_ends_it_with_one_line(arm_manifest, tmp_path, signum, group):
    """``batch`` interrupted while its local Dask cluster's two worker processes start or estimate: 128 + n,
    the one line (issue 37: each Dask worker printed a KeyboardInterrupt traceback of its own), no process of
    its group left; a result written is whole (the next run goes on from it). Issue 53, class 17: nothing else is
    left in the results and tables folders (the workers' partial files stayed there until the next run), nor the
    batch's lock."""
    proc = _start("batch", arm_manifest, "-o", tmp_path / "results", "--tables", tmp_path / "tables", cwd=tmp_path)
    kids = _pool_busy(proc)
    time.sleep(1.0)
    _interrupt(proc, kids, signum, group)
    from wbfriction.fleet.results import read_parts

    assert all(part.rows is not None for part in read_parts(tmp_path / "results"))
    assert _leftovers(tmp_path / "results", tmp_path / "tables") == []


def _interrupt(proc, kids: list, signum: int, group: bool) -> None:
    """Send ``signum`` to the batch (its process group with ``group``) and check it ended as a signal ends a command:
    its exit status, one line, its worker processes gone."""
    name = signal.Signals(signum).name
    (os.killpg if group else os.kill)(proc.pid, signum)
    _, err = ended_within(proc, 60, name)
    assert proc.returncode == 128 + signum, err
    assert _stderr_lines(err) == [f"interrupted ({name})"], err
    assert _wait_gone(kids, 10.0) < 10.0, f"left alive: {_alive(kids)}"
    assert _group(proc.pid) == []


def _leftovers(*folders: Path) -> list[Path]:
    """What is in ``folders`` besides whole results and tables: hidden files or folders, other files."""
    return [p for folder in folders for p in folder.rglob("*")
            if p.name.startswith(".") or p.is_file() and p.suffix != ".parquet"]


@pytest.mark.parametrize(("signum", "group"), [(signal.SIGINT, True), (signal.SIGTERM, False)],
                         ids=["ctrl-c to the job", "sigterm to the command"])
def test_a_signal_while_a_dask_batchs_tasks_run_leaves_no_partial_file(arm_manifest, tmp_path, signum, group):
    """Issue 53, class 17: a batch interrupted while its Dask workers' tasks estimate left their scratch folders
    (``.wbfriction-<host>-<pid>-<token>``) in the results folder until the next run. They are removed when the batch
    ends on the signal, with the batch's lock; the results written are whole."""
    results, tables = tmp_path / "results", tmp_path / "tables"
    proc = _start("batch", arm_manifest, "-o", results, "--tables", tables, cwd=tmp_path)
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline and len(_leftovers(results)) < 2:
        time.sleep(0.05)  # both workers' tasks under way: their scratch folders (and the lock) are there
    assert proc.poll() is None, "the batch ended before it could be interrupted"
    time.sleep(0.5)
    kids = _children(proc.pid)
    _interrupt(proc, kids, signum, group)
    assert _leftovers(results, tables) == []
    from wbfriction.fleet.results import read_parts

    assert all(part.rows is not None for part in read_parts(results))


def test_ctrl_c_while_the_libraries_load_exits_130_without_a_traceback(tmp_path):
    """The command handles the signals before it loads NumPy or Pinocchio (seconds): a Ctrl-C then
    is one line and status 130."""
    proc = _start(*ESTIMATE, tmp_path / "missing.parquet", "-o", tmp_path / "f.parquet", cwd=tmp_path)
    deadline = time.monotonic() + 30
    while not _caught(proc.pid, signal.SIGTERM) and time.monotonic() < deadline:
        time.sleep(0.002)
    maps = Path(f"/proc/{proc.pid}/maps").read_text()
    assert "pinocchio" not in maps, "the signals were handled only after the heavy imports"
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert _stderr_lines(err) == ["interrupted (SIGINT)"], err
    assert list(tmp_path.iterdir()) == []


def test_sigkill_leaves_no_process_and_the_next_write_removes_its_file(walk_log, tmp_path):
    """SIGKILL of the command mid-run: its workers and multiprocessing's resource tracker are gone
    within 5 s; its half-written temporary file is removed by the next write into the folder."""
    out = tmp_path / "f.parquet"
    proc = _start(*ESTIMATE, walk_log, "-o", out, cwd=tmp_path)
    kids = _mid_run(proc, tmp_path, out.name)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=30)
    waited = _wait_gone(kids, 5.0)
    assert not _alive(kids), f"alive 5 s after SIGKILL: {_alive(kids)}"
    print(f"{len(kids)} children gone {waited:.3f} s after SIGKILL")
    left = [p.name for p in tmp_path.iterdir()]
    assert len(left) == 1 and left[0].startswith(".f.parquet.") and f"-{proc.pid}-" in left[0], left
    write_json(tmp_path / "next.json", {})
    assert [p.name for p in tmp_path.iterdir()] == ["next.json"]


# ------------------------------------------------------------------ the entry point alone, on a stand-in command line
STAND_IN = """
import os, signal, sys, time, types
cli = types.ModuleType("wbfriction.cli")

class Bomb:
    def __del__(self):
        os.kill(os.getpid(), signal.SIGINT)
        len("a call: the handler runs here, inside __del__")

def main():
    case = sys.argv[1]
    if case == "swallowed":
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)
        except BaseException:
            pass
    elif case == "in __del__":
        Bomb()
        t0 = time.monotonic()
        while time.monotonic() - t0 < 5:
            pass
    elif case == "status":
        sys.exit(3)
    elif case == "error":
        raise ValueError("a bug")
    print("finished")

cli.main = main
sys.modules["wbfriction.cli"] = cli
from wbfriction.entry import main
main()
"""


@pytest.mark.parametrize(("case", "status", "stderr"), [
    ("swallowed", 143, ["interrupted (SIGTERM)"]),
    ("in __del__", 130, ["interrupted (SIGINT)"]),
    ("status", 3, []),
    ("error", 1, None),
])
def test_the_entry_point_reports_every_signal_and_nothing_else(case, status, stderr):
    """A signal whose exception some code swallowed still ends in 128 + n; one raised inside an
    object's ``__del__`` (where Python can only print it) stops the command all the same, without
    a traceback; a command's own status and its errors pass through unchanged."""
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(STAND_IN), case], capture_output=True, text=True,
                         timeout=60)
    assert res.returncode == status, res.stderr
    if stderr is None:
        assert "Traceback" in res.stderr and "ValueError: a bug" in res.stderr
    else:
        assert _stderr_lines(res.stderr) == stderr
    assert ("finished" in res.stdout) == (case == "swallowed")

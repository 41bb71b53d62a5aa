"""A long log in bounded memory: samples per second and peak memory of the chunked estimate.

Builds a log of ``--minutes`` at 1 kHz for TALOS by repeating a simulated combined walk
(with a 0.5 s time gap between repetitions, so that the log has segments as real logs with
pauses do), written tile by tile (never held whole), then runs ``wbfriction estimate`` on it
(chunked, :mod:`wbfriction.pipeline.chunked`) and prints rows per second, the CPU time of the command and
its workers together (what the wall time is on idle cores: the figure that holds on a shared machine)
and their peak resident memory together.

    python benchmarks/bench_long_log.py --minutes 60 --workers 2
"""

from __future__ import annotations

import argparse
import contextlib
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.model.loading import load_robot
from wbfriction.pipeline.chunks import Chunking
from wbfriction.sim import simulate_ideal
from wbfriction.studies.common import leg_joints
from wbfriction.walking import GaitOptions, walking_reference


def walk_log(robot):
    """The tile both long-input benchmarks repeat: a 3-step combined walk of the ideal
    simulator with Table 6.1 friction on the legs."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(robot)}
    return simulate_ideal(robot, walking_reference(robot, GaitOptions(gait="combined", steps=3)), friction).log


def build_log(path: Path, minutes: float) -> int:
    robot = load_robot("talos")
    log = walk_log(robot)
    tile = log.to_table(robot)
    period = float(np.median(np.diff(log.time)))
    span = log.time[-1] - log.time[0] + 0.5  # a 0.5 s gap between repetitions
    rows, total, k = len(log), int(minutes * 60 / period), 0
    with pq.ParquetWriter(path, tile.schema) as writer:
        while k * rows < total:
            t = tile.column("time").to_numpy() + k * span
            writer.write_table(tile.set_column(0, "time", pa.array(t)))
            k += 1
    return k * rows


def tree_rss(pid: int) -> int:
    """Resident memory of a process and all its descendants [bytes] (Linux /proc)."""
    parents: dict[int, int] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            parents[int(stat.parent.name)] = int(fields[1])
        except (OSError, IndexError, ValueError):
            continue
    tree, grew = {pid}, True
    while grew:
        more = {p for p, pp in parents.items() if pp in tree} - tree
        grew = bool(more)
        tree |= more
    total = 0
    for p in tree:
        try:
            for line in Path(f"/proc/{p}/status").read_text().splitlines():
                if line.startswith("VmRSS:"):
                    total += int(line.split()[1]) * 1024
        except OSError:
            continue
    return total


def measure(cmd: list[str]) -> tuple[float, int]:
    """Run ``cmd``: its wall time [s] and the peak resident memory of its process tree [bytes]
    (sampled every 0.2 s). Exits with the command's error output if it fails."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    peak = 0
    while proc.poll() is None:
        peak = max(peak, tree_rss(proc.pid))
        time.sleep(0.2)
    if proc.returncode != 0:
        raise SystemExit(proc.stderr.read())
    return time.perf_counter() - t0, peak


@contextlib.contextmanager
def work_folder(keep: Path | None, prefix: str):
    """A folder for a benchmark's files: ``keep`` (kept), or a temporary one removed afterwards."""
    folder = Path(tempfile.mkdtemp(prefix=prefix)) if keep is None else keep
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    finally:
        if keep is None:
            shutil.rmtree(folder, ignore_errors=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--chunk-rows", type=int, default=Chunking().rows)
    parser.add_argument("--keep", type=Path, default=None, help="Folder to keep the log and the estimate in.")
    args = parser.parse_args()
    with work_folder(args.keep, "wbf-long-") as folder:
        log = folder / "long_log.parquet"
        t0 = time.perf_counter()
        rows = build_log(log, args.minutes)
        t1 = time.perf_counter()
        # the command line, as a user runs it, in a process tree of its own: its memory is
        # sampled as the sum of the resident sets of the process and its workers
        cmd = [sys.executable, "-m", "wbfriction", "estimate", str(log), "-o", str(folder / "long_friction.parquet"),
               "--workers", str(args.workers), "--chunk-rows", str(args.chunk_rows)]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        seconds, peak = measure(cmd)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        t2 = t1 + seconds
        largest = after.ru_maxrss / 1024
        print(f"log: {rows} rows ({rows / 1000 / 60:.1f} min at 1 kHz), {log.stat().st_size / 2**30:.2f} GiB, "
              f"built in {t1 - t0:.0f} s")
        print(f"wbfriction estimate: {args.workers} workers, {t2 - t1:.0f} s: {rows / (t2 - t1):.0f} rows/s; "
              f"{cpu:.0f} s CPU (the command and its workers: {cpu / args.workers:.0f} s on {args.workers} idle cores)")
        print(f"output: {(folder / 'long_friction.parquet').stat().st_size / 2**30:.2f} GiB")
        print(f"peak memory: {peak / 2**20:.0f} MiB resident in all (the command and its workers, sampled every "
              f"0.2 s); largest single process {largest:.0f} MiB")


if __name__ == "__main__":
    main()

"""Where the time of ``wbfriction estimate`` goes, stage by stage, next to the bare rigid-body loop.

Runs the whole command in this process under :mod:`cProfile` (``--workers 1``, defaults: both routes) on

* the 31,801-row TALOS combined walk of the ideal simulator (``bench_estimate.combined_walk``), and
* 8 s of the point-foot Go2 trotting in the ideal simulator (``simulate --robot go2_walking --gait trot``),

the second of two runs (the modules imported by the first: the start-up is timed apart, ``estimate --help`` in a
process of its own). Each function's own time goes to the stage of its nearest caller that names one
(:data:`STAGES`). The call graph cProfile keeps is one level deep: a function called from several places is split
among its callers in proportion to the time it spent under each, and so on up. Each stage's share is of the
profiled run. The profiler slows Python code more than the C++ it calls, so the shares overstate the Python stages
a little. The command's time in this process without the profiler is printed beside, and for TALOS the bare
single-core ``pin.constraintDynamics`` loop over the same rows (``bench_estimate.bare_loop``).

    python benchmarks/bench_estimate_stages.py [--keep DIR]
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import io
import os
import pstats
import sys
import time
from collections import defaultdict
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pyarrow.parquet as pq  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from bench_estimate import bare_loop, combined_walk  # noqa: E402
from bench_long_log import work_folder  # noqa: E402

from wbfriction.entry import main as wbfriction_main  # noqa: E402
from wbfriction.model.loading import load_robot  # noqa: E402

STAGES: tuple[tuple[str, str, str], ...] = (
    ("load_robot", "model/loading.py", "loading the robot"),
    ("*", "pipeline/provenance.py", "provenance (the log's hash)"),
    ("read", "logs/tables.py", "reading"),
    ("log_from_table", "logs/log.py", "reading"),
    ("plan_columns", "pipeline/chunks.py", "planning columns"),
    ("decide_log", "friction/decision.py", "choosing the differentiation"),
    ("measure", "signals/kinematics.py", "differentiation and filters"),
    ("base_motion_from_imu", "model/imu.py", "the base's motion from the IMU"),
    ("determination", "model/determination.py", "determination"),
    ("joint_torques", "model/determination.py", "acceleration route: point-contact dynamics"),
    ("single_support", "friction/estimate.py", "acceleration route: single-support RNEA"),
    ("constrained_dynamics", "model/dynamics.py", "acceleration route: constrained dynamics"),
    ("_acceleration_segment", "friction/estimate.py", "acceleration route: the rest"),
    ("momentum_estimate", "friction/momentum.py", "momentum route"),
    ("write", "logs/tables.py", "writing"),
)
"""``(function, file, stage)``: a function of that name (any, for ``*``) in the package's file of that path starts
the stage; time under it belongs to it unless a function nearer it starts another. What reaches none is ``other``
(the command line's parsing, the chunk plan, the messages)."""


def stage_of(key: tuple[str, int, str]) -> str | None:
    """The stage a profiled function starts, or None."""
    file, _, name = key
    file = file.replace(os.sep, "/")
    for func, where, stage in STAGES:
        if func in (name, "*") and file.endswith(f"wbfriction/{where}"):
            return stage
    return None


def stage_times(stats: pstats.Stats) -> dict[str, float]:
    """Each stage's time [s]: every function's own time given to the stages of its callers (module docstring);
    ``other`` what reaches no stage. A call cycle is cut where it closes."""
    calls = stats.stats  # type: ignore[attr-defined]
    shares: dict[tuple, dict[str, float]] = {}
    open_: set[tuple] = set()

    def share(key: tuple) -> dict[str, float]:
        if key in shares:
            return shares[key]
        named = stage_of(key)
        if named is not None:
            shares[key] = {named: 1.0}
            return shares[key]
        open_.add(key)
        callers = {c: edge[3] for c, edge in calls[key][4].items() if c not in open_ and c in calls}
        total = sum(callers.values())
        out: dict[str, float] = defaultdict(float)
        if total <= 0:
            out["other"] = 1.0
        for caller, ct in callers.items():
            for stage, w in share(caller).items():
                out[stage] += w * ct / total
        open_.discard(key)
        shares[key] = dict(out)
        return shares[key]

    times: dict[str, float] = defaultdict(float)
    for key, (_, _, own, _, _) in calls.items():
        for stage, w in share(key).items():
            times[stage] += own * w
    return dict(times)


def in_process(argv: list[str], profile: cProfile.Profile | None = None) -> float:
    """Wall time [s] of ``wbfriction ARGV`` run in this process (its printing dropped), under ``profile`` if given."""
    sys.argv = ["wbfriction", *argv]
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        if profile is not None:
            profile.enable()
        try:
            wbfriction_main()
        except SystemExit as exc:
            if exc.code not in (0, None):
                raise
        finally:
            if profile is not None:
                profile.disable()
    return time.perf_counter() - t0


def profiled(argv: list[str]) -> tuple[dict[str, float], float]:
    """The stages' times of ``wbfriction ARGV`` run a second time in this process under cProfile, and its total
    [s]."""
    in_process(argv)
    profile = cProfile.Profile()
    total = in_process(argv, profile)
    return stage_times(pstats.Stats(profile)), total


def wall(argv: list[str]) -> float:
    """Wall time [s] of ``python -m wbfriction ARGV`` in its own process, start-up included."""
    import subprocess

    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "wbfriction", *argv], check=True, capture_output=True)
    return time.perf_counter() - t0


def table(name: str, rows: int, times: dict[str, float], total: float, command: float, floor: float | None) -> str:
    """The markdown table of one log (``command``: its wall time in this process, without the profiler)."""
    lines = [f"### {name}: {rows} rows; the command {command:.2f} s wall in process ({rows / command:,.0f} rows/s)"
             + ("" if floor is None else f"; the bare constraintDynamics loop {floor:.2f} s CPU "
                f"({rows / floor:,.0f} rows/s, the command at {floor / command:.2f}× it)"),
             "", "| stage | profiled [s] | share |", "|---|---|---|"]
    for stage, t in sorted(times.items(), key=lambda kv: -kv[1]):
        lines.append(f"| {stage} | {t:.3f} | {t / total:.0%} |")
    lines.append(f"| all (profiled) | {total:.3f} | 100% |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", type=Path, default=None, help="Folder to keep the logs and outputs in.")
    args = parser.parse_args()
    out = [f"start-up (estimate --help, its own process): {wall(['estimate', '--help']):.2f} s wall"]
    with work_folder(args.keep, "wbf-bench-stages-") as folder:
        talos = load_robot("talos")
        walk = folder / "walk.parquet"
        pq.write_table(combined_walk(talos), walk)
        trot = folder / "trot.parquet"
        wall(["simulate", "--robot", "go2_walking", "--gait", "trot", "--duration", "8", "-o", str(trot)])
        for name, robot, log, floor in (("TALOS combined walk", "talos", walk, bare_loop(talos, pq.read_table(walk))),
                                         ("Go2 trot on point feet", "go2_walking", trot, None)):
            argv = ["estimate", str(log), "--robot", robot, "--workers", "1", "-o", str(folder / "f.parquet")]
            times, total = profiled(argv)
            out.append(table(name, pq.read_metadata(log).num_rows, times, total, in_process(argv), floor))
    print("\n\n".join(out))


if __name__ == "__main__":
    main()

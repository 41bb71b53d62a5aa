"""Ideal simulator speed (real-time factor) and the ``simulate`` command's total run time.

Run: ``taskset -c 0 python benchmarks/bench_simulate.py``. Prints, for TALOS walking
10 steps forward at 1 kHz: the time to plan the reference (footsteps, LIPM, whole-body IK),
the simulation (controller included: feed-forward inverse dynamics and PD), and the
real-time factors, in wall and CPU time (CPU time is the steadier on a shared machine);
then runs ``wbfriction simulate --gait combined`` (31.8 s of walking: reference, simulation,
writing the log) and ``wbfriction demo`` once each and prints their wall and CPU times.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from wbfriction.model.loading import load_robot
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.studies.common import SIMULATOR
from wbfriction.walking import GaitOptions, walking_reference

T = TypeVar("T")


def timed(f: Callable[[], T]) -> tuple[T, float, float]:
    """``f()``, its wall time and its CPU time [s]."""
    w, c = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - w, time.process_time() - c


def command(args: list[str]) -> tuple[float, float]:
    """Wall and CPU time (user + system, children) [s] of ``python -m wbfriction args``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    w = time.perf_counter()
    subprocess.run([sys.executable, "-m", "wbfriction", *args], check=True, capture_output=True)
    wall = time.perf_counter() - w
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main() -> None:
    robot = load_robot("talos")
    ref, w_ref, c_ref = timed(lambda: walking_reference(robot, GaitOptions(gait="forward", steps=10)))
    sim_time = float(ref.time[-1])
    print(f"simulated time {sim_time:.1f} s ({len(ref)} samples at 1 kHz); times: wall / CPU")

    def report(label: str, wall: float, cpu: float) -> None:
        print(f"{label}: {wall:.2f} / {cpu:.2f} s, real-time factor {sim_time / wall:.1f} / {sim_time / cpu:.1f}")

    report("reference (plan + IK)", w_ref, c_ref)
    _, w, c = timed(lambda: simulate_ideal(robot, ref))
    report("simulation (controller included), velocity projected at every sample", w, c)
    report("reference + simulation", w_ref + w, c_ref + c)
    _, w, c = timed(lambda: simulate_ideal(robot, ref, options=IdealOptions(projection="touch-down")))
    report("simulation, velocity projected at touch-down only", w, c)
    _, w, c = timed(lambda: simulate_ideal(robot, ref, options=SIMULATOR))
    report(f"simulation as in the demo, {SIMULATOR.substeps} physics steps per sample", w, c)
    with tempfile.TemporaryDirectory() as out:
        w, c = command(["simulate", "-o", str(Path(out) / "walk.parquet"), "--gait", "combined"])
        print(f"wbfriction simulate --gait combined (31.8 s walked): {w:.1f} / {c:.1f} s, "
              f"real-time factor {31.8 / w:.1f} / {31.8 / c:.1f}")
        w, c = command(["demo", "-o", out])
        print(f"wbfriction demo: {w:.1f} / {c:.1f} s")


if __name__ == "__main__":
    main()

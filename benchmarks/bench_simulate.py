"""Ideal simulator speed (real-time factor) and the demo's total run time.

Run: ``taskset -c 0 python benchmarks/bench_simulate.py``. Prints, for TALOS walking
10 steps forward at 1 kHz: the time to plan the reference (footsteps, LIPM, whole-body IK),
the simulation loop (controller included: feed-forward inverse dynamics and PD), and the
real-time factors; then runs ``wbfriction demo`` once and prints its wall time.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time

from wbfriction.model.loading import load_robot
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.studies.common import SIMULATOR
from wbfriction.walking import GaitOptions, walking_reference


def main() -> None:
    robot = load_robot("talos")
    t0 = time.perf_counter()
    ref = walking_reference(robot, GaitOptions(gait="forward", steps=10))
    t1 = time.perf_counter()
    simulate_ideal(robot, ref)
    t2 = time.perf_counter()
    simulate_ideal(robot, ref, options=IdealOptions(projection="touch-down"))
    t3 = time.perf_counter()
    simulate_ideal(robot, ref, options=SIMULATOR)
    t4 = time.perf_counter()
    sim_time = ref.time[-1]
    print(f"simulated time {sim_time:.1f} s ({len(ref)} samples at 1 kHz)")
    print(f"reference (plan + IK): {t1 - t0:.2f} s, real-time factor {sim_time / (t1 - t0):.1f}")
    print(f"simulation (controller included), velocity projected at every sample: {t2 - t1:.2f} s, "
          f"real-time factor {sim_time / (t2 - t1):.1f}")
    print(f"simulation, velocity projected at touch-down only: {t3 - t2:.2f} s, "
          f"real-time factor {sim_time / (t3 - t2):.1f}")
    print(f"simulation as in the demo, {SIMULATOR.substeps} physics steps per sample: {t4 - t3:.2f} s, "
          f"real-time factor {sim_time / (t4 - t3):.1f}")
    print(f"reference + simulation: real-time factor {sim_time / (t2 - t0):.1f}")
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "wbfriction", "demo", "-o", out], check=True, capture_output=True)
        print(f"wbfriction demo: {time.perf_counter() - t:.1f} s")


if __name__ == "__main__":
    main()

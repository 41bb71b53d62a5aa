"""MuJoCo simulator speed (real-time factor), controller included.

Run: ``taskset -c 0 python benchmarks/bench_mujoco.py``. Prints, for TALOS walking the command line's
default combined gait (``wbfriction simulate --gait combined --simulator mujoco``: 31.8 s at 1 kHz, 4 physics
steps per control period, friction (3.5) on the 12 leg joints at every physics step, sensors logged), the set-up
(model, feed-forward inverse dynamics of the reference, gains), the simulation loop alone (controller, physics,
sensors) and the log's assembly, each in wall and CPU seconds, and the loop's real-time factor; the same with
MuJoCo's own joint friction, and with sensor noise and a 2 ms delay. The reference (plan + IK) is timed apart,
as in ``bench_simulate.py``. On a shared machine, read the CPU times (and compare against another checkout run
back to back).
"""

from __future__ import annotations

import time

from wbfriction.model.loading import load_robot
from wbfriction.sim import MujocoOptions
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.sim.mujoco_sim import MujocoRun
from wbfriction.studies.realistic import NOISE
from wbfriction.walking import GaitOptions, walking_reference


def _clock() -> tuple[float, float]:
    """(wall, CPU) time now [s]."""
    return time.perf_counter(), time.process_time()


def main() -> None:
    robot = load_robot("talos")
    t0 = time.perf_counter()
    ref = walking_reference(robot, GaitOptions(gait="combined"))
    t1 = time.perf_counter()
    mjr = build_mujoco_robot(robot)
    sim_time = ref.time[-1] - ref.time[0]
    print(f"simulated time {sim_time:.1f} s ({len(ref)} samples at 1 kHz); reference (plan + IK): {t1 - t0:.2f} s")
    for label, options in (("friction (3.5) as joint torque", MujocoOptions()),
                           ("MuJoCo frictionloss + damping", MujocoOptions(friction="mujoco")),
                           ("friction (3.5), sensor noise, 2 ms delay", MujocoOptions(sensors=NOISE, delay=0.002))):
        clock = [_clock()]
        run = MujocoRun(robot, ref, None, options, mjr)  # what simulate_mujoco does, timed part by part
        clock.append(_clock())
        for k in range(len(ref)):
            run.sample(k)
        clock.append(_clock())
        run.result()
        clock.append(_clock())
        (setup_w, setup_c), (loop_w, loop_c), (log_w, log_c) = (
            (b[0] - a[0], b[1] - a[1]) for a, b in zip(clock, clock[1:]))
        print(f"{label}: set-up {setup_w:.2f} s (CPU {setup_c:.2f}), loop {loop_w:.2f} s (CPU {loop_c:.2f}), "
              f"real-time factor {sim_time / loop_w:.1f} (CPU {sim_time / loop_c:.1f}), log {log_w:.2f} s "
              f"(CPU {log_c:.2f}); {options.substeps} physics steps per period")


if __name__ == "__main__":
    main()

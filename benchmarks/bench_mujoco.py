"""MuJoCo simulator speed (real-time factor), controller included.

Run: ``taskset -c 0 python benchmarks/bench_mujoco.py``. Prints, for TALOS walking 10 steps
forward and 10 sideways at 1 kHz on MuJoCo (default options: 4 physics steps per
control period, friction (3.5) on the 12 leg joints at every physics step): the time of
the simulation loop including the controller (feed-forward inverse dynamics of the
reference, PD on the measured state) and its real-time factor; the same with MuJoCo's own
joint friction, and with sensor noise and a 2 ms delay. The reference (plan + IK) is
timed apart, as in ``bench_simulate.py``.
"""

from __future__ import annotations

import time

from wbfriction.model.loading import load_robot
from wbfriction.sim import MujocoOptions, simulate_mujoco
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.studies.realistic import NOISE
from wbfriction.walking import GaitOptions, walking_reference


def main() -> None:
    robot = load_robot("talos")
    t0 = time.perf_counter()
    ref = walking_reference(robot, GaitOptions(gait="both", steps=10))
    t1 = time.perf_counter()
    mjr = build_mujoco_robot(robot)
    sim_time = ref.time[-1]
    print(f"simulated time {sim_time:.1f} s ({len(ref)} samples at 1 kHz); reference (plan + IK): {t1 - t0:.2f} s")
    for label, options in (("friction (3.5) as joint torque", MujocoOptions()),
                           ("MuJoCo frictionloss + damping", MujocoOptions(friction="mujoco")),
                           ("friction (3.5), sensor noise, 2 ms delay", MujocoOptions(sensors=NOISE, delay=0.002))):
        t = time.perf_counter()
        simulate_mujoco(robot, ref, options=options, mjr=mjr)
        elapsed = time.perf_counter() - t
        print(f"{label}: {elapsed:.2f} s, real-time factor {sim_time / elapsed:.1f} "
              f"({options.substeps} physics steps per period)")


if __name__ == "__main__":
    main()

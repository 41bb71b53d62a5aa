"""Ideal simulator speed against the bare dynamics of the same steps, and the ``simulate`` command as a user runs it.

Run: ``taskset -c 0 python benchmarks/bench_simulate.py [--reference SRC] [--demo]``. For TALOS walking 10 steps
forward at 1 kHz (11.8 s simulated) it prints, in wall and CPU seconds and as real-time factors (simulated time /
time taken; CPU time is the steadier on a shared machine):

* the reference (plan + IK) and the simulation (controller included: feed-forward inverse dynamics, PD, friction,
  log), with the velocity projected at every sample (the default) and at touch-downs only;
* the bare dynamics of the same steps, measured in the same run: a Python loop of ``pin.impulseDynamics`` and
  ``pin.constraintDynamics`` over the simulation's own states and torques with the same contact constraints (what
  each step of the simulator must compute), and of ``pin.constraintDynamics`` alone; the simulation's ratio to it
  (1.0 would be a simulator with no cost beyond Pinocchio's);
* ``wbfriction simulate --gait combined`` (31.8 s walked), process start to log written, best CPU of two runs,
  against its floor measured in the same run: the combined walk's reference (plan + IK) plus the bare dynamics of
  its steps (``--reference SRC`` also times another checkout's ``src``, e.g. the code before a change);
* the combined walk's reference (plan + IK) in a fresh process, CPU per sample, against the simulation of the
  same walk (its floor's other half, the bare dynamics) and, with ``--reference SRC``, against the other
  checkout's reference measured the same way (:func:`reference_cpu`);
* with ``--demo``: the simulation as in the demo (10 physics steps per sample) and ``wbfriction demo``.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np
import pinocchio as pin

from wbfriction.model.loading import load_robot
from wbfriction.model.robot import Robot
from wbfriction.sim import IdealOptions, SimulationResult, simulate_ideal
from wbfriction.sim.ideal import contact_constraints
from wbfriction.studies.common import SIMULATOR
from wbfriction.walking import GaitOptions, WalkingReference, walking_reference
from wbfriction.walking.swing import foot_placement

T = TypeVar("T")


def timed(f: Callable[[], T]) -> tuple[T, float, float]:
    """``f()``, its wall time and its CPU time [s]."""
    w, c = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - w, time.process_time() - c


def command(args: list[str], src: str | None = None, repeat: int = 2) -> tuple[float, float]:
    """Wall and CPU time (user + system of the child) [s] of ``python -m wbfriction args``, the run of least CPU
    of ``repeat``; ``src``: another checkout's ``src`` folder to run instead of this one."""
    env = dict(os.environ) if src is None else {**os.environ, "PYTHONPATH": src}
    runs = []
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        w = time.perf_counter()
        subprocess.run([sys.executable, "-m", "wbfriction", *args], check=True, capture_output=True, env=env)
        wall = time.perf_counter() - w
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        runs.append((wall, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime))
    return min(runs, key=lambda r: r[1])


REFERENCE_RUN = """
import time
from wbfriction.model.loading import load_robot
from wbfriction.walking import GaitOptions, walking_reference
robot = load_robot("talos")
walking_reference(robot, GaitOptions(gait="forward", steps=1))  # imports and first calls out of the timing
cpu = time.process_time()
n = len(walking_reference(robot, GaitOptions(gait="combined", steps=10)))
print(time.process_time() - cpu, n)
"""


def reference_cpu(src: str | None = None, repeat: int = 2) -> tuple[float, int]:
    """CPU time [s] of the combined walk's reference (10 steps each way: plan, LIPM, whole-body IK) in a fresh
    process, imports excluded, least of ``repeat``, and its number of samples; ``src``: another checkout's
    ``src`` folder to run instead of this one."""
    env = dict(os.environ) if src is None else {**os.environ, "PYTHONPATH": src}
    runs = []
    for _ in range(repeat):
        out = subprocess.run([sys.executable, "-c", REFERENCE_RUN], check=True, capture_output=True, text=True,
                             env=env).stdout.split()
        runs.append((float(out[0]), int(out[1])))
    return min(runs)


def print_reference_cpu(src: str | None, versus: tuple[str, float] | None = None) -> None:
    """Print the combined walk's reference CPU (:func:`reference_cpu`) of this checkout, per sample, against
    ``versus`` (a label and a CPU time [s] measured in this run) and, given ``src``, against that checkout's."""
    cpu, n = reference_cpu()
    line = (f"  reference (plan + IK) of the combined walk, fresh process: {cpu:.2f} s CPU, "
            f"{cpu / n * 1e6:.0f} us/sample")
    if versus is not None:
        line += f"; {cpu / versus[1]:.2f} x {versus[0]}"
    print(line)
    if src is not None:
        before, _ = reference_cpu(src)
        print(f"  [reference] the same: {before:.2f} s CPU, {before / n * 1e6:.0f} us/sample; this checkout "
              f"{before / cpu:.2f} x faster")


def bare_dynamics(robot: Robot, reference: WalkingReference, result: SimulationResult, impulse: bool = True,
                  baumgarte: tuple[float, float] = IdealOptions().baumgarte) -> tuple[float, float]:
    """Wall and CPU time [s] of the dynamics alone over a simulation's samples: at each, ``pin.impulseDynamics``
    (if ``impulse``) and ``pin.constraintDynamics`` at the logged state (configuration, velocity), with the
    logged torque commands plus friction on the torque-controlled joints, the feet welded where the simulator
    welds them (flat on the planned footprint from their landing on) and the simulator's Proximal settings."""
    model, data = robot.model, robot.model.createData()
    settings = pin.ProximalSettings(1e-12, 1e-10, 50)
    contact = reference.contact
    switches = np.flatnonzero(np.any(np.diff(contact, axis=0, prepend=False), axis=1))
    tau = np.zeros((len(reference), model.nv))
    tau[:, robot.act_v_index[robot.tc_index]] = result.log.tau + np.nan_to_num(result.log.tau_f_true)
    q, v = result.q, result.v
    anchors: dict[int, pin.SE3] = {}
    sets = {}
    for k in switches:  # the constraint sets of the run, built before the timed loop
        landing = contact[k] & ~(contact[k - 1] if k > 0 else np.zeros_like(contact[k]))
        anchors.update({int(c): foot_placement(reference.feet[k, c]) for c in np.flatnonzero(landing)})
        sets[int(k)] = contact_constraints(robot, data, contact[k], anchors, baumgarte)
    impulse_dynamics, constraint_dynamics = pin.impulseDynamics, pin.constraintDynamics
    w, c = time.perf_counter(), time.process_time()
    for k in range(len(reference)):
        if k in sets:
            cmodels, cdatas = sets[k]
            pin.initConstraintDynamics(model, data, cmodels, cdatas)
        if impulse:
            impulse_dynamics(model, data, q[k], v[k], cmodels, cdatas, 0.0, settings)
        constraint_dynamics(model, data, q[k], v[k], tau[k], cmodels, cdatas, settings)
    return time.perf_counter() - w, time.process_time() - c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default=None, help="Another checkout's src folder: its command timed too.")
    parser.add_argument("--demo", action="store_true", help="Also the demo's simulator and wbfriction demo.")
    args = parser.parse_args()
    robot = load_robot("talos")
    ref, w_ref, c_ref = timed(lambda: walking_reference(robot, GaitOptions(gait="forward", steps=10)))
    sim_time = float(ref.time[-1])
    print(f"TALOS, 10 steps forward: {sim_time:.1f} s simulated ({len(ref)} samples at 1 kHz); wall / CPU [s], "
          "real-time factor wall / CPU")

    def report(label: str, wall: float, cpu: float, span: float = sim_time, versus: tuple[float, float] | None = None
               ) -> None:
        ratio = "" if versus is None else f"; {wall / versus[0]:.2f} / {cpu / versus[1]:.2f} x the bare dynamics"
        print(f"  {label}: {wall:.2f} / {cpu:.2f} s, real-time factor {span / wall:.1f} / {span / cpu:.1f}{ratio}")

    report("reference (plan + IK)", w_ref, c_ref)
    result, w, c = timed(lambda: simulate_ideal(robot, ref))
    bare = bare_dynamics(robot, ref, result)
    report("bare dynamics of the same steps (impulseDynamics + constraintDynamics)", *bare)
    report("simulation (controller included), velocity projected at every sample", w, c, versus=bare)
    report("reference + simulation", w_ref + w, c_ref + c)
    bare_td = bare_dynamics(robot, ref, result, impulse=False)
    report("bare dynamics without the projection (constraintDynamics only)", *bare_td)
    _, w, c = timed(lambda: simulate_ideal(robot, ref, options=IdealOptions(projection="touch-down")))
    report("simulation, velocity projected at touch-downs only", w, c, versus=bare_td)
    if args.demo:
        _, w, c = timed(lambda: simulate_ideal(robot, ref, options=SIMULATOR))
        report(f"simulation as in the demo, {SIMULATOR.substeps} physics steps per sample", w, c)

    combined, w_cref, c_cref = timed(lambda: walking_reference(robot, GaitOptions(gait="combined", steps=10)))
    span = float(combined.time[-1])
    combined_sim, _, c_sim = timed(lambda: simulate_ideal(robot, combined))
    w_cb, c_cb = bare_dynamics(robot, combined, combined_sim)
    floor = (w_cref + w_cb, c_cref + c_cb)
    print(f"wbfriction simulate --gait combined ({span:.1f} s walked), best of 2; its floor in this run: the "
          f"reference {w_cref:.2f} / {c_cref:.2f} s + the bare dynamics {w_cb:.2f} / {c_cb:.2f} s")
    report("floor (reference + bare dynamics)", *floor, span=span)
    print_reference_cpu(args.reference, ("its simulation", c_sim))
    codes = {"this checkout": None} if args.reference is None else {"this checkout": None, "reference": args.reference}
    with tempfile.TemporaryDirectory() as out:
        for code, src in codes.items():
            wall, cpu = command(["simulate", "-o", str(Path(out) / "walk.parquet"), "--gait", "combined"], src)
            print(f"  [{code}] command: {wall:.2f} / {cpu:.2f} s, real-time factor {span / wall:.1f} / "
                  f"{span / cpu:.1f}; {wall / floor[0]:.2f} / {cpu / floor[1]:.2f} x its floor")
        if args.demo:
            w, c = command(["demo", "-o", out], repeat=1)
            print(f"wbfriction demo: {w:.1f} / {c:.1f} s")


if __name__ == "__main__":
    main()

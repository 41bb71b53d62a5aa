"""MuJoCo simulator speed against MuJoCo's own physics over the same steps, and the command as a user runs it.

Run: ``taskset -c 0 python benchmarks/bench_mujoco.py [--reference SRC]``. For TALOS walking the command line's
default combined gait (31.8 s at 1 kHz, 4 physics steps per control period, friction (3.5) on the 12 leg joints at
every physics step, sensors logged) it prints, in wall and CPU seconds:

* per option set (friction (3.5) as a joint torque; MuJoCo's own joint friction; sensor noise and a 2 ms delay):
  the set-up (feed-forward inverse dynamics of the reference, gains), the simulation loop (controller, physics,
  sensors) with its real-time factor, and the log's assembly; against the physics alone, measured in the same
  run over the same steps (:func:`bare_physics`: ``mj_step`` from each period's logged state with its logged motor
  torques and friction, the loop's floor), as the loop's ratio to it;
* ``wbfriction simulate --gait combined --simulator mujoco``, process start to log written (best CPU of two runs),
  with its real-time factor, against its floor in this run: the reference (plan + IK) plus the physics alone
  (``--reference SRC`` also times another checkout's ``src``, e.g. the code before a change);
* the reference (plan + IK) in a fresh process against the physics alone and, with ``--reference SRC``, against
  the other checkout's (:func:`bench_simulate.print_reference_cpu`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import mujoco
from bench_simulate import command, print_reference_cpu

from wbfriction.model.loading import load_robot
from wbfriction.sim import MujocoOptions
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.sim.mujoco_sim import MujocoRun
from wbfriction.studies.realistic import NOISE
from wbfriction.walking import GaitOptions, walking_reference


def _clock() -> tuple[float, float]:
    """(wall, CPU) time now [s]."""
    return time.perf_counter(), time.process_time()


def bare_physics(run: MujocoRun) -> tuple[float, float]:
    """Wall and CPU time [s] of MuJoCo's physics alone over a finished run's steps: for each period, the state the
    run logged at its start, the motor torques and (with the ``model`` friction) the first step's friction held,
    then ``mj_step`` for the period's physics steps in one call (no Python between them)."""
    model, data, n = run.model, mujoco.MjData(run.model), run.options.substeps
    qpos, qvel, ctrl, friction = run.qpos, run.qvel, run.tau_motor, run.tau_f_first
    applied = data.qfrc_applied
    clock = _clock()
    for k in range(len(qpos)):
        data.qpos[:], data.qvel[:], data.ctrl[:] = qpos[k], qvel[k], ctrl[k]
        if run.torque_friction:
            applied[run.dof_f] = friction[k]
        mujoco.mj_step(model, data, n)
    end = _clock()
    return end[0] - clock[0], end[1] - clock[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default=None, help="Another checkout's src folder: its command timed too.")
    args = parser.parse_args()
    robot = load_robot("talos")
    t0 = _clock()
    ref = walking_reference(robot, GaitOptions(gait="combined"))
    t1 = _clock()
    mjr = build_mujoco_robot(robot)
    sim_time = ref.time[-1] - ref.time[0]
    print(f"TALOS, combined walk: {sim_time:.1f} s simulated ({len(ref)} samples at 1 kHz); reference (plan + IK) "
          f"{t1[0] - t0[0]:.2f} / {t1[1] - t0[1]:.2f} s; wall / CPU [s]")
    physics_default = 0.0  # CPU [s]
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
        bare_w, bare_c = bare_physics(run)
        physics_default = physics_default or bare_c
        print(f"{label} ({options.substeps} physics steps per period):\n"
              f"  set-up {setup_w:.2f} / {setup_c:.2f} s; loop {loop_w:.2f} / {loop_c:.2f} s, real-time factor "
              f"{sim_time / loop_w:.1f} / {sim_time / loop_c:.1f}; log {log_w:.2f} / {log_c:.2f} s\n"
              f"  physics alone (the same steps, bare mj_step) {bare_w:.2f} / {bare_c:.2f} s, real-time factor "
              f"{sim_time / bare_w:.1f} / {sim_time / bare_c:.1f}; the loop {loop_w / bare_w:.2f} / "
              f"{loop_c / bare_c:.2f} x the physics")
    floor = t1[1] - t0[1] + physics_default
    print(f"wbfriction simulate --gait combined --simulator mujoco, best of 2; its floor in this run: the reference "
          f"plus the physics alone {floor:.2f} s (CPU), real-time factor {sim_time / floor:.1f}")
    print_reference_cpu(args.reference, ("the physics alone", physics_default))
    codes = {"this checkout": None} if args.reference is None else {"this checkout": None, "reference": args.reference}
    with tempfile.TemporaryDirectory() as out:
        for code, src in codes.items():
            wall, cpu = command(["simulate", "-o", str(Path(out) / "walk.parquet"), "--gait", "combined",
                                 "--simulator", "mujoco"], src)
            print(f"  [{code}] command: {wall:.2f} / {cpu:.2f} s, real-time factor {sim_time / wall:.1f} / "
                  f"{sim_time / cpu:.1f}; {cpu / floor:.2f} x its floor (CPU)")


if __name__ == "__main__":
    main()

"""Estimation throughput on TALOS in single support, next to a bare constraintDynamics loop.

Prints samples/s of ``wbfriction.estimate_friction`` (default route: inverse dynamics
on the stance-rooted tree, batched) and of a plain Python loop of
``pin.constraintDynamics`` (one 6D contact) over the same samples, and their ratio.
Pinned to one thread: run with ``taskset -c 0`` for a strict one-core figure.

    python benchmarks/bench_estimate.py [--samples 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

from wbfriction.friction.estimate import EstimateOptions, estimate_friction  # noqa: E402
from wbfriction.model.loading import load_robot  # noqa: E402
from wbfriction.signals.kinematics import MeasuredKinematics  # noqa: E402


def samples(robot, n: int, seed: int = 0) -> tuple[MeasuredKinematics, np.ndarray, np.ndarray]:
    """Random single-support samples on the left sole (q within limits, qd, qdd, tau)."""
    rng = np.random.default_rng(seed)
    lo, hi = robot.angle_limits
    angles = rng.uniform(lo, hi, (n, robot.n_act))
    qd = rng.normal(0, 1, (n, robot.n_act))
    qdd = rng.normal(0, 5, (n, robot.n_act))
    tau = rng.normal(0, 20, (n, len(robot.torque_controlled)))
    contact = np.zeros((n, len(robot.contact_frames)), dtype=bool)
    contact[:, 0] = True
    kin = MeasuredKinematics(time=np.arange(n) * 1e-3, q=angles, qd=qd, qdd=qdd, tau=tau, contact=contact)
    return kin, angles, qd


def bare_constraint_dynamics(robot, angles: np.ndarray, qd: np.ndarray) -> float:
    """Seconds for a Python loop of pin.constraintDynamics (6D contact on the left sole)."""
    model, data = robot.model, robot.model.createData()
    fr = model.frames[robot.contact_frame_ids[0]]
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, fr.parentJoint, fr.placement, pin.LOCAL)
    models, datas = [cm], [cm.createData()]
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-12, 1e-12, 1)
    q = robot.configuration(angles)
    v = np.zeros((len(angles), model.nv))
    v[:, robot.act_v_index] = qd
    tau = np.zeros(model.nv)
    t0 = time.perf_counter()
    for k in range(len(angles)):
        pin.constraintDynamics(model, data, q[k], v[k], tau, models, datas, settings)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    robot = load_robot("talos")
    kin, angles, qd = samples(robot, args.samples)
    opts = EstimateOptions(lift_off_skip=0.0, touch_down_skip=0.0)
    bare = EstimateOptions(lift_off_skip=0.0, touch_down_skip=0.0, acceleration_difference=False)
    estimate_friction(robot, kin, opts)  # warm-up: builds and caches the stance model
    t_est = min(_timed(lambda: estimate_friction(robot, kin, opts)) for _ in range(args.repeat))
    t_tau = min(_timed(lambda: estimate_friction(robot, kin, bare)) for _ in range(args.repeat))
    t_bare = min(bare_constraint_dynamics(robot, angles, qd) for _ in range(args.repeat))
    n = args.samples
    print(f"TALOS, {n} single-support samples, best of {args.repeat}, one thread")
    print(f"  wbfriction.estimate_friction : {n / t_est:10.0f} samples/s  ({1e6 * t_est / n:6.2f} us/sample)")
    print(f"    without Delta qdd (tau_f only): {n / t_tau:7.0f} samples/s  ({1e6 * t_tau / n:6.2f} us/sample)")
    print(f"  bare pin.constraintDynamics  : {n / t_bare:10.0f} samples/s  ({1e6 * t_bare / n:6.2f} us/sample)")
    print(f"  time per sample, estimator / bare loop: {t_est / t_bare:.3f}")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()

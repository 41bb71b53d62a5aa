"""Time of the identification loop (``wbfriction identify``) on the demo's combined walk.

Simulates the walk (Table 6.1 friction on the legs), gives the loop a model with every
body's principal moments x1.1 and mass x1.05, and prints the time of each stage (the
acceleration routes, the identifications) and the leg joints' worst friction errors
before and after, the held-out torque RMS and the total mass. With ``--blas`` it then times
the identification on one BLAS thread (as it runs: the same bytes whatever the thread count,
issue 37) against the same work on every BLAS thread available, wall and CPU time.

    python benchmarks/bench_identify.py [--steps 10] [--workers 2] [--passes 2] [--blas]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_info, threadpool_limits

from wbfriction.friction.targets import THESIS_TARGETS
from wbfriction.inertia.closed_loop import identify
from wbfriction.inertia.identification import identify_inertia, log_samples
from wbfriction.inertia.sensitivity import scaled_robot
from wbfriction.model.loading import load_robot
from wbfriction.sim import simulate_ideal
from wbfriction.studies.common import SIMULATOR, leg_joints
from wbfriction.walking import GaitOptions, walking_reference


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10, help="steps per direction of the combined walk")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--passes", type=int, default=2)
    parser.add_argument("--blas", action="store_true", help="time the identification on 1 and on every BLAS thread")
    args = parser.parse_args()

    talos = load_robot("talos")
    legs = leg_joints(talos)
    t = time.perf_counter()
    ref = walking_reference(talos, GaitOptions(gait="combined", steps=args.steps))
    log = simulate_ideal(talos, ref, {j: THESIS_TARGETS[g] for j, _, g in legs}, SIMULATOR).log
    print(f"simulated {len(log.time)} samples in {time.perf_counter() - t:.1f} s")
    wrong = scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")

    start = last = time.perf_counter()

    def stage(label: str) -> None:
        nonlocal last
        now = time.perf_counter()
        print(f"{now - start:7.1f} s (+{now - last:5.1f}) {label}", flush=True)
        last = now

    loop = identify(wrong, log, passes=args.passes, progress=stage, workers=args.workers)
    stage("done")
    names = {j for j, _, _ in legs}
    for label, route in (("given model", loop.given), ("identified model", loop.final.route)):
        fits = [f for f in route.fits if f.joint in names]
        worst = {n: max(f.error_percent()[n] for f in fits) for n in ("F_v", "F_c", "tau_os")}
        gen = max(e.generating_share for e in route.energy)
        print(f"{label:17s} leg worst: " + ", ".join(f"{n} {v:.2f} %" for n, v in worst.items())
              + f"; power-generating share, every joint: {100 * gen:.2f} %")
    ident = loop.final.identification
    legs_tc = np.isin(talos.torque_controlled, list(names))
    for label, rms in (("identified", ident.holdout.identified), ("validated", ident.holdout.validated),
                       ("given", ident.holdout.given), ("given + best friction", ident.holdout.given_with_friction)):
        if rms is not None:
            print(f"held-out RMS per leg joint, {label}: {rms[legs_tc].min():.4f}-{rms[legs_tc].max():.4f} N·m"
                  f" (upper body at most {rms[~legs_tc].max():.4f})")
    print(f"total mass {ident.pi[:, 0].sum():.3f} kg; {ident.message}")
    if args.blas:
        blas_cost(wrong, log, loop.final.stribeck_velocity, loop.final.stribeck_joints)


def blas_cost(robot, log, v_s, joints) -> None:
    """The last pass's identification, on one BLAS thread (as it runs) and on every thread available
    (``blas_threads=None``); the log's split shared, made once."""
    from dataclasses import replace

    from wbfriction.friction.estimate import resolve_differentiation
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.inertia.options import InertialOptions

    estimate, _ = resolve_differentiation(EstimateOptions(), log)
    options = replace(InertialOptions(), stribeck_velocity=v_s, stribeck_joints=joints)
    shared = log_samples(robot, log, estimate, options)
    most = max(int(p["num_threads"]) for p in threadpool_info() if p["user_api"] == "blas")
    runs = {"1 BLAS thread": lambda: identify_inertia(robot, log, estimate, options, shared=shared)}
    with threadpool_limits(most, user_api="blas"):
        runs[f"{most} BLAS threads"] = lambda: identify_inertia(robot, log, estimate, options, shared=shared,
                                                                       blas_threads=None)
        for label, run in runs.items():
            wall, cpu = time.perf_counter(), time.process_time()
            run()
            print(f"identification on {label}: {time.perf_counter() - wall:.1f} s wall, "
                  f"{time.process_time() - cpu:.1f} s CPU", flush=True)


if __name__ == "__main__":
    main()

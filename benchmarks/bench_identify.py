"""Time of the identification loop (``wbfriction identify``) on the demo's combined walk.

Simulates the walk (Table 6.1 friction on the legs), gives the loop a model with every
body's principal moments x1.1 and mass x1.05, and prints the time of each stage (the
acceleration routes, the identifications) and the leg joints' worst friction errors
before and after.

    python benchmarks/bench_identify.py [--steps 10] [--workers 2] [--passes 2]
"""

from __future__ import annotations

import argparse
import time

from wbfriction.friction.targets import THESIS_TARGETS
from wbfriction.inertia.closed_loop import identify
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


if __name__ == "__main__":
    main()

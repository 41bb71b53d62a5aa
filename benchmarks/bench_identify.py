"""The whole ``wbfriction identify`` command on the combined walk, against ``wbfriction estimate`` of the same log.

Issue 41's figure: ``identify`` on the TALOS combined walk (ideal simulator, ``--steps`` of each gait, Table 6.1
friction on the legs) through a model with every body's principal moments x1.1 and mass x1.05 (the README's case),
timed as a user runs it (``python -m wbfriction identify LOG --robot talos --urdf WRONG -o OUT --json JSON
--workers W``: wall and the child's CPU time, the run of least CPU of ``--repeat``), next to the ``estimate``
command of the same log and model measured in the same run (the ratio: ``identify`` runs the acceleration route
three times, and two identifications), and, with ``--reference SRC``, another checkout's ``identify`` (e.g. the
code before a change) on the same files. Target of issue 41: under 30 s wall on 2 cores.

Then, in this process, the closed loop's stages (:func:`~wbfriction.inertia.closed_loop.identify`): the time of each
acceleration route and each identification, and the leg joints' worst friction errors before and after, the held-out
torque RMS and the total mass. With ``--blas`` it then times the identification on one BLAS thread (as it runs: the
same bytes whatever the thread count, issue 37) against the same work on every BLAS thread available, wall and CPU.

    python benchmarks/bench_identify.py [--steps 10] [--workers 2] [--repeat 1] [--reference SRC] [--keep DIR] [--blas]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from threadpoolctl import threadpool_info, threadpool_limits

sys.path.insert(0, str(Path(__file__).parent))
from bench_estimate import run  # noqa: E402
from bench_long_log import work_folder  # noqa: E402

from wbfriction.fit.targets import THESIS_TARGETS  # noqa: E402
from wbfriction.inertia.closed_loop import identify  # noqa: E402
from wbfriction.inertia.identification import identify_inertia, log_samples  # noqa: E402
from wbfriction.inertia.regressor import body_parameters  # noqa: E402
from wbfriction.inertia.sensitivity import scaled_robot  # noqa: E402
from wbfriction.inertia.urdf import write_urdf  # noqa: E402
from wbfriction.model.loading import load_robot  # noqa: E402
from wbfriction.sim import simulate_ideal  # noqa: E402
from wbfriction.studies.common import SIMULATOR, leg_joints  # noqa: E402
from wbfriction.walking import GaitOptions, walking_reference  # noqa: E402

TARGET = 30.0
"""Issue 41: ``identify`` on the combined walk under this many seconds of wall time on 2 cores."""


def commands(folder: Path, workers: int, repeat: int, reference: str | None) -> None:
    """Time ``estimate`` and ``identify`` (this checkout's, and ``reference``'s) on the files in ``folder``."""
    log, urdf = str(folder / "walk.parquet"), str(folder / "wrong.urdf")
    model = ["--robot", "talos", "--urdf", urdf]
    codes = {"this checkout": None} if reference is None else {"this checkout": None, "reference": reference}
    print(f"\nwhole commands, best of {repeat} (wall; CPU of the process and its workers)")
    est_wall, est_cpu = run(["estimate", log, *model, "-o", str(folder / "friction.parquet"), "--workers", "1"],
                            None, repeat)
    print(f"  estimate (the reference, this checkout): {est_wall:6.1f} s wall, {est_cpu:6.1f} s CPU")
    for code, src in codes.items():
        stem = folder / code.replace(" ", "_")
        wall, cpu = run(["identify", log, *model, "-o", f"{stem}.urdf", "--json", f"{stem}.json",
                         "--workers", str(workers)], src, repeat)
        verdict = "met" if wall < TARGET else "not met"
        print(f"  identify [{code}]: {wall:6.1f} s wall, {cpu:6.1f} s CPU; {wall / est_wall:.1f}x the estimate's "
              f"wall, {cpu / est_cpu:.1f}x its CPU; target {TARGET:.0f} s wall: {verdict}")
    if reference is not None:
        same = all((folder / f"this_checkout{ext}").read_bytes() == (folder / f"reference{ext}").read_bytes()
                   for ext in (".urdf", ".json"))
        print(f"  URDF and JSON of the two checkouts: {'the same bytes' if same else 'differ'}")


def stages(talos, wrong, log, workers: int, passes: int):
    """The closed loop in this process, each stage timed; the friction errors, held-out RMS and mass."""
    legs = leg_joints(talos)
    start = last = time.perf_counter()
    cpu_last = time.process_time()
    spent: dict[str, float] = {"acceleration": 0.0, "identifying": 0.0}
    current = [""]

    def stage(label: str) -> None:
        nonlocal last, cpu_last
        now, cpu = time.perf_counter(), time.process_time()
        if current[0]:
            spent[current[0].split()[0]] += cpu - cpu_last
        print(f"{now - start:7.1f} s (+{now - last:5.1f} wall, {cpu - cpu_last:5.1f} CPU) {label}", flush=True)
        last, cpu_last, current[0] = now, cpu, label

    print("\nthe closed loop in this process (CPU of this process only: the route's fit workers are not counted)")
    loop = identify(wrong, log, passes=passes, progress=stage, workers=workers)
    stage("done")
    print(f"CPU in this process: identifications {spent['identifying']:.1f} s, acceleration routes "
          f"{spent['acceleration']:.1f} s")
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
    return loop


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
        for label, run_it in runs.items():
            wall, cpu = time.perf_counter(), time.process_time()
            run_it()
            print(f"identification on {label}: {time.perf_counter() - wall:.1f} s wall, "
                  f"{time.process_time() - cpu:.1f} s CPU", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=10, help="steps per direction of the combined walk")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--passes", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=1, help="runs of each command; the least CPU is kept")
    parser.add_argument("--reference", default=None, help="another checkout's src folder, timed alongside")
    parser.add_argument("--keep", type=Path, default=None, help="folder to keep the log, the model and outputs in")
    parser.add_argument("--no-stages", action="store_true", help="time the whole commands only")
    parser.add_argument("--blas", action="store_true", help="time the identification on 1 and on every BLAS thread")
    args = parser.parse_args()

    talos = load_robot("talos")
    t = time.perf_counter()
    ref = walking_reference(talos, GaitOptions(gait="combined", steps=args.steps))
    log = simulate_ideal(talos, ref, {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}, SIMULATOR).log
    print(f"simulated {len(log.time)} samples in {time.perf_counter() - t:.1f} s")
    wrong = scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")
    with work_folder(args.keep, "wbf-bench-identify-") as folder:
        pq.write_table(log.to_table(talos), folder / "walk.parquet")
        write_urdf(talos, body_parameters(wrong.model), folder / "wrong.urdf")
        commands(folder, args.workers, args.repeat, args.reference)
    if not args.no_stages:
        loop = stages(talos, wrong, log, args.workers, args.passes)
        if args.blas:
            blas_cost(wrong, log, loop.final.stribeck_velocity, loop.final.stribeck_joints)


if __name__ == "__main__":
    main()

"""The whole ``wbfriction estimate`` command against a bare ``pin.constraintDynamics`` loop.

Times what a user waits for: the command from process start to output written (``python -m
wbfriction estimate LOG -o OUT --workers 1``, CPU time of the child process and wall time), on

* the 31,801-row TALOS combined walk of the ideal simulator (24 % double support), and
* a 20,000-row single-support log (the same walk's rows, the left sole flagged throughout),

next to a Python loop of ``pin.constraintDynamics`` (one 6D contact on the left sole, PROXIMAL
settings as in Pinocchio's examples) over the same rows, measured in the same run. Prints rows/s
and the speed ratio (command rows/s / bare-loop rows/s: issue 41's figure, target >= 1.0), the
command's fixed start-up cost (``estimate --help``: interpreter, imports) and its marginal cost per
row (the same log repeated four times, minus once). Then the cost of each route alone, in this
process (``estimate_resolved`` without the other route's check, the log already read; issue 41: the
momentum route at no more than 1.2 times the acceleration route's). ``--reference SRC`` also times
another checkout's ``src`` (e.g. the code before a change) on the same logs. One thread per process;
run under ``taskset -c 0`` for a strict one-core figure.

    python benchmarks/bench_estimate.py [--repeat 3] [--reference /path/to/old/src] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
import pyarrow as pa  # noqa: E402
import pyarrow.compute as pc  # noqa: E402
import pyarrow.parquet as pq  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from bench_long_log import work_folder  # noqa: E402

from wbfriction.fit.targets import THESIS_TARGETS  # noqa: E402
from wbfriction.model.loading import load_robot  # noqa: E402
from wbfriction.sim import simulate_ideal  # noqa: E402
from wbfriction.studies.common import leg_joints  # noqa: E402
from wbfriction.walking import GaitOptions, walking_reference  # noqa: E402


def combined_walk(robot) -> pa.Table:
    """The issue's log: 10 steps of each gait (31,801 rows), Table 6.1 friction on the legs."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(robot)}
    ref = walking_reference(robot, GaitOptions(gait="combined", steps=10))
    return simulate_ideal(robot, ref, friction).log.to_table(robot)


def single_support_log(walk: pa.Table, rows: int) -> pa.Table:
    """The walk's first ``rows`` rows (tiled if needed) with the left sole flagged in contact throughout."""
    tiles = [walk] * (rows // walk.num_rows + 1)
    table = pa.concat_tables(tiles).slice(0, rows)
    period = float(np.median(np.diff(walk.column("time").to_numpy()[:100])))
    table = table.set_column(table.column_names.index("time"), "time", pa.array(np.arange(rows) * period))
    for name in table.column_names:
        if name.startswith("contact."):
            value = name == "contact.left_sole_link"
            table = table.set_column(table.column_names.index(name), name,
                                     pc.cast(pa.array(np.full(rows, value)), table.schema.field(name).type))
    return table


def tiled(table: pa.Table, times: int) -> pa.Table:
    """``table`` repeated ``times`` times, its clock continued without a gap."""
    t = table.column("time").to_numpy()
    span = t[-1] - t[0] + float(np.median(np.diff(t[:100])))
    parts = [table.set_column(0, "time", pa.array(t + k * span)) for k in range(times)]
    return pa.concat_tables(parts)


def run(args: list[str], src: str | None, repeat: int) -> tuple[float, float]:
    """Wall and CPU time [s] (user + system, the child's) of ``python -m wbfriction ARGS``, the
    run of least CPU time of ``repeat``."""
    return min((_run(args, src) for _ in range(repeat)), key=lambda r: r[1])


def _run(args: list[str], src: str | None) -> tuple[float, float]:
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "wbfriction", *args], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"wbfriction {' '.join(args)} failed:\n{proc.stderr}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def bare_loop(robot, table: pa.Table) -> float:
    """CPU seconds of a Python loop of pin.constraintDynamics over the log's rows (6D contact on the left sole)."""
    model, data = robot.model, robot.model.createData()
    fr = model.frames[robot.contact_frame_ids[0]]
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, fr.parentJoint, fr.placement, pin.LOCAL)
    models, datas = [cm], [cm.createData()]
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-12, 1e-12, 1)
    angles = np.column_stack([table.column(f"q.{j}").to_numpy() for j in robot.actuated])
    q = robot.configuration(angles)
    v = np.zeros((len(angles), model.nv))
    v[1:, robot.act_v_index] = np.diff(angles, axis=0) / 1e-3
    tau = np.zeros(model.nv)
    t0 = time.process_time()
    for k in range(len(angles)):
        pin.constraintDynamics(model, data, q[k], v[k], tau, models, datas, settings)
    return time.process_time() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="Runs of each measurement; the best is kept.")
    parser.add_argument("--reference", default=None, help="Another checkout's src folder to time alongside.")
    parser.add_argument("--keep", type=Path, default=None, help="Folder to keep the logs and outputs in.")
    parser.add_argument("--single-rows", type=int, default=20_000)
    args = parser.parse_args()
    robot = load_robot("talos")
    codes = {"this checkout": None} if args.reference is None else {"this checkout": None, "reference": args.reference}
    with work_folder(args.keep, "wbf-bench-estimate-") as folder:
        walk = combined_walk(robot)
        logs = {"combined walk": walk, "single support": single_support_log(walk, args.single_rows)}
        for name, table in logs.items():
            pq.write_table(table, folder / f"{name.replace(' ', '_')}.parquet")
            pq.write_table(tiled(table, 4), folder / f"{name.replace(' ', '_')}_x4.parquet")
        print(f"TALOS, wbfriction estimate --workers 1, best of {args.repeat} (CPU time of the process; wall)")
        for code, src in codes.items():
            help_wall, help_cpu = run(["estimate", "--help"], src, args.repeat)
            print(f"\n[{code}] start-up (estimate --help): {help_cpu:.2f} s CPU, {help_wall:.2f} s wall")
            for name, table in logs.items():
                stem = folder / name.replace(" ", "_")
                n = table.num_rows
                wall, cpu = run(["estimate", f"{stem}.parquet", "-o", f"{stem}_out.parquet", "--workers", "1"], src,
                                args.repeat)
                wall4, cpu4 = run(["estimate", f"{stem}_x4.parquet", "-o", f"{stem}_x4_out.parquet", "--workers", "1"],
                                  src, args.repeat)
                bare = min(bare_loop(robot, table) for _ in range(args.repeat))
                marginal = (cpu4 - cpu) / (3 * n)
                print(f"  {name}, {n} rows: command {cpu:.2f} s CPU ({wall:.2f} s wall) = {n / cpu:,.0f} rows/s, "
                      f"{1e6 * cpu / n:.1f} us/row; bare constraintDynamics loop {n / bare:,.0f} rows/s, "
                      f"{1e6 * bare / n:.1f} us/row; speed ratio command / bare loop {bare / cpu:.2f}")
                print(f"    marginal cost per row (x4 log: {4 * n} rows in {cpu4:.2f} s CPU): {1e6 * marginal:.1f} "
                      f"us/row = {1 / marginal:,.0f} rows/s; speed ratio to the bare loop {bare / (marginal * n):.2f}")
        if args.reference is None:
            print("\nEach route alone, in this process (CPU time, best of the runs):")
            for name, table in logs.items():
                cost = route_costs(robot, table, args.repeat)
                print(f"  {name}: acceleration {cost['acceleration']:.2f} s, momentum {cost['momentum']:.2f} s: "
                      f"momentum / acceleration {cost['momentum'] / cost['acceleration']:.2f}")


def route_costs(robot, table: pa.Table, repeat: int) -> dict[str, float]:
    """CPU seconds of each route's estimate of the log alone (options resolved once, as the command does; no
    check by the other route), the least of ``repeat`` runs."""
    from dataclasses import replace

    from wbfriction.friction.estimate import estimate_resolved, resolve_differentiation
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.friction.route import resolve_route
    from wbfriction.logs.log import log_from_table

    log = log_from_table(table, robot)
    options, choice = resolve_differentiation(EstimateOptions(), log)
    options, _ = resolve_route(options, log, choice=choice)
    costs = {}
    for route in ("acceleration", "momentum"):
        chosen = replace(options, route=route, check_route=False)
        estimate_resolved(robot, log, chosen, require_single_support=False)  # warm: the stance models built
        times = []
        for _ in range(repeat):
            t0 = time.process_time()
            estimate_resolved(robot, log, chosen, require_single_support=False)
            times.append(time.process_time() - t0)
        costs[route] = min(times)
    return costs

if __name__ == "__main__":
    main()

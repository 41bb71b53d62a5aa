"""The whole ``wbfriction fit`` command on 30 joints, against ``wbfriction estimate`` of the same log.

Issue 41's figure: the fit of the 30 torque-controlled joints of the TALOS combined walk (ideal simulator, 10 steps
of each gait, Table 6.1 friction on the legs; both routes fitted, the model chosen per joint on held-out data),
timed as a user runs it (``python -m wbfriction fit TABLE -o PARAMS --workers W``: wall and the child's CPU time,
the run of least CPU of ``--repeat``), next to the ``estimate`` command that wrote the table, measured in the same
run (the ratio: how much of a log's processing the fit takes; issue 41 measured about 4 on a fleet task). Then, in
this process, where the fit's time goes: the solver runs (``scipy.optimize.least_squares``), their evaluations of
the model and its Jacobian, and the share of the model's expectation under the velocity noise
(:mod:`wbfriction.fit.eiv`). Target of issue 41: under 3 s wall on 2 cores.

    python benchmarks/bench_fit.py [--repeat 3] [--workers 2] [--keep DIR]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
from pathlib import Path

import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).parent))
from bench_estimate import combined_walk, run  # noqa: E402
from bench_long_log import work_folder  # noqa: E402

from wbfriction.fit.joints import fit_estimate  # noqa: E402
from wbfriction.friction.io import read_friction_file  # noqa: E402
from wbfriction.model.loading import load_robot  # noqa: E402


def solver_profile(table: Path) -> None:
    """Solver runs, evaluations and the expectation's share of one in-process ``fit_estimate`` (one worker)."""
    est = read_friction_file(table)
    profile = cProfile.Profile()
    profile.enable()
    fit_estimate(est)
    profile.disable()
    stats = pstats.Stats(profile).stats  # type: ignore[attr-defined]
    total = max(v[3] for v in stats.values())

    def of(module: str, name: str) -> tuple[int, float]:
        rows = [(v[1], v[3]) for (path, _, fn), v in stats.items() if path.endswith(module) and fn == name]
        return (sum(r[0] for r in rows), sum(r[1] for r in rows)) if rows else (0, 0.0)

    runs, solve = of("least_squares.py", "least_squares")
    values, _ = of("eiv.py", "expected_values")
    jacobians, _ = of("eiv.py", "expected_jacobian")
    _, eiv = of("eiv.py", "_tanh_terms")
    print(f"in process (1 worker, profiled): {total:.2f} s; {runs} solver runs ({100 * solve / total:.0f} %), "
          f"{values} model and {jacobians} Jacobian evaluations under the velocity noise; the expectation's "
          f"tanh terms {100 * eiv / total:.0f} %")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--keep", type=Path, default=None, help="keep the log, table and parameters here")
    args = parser.parse_args()
    robot = load_robot("talos")
    with work_folder(args.keep, "bench_fit_") as folder:
        log, table, params = folder / "walk.parquet", folder / "walk_friction.parquet", folder / "params.json"
        walk = combined_walk(robot)
        pq.write_table(walk, log)
        est_wall, est_cpu = run(["estimate", str(log), "-o", str(table), "--workers", "1"], None, args.repeat)
        fit_wall, fit_cpu = run(["fit", str(table), "-o", str(params), "--workers", str(args.workers)], None,
                                args.repeat)
        joints = sum(1 for c in pq.read_schema(table).names if c.startswith("tau_f."))
        print(f"log: {walk.num_rows} rows, {joints} joints")
        print(f"estimate (reference): {est_wall:6.2f} s wall, {est_cpu:6.2f} s CPU")
        print(f"fit --workers {args.workers}:      {fit_wall:6.2f} s wall, {fit_cpu:6.2f} s CPU; "
              f"fit / estimate: {fit_wall / est_wall:.2f} wall, {fit_cpu / est_cpu:.2f} CPU (target: under 3 s wall)")
        solver_profile(table)


if __name__ == "__main__":
    main()

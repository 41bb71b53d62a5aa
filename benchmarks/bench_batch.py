"""The batch on Dask against the serial run, and the trend report (issue 25).

Makes ``--logs`` logs (two simulated Panda arms, ``--seconds`` each, a different noise seed per log:
:func:`~wbfriction.studies.drifting_fleet.simulate_arm_fleet`) or takes a
``--manifest``, then, in this one run, processes them serially (the reference) and on a local Dask cluster of
``--workers`` processes, and prints for each: logs per minute, rows per second, and the Dask run's overhead per
task (``(workers * wall_dask - wall_serial) / logs``: what the cluster costs beyond dividing the work), the
cluster's start-up apart. It checks the two runs wrote the same bytes. Then it times the trend report
(:func:`~wbfriction.fleet.trends.fleet_trends` and its HTML page) on ``--trend-logs`` logs per robot, made by
repeating the batch's results at later dates.

    python benchmarks/bench_batch.py --logs 24 --workers 2
"""

from __future__ import annotations

import argparse
import tempfile
import time
from datetime import timedelta
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from wbfriction.fleet.batch import local_cluster, run_batch
from wbfriction.fleet.manifest import read_manifest
from wbfriction.fleet.results import read_results
from wbfriction.studies.drifting_fleet import simulate_arm_fleet


def files(results: Path) -> dict[str, bytes]:
    return {str(p.relative_to(results)): p.read_bytes() for p in sorted(results.glob("*/*.parquet"))}


def timed(run) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    run()
    return time.perf_counter() - wall, time.process_time() - cpu


def repeated(table: pa.Table, per_robot: int) -> pa.Table:
    """The results repeated at later dates until every robot has ``per_robot`` logs."""
    parts, shift = [], 0
    logs = len(set(table.column("log").to_pylist()))
    robots = len(set(table.column("robot_id").to_pylist()))
    while shift * logs < per_robot * robots:
        t = table.set_column(table.schema.get_field_index("start_time"), "start_time",
                             pc.add(table.column("start_time"), pa.scalar(timedelta(days=365 * shift))))
        t = t.set_column(t.schema.get_field_index("log"), "log", pc.binary_join_element_wise(
            t.column("log"), pa.scalar(f"#{shift}"), ""))
        parts.append(t)
        shift += 1
    return pa.concat_tables(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", type=int, default=24)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--manifest", type=Path)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--trend-logs", type=int, default=100, help="logs per robot for the trend report")
    args = parser.parse_args()
    from distributed import Client

    with tempfile.TemporaryDirectory() as tmp:
        tmp_path = Path(tmp)
        manifest = args.manifest or simulate_arm_fleet(tmp_path, robots=2, logs=(args.logs + 1) // 2,
                                                       seconds=args.seconds)
        entries = read_manifest(manifest)
        rows = sum(pq.ParquetFile(e.log).metadata.num_rows for e in entries)
        serial = timed(lambda: run_batch(entries, tmp_path / "serial", engine="serial"))
        t0 = time.perf_counter()
        cluster = local_cluster(args.workers)
        client = Client(cluster)
        client.run(lambda: __import__("wbfriction.fleet.task"))  # the workers' imports, as a warm cluster has them
        startup = time.perf_counter() - t0
        dask = timed(lambda: run_batch(entries, tmp_path / "dask", client=client))
        client.close()
        cluster.close()
        same = files(tmp_path / "serial") == files(tmp_path / "dask")
        n = len(entries)
        print(f"{n} logs, {rows} rows ({rows / n:.0f} per log); {args.workers} local Dask workers")
        print(f"{'run':<8} {'wall s':>8} {'logs/min':>9} {'rows/s':>9}")
        for name, (wall, _) in (("serial", serial), ("dask", dask)):
            print(f"{name:<8} {wall:8.2f} {60 * n / wall:9.1f} {rows / wall:9.0f}")
        print(f"speed-up {serial[0] / dask[0]:.2f}x on {args.workers} workers; overhead per task "
              f"{(args.workers * dask[0] - serial[0]) / n * 1e3:.0f} ms; cluster start-up {startup:.2f} s; "
              f"same bytes: {same}")
        try:
            from wbfriction.fleet.trends import fleet_trends
            from wbfriction.report.trends import write_trends_html
        except ImportError:
            return
        table = repeated(read_results(tmp_path / "serial").table, args.trend_logs)
        robots = len(set(table.column("robot_id").to_pylist()))
        wall, _ = timed(lambda: write_trends_html(fleet_trends(table), tmp_path / "trends.html"))
        print(f"trend report: {robots} robots x {args.trend_logs} logs, {table.num_rows} rows: {wall:.2f} s")


if __name__ == "__main__":
    main()

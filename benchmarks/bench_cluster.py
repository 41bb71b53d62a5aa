"""A batch on a user's own Dask cluster (``dask scheduler`` + ``dask worker``) against ``--serial``, and one fleet
task's CPU time (issue 41).

Makes ``--logs`` Panda logs of ``--seconds`` each (:func:`~wbfriction.studies.drifting_fleet.simulate_arm_fleet`),
starts a scheduler and ``dask worker --nworkers W --nthreads 1`` as a user does (their own processes, Dask's own
environment: its nanny sets ``MALLOC_TRIM_THRESHOLD_``), warms the workers with one batch (their imports and the
robot loaded), then times, as whole commands, ``wbfriction batch --scheduler`` and ``wbfriction batch --serial``
on the same manifest into fresh results (the reference, in the same run), and prints the wall time per log of
each, their ratio (issue 41's target: the cluster no slower per log than ``--serial``) and whether both wrote the
same bytes. Then one fleet task (:func:`~wbfriction.fleet.task.process_log`: estimate, fit, check) on one log, in
this process after a first run: its CPU time (target: under 3 s on a 6 s arm log) next to the ``estimate``
command's share of it.

    python benchmarks/bench_cluster.py [--logs 6] [--seconds 6] [--workers 2]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_batch import files  # noqa: E402
from bench_simulate import command  # noqa: E402

from wbfriction.fleet.manifest import read_manifest  # noqa: E402
from wbfriction.fleet.options import BatchOptions  # noqa: E402
from wbfriction.fleet.task import process_log, result_key  # noqa: E402
from wbfriction.studies.drifting_fleet import simulate_arm_fleet  # noqa: E402


def dask_cluster(folder: Path, workers: int) -> tuple[str, list[subprocess.Popen]]:
    """A scheduler and ``workers`` single-threaded workers started by Dask's own commands; its address."""
    scheduler_file = folder / "scheduler.json"
    scheduler = subprocess.Popen(["dask", "scheduler", "--scheduler-file", str(scheduler_file), "--port", "0",
                                  "--dashboard-address", ":0"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = subprocess.Popen(["dask", "worker", "--scheduler-file", str(scheduler_file), "--nworkers", str(workers),
                               "--nthreads", "1", "--dashboard-address", ":0"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    from distributed import Client
    while not scheduler_file.exists():
        time.sleep(0.1)
    with Client(scheduler_file=str(scheduler_file)) as client:
        client.wait_for_workers(workers, timeout=60)
        address = client.scheduler.address
    return address, [worker, scheduler]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", type=int, default=6)
    parser.add_argument("--seconds", type=float, default=6.0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "fleet").mkdir()
        manifest = simulate_arm_fleet(folder / "fleet", robots=1, logs=args.logs, seconds=args.seconds)
        address, processes = dask_cluster(folder, args.workers)
        try:
            common = [str(manifest), "--robot", "panda"]
            command(["batch", *common, "-o", str(folder / "warm"), "--scheduler", address], repeat=1)
            on_cluster = command(["batch", *common, "-o", str(folder / "cluster"), "--scheduler", address], repeat=1)
        finally:
            for p in processes:
                p.terminate()
                p.wait()
        serial = command(["batch", *common, "-o", str(folder / "serial"), "--serial"], repeat=1)
        same = files(folder / "serial") == files(folder / "cluster")
        n = args.logs
        print(f"{n} Panda logs of {args.seconds:g} s; dask scheduler + dask worker --nworkers {args.workers} "
              "--nthreads 1, warm")
        print(f"batch --serial (reference): {serial[0]:6.2f} s wall, {serial[0] / n:5.2f} s per log")
        print(f"batch --scheduler:          {on_cluster[0]:6.2f} s wall, {on_cluster[0] / n:5.2f} s per log; "
              f"per log against --serial: {on_cluster[0] / serial[0]:.2f} (target: at most 1); same bytes: {same}")
        entry = read_manifest(manifest)[0]
        options = BatchOptions()
        key = result_key(entry, "bench", "bench", options)
        (folder / "scratch").mkdir()
        process_log(entry, key, options, folder / "scratch")  # imports, the robot loaded
        cpu = time.process_time()
        process_log(entry, key, options, folder / "scratch")
        task = time.process_time() - cpu
        one = ["estimate", str(entry.log), "--robot", "panda", "-o", str(folder / "one.parquet")]
        estimate = command(one, repeat=1)
        print(f"one fleet task (estimate, fit, check) on a {args.seconds:g} s log: {task:.2f} s CPU (target: under "
              f"3 s); the estimate command alone, start-up included: {estimate[1]:.2f} s CPU")


if __name__ == "__main__":
    main()

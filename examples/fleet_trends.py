"""A fleet's friction over time: many logs on Dask, then the joints whose friction drifted.

    python examples/fleet_trends.py                 # two simulated Panda arms, 12 logs each, in a temporary folder
    python examples/fleet_trends.py --output fleet  # keep the logs, the results and trends.html

Arm 1's fourth joint wears: its Coulomb friction grows by 40 % over its last 5 logs. The batch estimates and fits
every log on a local Dask cluster (``wbfriction batch`` does the same from a manifest), and the trends flag that
joint alone, with the day its drift started. Sign convention: ``tau_f`` is the torque friction exerts on the
joint; F_c > 0 opposes the motion.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from wbfriction.fleet import fleet_trends, read_manifest, read_results, run_batch
from wbfriction.report.trends import write_trends_html
from wbfriction.studies.drifting_fleet import Drift, simulate_arm_fleet

WORN = Drift("arm-1", "panda_joint4", "F_c", 0.40, 5)
"""Arm 1's fourth joint: its Coulomb friction 40 % higher by its last log, growing over its last 5."""


def say(line: str) -> None:
    """A progress line on standard error (standard output keeps the results)."""
    print(line, file=sys.stderr, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, help="folder to keep (default: a temporary one)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.output or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        manifest = simulate_arm_fleet(folder, robots=2, logs=12, drifts=(WORN,), progress=say)
        logs = read_manifest(manifest)
        done = []
        summary = run_batch(logs, folder / "results", workers=2, progress=lambda outcome: (
            done.append(outcome), say(f"batch: {len(done)} of {len(logs)} logs estimated and fitted")))
        print(f"{summary.processed} logs processed on Dask, {summary.skipped} already done")
        trends = fleet_trends(read_results(folder / "results").table)
        write_trends_html(trends, folder / "trends.html")
        for joint in trends.flagged:
            drift = joint.drifts[0]
            print(f"drift: {joint.robot_id} {joint.joint} {drift.quantity} {100 * drift.relative:+.0f} % from "
                  f"{drift.onset_time:%Y-%m-%d}")
        print(f"{trends.summary()}; wrote {folder / 'trends.html'}")


if __name__ == "__main__":
    main()

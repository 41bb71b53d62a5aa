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
import dataclasses
import tempfile
from datetime import UTC, datetime, timedelta
from pathlib import Path

from wbfriction import load_robot
from wbfriction.fleet import fleet_trends, read_manifest, read_results, run_batch
from wbfriction.logs import write_table
from wbfriction.report.trends import write_trends_html
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

LOGS = 12
WORN = ("arm-1", "panda_joint4")


def simulate(folder: Path) -> Path:
    """Two arms' logs, one a day, and their manifest; arm 1's joint 4 wears over its last 5 logs."""
    robot = load_robot("panda")
    base = default_arm_friction(robot)
    lines = ["log,robot_id,start_time,robot"]
    for r in range(2):
        for i in range(LOGS):
            friction = dict(base)
            if f"arm-{r}" == WORN[0]:
                wear = 1.0 + 0.4 * max(0, i - (LOGS - 5) + 1) / 5
                friction[WORN[1]] = dataclasses.replace(base[WORN[1]], F_c=base[WORN[1]].F_c * wear)
            sim = simulate_arm(robot, friction, options=ArmOptions(duration=3.0, seed=100 * r + i, torque_std=0.01))
            write_table(sim.table, folder / f"arm{r}_{i:02d}.parquet")
            start = datetime(2026, 1, 5, 8, tzinfo=UTC) + timedelta(days=i)
            lines.append(f"arm{r}_{i:02d}.parquet,arm-{r},{start.isoformat()},panda")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder / "manifest.csv"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, help="folder to keep (default: a temporary one)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.output or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        manifest = simulate(folder)
        summary = run_batch(read_manifest(manifest), folder / "results", workers=2)
        print(f"{summary.processed} logs processed on Dask, {summary.skipped} already done")
        trends = fleet_trends(read_results(folder / "results"))
        write_trends_html(trends, folder / "trends.html")
        for joint in trends.flagged:
            drift = joint.drifts[0]
            print(f"drift: {joint.robot_id} {joint.joint} {drift.quantity} {100 * drift.relative:+.0f} % from "
                  f"{drift.onset_time:%Y-%m-%d}")
        print(f"{len(trends.flagged)} of {len(trends.joints)} joints drifted; wrote {folder / 'trends.html'}")


if __name__ == "__main__":
    main()

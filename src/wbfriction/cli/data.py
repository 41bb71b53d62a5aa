"""``wbfriction dataset``: real robots' logs, fetched and checked, written as logs with the robot beside them."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import typer

from wbfriction.cli.common import app, console, out, stages
from wbfriction.cli.helpformat import LOGS
from wbfriction.pipeline.paths import check_paths

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only typer:
# the datasets' registry (wbfriction.datasets.DATASETS, which these names equal: tested) is imported when it runs.
DatasetName = Literal["aliengo", "go2", "kuka-lwr4", "panda", "ur10e"]


@app.command(rich_help_panel=LOGS,
             short_help="Fetch a real robot's logs and write them as wbfriction logs")
def dataset(name: DatasetName = typer.Argument(..., metavar="NAME",
                                               help="The dataset: kuka-lwr4 (FloBaRoID's KUKA LWR4+: three runs of "
                                                    "25 s, link-side joint torque sensors, about 6 MB), ur10e "
                                                    "(Mamedov et al.'s UR10e: a 50 s excitation and a joint sweep, "
                                                    "motor currents at 100 Hz, 1 MB), panda (Gaz et al.'s Franka "
                                                    "Panda: 21 s of excitation, link-side torque sensors at 1 kHz, "
                                                    "9 MB), aliengo (the iit-DLSLab's Unitree Aliengo, hung: "
                                                    "23.5 s of ramps on 12 PD-driven joints, no torque sensor, "
                                                    "200 Hz, 1 MB) or go2 (the same lab's Unitree Go2, hung: "
                                                    "23.9 s of ramps, kp 20, kd 1.5, 1 MB)."),
            output_dir: Path = typer.Option(..., "-o", "--output-dir",
                                            help="Folder to write into (made if missing): the logs (kuka-lwr4: "
                                                 "runs12.parquet, run3.parquet held out; ur10e: excitation.parquet, "
                                                 "joint1.parquet held out; panda: excitation.parquet; aliengo, "
                                                 "go2: train.parquet, held_out.parquet, and the peer's "
                                                 "identification peer.toml), the robot's URDF where it is the "
                                                 "dataset's and its configuration <robot>.toml.")) -> None:
    """Fetch a real robot's logs and write them as wbfriction logs with the robot beside them: downloaded once
    into the user's cache, each file checked against its SHA-256, or taken from $WBFRICTION_DATA/<dataset>/ (a
    local copy, for offline machines, checked the same way). Prints the commands to run next."""
    from wbfriction.datasets import write_dataset

    check_paths({}, {}, {"-o": output_dir})
    with stages() as stage:
        stage(f"fetching the {name} dataset")
        written = write_dataset(name, output_dir)
    logs = ", ".join(f"{path} ({written.rows[role]} samples: {written.described.get(role, role)})"
                     for role, path in written.logs.items())
    console.print(f"wrote {logs} and the robot, {written.config}", highlight=False, markup=False)
    for line in ("next:", *(f"  {command}" for command in written.commands)):
        out.print(line, highlight=False, markup=False, soft_wrap=True)
